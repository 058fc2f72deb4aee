//! Camera response curves and their recovery from an exposure bracket (Debevec & Malik 1997).
//!
//! Glossary: a frame's *code value* Z ∈ 0..=255 is what the camera wrote for a pixel; the camera maps
//! exposure X = E·Δt (irradiance E times shutter time Δt) to Z = f(X). The *response* stored here is
//! g(Z) = ln f⁻¹(Z) = ln E + ln Δt (Debevec & Malik 1997, eq. 2), one table of 256 values per channel.
//! Exposure is only known up to a common factor, so g is only known up to an additive constant: the
//! *gauge*. Recovered curves use the paper's gauge g(128) = 0 (its appendix, `A(k,129) = 1`), so a
//! radiance of 1 is the irradiance that gives code 128 in a 1 s exposure.
//!
//! The module by concept: `curve` (the response table [`ResponseCurve`]); `gsolve` (Debevec &
//! Malik's system, the hat weight); `solve` (least squares, the corrected semi-normal equations,
//! the monotone solve by non-negative least squares); `comb` (the spline refit and the comb in log
//! exposure that remove the bracket-period ripple); `toe` (the forward toe); `samples` (sample
//! pixel selection); `recover` ([`recover_response`]: all of it per channel, and the check that g
//! rises); `refit` ([`refit_response_to_map`]: the curve refitted to a merged map, every pixel's
//! codes regressed on its log exposure).

mod comb;
mod curve;
mod gsolve;
mod recover;
mod refit;
mod samples;
mod solve;
mod toe;

pub use comb::AMBIGUITY_KNOT_STEP;
pub use curve::{LEVELS, ResponseCurve};
pub use gsolve::{ChannelSolution, gsolve, hat_weight};
pub use recover::{CalibrateOptions, Calibration, MAX_RESPONSE_FALL, recover_response};
pub use refit::refit_response_to_map;
pub use samples::{MAX_RESPONSE_SAMPLES, SamplePixel, min_response_samples, select_samples};
pub use toe::{TOE_PIXELS, TOE_TRUST_HI, TOE_TRUST_LO, forward_toe};
