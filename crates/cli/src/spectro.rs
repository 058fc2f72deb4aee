//! `scatterfit spectro`: the spectrophotometer stage on one reading.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use crate::output::outln;
use anyhow::{Context, bail};
use scatterfit_optics::colour::{Lab, Observer};
use scatterfit_optics::spectro::{SpectroAnalysis, SpectroOptions, SpectroReading, analyse};
use serde::Serialize;

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

/// The JSON document `scatterfit spectro` writes.
#[derive(Debug, Serialize)]
pub struct SpectroReport<'a> {
    /// The input file.
    pub file: String,
    /// The options that shaped the result.
    pub lab: Option<Lab>,
    /// Observer of `lab`.
    pub lab_observer: Option<u32>,
    /// The analysis.
    #[serde(flatten)]
    pub analysis: &'a SpectroAnalysis,
    /// scatterfit's version.
    pub version: &'static str,
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
        print_summary(&args.file, &reading, &analysis)?;
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
    SpectroReport {
        file: args.file.display().to_string(),
        lab: analysis_lab(args),
        lab_observer: args.lab.as_ref().map(|_| args.observer),
        analysis,
        version: env!("CARGO_PKG_VERSION"),
    }
}

fn analysis_lab(args: &Args) -> Option<Lab> {
    args.lab.as_ref().map(|v| Lab {
        l: v[0],
        a: v[1],
        b: v[2],
    })
}

fn print_summary(file: &Path, reading: &SpectroReading, a: &SpectroAnalysis) -> anyhow::Result<()> {
    let wl = reading.wavelengths_nm();
    outln!(
        "{}: {} wavelengths, {}–{} nm",
        file.display(),
        wl.len(),
        wl.first().copied().unwrap_or(0.0),
        wl.last().copied().unwrap_or(0.0)
    )?;
    match a.eta_source {
        scatterfit_optics::spectro::EtaSource::Given => outln!("η = {:.4} (given)", a.eta)?,
        scatterfit_optics::spectro::EtaSource::SchlickSciMinusSce => outln!(
            "η = {:.4}  (Schlick at 8° from SCI − SCE = {:.5}, luminance-weighted; exact Fresnel: {})",
            a.eta,
            a.specular_mean,
            a.eta_exact_fresnel
                .map_or("—".into(), |e| format!("{e:.4}"))
        )?,
    }
    let ch = |c: usize| {
        a.channels[c]
            .eta_channel
            .map_or("—".into(), |e| format!("{e:.4}"))
    };
    outln!(
        "η per channel: R {}  G {}  B {}  (dispersion {})",
        ch(0),
        ch(1),
        ch(2),
        if a.dispersion_significant {
            "significant"
        } else {
            "not significant"
        }
    )?;
    outln!(
        "SCE colour: L*a*b* D65/2° {:.3} {:.3} {:.3}   D65/10° {:.3} {:.3} {:.3}",
        a.lab_2deg.l,
        a.lab_2deg.a,
        a.lab_2deg.b,
        a.lab_10deg.l,
        a.lab_10deg.a,
        a.lab_10deg.b
    )?;
    outln!(
        "            XYZ 2° {:.4} {:.4} {:.4}   10° {:.4} {:.4} {:.4}",
        a.xyz_2deg.x,
        a.xyz_2deg.y,
        a.xyz_2deg.z,
        a.xyz_10deg.x,
        a.xyz_10deg.y,
        a.xyz_10deg.z
    )?;
    let source = match a.colour_source {
        scatterfit_optics::spectro::ColourSource::SceSpectrum => "SCE spectrum",
        scatterfit_optics::spectro::ColourSource::Lab2 => "given L*a*b* (2°)",
        scatterfit_optics::spectro::ColourSource::Lab10 => "given L*a*b* (10°, Bradford to 2°)",
    };
    outln!(
        "\nchannel  Rd (linear sRGB, from {source})   α′ (dipole, η = {:.4})",
        a.eta
    )?;
    for (name, c) in ["R", "G", "B"].iter().zip(&a.channels) {
        let albedo = c.albedo_prime.map_or("—".to_owned(), |v| format!("{v:.6}"));
        outln!("{name:<8} {:<38.6} {albedo}", c.rd_total)?;
    }
    for c in &a.channels {
        if let Some(p) = &c.problem {
            outln!("problem: {p}")?;
        }
    }
    for w in &a.warnings {
        outln!("warning: {w}")?;
    }
    Ok(())
}
