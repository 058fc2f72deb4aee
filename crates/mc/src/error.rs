//! Errors of the Monte Carlo crate.

use std::path::PathBuf;

/// What went wrong while configuring or running a simulation, or reading a table.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum McError {
    /// A physical or numerical parameter is outside its domain.
    #[error("invalid parameter {name} = {}: {reason}", short_number(*value))]
    InvalidParameter {
        /// The parameter's name as the API spells it, e.g. `sigma_a`.
        name: &'static str,
        /// The offending value.
        value: f64,
        /// What the domain is, and what to do.
        reason: &'static str,
    },
    /// The simulation would never finish: photon paths without a finite mean length.
    #[error("{what}; {hint}")]
    NeverEnds {
        /// What cannot terminate.
        what: &'static str,
        /// What to do instead.
        hint: &'static str,
    },
    /// A Henyey–Greenstein g that the (η, g) grid of tables neither holds nor interpolates
    /// ([`crate::McGridSet`]).
    #[error(
        "g = {given} is not covered by the Monte Carlo tables: they hold {tabulated}; use a g \
         they cover (a g above the last node is not extrapolated: the nearest node is the closest \
         the tool can model), or add tables at this g to the build (`cargo run --release -p \
         scatterfit-mc --example build_g_tables -- --out DIR --g {given}`, then listed in \
         crates/mc/src/bundled.rs and the tool rebuilt: crates/mc/tables-g/README.md)"
    )]
    AnisotropyNotTabulated {
        /// The g asked for.
        given: f64,
        /// What the grid covers, in words.
        tabulated: String,
    },
    /// η lies outside the tables of a g node the query needs (the nodes at g ≠ 0 span a
    /// narrower η range than g = 0's).
    #[error(
        "η = {eta:.4} at g = {g}: the Monte Carlo tables at g = {node} cover η {min}–{max} only \
         (the whole grid: {tabulated}); at this η give a g the tables cover, or use a diffusion \
         model (`--model dipole`), which does not depend on g"
    )]
    EtaNotTabulatedAtG {
        /// The η asked for.
        eta: f64,
        /// The g asked for.
        g: f64,
        /// The g node whose tables do not reach η.
        node: f64,
        /// That node's lowest η.
        min: f64,
        /// That node's highest η.
        max: f64,
        /// What the grid covers, in words.
        tabulated: String,
    },
    /// A query falls outside what a profile table covers.
    #[error("{name} = {value} is outside the table's range [{min}, {max}]")]
    OutOfTable {
        /// Which coordinate, e.g. `albedo_prime`.
        name: &'static str,
        /// The requested value.
        value: f64,
        /// The table's lower limit.
        min: f64,
        /// The table's upper limit.
        max: f64,
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
        Err(McError::InvalidParameter {
            name,
            value,
            reason,
        })
    }
}

/// A number for messages: as written for ordinary magnitudes, in scientific notation beyond them
/// (Display writes 1e300 as 301 digits).
fn short_number(v: f64) -> String {
    if v == 0.0 || !v.is_finite() || (1e-4..1e9).contains(&v.abs()) {
        format!("{v}")
    } else {
        format!("{v:.4e}")
    }
}
