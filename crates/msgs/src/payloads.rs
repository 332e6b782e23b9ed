//! The fixed-size payloads of every non-image topic.

use crate::{Header, Message, ZeroCopySend};

/// Sensors on the DRV's ring (001 §3: 24 Polaroid sensors).
pub const SONAR_SENSORS: usize = 24;
/// Sensors fired together in one bank (001 §3: 3 banks of 8).
pub const SONAR_BANK_SIZE: usize = 8;
/// Most features one detection message carries.
pub const MAX_FEATURES: usize = 32;
/// Most vertices of the uncertainty polygon.
pub const MAX_POLYGON_VERTICES: usize = 32;

macro_rules! message {
    ($t:ty) => {
        impl Message for $t {
            fn header(&self) -> &Header {
                &self.header
            }
        }
    };
}
pub(crate) use message;

/// The planar pose (`harvey_geometry::Pose2`) travels in messages as it is.
pub use harvey_geometry::Pose2;

/// The simulator's true pose of the robot (`sim/truth`): for the renderer and for evaluation only.
#[derive(Debug, Default, Clone, Copy, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("harvey_msgs/TruePose")]
pub struct TruePose {
    pub header: Header,
    pub world_from_robot: Pose2,
}
message!(TruePose);

/// Deterministic mode: a party of the clock chain has finished every tick up to
/// `header.stamp_ns` (see `topics::clock_progress`). `header.seq` counts its turns.
#[derive(Debug, Default, Clone, Copy, PartialEq, Eq, ZeroCopySend)]
#[repr(C)]
#[type_name("harvey_msgs/Progress")]
pub struct Progress {
    pub header: Header,
}
message!(Progress);

/// One bank of sonar readings as the DRV reported them, converted to metres by the bridge.
#[derive(Debug, Default, Clone, Copy, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("harvey_msgs/SonarRaw")]
pub struct SonarRaw {
    pub header: Header,
    /// Which bank fired: 0, 1 or 2; sensor `bank + 3 * i` is `range_m[i]`.
    pub bank: u32,
    /// Bit i set: `range_m[i]` is an echo; clear: no echo within the sonar's limit.
    pub echo_mask: u32,
    pub range_m: [f32; SONAR_BANK_SIZE],
}
message!(SonarRaw);

/// The whole ring, latest reading of each sensor with its geometry in the robot frame.
#[derive(Debug, Default, Clone, Copy, PartialEq, ZeroCopySend, serde::Serialize, serde::Deserialize)]
#[repr(C)]
#[type_name("harvey_msgs/SonarRing")]
pub struct SonarRing {
    pub header: Header,
    pub range_m: [f32; SONAR_SENSORS],
    /// Bearing of each sensor's axis in the robot frame.
    pub bearing_rad: [f32; SONAR_SENSORS],
    /// Stamp of each sensor's latest reading (0 = never read).
    pub reading_stamp_ns: [u64; SONAR_SENSORS],
    /// Bit i set: sensor i holds a valid echo.
    pub valid_mask: u32,
    /// Set when the panic-stop reflex fired on this ring.
    pub panic_stop: u32,
}
message!(SonarRing);

/// Shaft-encoder report as the DRV gives it (dead reckoning, not the truth), in SI units.
#[derive(Debug, Default, Clone, Copy, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("harvey_msgs/EncodersRaw")]
pub struct EncodersRaw {
    pub header: Header,
    pub x_m: f64,
    pub y_m: f64,
    pub heading_rad: f64,
    /// 1 while the DRV executes a motion, 0 when idle.
    pub moving: u32,
    /// Id of the last command the DRV accepted.
    pub command_id: u32,
}
message!(EncodersRaw);

/// What a motion command asks for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u32)]
pub enum CommandKind {
    Stop = 0,
    Move = 1,
    Turn = 2,
    Velocity = 3,
}

impl CommandKind {
    pub fn from_raw(raw: u32) -> Option<Self> {
        match raw {
            0 => Some(Self::Stop),
            1 => Some(Self::Move),
            2 => Some(Self::Turn),
            3 => Some(Self::Velocity),
            _ => None,
        }
    }
}

/// A motion command for the vehicle (`vehicle/command`).
#[derive(Debug, Default, Clone, Copy, PartialEq, ZeroCopySend, serde::Serialize, serde::Deserialize)]
#[repr(C)]
#[type_name("harvey_msgs/MotionCommand")]
pub struct MotionCommand {
    pub header: Header,
    /// [`CommandKind`] as its discriminant.
    pub kind: u32,
    /// Non-zero for commands that must pre-empt everything (panic-stop).
    pub urgent: u32,
    pub distance_m: f64,
    pub angle_rad: f64,
    pub linear_mps: f64,
    pub angular_radps: f64,
    /// Caller-chosen id, echoed in [`EncodersRaw::command_id`] once accepted.
    pub command_id: u32,
    pub reserved: u32,
}
message!(MotionCommand);

/// Command ids with this bit set are the sonar reflexes' (`vehicle/reflex`): the executive
/// knows by it that a reflex has taken the vehicle.
pub const REFLEX_ID_BIT: u32 = 0x8000_0000;
/// The panic-stop's ids have the two top bits set; the panic-avoid's only the top one.
pub const PANIC_STOP_IDS: u32 = 0xC000_0000;
/// The panic-stop watches the sonar sensors whose axis lies within this angle of straight
/// ahead (the forward five of 24); a ring's `panic_stop` flag is theirs.
pub const PANIC_STOP_ARC_RAD: f64 = std::f64::consts::FRAC_PI_6;

impl MotionCommand {
    pub fn kind(&self) -> Option<CommandKind> {
        CommandKind::from_raw(self.kind)
    }
}

/// Dead-reckoned odometry with the motion that was commanded (`odometry`).
#[derive(Debug, Default, Clone, Copy, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("harvey_msgs/Odometry")]
pub struct Odometry {
    pub header: Header,
    pub world_from_robot: Pose2,
    /// Distance travelled since the last command was accepted.
    pub travelled_m: f64,
    /// Rotation since the last command was accepted.
    pub turned_rad: f64,
    pub command: MotionCommand,
    pub moving: u32,
    /// 1 once the DRV reported the last command as accepted.
    pub command_accepted: u32,
}
message!(Odometry);

/// An image feature found by a vision worker.
#[derive(Debug, Default, Clone, Copy, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("harvey_msgs/Feature")]
pub struct Feature {
    pub x_px: f32,
    pub y_px: f32,
    pub score: f32,
    pub kind: u32,
}

/// The answer of a vision worker for one frame (`vision/detections`).
#[derive(Debug, Default, Clone, Copy, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("harvey_msgs/Detections")]
pub struct Detections {
    pub header: Header,
    pub frame_seq: u64,
    pub algorithm: u32,
    pub count: u32,
    pub confidence: f32,
    pub reserved: u32,
    pub features: [Feature; MAX_FEATURES],
}
message!(Detections);

/// The uncertainty map (`ums/map`): a convex polygon around the most likely position and a
/// heading wedge, in the world frame.
#[derive(Debug, Default, Clone, Copy, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("harvey_msgs/UncertaintyMap")]
pub struct UncertaintyMap {
    pub header: Header,
    pub centre: Pose2,
    pub vertex_count: u32,
    /// 1 when the UMS considers the robot lost (area over its limit or landmarks missed).
    pub lost: u32,
    pub vertices_m: [[f64; 2]; MAX_POLYGON_VERTICES],
    /// How far the true heading may lie clockwise / counter-clockwise of `centre.heading_rad`.
    pub heading_cw_rad: f64,
    pub heading_ccw_rad: f64,
    pub area_m2: f64,
    /// Predicted landmarks missed in a row.
    pub missed_landmarks: u32,
    pub reserved: u32,
}
message!(UncertaintyMap);

/// What a landmark sighting measured (`LandmarkSighting::kind`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u32)]
pub enum SightingKind {
    /// The landmark was looked for in its window and not found.
    NotFound = 0,
    /// Class I: `a` is the bearing (rad, counter-clockwise from the heading).
    Bearing = 1,
    /// Class II: `a` bearing (rad), `b` horizontal range (m).
    BearingRange = 2,
    /// Class III: `a` the robot's heading relative to the line (rad), `b` its signed offset
    /// from the line (m, left positive).
    GroundLine = 3,
}

impl SightingKind {
    pub fn from_raw(raw: u32) -> Option<Self> {
        match raw {
            0 => Some(Self::NotFound),
            1 => Some(Self::Bearing),
            2 => Some(Self::BearingRange),
            3 => Some(Self::GroundLine),
            _ => None,
        }
    }
}

/// A landmark recognised (or not) in a frame (`vision/sightings`), in the robot frame.
#[derive(Debug, Default, Clone, Copy, PartialEq, ZeroCopySend, serde::Serialize, serde::Deserialize)]
#[repr(C)]
#[type_name("harvey_msgs/LandmarkSighting")]
pub struct LandmarkSighting {
    pub header: Header,
    pub frame_seq: u64,
    /// Index of the landmark in the world file's `[[landmark]]` list.
    pub landmark_index: u32,
    /// [`SightingKind`] as its discriminant.
    pub kind: u32,
    pub a: f64,
    pub a_sd: f64,
    pub b: f64,
    pub b_sd: f64,
}
message!(LandmarkSighting);

/// The Expecter's window for a landmark (`ums/expectations`): where to look in the next frames.
#[derive(Debug, Default, Clone, Copy, PartialEq, ZeroCopySend, serde::Serialize, serde::Deserialize)]
#[repr(C)]
#[type_name("harvey_msgs/Expectation")]
pub struct Expectation {
    pub header: Header,
    pub landmark_index: u32,
    /// Landmark class, 1..=3.
    pub class: u32,
    /// `[u0, v0, u1, v1]` in pixels of a `width_px x height_px` image.
    pub window_px: [f32; 4],
    pub width_px: u32,
    pub height_px: u32,
    /// A class I landmark's look, as the map predicts it from the believed pose: the step in
    /// reflectance across its line, right side less left, in four equal bands of the window's
    /// rows, top first (`harvey_render::edge_contrast`). All 0: no prediction.
    pub contrast: [f32; 4],
}
message!(Expectation);

/// Mission states published by the executive.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u32)]
pub enum MissionState {
    Running = 0,
    Succeeded = 1,
    Failed = 2,
}

impl MissionState {
    pub fn from_raw(raw: u32) -> Option<Self> {
        match raw {
            0 => Some(Self::Running),
            1 => Some(Self::Succeeded),
            2 => Some(Self::Failed),
            _ => None,
        }
    }
}

/// The executive's progress (`executive/status`).
#[derive(Debug, Default, Clone, Copy, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("harvey_msgs/MissionStatus")]
pub struct MissionStatus {
    pub header: Header,
    /// [`MissionState`] as its discriminant.
    pub state: u32,
    /// Index of the step under way (== `step_count` when done).
    pub step: u32,
    pub step_count: u32,
    /// [`crate::ServoLevel`] as its discriminant.
    pub servo: u32,
    pub estimated: Pose2,
    pub goal: Pose2,
    /// Sonar rings, frames' detections and maps seen so far: proof the data flowed.
    pub sonar_rings_seen: u64,
    pub detections_seen: u64,
    pub maps_seen: u64,
}
message!(MissionStatus);

impl MissionStatus {
    pub fn state(&self) -> Option<MissionState> {
        MissionState::from_raw(self.state)
    }
}
