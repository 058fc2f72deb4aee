//! `scatterfit bench` (work in progress: see the open issue that owns it).

use std::process::ExitCode;

/// Arguments of `scatterfit bench`.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// Runs `scatterfit bench`.
pub fn run(_args: Args) -> anyhow::Result<ExitCode> {
    anyhow::bail!("`scatterfit bench` is not built yet")
}
