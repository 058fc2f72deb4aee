//! The rig twin: what the optical imaging equipment and the spectrophotometer of Choi, Lee & Chin
//! (2014, §3.1–3.2) would record for a material of known σ′s, σa and η — made with the Monte Carlo
//! engine, never with the diffusion model that the tool fits.
//!
//! - **Profile**: per channel, an MCML-physics run of a half-space lit by a uniform 1 mm disk
//!   ([`McProfile`], `scatterfit-mc`), tallied on fine rings near the spot and logarithmic rings
//!   beyond, its noise smoothed where it is noisy ([`SmoothProfile`]).
//! - **Images**: the profile at every pixel centre around a spot centre with a random sub-pixel
//!   offset, times per-channel gains the tool is not told (light spectrum × camera sensitivity),
//!   through a linear sensor counted in electrons (Poisson shot noise, Gaussian read noise, full
//!   well), a smooth monotone non-linear tone curve ([`CameraModel::tone`], not the inverse of
//!   anything the tool assumes), 8-bit rounding and clipping: 13 exposures from 1/600 s to 3 s,
//!   geometric, as the paper's rig.
//! - **Spectrophotometer**: SCE with the linear-sRGB colour of the Monte Carlo total diffuse
//!   reflectance per channel, SCI adding the exact Fresnel specular at 8° ([`crate::spectro`]).
//!
//! Photon counts follow a budget of random-walk steps so that a sample renders in seconds: a
//! channel with little absorption walks long (MCML's implicit capture keeps a photon until its
//! weight α^n falls to the roulette threshold) and gets fewer photons, down to a floor.

use std::path::Path;

use rand::{RngExt, SeedableRng};
use rand_distr::{Distribution, Normal, Poisson};
use rand_xoshiro::Xoshiro256PlusPlus;
use rayon::prelude::*;
use scatterfit_imaging::ImageBuf;
use scatterfit_mc::{Beam, BeamProfile, Layer, McMean, RadialGrid, Sample, Simulation};
use serde::{Deserialize, Serialize};

use crate::SynthError;

mod profile;

pub use profile::{McProfile, ProfileSpec, SmoothProfile};

mod camera;

pub use camera::{CameraModel, SensorOutput, ToneCurve};

/// The photon scales [`RigSpec::with_photon_scale`] takes.
pub const PHOTON_SCALE_RANGE: std::ops::RangeInclusive<f64> = 0.01..=1000.0;

/// The geometry, exposures and camera of the twin.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RigSpec {
    /// Image width \[px\].
    pub width: usize,
    /// Image height \[px\].
    pub height: usize,
    /// Image scale on the sample [mm per pixel].
    pub mm_per_pixel: f64,
    /// Radius of the uniform light spot \[mm\] (the paper: "less than 1 mm in diameter").
    pub spot_radius_mm: f64,
    /// Shutter times \[s\], shortest first.
    pub times_s: Vec<f64>,
    /// The camera.
    pub camera: CameraModel,
    /// Henyey–Greenstein g of the material (σs = σ′s/(1 − g)).
    pub g: f64,
    /// Random-walk steps per channel the photon count is sized for.
    pub steps_budget: f64,
    /// Fewest photons per channel.
    pub min_photons: u64,
    /// Most photons per channel.
    pub max_photons: u64,
    /// The brightest channel's spot centre reaches this fraction of the full well in the shortest
    /// exposure (so that the bracket holds the peak unclipped once).
    pub peak_fill: f64,
    /// What a real rig adds: glare, vignetting, shutter errors, a Gaussian spot; all off
    /// by default.
    #[serde(default, skip_serializing_if = "RigEffects::is_none")]
    pub effects: RigEffects,
}

/// What a real rig adds to the ideal one, each a switch of the twin; all zero (off) by
/// default.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RigEffects {
    /// Veiling glare: stray light spread uniformly over the frame, as a fraction of the spot's
    /// radiance at its centre (10⁻⁴–10⁻³ for a lens; the far profile is 10⁻⁵ of the peak).
    pub glare: f64,
    /// Vignetting: the fall-off of the image's irradiance at the frame's corner (0.3 = 30 %),
    /// V(ρ) = (1 + kρ²)⁻² around the frame's centre (the cos⁴ law's shape); a flat frame of a
    /// uniform target is rendered with it.
    pub vignetting: f64,
    /// Shutter error: each frame's true exposure is its nominal time × exp(ε), ε normal with this
    /// standard deviation (0.03 = 3 %); the nominal times are what the files say.
    pub exposure_error: f64,
    /// The beam is Gaussian, I ∝ exp(−2ρ²/w²) with w = [`RigSpec::spot_radius_mm`] (the 1/e²
    /// radius), instead of a uniform disk of that radius.
    pub gaussian_spot: bool,
    /// Render the spot on a thin opaque white target (what `camera.spot_image` takes).
    pub spot_image: bool,
}

impl RigEffects {
    fn is_none(&self) -> bool {
        *self == RigEffects::default()
    }
}

impl RigSpec {
    /// The paper's rig (§3.2): 13 exposures from 1/600 s to 3 s (geometric), a 1 mm spot; a 1 MP
    /// (1024 × 1024) camera at 0.05 mm per pixel (51 mm field; the paper's 300-pixel cut-off is
    /// then 15 mm).
    pub fn paper() -> Self {
        let n = 13;
        let (t0, t1) = (1.0 / 600.0, 3.0f64);
        Self {
            width: 1024,
            height: 1024,
            mm_per_pixel: 0.05,
            spot_radius_mm: 0.5,
            times_s: (0..n)
                .map(|k| t0 * (t1 / t0).powf(k as f64 / (n - 1) as f64))
                .collect(),
            camera: CameraModel::default(),
            g: 0.0,
            steps_budget: 2e7,
            min_photons: 100_000,
            max_photons: 2_000_000,
            peak_fill: 0.8,
            effects: RigEffects::default(),
        }
    }

    /// A small, fast rig for tests and quick looks: 256 × 256 px at 0.1 mm per pixel (so the
    /// paper's 300-pixel cut-off is not reached: the profile stops at the image edge, 12.8 mm), a
    /// tenth of the photons. Same camera, spot and exposures.
    pub fn quick() -> Self {
        Self {
            width: 256,
            height: 256,
            mm_per_pixel: 0.1,
            steps_budget: 2e6,
            min_photons: 20_000,
            max_photons: 400_000,
            ..Self::paper()
        }
    }

    /// The same rig with `scale` times the Monte Carlo photons per channel (the steps budget and
    /// both photon bounds): the twin's own noise — its profile's and its spectrophotometer
    /// reading's — falls as 1/√scale at scale times the Monte Carlo time. At α′ ≥ 0.999 the paper
    /// rig's twin carries a few tenths of a percent of noise in its far field and total, which
    /// reaches σ′s and σa at 1–2.5 % (BENCHMARKS.md, "The g axis"): a study that should resolve
    /// the method's error there needs a larger scale, not a better model.
    ///
    /// # Errors
    /// [`SynthError::InvalidParameter`] unless `scale` lies in [`PHOTON_SCALE_RANGE`].
    pub fn with_photon_scale(mut self, scale: f64) -> Result<Self, SynthError> {
        if !PHOTON_SCALE_RANGE.contains(&scale) {
            return Err(SynthError::InvalidParameter {
                name: "photon scale",
                value: scale,
                reason: "must lie in [0.01, 1000]",
            });
        }
        self.steps_budget *= scale;
        // At least one photon, whatever the scale.
        self.min_photons = ((self.min_photons as f64 * scale).round() as u64).max(1);
        self.max_photons = ((self.max_photons as f64 * scale).round() as u64).max(self.min_photons);
        Ok(self)
    }

    /// Checks every field.
    ///
    /// # Errors
    /// [`SynthError::InvalidParameter`] naming the first bad one.
    pub fn validate(&self) -> Result<(), SynthError> {
        let bad = |name: &'static str, value: f64, reason: &'static str| {
            Err(SynthError::InvalidParameter {
                name,
                value,
                reason,
            })
        };
        if !(16..=16384).contains(&self.width) || !(16..=16384).contains(&self.height) {
            return bad(
                "image size [px]",
                self.width.max(self.height) as f64,
                "width and height must lie in 16..16384",
            );
        }
        if !(self.mm_per_pixel.is_finite() && self.mm_per_pixel > 0.0) {
            return bad("mm_per_pixel", self.mm_per_pixel, "must be finite and > 0");
        }
        if !(self.spot_radius_mm.is_finite() && self.spot_radius_mm > 0.0) {
            return bad(
                "spot radius [mm]",
                self.spot_radius_mm,
                "must be finite and > 0",
            );
        }
        if self.times_s.len() < 2
            || self.times_s.windows(2).any(|w| w[1] <= w[0])
            || self.times_s.iter().any(|t| !(t.is_finite() && *t > 0.0))
        {
            return bad(
                "times_s",
                self.times_s.len() as f64,
                "need ≥ 2 positive, strictly increasing shutter times",
            );
        }
        if !(self.g.is_finite() && self.g.abs() < 0.99) {
            return bad("g", self.g, "must lie in (−0.99, 0.99)");
        }
        if !(self.peak_fill > 0.0 && self.peak_fill <= 1.0) {
            return bad("peak_fill", self.peak_fill, "must lie in (0, 1]");
        }
        let c = &self.camera;
        if !(c.full_well_e >= 100.0 && c.read_noise_e >= 0.0 && c.tone_knee > 0.0) {
            return bad(
                "camera",
                c.full_well_e,
                "full well ≥ 100 e⁻, read noise ≥ 0, tone knee > 0",
            );
        }
        if let SensorOutput::Linear {
            black_level,
            white_level,
        } = c.output
            && !(white_level <= 65535.0
                && black_level
                    .iter()
                    .all(|b| (0.0..0.5 * white_level).contains(b)))
        {
            return bad(
                "camera black/white level [DN]",
                white_level,
                "white ≤ 65535 and 0 ≤ black < white/2",
            );
        }
        let e = &self.effects;
        if !(0.0..=0.1).contains(&e.glare) {
            return bad(
                "glare",
                e.glare,
                "must lie in [0, 0.1] of the spot's radiance",
            );
        }
        if !(0.0..=0.9).contains(&e.vignetting) {
            return bad("vignetting", e.vignetting, "must lie in [0, 0.9]");
        }
        if !(0.0..=0.3).contains(&e.exposure_error) {
            return bad(
                "exposure_error",
                e.exposure_error,
                "must lie in [0, 0.3] (relative)",
            );
        }
        Ok(())
    }

    /// Distance from the image centre to a corner \[mm\]: how far the profile must reach.
    pub fn corner_mm(&self) -> f64 {
        0.5 * (self.width as f64).hypot(self.height as f64) * self.mm_per_pixel + 1.0
    }
}

/// Photons for one channel: the steps budget over the expected steps per photon, within
/// [min, max]. A photon in a half-space keeps walking until it escapes or its weight
/// α^n (α = σs/σt, the single-scattering albedo) falls below MCML's roulette threshold 10⁻⁴; the
/// return time to the surface has a tail P(T > n) ∝ n^{−1/2}, so the expected steps grow like
/// √n_max with n_max = ln 10⁻⁴ / ln α. Deterministic: the count depends on the optics only.
///
/// The count is that of the similar isotropic medium (σs = σ′s, g = 0) whatever [`RigSpec::g`]:
/// a twin at g ≠ 0 gets the photons, and so the profile's and the total's Monte Carlo noise, of
/// the same material at g = 0, and costs about 1/(1 − g) times the steps (a Henyey–Greenstein
/// walk needs 1/(1 − g) scattering events per transport mean free path; docs/physics.md §2.3).
/// Budgeting the steps at g instead left a g = 0.8 quick twin's total reflectance 2.2× noisier in
/// variance at α′ = 0.993 (σa ±2–6 % from the reading alone, BENCHMARKS.md "The `mc` model over
/// g"), which is the twin's error and not the method's.
pub fn photons_for(sigma_s_prime: f64, sigma_a: f64, rig: &RigSpec) -> u64 {
    let alpha = sigma_s_prime / (sigma_s_prime + sigma_a);
    let n_max = if alpha < 1.0 {
        (1e-4f64).ln() / alpha.ln()
    } else {
        1e9
    };
    let steps = 2.0 + 1.2 * n_max.min(1e9).sqrt();
    ((rig.steps_budget / steps) as u64).clamp(rig.min_photons, rig.max_photons)
}

/// What the twin knows about one channel and the tool does not.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ChannelTruth {
    /// σ′s [mm⁻¹].
    pub sigma_s_prime: f64,
    /// σa [mm⁻¹].
    pub sigma_a: f64,
    /// α′.
    pub albedo_prime: f64,
    /// The Monte Carlo total diffuse reflectance (what the spectrophotometer's SCE carries).
    pub rd_total: f64,
    /// Its standard error.
    pub rd_total_stderr: f64,
    /// Photons traced.
    pub photons: u64,
    /// Electrons per (mm⁻² of Rd) per second reaching a pixel: light × camera gain.
    pub gain_e_per_rd_s: f64,
}

/// The truth behind a synthetic sample (`truth.json`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Truth {
    /// Sample name.
    pub name: String,
    /// η.
    pub eta: f64,
    /// Henyey–Greenstein g.
    pub g: f64,
    /// R, G, B.
    pub channels: [ChannelTruth; 3],
    /// Spot centre [x, y] in pixels (pixel centres at integers).
    pub center_px: [f64; 2],
    /// The rig.
    pub rig: RigSpec,
    /// Seed.
    pub seed: u64,
    /// The spectrophotometer's port the reading was made through (`synth --aperture-mm`); absent:
    /// the reading is the loss-free total.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub port: Option<crate::port::PortTruth>,
}

/// A frame the twin camera wrote: 8-bit codes or linear raw values.
#[derive(Debug, Clone, PartialEq)]
pub enum Frame {
    /// 8-bit codes through the tone curve.
    U8(ImageBuf<u8>),
    /// Linear raw values (black level included).
    U16(ImageBuf<u16>),
}

/// The bracket and the truth of a synthetic sample (the spectro reading comes from
/// [`crate::spectro::reading_for`] with the truth's totals).
#[derive(Debug, Clone)]
pub struct Bracket {
    /// 8-bit RGB frames, shortest exposure first (empty for a linear camera: see `frames_u16`).
    pub frames: Vec<ImageBuf<u8>>,
    /// Linear raw RGB frames of a [`SensorOutput::Linear`] camera, shortest first (else empty).
    pub frames_u16: Vec<ImageBuf<u16>>,
    /// Their nominal shutter times \[s\] (what the files say).
    pub times_s: Vec<f64>,
    /// The true exposure times \[s\] (the nominal ones unless [`RigEffects::exposure_error`]).
    pub true_times_s: Vec<f64>,
    /// The spot centre used [x, y] px.
    pub center_px: [f64; 2],
    /// Gains used per channel [e⁻ per mm⁻² per s].
    pub gains: [f64; 3],
    /// A frame of a uniform white target through the same camera (when the rig vignettes).
    pub flat: Option<Frame>,
    /// The spot on a thin opaque white target (when [`RigEffects::spot_image`]).
    pub spot_image: Option<Frame>,
}

/// Renders the exposure bracket of `profiles` (R, G, B) through the rig's camera. The spot centre
/// and the per-channel gains are drawn from `seed`; every pixel and frame has its own noise
/// stream (seed, frame, row), so the result is the same on any number of threads.
///
/// # Errors
/// [`SynthError::InvalidParameter`] for a bad rig or an unusable profile.
pub fn render_bracket(
    profiles: &[McProfile; 3],
    rig: &RigSpec,
    seed: u64,
) -> Result<Bracket, SynthError> {
    rig.validate()?;
    let smooth: Vec<SmoothProfile> = profiles
        .iter()
        .map(SmoothProfile::new)
        .collect::<Result<_, _>>()?;
    render_bracket_fn(&|c, r| smooth[c].at(r), None, rig, seed)
}

/// [`render_bracket`] for any radial profile `rd(channel, r_mm)` [mm⁻²] (e.g. a diffusion model,
/// for tests of the imaging stage that need no Monte Carlo). `relative_gains` replaces the drawn
/// relative channel gains (the brightest channel's peak still fills [`RigSpec::peak_fill`] of the
/// well at the shortest exposure).
///
/// # Errors
/// [`SynthError::InvalidParameter`] for a bad rig.
pub fn render_bracket_fn(
    rd_at: &(dyn Fn(usize, f64) -> f64 + Sync),
    relative_gains: Option<[f64; 3]>,
    rig: &RigSpec,
    seed: u64,
) -> Result<Bracket, SynthError> {
    rig.validate()?;
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed ^ 0x5eed_0fc0_ffee);
    let center_px = [
        0.5 * (rig.width as f64 - 1.0) + rng.random_range(-3.0..3.0),
        0.5 * (rig.height as f64 - 1.0) + rng.random_range(-3.0..3.0),
    ];
    // Relative gains of a white LED through an RGB sensor, perturbed so the tool cannot know them.
    let drawn = [0.75, 1.0, 0.6].map(|g: f64| g * rng.random_range(0.8..1.2));
    let rel = relative_gains.unwrap_or(drawn);
    let peak = (0..3)
        .map(|c| rel[c] * rd_at(c, 0.0))
        .fold(0.0f64, f64::max);
    let scale = rig.peak_fill * rig.camera.full_well_e / (peak * rig.times_s[0]);
    let gains = rel.map(|g| g * scale);
    let fx = &rig.effects;
    // Shutter errors from their own stream (the default rig draws nothing more from `rng`).
    let true_times_s: Vec<f64> = if fx.exposure_error > 0.0 {
        let mut r = Xoshiro256PlusPlus::seed_from_u64(seed ^ 0x7157_e55e_0e77_0a11);
        let n = Normal::new(0.0, fx.exposure_error).ok();
        rig.times_s
            .iter()
            .map(|t| t * n.as_ref().map_or(1.0, |n| n.sample(&mut r)).exp())
            .collect()
    } else {
        rig.times_s.clone()
    };
    let (w, h) = (rig.width, rig.height);
    let vignette = vignetting(rig);
    // Glare per channel [electrons/s]: a fraction of the spot centre's signal, uniform.
    let glare: [f64; 3] = std::array::from_fn(|c| fx.glare * gains[c] * rd_at(c, 0.0));
    // Rd at every pixel centre, per channel (shared by all frames).
    let rd: Vec<f32> = (0..h)
        .into_par_iter()
        .flat_map_iter(|y| {
            (0..w).flat_map(move |x| {
                let r =
                    ((x as f64 - center_px[0]).hypot(y as f64 - center_px[1])) * rig.mm_per_pixel;
                (0..3).map(move |c| rd_at(c, r) as f32)
            })
        })
        .collect();
    let camera = rig.camera;
    let linear = matches!(camera.output, SensorOutput::Linear { .. });
    // One exposure of `t` seconds of a scene whose signal rate at pixel (x, y), channel c is
    // rate(x, y, c) [e⁻/s]; noise stream (seed, j, row).
    let expose = |j: usize, t: f64, rate: &(dyn Fn(usize, usize, usize) -> f64 + Sync)| -> Frame {
        let electrons = |y: usize, k: usize, rng: &mut Xoshiro256PlusPlus| {
            let mut e = shot(rate(k / 3, y, k % 3) * t, rng);
            if let Ok(n) = Normal::new(0.0, camera.read_noise_e.max(1e-12)) {
                e += n.sample(rng);
            }
            e
        };
        let stream = |y: usize| {
            Xoshiro256PlusPlus::seed_from_u64(
                seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) ^ ((j as u64) << 32) ^ y as u64,
            )
        };
        if linear {
            let mut raw = vec![0u16; w * h * 3];
            raw.par_chunks_mut(w * 3).enumerate().for_each(|(y, row)| {
                let mut rng = stream(y);
                for (k, out) in row.iter_mut().enumerate() {
                    *out = camera.raw_value(electrons(y, k, &mut rng), k % 3);
                }
            });
            Frame::U16(ImageBuf::new(w, h, 3, raw).expect("w × h × 3 samples"))
        } else {
            let mut codes = vec![0u8; w * h * 3];
            codes
                .par_chunks_mut(w * 3)
                .enumerate()
                .for_each(|(y, row)| {
                    let mut rng = stream(y);
                    for (k, out) in row.iter_mut().enumerate() {
                        *out = camera.code(electrons(y, k, &mut rng));
                    }
                });
            Frame::U8(ImageBuf::new(w, h, 3, codes).expect("w × h × 3 samples"))
        }
    };
    // Without effects the mean is gains·Rd·t exactly, as for an ideal rig (v = 1, glare 0).
    let scene = |x: usize, y: usize, c: usize| {
        vignette(x, y) * (gains[c] * f64::from(rd[(y * w + x) * 3 + c]) + glare[c])
    };
    let rendered: Vec<Frame> = true_times_s
        .par_iter()
        .enumerate()
        .map(|(j, &t)| expose(j, t, &scene))
        .collect();
    let (mut frames, mut frames_u16) = (Vec::new(), Vec::new());
    for f in rendered {
        match f {
            Frame::U8(b) => frames.push(b),
            Frame::U16(b) => frames_u16.push(b),
        }
    }
    // The flat: a uniform white target filling half the well, through the same vignetting, the
    // mean of 16 frames as a lab would take it (read and shot noise / 4).
    let flat = (fx.vignetting > 0.0).then(|| {
        let t = 1.0;
        let level = 0.5 * camera.full_well_e / t;
        let frames: Vec<Frame> = (0..16)
            .map(|i| expose(1000 + i, t, &|x, y, _| vignette(x, y) * level))
            .collect();
        average_frames(&frames)
    });
    // The spot on a thin opaque white target: the beam's irradiance (a disk averaged over 4 × 4
    // points per pixel, or the Gaussian), peak at half the well.
    let spot_image = fx.spot_image.then(|| {
        let a = rig.spot_radius_mm;
        let irradiance = |r: f64| -> f64 {
            if fx.gaussian_spot {
                (-2.0 * r * r / (a * a)).exp()
            } else if r < a {
                1.0
            } else {
                0.0
            }
        };
        let t = 1.0;
        let level = 0.5 * camera.full_well_e / t;
        let mut spot_rate = vec![0.0f64; w * h];
        for y in 0..h {
            for x in 0..w {
                let mut sum = 0.0;
                for sy in 0..4 {
                    for sx in 0..4 {
                        let px = x as f64 - 0.375 + 0.25 * sx as f64;
                        let py = y as f64 - 0.375 + 0.25 * sy as f64;
                        let r = (px - center_px[0]).hypot(py - center_px[1]) * rig.mm_per_pixel;
                        sum += irradiance(r);
                    }
                }
                spot_rate[y * w + x] = vignette(x, y) * level * sum / 16.0;
            }
        }
        expose(2000, t, &|x, y, _| spot_rate[y * w + x])
    });
    Ok(Bracket {
        frames,
        frames_u16,
        times_s: rig.times_s.clone(),
        true_times_s,
        center_px,
        gains,
        flat,
        spot_image,
    })
}

/// The rig's vignetting V(x, y) ∈ (0, 1]: (1 + kρ²)⁻² with ρ the distance from the frame's centre
/// [px] and k such that V = 1 − v at the corner.
fn vignetting(rig: &RigSpec) -> impl Fn(usize, usize) -> f64 + Sync + use<> {
    let (cx, cy) = (
        0.5 * (rig.width as f64 - 1.0),
        0.5 * (rig.height as f64 - 1.0),
    );
    let rho_c2 = cx * cx + cy * cy;
    let v = rig.effects.vignetting;
    let k = ((1.0 - v).powf(-0.5) - 1.0) / rho_c2;
    move |x, y| {
        let (dx, dy) = (x as f64 - cx, y as f64 - cy);
        (1.0 + k * (dx * dx + dy * dy)).powi(-2)
    }
}

/// The pixel-wise mean of frames (rounded), as a lab averages repeated flat frames.
fn average_frames(frames: &[Frame]) -> Frame {
    let n = frames.len() as f64;
    match &frames[0] {
        Frame::U8(f0) => {
            let mut sum = vec![0.0f64; f0.data().len()];
            for f in frames {
                if let Frame::U8(b) = f {
                    for (s, v) in sum.iter_mut().zip(b.data()) {
                        *s += f64::from(*v);
                    }
                }
            }
            let data = sum.iter().map(|s| (s / n).round() as u8).collect();
            Frame::U8(ImageBuf::new(f0.width(), f0.height(), 3, data).expect("same shape"))
        }
        Frame::U16(f0) => {
            let mut sum = vec![0.0f64; f0.data().len()];
            for f in frames {
                if let Frame::U16(b) = f {
                    for (s, v) in sum.iter_mut().zip(b.data()) {
                        *s += f64::from(*v);
                    }
                }
            }
            let data = sum.iter().map(|s| (s / n).round() as u16).collect();
            Frame::U16(ImageBuf::new(f0.width(), f0.height(), 3, data).expect("same shape"))
        }
    }
}

/// Photo-electrons for a mean of `mean`: Poisson below 1000, its normal approximation above
/// (relative error of the approximation's skew < 3 % of σ there, far below the 8-bit step).
fn shot(mean: f64, rng: &mut Xoshiro256PlusPlus) -> f64 {
    if mean <= 0.0 {
        return 0.0;
    }
    if mean < 1000.0 {
        Poisson::new(mean).map_or(mean, |p| p.sample(rng))
    } else {
        Normal::new(mean, mean.sqrt()).map_or(mean, |n| n.sample(rng))
    }
}

#[cfg(test)]
mod tests {
    use super::profile::*;
    use super::*;

    /// The tone curve is monotone with T(0) = 0, T(1) = 1, and codes clip at 0 and 255.
    #[test]
    fn tone_curve_and_codes() {
        let cam = CameraModel::default();
        assert_eq!(cam.tone(0.0), 0.0);
        assert!((cam.tone(1.0) - 1.0).abs() < 1e-15);
        let mut prev = -1.0;
        for i in 0..=1000 {
            let v = cam.tone(i as f64 / 1000.0);
            assert!(v > prev);
            prev = v;
        }
        assert_eq!(cam.code(-50.0), 0);
        assert_eq!(cam.code(1e9), 255);
        // Read noise alone is about half a code at black: slope 255·(1 + b)/b per full well.
        let slope = 255.0 * (1.0 + cam.tone_knee) / cam.tone_knee / cam.full_well_e;
        assert!((0.3..0.8).contains(&(slope * cam.read_noise_e)));
    }

    /// What the step budget buys: the Monte Carlo work a channel really costs. For each channel of
    /// the paper's seven materials, the photons [`photons_for`] grants times the random-walk steps per
    /// photon that the engine counts on a short run of the same half-space (launch + scattering
    /// events; 4096 photons estimate the heavy-tailed mean to about 20 %) is compared with the
    /// documented budget, 2·10⁷ steps per channel on the paper's rig and 2·10⁶ on the quick one
    /// (ARCHITECTURE.md, "synth: the rig twin").
    ///
    /// The budget is a floor: the step model 2 + 1.2√n_max ignores the boundary's internal
    /// reflection, which sends a photon back into the medium about 1/(1 − Fdr(η)) times before it
    /// escapes (Fdr: docs/physics.md §1.2), and under-counts the return-time tail, so a channel
    /// costs more than the budget — measured 2.4× (nephrite, η = 1.08) to 10× (red aluminum R,
    /// η = 2.41) — but not more than 3/(1 − Fdr(η)) times it. A count held at a bound is exempt from
    /// the side that bound decides (the floor of photons may exceed the budget, the ceiling fall
    /// short of it). A tenfold smaller budget puts the work of most channels below the floor.
    #[test]
    fn photon_budget() {
        for (rig, budget) in [(RigSpec::paper(), 2e7), (RigSpec::quick(), 2e6)] {
            let mut inside_the_bounds = 0;
            for m in scatterfit_optics::materials::CHOI_2014 {
                for c in 0..3 {
                    let (sp, sa) = (m.sigma_s_prime[c], m.sigma_a[c]);
                    let photons = photons_for(sp, sa, &rig);
                    let layer = Layer::from_reduced(sp, sa, rig.g, m.eta, f64::INFINITY).unwrap();
                    let beam = Beam::new(BeamProfile::Disk {
                        radius: rig.spot_radius_mm,
                    })
                    .unwrap();
                    let grid = RadialGrid::from_edges(vec![0.0, 1.0]).unwrap();
                    let short = 4096;
                    let run =
                        Simulation::new(Sample::slab(layer, 1.0).unwrap(), beam, grid, short, 7)
                            .unwrap()
                            .run();
                    let steps_per_photon = 1.0 + run.interactions as f64 / short as f64;
                    let ratio = photons as f64 * steps_per_photon / budget;
                    let most = 3.0 / (1.0 - scatterfit_optics::dipole::f_dr(m.eta));
                    let what = format!(
                        "{} {c}: {photons} photons × {steps_per_photon:.1} steps = {ratio:.2} × the \
                         budget (at most {most:.2})",
                        m.name
                    );
                    if photons < rig.max_photons {
                        assert!(ratio >= 1.0, "{what}");
                    }
                    if photons > rig.min_photons {
                        assert!(ratio <= most, "{what}");
                    }
                    if photons > rig.min_photons && photons < rig.max_photons {
                        inside_the_bounds += 1;
                    }
                }
            }
            assert!(
                inside_the_bounds >= 10,
                "{inside_the_bounds} channels inside the bounds"
            );
            // Absorbing channels walk shorter and get more photons than clear ones.
            assert!(photons_for(1.189, 1.189, &rig) > photons_for(1.979, 0.000792, &rig));
        }
    }

    /// `with_photon_scale` gives a channel `scale` times the photons (within a rounding of the
    /// steps budget) and so 1/√scale of the Monte Carlo noise: the engine's own standard error of
    /// the total reflectance, from runs with the two counts, falls by 2 at scale 4 (the standard
    /// error's own estimate is good to about 1 % at 10⁵ photons; 10 % is allowed). Scales outside
    /// [0.01, 1000] are refused by name.
    #[test]
    fn photon_scale_multiplies_the_photons_and_divides_the_noise() {
        let rig = RigSpec::quick();
        let big = rig.clone().with_photon_scale(4.0).unwrap();
        let (sp, sa, eta) = (1.0, 0.1, 1.3);
        let (n1, n4) = (photons_for(sp, sa, &rig), photons_for(sp, sa, &big));
        assert!(n1 > rig.min_photons && n1 < rig.max_photons, "{n1}");
        assert!(n4.abs_diff(4 * n1) <= 4, "{n1} → {n4}");
        let total_stderr = |photons: u64| {
            let layer = Layer::from_reduced(sp, sa, 0.0, eta, f64::INFINITY).unwrap();
            let beam = Beam::new(BeamProfile::Disk {
                radius: rig.spot_radius_mm,
            })
            .unwrap();
            let grid = RadialGrid::from_edges(vec![0.0, 1.0]).unwrap();
            let run = Simulation::new(Sample::slab(layer, 1.0).unwrap(), beam, grid, photons, 3)
                .unwrap()
                .run();
            run.rd_total.stderr
        };
        let ratio = total_stderr(n1) / total_stderr(n4);
        assert!((ratio - 2.0).abs() < 0.2, "noise ratio {ratio}");
        for bad in [0.0, -1.0, 0.005, 2000.0, f64::NAN] {
            let e = rig.clone().with_photon_scale(bad).unwrap_err().to_string();
            assert!(e.contains("photon scale"), "{e}");
        }
    }

    /// The smoother leaves a clean profile alone, extrapolates a pure far field exactly, and
    /// interpolates between bin centres.
    #[test]
    fn smooth_profile_follows_a_known_curve() {
        let rig = RigSpec::paper();
        let spec = ProfileSpec::for_channel(1.0, 0.1, 1.3, &rig, 1).unwrap();
        let grid = RadialGrid::from_edges(spec.edges.clone()).unwrap();
        let f = |r: f64| (-0.5 * r).exp() / (1.0 + r * r);
        let centers: Vec<f64> = (0..grid.bins()).map(|i| grid.center(i)).collect();
        let p = McProfile {
            format: PROFILE_FORMAT.into(),
            spec,
            value: centers.iter().map(|&r| f(r)).collect(),
            stderr: centers.iter().map(|&r| 1e-4 * f(r)).collect(),
            centers,
            rd_total: McMean {
                value: 0.5,
                stderr: 0.0,
            },
        };
        let s = SmoothProfile::new(&p).unwrap();
        for r in [0.05, 0.3, 1.0, 2.5, 7.7, 20.0] {
            assert!(
                (s.at(r) / f(r) - 1.0).abs() < 2e-3,
                "r = {r}: {} vs {}",
                s.at(r),
                f(r)
            );
        }
    }
}
