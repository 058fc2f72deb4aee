//! Many sample folders with one progress bar (`batch`, `compare`, `demo`): the scheduling is the
//! library's ([`scatterfit_pipeline::batch`], [`scatterfit_report::compare_set`]); this file turns
//! its events into the progress bar and its outcomes into the commands' error texts. A failed
//! sample never stops the others; each outcome is kept with its folder.

use std::path::{Path, PathBuf};

use anyhow::Context;
use indicatif::ProgressBar;
use scatterfit_pipeline::batch::{BatchEvent, BatchRequest, measure_batch_with};
use scatterfit_pipeline::{Measurement, Overrides};
use scatterfit_report::compare_set::compare_dirs as compare_dirs_with;

/// One sample's outcome.
pub struct Outcome {
    /// The folder.
    pub dir: PathBuf,
    /// The measurement, or why there is none.
    pub result: anyhow::Result<Measurement>,
}

/// The progress bar's view of a batch: the plan (a note on stderr when the memory budget runs
/// fewer samples at once than asked) and each finished sample.
fn on_event(event: BatchEvent<'_>, bar: &ProgressBar, quiet: bool) {
    match event {
        BatchEvent::Started(plan) if plan.reduced() && !quiet => crate::output::errln!(
            "note: measuring {} sample(s) at a time instead of {}: {} of these samples would \
             need about {} of memory, more than the budget of {} ({}=<MiB> raises it)",
            plan.jobs,
            plan.requested,
            plan.requested,
            scatterfit_io::budget::describe_bytes(plan.memory_needed),
            scatterfit_io::budget::describe_bytes(plan.memory_budget),
            scatterfit_io::budget::MEMORY_BUDGET_ENV
        ),
        BatchEvent::Finished { dir, .. } => {
            bar.inc(1);
            if let Some(name) = dir.file_name() {
                bar.set_message(name.to_string_lossy().into_owned());
            }
        }
        _ => {}
    }
}

fn progress(len: usize, quiet: bool) -> ProgressBar {
    crate::common::bar(
        len as u64,
        "measuring {bar:30} {pos}/{len} samples {elapsed} (eta {eta}) {msg}",
        quiet,
    )
}

/// Measures every folder of `dirs` with `jobs` samples at a time (0: one per core, fewer when the
/// memory budget says so), calling `done` for each as soon as it is finished (from a worker
/// thread) so results can be written before the others end.
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
    let bar = progress(dirs.len(), quiet);
    let request = BatchRequest::new(dirs.iter().cloned(), *overrides).jobs(jobs);
    let batch = measure_batch_with(
        request,
        &|dir, measured| {
            let result = measured
                .map_err(anyhow::Error::from)
                .with_context(|| format!("measuring {}", dir.display()));
            done(dir, &result);
            result
        },
        &|e| on_event(e, &bar, quiet),
    )?;
    bar.finish_and_clear();
    Ok(batch
        .samples
        .into_iter()
        .map(|s| Outcome {
            dir: s.dir,
            result: s.outcome,
        })
        .collect())
}

pub use scatterfit_report::compare_set::Comparison;

/// Measures `dirs` once and fits each both ways, with the progress bar
/// ([`scatterfit_report::compare_set::compare_dirs`]: its files, the paper's fits with `paper`).
///
/// # Errors
/// Only when the worker threads cannot start.
pub fn compare_dirs(
    dirs: &[PathBuf],
    overrides: &Overrides,
    jobs: usize,
    quiet: bool,
    write_results: bool,
    paper: bool,
) -> anyhow::Result<Comparison> {
    let bar = progress(dirs.len(), quiet);
    let request = BatchRequest::new(dirs.iter().cloned(), *overrides).jobs(jobs);
    let comparison = compare_dirs_with(request, write_results, paper, &|e| {
        on_event(e, &bar, quiet);
    })?;
    bar.finish_and_clear();
    Ok(comparison)
}
