//! The acceptor-sequenced behaviours a mission may run instead of a script or a plan (004): a
//! finite state acceptor (`fsa.rs`, its bookkeeping in `sequenced.rs`) picks each tick's
//! perceptual algorithm, and motor schemas (`schemas.rs`, on the robot in `drive.rs`) drive.
//! Docking (`docking.rs`, the pose from the dock in `dock_pose.rs`, judged by the UMS's region in
//! `region.rs`) and the pole hunt
//! (`pole_hunt.rs`) behind one face (`behaviour.rs`), with CMU's stop-go-stop navigation by
//! stereo (003, `neptune.rs`, its path round the obstacles seen in `grid_plan.rs`), and door
//! finding by sonar alone (001 §3.2, `door_finding.rs`: the wall followed in `wall.rs`, its
//! openings told in `opening.rs`, the schema-based way in `door_schemas.rs`), and path following
//! by the line finder (001 §2.1, `path_follow.rs`, the camera's view of the path in `path_view.rs`).

pub mod behaviour;
mod depth_look;
pub mod depth_obstacles;
pub mod dock_pose;
pub mod docking;
pub mod door_finding;
mod door_follow;
mod door_locate;
mod door_schemas;
pub mod drive;
pub mod fsa;
pub mod grid_plan;
pub mod neptune;
mod odo_scale;
pub mod opening;
pub mod path_follow;
pub mod path_view;
pub mod pole_hunt;
pub mod region;
pub mod schemas;
pub mod sequenced;
pub mod wall;

pub use behaviour::{Behaviour, Run};
