//! `scatterfit demo` (work in progress: see the open issue that owns it).

use std::process::ExitCode;

/// Arguments of `scatterfit demo`.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// Runs `scatterfit demo`.
pub fn run(_args: Args) -> anyhow::Result<ExitCode> {
    anyhow::bail!("`scatterfit demo` is not built yet")
}
