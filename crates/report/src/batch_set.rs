//! A batch's results as one set (`scatterfit batch`, and `scatterfit combine` of its shards): each
//! sample's entry ([`BatchEntry`], also a shard's partial data), why a result is not a complete,
//! trusted measurement ([`failure_of`]), and the summary files made of the entries
//! ([`write_batch_summary`]: Table 1 and the index page); which samples are measured and which
//! reused ([`plan_batch`]).

use std::path::{Path, PathBuf};

use scatterfit_io::result_json::MeasurementResult;
use serde::{Deserialize, Serialize};

use crate::Result;

/// One sample of a batch: its place in the sorted list, and its result or why it has none.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct BatchEntry {
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

impl BatchEntry {
    /// A sample with its result (measured now, or `reused`); its failure is [`failure_of`] it.
    pub fn with_result(
        index: usize,
        dir: PathBuf,
        result: MeasurementResult,
        reused: bool,
    ) -> Self {
        Self {
            index,
            dir,
            failure: failure_of(&result),
            result: Some(result),
            reused,
        }
    }

    /// A sample without a result, and why.
    pub fn failed(index: usize, dir: PathBuf, why: String) -> Self {
        Self {
            index,
            dir,
            result: None,
            failure: Some(why),
            reused: false,
        }
    }
}

/// A batch's samples before any is measured ([`plan_batch`]).
#[derive(Debug, Default)]
pub struct BatchPlan {
    /// The samples that are not measured: reused results, misspelt folders.
    pub entries: Vec<BatchEntry>,
    /// The samples to measure: (index, folder).
    pub todo: Vec<(usize, PathBuf)>,
}

/// Sorts a batch's samples — `dirs` (indices 0…), then the `misspelt` folders with why (numbered
/// after them), only those `owned` (all, or a shard's) — into entries and work: a sample whose
/// result files match its inputs and `overrides` is reused unless `force`
/// ([`scatterfit_pipeline::reuse::reusable_result`]), a misspelt folder is an entry with why, the
/// others are to be measured.
pub fn plan_batch(
    dirs: &[PathBuf],
    misspelt: &[(PathBuf, String)],
    overrides: &scatterfit_pipeline::Overrides,
    force: bool,
    owned: &dyn Fn(usize) -> bool,
) -> BatchPlan {
    let mut plan = BatchPlan::default();
    for (i, dir) in dirs.iter().enumerate().filter(|(i, _)| owned(*i)) {
        match (!force)
            .then(|| scatterfit_pipeline::reuse::reusable_result(dir, overrides))
            .flatten()
        {
            Some(r) => plan
                .entries
                .push(BatchEntry::with_result(i, dir.clone(), r, true)),
            None => plan.todo.push((i, dir.clone())),
        }
    }
    for (j, (dir, why)) in misspelt.iter().enumerate() {
        if owned(dirs.len() + j) {
            let entry = BatchEntry::failed(dirs.len() + j, dir.clone(), why.clone());
            plan.entries.push(entry);
        }
    }
    plan
}

/// Why a result is not a complete, trusted measurement (None: it is): its channels' problems, else
/// the data checks' suspect channels.
pub fn failure_of(r: &MeasurementResult) -> Option<String> {
    let why: Vec<String> = r
        .channels
        .iter()
        .filter_map(|c| c.problem.clone())
        .collect();
    if !why.is_empty() {
        Some(why.join("; "))
    } else if !crate::trusted(r) {
        Some(crate::suspect_text(r))
    } else {
        None
    }
}

/// What [`write_batch_summary`] made.
#[derive(Debug)]
pub struct BatchSummary {
    /// The results, in the entries' order.
    pub results: Vec<MeasurementResult>,
    /// The samples that failed, are incomplete or suspect, with why.
    pub failed: Vec<(PathBuf, String)>,
    /// The index page.
    pub index: PathBuf,
}

/// Writes summary.csv and summary.md (Table 1) and index.html for `entries` into `dir` (which must
/// exist); a sample without a result is listed on the page with why.
///
/// # Errors
/// A file cannot be written.
pub fn write_batch_summary(dir: &Path, entries: &[BatchEntry]) -> Result<BatchSummary> {
    let mut results = Vec::new();
    let mut result_dirs = Vec::new();
    let mut failed = Vec::new();
    let mut not_measured = Vec::new();
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
    crate::write_table1(dir, &results)?;
    let index = crate::html::write_results_index(
        dir,
        "scatterfit batch",
        "One row per sample: its verdict (the data checks per channel), η, σ′s and σa per channel; \
         the sample's name opens its report.",
        &results,
        &result_dirs,
        &not_measured,
        &crate::tables::TABLE1_FILES,
    )?;
    Ok(BatchSummary {
        results,
        failed,
        index,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn samples_without_a_result_are_failures_on_the_index() {
        let dir = tempfile::tempdir().unwrap();
        let entries = [BatchEntry {
            index: 0,
            dir: dir.path().join("sulfur"),
            result: None,
            failure: Some("no sample.toml".into()),
            reused: false,
        }];
        let s = write_batch_summary(dir.path(), &entries).unwrap();
        assert!(s.results.is_empty());
        assert_eq!(
            s.failed,
            [(dir.path().join("sulfur"), "no sample.toml".to_owned())]
        );
        for f in crate::tables::TABLE1_FILES {
            assert!(dir.path().join(f).is_file(), "{f}");
        }
        let page = std::fs::read_to_string(&s.index).unwrap();
        assert!(page.contains("no sample.toml"), "{page}");
    }
}
