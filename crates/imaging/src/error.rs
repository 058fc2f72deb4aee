//! The crate's error type: bad input is refused with a typed, descriptive error, never a panic.

use crate::buffer::ShapeError;

/// Everything the imaging functions refuse. Numerical outcomes that are not errors (pixels clipped in
/// every exposure, empty rings) are reported in the result types instead.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ImagingError {
    /// An HDR merge or response recovery needs at least two exposures.
    #[error(
        "{got} exposure(s) given; an HDR merge needs at least 2 frames with different exposure times"
    )]
    TooFewFrames {
        /// Number of frames given.
        got: usize,
    },
    /// The number of exposure times differs from the number of frames.
    #[error("{frames} frames but {times} exposure times; give exactly one time per frame")]
    TimeCountMismatch {
        /// Number of frames.
        frames: usize,
        /// Number of exposure times.
        times: usize,
    },
    /// An exposure time is zero, negative or not finite.
    #[error("exposure time of frame {index} is {time_s} s; exposure times must be finite and > 0")]
    NonPositiveTime {
        /// Index of the frame in the bracket.
        index: usize,
        /// The time given, in seconds.
        time_s: f64,
    },
    /// Two frames have the same exposure time.
    #[error(
        "frames {first} and {second} both have exposure time {time_s} s; every frame of a bracket \
         needs a distinct time"
    )]
    DuplicateTime {
        /// Index of the first frame.
        first: usize,
        /// Index of the second frame.
        second: usize,
        /// The shared time, in seconds.
        time_s: f64,
    },
    /// An image does not have the shape of the others (frames of a bracket, dark frame, mask).
    #[error(
        "{what} is {got_w}×{got_h}×{got_c} (width×height×channels) but {expected_w}×{expected_h}×\
         {expected_c} was expected; all images of a bracket must have the same size and channels"
    )]
    ShapeMismatch {
        /// Which image ("frame 3", "dark frame", "mask").
        what: String,
        /// Expected width.
        expected_w: usize,
        /// Expected height.
        expected_h: usize,
        /// Expected channel count.
        expected_c: usize,
        /// Width found.
        got_w: usize,
        /// Height found.
        got_h: usize,
        /// Channels found.
        got_c: usize,
    },
    /// The response curve has a different number of channels than the images.
    #[error(
        "response curve has {response} channel(s) but the images have {image}; give one curve per \
         channel (or a single curve for grey images)"
    )]
    ChannelMismatch {
        /// Channels of the response curve.
        response: usize,
        /// Channels of the images.
        image: usize,
    },
    /// A given response curve is unusable.
    #[error("response curve, channel {channel}, code value {z}: {reason}")]
    InvalidResponse {
        /// Channel index.
        channel: usize,
        /// Code value (0..=255) where the problem is.
        z: usize,
        /// What is wrong.
        reason: &'static str,
    },
    /// An option is out of its domain.
    #[error("option `{name}` = {value} is invalid: {reason}")]
    InvalidOption {
        /// Option name.
        name: &'static str,
        /// The value given.
        value: f64,
        /// The domain it must lie in.
        reason: &'static str,
    },
    /// Not enough usable sample pixels to recover the camera response.
    #[error(
        "channel {channel}: only {found} usable sample pixels (at least {needed} needed); the bracket \
         has too few well-exposed, non-flat pixels — check the exposures or give a known response"
    )]
    NotEnoughSamples {
        /// Channel index.
        channel: usize,
        /// Usable pixels found.
        found: usize,
        /// Pixels required.
        needed: usize,
    },
    /// The number of sample pixels for response recovery is outside what the bracket needs and
    /// what the solver can hold.
    #[error(
        "{samples} sample pixels per channel with {frames} frames: the response recovery takes \
         {min} to {max} (at least ⌈256/(P − 1)⌉, so that N·(P − 1) ≥ 256 equations determine the 256 \
         values of g, Debevec & Malik 1997 §2.1; more than {max} only cost time and memory)"
    )]
    SampleCount {
        /// Samples asked for.
        samples: usize,
        /// Frames in the bracket.
        frames: usize,
        /// The least number for this bracket, ⌈256/(P − 1)⌉.
        min: usize,
        /// The most accepted, [`crate::MAX_RESPONSE_SAMPLES`].
        max: usize,
    },
    /// The recovered response does not increase with the code value: a camera's does, so the
    /// exposure times do not belong to their frames (reversed or shuffled) or the bracket carries
    /// too little information.
    #[error(
        "channel {channel}: the recovered camera response falls by {drop:.3} (ln units) between code \
         {z_from} and code {z_to}, over a rise of {span:.3} across the codes the samples use; a \
         camera's response increases with exposure — are the exposure times in the right order, each \
         with its own frame? (check the exposures CSV or the files' EXIF times, or give a known \
         response)"
    )]
    ResponseNotIncreasing {
        /// Channel index.
        channel: usize,
        /// Code where the fall starts (the running maximum).
        z_from: usize,
        /// Code where the fall is largest.
        z_to: usize,
        /// The fall g(z_from) − g(z_to) [ln exposure].
        drop: f64,
        /// g(z_hi) − g(z_lo) over the codes the samples use (negative for a curve that runs
        /// downward).
        span: f64,
    },
    /// The frames do not brighten with their exposure times: a frame with a longer time is darker
    /// than (or the same as) one with a shorter time — times reversed or shuffled, or one frame
    /// listed twice. Seen directly in the frames, before any response is recovered
    /// ([`crate::check_bracket_order`]).
    #[error(
        "the frames do not brighten with their exposure times: {what} (frame {longer} at {t_longer} s \
         against frame {shorter} at {t_shorter} s, counting frames in the order given from 0; of the \
         {compared} pixel values that differ and carry signal in both (above each frame's noise \
         floor, below the clip), {darker} got darker and {brighter} brighter with the longer time) — are the exposure times in the right order, each \
         with its own frame? (check the exposures CSV or the files' EXIF times)"
    )]
    BracketOutOfOrder {
        /// What was seen: "the longer exposure is darker", "the two frames are identical", …
        what: &'static str,
        /// Index (as given) of the frame with the shorter time.
        shorter: usize,
        /// Index (as given) of the frame with the longer time.
        longer: usize,
        /// Its time \[s\].
        t_shorter: f64,
        /// Its time \[s\].
        t_longer: f64,
        /// Pixel values compared that differ (above both frames' noise floors, below the clip).
        compared: usize,
        /// Of those, how many are lower in the longer exposure.
        darker: usize,
        /// And how many higher.
        brighter: usize,
    },
    /// A frame holds far more or less light than its exposure time says, measured against its
    /// neighbours on the pixels well exposed in both: more than a shutter's error.
    #[error(
        "frame {frame} (at {time_s} s, counting frames by time from 0) holds {factor:.3} × the \
         light its exposure time says, measured against its neighbours on the pixels well exposed \
         in both — more than half a stop off (beyond {limit:.3} × either way, and beyond the \
         estimate's noise), more than a shutter errs: is it the right file for that time (one \
         frame listed twice, a frame of another bracket, the light changed)?"
    )]
    ExposureMismatch {
        /// Index of the frame, by time.
        frame: usize,
        /// Its nominal time \[s\].
        time_s: f64,
        /// Its estimated exposure over the nominal one.
        factor: f64,
        /// The largest factor (and its inverse the least) taken for a shutter's error.
        limit: f64,
    },
    /// The dark frame is at or above the signal: fewer than [`crate::MIN_VALID_FRACTION`] of a
    /// channel's pixels rise above it even in the longest exposure.
    #[error(
        "dark frame, channel {channel}: only {above} of {total} pixels of the longest exposure are \
         brighter than the dark frame; a dark frame is taken with the light blocked (lens capped) at \
         the bracket's settings and must be darker than the scene — is it the right file, or taken \
         with the light on?"
    )]
    DarkFrameAboveSignal {
        /// Channel index.
        channel: usize,
        /// Pixels of the longest exposure above the dark frame.
        above: usize,
        /// Pixels in the image.
        total: usize,
    },
    /// No frame of the bracket carries signal: every value of every frame is at its noise floor or
    /// clipped ([`crate::bracket_signal`]).
    #[error(
        "none of the {frames} frames carries signal: every value is at its noise floor or clipped \
         (black, or white all over) — was the lens capped or the light off, or is every exposure \
         far too short or too long? Check the frames and their exposure times"
    )]
    NoSignal {
        /// Frames in the bracket.
        frames: usize,
    },
    /// (Nearly) every pixel of a channel is clipped in every exposure: the merge has no radiance to
    /// give.
    #[error(
        "channel {channel}: only {valid} of {total} pixels have a radiance ({saturated} saturated in \
         every exposure, {dark} at or below the black level in every exposure); {advice}"
    )]
    NoValidRadiance {
        /// Channel index.
        channel: usize,
        /// Pixels with an estimate.
        valid: usize,
        /// Pixels in the image.
        total: usize,
        /// Pixels saturated in every exposure.
        saturated: usize,
        /// Pixels at the low clip (or the dark level) in every exposure.
        dark: usize,
        /// What to do.
        advice: &'static str,
    },
    /// The least-squares system for the response is rank deficient or not finite.
    #[error("channel {channel}: response recovery failed: {reason}")]
    SolveFailed {
        /// Channel index.
        channel: usize,
        /// What went wrong.
        reason: &'static str,
    },
    /// No light spot could be found in the image.
    #[error("no light spot found: {reason}")]
    NoSpot {
        /// Why.
        reason: &'static str,
    },
    /// A given centre lies outside the image or is not finite.
    #[error("spot centre ({x}, {y}) px is outside the {width}×{height} image or not finite")]
    CenterOutside {
        /// x in pixels.
        x: f64,
        /// y in pixels.
        y: f64,
        /// Image width.
        width: usize,
        /// Image height.
        height: usize,
    },
    /// A buffer could not be built.
    #[error(transparent)]
    Shape(#[from] ShapeError),
}

impl ImagingError {
    /// True when the error says that a measurement ran and failed (the CLI's exit code 1): the data
    /// do not yield a result — a bracket with too few usable pixels, a response that does not
    /// increase, a radiance map without valid pixels, no light spot. False for bad input or options
    /// (exit code 2), which are found before any work: mismatched frames, times, shapes, an option
    /// out of range, a dark frame at or above the signal.
    pub fn is_failed_measurement(&self) -> bool {
        matches!(
            self,
            Self::NotEnoughSamples { .. }
                | Self::SolveFailed { .. }
                | Self::ResponseNotIncreasing { .. }
                | Self::BracketOutOfOrder { .. }
                | Self::ExposureMismatch { .. }
                | Self::NoValidRadiance { .. }
                | Self::NoSpot { .. }
        )
    }
}

/// Result with [`ImagingError`].
pub type Result<T> = std::result::Result<T, ImagingError>;

/// Checks a bracket: at least two frames, one finite positive, distinct time per frame, equal shapes.
pub(crate) fn check_bracket<T: Copy>(frames: &[crate::ImageBuf<T>], times_s: &[f64]) -> Result<()> {
    if frames.len() < 2 {
        return Err(ImagingError::TooFewFrames { got: frames.len() });
    }
    if frames.len() != times_s.len() {
        return Err(ImagingError::TimeCountMismatch {
            frames: frames.len(),
            times: times_s.len(),
        });
    }
    for (index, &t) in times_s.iter().enumerate() {
        if !(t.is_finite() && t > 0.0) {
            return Err(ImagingError::NonPositiveTime { index, time_s: t });
        }
    }
    for first in 0..times_s.len() {
        for second in first + 1..times_s.len() {
            if times_s[first] == times_s[second] {
                return Err(ImagingError::DuplicateTime {
                    first,
                    second,
                    time_s: times_s[first],
                });
            }
        }
    }
    let f0 = &frames[0];
    for (i, f) in frames.iter().enumerate().skip(1) {
        check_shape(f0, f, || format!("frame {i}"))?;
    }
    Ok(())
}

/// Checks a bracket, the radiance map merged from it (its shape) and the response it was merged
/// with (one curve, or one per channel); returns the frames' channel count.
pub(crate) fn check_bracket_map(
    frames: &[crate::ImageBuf<u8>],
    times_s: &[f64],
    response: &crate::ResponseCurve,
    hdr: &crate::HdrImage,
) -> Result<usize> {
    check_bracket(frames, times_s)?;
    check_shape(&frames[0], &hdr.radiance, || "radiance map".to_string())?;
    let ch = frames[0].channels();
    if response.channels() != ch && response.channels() != 1 {
        return Err(ImagingError::ChannelMismatch {
            response: response.channels(),
            image: ch,
        });
    }
    Ok(ch)
}

/// Checks that `other` has the shape of `reference`; `what` names `other` in the error.
pub(crate) fn check_shape<T: Copy, U: Copy>(
    reference: &crate::ImageBuf<T>,
    other: &crate::ImageBuf<U>,
    what: impl FnOnce() -> String,
) -> Result<()> {
    if reference.same_shape(other) {
        return Ok(());
    }
    Err(ImagingError::ShapeMismatch {
        what: what(),
        expected_w: reference.width(),
        expected_h: reference.height(),
        expected_c: reference.channels(),
        got_w: other.width(),
        got_h: other.height(),
        got_c: other.channels(),
    })
}
