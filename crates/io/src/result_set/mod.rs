//! A sample's result files as one set a reader can trust.
//!
//! Each result file is written atomically, but a run killed between two of them (or two runs into
//! the same folder) would leave a folder of old and new files — a `result.json` beside the
//! `profile.csv` of another run — that look complete. So a run:
//!
//! 1. removes the folder's set manifest, [`SET_FILE`], first ([`begin`]): from now until the end of
//!    the run the folder has no manifest, which says "incomplete";
//! 2. writes its files (each atomically);
//! 3. writes [`SET_FILE`] **last** ([`finish`]): the run's id, the sample (name and resolved
//!    folder), and every file's name, size and SHA-256.
//!
//! A reader ([`verify`]) that needs several files to belong together (`render --profile`: the
//! result and its profile) checks them against the manifest: all listed with matching hashes is a
//! complete set of one run; a mismatch is a mix (refused); no manifest is a run that was
//! interrupted, or a folder written before manifests existed (the reader says it cannot tell).

use std::path::Path;

use sha2::{Digest, Sha256};

pub(crate) mod set_file;

pub use set_file::{ResultSet, ResultSetError, SET_FILE, SET_FORMAT, SetEntry, read};

/// What [`verify`] found.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub enum SetStatus {
    /// Every file asked for is listed in the manifest with its hash: one run's complete set.
    Complete(ResultSet),
    /// No manifest: an interrupted run, or results written before manifests existed.
    Unknown,
}

/// Removes `dir`'s set manifest (if any) before a run writes its files: from now until [`finish`]
/// the folder says "incomplete". A link of that name is removed itself (never followed).
///
/// # Errors
/// [`ResultSetError::Io`] when it exists and cannot be removed.
pub fn begin(dir: &Path) -> Result<(), ResultSetError> {
    let path = dir.join(SET_FILE);
    match std::fs::remove_file(&path) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
            Err(ResultSetError::Io { path, source: e })
        }
        _ => Ok(()),
    }
}

/// A run id: the time and the process.
pub fn new_run_id() -> String {
    let t = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .unwrap_or_default();
    format!(
        "{}.{:09}-{}",
        t.as_secs(),
        t.subsec_nanos(),
        std::process::id()
    )
}

/// Hashes the files `names` of `dir` as written and writes the set manifest last (atomically).
///
/// # Errors
/// [`ResultSetError::Io`] for a file that cannot be read back or a manifest that cannot be written.
pub fn finish(
    dir: &Path,
    names: &[&str],
    sample: &str,
    sample_dir: &Path,
) -> Result<ResultSet, ResultSetError> {
    let files = names
        .iter()
        .map(|name| {
            let (bytes, sha256) = hash(&dir.join(name))?;
            Ok(SetEntry {
                name: (*name).to_string(),
                bytes,
                sha256,
            })
        })
        .collect::<Result<Vec<_>, ResultSetError>>()?;
    let set = ResultSet {
        format: SET_FORMAT.into(),
        run_id: new_run_id(),
        sample: sample.to_string(),
        sample_dir: std::fs::canonicalize(sample_dir)
            .unwrap_or_else(|_| sample_dir.to_path_buf())
            .to_string_lossy()
            .into_owned(),
        files,
    };
    let path = dir.join(SET_FILE);
    let mut text = serde_json::to_string_pretty(&set).map_err(|e| ResultSetError::Invalid {
        path: path.clone(),
        detail: e.to_string(),
    })?;
    text.push('\n');
    crate::atomic::write_atomic(&path, text.as_bytes())
        .map_err(|source| ResultSetError::Io { path, source })?;
    Ok(set)
}

/// Size and SHA-256 of a file (a regular file of at most the memory budget).
fn hash(path: &Path) -> Result<(u64, String), ResultSetError> {
    let bytes = scatterfit_safefs::read::read_limited(path, crate::budget::memory_budget_bytes())
        .map_err(|source| ResultSetError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let digest = Sha256::digest(&bytes);
    Ok((
        bytes.len() as u64,
        digest.iter().map(|b| format!("{b:02x}")).collect(),
    ))
}

/// Checks that the files `names` of `dir` are one run's: listed in the set manifest with the
/// size and hash they have now.
///
/// # Errors
/// [`ResultSetError::Mixed`] naming the first file that differs or is not listed; the errors of
/// [`read`] and of reading a file.
pub fn verify(dir: &Path, names: &[&str]) -> Result<SetStatus, ResultSetError> {
    let Some(set) = read(dir)? else {
        return Ok(SetStatus::Unknown);
    };
    for name in names {
        let mixed = |problem: String| ResultSetError::Mixed {
            dir: dir.to_path_buf(),
            name: (*name).to_string(),
            problem,
        };
        let Some(entry) = set.files.iter().find(|e| e.name == *name) else {
            return Err(mixed(format!("is not listed in {SET_FILE}")));
        };
        let path = dir.join(name);
        if std::fs::symlink_metadata(&path).is_err() {
            return Err(mixed(format!("is listed in {SET_FILE} but missing")));
        }
        let (bytes, sha256) = hash(&path)?;
        if bytes != entry.bytes || sha256 != entry.sha256 {
            return Err(mixed(format!(
                "differs from the file run {} wrote (listed in {SET_FILE})",
                crate::escape::token(&set.run_id)
            )));
        }
    }
    Ok(SetStatus::Complete(set))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::fs;

    const NAMES: [&str; 3] = ["profile.csv", "result.json", "fit.png"];

    fn run(dir: &Path, tag: &str, crash_after: usize) -> Result<(), ResultSetError> {
        begin(dir)?;
        for (i, name) in NAMES.iter().enumerate() {
            if i == crash_after {
                return Ok(()); // the process died here: no manifest
            }
            crate::atomic::write_atomic(&dir.join(name), format!("{tag} {name}").as_bytes())
                .unwrap();
        }
        finish(dir, &NAMES, "wood", dir)?;
        Ok(())
    }

    #[test]
    fn a_complete_run_verifies() {
        let dir = tempfile::tempdir().unwrap();
        run(dir.path(), "old", usize::MAX).unwrap();
        let SetStatus::Complete(set) = verify(dir.path(), &["result.json", "profile.csv"]).unwrap()
        else {
            panic!("not complete")
        };
        assert_eq!(set.files.len(), 3);
        assert_eq!(set.sample, "wood");
    }

    /// Fault injection: a second run dies after each of its writes in turn. The folder then holds
    /// new and old files; a reader never takes it for a complete set — it has no manifest (the
    /// run removed the old one first), and had the old manifest been kept, the hashes would tell.
    #[test]
    fn a_run_killed_between_writes_is_never_a_complete_set() {
        for crash_after in 0..NAMES.len() {
            let dir = tempfile::tempdir().unwrap();
            run(dir.path(), "old", usize::MAX).unwrap();
            let old_manifest = fs::read(dir.path().join(SET_FILE)).unwrap();
            run(dir.path(), "new", crash_after).unwrap();
            assert_eq!(
                verify(dir.path(), &["result.json", "profile.csv"]).unwrap(),
                SetStatus::Unknown,
                "crash after {crash_after}"
            );
            // Had the run not removed the old manifest, the mix would still be caught.
            fs::write(dir.path().join(SET_FILE), &old_manifest).unwrap();
            let v = verify(dir.path(), &["profile.csv", "result.json"]);
            if crash_after == 0 {
                assert!(v.is_ok(), "nothing new was written");
            } else {
                let e = v.unwrap_err().to_string();
                assert!(e.contains("different runs"), "{e}");
            }
        }
    }

    #[test]
    fn files_not_listed_or_edited_are_a_mix() {
        let dir = tempfile::tempdir().unwrap();
        run(dir.path(), "old", usize::MAX).unwrap();
        let e = verify(dir.path(), &["result.md"]).unwrap_err().to_string();
        assert!(e.contains("not listed"), "{e}");
        fs::write(dir.path().join("result.json"), b"edited").unwrap();
        let e = verify(dir.path(), &["result.json"])
            .unwrap_err()
            .to_string();
        assert!(e.contains("result.json differs"), "{e}");
        fs::write(dir.path().join(SET_FILE), b"root:$6$SECRET").unwrap();
        let e = verify(dir.path(), &["result.json"])
            .unwrap_err()
            .to_string();
        assert!(
            !e.contains("SECRET") && e.contains("not a scatterfit"),
            "{e}"
        );
    }
}
