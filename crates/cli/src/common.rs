//! Helpers shared by the subcommands: value parsers, progress bars, output-folder safety and the
//! exit-code classes.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};

use anyhow::bail;

/// A measurement that ran and failed (exit code 1), as opposed to bad input (2).
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct MeasurementFailed(pub String);

/// True when `err` (or a cause) is a failed measurement: exit 1.
pub fn is_measurement_failure(err: &anyhow::Error) -> bool {
    err.chain().any(|e| {
        e.is::<MeasurementFailed>()
            || e.downcast_ref::<scatterfit_pipeline::PipelineError>()
                .is_some_and(scatterfit_pipeline::PipelineError::is_measurement_failure)
    })
}

/// Parses `R,G,B` (three numbers).
pub fn parse_rgb(text: &str) -> Result<[f64; 3], String> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    let values: Vec<f64> = parts.iter().filter_map(|p| p.parse::<f64>().ok()).collect();
    match (parts.len(), values.as_slice()) {
        (3, &[r, g, b]) if [r, g, b].iter().all(|v| v.is_finite()) => Ok([r, g, b]),
        _ => Err(format!(
            "`{text}` is not three numbers R,G,B (e.g. 1.979,1.893,1.992)"
        )),
    }
}

/// A progress bar on stderr when it is a terminal and not `quiet`, else hidden.
pub fn bar(len: u64, template: &str, quiet: bool) -> indicatif::ProgressBar {
    if quiet || !std::io::stderr().is_terminal() {
        return indicatif::ProgressBar::hidden();
    }
    let bar = indicatif::ProgressBar::new(len);
    bar.set_style(
        indicatif::ProgressStyle::with_template(template)
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    bar
}

/// Refuses to write into `dir` when any of `files` already exists there, unless `force`.
///
/// # Errors
/// Names the first existing file and says how to proceed.
pub fn check_output_files(dir: &Path, files: &[String], force: bool) -> anyhow::Result<()> {
    if force {
        return Ok(());
    }
    if let Some(f) = files.iter().find(|f| dir.join(f).exists()) {
        bail!(
            "{} already exists; nothing was written — choose another folder or pass --force to \
             overwrite",
            dir.join(f).display()
        );
    }
    Ok(())
}

/// The cache folder for Monte Carlo results: `--cache-dir`, else the mc crate's default.
pub fn cache_dir(given: Option<&Path>) -> Option<PathBuf> {
    given
        .map(Path::to_path_buf)
        .or_else(scatterfit_mc::table::default_cache_dir)
}

/// `1/600` for short times that are whole fractions, else 4 significant digits.
pub fn shutter(t: f64) -> String {
    if t < 0.5 && t > 0.0 {
        let inv = 1.0 / t;
        if (inv - inv.round()).abs() < 1e-6 * inv {
            return format!("1/{}", inv.round());
        }
    }
    if (1e-3..1e4).contains(&t) {
        let decimals = (3 - t.log10().floor() as i32).max(0) as usize;
        format!("{t:.decimals$}")
    } else {
        format!("{t:.3e}")
    }
}
