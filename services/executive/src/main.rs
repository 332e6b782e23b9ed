//! harvey-executive: process entry point.
fn main() {}
