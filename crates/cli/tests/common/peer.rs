//! Tests that need a program beside ours — a renderer's Python package, a browser — and say when
//! they did not run.
//!
//! Such tests are the `peers` test binary, which is its own harness (`harness = false` in
//! `crates/cli/Cargo.toml`, the `libtest-mimic` crate; `tests/peers.rs`): each test runs with its
//! peer's path, or is reported as **ignored, with the reason**, when the peer is missing — so that
//! `cargo test` counts it under "ignored" instead of "passed". With the peer's `SCATTERFIT_REQUIRE_*`
//! variable set to `1` (CI sets them), a missing peer fails every test that needs it instead. A
//! peer is looked for once, when the first of its tests runs (a filter that leaves out all of its
//! tests does not start it).

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::{Arc, OnceLock};

use libtest_mimic::{Arguments, Completion, Failed, Trial};

/// A peer program: how to find it (its path, or why it is not there), found once.
pub struct Peer {
    group: &'static str,
    find: fn() -> Result<PathBuf, String>,
    found: Arc<OnceLock<Result<PathBuf, String>>>,
    require_var: &'static str,
}

impl Peer {
    /// The peer of the tests named `group::…` (their file's name); `find` gives its path or why it
    /// is missing; `require_var` is the environment variable whose value `1` makes a missing peer a
    /// failure.
    pub fn new(
        group: &'static str,
        find: fn() -> Result<PathBuf, String>,
        require_var: &'static str,
    ) -> Self {
        Self {
            group,
            find,
            found: Arc::new(OnceLock::new()),
            require_var,
        }
    }

    /// Whether a missing peer fails the tests (`require_var` = 1).
    pub fn required(&self) -> bool {
        std::env::var(self.require_var).is_ok_and(|v| v == "1")
    }

    /// The test `group::name`, which runs `test` with the peer's path; without the peer it is
    /// ignored at run time with the reason (or fails, when the peer is required).
    pub fn trial(&self, name: &str, test: fn(&Path)) -> Trial {
        let found = Arc::clone(&self.found);
        let find = self.find;
        let required = self.required();
        let var = self.require_var;
        Trial::ignorable_test(format!("{}::{name}", self.group), move || {
            match found.get_or_init(find) {
                Ok(path) => {
                    test(path);
                    Ok(Completion::Completed)
                }
                Err(why) if required => Err(Failed::from(format!(
                    "{why}; {var}=1 makes this test required"
                ))),
                Err(why) => Ok(Completion::ignored_with(format!("not run: {why}"))),
            }
        })
    }
}

/// Runs `trials` as `cargo test` would (the same arguments: filters, `--ignored`, `--nocapture`
/// is accepted, `--list`), and exits with the harness's code.
pub fn run(trials: Vec<Trial>) -> ExitCode {
    libtest_mimic::run(&Arguments::from_args(), trials).exit_code()
}
