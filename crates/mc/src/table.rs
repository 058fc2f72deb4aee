//! Profile tables: Monte Carlo Rd(r) of a half-space for a grid of reduced albedos α′ at σ′t = 1
//! mm⁻¹, for one η and g, scaled to any σ′t by the similarity law, plus total Rd(α′).
//!
//! Similarity (pbrt's `TabulatedBSSRDF::Sr`, physics.md §2.3): a half-space with coefficients
//! σ′t·(σa, σs) is the σ′t = 1 half-space with every length divided by σ′t, so
//! Rd(r; σ′t, α′) = σ′t² R̂(σ′t r; α′) exactly (same g, η). Tables are cached on disk with the
//! parameters that made them and a format version; a cached file is reused only when both match.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::beam::Beam;
use crate::engine::Simulation;
use crate::error::{McError, Result, check};
use crate::grid::RadialGrid;
use crate::sample::{Layer, Sample};

/// Version of the table file format; files of another version are rebuilt.
pub const FORMAT_VERSION: u32 = 1;
/// Largest reduced albedo of the default grid: at α′ = 1 a half-space has no absorption and photon
/// paths have unbounded mean length.
pub const DEFAULT_MAX_ALBEDO: f64 = 0.999;

/// What a table is made of. Two specs that compare equal give the same table bit for bit.
///
/// Built only through [`TableSpec::new`], [`TableSpec::coarse`] and [`TableSpec::from_parts`] (and
/// the checked `with_*` variations); a cache file's spec is read through the same checks
/// (`#[serde(try_from)]`), so every value of this type is valid.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "RawSpec")]
pub struct TableSpec {
    /// Relative refractive index η of the half-space (outside index 1).
    eta: f64,
    /// Henyey–Greenstein asymmetry g (σs = σ′s/(1 − g)).
    g: f64,
    /// Reduced albedos α′, strictly increasing, in [0, 1).
    albedos: Vec<f64>,
    /// Radial bin edges in units of the reduced mean free path 1/σ′t (the radii at σ′t = 1 mm⁻¹).
    radial_edges: Vec<f64>,
    /// Photons traced per albedo.
    photons_per_albedo: u64,
    /// Seed; albedo i uses seed + i.
    seed: u64,
}

/// The unchecked shape of [`TableSpec`] in files.
#[derive(Deserialize)]
struct RawSpec {
    eta: f64,
    g: f64,
    albedos: Vec<f64>,
    radial_edges: Vec<f64>,
    photons_per_albedo: u64,
    seed: u64,
}

impl TryFrom<RawSpec> for TableSpec {
    type Error = McError;
    fn try_from(raw: RawSpec) -> Result<Self> {
        Self::from_parts(
            raw.eta,
            raw.g,
            raw.albedos,
            raw.radial_edges,
            raw.photons_per_albedo,
            raw.seed,
        )
    }
}

impl TableSpec {
    /// A spec from all its parts, checked ([`TableSpec::validate`]'s rules).
    ///
    /// # Errors
    /// `InvalidParameter` naming the first bad part.
    pub fn from_parts(
        eta: f64,
        g: f64,
        albedos: Vec<f64>,
        radial_edges: Vec<f64>,
        photons_per_albedo: u64,
        seed: u64,
    ) -> Result<Self> {
        let spec = Self {
            eta,
            g,
            albedos,
            radial_edges,
            photons_per_albedo,
            seed,
        };
        spec.validate()?;
        Ok(spec)
    }

    /// The same spec with other albedos.
    ///
    /// # Errors
    /// As [`TableSpec::from_parts`].
    pub fn with_albedos(self, albedos: Vec<f64>) -> Result<Self> {
        Self::from_parts(
            self.eta,
            self.g,
            albedos,
            self.radial_edges,
            self.photons_per_albedo,
            self.seed,
        )
    }

    /// The same spec with another seed (always valid).
    #[must_use]
    pub fn with_seed(mut self, seed: u64) -> Self {
        self.seed = seed;
        self
    }

    /// Relative refractive index η of the half-space (outside index 1).
    pub fn eta(&self) -> f64 {
        self.eta
    }
    /// Henyey–Greenstein asymmetry g.
    pub fn g(&self) -> f64 {
        self.g
    }
    /// Reduced albedos α′, strictly increasing, in [0, 1).
    pub fn albedos(&self) -> &[f64] {
        &self.albedos
    }
    /// Radial bin edges in reduced mean free paths (the radii at σ′t = 1 mm⁻¹).
    pub fn radial_edges(&self) -> &[f64] {
        &self.radial_edges
    }
    /// Photons traced per albedo.
    pub fn photons_per_albedo(&self) -> u64 {
        self.photons_per_albedo
    }
    /// Seed; albedo i uses seed + i.
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// The default layout: `albedo_count` albedos equally spaced in √(1 − α′) from α′ = 0 to
    /// [`DEFAULT_MAX_ALBEDO`] (dense near 1, where profiles change fastest), 64 radial bins, the
    /// first [0, 0.005), then logarithmic to 200 mean free paths.
    ///
    /// # Errors
    /// `InvalidParameter` for η not finite and > 0, g outside (−1, 1), fewer than 2 albedos or zero
    /// photons.
    pub fn new(eta: f64, g: f64, albedo_count: usize, photons_per_albedo: u64) -> Result<Self> {
        check(
            albedo_count >= 2,
            "albedo_count",
            albedo_count as f64,
            "need at least 2 albedos",
        )?;
        let u_max = (1.0 - DEFAULT_MAX_ALBEDO).sqrt();
        let albedos = (0..albedo_count)
            .map(|i| {
                let t = i as f64 / (albedo_count - 1) as f64;
                let u = 1.0 + (u_max - 1.0) * t;
                1.0 - u * u
            })
            .collect();
        let radial_edges = RadialGrid::logarithmic(0.005, 200.0, 64)?.edges().to_vec();
        Self::from_parts(eta, g, albedos, radial_edges, photons_per_albedo, 1)
    }

    /// A coarse table that builds in seconds: 16 albedos × 50 000 photons.
    ///
    /// # Errors
    /// As [`TableSpec::new`].
    pub fn coarse(eta: f64, g: f64) -> Result<Self> {
        Self::new(eta, g, 16, 50_000)
    }

    /// Checks every field (every constructor does; kept public for callers that hold a spec from
    /// elsewhere).
    ///
    /// # Errors
    /// `InvalidParameter` naming the first bad field.
    pub fn validate(&self) -> Result<()> {
        check(
            self.eta.is_finite() && self.eta > 0.0,
            "eta",
            self.eta,
            "η must be finite and > 0",
        )?;
        check(
            self.g.is_finite() && self.g.abs() < 1.0,
            "g",
            self.g,
            "g must lie in (−1, 1)",
        )?;
        check(
            self.photons_per_albedo > 0,
            "photons_per_albedo",
            0.0,
            "need photons",
        )?;
        check(
            self.albedos.len() >= 2,
            "albedos",
            self.albedos.len() as f64,
            "need ≥ 2 albedos",
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
        check(lo >= 0.0, "albedo_prime", lo, "albedos must be ≥ 0")?;
        check(
            hi < 1.0,
            "albedo_prime",
            hi,
            "albedos must be < 1 (α′ = 1 never ends)",
        )?;
        RadialGrid::from_edges(self.radial_edges.clone())?;
        Ok(())
    }

    /// The expected cost of [`ProfileTable::build`]: the sum over albedos of each simulation's
    /// [`Simulation::cost_estimate`] (memory: the largest, they run one after the other).
    ///
    /// # Errors
    /// `InvalidParameter` if a simulation cannot be set up (not for a valid spec).
    pub fn cost_estimate(&self) -> Result<crate::CostEstimate> {
        let grid = RadialGrid::from_edges(self.radial_edges.clone())?;
        let mut total = crate::CostEstimate {
            interactions_per_photon: 0.0,
            interactions: 0.0,
            memory_bytes: 0,
        };
        for &albedo in &self.albedos {
            let layer = Layer::from_reduced(albedo, 1.0 - albedo, self.g, self.eta, f64::INFINITY)?;
            let sim = Simulation::new(
                Sample::slab(layer, 1.0)?,
                Beam::pencil(),
                grid.clone(),
                self.photons_per_albedo,
                0,
            )?;
            let c = sim.cost_estimate();
            total.interactions += c.interactions;
            total.memory_bytes = total.memory_bytes.max(c.memory_bytes);
        }
        total.interactions_per_photon =
            total.interactions / (self.photons_per_albedo as f64 * self.albedos.len() as f64);
        Ok(total)
    }

    /// A short stable hash of the spec (FNV-1a 64 of its JSON), used in the cache file name.
    pub fn fingerprint(&self) -> String {
        let json = serde_json::to_string(self).expect("a spec of numbers always serialises");
        let mut h: u64 = 0xcbf2_9ce4_8422_2325;
        for b in json.bytes() {
            h ^= u64::from(b);
            h = h.wrapping_mul(0x0000_0100_0000_01b3);
        }
        format!("{h:016x}")
    }

    /// The cache file name for this spec.
    pub fn file_name(&self) -> String {
        format!(
            "mc-table-v{FORMAT_VERSION}-eta{:.4}-g{:.3}-{}.json",
            self.eta,
            self.g,
            self.fingerprint()
        )
    }
}

/// A built table: R̂(ρ; α′) per albedo and radial bin at σ′t = 1, with standard errors, and totals.
/// Read from JSON through the consistency checks of [`ProfileTable::load`] (`#[serde(try_from)]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "RawTable")]
pub struct ProfileTable {
    format: String,
    version: u32,
    spec: TableSpec,
    /// R̂ per (albedo, bin), row-major [mm⁻² at σ′t = 1].
    rd: Vec<f64>,
    rd_stderr: Vec<f64>,
    rd_total: Vec<f64>,
    rd_total_stderr: Vec<f64>,
    /// Area-weighted bin centres (optical radii).
    centers: Vec<f64>,
}

/// The unchecked shape of [`ProfileTable`] in files.
#[derive(Deserialize)]
struct RawTable {
    format: String,
    version: u32,
    spec: TableSpec,
    rd: Vec<f64>,
    rd_stderr: Vec<f64>,
    rd_total: Vec<f64>,
    rd_total_stderr: Vec<f64>,
    centers: Vec<f64>,
}

impl TryFrom<RawTable> for ProfileTable {
    type Error = String;
    /// The format tag and version, and every array's length against the spec.
    fn try_from(raw: RawTable) -> std::result::Result<Self, String> {
        let bins = raw.spec.radial_edges.len() - 1;
        let rows = raw.spec.albedos.len();
        if raw.format != FORMAT_TAG || raw.version != FORMAT_VERSION {
            return Err(format!(
                "format {:?} version {}, expected {FORMAT_TAG:?} version {FORMAT_VERSION}",
                raw.format, raw.version
            ));
        }
        let sizes = [
            ("centers", raw.centers.len(), bins),
            ("rd", raw.rd.len(), bins * rows),
            ("rd_stderr", raw.rd_stderr.len(), bins * rows),
            ("rd_total", raw.rd_total.len(), rows),
            ("rd_total_stderr", raw.rd_total_stderr.len(), rows),
        ];
        if let Some((name, got, want)) = sizes.iter().find(|(_, got, want)| got != want) {
            return Err(format!("`{name}` has {got} values, the spec needs {want}"));
        }
        Ok(Self {
            format: raw.format,
            version: raw.version,
            spec: raw.spec,
            rd: raw.rd,
            rd_stderr: raw.rd_stderr,
            rd_total: raw.rd_total,
            rd_total_stderr: raw.rd_total_stderr,
            centers: raw.centers,
        })
    }
}

/// How [`ProfileTable::load_or_build`] obtained its table.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum CacheStatus {
    /// Read from a cache file made with the same spec and format.
    Loaded,
    /// Simulated and written to the cache (no usable file was there).
    Built,
}

const FORMAT_TAG: &str = "scatterfit-mc-profile-table";

impl ProfileTable {
    /// Simulates the table on the current rayon pool; `progress(done, total)` counts photons.
    ///
    /// # Errors
    /// `InvalidParameter` for a bad spec.
    pub fn build(spec: &TableSpec, progress: &(dyn Fn(u64, u64) + Sync)) -> Result<Self> {
        spec.validate()?;
        let grid = RadialGrid::from_edges(spec.radial_edges.clone())?;
        let bins = grid.bins();
        let total = spec.photons_per_albedo * spec.albedos.len() as u64;
        let mut table = Self {
            format: FORMAT_TAG.to_owned(),
            version: FORMAT_VERSION,
            spec: spec.clone(),
            rd: Vec::with_capacity(bins * spec.albedos.len()),
            rd_stderr: Vec::with_capacity(bins * spec.albedos.len()),
            rd_total: Vec::new(),
            rd_total_stderr: Vec::new(),
            centers: (0..bins).map(|i| grid.center(i)).collect(),
        };
        for (i, &albedo) in spec.albedos.iter().enumerate() {
            // σ′t = 1: σ′s = α′, σa = 1 − α′.
            let layer = Layer::from_reduced(albedo, 1.0 - albedo, spec.g, spec.eta, f64::INFINITY)?;
            let sample = Sample::slab(layer, 1.0)?;
            let sim = Simulation::new(
                sample,
                Beam::pencil(),
                grid.clone(),
                spec.photons_per_albedo,
                spec.seed.wrapping_add(i as u64),
            )?;
            let done = spec.photons_per_albedo * i as u64;
            let result = sim.run_with_progress(&|n| progress(done + n, total));
            table.rd.extend(result.rd_profile.iter().map(|e| e.value));
            table
                .rd_stderr
                .extend(result.rd_profile.iter().map(|e| e.stderr));
            table.rd_total.push(result.rd_total.value);
            table.rd_total_stderr.push(result.rd_total.stderr);
        }
        Ok(table)
    }

    /// The spec that made the table.
    pub fn spec(&self) -> &TableSpec {
        &self.spec
    }

    /// Area-weighted centres of the radial bins [reduced mean free paths].
    pub fn centers(&self) -> &[f64] {
        &self.centers
    }

    /// R̂ of albedo `i` (an index into `spec().albedos`) per radial bin [mm⁻² at σ′t = 1].
    pub fn profile(&self, i: usize) -> &[f64] {
        let b = self.centers.len();
        &self.rd[i * b..(i + 1) * b]
    }

    /// Standard errors of [`ProfileTable::profile`].
    pub fn profile_stderr(&self, i: usize) -> &[f64] {
        let b = self.centers.len();
        &self.rd_stderr[i * b..(i + 1) * b]
    }

    /// Total diffuse reflectance (excluding R_sp) at each tabulated albedo, and standard errors.
    pub fn totals(&self) -> (&[f64], &[f64]) {
        (&self.rd_total, &self.rd_total_stderr)
    }

    /// Catmull-Rom weights of α′ in the albedo grid, in the coordinate x = −√(1 − α′) (increasing
    /// with α′; Rd varies like √(1 − α′) near α′ = 1, Jensen 2001's total Rd): value =
    /// Σₖ w[k]·f[i − 1 + k] (pbrt's `CatmullRomWeights`, physics.md §2.3).
    fn albedo_weights(&self, albedo: f64) -> Result<(usize, [f64; 4])> {
        let a = &self.spec.albedos;
        let (lo, hi) = (a[0], a[a.len() - 1]);
        if !(albedo >= lo && albedo <= hi) {
            return Err(McError::OutOfTable {
                name: "albedo_prime",
                value: albedo,
                min: lo,
                max: hi,
            });
        }
        let x = |v: f64| -(1.0 - v).sqrt();
        Ok(catmull_rom_weights(a.len(), |k| x(a[k]), x(albedo)))
    }

    /// R̂(ρ) of albedo row `i` at optical radius ρ, interpolated between bin centres (log-linear where
    /// both neighbours are positive, else linear; constant inside the first centre).
    fn row_at(&self, i: usize, rho: f64) -> f64 {
        let c = &self.centers;
        let row = self.profile(i);
        if rho <= c[0] {
            return row[0];
        }
        let j = c.partition_point(|&x| x <= rho).min(c.len() - 1) - 1;
        let t = (rho - c[j]) / (c[j + 1] - c[j]);
        let (a, b) = (row[j], row[j + 1]);
        if a > 0.0 && b > 0.0 {
            (a.ln() * (1.0 - t) + b.ln() * t).exp()
        } else {
            a * (1.0 - t) + b * t
        }
    }

    /// Rd(r) [mm⁻²] of a half-space with reduced extinction σ′t [mm⁻¹] and reduced albedo α′, by the
    /// similarity law Rd(r; σ′t, α′) = σ′t² R̂(σ′t r; α′) (physics.md §2.3). Between albedos: Catmull-Rom
    /// in √(1 − α′) on ln R̂ (pbrt's table uses Catmull-Rom, physics.md §2.3; the logarithm because
    /// far from the source R̂ ∝ exp(−√(3(1 − α′))·ρ), which is linear in √(1 − α′) after the log, and
    /// varies by an order of magnitude between neighbouring default albedos near α′ = 1); on the
    /// values themselves where one of them is not positive. Between bin centres: log-linear in ρ.
    ///
    /// # Errors
    /// `InvalidParameter` for r < 0 or σ′t ≤ 0 (or not finite); `OutOfTable` for α′ outside the
    /// tabulated range or σ′t r beyond the last bin centre.
    pub fn rd(&self, r: f64, sigma_t_prime: f64, albedo_prime: f64) -> Result<f64> {
        check(
            r.is_finite() && r >= 0.0,
            "r",
            r,
            "the radius must be finite and ≥ 0 mm",
        )?;
        check(
            sigma_t_prime.is_finite() && sigma_t_prime > 0.0,
            "sigma_t_prime",
            sigma_t_prime,
            "σ′t must be finite and > 0 mm⁻¹",
        )?;
        let rho = r * sigma_t_prime;
        let last = self.centers[self.centers.len() - 1];
        if rho > last {
            return Err(McError::OutOfTable {
                name: "sigma_t_prime * r",
                value: rho,
                min: 0.0,
                max: last,
            });
        }
        let (i, w) = self.albedo_weights(albedo_prime)?;
        let mut rows = [0.0; 4];
        for (k, v) in rows.iter_mut().enumerate() {
            if w[k] != 0.0 {
                *v = self.row_at(i + k - 1, rho);
            }
        }
        let used = || (0..4).filter(|&k| w[k] != 0.0);
        let v = if let Some(k) = (0..4).find(|&k| w[k] == 1.0) {
            // At a node: the row itself (exp∘ln would round).
            rows[k]
        } else if used().all(|k| rows[k] > 0.0) {
            used().map(|k| w[k] * rows[k].ln()).sum::<f64>().exp()
        } else {
            used().map(|k| w[k] * rows[k]).sum::<f64>().max(0.0)
        };
        Ok(sigma_t_prime * sigma_t_prime * v)
    }

    /// Total diffuse reflectance Rd(α′) (excluding R_sp): Catmull-Rom in √(1 − α′) between albedos
    /// (pbrt's ρ_eff table, physics.md §2.4).
    ///
    /// # Errors
    /// `OutOfTable` for α′ outside the tabulated range.
    pub fn rd_total(&self, albedo_prime: f64) -> Result<f64> {
        let (i, w) = self.albedo_weights(albedo_prime)?;
        Ok((0..4)
            .filter(|&k| w[k] != 0.0)
            .map(|k| w[k] * self.rd_total[i + k - 1])
            .sum())
    }

    /// The reduced albedo α′ whose total diffuse reflectance is `rd`: the inverse of
    /// [`ProfileTable::rd_total`] (Rd increases with α′), found like pbrt's `InvertCatmullRom`
    /// (physics.md §2.4) by bisection in √(1 − α′) inside the interval whose node totals bracket `rd`.
    ///
    /// # Errors
    /// `OutOfTable` when `rd` lies outside the tabulated totals.
    pub fn albedo_from_rd_total(&self, rd: f64) -> Result<f64> {
        let r = &self.rd_total;
        let a = &self.spec.albedos;
        let (lo, hi) = (r[0], r[r.len() - 1]);
        for i in 0..r.len() - 1 {
            if rd >= r[i] && rd <= r[i + 1] && r[i + 1] > r[i] {
                if rd == r[i] {
                    return Ok(a[i]);
                }
                if rd == r[i + 1] {
                    return Ok(a[i + 1]);
                }
                // Bisection on u = √(1 − α′) ∈ [u(a[i+1]), u(a[i])]; Rd decreases with u.
                let (mut u_lo, mut u_hi) = ((1.0 - a[i + 1]).sqrt(), (1.0 - a[i]).sqrt());
                for _ in 0..200 {
                    let u = 0.5 * (u_lo + u_hi);
                    if u <= u_lo || u >= u_hi {
                        break;
                    }
                    if self.rd_total(1.0 - u * u)? >= rd {
                        u_lo = u;
                    } else {
                        u_hi = u;
                    }
                }
                let u = 0.5 * (u_lo + u_hi);
                return Ok((1.0 - u * u).clamp(a[i], a[i + 1]));
            }
        }
        Err(McError::OutOfTable {
            name: "rd_total",
            value: rd,
            min: lo,
            max: hi,
        })
    }

    /// Reads a table file.
    ///
    /// # Errors
    /// `Io` when it cannot be read, `Format` when it is not a table of this format version.
    pub fn load(path: &Path) -> Result<Self> {
        crate::cache::read_with(path, |text| {
            serde_json::from_str(text).map_err(|e| e.to_string())
        })
    }

    /// Writes the table atomically: a temporary file in the same folder, synced, then renamed.
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
    /// `InvalidParameter` for a bad spec, `Io` when the cache cannot be written.
    pub fn load_or_build(
        spec: &TableSpec,
        dir: &Path,
        progress: &(dyn Fn(u64, u64) + Sync),
    ) -> Result<(Self, CacheStatus, PathBuf)> {
        spec.validate()?;
        crate::cache::load_or_build(
            dir.join(spec.file_name()),
            Self::load,
            |t| t.spec == *spec,
            || Self::build(spec, progress),
            Self::save,
        )
    }
}

/// Catmull-Rom weights at `x` over the `n` strictly increasing nodes `node(k)` (pbrt-v3's
/// `CatmullRomWeights`, physics.md §2.3): returns (i, w) with x ∈ [node(i), node(i + 1)] and the
/// interpolant Σₖ w[k]·f(i − 1 + k); the end derivatives are one-sided (w[0] or w[3] is then 0).
/// Cubic Hermite with finite-difference derivatives on non-uniform nodes; exact at the nodes.
pub(crate) fn catmull_rom_weights(
    n: usize,
    node: impl Fn(usize) -> f64,
    x: f64,
) -> (usize, [f64; 4]) {
    // First i with node(i + 1) > x, clamped to the last interval.
    let mut i = 0;
    while i + 2 < n && node(i + 1) <= x {
        i += 1;
    }
    let (x0, x1) = (node(i), node(i + 1));
    let t = ((x - x0) / (x1 - x0)).clamp(0.0, 1.0);
    let (t2, t3) = (t * t, t * t * t);
    let mut w = [0.0, 2.0 * t3 - 3.0 * t2 + 1.0, -2.0 * t3 + 3.0 * t2, 0.0];
    let w0 = t3 - 2.0 * t2 + t;
    if i > 0 {
        let w0 = w0 * (x1 - x0) / (x1 - node(i - 1));
        w[0] = -w0;
        w[2] += w0;
    } else {
        w[1] -= w0;
        w[2] += w0;
    }
    let w3 = t3 - t2;
    if i + 2 < n {
        let w3 = w3 * (x1 - x0) / (node(i + 2) - x0);
        w[1] -= w3;
        w[3] = w3;
    } else {
        w[1] -= w3;
        w[2] += w3;
    }
    (i, w)
}

/// The cache folder: `$SCATTERFIT_CACHE`, else `$XDG_CACHE_HOME/scatterfit`, else
/// `$HOME/.cache/scatterfit`; `None` when none of these is set.
pub fn default_cache_dir() -> Option<PathBuf> {
    let var = |k| {
        std::env::var_os(k)
            .filter(|v| !v.is_empty())
            .map(PathBuf::from)
    };
    var("SCATTERFIT_CACHE")
        .or_else(|| var("XDG_CACHE_HOME").map(|p| p.join("scatterfit")))
        .or_else(|| var("HOME").map(|p| p.join(".cache").join("scatterfit")))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn small_spec() -> TableSpec {
        TableSpec::new(1.3, 0.0, 3, 2_000)
            .unwrap()
            .with_albedos(vec![0.3, 0.8, 0.95])
            .unwrap()
    }

    /// A spec or a table read back from JSON equals the one written; a spec or table that breaks
    /// the constructor's rules or the sizes is refused on reading.
    #[test]
    fn json_goes_through_the_checks() {
        let spec = small_spec();
        let json = serde_json::to_string(&spec).unwrap();
        assert_eq!(serde_json::from_str::<TableSpec>(&json).unwrap(), spec);
        for (from, to) in [
            ("\"eta\":1.3", "\"eta\":-1.3"),
            ("\"g\":0.0", "\"g\":1.0"),
            ("\"photons_per_albedo\":2000", "\"photons_per_albedo\":0"),
            ("[0.3,0.8,0.95]", "[0.8,0.3,0.95]"),
            ("[0.3,0.8,0.95]", "[0.3,0.8,1.0]"),
        ] {
            assert!(json.contains(from), "{from} in {json}");
            let bad = json.replace(from, to);
            assert!(serde_json::from_str::<TableSpec>(&bad).is_err(), "{bad}");
        }
        assert!(spec.clone().with_albedos(vec![0.5]).is_err());
        let table = ProfileTable::build(&spec, &|_, _| {}).unwrap();
        let json = serde_json::to_string(&table).unwrap();
        assert_eq!(serde_json::from_str::<ProfileTable>(&json).unwrap(), table);
        let short = json.replacen("\"rd_total\":[", "\"rd_total\":[0.5,", 1);
        let err = serde_json::from_str::<ProfileTable>(&short)
            .unwrap_err()
            .to_string();
        assert!(err.contains("rd_total"), "{err}");
    }

    /// A cached table is reused when its spec matches, rebuilt when the spec differs or the file is
    /// damaged; the file round-trips exactly.
    #[test]
    fn cache_reuse_and_rebuild() {
        let dir = tempfile::tempdir().unwrap();
        let spec = small_spec();
        let (a, s1, path) = ProfileTable::load_or_build(&spec, dir.path(), &|_, _| {}).unwrap();
        assert_eq!(s1, CacheStatus::Built);
        let (b, s2, _) = ProfileTable::load_or_build(&spec, dir.path(), &|_, _| {}).unwrap();
        assert_eq!(s2, CacheStatus::Loaded);
        assert_eq!(a, b);
        let other = spec.clone().with_seed(2);
        assert_ne!(other.file_name(), spec.file_name());
        std::fs::write(&path, b"{ not json").unwrap();
        let (c, s3, _) = ProfileTable::load_or_build(&spec, dir.path(), &|_, _| {}).unwrap();
        assert_eq!(s3, CacheStatus::Built);
        assert_eq!(a, c);
        // No temporary files are left behind.
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    /// Lookups: exact at albedo nodes and bin centres, σ′t² scaling, clear errors outside the table,
    /// and α′ from Rd inverts Rd from α′.
    #[test]
    fn lookup_and_inversion() {
        let t = ProfileTable::build(&small_spec(), &|_, _| {}).unwrap();
        let c = t.centers()[10];
        let v = t.profile(1)[10];
        assert!((t.rd(c, 1.0, 0.8).unwrap() - v).abs() <= 1e-15 * v);
        assert!((t.rd(c / 3.0, 3.0, 0.8).unwrap() - 9.0 * v).abs() <= 1e-12 * v);
        assert!(matches!(
            t.rd(c, 1.0, 0.99),
            Err(McError::OutOfTable { .. })
        ));
        assert!(matches!(
            t.rd(1e6, 1.0, 0.8),
            Err(McError::OutOfTable { .. })
        ));
        assert!(matches!(
            t.rd(-1.0, 1.0, 0.8),
            Err(McError::InvalidParameter { .. })
        ));
        for a in [0.3, 0.5, 0.8, 0.9, 0.95] {
            let rd = t.rd_total(a).unwrap();
            assert!(
                (t.albedo_from_rd_total(rd).unwrap() - a).abs() < 1e-12,
                "α′ = {a}"
            );
        }
        assert!(t.albedo_from_rd_total(0.99).is_err());
    }
}
