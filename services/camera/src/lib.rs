//! The camera service's node, for its own process (`main.rs`) and for in-process runs.

mod folder;
pub mod node;
