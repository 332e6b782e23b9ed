//! harvey-recorder: process entry point.
fn main() {}
