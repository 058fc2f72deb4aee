//! `scatterfit study`: the bias study. Rig-twin samples (Monte Carlo, noisy 8-bit brackets) over a
//! grid of reduced albedos α′ and refractive indices η are measured once each and fitted with every
//! forward model and method; the errors of σ′s, σa and α′ against the truth are tabulated per
//! (model, albedo model, method) and plotted, and where each model stops being usable is stated.
//!
//! Every grid point is one channel; three albedos at the same η share a sample. σ′t is the same for
//! all (default 2 mm⁻¹, a mean free path of 0.5 mm, like the paper's materials), so σ′s = α′σ′t and
//! σa = (1 − α′)σ′t. The study owns its output folder (a `.scatterfit-study` marker).

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{Context, bail};
use rayon::prelude::*;
use scatterfit_pipeline::study::{
    Row, StudySample, combos, dedup, rows_csv, samples, study_sample, summary_markdown,
};

use crate::common::cache_dir;
use crate::output::{errln, out, outln};
use crate::twin::{Material, synthesize, write_sample};

/// Arguments of `scatterfit study`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Folder for the samples and the study's tables and plot (created; the study's own).
    #[arg(
        short = 'o',
        long = "output-dir",
        default_value = "scatterfit-study",
        value_name = "DIR"
    )]
    pub output_dir: PathBuf,
    /// Refractive indices η, each in [1, 2.5] (the Monte Carlo tables' range).
    #[arg(long, value_delimiter = ',', default_values_t = [1.0, 1.2, 1.4, 1.6, 2.0, 2.4])]
    pub etas: Vec<f64>,
    /// Reduced albedos α′, each in [0.3, 0.9999].
    #[arg(long, value_delimiter = ',', default_values_t = [0.3, 0.5, 0.7, 0.9, 0.95, 0.98, 0.99, 0.999, 0.9999])]
    pub albedos: Vec<f64>,
    /// Reduced extinction σ′t of every grid point [mm⁻¹, 0.2–20].
    #[arg(long, default_value_t = 2.0, value_name = "MM-1")]
    pub sigma_t_prime: f64,
    /// Small fast samples (256 × 256 px at 0.1 mm/px, a tenth of the photons).
    #[arg(long)]
    pub quick: bool,
    /// Seed of the rig twin.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Samples measured at the same time [1, 256] (default: one per core).
    #[arg(short = 'j', long, value_name = "N", value_parser = clap::value_parser!(u16).range(1..=256))]
    pub jobs: Option<u16>,
    /// Leave out photon beam diffusion (its fits take milliseconds, not microseconds).
    #[arg(long)]
    pub no_pbd: bool,
    /// Use a folder that holds other files than a previous study's.
    #[arg(long)]
    pub force: bool,
    /// Folder for cached Monte Carlo profiles.
    #[arg(long, value_name = "DIR")]
    pub cache_dir: Option<PathBuf>,
    /// Print the rows as JSON.
    #[arg(long)]
    pub json: bool,
    /// No progress bars.
    #[arg(long)]
    pub quiet: bool,
}

const MARKER: &str = ".scatterfit-study";

fn check_args(args: &Args) -> anyhow::Result<()> {
    if args.etas.is_empty() || args.albedos.is_empty() {
        bail!("give at least one η and one α′");
    }
    if let Some(e) = args.etas.iter().find(|e| !(1.0..=2.5).contains(*e)) {
        bail!(
            "--etas: {} is outside [1, 2.5], the range of the Monte Carlo tables",
            crate::numeric::show(*e)
        );
    }
    if let Some(a) = args.albedos.iter().find(|a| !(0.3..=0.9999).contains(*a)) {
        bail!(
            "--albedos: {} is outside [0.3, 0.9999]",
            crate::numeric::show(*a)
        );
    }
    if !(0.2..=20.0).contains(&args.sigma_t_prime) {
        bail!(
            "--sigma-t-prime {}: must lie in [0.2, 20] mm⁻¹",
            crate::numeric::show(args.sigma_t_prime)
        );
    }
    let dir = &args.output_dir;
    if dir.exists()
        && !args.force
        && !dir.join(MARKER).exists()
        && let Some(e) = std::fs::read_dir(dir)?.flatten().next()
    {
        bail!(
            "{} holds {} and was not made by `scatterfit study`; choose another folder with -o or \
             pass --force",
            dir.display(),
            e.file_name().to_string_lossy()
        );
    }
    Ok(())
}

/// Runs `scatterfit study`.
pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    check_args(&args)?;
    let t0 = Instant::now();
    let out = &args.output_dir;
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    scatterfit_io::atomic::write_atomic(
        &out.join(MARKER),
        b"made by `scatterfit study`; it may replace the files in this folder\n",
    )?;
    let quiet = args.quiet || args.json;
    let cache = cache_dir(args.cache_dir.as_deref());
    // Samples: three albedos per η each (the last triple padded with its last albedo).
    let samples: Vec<StudySample> = samples(out, &args.etas, &args.albedos);
    if !quiet {
        errln!(
            "study: {} samples ({} η × {} α′) on the {} rig, Monte Carlo cached in {}",
            samples.len(),
            args.etas.len(),
            args.albedos.len(),
            if args.quick { "quick" } else { "paper's" },
            cache
                .as_deref()
                .map_or("no cache".into(), |p| p.display().to_string())
        );
    }
    for sample in &samples {
        let m = Material {
            name: sample.name(),
            sigma_s_prime: sample.sigma_s_prime(args.sigma_t_prime),
            sigma_a: sample.sigma_a(args.sigma_t_prime),
            eta: sample.eta,
        };
        let s = synthesize(&m, args.seed, cache.as_deref(), quiet, args.quick)?;
        write_sample(&sample.dir, &s)?;
    }
    let synth_s = t0.elapsed().as_secs_f64();
    let combos = combos(args.no_pbd);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.jobs.map_or(0, usize::from))
        .build()?;
    let bar = crate::common::bar(
        samples.len() as u64,
        "fitting {bar:30} {pos}/{len} samples {elapsed}",
        quiet,
    );
    let results: Vec<anyhow::Result<Vec<Row>>> = pool.install(|| {
        samples
            .par_iter()
            .map(|sample| {
                let r = study_sample(sample, &combos).map_err(anyhow::Error::from);
                bar.inc(1);
                r
            })
            .collect()
    });
    bar.finish_and_clear();
    let mut rows = Vec::new();
    let mut failed = Vec::new();
    for (r, StudySample { dir, .. }) in results.into_iter().zip(&samples) {
        match r {
            Ok(v) => rows.extend(v),
            Err(e) => failed.push(format!(
                "{}: {}",
                dir.display(),
                crate::common::error_text(&e)
            )),
        }
    }
    // A padded triple repeats its last albedo: keep one row per grid point and configuration.
    dedup(&mut rows);
    let summary = summary_markdown(&rows, &combos);
    let csv = rows_csv(&rows);
    for (name, text) in [("study.csv", csv), ("study.md", summary.clone())] {
        let p = out.join(name);
        scatterfit_io::atomic::write_atomic(&p, text.as_bytes())
            .with_context(|| format!("writing {}", p.display()))?;
    }
    scatterfit_report::write_figure(
        &scatterfit_report::study::study_figure(&rows, &combos),
        Some(&out.join("study.svg")),
        Some(&out.join("study.png")),
    )?;
    if args.json {
        crate::output::print_json(&rows)?;
    } else {
        out!("{summary}")?;
        outln!(
            "\ntime: {synth_s:.0} s synthesising, {:.0} s fitting; files: {}/study.md, study.csv, study.png",
            t0.elapsed().as_secs_f64() - synth_s,
            out.display()
        )?;
    }
    if !failed.is_empty() {
        errln!("\n{} sample(s) failed:", failed.len());
        for f in &failed {
            errln!("  {f}");
        }
        return Ok(ExitCode::from(1));
    }
    Ok(ExitCode::SUCCESS)
}
