//! How a bracket is merged: the weighting of the 8-bit merge and the options of the 8-bit and the
//! linear merges.

use super::image::ClippedFill;
use crate::error::{ImagingError, Result};

/// How [`merge`](crate::merge::merge) weights the samples of a pixel-channel across the bracket.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum Weighting {
    /// Noise-aware, the default: the maximum-likelihood estimate of Robertson, Borman & Stevenson
    /// 2003 (J. Electronic Imaging 12(2), §3), E = Σ_j w_j Δt_j X(Z_j) / Σ_j w_j Δt_j², averaged in the
    /// *linear* domain X = exp g(Z), with inverse-variance weights w_j = Δt_j²·u(Z_j) (Granados et
    /// al. 2010, CVPR, "Optimal HDR reconstruction with linear digital cameras": w_j = Δt_j²/σ²_j,
    /// here with a noise σ constant in the linear signal), so each frame counts by Δt² and a short
    /// frame's noisy low codes barely move the estimate. u(z) = 1 up to code 128 and the upper half
    /// of the paper's hat above, (255 − z)/127, which fades out codes near the clip where the tone
    /// curve is compressed (a choice of ours, measured in BENCHMARKS.md); saturated codes (255) are
    /// dropped; a code-0 sample counts as X = 0 (it is a censored reading, evidence
    /// that the exposure was at most the first code's), so dark frames no longer bias dim pixels
    /// upwards as dropping them would (what the censoring at code 0 still leaves — a frame within
    /// a few noise σ of black averages high — goes with [`MergeOptions::expected_floor`]). A
    /// pixel-channel with no sample above code 0 (or above the dark level) has no estimate.
    #[default]
    NoiseOptimal,
    /// The paper's hat, Debevec & Malik 1997 eq. (6): ln E = Σ w(Z)(g(Z) − ln Δt)/Σ w(Z) with
    /// w = [`crate::hat_weight`] (codes 0 and 255 dropped). Biased high for pixels whose brightest
    /// frame stays at a low code (noisy low codes are kept, zero codes dropped); see BENCHMARKS.md.
    DebevecHat,
}

/// Options of [`merge`](crate::merge::merge). Its fields are public: two enums, every combination valid (nothing to
/// check, unlike [`LinearMergeOptions`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct MergeOptions {
    /// Value of pixel-channels clipped in every exposure.
    pub clipped_fill: ClippedFill,
    /// Sample weighting (default [`Weighting::NoiseOptimal`]).
    pub weighting: Weighting,
    /// The expected-signal floor of [`Weighting::NoiseOptimal`] (default `None`: every frame
    /// counts): per channel (channel c uses entry min(c, 3)) a code below which a frame's reading
    /// of a pixel is left out of the merge *because of the signal it is expected to have*, not the
    /// code it shows. See [`merge`](crate::merge::merge)'s second pass.
    pub expected_floor: Option<[u8; 4]>,
}

/// Options of [`merge_linear_u16`](crate::merge::merge_linear_u16); built through [`LinearMergeOptions::new`], so always valid.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinearMergeOptions {
    pub(super) saturation: u16,
    pub(super) clipped_fill: ClippedFill,
}

impl LinearMergeOptions {
    /// Options with the raw value at and above which a sample counts as saturated (many sensors
    /// clip below 65535, e.g. 4095 × 16 for 12-bit data; default 65535) and the value of
    /// pixel-channels clipped in every exposure.
    ///
    /// # Errors
    /// [`ImagingError::InvalidOption`] for a saturation below 2 (the hat weight needs a range).
    pub fn new(saturation: u16, clipped_fill: ClippedFill) -> Result<Self> {
        if saturation < 2 {
            return Err(ImagingError::InvalidOption {
                name: "saturation",
                value: f64::from(saturation),
                reason: "must be ≥ 2",
            });
        }
        Ok(Self {
            saturation,
            clipped_fill,
        })
    }

    /// The saturation level [raw value], ≥ 2.
    pub fn saturation(&self) -> u16 {
        self.saturation
    }

    /// The value of pixel-channels clipped in every exposure.
    pub fn clipped_fill(&self) -> ClippedFill {
        self.clipped_fill
    }
}

impl Default for LinearMergeOptions {
    fn default() -> Self {
        Self {
            saturation: u16::MAX,
            clipped_fill: ClippedFill::Nan,
        }
    }
}
