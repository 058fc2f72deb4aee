//! Atomic file output: every file scatterfit writes goes through here (or, in the crates below io,
//! through the same functions of `scatterfit-safefs`, which this module re-exports).
//!
//! A write goes to an exclusively created temporary with an unpredictable name in the target's
//! folder (`.scatterfit-tmp-<random>-<name>`), locked while in flight, synced, and renamed over the
//! target; a target that is a symbolic link, a folder or anything but a regular file is refused, and
//! the rename never follows a link. A reader (or a crash) never sees a half-written result, and an
//! existing file is replaced in one step.
//!
//! Temporary files in flight are kept in a process-wide registry shared with the Monte Carlo and
//! synth caches, so that nothing is left behind: a failed write removes its own, and
//! [`remove_in_flight`] (what the command-line tool calls on Ctrl-C, before it exits) removes every
//! one still open and refuses new ones. Temporaries of a run that was killed (SIGKILL, power cut)
//! are removed by a later run's first write into that folder, when they are stale (unlocked, older
//! than [`STALE_AFTER`]), regular files and owned by the user; links are never followed.

pub use scatterfit_safefs::UnsafeFile;
pub use scatterfit_safefs::ledger::{LEDGER_NAME, guard as guard_outputs};
pub use scatterfit_safefs::write::{
    STALE_AFTER, TEMP_PREFIX, check_can_write_in, in_flight, is_temporary_name, remove_in_flight,
    remove_stale_temporaries,
};

use std::io;
use std::path::Path;

use scatterfit_safefs::{ledger, write};

use crate::result_set::set_file;

/// True when an older run listed `name` among the result files of `dir` (its set manifest,
/// [`crate::result_set`]): results written before the ledger existed are scatterfit's too.
fn listed_by_a_result_set(dir: &Path, name: &str) -> bool {
    match set_file::read(dir) {
        Ok(Some(set)) => name == set_file::SET_FILE || set.files.iter().any(|f| f.name == name),
        _ => false,
    }
}

/// Refuses a destination that is a symbolic link or exists and is not a regular file, and — when
/// the output ledger is on ([`guard_outputs`], `scatterfit_safefs::ledger`) — an existing file
/// scatterfit did not write. A file an older run's result set lists is taken into the ledger here
/// (the run's set manifest is removed while it writes).
///
/// # Errors
/// An [`UnsafeFile`] inside an `io::Error`.
pub fn check_destination(path: &Path) -> io::Result<()> {
    write::check_destination(path)?;
    ledger::check_replaceable(path, &|dir: &Path, name: &str| {
        listed_by_a_result_set(dir, name)
    })?;
    if ledger::is_on() && std::fs::symlink_metadata(path).is_ok() {
        ledger::record(path)?;
    }
    Ok(())
}

/// Writes `bytes` to `path` atomically (`scatterfit_safefs::write::write_atomic`), after
/// [`check_destination`]; the file is recorded in its folder's ledger when the ledger is on.
///
/// # Errors
/// As [`check_destination`] and `scatterfit_safefs::write::write_atomic`.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> io::Result<()> {
    write_atomic_with(path, |w| w.write_all(bytes))
}

/// [`write_atomic`] through a callback that receives a buffered writer.
///
/// # Errors
/// As [`write_atomic`], or the callback's error.
pub fn write_atomic_with<F>(path: &Path, f: F) -> io::Result<()>
where
    F: FnOnce(&mut dyn io::Write) -> io::Result<()>,
{
    check_destination(path)?;
    write::write_atomic_with(path, f)?;
    ledger::record(path)
}
