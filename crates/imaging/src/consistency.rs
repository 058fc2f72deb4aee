//! How well a merged radiance map and its response explain the frames they came from.
//!
//! A merge is self-consistent when every well-exposed code of every frame is the code the camera
//! would write for the merged radiance at the frame's stated time: z ≈ f(E·Δt) with f = exp g⁻¹,
//! the response's inverse (Debevec & Malik 1997, eq. 1–2). The RMS of z − f(E·Δt) in code values
//! is a score that needs no ground truth, so it compares two merges of a real bracket — ours and
//! OpenCV's `CalibrateDebevec` + `MergeDebevec` — on equal terms (BENCHMARKS.md, "Real brackets").

use rayon::prelude::*;

use crate::error::{Result, check_bracket_map};
use crate::{HdrImage, ImageBuf, LEVELS, ResponseCurve};

/// The codes a frame's value must lie strictly between to count in [`self_consistency`]: well
/// exposed, away from the noise floor and the clip (10 < z < 245).
pub const WELL_EXPOSED: (u8, u8) = (10, 245);

/// The outcome of [`self_consistency`].
#[derive(Debug, Clone, PartialEq)]
pub struct SelfConsistency {
    /// RMS over every frame's well-exposed codes of z − f(E·Δt) \[code values\].
    pub rms: f64,
    /// The same per channel.
    pub per_channel: Vec<f64>,
    /// The same per frame (as given).
    pub per_frame: Vec<f64>,
    /// Per frame, the exposure the map implies over the stated one: exp of the mean of
    /// g(z) − ln(E·Δt) over its well-exposed codes (1 when the map implies the stated time).
    pub implied_time_factor: Vec<f64>,
    /// Codes counted.
    pub count: usize,
}

#[cfg(test)]
/// The code the response predicts for log exposure `u`: the piecewise-linear inverse of g made
/// non-decreasing (`g` already is), z* = m + (u − g(m))/(g(m + 1) − g(m)) where m is the number of
/// codes 1..=255 with g ≤ u, clamped to 0..=255.
fn predicted_code(g: &[f64; LEVELS], u: f64) -> f64 {
    // m = #{z in 1..=255 : g(z) ≤ u}
    code_between(g, g[1..].partition_point(|&v| v <= u), u)
}

/// The code at log exposure `u` given m, the count of codes 1..=255 with g ≤ u: m plus the linear
/// fraction of the way from g(m) to g(m + 1), clamped to 0..=255.
fn code_between(g: &[f64; LEVELS], m: usize, u: f64) -> f64 {
    if m >= LEVELS - 1 {
        return (LEVELS - 1) as f64;
    }
    let (g0, g1) = (g[m], g[m + 1]);
    let frac = if g1 > g0 {
        ((u - g0) / (g1 - g0)).clamp(0.0, 1.0)
    } else {
        0.0
    };
    m as f64 + frac
}

/// The code the response predicts for log exposure `u`, through a table (the piecewise-linear
/// inverse of g, as `predicted_code` in the tests computes it by binary search): for a
/// non-decreasing `g`, the count m of codes with g ≤ u at the start of each of [`CodeLookup::CELLS`] equal cells of u between g(1) and g(255),
/// from which the exact m is found by a few steps forward (the same value as the binary search).
struct CodeLookup<'a> {
    g: &'a [f64; LEVELS],
    u0: f64,
    inv_h: f64,
    start: Vec<usize>,
}

impl<'a> CodeLookup<'a> {
    const CELLS: usize = 2048;

    fn new(g: &'a [f64; LEVELS]) -> Self {
        let (u0, u1) = (g[1], g[LEVELS - 1]);
        let span = u1 - u0;
        let inv_h = if span > 0.0 && span.is_finite() {
            Self::CELLS as f64 / span
        } else {
            0.0
        };
        let start = (0..=Self::CELLS)
            .map(|c| {
                let u = u0 + c as f64 / inv_h.max(f64::MIN_POSITIVE);
                g[1..].partition_point(|&v| v <= u)
            })
            .collect();
        Self {
            g,
            u0,
            inv_h,
            start,
        }
    }

    fn code(&self, u: f64) -> f64 {
        let g = self.g;
        let m = if self.inv_h > 0.0 && u >= self.u0 {
            let c = ((u - self.u0) * self.inv_h) as usize;
            // One cell back: a lower bound on m whatever the rounding of the cell index.
            let mut m = self.start[c.min(Self::CELLS).saturating_sub(1)];
            while m < LEVELS - 1 && g[m + 1] <= u {
                m += 1;
            }
            m
        } else {
            g[1..].partition_point(|&v| v <= u)
        };
        code_between(g, m, u)
    }
}

/// The self-consistency of a merge (module docs): for every frame j and every value z of it with
/// 10 < z < 245 ([`WELL_EXPOSED`]) at a pixel-channel that has a radiance E (finite, > 0), the
/// difference between z and the code the response predicts for E·Δt_j at the frame's *stated*
/// time (the response's piecewise-linear inverse, the response made non-decreasing by a running
/// maximum first). A response with one channel serves every channel.
///
/// # Errors
/// Bracket errors, [`ImagingError::ShapeMismatch`](crate::ImagingError::ShapeMismatch) for a map of another shape,
/// [`ImagingError::ChannelMismatch`](crate::ImagingError::ChannelMismatch).
pub fn self_consistency(
    frames: &[ImageBuf<u8>],
    times_s: &[f64],
    response: &ResponseCurve,
    hdr: &HdrImage,
) -> Result<SelfConsistency> {
    self_consistency_sampled(frames, times_s, response, hdr, usize::MAX)
}

/// [`self_consistency`] over a regular subsample of the frames' pixels: every s-th pixel in raster
/// order, s the smallest step that leaves at most about `max_pixels` pixels (every pixel when the
/// frames have fewer). Over 65 536 pixels the six real brackets of the corpus score within
/// −0.2 … +1.4 % of their full scores (the residuals follow the scene, so the subsample's error is
/// more than the codes' count alone gives), at a sixth of the memorial's cost (BENCHMARKS.md, "Real
/// brackets").
///
/// # Errors
/// As [`self_consistency`].
pub fn self_consistency_sampled(
    frames: &[ImageBuf<u8>],
    times_s: &[f64],
    response: &ResponseCurve,
    hdr: &HdrImage,
    max_pixels: usize,
) -> Result<SelfConsistency> {
    let ch = check_bracket_map(frames, times_s, response, hdr)?;
    let g: Vec<[f64; LEVELS]> = (0..ch)
        .map(|c| {
            let mut t = response.tables()[if response.channels() == 1 { 0 } else { c }];
            for z in 1..LEVELS {
                t[z] = t[z].max(t[z - 1]);
            }
            t
        })
        .collect();
    let lookup: Vec<CodeLookup<'_>> = g.iter().map(CodeLookup::new).collect();
    let p = frames.len();
    let ln_t: Vec<f64> = times_s.iter().map(|t| t.ln()).collect();
    let (lo, hi) = WELL_EXPOSED;
    let rad = hdr.radiance.data();
    let stride = frames[0].width() * ch;
    // Per row: per frame and channel the sum of squares, the count, and the sum of g(z) − ln(EΔt).
    let zero = || (vec![0.0f64; p * ch], vec![0usize; p * ch], vec![0.0f64; p]);
    let n_px = frames[0].width() * frames[0].height();
    let w = frames[0].width();
    // Every s-th pixel in raster order (a lattice that covers the frame).
    let s = n_px.div_ceil(max_pixels.max(1)).max(1);
    let (ss, cnt, off) = rad
        .par_chunks(stride)
        .enumerate()
        .fold(zero, |(mut ss, mut cnt, mut off), (y, row)| {
            let x0 = (s - (y * w) % s) % s;
            for k in (x0..w).step_by(s).flat_map(|x| x * ch..(x + 1) * ch) {
                let e = f64::from(row[k]);
                if !(e.is_finite() && e > 0.0) {
                    continue;
                }
                let c = k % ch;
                let ln_e = e.ln();
                for j in 0..p {
                    let z = frames[j].data()[y * stride + k];
                    if z <= lo || z >= hi {
                        continue;
                    }
                    let u = ln_e + ln_t[j];
                    let d = f64::from(z) - lookup[c].code(u);
                    ss[j * ch + c] += d * d;
                    cnt[j * ch + c] += 1;
                    off[j] += g[c][usize::from(z)] - u;
                }
            }
            (ss, cnt, off)
        })
        .reduce(zero, |mut a, b| {
            a.0.iter_mut().zip(&b.0).for_each(|(x, y)| *x += y);
            a.1.iter_mut().zip(&b.1).for_each(|(x, y)| *x += y);
            a.2.iter_mut().zip(&b.2).for_each(|(x, y)| *x += y);
            a
        });
    let rms_of = |s: f64, n: usize| if n > 0 { (s / n as f64).sqrt() } else { 0.0 };
    let total_ss: f64 = ss.iter().sum();
    let count: usize = cnt.iter().sum();
    let per_channel = (0..ch)
        .map(|c| {
            let s: f64 = (0..p).map(|j| ss[j * ch + c]).sum();
            let n: usize = (0..p).map(|j| cnt[j * ch + c]).sum();
            rms_of(s, n)
        })
        .collect();
    let frame_n: Vec<usize> = (0..p)
        .map(|j| cnt[j * ch..(j + 1) * ch].iter().sum())
        .collect();
    let per_frame = (0..p)
        .map(|j| rms_of(ss[j * ch..(j + 1) * ch].iter().sum(), frame_n[j]))
        .collect();
    let implied_time_factor = (0..p)
        .map(|j| {
            if frame_n[j] > 0 {
                (off[j] / frame_n[j] as f64).exp()
            } else {
                f64::NAN
            }
        })
        .collect();
    Ok(SelfConsistency {
        rms: rms_of(total_ss, count),
        per_channel,
        per_frame,
        implied_time_factor,
        count,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_inverse_is_piecewise_linear_and_clamped() {
        let mut g = [0.0; LEVELS];
        for (z, v) in g.iter_mut().enumerate() {
            *v = z as f64;
        }
        assert_eq!(predicted_code(&g, 10.25), 10.25);
        assert_eq!(predicted_code(&g, -3.0), 0.0);
        assert_eq!(predicted_code(&g, 300.0), 255.0);
        // A flat stretch g(5..=7) = 5: u = 5 passes it.
        g[6..=7].fill(5.0);
        assert_eq!(predicted_code(&g, 5.0), 7.0);
        // Then from g(7) = 5 to g(8) = 8.
        assert!((predicted_code(&g, 7.5) - (7.0 + 2.5 / 3.0)).abs() < 1e-12);
    }

    #[test]
    fn the_lookup_gives_the_binary_searchs_code() {
        // A curve with a steep toe, a flat stretch and a shoulder, sampled densely and at the
        // knots themselves: the table's code equals the search's everywhere.
        let mut g = [0.0; LEVELS];
        for (z, v) in g.iter_mut().enumerate() {
            let x = z as f64 / 255.0;
            *v = (x.max(1e-4)).ln() * 1.7 + 0.3 * x * x * x;
        }
        let flat = g[100];
        g[100..=104].fill(flat);
        let lookup = CodeLookup::new(&g);
        let mut us: Vec<f64> = (0..20_000)
            .map(|k| g[0] - 1.0 + (g[255] - g[0] + 2.0) * k as f64 / 19_999.0)
            .collect();
        us.extend(g.iter().copied());
        us.extend(g.iter().map(|v| v - 1e-13));
        for u in us {
            assert_eq!(lookup.code(u), predicted_code(&g, u), "u = {u}");
        }
    }
}
