//! `scatterfit merge` (work in progress: see the open issue that owns it).

use std::process::ExitCode;

/// Arguments of `scatterfit merge`.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// Runs `scatterfit merge`.
pub fn run(_args: Args) -> anyhow::Result<ExitCode> {
    anyhow::bail!("`scatterfit merge` is not built yet")
}

/// Contributes this area's figures to `scatterfit bench`.
pub fn bench(_args: &crate::bench::Args) -> anyhow::Result<Vec<crate::bench::Figure>> {
    Ok(Vec::new())
}
