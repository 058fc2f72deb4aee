//! Table files: the cache folder ([`default_cache_dir`]), JSON read and written atomically, and the
//! cache rule — reuse a file only when it was made with the same spec (and format), else simulate
//! and save ([`CacheStatus`] says which happened).

use std::path::{Path, PathBuf};

use serde::Serialize;

use crate::error::{McError, Result};

/// How a `load_or_build` obtained its table.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum CacheStatus {
    /// Read from a cache file made with the same spec and format.
    Loaded,
    /// Simulated and written to the cache (no usable file was there).
    Built,
}

/// The cache folder a user gave (`--cache-dir`), else [`default_cache_dir`].
pub fn cache_dir_or_default(given: Option<&std::path::Path>) -> Option<PathBuf> {
    given
        .map(std::path::Path::to_path_buf)
        .or_else(default_cache_dir)
}

/// The cache folder: `$SCATTERFIT_CACHE`, else `$XDG_CACHE_HOME/scatterfit`, else
/// `$HOME/.cache/scatterfit`; `None` when none of these is set.
pub fn default_cache_dir() -> Option<PathBuf> {
    let var = |k| {
        std::env::var_os(k)
            .filter(|v| !v.is_empty())
            .map(PathBuf::from)
    };
    var("SCATTERFIT_CACHE")
        .or_else(|| var("XDG_CACHE_HOME").map(|p| p.join("scatterfit")))
        .or_else(|| var("HOME").map(|p| p.join(".cache").join("scatterfit")))
}

/// The text of `path`, parsed by `parse` (a table's own JSON reader, which validates).
///
/// # Errors
/// `Io` when the file cannot be read, `Format` (with the parser's message) when it does not parse.
pub(crate) fn read_with<T>(
    path: &Path,
    parse: impl FnOnce(&str) -> std::result::Result<T, String>,
) -> Result<T> {
    let text =
        scatterfit_safefs::read::read_to_string_limited(path, scatterfit_safefs::MAX_TEXT_BYTES)
            .map_err(|source| McError::Io {
                path: path.to_owned(),
                source,
            })?;
    parse(&text).map_err(|message| McError::Format {
        path: path.to_owned(),
        message,
    })
}

/// `value` as JSON at `path`, atomically ([`write_atomic`]).
///
/// # Errors
/// `Format` if it cannot be serialised, `Io` on any file-system error (the target is then untouched).
pub(crate) fn save_json<T: Serialize>(value: &T, path: &Path) -> Result<()> {
    let json = serde_json::to_vec(value).map_err(|e| McError::Format {
        path: path.to_owned(),
        message: e.to_string(),
    })?;
    write_atomic(path, &json)
}

/// The cache rule: the table at `path` when `load` reads it and `matches` accepts it (same spec),
/// else `build`, saved at `path` by `save`.
///
/// # Errors
/// As `build`, or `save`'s when the cache cannot be written.
pub(crate) fn load_or_build<T>(
    path: PathBuf,
    load: impl FnOnce(&Path) -> Result<T>,
    matches: impl FnOnce(&T) -> bool,
    build: impl FnOnce() -> Result<T>,
    save: impl FnOnce(&T, &Path) -> Result<()>,
) -> Result<(T, CacheStatus, PathBuf)> {
    if let Ok(table) = load(&path)
        && matches(&table)
    {
        return Ok((table, CacheStatus::Loaded, path));
    }
    // A cache that cannot take the file fails now, not after the Monte Carlo work.
    prepare_write(&path)?;
    let table = build()?;
    save(&table, &path)?;
    Ok((table, CacheStatus::Built, path))
}

/// Checks, before a cache file is computed, that it can be written at `path`: its folder exists (it
/// is created) and takes a new file, and what is at `path` (if anything) is a regular file, not a
/// link, a folder or a device. A corrupt file is no obstacle: it is replaced.
///
/// # Errors
/// [`McError::Cache`] naming the file.
pub fn prepare_write(path: &Path) -> Result<()> {
    let cache = |source| McError::Cache {
        path: path.to_owned(),
        source,
    };
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    std::fs::create_dir_all(dir).map_err(cache)?;
    scatterfit_safefs::write::check_destination(path).map_err(cache)?;
    scatterfit_safefs::write::check_can_write_in(dir).map_err(cache)
}

/// Writes `bytes` to `path` atomically, creating its folder if missing: through
/// `scatterfit_safefs::write::write_atomic` (an exclusively created temporary with an unpredictable
/// name, registered for Ctrl-C, renamed over a regular file or nothing — never through a link). mc
/// does not depend on io, whose `write_atomic` is the same function; synth's profile cache uses this
/// one.
///
/// # Errors
/// `Io` when the folder cannot be created, `Cache` when the file cannot be written (the target is
/// then untouched).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let io = |source| McError::Io {
        path: path.to_owned(),
        source,
    };
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    std::fs::create_dir_all(dir).map_err(io)?;
    scatterfit_safefs::write::write_atomic(path, bytes).map_err(|source| McError::Cache {
        path: path.to_owned(),
        source,
    })
}
