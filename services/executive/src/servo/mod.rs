//! Perceptual servoing at its three levels (000 §5): action level, the heading corrections of a
//! leg driven in increments (`action.rs`); plan level, the pose refined from landmark vertices
//! (`pose.rs`, starting from the matches that agree, `consensus.rs`; the vertices in view in
//! `vertices.rs`, which of them to ask for in `choose.rs`)
//! and the belief it leaves (`belief.rs`).
//! Goal level, getting back to the plan, is the script runner's (`script/recover.rs`) and
//! plan-and-monitor's.

pub mod action;
pub mod belief;
pub mod choose;
pub mod consensus;
pub mod linalg;
pub mod pose;
pub mod vertices;

pub use action::{ServoParams, correction, correction_off_line, heading_error, heading_error_off_line};
