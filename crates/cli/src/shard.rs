//! `--shard K/N` for the heavy commands (`table`, `study`, `batch`); the partial files they write,
//! which `scatterfit combine` adds up, are `scatterfit_lab::partial`'s.

use std::path::{Path, PathBuf};

use anyhow::bail;
use scatterfit_mc::Shard;

pub use scatterfit_lab::partial::{Job, Kind, Partial, check_set, fingerprint, read};

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
