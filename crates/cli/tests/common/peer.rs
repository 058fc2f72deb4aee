//! Tests that need a program beside ours — a renderer's Python package, a browser — and say when
//! they did not run.
//!
//! Such a test file is its own harness (`harness = false` in `crates/cli/Cargo.toml`, the
//! `libtest-mimic` crate): it finds its peer once, and each test runs with the peer's path, or is
//! reported as **ignored, with the reason**, when the peer is missing — so that `cargo test` counts
//! it under "ignored" instead of "passed". With the peer's `SCATTERFIT_REQUIRE_*` variable set to
//! `1` (CI sets them), a missing peer fails every test that needs it instead.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use libtest_mimic::{Arguments, Completion, Failed, Trial};

/// A peer program: its path, or why it is not there.
pub struct Peer {
    found: Result<PathBuf, String>,
    require_var: &'static str,
}

impl Peer {
    /// `found` is the peer's path or why it is missing; `require_var` the environment variable whose
    /// value `1` makes a missing peer a failure.
    pub fn new(found: Result<PathBuf, String>, require_var: &'static str) -> Self {
        Self { found, require_var }
    }

    /// Whether a missing peer fails the tests (`require_var` = 1).
    pub fn required(&self) -> bool {
        std::env::var(self.require_var).is_ok_and(|v| v == "1")
    }

    /// The test `name`, which runs `test` with the peer's path; without the peer it is ignored at
    /// run time with the reason (or fails, when the peer is required).
    pub fn trial(&self, name: &'static str, test: fn(&Path)) -> Trial {
        let found = self.found.clone();
        let required = self.required();
        let var = self.require_var;
        Trial::ignorable_test(name, move || match found {
            Ok(path) => {
                test(&path);
                Ok(Completion::Completed)
            }
            Err(why) if required => Err(Failed::from(format!(
                "{why}; {var}=1 makes this test required"
            ))),
            Err(why) => Ok(Completion::ignored_with(format!("not run: {why}"))),
        })
    }
}

/// Runs `trials` as `cargo test` would (the same arguments: filters, `--ignored`, `--nocapture`
/// is accepted, `--list`), and exits with the harness's code.
pub fn run(trials: Vec<Trial>) -> ExitCode {
    libtest_mimic::run(&Arguments::from_args(), trials).exit_code()
}
