//! What a real camera adds to the rig's ideal one, estimated from the frames and
//! removed: the black level of linear data, exposure times that are not what the camera says, and
//! vignetting (a flat frame). Veiling glare is estimated on the profile ([`crate::profile`]); the
//! spot's shape is the fit's kernel ([`crate::fit`]).

use scatterfit_imaging::ImageBuf;
use serde::Serialize;

/// Pixels in the frame's far corners: farther from the frame's centre than this fraction of the
/// half-diagonal (about 5 % of a square frame's pixels). With the spot near the centre they see the
/// least of its light.
pub const CORNER_FRACTION: f64 = 0.85;

/// The indices (y·w + x) of the far-corner pixels of a w × h frame, every `step`-th in each
/// direction.
pub fn corner_pixels(w: usize, h: usize, step: usize) -> Vec<usize> {
    let (cx, cy) = (0.5 * (w as f64 - 1.0), 0.5 * (h as f64 - 1.0));
    let r2 = (CORNER_FRACTION * CORNER_FRACTION) * (cx * cx + cy * cy);
    let step = step.max(1);
    let mut v = Vec::new();
    for y in (0..h).step_by(step) {
        for x in (0..w).step_by(step) {
            let (dx, dy) = (x as f64 - cx, y as f64 - cy);
            if dx * dx + dy * dy >= r2 {
                v.push(y * w + x);
            }
        }
    }
    v
}

/// A black level estimated from the far corners of a linear bracket.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BlackLevelEstimate {
    /// Per channel \[DN\]: the intercept at Δt = 0 of the corners' mean value against exposure time
    /// (the part that does not grow with time: the sensor's pedestal).
    pub level: Vec<f64>,
    /// Per channel, the slope [DN/s]: what grows with time in the corners (veiling glare, dark
    /// current, the profile's own tail); removed later as the profile's background.
    pub rate: Vec<f64>,
    /// Per channel, the standard error of `level` \[DN\]: the corner means' own scatter (the
    /// pixels' sample variance over their count, per frame) carried through the straight-line
    /// fit's intercept (a linear combination Σ cⱼ mⱼ of the frame means; NaN with fewer than two
    /// usable frames).
    pub level_stderr: Vec<f64>,
    /// Fraction of the shortest frame's corner samples at 0: a camera that clips its data at 0 has
    /// no pedestal (level then 0).
    pub zero_fraction: f64,
    /// Per channel, the frame whose corner mean lies farthest from the straight line, in its own
    /// standard errors ([`CornerDeparture`]); `None` with fewer than three usable frames.
    pub departure: Vec<Option<CornerDeparture>>,
}

/// The frame whose far-corner mean departs most from the straight line m = level + rate·Δt that
/// the corner means of a static scene follow (a constant pedestal, plus the light that reaches the
/// corners — the profile's tail, veiling glare, dark current, a lamp that stays on — in proportion
/// to the exposure time). Light that changed during the bracket (room light switched on or off)
/// reaches some frames and not others and bends the line; the straight-line fit then also moves
/// the intercept, the black level read from the corners.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CornerDeparture {
    /// The frame, by its index in the bracket as given.
    pub frame: usize,
    /// Its exposure time \[s\].
    pub time_s: f64,
    /// Its corner mean less the line's value there \[DN\].
    pub residual_dn: f64,
    /// The residual in the corner mean's standard errors.
    pub z: f64,
    /// The residual over the line's time-proportional part at that frame, |rate·Δt| (at least
    /// 1 DN): what a shutter's error of that fraction would leave.
    pub relative: f64,
}

/// Estimates the black level of a linear bracket from the far corners ([`corner_pixels`]): per
/// channel and frame the mean corner value m_j (frames where a corner sample saturates are left
/// out), fitted as m_j = level + rate·Δt_j by least squares. A camera whose data have no pedestal
/// clips read noise at 0: when more than 1 % of the shortest frame's corner samples are 0, the
/// level is 0.
pub fn estimate_black_level(
    frames: &[&ImageBuf<u16>],
    times_s: &[f64],
    saturation: u16,
) -> BlackLevelEstimate {
    let (w, h, ch) = (frames[0].width(), frames[0].height(), frames[0].channels());
    let corners = corner_pixels(w, h, 1);
    let shortest = (0..frames.len())
        .min_by(|&a, &b| times_s[a].total_cmp(&times_s[b]))
        .unwrap_or(0);
    let zeros = corners
        .iter()
        .flat_map(|&p| (0..ch).map(move |c| p * ch + c))
        .filter(|&i| frames[shortest].data()[i] == 0)
        .count();
    let zero_fraction = zeros as f64 / (corners.len() * ch).max(1) as f64;
    let mut level = vec![0.0; ch];
    let mut rate = vec![0.0; ch];
    let mut level_stderr = vec![f64::NAN; ch];
    let mut departure = vec![None; ch];
    let count = corners.len().max(1) as f64;
    for c in 0..ch {
        // (time, corner mean, the mean's variance, frame) per frame.
        let pts: Vec<(f64, f64, f64, usize)> = frames
            .iter()
            .zip(times_s)
            .enumerate()
            .filter_map(|(j, (f, &t))| {
                let (mut sum, mut sum2) = (0.0, 0.0);
                for &p in &corners {
                    let v = f.data()[p * ch + c];
                    if v >= saturation {
                        return None;
                    }
                    let v = f64::from(v);
                    sum += v;
                    sum2 += v * v;
                }
                let mean = sum / count;
                let var = (sum2 / count - mean * mean).max(0.0) / (count - 1.0).max(1.0);
                Some((t, mean, var, j))
            })
            .collect();
        if pts.len() < 2 {
            continue;
        }
        let n = pts.len() as f64;
        let mt = pts.iter().map(|p| p.0).sum::<f64>() / n;
        let mm = pts.iter().map(|p| p.1).sum::<f64>() / n;
        let stt: f64 = pts.iter().map(|p| (p.0 - mt).powi(2)).sum();
        let stm: f64 = pts.iter().map(|p| (p.0 - mt) * (p.1 - mm)).sum();
        let slope = if stt > 0.0 { stm / stt } else { 0.0 };
        // The intercept mm − slope·mt = Σ cⱼ mⱼ with cⱼ = 1/n − mt (tⱼ − mt)/stt.
        level_stderr[c] = pts
            .iter()
            .map(|p| {
                let cj = 1.0 / n
                    - if stt > 0.0 {
                        mt * (p.0 - mt) / stt
                    } else {
                        0.0
                    };
                cj * cj * p.2
            })
            .sum::<f64>()
            .sqrt();
        rate[c] = slope;
        let intercept = mm - slope * mt;
        departure[c] = (pts.len() >= 3)
            .then(|| {
                pts.iter()
                    .map(|&(t, m, var, frame)| {
                        let residual_dn = m - (intercept + slope * t);
                        CornerDeparture {
                            frame,
                            time_s: t,
                            residual_dn,
                            z: residual_dn / var.sqrt().max(1e-9),
                            relative: residual_dn / (slope * t).abs().max(1.0),
                        }
                    })
                    .max_by(|a, b| a.z.abs().total_cmp(&b.z.abs()))
            })
            .flatten();
        level[c] = if zero_fraction > 0.01 {
            0.0
        } else {
            (mm - slope * mt).max(0.0)
        };
    }
    BlackLevelEstimate {
        level,
        rate,
        level_stderr,
        zero_fraction,
        departure,
    }
}

/// Exposure times estimated from the frames.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ExposureEstimate {
    /// Per frame (shortest first), the estimated true time over the nominal one (geometric mean 1).
    pub factor: Vec<f64>,
    /// Per adjacent pair, the number of well-exposed pixel values the ratio came from.
    pub pairs: Vec<usize>,
    /// The largest |factor − 1|.
    pub max_correction: f64,
    /// Per frame, the standard error of ln factor: from the spread of the ratios of the pairs it
    /// belongs to (the median's, 1.2533·1.4826·MAD/√n, Kendall & Stuart), the larger of its two
    /// pairs; 0 where a pair had too few values to be estimated (the nominal step kept).
    #[serde(skip)]
    pub stderr_ln: Vec<f64>,
}

/// Relative exposures from the frames themselves: for each pair of frames adjacent in time, the
/// median over the pixel values well exposed in both of ln(X_{j+1}/X_j), with X the linear value
/// (`linear(j, i)`: `None` where the value is not well exposed); chained into estimated times,
/// normalised to the nominal times' geometric mean. With `remove_trend` the part of the log
/// correction linear in ln Δt is removed too: with a response recovered from the same bracket a
/// power of the times, Δt^γ, cannot be told from the response's own shape (Debevec & Malik's g is
/// only known up to such a change of scale), so only the scatter about the nominal progression is
/// estimated. `n` values per frame; at most about 200 000 are compared per pair.
pub fn estimate_exposures(
    times_s: &[f64],
    n: usize,
    linear: &(dyn Fn(usize, usize) -> Option<f64> + Sync),
    remove_trend: bool,
) -> ExposureEstimate {
    let p = times_s.len();
    let step = (n / 200_000).max(1);
    // Per adjacent pair (in parallel): the median log ratio, the values it came from, and its
    // standard error. The median and the median absolute deviation by selection (the middle
    // element, as a full sort would give it).
    let per_pair: Vec<(f64, usize, f64)> = {
        use rayon::prelude::*;
        (0..p.saturating_sub(1))
            .into_par_iter()
            .map(|j| {
                let mut r: Vec<f64> = (0..n)
                    .step_by(step)
                    .filter_map(|i| {
                        let (a, b) = (linear(j, i)?, linear(j + 1, i)?);
                        (a > 0.0 && b > 0.0).then(|| (b / a).ln())
                    })
                    .collect();
                let nominal = (times_s[j + 1] / times_s[j]).ln();
                if r.len() >= 100 {
                    let mid = r.len() / 2;
                    let median = *r.select_nth_unstable_by(mid, f64::total_cmp).1;
                    let mut dev: Vec<f64> = r.iter().map(|v| (v - median).abs()).collect();
                    let mad = *dev.select_nth_unstable_by(mid, f64::total_cmp).1;
                    (
                        median,
                        r.len(),
                        1.2533 * 1.4826 * mad / (r.len() as f64).sqrt(),
                    )
                } else {
                    (nominal, r.len(), 0.0)
                }
            })
            .collect()
    };
    let mut ln_t = vec![0.0; p];
    let mut pairs = Vec::with_capacity(p.saturating_sub(1));
    let mut pair_se = Vec::with_capacity(p.saturating_sub(1));
    for (j, &(step_ln, count, se)) in per_pair.iter().enumerate() {
        pairs.push(count);
        pair_se.push(se);
        ln_t[j + 1] = ln_t[j] + step_ln;
    }
    let ln_nom: Vec<f64> = times_s.iter().map(|t| t.ln()).collect();
    let mut d: Vec<f64> = (0..p).map(|j| ln_t[j] - ln_nom[j]).collect();
    let mean = d.iter().sum::<f64>() / p as f64;
    d.iter_mut().for_each(|v| *v -= mean);
    if remove_trend && p > 2 {
        let mx = ln_nom.iter().sum::<f64>() / p as f64;
        let sxx: f64 = ln_nom.iter().map(|x| (x - mx).powi(2)).sum();
        let sxy: f64 = ln_nom.iter().zip(&d).map(|(x, y)| (x - mx) * y).sum();
        let slope = if sxx > 0.0 { sxy / sxx } else { 0.0 };
        for (v, x) in d.iter_mut().zip(&ln_nom) {
            *v -= slope * (x - mx);
        }
    }
    let factor: Vec<f64> = d.iter().map(|v| v.exp()).collect();
    let max_correction = factor.iter().map(|f| (f - 1.0).abs()).fold(0.0, f64::max);
    let stderr_ln = (0..p)
        .map(|j| {
            let before = if j > 0 { pair_se[j - 1] } else { 0.0 };
            let after = pair_se.get(j).copied().unwrap_or(0.0);
            f64::max(before, after)
        })
        .collect();
    ExposureEstimate {
        factor,
        pairs,
        max_correction,
        stderr_ln,
    }
}

/// A flat frame made into a divisor: its linear values smoothed (two passes of a 9 × 9 box, which
/// leaves vignetting's smooth fall-off and removes the pixel noise) and divided by their median, so
/// dividing a radiance map by it removes the fall-off and keeps the map's scale.
pub fn flat_divisor(linear: &ImageBuf<f32>) -> Option<ImageBuf<f32>> {
    let (w, h, ch) = (linear.width(), linear.height(), linear.channels());
    let mut data: Vec<f32> = linear.data().to_vec();
    for _ in 0..2 {
        data = box_blur(&data, w, h, ch, 4);
    }
    let mut sorted: Vec<f32> = data.iter().copied().filter(|v| v.is_finite()).collect();
    if sorted.is_empty() {
        return None;
    }
    sorted.sort_by(f32::total_cmp);
    let median = sorted[sorted.len() / 2];
    if median.is_nan() || median <= 0.0 {
        return None;
    }
    data.iter_mut().for_each(|v| *v /= median);
    ImageBuf::new(w, h, ch, data).ok()
}

/// A separable box blur of radius `r` (edges: the mean of the pixels inside the image).
fn box_blur(data: &[f32], w: usize, h: usize, ch: usize, r: usize) -> Vec<f32> {
    let pass = |src: &[f32], horizontal: bool| -> Vec<f32> {
        let mut out = vec![0.0f32; src.len()];
        let (n_lines, len) = if horizontal { (h, w) } else { (w, h) };
        for line in 0..n_lines {
            for c in 0..ch {
                let idx = |i: usize| {
                    if horizontal {
                        (line * w + i) * ch + c
                    } else {
                        (i * w + line) * ch + c
                    }
                };
                let mut prefix = vec![0.0f64; len + 1];
                for i in 0..len {
                    prefix[i + 1] = prefix[i] + f64::from(src[idx(i)]);
                }
                for i in 0..len {
                    let (a, b) = (i.saturating_sub(r), (i + r + 1).min(len));
                    out[idx(i)] = ((prefix[b] - prefix[a]) / (b - a) as f64) as f32;
                }
            }
        }
        out
    };
    let tmp = pass(data, true);
    pass(&tmp, false)
}

/// The veiling glare (stray light) of a channel: a constant background under the profile,
/// estimated on the rings beyond the profile's near field — the record `result.json` keeps
/// (`inputs.options.camera.background`).
pub use scatterfit_io::result_json::BackgroundLevel as Background;

/// Fits y(r) = b + A e^{−s r}/r^p to rings (r \[mm\], value, standard error) — a diffusion profile's
/// far field over a constant background — by least squares in (b, A) for each s on a log grid in
/// [0.005, 20] mm⁻¹ and p ∈ {1, 1.5, 2, 3}, keeping the best. Returns (b, σ_b), σ_b scaled by
/// √χ²_red when that exceeds 1. `None` for fewer than 8 rings.
pub fn fit_background(rings: &[(f64, f64, f64)]) -> Option<(f64, f64)> {
    if rings.len() < 8 {
        return None;
    }
    let floor = rings.iter().map(|r| r.1.abs()).fold(0.0, f64::max) * 1e-6;
    let mut best: Option<(f64, f64, f64)> = None;
    for p in [1.0, 1.5, 2.0, 3.0] {
        for k in 0..=80 {
            let s = 0.005 * (20.0f64 / 0.005).powf(k as f64 / 80.0);
            // Weighted normal equations for (b, A) with basis (1, f).
            let (mut s11, mut s12, mut s22, mut t1, mut t2) = (0.0, 0.0, 0.0, 0.0, 0.0);
            for &(r, y, e) in rings {
                let wgt = 1.0 / (e * e).max(floor * floor).max(f64::MIN_POSITIVE);
                let f = (-s * r).exp() / r.powf(p);
                s11 += wgt;
                s12 += wgt * f;
                s22 += wgt * f * f;
                t1 += wgt * y;
                t2 += wgt * f * y;
            }
            let det = s11 * s22 - s12 * s12;
            if !(det.is_finite() && det > 0.0) {
                continue;
            }
            let b = (s22 * t1 - s12 * t2) / det;
            let a = (s11 * t2 - s12 * t1) / det;
            let chi2: f64 = rings
                .iter()
                .map(|&(r, y, e)| {
                    let m = b + a * (-s * r).exp() / r.powf(p);
                    (y - m).powi(2) / (e * e).max(floor * floor).max(f64::MIN_POSITIVE)
                })
                .sum();
            let var_b = s22 / det;
            if best.is_none_or(|(c, ..)| chi2 < c) {
                best = Some((chi2, b, var_b));
            }
        }
    }
    let (chi2, b, var_b) = best?;
    let dof = (rings.len() - 3) as f64;
    let scale = (chi2 / dof).max(1.0);
    Some((b, (var_b * scale).sqrt()))
}

/// The fit's spot kernel from an image of the spot on a thin opaque white target (linear values):
/// its centre found as the bracket's is ([`scatterfit_imaging::find_spot_center`]), the far
/// corners' median subtracted (stray light, black), the rest averaged on ½-pixel annuli out to the
/// radius that holds 99.5 % of the power within eight half-maximum radii, and made a mixture of
/// disks ([`scatterfit_fit::RadialSpot::from_annuli`]).
///
/// # Errors
/// A message saying what is wrong with the image (no spot found, no power).
pub fn spot_from_image(
    linear: &ImageBuf<f32>,
    mm_per_pixel: f64,
) -> std::result::Result<scatterfit_fit::RadialSpot, String> {
    let center =
        scatterfit_imaging::find_spot_center(linear, &scatterfit_imaging::CenterOptions::default())
            .map_err(|e| format!("no spot found in it ({e})"))?;
    let [cx, cy] = center.xy();
    let (w, h, ch) = (linear.width(), linear.height(), linear.channels());
    // Grey: the mean of the channels.
    let grey: Vec<f64> = linear
        .data()
        .chunks_exact(ch)
        .map(|p| p.iter().map(|&v| f64::from(v)).sum::<f64>() / ch as f64)
        .collect();
    let mut corner: Vec<f64> = corner_pixels(w, h, 1)
        .into_iter()
        .map(|i| grey[i])
        .filter(|v| v.is_finite())
        .collect();
    corner.sort_by(f64::total_cmp);
    let bg = corner.get(corner.len() / 2).copied().unwrap_or(0.0);
    let step = 0.5;
    let r_lim = (w.min(h) as f64) * 0.45;
    let nbin = (r_lim / step).ceil() as usize;
    let (mut sum, mut cnt) = (vec![0.0f64; nbin], vec![0usize; nbin]);
    for y in 0..h {
        for x in 0..w {
            let r = (x as f64 - cx).hypot(y as f64 - cy);
            let k = (r / step) as usize;
            let v = grey[y * w + x];
            if k < nbin && v.is_finite() {
                sum[k] += v - bg;
                cnt[k] += 1;
            }
        }
    }
    let mean: Vec<f64> = (0..nbin)
        .map(|k| {
            if cnt[k] > 0 {
                sum[k] / cnt[k] as f64
            } else {
                0.0
            }
        })
        .collect();
    let peak = mean.iter().copied().fold(0.0f64, f64::max);
    if peak.is_nan() || peak <= 0.0 {
        return Err("it holds no light above its corners".into());
    }
    let half = mean.iter().position(|&v| v < 0.5 * peak).unwrap_or(nbin);
    let reach = ((8 * half.max(2)).min(nbin)).max(2);
    let power: Vec<f64> = (0..reach)
        .map(|k| {
            let (a, b) = (k as f64 * step, (k + 1) as f64 * step);
            mean[k] * std::f64::consts::PI * (b * b - a * a)
        })
        .collect();
    let total: f64 = power.iter().sum();
    let mut acc = 0.0;
    let mut n = reach;
    for (k, p) in power.iter().enumerate() {
        acc += p;
        if acc >= 0.995 * total {
            n = k + 1;
            break;
        }
    }
    let edges: Vec<f64> = (0..=n).map(|k| k as f64 * step * mm_per_pixel).collect();
    scatterfit_fit::RadialSpot::from_annuli(&edges, &mean[..n])
        .map_err(|e| format!("its radial profile is not a spot ({e})"))
}
