//! Bounding-volume benches (placeholder until the foundation work lands).
fn main() {}
