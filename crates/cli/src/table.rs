//! `scatterfit table`: builds (or shows) a cached Monte Carlo profile table Rd(α′, r) for one η and g.

use std::io::IsTerminal;
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, bail};
use scatterfit_mc::table::{CacheStatus, ProfileTable, TableSpec, default_cache_dir};
use serde::Serialize;

/// Arguments of `scatterfit table`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Relative refractive index η of the material.
    #[arg(long, allow_hyphen_values = true)]
    pub eta: f64,
    /// Henyey–Greenstein asymmetry g ∈ (−1, 1).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub g: f64,
    /// Number of reduced albedos α′ (equally spaced in √(1 − α′) from 0 to 0.999).
    #[arg(long, default_value_t = 32)]
    pub albedos: usize,
    /// Photons per albedo.
    #[arg(long, default_value_t = 200_000)]
    pub photons_per_albedo: u64,
    /// A coarse table that builds in seconds (16 albedos × 50 000 photons); overrides the two above.
    #[arg(long)]
    pub coarse: bool,
    /// Cache folder (default: $SCATTERFIT_CACHE, else $XDG_CACHE_HOME/scatterfit, else ~/.cache/scatterfit).
    #[arg(long)]
    pub cache_dir: Option<PathBuf>,
    /// Accept η < 1.
    #[arg(long)]
    pub allow_eta_below_one: bool,
    /// Print the table summary as JSON.
    #[arg(long)]
    pub json: bool,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
}

#[derive(Debug, Serialize)]
struct Summary {
    path: PathBuf,
    status: &'static str,
    eta: f64,
    g: f64,
    albedos: Vec<f64>,
    rd_total: Vec<f64>,
    rd_total_stderr: Vec<f64>,
    radial_bins: usize,
    photons_per_albedo: u64,
}

/// Runs `scatterfit table`.
pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    if args.eta < 1.0 && !args.allow_eta_below_one {
        bail!(
            "--eta {}: below 1 is unusual for a solid; pass --allow-eta-below-one if you mean it",
            args.eta
        );
    }
    let spec = if args.coarse {
        TableSpec::coarse(args.eta, args.g)
    } else {
        TableSpec::new(args.eta, args.g, args.albedos, args.photons_per_albedo)
    }
    .context("bad table parameters")?;
    let dir = match args.cache_dir.clone().or_else(default_cache_dir) {
        Some(d) => d,
        None => bail!("no cache folder: pass --cache-dir or set SCATTERFIT_CACHE"),
    };
    let bar = (!args.quiet && std::io::stderr().is_terminal()).then(|| {
        let bar = indicatif::ProgressBar::new(0);
        bar.set_style(
            indicatif::ProgressStyle::with_template(
                "{bar:40} {human_pos}/{human_len} photons  {per_sec}  ETA {eta}",
            )
            .expect("static template"),
        );
        bar
    });
    let (table, status, path) = ProfileTable::load_or_build(&spec, &dir, &|done, total| {
        if let Some(b) = &bar {
            b.set_length(total);
            b.set_position(done);
        }
    })
    .with_context(|| format!("building the table in {}", dir.display()))?;
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    let (tot, se) = table.totals();
    let summary = Summary {
        path,
        status: match status {
            CacheStatus::Loaded => "loaded from cache",
            _ => "built and cached",
        },
        eta: spec.eta,
        g: spec.g,
        albedos: spec.albedos.clone(),
        rd_total: tot.to_vec(),
        rd_total_stderr: se.to_vec(),
        radial_bins: table.centers().len(),
        photons_per_albedo: spec.photons_per_albedo,
    };
    if args.json {
        crate::output::print_json(&summary)?;
    } else {
        println!("table   {} ({})", summary.path.display(), summary.status);
        println!(
            "eta {}  g {}  {} radial bins  {} photons/albedo",
            spec.eta, spec.g, summary.radial_bins, spec.photons_per_albedo
        );
        println!("{:>10} {:>12} {:>10}", "albedo'", "Rd total", "s.e.");
        for ((a, r), s) in spec.albedos.iter().zip(tot).zip(se) {
            println!("{a:>10.6} {r:>12.6} {s:>10.6}");
        }
    }
    Ok(ExitCode::SUCCESS)
}
