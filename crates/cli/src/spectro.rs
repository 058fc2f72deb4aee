//! `scatterfit spectro`: the spectrophotometer stage on one reading (`scatterfit_optics::spectro`),
//! reported by `scatterfit_report::spectro`.

use std::path::PathBuf;
use std::process::ExitCode;

use crate::output::out;
use anyhow::{Context, bail};
use scatterfit_optics::colour::{Lab, Observer};
use scatterfit_optics::spectro::{SpectroAnalysis, SpectroOptions, analyse};
use scatterfit_report::{SpectroReport, spectro_text};

/// Arguments of `scatterfit spectro`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Spectrophotometer CSV: `wavelength_nm,sci,sce` (fractions) or `…,sci_pct,sce_pct` (percent).
    pub file: PathBuf,
    /// Measured L*a*b* (D65) to use for the colour instead of the SCE spectrum: L* in [0, 100], a*
    /// and b* finite.
    #[arg(long, num_args = 3, value_names = ["L", "A", "B"], allow_negative_numbers = true)]
    pub lab: Option<Vec<f64>>,
    /// Observer of --lab: 10 (the instrument default) or 2.
    #[arg(long, default_value_t = 10, value_name = "2|10")]
    pub observer: u32,
    /// A known η to use instead of the one measured from SCI − SCE (e.g. for matte samples), in
    /// [1, 3].
    #[arg(long, value_parser = crate::numeric::parse_finite)]
    pub eta: Option<f64>,
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
    let options = options_from(&args)?;
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

fn options_from(args: &Args) -> anyhow::Result<SpectroOptions> {
    let lab = match &args.lab {
        None => None,
        Some(v) => {
            let [l, a, b] = v[..] else {
                bail!("--lab takes three numbers: L* a* b*")
            };
            if !(0.0..=100.0).contains(&l) || !a.is_finite() || !b.is_finite() {
                bail!(
                    "--lab {} {} {}: L* must lie in 0..100 and a*, b* be finite numbers",
                    crate::numeric::show(l),
                    crate::numeric::show(a),
                    crate::numeric::show(b)
                );
            }
            let observer = Observer::from_degrees(args.observer)
                .with_context(|| format!("--observer {}: use 2 or 10", args.observer))?;
            Some((Lab { l, a, b }, observer))
        }
    };
    if let Some(eta) = args.eta
        && !(1.0..=3.0).contains(&eta)
    {
        bail!(
            "--eta {}: the relative refractive index must lie in [1, 3]",
            crate::numeric::show(eta)
        );
    }
    Ok(SpectroOptions { lab, eta: args.eta })
}

fn report<'a>(args: &Args, analysis: &'a SpectroAnalysis) -> SpectroReport<'a> {
    let lab = args.lab.as_ref().map(|v| {
        let lab = Lab {
            l: v[0],
            a: v[1],
            b: v[2],
        };
        (lab, args.observer)
    });
    SpectroReport::new(&args.file, lab, analysis)
}
