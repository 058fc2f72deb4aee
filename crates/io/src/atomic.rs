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
pub use scatterfit_safefs::write::{
    STALE_AFTER, TEMP_PREFIX, check_can_write_in, check_destination, in_flight, is_temporary_name,
    remove_in_flight, remove_stale_temporaries, write_atomic, write_atomic_with,
};
