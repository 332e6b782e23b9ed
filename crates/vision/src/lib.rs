//! The papers' perceptual algorithms as pure kernels on grey images read in place: each a function
//! or a state machine with reusable buffers, no IO, no clock. The vision-workers service runs them
//! on camera frames in shared memory, inside the windows it is asked to look in.

mod activity;
mod cross;
pub mod cues;
pub mod depth;
mod depth_fit;
mod depth_ground;
mod depth_radial;
pub mod flf;
mod flf_pass;
pub mod frs;
pub mod hough;
pub mod image;
pub mod levels;
pub mod moravec;
pub mod nc;
mod nc_pass;
pub mod noise;
pub mod odometry;
pub mod path;
pub mod path_steps;
pub mod pyramid;
pub mod regions;
mod register;
mod run_pass;
pub mod simd;
pub mod step_line;
pub mod stereo;
pub mod unique;

pub use image::{Gray, GrayBuf, Rect, VisionError};
