//! `scatterfit spectro`: the spectrophotometer stage on one reading (`scatterfit_optics::spectro`),
//! reported by `scatterfit_report::spectro`.

use std::path::PathBuf;
use std::process::ExitCode;

use crate::output::out;
use anyhow::Context;
use scatterfit_optics::spectro::{SpectroAnalysis, analyse};
use scatterfit_pipeline::spectro_args::SpectroArgs;
use scatterfit_report::{SpectroReport, spectro_text};

/// Arguments of `scatterfit spectro`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Spectrophotometer CSV: `wavelength_nm,sci,sce` (fractions) or `…,sci_pct,sce_pct` (percent).
    pub file: PathBuf,
    #[command(flatten)]
    pub spectro: SpectroArgs,
    /// Print the full result as JSON on stdout instead of the summary.
    #[arg(long)]
    pub json: bool,
    /// Also write the full result as JSON to this file (`.json`, atomically; checked before any work;
    /// an existing file only with --force).
    #[arg(short = 'o', long = "output", alias = "out", value_name = "FILE")]
    pub out: Option<PathBuf>,
    /// Replace an existing output file.
    #[arg(long)]
    pub force: bool,
}

/// Runs `scatterfit spectro`.
pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let options = args.spectro.options()?;
    if let Some(out) = &args.out {
        crate::common::check_output_file(
            out,
            "-o",
            crate::common::Format {
                extensions: &["json"],
                what: "the result is written as JSON",
            },
            &[args.file.as_path()],
            args.force,
        )?;
    }
    let reading = scatterfit_io::spectro::read_spectro_csv(&args.file)?;
    let analysis =
        analyse(&reading, &options).with_context(|| format!("{}", args.file.display()))?;
    if let Some(out) = &args.out {
        crate::output::write_json_file(out, &report(&args, &analysis))?;
    }
    if args.json {
        crate::output::print_json(&report(&args, &analysis))?;
    } else {
        out!("{}", spectro_text(&args.file, &reading, &analysis))?;
    }
    Ok(if analysis.complete() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

fn report<'a>(args: &Args, analysis: &'a SpectroAnalysis) -> SpectroReport<'a> {
    SpectroReport::new(&args.file, args.spectro.lab_given(), analysis)
}
