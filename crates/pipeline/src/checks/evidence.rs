//! Cross-checks from the data's own redundancy: what one part of a measurement says that another
//! part can confirm.
//!
//! - **The profile's own α′.** Under exact transport the shape of Rd(r) determines σ′s and σa
//!   both (the existing method of Jensen et al. 2001 fits them), so the profile carries its own
//!   reduced albedo beside the spectrophotometer's. Another sample's spectrophotometer file, a
//!   reading through a wrong port or a profile from elsewhere make the two disagree far beyond
//!   their errors, and the proposed fit (α′ held at the reading's) then misses the profile's shape
//!   that the two-parameter fit follows ([`AlbedoCheck`]).
//! - **The spot's size in pixels.** The fitted model convolved with the stated spot, at the
//!   stated scale, predicts the profile inside the spot too, where the fit did not look: its half
//!   width in pixels is the spot's radius over `mm_per_pixel`, widened by the light's spread in
//!   the material. The image's half width against it ([`spot_scale`](super::spot_scale)) measures the scale (or the
//!   spot's diameter) to a few percent.

use scatterfit_optics::{Channel, Rgb};
use serde::Serialize;

use crate::fit::outcome::ChannelOutcome;
use crate::spectro::SpectroStage;

/// One channel's α′ from the profile's shape against the spectrophotometer's.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct AlbedoCheck {
    /// α′ of the two-parameter fit (σ′s and σa both from the profile).
    pub profile: f64,
    /// Its standard error in ln(1 − α′) (from the fit's σ′s and σa errors and their
    /// correlation).
    pub profile_se_ln: f64,
    /// α′ of the spectrophotometer's reading.
    pub spectro: f64,
    /// Its standard error in ln(1 − α′) (the reading's repeatability; 0 when unknown).
    pub spectro_se_ln: f64,
    /// |ln(1 − α′ profile) − ln(1 − α′ spectro)| over the two errors in quadrature.
    pub z: f64,
    /// χ²/dof of the proposed fit (α′ held at the reading's).
    pub chi2_proposed: f64,
    /// χ²/dof of the two-parameter fit on the same rings.
    pub chi2_profile: f64,
}

/// What the measurement's redundancy gave, kept with it ([`Measurement::evidence`](crate::Measurement::evidence)).
#[derive(Debug, Clone, Default, Serialize)]
pub struct Evidence {
    /// Per channel, the profile's α′ against the reading's (proposed method only; `None` where
    /// either fit is missing).
    pub albedo: Rgb<Option<AlbedoCheck>>,
    /// The image's spot half width over the fitted model's at the stated scale ([`spot_scale`](super::spot_scale)),
    /// made with the measurement (and its full refits) after the fits; `None` where it could not
    /// be measured, and for a refit of values only.
    pub spot_scale: Option<SpotScale>,
}

/// Gathers the evidence of a measurement made with the proposed method from its fits and the
/// two-parameter fits of the same rings with the same model ([`crate::fit::free_fits`]; `None`,
/// no evidence, for the existing method).
pub fn gather(
    spectro: &SpectroStage,
    fits: &Rgb<ChannelOutcome>,
    free_fits: Option<&Rgb<ChannelOutcome>>,
) -> Evidence {
    let Some(profile_fits) = free_fits else {
        return Evidence::default();
    };
    let albedo = Rgb::from_fn(|c: Channel| {
        let proposed = fits[c].report().filter(|r| r.converged)?;
        let free = profile_fits[c].report().filter(|r| r.converged)?;
        albedo_check(proposed, free, spectro.uncertainty.albedo_prime_stderr[c])
    });
    Evidence {
        albedo,
        spot_scale: None,
    }
}

/// The comparison of one channel's two fits ([`AlbedoCheck`]); `None` when the two-parameter fit
/// left a parameter unconstrained or its α′ is not in (0, 1).
fn albedo_check(
    proposed: &scatterfit_fit::FitReport,
    free: &scatterfit_fit::FitReport,
    spectro_stderr: Option<f64>,
) -> Option<AlbedoCheck> {
    if !free.unconstrained.is_empty() {
        return None;
    }
    let (s, a) = (free.sigma_s_prime, free.sigma_a);
    let alpha = s.value / (s.value + a.value);
    if !(alpha > 0.0 && alpha < 1.0) {
        return None;
    }
    // ln(1 − α′) = ln σa − ln(σ′s + σa), so d ln(1 − α′) = α′ (dσa/σa − dσ′s/σ′s): its variance
    // from the relative errors and their correlation (delta method).
    let (rs, ra) = (s.stderr / s.value, a.stderr / a.value);
    let index =
        |name: scatterfit_optics::Parameter| free.parameters.iter().position(|p| *p == name);
    let rho = match (
        index(scatterfit_optics::Parameter::SigmaSPrime),
        index(scatterfit_optics::Parameter::SigmaA),
    ) {
        (Some(i), Some(j)) => free
            .correlation
            .get(i)
            .and_then(|row| row.get(j))
            .copied()
            .unwrap_or(0.0),
        _ => 0.0,
    };
    let var = alpha * alpha * (ra * ra + rs * rs - 2.0 * rho * ra * rs);
    let profile_se_ln = var.max(0.0).sqrt();
    let spectro = proposed.albedo_prime;
    let spectro_se_ln = spectro_stderr.map_or(0.0, |e| e / (1.0 - spectro));
    let gap = ((1.0 - alpha).ln() - (1.0 - spectro).ln()).abs();
    let se = profile_se_ln.hypot(spectro_se_ln);
    let z = if se > 0.0 { gap / se } else { f64::INFINITY };
    profile_se_ln.is_finite().then_some(AlbedoCheck {
        profile: alpha,
        profile_se_ln,
        spectro,
        spectro_se_ln,
        z,
        chi2_proposed: proposed.chi2_reduced,
        chi2_profile: free.chi2_reduced,
    })
}

/// The image's spot half width against the fitted model's at the stated scale: for the channel
/// sum and for each channel alone ([`spot_scale`](super::spot_scale)).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SpotScale {
    /// The channel sum's ratio (image over model).
    pub factor: f64,
    /// Each channel's own ratio (R, G, B); `None` where a channel has no half width.
    pub channels: [Option<f64>; 3],
}

impl SpotScale {
    /// True when every channel, measured alone, finds the spot too large (`above`) or too small
    /// by more than [`crate::checks::SPOT_CHANNEL_MARGIN`]. A wrong scale (or spot diameter) is
    /// common to the channels and moves each of them alike; a JPEG's 8 × 8 blocks and chroma
    /// subsampling move the edge of a small spot differently in each (Pillow's quality 75 on the
    /// quick twin's 10-pixel spot: R 1.05, G 1.10, B 0.98).
    pub fn every_channel_agrees(&self, above: bool) -> bool {
        let m = crate::checks::SPOT_CHANNEL_MARGIN;
        self.channels
            .iter()
            .all(|c| c.is_some_and(|f| if above { f > 1.0 + m } else { f < 1.0 - m }))
    }
}

/// The half width at half maximum of ring values `v` at radii `r` \[px\], as
/// [`crate::checks::spot_hwhm_px`] measures the image's.
pub(crate) fn hwhm_of(v: &[f64], r: &[f64]) -> Option<f64> {
    let peak = v
        .iter()
        .take(4)
        .copied()
        .filter(|x| x.is_finite())
        .fold(f64::NAN, f64::max);
    if peak.is_nan() || peak <= 0.0 {
        return None;
    }
    for k in 1..v.len() {
        let (u, w) = (v[k - 1], v[k]);
        if w.is_finite() && w < 0.5 * peak {
            let t = if u.is_finite() && u > w {
                ((u - 0.5 * peak) / (u - w)).clamp(0.0, 1.0)
            } else {
                0.0
            };
            return Some(r[k - 1] + t * (r[k] - r[k - 1]));
        }
    }
    None
}
