//! harvey-camera: process entry point.
fn main() {}
