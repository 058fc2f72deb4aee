//! Helpers shared by the subcommands: value parsers, progress bars, output-folder safety and the
//! exit-code classes.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};

/// A measurement that ran and failed (exit code 1), as opposed to bad input (2).
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct MeasurementFailed(pub String);

/// True when `err` (or a cause) is a failed measurement: exit 1. The classes: the CLI's
/// [`MeasurementFailed`], [`scatterfit_pipeline::PipelineError::is_measurement_failure`] (every
/// command that runs a pipeline stage) and [`scatterfit_imaging::ImagingError::is_failed_measurement`]
/// (an imaging error anywhere in the chain, e.g. the source of a pipeline error: an all-saturated
/// bracket, exposure times in the wrong order). Everything else is bad usage or input (exit 2).
pub fn is_measurement_failure(err: &anyhow::Error) -> bool {
    err.chain().any(|e| {
        e.is::<MeasurementFailed>()
            || e.downcast_ref::<scatterfit_pipeline::PipelineError>()
                .is_some_and(scatterfit_pipeline::PipelineError::is_measurement_failure)
            || e.downcast_ref::<scatterfit_imaging::ImagingError>()
                .is_some_and(scatterfit_imaging::ImagingError::is_failed_measurement)
    })
}

/// The error and its causes joined by ": ", skipping a cause whose text the message already holds
/// (many library errors name their source in their own message, and `{:#}` would repeat it).
pub fn error_text(err: &anyhow::Error) -> String {
    scatterfit_report::error::error_text(err.as_ref())
}

pub use scatterfit_io::flags::parse_rgb;

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

/// Progress for a log: when stderr is not a terminal (piped, redirected, a batch job) a progress
/// bar is hidden, so a long run would say nothing for minutes; then a status line is printed at
/// the first update and at most once per [`StatusLines::EVERY`] after. Nothing when `quiet` or on
/// a terminal (the bar shows there).
#[derive(Debug)]
pub struct StatusLines {
    on: bool,
    start: std::time::Instant,
    last: std::sync::Mutex<Option<std::time::Instant>>,
}

impl StatusLines {
    /// Seconds between status lines.
    pub const EVERY: std::time::Duration = std::time::Duration::from_secs(5);

    /// Status lines unless `quiet` or stderr is a terminal.
    pub fn new(quiet: bool) -> Self {
        Self {
            on: !quiet && !std::io::stderr().is_terminal(),
            start: std::time::Instant::now(),
            last: std::sync::Mutex::new(None),
        }
    }

    /// Prints `line()` with the elapsed time when the last line is at least [`Self::EVERY`] old.
    pub fn update(&self, line: impl FnOnce() -> String) {
        if !self.on {
            return;
        }
        let Ok(mut last) = self.last.lock() else {
            return;
        };
        let now = std::time::Instant::now();
        if last.is_some_and(|t| now.duration_since(t) < Self::EVERY) {
            return;
        }
        *last = Some(now);
        crate::output::errln!(
            "{} ({:.0} s)",
            line(),
            now.duration_since(self.start).as_secs_f64()
        );
    }
}

/// The progress bar of a Monte Carlo run (`simulate`, `table`).
pub const PHOTONS_BAR: &str = "{bar:40} {human_pos}/{human_len} photons  {per_sec}  ETA {eta}";

/// The cache folder for Monte Carlo results: `--cache-dir`, else the mc crate's default. (Its
/// writes go through `scatterfit-safefs` like every other, so Ctrl-C removes their temporaries.)
pub use scatterfit_mc::cache::cache_dir_or_default as cache_dir;

pub use scatterfit_pipeline::fit_args::FitArgs;

pub use scatterfit_pipeline::batch_args::{JobsArgs, SamplesArgs};

/// The Monte Carlo profile cache of the rig twin (`synth`, `demo`).
#[derive(Debug, Clone, clap::Args)]
pub struct CacheArgs {
    /// Folder for cached Monte Carlo profiles (default: $SCATTERFIT_CACHE, the XDG cache, ~/.cache).
    #[arg(long, value_name = "DIR")]
    pub cache_dir: Option<PathBuf>,
}

impl CacheArgs {
    /// The cache folder: the flag's, else the default ([`cache_dir`]).
    pub fn dir(&self) -> Option<PathBuf> {
        cache_dir(self.cache_dir.as_deref())
    }
}

pub use scatterfit_pipeline::outputs::{
    Failures, Format, RESULT_FILES, check_destination, check_new_output, check_output_dir,
    check_output_file, check_output_files, refuse_foreign_folder, refuse_foreign_results,
    refuse_outputs_that_are_inputs, refuse_overwrite,
};

/// The sample folders of a command over many samples (`batch`, `compare`), found and checked before
/// any work ([`scatterfit_pipeline::outputs::check_samples`]): each folder once (other spellings of
/// it — `a`, `./a`, `a/`, a link — noted on stderr unless `quiet`), folders whose manifest is
/// misspelt returned as failures to report.
///
/// # Errors
/// An output that is an input, or a link at an output's name; `out_dir` being another sample's
/// folder (unless `force`).
#[allow(clippy::too_many_arguments)]
pub fn samples_for(
    command: &str,
    dirs: &[PathBuf],
    per_sample: &[&str],
    shared: &[PathBuf],
    out_dir: &Path,
    force: bool,
    allow_outside: bool,
    quiet: bool,
) -> anyhow::Result<(Vec<PathBuf>, Failures)> {
    let found = scatterfit_pipeline::outputs::check_samples(
        command,
        dirs,
        per_sample,
        shared,
        allow_outside,
    )?;
    refuse_foreign_folder(out_dir, &found.dirs, force)?;
    if !quiet {
        for (path, kept) in &found.duplicates {
            crate::output::errln!(
                "note: {} is the same folder as {}; measured once",
                path.display(),
                kept.display()
            );
        }
    }
    Ok((found.dirs, found.misspelt))
}

/// Lists the samples of `failed` with why on stderr under `{n} sample(s) {what}:` and returns exit
/// code 1; exit 0 when there are none.
pub fn list_failures(what: &str, failed: &[(PathBuf, String)]) -> std::process::ExitCode {
    if failed.is_empty() {
        return std::process::ExitCode::SUCCESS;
    }
    crate::output::errln!("\n{} sample(s) {what}:", failed.len());
    for (dir, why) in failed {
        crate::output::errln!("  {}: {why}", dir.display());
    }
    std::process::ExitCode::from(1)
}

/// Downstream honesty: for a result whose data checks did not pass every channel, a warning on
/// stderr (always: `--quiet` silences progress, not this) and exit 1, unless `allow_suspect` (then
/// the warning and exit 0). Exit 0 for a trusted result.
pub fn suspect_exit(
    file: &Path,
    result: &scatterfit_io::result_json::MeasurementResult,
    allow_suspect: bool,
) -> std::process::ExitCode {
    let Some(why) = result.untrusted() else {
        return std::process::ExitCode::SUCCESS;
    };
    crate::output::errln!(
        "warning: {}: not every channel passed the measurement's data checks ({why}); the numbers \
         are not trusted{}",
        file.display(),
        if allow_suspect {
            ""
        } else {
            " — exit 1; pass --allow-suspect to use them anyway"
        }
    );
    if allow_suspect {
        std::process::ExitCode::SUCCESS
    } else {
        std::process::ExitCode::from(1)
    }
}
