//! harvey-encoders: process entry point.
fn main() {}
