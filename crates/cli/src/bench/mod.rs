//! `scatterfit bench`: measures the hot paths on this machine and prints the figures that
//! BENCHMARKS.md records. The areas are the `scatterfit-bench` crate's (`optics`, `mc`, `imaging`,
//! `fit`, `render`); `fit` first writes a rig-twin sample folder through the shared `twin` module,
//! as `synth` does.

mod fit;

use std::process::ExitCode;

use crate::output::outln;
pub use scatterfit_bench::Figure;

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

/// Runs `scatterfit bench`.
pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let mut figures = Vec::new();
    let all = args.area == Area::All;
    if all || args.area == Area::Optics {
        figures.extend(scatterfit_bench::optics::figures(args.quick)?);
    }
    if all || args.area == Area::Mc {
        figures.extend(scatterfit_bench::mc::figures(args.quick)?);
    }
    if all || args.area == Area::Imaging {
        figures.extend(scatterfit_bench::imaging::figures(args.quick)?);
    }
    if all || args.area == Area::Fit {
        figures.extend(fit::figures(&args)?);
    }
    if all || args.area == Area::Render {
        figures.extend(scatterfit_bench::render::figures(args.quick)?);
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
