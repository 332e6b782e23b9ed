//! Checked configuration files: the ranges a number of a world, launch or mission file may take
//! (with the refusal that names the key), and where in the file's text a key stands, so that an
//! error names the file, line and key. Shared by the world, the supervisor and the executive.

pub mod range;
pub mod spans;

pub use range::{OutOfRange, Range, check, check_all, check_int, check_len};
pub use spans::{KeyPath, Step, line_of, line_of_key};
