//! Benchmarks of scatterfit-imaging (placeholder; filled in below).

fn main() {}
