//! A batch's results as one set: the samples of `scatterfit batch` (measured now or reused) and
//! the summary, index and failure list made of them (`scatterfit_report::batch_set`) — by `batch`
//! itself, and by `scatterfit combine` from the partial files of `batch --shard K/N`.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

pub use scatterfit_report::batch_set::BatchEntry as Entry;
use scatterfit_report::batch_set::{BatchSummary, write_batch_summary};

use crate::output::{out, outln};

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
    std::fs::create_dir_all(output_dir)?;
    let BatchSummary {
        results,
        failed,
        index,
    } = write_batch_summary(output_dir, entries)?;
    let samples = entries.len();
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
            output_dir.join("summary.csv").display(),
            output_dir.join("summary.md").display()
        )?;
        outln!("index: {}", index.display())?;
    }
    Ok(crate::common::list_failures(
        "failed, are incomplete or suspect",
        &failed,
    ))
}
