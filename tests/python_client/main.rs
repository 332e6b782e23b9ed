//! The Python client (`python/harvey_client`) against Rust: its ctypes structures have the Rust
//! payloads' type names, sizes, alignments and field offsets, and its topic table is
//! `topics::ALL` with the same types and QoS (`layout.rs`); on a live realtime mission it
//! receives sonar rings, odometry and camera frames that are, field for field and pixel for
//! pixel, what the recorder recorded (`live.rs`, compared by `compare.rs`).
//!
//! The test makes its own Python environment (`venv.rs`): a venv in `target/py-client-venv` into
//! which it pip-installs the package (from PyPI: `iceoryx2==0.10.0`, `numpy`). Without network
//! access on the first run it fails, saying so.
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

#[path = "../common/mod.rs"]
mod common;
mod compare;
mod layout;
mod live;
mod venv;

use std::process::Output;

/// A process's stdout and stderr, for assertion messages.
fn text(out: &Output) -> String {
    format!("{}\n{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr))
}
