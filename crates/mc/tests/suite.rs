//! The integration tests of `scatterfit-mc` as one test binary: each file beside this one is a
//! module of it, and `cargo test -p scatterfit-mc --test suite FILE::` runs one file's tests.
//! One binary instead of one per file: the dependencies' generics are instantiated and the
//! executable linked once. `autotests = false` (Cargo.toml): a file added under `tests/` is
//! declared here (`.ci/check-test-modules` fails when one is not).

mod anisotropic_references;
mod cost;
mod forward_models_vs_mcml;
mod g_model;
mod optics_crosscheck;
mod port;
mod shards;
mod table_accuracy;
mod validation;
