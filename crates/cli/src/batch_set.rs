//! A batch's results as one set: the samples of `scatterfit batch` (measured now or reused) and
//! the summary, index and failure list made of them — by `batch` itself, and by `scatterfit combine`
//! from the partial files of `batch --shard K/N`.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use scatterfit_io::result_json::MeasurementResult;
use serde::{Deserialize, Serialize};

use crate::output::{out, outln};

/// One sample of a batch: its place in the sorted list, and its result or why it has none.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Entry {
    /// Index in the batch's sorted sample list (misspelt folders after the rest).
    pub index: usize,
    /// The sample folder.
    pub dir: PathBuf,
    /// Its result (measured now or reused).
    pub result: Option<MeasurementResult>,
    /// Why it is not measured completely with every check ok (None: it is).
    pub failure: Option<String>,
    /// Whether the result was reused (it matched its inputs), not measured now.
    pub reused: bool,
}

/// Why a result is not a complete, trusted measurement (None: it is).
pub fn failure_of(r: &MeasurementResult) -> Option<String> {
    let why: Vec<String> = r
        .channels
        .iter()
        .filter_map(|c| c.problem.clone())
        .collect();
    if !why.is_empty() {
        Some(why.join("; "))
    } else if !scatterfit_report::trusted(r) {
        Some(scatterfit_report::suspect_text(r))
    } else {
        None
    }
}

/// The combined shards of `scatterfit batch --shard` (`scatterfit combine`): the summary and index
/// of every sample into `output_dir`.
///
/// # Errors
/// A damaged partial file, or the summary's files cannot be written.
pub fn combine(output_dir: &Path, partials: &[PathBuf], json: bool) -> anyhow::Result<ExitCode> {
    crate::common::check_output_dir(output_dir, "-o")?;
    let mut entries: Vec<Entry> = Vec::new();
    for path in partials {
        entries.extend(crate::shard::read::<Vec<Entry>>(path)?.data);
    }
    entries.sort_by_key(|e| e.index);
    summarise(output_dir, &entries, json)
}

/// Writes summary.csv, summary.md and index.html for `entries` into `output_dir`, prints the
/// results, lists the failures; exit 1 if any.
pub fn summarise(output_dir: &Path, entries: &[Entry], json: bool) -> anyhow::Result<ExitCode> {
    let mut results: Vec<MeasurementResult> = Vec::new();
    let mut result_dirs: Vec<PathBuf> = Vec::new();
    let mut failed: Vec<(PathBuf, String)> = Vec::new();
    let mut not_measured: Vec<(PathBuf, String)> = Vec::new();
    for e in entries {
        if let Some(why) = &e.failure {
            failed.push((e.dir.clone(), why.clone()));
        }
        match &e.result {
            Some(r) => {
                results.push(r.clone());
                result_dirs.push(e.dir.clone());
            }
            None => not_measured.push((e.dir.clone(), e.failure.clone().unwrap_or_default())),
        }
    }
    let samples = entries.len();
    let args_output_dir = output_dir;
    std::fs::create_dir_all(args_output_dir)?;
    scatterfit_report::write_table1(args_output_dir, &results)?;
    let index = scatterfit_report::html::write_results_index(
        args_output_dir,
        "scatterfit batch",
        "One row per sample: its verdict (the data checks per channel), η, σ′s and σa per channel; \
         the sample's name opens its report.",
        &results,
        &result_dirs,
        &not_measured,
        &scatterfit_report::tables::TABLE1_FILES,
    )?;
    if json {
        crate::output::print_json(&results)?;
    } else {
        for r in &results {
            out!("{}", scatterfit_report::summary_text(r))?;
        }
        outln!(
            "\n{} of {} samples measured completely with every check ok; summary: {} and {}",
            samples - failed.len(),
            samples,
            args_output_dir.join("summary.csv").display(),
            args_output_dir.join("summary.md").display()
        )?;
        outln!("index: {}", index.display())?;
    }
    Ok(crate::common::list_failures(
        "failed, are incomplete or suspect",
        &failed,
    ))
}
