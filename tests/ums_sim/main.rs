//! The UMS's map against the simulated robot, in one process: the UMS library driven by the
//! simulated DRV's motion (no bus, no processes). These tests join two services' libraries, so
//! they live at the workspace's root, not in either service.
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

mod bounded;
mod containment;
mod expecter;
