//! `scatterfit table` (work in progress: see the open issue that owns it).

use std::process::ExitCode;

/// Arguments of `scatterfit table`.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// Runs `scatterfit table`.
pub fn run(_args: Args) -> anyhow::Result<ExitCode> {
    anyhow::bail!("`scatterfit table` is not built yet")
}
