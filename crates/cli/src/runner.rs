//! Measuring many sample folders in parallel with one progress bar (`batch`, `compare`, `demo`).
//! A failed sample never stops the others; each outcome is kept with its folder.

use std::path::{Path, PathBuf};

use anyhow::Context;
use rayon::prelude::*;
use scatterfit_io::result_json::MeasurementResult;
use scatterfit_optics::Method;
use scatterfit_pipeline::{Measurement, Overrides, measure_sample};

/// One sample's outcome.
pub struct Outcome {
    /// The folder.
    pub dir: PathBuf,
    /// The measurement, or why there is none.
    pub result: anyhow::Result<Measurement>,
}

/// Samples measured at once [1, 256] (`-j`): the help text shared by `batch`, `compare`, `demo`.
pub const JOBS_HELP: &str = "Samples measured at the same time: a count, 1 to 256 (default: one \
     per core). Fewer are run at once when that many would not fit the memory budget \
     ($SCATTERFIT_MAX_MEMORY_MIB, default 8192 MiB; each sample holds its decoded bracket and \
     radiance map); a note on stderr says so";

/// Parses `-j`: a count in 1..=256.
///
/// # Errors
/// A message for clap.
pub fn parse_jobs(text: &str) -> Result<usize, String> {
    match crate::numeric::parse_size(text)? {
        n @ 1..=256 => Ok(n),
        n => Err(format!(
            "{n} samples at once: give 1 to 256 (each holds a whole bracket in memory)"
        )),
    }
}

/// A sample's peak memory [bytes], estimated from its frames' headers: the decoded bracket, and as
/// much again for the radiance map, its mask and the decoders' copies. 0 when unknown (the sample's
/// own reading reports what is wrong with it).
fn sample_memory(dir: &Path) -> u64 {
    let Ok(m) = scatterfit_io::manifest::read_manifest(dir) else {
        return 0;
    };
    let images: Vec<PathBuf> = m
        .camera
        .images
        .iter()
        .flatten()
        .map(|p| m.resolve(p))
        .collect();
    let exposures = m.camera.exposures.as_ref().map(|p| m.resolve(p));
    if let Some(hdr) = &m.camera.hdr {
        // A float map: decoded ≈ 3 × the file (PIZ) at most; with the copy made on reading.
        return std::fs::metadata(m.resolve(hdr)).map_or(0, |md| md.len().saturating_mul(6));
    }
    match scatterfit_io::bracket::planned_frames(&images, exposures.as_deref()) {
        Ok(frames) => {
            let (total, _, _) =
                scatterfit_io::bracket::decoded_size(frames.iter().map(PathBuf::as_path));
            total.saturating_mul(2)
        }
        Err(_) => 0,
    }
}

/// How many of `dirs` to measure at once: `requested` (0: one per core), fewer when that many of
/// the largest samples would not fit the memory budget (checked from the frames' headers before
/// any is read), never below one.
pub fn jobs_within_budget(dirs: &[PathBuf], requested: usize, quiet: bool) -> usize {
    let want = if requested == 0 {
        rayon::current_num_threads()
    } else {
        requested
    }
    .clamp(1, dirs.len().max(1));
    let mut sizes: Vec<u64> = dirs.iter().map(|d| sample_memory(d)).collect();
    sizes.sort_unstable_by(|a, b| b.cmp(a));
    let budget = scatterfit_io::budget::memory_budget_bytes();
    let mut jobs = want;
    while jobs > 1 && sizes.iter().take(jobs).sum::<u64>() > budget {
        jobs -= 1;
    }
    if jobs < want && !quiet {
        crate::output::errln!(
            "note: measuring {jobs} sample(s) at a time instead of {want}: {want} of these samples \
             would need about {} of memory, more than the budget of {} ({}=<MiB> raises it)",
            scatterfit_io::budget::describe_bytes(sizes.iter().take(want).sum()),
            scatterfit_io::budget::describe_bytes(budget),
            scatterfit_io::budget::MEMORY_BUDGET_ENV
        );
    }
    jobs
}

/// Measures every folder of `dirs` with `jobs` samples at a time (0: one per core), calling
/// `done` for each as soon as it is finished (from a worker thread) so results can be written
/// before the others end.
///
/// # Errors
/// Only when the thread pool cannot be built.
pub fn measure_many(
    dirs: &[PathBuf],
    overrides: &Overrides,
    jobs: usize,
    quiet: bool,
    done: &(dyn Fn(&Path, &anyhow::Result<Measurement>) + Sync),
) -> anyhow::Result<Vec<Outcome>> {
    let jobs = jobs_within_budget(dirs, jobs, quiet);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(jobs)
        .build()
        .context("starting the worker threads")?;
    let bar = crate::common::bar(
        dirs.len() as u64,
        "measuring {bar:30} {pos}/{len} samples {elapsed} (eta {eta}) {msg}",
        quiet,
    );
    let outcomes = pool.install(|| {
        dirs.par_iter()
            .map(|dir| {
                let result = measure_sample(dir, overrides, &|_| {})
                    .with_context(|| format!("measuring {}", dir.display()));
                done(dir, &result);
                bar.inc(1);
                if let Some(name) = dir.file_name() {
                    bar.set_message(name.to_string_lossy().into_owned());
                }
                Outcome {
                    dir: dir.clone(),
                    result,
                }
            })
            .collect::<Vec<_>>()
    });
    bar.finish_and_clear();
    Ok(outcomes)
}

/// Samples that failed, with why.
pub type Failures = Vec<(PathBuf, String)>;

/// One sample compared: (existing, proposed).
pub type Pair = (MeasurementResult, MeasurementResult);

/// What [`compare_dirs_exact`] gives.
pub struct Compared {
    /// The samples compared: (existing, proposed).
    pub pairs: Vec<Pair>,
    /// Each pair's folder.
    pub dirs: Vec<PathBuf>,
    /// Per pair, the exact fit (when asked for).
    pub exacts: Vec<Option<MeasurementResult>>,
    /// The samples that failed, with why.
    pub failed: Failures,
}

/// Measures `dirs` once and fits each both ways; writes compare.svg/png into each sample folder
/// (and, with `write_results`, the proposed measurement's result files as `measure` does, its
/// report.html with Figure 6). Returns the pairs, their folders and the samples that failed.
///
/// # Errors
/// Only when the worker threads cannot start.
pub fn compare_dirs(
    dirs: &[PathBuf],
    fit: &crate::common::FitArgs,
    jobs: usize,
    quiet: bool,
    write_results: bool,
) -> anyhow::Result<Compared> {
    compare_dirs_exact(dirs, fit, jobs, quiet, write_results, false)
}

/// [`compare_dirs`], and with `exact` each sample also fitted beyond the paper: the Monte Carlo
/// forward model with α′ from the Monte Carlo total (`None` where that fit cannot run).
///
/// # Errors
/// Only when the worker threads cannot start.
pub fn compare_dirs_exact(
    dirs: &[PathBuf],
    fit: &crate::common::FitArgs,
    jobs: usize,
    quiet: bool,
    write_results: bool,
    exact: bool,
) -> anyhow::Result<Compared> {
    let mut overrides = fit.overrides()?;
    overrides.method = Some(Method::Proposed);
    let outcomes = measure_many(dirs, &overrides, jobs, quiet, &|_, _| {})?;
    let mut pairs = Vec::new();
    let mut pair_dirs = Vec::new();
    let mut exacts = Vec::new();
    let mut failed = Vec::new();
    for o in outcomes {
        let proposed = match o.result {
            Ok(m) => m,
            Err(e) => {
                failed.push((o.dir, crate::common::error_text(&e)));
                continue;
            }
        };
        let existing = match proposed.refit(Method::Existing) {
            Ok(m) => m,
            Err(e) => {
                failed.push((o.dir, e.to_string()));
                continue;
            }
        };
        if write_results
            && let Err(e) =
                scatterfit_report::write_measurement_with(&o.dir, &proposed, Some(&existing))
        {
            let e = anyhow::Error::from(e);
            failed.push((o.dir.clone(), format!("writing the results: {e:#}")));
        }
        let name = proposed.manifest.display_name();
        let fig = scatterfit_report::compare_figure(&existing, &proposed, &name);
        if let Err(e) = scatterfit_report::write_figure(
            &fig,
            Some(&o.dir.join("compare.svg")),
            Some(&o.dir.join("compare.png")),
        ) {
            let e = anyhow::Error::from(e);
            failed.push((o.dir.clone(), format!("writing the plot: {e:#}")));
        }
        if exact {
            let settings = scatterfit_pipeline::fit::FitSettings {
                model: scatterfit_optics::ModelName::Mc,
                albedo_model: scatterfit_optics::AlbedoModel::Mc,
                ..proposed.settings
            };
            exacts.push(
                proposed
                    .refit_with(settings)
                    .ok()
                    .map(|m| m.to_result(Some("profile.csv"))),
            );
        }
        pairs.push((
            existing.to_result(Some("profile.csv")),
            proposed.to_result(Some("profile.csv")),
        ));
        pair_dirs.push(o.dir);
    }
    Ok(Compared {
        pairs,
        dirs: pair_dirs,
        exacts,
        failed,
    })
}
