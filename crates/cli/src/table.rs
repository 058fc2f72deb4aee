//! `scatterfit table`: builds (or shows) a cached Monte Carlo profile table Rd(α′, r) for one η and g.

use std::io::IsTerminal;
use std::path::PathBuf;
use std::process::ExitCode;

use crate::output::{errln, outln};
use anyhow::{Context, bail};
use scatterfit_mc::table::{CacheStatus, ProfileTable, TableSpec};
use serde::Serialize;

/// Arguments of `scatterfit table`. Every number is checked before any work (exit 2 when out of
/// range); the build's expected work and memory are checked against `--max-interactions` and
/// `--max-memory-mib` before it starts.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Relative refractive index η of the material: 1 to 10 (below 1 with --allow-eta-below-one).
    #[arg(long, allow_hyphen_values = true, value_parser = crate::numeric::parse_finite)]
    pub eta: f64,
    /// Henyey–Greenstein asymmetry g, in (−1, 1); the work grows like 1/(1 − g) as g → 1.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true, value_parser = crate::numeric::parse_finite)]
    pub g: f64,
    /// Number of reduced albedos α′ (equally spaced in √(1 − α′) from 0 to 0.999): a count, 2 to
    /// 1000.
    #[arg(long, default_value = "32", value_parser = crate::numeric::parse_size)]
    pub albedos: usize,
    /// Photons per albedo: a count ≥ 1 (2e5 is fine); the expected work must fit --max-interactions.
    #[arg(long, default_value = "200000", value_parser = crate::numeric::parse_count)]
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
    #[arg(long, default_value = "1e12", value_parser = crate::numeric::parse_count,
          help = crate::numeric::MAX_INTERACTIONS_HELP)]
    pub max_interactions: u64,
    #[arg(long, value_parser = crate::numeric::parse_mib, help = crate::numeric::MAX_MEMORY_HELP)]
    pub max_memory_mib: Option<u64>,
    /// Print the table summary as JSON.
    #[arg(long)]
    pub json: bool,
    /// No progress bar and no cost estimate on stderr.
    #[arg(long)]
    pub quiet: bool,
}

/// Most albedos of a table: far more than interpolation needs (the default is 32).
const MAX_ALBEDOS: usize = 1000;

/// Checks the flags' ranges, then the spec's expected work and memory, before anything is built.
fn spec_from(args: &Args) -> anyhow::Result<TableSpec> {
    if !(args.eta > 0.0 && args.eta <= 10.0) {
        bail!(
            "--eta {}: the relative refractive index must lie in (0, 10]",
            crate::numeric::show(args.eta)
        );
    }
    if args.eta < 1.0 && !args.allow_eta_below_one {
        bail!(
            "--eta {}: below 1 is unusual for a solid; pass --allow-eta-below-one if you mean it",
            crate::numeric::show(args.eta)
        );
    }
    if !(args.g > -1.0 && args.g < 1.0) {
        bail!(
            "--g {}: the Henyey–Greenstein asymmetry must lie in (−1, 1)",
            crate::numeric::show(args.g)
        );
    }
    if !args.coarse {
        if !(2..=MAX_ALBEDOS).contains(&args.albedos) {
            bail!(
                "--albedos {}: a table has 2 to {MAX_ALBEDOS} albedos",
                args.albedos
            );
        }
        if args.photons_per_albedo == 0 {
            bail!("--photons-per-albedo 0: trace at least one photon per albedo");
        }
    }
    let spec = if args.coarse {
        TableSpec::coarse(args.eta, args.g)
    } else {
        TableSpec::new(args.eta, args.g, args.albedos, args.photons_per_albedo)
    }
    .context("bad table parameters")?;
    let cost = spec.cost_estimate()?;
    // The table itself: value and standard error per albedo and bin, plus the JSON text.
    let bins = spec.radial_edges().len() - 1;
    let table_bytes = (spec.albedos().len() as u64) * (bins as u64 + 1) * 16 * 4;
    crate::numeric::check_memory(
        "the table",
        cost.memory_bytes + table_bytes,
        crate::numeric::memory_budget(args.max_memory_mib),
    )?;
    if cost.interactions > args.max_interactions as f64 {
        bail!(
            "building this table is expected to take about {:.1e} interactions ({} albedos × {} \
             photons, {:.3e} per photon on average; g = {} multiplies them by about 1/(1 − g)), \
             about {} on {} threads, more than the work budget of {:.1e} (--max-interactions); use \
             fewer photons or albedos, a g further from 1, or raise --max-interactions",
            cost.interactions,
            spec.albedos().len(),
            spec.photons_per_albedo(),
            cost.interactions_per_photon,
            spec.g(),
            crate::numeric::describe_seconds(cost.seconds(rayon::current_num_threads())),
            rayon::current_num_threads(),
            args.max_interactions as f64,
        );
    }
    Ok(spec)
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
    let spec = spec_from(&args)?;
    let dir = match crate::common::cache_dir(args.cache_dir.as_deref()) {
        Some(d) => d,
        None => bail!("no cache folder: pass --cache-dir or set SCATTERFIT_CACHE"),
    };
    let cached = dir.join(spec.file_name()).is_file();
    if !cached {
        // The table is written there once built: find out now, not after the build.
        crate::common::check_output_dir(&dir, "--cache-dir")?;
    }
    let cost = spec.cost_estimate()?;
    let expected_s = cost.seconds(rayon::current_num_threads());
    if !args.quiet && !cached && expected_s > 10.0 {
        errln!(
            "expected work: {:.1e} interactions, about {} on {} threads",
            cost.interactions,
            crate::numeric::describe_seconds(expected_s),
            rayon::current_num_threads()
        );
    }
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
        eta: spec.eta(),
        g: spec.g(),
        albedos: spec.albedos().to_vec(),
        rd_total: tot.to_vec(),
        rd_total_stderr: se.to_vec(),
        radial_bins: table.centers().len(),
        photons_per_albedo: spec.photons_per_albedo(),
    };
    if args.json {
        crate::output::print_json(&summary)?;
    } else {
        outln!("table   {} ({})", summary.path.display(), summary.status)?;
        outln!(
            "eta {}  g {}  {} radial bins  {} photons/albedo",
            spec.eta(),
            spec.g(),
            summary.radial_bins,
            spec.photons_per_albedo()
        )?;
        outln!("{:>10} {:>12} {:>10}", "albedo'", "Rd total", "s.e.")?;
        for ((a, r), s) in spec.albedos().iter().zip(tot).zip(se) {
            outln!("{a:>10.6} {r:>12.6} {s:>10.6}")?;
        }
    }
    Ok(ExitCode::SUCCESS)
}
