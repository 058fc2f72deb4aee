//! Bounded reads of regular files only.
//!
//! An input may be named by a manifest, a result file, a cache folder or the command line, and the
//! folder it lives in may be writable by others: it may be a FIFO (a read blocks forever), a device
//! (`/dev/zero`: a read never ends), a folder or a socket. [`open_regular`] looks at the path first
//! (a clear message), opens it without blocking (`O_NONBLOCK`: opening a FIFO does not wait for a
//! writer) and checks the opened file again (the path may have been swapped in between); only a
//! regular file is returned. [`read_limited`] then refuses a file larger than the caller's limit
//! from its size, and stops reading one byte past the limit in case it grows.

use std::fs::{self, File, Metadata};
use std::io::{self, Read};
use std::path::Path;

use crate::{UnsafeFile, describe_file_type};

fn not_regular(meta: &Metadata) -> io::Error {
    UnsafeFile::InputNotRegular {
        kind: describe_file_type(&meta.file_type()),
    }
    .into_io()
}

/// Opens `path` for reading when it is (or, through links, leads to) a regular file; never blocks.
///
/// # Errors
/// The `io::Error` of `stat` or `open` (not found, permission denied), or an
/// [`UnsafeFile::InputNotRegular`] for anything that is not a regular file.
pub fn open_regular(path: &Path) -> io::Result<(File, Metadata)> {
    let before = fs::metadata(path)?;
    if !before.is_file() {
        return Err(not_regular(&before));
    }
    let file = open_nonblocking(path)?;
    let meta = file.metadata()?;
    if !meta.is_file() {
        return Err(not_regular(&meta));
    }
    Ok((file, meta))
}

#[cfg(unix)]
fn open_nonblocking(path: &Path) -> io::Result<File> {
    use std::os::unix::fs::OpenOptionsExt;
    fs::OpenOptions::new()
        .read(true)
        .custom_flags(rustix::fs::OFlags::NONBLOCK.bits() as i32)
        .open(path)
}

#[cfg(not(unix))]
fn open_nonblocking(path: &Path) -> io::Result<File> {
    File::open(path)
}

/// The bytes of the regular file `path`, at most `limit` of them.
///
/// # Errors
/// As [`open_regular`], [`UnsafeFile::TooLarge`] beyond `limit` (from the size before reading, or
/// from the bytes read when the file grew), or a read error.
pub fn read_limited(path: &Path, limit: u64) -> io::Result<Vec<u8>> {
    let (file, meta) = open_regular(path)?;
    let too_large = |bytes| UnsafeFile::TooLarge { bytes, limit }.into_io();
    if meta.len() > limit {
        return Err(too_large(meta.len()));
    }
    let mut bytes = Vec::with_capacity(usize::try_from(meta.len()).unwrap_or(0));
    file.take(limit.saturating_add(1)).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > limit {
        return Err(too_large(bytes.len() as u64));
    }
    Ok(bytes)
}

/// [`read_limited`] as UTF-8 text (for files scatterfit wrote itself, such as caches).
///
/// # Errors
/// As [`read_limited`], or `InvalidData` when the bytes are not UTF-8.
pub fn read_to_string_limited(path: &Path, limit: u64) -> io::Result<String> {
    String::from_utf8(read_limited(path, limit)?)
        .map_err(|_| io::Error::new(io::ErrorKind::InvalidData, "not UTF-8 text"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::{Duration, Instant};

    fn inner(e: &io::Error) -> UnsafeFile {
        UnsafeFile::of(e).cloned().unwrap_or_else(|| panic!("{e}"))
    }

    #[test]
    fn regular_files_are_read_within_the_limit() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.csv");
        fs::write(&p, b"0123456789").unwrap();
        assert_eq!(read_limited(&p, 10).unwrap(), b"0123456789");
        let e = read_limited(&p, 9).unwrap_err();
        assert_eq!(
            inner(&e),
            UnsafeFile::TooLarge {
                bytes: 10,
                limit: 9
            }
        );
        assert!(e.to_string().contains("10 bytes"), "{e}");
    }

    #[test]
    fn a_folder_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let e = read_limited(dir.path(), 10).unwrap_err();
        assert_eq!(inner(&e), UnsafeFile::InputNotRegular { kind: "a folder" });
    }

    /// `/dev/zero` would be read until memory runs out; it is refused at once, as is `/dev/null`.
    #[cfg(unix)]
    #[test]
    fn devices_are_refused_at_once() {
        for dev in ["/dev/zero", "/dev/null", "/dev/urandom"] {
            let t = Instant::now();
            let e = read_limited(Path::new(dev), 1 << 30).unwrap_err();
            assert_eq!(
                inner(&e),
                UnsafeFile::InputNotRegular {
                    kind: "a character device"
                },
                "{dev}"
            );
            assert!(t.elapsed() < Duration::from_secs(1));
        }
    }

    /// A FIFO without a writer would block a plain `open` forever; a symbolic link to one too.
    #[cfg(unix)]
    #[test]
    fn a_fifo_is_refused_without_blocking() {
        let dir = tempfile::tempdir().unwrap();
        let fifo = dir.path().join("spectro.csv");
        rustix::fs::mkfifoat(rustix::fs::CWD, &fifo, rustix::fs::Mode::from(0o600)).unwrap();
        let link = dir.path().join("link.csv");
        std::os::unix::fs::symlink(&fifo, &link).unwrap();
        for p in [&fifo, &link] {
            let t = Instant::now();
            let e = read_limited(p, 100).unwrap_err();
            assert_eq!(
                inner(&e),
                UnsafeFile::InputNotRegular {
                    kind: "a FIFO (named pipe)"
                }
            );
            assert!(t.elapsed() < Duration::from_secs(1));
        }
    }

    #[cfg(unix)]
    #[test]
    fn a_socket_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let sock = dir.path().join("frame.png");
        let _listener = std::os::unix::net::UnixListener::bind(&sock).unwrap();
        let e = read_limited(&sock, 100).unwrap_err();
        assert_eq!(inner(&e), UnsafeFile::InputNotRegular { kind: "a socket" });
    }

    #[test]
    fn a_missing_file_is_the_plain_io_error() {
        let dir = tempfile::tempdir().unwrap();
        let e = read_limited(&dir.path().join("none"), 10).unwrap_err();
        assert_eq!(e.kind(), io::ErrorKind::NotFound);
        assert!(UnsafeFile::of(&e).is_none());
    }
}
