//! The output ledger: which files of a folder scatterfit wrote, so that it never replaces one it did
//! not.
//!
//! A drop folder, a working folder or a sample folder holds the user's own files beside
//! scatterfit's: notes called `result.md`, a lab's `index.html`, a `summary.md`. A run that writes
//! a file of the same name would destroy them. So, once a program turns the ledger on
//! ([`guard`]; the command-line tool does, library users may not), every write that goes through
//! [`check_replaceable`] and [`record`]:
//!
//! - records the file's name in its folder's ledger, [`LEDGER_NAME`] (a small JSON list of names,
//!   written atomically, read with a bound);
//! - refuses to replace an existing file whose name the ledger does not list, unless the user
//!   insisted ([`guard`]'s `replace_unlisted`, the tool's `--force`).
//!
//! A file is judged by name, not content: scatterfit's own results, edited by hand afterwards, are
//! still its own. A new file is always fine.

use std::collections::BTreeSet;
use std::io;
use std::path::Path;
use std::sync::Mutex;
use std::sync::atomic::{AtomicU8, Ordering};

use crate::UnsafeFile;

/// The ledger's file name in each folder scatterfit writes into.
pub const LEDGER_NAME: &str = ".scatterfit-written.json";

/// Largest ledger read (1 MiB: some 30 000 names).
const MAX_LEDGER_BYTES: u64 = 1 << 20;

/// 0: off; 1: on; 2: on, unlisted files may be replaced (the user insisted).
static MODE: AtomicU8 = AtomicU8::new(0);

/// One writer of ledgers at a time in this process (parallel samples write into one folder).
static LOCK: Mutex<()> = Mutex::new(());

/// Turns the ledger on for this process; `replace_unlisted` lets files it does not list be
/// replaced (still recorded).
pub fn guard(replace_unlisted: bool) {
    MODE.store(if replace_unlisted { 2 } else { 1 }, Ordering::SeqCst);
}

/// True when the ledger is on.
pub fn is_on() -> bool {
    MODE.load(Ordering::SeqCst) != 0
}

/// The names the ledger of `dir` lists (none when it is missing or unreadable).
pub fn listed(dir: &Path) -> BTreeSet<String> {
    crate::read::read_limited(&dir.join(LEDGER_NAME), MAX_LEDGER_BYTES)
        .ok()
        .and_then(|b| serde_json::from_slice::<Ledger>(&b).ok())
        .map(|l| l.files.into_iter().collect())
        .unwrap_or_default()
}

#[derive(serde::Serialize, serde::Deserialize)]
struct Ledger {
    written_by: String,
    files: Vec<String>,
}

/// Refuses to replace `path` when the ledger is on, the file exists, its folder's ledger does not
/// list it and `also_ours` (a caller's knowledge, e.g. an older run's list of result files) does
/// not accept its name either.
///
/// # Errors
/// [`UnsafeFile::NotWrittenByScatterfit`] inside an `io::Error`.
pub fn check_replaceable(path: &Path, also_ours: &dyn Fn(&Path, &str) -> bool) -> io::Result<()> {
    if MODE.load(Ordering::SeqCst) != 1 || std::fs::symlink_metadata(path).is_err() {
        return Ok(());
    }
    let (dir, name) = split(path);
    if listed(dir).contains(&name) || also_ours(dir, &name) {
        return Ok(());
    }
    Err(UnsafeFile::NotWrittenByScatterfit.into_io())
}

/// Records `path` as written by scatterfit in its folder's ledger (when the ledger is on).
///
/// # Errors
/// Writing the ledger.
pub fn record(path: &Path) -> io::Result<()> {
    if !is_on() {
        return Ok(());
    }
    let (dir, name) = split(path);
    if name == LEDGER_NAME {
        return Ok(());
    }
    let _held = LOCK
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    let mut names = listed(dir);
    if !names.insert(name) {
        return Ok(());
    }
    let ledger = Ledger {
        written_by: "scatterfit: files it wrote here and may replace; others it never replaces"
            .into(),
        files: names.into_iter().collect(),
    };
    let text = serde_json::to_string_pretty(&ledger).map_err(io::Error::other)?;
    crate::write::write_atomic(&dir.join(LEDGER_NAME), text.as_bytes())
}

fn split(path: &Path) -> (&Path, String) {
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    (dir, name)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Off by default; on, a file the ledger lists is replaceable, one it does not is refused
    /// unless the user insisted, a new one is fine. (One test: the mode is process-wide.)
    #[test]
    fn only_listed_files_are_replaced() {
        let dir = tempfile::tempdir().unwrap();
        let notes = dir.path().join("result.md");
        std::fs::write(&notes, b"my notes").unwrap();
        let none = |_: &Path, _: &str| false;
        check_replaceable(&notes, &none).unwrap();
        guard(false);
        let e = check_replaceable(&notes, &none).unwrap_err();
        assert_eq!(
            UnsafeFile::of(&e),
            Some(&UnsafeFile::NotWrittenByScatterfit)
        );
        assert!(e.to_string().contains("--force"), "{e}");
        check_replaceable(&notes, &|_, n| n == "result.md").unwrap();
        let ours = dir.path().join("summary.md");
        check_replaceable(&ours, &none).unwrap();
        crate::write::write_atomic(&ours, b"x").unwrap();
        record(&ours).unwrap();
        check_replaceable(&ours, &none).unwrap();
        assert!(listed(dir.path()).contains("summary.md"));
        guard(true);
        check_replaceable(&notes, &none).unwrap();
        MODE.store(0, Ordering::SeqCst);
    }
}
