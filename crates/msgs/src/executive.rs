//! What the executive publishes about its own working besides its mission status: the servoing
//! level it is at, and each action-level correction (`executive/servo`, 000 §5.5).

use crate::{Header, Message, ZeroCopySend};

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
