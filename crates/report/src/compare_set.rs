//! Many sample folders fitted both ways, each sample's files written as soon as it is done
//! (`scatterfit compare`, the demo): the scheduling is [`scatterfit_pipeline::compare`]'s, the
//! files [`crate::write_comparison`]'s; this gathers the pairs of results (the paper's Table 2
//! rows) with their folders and the samples that failed, a failed sample never stopping the
//! others.

use std::path::PathBuf;

use scatterfit_io::result_json::MeasurementResult;
use scatterfit_pipeline::batch::{BatchError, BatchEvent, BatchRequest};
use scatterfit_pipeline::compare::compare_batch_with;
use scatterfit_pipeline::outputs::Failures;

use crate::error::chain_text_after;

/// One sample compared: (existing, proposed).
pub type Pair = (MeasurementResult, MeasurementResult);

/// What one sample's comparison gave: the pair, the paper's fit, the files that could not be
/// written; or why the sample failed.
type SampleOutcome = Result<(Pair, Option<MeasurementResult>, Vec<String>), String>;

/// What [`compare_dirs`] gives.
#[derive(Debug, Default)]
pub struct Comparison {
    /// The samples compared: (existing, proposed).
    pub pairs: Vec<Pair>,
    /// Each pair's folder.
    pub dirs: Vec<PathBuf>,
    /// Per pair, the paper's fit (the dipole, α′ from its total; empty without `paper`).
    pub papers: Vec<Option<MeasurementResult>>,
    /// The samples that failed, with why (`measuring DIR: …`), and the files that could not be
    /// written.
    pub failed: Failures,
}

/// Measures the folders of `request` once and fits each both ways
/// ([`scatterfit_pipeline::compare`]); writes compare.svg/png into each sample folder (and, with
/// `write_results`, the proposed measurement's result files as `measure` does, its report.html with
/// Figure 6; [`crate::write_comparison`]); with `paper` each sample is also fitted with the paper's
/// own model ([`scatterfit_pipeline::compare::paper_settings`]; `None` where that fit cannot run).
/// `on_event` sees the plan and each finished sample (a progress bar).
///
/// # Errors
/// Only when the worker threads cannot start.
pub fn compare_dirs(
    request: BatchRequest,
    write_results: bool,
    paper: bool,
    on_event: &(dyn Fn(BatchEvent<'_>) + Sync),
) -> Result<Comparison, BatchError> {
    let batch = compare_batch_with(
        request,
        paper,
        &|dir, compared| -> SampleOutcome {
            let c = compared
                .map_err(|e| chain_text_after(format!("measuring {}", dir.display()), &e))?;
            let problems = crate::write_comparison(dir, &c, write_results);
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
        on_event,
    )?;
    let mut out = Comparison::default();
    for s in batch.samples {
        match s.outcome {
            Ok((pair, paper_fit, problems)) => {
                out.failed
                    .extend(problems.into_iter().map(|p| (s.dir.clone(), p)));
                out.pairs.push(pair);
                out.dirs.push(s.dir);
                if paper {
                    out.papers.push(paper_fit);
                }
            }
            Err(e) => out.failed.push((s.dir, e)),
        }
    }
    Ok(out)
}
