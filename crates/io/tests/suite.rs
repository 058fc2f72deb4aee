//! The integration tests of `scatterfit-io` as one test binary: each file beside this one is a
//! module of it, and `cargo test -p scatterfit-io --test suite FILE::` runs one file's tests.
//! One binary instead of one per file: the dependencies' generics are instantiated and the
//! executable linked once. `autotests = false` (Cargo.toml): a file added under `tests/` is
//! declared here (`.ci/check-test-modules` fails when one is not).
//!
//! `atomic_interrupt.rs` is a binary of its own: the interruption it tests is process-wide.

mod fuzz_images;
mod fuzz_text;
mod images;
