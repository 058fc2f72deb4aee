//! Recovering a response from an exposure bracket: sample pixels, Debevec & Malik's system per
//! channel, the filters in log exposure, the forward toe, and the check that g rises.

use super::comb::{
    AMBIGUITY_KNOT_STEP, comb_in_log_exposure, smooth_in_log_exposure, spans_periods,
};
use super::curve::{LEVELS, ResponseCurve};
use super::gsolve::{ChannelSolution, gsolve};
use super::samples::{MAX_RESPONSE_SAMPLES, SamplePixel, min_response_samples, select_samples};
use super::toe::forward_toe_both;
use crate::ImageBuf;
use crate::error::{ImagingError, Result, check_bracket};

/// Largest fall of a recovered response, as a fraction of its rise over the codes the samples use,
/// that is taken for noise rather than a curve running the wrong way (see
/// [`ImagingError::ResponseNotIncreasing`]).
pub const MAX_RESPONSE_FALL: f64 = 0.05;

/// Options of [`recover_response`]; built through [`CalibrateOptions::new`], so always valid.
#[derive(Debug, Clone, PartialEq)]
pub struct CalibrateOptions {
    samples: usize,
    lambda: f64,
    order_checked: bool,
    pixels: Option<Vec<Vec<SamplePixel>>>,
}

impl CalibrateOptions {
    /// Options with N sample pixels per channel (OpenCV's default is 70; Debevec & Malik ask for
    /// N(P − 1) > 255 with P frames; default 100) and the smoothness weight λ of the
    /// second-difference rows (Debevec & Malik 1997, eq. 3; default 10, OpenCV's).
    ///
    /// # Errors
    /// [`ImagingError::InvalidOption`] for N outside 1..=[`MAX_RESPONSE_SAMPLES`] (the lower bound
    /// for a bracket, [`min_response_samples`]`(P)`, is checked by [`recover_response`], which
    /// knows P) or λ not finite and ≥ 0.
    pub fn new(samples: usize, lambda: f64) -> Result<Self> {
        if !(1..=MAX_RESPONSE_SAMPLES).contains(&samples) {
            return Err(ImagingError::InvalidOption {
                name: "samples",
                value: samples as f64,
                reason: "must lie in 1..=1000 (MAX_RESPONSE_SAMPLES) sample pixels per channel",
            });
        }
        if !(lambda.is_finite() && lambda >= 0.0) {
            return Err(ImagingError::InvalidOption {
                name: "lambda",
                value: lambda,
                reason: "must be finite and ≥ 0",
            });
        }
        Ok(Self {
            samples,
            lambda,
            order_checked: false,
            pixels: None,
        })
    }

    /// The same options for a caller that has already checked the bracket's order
    /// ([`crate::check_bracket_order`]) on the same frames and times: [`recover_response`] then
    /// does not check it again (a caller that recovers the response in rounds, with corrected
    /// times, checks once).
    #[must_use]
    pub fn order_checked(mut self) -> Self {
        self.order_checked = true;
        self
    }

    /// The same options with the sample pixels given per channel ([`Calibration::samples`] of an
    /// earlier recovery on the same frames): [`select_samples`] chooses them from the frames' codes
    /// alone, not from the times, so a caller that recovers the response in rounds with corrected
    /// times chooses them once. [`recover_response`] refuses pixels outside the frames or a
    /// channel with fewer than the bracket's minimum.
    #[must_use]
    pub fn with_sample_pixels(mut self, pixels: Vec<Vec<SamplePixel>>) -> Self {
        self.pixels = Some(pixels);
        self
    }

    /// Sample pixels per channel.
    pub fn samples(&self) -> usize {
        self.samples
    }

    /// Smoothness weight λ.
    pub fn lambda(&self) -> f64 {
        self.lambda
    }
}

impl Default for CalibrateOptions {
    fn default() -> Self {
        Self {
            samples: 100,
            lambda: 10.0,
            order_checked: false,
            pixels: None,
        }
    }
}

/// The outcome of [`recover_response`].
#[derive(Debug, Clone, PartialEq)]
pub struct Calibration {
    /// The recovered response, gauge g(128) = 0 per channel: X(z) unbiased for the mean of the
    /// readings at one exposure (what the merge averages).
    pub response: ResponseCurve,
    /// The same response with the toe to first order only ([`forward_toe`](crate::response::forward_toe)): unbiased for the
    /// *median* of the readings at one exposure, for statistics of medians (the pipeline's
    /// exposure estimate takes the median of pixel ratios). Equal to `response` above the toe.
    pub median_response: ResponseCurve,
    /// The sample pixels used, per channel.
    pub samples: Vec<Vec<SamplePixel>>,
    /// Each channel's solution (g, ln E of the samples, residual).
    pub solutions: Vec<ChannelSolution>,
}

/// Recovers the camera response of each channel from an 8-bit bracket (Debevec & Malik 1997): picks
/// [`CalibrateOptions::samples`] pixels per channel with [`select_samples`] and solves [`gsolve`].
///
/// Each solution is then refitted by a cubic spline with knots [`AMBIGUITY_KNOT_STEP`]·ln k apart
/// in log exposure (`smooth_in_log_exposure`): with exposure times in a constant ratio k a ripple
/// of g periodic in ln X with period ln k is invisible to the data (Grossberg & Nayar 2003's
/// "fractal ambiguity"), held only by the smoothness rows, and it would reach the merged radiance
/// as a ripple of the same period; the spline cannot carry it. The solution's ln E_i and residual
/// are those of the refitted g.
///
/// The recovered curve is checked: over the codes the samples use (1st to 99th percentile, codes 0
/// and 255 left out) it must rise, and fall nowhere by more than [`MAX_RESPONSE_FALL`] of that rise
/// (noise can make an estimate dip by a hair; exposure times in the wrong order make it run
/// downward).
///
/// # Errors
/// Bracket errors (fewer than 2 frames, times not one per frame, non-positive or duplicate times,
/// frames of different shapes), [`ImagingError::SampleCount`] for a sample count outside
/// [`min_response_samples`]`(P)..=`[`MAX_RESPONSE_SAMPLES`], [`ImagingError::InvalidOption`],
/// [`ImagingError::NotEnoughSamples`] when the bracket has fewer usable pixels than that minimum,
/// [`ImagingError::SolveFailed`], [`ImagingError::ResponseNotIncreasing`].
pub fn recover_response(
    frames: &[ImageBuf<u8>],
    times_s: &[f64],
    opts: &CalibrateOptions,
) -> Result<Calibration> {
    check_bracket(frames, times_s)?;
    if !opts.order_checked {
        crate::order::check_bracket_order(frames, times_s, u8::MAX)?;
    }
    let p = frames.len();
    let min = min_response_samples(p);
    if !(min..=MAX_RESPONSE_SAMPLES).contains(&opts.samples) {
        return Err(ImagingError::SampleCount {
            samples: opts.samples,
            frames: p,
            min,
            max: MAX_RESPONSE_SAMPLES,
        });
    }
    let ln_dt: Vec<f64> = times_s.iter().map(|t| t.ln()).collect();
    // The channels are independent: solved in parallel, the first channel's error reported.
    let per_channel: Vec<Result<RecoveredChannel>> = {
        use rayon::prelude::*;
        (0..frames[0].channels())
            .into_par_iter()
            .map(|c| recover_channel(frames, times_s, &ln_dt, c, opts, min))
            .collect()
    };
    let mut samples = Vec::new();
    let mut solutions = Vec::new();
    let mut medians = Vec::new();
    for r in per_channel {
        let (picked, solution, median_g) = r?;
        samples.push(picked);
        solutions.push(solution);
        medians.push(median_g);
    }
    let response = ResponseCurve {
        g: solutions.iter().map(|s| s.g).collect(),
    };
    Ok(Calibration {
        response,
        median_response: ResponseCurve { g: medians },
        samples,
        solutions,
    })
}

/// One channel of [`recover_response`]: its samples, its solution (spline, comb and toe applied)
/// and its curve with the toe to first order.
type RecoveredChannel = (Vec<SamplePixel>, ChannelSolution, [f64; LEVELS]);

/// One channel of [`recover_response`] (see [`RecoveredChannel`]).
fn recover_channel(
    frames: &[ImageBuf<u8>],
    times_s: &[f64],
    ln_dt: &[f64],
    c: usize,
    opts: &CalibrateOptions,
    min: usize,
) -> Result<RecoveredChannel> {
    let p = frames.len();
    let picked = match opts.pixels.as_ref() {
        Some(given) => {
            let (w, h) = (frames[0].width(), frames[0].height());
            let picked = given.get(c).cloned().unwrap_or_default();
            if let Some(bad) = picked.iter().find(|s| s.x >= w || s.y >= h) {
                return Err(ImagingError::InvalidOption {
                    name: "sample pixel",
                    value: (bad.y * w + bad.x) as f64,
                    reason: "the sample pixels given lie outside the frames (chosen on another bracket?)",
                });
            }
            picked
        }
        None => select_samples(frames, times_s, c, opts.samples)?,
    };
    if picked.len() < min {
        return Err(ImagingError::NotEnoughSamples {
            channel: c,
            found: picked.len(),
            needed: min,
        });
    }
    let mut z = Vec::with_capacity(picked.len() * p);
    for s in &picked {
        for f in frames {
            z.push(f.data()[(s.y * f.width() + s.x) * f.channels() + c]);
        }
    }
    let mut solution = gsolve(&z, ln_dt, opts.lambda, c)?;
    // The component the data cannot see (a ripple of period ln k in ln X) taken out: by a
    // spline too coarse to follow it where the curve spans more than three periods, then by
    // the comb. A curve of three periods or fewer (a linear 8-bit camera at steps ≥ 3×) keeps
    // least squares' curve for the comb: a spline with knots 1.2 ln k apart has only two or
    // three intervals there and bends the curve itself (a linear camera at 4× steps: ±4 %).
    if spans_periods(&solution.g, ln_dt).is_some_and(|n| n > 3.0)
        && let Some(g) = smooth_in_log_exposure(&solution.g, ln_dt, AMBIGUITY_KNOT_STEP)
    {
        solution = ChannelSolution::with_g(g, &z, ln_dt);
    }
    // Whatever of that ripple the spline still follows, filtered out exactly.
    if let Some(g) = comb_in_log_exposure(&solution.g, ln_dt) {
        solution = ChannelSolution::with_g(g, &z, ln_dt);
    }
    // The toe: the inverse of the mean code at known exposure, not the mean exposure at a
    // given code (which noise pulls towards the dark pixels' exposures); to second order for
    // the merge, to first order for medians.
    let mut median_g = solution.g;
    if let Some((first, second)) = forward_toe_both(frames, times_s, c, &solution.g) {
        solution = ChannelSolution::with_g(second, &z, ln_dt);
        median_g = first;
    }
    check_increasing(&solution.g, &z, c)?;
    Ok((picked, solution, median_g))
}

/// Refuses a recovered curve that does not rise over the codes the samples use (1st to 99th
/// percentile of their codes, 0 and 255 left out), or falls anywhere there by more than
/// [`MAX_RESPONSE_FALL`] of its rise.
fn check_increasing(g: &[f64; LEVELS], z: &[u8], channel: usize) -> Result<()> {
    let mut hist = [0usize; LEVELS];
    for &v in z {
        if v != 0 && v != u8::MAX {
            hist[usize::from(v)] += 1;
        }
    }
    let n: usize = hist.iter().sum();
    let quantile = |q: f64| {
        let target = ((q * n as f64).ceil() as usize).max(1);
        let mut acc = 0;
        for (code, count) in hist.iter().enumerate() {
            acc += count;
            if acc >= target {
                return code;
            }
        }
        LEVELS - 1
    };
    let (lo, hi) = (quantile(0.01), quantile(0.99));
    if n == 0 || hi <= lo {
        return Ok(());
    }
    let span = g[hi] - g[lo];
    let (mut peak, mut drop, mut z_from, mut z_to) = (lo, 0.0f64, lo, lo);
    for code in lo..=hi {
        if g[code] > g[peak] {
            peak = code;
        }
        if g[peak] - g[code] > drop {
            (drop, z_from, z_to) = (g[peak] - g[code], peak, code);
        }
    }
    if span <= 0.0 || drop > MAX_RESPONSE_FALL * span {
        return Err(ImagingError::ResponseNotIncreasing {
            channel,
            z_from,
            z_to,
            drop,
            span,
        });
    }
    Ok(())
}
