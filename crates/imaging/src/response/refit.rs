//! The response refitted to a merged map: the codes the frames hold regressed on the map's log
//! exposure, per channel (one step of the alternation of Robertson, Borman & Stevenson 1999).
//!
//! Debevec & Malik's recovery (`gsolve`) fits g from a hundred sample pixels, least squares in log
//! exposure; a merge then has the whole frame. Given the map E, every pixel-channel of every frame
//! is a pair (u, z) with u = ln(E·Δt): the camera's curve is the code it writes at u, so the curve
//! that predicts the frames' codes best in the least-squares sense is the conditional mean E[z | u]
//! — the regression of code on log exposure (the forward curve), made non-decreasing, whose inverse
//! is the new g. Robertson et al. regress the other way (the mean of the exposures that gave code
//! z); that is the best g in log exposure, but where a code step spans much log exposure (the toe,
//! the shoulder) it drags g towards the mean of a wide, noisy spread and predicts the codes worse
//! (on Debevec's memorial 11.2 code values RMS against the forward curve's 5.4). The forward curve
//! is what [`crate::self_consistency`] scores, so a caller can keep the refit only where it
//! explains the frames better.

use rayon::prelude::*;

use super::curve::{LEVELS, ResponseCurve};
use crate::error::{Result, check_bracket_map};
use crate::{HdrImage, ImageBuf};

/// Bins of log exposure the forward curve is averaged in, between g(1) − 0.5 and g(254) + 0.5 of
/// the response the map was merged with (about 0.01 in ln X a bin for a 20-stop curve: finer than
/// one code step of a mid-grey).
const BINS: usize = 2048;

/// Fewest readings a bin needs to count.
const MIN_BIN_COUNT: u32 = 4;

/// Fewest readings a channel needs to be refitted at all; below it the channel keeps its curve.
const MIN_CHANNEL_READINGS: u64 = 1000;

/// The response refitted to the merged map `hdr` (module docs): per channel, the frames' codes at
/// every s-th pixel in raster order (at most about `max_pixels` pixels) with a radiance (finite
/// and positive, not flagged in the map's mask) are binned by u = ln(E·Δt_j) at the times the map was
/// merged with; the bins' mean codes made non-decreasing by pool-adjacent-violators (isotonic
/// regression weighted by the bins' counts; Barlow et al. 1972); the new g(z) the piecewise-linear
/// inverse of the pooled points, joined to the old curve (shifted to meet it) beyond the first and
/// last pooled code, and put in the gauge g(128) = 0. A channel with too few readings keeps its
/// curve. A one-channel response serves every channel and is refitted on all of them together.
///
/// # Errors
/// Bracket errors, [`ImagingError::ShapeMismatch`](crate::ImagingError::ShapeMismatch) for a map of another shape,
/// [`ImagingError::ChannelMismatch`](crate::ImagingError::ChannelMismatch).
pub fn refit_response_to_map(
    frames: &[ImageBuf<u8>],
    times_s: &[f64],
    response: &ResponseCurve,
    hdr: &HdrImage,
    max_pixels: usize,
) -> Result<ResponseCurve> {
    let ch = check_bracket_map(frames, times_s, response, hdr)?;
    let curves = response.channels();
    let curve_of = |c: usize| if curves == 1 { 0 } else { c };
    // Per curve, the bins' range in log exposure.
    let range: Vec<(f64, f64)> = response
        .tables()
        .iter()
        .map(|g| {
            let (lo, hi) = (g[1] - 0.5, g[LEVELS - 2] + 0.5);
            (lo, BINS as f64 / (hi - lo).max(f64::MIN_POSITIVE))
        })
        .collect();
    let ln_t: Vec<f64> = times_s.iter().map(|t| t.ln()).collect();
    let rad = hdr.radiance.data();
    let mask = hdr.clipped.data();
    let w = frames[0].width();
    let stride = w * ch;
    let n_px = w * frames[0].height();
    let s = n_px.div_ceil(max_pixels.max(1)).max(1);
    // Per curve and bin: readings, Σu, Σz.
    let zero = || {
        (
            vec![0u32; curves * BINS],
            vec![0.0f64; curves * BINS],
            vec![0.0f64; curves * BINS],
        )
    };
    let (count, sum_u, sum_z) = rad
        .par_chunks(stride)
        .enumerate()
        .fold(zero, |(mut n, mut su, mut sz), (y, row)| {
            let x0 = (s - (y * w) % s) % s;
            for k in (x0..w).step_by(s).flat_map(|x| x * ch..(x + 1) * ch) {
                let e = f64::from(row[k]);
                if !(e.is_finite() && e > 0.0) || mask[y * stride + k] != 0 {
                    continue;
                }
                let c = curve_of(k % ch);
                let (lo, inv_h) = range[c];
                let ln_e = e.ln();
                for (frame, lt) in frames.iter().zip(&ln_t) {
                    let u = ln_e + lt;
                    let b = (u - lo) * inv_h;
                    if !(0.0..BINS as f64).contains(&b) {
                        continue;
                    }
                    let i = c * BINS + b as usize;
                    n[i] += 1;
                    su[i] += u;
                    sz[i] += f64::from(frame.data()[y * stride + k]);
                }
            }
            (n, su, sz)
        })
        .reduce(zero, |mut a, b| {
            a.0.iter_mut().zip(&b.0).for_each(|(x, y)| *x += y);
            a.1.iter_mut().zip(&b.1).for_each(|(x, y)| *x += y);
            a.2.iter_mut().zip(&b.2).for_each(|(x, y)| *x += y);
            a
        });
    let tables = (0..curves)
        .map(|c| {
            let bins = c * BINS..(c + 1) * BINS;
            let readings: u64 = count[bins.clone()].iter().map(|&n| u64::from(n)).sum();
            let old = &response.tables()[c];
            if readings < MIN_CHANNEL_READINGS {
                return *old;
            }
            let points: Vec<Pooled> = bins
                .filter(|&i| count[i] >= MIN_BIN_COUNT)
                .map(|i| Pooled {
                    n: f64::from(count[i]),
                    u: sum_u[i],
                    z: sum_z[i],
                })
                .collect();
            inverse_of_forward_curve(&isotonic(points), old)
        })
        .collect();
    ResponseCurve::from_log_exposure(tables)
}

/// A block of readings: their count and the sums of their log exposures and codes.
#[derive(Debug, Clone, Copy)]
struct Pooled {
    n: f64,
    u: f64,
    z: f64,
}

impl Pooled {
    fn mean_z(&self) -> f64 {
        self.z / self.n
    }
    fn mean_u(&self) -> f64 {
        self.u / self.n
    }
}

/// Pool-adjacent-violators (Barlow et al. 1972, "Statistical inference under order
/// restrictions"): the blocks, in order of log exposure, pooled until their mean codes rise
/// strictly. Written out here (a dozen lines on a few thousand bins) rather than taken from a
/// crate: none of the isotonic-regression crates is kept up, and the pooled u is needed too.
fn isotonic(points: Vec<Pooled>) -> Vec<Pooled> {
    let mut out: Vec<Pooled> = Vec::with_capacity(points.len());
    for p in points {
        out.push(p);
        while out.len() > 1 {
            let (a, b) = (out[out.len() - 2], out[out.len() - 1]);
            if a.mean_z() < b.mean_z() {
                break;
            }
            out.pop();
            let last = out.last_mut().expect("two blocks");
            *last = Pooled {
                n: a.n + b.n,
                u: a.u + b.u,
                z: a.z + b.z,
            };
        }
    }
    out
}

/// g(z) from the pooled forward curve: linear between the pooled points (mean code, mean log
/// exposure), the old curve shifted to meet it beyond them, made non-decreasing, gauge g(128) = 0.
fn inverse_of_forward_curve(points: &[Pooled], old: &[f64; LEVELS]) -> [f64; LEVELS] {
    if points.len() < 2 {
        return *old;
    }
    let zs: Vec<f64> = points.iter().map(Pooled::mean_z).collect();
    let us: Vec<f64> = points.iter().map(Pooled::mean_u).collect();
    let (z_first, z_last) = (zs[0], zs[zs.len() - 1]);
    let inside = |z: f64| -> f64 {
        let k = zs.partition_point(|&v| v <= z).clamp(1, zs.len() - 1);
        let (z0, z1, u0, u1) = (zs[k - 1], zs[k], us[k - 1], us[k]);
        u0 + (z - z0) / (z1 - z0) * (u1 - u0)
    };
    let first = (z_first.ceil() as usize).min(LEVELS - 1);
    let last = (z_last.floor() as usize).min(LEVELS - 1);
    if first > last {
        return *old;
    }
    let mut g = [0.0; LEVELS];
    for (z, v) in g.iter_mut().enumerate() {
        *v = if z < first {
            old[z] - old[first] + inside(first as f64)
        } else if z > last {
            old[z] - old[last] + inside(last as f64)
        } else {
            inside(z as f64)
        };
    }
    for z in 1..LEVELS {
        g[z] = g[z].max(g[z - 1]);
    }
    let gauge = g[128];
    if !g.iter().all(|v| v.is_finite()) {
        return *old;
    }
    g.map(|v| v - gauge)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pooling_makes_the_means_rise_and_keeps_the_totals() {
        // Means 1, 3, 2, 2, 5 with counts 1, 1, 1, 2, 1: 3, 2, 2 pool to 9/4 (worked by hand).
        let p = |n: f64, z: f64| Pooled { n, u: n, z: n * z };
        let out = isotonic(vec![
            p(1.0, 1.0),
            p(1.0, 3.0),
            p(1.0, 2.0),
            p(2.0, 2.0),
            p(1.0, 5.0),
        ]);
        let means: Vec<f64> = out.iter().map(Pooled::mean_z).collect();
        assert_eq!(means, vec![1.0, 2.25, 5.0]);
        assert_eq!(out.iter().map(|b| b.n).sum::<f64>(), 6.0);
    }

    /// A camera's curve: code = 255 (X/(1 + X))^(1/2.2) for exposure X (a toe and a shoulder).
    fn true_g(z: f64) -> f64 {
        let y = (z / 255.0).powf(2.2);
        (y / (1.0 - y)).ln()
    }

    fn code(x: f64) -> u8 {
        (255.0 * (x / (1.0 + x)).powf(1.0 / 2.2)).round() as u8
    }

    /// Noise-free frames of a smooth radiance ramp over 14 stops, five times a stop apart, and the
    /// exact radiance as the map: the refit from a wrong curve (the true one bent by 0.3 in ln X at
    /// mid codes) comes back to the true curve within a quarter of a code step at every code
    /// the frames use, and predicts the frames' codes better.
    #[test]
    fn a_bent_curve_comes_back_to_the_camera_s() {
        let (w, h) = (512usize, 64usize);
        let times = [0.25, 0.5, 1.0, 2.0, 4.0];
        let e: Vec<f64> = (0..w * h)
            .map(|i| (-7.0 + 14.0 * (i % w) as f64 / w as f64 + 0.01 * (i / w) as f64).exp2())
            .collect();
        let frames: Vec<ImageBuf<u8>> = times
            .iter()
            .map(|t| ImageBuf::new(w, h, 1, e.iter().map(|x| code(x * t)).collect()).unwrap())
            .collect();
        let hdr = HdrImage {
            radiance: ImageBuf::new(w, h, 1, e.iter().map(|&x| x as f32).collect()).unwrap(),
            clipped: ImageBuf::new(w, h, 1, vec![0u8; w * h]).unwrap(),
            clipped_count: 0,
        };
        // The true curve in the map's own gauge (the map is exact), extended flat-free at the ends.
        let mut truth = [0.0; LEVELS];
        for (z, v) in truth.iter_mut().enumerate() {
            *v = true_g((z as f64).clamp(0.5, 254.5));
        }
        let mut bent = truth;
        for (z, v) in bent.iter_mut().enumerate() {
            *v += 0.3 * (std::f64::consts::PI * z as f64 / 255.0).sin();
        }
        let old = ResponseCurve::from_log_exposure(vec![bent]).unwrap();
        let new = refit_response_to_map(&frames, &times, &old, &hdr, usize::MAX).unwrap();
        let g = new.tables()[0];
        // Compare shapes: the refit is in the gauge g(128) = 0, the truth in the map's.
        let shift = truth[128];
        let used = |f: fn(u8, u8) -> u8| {
            frames
                .iter()
                .flat_map(|b| b.data())
                .copied()
                .reduce(f)
                .unwrap()
        };
        let (lo, hi) = (usize::from(used(u8::min)), usize::from(used(u8::max)));
        assert!(lo < 20 && hi > 240, "the frames use codes {lo}..={hi}");
        for z in lo + 1..hi {
            let step = 0.5 * (truth[z + 1] - truth[z - 1]);
            let err = g[z] - (truth[z] - shift);
            assert!(
                err.abs() < 0.25 * step,
                "code {z}: refit {:.4} against {:.4} (a code step {step:.4})",
                g[z],
                truth[z] - shift
            );
        }
        let before = crate::self_consistency(&frames, &times, &old, &hdr)
            .unwrap()
            .rms;
        let shifted = HdrImage {
            radiance: ImageBuf::new(
                w,
                h,
                1,
                e.iter().map(|&x| (x * (-shift).exp()) as f32).collect(),
            )
            .unwrap(),
            ..hdr.clone()
        };
        let after = crate::self_consistency(&frames, &times, &new, &shifted)
            .unwrap()
            .rms;
        assert!(
            after < 0.5 * before,
            "self-consistency {after:.3} against {before:.3}"
        );
    }
}
