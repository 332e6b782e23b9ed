//! harvey-sonar: process entry point.
fn main() {}
