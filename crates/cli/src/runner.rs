//! Many sample folders with one progress bar (`batch`, `compare`, `demo`): the scheduling is the
//! library's ([`scatterfit_pipeline::batch`], [`scatterfit_pipeline::compare`]); this file turns
//! its events into the progress bar and its outcomes into the commands' error texts. A failed
//! sample never stops the others; each outcome is kept with its folder.

use std::path::{Path, PathBuf};

use anyhow::Context;
use indicatif::ProgressBar;
use scatterfit_io::result_json::MeasurementResult;
use scatterfit_pipeline::batch::{BatchEvent, BatchRequest, measure_batch_with};
use scatterfit_pipeline::compare::compare_batch_with;
use scatterfit_pipeline::outputs::Failures;
use scatterfit_pipeline::{Measurement, Overrides};

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

/// One sample compared: (existing, proposed).
pub type Pair = (MeasurementResult, MeasurementResult);

/// What one sample's comparison gave the command.
type Compared = Result<(Pair, Option<MeasurementResult>, Vec<String>), String>;

/// What [`compare_dirs`] gives.
pub struct Comparison {
    /// The samples compared: (existing, proposed).
    pub pairs: Vec<Pair>,
    /// Each pair's folder.
    pub dirs: Vec<PathBuf>,
    /// Per pair, the paper's fit (the dipole, α′ from its total; empty without `paper`).
    pub papers: Vec<Option<MeasurementResult>>,
    /// The samples that failed, with why.
    pub failed: Failures,
}

/// Measures `dirs` once and fits each both ways ([`scatterfit_pipeline::compare`]); writes
/// compare.svg/png into each sample folder (and, with `write_results`, the proposed measurement's
/// result files as `measure` does, its report.html with Figure 6); with `paper` each sample is also
/// fitted with the paper's own model ([`scatterfit_pipeline::compare::paper_settings`]; `None` where
/// that fit cannot run). Returns the pairs with their folders, the paper's fits (empty without
/// `paper`) and the samples that failed.
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
    let batch = compare_batch_with(
        request,
        paper,
        &|dir, compared| -> Compared {
            let c = compared.map_err(|e| {
                let e = anyhow::Error::from(e).context(format!("measuring {}", dir.display()));
                crate::common::error_text(&e)
            })?;
            let problems = scatterfit_report::write_comparison(dir, &c, write_results);
            let paper = c
                .paper
                .and_then(Result::ok)
                .map(|m| m.to_result(Some("profile.csv")));
            let pair = (
                c.existing.to_result(Some("profile.csv")),
                c.proposed.to_result(Some("profile.csv")),
            );
            Ok((pair, paper, problems))
        },
        &|e| on_event(e, &bar, quiet),
    )?;
    bar.finish_and_clear();
    let (mut pairs, mut papers, mut failed) = (Vec::new(), Vec::new(), Vec::new());
    let mut pair_dirs = Vec::new();
    for s in batch.samples {
        match s.outcome {
            Ok((pair, paper_fit, problems)) => {
                failed.extend(problems.into_iter().map(|p| (s.dir.clone(), p)));
                pairs.push(pair);
                pair_dirs.push(s.dir);
                if paper {
                    papers.push(paper_fit);
                }
            }
            Err(e) => failed.push((s.dir, e)),
        }
    }
    Ok(Comparison {
        pairs,
        dirs: pair_dirs,
        papers,
        failed,
    })
}
