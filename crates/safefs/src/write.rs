//! Atomic writes that cannot be redirected.
//!
//! Every file scatterfit writes goes through [`write_atomic`] / [`write_atomic_with`]:
//!
//! 1. The destination is looked at without following links: a symbolic link, a folder, a FIFO or a
//!    device there is refused ([`UnsafeFile::SymlinkDestination`],
//!    [`UnsafeFile::DestinationNotRegular`]); only a regular file is ever replaced.
//! 2. The data go to a temporary in the destination's folder, created **exclusively**
//!    (`O_CREAT | O_EXCL`: a planted file or link of that name makes the creation fail and another
//!    name is drawn) under an **unpredictable** name, `.scatterfit-tmp-<12 random characters>-<name>`
//!    (`tempfile`). Nothing is opened by a name someone else could have chosen.
//! 3. The temporary is locked (an advisory `flock`) for as long as it is in flight, written,
//!    synced, and renamed over the destination. `rename` replaces the directory entry — never the
//!    file a link would point to — so even a link planted after step 1 is replaced, not followed.
//!    The folder is synced after the rename so the new entry survives a power cut.
//!
//! Temporaries in flight are kept in a process-wide registry: a failed write removes its own, and
//! [`remove_in_flight`] (what the command-line tool calls on Ctrl-C) removes every one and refuses
//! new writes. A temporary whose writer was killed (`kill -9`, a power cut) is recognised by later
//! runs: its name starts with [`TEMP_PREFIX`], it is a regular file (never a link: it is looked at
//! and opened without following links), it is owned by the current user, it is older than
//! [`STALE_AFTER`] and nobody holds its lock ([`remove_stale_temporaries`]; the first write into a
//! folder in each process sweeps it).

use std::ffi::OsStr;
use std::fs::{self, File};
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard};
use std::time::{Duration, SystemTime};

use tempfile::NamedTempFile;

use crate::{UnsafeFile, describe_file_type};

/// How every temporary file of scatterfit's starts (followed by random characters, a `-` and the
/// destination's name).
pub const TEMP_PREFIX: &str = ".scatterfit-tmp-";

/// Random characters in a temporary's name (62¹² ≈ 3·10²¹ names).
const RAND_CHARS: usize = 12;

/// Longest part of the destination's name kept in a temporary's name [bytes] (a file name may have
/// 255 bytes; the prefix and the random part take 29).
const NAME_PART_BYTES: usize = 64;

/// Age below which an unlocked temporary is left alone by [`remove_stale_temporaries`] (the moment
/// between its creation and its lock, and file systems without locks, are covered by it).
pub const STALE_AFTER: Duration = Duration::from_secs(60);

/// What is in flight.
#[derive(Default)]
struct Registry {
    /// Temporary files created and not yet renamed or removed.
    files: Vec<PathBuf>,
    /// Folders already swept for stale temporaries by this process.
    swept: Vec<PathBuf>,
    /// Set by [`remove_in_flight`]: no new temporary file may be created.
    interrupted: bool,
}

static REGISTRY: Mutex<Registry> = Mutex::new(Registry {
    files: Vec::new(),
    swept: Vec::new(),
    interrupted: false,
});

fn registry() -> MutexGuard<'static, Registry> {
    // A panic while the lock was held leaves the list as it was: still usable.
    REGISTRY
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// True for a name of [`TEMP_PREFIX`]'s shape.
pub fn is_temporary_name(name: &OsStr) -> bool {
    name.as_encoded_bytes().starts_with(TEMP_PREFIX.as_bytes())
}

/// Refuses a destination that is a symbolic link or exists and is not a regular file (looked at
/// without following links). A missing destination is fine, and so is one that cannot be looked at
/// (a folder in its path that is a file, no permission): creating the temporary reports that.
///
/// # Errors
/// [`UnsafeFile::SymlinkDestination`] or [`UnsafeFile::DestinationNotRegular`] inside an
/// `io::Error`.
pub fn check_destination(path: &Path) -> io::Result<()> {
    match fs::symlink_metadata(path) {
        Err(_) => Ok(()),
        Ok(m) if m.file_type().is_symlink() => Err(UnsafeFile::SymlinkDestination.into_io()),
        Ok(m) if m.is_file() => Ok(()),
        Ok(m) => Err(UnsafeFile::DestinationNotRegular {
            kind: describe_file_type(&m.file_type()),
        }
        .into_io()),
    }
}

/// The folder and file name of `path`.
fn split(path: &Path) -> io::Result<(&Path, &OsStr)> {
    let name = path.file_name().ok_or_else(|| {
        io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("{} is not a file path", path.display()),
        )
    })?;
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    Ok((dir, name))
}

/// `-<name>`, shortened to [`NAME_PART_BYTES`] (for people looking at a folder; never parsed).
fn name_part(name: &OsStr) -> String {
    let name = name.to_string_lossy();
    let mut end = name.len().min(NAME_PART_BYTES);
    while !name.is_char_boundary(end) {
        end -= 1;
    }
    format!("-{}", &name[..end])
}

/// A new temporary in `dir` (exclusive creation, unpredictable name, locked), registered in one step
/// under the registry's lock, so an interruption either sees it or prevents it.
fn create_registered(dir: &Path, name: &OsStr) -> io::Result<NamedTempFile> {
    let mut reg = registry();
    if reg.interrupted {
        return Err(UnsafeFile::Interrupted.into_io());
    }
    let suffix = name_part(name);
    let mut builder = tempfile::Builder::new();
    builder
        .prefix(TEMP_PREFIX)
        .suffix(&suffix)
        .rand_bytes(RAND_CHARS);
    // The usual permissions of a new file (0666 less the umask), not tempfile's private 0600: the
    // temporary becomes the result file, which a lab shares.
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(fs::Permissions::from_mode(0o666));
    }
    let tmp = builder.tempfile_in(dir)?;
    // Held until the file is closed: how a later run tells a temporary in flight (in this or another
    // process) from one whose writer died. A file system without locks leaves it unlocked; the age
    // rule then protects it.
    let _ = tmp.as_file().try_lock();
    reg.files.push(tmp.path().to_path_buf());
    Ok(tmp)
}

fn forget(tmp: &Path) {
    registry().files.retain(|p| p != tmp);
}

/// Renames `tmp` over `path` (refusing a link or non-file there), under the registry's lock.
fn persist_registered(tmp: NamedTempFile, path: &Path) -> io::Result<()> {
    let reg = registry();
    if reg.interrupted {
        // Already removed by the interruption, or removed now by the drop.
        return Err(UnsafeFile::Interrupted.into_io());
    }
    check_destination(path)?;
    tmp.persist(path).map(drop).map_err(|e| e.error)
}

/// Syncs a folder so that a rename in it is durable (a no-op where folders cannot be opened).
fn sync_dir(dir: &Path) {
    #[cfg(unix)]
    if let Ok(d) = File::open(dir) {
        let _ = d.sync_all();
    }
    #[cfg(not(unix))]
    let _ = dir;
}

/// Sweeps `dir` for stale temporaries once per process (on its first write there).
fn sweep_once(dir: &Path) {
    {
        let mut reg = registry();
        if reg.swept.iter().any(|d| d == dir) {
            return;
        }
        reg.swept.push(dir.to_path_buf());
    }
    let _ = remove_stale_temporaries(dir, STALE_AFTER);
}

/// Writes `bytes` to `path` atomically (see the module documentation).
///
/// # Errors
/// An [`UnsafeFile`] for a destination that is a link or not a regular file, or after
/// [`remove_in_flight`]; any I/O error from creating, writing, syncing or renaming. The destination
/// is then untouched and the temporary removed.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> io::Result<()> {
    write_atomic_with(path, |w| w.write_all(bytes))
}

/// Writes to `path` atomically through a callback that receives a buffered writer on the temporary
/// file (nothing is held in memory).
///
/// # Errors
/// The callback's error, or as [`write_atomic`]; the destination is then untouched and the
/// temporary removed.
pub fn write_atomic_with<F>(path: &Path, write: F) -> io::Result<()>
where
    F: FnOnce(&mut dyn Write) -> io::Result<()>,
{
    let (dir, name) = split(path)?;
    check_destination(path)?;
    sweep_once(dir);
    let tmp = create_registered(dir, name)?;
    let tmp_path = tmp.path().to_path_buf();
    let result = (|| {
        {
            let mut writer = BufWriter::new(tmp.as_file());
            write(&mut writer)?;
            writer.flush()?;
        }
        tmp.as_file().sync_all()?;
        persist_registered(tmp, path)
    })();
    // On success the temporary is the destination now; on failure `tmp` was dropped, which removed
    // it. Either way the registry forgets it.
    forget(&tmp_path);
    if result.is_ok() {
        sync_dir(dir);
    }
    result
}

/// Checks that a file can be created in `dir` (it exists, is a folder and is writable), by creating
/// and removing a probe — a temporary like any other (exclusive, unpredictable name) — the only test
/// that holds for every permission scheme. Commands call it before their work so that an unwritable
/// output fails in milliseconds. Stale temporaries in `dir` are swept on the way.
///
/// # Errors
/// The I/O error of creating the probe.
pub fn check_can_write_in(dir: &Path) -> io::Result<()> {
    let dir = if dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        dir
    };
    sweep_once(dir);
    let probe = create_registered(dir, OsStr::new("probe"))?;
    let p = probe.path().to_path_buf();
    drop(probe);
    forget(&p);
    Ok(())
}

/// Removes every temporary file in flight and makes every later write fail with
/// [`UnsafeFile::Interrupted`] instead of creating a new one. Called on Ctrl-C before the process
/// exits; returns the files removed.
pub fn remove_in_flight() -> Vec<PathBuf> {
    let mut reg = registry();
    reg.interrupted = true;
    let mut removed = Vec::new();
    for tmp in std::mem::take(&mut reg.files) {
        if fs::remove_file(&tmp).is_ok() {
            removed.push(tmp);
        }
    }
    removed
}

/// The temporary files now in flight (for tests and diagnostics).
pub fn in_flight() -> Vec<PathBuf> {
    registry().files.clone()
}

/// Removes the temporaries in `dir` that a killed run left behind, and only those: names starting
/// with [`TEMP_PREFIX`] that are regular files (looked at and opened without following links, and
/// the opened file checked to be the one looked at), owned by the current user, last modified at
/// least `min_age` ago, and whose lock nobody holds (a writer in this or another process holds it
/// until its rename). Returns the files removed.
///
/// # Errors
/// The error of reading the folder; a file that cannot be examined is skipped.
pub fn remove_stale_temporaries(dir: &Path, min_age: Duration) -> io::Result<Vec<PathBuf>> {
    let mut removed = Vec::new();
    for entry in fs::read_dir(dir)?.flatten() {
        if !is_temporary_name(&entry.file_name()) {
            continue;
        }
        let path = entry.path();
        if is_stale(&path, min_age) && fs::remove_file(&path).is_ok() {
            removed.push(path);
        }
    }
    Ok(removed)
}

fn is_stale(path: &Path, min_age: Duration) -> bool {
    let Ok(meta) = fs::symlink_metadata(path) else {
        return false;
    };
    if !meta.file_type().is_file() || !owned_by_us(&meta) {
        return false;
    }
    let age = meta
        .modified()
        .ok()
        .and_then(|m| SystemTime::now().duration_since(m).ok());
    if age.is_none_or(|a| a < min_age) {
        return false;
    }
    let Ok(file) = open_nofollow(path) else {
        return false;
    };
    let Ok(opened) = file.metadata() else {
        return false;
    };
    if !same_file(&meta, &opened) {
        return false;
    }
    // Free lock: nobody is writing it. (The lock is released when `file` is closed.)
    file.try_lock().is_ok()
}

#[cfg(unix)]
fn owned_by_us(meta: &fs::Metadata) -> bool {
    use std::os::unix::fs::MetadataExt;
    meta.uid() == rustix::process::geteuid().as_raw()
}

#[cfg(not(unix))]
fn owned_by_us(_: &fs::Metadata) -> bool {
    true
}

#[cfg(unix)]
fn same_file(a: &fs::Metadata, b: &fs::Metadata) -> bool {
    use std::os::unix::fs::MetadataExt;
    a.dev() == b.dev() && a.ino() == b.ino() && b.is_file()
}

#[cfg(not(unix))]
fn same_file(_: &fs::Metadata, b: &fs::Metadata) -> bool {
    b.is_file()
}

/// Opens a file for reading without following a final symbolic link and without blocking.
#[cfg(unix)]
fn open_nofollow(path: &Path) -> io::Result<File> {
    use rustix::fs::OFlags;
    use std::os::unix::fs::OpenOptionsExt;
    fs::OpenOptions::new()
        .read(true)
        .custom_flags((OFlags::NOFOLLOW | OFlags::NONBLOCK).bits() as i32)
        .open(path)
}

#[cfg(not(unix))]
fn open_nofollow(path: &Path) -> io::Result<File> {
    File::open(path)
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

    fn temporaries(dir: &Path) -> Vec<PathBuf> {
        fs::read_dir(dir)
            .unwrap()
            .flatten()
            .filter(|e| is_temporary_name(&e.file_name()))
            .map(|e| e.path())
            .collect()
    }

    fn age(path: &Path, by: Duration) {
        let f = fs::OpenOptions::new().write(true).open(path).unwrap();
        f.set_modified(SystemTime::now() - by).unwrap();
    }

    #[test]
    fn replaces_existing_file_and_leaves_no_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("result.json");
        fs::write(&target, b"old").unwrap();
        write_atomic(&target, b"new contents").unwrap();
        assert_eq!(fs::read(&target).unwrap(), b"new contents");
        assert_eq!(entries(dir.path()), ["result.json"]);
    }

    #[cfg(unix)]
    #[test]
    fn results_get_the_usual_permissions() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("result.csv");
        write_atomic(&target, b"x").unwrap();
        let mode = fs::metadata(&target).unwrap().permissions().mode();
        assert_eq!(mode & 0o600, 0o600, "{mode:o}");
        // With the common umask 022 a lab's colleagues can read it (not tempfile's private 0600).
        let umask_022 = mode & 0o044 == 0o044;
        let private_umask = mode & 0o077 == 0;
        assert!(umask_022 || private_umask, "{mode:o}");
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
        let d = dir.path().to_path_buf();
        let err = write_atomic_with(&target, |w| {
            w.write_all(&[7u8; 100_000])?;
            w.flush()?;
            let tmps = temporaries(&d);
            assert_eq!(tmps.len(), 1, "the data go to one temporary file");
            assert!(in_flight().contains(&tmps[0]), "and it is registered");
            Err(io::Error::other("disk full"))
        })
        .unwrap_err();
        assert_eq!(err.to_string(), "disk full");
        assert!(entries(dir.path()).is_empty(), "{:?}", entries(dir.path()));
        assert!(in_flight().iter().all(|p| !p.starts_with(dir.path())));
    }

    /// A destination that is a folder (or anything but a regular file) is refused before anything is
    /// created, and the folder is untouched.
    #[test]
    fn a_destination_that_is_not_a_file_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("out.csv");
        fs::create_dir(&target).unwrap();
        fs::write(target.join("keep"), b"x").unwrap();
        let e = write_atomic(&target, b"data").unwrap_err();
        assert_eq!(
            UnsafeFile::of(&e),
            Some(&UnsafeFile::DestinationNotRegular { kind: "a folder" })
        );
        assert_eq!(entries(dir.path()), ["out.csv"]);
        assert_eq!(entries(&target), ["keep"]);
    }

    /// The classic attack on a shared folder: a symbolic link planted at the destination must not redirect the
    /// write to the file it points to. It is refused, and the file outside is untouched.
    #[cfg(unix)]
    #[test]
    fn a_symlink_at_the_destination_is_refused_and_its_target_untouched() {
        let dir = tempfile::tempdir().unwrap();
        let outside = tempfile::tempdir().unwrap();
        let victim = outside.path().join("victim");
        fs::write(&victim, b"precious").unwrap();
        let target = dir.path().join("result.json");
        std::os::unix::fs::symlink(&victim, &target).unwrap();
        let e = write_atomic(&target, b"attack").unwrap_err();
        assert_eq!(UnsafeFile::of(&e), Some(&UnsafeFile::SymlinkDestination));
        assert_eq!(fs::read(&victim).unwrap(), b"precious");
        assert!(
            fs::symlink_metadata(&target)
                .unwrap()
                .file_type()
                .is_symlink()
        );
        assert!(temporaries(dir.path()).is_empty());
        // A dangling link too (it would create the file it names).
        let dangling = dir.path().join("fit.png");
        let created = outside.path().join("created");
        std::os::unix::fs::symlink(&created, &dangling).unwrap();
        assert!(write_atomic(&dangling, b"attack").is_err());
        assert!(!created.exists());
    }

    /// Temporaries cannot be predicted: two writes of the same file use different names, and a
    /// planted link at the old `.NAME.tmp-<pid>` name (or any name of ours we could guess) is not
    /// followed.
    #[cfg(unix)]
    #[test]
    fn planted_links_at_temporary_names_are_never_followed() {
        let dir = tempfile::tempdir().unwrap();
        let outside = tempfile::tempdir().unwrap();
        let victim = outside.path().join("victim");
        fs::write(&victim, b"precious").unwrap();
        let target = dir.path().join("result.json");
        // The old pattern, the probe's old pattern, and names of the new prefix.
        let pid = std::process::id();
        for name in [
            format!(".result.json.tmp-{pid}"),
            format!(".scatterfit-probe.tmp-{pid}"),
            format!("{TEMP_PREFIX}aaaaaaaaaaaa-result.json"),
            format!("{TEMP_PREFIX}probe"),
        ] {
            std::os::unix::fs::symlink(&victim, dir.path().join(name)).unwrap();
        }
        let mut seen = Vec::new();
        for _ in 0..20 {
            write_atomic_with(&target, |w| {
                seen.extend(
                    temporaries(dir.path())
                        .into_iter()
                        .filter(|p| !fs::symlink_metadata(p).unwrap().file_type().is_symlink()),
                );
                w.write_all(b"ok")
            })
            .unwrap();
            check_can_write_in(dir.path()).unwrap();
        }
        assert_eq!(fs::read(&victim).unwrap(), b"precious");
        assert_eq!(fs::read(&target).unwrap(), b"ok");
        seen.sort();
        seen.dedup();
        assert_eq!(seen.len(), 20, "every write draws a new name");
        // The planted links are still links (never replaced, never removed by the sweeper).
        assert_eq!(temporaries(dir.path()).len(), 2);
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

    /// A killed writer's temporary (unlocked, old) is removed by a later sweep; a live one (locked)
    /// and a young one are not; neither are links, folders or files of other names.
    #[test]
    fn stale_temporaries_are_swept_and_live_ones_kept() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        let stale = d.join(format!("{TEMP_PREFIX}deadbeef0000-result.json"));
        fs::write(&stale, b"half").unwrap();
        age(&stale, Duration::from_secs(3600));
        let young = d.join(format!("{TEMP_PREFIX}young0000000-result.json"));
        fs::write(&young, b"half").unwrap();
        let other = d.join("notes.txt");
        fs::write(&other, b"keep").unwrap();
        age(&other, Duration::from_secs(3600));
        let folder = d.join(format!("{TEMP_PREFIX}folder"));
        fs::create_dir(&folder).unwrap();
        // A live temporary: a write in progress, held open and locked, made old.
        let live = create_registered(d, OsStr::new("fit.png")).unwrap();
        age(live.path(), Duration::from_secs(3600));
        let removed = remove_stale_temporaries(d, STALE_AFTER).unwrap();
        assert_eq!(removed, vec![stale.clone()]);
        assert!(young.exists() && other.exists() && folder.exists() && live.path().exists());
        let live_path = live.path().to_path_buf();
        drop(live);
        forget(&live_path);
    }

    /// The sweeper never follows a link, even one named like a temporary and pointing at a file
    /// of ours that is old and unlocked.
    #[cfg(unix)]
    #[test]
    fn the_sweeper_never_follows_links() {
        let dir = tempfile::tempdir().unwrap();
        let outside = tempfile::tempdir().unwrap();
        let victim = outside.path().join("victim");
        fs::write(&victim, b"precious").unwrap();
        age(&victim, Duration::from_secs(3600));
        let link = dir.path().join(format!("{TEMP_PREFIX}planted00000-x"));
        std::os::unix::fs::symlink(&victim, &link).unwrap();
        assert!(
            remove_stale_temporaries(dir.path(), Duration::ZERO)
                .unwrap()
                .is_empty()
        );
        assert_eq!(fs::read(&victim).unwrap(), b"precious");
        assert!(fs::symlink_metadata(&link).is_ok());
    }
}
