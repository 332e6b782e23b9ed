//! What the executive publishes about its own working besides its mission status: the servoing
//! level it is at, each action-level correction (`executive/servo`, 000 §5.5), each plan-level
//! pose refinement (`executive/pose`, 000 §5.6), its plan sketch (`executive/plan`, 000 §2) and
//! the state of a behaviour sequenced by a finite state acceptor (`executive/behaviour`, 004).

use crate::{Header, Message, Pose2, ZeroCopySend};

/// Which level of perceptual servoing is steering (`MissionStatus::servo`), 000 §4.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u32)]
pub enum ServoLevel {
    /// Dead reckoning only.
    None = 0,
    /// Corrections after each increment of a move.
    Action = 1,
    /// Pose refinement at milestones.
    Plan = 2,
    /// Re-development after a missed milestone or a reflex.
    Goal = 3,
}

impl ServoLevel {
    pub fn from_raw(raw: u32) -> Option<Self> {
        use ServoLevel::*;
        [None, Action, Plan, Goal].into_iter().find(|l| *l as u32 == raw)
    }
}

/// One action-level correction: the landmark seen after increment `increment`, what that says
/// about the heading, and the turn commanded.
#[derive(Debug, Default, Clone, Copy, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("harvey_msgs/ServoCorrection")]
pub struct ServoCorrection {
    pub header: Header,
    /// Increments done in the leg (1 = after the first).
    pub increment: u32,
    pub landmark_index: u32,
    /// Where the landmark's point was found in the image (pixels).
    pub found_px: [f32; 2],
    /// Heading error relative to the intended line (radians, left positive) and the turn.
    pub heading_error_rad: f64,
    pub correction_rad: f64,
    /// Estimated offset from the line (m, left positive) and distance behind the plan (m).
    pub offset_m: f64,
    pub shortfall_m: f64,
}
crate::payloads::message!(ServoCorrection);

/// One plan-level pose refinement: the pose expected, the pose the landmark vertices gave.
#[derive(Debug, Default, Clone, Copy, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("harvey_msgs/PoseFix")]
pub struct PoseFix {
    pub header: Header,
    pub expected: Pose2,
    pub refined: Pose2,
    /// Vertices asked for, found by correlation, and kept by the refinement.
    pub asked: u32,
    pub found: u32,
    pub kept: u32,
    pub reserved: u32,
    /// Root-mean-square image residual of the kept vertices (pixels).
    pub rms_px: f64,
}
crate::payloads::message!(PoseFix);

/// Milestones a [`PlanSketch`] carries: more than any route in the worlds has.
pub const SKETCH_PLACES: usize = 12;

/// Where plan-and-monitor is (000 §2, §4): the plan sketch from the current subgoal's start to
/// the goal, detailed at the front, abstract at the back, and the latest milestone check.
#[derive(Debug, Default, Clone, Copy, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("harvey_msgs/PlanSketch")]
pub struct PlanSketch {
    pub header: Header,
    /// `x0 y0 x1 y1 ...`: the current subgoal's start, then the milestone ending each subgoal.
    pub places_m: [f64; 2 * SKETCH_PLACES],
    pub place_count: u32,
    /// Bit `k`: subgoal `k` (from place `k` to `k + 1`) is primitive (a TURN then a MOVE); the
    /// others are abstract, to be developed when execution reaches them.
    pub primitive_mask: u32,
    /// What the current subgoal is doing ([`PlanStage`]).
    pub stage: u32,
    /// Milestone checks so far, and plans developed afresh after a miss.
    pub checks: u32,
    pub replans: u32,
    /// The latest check ([`CheckOutcome`]) and how far off its milestone the robot was (m).
    pub last_outcome: u32,
    pub last_off_m: f64,
}
crate::payloads::message!(PlanSketch);

/// A subgoal's stages (`PlanSketch::stage`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u32)]
pub enum PlanStage {
    Developing = 0,
    /// Turning to face the milestone, then fixing the pose.
    Aiming = 1,
    Moving = 2,
    /// At the milestone: fixing the pose to check it.
    Arriving = 3,
    Checking = 4,
    /// The goal is reached: taking its heading.
    Settling = 5,
    Arrived = 6,
}

/// How a milestone check came out (`PlanSketch::last_outcome`; 0 before the first).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u32)]
pub enum CheckOutcome {
    Reached = 1,
    /// Missed by a little: the subgoal is retried from the last known location (plan level).
    Retried = 2,
    /// Missed by a lot, or too often: the plan is developed afresh from there (goal level).
    Replanned = 3,
}

/// A behaviour under a finite state acceptor (004 §3): the acceptor's state, the last trigger,
/// and the motor schemas' velocity vectors this tick (004 §2.1), once per odometry tick.
#[derive(Debug, Default, Clone, Copy, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("harvey_msgs/BehaviourState")]
pub struct BehaviourState {
    pub header: Header,
    /// The pose the vectors start from (the executive's belief).
    pub at: Pose2,
    /// Index of the acceptor's state (`q0` = 0 …) and the transitions taken so far.
    pub fsa_state: u32,
    pub transitions: u32,
    /// The latest trigger: 0 normal, 1 terminal, 2 recoverable error, 3 fatal error.
    pub last_trigger: u32,
    /// Things the behaviour has reached so far (poles parked by; 1 once docked).
    pub achieved: u32,
    /// World-frame vectors (m/s), `x y` each: move-to-goal, avoid-static-obstacle, noise,
    /// avoid-past, probe, and their clipped sum.
    pub vectors_mps: [f64; 12],
    /// The velocity command sent: speed (m/s) and turn rate (rad/s).
    pub linear_mps: f64,
    pub angular_radps: f64,
}
crate::payloads::message!(BehaviourState);
