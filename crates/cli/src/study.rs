//! `scatterfit study`: the bias study. Rig-twin samples (Monte Carlo, noisy 8-bit brackets) over a
//! grid of reduced albedos α′ and refractive indices η are measured once each and fitted with every
//! forward model and method; the errors of σ′s, σa and α′ against the truth are tabulated per
//! (model, albedo model, method) and plotted, and where each model stops being usable is stated.
//!
//! Every grid point is one channel; three albedos at the same η share a sample. σ′t is the same for
//! all (default 2 mm⁻¹, a mean free path of 0.5 mm, like the paper's materials), so σ′s = α′σ′t and
//! σa = (1 − α′)σ′t. The study owns its output folder (a `.scatterfit-study` marker).
//!
//! `--shard K/N` does every Nth sample of the grid (round-robin) and writes its rows into a partial
//! file; `scatterfit combine` makes the tables and the figure of all (`study_set`).
//!
//! `--g` gives the study a g axis: the twins are made at each Henyey–Greenstein g, fitted
//! every way assuming g = 0 and once more with the g-aware `mc` model told the true g
//! (`scatterfit_lab::study::g_given_combo`); `study.md` gains a table per model over g.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use scatterfit_lab::study::StudySample;
use scatterfit_lab::study_run::{StudyConfig, StudyPart, fit_plan, fit_samples};
use scatterfit_pipeline::outputs::claim_folder;

use crate::common::{JobsArgs, cache_dir};
use crate::output::errln;
use crate::twin::{synthesize_on, write_sample};

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
    #[command(flatten)]
    pub config: StudyConfig,
    #[command(flatten)]
    pub jobs: JobsArgs,
    /// Leave out photon beam diffusion (its fits take milliseconds, not microseconds).
    #[arg(long)]
    pub no_pbd: bool,
    /// Use a folder that holds other files than a previous study's.
    #[arg(long)]
    pub force: bool,
    /// Folder for cached Monte Carlo profiles.
    #[arg(long, value_name = "DIR")]
    pub cache_dir: Option<PathBuf>,
    #[command(flatten)]
    pub shard: crate::shard::ShardArgs,
    /// Print the rows as JSON.
    #[arg(long)]
    pub json: bool,
    /// No progress bars.
    #[arg(long)]
    pub quiet: bool,
}

/// Runs `scatterfit study`.
pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let config = StudyConfig {
        no_pbd: args.no_pbd,
        ..args.config.clone()
    };
    config.check()?;
    let t0 = Instant::now();
    let out = &args.output_dir;
    claim_folder(out, ".scatterfit-study", "study", "", args.force)?;
    let quiet = args.quiet || args.json;
    let cache = cache_dir(args.cache_dir.as_deref());
    let g_axis = config.g_axis();
    let all: Vec<StudySample> = config.samples(out);
    // With --shard, every Nth sample (round-robin over the grid's samples).
    let job = match args.shard.get()? {
        Some((shard, dir)) => {
            let job = crate::shard::Job::new(dir, crate::shard::Kind::Study, shard, &config);
            if job.done::<StudyPart>(args.force, |_| true)? {
                if !quiet {
                    errln!(
                        "shard {shard}: {} is there and matches; nothing to do",
                        job.path.display()
                    );
                }
                return Ok(ExitCode::SUCCESS);
            }
            Some((shard, job))
        }
        None => None,
    };
    let samples: Vec<StudySample> = all
        .into_iter()
        .enumerate()
        .filter(|(i, _)| job.as_ref().is_none_or(|(shard, _)| shard.owns(*i)))
        .map(|(_, s)| s)
        .collect();
    if !quiet {
        errln!(
            "study: {} samples ({} η × {} α′{}) on the {} rig, Monte Carlo cached in {}",
            samples.len(),
            config.etas.len(),
            config.albedos.len(),
            if g_axis {
                format!(" × {} g", config.g.len())
            } else {
                String::new()
            },
            if config.quick { "quick" } else { "paper's" },
            cache
                .as_deref()
                .map_or("no cache".into(), |p| p.display().to_string())
        );
    }
    for sample in &samples {
        let (m, rig) = config.twin(sample)?;
        let s = synthesize_on(&m, &rig, config.seed, cache.as_deref(), quiet)?;
        write_sample(&sample.dir, &s)?;
    }
    let synth_s = t0.elapsed().as_secs_f64();
    let combos = config.combos();
    // As many samples at once as `-j` asks and the memory budget allows (as `batch`).
    let plan = fit_plan(&samples, args.jobs.count());
    if plan.reduced() && !quiet {
        errln!(
            "note: fitting {} sample(s) at a time instead of {}: that many would need about {} of \
             memory, more than the budget of {} ({}=<MiB> raises it)",
            plan.jobs,
            plan.requested,
            scatterfit_io::budget::describe_bytes(plan.memory_needed),
            scatterfit_io::budget::describe_bytes(plan.memory_budget),
            scatterfit_io::budget::MEMORY_BUDGET_ENV
        );
    }
    let bar = crate::common::bar(
        samples.len() as u64,
        "fitting {bar:30} {pos}/{len} samples {elapsed}",
        quiet,
    );
    let results = fit_samples(&samples, &combos, plan.jobs, &|| bar.inc(1))?;
    bar.finish_and_clear();
    let mut rows = Vec::new();
    let mut failed = Vec::new();
    for (r, StudySample { dir, .. }) in results.into_iter().zip(&samples) {
        match r {
            Ok(v) => rows.extend(v),
            Err(e) => failed.push(format!(
                "{}: {}",
                dir.display(),
                crate::common::error_text(&e.into())
            )),
        }
    }
    if let Some((shard, job)) = job {
        let n = samples.len();
        job.write(
            StudyPart {
                rows: rows.clone(),
                failed: failed.clone(),
                synth_s,
                fit_s: t0.elapsed().as_secs_f64() - synth_s,
            },
            std::env::args().collect(),
        )?;
        if !quiet {
            errln!(
                "shard {shard}: {n} sample(s), {} failed; {} (the tables and the figure: \
                 `scatterfit combine`)",
                failed.len(),
                job.path.display()
            );
        }
        // A failed sample is the combined study's news: the shard succeeded, so that a job array's
        // dependent combine step runs.
        return Ok(ExitCode::SUCCESS);
    }
    crate::study_set::write(
        out,
        &config,
        rows,
        &failed,
        synth_s,
        t0.elapsed().as_secs_f64() - synth_s,
        args.json,
    )
}
