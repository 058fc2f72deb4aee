//! `scatterfit spectro` (work in progress: see the open issue that owns it).

use std::process::ExitCode;

/// Arguments of `scatterfit spectro`.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// Runs `scatterfit spectro`.
pub fn run(_args: Args) -> anyhow::Result<ExitCode> {
    anyhow::bail!("`scatterfit spectro` is not built yet")
}
