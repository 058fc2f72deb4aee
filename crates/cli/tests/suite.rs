//! The integration tests of `scatterfit` as one test binary: each file beside this one is a
//! module of it, and `cargo test -p scatterfit --test suite FILE::` runs one file's tests.
//! One binary instead of one per file: the dependencies' generics are instantiated and the
//! executable linked once. `autotests = false` (Cargo.toml): a file added under `tests/` is
//! declared here (`.ci/check-test-modules` fails when one is not).
//!
//! The tests that need a peer program (a renderer, a browser) are the other binary, `peers.rs`
//! (its own harness).

mod common;
mod export;
mod hostile;
mod imaging;
mod mc;
mod measure;
mod render;
mod robustness;
mod safety;
mod shards;
mod spectro;
