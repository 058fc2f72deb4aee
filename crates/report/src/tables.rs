//! The summary tables of a command over many samples, written atomically into its output folder:
//! Table 1 (`summary.csv`, `summary.md`: one row per sample, the paper's Table 1) and Table 2
//! (`compare.csv`, `compare.md`: both methods per sample, its Table 2).

use std::path::Path;

use scatterfit_io::result_json::MeasurementResult;
use scatterfit_io::result_table::{table1_csv, table1_markdown, table2_csv, table2_markdown};

use crate::error::{ReportError, Result};

/// The files of [`write_table1`].
pub const TABLE1_FILES: [&str; 2] = ["summary.csv", "summary.md"];
/// The files of [`write_table2`].
pub const TABLE2_FILES: [&str; 2] = ["compare.csv", "compare.md"];

/// Writes `summary.csv` and `summary.md` (Table 1 of `results`) into `dir`.
///
/// # Errors
/// [`ReportError::Write`] naming the file.
pub fn write_table1(dir: &Path, results: &[MeasurementResult]) -> Result<()> {
    write_text(&dir.join(TABLE1_FILES[0]), &table1_csv(results))?;
    write_text(&dir.join(TABLE1_FILES[1]), &table1_markdown(results))
}

/// Writes `compare.csv` and `compare.md` (Table 2 of the (existing, proposed) `pairs`) into `dir`.
///
/// # Errors
/// [`ReportError::Write`] naming the file.
pub fn write_table2(dir: &Path, pairs: &[(MeasurementResult, MeasurementResult)]) -> Result<()> {
    write_text(&dir.join(TABLE2_FILES[0]), &table2_csv(pairs))?;
    write_text(&dir.join(TABLE2_FILES[1]), &table2_markdown(pairs))
}

/// Writes `text` to `path` atomically.
///
/// # Errors
/// [`ReportError::Write`] naming the file.
pub fn write_text(path: &Path, text: &str) -> Result<()> {
    scatterfit_io::atomic::write_atomic(path, text.as_bytes()).map_err(|source| {
        ReportError::Write {
            path: path.to_path_buf(),
            source,
        }
    })
}
