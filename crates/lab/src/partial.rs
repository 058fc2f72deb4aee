//! The partial files of a sharded run (`--shard K/N` of `table`, `batch`, `study`), which
//! `scatterfit combine` adds up.
//!
//! A partial file is JSON: an envelope with its provenance — the kind of run, the scatterfit
//! version, a fingerprint of everything the whole run computes (a table's spec with its seed; a
//! batch's sample list and fit options), the shard, the command line and the run's inputs — around
//! the shard's data. Its name is `<kind>-<fingerprint>-<K>-of-<N>.json` in the partial folder, so
//! shards of one run land beside each other and another run's never take their names. A shard
//! whose file is already there and matches (same run, shard and version, and it parses) is not
//! redone: a resubmitted job array picks up where it stopped. [`check_set`] checks that a set of
//! files is the shards 1…N of one run, once each.

use std::path::{Path, PathBuf};

use scatterfit_mc::Shard;
use serde::de::{DeserializeOwned, IgnoredAny};
use serde::{Deserialize, Serialize};

/// The format tag of a partial file.
pub const PARTIAL_FORMAT: &str = "scatterfit-partial/1";

/// The version every partial file is written with and checked against.
const VERSION: &str = env!("CARGO_PKG_VERSION");

/// Why a partial file cannot be read, written or used.
#[derive(Debug, thiserror::Error)]
pub enum PartialError {
    /// Not this run's, not this version's, or a set that is not one run's shards once each.
    #[error("{0}")]
    Refused(String),
    /// The file cannot be read.
    #[error("reading {}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// The file is not JSON, or its data are not what the run holds.
    #[error("{}: {what}", path.display())]
    Parse {
        /// The file.
        path: PathBuf,
        /// `not JSON`, or `a damaged partial file`.
        what: &'static str,
        /// Why.
        #[source]
        source: serde_json::Error,
    },
    /// The data do not serialise (a defect).
    #[error("the partial does not serialise (a defect)")]
    Serialise(#[source] serde_json::Error),
    /// The partial folder or file cannot be written.
    #[error("{what} {}", path.display())]
    Write {
        /// `creating` or `writing`.
        what: &'static str,
        /// The folder or file.
        path: PathBuf,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// The partial folder cannot take the file.
    #[error(transparent)]
    Output(#[from] scatterfit_pipeline::outputs::OutputError),
    /// A table's partial file holds no table spec.
    #[error("{}: the table spec", path.display())]
    TableSpec {
        /// The file.
        path: PathBuf,
        /// Why.
        #[source]
        source: serde_json::Error,
    },
    /// The Monte Carlo engine refused the spec or the shards' sums, with what was being done.
    #[error("{what}")]
    Table {
        /// The file being added, `combining the shards` or `smoothing the combined table`.
        what: String,
        /// The engine's reason.
        #[source]
        source: scatterfit_mc::McError,
    },
    /// The Monte Carlo engine refused the spec.
    #[error(transparent)]
    Mc(#[from] scatterfit_mc::McError),
}

/// What a partial file is a part of: the sharded command.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Kind {
    /// A Monte Carlo table (`scatterfit table`).
    Table,
    /// A batch of samples (`scatterfit batch`).
    Batch,
    /// A bias study (`scatterfit study`).
    Study,
}

impl Kind {
    /// The command's name.
    pub fn name(self) -> &'static str {
        match self {
            Kind::Table => "table",
            Kind::Batch => "batch",
            Kind::Study => "study",
        }
    }
}

/// A partial file: provenance around a shard's data.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Partial<T> {
    /// [`PARTIAL_FORMAT`].
    pub format: String,
    /// What the whole run makes.
    pub kind: Kind,
    /// The scatterfit version that wrote it (shards of different versions are not combined).
    pub version: String,
    /// FNV-1a 64 of the run's inputs as JSON: equal for every shard of one run.
    pub run: String,
    /// Which shard.
    pub shard: Shard,
    /// The command line that wrote it.
    pub command: Vec<String>,
    /// What the whole run computes from (a table's spec; a batch's samples and options).
    pub inputs: serde_json::Value,
    /// The shard's result.
    pub data: T,
}

/// FNV-1a 64 of `value`'s JSON, as 16 hex digits (the same hash as a table spec's fingerprint).
pub fn fingerprint<T: Serialize>(value: &T) -> String {
    let json = serde_json::to_string(value).unwrap_or_default();
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in json.bytes() {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    format!("{h:016x}")
}

/// The partial file of `shard` of the run `run` in `dir`: `<kind>-<run>-<K>-of-<N>.json`, K and N
/// zero-padded to 4 digits (so that they sort).
pub fn partial_path(dir: &Path, kind: Kind, run: &str, shard: Shard) -> PathBuf {
    dir.join(format!(
        "{}-{run}-{:04}-of-{:04}.json",
        kind.name(),
        shard.index(),
        shard.count()
    ))
}

/// An error and its causes joined by ": ", skipping a cause whose text the message already holds.
fn chain_text(err: &dyn std::error::Error) -> String {
    let mut text = err.to_string();
    let mut cause = err.source();
    while let Some(c) = cause {
        let t = c.to_string();
        if !text.contains(&t) {
            text.push_str(": ");
            text.push_str(&t);
        }
        cause = c.source();
    }
    text
}

/// A shard about to run: its partial file, and the envelope's provenance.
#[derive(Debug)]
pub struct Job {
    /// The partial file.
    pub path: PathBuf,
    kind: Kind,
    run: String,
    shard: Shard,
    inputs: serde_json::Value,
}

impl Job {
    /// The job for `shard` of the run whose inputs are `inputs`, its file in `dir`.
    pub fn new<I: Serialize>(dir: &Path, kind: Kind, shard: Shard, inputs: &I) -> Self {
        let run = fingerprint(inputs);
        Self {
            path: partial_path(dir, kind, &run, shard),
            kind,
            run,
            shard,
            inputs: serde_json::to_value(inputs).unwrap_or_default(),
        }
    }

    /// Whether the shard is already done: its file is there and is this shard of this run by this
    /// version, and its data parse (`check` may look further). A file there that does not match
    /// is an error unless `force` (then it is replaced).
    ///
    /// # Errors
    /// A file at the partial's name that is not this shard's; a partial folder that cannot take
    /// the file.
    pub fn done<T: DeserializeOwned>(
        &self,
        force: bool,
        check: impl FnOnce(&T) -> bool,
    ) -> Result<bool, PartialError> {
        if !self.path.exists() {
            scatterfit_pipeline::outputs::check_output_dir(
                self.path.parent().unwrap_or(Path::new(".")),
                "--partial-dir",
            )?;
            return Ok(false);
        }
        let why = match read::<T>(&self.path) {
            Ok(p) if p.kind != self.kind || p.run != self.run || p.shard != self.shard => {
                "it is a part of another run".to_owned()
            }
            Ok(p) if p.version != VERSION => format!("it was written by scatterfit {}", p.version),
            Ok(p) if !check(&p.data) => "its data do not fit the run".to_owned(),
            Ok(_) => return Ok(true),
            Err(e) => chain_text(&e),
        };
        if force {
            return Ok(false);
        }
        Err(PartialError::Refused(format!(
            "{} exists but does not match shard {} of this run ({why}); remove it, or pass --force \
             to redo the shard",
            self.path.display(),
            self.shard
        )))
    }

    /// Writes the partial file atomically, `command` the command line that made it.
    ///
    /// # Errors
    /// On a file-system error.
    pub fn write<T: Serialize>(&self, data: T, command: Vec<String>) -> Result<(), PartialError> {
        let partial = Partial {
            format: PARTIAL_FORMAT.to_owned(),
            kind: self.kind,
            version: VERSION.to_owned(),
            run: self.run.clone(),
            shard: self.shard,
            command,
            inputs: self.inputs.clone(),
            data,
        };
        let json = serde_json::to_vec(&partial).map_err(PartialError::Serialise)?;
        if let Some(dir) = self.path.parent() {
            std::fs::create_dir_all(dir).map_err(|source| PartialError::Write {
                what: "creating",
                path: dir.to_path_buf(),
                source,
            })?;
        }
        scatterfit_io::atomic::write_atomic(&self.path, &json).map_err(|source| {
            PartialError::Write {
                what: "writing",
                path: self.path.clone(),
                source,
            }
        })
    }
}

/// Reads a partial file with data of type `T`.
///
/// # Errors
/// When it cannot be read, is not a partial file of this format, or its data are not a `T`.
pub fn read<T: DeserializeOwned>(path: &Path) -> Result<Partial<T>, PartialError> {
    // The tag first (serde skips the rest without building it), so that another file is named as
    // such rather than as a damaged partial.
    #[derive(Deserialize)]
    struct Tag {
        format: Option<String>,
    }
    let text = std::fs::read_to_string(path).map_err(|source| PartialError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    let parse = |what, source| PartialError::Parse {
        path: path.to_path_buf(),
        what,
        source,
    };
    let tag: Tag = serde_json::from_str(&text).map_err(|e| parse("not JSON", e))?;
    if tag.format.as_deref() != Some(PARTIAL_FORMAT) {
        return Err(PartialError::Refused(format!(
            "{}: not a scatterfit partial file (format {PARTIAL_FORMAT}); give the files that \
             `--shard` wrote",
            path.display()
        )));
    }
    serde_json::from_str(&text).map_err(|e| parse("a damaged partial file", e))
}

/// Reads every file's envelope and checks that they are the shards 1…N of one run, once each, by
/// this version.
///
/// # Errors
/// A file of another version or run, of another split, a shard given twice, or shards missing
/// (named by the file names they would have beside the first).
pub fn check_set(paths: &[PathBuf]) -> Result<Vec<Partial<IgnoredAny>>, PartialError> {
    let refuse = |text: String| Err(PartialError::Refused(text));
    let mut parts = Vec::with_capacity(paths.len());
    for p in paths {
        parts.push(read::<IgnoredAny>(p)?);
    }
    let Some(first) = parts.first() else {
        return refuse("no partial files given".into());
    };
    for (p, path) in parts.iter().zip(paths) {
        if p.version != VERSION {
            return refuse(format!(
                "{} was written by scatterfit {}, this is {VERSION}: redo its shards with this \
                 version",
                path.display(),
                p.version
            ));
        }
        if p.kind != first.kind || p.run != first.run {
            return refuse(format!(
                "{} is a shard of another run ({} {}) than {} ({} {}): a foreign shard; give the \
                 files of one run",
                path.display(),
                p.kind.name(),
                p.run,
                paths[0].display(),
                first.kind.name(),
                first.run
            ));
        }
        if p.shard.count() != first.shard.count() {
            return refuse(format!(
                "{} is shard {} but {} is of {} shards: give the files of one split",
                path.display(),
                p.shard,
                paths[0].display(),
                first.shard.count()
            ));
        }
    }
    let n = first.shard.count();
    let mut seen: Vec<Option<&PathBuf>> = vec![None; n as usize];
    for (p, path) in parts.iter().zip(paths) {
        let slot = &mut seen[p.shard.index() as usize - 1];
        if let Some(other) = slot {
            return refuse(format!(
                "shard {} is given twice: {} and {}",
                p.shard,
                other.display(),
                path.display()
            ));
        }
        *slot = Some(path);
    }
    let dir = paths[0].parent().unwrap_or(Path::new("."));
    let missing: Vec<String> = (1..=n)
        .filter(|k| seen[*k as usize - 1].is_none())
        .filter_map(|k| Shard::new(k, n).ok())
        .map(|shard| {
            partial_path(dir, first.kind, &first.run, shard)
                .display()
                .to_string()
        })
        .collect();
    if !missing.is_empty() {
        return refuse(format!(
            "{} of {n} shards missing: {}; run them (a resubmitted job array does only these) and \
             combine again",
            missing.len(),
            missing.join(", ")
        ));
    }
    Ok(parts)
}

/// The table of a sharded `scatterfit table` run from its `partials` (checked by [`check_set`]:
/// `count` shards of one run): the spec from the first file's run `inputs`, then each file's exact
/// sums added into the running sums one at a time (memory: the sums and one part, not every file
/// at once), smoothed once — the table the run on one machine builds, byte for byte.
///
/// # Errors
/// A damaged partial file, a spec the engine refuses, shards that do not add up (named).
pub fn combine_table(
    inputs: &serde_json::Value,
    count: u64,
    partials: &[PathBuf],
) -> Result<(scatterfit_mc::McTableSpec, scatterfit_mc::McTable), PartialError> {
    use scatterfit_mc::white::{Combiner, WhitePartial};
    let first = partials.first().cloned().unwrap_or_default();
    let spec: scatterfit_mc::McTableSpec =
        serde_json::from_value(inputs.clone()).map_err(|source| PartialError::TableSpec {
            path: first,
            source,
        })?;
    let table_error = |what: String| move |source| PartialError::Table { what, source };
    let mut combiner = Combiner::new(spec.white()?, count)?;
    for path in partials {
        let p = read::<WhitePartial>(path)?;
        combiner
            .add(&p.data)
            .map_err(table_error(path.display().to_string()))?;
    }
    let tally = combiner
        .finish()
        .map_err(table_error("combining the shards".into()))?;
    let table = scatterfit_mc::McTable::from_tally(&spec, &tally)
        .map_err(table_error("smoothing the combined table".into()))?;
    Ok((spec, table))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn shard(k: u64, n: u64) -> Shard {
        Shard::new(k, n).unwrap()
    }

    #[test]
    fn a_shard_is_written_found_done_and_refused_when_foreign() {
        let dir = tempfile::tempdir().unwrap();
        let job = Job::new(dir.path(), Kind::Table, shard(2, 3), &[1.5, 2.0]);
        let name = job.path.file_name().unwrap().to_string_lossy().into_owned();
        assert!(
            name.starts_with("table-") && name.ends_with("-0002-of-0003.json"),
            "{name}"
        );
        assert!(!job.done::<Vec<u32>>(false, |_| true).unwrap());
        job.write(vec![7u32, 8], vec!["scatterfit".into()]).unwrap();
        assert!(job.done::<Vec<u32>>(false, |d| d == &[7, 8]).unwrap());
        let p = read::<Vec<u32>>(&job.path).unwrap();
        assert_eq!(
            (p.kind, p.shard, p.data),
            (Kind::Table, shard(2, 3), vec![7, 8])
        );
        // The same file name for other inputs cannot happen; the same inputs, other data can.
        let e = job
            .done::<Vec<u32>>(false, |_| false)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("does not match shard 2/3 of this run (its data do not fit"),
            "{e}"
        );
        assert!(!job.done::<Vec<u32>>(true, |_| false).unwrap());
    }

    #[test]
    fn a_set_must_be_one_runs_shards_once_each() {
        let dir = tempfile::tempdir().unwrap();
        let write = |k, n, inputs: &str| {
            let job = Job::new(dir.path(), Kind::Batch, shard(k, n), &inputs);
            job.write(0u8, vec![]).unwrap();
            job.path
        };
        let (a, b, c) = (write(1, 3, "x"), write(2, 3, "x"), write(3, 3, "x"));
        assert_eq!(
            check_set(&[c.clone(), a.clone(), b.clone()]).unwrap().len(),
            3
        );
        let e = check_set(&[a.clone(), c.clone()]).unwrap_err().to_string();
        assert!(e.starts_with("1 of 3 shards missing: "), "{e}");
        assert!(e.contains("-0002-of-0003.json"), "{e}");
        let e = check_set(&[a.clone(), a.clone(), b.clone()])
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("shard 1/3 is given twice"), "{e}");
        let other = write(2, 3, "y");
        let e = check_set(&[a, other, c]).unwrap_err().to_string();
        assert!(e.contains("a foreign shard"), "{e}");
        let junk = dir.path().join("junk.json");
        std::fs::write(&junk, "{\"format\": \"x\"}").unwrap();
        let e = check_set(&[junk]).unwrap_err().to_string();
        assert!(e.contains("not a scatterfit partial file"), "{e}");
    }
}
