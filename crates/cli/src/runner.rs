//! Measuring many sample folders in parallel with one progress bar (`batch`, `compare`, `demo`).
//! A failed sample never stops the others; each outcome is kept with its folder.

use std::path::{Path, PathBuf};

use anyhow::Context;
use rayon::prelude::*;
use scatterfit_io::manifest::MethodName;
use scatterfit_io::result_json::MeasurementResult;
use scatterfit_pipeline::{Measurement, Overrides, measure_sample};

/// One sample's outcome.
pub struct Outcome {
    /// The folder.
    pub dir: PathBuf,
    /// The measurement, or why there is none.
    pub result: anyhow::Result<Measurement>,
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

/// Measures `dirs` once and fits each both ways; writes compare.svg/png into each sample folder
/// (and, with `write_results`, the proposed measurement's result files as `measure` does).
/// Returns the pairs and the samples that failed.
///
/// # Errors
/// Only when the worker threads cannot start.
pub fn compare_dirs(
    dirs: &[PathBuf],
    fit: &crate::common::FitArgs,
    jobs: usize,
    quiet: bool,
    write_results: bool,
) -> anyhow::Result<(Vec<Pair>, Failures)> {
    let mut overrides = fit.overrides()?;
    overrides.method = Some(MethodName::Proposed);
    let outcomes = measure_many(dirs, &overrides, jobs, quiet, &|_, _| {})?;
    let mut pairs = Vec::new();
    let mut failed = Vec::new();
    for o in outcomes {
        let proposed = match o.result {
            Ok(m) => m,
            Err(e) => {
                failed.push((o.dir, crate::common::error_text(&e)));
                continue;
            }
        };
        let existing = match proposed.refit(MethodName::Existing) {
            Ok(m) => m,
            Err(e) => {
                failed.push((o.dir, e.to_string()));
                continue;
            }
        };
        if write_results && let Err(e) = crate::report::write_measurement(&o.dir, &proposed) {
            failed.push((o.dir.clone(), format!("writing the results: {e:#}")));
        }
        let name = proposed.manifest.display_name();
        let fig = crate::figures::compare_figure(&existing, &proposed, &name);
        if let Err(e) = crate::plot::write_figure(
            &fig,
            Some(&o.dir.join("compare.svg")),
            Some(&o.dir.join("compare.png")),
        ) {
            failed.push((o.dir.clone(), format!("writing the plot: {e:#}")));
        }
        pairs.push((
            existing.to_result(Some("profile.csv")),
            proposed.to_result(Some("profile.csv")),
        ));
    }
    Ok((pairs, failed))
}
