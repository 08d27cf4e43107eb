//! Benchmarks of nesy-vlm (filled in below).
fn main() {}
