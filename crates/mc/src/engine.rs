//! The photon tracer: MCML's physics (Wang, Jacques & Zheng 1995; docs/physics.md §4.1) in mm units, run
//! in fixed-size chunks of photons with one random stream per chunk, so that a seed gives the same
//! result bit for bit whatever the number of threads.

use std::f64::consts::{FRAC_PI_2, PI};

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::beam::{Beam, BeamProfile};
use crate::error::{Result, check};
use crate::fresnel::fresnel_mcml;
use crate::grid::RadialGrid;
use crate::phase::{HgSampler, scatter_hg};
use crate::rng::{PhotonRng, stream};
use crate::sample::Sample;

/// MCML's roulette threshold `WEIGHT` (docs/physics.md §4.1).
pub const ROULETTE_THRESHOLD: f64 = 1e-4;
/// MCML's roulette survival chance `CHANCE` (docs/physics.md §4.1).
pub const ROULETTE_CHANCE: f64 = 0.1;
/// Photons per chunk: the unit of work with its own random stream. Fixed, so that results do not
/// depend on the thread count; 2048 photons are 0.1–20 ms of work, large against rayon's overhead.
pub const CHUNK_PHOTONS: u64 = 2048;
/// Most chunks traced in parallel before their tallies are summed (in chunk order). Bounds memory by
/// `WAVE_CHUNKS` tallies whatever the photon count.
const WAVE_CHUNKS: u64 = 64;
/// Interactions a wave aims at, so that progress is reported every few seconds even when photons
/// are expensive (a wave is never less than one chunk per thread). Waves only group chunks: the
/// tallies are summed in chunk order whatever the wave size, so results do not depend on it.
const WAVE_INTERACTIONS: f64 = 1e8;

/// Bytes of one chunk tally per tally bin (radial or angular): a sum and a sum of squares, f64 each.
const TALLY_BYTES_PER_BIN: u64 = 16;

/// Steps (interactions) per second per thread on the project's standard machine (2-core AMD EPYC VM,
/// shared: 1.6e7–2.2e7 on paths of hundreds of steps; BENCHMARKS.md, "Monte Carlo cost model"),
/// measured with `cargo test --release -p scatterfit-mc --test suite cost:: -- --ignored
/// --nocapture`: only for turning a step count into an expected run time in messages.
pub const REFERENCE_INTERACTIONS_PER_SECOND: f64 = 2.0e7;

/// What a simulation is expected to cost, before it runs ([`Simulation::cost_estimate`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CostEstimate {
    /// Expected steps per photon: interactions (scattering events) plus the launch.
    pub interactions_per_photon: f64,
    /// Expected steps in all, photons × the above.
    pub interactions: f64,
    /// Memory the tallies take while running \[bytes\].
    pub memory_bytes: u64,
}

impl CostEstimate {
    /// The expected run time \[s\] on `threads` threads at [`REFERENCE_INTERACTIONS_PER_SECOND`].
    pub fn seconds(&self, threads: usize) -> f64 {
        self.interactions / (REFERENCE_INTERACTIONS_PER_SECOND * threads.max(1) as f64)
    }
}

/// A Monte Carlo estimate: the mean over photons and its standard error (named apart from
/// `scatterfit_optics::Estimate`, a measured value with its uncertainty terms).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct McMean {
    /// The estimate.
    pub value: f64,
    /// Its standard error (one standard deviation of the mean).
    pub stderr: f64,
}

impl McMean {
    /// Mean and standard error of per-photon scores from their sum `s1`, sum of squares `s2` and count.
    fn from_moments(s1: f64, s2: f64, n: u64) -> Self {
        let nf = n as f64;
        let mean = s1 / nf;
        let var = (s2 / nf - mean * mean).max(0.0);
        let stderr = if n > 1 {
            (var / (nf - 1.0)).sqrt()
        } else {
            f64::INFINITY
        };
        Self {
            value: mean,
            stderr,
        }
    }

    fn scaled(self, k: f64) -> Self {
        Self {
            value: self.value * k,
            stderr: self.stderr * k,
        }
    }
}

/// A configured simulation: sample, beam, tally grid, photon count and seed.
#[derive(Debug, Clone)]
pub struct Simulation {
    sample: Sample,
    beam: Beam,
    grid: RadialGrid,
    angle_bins: usize,
    photons: u64,
    seed: u64,
}

impl Simulation {
    /// A simulation of `photons` photons from `beam` into `sample`, tallying Rd(r) on `grid`.
    ///
    /// # Errors
    /// `InvalidParameter` for zero photons; `NeverEnds` for a half-space whose infinite layer does
    /// not absorb (σa = 0): a random walk in a half-space returns to the surface with probability 1
    /// but after a time of infinite mean, and without absorption the photon's weight never falls to
    /// the roulette, so the run has no finite expected length.
    pub fn new(
        sample: Sample,
        beam: Beam,
        grid: RadialGrid,
        photons: u64,
        seed: u64,
    ) -> Result<Self> {
        check(photons > 0, "photons", 0.0, "trace at least one photon")?;
        if let Some(last) = sample.layers().last()
            && !last.thickness().is_finite()
            && last.sigma_a() == 0.0
        {
            return Err(crate::McError::NeverEnds {
                what: "σa = 0 in a half-space: photons walk without absorption, and the mean length \
                       of a path that must return to the surface is infinite, so the simulation \
                       would never end",
                hint: "give a thickness (a slab) or a small absorption σa > 0 (e.g. 1e-4 mm⁻¹; the \
                       cost estimate tells how long it will take)",
            });
        }
        Ok(Self {
            sample,
            beam,
            grid,
            angle_bins: 0,
            photons,
            seed,
        })
    }

    /// Also tallies diffuse reflectance by exit angle in `bins` bins uniform in θ ∈ [0, π/2]
    /// (MCML's `Rd_a`, per steradian); 0 turns the tally off.
    #[must_use]
    pub fn with_angle_bins(mut self, bins: usize) -> Self {
        self.angle_bins = bins;
        self
    }

    /// The sample.
    pub fn sample(&self) -> &Sample {
        &self.sample
    }
    /// The number of photons.
    pub fn photons(&self) -> u64 {
        self.photons
    }

    /// Memory the tallies take while running \[bytes\]: a wave of `WAVE_CHUNKS` chunk tallies plus
    /// the running total, each a sum and a sum of squares per radial and angular bin, and the
    /// result. Independent of the photon count.
    pub fn memory_bytes(&self) -> u64 {
        Self::tally_memory_bytes(self.grid.bins(), self.angle_bins)
    }

    /// [`Simulation::memory_bytes`] for a grid of `bins` radial and `angle_bins` angular bins, before
    /// either is allocated.
    pub fn tally_memory_bytes(bins: usize, angle_bins: usize) -> u64 {
        let per_bin = TALLY_BYTES_PER_BIN * (WAVE_CHUNKS + 2) + 8;
        (bins as u64)
            .saturating_add(angle_bins as u64)
            .saturating_mul(per_bin)
    }

    /// The expected cost of [`Simulation::run`], from the sample's coefficients alone (no photon is
    /// traced), in steps per photon (interactions plus the launch). It is the smallest of three
    /// bounds, with η² (the largest layer index over the outside one, squared) for the light that
    /// internal reflection keeps inside:
    ///
    /// - *absorption*: with implicit capture the weight falls by α = σs/σt per interaction, so the
    ///   roulette (threshold W = 10⁻⁴, chance 0.1) ends a path after N_abs ≈ (ln(1/W) + 0.26)/(−ln α)
    ///   interactions (0.26: the roulette's expected tail), α the stack's largest;
    /// - *slab*: a non-absorbing slab of optical thickness τ = Σ σt·d is left after about 2η²τ
    ///   interactions (the mean path length in a body under uniform illumination is 4V/S = 2d for a
    ///   slab, whatever the scattering: Blanco & Fournier 2003, Europhys. Lett. 61, 168);
    /// - *half-space*: a path that leaves through the surface it entered is a one-dimensional walk
    ///   of transport steps, cut off after K = (1 − g)·N_abs of them; the expected length of such a
    ///   walk until its first return, truncated at K, grows as 2√(2K/π) (Feller, vol. 1, §III.7),
    ///   so η²(1 + 2√(2K/π))/(1 − g) interactions.
    ///
    /// An order-of-magnitude estimate for refusing runs that would not finish and for telling how
    /// long a run will take, not a prediction: `tests/cost.rs` holds it within a factor 3 of measured
    /// counts over slabs and half-spaces, g from 0 to 0.9, α′ from 0.5 to 0.999.
    pub fn cost_estimate(&self) -> CostEstimate {
        let per_photon = interactions_per_photon(&self.sample);
        CostEstimate {
            interactions_per_photon: per_photon,
            interactions: per_photon * self.photons as f64,
            memory_bytes: self.memory_bytes(),
        }
    }

    /// Runs on the current rayon thread pool.
    pub fn run(&self) -> SimulationResult {
        self.run_with_progress(&|_| {})
    }

    /// Runs on the current rayon thread pool, calling `progress(photons_done)` after every wave of
    /// chunks (from the calling thread).
    pub fn run_with_progress(&self, progress: &(dyn Fn(u64) + Sync)) -> SimulationResult {
        self.run_until(progress, &|| false)
            .expect("a run that is never stopped finishes")
    }

    /// [`Simulation::run_with_progress`], stopped when `stop` answers true: it is asked after each
    /// wave of photon chunks (about 10⁸ interactions apart, or one chunk per thread), and a
    /// stopped run returns `None` (a partial tally is not a simulation of the photons asked for).
    /// A caller that must stay responsive (a notebook's Ctrl-C, a scheduler's time limit) uses it.
    pub fn run_until(
        &self,
        progress: &(dyn Fn(u64) + Sync),
        stop: &(dyn Fn() -> bool + Sync),
    ) -> Option<SimulationResult> {
        let tracer = Tracer::new(self);
        let chunks = self.photons.div_ceil(CHUNK_PHOTONS);
        let mut total = Accum::new(self.grid.bins(), self.angle_bins);
        let per_chunk = interactions_per_photon(&self.sample) * CHUNK_PHOTONS as f64;
        let wave_chunks = ((WAVE_INTERACTIONS / per_chunk) as u64)
            .max(rayon::current_num_threads() as u64)
            .clamp(1, WAVE_CHUNKS);
        let mut first = 0;
        while first < chunks {
            let last = (first + wave_chunks).min(chunks);
            let wave: Vec<Accum> = (first..last)
                .into_par_iter()
                .map(|c| {
                    let count = CHUNK_PHOTONS.min(self.photons - c * CHUNK_PHOTONS);
                    let mut acc = Accum::new(self.grid.bins(), self.angle_bins);
                    let mut rng = stream(self.seed, c);
                    if tracer.anisotropic {
                        for _ in 0..count {
                            tracer.trace::<true>(&mut rng, &mut acc);
                        }
                    } else {
                        for _ in 0..count {
                            tracer.trace::<false>(&mut rng, &mut acc);
                        }
                    }
                    acc
                })
                .collect();
            for acc in &wave {
                total.add(acc);
            }
            first = last;
            progress((last * CHUNK_PHOTONS).min(self.photons));
            if first < chunks && stop() {
                return None;
            }
        }
        Some(total.finish(self, tracer.specular))
    }
}

/// Expected interactions per photon in `sample` (see [`Simulation::cost_estimate`]).
fn interactions_per_photon(sample: &Sample) -> f64 {
    let layers = sample.layers();
    let outside = sample.n_above().min(sample.n_below());
    let trap = layers
        .iter()
        .map(|l| (l.n() / outside).powi(2))
        .fold(1.0f64, f64::max);
    // Implicit capture + roulette: ln(1/W) to reach the threshold, plus the roulette's tail
    // Σ_k 0.1^k ln(10) ≈ 0.26, each interaction multiplying the weight by α.
    let roulette = (1.0 / ROULETTE_THRESHOLD).ln()
        + ROULETTE_CHANCE * (1.0 / ROULETTE_CHANCE).ln() / (1.0 - ROULETTE_CHANCE);
    let absorb_bound = |l: &crate::Layer| {
        let sigma_t = l.sigma_a() + l.sigma_s();
        let alpha = l.sigma_s() / sigma_t;
        if alpha >= 1.0 {
            f64::INFINITY
        } else {
            // −ln α, accurate for α near 1.
            roulette / -(-l.sigma_a() / sigma_t).ln_1p()
        }
    };
    let n_abs = layers.iter().map(absorb_bound).fold(0.0f64, f64::max);
    // A walk from the surface into a half-space of this layer, cut off after K transport steps.
    let half_space_bound = |l: &crate::Layer| {
        let one_minus_g = 1.0 - l.g();
        let k = one_minus_g * absorb_bound(l);
        trap * (1.0 + 2.0 * (2.0 * k / std::f64::consts::PI).sqrt()) / one_minus_g
    };
    let n_half = layers.iter().map(half_space_bound).fold(0.0f64, f64::max);
    let last = layers[layers.len() - 1];
    let n_escape = if last.thickness().is_finite() {
        let optical: f64 = layers
            .iter()
            .map(|l| (l.sigma_a() + l.sigma_s()) * l.thickness())
            .sum();
        (2.0 * trap * optical).min(n_half)
    } else {
        n_half
    };
    // Plus the launch step every photon takes.
    n_abs.min(n_escape) + 1.0
}

/// What a simulation measured. All quantities are per incident photon weight (fractions), Rd(r) in
/// mm⁻², the angular tally per steradian.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SimulationResult {
    /// Photons traced.
    pub photons: u64,
    /// Interactions (scattering events) traced, all photons together.
    #[serde(default)]
    pub interactions: u64,
    /// Seed of the random streams.
    pub seed: u64,
    /// Specular reflectance at entry R_sp (exact, not sampled; not part of `rd_total`).
    pub specular: f64,
    /// Total diffuse reflectance Rd (excludes R_sp).
    pub rd_total: McMean,
    /// Total transmittance Tt (includes unscattered light; 0 for a half-space).
    pub transmittance: McMean,
    /// Absorbed fraction A.
    pub absorbed: McMean,
    /// R_sp + Rd + Tt + A, which is 1 up to Russian-roulette noise.
    pub conservation: McMean,
    /// The radial grid \[mm\].
    pub grid: RadialGrid,
    /// Rd(r) per annulus of `grid` [mm⁻²]: reflected weight / (photons × annulus area).
    pub rd_profile: Vec<McMean>,
    /// Exit-angle bin edges θ \[radians\], empty when the tally is off.
    pub angle_edges: Vec<f64>,
    /// Diffuse reflectance per exit-angle bin per steradian of solid angle [sr⁻¹].
    pub rd_angle: Vec<McMean>,
}

/// Per-chunk sums of per-photon scores and their squares.
#[derive(Debug, Clone)]
struct Accum {
    rd_w: Vec<f64>,
    rd_w2: Vec<f64>,
    ang_w: Vec<f64>,
    ang_w2: Vec<f64>,
    /// [R, R², T, T², A, A², R+T+A, (R+T+A)²]
    sums: [f64; 8],
    /// Interactions traced.
    interactions: u64,
}

impl Accum {
    fn new(bins: usize, angle_bins: usize) -> Self {
        Self {
            rd_w: vec![0.0; bins],
            rd_w2: vec![0.0; bins],
            ang_w: vec![0.0; angle_bins],
            ang_w2: vec![0.0; angle_bins],
            sums: [0.0; 8],
            interactions: 0,
        }
    }

    fn add(&mut self, o: &Accum) {
        for (a, b) in self.rd_w.iter_mut().zip(&o.rd_w) {
            *a += b;
        }
        for (a, b) in self.rd_w2.iter_mut().zip(&o.rd_w2) {
            *a += b;
        }
        for (a, b) in self.ang_w.iter_mut().zip(&o.ang_w) {
            *a += b;
        }
        for (a, b) in self.ang_w2.iter_mut().zip(&o.ang_w2) {
            *a += b;
        }
        for (a, b) in self.sums.iter_mut().zip(&o.sums) {
            *a += b;
        }
        self.interactions += o.interactions;
    }

    fn finish(self, sim: &Simulation, specular: f64) -> SimulationResult {
        let n = sim.photons;
        let s = &self.sums;
        let rd_profile = (0..sim.grid.bins())
            .map(|i| {
                McMean::from_moments(self.rd_w[i], self.rd_w2[i], n).scaled(1.0 / sim.grid.area(i))
            })
            .collect();
        let nb = sim.angle_bins;
        let angle_edges: Vec<f64> = if nb > 0 {
            (0..=nb).map(|i| FRAC_PI_2 * i as f64 / nb as f64).collect()
        } else {
            Vec::new()
        };
        let rd_angle = (0..nb)
            .map(|i| {
                let solid = 2.0 * PI * (angle_edges[i].cos() - angle_edges[i + 1].cos());
                McMean::from_moments(self.ang_w[i], self.ang_w2[i], n).scaled(1.0 / solid)
            })
            .collect();
        let mut conservation = McMean::from_moments(s[6], s[7], n);
        conservation.value += specular;
        SimulationResult {
            photons: n,
            interactions: self.interactions,
            seed: sim.seed,
            specular,
            rd_total: McMean::from_moments(s[0], s[1], n),
            transmittance: McMean::from_moments(s[2], s[3], n),
            absorbed: McMean::from_moments(s[4], s[5], n),
            conservation,
            grid: sim.grid.clone(),
            rd_profile,
            angle_edges,
            rd_angle,
        }
    }
}

/// A layer prepared for tracing: boundaries, coefficients and the indices on both sides.
#[derive(Debug, Clone, Copy)]
struct LayerK {
    z0: f64,
    z1: f64,
    sigma_t: f64,
    inv_sigma_t: f64,
    /// σa/σt: the fraction of weight deposited at each interaction (implicit capture).
    absorb: f64,
    g: f64,
    /// Henyey–Greenstein sampling constants of `g`.
    hg: HgSampler,
    n: f64,
    n_up: f64,
    n_down: f64,
    /// Cosine of the critical angle towards the layer above / below (0 when there is none).
    cos_crit_up: f64,
    cos_crit_down: f64,
}

/// Cosine of the critical angle from index `n_i` into `n_t`: √(1 − (n_t/n_i)²) when n_i > n_t, else 0.
fn cos_critical(n_i: f64, n_t: f64) -> f64 {
    if n_i > n_t {
        (1.0 - (n_t / n_i).powi(2)).sqrt()
    } else {
        0.0
    }
}

/// Everything the inner loop reads, precomputed once per simulation.
#[derive(Debug)]
struct Tracer<'a> {
    layers: Vec<LayerK>,
    grid: &'a RadialGrid,
    angle_bins: usize,
    profile: BeamProfile,
    /// Footprint stretch 1/cos θi along x for an oblique beam.
    stretch_x: f64,
    /// Launch direction in the first layer (refracted beam).
    ux0: f64,
    uz0: f64,
    /// R_sp at entry.
    specular: f64,
    /// Some layer scatters anisotropically (g ≠ 0).
    anisotropic: bool,
}

impl<'a> Tracer<'a> {
    fn new(sim: &'a Simulation) -> Self {
        let s = &sim.sample;
        let nl = s.layers().len();
        let mut z = 0.0;
        let layers = s
            .layers()
            .iter()
            .enumerate()
            .map(|(i, l)| {
                let sigma_t = l.sigma_a() + l.sigma_s();
                let k = LayerK {
                    z0: z,
                    z1: z + l.thickness(),
                    sigma_t,
                    inv_sigma_t: 1.0 / sigma_t,
                    absorb: l.sigma_a() / sigma_t,
                    g: l.g(),
                    hg: HgSampler::new(l.g()),
                    n: l.n(),
                    n_up: if i == 0 {
                        s.n_above()
                    } else {
                        s.layers()[i - 1].n()
                    },
                    n_down: if i + 1 == nl {
                        s.n_below()
                    } else {
                        s.layers()[i + 1].n()
                    },
                    cos_crit_up: 0.0,
                    cos_crit_down: 0.0,
                };
                let k = LayerK {
                    cos_crit_up: cos_critical(k.n, k.n_up),
                    cos_crit_down: cos_critical(k.n, k.n_down),
                    ..k
                };
                z += l.thickness();
                k
            })
            .collect::<Vec<_>>();
        let theta_i = sim.beam.incidence();
        let cos_i = theta_i.cos();
        // Entry: specular reflection (Fresnel, exact) and refraction of the beam (Snell).
        let entry = fresnel_mcml(s.n_above(), layers[0].n, cos_i);
        let sin_t = s.n_above() / layers[0].n * theta_i.sin();
        Self {
            grid: &sim.grid,
            angle_bins: sim.angle_bins,
            profile: sim.beam.profile(),
            stretch_x: 1.0 / cos_i,
            ux0: sin_t,
            uz0: (1.0 - sin_t * sin_t).sqrt(),
            specular: entry.reflectance,
            anisotropic: layers.iter().any(|l| l.g != 0.0),
            layers,
        }
    }

    /// Traces one photon from launch to death and adds its scores to `acc`. No allocation.
    /// `ANISO`: some layer has g ≠ 0; without it (every layer isotropic) the loop has no test of g.
    #[inline]
    fn trace<const ANISO: bool>(&self, rng: &mut PhotonRng, acc: &mut Accum) {
        // Launch (MCML `LaunchPhoton`): weight 1 − R_sp at the entry point of the beam.
        let (mut x, mut y) = match self.profile {
            BeamProfile::Pencil => (0.0, 0.0),
            BeamProfile::Disk { radius } => {
                let rho = radius * rng.uniform().sqrt();
                let (s, c) = (2.0 * PI * rng.uniform()).sin_cos();
                (rho * c, rho * s)
            }
            BeamProfile::Gaussian { radius } => {
                // I(ρ) ∝ exp(−2ρ²/w²) ⇒ P(ρ > r) = exp(−2r²/w²) ⇒ ρ = w √(−ln ξ / 2).
                let rho = radius * (-rng.uniform_open0().ln() * 0.5).sqrt();
                let (s, c) = (2.0 * PI * rng.uniform()).sin_cos();
                (rho * c, rho * s)
            }
        };
        x *= self.stretch_x;
        let mut z = 0.0;
        let (mut ux, mut uy, mut uz) = (self.ux0, 0.0, self.uz0);
        let mut w = 1.0 - self.specular;
        let mut layer = 0usize;
        let mut sleft = 0.0; // dimensionless leftover step (optical depth), MCML's `sleft`
        let mut absorbed = 0.0;
        let mut reflected = 0.0;
        let mut transmitted = 0.0;
        let last = self.layers.len() - 1;
        let mut l = self.layers[0];
        let mut cos_out = 0.0;
        let mut interactions = 0u64;
        loop {
            // StepSizeInTissue: s = −ln ξ / σt (an Exp(1) variate / σt), or the leftover from a
            // boundary hit.
            let s = if sleft == 0.0 {
                rng.exp1() * l.inv_sigma_t
            } else {
                let s = sleft * l.inv_sigma_t;
                sleft = 0.0;
                s
            };
            // HitBoundary: does the step leave the layer? (Tested on the end point, which spares the
            // division by u_z on steps that stay inside.)
            let z_end = z + s * uz;
            if z_end < l.z0 || z_end > l.z1 {
                let up = uz < 0.0;
                let z_face = if up { l.z0 } else { l.z1 };
                let db = (z_face - z) / uz;
                sleft = (s - db) * l.sigma_t;
                x += db * ux;
                y += db * uy;
                z = z_face;
                // CrossOrNot: Fresnel decides reflection or transmission (statistical splitting);
                // beyond the critical angle the photon is reflected without a draw.
                let (n_t, cos_crit) = if up {
                    (l.n_up, l.cos_crit_up)
                } else {
                    (l.n_down, l.cos_crit_down)
                };
                let cos_i = uz.abs();
                let transmit = cos_i > cos_crit && {
                    let f = fresnel_mcml(l.n, n_t, cos_i);
                    cos_out = f.cos_t;
                    f.reflectance == 0.0 || rng.uniform() > f.reflectance
                };
                if transmit {
                    if up && layer == 0 {
                        reflected = w;
                        self.tally_exit(acc, x, y, cos_out, w);
                        break;
                    } else if !up && layer == last {
                        transmitted = w;
                        break;
                    }
                    // Into the neighbouring layer: refract.
                    let ratio = l.n / n_t;
                    ux *= ratio;
                    uy *= ratio;
                    if up {
                        uz = -cos_out;
                        layer -= 1;
                    } else {
                        uz = cos_out;
                        layer += 1;
                    }
                    l = self.layers[layer];
                } else {
                    uz = -uz;
                }
            } else {
                // Hop.
                interactions += 1;
                x += s * ux;
                y += s * uy;
                z += s * uz;
                // Drop (implicit capture): deposit w σa/σt.
                let dw = w * l.absorb;
                w -= dw;
                absorbed += dw;
                // Spin (Henyey–Greenstein, MCML `Spin`).
                if ANISO && l.g != 0.0 {
                    [ux, uy, uz] = scatter_hg([ux, uy, uz], &l.hg, rng);
                } else {
                    (ux, uy, uz) = spin_isotropic(rng);
                }
            }
            // Roulette (MCML: threshold 1e-4, survival chance 0.1).
            if w < ROULETTE_THRESHOLD {
                if w == 0.0 || rng.uniform() >= ROULETTE_CHANCE {
                    break;
                }
                w /= ROULETTE_CHANCE;
            }
        }
        acc.interactions += interactions;
        let total = reflected + transmitted + absorbed;
        let s = &mut acc.sums;
        s[0] += reflected;
        s[1] += reflected * reflected;
        s[2] += transmitted;
        s[3] += transmitted * transmitted;
        s[4] += absorbed;
        s[5] += absorbed * absorbed;
        s[6] += total;
        s[7] += total * total;
    }

    /// Records a photon leaving through the top face at (x, y) with exit cosine `cos_out`.
    #[inline]
    fn tally_exit(&self, acc: &mut Accum, x: f64, y: f64, cos_out: f64, w: f64) {
        let r = (x * x + y * y).sqrt();
        if let Some(i) = self.grid.find(r) {
            acc.rd_w[i] += w;
            acc.rd_w2[i] += w * w;
        }
        if self.angle_bins > 0 {
            let theta = cos_out.clamp(0.0, 1.0).acos();
            let i =
                ((theta / FRAC_PI_2 * self.angle_bins as f64) as usize).min(self.angle_bins - 1);
            acc.ang_w[i] += w;
            acc.ang_w2[i] += w * w;
        }
    }
}

/// New direction after an isotropic scattering event (MCML `Spin` at g = 0, Wang, Jacques & Zheng
/// 1995, eq. 3.28 with cos θ = 2ξ − 1): independent of the old direction, so it is drawn directly —
/// Marsaglia 1972's uniform direction on the sphere from a point (a, b) of the unit disk,
/// s = a² + b²: (2a√(1 − s), 2b√(1 − s), 1 − 2s).
#[inline(always)]
pub(crate) fn spin_isotropic(rng: &mut PhotonRng) -> (f64, f64, f64) {
    let (a, b, s2) = rng.unit_disk();
    let k = 2.0 * (1.0 - s2).sqrt();
    (a * k, b * k, 1.0 - 2.0 * s2)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::phase::{hg_cdf_cos, hg_pdf_cos, sample_hg_cos};

    /// A run stopped after its first wave returns nothing (no partial tally passes for the whole);
    /// one never stopped gives the same tallies as `run`.
    #[test]
    fn a_stopped_run_returns_none() {
        let layer = crate::Layer::from_reduced(1.0, 0.1, 0.0, 1.4, f64::INFINITY).unwrap();
        let sim = Simulation::new(
            crate::Sample::slab(layer, 1.0).unwrap(),
            crate::Beam::pencil(),
            RadialGrid::uniform(0.1, 10).unwrap(),
            // Many waves: at least one chunk per thread and wave, far more chunks than threads.
            CHUNK_PHOTONS * 64 * rayon::current_num_threads() as u64,
            5,
        )
        .unwrap();
        let waves = std::sync::atomic::AtomicU64::new(0);
        let stopped = sim.run_until(
            &|_| {
                waves.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            },
            &|| true,
        );
        assert!(stopped.is_none());
        assert_eq!(waves.load(std::sync::atomic::Ordering::Relaxed), 1);
        let small = Simulation::new(
            sim.sample().clone(),
            crate::Beam::pencil(),
            RadialGrid::uniform(0.1, 10).unwrap(),
            2_000,
            5,
        )
        .unwrap();
        let whole = small.run_until(&|_| {}, &|| false).expect("not stopped");
        assert_eq!(whole.interactions, small.run().interactions);
    }

    /// One scattering event as the tracer does it.
    fn spin(g: f64, u: [f64; 3], rng: &mut PhotonRng) -> [f64; 3] {
        if g == 0.0 {
            let (x, y, z) = spin_isotropic(rng);
            [x, y, z]
        } else {
            scatter_hg(u, &HgSampler::new(g), rng)
        }
    }

    /// The spun direction stays a unit vector and its mean cosine with the old one is g (the first
    /// Legendre moment of Henyey–Greenstein), within 4 standard errors; the variance of μ is
    /// E[μ²] − g² with E[μ²] = (1 + 2g²)/3 (second moment g² of P₂).
    #[test]
    fn spin_mean_cosine_is_g() {
        let mut rng = stream(11, 0);
        for &g in &[0.0, 0.3, 0.75, 0.9, -0.5] {
            let n = 200_000;
            let mut u = [0.0, 0.0, 1.0];
            let mut sum = 0.0;
            for _ in 0..n {
                let [vx, vy, vz] = spin(g, u, &mut rng);
                let norm = (vx * vx + vy * vy + vz * vz).sqrt();
                assert!((norm - 1.0).abs() < 1e-9, "g = {g}: |u| = {norm}");
                sum += u[0] * vx + u[1] * vy + u[2] * vz;
                u = [vx / norm, vy / norm, vz / norm];
            }
            let var = (1.0 + 2.0 * g * g) / 3.0 - g * g;
            let se = (var / n as f64).sqrt();
            let mean = sum / n as f64;
            assert!(
                (mean - g).abs() < 4.0 * se,
                "g = {g}: mean cosine {mean} ± {se}"
            );
        }
    }

    /// Chi-square goodness of fit of the tracer's whole anisotropic event ([`scatter_hg`]) in
    /// both angles: the cosine between the old and the new direction against the Henyey–Greenstein
    /// CDF, and the azimuth of the new direction about the old one — measured in a basis built
    /// independently of the tracer's (MCML's: the polar unit vector) — against the uniform
    /// distribution. 40 bins each, 39 degrees of freedom, critical value χ²₀.₉₉₉(39) = 72.0547
    /// (scipy 1.17 `chi2.ppf(0.999, 39)`). Old directions wander (and are mirrored) as in a walk.
    #[test]
    fn hg_spin_chi_square_in_both_angles() {
        let bins = 40;
        let n = 400_000;
        for &g in &[0.5, 0.9, 0.95, -0.5] {
            let mut rng = stream(21, 3);
            let mut v = [0.3, -0.4, (1.0f64 - 0.25).sqrt()];
            let (mut c_mu, mut c_psi) = (vec![0u64; bins], vec![0u64; bins]);
            for k in 0..n {
                if k % 13 == 0 {
                    v[2] = -v[2];
                }
                let u = v;
                v = scatter_hg(u, &HgSampler::new(g), &mut rng);
                let mu = u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
                c_mu[(((mu + 1.0) * 0.5 * bins as f64) as usize).min(bins - 1)] += 1;
                // Reference basis of u: polar unit vector t1 and t2 = u × t1.
                let perp = (u[0] * u[0] + u[1] * u[1]).sqrt();
                let t1 = [u[0] * u[2] / perp, u[1] * u[2] / perp, -perp];
                let t2 = [
                    u[1] * t1[2] - u[2] * t1[1],
                    u[2] * t1[0] - u[0] * t1[2],
                    u[0] * t1[1] - u[1] * t1[0],
                ];
                let x = v[0] * t1[0] + v[1] * t1[1] + v[2] * t1[2];
                let y = v[0] * t2[0] + v[1] * t2[1] + v[2] * t2[2];
                let psi = y.atan2(x) + PI;
                c_psi[((psi / (2.0 * PI) * bins as f64) as usize).min(bins - 1)] += 1;
            }
            let mut chi_mu = 0.0;
            let mut chi_psi = 0.0;
            for i in 0..bins {
                let lo = -1.0 + 2.0 * i as f64 / bins as f64;
                let hi = -1.0 + 2.0 * (i + 1) as f64 / bins as f64;
                let e = n as f64 * (hg_cdf_cos(g, hi) - hg_cdf_cos(g, lo));
                chi_mu += (c_mu[i] as f64 - e).powi(2) / e;
                let e = n as f64 / bins as f64;
                chi_psi += (c_psi[i] as f64 - e).powi(2) / e;
            }
            assert!(chi_mu < 72.05, "g = {g}: chi² of cos θ = {chi_mu}");
            assert!(chi_psi < 72.05, "g = {g}: chi² of ψ = {chi_psi}");
        }
    }

    /// Chi-square goodness of fit of sampled cos θ against the Henyey–Greenstein density: 40 equal
    /// bins in μ, expected counts from the analytic CDF; 39 degrees of freedom, critical value
    /// χ²₀.₉₉₉(39) = 72.0547 (scipy 1.17 `chi2.ppf(0.999, 39)`).
    #[test]
    fn hg_sampling_chi_square() {
        let mut rng = stream(5, 1);
        let bins = 40;
        let n = 400_000;
        for &g in &[0.0, 0.3, 0.75, 0.9, -0.5] {
            let mut counts = vec![0u64; bins];
            for _ in 0..n {
                let mu = sample_hg_cos(g, rng.uniform());
                let i = (((mu + 1.0) * 0.5 * bins as f64) as usize).min(bins - 1);
                counts[i] += 1;
            }
            let mut chi2 = 0.0;
            for (i, &c) in counts.iter().enumerate() {
                let lo = -1.0 + 2.0 * i as f64 / bins as f64;
                let hi = -1.0 + 2.0 * (i + 1) as f64 / bins as f64;
                let expected = n as f64 * (hg_cdf_cos(g, hi) - hg_cdf_cos(g, lo));
                chi2 += (c as f64 - expected).powi(2) / expected;
            }
            assert!(chi2 < 72.05, "g = {g}: chi² = {chi2}");
            // The CDF is the integral of the pdf (midpoint rule on a fine grid).
            let m = 200_000;
            let integral: f64 = (0..m)
                .map(|j| hg_pdf_cos(g, -1.0 + 2.0 * (j as f64 + 0.5) / m as f64) * 2.0 / m as f64)
                .sum();
            assert!((integral - 1.0).abs() < 1e-6, "g = {g}: ∫p = {integral}");
            assert!((hg_cdf_cos(g, 1.0) - 1.0).abs() < 1e-12);
        }
    }
}
