//! HDR merge of an exposure bracket into a per-channel radiance map.
//!
//! 8-bit: by default the noise-aware linear-domain estimate E = Σ_j w_j Δt_j X(Z_j)/Σ_j w_j Δt_j²
//! (Robertson, Borman & Stevenson 2003; see [`Weighting::NoiseOptimal`]), or the paper's
//! ln E = Σ_j w(Z_j)(g(Z_j) − ln Δt_j) / Σ_j w(Z_j) with the hat weight (Debevec & Malik 1997, eq. 6;
//! [`Weighting::DebevecHat`]). Saturated samples carry no weight. A pixel-channel
//! clipped in *every* exposure has no estimate: it is flagged in [`HdrImage::clipped`] and its
//! radiance is set by [`ClippedFill`] (NaN by default, never a made-up number).
//!
//! Radiance is relative: for an 8-bit merge it is in the response's gauge (E = 1 gives code 128 in a
//! 1 s exposure with a recovered curve); for a 16-bit linear merge it is digital numbers per second.
//!
//! The module by concept: `image` ([`HdrImage`], the clipping flags and checks), `options` (the
//! weighting and the options), `eight_bit` ([`merge`]), `lut` (its per-code tables and row
//! kernel), `refine` (its expected-signal second pass), `linear` ([`merge_linear_u16`],
//! [`merge_linear_black`]).

mod eight_bit;
mod image;
mod linear;
mod lut;
mod options;
mod refine;

pub use eight_bit::merge;
pub use image::{CLIPPED_HIGH, CLIPPED_LOW, ClippedFill, HdrImage, MIN_VALID_FRACTION};
pub use linear::{merge_linear_black, merge_linear_u16};
pub use options::{LinearMergeOptions, MergeOptions, Weighting};
