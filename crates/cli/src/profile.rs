//! `scatterfit profile` (work in progress: see the open issue that owns it).

use std::process::ExitCode;

/// Arguments of `scatterfit profile`.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// Runs `scatterfit profile`.
pub fn run(_args: Args) -> anyhow::Result<ExitCode> {
    anyhow::bail!("`scatterfit profile` is not built yet")
}
