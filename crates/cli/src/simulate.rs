//! `scatterfit simulate` (work in progress: see the open issue that owns it).

use std::process::ExitCode;

/// Arguments of `scatterfit simulate`.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// Runs `scatterfit simulate`.
pub fn run(_args: Args) -> anyhow::Result<ExitCode> {
    anyhow::bail!("`scatterfit simulate` is not built yet")
}

/// Contributes this area's figures to `scatterfit bench`.
pub fn bench(_args: &crate::bench::Args) -> anyhow::Result<Vec<crate::bench::Figure>> {
    Ok(Vec::new())
}
