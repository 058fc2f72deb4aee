//! scatterfit-safefs: the file-system rules every scatterfit crate writes and reads by.
//!
//! scatterfit runs unattended in shared folders (a lab's drop folder processed overnight), so anyone
//! who can write into a sample or output folder must not be able to make it write or read
//! elsewhere, block, or exhaust memory. Two halves, used by `scatterfit-io` (every format), the Monte
//! Carlo cache of `scatterfit-mc` and the profile cache of `scatterfit-synth`:
//!
//! - [`mod@write`]: atomic writes through an **exclusively created, unpredictable temporary** in the
//!   target's folder (`tempfile`), locked while in flight, synced, renamed over a destination that
//!   must be a regular file or absent (never a symbolic link), the folder synced after. A registry
//!   of temporaries in flight serves Ctrl-C; temporaries left by a killed run are recognised by
//!   their prefix ([`write::TEMP_PREFIX`]) and their free lock, and removed by later runs.
//! - [`read`]: inputs are **regular files only** (a FIFO, a device, a folder or a socket is refused
//!   at once, never opened in a way that blocks) and **bounded** (the size is checked before reading
//!   and the read stops one byte past the limit).
//!
//! Errors are `std::io::Error`s (so every caller's `source: io::Error` keeps working) whose inner
//! error is one of this crate's types ([`UnsafeFile`]), for callers that want to tell them apart.

pub mod ledger;
pub mod read;
pub mod write;

use std::fs::FileType;

/// Largest text file read anywhere (64 MiB): every text file of a measurement, a manifest, a
/// result and a cache file is far smaller.
pub const MAX_TEXT_BYTES: u64 = 64 << 20;

/// Why a path was refused: the inner error of the `io::Error`s of this crate.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum UnsafeFile {
    /// An input is not a regular file.
    #[error(
        "is {kind}, not a regular file; scatterfit reads regular files only (a pipe or a device \
         could block or never end)"
    )]
    InputNotRegular {
        /// What it is, e.g. `a FIFO (named pipe)`.
        kind: &'static str,
    },
    /// An input is larger than the limit for its kind.
    #[error(
        "is {bytes} bytes, more than the {limit} bytes scatterfit reads from such a file; is this the right file?"
    )]
    TooLarge {
        /// Its size (at least this many bytes).
        bytes: u64,
        /// The limit.
        limit: u64,
    },
    /// An output path is a symbolic link.
    #[error(
        "is a symbolic link; scatterfit never writes through a link (it could point anywhere) — \
         remove the link or choose another name"
    )]
    SymlinkDestination,
    /// An output path exists and is not a regular file.
    #[error("is {kind}; scatterfit replaces regular files only — choose another name")]
    DestinationNotRegular {
        /// What it is, e.g. `a folder`.
        kind: &'static str,
    },
    /// An output path exists and scatterfit did not write it (its folder's ledger does not list
    /// it, [`ledger`]).
    #[error(
        "exists and was not written by scatterfit (it is not in the folder's {ledger}); \
         scatterfit never replaces a file it did not write — move the file away, choose another \
         output folder, or pass --force to replace it",
        ledger = ledger::LEDGER_NAME
    )]
    NotWrittenByScatterfit,
    /// Writing stopped: the process is being interrupted (Ctrl-C).
    #[error("interrupted: no more files are written")]
    Interrupted,
}

impl UnsafeFile {
    /// As an `io::Error` (kind `InvalidInput`, `InvalidData` or `Interrupted`) carrying `self`.
    pub fn into_io(self) -> std::io::Error {
        let kind = match self {
            Self::TooLarge { .. } => std::io::ErrorKind::InvalidData,
            Self::Interrupted => std::io::ErrorKind::Interrupted,
            _ => std::io::ErrorKind::InvalidInput,
        };
        std::io::Error::new(kind, self)
    }

    /// The [`UnsafeFile`] inside `e`, if it is one of ours.
    pub fn of(e: &std::io::Error) -> Option<&UnsafeFile> {
        e.get_ref()
            .and_then(|inner| inner.downcast_ref::<UnsafeFile>())
    }
}

/// What a file type is, for messages: `a folder`, `a FIFO (named pipe)`, …
pub fn describe_file_type(t: &FileType) -> &'static str {
    if t.is_file() {
        return "a regular file";
    }
    if t.is_dir() {
        return "a folder";
    }
    if t.is_symlink() {
        return "a symbolic link";
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_fifo() {
            return "a FIFO (named pipe)";
        }
        if t.is_socket() {
            return "a socket";
        }
        if t.is_char_device() {
            return "a character device";
        }
        if t.is_block_device() {
            return "a block device";
        }
    }
    "a special file"
}
