//! Placeholder until the offsets bench lands.
fn main() {}
