//! `scatterfit bench`: measures the hot paths on this machine and prints the figures that
//! BENCHMARKS.md records. Each area has its module here (`optics`, `mc`, `imaging`, `fit`,
//! `render`, as `scatterfit bench --help` lists them), which calls the library crates and the
//! shared cli modules, never a command's file.

mod fit;
mod imaging;
mod mc;
mod optics;
mod render;

use std::process::ExitCode;

use crate::output::outln;
use serde::Serialize;

/// Which part of the pipeline to measure.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Area {
    /// Everything below.
    All,
    /// Optics core: dipole profile with derivatives, α′ inversion.
    Optics,
    /// Monte Carlo photon transport.
    Mc,
    /// HDR merge and radial profile.
    Imaging,
    /// The profile fit per channel and a whole sample's measurement.
    Fit,
    /// Validation renderer: BVH, both rendering methods at 512×512 on a 100k-triangle mesh.
    Render,
}

/// Arguments of `scatterfit bench`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// What to measure.
    #[arg(value_enum, default_value_t = Area::All)]
    pub area: Area,
    /// Smaller problem sizes, for a quick look (figures are then not comparable with BENCHMARKS.md).
    #[arg(long)]
    pub quick: bool,
    /// Print the figures as JSON instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// One measured figure.
#[derive(Debug, Clone, Serialize)]
pub struct Figure {
    /// What was measured, e.g. "dipole Rd(r) + derivatives, 300 radii".
    pub name: String,
    /// The measured value.
    pub value: f64,
    /// Its unit, e.g. "µs", "photons/s", "s".
    pub unit: String,
    /// Context: problem size, threads, the target from the issue.
    pub note: String,
}

/// Runs `scatterfit bench`.
pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let mut figures = Vec::new();
    let all = args.area == Area::All;
    if all || args.area == Area::Optics {
        figures.extend(optics::figures(&args)?);
    }
    if all || args.area == Area::Mc {
        figures.extend(mc::figures(&args)?);
    }
    if all || args.area == Area::Imaging {
        figures.extend(imaging::figures(&args)?);
    }
    if all || args.area == Area::Fit {
        figures.extend(fit::figures(&args)?);
    }
    if all || args.area == Area::Render {
        figures.extend(render::figures(&args)?);
    }
    if args.json {
        crate::output::print_json(&figures)?;
    } else {
        outln!("{:<64} {:>14} {:<10} note", "benchmark", "value", "unit")?;
        for f in &figures {
            outln!("{:<64} {:>14.4} {:<10} {}", f.name, f.value, f.unit, f.note)?;
        }
    }
    Ok(ExitCode::SUCCESS)
}
