//! The integration tests of `scatterfit-pipeline` as one test binary: each file beside this one is a
//! module of it, and `cargo test -p scatterfit-pipeline --test suite FILE::` runs one file's tests.
//! One binary instead of one per file: the dependencies' generics are instantiated and the
//! executable linked once. `autotests = false` (Cargo.toml): a file added under `tests/` is
//! declared here (`.ci/check-test-modules` fails when one is not).

mod camera;
mod camera_bias;
mod checks;
mod common;
mod evidence;
mod g_fit;
mod g_setting;
mod g_term;
mod hdr_stage;
mod port;
mod provenance;
mod real_brackets;
mod rig_twin;
mod uncertainty;
