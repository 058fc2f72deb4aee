//! How a Monte Carlo table is made: [`McTableSpec`] (the white run, its albedo nodes and radial
//! bins, the smoother), the spacing of its albedo nodes, and the short run of its lowest nodes.

use serde::{Deserialize, Serialize};

use crate::error::{Result, check};
use crate::model::MC_TABLE_VERSION;
use crate::smooth::SmoothParams;
use crate::white::WhiteSpec;

/// How an [`McTable`](crate::McTable) is made: the Monte Carlo run and the smoother.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct McTableSpec {
    /// Relative refractive index η (outside index 1).
    pub eta: f64,
    /// Henyey–Greenstein asymmetry g.
    pub g: f64,
    /// Number of albedo nodes, from `albedo_min` to `albedo_max`, spaced as `albedo_spacing` says.
    pub albedo_count: usize,
    /// How the albedo nodes are spaced (default: equally in √(1 − a); absent from the files of
    /// tables built that way, so their specs and cache names are unchanged).
    #[serde(default, skip_serializing_if = "AlbedoSpacing::is_default")]
    pub albedo_spacing: AlbedoSpacing,
    /// Smallest single-scattering albedo.
    pub albedo_min: f64,
    /// Largest single-scattering albedo.
    pub albedo_max: f64,
    /// Inner radius of the log-spaced bins [mean free paths]; below it one bin [0, ρ₀).
    pub rho_min: f64,
    /// Outer radius of the last bin [mean free paths].
    pub rho_max: f64,
    /// Log-spaced radial bins between `rho_min` and `rho_max`.
    pub radial_bins: usize,
    /// Photons traced in each path-length stratum ([`crate::white`]).
    pub photons: Vec<u64>,
    /// Interaction counts separating the strata (one fewer than `photons`).
    pub stratum_bounds: Vec<u64>,
    /// Seed of the random streams.
    pub seed: u64,
    /// The smoother.
    pub smooth: SmoothParams,
    /// Nodes below `albedo_min` from a short run of their own ([`LowAlbedoRun`]); absent from the
    /// files of tables without them, so their specs and cache names are unchanged.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub low_albedos: Option<LowAlbedoRun>,
}

/// Mixed into a table's seed for its low-albedo run, so that its streams are not the main run's
/// (whose strata mix the seed with multiples of 0x9E37_79B9_7F4A_7C15, [`crate::white`]).
pub const LOW_ALBEDO_SEED_MIX: u64 = 0xD1B5_4A32_D192_ED03;

/// Albedo nodes below a table's smallest albedo, from a short white run of their own.
///
/// A white run traces every photon to the cap its largest albedo needs (⌈12/(−ln a_max)⌉
/// interactions, [`WhiteSpec::new`]), whatever its smallest albedo: at g = 0.9 a table reaching
/// α′ = 0.99995 stops its longest photons after about 10⁶ interactions, while nodes below α′ = 0.2
/// (a < 0.72) need 34. Widening the long run's albedo range would cost the whole run again and
/// thin its nodes; a run of its own for the low nodes costs seconds. Same radial bins, same
/// smoother, its own random streams; its nodes continue the table's spacing
/// ([`McTableSpec::albedo_spacing`]) below the first node, no wider than the table's own step, so
/// the albedo interpolation ([`McTable`](crate::McTable)) runs across the join as across any node.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LowAlbedoRun {
    /// Number of nodes, from the smallest up to one step below the table's `albedo_min`.
    pub albedo_count: usize,
    /// The smallest single-scattering albedo (the first node).
    pub albedo_min: f64,
    /// Photons of the run (one stratum, stopped at the cap of its largest node).
    pub photons: u64,
}

/// How a table's albedo nodes are spaced between its smallest and largest single-scattering
/// albedo a.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AlbedoSpacing {
    /// Equally in √(1 − a) (the g = 0 tables, and the g ≠ 0 tables shipped first).
    #[default]
    SqrtOneMinusA,
    /// Equally in √(1 − α′), α′ = a(1 − g)/(1 − ag) the reduced albedo. At g ≠ 0 the first spacing
    /// crowds the nodes toward α′ → 1 less than at g = 0 (1 − a ≈ (1 − g)(1 − α′) there): at
    /// g = 0.9 only two of 64 nodes lie above α′ 0.998, and the far field between them is 1–5 %
    /// off (BENCHMARKS.md, "Weak absorption"). This spacing gives a g ≠ 0 table the g = 0 table's
    /// node density in α′, where the profile's shape is set.
    SqrtOneMinusReducedAlbedo,
}

impl AlbedoSpacing {
    /// Whether this is the default spacing (serde: omitted from files).
    pub fn is_default(&self) -> bool {
        *self == Self::default()
    }
}

impl McTableSpec {
    /// The default layout for η and g: 64 albedos from 0.02 to 0.9999 (√(1 − a) spacing 0.0156),
    /// 216 radial bins (Δ ln ρ = 0.05) from 0.01 to 500 mean free paths, seed 1, and three
    /// path-length strata: `photons` full-length photons, 4× as many stopped at 1024 interactions and
    /// 16× as many stopped at 64 (module [`crate::white`]).
    ///
    /// # Errors
    /// `InvalidParameter` for η < 1, g outside (−1, 1) or no photons.
    pub fn new(eta: f64, g: f64, photons: u64) -> Result<Self> {
        Self::with_strata(
            eta,
            g,
            vec![16 * photons, 4 * photons, photons],
            vec![64, 1024],
        )
    }

    /// The layout of the g = 0 tables shipped with the crate (`crates/mc/tables/`, rebuilt
    /// 2026-11-27): the default one with 128 albedo nodes instead of 64 (√(1 − a) spacing 0.0078),
    /// 4·10⁶ full-length photons, 1.6·10⁷ stopped at 1024 interactions and 3.2·10⁷ at 64, and the
    /// seed 1000 + round(100 η), so that the tables' Monte Carlo noise is independent from one η to
    /// the next. Why (CHANGELOG.md, "The g = 0 tables rebuilt"): between the 64 nodes' last two
    /// (α′ 0.99935–0.9999) Catmull-Rom put the far field 1–2 % low beyond 30 mean free paths — the
    /// light a spectrophotometer's port loses, and the g ≠ 0 model's continuation past its join
    /// ([`crate::model::McProfile::far_field_join`]) — and the full-length stratum's 2·10⁶ photons,
    /// one seed for every η, left the totals near α′ = 1 a few 10⁻⁴ off together. Below its first
    /// node (α′ 0.02) one more at 0.01 from a low-albedo run ([`LowAlbedoRun`], 6.4·10⁸ photons).
    ///
    /// # Errors
    /// `InvalidParameter` for η < 1.
    pub fn shipped(eta: f64) -> Result<Self> {
        let mut spec = Self::with_strata(
            eta,
            0.0,
            vec![32_000_000, 16_000_000, 4_000_000],
            vec![64, 1024],
        )?;
        spec.albedo_count = 128;
        spec.seed = 1000 + (100.0 * eta).round() as u64;
        spec.white()?;
        // A node at α′ 0.01 below the main run's first (0.02), from a short run of its own with
        // 160 photons per full-length photon, as the g ≠ 0 tables' low runs (added 2026-11-29: a
        // channel darker than α′ 0.02 failed at g = 0 and so, with g unknown, everywhere).
        spec.with_low_albedos_to(0.01, 160 * 4_000_000)
    }

    /// The default layout with explicit strata (`photons[k]` photons, separated at `bounds`).
    ///
    /// # Errors
    /// `InvalidParameter` for a bad field.
    pub fn with_strata(eta: f64, g: f64, photons: Vec<u64>, bounds: Vec<u64>) -> Result<Self> {
        let spec = Self {
            eta,
            g,
            albedo_count: 64,
            albedo_spacing: AlbedoSpacing::SqrtOneMinusA,
            albedo_min: 0.02,
            albedo_max: 0.9999,
            rho_min: 0.01,
            rho_max: 500.0,
            radial_bins: 216,
            photons,
            stratum_bounds: bounds,
            seed: 1,
            smooth: SmoothParams::default(),
            low_albedos: None,
        };
        spec.white()?;
        Ok(spec)
    }

    /// To and from the variable the nodes are equally spaced in, v = a or α′ (docs on
    /// [`AlbedoSpacing`]; α′ = a(1 − g)/(1 − ag) ⇔ a = α′/(1 − g + gα′)), as x = √(1 − v).
    fn spacing(&self) -> (impl Fn(f64) -> f64 + use<>, impl Fn(f64) -> f64 + use<>) {
        let g = self.g;
        let reduced = self.albedo_spacing == AlbedoSpacing::SqrtOneMinusReducedAlbedo;
        let to_x = move |a: f64| {
            let v = if reduced {
                a * (1.0 - g) / (1.0 - a * g)
            } else {
                a
            };
            (1.0 - v).sqrt()
        };
        let from_x = move |x: f64| {
            let v = 1.0 - x * x;
            if reduced { v / (1.0 - g + g * v) } else { v }
        };
        (to_x, from_x)
    }

    /// The nodes of the main run: `albedo_count` albedos from `albedo_min` to `albedo_max`.
    fn run_albedos(&self) -> Vec<f64> {
        let (to_x, from_x) = self.spacing();
        let (x0, x1) = (to_x(self.albedo_max), to_x(self.albedo_min));
        let n = self.albedo_count.max(2);
        (0..n)
            .rev()
            .map(|i| from_x(x0 + (x1 - x0) * i as f64 / (n - 1) as f64))
            .collect()
    }

    /// The nodes of the low-albedo run ([`LowAlbedoRun`]): from its `albedo_min` up to one step
    /// below the main run's first node, equally spaced in the same variable (none without it).
    fn low_run_albedos(&self) -> Vec<f64> {
        let Some(low) = &self.low_albedos else {
            return Vec::new();
        };
        let (to_x, from_x) = self.spacing();
        let (x_low, x_first) = (to_x(low.albedo_min), to_x(self.albedo_min));
        let n = low.albedo_count.max(1);
        (0..n)
            .map(|j| from_x(x_low + (x_first - x_low) * j as f64 / n as f64))
            .collect()
    }

    /// Every albedo node of the table (single-scattering albedos a, increasing): the low-albedo
    /// run's, then the main run's, spaced as `albedo_spacing` says.
    pub fn albedos(&self) -> Vec<f64> {
        let mut nodes = self.low_run_albedos();
        nodes.extend(self.run_albedos());
        nodes
    }

    /// How many albedo nodes the table has (both runs).
    pub fn node_count(&self) -> usize {
        self.albedo_count + self.low_albedos.as_ref().map_or(0, |l| l.albedo_count)
    }

    /// This spec with low-albedo nodes down to `albedo_min` ([`LowAlbedoRun`], `photons` traced):
    /// as many as keep their spacing at most the main run's step.
    ///
    /// # Errors
    /// `InvalidParameter` when `albedo_min` is not in (0, the main run's `albedo_min`), for no
    /// photons, or a bad field of the spec.
    pub fn with_low_albedos_to(mut self, albedo_min: f64, photons: u64) -> Result<Self> {
        check(
            albedo_min > 0.0 && albedo_min < self.albedo_min,
            "albedo_min",
            albedo_min,
            "the low-albedo nodes must start above 0 and below the table's smallest albedo",
        )?;
        let (to_x, _) = self.spacing();
        let step =
            (to_x(self.albedo_min) - to_x(self.albedo_max)) / (self.albedo_count.max(2) - 1) as f64;
        let width = to_x(albedo_min) - to_x(self.albedo_min);
        self.low_albedos = Some(LowAlbedoRun {
            albedo_count: (width / step).ceil().max(1.0) as usize,
            albedo_min,
            photons,
        });
        self.white()?;
        Ok(self)
    }

    /// The radial bin edges [mean free paths].
    pub fn radial_edges(&self) -> Vec<f64> {
        let mut e = vec![0.0];
        let q = (self.rho_max / self.rho_min).ln() / self.radial_bins.max(1) as f64;
        e.extend((0..=self.radial_bins).map(|i| self.rho_min * (q * i as f64).exp()));
        e
    }

    /// The white Monte Carlo run this spec asks for.
    ///
    /// # Errors
    /// `InvalidParameter` for a bad field.
    pub fn white(&self) -> Result<WhiteSpec> {
        check(
            self.albedo_count >= 4,
            "albedo_count",
            self.albedo_count as f64,
            "need at least 4 albedos (Catmull-Rom)",
        )?;
        check(
            self.albedo_min > 0.0 && self.albedo_max < 1.0 && self.albedo_min < self.albedo_max,
            "albedo_max",
            self.albedo_max,
            "need 0 < albedo_min < albedo_max < 1",
        )?;
        check(
            self.rho_min > 0.0 && self.rho_max > self.rho_min && self.radial_bins >= 8,
            "rho_max",
            self.rho_max,
            "need 0 < rho_min < rho_max and at least 8 radial bins",
        )?;
        if let Some(low) = &self.low_albedos {
            check(
                low.albedo_min > 0.0 && low.albedo_min < self.albedo_min,
                "low_albedos.albedo_min",
                low.albedo_min,
                "the low-albedo nodes must start above 0 and below the table's smallest albedo",
            )?;
            check(
                (1..=4096).contains(&low.albedo_count) && low.photons > 0,
                "low_albedos.albedo_count",
                low.albedo_count as f64,
                "the low-albedo run needs 1 to 4096 nodes and at least one photon",
            )?;
        }
        WhiteSpec::new(
            self.eta,
            self.g,
            self.run_albedos(),
            self.radial_edges(),
            &self.photons,
            &self.stratum_bounds,
            self.seed,
        )
    }

    /// The white run of the low-albedo nodes ([`LowAlbedoRun`]), if the spec has them: one stratum
    /// of its photons, stopped at the cap of its largest node ([`WhiteSpec::new`]), with random
    /// streams of their own (the seed mixed with [`LOW_ALBEDO_SEED_MIX`]).
    ///
    /// # Errors
    /// `InvalidParameter` for a bad field.
    pub fn low_albedo_white(&self) -> Result<Option<WhiteSpec>> {
        self.white()?;
        let Some(low) = &self.low_albedos else {
            return Ok(None);
        };
        WhiteSpec::new(
            self.eta,
            self.g,
            self.low_run_albedos(),
            self.radial_edges(),
            &[low.photons],
            &[],
            self.seed ^ LOW_ALBEDO_SEED_MIX,
        )
        .map(Some)
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
            "mc-white-v{MC_TABLE_VERSION}-eta{:.4}-g{:.3}-{}.json",
            self.eta,
            self.g,
            self.fingerprint()
        )
    }

    /// The default layout with few photons (20 000 full-length, 80 000 and 320 000 in the shorter
    /// strata): a table that builds in a few seconds (1–4 s on two cores for η = 1–2.5, g = 0), at
    /// about ten times the default table's noise.
    ///
    /// # Errors
    /// As [`McTableSpec::new`].
    pub fn coarse(eta: f64, g: f64) -> Result<Self> {
        Self::new(eta, g, 20_000)
    }

    /// The expected cost of [`McTable::build`](crate::McTable::build), before it runs: interactions, from a fit to measured
    /// counts of white runs (η 1–2.5, g 0–0.9, stratum caps 64 to 120 000; within a factor 2 of
    /// them, `cost_estimate_matches_measured_work`), and the tallies' memory.
    ///
    /// Per photon of a stratum that stops at N interactions, with the roulette at R < N keeping ¼:
    /// I = φ(R) + ¼(φ(N) − φ(R)) (else φ(N)), φ(n) = min(n, 3.5 √n η²/√(1 − g)) — a non-absorbing
    /// half-space returns a photon after n interactions with probability ∝ n^{−3/2}, so the mean of
    /// min(n, N) grows like √N; total internal reflection (η²) and forward scattering (1/(1 − g)
    /// interactions per transport mean free path) lengthen the walks. Bounded by N whatever g is.
    ///
    /// # Errors
    /// `InvalidParameter` for a bad field.
    pub fn cost_estimate(&self) -> Result<crate::CostEstimate> {
        let runs: Vec<WhiteSpec> = std::iter::once(self.white()?)
            .chain(self.low_albedo_white()?)
            .collect();
        let x = |n: f64| (3.5 * n.sqrt() * self.eta * self.eta / (1.0 - self.g).sqrt()).min(n);
        let mut interactions = 0.0;
        for white in &runs {
            let roulette = white.roulette_interactions as f64;
            for s in &white.strata {
                let cap = s.max_interactions as f64;
                let per_photon = if roulette > 0.0 && roulette < cap {
                    x(roulette) + crate::white::ROULETTE_SURVIVAL * (x(cap) - x(roulette))
                } else {
                    x(cap)
                };
                interactions += per_photon * s.photons as f64;
            }
        }
        // Tallies: a sum and a sum of squares per (albedo, bin) and per albedo, for each of the 32
        // chunks of a wave, the running total and the result; then the table with its raw profiles.
        let nodes = self.node_count();
        let cells = (nodes * (self.radial_bins + 2) + nodes) as u64;
        let memory_bytes = 2 * cells * 8 * (32 + 2 + 2);
        let photons: u64 = runs.iter().map(WhiteSpec::photons).sum();
        Ok(crate::CostEstimate {
            interactions_per_photon: interactions / photons.max(1) as f64,
            interactions,
            memory_bytes,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::white::simulate;

    /// `AlbedoSpacing::SqrtOneMinusReducedAlbedo`: at g = 0.9 the nodes' reduced albedos
    /// (α′ = a(1 − g)/(1 − ag), computed here from each node) are equally spaced in √(1 − α′) and
    /// the end nodes are the spec's own ends; at g = 0 the two spacings coincide; the default is
    /// left out of the spec's JSON (so the shipped tables' specs and cache names do not change)
    /// and the other one round-trips.
    #[test]
    fn reduced_albedo_spacing_is_even_in_sqrt_one_minus_albedo_prime() {
        let mut spec = McTableSpec::new(1.4, 0.9, 1000).unwrap();
        spec.albedo_min = 0.2 / (0.1 + 0.9 * 0.2);
        spec.albedo_max = 0.99995 / (0.1 + 0.9 * 0.99995);
        let plain = spec.albedos();
        spec.albedo_spacing = AlbedoSpacing::SqrtOneMinusReducedAlbedo;
        let nodes = spec.albedos();
        assert_eq!(nodes.len(), 64);
        assert!((nodes[0] - spec.albedo_min).abs() < 1e-12);
        assert!((nodes[63] - spec.albedo_max).abs() < 1e-12);
        let x: Vec<f64> = nodes
            .iter()
            .map(|&a| (1.0 - a * 0.1 / (1.0 - 0.9 * a)).sqrt())
            .collect();
        let step = x[0] - x[1];
        for w in x.windows(2) {
            assert!(((w[0] - w[1]) / step - 1.0).abs() < 1e-9, "{w:?} vs {step}");
        }
        // Toward α′ → 1 the last interval, in √(1 − α′), is about half the old spacing's (whose
        // nodes above α′ 0.998 are two: 0.99995 and 0.99886).
        let top = |v: &[f64]| {
            let x = |a: f64| (1.0 - a * 0.1 / (1.0 - 0.9 * a)).sqrt();
            x(v[62]) - x(v[63])
        };
        assert!(
            top(&nodes) < 0.55 * top(&plain),
            "{} vs {}",
            top(&nodes),
            top(&plain)
        );
        let json = serde_json::to_string(&spec).unwrap();
        assert!(json.contains("sqrt_one_minus_reduced_albedo"), "{json}");
        assert_eq!(serde_json::from_str::<McTableSpec>(&json).unwrap(), spec);
        let g0 = McTableSpec::new(1.4, 0.0, 1000).unwrap();
        assert!(
            !serde_json::to_string(&g0)
                .unwrap()
                .contains("albedo_spacing")
        );
        let reduced = McTableSpec {
            albedo_spacing: AlbedoSpacing::SqrtOneMinusReducedAlbedo,
            ..g0.clone()
        };
        for (a, b) in reduced.albedos().iter().zip(g0.albedos()) {
            assert!((a - b).abs() < 1e-15, "{a} vs {b}");
        }
    }

    /// Low-albedo nodes ([`LowAlbedoRun`]): at g = 0.9 (nodes in √(1 − α′)) from exactly the
    /// requested α′ = 0.01 up to the main run's first node, strictly increasing, spaced in
    /// √(1 − α′) evenly and no wider than the main run's step (and more than half of it); the main
    /// run keeps its own nodes, the low run gets the others, its own streams and a cap of a few
    /// dozen interactions; the spec round-trips through JSON, and one without low nodes has no
    /// `low_albedos` key (its cache name is unchanged). Bad requests are refused.
    #[test]
    fn low_albedo_nodes_continue_the_tables_spacing_below_it() {
        let g = 0.9;
        let a_of = |ap: f64| ap / (1.0 - g + g * ap);
        let x_of = |a: f64| (1.0 - a * (1.0 - g) / (1.0 - a * g)).sqrt();
        let mut main = McTableSpec::new(1.4, g, 1000).unwrap();
        main.albedo_min = a_of(0.2);
        main.albedo_max = a_of(0.99995);
        main.albedo_spacing = AlbedoSpacing::SqrtOneMinusReducedAlbedo;
        assert!(
            !serde_json::to_string(&main)
                .unwrap()
                .contains("low_albedos")
        );
        let spec = main.clone().with_low_albedos_to(a_of(0.01), 5000).unwrap();
        let low = spec.low_albedos.clone().unwrap();
        let nodes = spec.albedos();
        assert_eq!(nodes.len(), spec.node_count());
        assert_eq!(nodes.len(), 64 + low.albedo_count);
        assert!((nodes[0] - a_of(0.01)).abs() < 1e-12, "{}", nodes[0]);
        assert!(nodes.windows(2).all(|w| w[1] > w[0]));
        let step = x_of(main.albedo_min) - x_of(spec.albedos()[low.albedo_count + 1]);
        let low_steps: Vec<f64> = nodes[..=low.albedo_count]
            .windows(2)
            .map(|w| x_of(w[0]) - x_of(w[1]))
            .collect();
        for d in &low_steps {
            assert!(
                *d <= step * (1.0 + 1e-9) && *d > 0.5 * step,
                "{d} vs {step}"
            );
            assert!(
                (d / low_steps[0] - 1.0).abs() < 1e-9,
                "uneven: {low_steps:?}"
            );
        }
        assert_eq!(spec.white().unwrap(), main.white().unwrap());
        let run = spec.low_albedo_white().unwrap().unwrap();
        assert_eq!(run.albedos, nodes[..low.albedo_count].to_vec());
        assert_ne!(run.seed, spec.seed);
        assert_eq!(run.strata.len(), 1);
        assert!(run.strata[0].max_interactions < 50, "{:?}", run.strata);
        assert_eq!(main.low_albedo_white().unwrap(), None);
        let json = serde_json::to_string(&spec).unwrap();
        assert_eq!(serde_json::from_str::<McTableSpec>(&json).unwrap(), spec);
        assert_ne!(spec.file_name(), main.file_name());
        for bad in [0.0, main.albedo_min, 0.9] {
            assert!(
                main.clone().with_low_albedos_to(bad, 5000).is_err(),
                "{bad}"
            );
        }
        assert!(main.clone().with_low_albedos_to(0.05, 0).is_err());
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
}
