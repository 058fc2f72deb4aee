//! Errors of the Monte Carlo crate.

use std::path::PathBuf;

/// What went wrong while configuring or running a simulation, or reading a table.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum McError {
    /// A parameter outside its domain, or outside what the tables cover (η, α′, g): the optics
    /// vocabulary's error, which every forward model answers with (no copy of its variants here).
    #[error(transparent)]
    Optics(#[from] scatterfit_optics::OpticsError),
    /// The simulation would never finish: photon paths without a finite mean length.
    #[error("{what}; {hint}")]
    NeverEnds {
        /// What cannot terminate.
        what: &'static str,
        /// What to do instead.
        hint: &'static str,
    },
    /// A Monte Carlo table could not be smoothed into a model.
    #[error("cannot smooth the Monte Carlo table at albedo {albedo}: {reason}")]
    Smoothing {
        /// The albedo row concerned.
        albedo: f64,
        /// Why, and what to do.
        reason: &'static str,
    },
    /// Reading or writing a cache file failed.
    #[error("{path}: {source}")]
    Io {
        /// The file or folder involved.
        path: PathBuf,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
    /// The cache cannot take a new file (found before the Monte Carlo work, or when saving).
    #[error(
        "cannot write the cache file {}: {source}; choose a writable cache folder (--cache-dir or \
         SCATTERFIT_CACHE), or remove what is at that name",
        path.display()
    )]
    Cache {
        /// The cache file.
        path: PathBuf,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
    /// A cache file could not be parsed or serialised.
    #[error("{path}: not a valid table file: {message}")]
    Format {
        /// The file involved.
        path: PathBuf,
        /// What was wrong.
        message: String,
    },
    /// Shards of a run that do not add up to the run (another spec, a shard missing or twice).
    #[error("the shards do not make one run: {message}")]
    Shards {
        /// What is wrong, naming the shard.
        message: String,
    },
    /// The tables compiled into the crate do not load (a build defect, not the user's).
    #[error(
        "the Monte Carlo tables shipped with scatterfit do not load: {0}; this is a defect of the \
         build: choose another model (--model dipole) and report it"
    )]
    BundledTables(String),
}

/// Result type of this crate.
pub type Result<T> = std::result::Result<T, McError>;

/// Returns `Err(InvalidParameter)` unless `ok`.
pub(crate) fn check(ok: bool, name: &'static str, value: f64, reason: &'static str) -> Result<()> {
    if ok {
        Ok(())
    } else {
        Err(McError::Optics(
            scatterfit_optics::OpticsError::InvalidParameter {
                name,
                value,
                reason,
            },
        ))
    }
}

/// A query outside what a table covers (`OpticsError::OutOfTable`, as the crate returns it).
pub(crate) fn out_of_table(name: &'static str, value: f64, min: f64, max: f64) -> McError {
    McError::Optics(scatterfit_optics::OpticsError::OutOfTable {
        name,
        value,
        min,
        max,
    })
}
