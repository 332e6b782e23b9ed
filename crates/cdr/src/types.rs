//! Harvey's messages in CDR: their `ros2msg` definitions and field-by-field codecs.
//! A `Header` is written as a `std_msgs/Header` followed by `uint64 seq`.

use harvey_msgs::{
    Detections, EncodersRaw, Expectation, Feature, FrameHeader, Header, LandmarkSighting, MissionStatus,
    MotionCommand, Odometry, Pose2, ServoCorrection, SonarRaw, SonarRing, TruePose, UncertaintyMap,
    VisionItem, VisionRequest, VisionResult,
};

use harvey_msgs::{BehaviourState, PlanSketch, PoseFix};

use crate::codec::{Cdr, CdrError, CdrReader, CdrWriter};
use crate::frames;
use crate::schema::Def;

/// A message type with a ROS 2 definition.
pub trait Ros2Msg: Cdr {
    const DEF: &'static Def;
}

pub(crate) static TIME: Def =
    Def { name: "builtin_interfaces/Time", text: "int32 sec\nuint32 nanosec\n", deps: &[] };
pub(crate) static STD_HEADER: Def =
    Def { name: "std_msgs/Header", text: "builtin_interfaces/Time stamp\nstring frame_id\n", deps: &[&TIME] };
static MOTION_COMMAND: Def = Def {
    name: "harvey_msgs/MotionCommand",
    text: "std_msgs/Header header\nuint64 seq\n\
           uint32 kind # 0 stop, 1 move, 2 turn, 3 velocity\nuint32 urgent\n\
           float64 distance_m\nfloat64 angle_rad\nfloat64 linear_mps\nfloat64 angular_radps\n\
           uint32 command_id\nuint32 reserved\n",
    deps: &[&STD_HEADER],
};
static IMAGE: Def = Def {
    name: "sensor_msgs/Image",
    text: "std_msgs/Header header\nuint32 height\nuint32 width\nstring encoding\nuint8 is_bigendian\nuint32 step\nuint8[] data\n",
    deps: &[&STD_HEADER],
};

/// The definition of `sensor_msgs/msg/Image`, the camera topic's type.
pub fn image_def() -> &'static Def {
    &IMAGE
}

pub(crate) fn write_std_header(stamp_ns: u64, frame_id: &str, w: &mut CdrWriter) {
    w.prim((stamp_ns / 1_000_000_000) as i32);
    w.prim((stamp_ns % 1_000_000_000) as u32);
    w.string(frame_id);
}

impl Cdr for Header {
    fn write(&self, w: &mut CdrWriter) {
        write_std_header(self.stamp_ns, w.frame_id(), w);
        w.prim(self.seq);
    }
    fn read(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        let sec = r.prim::<i32>()?;
        let nanosec = r.prim::<u32>()?;
        let _frame_id = r.string()?;
        let seq = r.prim::<u64>()?;
        let stamp_ns = u64::try_from(sec).unwrap_or(0) * 1_000_000_000 + u64::from(nanosec);
        Ok(Header { seq, stamp_ns })
    }
}

/// Encodes a camera frame as `sensor_msgs/msg/Image` into `buf` (reused). A stereo pair is one
/// image of its views stacked (left on top), named by its frame id ([`frames::STEREO_PAIR`]).
pub fn encode_image(h: &FrameHeader, pixels: &[u8], buf: Vec<u8>) -> Vec<u8> {
    let mut w = CdrWriter::start(buf);
    let stereo = h.views() == 2;
    write_std_header(h.stamp_ns, if stereo { frames::STEREO_PAIR } else { frames::CAMERA }, &mut w);
    w.prim(h.height_px * h.views());
    w.prim(h.width_px);
    w.string(h.encoding().map_or("", |e| e.ros_name()));
    w.prim(0u8);
    w.prim(h.stride_bytes);
    w.byte_seq(pixels);
    w.finish()
}

/// Decodes a `sensor_msgs/msg/Image` back to a frame header (sequence number 0: the standard
/// type has none) and its pixels, borrowed from `data`.
pub fn decode_image(data: &[u8]) -> Result<(FrameHeader, &[u8]), CdrError> {
    let (h, at) = decode_image_head(data)?;
    let pixels = data
        .get(at..at + h.payload_len())
        .ok_or(CdrError::Truncated { at, needed: (at + h.payload_len()).saturating_sub(data.len()) })?;
    Ok((h, pixels))
}

/// Reads the fields of a `sensor_msgs/msg/Image` before its pixels from `prefix`, the message's
/// first bytes (the pixels need not follow): the frame header, checked against the pixel count
/// the message declares, and the offset at which its `payload_len()` pixel bytes start. For a
/// message that arrives in pieces (a Zenoh sample of many fragments), whose pixels are then
/// copied piece by piece instead of being gathered first.
pub fn decode_image_head(prefix: &[u8]) -> Result<(FrameHeader, usize), CdrError> {
    let mut r = CdrReader::new(prefix)?;
    let sec = r.prim::<i32>()?;
    let nanosec = r.prim::<u32>()?;
    let frame_id = r.string()?;
    let at = r.offset();
    let rows = r.prim::<u32>()?;
    let views = if frame_id == frames::STEREO_PAIR { 2 } else { 1 };
    if rows % views != 0 {
        return Err(CdrError::Invalid {
            at,
            what: format!("a stereo pair of {rows} rows (not two equal images)"),
        });
    }
    let height_px = rows / views;
    let width_px = r.prim::<u32>()?;
    let at = r.offset();
    let encoding = r.string()?;
    let enc = harvey_msgs::Encoding::parse(&encoding)
        .ok_or(CdrError::Invalid { at, what: format!("image encoding `{encoding}` is not mono8 or rgb8") })?;
    let _bigendian = r.prim::<u8>()?;
    let at = r.offset();
    let stride_bytes = r.prim::<u32>()?;
    // A row must hold its pixels: readers take each row's first width x bytes-per-pixel bytes.
    let row = u64::from(width_px) * u64::from(enc.bytes_per_pixel());
    if u64::from(stride_bytes) < row {
        return Err(CdrError::Invalid {
            at,
            what: format!(
                "a row step of {stride_bytes} bytes for {width_px} {encoding} pixels ({row} bytes)"
            ),
        });
    }
    let at = r.offset();
    let len = r.prim::<u32>()? as usize;
    let stamp_ns = u64::try_from(sec).unwrap_or(0) * 1_000_000_000 + u64::from(nanosec);
    let h = FrameHeader {
        seq: 0,
        stamp_ns,
        width_px,
        height_px,
        stride_bytes,
        encoding: enc as u32,
        views,
        reserved: 0,
    };
    if len != h.payload_len() {
        return Err(CdrError::Invalid {
            at,
            what: format!("{len} pixel bytes for a {width_px}x{rows} {encoding} image"),
        });
    }
    Ok((h, r.offset()))
}

macro_rules! ros2_struct {
    ($t:ty, $def:ident = ($name:literal, $text:expr, [$($dep:expr),*]) { $($f:ident),* $(,)? }) => {
        ros2_struct!($t, "", $def = ($name, $text, [$($dep),*]) { $($f),* });
    };
    ($t:ty, $frame:expr, $def:ident = ($name:literal, $text:expr, [$($dep:expr),*]) { $($f:ident),* $(,)? }) => {
        static $def: Def = Def { name: $name, text: $text, deps: &[$($dep),*] };
        impl Cdr for $t {
            const FRAME_ID: &'static str = $frame;
            fn write(&self, w: &mut CdrWriter) {
                $( self.$f.write(w); )*
            }
            fn read(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
                Ok(Self { $( $f: Cdr::read(r)?, )* })
            }
        }
        impl Ros2Msg for $t {
            const DEF: &'static Def = &$def;
        }
    };
}

/// A Harvey message's text begins with its header: `std_msgs/Header` plus the sequence number.
macro_rules! with_header {
    ($s:literal) => {
        concat!("std_msgs/Header header\nuint64 seq\n", $s)
    };
}

ros2_struct!(Pose2, POSE2 = ("harvey_msgs/Pose2", "float64 x_m\nfloat64 y_m\nfloat64 heading_rad\n", []) { x_m, y_m, heading_rad });
ros2_struct!(Feature, FEATURE = ("harvey_msgs/Feature", "float32 x_px\nfloat32 y_px\nfloat32 score\nuint32 kind\n", []) { x_px, y_px, score, kind });
ros2_struct!(TruePose, frames::WORLD, TRUE_POSE = ("harvey_msgs/TruePose", with_header!("harvey_msgs/Pose2 world_from_robot\n"), [&STD_HEADER, &POSE2]) { header, world_from_robot });
ros2_struct!(SonarRaw, frames::BASE_LINK, SONAR_RAW = ("harvey_msgs/SonarRaw", with_header!("uint32 bank\nuint32 echo_mask\nfloat32[8] range_m\n"), [&STD_HEADER]) { header, bank, echo_mask, range_m });
ros2_struct!(SonarRing, frames::BASE_LINK, SONAR_RING = ("harvey_msgs/SonarRing", with_header!("float32[24] range_m\nfloat32[24] bearing_rad\nuint64[24] reading_stamp_ns\nuint32 valid_mask\nuint32 panic_stop\n"), [&STD_HEADER]) { header, range_m, bearing_rad, reading_stamp_ns, valid_mask, panic_stop });
ros2_struct!(EncodersRaw, frames::ODOM, ENCODERS_RAW = ("harvey_msgs/EncodersRaw", with_header!("float64 x_m\nfloat64 y_m\nfloat64 heading_rad\nuint32 moving\nuint32 command_id\n"), [&STD_HEADER]) { header, x_m, y_m, heading_rad, moving, command_id });
ros2_struct!(Odometry, frames::ODOM, ODOMETRY = ("harvey_msgs/Odometry", with_header!("harvey_msgs/Pose2 world_from_robot\nfloat64 travelled_m\nfloat64 turned_rad\nharvey_msgs/MotionCommand command\nuint32 moving\nuint32 command_accepted\n"), [&STD_HEADER, &POSE2, &MOTION_COMMAND]) { header, world_from_robot, travelled_m, turned_rad, command, moving, command_accepted });
ros2_struct!(Detections, frames::CAMERA, DETECTIONS = ("harvey_msgs/Detections", with_header!("uint64 frame_seq\nuint32 algorithm\nuint32 count\nfloat32 confidence\nuint32 reserved\nharvey_msgs/Feature[32] features\n"), [&STD_HEADER, &FEATURE]) { header, frame_seq, algorithm, count, confidence, reserved, features });
ros2_struct!(UncertaintyMap, frames::WORLD, UNCERTAINTY_MAP = ("harvey_msgs/UncertaintyMap", with_header!("harvey_msgs/Pose2 centre\nuint32 vertex_count\nuint32 lost\nfloat64[64] vertices_m # x0 y0 x1 y1 ...\nfloat64 heading_cw_rad\nfloat64 heading_ccw_rad\nfloat64 area_m2\nuint32 missed_landmarks\nuint32 reserved\n"), [&STD_HEADER, &POSE2]) { header, centre, vertex_count, lost, vertices_m, heading_cw_rad, heading_ccw_rad, area_m2, missed_landmarks, reserved });
ros2_struct!(LandmarkSighting, frames::CAMERA, LANDMARK_SIGHTING = ("harvey_msgs/LandmarkSighting", with_header!("uint64 frame_seq\nuint32 landmark_index\nuint32 kind # 0 not found, 1 bearing, 2 bearing+range, 3 ground line\nfloat64 a\nfloat64 a_sd\nfloat64 b\nfloat64 b_sd\n"), [&STD_HEADER]) { header, frame_seq, landmark_index, kind, a, a_sd, b, b_sd });
ros2_struct!(Expectation, frames::CAMERA, EXPECTATION = ("harvey_msgs/Expectation", with_header!("uint32 landmark_index\nuint32 class\nfloat32[4] window_px # u0 v0 u1 v1\nuint32 width_px\nuint32 height_px\nfloat32[4] contrast # right less left, four row bands\n"), [&STD_HEADER]) { header, landmark_index, class, window_px, width_px, height_px, contrast });
ros2_struct!(VisionItem, VISION_ITEM = ("harvey_msgs/VisionItem", "float32[6] values\n", []) { values });
ros2_struct!(VisionRequest, frames::CAMERA, VISION_REQUEST = ("harvey_msgs/VisionRequest", with_header!("uint32 request_id\nuint32 algorithm # 1 correlate, 2 moravec, 3 line finder, 4 region segmenter, 5 phototropic, 6 activity, 7 dock, 8 poles\nuint32 standing\nuint32 landmark_index\nharvey_msgs/Pose2 expected\nfloat32[4] window_px # u0 v0 u1 v1\nfloat32[8] params\n"), [&STD_HEADER, &POSE2]) { header, request_id, algorithm, standing, landmark_index, expected, window_px, params });
ros2_struct!(VisionResult, frames::CAMERA, VISION_RESULT = ("harvey_msgs/VisionResult", with_header!("uint64 frame_seq\nuint32 request_id\nuint32 algorithm\nuint32 status # 0 found, 1 not found, 2 window outside, 3 unknown landmark, 4 unknown algorithm, 5 bad parameter, 6 bad template, 7 bad frame\nuint32 found\nuint32 count\nuint32 reserved\nharvey_msgs/VisionItem[32] items\n"), [&STD_HEADER, &VISION_ITEM]) { header, frame_seq, request_id, algorithm, status, found, count, reserved, items });
ros2_struct!(MissionStatus, frames::WORLD, MISSION_STATUS = ("harvey_msgs/MissionStatus", with_header!("uint32 state # 0 running, 1 succeeded, 2 failed\nuint32 step\nuint32 step_count\nuint32 servo # 0 none, 1 action, 2 plan, 3 goal level\nharvey_msgs/Pose2 estimated\nharvey_msgs/Pose2 goal\nuint64 sonar_rings_seen\nuint64 detections_seen\nuint64 maps_seen\n"), [&STD_HEADER, &POSE2]) { header, state, step, step_count, servo, estimated, goal, sonar_rings_seen, detections_seen, maps_seen });
ros2_struct!(PoseFix, frames::WORLD, POSE_FIX = ("harvey_msgs/PoseFix", with_header!("harvey_msgs/Pose2 expected\nharvey_msgs/Pose2 refined\nuint32 asked\nuint32 found\nuint32 kept\nuint32 reserved\nfloat64 rms_px\n"), [&STD_HEADER, &POSE2]) { header, expected, refined, asked, found, kept, reserved, rms_px });
ros2_struct!(PlanSketch, frames::WORLD, PLAN_SKETCH = ("harvey_msgs/PlanSketch", with_header!("float64[24] places_m # x0 y0 x1 y1 ...: the subgoal's start, then each milestone\nuint32 place_count\nuint32 primitive_mask # bit k: subgoal k is primitive\nuint32 stage # 0 developing, 1 aiming, 2 moving, 3 arriving, 4 checking, 5 settling, 6 arrived\nuint32 checks\nuint32 replans\nuint32 last_outcome # 0 none, 1 reached, 2 retried, 3 replanned\nfloat64 last_off_m\n"), [&STD_HEADER]) { header, places_m, place_count, primitive_mask, stage, checks, replans, last_outcome, last_off_m });
ros2_struct!(BehaviourState, frames::WORLD, BEHAVIOUR_STATE = ("harvey_msgs/BehaviourState", with_header!("harvey_msgs/Pose2 at\nuint32 fsa_state\nuint32 transitions\nuint32 last_trigger # 0 normal, 1 terminal, 2 recoverable, 3 fatal\nuint32 achieved\nfloat64[12] vectors_mps # move-to-goal, avoid-static-obstacle, noise, avoid-past, probe, sum: x y each\nfloat64 linear_mps\nfloat64 angular_radps\n"), [&STD_HEADER, &POSE2]) { header, at, fsa_state, transitions, last_trigger, achieved, vectors_mps, linear_mps, angular_radps });
ros2_struct!(ServoCorrection, frames::BASE_LINK, SERVO_CORRECTION = ("harvey_msgs/ServoCorrection", with_header!("uint32 increment\nuint32 landmark_index\nfloat32[2] found_px\nfloat64 heading_error_rad # left positive\nfloat64 correction_rad\nfloat64 offset_m # from the intended line, left positive\nfloat64 shortfall_m\n"), [&STD_HEADER]) { header, increment, landmark_index, found_px, heading_error_rad, correction_rad, offset_m, shortfall_m });

impl Cdr for MotionCommand {
    const FRAME_ID: &'static str = frames::BASE_LINK;
    fn write(&self, w: &mut CdrWriter) {
        self.header.write(w);
        [self.kind, self.urgent].write(w);
        [self.distance_m, self.angle_rad, self.linear_mps, self.angular_radps].write(w);
        [self.command_id, self.reserved].write(w);
    }
    fn read(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        let header = Header::read(r)?;
        let [kind, urgent] = <[u32; 2]>::read(r)?;
        let [distance_m, angle_rad, linear_mps, angular_radps] = <[f64; 4]>::read(r)?;
        let [command_id, reserved] = <[u32; 2]>::read(r)?;
        Ok(Self {
            header,
            kind,
            urgent,
            distance_m,
            angle_rad,
            linear_mps,
            angular_radps,
            command_id,
            reserved,
        })
    }
}

impl Ros2Msg for MotionCommand {
    const DEF: &'static Def = &MOTION_COMMAND;
}

#[cfg(test)]
mod tests;
