//! The set manifest on disk: its file name, its format and [`read`]ing it. The run protocol that
//! writes it (begin, finish, verify) is the folder module, [`super`]; this file stands below
//! [`crate::atomic`], which asks it whether a file is scatterfit's.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

/// The set manifest's file name.
pub const SET_FILE: &str = "result-files.json";

/// The manifest's format tag.
pub const SET_FORMAT: &str = "scatterfit-result-files/1";

/// One file of the set.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct SetEntry {
    /// The file name (in the set's folder).
    pub name: String,
    /// Its size \[bytes\].
    pub bytes: u64,
    /// SHA-256 of its bytes, lower-case hex.
    pub sha256: String,
}

/// The set manifest.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct ResultSet {
    /// [`SET_FORMAT`].
    pub format: String,
    /// The run that wrote the set: `<unix seconds>.<nanoseconds>-<process id>`.
    pub run_id: String,
    /// The sample's name.
    pub sample: String,
    /// The sample folder, resolved (what `measure A -o B` compares to tell another sample's
    /// results from this one's).
    pub sample_dir: String,
    /// The files, in the order written.
    pub files: Vec<SetEntry>,
}

/// What can go wrong writing or checking a set.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ResultSetError {
    /// A file could not be read, written or removed.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The manifest is not one we wrote.
    #[error(
        "{}: not a scatterfit result-set manifest ({detail}); delete it and measure the sample \
         again",
        path.display()
    )]
    Invalid {
        /// The manifest.
        path: PathBuf,
        /// What was wrong (no content of the file).
        detail: String,
    },
    /// A file differs from what the manifest lists, or is missing from it: the folder holds files
    /// of different runs.
    #[error(
        "{}: {name} {problem} — the folder holds files of different runs (an interrupted run, two \
         runs at once, or a file edited by hand); measure the sample again (or, if you edited a \
         file on purpose, delete {SET_FILE})",
        dir.display()
    )]
    Mixed {
        /// The folder.
        dir: PathBuf,
        /// The file.
        name: String,
        /// What differs.
        problem: String,
    },
}

/// The set manifest of `dir`, if there is one.
///
/// # Errors
/// [`ResultSetError::Io`] when it exists and cannot be read; [`ResultSetError::Invalid`] when it
/// is not a manifest we wrote.
pub fn read(dir: &Path) -> Result<Option<ResultSet>, ResultSetError> {
    let path = dir.join(SET_FILE);
    if std::fs::symlink_metadata(&path).is_err() {
        return Ok(None);
    }
    let text = crate::text::read_text_file(&path).map_err(|e| ResultSetError::Invalid {
        path: path.clone(),
        detail: e.to_string(),
    })?;
    let set: ResultSet = serde_json::from_str(&text.text).map_err(|e| ResultSetError::Invalid {
        path: path.clone(),
        detail: format!("line {}, column {}", e.line(), e.column()),
    })?;
    if set.format != SET_FORMAT {
        return Err(ResultSetError::Invalid {
            path,
            detail: format!("format {}", crate::escape::token(&set.format)),
        });
    }
    Ok(Some(set))
}
