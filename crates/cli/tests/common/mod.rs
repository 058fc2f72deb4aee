//! What the CLI's integration tests share: the real binary run in a folder (ripgrep's shape), one
//! Monte Carlo cache per test binary, temporary folders, and reading what a command wrote.
//!
//! The test binaries (`tests/suite.rs`, `tests/peers.rs`) each declare this module once, and each
//! file uses a part of it, hence the `dead_code` allowance.
#![allow(dead_code)]

pub mod peer;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::OnceLock;

/// What one run of the binary gave: its exit code (−1 when a signal ended it) and its output as
/// text.
#[derive(Debug)]
pub struct Run {
    /// The exit code; −1 when the process was ended by a signal.
    pub code: i32,
    /// Standard output (lossy UTF-8).
    pub stdout: String,
    /// Standard error (lossy UTF-8).
    pub stderr: String,
}

impl From<Output> for Run {
    fn from(out: Output) -> Self {
        Self {
            code: exit_code(&out),
            stdout: text(&out.stdout),
            stderr: text(&out.stderr),
        }
    }
}

/// The binary under test, `scatterfit`, with the environment the test runs in.
pub fn command() -> Command {
    Command::new(env!("CARGO_BIN_EXE_scatterfit"))
}

/// [`command`] with `SCATTERFIT_CACHE` set to this test binary's own Monte Carlo cache
/// ([`cache`]), so each material is simulated once per test binary and never read from the user's
/// cache.
pub fn cached_command() -> Command {
    let mut c = command();
    c.env("SCATTERFIT_CACHE", cache());
    c
}

/// `scatterfit ARGS` run in `cwd`.
pub fn run(cwd: &Path, args: &[&str]) -> Run {
    command()
        .args(args)
        .current_dir(cwd)
        .output()
        .expect("run scatterfit")
        .into()
}

/// [`run`] with this test binary's Monte Carlo cache ([`cached_command`]).
pub fn run_cached(cwd: &Path, args: &[&str]) -> Run {
    cached_command()
        .args(args)
        .current_dir(cwd)
        .output()
        .expect("run scatterfit")
        .into()
}

/// One Monte Carlo cache folder for the whole test binary.
pub fn cache() -> &'static Path {
    static DIR: OnceLock<tempfile::TempDir> = OnceLock::new();
    DIR.get_or_init(temp_dir).path()
}

/// A fresh temporary folder, removed when dropped.
pub fn temp_dir() -> tempfile::TempDir {
    tempfile::tempdir().expect("a temporary folder")
}

/// Bytes as text (lossy UTF-8).
pub fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// A finished process's exit code; −1 when a signal ended it.
pub fn exit_code(out: &Output) -> i32 {
    out.status.code().unwrap_or(-1)
}

/// The text of a file a command wrote.
pub fn read_text(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// A JSON file a command wrote (result.json, truth.json, …).
pub fn read_json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&read_text(path)).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The workspace's root folder (two levels above this crate).
pub fn workspace_root() -> PathBuf {
    let manifest = Path::new(env!("CARGO_MANIFEST_DIR"));
    manifest
        .parent()
        .and_then(Path::parent)
        .unwrap_or(manifest)
        .to_path_buf()
}

/// A quick rig-twin sample of `material` in `cwd/dir` (`synth --quick`, this test binary's cache):
/// about a second once the cache holds the material.
pub fn synth_quick(cwd: &Path, material: &str, dir: &str) {
    let out = run_cached(
        cwd,
        &[
            "synth",
            "--material",
            material,
            "--quick",
            "-o",
            dir,
            "--quiet",
        ],
    );
    assert_eq!(out.code, 0, "{}", out.stderr);
}
