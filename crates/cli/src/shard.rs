//! `--shard K/N` for the heavy commands (`table`, `study`, `batch`) and the partial files they
//! write, which `scatterfit combine` adds up.
//!
//! A partial file is JSON: an envelope with its provenance — the kind of run, the scatterfit
//! version, a fingerprint of everything the whole run computes (a table's spec with its seed; a
//! batch's sample list and fit options), the shard, the command line and the run's inputs — around
//! the shard's data. Its name is `<kind>-<fingerprint>-<K>-of-<N>.json` in `--partial-dir`, so
//! shards of one run land beside each other and another run's never take their names. A shard
//! whose file is already there and matches (same run, shard and version, and it parses) is not
//! redone: a resubmitted job array picks up where it stopped.

use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use scatterfit_mc::Shard;
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

/// The format tag of a partial file.
pub const PARTIAL_FORMAT: &str = "scatterfit-partial/1";

/// `--shard K/N` and where its partial file goes.
#[derive(Debug, Clone, clap::Args)]
pub struct ShardArgs {
    /// Do shard K of N of the work (1 ≤ K ≤ N; e.g. `--shard $SLURM_ARRAY_TASK_ID/8`) and write
    /// it as a partial file into --partial-dir; `scatterfit combine` adds the N files up to what
    /// one run gives. A shard whose partial file is already there and matches is skipped.
    #[arg(long, value_name = "K/N")]
    pub shard: Option<Shard>,
    /// Folder for the partial files of --shard (created; on a cluster, a shared file system).
    #[arg(long, value_name = "DIR")]
    pub partial_dir: Option<PathBuf>,
}

impl ShardArgs {
    /// The shard and its folder, when --shard is given.
    ///
    /// # Errors
    /// --shard without --partial-dir, or --partial-dir without --shard.
    pub fn get(&self) -> anyhow::Result<Option<(Shard, &Path)>> {
        match (self.shard, self.partial_dir.as_deref()) {
            (Some(s), Some(d)) => Ok(Some((s, d))),
            (None, None) => Ok(None),
            (Some(s), None) => {
                bail!("--shard {s} needs --partial-dir DIR: the folder its partial file goes into")
            }
            (None, Some(d)) => bail!(
                "--partial-dir {} is for --shard K/N; give both, or neither",
                d.display()
            ),
        }
    }
}

/// What a partial file is a part of.
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

/// The partial file of `shard` of the run `run` in `dir`.
pub fn partial_path(dir: &Path, kind: Kind, run: &str, shard: Shard) -> PathBuf {
    dir.join(partial_name(kind, run, shard))
}

/// `<kind>-<run>-<K>-of-<N>.json`, K and N zero-padded to 4 digits (so that they sort).
pub fn partial_name(kind: Kind, run: &str, shard: Shard) -> String {
    format!(
        "{}-{run}-{:04}-of-{:04}.json",
        kind.name(),
        shard.index(),
        shard.count()
    )
}

/// A shard about to run: its partial file, and the envelope's provenance.
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
    /// A file at the partial's name that is not this shard's.
    pub fn done<T: DeserializeOwned>(
        &self,
        force: bool,
        check: impl FnOnce(&T) -> bool,
    ) -> anyhow::Result<bool> {
        if !self.path.exists() {
            crate::common::check_output_dir(
                self.path.parent().unwrap_or(Path::new(".")),
                "--partial-dir",
            )?;
            return Ok(false);
        }
        let why = match read::<T>(&self.path) {
            Ok(p) if p.kind != self.kind || p.run != self.run || p.shard != self.shard => {
                "it is a part of another run".to_owned()
            }
            Ok(p) if p.version != env!("CARGO_PKG_VERSION") => {
                format!("it was written by scatterfit {}", p.version)
            }
            Ok(p) if !check(&p.data) => "its data do not fit the run".to_owned(),
            Ok(_) => return Ok(true),
            Err(e) => crate::common::error_text(&e),
        };
        if force {
            return Ok(false);
        }
        bail!(
            "{} exists but does not match shard {} of this run ({why}); remove it, or pass --force \
             to redo the shard",
            self.path.display(),
            self.shard
        )
    }

    /// Writes the partial file atomically.
    ///
    /// # Errors
    /// On a file-system error.
    pub fn write<T: Serialize>(&self, data: T) -> anyhow::Result<()> {
        let partial = Partial {
            format: PARTIAL_FORMAT.to_owned(),
            kind: self.kind,
            version: env!("CARGO_PKG_VERSION").to_owned(),
            run: self.run.clone(),
            shard: self.shard,
            command: std::env::args().collect(),
            inputs: self.inputs.clone(),
            data,
        };
        let json =
            serde_json::to_vec(&partial).context("the partial does not serialise (a defect)")?;
        if let Some(dir) = self.path.parent() {
            std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        }
        scatterfit_io::atomic::write_atomic(&self.path, &json)
            .with_context(|| format!("writing {}", self.path.display()))
    }
}

/// Reads a partial file with data of type `T`.
///
/// # Errors
/// When it cannot be read, is not a partial file of this format, or its data are not a `T`.
pub fn read<T: DeserializeOwned>(path: &Path) -> anyhow::Result<Partial<T>> {
    // The tag first (serde skips the rest without building it), so that another file is named as
    // such rather than as a damaged partial.
    #[derive(Deserialize)]
    struct Tag {
        format: Option<String>,
    }
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let tag: Tag =
        serde_json::from_str(&text).with_context(|| format!("{}: not JSON", path.display()))?;
    if tag.format.as_deref() != Some(PARTIAL_FORMAT) {
        bail!(
            "{}: not a scatterfit partial file (format {PARTIAL_FORMAT}); give the files that \
             `--shard` wrote",
            path.display()
        );
    }
    serde_json::from_str(&text)
        .with_context(|| format!("{}: a damaged partial file", path.display()))
}
