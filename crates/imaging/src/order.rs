//! Is the bracket's order right? A camera's output rises with exposure, so in a bracket sorted by
//! time each frame must be brighter than the one before — pixel by pixel, wherever neither frame
//! is clipped. A bracket whose times were reversed, shuffled or given to the wrong files, or in
//! which one frame was listed twice, fails this test directly, before any response is recovered
//! (issue 16: a recovered response that dips is no evidence of a wrong order — noise at low codes
//! does it too — so the response recovery no longer judges the order; this does).

use crate::ImageBuf;
use crate::error::{ImagingError, Result, check_bracket};

/// Pairs of frames whose times differ by at least this factor must brighten more pixel values than
/// they darken by a clear margin (a repeated frame under another time brightens none); pairs closer
/// in time are only refused when they clearly darken.
pub const MIN_RATIO_FOR_BRIGHTENING: f64 = 1.25;

/// Checks that the frames of a bracket brighten with their exposure times: for each pair of frames
/// adjacent in time, over the pixel values that are not clipped at the same end in both (`0` and
/// `max` are the clip codes), that carry signal in one of them (at least 1/32 of the way from the
/// bracket's floor, its 1st percentile, to `max`: values near the floor are noise that moves
/// either way) and that differ, the count that got darker (d) and brighter (b) with
/// the longer time. Refused when d − b > 3√(b + d) (the longer frame is clearly darker: times
/// reversed or shuffled), when the two frames are identical value for value and some value carries
/// signal (one frame listed twice), or, for times ≥ [`MIN_RATIO_FOR_BRIGHTENING`] apart,
/// when b − d < 3√(b + d) (a longer exposure that is not clearly brighter). Noise alone moves
/// b − d by about √(b + d), so a good bracket passes with a wide margin (on the twin's brackets,
/// b/d > 50 for every pair).
///
/// `max` is the clip value (255 for 8-bit, the saturation for linear data). At most about 200 000
/// values per pair are compared (a regular subsample).
///
/// # Errors
/// Bracket errors, [`ImagingError::BracketOutOfOrder`].
pub fn check_bracket_order<T>(frames: &[ImageBuf<T>], times_s: &[f64], max: T) -> Result<()>
where
    T: Copy + PartialOrd + PartialEq + Default + Sync + Into<f64>,
    [T]: PartialEq,
{
    check_bracket(frames, times_s)?;
    let mut order: Vec<usize> = (0..frames.len()).collect();
    order.sort_by(|&a, &b| times_s[a].total_cmp(&times_s[b]));
    let n = frames[0].data().len();
    let step = (n / 200_000).max(1);
    let zero = T::default();
    // Values near the sensor's floor are noise that moves either way (a dark sample's short
    // frames are mostly read noise about code 0 or the black level): only values that reach a
    // 32nd of the way from the bracket's floor (its 1st percentile) to the clip count.
    let mut sample: Vec<f64> = frames
        .iter()
        .flat_map(|f| f.data().iter().step_by(step * 7 + 1).map(|&v| v.into()))
        .collect();
    sample.sort_by(f64::total_cmp);
    let floor = sample.get(sample.len() / 100).copied().unwrap_or(0.0);
    let top: f64 = max.into();
    let signal = floor + (top - floor) / 32.0;
    for pair in order.windows(2) {
        let (s, l) = (pair[0], pair[1]);
        let (a, b) = (frames[s].data(), frames[l].data());
        let (mut darker, mut brighter, mut compared, mut unclipped) = (0, 0, 0, 0);
        let mut k = 0;
        while k < n {
            let (x, y) = (a[k], b[k]);
            let low = x == zero && y == zero;
            let high = x == max && y == max;
            let weak = x.into() < signal && y.into() < signal;
            if !low && !high && !weak {
                unclipped += 1;
                if y < x {
                    darker += 1;
                    compared += 1;
                } else if y > x {
                    brighter += 1;
                    compared += 1;
                }
            }
            k += step;
        }
        let margin = 3.0 * ((darker + brighter) as f64).sqrt();
        let ratio = times_s[l] / times_s[s];
        let what = if darker as f64 - brighter as f64 > margin {
            Some("the longer exposure is darker")
        } else if a == b && unclipped > 0 {
            Some("the two frames are identical (one frame listed twice?)")
        } else if ratio >= MIN_RATIO_FOR_BRIGHTENING
            && compared >= 100
            && (brighter as f64 - darker as f64) < margin
        {
            Some("the longer exposure is no brighter")
        } else {
            None
        };
        if let Some(what) = what {
            return Err(ImagingError::BracketOutOfOrder {
                what,
                shorter: s,
                longer: l,
                t_shorter: times_s[s],
                t_longer: times_s[l],
                compared,
                darker,
                brighter,
            });
        }
    }
    Ok(())
}
