//! The integration tests of `scatterfit-imaging` as one test binary: each file beside this one is a
//! module of it, and `cargo test -p scatterfit-imaging --test suite FILE::` runs one file's tests.
//! One binary instead of one per file: the dependencies' generics are instantiated and the
//! executable linked once. `autotests = false` (Cargo.toml): a file added under `tests/` is
//! declared here (`.ci/check-test-modules` fails when one is not).

mod merge;
mod order;
mod response;
mod spot;
