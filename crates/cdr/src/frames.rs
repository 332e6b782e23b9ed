//! The coordinate frames Harvey's messages name in their `frame_id`s, and the transform tree the
//! recorder derives between them (`/tf`, `/tf_static`; `harvey_recording::derive`), in ROS's
//! REP 105 names:
//!
//! ```text
//! world ─┬─ odom ── base_link ── camera
//!        └─ truth
//! ```
//!
//! `world` is the world file's frame (x east, y north, z up); `odom` is where dead reckoning puts
//! the world (`world → odom` is the robot's correction, its estimate less its odometry);
//! `base_link` is the robot (x ahead, y left, z up) on the floor; `camera` is the camera's optical
//! frame (z along the view, x right, y down, as `sensor_msgs/Image` expects); `truth` is where
//! the simulator has the robot, which the robot never sees.

/// The world file's frame: every map, plan, estimate and pose is expressed in it.
pub const WORLD: &str = "world";
/// Dead reckoning's frame: odometry poses are in it.
pub const ODOM: &str = "odom";
/// The robot: sonar returns and motion commands are relative to it.
pub const BASE_LINK: &str = "base_link";
/// The camera's optical frame: images, features, windows and sightings are in it.
pub const CAMERA: &str = "camera";
/// A stereo pair's image (003): the left camera's image (its optical frame is [`CAMERA`]) with
/// the right one stacked under it, twice the camera's height. Only the frame id tells a
/// recorded pair from one tall image, so it is how the pair is read back.
pub const STEREO_PAIR: &str = "camera_stereo_pair";
/// The simulator's true robot pose.
pub const TRUTH: &str = "truth";
