//! ROS 2 interoperability, pure: the RIHS01 type hashes of Harvey's message definitions and
//! rmw_zenoh's (ROS 2 Jazzy) key expressions, attachments and liveliness tokens, so that a
//! `ros2 topic echo` over `rmw_zenoh_cpp` can see what the bridge puts on Zenoh. Nothing here
//! touches a session; the bridge declares what these functions name.

// rmw's whole QoS vocabulary and the attachment's decoder are kept (tests read with them), though
// the bridge publishes one profile and reads no ROS 2 samples yet.
#[allow(dead_code)]
mod keys;
#[allow(dead_code)]
mod rihs;

pub use keys::{GID_LEN, Node, Qos, attachment, data_key, dds_type_name, node_token, publisher_token};
pub use rihs::rihs01;
