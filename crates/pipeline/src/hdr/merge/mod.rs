//! The merge proper, one function per kind of bracket: 8-bit frames through a given or recovered
//! response (Debevec \& Malik 1997), 16-bit and RAW frames as linear data; each checks and corrects
//! the exposure times from the frames and divides out a flat frame.
//!
//! By concept: this file holds what both kinds share (the context, the outcome, the frame
//! selection and the order check); `eight_bit` (8-bit frames through a response), `linear`
//! (16-bit and RAW), `flat` (the flat frame), `detection` (the detection limit).

use super::*;

mod detection;
mod eight_bit;
mod flat;
mod linear;

pub(super) use eight_bit::merge_8bit;
pub use flat::{FLAT_MAX_PEAK, FLAT_MIN_LOW};
pub(super) use linear::merge_linear;

/// What both kinds of bracket are merged with.
pub(super) struct MergeContext<'a> {
    /// The exposure times as given \[s\], shortest first.
    pub(super) times: &'a [f64],
    pub(super) dark: Option<CameraFrame>,
    pub(super) flat: Option<&'a (PathBuf, CameraFrame)>,
    pub(super) inputs: &'a HdrInputs,
    /// The frames by time, for the order check's message.
    pub(super) order: &'a dyn Fn() -> String,
}

/// What a merge gives besides the frames' bookkeeping.
pub(super) struct Merged {
    pub(super) hdr: HdrImage,
    pub(super) response: Option<ResponseCurve>,
    pub(super) kind: ResponseKind,
    pub(super) rms: Vec<f64>,
    pub(super) detection_limit: Vec<f64>,
}

pub(super) fn imaging(
    context: &str,
) -> impl FnOnce(scatterfit_imaging::ImagingError) -> PipelineError + use<> {
    let context = context.to_string();
    move |source| PipelineError::Imaging { context, source }
}

/// Leaves out of the merge the frames that carry no signal ([`scatterfit_imaging::bracket_signal`]:
/// fewer than 0.1 % of their values above their noise floor and below the clip), noting them in
/// `corrections.no_signal` (indices by time); all frames are kept when fewer than two would remain,
/// and a bracket in which no frame carries signal is refused ([`scatterfit_imaging::ImagingError::NoSignal`]).
/// Returns the frames and times kept, and their signal when every frame was kept (for the order
/// check; a frame left out changes the others' noise floors, measured from the frames kept).
#[allow(clippy::type_complexity)]
pub(super) fn keep_frames_with_signal<T>(
    bufs: Vec<ImageBuf<T>>,
    times: &[f64],
    max: T,
    corrections: &mut Corrections,
) -> std::result::Result<
    (
        Vec<ImageBuf<T>>,
        Vec<f64>,
        Option<scatterfit_imaging::BracketSignal>,
    ),
    scatterfit_imaging::ImagingError,
>
where
    T: Copy + PartialOrd + Default + Sync + Into<f64>,
{
    let signal = scatterfit_imaging::bracket_signal(&bufs, times, max)?;
    let kept = signal.has_signal.iter().filter(|&&s| s).count();
    if kept == 0 {
        return Err(scatterfit_imaging::ImagingError::NoSignal { frames: bufs.len() });
    }
    if kept == bufs.len() || kept < 2 {
        return Ok((bufs, times.to_vec(), Some(signal)));
    }
    corrections.no_signal = (0..bufs.len()).filter(|&j| !signal.has_signal[j]).collect();
    let t = times
        .iter()
        .zip(&signal.has_signal)
        .filter_map(|(&t, &s)| s.then_some(t))
        .collect();
    let b = bufs
        .into_iter()
        .zip(&signal.has_signal)
        .filter_map(|(b, &s)| s.then_some(b))
        .collect();
    Ok((b, t, None))
}

/// The bracket's order check ([`scatterfit_imaging::check_bracket_order`]), with the frames'
/// signal when it is already measured.
fn check_order<T>(
    bufs: &[ImageBuf<T>],
    times: &[f64],
    max: T,
    signal: Option<&scatterfit_imaging::BracketSignal>,
) -> std::result::Result<(), scatterfit_imaging::ImagingError>
where
    T: Copy + PartialOrd + PartialEq + Default + Sync + Into<f64>,
    [T]: PartialEq,
{
    match signal {
        Some(s) => scatterfit_imaging::check_bracket_order_with_signal(bufs, times, max, s),
        None => scatterfit_imaging::check_bracket_order(bufs, times, max),
    }
}
