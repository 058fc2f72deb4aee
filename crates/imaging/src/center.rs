//! The light spot's centre, to sub-pixel accuracy.
//!
//! Coordinates: pixel (x, y) covers [x − ½, x + ½] × [y − ½, y + ½], i.e. its centre is at (x, y)
//! (OpenCV's convention). The same convention is used by [`crate::radial_profile`] and by the
//! manifest's `center_px`.

use rayon::prelude::*;

use crate::ImageBuf;
use crate::error::{ImagingError, Result};

/// Options of [`find_spot_center`]; built through [`CenterOptions::new`], so always valid.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CenterOptions {
    threshold_fraction: f64,
}

impl CenterOptions {
    /// Options with the spot's threshold: the spot is where the (channel-mean) radiance exceeds
    /// this fraction of the spot's robust maximum (default 0.01: the centroid then uses the top two
    /// decades of the spot).
    ///
    /// # Errors
    /// [`ImagingError::InvalidOption`] for a fraction outside (0, 1).
    pub fn new(threshold_fraction: f64) -> Result<Self> {
        if !(threshold_fraction > 0.0 && threshold_fraction < 1.0) {
            return Err(ImagingError::InvalidOption {
                name: "threshold_fraction",
                value: threshold_fraction,
                reason: "must lie in (0, 1)",
            });
        }
        Ok(Self { threshold_fraction })
    }

    /// The threshold as a fraction of the spot's robust maximum, in (0, 1).
    pub fn threshold_fraction(&self) -> f64 {
        self.threshold_fraction
    }
}

impl Default for CenterOptions {
    fn default() -> Self {
        Self {
            threshold_fraction: 0.01,
        }
    }
}

/// A spot centre and what it was found from: found by [`find_spot_center`] or given through
/// [`SpotCenter::given`], so its coordinates are finite and inside the image it belongs to.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpotCenter {
    x: f64,
    y: f64,
    spot_pixels: usize,
    threshold: f64,
}

impl SpotCenter {
    /// A centre given by the user (e.g. the manifest's `center_px`), checked to lie in the image.
    ///
    /// # Errors
    /// [`ImagingError::CenterOutside`] if not finite or outside [−½, width − ½] × [−½, height − ½].
    pub fn given<T: Copy>(img: &ImageBuf<T>, x: f64, y: f64) -> Result<Self> {
        let inside = x.is_finite()
            && y.is_finite()
            && (-0.5..=img.width() as f64 - 0.5).contains(&x)
            && (-0.5..=img.height() as f64 - 0.5).contains(&y);
        if !inside {
            return Err(ImagingError::CenterOutside {
                x,
                y,
                width: img.width(),
                height: img.height(),
            });
        }
        Ok(Self {
            x,
            y,
            spot_pixels: 0,
            threshold: f64::NAN,
        })
    }

    /// `[x, y]` in pixels (pixel centres at integers).
    pub fn xy(&self) -> [f64; 2] {
        [self.x, self.y]
    }

    /// x in pixels (pixel centres at integers).
    pub fn x(&self) -> f64 {
        self.x
    }

    /// y in pixels.
    pub fn y(&self) -> f64 {
        self.y
    }

    /// Pixels in the spot's connected bright region (0 for a given centre).
    pub fn spot_pixels(&self) -> usize {
        self.spot_pixels
    }

    /// Radiance threshold that delimited the region (NaN for a given centre).
    pub fn threshold(&self) -> f64 {
        self.threshold
    }
}

/// Finds the centre of the light spot in a radiance map.
///
/// 1. The channel-mean radiance L (finite channels only) is binned to about 1 Mpx and smoothed
///    3 × 3; its *robust maximum* is the 16th largest value, so a speck of a few pixels cannot set
///    the scale.
/// 2. Bins above `threshold_fraction` × that maximum — and NaN bins (clipped everywhere), which join
///    whatever bright region they touch — form 8-connected regions; the one with the most finite bright
///    bins is the spot (a dust speck or hot pixel is a smaller one). The threshold is then re-derived
///    from the spot's own maximum.
/// 3. At full resolution, in the spot's box, the connected region above the threshold t is the spot;
///    its centre is the centroid with weights ln(min(L, L_max)/t) (log radiance above the threshold,
///    NaN pixels at L_max). The weight goes continuously to zero at the region's edge, so the ragged,
///    noisy edge adds little, and a flat clipped core is symmetric and does not bias the result.
///
/// # Errors
/// [`ImagingError::NoSpot`] if the image has no positive finite value.
pub fn find_spot_center(img: &ImageBuf<f32>, opts: &CenterOptions) -> Result<SpotCenter> {
    let frac = opts.threshold_fraction;
    let (w, h) = (img.width(), img.height());
    let lum = |x: usize, y: usize| -> f64 { channel_mean(img.pixel(x, y).unwrap_or(&[])) };
    // 1. Binned, smoothed luminance.
    let bin = ((w * h) as f64 / 1.0e6).sqrt().round().max(1.0) as usize;
    let (bw, bh) = (w.div_ceil(bin), h.div_ceil(bin));
    let mut coarse = vec![f64::NAN; bw * bh];
    // Rows of bins in parallel (each bin's sum in the same order as one loop would form it).
    coarse.par_chunks_mut(bw).enumerate().for_each(|(by, row)| {
        for (bx, out) in row.iter_mut().enumerate() {
            let (mut s, mut n) = (0.0, 0usize);
            for y in by * bin..((by + 1) * bin).min(h) {
                for x in bx * bin..((bx + 1) * bin).min(w) {
                    let v = lum(x, y);
                    if v.is_finite() {
                        s += v;
                        n += 1;
                    }
                }
            }
            if n > 0 {
                *out = s / n as f64;
            }
        }
    });
    let smooth = box3(&coarse, bw, bh);
    let mut finite: Vec<f64> = smooth.iter().copied().filter(|v| v.is_finite()).collect();
    if !finite.iter().any(|&v| v > 0.0) {
        return Err(ImagingError::NoSpot {
            reason: "the image has no positive finite radiance",
        });
    }
    let k = 16.min(finite.len());
    let nth = finite.len() - k;
    finite.select_nth_unstable_by(nth, |a, b| a.total_cmp(b));
    let robust_max = finite[nth];
    // A spot is brighter than most of the frame: the profile falls by orders of magnitude from it.
    // A frame whose median is half its maximum or more (a uniform grey, a flat frame, a white
    // wall) has no spot, and "its centre" would be the middle of the frame.
    let mid = finite.len() / 2;
    let (_, median, _) = finite.select_nth_unstable_by(mid, |a, b| a.total_cmp(b));
    if *median >= UNIFORM_MEDIAN_FRACTION * robust_max {
        return Err(ImagingError::NoSpot {
            reason: "the image is nearly uniform (its median is at least half its brightest \
                     part): a spot image has a bright spot fading into a dark surround — is \
                     this a flat frame, or a frame of the wrong scene?",
        });
    }
    // 2. Largest bright region (twice: the second time with the spot's own maximum).
    let mut t = frac * robust_max;
    let mut region = largest_region(&smooth, bw, bh, t);
    let spot_max = region
        .iter()
        .map(|&i| smooth[i])
        .filter(|v| v.is_finite())
        .fold(f64::MIN, f64::max);
    if spot_max > 0.0 {
        t = frac * spot_max;
        region = largest_region(&smooth, bw, bh, t);
    }
    if region.is_empty() {
        return Err(ImagingError::NoSpot {
            reason: "no bright region above the threshold",
        });
    }
    // 3. Full resolution in the region's box (plus one bin of margin).
    let (mut x0, mut x1, mut y0, mut y1) = (usize::MAX, 0, usize::MAX, 0);
    for &i in &region {
        let (bx, by) = (i % bw, i / bw);
        x0 = x0.min(bx);
        x1 = x1.max(bx);
        y0 = y0.min(by);
        y1 = y1.max(by);
    }
    let x0 = (x0.saturating_sub(1)) * bin;
    let y0 = (y0.saturating_sub(1)) * bin;
    let x1 = ((x1 + 2) * bin).min(w);
    let y1 = ((y1 + 2) * bin).min(h);
    let (ww, wh) = (x1 - x0, y1 - y0);
    let win: Vec<f64> = (y0..y1)
        .flat_map(|y| (x0..x1).map(move |x| (x, y)))
        .map(|(x, y)| lum(x, y))
        .collect();
    let l_max = win
        .iter()
        .copied()
        .filter(|v| v.is_finite())
        .fold(f64::MIN, f64::max);
    // Seeds: window pixels in the coarse region above threshold.
    let mut in_region = vec![false; bw * bh];
    for &i in &region {
        in_region[i] = true;
    }
    let bright = |v: f64| v.is_nan() || v >= t;
    let mut label = vec![false; ww * wh];
    let mut stack = Vec::new();
    for yy in 0..wh {
        for xx in 0..ww {
            let (x, y) = (x0 + xx, y0 + yy);
            let idx = yy * ww + xx;
            if in_region[(y / bin) * bw + x / bin] && bright(win[idx]) && win[idx].is_finite() {
                label[idx] = true;
                stack.push(idx);
            }
        }
    }
    flood(&win, ww, wh, &mut label, &mut stack, bright);
    let (mut sw, mut sx, mut sy, mut n) = (0.0, 0.0, 0.0, 0usize);
    let ln_t = t.ln();
    let ln_max = l_max.max(t).ln();
    for (idx, &on) in label.iter().enumerate() {
        if !on {
            continue;
        }
        let v = win[idx];
        let lw = if v.is_nan() {
            ln_max
        } else {
            v.min(l_max).ln()
        } - ln_t;
        let wgt = lw.max(0.0);
        sw += wgt;
        sx += wgt * (x0 + idx % ww) as f64;
        sy += wgt * (y0 + idx / ww) as f64;
        n += 1;
    }
    if sw <= 0.0 {
        return Err(ImagingError::NoSpot {
            reason: "the bright region has no weight above the threshold",
        });
    }
    Ok(SpotCenter {
        x: sx / sw,
        y: sy / sw,
        spot_pixels: n,
        threshold: t,
    })
}

/// A frame whose median (binned, smoothed) radiance is at least this fraction of its maximum has
/// no light spot ([`find_spot_center`]).
const UNIFORM_MEDIAN_FRACTION: f64 = 0.5;

/// Mean of the finite samples, NaN if none.
fn channel_mean(p: &[f32]) -> f64 {
    let (mut s, mut n) = (0.0, 0usize);
    for &v in p {
        if v.is_finite() {
            s += f64::from(v);
            n += 1;
        }
    }
    if n > 0 { s / n as f64 } else { f64::NAN }
}

/// 3 × 3 mean of the finite neighbours; NaN stays NaN.
fn box3(v: &[f64], w: usize, h: usize) -> Vec<f64> {
    let mut out = vec![f64::NAN; v.len()];
    // Rows in parallel.
    out.par_chunks_mut(w.max(1))
        .enumerate()
        .for_each(|(y, out)| {
            for x in 0..w {
                if v[y * w + x].is_nan() {
                    continue;
                }
                let (mut s, mut n) = (0.0, 0usize);
                for yy in y.saturating_sub(1)..(y + 2).min(h) {
                    for xx in x.saturating_sub(1)..(x + 2).min(w) {
                        let u = v[yy * w + xx];
                        if u.is_finite() {
                            s += u;
                            n += 1;
                        }
                    }
                }
                out[x] = s / n as f64;
            }
        });
    out
}

/// The 8-connected region of {v ≥ t or NaN} with the most finite bright cells (indices), or empty.
fn largest_region(v: &[f64], w: usize, h: usize, t: f64) -> Vec<usize> {
    let bright = |u: f64| u.is_nan() || u >= t;
    let mut seen = vec![false; v.len()];
    let mut best: Vec<usize> = Vec::new();
    let mut best_score = 0usize;
    let mut stack = Vec::new();
    for start in 0..v.len() {
        if seen[start] || !(v[start].is_finite() && v[start] >= t) {
            continue;
        }
        let mut label = Vec::new();
        seen[start] = true;
        stack.push(start);
        while let Some(i) = stack.pop() {
            label.push(i);
            let (x, y) = (i % w, i / w);
            for yy in y.saturating_sub(1)..(y + 2).min(h) {
                for xx in x.saturating_sub(1)..(x + 2).min(w) {
                    let j = yy * w + xx;
                    if !seen[j] && bright(v[j]) {
                        seen[j] = true;
                        stack.push(j);
                    }
                }
            }
        }
        let score = label.iter().filter(|&&i| v[i].is_finite()).count();
        if score > best_score {
            best_score = score;
            best = label;
        }
    }
    best
}

/// Grows `label` from the seeds on `stack` over 8-connected cells where `keep` holds.
fn flood(
    v: &[f64],
    w: usize,
    h: usize,
    label: &mut [bool],
    stack: &mut Vec<usize>,
    keep: impl Fn(f64) -> bool,
) {
    while let Some(i) = stack.pop() {
        let (x, y) = (i % w, i / w);
        for yy in y.saturating_sub(1)..(y + 2).min(h) {
            for xx in x.saturating_sub(1)..(x + 2).min(w) {
                let j = yy * w + xx;
                if !label[j] && keep(v[j]) {
                    label[j] = true;
                    stack.push(j);
                }
            }
        }
    }
}
