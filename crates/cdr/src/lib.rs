//! ROS 2 CDR encoding (little-endian, `00 01 00 00` encapsulation) and `ros2msg` schema texts for
//! Harvey's messages, so that ROS 2 tools, Foxglove and the Python `mcap-ros2-support` decoder
//! read Harvey's recordings without Harvey's code. Decoding serves replay and `harvey info`.

mod camera_info;
mod codec;
mod dynamic;
pub mod frames;
mod geometry;
mod log;
mod marker;
mod schema;
mod types;

pub use camera_info::CameraInfo;
pub use codec::{Cdr, CdrError, CdrReader, CdrWriter, decode, encode};
pub use dynamic::{Schema, SchemaError};
pub use geometry::{Point, Quaternion, TfMessage, Transform};
pub use marker::{Colour, Marker, MarkerArray, MarkerKind};
pub use schema::{Def, full_text};
pub use types::{Ros2Msg, decode_image, decode_image_head, encode_image, image_def};
