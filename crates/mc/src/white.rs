//! "White" Monte Carlo for a half-space: one photon run serves every albedo.
//!
//! At σt = 1 the photon paths in a homogeneous half-space do not depend on the single-scattering
//! albedo a: with MCML's implicit capture (docs/physics.md §4.1, `Drop`) a photon that leaves the surface
//! after n interactions carries the weight (1 − R_sp)·aⁿ, whatever else happened. So we trace
//! non-absorbing photons once and score each escape with aₖⁿ for every albedo aₖ of the table — the
//! "white Monte Carlo" of Pifferi et al. 1998 (Appl. Opt. 37:2774) and Alerstam, Andersson-Engels &
//! Svensson 2008 (J. Biomed. Opt. 13:041304), here with MCML's boundary physics: statistical Fresnel
//! reflection at the surface (`CrossOrNot`), Henyey–Greenstein scattering (`Spin`), leftover step
//! after a reflection (`sleft`). Without absorption there is no roulette; a photon is stopped after
//! `max_interactions` interactions instead, which drops weight aⁿ ≤ a_max^max_interactions (chosen
//! ≤ e⁻¹⁸ by [`WhiteSpec::new`]), a bias below 1e-8 of the total.
//!
//! Stratified by path length: a table is the sum of independent runs ("strata") k = 0, 1, …, each
//! scoring only the escapes after bₖ₋₁ ≤ n < bₖ interactions and stopping its photons at n = bₖ
//! (b₋₁ = 0, the last bₖ is the cap above). Every escape belongs to exactly one stratum, so the sum is
//! unbiased, and each stratum gets its own photon count: short paths (near the source, and every
//! low albedo) are cheap and get many photons, long paths (far from the source at high albedo) are
//! costly and get fewer. Variances add.
//!
//! Scores are per photon, so standard errors come from per-photon second moments, as in the engine;
//! photons run in chunks with one random stream per chunk, so a seed gives the same tally bit for bit
//! on any number of threads.
//!
//! Shards ([`simulate_shard`], [`combine`]): a run split over machines traces, per stratum, a
//! contiguous range of its chunks ([`Shard::chunk_range`] over groups of ⌈chunks/1024⌉ chunks) and
//! keeps its sums *exactly* ([`ExactSum`]: each group's f64 sums — its chunks added in chunk order,
//! an order the spec fixes — added without rounding), so that the shards' sums added in any order
//! are the one run's sums, and rounding them once gives the same f64 bit for bit.
//! [`simulate`] is the one-shard case of the same path: a table built on one machine and one merged
//! from N shards are the same bytes.

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::engine::{CHUNK_PHOTONS, spin_isotropic};
use crate::error::{McError, Result, check};
use crate::exact::ExactSum;
use crate::fresnel::fresnel_mcml;
use crate::grid::RadialGrid;
use crate::phase::{HgSampler, scatter_hg};
use crate::rng::{PhotonRng, stream};
use crate::shard::Shard;

/// Survival probability of the interaction-count roulette.
pub const ROULETTE_SURVIVAL: f64 = 0.25;

/// Chunks traced in parallel before their tallies are summed (in chunk order).
const WAVE_CHUNKS: u64 = 32;

/// One stratum of a white run: its photons and the interaction count at which they stop.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Stratum {
    /// Photons traced in this stratum.
    pub photons: u64,
    /// Photons stop when they reach this many interactions; escapes with n below it (and at least
    /// the previous stratum's bound) are scored.
    pub max_interactions: u64,
}

/// What a white run traces and tallies. Lengths are optical (σt = 1).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WhiteSpec {
    /// Relative refractive index η of the half-space (outside index 1).
    pub eta: f64,
    /// Henyey–Greenstein asymmetry g.
    pub g: f64,
    /// Single-scattering albedos a = σs/σt scored, strictly increasing in (0, 1) (a = α′ when g = 0).
    pub albedos: Vec<f64>,
    /// Radial bin edges in mean free paths 1/σt (first edge 0).
    pub radial_edges: Vec<f64>,
    /// Seed of the random streams (stratum k uses its own streams derived from it).
    pub seed: u64,
    /// The strata, by increasing `max_interactions`; the last one's is the cap.
    pub strata: Vec<Stratum>,
    /// Interactions at which the count roulette is played (never, if beyond the cap).
    pub roulette_interactions: u64,
}

impl WhiteSpec {
    /// A spec with strata of `photons[k]` photons separated at the interaction counts `bounds`
    /// (`bounds.len() == photons.len() − 1`, increasing), the last stratum ending at the cap
    /// ⌈12/(−ln a_max)⌉ (at most e⁻¹² of a photon's weight dropped at the largest albedo), and the
    /// roulette where the weight is e⁻¹² at a = min(0.999, a_max), ⌈12/(−ln a)⌉.
    ///
    /// # Errors
    /// `InvalidParameter` for a bad field (see [`WhiteSpec::validate`]).
    pub fn new(
        eta: f64,
        g: f64,
        albedos: Vec<f64>,
        radial_edges: Vec<f64>,
        photons: &[u64],
        bounds: &[u64],
        seed: u64,
    ) -> Result<Self> {
        check(
            !photons.is_empty() && bounds.len() + 1 == photons.len(),
            "bounds",
            bounds.len() as f64,
            "need one bound fewer than strata",
        )?;
        let a_max = albedos.last().copied().unwrap_or(0.5);
        let cap = (12.0 / -a_max.ln()).ceil();
        let roulette = (12.0 / -a_max.min(0.999).ln()).ceil();
        let cap = if cap.is_finite() { cap as u64 } else { 0 };
        let strata = photons
            .iter()
            .enumerate()
            .map(|(k, &p)| Stratum {
                photons: p,
                max_interactions: bounds.get(k).copied().unwrap_or(cap),
            })
            .collect();
        let spec = Self {
            eta,
            g,
            albedos,
            radial_edges,
            seed,
            strata,
            roulette_interactions: if roulette.is_finite() {
                roulette as u64
            } else {
                0
            },
        };
        spec.validate()?;
        Ok(spec)
    }

    /// Photons over all strata.
    pub fn photons(&self) -> u64 {
        self.strata.iter().map(|s| s.photons).sum()
    }

    /// Photons `shard` traces, over all strata ([`simulate_shard`]).
    pub fn shard_photons(&self, shard: Shard) -> u64 {
        self.strata
            .iter()
            .map(|s| photons_in(&stratum_chunks(shard, s.photons), s.photons))
            .sum()
    }

    /// Checks every field.
    ///
    /// # Errors
    /// `InvalidParameter` naming the first bad field.
    pub fn validate(&self) -> Result<()> {
        check(
            self.eta.is_finite() && self.eta >= 1.0,
            "eta",
            self.eta,
            "η must be finite and ≥ 1",
        )?;
        check(
            self.g.is_finite() && self.g.abs() < 1.0,
            "g",
            self.g,
            "g must lie in (−1, 1)",
        )?;
        check(!self.strata.is_empty(), "strata", 0.0, "need a stratum")?;
        let mut prev = 0;
        for s in &self.strata {
            check(s.photons > 0, "photons", 0.0, "every stratum needs photons")?;
            check(
                s.max_interactions > prev,
                "max_interactions",
                s.max_interactions as f64,
                "strata must end at increasing interaction counts",
            )?;
            prev = s.max_interactions;
        }
        check(
            !self.albedos.is_empty(),
            "albedos",
            0.0,
            "need at least one albedo",
        )?;
        for w in self.albedos.windows(2) {
            check(
                w[1] > w[0],
                "albedos",
                w[1],
                "albedos must be strictly increasing",
            )?;
        }
        let (lo, hi) = (self.albedos[0], self.albedos[self.albedos.len() - 1]);
        check(lo > 0.0, "albedos", lo, "albedos must be > 0")?;
        check(hi < 1.0, "albedos", hi, "albedos must be < 1")?;
        RadialGrid::from_edges(self.radial_edges.clone())?;
        Ok(())
    }
}

/// The tally of a white run: Rd per albedo and radial bin [per mean free path², at σt = 1], totals,
/// all with standard errors. Row-major: albedo k, bin j at `k * bins + j`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WhiteTally {
    /// The spec that made it.
    pub spec: WhiteSpec,
    /// R̂(bin; aₖ): reflected weight / (photons × annulus area).
    pub rd: Vec<f64>,
    /// Standard errors of `rd`.
    pub rd_stderr: Vec<f64>,
    /// Total diffuse reflectance per albedo (excluding R_sp), including photons beyond the last bin.
    pub rd_total: Vec<f64>,
    /// Standard errors of `rd_total`.
    pub rd_total_stderr: Vec<f64>,
    /// Photons of the last stratum stopped by the interaction cap.
    pub capped: u64,
    /// Interactions traced in all (a measure of cost).
    pub interactions: u64,
}

impl WhiteTally {
    /// Number of radial bins.
    pub fn bins(&self) -> usize {
        self.spec.radial_edges.len() - 1
    }
}

/// Per-chunk sums of per-photon scores and their squares.
struct Accum {
    w: Vec<f64>,
    w2: Vec<f64>,
    tot: Vec<f64>,
    tot2: Vec<f64>,
    capped: u64,
    interactions: u64,
}

impl Accum {
    fn new(k: usize, bins: usize) -> Self {
        Self {
            w: vec![0.0; k * bins],
            w2: vec![0.0; k * bins],
            tot: vec![0.0; k],
            tot2: vec![0.0; k],
            capped: 0,
            interactions: 0,
        }
    }

    /// Adds another tally's f64 sums (within a group of chunks, in chunk order).
    fn add(&mut self, o: &Accum) {
        for (a, b) in [
            (&mut self.w, &o.w),
            (&mut self.w2, &o.w2),
            (&mut self.tot, &o.tot),
            (&mut self.tot2, &o.tot2),
        ] {
            for (x, y) in a.iter_mut().zip(b) {
                *x += y;
            }
        }
        self.capped += o.capped;
        self.interactions += o.interactions;
    }
}

/// One stratum's share of a sharded white run: its chunk range and the exact sums of the per-photon
/// scores over those chunks (row-major as [`WhiteTally`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StratumSums {
    /// The chunks traced, [first, end) of the stratum's ⌈photons / CHUNK_PHOTONS⌉.
    pub chunks: [u64; 2],
    /// Σ score per (albedo, bin).
    pub w: Vec<ExactSum>,
    /// Σ score² per (albedo, bin).
    pub w2: Vec<ExactSum>,
    /// Σ score per albedo (all radii).
    pub tot: Vec<ExactSum>,
    /// Σ score² per albedo.
    pub tot2: Vec<ExactSum>,
    /// Photons stopped by the stratum's interaction cap.
    pub capped: u64,
    /// Interactions traced.
    pub interactions: u64,
}

/// A shard's part of a white run ([`simulate_shard`]): exact sums per stratum, to be added to the
/// other shards' by [`combine`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WhitePartial {
    /// The whole run's spec.
    pub spec: WhiteSpec,
    /// Which slice of it this is.
    pub shard: Shard,
    /// Per stratum of `spec`.
    pub strata: Vec<StratumSums>,
}

/// Runs the white simulation on the current rayon pool, stratum after stratum; `progress(done)`
/// counts photons over all strata. The one-shard case of [`simulate_shard`] and [`combine`].
///
/// # Errors
/// `InvalidParameter` for a bad spec.
pub fn simulate(spec: &WhiteSpec, progress: &(dyn Fn(u64) + Sync)) -> Result<WhiteTally> {
    combine(&[simulate_shard(spec, Shard::WHOLE, progress)?])
}

/// Most groups of chunks per stratum. A group's chunks are summed in f64 in chunk order (fixed by
/// the spec, whatever the shards) and each group's sums are then added exactly: exact additions
/// cost about as much as tracing a chunk of short paths, so grouping keeps them to ≤ 1024 per
/// stratum (cells × 1024), while a stratum still splits into up to 1024 shards.
const GROUPS_PER_STRATUM: u64 = 1024;

/// Chunks per group for a stratum of `photons` photons: ⌈chunks / 1024⌉.
fn group_chunks(photons: u64) -> u64 {
    photons
        .div_ceil(CHUNK_PHOTONS)
        .div_ceil(GROUPS_PER_STRATUM)
        .max(1)
}

/// The chunks `shard` traces in a stratum of `photons` photons: its range of the stratum's groups
/// ([`Shard::chunk_range`] over the groups), in chunks.
fn stratum_chunks(shard: Shard, photons: u64) -> std::ops::Range<u64> {
    let chunks = photons.div_ceil(CHUNK_PHOTONS);
    let per = group_chunks(photons);
    let groups = shard.chunk_range(chunks.div_ceil(per));
    (groups.start * per).min(chunks)..(groups.end * per).min(chunks)
}

/// Photons of a stratum traced by the chunks `range`.
fn photons_in(range: &std::ops::Range<u64>, photons: u64) -> u64 {
    (range.end * CHUNK_PHOTONS).min(photons) - (range.start * CHUNK_PHOTONS).min(photons)
}

/// Runs `shard`'s slice of the white simulation (per stratum, its range of chunks) on the current
/// rayon pool and keeps the sums exactly; `progress(done)` counts the shard's photons.
///
/// # Errors
/// `InvalidParameter` for a bad spec.
pub fn simulate_shard(
    spec: &WhiteSpec,
    shard: Shard,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<WhitePartial> {
    spec.validate()?;
    let grid = RadialGrid::from_edges(spec.radial_edges.clone())?;
    let bins = grid.bins();
    let k = spec.albedos.len();
    let ln_a: Vec<f64> = spec.albedos.iter().map(|a| a.ln()).collect();
    let cos_crit = if spec.eta > 1.0 {
        (1.0 - 1.0 / (spec.eta * spec.eta)).sqrt()
    } else {
        0.0
    };
    let mut strata = Vec::with_capacity(spec.strata.len());
    let mut done_before = 0;
    let mut min_n = 0;
    for (si, stratum) in spec.strata.iter().enumerate() {
        let tracer = Tracer {
            eta: spec.eta,
            g: spec.g,
            hg: HgSampler::new(spec.g),
            cos_crit,
            min_n,
            max_n: stratum.max_interactions,
            roulette_n: spec.roulette_interactions,
            grid: &grid,
            ln_a: &ln_a,
            bins,
        };
        let photons = stratum.photons;
        // Stratum k's streams: (seed mixed with k, chunk index).
        let seed = spec.seed ^ (si as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15);
        let range = stratum_chunks(shard, photons);
        let per_group = group_chunks(photons);
        let mut group = Accum::new(k, bins);
        let mut sums = StratumSums {
            chunks: [range.start, range.end],
            w: vec![ExactSum::new(); k * bins],
            w2: vec![ExactSum::new(); k * bins],
            tot: vec![ExactSum::new(); k],
            tot2: vec![ExactSum::new(); k],
            capped: 0,
            interactions: 0,
        };
        let mut first = range.start;
        while first < range.end {
            let last = (first + WAVE_CHUNKS).min(range.end);
            let wave: Vec<Accum> = (first..last)
                .into_par_iter()
                .map(|c| {
                    let count = CHUNK_PHOTONS.min(photons - c * CHUNK_PHOTONS);
                    let mut acc = Accum::new(k, bins);
                    let mut rng = stream(seed, c);
                    let mut w = vec![0.0; k];
                    if tracer.g == 0.0 {
                        for _ in 0..count {
                            tracer.trace::<false>(&mut rng, &mut acc, &mut w);
                        }
                    } else {
                        for _ in 0..count {
                            tracer.trace::<true>(&mut rng, &mut acc, &mut w);
                        }
                    }
                    acc
                })
                .collect();
            // In chunk order: f64 sums within a group, each finished group added exactly.
            for (c, acc) in (first..last).zip(&wave) {
                group.add(acc);
                if (c + 1) % per_group == 0 || c + 1 == range.end {
                    sums.add_exactly(&group);
                    group = Accum::new(k, bins);
                }
            }
            first = last;
            progress(done_before + photons_in(&(range.start..last), photons));
        }
        done_before += photons_in(&range, photons);
        strata.push(sums);
        min_n = stratum.max_interactions;
    }
    Ok(WhitePartial {
        spec: spec.clone(),
        shard,
        strata,
    })
}

impl StratumSums {
    /// Adds a chunk's f64 sums exactly.
    fn add_exactly(&mut self, acc: &Accum) {
        for (pairs, xs) in [
            (&mut self.w, &acc.w),
            (&mut self.w2, &acc.w2),
            (&mut self.tot, &acc.tot),
            (&mut self.tot2, &acc.tot2),
        ] {
            for (s, &x) in pairs.iter_mut().zip(xs) {
                s.add(x);
            }
        }
        self.capped += acc.capped;
        self.interactions += acc.interactions;
    }
}

/// The tally of a whole run from its shards' parts: every shard 1…N of one spec exactly once, in
/// any order. The sums are added exactly and rounded once, so the result does not depend on N or
/// on the order of `parts`. ([`Combiner`] does the same one part at a time.)
///
/// # Errors
/// [`McError::Shards`] for an empty list, parts of different specs or shard counts, a shard
/// missing or given twice, or a part whose chunk ranges or sums do not fit its spec;
/// `InvalidParameter` for a bad spec.
pub fn combine(parts: &[WhitePartial]) -> Result<WhiteTally> {
    let Some(first) = parts.first() else {
        return Err(McError::Shards {
            message: "no parts to combine".into(),
        });
    };
    let mut c = Combiner::new(first.spec.clone(), first.shard.count())?;
    for p in parts {
        c.add(p)?;
    }
    c.finish()
}

/// Adds the parts of a sharded white run one at a time, exactly (so that only the running sums and
/// the part being added need memory: a merge of 64 parts of a shipped table holds two, not 64), and
/// makes the tally once every shard is in.
#[derive(Debug, Clone)]
pub struct Combiner {
    spec: WhiteSpec,
    count: u64,
    seen: Vec<bool>,
    strata: Vec<StratumSums>,
}

impl Combiner {
    /// A combiner for the `count` shards of the run `spec`.
    ///
    /// # Errors
    /// `InvalidParameter` for a bad spec; [`McError::Shards`] for no shards.
    pub fn new(spec: WhiteSpec, count: u64) -> Result<Self> {
        spec.validate()?;
        if count == 0 {
            return Err(McError::Shards {
                message: "a run of 0 shards".into(),
            });
        }
        let bins = spec.radial_edges.len() - 1;
        let k = spec.albedos.len();
        let strata = spec
            .strata
            .iter()
            .map(|_| StratumSums {
                chunks: [0, 0],
                w: vec![ExactSum::new(); k * bins],
                w2: vec![ExactSum::new(); k * bins],
                tot: vec![ExactSum::new(); k],
                tot2: vec![ExactSum::new(); k],
                capped: 0,
                interactions: 0,
            })
            .collect();
        Ok(Self {
            seen: vec![false; count as usize],
            spec,
            count,
            strata,
        })
    }

    /// Adds a part's sums exactly.
    ///
    /// # Errors
    /// [`McError::Shards`] for a part of another spec or shard count, a shard given twice, or a
    /// part whose chunk ranges or sums do not fit its spec (nothing is added then).
    pub fn add(&mut self, p: &WhitePartial) -> Result<()> {
        let bad = |message: String| Err(McError::Shards { message });
        if p.spec != self.spec {
            return bad(format!(
                "shard {} was made from another spec than the others",
                p.shard
            ));
        }
        if p.shard.count() != self.count {
            return bad(format!(
                "shard {} is not one of {} shards",
                p.shard, self.count
            ));
        }
        let slot = &mut self.seen[p.shard.index() as usize - 1];
        if *slot {
            return bad(format!("shard {} is given twice", p.shard));
        }
        check_part(p)?;
        *slot = true;
        for (acc, part) in self.strata.iter_mut().zip(&p.strata) {
            for (sums, add) in [
                (&mut acc.w, &part.w),
                (&mut acc.w2, &part.w2),
                (&mut acc.tot, &part.tot),
                (&mut acc.tot2, &part.tot2),
            ] {
                for (s, x) in sums.iter_mut().zip(add) {
                    s.add_sum(x);
                }
            }
            acc.capped += part.capped;
            acc.interactions += part.interactions;
        }
        Ok(())
    }

    /// The tally: every sum rounded once, then the per-stratum means and variances as
    /// [`simulate`] has always made them.
    ///
    /// # Errors
    /// [`McError::Shards`] naming the shards not added.
    pub fn finish(self) -> Result<WhiteTally> {
        let count = self.count;
        let missing: Vec<String> = self
            .seen
            .iter()
            .enumerate()
            .filter(|(_, s)| !**s)
            .map(|(k, _)| format!("{}/{count}", k + 1))
            .collect();
        if !missing.is_empty() {
            return Err(McError::Shards {
                message: format!("shard(s) {} missing", missing.join(", ")),
            });
        }
        let spec = self.spec;
        let grid = RadialGrid::from_edges(spec.radial_edges.clone())?;
        let bins = grid.bins();
        let k = spec.albedos.len();
        // Launch weight 1 − R_sp (MCML `LaunchPhoton`, normal incidence from air).
        let w0 = 1.0 - ((spec.eta - 1.0) / (spec.eta + 1.0)).powi(2);
        let mut rd = vec![0.0; k * bins];
        let mut var = vec![0.0; k * bins];
        let mut rd_total = vec![0.0; k];
        let mut var_total = vec![0.0; k];
        let (mut capped, mut interactions) = (0, 0);
        for (si, (stratum, sums)) in spec.strata.iter().zip(&self.strata).enumerate() {
            let round = |v: &[ExactSum]| -> Vec<f64> { v.iter().map(ExactSum::value).collect() };
            let (w, w2, tot, tot2) = (
                round(&sums.w),
                round(&sums.w2),
                round(&sums.tot),
                round(&sums.tot2),
            );
            let photons = stratum.photons;
            let n = photons as f64;
            // Mean and variance of the mean of per-photon scores.
            let moments = |s1: f64, s2: f64| {
                let mean = s1 / n;
                let v = if photons > 1 {
                    (s2 / n - mean * mean).max(0.0) / (n - 1.0)
                } else {
                    f64::INFINITY
                };
                (mean, v)
            };
            for kk in 0..k {
                for j in 0..bins {
                    let i = kk * bins + j;
                    let scale = w0 / grid.area(j);
                    let (m, v) = moments(w[i], w2[i]);
                    rd[i] += m * scale;
                    var[i] += v * scale * scale;
                }
                let (m, v) = moments(tot[kk], tot2[kk]);
                rd_total[kk] += m * w0;
                var_total[kk] += v * w0 * w0;
            }
            if si + 1 == spec.strata.len() {
                capped = sums.capped;
            }
            interactions += sums.interactions;
        }
        Ok(WhiteTally {
            rd,
            rd_stderr: var.iter().map(|v| v.sqrt()).collect(),
            rd_total,
            rd_total_stderr: var_total.iter().map(|v| v.sqrt()).collect(),
            capped,
            interactions,
            spec,
        })
    }
}

/// Checks that a part's strata fit its spec and shard: the chunk ranges its shard owns, sums of the
/// right sizes, valid expansions.
fn check_part(p: &WhitePartial) -> Result<()> {
    let bad = |why: &str| {
        Err(McError::Shards {
            message: format!("shard {}: {why}", p.shard),
        })
    };
    if p.strata.len() != p.spec.strata.len() {
        return bad("its strata do not match its spec");
    }
    let bins = p.spec.radial_edges.len().saturating_sub(1);
    let k = p.spec.albedos.len();
    for (s, spec) in p.strata.iter().zip(&p.spec.strata) {
        let range = stratum_chunks(p.shard, spec.photons);
        if s.chunks != [range.start, range.end] {
            return bad("its chunk range is not the one its shard owns");
        }
        if s.w.len() != k * bins || s.w2.len() != k * bins || s.tot.len() != k || s.tot2.len() != k
        {
            return bad("its sums do not have the spec's size");
        }
        if ![&s.w, &s.w2, &s.tot, &s.tot2]
            .iter()
            .all(|v| v.iter().all(ExactSum::is_valid))
        {
            return bad("a sum is not a valid exact sum (damaged file?)");
        }
    }
    Ok(())
}

/// What the inner loop reads.
struct Tracer<'a> {
    eta: f64,
    g: f64,
    /// Henyey–Greenstein sampling constants of `g`.
    hg: HgSampler,
    cos_crit: f64,
    min_n: u64,
    max_n: u64,
    roulette_n: u64,
    grid: &'a RadialGrid,
    ln_a: &'a [f64],
    bins: usize,
}

impl Tracer<'_> {
    /// Traces one non-absorbing photon from a normally incident pencil beam at the origin until it
    /// leaves through the surface z = 0 (scored if it had at least `min_n` interactions) or reaches
    /// `max_n` interactions. `ANISO`: g ≠ 0.
    #[inline]
    fn trace<const ANISO: bool>(&self, rng: &mut PhotonRng, acc: &mut Accum, w: &mut [f64]) {
        let (mut x, mut y, mut z) = (0.0f64, 0.0f64, 0.0f64);
        let (mut ux, mut uy, mut uz) = (0.0f64, 0.0f64, 1.0f64);
        let mut n: u64 = 0;
        let mut weight = 1.0;
        loop {
            // Step of Exp(1) optical length at σt = 1 (MCML `StepSizeInTissue`).
            let s = rng.exp1();
            let z_end = z + s * uz;
            if z_end < 0.0 {
                // Hits the surface (MCML `HitBoundary`): move there, then Fresnel decides
                // (`CrossOrNot`); on reflection the leftover step continues mirrored.
                let db = -z / uz;
                x += db * ux;
                y += db * uy;
                let cos_i = -uz;
                let escapes = cos_i > self.cos_crit && {
                    let r = fresnel_mcml(self.eta, 1.0, cos_i).reflectance;
                    r == 0.0 || rng.uniform() > r
                };
                if escapes {
                    acc.interactions += n;
                    if n >= self.min_n {
                        self.score(acc, w, n, weight, x, y);
                    }
                    return;
                }
                let left = s - db;
                uz = -uz;
                x += left * ux;
                y += left * uy;
                z = left * uz;
            } else {
                x += s * ux;
                y += s * uy;
                z = z_end;
            }
            // Interaction: implicit capture would multiply the weight by a; here n counts them.
            n += 1;
            if n >= self.max_n {
                acc.interactions += n;
                acc.capped += 1;
                return;
            }
            if n == self.roulette_n {
                if rng.uniform() >= ROULETTE_SURVIVAL {
                    acc.interactions += n;
                    return;
                }
                weight /= ROULETTE_SURVIVAL;
            }
            if ANISO {
                [ux, uy, uz] = scatter_hg([ux, uy, uz], &self.hg, rng);
            } else {
                (ux, uy, uz) = spin_isotropic(rng);
            }
        }
    }

    /// Scores an escape after `n` interactions at (x, y): weight·aₖⁿ for every albedo.
    #[inline]
    fn score(&self, acc: &mut Accum, w: &mut [f64], n: u64, weight: f64, x: f64, y: f64) {
        let nf = n as f64;
        for (wk, la) in w.iter_mut().zip(self.ln_a) {
            *wk = weight * (nf * la).exp();
        }
        for (k, &wk) in w.iter().enumerate() {
            acc.tot[k] += wk;
            acc.tot2[k] += wk * wk;
        }
        let r = (x * x + y * y).sqrt();
        if let Some(j) = self.grid.find(r) {
            for (k, &wk) in w.iter().enumerate() {
                let i = k * self.bins + j;
                acc.w[i] += wk;
                acc.w2[i] += wk * wk;
            }
        }
    }
}
