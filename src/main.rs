//! harvey CLI
fn main() {}
