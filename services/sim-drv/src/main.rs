//! harvey-sim-drv: process entry point.
fn main() {}
