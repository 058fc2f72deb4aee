//! scatterfit-imaging: pure pixel work on buffers.
//!
//! Camera response recovery and HDR merging (Debevec & Malik 1997), the light spot's centre, and the
//! radial profile Rd(r). No file formats here: `scatterfit-io` decodes files into [`ImageBuf`]s.
//!
//! The pipeline, with its entry points:
//! 1. [`recover_response`] (or [`ResponseCurve::from_log_exposure`] / [`ResponseCurve::linear`] for a
//!    known curve) — the camera response g(z) = ln exposure per channel, gauge g(128) = 0;
//! 2. [`merge()`] (8-bit frames and a response) or [`merge_linear_u16`] (linear 16-bit frames) — a
//!    relative radiance map with a mask of pixels clipped in every exposure;
//! 3. [`find_spot_center`] (or [`SpotCenter::given`]) — the spot centre, sub-pixel;
//! 4. [`radial_profile`] — per-ring mean, standard error and count, radius in pixels and mm.
//!
//! Beside the pipeline, [`text`] draws a line of text onto a buffer (the workspace's one glyph
//! rasteriser, with the embedded DejaVu Sans), for plot labels and figure captions.
//!
//! Pixel coordinates: pixel (x, y) has its centre at (x, y).

pub mod buffer;
pub mod center;
pub mod consistency;
pub mod error;
pub mod merge;
pub mod order;
pub mod profile;
pub mod response;
pub mod text;

pub use buffer::{ImageBuf, ShapeError};
pub use center::{CenterOptions, SpotCenter, find_spot_center};
pub use consistency::{SelfConsistency, WELL_EXPOSED, self_consistency, self_consistency_sampled};
pub use error::{ImagingError, Result};
pub use merge::{
    CLIPPED_HIGH, CLIPPED_LOW, ClippedFill, HdrImage, LinearMergeOptions, MIN_VALID_FRACTION,
    MergeOptions, Weighting, merge, merge_linear_black, merge_linear_u16,
};
pub use order::{
    BracketSignal, FLOOR_PIXELS, bracket_signal, check_bracket_order,
    check_bracket_order_with_signal,
};
pub use profile::{MAX_RINGS, ProfileOptions, RadialProfile, Ring, RingChannel, radial_profile};
pub use response::{
    CalibrateOptions, Calibration, ChannelSolution, LEVELS, MAX_RESPONSE_FALL,
    MAX_RESPONSE_SAMPLES, ResponseCurve, SamplePixel, TOE_PIXELS, TOE_TRUST_HI, TOE_TRUST_LO,
    forward_toe, gsolve, hat_weight, min_response_samples, recover_response, refit_response_to_map,
    select_samples,
};
