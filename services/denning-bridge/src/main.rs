//! harvey-denning-bridge: process entry point.
fn main() {}
