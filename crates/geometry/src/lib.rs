//! Harvey's geometry vocabulary, shared by the simulator, the world model, the services and the
//! tools: one planar pose ([`Pose2`]), angle wrapping, units, the median, and the seeded random generator.
//! No IO, no clock.

mod angle;
mod pose;
mod rng;
mod segment;
mod stats;
pub mod units;

pub use angle::{wrap, wrap_deg};
pub use pose::{Pose2, PoseParseError};
pub use rng::Rng;
pub use segment::distance_to_segment;
pub use stats::median;
pub use units::{FT, INCH};
