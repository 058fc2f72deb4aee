//! Atomic file output: write to a temporary file beside the target, flush it, then rename.
//!
//! A reader (or a crash) never sees a half-written result, and an existing file is replaced in one
//! step. The temporary file lives in the target's folder so that the rename stays on one file system.
//!
//! Temporary files in flight are kept in a process-wide registry, so that nothing is left behind:
//! a failed write removes its own, and [`remove_in_flight`] (what the command-line tool calls on
//! Ctrl-C, before it exits) removes every one still open and refuses new ones. Folders where other
//! code writes temporaries of the same shape (`.<name>.tmp-<pid>`: the Monte Carlo caches, whose
//! crates do no IO through this one) can be registered with [`sweep_on_interrupt`].

use std::fs;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard};

/// What is in flight.
#[derive(Default)]
struct Registry {
    /// Temporary files created and not yet renamed or removed.
    files: Vec<PathBuf>,
    /// Folders swept for `.*.tmp-<pid>` files on interruption.
    sweep: Vec<PathBuf>,
    /// Set by [`remove_in_flight`]: no new temporary file may be created.
    interrupted: bool,
}

static REGISTRY: Mutex<Registry> = Mutex::new(Registry {
    files: Vec::new(),
    sweep: Vec::new(),
    interrupted: false,
});

fn registry() -> MutexGuard<'static, Registry> {
    // A panic while the lock was held leaves the list as it was: still usable.
    REGISTRY
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

fn interrupted_error() -> io::Error {
    io::Error::new(
        io::ErrorKind::Interrupted,
        "interrupted: no more files are written",
    )
}

/// Creates `tmp` and registers it, in one step under the registry's lock (so an interruption either
/// sees the file or prevents it).
fn create_registered(tmp: &Path) -> io::Result<fs::File> {
    let mut reg = registry();
    if reg.interrupted {
        return Err(interrupted_error());
    }
    let file = fs::File::create(tmp)?;
    reg.files.push(tmp.to_path_buf());
    Ok(file)
}

fn forget(reg: &mut Registry, tmp: &Path) {
    reg.files.retain(|p| p != tmp);
}

/// Renames `tmp` over `path` and forgets it.
fn rename_registered(tmp: &Path, path: &Path) -> io::Result<()> {
    let mut reg = registry();
    if reg.interrupted {
        return Err(interrupted_error());
    }
    let result = fs::rename(tmp, path);
    if result.is_ok() {
        forget(&mut reg, tmp);
    }
    result
}

/// Removes `tmp` (if it is still there) and forgets it.
fn remove_registered(tmp: &Path) {
    let mut reg = registry();
    let _ = fs::remove_file(tmp);
    forget(&mut reg, tmp);
}

/// Writes `bytes` to `path` atomically: the data go to `.<name>.tmp-<pid>` beside `path`, are synced
/// to disk, and the temporary file is renamed over `path`. The temporary file is removed on failure.
///
/// # Errors
/// Any I/O error from creating, writing, syncing or renaming (or [`io::ErrorKind::Interrupted`]
/// after [`remove_in_flight`]); the target is then left untouched.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> io::Result<()> {
    write_atomic_with(path, |w| w.write_all(bytes))
}

/// Writes to `path` atomically through a callback that receives a buffered writer on the temporary
/// file (nothing is held in memory).
///
/// # Errors
/// The callback's error, or any I/O error; the target is then left untouched and the temporary file
/// removed.
pub fn write_atomic_with<F>(path: &Path, write: F) -> io::Result<()>
where
    F: FnOnce(&mut dyn Write) -> io::Result<()>,
{
    let tmp = temporary_path(path)?;
    let file = create_registered(&tmp)?;
    let result = (|| {
        let mut writer = BufWriter::new(file);
        write(&mut writer)?;
        let file = writer
            .into_inner()
            .map_err(io::IntoInnerError::into_error)?;
        file.sync_all()?;
        drop(file);
        rename_registered(&tmp, path)
    })();
    if result.is_err() {
        remove_registered(&tmp);
    }
    result
}

/// Checks that a file can be created in `dir` (it exists, is a folder and is writable), by creating
/// and removing a probe file there — the only test that holds for every permission scheme. Commands
/// call it before their work so that an unwritable output fails in milliseconds.
///
/// # Errors
/// The I/O error of creating the probe.
pub fn check_can_write_in(dir: &Path) -> io::Result<()> {
    let dir = if dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        dir
    };
    let probe = dir.join(format!(".scatterfit-probe.tmp-{}", std::process::id()));
    let file = create_registered(&probe)?;
    drop(file);
    remove_registered(&probe);
    Ok(())
}

/// Registers `dir` to be swept by [`remove_in_flight`] for this process's `.<name>.tmp-<pid>` files
/// (temporaries written by code that does not go through this module, e.g. the Monte Carlo caches).
pub fn sweep_on_interrupt(dir: &Path) {
    let mut reg = registry();
    if !reg.sweep.iter().any(|d| d == dir) {
        reg.sweep.push(dir.to_path_buf());
    }
}

/// Removes every temporary file in flight (and this process's temporaries in the folders given to
/// [`sweep_on_interrupt`]), and makes every later write fail with [`io::ErrorKind::Interrupted`]
/// instead of creating a new one. Called on Ctrl-C before the process exits; returns the files
/// removed.
pub fn remove_in_flight() -> Vec<PathBuf> {
    let mut reg = registry();
    reg.interrupted = true;
    let mut removed = Vec::new();
    for tmp in std::mem::take(&mut reg.files) {
        if fs::remove_file(&tmp).is_ok() {
            removed.push(tmp);
        }
    }
    let suffix = format!(".tmp-{}", std::process::id());
    for dir in &reg.sweep {
        let Ok(entries) = fs::read_dir(dir) else {
            continue;
        };
        for entry in entries.flatten() {
            let name = entry.file_name();
            let name = name.to_string_lossy();
            if name.starts_with('.') && name.ends_with(&suffix) {
                let path = entry.path();
                if fs::remove_file(&path).is_ok() {
                    removed.push(path);
                }
            }
        }
    }
    removed
}

/// The temporary files now in flight (for tests and diagnostics).
pub fn in_flight() -> Vec<PathBuf> {
    registry().files.clone()
}

/// The temporary file of `path`: `.<name>.tmp-<pid>` in the same folder.
///
/// # Errors
/// [`io::ErrorKind::InvalidInput`] for a path without a file name.
pub fn temporary_path(path: &Path) -> io::Result<PathBuf> {
    let name = path.file_name().ok_or_else(|| {
        io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("{} is not a file path", path.display()),
        )
    })?;
    let mut tmp_name = std::ffi::OsString::from(".");
    tmp_name.push(name);
    tmp_name.push(format!(".tmp-{}", std::process::id()));
    Ok(path.with_file_name(tmp_name))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn entries(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn replaces_existing_file_and_leaves_no_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("result.json");
        fs::write(&target, b"old").unwrap();
        write_atomic(&target, b"new contents").unwrap();
        assert_eq!(fs::read(&target).unwrap(), b"new contents");
        assert_eq!(
            entries(dir.path()),
            ["result.json"],
            "only the target remains"
        );
    }

    #[test]
    fn failure_leaves_target_untouched() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("missing-folder").join("result.json");
        assert!(write_atomic(&target, b"x").is_err());
        assert!(!target.exists());
    }

    /// The error path: a writer that fails half-way (a full disk, an encoder error) leaves neither
    /// the target nor the temporary file, and the registry forgets it.
    #[test]
    fn a_failed_write_removes_its_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("radiance.exr");
        let tmp = temporary_path(&target).unwrap();
        let err = write_atomic_with(&target, |w| {
            w.write_all(&[7u8; 100_000])?;
            assert!(tmp.exists(), "the data go to the temporary file");
            assert!(in_flight().contains(&tmp), "and it is registered");
            Err(io::Error::other("disk full"))
        })
        .unwrap_err();
        assert_eq!(err.to_string(), "disk full");
        assert!(entries(dir.path()).is_empty(), "{:?}", entries(dir.path()));
        assert!(!in_flight().contains(&tmp));
    }

    /// A rename that fails (the target is a folder) removes the temporary file too.
    #[test]
    fn a_failed_rename_removes_its_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("out.csv");
        fs::create_dir(&target).unwrap();
        fs::write(target.join("keep"), b"x").unwrap();
        assert!(write_atomic(&target, b"data").is_err());
        assert_eq!(entries(dir.path()), ["out.csv"]);
        assert!(!in_flight().contains(&temporary_path(&target).unwrap()));
    }

    #[test]
    fn probing_a_folder_leaves_nothing() {
        let dir = tempfile::tempdir().unwrap();
        check_can_write_in(dir.path()).unwrap();
        assert!(entries(dir.path()).is_empty());
        // A "folder" that is a file cannot be written in, whoever runs the test (even root).
        let file = dir.path().join("plain");
        fs::write(&file, b"x").unwrap();
        assert!(check_can_write_in(&file).is_err());
        assert!(check_can_write_in(&dir.path().join("missing")).is_err());
    }
}
