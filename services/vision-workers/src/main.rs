//! harvey-vision-workers: process entry point.
fn main() {}
