//! Is the bracket's order right? A camera's output rises with exposure, so in a bracket sorted by
//! time each frame must be brighter than the one before — pixel by pixel, wherever neither frame
//! is clipped. A bracket whose times were reversed, shuffled or given to the wrong files, or in
//! which one frame was listed twice, fails this test directly, before any response is recovered
//! (issue 16: a recovered response that dips is no evidence of a wrong order — noise at low codes
//! does it too — so the response recovery no longer judges the order; this does).

use crate::ImageBuf;
use crate::error::{ImagingError, Result, check_bracket};

/// Checks that the frames of a bracket brighten with their exposure times: for each pair of frames
/// adjacent in time, over the pixel values that are not clipped at the same end in both (`0` and
/// `max` are the clip codes), the summed change Σ(y − x) from the shorter frame x to the longer y
/// in units of its noise, z = Σ(y − x)/√Σ(y − x)² (noise moves a value either way, so over values
/// without signal z stays within a few units of 0, whatever the noise; values with signal add to
/// it). Refused when z < −3 (the longer frame is clearly darker: times reversed or shuffled), when
/// the two frames are identical value for value (one frame listed twice). A frame shot twice and
/// listed under two times differs from its twin by noise only and is not refused here (a pair of
/// short frames of a dark sample looks the same); the HDR stage's exposure estimate finds it
/// (`ImagingError::ExposureMismatch`). The message gives how many values got darker and brighter.
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
    for pair in order.windows(2) {
        let (s, l) = (pair[0], pair[1]);
        let (a, b) = (frames[s].data(), frames[l].data());
        let (mut darker, mut brighter, mut compared, mut unclipped) = (0, 0, 0, 0);
        let (mut sum, mut sum2) = (0.0f64, 0.0f64);
        let mut k = 0;
        while k < n {
            let (x, y) = (a[k], b[k]);
            let low = x == zero && y == zero;
            let high = x == max && y == max;
            if !low && !high {
                unclipped += 1;
                let d = y.into() - x.into();
                sum += d;
                sum2 += d * d;
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
        // z: the summed change in units of its noise (noise moves each value either way).
        let z = if sum2 > 0.0 { sum / sum2.sqrt() } else { 0.0 };
        let what = if z < -3.0 {
            Some("the longer exposure is darker")
        } else if a == b && unclipped > 0 {
            Some("the two frames are identical (one frame listed twice?)")
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
