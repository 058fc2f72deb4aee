//! The flags of a run over many sample folders (`scatterfit batch`, `compare`, and `-j` of the
//! demo and the study): the folders, how many samples are measured at once
//! (`jobs` of [`crate::batch::BatchRequest`], within the memory budget) and `--force`.

use std::path::PathBuf;

use scatterfit_io::flags::{FlagError, parse_size};

/// The sample folders of `batch` and `compare`, and how many are measured at once.
#[derive(Debug, Clone, Default)]
#[cfg_attr(feature = "clap", derive(clap::Args))]
pub struct SamplesArgs {
    /// Sample folders (each with a sample.toml), or folders holding sample folders.
    #[cfg_attr(feature = "clap", arg(required = true))]
    pub dirs: Vec<PathBuf>,
    /// How many are measured at once.
    #[cfg_attr(feature = "clap", command(flatten))]
    pub jobs: JobsArgs,
    /// Write -o into another sample's folder, and replace files there or in the sample folders
    /// that scatterfit did not write (its ledger, .scatterfit-written.json, does not list them);
    /// for `batch`, also measure every sample again, even one whose result files match its inputs
    /// (by default such a sample's result is reused: its result set complete, its inputs' SHA-256
    /// and the options given as result.json records them), and with --shard redo a shard whose
    /// partial file is there.
    #[cfg_attr(feature = "clap", arg(long))]
    pub force: bool,
}

/// How many samples are measured at once (`batch`, `compare`, `demo`, `study`).
#[derive(Debug, Clone, Default)]
#[cfg_attr(feature = "clap", derive(clap::Args))]
pub struct JobsArgs {
    /// Samples measured at once, 1 to 256 (`None`: one per core, within the memory budget).
    #[cfg_attr(feature = "clap", arg(short = 'j', long, value_name = "N", value_parser = parse_jobs, help = JOBS_HELP))]
    pub jobs: Option<usize>,
}

impl JobsArgs {
    /// The count asked for; 0 for the default (one per core, fewer when the memory budget says so).
    pub fn count(&self) -> usize {
        self.jobs.unwrap_or(0)
    }
}

/// Samples measured at once \[1, 256\] (`-j`): the help text shared by `batch`, `compare`, `demo`,
/// `study`.
pub const JOBS_HELP: &str = "Samples measured at the same time: a count, 1 to 256 (default: one \
     per core). Fewer are run at once when that many would not fit the memory budget \
     ($SCATTERFIT_MAX_MEMORY_MIB, default half of this machine's memory; each sample holds its decoded bracket and \
     radiance map); a note on stderr says so";

/// Parses `-j`: a count in 1..=256.
///
/// # Errors
/// Not a count, or outside 1..=256.
pub fn parse_jobs(text: &str) -> Result<usize, FlagError> {
    match parse_size(text)? {
        n @ 1..=256 => Ok(n),
        n => Err(FlagError(format!(
            "{n} samples at once: give 1 to 256 (each holds a whole bracket in memory)"
        ))),
    }
}
