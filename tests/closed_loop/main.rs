//! The executive in a closed loop, in one process: the simulated DRV, the denning-bridge's
//! conversions, the sonar ring and its reflexes, the encoders' odometry, the camera's renderer,
//! the vision workers (requests, landmarks, edges), the UMS and the executive, stepped tick by
//! tick in the order the lockstep clock chain runs them (`rig.rs`), with the launch file's
//! settings (`launch.rs`). No processes, no bus: docking, the pole hunt, pose refinement and
//! plan-and-monitor tested as unit tests. These tests join several services' libraries, so
//! they live at the workspace's root, not in any one service.
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

#[path = "../common/docked.rs"]
mod docked;
mod docking;
mod launch;
mod plan;
mod poles;
mod refining;
mod rig;
