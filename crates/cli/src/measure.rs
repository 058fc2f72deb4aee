//! `scatterfit measure`: one sample folder → σ′s, σa and η per channel (the paper's Table 1 row),
//! with the result files written into the folder (or `--output-dir`).

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
use scatterfit_io::manifest::{MethodName, ModelName};
use scatterfit_pipeline::{Overrides, Stage, measure_sample};
use serde::Serialize;

use crate::common::bar;

/// The fitting method.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum MethodArg {
    /// Choi et al. 2014: α′ from the spectrophotometer, σ′s (and the profile's scale) fitted.
    Proposed,
    /// Jensen et al. 2001: σ′s, σa (and the scale) fitted.
    Existing,
}

impl From<MethodArg> for MethodName {
    fn from(m: MethodArg) -> Self {
        match m {
            MethodArg::Proposed => MethodName::Proposed,
            MethodArg::Existing => MethodName::Existing,
        }
    }
}

/// The forward model.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum ModelArg {
    /// The classical dipole, Jensen et al. 2001 (the paper's).
    Dipole,
    /// d'Eon 2012 (not available yet).
    BetterDipole,
    /// Photon beam diffusion (not available yet).
    Pbd,
    /// Monte Carlo tables (not available yet).
    Mc,
}

impl From<ModelArg> for ModelName {
    fn from(m: ModelArg) -> Self {
        match m {
            ModelArg::Dipole => ModelName::Dipole,
            ModelArg::BetterDipole => ModelName::BetterDipole,
            ModelArg::Pbd => ModelName::Pbd,
            ModelArg::Mc => ModelName::Mc,
        }
    }
}

/// Options shared by `measure`, `batch` and `compare`: what overrides the manifests' `[fit]`.
#[derive(Debug, Clone, clap::Args)]
pub struct FitArgs {
    /// The fitting method (default: the manifest's `fit.method`, else proposed).
    #[arg(long, value_enum)]
    pub method: Option<MethodArg>,
    /// The forward model (default: the manifest's `fit.model`, else dipole).
    #[arg(long, value_enum)]
    pub model: Option<ModelArg>,
    /// A known η instead of the one measured from SCI − SCE [1, 3].
    #[arg(long)]
    pub eta: Option<f64>,
    /// Proposed method: fix the profile's scale by the spectrophotometer's Rd instead of fitting it.
    #[arg(long)]
    pub normalise_with_spectro: bool,
}

impl FitArgs {
    /// The pipeline's overrides.
    ///
    /// # Errors
    /// An η outside [1, 3].
    pub fn overrides(&self) -> anyhow::Result<Overrides> {
        if let Some(e) = self.eta
            && !(e.is_finite() && (1.0..=3.0).contains(&e))
        {
            anyhow::bail!("--eta {e}: the relative refractive index must lie in [1, 3]");
        }
        Ok(Overrides {
            method: self.method.map(Into::into),
            model: self.model.map(Into::into),
            eta: self.eta,
            normalise_with_spectro: self.normalise_with_spectro.then_some(true),
        })
    }
}

/// Arguments of `scatterfit measure`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The sample folder (holding sample.toml).
    pub dir: PathBuf,
    /// Where to write result.json, result.csv, result.md, profile.csv, fit.svg and fit.png
    /// (default: the sample folder; these files are the command's own and are replaced).
    #[arg(short = 'o', long = "output-dir", value_name = "DIR")]
    pub output_dir: Option<PathBuf>,
    #[command(flatten)]
    pub fit: FitArgs,
    /// Print result.json on stdout instead of the summary.
    #[arg(long)]
    pub json: bool,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
}

#[derive(Serialize)]
struct Timing {
    timings: scatterfit_pipeline::Timings,
}

/// Runs `scatterfit measure`.
pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let overrides = args.fit.overrides()?;
    let out = args.output_dir.clone().unwrap_or_else(|| args.dir.clone());
    let bar = bar(5, "{msg} {bar:30} {elapsed}", args.quiet || args.json);
    let m = measure_sample(&args.dir, &overrides, &|stage| {
        let msg = match stage {
            Stage::Spectro => "spectrophotometer",
            Stage::ReadFrame => "reading frames",
            Stage::Merge => "merging",
            Stage::Profile => "profile",
            Stage::Fit => "fitting",
            _ => "",
        };
        bar.set_message(msg);
        bar.tick();
    })
    .with_context(|| format!("measuring {}", args.dir.display()))?;
    bar.finish_and_clear();
    for w in &m.spectro.warnings {
        eprintln!("warning: {w}");
    }
    for p in &m.hdr.dropped_alpha {
        eprintln!("note: {}: alpha channel ignored", p.display());
    }
    let (result, written) = crate::report::write_measurement(&out, &m)?;
    if args.json {
        crate::output::print_json(&result)?;
    } else {
        print!("{}", crate::report::summary_text(&result));
        let t = &m.timings;
        println!(
            "  time: {:.3} s (spectro {:.3}, read {:.3}, merge {:.3}, profile {:.3}, fits {:.4})",
            t.total_s, t.spectro_s, t.read_s, t.merge_s, t.profile_s, t.fit_s
        );
        println!(
            "  wrote {} files in {}: {}",
            written.len(),
            out.display(),
            written
                .iter()
                .filter_map(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    let _ = Timing { timings: m.timings };
    Ok(if m.complete() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}
