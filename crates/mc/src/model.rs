//! The `mc` forward model: Rd(r; σ′s, σa) of a half-space from Monte Carlo tables, smooth in the
//! albedo and the radius, with analytic derivatives of the interpolant.
//!
//! * [`McTable`] — one (η, g): a white Monte Carlo run ([`crate::white`]) scored at a grid of
//!   single-scattering albedos aₖ (σt = 1), each row smoothed by [`crate::smooth::fit_row`] into
//!   ln R̂(ρ; aₖ) = Sₖ(ln ρ) − κ₀(aₖ)ρ, plus the Monte Carlo total Rd(aₖ). Cached on disk as JSON
//!   ([`crate::cache`]: the folder is [`crate::cache::default_cache_dir`]); `scatterfit table` builds
//!   one for any η and g, and the tables shipped in the crate ([`crate::bundled`]) are such tables.
//! * [`McTableSet`] — tables for several η (same g and layout); interpolates in η.
//! * [`McProfile`] — the model for one set of optical properties, implementing
//!   [`scatterfit_optics::ProfileModel`]; the set is the `mc` [`scatterfit_optics::ModelFamily`]
//!   (the [`family`](mod@crate::family) module).
//!
//! Similarity (pbrt's `TabulatedBSSRDF::Sr`, docs/physics.md §2.3): with σs = σ′s/(1 − g), σt = σa + σs and
//! a = σs/σt, Rd(r) = σt² R̂(σt r; a) exactly (same η, g). For g = 0, σt = σ′t and a = α′.
//!
//! Interpolation: between albedos, cubic Hermite in x = −√(1 − a) on the spline coefficients less
//! ln a (so on S − ln a, after the analytic κ₀(a)ρ is taken out: C¹ in a) and on ln(Rd/a) for the
//! totals, ln a added back after. At low albedo light leaves mostly after one scattering, so R̂ ∝ a
//! to first order (the single-scattering term of the collision expansion Rd = Σₙ aⁿRₙ) and ln R̂
//! bends like ln a, which a cubic in √(1 − a) cannot follow across the first nodes: on ln Rd itself
//! the totals between the g ≠ 0 tables' first two nodes (α′ 0.01 and 0.035) were 7–10 % below
//! adding-doubling's at α′ 0.02 and 1–2 % above at 0.05; toward a → 1, ln a ≈ −(1 − a) is smooth in
//! √(1 − a) and changes little (BENCHMARKS.md, "Low albedo at g ≠ 0") — Catmull-Rom
//! derivatives inside (pbrt's `CatmullRomWeights`), the parabola through the three end nodes at the
//! first and last node (`Ends`); between η nodes,
//! Catmull-Rom in η on the same coefficients (linear with two tables); in ρ, the cubic B-spline itself
//! (C²). Derivatives ∂Rd/∂σ′s, ∂Rd/∂σa are those of this interpolant: through σt (the σt² factor and
//! ρ = σt r) and through a (the albedo weights' derivatives and dκ₀/da) — never finite differences.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use scatterfit_optics::{OpticalProperties, ProfileModel, ProfileSample};

use crate::cache::CacheStatus;
use crate::error::{McError, Result, check};
use crate::shard::Shard;
use crate::smooth::{Knots, fit_row, kappa0};
use crate::white::{WhitePartial, WhiteSpec, WhiteTally, simulate, simulate_shard};

pub use crate::spec::{AlbedoSpacing, LowAlbedoRun, McTableSpec};

/// Version of the `McTable` file format; files of another version are rebuilt.
pub const MC_TABLE_VERSION: u32 = 1;
const MC_TABLE_TAG: &str = "scatterfit-mc-white-table";

/// The raw Monte Carlo profiles behind a table (kept in cache files for diagnostics; dropped by
/// [`McTable::without_raw`] for shipping).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RawProfiles {
    /// Radial bin edges [mean free paths].
    pub edges: Vec<f64>,
    /// R̂ per (albedo, bin), row-major.
    pub rd: Vec<f64>,
    /// Standard errors of `rd`.
    pub rd_stderr: Vec<f64>,
}

/// The smoothed rows of one white run, in the table's layout.
struct Rows {
    knots: Knots,
    coefs: Vec<f64>,
    rho_data_min: Vec<f64>,
    rho_data_max: Vec<f64>,
    chi2_per_bin: Vec<f64>,
}

impl Rows {
    /// Each albedo row of `tally` (made from `white`) smoothed by [`fit_row`] with `spec`'s knots
    /// and smoother; the totals checked to increase with the albedo.
    fn smooth(spec: &McTableSpec, white: &WhiteSpec, tally: &WhiteTally) -> Result<Self> {
        let edges = &white.radial_edges;
        let bins = tally.bins();
        let knots = Knots::covering(
            edges[1].ln(),
            edges[edges.len() - 1].ln(),
            spec.smooth.knot_spacing,
        );
        let mut rows = Self {
            coefs: Vec::with_capacity(white.albedos.len() * knots.len()),
            knots,
            rho_data_min: Vec::new(),
            rho_data_max: Vec::new(),
            chi2_per_bin: Vec::new(),
        };
        for (k, &a) in white.albedos.iter().enumerate() {
            let row = k * bins..(k + 1) * bins;
            let fit = fit_row(
                edges,
                &tally.rd[row.clone()],
                &tally.rd_stderr[row],
                kappa0(a, spec.g).0,
                &rows.knots,
                &spec.smooth,
            )
            .ok_or(McError::Smoothing {
                albedo: a,
                reason: "fewer than 4 radial bins with data: trace more photons",
            })?;
            rows.coefs.extend_from_slice(&fit.coefs);
            rows.rho_data_min.push(fit.rho_data_min);
            rows.rho_data_max.push(fit.rho_data_max);
            rows.chi2_per_bin.push(fit.chi2 / fit.bins_used as f64);
        }
        for (k, w) in tally.rd_total.windows(2).enumerate() {
            if w[1] <= w[0] {
                return Err(McError::Smoothing {
                    albedo: white.albedos[k + 1],
                    reason: "total Rd does not increase with the albedo: trace more photons",
                });
            }
        }
        Ok(rows)
    }
}

/// A smoothed Monte Carlo profile table for one η and g (module docs).
///
/// Read from JSON only through the same checks as [`McTable::from_json`] (`#[serde(try_from)]`), so
/// every value of this type is consistent.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "RawTable")]
pub struct McTable {
    format: String,
    version: u32,
    spec: McTableSpec,
    albedos: Vec<f64>,
    knots: Knots,
    /// Spline coefficients per albedo, row-major (albedo k, coefficient m).
    coefs: Vec<f64>,
    /// Inner and outer radius of the data behind each row [mean free paths].
    rho_data_min: Vec<f64>,
    rho_data_max: Vec<f64>,
    rd_total: Vec<f64>,
    rd_total_stderr: Vec<f64>,
    /// χ² per degree of freedom of each row's smoothing fit.
    chi2_per_bin: Vec<f64>,
    raw: Option<RawProfiles>,
}

/// The unchecked shape of [`McTable`] in files.
#[derive(Deserialize)]
struct RawTable {
    format: String,
    version: u32,
    spec: McTableSpec,
    albedos: Vec<f64>,
    knots: Knots,
    coefs: Vec<f64>,
    rho_data_min: Vec<f64>,
    rho_data_max: Vec<f64>,
    rd_total: Vec<f64>,
    rd_total_stderr: Vec<f64>,
    chi2_per_bin: Vec<f64>,
    raw: Option<RawProfiles>,
}

impl TryFrom<RawTable> for McTable {
    type Error = String;
    fn try_from(t: RawTable) -> std::result::Result<Self, String> {
        let k = t.spec.node_count();
        let finite = |v: &[f64]| v.iter().all(|x| x.is_finite());
        let checks: [(bool, &str); 10] = [
            (
                t.format == MC_TABLE_TAG && t.version == MC_TABLE_VERSION,
                "not a table of this format version",
            ),
            (t.spec.white().is_ok(), "invalid spec"),
            (
                t.albedos == t.spec.albedos(),
                "albedos do not match the spec",
            ),
            (
                t.knots.intervals >= 1
                    && t.knots.intervals <= 100_000
                    && t.knots.h.is_finite()
                    && t.knots.h > 0.0
                    && t.knots.u0.is_finite(),
                "bad knots",
            ),
            (
                t.coefs.len() == k.saturating_mul(t.knots.len()) && finite(&t.coefs),
                "coefficients missing or not finite",
            ),
            (
                [
                    &t.rho_data_min,
                    &t.rho_data_max,
                    &t.rd_total,
                    &t.rd_total_stderr,
                    &t.chi2_per_bin,
                ]
                .iter()
                .all(|v| v.len() == k && finite(v)),
                "per-albedo vectors of the wrong length or not finite",
            ),
            (
                t.rd_total.windows(2).all(|w| w[1] > w[0]) && t.rd_total.iter().all(|&r| r > 0.0),
                "totals must be positive and increase with the albedo",
            ),
            (
                t.raw.as_ref().is_none_or(|r| {
                    let n = k.saturating_mul(r.edges.len().saturating_sub(1));
                    r.rd.len() == n && r.rd_stderr.len() == n
                }),
                "raw profiles of the wrong size",
            ),
            (t.spec.albedo_count >= 4, "need at least 4 albedos"),
            (t.rd_total.iter().all(|&r| r <= 1.5), "totals above 1.5"),
        ];
        if let Some((_, why)) = checks.iter().find(|(ok, _)| !ok) {
            return Err(format!("{MC_TABLE_TAG} v{MC_TABLE_VERSION}: {why}"));
        }
        Ok(Self {
            format: t.format,
            version: t.version,
            spec: t.spec,
            albedos: t.albedos,
            knots: t.knots,
            coefs: t.coefs,
            rho_data_min: t.rho_data_min,
            rho_data_max: t.rho_data_max,
            rd_total: t.rd_total,
            rd_total_stderr: t.rd_total_stderr,
            chi2_per_bin: t.chi2_per_bin,
            raw: t.raw,
        })
    }
}

impl McTable {
    /// Simulates and smooths the table on the current rayon pool; `progress(done, total)` counts
    /// photons.
    ///
    /// # Errors
    /// `InvalidParameter` for a bad spec; `Smoothing` if a row has too little data to smooth.
    /// The one-shard case of [`McTable::build_shard`] and [`McTable::combine`]: a table built here
    /// and one combined from N shards of the same spec are equal, bit for bit.
    pub fn build(spec: &McTableSpec, progress: &(dyn Fn(u64, u64) + Sync)) -> Result<Self> {
        let part = Self::build_shard(spec, Shard::WHOLE, progress)?;
        Self::combine(spec, &[part])
    }

    /// Simulates `shard`'s slice of the table's white run ([`crate::white::simulate_shard`]: per
    /// path-length stratum, a contiguous range of its chunks of photons, with their own random
    /// streams) and keeps its sums exactly; `progress(done, total)` counts the shard's photons.
    ///
    /// # Errors
    /// `InvalidParameter` for a bad spec.
    pub fn build_shard(
        spec: &McTableSpec,
        shard: Shard,
        progress: &(dyn Fn(u64, u64) + Sync),
    ) -> Result<WhitePartial> {
        let white = spec.white()?;
        let total = white.shard_photons(shard);
        simulate_shard(&white, shard, &|done| progress(done, total))
    }

    /// The table from the parts of all shards 1…N of `spec`'s run, in any order: their sums added
    /// exactly and rounded once ([`crate::white::combine`]), then smoothed as [`McTable::build`].
    ///
    /// # Errors
    /// [`McError::Shards`] when the parts are not every shard of this spec's run exactly once;
    /// `Smoothing` as [`McTable::from_tally`].
    pub fn combine(spec: &McTableSpec, parts: &[WhitePartial]) -> Result<Self> {
        let white = spec.white()?;
        if let Some(p) = parts.iter().find(|p| p.spec != white) {
            return Err(McError::Shards {
                message: format!("shard {} was made for another table spec", p.shard),
            });
        }
        let tally = crate::white::combine(parts)?;
        Self::from_tally(spec, &tally)
    }

    /// Smooths an existing white tally made from `spec.white()` (the main run). A spec with
    /// low-albedo nodes ([`LowAlbedoRun`]) has their short run simulated and smoothed here too
    /// ([`McTable::with_low_albedos`]: seconds), so that every way to a table — one machine, or N
    /// shards combined — goes through this one function.
    ///
    /// # Errors
    /// `InvalidParameter` when the tally was not made from this spec; `Smoothing` if a row has too
    /// little data, or the totals do not increase with the albedo.
    pub fn from_tally(spec: &McTableSpec, tally: &WhiteTally) -> Result<Self> {
        let white = spec.white()?;
        check(
            tally.spec == white,
            "tally",
            0.0,
            "the tally was made from another spec",
        )?;
        let main = McTableSpec {
            low_albedos: None,
            ..spec.clone()
        };
        let rows = Rows::smooth(&main, &white, tally)?;
        let table = Self {
            format: MC_TABLE_TAG.to_owned(),
            version: MC_TABLE_VERSION,
            spec: main,
            albedos: white.albedos.clone(),
            knots: rows.knots,
            coefs: rows.coefs,
            rho_data_min: rows.rho_data_min,
            rho_data_max: rows.rho_data_max,
            rd_total: tally.rd_total.clone(),
            rd_total_stderr: tally.rd_total_stderr.clone(),
            chi2_per_bin: rows.chi2_per_bin,
            raw: Some(RawProfiles {
                edges: white.radial_edges.clone(),
                rd: tally.rd.clone(),
                rd_stderr: tally.rd_stderr.clone(),
            }),
        };
        match &spec.low_albedos {
            None => Ok(table),
            Some(low) => table.with_low_albedos(low.clone()),
        }
    }

    /// This table with low-albedo nodes below its first ([`LowAlbedoRun`]): their white run
    /// ([`McTableSpec::low_albedo_white`]) simulated on the current rayon pool, smoothed as the
    /// table's own rows, and put in front of them; the spec records the run. Raw profiles are kept
    /// only if the table kept its own. A table shipped without low nodes gains them this way, equal
    /// to the table built from the extended spec (its rows are the same numbers; compacting is per
    /// value).
    ///
    /// # Errors
    /// `InvalidParameter` when the table has low-albedo nodes already or `low` is not below its
    /// first node; `Smoothing` as [`McTable::from_tally`], or when the low run's totals do not rise
    /// to the table's first.
    pub fn with_low_albedos(self, low: LowAlbedoRun) -> Result<Self> {
        check(
            self.spec.low_albedos.is_none(),
            "low_albedos",
            0.0,
            "the table has low-albedo nodes already",
        )?;
        let spec = McTableSpec {
            low_albedos: Some(low),
            ..self.spec.clone()
        };
        let white = spec
            .low_albedo_white()?
            .expect("a spec with low albedos has their run");
        let tally = simulate(&white, &|_| {})?;
        let rows = Rows::smooth(&spec, &white, &tally)?;
        check(
            rows.knots == self.knots,
            "knots",
            rows.knots.len() as f64,
            "the low-albedo rows have other knots than the table's (a defect)",
        )?;
        let last = tally.rd_total[tally.rd_total.len() - 1];
        if last >= self.rd_total[0] {
            return Err(McError::Smoothing {
                albedo: self.albedos[0],
                reason: "the low-albedo run's largest total is not below the table's first: trace more photons",
            });
        }
        let front = |low: &[f64], own: &[f64]| [low, own].concat();
        Ok(Self {
            albedos: front(&white.albedos, &self.albedos),
            coefs: front(&rows.coefs, &self.coefs),
            rho_data_min: front(&rows.rho_data_min, &self.rho_data_min),
            rho_data_max: front(&rows.rho_data_max, &self.rho_data_max),
            rd_total: front(&tally.rd_total, &self.rd_total),
            rd_total_stderr: front(&tally.rd_total_stderr, &self.rd_total_stderr),
            chi2_per_bin: front(&rows.chi2_per_bin, &self.chi2_per_bin),
            raw: self.raw.map(|r| RawProfiles {
                rd: front(&tally.rd, &r.rd),
                rd_stderr: front(&tally.rd_stderr, &r.rd_stderr),
                edges: r.edges,
            }),
            spec,
            ..self
        })
    }

    /// The same table without its raw profiles (what a shipped table needs).
    #[must_use]
    pub fn without_raw(mut self) -> Self {
        self.raw = None;
        self
    }

    /// [`McTable::without_raw`], with the spline coefficients rounded to 1e-9 (they are logarithms
    /// of R̂, so this changes the model by < 1e-8 relative, far below its Monte Carlo noise) and the
    /// totals to 1e-9, so that the JSON is about a third as long.
    #[must_use]
    pub fn compact(self) -> Self {
        let round = |v: &mut Vec<f64>| {
            for x in v.iter_mut() {
                *x = (*x * 1e9).round() / 1e9;
            }
        };
        let mut t = self.without_raw();
        round(&mut t.coefs);
        round(&mut t.rd_total);
        round(&mut t.rd_total_stderr);
        round(&mut t.chi2_per_bin);
        round(&mut t.rho_data_max);
        round(&mut t.rho_data_min);
        t
    }

    /// The spec that made the table.
    pub fn spec(&self) -> &McTableSpec {
        &self.spec
    }

    /// The albedo nodes.
    pub fn albedos(&self) -> &[f64] {
        &self.albedos
    }

    /// The raw Monte Carlo profiles, when kept.
    pub fn raw(&self) -> Option<&RawProfiles> {
        self.raw.as_ref()
    }

    /// Outer radius of the Monte Carlo data behind each albedo row [mean free paths]; beyond it the
    /// model is the smoother's extrapolation (a power law times e^{−κ₀ρ}).
    pub fn rho_data_max(&self) -> &[f64] {
        &self.rho_data_max
    }

    /// Inner radius of the Monte Carlo data behind each albedo row [mean free paths] (the innermost
    /// annuli are small and noisy at low albedo); inside it the model is extrapolated likewise.
    pub fn rho_data_min(&self) -> &[f64] {
        &self.rho_data_min
    }

    /// χ² per bin of each row's smoothing fit (≈ 1 when the smooth curve is within the noise).
    pub fn chi2_per_bin(&self) -> &[f64] {
        &self.chi2_per_bin
    }

    /// Monte Carlo total diffuse reflectance per albedo node (excluding R_sp) and standard errors.
    pub fn totals(&self) -> (&[f64], &[f64]) {
        (&self.rd_total, &self.rd_total_stderr)
    }

    fn row(&self, k: usize) -> &[f64] {
        let m = self.knots.len();
        &self.coefs[k * m..(k + 1) * m]
    }

    /// Cubic Hermite weights (and their derivatives in a) of albedo `a` over the nodes, in
    /// x = −√(1 − a): Catmull-Rom inside, parabolic at the first and last node ([`Ends`]).
    fn albedo_weights(&self, a: f64) -> Result<(usize, [f64; 4], [f64; 4])> {
        let al = &self.albedos;
        let (lo, hi) = (al[0], al[al.len() - 1]);
        // An end reached through a round trip (α′ ↔ a at g: a table's first node mapped to α′
        // and back lands an ulp or two outside) is that end.
        let tol = 1e-12;
        let a = if a < lo && a >= lo - tol {
            lo
        } else if a > hi && a <= hi + tol {
            hi
        } else {
            a
        };
        if !(a >= lo && a <= hi) {
            return Err(crate::error::out_of_table("albedo (σs/σt)", a, lo, hi));
        }
        let x = |v: f64| -(1.0 - v).sqrt();
        let (i, w, dw_dx) = hermite_weights(al.len(), |k| x(al[k]), x(a), Ends::Parabola);
        let dx_da = 0.5 / (1.0 - a).sqrt();
        Ok((i, w, dw_dx.map(|d| d * dx_da)))
    }

    /// Total diffuse reflectance Rd(a) (excluding R_sp): cubic Hermite in √(1 − a) with parabolic
    /// ends (`Ends::Parabola`) on ln(Rd/a) between the Monte Carlo totals of the nodes (module docs,
    /// "Interpolation": then × a). On ln Rd, as
    /// the profile's coefficients are: toward a → 1 at η = 2 Rd itself bends so much within the last
    /// interval that its interpolant was 1.5–2.3·10⁻³ high at α′ 0.9993–0.9998 (g 0.8–0.9) against
    /// adding-doubling, ln Rd 4–6·10⁻⁴ (6·10⁻³ with the chord ends; BENCHMARKS.md).
    ///
    /// # Errors
    /// `OutOfTable` for a outside the tabulated albedos.
    pub fn rd_total(&self, a: f64) -> Result<f64> {
        let (i, w, _) = self.albedo_weights(a)?;
        let al = &self.albedos;
        // An end reached through a round trip is that end (as in the weights), so that the
        // totals at the ends are the nodes' own, bit for bit.
        let a = a.clamp(al[0], al[al.len() - 1]);
        Ok(a * dot4(&w, |k| (self.rd_total[i + k - 1] / al[i + k - 1]).ln()).exp())
    }
}

/// Σₖ w[k]·f(k) over the nonzero weights (index k − 1 relative to the interval start).
fn dot4(w: &[f64; 4], f: impl Fn(usize) -> f64) -> f64 {
    (0..4).filter(|&k| w[k] != 0.0).map(|k| w[k] * f(k)).sum()
}

/// Catmull-Rom weights at `x` over the `n` strictly increasing nodes `node(k)` (pbrt-v3's
/// `CatmullRomWeights`, docs/physics.md §2.3): returns (i, w) with x ∈ [node(i), node(i + 1)] and the
/// interpolant Σₖ w[k]·f(i − 1 + k); the end derivatives are one-sided (w[0] or w[3] is then 0).
/// Cubic Hermite with finite-difference derivatives on non-uniform nodes; exact at the nodes.
fn catmull_rom_weights(n: usize, node: impl Fn(usize) -> f64, x: f64) -> (usize, [f64; 4]) {
    let (i, w, _) = hermite_weights(n, node, x, Ends::Chord);
    (i, w)
}

/// How a cubic Hermite interpolant takes its derivative at the first and last node.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Ends {
    /// The end interval's chord (pbrt's Catmull-Rom): exact for straight lines only.
    Chord,
    /// The parabola through the three end nodes (the second-order one-sided difference, e.g.
    /// Fornberg 1988, Math. Comp. 51:699, table 1): exact for quadratics, so the end interval is
    /// as accurate as an interior one. Used in albedo, where the last interval of the tables
    /// (toward a → 1) spans a wide range of 1 − α′ and Rd(√(1 − a)) is curved: with the chord the
    /// totals were 1–1.5·10⁻³ high at α′ 0.9996–0.9998 for g 0.8–0.9 against adding-doubling,
    /// with the parabola within 2.5·10⁻⁴ (BENCHMARKS.md, "The `mc` model over g").
    Parabola,
}

/// Cubic Hermite weights at `x` over the `n` strictly increasing nodes with Catmull-Rom
/// (finite-difference) derivatives inside and `ends` at the first and last node: (i, w, dw/dx)
/// with x ∈ [node(i), node(i + 1)] and the interpolant Σₖ w[k]·f(i − 1 + k).
fn hermite_weights(
    n: usize,
    node: impl Fn(usize) -> f64,
    x: f64,
    ends: Ends,
) -> (usize, [f64; 4], [f64; 4]) {
    // First i with node(i + 1) > x, clamped to the last interval.
    let mut i = 0;
    while i + 2 < n && node(i + 1) <= x {
        i += 1;
    }
    let (x0, x1) = (node(i), node(i + 1));
    let h = x1 - x0;
    let t = ((x - x0) / h).clamp(0.0, 1.0);
    let (t2, t3) = (t * t, t * t * t);
    let inv = 1.0 / h;
    // Value and x-derivative of the four Hermite basis functions: h00, h10 (times h), h01, h11.
    let mut w = [0.0, 2.0 * t3 - 3.0 * t2 + 1.0, -2.0 * t3 + 3.0 * t2, 0.0];
    let mut d = [
        0.0,
        (6.0 * t2 - 6.0 * t) * inv,
        (-6.0 * t2 + 6.0 * t) * inv,
        0.0,
    ];
    // h·f′(x0) as weights on (f(i − 1), f(i), f(i + 1), f(i + 2)).
    let start: [f64; 4] = if i > 0 {
        let c = h / (x1 - node(i - 1));
        [-c, 0.0, c, 0.0]
    } else if ends == Ends::Parabola && n >= 3 {
        // Parabola through x0, x1, x2: h f′(x0) = (1 + c)(f1 − f0) − c r (f2 − f1).
        let h2 = node(i + 2) - x1;
        let (c, r) = (h / (h + h2), h / h2);
        [0.0, -(1.0 + c), 1.0 + c + c * r, -c * r]
    } else {
        [0.0, -1.0, 1.0, 0.0]
    };
    // h·f′(x1) likewise.
    let end: [f64; 4] = if i + 2 < n {
        let c = h / (node(i + 2) - x0);
        [0.0, -c, 0.0, c]
    } else if ends == Ends::Parabola && i > 0 {
        // Parabola through x₋₁, x0, x1: h f′(x1) = (1 + c)(f1 − f0) − c r (f0 − f₋₁).
        let h1 = x0 - node(i - 1);
        let (c, r) = (h / (h1 + h), h / h1);
        [c * r, -(1.0 + c + c * r), 1.0 + c, 0.0]
    } else {
        [0.0, -1.0, 1.0, 0.0]
    };
    let (b0, db0) = (t3 - 2.0 * t2 + t, (3.0 * t2 - 4.0 * t + 1.0) * inv);
    let (b1, db1) = (t3 - t2, (3.0 * t2 - 2.0 * t) * inv);
    for k in 0..4 {
        w[k] += b0 * start[k] + b1 * end[k];
        d[k] += db0 * start[k] + db1 * end[k];
    }
    (i, w, d)
}

/// Monte Carlo tables for several η with the same g and layout; interpolates in η.
#[derive(Debug, Clone, PartialEq)]
pub struct McTableSet {
    tables: Vec<McTable>,
}

impl McTableSet {
    /// A set from tables (sorted here by η). All must share g and the albedo and radial layout.
    ///
    /// # Errors
    /// `InvalidParameter` for an empty list, mixed g or layouts, or two tables at one η.
    pub fn new(mut tables: Vec<McTable>) -> Result<Self> {
        check(!tables.is_empty(), "tables", 0.0, "need at least one table")?;
        tables.sort_by(|a, b| a.spec.eta.total_cmp(&b.spec.eta));
        let first = &tables[0];
        for t in &tables[1..] {
            check(
                t.spec.g == first.spec.g,
                "g",
                t.spec.g,
                "every table of a set must have one g",
            )?;
            check(
                t.albedos == first.albedos && t.knots == first.knots,
                "eta",
                t.spec.eta,
                "every table of a set must have the same albedo nodes and knots",
            )?;
        }
        for w in tables.windows(2) {
            check(
                w[1].spec.eta > w[0].spec.eta,
                "eta",
                w[1].spec.eta,
                "two tables at one η",
            )?;
        }
        Ok(Self { tables })
    }

    /// The tables for `etas` (each from `template` with its η), from the cache folder `dir` where a
    /// matching file is there, else simulated and saved there. `progress(table, done, total)`.
    ///
    /// # Errors
    /// As [`McTable::load_or_build`] and [`McTableSet::new`].
    pub fn load_or_build(
        etas: &[f64],
        template: &McTableSpec,
        dir: &Path,
        progress: &(dyn Fn(usize, u64, u64) + Sync),
    ) -> Result<Self> {
        let mut tables = Vec::with_capacity(etas.len());
        for (i, &eta) in etas.iter().enumerate() {
            let spec = McTableSpec {
                eta,
                ..template.clone()
            };
            let (t, _, _) = McTable::load_or_build(&spec, dir, &|d, n| progress(i, d, n))?;
            tables.push(t);
        }
        Self::new(tables)
    }

    /// The tables, by increasing η.
    pub fn tables(&self) -> &[McTable] {
        &self.tables
    }

    /// The η range covered.
    pub fn eta_range(&self) -> (f64, f64) {
        (
            self.tables[0].spec.eta,
            self.tables[self.tables.len() - 1].spec.eta,
        )
    }

    /// The Henyey–Greenstein g of every table.
    pub fn g(&self) -> f64 {
        self.tables[0].spec.g
    }

    /// Catmull-Rom weights of η over the tables (the single table itself when there is one and η is
    /// its own).
    fn eta_weights(&self, eta: f64) -> Result<(usize, [f64; 4])> {
        let (lo, hi) = self.eta_range();
        let n = self.tables.len();
        if n == 1 {
            return if (eta - lo).abs() <= 1e-9 {
                Ok((0, [0.0, 1.0, 0.0, 0.0]))
            } else {
                Err(crate::error::out_of_table("eta", eta, lo, hi))
            };
        }
        if !(eta >= lo - ETA_EDGE_TOLERANCE && eta <= hi + ETA_EDGE_TOLERANCE) {
            return Err(crate::error::out_of_table("eta", eta, lo, hi));
        }
        // Within the tolerance beyond an end, the end table (a measured η of 2.4002 for a material
        // of 2.4 must not fail).
        let eta = eta.clamp(lo, hi);
        Ok(catmull_rom_weights(n, |k| self.tables[k].spec.eta, eta))
    }

    /// Total diffuse reflectance Rd(a, η) (excluding R_sp) by Monte Carlo: cubic Hermite in √(1 − a)
    /// on ln Rd over the albedo nodes ([`McTable::rd_total`]), then Catmull-Rom in η on ln Rd over the tables (on the default η grid
    /// within 0.2 % of adding-doubling between tables, BENCHMARKS.md). a is the single-scattering
    /// albedo (α′ for g = 0; for g ≠ 0, α′ = a(1 − g)/(1 − ag)).
    ///
    /// # Errors
    /// `OutOfTable` for a or η outside the tables.
    pub fn rd_total(&self, a: f64, eta: f64) -> Result<f64> {
        let (j, we) = self.eta_weights(eta)?;
        let mut ln_sum = 0.0;
        for (q, &w) in we.iter().enumerate() {
            if w != 0.0 {
                ln_sum += w * self.tables[j + q - 1].rd_total(a)?.ln();
            }
        }
        Ok(ln_sum.exp())
    }

    /// The albedo a (α′ for g = 0) whose Monte Carlo total diffuse reflectance at η is `rd`: the
    /// inverse of [`McTableSet::rd_total`] (increasing in a; checked at every node when a table is
    /// built), by bisection in √(1 − a) to 1e-14, so the round trip is exact to ~1e-12 in Rd.
    ///
    /// # Errors
    /// `OutOfTable` when `rd` lies outside [Rd(a_min), Rd(a_max)] at this η, or η outside the tables.
    pub fn albedo_from_rd_total(&self, rd: f64, eta: f64) -> Result<f64> {
        let a = &self.tables[0].albedos;
        invert_increasing_total(rd, a[0], a[a.len() - 1], |a| self.rd_total(a, eta))
    }
}

impl McTable {
    /// Reads a table file.
    ///
    /// # Errors
    /// `Io` when it cannot be read, `Format` when it is not a table of this format version.
    pub fn load(path: &Path) -> Result<Self> {
        crate::cache::read_with(path, Self::from_json)
    }

    /// Parses a table from JSON (a file's text, or one shipped inside a program).
    ///
    /// # Errors
    /// A message when the text is not a consistent table of this format version.
    pub fn from_json(text: &str) -> std::result::Result<Self, String> {
        serde_json::from_str(text).map_err(|e| e.to_string())
    }

    /// Writes the table atomically (temporary file, sync, rename).
    ///
    /// # Errors
    /// `Io` on any file-system error (the target is then untouched).
    pub fn save(&self, path: &Path) -> Result<()> {
        crate::cache::save_json(self, path)
    }

    /// The table for `spec` from the cache folder `dir` when a file made with the same spec and
    /// format is there, else simulated and saved there.
    ///
    /// # Errors
    /// As [`McTable::build`], or `Io` when the cache cannot be written.
    pub fn load_or_build(
        spec: &McTableSpec,
        dir: &Path,
        progress: &(dyn Fn(u64, u64) + Sync),
    ) -> Result<(Self, CacheStatus, PathBuf)> {
        spec.white()?;
        crate::cache::load_or_build(
            dir.join(spec.file_name()),
            Self::load,
            |t| t.spec == *spec,
            || Self::build(spec, progress),
            Self::save,
        )
    }
}

/// How far beyond the first or last table's η a lookup may go; it then uses that table. A measured
/// η carries ~10⁻⁴ of Schlick's and the reading's error, and Rd changes with η by less than 0.2 %
/// over 0.005 (the tables' totals between η = 2.3 and 2.4), well inside the measurement's error.
pub const ETA_EDGE_TOLERANCE: f64 = 0.005;

/// The `mc` forward model for one set of optical properties: the table set's interpolant at (a, η)
/// collapsed into one spline in u = ln ρ with its a-derivative, and the similarity scaling.
#[derive(Debug, Clone, PartialEq)]
pub struct McProfile {
    props: OpticalProperties,
    knots: Knots,
    /// S's coefficients at (a, η), and their derivatives in a.
    coefs: Vec<f64>,
    dcoefs: Vec<f64>,
    /// σt, a, κ₀(a), dκ₀/da.
    sigma_t: f64,
    kappa: f64,
    dkappa: f64,
    /// ∂σt/∂σ′s, ∂a/∂σ′s, ∂a/∂σa (∂σt/∂σa = 1).
    dst_dsp: f64,
    da_dsp: f64,
    da_dsa: f64,
    /// Smallest optical radius of the spline (below it Rd is held constant).
    rho_floor: f64,
    /// Outer radius of the Monte Carlo data at this albedo [mm].
    r_data_max: f64,
    /// The tables' outer radial edge [mean free paths 1/σt of the set's g].
    rho_max: f64,
    rd_total: f64,
    /// Beyond a g ≠ 0 set's radial range, the g = 0 model's shape ([`McProfile::with_far_field`]).
    far: Option<Box<FarField>>,
}

/// Where a g ≠ 0 set's profile hands over to the g = 0 model's shape, as a fraction of the set's
/// outer radial edge (`McTableSpec::rho_max`, in its own mean free paths 1/σt): inside the data,
/// clear of the last bins the smoother's end condition shapes.
pub const FAR_FIELD_JOIN: f64 = 0.8;

/// Where a g ≠ 0 set's profile hands over to the g = 0 model's shape at the latest, in reduced mean
/// free paths 1/σ′t: the g ≠ 0 tables' own far field is reliable only to about there at α′ → 1
/// (their photons need 1/(1 − g) times the interactions of g = 0 to get as far, and the smoother
/// bends the noisy rows). Measured at g 0.8, η 1.0, α′ 0.9999 against a direct engine run
/// (`g_point_check`, 2·10⁷ photons): the set's own profile is within 0.1 % to 20 reduced mean free
/// paths, then +0.7 … −1.9 % to 50 and −2 … −4 % beyond; continued from 25 it is within 0.7 % to
/// 100 (from 20: +0.9 … +1.5 %, the g = 0 shape not yet the g = 0.8 one there; from 30: within
/// 1.0 %); against MCML (`data/reference/mcml_far_field_g.csv`) within 0.4 % from 10 to 97.5, where
/// the node's own profile was 2.6 % low at 40–60. CHANGELOG.md, "The far field's join at 25
/// reduced mean free paths".
pub const FAR_FIELD_JOIN_REDUCED: f64 = 25.0;

/// The continuation of a [`McProfile`] beyond its set's radial range (see
/// [`McProfile::with_far_field`]): Rd(r) = c·Rd₀(r) for r > r_join, with c = Rd(r_join)/Rd₀(r_join).
#[derive(Debug, Clone, PartialEq)]
struct FarField {
    /// The g = 0 model at the same σ′s, σa and η.
    donor: McProfile,
    /// The join radius [mm].
    r_join: f64,
    /// ln c and its derivatives in σ′s and σa (the join radius moves with σt: included).
    ln_c: f64,
    d_ln_c: [f64; 2],
}

impl McProfile {
    /// The model for `props` (its η, and the set's g) from `set`.
    ///
    /// # Errors
    /// `OutOfTable` when η or the albedo a = σs/σt is outside the tables.
    pub fn new(set: &McTableSet, props: &OpticalProperties) -> Result<Self> {
        Self::build(set, props, false)
    }

    /// [`McProfile::new`], or with `beyond_top` for an albedo above the set's last node: the
    /// smoothed shape S (module docs) held at that node and the exact decay e^{−κ₀(a)ρ} at the true
    /// albedo — the far-field donor of [`McProfile::with_far_field`], where the g = 0 set (nodes
    /// to α′ 0.9999) must answer for g ≠ 0 sets that reach α′ 0.99995. Continuous at the node;
    /// above it the shape's own change with a (which the decay dominates there) is left out.
    fn build(set: &McTableSet, props: &OpticalProperties, beyond_top: bool) -> Result<Self> {
        let g = set.g();
        let sigma_s = props.sigma_s_prime() / (1.0 - g);
        let sigma_t = props.sigma_a() + sigma_s;
        let a = sigma_s / sigma_t;
        let eta = props.eta();
        let (j, we) = set.eta_weights(eta)?;
        let t0 = &set.tables[0];
        let top = t0.albedos[t0.albedos.len() - 1];
        let (i, wa, dwa) = if beyond_top && a > top {
            let (i, wa, _) = t0.albedo_weights(top)?;
            (i, wa, [0.0; 4])
        } else {
            t0.albedo_weights(a)?
        };
        let m = t0.knots.len();
        let (mut coefs, mut dcoefs) = (vec![0.0; m], vec![0.0; m]);
        let mut rho_data = 0.0;
        for (q, &w_eta) in we.iter().enumerate() {
            if w_eta == 0.0 {
                continue;
            }
            let t = &set.tables[j + q - 1];
            for k in 0..4 {
                if wa[k] == 0.0 && dwa[k] == 0.0 {
                    continue;
                }
                let row = t.row(i + k - 1);
                // The row's S less ln a of its node (module docs, "Interpolation"): a constant on every
                // coefficient, since the B-splines sum to 1.
                let ln_node = t0.albedos[i + k - 1].ln();
                let (w, dw) = (w_eta * wa[k], w_eta * dwa[k]);
                for ((c, d), &b) in coefs.iter_mut().zip(dcoefs.iter_mut()).zip(row) {
                    *c += w * (b - ln_node);
                    *d += dw * (b - ln_node);
                }
                rho_data += w * t.rho_data_max[i + k - 1];
            }
        }
        // ln a back (the η and albedo weights sum to 1, their a-derivatives to 0); held at the
        // last node above it, as the shape is.
        let (ln_a, dln_a) = if beyond_top && a > top {
            (top.ln(), 0.0)
        } else {
            (a.ln(), 1.0 / a)
        };
        for (c, d) in coefs.iter_mut().zip(dcoefs.iter_mut()) {
            *c += ln_a;
            *d += dln_a;
        }
        let (kappa, dkappa) = kappa0(a, g);
        let st2 = sigma_t * sigma_t;
        Ok(Self {
            props: *props,
            knots: t0.knots,
            coefs,
            dcoefs,
            sigma_t,
            kappa,
            dkappa,
            dst_dsp: 1.0 / (1.0 - g),
            da_dsp: props.sigma_a() / ((1.0 - g) * st2),
            da_dsa: -sigma_s / st2,
            rho_floor: t0.spec.rho_min,
            r_data_max: rho_data / sigma_t,
            rho_max: t0.spec.rho_max,
            rd_total: set.rd_total(a.min(top), eta)?,
            far: None,
        })
    }

    /// The far-field donor for [`McProfile::with_far_field`]: the g = 0 set's model at `props`,
    /// answering above the set's last albedo node too (its shape held there, the decay exact).
    ///
    /// # Errors
    /// As [`McProfile::new`] below the set's albedo range or outside its η range.
    pub fn far_field_donor(set: &McTableSet, props: &OpticalProperties) -> Result<Self> {
        Self::build(set, props, true)
    }

    /// The same model continued beyond its set's radial range by `donor`'s shape — the g = 0 set's
    /// model at the same σ′s, σa and η: Rd(r) = c·Rd₀(r) for r beyond r_join — the nearer of
    /// [`FAR_FIELD_JOIN`]·ρ_max/σt and [`FAR_FIELD_JOIN_REDUCED`]/σ′t
    /// ([`McProfile::far_field_join`]) — c making Rd continuous there.
    ///
    /// Why: every table spans ρ = σt·r up to ρ_max = 500 of its *own* mean free paths, which at
    /// g = 0.9 and 0.95 is only 50 and 25 reduced ones (σ′t r) — 8 mm at σ′s = 3 mm⁻¹ for g 0.95,
    /// inside the paper rig's 25 mm field, where at α′ → 1 the light still travels tens of
    /// millimetres. Beyond, the smoother's extrapolation (a power law times e^{−κ₀ρ}) was 10–50 %
    /// off (CHANGELOG.md, "The far field beyond the g tables' radius"). The far field follows
    /// similarity (in reduced units it is the same at every g: Wyman, Patterson & Wilson 1989;
    /// d'Eon 2012 §4 for the diffusion asymptote), and the g = 0 set's tables reach 500 reduced mean
    /// free paths, so its shape carries the profile on; the join's factor c keeps the g ≠ 0 set's
    /// own amplitude (which the near field sets). And where a g ≠ 0 set's data do reach, they are
    /// reliable only to about 25 reduced mean free paths at α′ → 1 ([`FAR_FIELD_JOIN_REDUCED`]): a
    /// fit that weights the far field read σ′s 2–2.5 % low at g 0.8, α′ 0.9999 from the set's own
    /// far field (CHANGELOG.md, "The far field's join at 25 reduced mean free paths"). The total
    /// is the set's own (tallied, not the profile's integral). Unchanged where the donor does not
    /// answer.
    #[must_use]
    pub fn with_far_field(mut self, donor: McProfile) -> Self {
        let (r_join, dr_join) = self.far_field_join();
        if !(r_join.is_finite() && r_join > 0.0) || donor.sigma_t <= 0.0 {
            return self;
        }
        let (own, d) = (
            self.rd_with_derivatives(r_join),
            donor.rd_with_derivatives(r_join),
        );
        if !(own.rd > 0.0 && d.rd > 0.0) {
            return self;
        }
        // ∂ln Rd/∂r at the join, of each (σt ∂ln R̂/∂ρ − nothing else: Rd = σt² R̂(σt r)).
        let slope = |m: &McProfile| m.sigma_t * m.ln_rhat(m.sigma_t * r_join).1;
        let dr = slope(&self) - slope(&donor);
        let d_ln_c = [
            own.d_sigma_s_prime / own.rd - d.d_sigma_s_prime / d.rd + dr * dr_join[0],
            own.d_sigma_a / own.rd - d.d_sigma_a / d.rd + dr * dr_join[1],
        ];
        self.far = Some(Box::new(FarField {
            ln_c: own.rd.ln() - d.rd.ln(),
            d_ln_c,
            r_join,
            donor,
        }));
        self
    }

    /// Where [`McProfile::with_far_field`] joins \[mm\] — the nearer of the reduced radius
    /// [`FAR_FIELD_JOIN_REDUCED`]/σ′t and [`FAR_FIELD_JOIN`]·ρ_max/σt (the set's own range) — with
    /// its derivatives in σ′s and σa (the join moves with the coefficients).
    pub fn far_field_join(&self) -> (f64, [f64; 2]) {
        let own_range = FAR_FIELD_JOIN * self.rho_max / self.sigma_t;
        let sigma_t_reduced = self.props.sigma_s_prime() + self.props.sigma_a();
        let reduced = FAR_FIELD_JOIN_REDUCED / sigma_t_reduced;
        if reduced < own_range {
            // r = J′/σ′t with σ′t = σ′s + σa.
            (reduced, [-reduced / sigma_t_reduced; 2])
        } else {
            // r = J ρ_max/σt with ∂σt/∂σ′s = 1/(1 − g), ∂σt/∂σa = 1.
            let per_sigma_t = -own_range / self.sigma_t;
            (own_range, [per_sigma_t * self.dst_dsp, per_sigma_t])
        }
    }

    /// The optical properties of this model.
    pub fn properties(&self) -> &OpticalProperties {
        &self.props
    }

    /// Outer radius of the Monte Carlo data behind the model at this albedo \[mm\] (interpolated like
    /// the model): beyond it Rd(r) is the smoother's extrapolation.
    pub fn r_data_max_mm(&self) -> f64 {
        self.r_data_max
    }

    /// ln R̂, ∂ln R̂/∂ρ, ∂ln R̂/∂a at optical radius ρ.
    #[inline]
    fn ln_rhat(&self, rho: f64) -> (f64, f64, f64) {
        let (rho, floor) = if rho < self.rho_floor {
            (self.rho_floor, true)
        } else {
            (rho, false)
        };
        let b = self.knots.basis(rho.ln());
        let c = &self.coefs[b.first..b.first + 4];
        let dc = &self.dcoefs[b.first..b.first + 4];
        let mut s = 0.0;
        let mut s_u = 0.0;
        let mut s_a = 0.0;
        for p in 0..4 {
            s += b.w[p] * c[p];
            s_u += b.dw[p] * c[p];
            s_a += b.w[p] * dc[p];
        }
        let d_rho = if floor { 0.0 } else { s_u / rho - self.kappa };
        (s - self.kappa * rho, d_rho, s_a - self.dkappa * rho)
    }

    /// Rd(r) with its derivatives in σ′s and σa.
    #[inline]
    pub fn rd_with_derivatives(&self, r_mm: f64) -> ProfileSample {
        if let Some(f) = self.far.as_deref().filter(|f| r_mm > f.r_join) {
            let d = f.donor.rd_with_derivatives(r_mm);
            let c = f.ln_c.exp();
            let rd = c * d.rd;
            return ProfileSample {
                rd,
                d_sigma_s_prime: c * d.d_sigma_s_prime + rd * f.d_ln_c[0],
                d_sigma_a: c * d.d_sigma_a + rd * f.d_ln_c[1],
            };
        }
        let st = self.sigma_t;
        let (l, l_rho, l_a) = self.ln_rhat(st * r_mm);
        let rd = st * st * l.exp();
        // ∂Rd/∂σt at fixed a = Rd (2/σt + r ∂ln R̂/∂ρ); ∂Rd/∂a at fixed σt = Rd ∂ln R̂/∂a.
        let d_st = rd * (2.0 / st + r_mm * l_rho);
        let d_a = rd * l_a;
        ProfileSample {
            rd,
            d_sigma_s_prime: d_st * self.dst_dsp + d_a * self.da_dsp,
            d_sigma_a: d_st + d_a * self.da_dsa,
        }
    }
}

impl ProfileModel for McProfile {
    fn rd(&self, r_mm: f64) -> f64 {
        if let Some(f) = self.far.as_deref().filter(|f| r_mm > f.r_join) {
            return f.ln_c.exp() * f.donor.rd(r_mm);
        }
        let st = self.sigma_t;
        st * st * self.ln_rhat(st * r_mm).0.exp()
    }

    fn profile_with_derivatives_into(&self, radii_mm: &[f64], out: &mut [ProfileSample]) {
        for (r, o) in radii_mm.iter().zip(out.iter_mut()) {
            *o = self.rd_with_derivatives(*r);
        }
    }

    /// The Monte Carlo total at this albedo and η (interpolated like the profile; not the integral
    /// of the smoothed profile, which misses the part beyond the table's last radius).
    fn rd_total(&self) -> f64 {
        self.rd_total
    }
}

/// The albedo in [lo, hi] at which an increasing total diffuse reflectance `total` equals `rd`:
/// bisection in u = √(1 − a), where the Monte Carlo totals are smooth up to a = 1, to 1e-14 in u
/// (so the round trip is exact to ~1e-12 in Rd). Written by hand: the totals are fallible table
/// lookups (`?` inside the loop), and a bracketed bisection in this variable is all they need.
///
/// # Errors
/// `OutOfTable` (`rd_total`) for an `rd` outside [total(lo), total(hi)]; the lookups' own errors.
pub(crate) fn invert_increasing_total(
    rd: f64,
    lo: f64,
    hi: f64,
    total: impl Fn(f64) -> Result<f64>,
) -> Result<f64> {
    let (r_lo, r_hi) = (total(lo)?, total(hi)?);
    if !(rd >= r_lo && rd <= r_hi) {
        return Err(crate::error::out_of_table("rd_total", rd, r_lo, r_hi));
    }
    let (mut u_lo, mut u_hi) = ((1.0 - hi).sqrt(), (1.0 - lo).sqrt());
    for _ in 0..200 {
        let u = 0.5 * (u_lo + u_hi);
        if u <= u_lo || u >= u_hi || u_hi - u_lo < 1e-14 {
            break;
        }
        if total(1.0 - u * u)? >= rd {
            u_lo = u;
        } else {
            u_hi = u;
        }
    }
    let u = 0.5 * (u_lo + u_hi);
    Ok((1.0 - u * u).clamp(lo, hi))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::white::simulate;

    /// A table that builds in a fraction of a second: 8 albedos 0.3–0.99, 120 bins to 60 mean free
    /// paths, 30 000 + 6 000 photons.
    fn small_spec(eta: f64) -> McTableSpec {
        small_spec_g(eta, 0.0)
    }

    fn small_spec_g(eta: f64, g: f64) -> McTableSpec {
        let mut spec = McTableSpec::with_strata(eta, g, vec![30_000, 6_000], vec![64]).unwrap();
        spec.albedo_count = 8;
        // Forward scattering (g > 0) sends low-albedo photons deep: start higher there.
        spec.albedo_min = if g == 0.0 { 0.3 } else { 0.7 };
        spec.albedo_max = 0.99;
        spec.radial_bins = 120;
        spec.rho_max = 60.0;
        spec
    }

    /// Low-albedo nodes ([`LowAlbedoRun`]) built with the table or added to it afterwards (what the
    /// shipped g ≠ 0 tables went through) give the same table bit for bit, compacted too; the nodes
    /// are the spec's, the totals rise across the join, the file reads back through the format's
    /// checks, and a second set of low nodes is refused.
    #[test]
    fn low_albedo_nodes_built_or_added_are_the_same_table() {
        let spec = small_spec_g(1.3, 0.5);
        let extended = spec.clone().with_low_albedos_to(0.3, 400_000).unwrap();
        let low = extended.low_albedos.clone().unwrap();
        let built = McTable::build(&extended, &|_, _| {}).unwrap();
        let added = McTable::build(&spec, &|_, _| {})
            .unwrap()
            .with_low_albedos(low.clone())
            .unwrap();
        let bytes = |t: &McTable| serde_json::to_vec(t).unwrap();
        assert_eq!(bytes(&built), bytes(&added));
        assert_eq!(bytes(&built.clone().compact()), bytes(&added.compact()));
        assert_eq!(built.albedos(), extended.albedos().as_slice());
        assert_eq!(built.albedos().len(), 8 + low.albedo_count);
        let (totals, _) = built.totals();
        assert!(totals.windows(2).all(|w| w[1] > w[0]), "{totals:?}");
        let text = serde_json::to_string(&built.clone().compact()).unwrap();
        let back = McTable::from_json(&text).unwrap();
        assert_eq!(back.spec(), &extended);
        assert!((back.rd_total(0.3).unwrap() / totals[0] - 1.0).abs() < 1e-6);
        assert!(built.with_low_albedos(low).is_err());
    }

    fn small_set(etas: &[f64]) -> McTableSet {
        McTableSet::new(
            etas.iter()
                .map(|&e| McTable::build(&small_spec(e), &|_, _| {}).unwrap())
                .collect(),
        )
        .unwrap()
    }

    /// The cost model against measured interaction counts of white runs: within a factor 2 over
    /// η 1–2.5, g 0–0.9 and the default strata (the run's own count, `WhiteTally::interactions`).
    /// Fixed seeds; 4 000 full-length photons keep the heavy-tailed counts' noise to a few per cent.
    #[test]
    fn cost_estimate_matches_measured_work() {
        for (eta, g) in [
            (1.0, 0.0),
            (1.4, 0.0),
            (2.5, 0.0),
            (1.4, 0.5),
            (1.4, 0.9),
            (2.0, 0.9),
        ] {
            let mut spec = McTableSpec::new(eta, g, 4_000).unwrap();
            spec.radial_bins = 40;
            let est = spec.cost_estimate().unwrap();
            let tally = simulate(&spec.white().unwrap(), &|_| {}).unwrap();
            let ratio = est.interactions / tally.interactions as f64;
            assert!(
                (0.5..=2.0).contains(&ratio),
                "η {eta} g {g}: estimate {:.3e} vs measured {:.3e}",
                est.interactions,
                tally.interactions as f64
            );
            assert!(est.memory_bytes > 0);
        }
        // Bounded by the interaction caps whatever g is.
        let spec = McTableSpec::new(1.4, 0.999_99, 1_000).unwrap();
        let bound: f64 = spec
            .white()
            .unwrap()
            .strata
            .iter()
            .map(|s| s.photons as f64 * s.max_interactions as f64)
            .sum();
        assert!(spec.cost_estimate().unwrap().interactions <= bound);
    }

    /// Catmull-Rom weight derivatives match central differences of the weights.
    #[test]
    fn weight_derivatives_match_finite_differences() {
        let nodes = [0.0, 0.3, 0.7, 1.2, 2.0, 2.1];
        for i in 0..100 {
            let x = 0.001 + 2.098 * i as f64 / 99.0;
            let (k, _, d) = hermite_weights(nodes.len(), |j| nodes[j], x, Ends::Chord);
            let h = 1e-7;
            let (kp, wp) = catmull_rom_weights(nodes.len(), |j| nodes[j], x + h);
            let (km, wm) = catmull_rom_weights(nodes.len(), |j| nodes[j], x - h);
            if kp != k || km != k {
                continue;
            }
            for q in 0..4 {
                assert!((d[q] - (wp[q] - wm[q]) / (2.0 * h)).abs() < 1e-6, "x = {x}");
            }
        }
    }

    /// With parabolic ends the interpolant reproduces any quadratic exactly on uniform nodes (as
    /// the albedo nodes are, in √(1 − a)), in the end intervals too — the chord ends do not: that
    /// was their error toward a → 1 — and so does its derivative.
    #[test]
    fn parabolic_ends_are_exact_for_quadratics() {
        let nodes = [0.0, 0.35, 0.7, 1.05, 1.4, 1.75, 2.1];
        let f = |x: f64| 1.0 - 2.5 * x + 3.0 * x * x;
        let mut chord_worst = 0.0f64;
        for i in 0..200 {
            let x = 2.1 * i as f64 / 199.0;
            let (k, w, d) = hermite_weights(nodes.len(), |j| nodes[j], x, Ends::Parabola);
            let val = |w: &[f64; 4]| dot4(w, |q| f(nodes[k + q - 1]));
            assert!((val(&w) - f(x)).abs() < 1e-12, "x = {x}");
            assert!((val(&d) - (-2.5 + 6.0 * x)).abs() < 1e-9, "x = {x}");
            let (_, wc) = catmull_rom_weights(nodes.len(), |j| nodes[j], x);
            chord_worst = chord_worst.max((val(&wc) - f(x)).abs());
        }
        assert!(
            chord_worst > 1e-3,
            "the chord ends were exact: {chord_worst}"
        );
    }

    /// The model's analytic derivatives (of the interpolant: albedo weights, κ₀(a), the spline in
    /// ln ρ, similarity) agree with central differences of the model itself, between albedo nodes,
    /// between η tables, and for g ≠ 0 the chain through σs = σ′s/(1 − g).
    #[test]
    fn derivatives_match_finite_differences() {
        let set = small_set(&[1.0, 1.2, 1.5]);
        let set_g = McTableSet::new(
            [1.2, 1.5]
                .iter()
                .map(|&e| McTable::build(&small_spec_g(e, 0.5), &|_, _| {}).unwrap())
                .collect(),
        )
        .unwrap();
        for (sp, sa, eta, set) in [
            (1.0, 0.05, 1.0, &set),
            (2.0, 0.4, 1.33, &set),
            (0.7, 0.02, 1.5, &set),
            (1.3, 0.3, 1.2, &set),
            (1.0, 0.1, 1.4, &set_g),
        ] {
            let model = |sp: f64, sa: f64| {
                McProfile::new(set, &OpticalProperties::new(sp, sa, eta).unwrap()).unwrap()
            };
            let m = model(sp, sa);
            for r in [0.02, 0.3, 1.0, 4.0, 12.0] {
                let got = m.rd_with_derivatives(r);
                let (h_sp, h_sa) = (1e-6 * sp, 1e-6 * sa);
                let fd_sp =
                    (model(sp + h_sp, sa).rd(r) - model(sp - h_sp, sa).rd(r)) / (2.0 * h_sp);
                let fd_sa =
                    (model(sp, sa + h_sa).rd(r) - model(sp, sa - h_sa).rd(r)) / (2.0 * h_sa);
                let tol = |fd: f64| 1e-5 * fd.abs() + 1e-7 * got.rd;
                assert!(
                    (got.d_sigma_s_prime - fd_sp).abs() <= tol(fd_sp),
                    "∂/∂σ′s r = {r} ({sp}, {sa}, {eta}): {} vs {fd_sp}",
                    got.d_sigma_s_prime
                );
                assert!(
                    (got.d_sigma_a - fd_sa).abs() <= tol(fd_sa),
                    "∂/∂σa r = {r} ({sp}, {sa}, {eta}): {} vs {fd_sa}",
                    got.d_sigma_a
                );
                assert_eq!(got.rd, m.rd(r));
            }
        }
    }

    /// Similarity: doubling σ′s and σa halves every length, so Rd(r/2) = 4 Rd(r); at a node η the
    /// set returns that table's own values; between η tables, totals lie between their neighbours;
    /// out-of-range albedo and η are errors naming the coordinate.
    #[test]
    fn similarity_nodes_and_ranges() {
        let set = small_set(&[1.0, 1.4]);
        let p1 = OpticalProperties::new(1.0, 0.1, 1.4).unwrap();
        let p2 = OpticalProperties::new(2.0, 0.2, 1.4).unwrap();
        let (m1, m2) = (
            McProfile::new(&set, &p1).unwrap(),
            McProfile::new(&set, &p2).unwrap(),
        );
        for r in [0.1, 1.0, 5.0] {
            assert!((m2.rd(r / 2.0) / (4.0 * m1.rd(r)) - 1.0).abs() < 1e-12);
        }
        let only = McTableSet::new(vec![set.tables()[1].clone()]).unwrap();
        assert_eq!(McProfile::new(&only, &p1).unwrap().rd(1.0), m1.rd(1.0));
        let a = 0.9;
        let (lo, hi) = (set.rd_total(a, 1.0).unwrap(), set.rd_total(a, 1.4).unwrap());
        let mid = set.rd_total(a, 1.2).unwrap();
        assert!(mid < lo && mid > hi, "{lo} {mid} {hi}");
        let e = McProfile::new(&set, &OpticalProperties::new(1.0, 10.0, 1.2).unwrap());
        assert!(matches!(
            e,
            Err(McError::Optics(
                scatterfit_optics::OpticsError::OutOfTable {
                    name: "albedo (σs/σt)",
                    ..
                }
            ))
        ));
        let e = McProfile::new(&set, &OpticalProperties::new(1.0, 0.1, 1.6).unwrap());
        assert!(matches!(
            e,
            Err(McError::Optics(
                scatterfit_optics::OpticsError::OutOfTable { name: "eta", .. }
            ))
        ));
        assert!(McProfile::new(&only, &OpticalProperties::new(1.0, 0.1, 1.41).unwrap()).is_err());
    }

    /// g ≠ 0: the white table is in the single-scattering albedo a at σt = 1, and McProfile maps
    /// (σ′s, σa, g) onto it; its total agrees with the MCML engine run on the same layer
    /// (`Layer::from_reduced`, σs = σ′s/(1 − g)) within 4 combined standard errors + 0.003 (the small
    /// table's interpolation).
    #[test]
    fn anisotropic_total_matches_engine() {
        let (g, eta, sp, sa) = (0.5, 1.3, 1.0, 0.05);
        let t = McTable::build(&small_spec_g(eta, g), &|_, _| {}).unwrap();
        let set = McTableSet::new(vec![t]).unwrap();
        let m = McProfile::new(&set, &OpticalProperties::new(sp, sa, eta).unwrap()).unwrap();
        let half = crate::Sample::slab(
            crate::Layer::from_reduced(sp, sa, g, eta, f64::INFINITY).unwrap(),
            1.0,
        )
        .unwrap();
        let grid = crate::RadialGrid::uniform(1.0, 10).unwrap();
        let d = crate::Simulation::new(half, crate::Beam::pencil(), grid, 40_000, 9)
            .unwrap()
            .run();
        let a = (sp / (1.0 - g)) / (sa + sp / (1.0 - g));
        let (_, se) = set.tables()[0].totals();
        let k = set.tables()[0].albedos().partition_point(|&x| x < a);
        let tol = 4.0 * (d.rd_total.stderr.powi(2) + se[k].powi(2)).sqrt() + 0.003;
        assert!(
            (m.rd_total() - d.rd_total.value).abs() <= tol,
            "{} vs engine {:?}",
            m.rd_total(),
            d.rd_total
        );
    }

    /// α′ from the Monte Carlo total inverts the total at any η of the set (round trip 1e-12), and an
    /// Rd outside the tabulated range is refused.
    #[test]
    fn albedo_from_total_round_trips_across_eta() {
        let set = small_set(&[1.0, 1.4]);
        for eta in [1.0, 1.17, 1.4] {
            for a in [0.31, 0.5, 0.8, 0.95, 0.989] {
                let rd = set.rd_total(a, eta).unwrap();
                let back = set.albedo_from_rd_total(rd, eta).unwrap();
                assert!(
                    (set.rd_total(back, eta).unwrap() - rd).abs() < 1e-12,
                    "η {eta} a {a}"
                );
                assert!((back - a).abs() < 1e-9);
            }
            assert!(set.albedo_from_rd_total(0.99, eta).is_err());
            assert!(set.albedo_from_rd_total(0.001, eta).is_err());
        }
    }

    /// The cache: built once, then loaded; a damaged file is rebuilt; the compact form (no raw
    /// profiles) gives the same model and parses back.
    #[test]
    fn cache_and_compact_round_trip() {
        let dir = tempfile::tempdir().unwrap();
        let spec = small_spec(1.2);
        let (a, s1, path) = McTable::load_or_build(&spec, dir.path(), &|_, _| {}).unwrap();
        assert_eq!(s1, CacheStatus::Built);
        let (b, s2, _) = McTable::load_or_build(&spec, dir.path(), &|_, _| {}).unwrap();
        assert_eq!((s2, &a), (CacheStatus::Loaded, &b));
        std::fs::write(&path, b"[1, 2").unwrap();
        let (c, s3, _) = McTable::load_or_build(&spec, dir.path(), &|_, _| {}).unwrap();
        assert_eq!((s3, &a), (CacheStatus::Built, &c));
        let compact = a.clone().without_raw();
        let json = serde_json::to_string(&compact).unwrap();
        let back = McTable::from_json(&json).unwrap();
        let p = OpticalProperties::new(1.0, 0.1, 1.2).unwrap();
        let (m1, m2) = (
            McProfile::new(&McTableSet::new(vec![a]).unwrap(), &p).unwrap(),
            McProfile::new(&McTableSet::new(vec![back]).unwrap(), &p).unwrap(),
        );
        assert_eq!(m1.rd(2.0), m2.rd(2.0));
        assert!(McTable::from_json("{}").is_err());
        // A table with broken knots or non-increasing totals is refused by the checks, not used.
        let mut bad: serde_json::Value = serde_json::from_str(&json).unwrap();
        bad["knots"]["intervals"] = 0.into();
        assert!(
            McTable::from_json(&bad.to_string())
                .unwrap_err()
                .contains("bad knots")
        );
        let mut bad: serde_json::Value = serde_json::from_str(&json).unwrap();
        bad["rd_total"][3] = 0.0.into();
        assert!(
            McTable::from_json(&bad.to_string())
                .unwrap_err()
                .contains("increase")
        );
    }
}
