//! [`McTable`]: the Monte Carlo table of one (η, g) — a white run scored at a grid of albedos, each
//! row smoothed into ln R̂(ρ; aₖ) = Sₖ(ln ρ) − κ₀(aₖ)ρ, with the totals Rd(aₖ); built, combined
//! from shards, extended by low-albedo nodes, and read and written as JSON.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::weights::{Ends, dot4, hermite_weights};
use crate::cache::CacheStatus;
use crate::error::{McError, Result, check};
use crate::shard::Shard;
use crate::smooth::{Knots, fit_row, kappa0};
use crate::spec::{LowAlbedoRun, McTableSpec};
use crate::white::{WhitePartial, WhiteSpec, WhiteTally, simulate, simulate_shard};

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
    pub(super) spec: McTableSpec,
    pub(super) albedos: Vec<f64>,
    pub(super) knots: Knots,
    /// Spline coefficients per albedo, row-major (albedo k, coefficient m).
    coefs: Vec<f64>,
    /// Inner and outer radius of the data behind each row [mean free paths].
    rho_data_min: Vec<f64>,
    pub(super) rho_data_max: Vec<f64>,
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

    /// This table as its main run left it: the low-albedo nodes ([`LowAlbedoRun`]) that
    /// [`McTable::with_low_albedos`] put in front of its rows taken off again (their nodes,
    /// coefficients, data ranges, totals, χ² and raw profiles), and the spec's `low_albedos`
    /// cleared. `t.with_low_albedos(low)?.without_low_albedos()?` is `t`, bit for bit; so is the
    /// compact form's (compacting is per value). The way to replace a table's low run (with more
    /// photons): this, then [`McTable::with_low_albedos`].
    ///
    /// # Errors
    /// `InvalidParameter` (field `low_albedos`) when the table has no low-albedo nodes, or when
    /// its vectors are shorter than the nodes its spec names (a defect: the file checks refuse
    /// such a table).
    pub fn without_low_albedos(self) -> Result<Self> {
        check(
            self.spec.low_albedos.is_some(),
            "low_albedos",
            0.0,
            "the table has no low-albedo nodes to take off",
        )?;
        let n = self.spec.low_albedos.as_ref().map_or(0, |l| l.albedo_count);
        let m = self.knots.len();
        check(
            n < self.albedos.len() && n * m < self.coefs.len(),
            "low_albedos",
            n as f64,
            "the table has fewer rows than its low-albedo nodes (a defect)",
        )?;
        let tail = |v: Vec<f64>, skip: usize| v[skip..].to_vec();
        Ok(Self {
            spec: McTableSpec {
                low_albedos: None,
                ..self.spec
            },
            albedos: tail(self.albedos, n),
            coefs: tail(self.coefs, n * m),
            rho_data_min: tail(self.rho_data_min, n),
            rho_data_max: tail(self.rho_data_max, n),
            rd_total: tail(self.rd_total, n),
            rd_total_stderr: tail(self.rd_total_stderr, n),
            chi2_per_bin: tail(self.chi2_per_bin, n),
            raw: self.raw.map(|r| {
                let bins = r.edges.len().saturating_sub(1);
                RawProfiles {
                    rd: tail(r.rd, n * bins),
                    rd_stderr: tail(r.rd_stderr, n * bins),
                    edges: r.edges,
                }
            }),
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

    pub(super) fn row(&self, k: usize) -> &[f64] {
        let m = self.knots.len();
        &self.coefs[k * m..(k + 1) * m]
    }

    /// Cubic Hermite weights (and their derivatives in a) of albedo `a` over the nodes for the
    /// profile's rows, in x = [`albedo_abscissa`]: Catmull-Rom inside, parabolic at the first and
    /// last node ([`Ends`]).
    pub(super) fn albedo_weights(&self, a: f64) -> Result<(usize, [f64; 4], [f64; 4])> {
        self.albedo_weights_in(a, ALBEDO_LOG_WEIGHT)
    }

    /// The weights in x = −√(1 − a) + `log_weight`·ln a.
    fn albedo_weights_in(&self, a: f64, log_weight: f64) -> Result<(usize, [f64; 4], [f64; 4])> {
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
        let (i, w, dw_dx) = hermite_weights(
            al.len(),
            |k| albedo_abscissa(al[k], log_weight),
            albedo_abscissa(a, log_weight),
            Ends::Parabola,
        );
        let dx_da = 0.5 / (1.0 - a).sqrt() + log_weight / a;
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
        // In √(1 − a) alone: ln(Rd/a) = ln(R₁ + aR₂ + …) is smooth in a at low albedo.
        let (i, w, _) = self.albedo_weights_in(a, 0.0)?;
        let al = &self.albedos;
        // An end reached through a round trip is that end (as in the weights), so that the
        // totals at the ends are the nodes' own, bit for bit.
        let a = a.clamp(al[0], al[al.len() - 1]);
        Ok(a * dot4(&w, |k| (self.rd_total[i + k - 1] / al[i + k - 1]).ln()).exp())
    }
}

/// The weight of ln a in [`albedo_abscissa`].
const ALBEDO_LOG_WEIGHT: f64 = 0.03;

/// The abscissa the albedo interpolation is cubic in: x = −√(1 − a) + c·ln a (c =
/// [`ALBEDO_LOG_WEIGHT`]). Toward a → 1 the square root dominates (the diffusion regime, where
/// 1 − R̂ and κ₀ go as √(1 − a)); at low albedo ln a does: light reaching ρ after n scatterings
/// carries aⁿ, so ln(R̂/a) bends like (n − 1) ln a across the first nodes, which a cubic in
/// √(1 − a) — nearly linear in a there — cannot follow.
fn albedo_abscissa(a: f64, log_weight: f64) -> f64 {
    -(1.0 - a).sqrt() + log_weight * a.ln()
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::profile::McProfile;
    use crate::model::set::McTableSet;
    use crate::model::testing::{small_spec, small_spec_g};
    use scatterfit_optics::{OpticalProperties, ProfileModel};

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

    /// Low-albedo nodes taken off again ([`McTable::without_low_albedos`]) leave the table the
    /// main run made, bit for bit, raw and compact; a low run replaced by one with more photons
    /// changes the low rows only (the main rows and the low nodes stay); a table without low
    /// nodes, or with fewer rows than its spec's low nodes, is refused with the field named.
    #[test]
    fn low_albedo_nodes_taken_off_leave_the_main_run_and_can_be_replaced() {
        let spec = small_spec_g(1.3, 0.5);
        let low = |photons| {
            spec.clone()
                .with_low_albedos_to(0.3, photons)
                .unwrap()
                .low_albedos
                .unwrap()
        };
        let main = McTable::build(&spec, &|_, _| {}).unwrap();
        let with = main.clone().with_low_albedos(low(200_000)).unwrap();
        let bytes = |t: &McTable| serde_json::to_vec(t).unwrap();
        let back = with.clone().without_low_albedos().unwrap();
        assert_eq!(bytes(&back), bytes(&main));
        assert_eq!(
            bytes(&with.clone().compact().without_low_albedos().unwrap()),
            bytes(&main.clone().compact())
        );
        // Through a file: the compact table read back, its low run replaced by a longer one.
        let text = serde_json::to_string(&with.clone().compact()).unwrap();
        let replaced = McTable::from_json(&text)
            .unwrap()
            .without_low_albedos()
            .unwrap()
            .with_low_albedos(low(400_000))
            .unwrap()
            .compact();
        let n = low(1).albedo_count;
        assert_eq!(replaced.spec().low_albedos, Some(low(400_000)));
        assert_eq!(replaced.albedos(), with.albedos());
        assert_ne!(replaced.totals().0[..n], with.totals().0[..n]);
        assert_eq!(
            bytes(&replaced.without_low_albedos().unwrap()),
            bytes(&main.clone().compact())
        );
        let err = main.without_low_albedos().unwrap_err().to_string();
        assert!(
            err.contains("low_albedos") && err.contains("no low-albedo"),
            "{err}"
        );
        let mut short = with;
        short.spec.low_albedos.as_mut().unwrap().albedo_count = short.albedos.len();
        let err = short.without_low_albedos().unwrap_err().to_string();
        assert!(err.contains("fewer rows"), "{err}");
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
