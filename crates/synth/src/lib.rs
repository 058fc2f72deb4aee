//! scatterfit-synth: the synthetic twin of the measuring rig.
//!
//! From known optical parameters it produces what the instruments would record — a d/8
//! spectrophotometer reading ([`spectro`]) and the imaging rig's exposure bracket ([`rig`]) — with
//! the Monte Carlo engine (`scatterfit-mc`), never with the diffusion model the tool fits, so that
//! the whole pipeline can be tested end to end against a known truth. The published materials that drive
//! the demo are `scatterfit_optics::materials`; [`synthesize`] puts the pieces together.

#![forbid(unsafe_code)]

pub mod mishaps;
pub mod port;
pub mod rig;
pub mod spectro;

use std::path::{Path, PathBuf};

use scatterfit_optics::colour::{self, Lab, Observer};
use scatterfit_optics::spectro::SpectroReading;

pub use rig::{Bracket, CameraModel, ChannelTruth, McProfile, ProfileSpec, RigSpec, Truth};

/// What can go wrong synthesising a sample.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SynthError {
    /// A parameter outside its domain.
    #[error("{name} = {value} is invalid: {reason}")]
    InvalidParameter {
        /// The quantity.
        name: &'static str,
        /// The value.
        value: f64,
        /// Why, and the accepted range.
        reason: &'static str,
    },
    /// The Monte Carlo engine refused the optics.
    #[error("Monte Carlo: {0}")]
    Mc(#[from] scatterfit_mc::McError),
    /// The colour cannot be made with the smooth spectral basis.
    #[error(transparent)]
    OutOfGamut(#[from] spectro::OutOfGamut),
    /// The profile cache could not be written.
    #[error("cannot write {}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
}

/// A whole synthetic sample: spectrophotometer reading, the L\*a\*b\* an instrument would print, the
/// exposure bracket and the truth.
#[derive(Debug, Clone)]
pub struct SyntheticSample {
    /// SCI and SCE, 400–700 nm at 10 nm.
    pub reading: SpectroReading,
    /// L\*a\*b\* of the SCE spectrum (D65, 10° observer, the instrument default).
    pub lab10: Lab,
    /// The bracket.
    pub bracket: Bracket,
    /// The truth.
    pub truth: Truth,
}

/// Synthesises a sample of a material with per-channel σ′s, σa [mm⁻¹] and η on `rig`.
/// Monte Carlo profiles are cached in `cache_dir` (when given) by their spec, so a second run is
/// fast; `progress(channel, photons_done, photons_total)` reports the simulations.
///
/// # Errors
/// [`SynthError`] for invalid optics or rig, an out-of-gamut colour, or an unwritable cache.
pub fn synthesize(
    name: &str,
    sigma_s_prime: [f64; 3],
    sigma_a: [f64; 3],
    eta: f64,
    rig: &RigSpec,
    seed: u64,
    cache_dir: Option<&Path>,
    progress: &(dyn Fn(usize, u64, u64) + Sync),
) -> Result<SyntheticSample, SynthError> {
    rig.validate()?;
    if !(eta.is_finite() && (1.0..=3.0).contains(&eta)) {
        return Err(SynthError::InvalidParameter {
            name: "eta",
            value: eta,
            reason: "the rig twin takes η in [1, 3]",
        });
    }
    let mut profiles = Vec::with_capacity(3);
    for c in 0..3 {
        let spec = ProfileSpec::for_channel(
            sigma_s_prime[c],
            sigma_a[c],
            eta,
            rig,
            seed.wrapping_mul(3).wrapping_add(c as u64),
        )?;
        let (p, _) = McProfile::load_or_simulate(&spec, cache_dir, &|d, t| progress(c, d, t))?;
        profiles.push(p);
    }
    let profiles: [McProfile; 3] = profiles.try_into().expect("three channels");
    let bracket = rig::render_bracket(&profiles, rig, seed)?;
    let rd: [f64; 3] = std::array::from_fn(|c| profiles[c].rd_total.value);
    let reading = spectro::reading_for(rd, eta)?;
    let lab10 = lab10_of(&reading)?;
    let channels = std::array::from_fn(|c| ChannelTruth {
        sigma_s_prime: sigma_s_prime[c],
        sigma_a: sigma_a[c],
        albedo_prime: sigma_s_prime[c] / (sigma_s_prime[c] + sigma_a[c]),
        rd_total: profiles[c].rd_total.value,
        rd_total_stderr: profiles[c].rd_total.stderr,
        photons: profiles[c].spec.photons,
        gain_e_per_rd_s: bracket.gains[c],
    });
    let truth = Truth {
        name: name.to_string(),
        eta,
        g: rig.g,
        channels,
        center_px: bracket.center_px,
        rig: rig.clone(),
        seed,
        port: None,
    };
    Ok(SyntheticSample {
        reading,
        lab10,
        bracket,
        truth,
    })
}

/// L\*a\*b\* of a reading's SCE spectrum (D65, 10° observer, the instrument default).
fn lab10_of(reading: &SpectroReading) -> Result<Lab, SynthError> {
    let xyz10 =
        colour::spectrum_to_xyz(reading.wavelengths_nm(), reading.sce(), Observer::TenDegree)
            .map_err(|_| SynthError::InvalidParameter {
                name: "spectrum",
                value: 0.0,
                reason: "the synthetic SCE spectrum does not cover 400–700 nm",
            })?;
    Ok(colour::xyz_to_lab(xyz10, Observer::TenDegree.d65_white()))
}
