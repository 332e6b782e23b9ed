//! harvey-ums: process entry point.
fn main() {}
