//! Shards: a deterministic slice of a run's work, so that N machines (a Slurm job array) each do
//! one and the slices add up to the whole run.
//!
//! A shard is `index/count`, 1-based (Slurm's array task ids usually start at 1). For a Monte
//! Carlo table the work is each stratum's chunks of photons ([`crate::white`]), split into
//! `count` contiguous ranges ([`Shard::chunk_range`]); a chunk's photons come from the chunk's own
//! random stream, so a shard traces exactly the photons the one-machine run traces for those
//! chunks. For a list of independent items (a study's samples, a batch's sample folders) the
//! items are dealt round-robin ([`Shard::owns`]), which spreads items of similar cost (neighbours
//! in the list) over the shards.

use std::fmt;
use std::ops::Range;
use std::str::FromStr;

use serde::{Deserialize, Serialize};

/// Shard `index` of `count` (1 ≤ index ≤ count).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(try_from = "RawShard")]
pub struct Shard {
    /// Which shard, from 1.
    index: u64,
    /// How many shards the work is split into.
    count: u64,
}

/// A shard that is not `K/N` with 1 ≤ K ≤ N.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("shard {given:?}: {why} (a shard is K/N with 1 ≤ K ≤ N, e.g. 3/8)")]
pub struct ShardError {
    /// What was given.
    pub given: String,
    /// What is wrong with it.
    pub why: &'static str,
}

impl Shard {
    /// The whole run: shard 1 of 1.
    pub const WHOLE: Shard = Shard { index: 1, count: 1 };

    /// Shard `index` of `count`.
    ///
    /// # Errors
    /// [`ShardError`] unless 1 ≤ index ≤ count.
    pub fn new(index: u64, count: u64) -> Result<Self, ShardError> {
        let given = format!("{index}/{count}");
        if count == 0 {
            return Err(ShardError {
                given,
                why: "N must be at least 1",
            });
        }
        if index == 0 || index > count {
            return Err(ShardError {
                given,
                why: "K must lie in 1…N (shards are counted from 1)",
            });
        }
        Ok(Self { index, count })
    }

    /// Which shard, from 1.
    pub fn index(&self) -> u64 {
        self.index
    }

    /// How many shards.
    pub fn count(&self) -> u64 {
        self.count
    }

    /// Whether this is the whole run (1/1).
    pub fn is_whole(&self) -> bool {
        self.count == 1
    }

    /// This shard's contiguous range of `chunks` work units: [⌊(K − 1)C/N⌋, ⌊KC/N⌋). The ranges
    /// of shards 1…N tile 0…C without gaps or overlaps; with more shards than chunks some are
    /// empty.
    pub fn chunk_range(&self, chunks: u64) -> Range<u64> {
        let at = |k: u64| (u128::from(k) * u128::from(chunks) / u128::from(self.count)) as u64;
        at(self.index - 1)..at(self.index)
    }

    /// Whether item `i` (0-based) of a list belongs to this shard: round-robin, i mod N = K − 1.
    pub fn owns(&self, i: usize) -> bool {
        i as u64 % self.count == self.index - 1
    }
}

impl fmt::Display for Shard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

impl FromStr for Shard {
    type Err = ShardError;
    fn from_str(s: &str) -> Result<Self, ShardError> {
        let bad = |why| ShardError {
            given: s.to_owned(),
            why,
        };
        let (k, n) = s.trim().split_once('/').ok_or_else(|| bad("no '/'"))?;
        let k: u64 = k
            .trim()
            .parse()
            .map_err(|_| bad("K is not a whole number"))?;
        let n: u64 = n
            .trim()
            .parse()
            .map_err(|_| bad("N is not a whole number"))?;
        Shard::new(k, n).map_err(|e| bad(e.why))
    }
}

/// The unchecked shape of [`Shard`] in files.
#[derive(Deserialize)]
struct RawShard {
    index: u64,
    count: u64,
}

impl TryFrom<RawShard> for Shard {
    type Error = ShardError;
    fn try_from(r: RawShard) -> Result<Self, ShardError> {
        Shard::new(r.index, r.count)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The ranges of all shards tile the chunks exactly once, for many (C, N).
    #[test]
    fn chunk_ranges_tile() {
        for chunks in [0u64, 1, 2, 7, 10, 64, 15_625] {
            for count in [1u64, 2, 3, 4, 8, 13, 64] {
                let mut next = 0;
                for k in 1..=count {
                    let r = Shard::new(k, count).unwrap().chunk_range(chunks);
                    assert_eq!(r.start, next, "C {chunks} N {count} K {k}");
                    assert!(r.end >= r.start);
                    next = r.end;
                }
                assert_eq!(next, chunks, "C {chunks} N {count}");
            }
        }
    }

    /// Round-robin owns every item once.
    #[test]
    fn items_owned_once() {
        for count in [1u64, 2, 5] {
            for i in 0..23 {
                let owners = (1..=count)
                    .filter(|&k| Shard::new(k, count).unwrap().owns(i))
                    .count();
                assert_eq!(owners, 1);
            }
        }
    }

    #[test]
    fn parse_and_refuse() {
        assert_eq!("3/8".parse::<Shard>().unwrap(), Shard::new(3, 8).unwrap());
        assert_eq!("3/8".parse::<Shard>().unwrap().to_string(), "3/8");
        for bad in ["0/8", "9/8", "1/0", "3", "a/8", "3/b", "-1/8", ""] {
            assert!(bad.parse::<Shard>().is_err(), "{bad}");
        }
    }
}
