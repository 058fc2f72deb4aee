//! The radially resolved profile Rd(r): pixels averaged over concentric rings around the spot centre
//! (Choi, Lee & Chin 2014: "pixels at equal distance from the spot", up to 300 px).
//!
//! Pixel (x, y) is at distance r = √((x − c_x)² + (y − c_y)²) from the centre (pixel centres at
//! integer coordinates, see [`crate::center`]); it belongs to ring k = ⌊r / width⌋ if r < r_max.

use crate::ImageBuf;
use crate::error::{ImagingError, Result, check_shape};

/// Most rings a profile may have (r_max / ring width): 10⁶ rings hold about 100 MB of statistics
/// for RGB, far more than a light spot's profile needs (the paper uses 300).
pub const MAX_RINGS: usize = 1_000_000;

/// Options of [`radial_profile`]; built through [`ProfileOptions::new`], so the ring count is
/// bounded before anything is allocated.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProfileOptions {
    ring_width_px: f64,
    r_max_px: f64,
}

impl ProfileOptions {
    /// Rings of `ring_width_px` (default 1) out to `r_max_px` (exclusive; default 300, the paper's
    /// cut-off), both in pixels.
    ///
    /// # Errors
    /// [`ImagingError::InvalidOption`] for a width or radius that is not finite and > 0, or more than
    /// [`MAX_RINGS`] rings (`ring_width_px` = 1e-300 would otherwise ask for an impossible
    /// allocation).
    pub fn new(ring_width_px: f64, r_max_px: f64) -> Result<Self> {
        for (name, v) in [("ring_width_px", ring_width_px), ("r_max_px", r_max_px)] {
            if !(v.is_finite() && v > 0.0) {
                return Err(ImagingError::InvalidOption {
                    name,
                    value: v,
                    reason: "must be finite and > 0",
                });
            }
        }
        let rings = (r_max_px / ring_width_px).ceil();
        if rings > MAX_RINGS as f64 {
            return Err(ImagingError::InvalidOption {
                name: "r_max_px / ring_width_px",
                value: rings,
                reason: "more than 1 000 000 rings (MAX_RINGS); widen the rings or reduce r_max",
            });
        }
        Ok(Self {
            ring_width_px,
            r_max_px,
        })
    }

    /// Ring width \[px\].
    pub fn ring_width_px(&self) -> f64 {
        self.ring_width_px
    }

    /// Outer radius \[px\] (exclusive).
    pub fn r_max_px(&self) -> f64 {
        self.r_max_px
    }

    /// Number of rings, ⌈r_max / width⌉ ≤ [`MAX_RINGS`].
    pub fn rings(&self) -> usize {
        (self.r_max_px / self.ring_width_px).ceil() as usize
    }
}

impl Default for ProfileOptions {
    fn default() -> Self {
        Self {
            ring_width_px: 1.0,
            r_max_px: 300.0,
        }
    }
}

/// One channel's statistics in one ring.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RingChannel {
    /// Mean radiance of the valid pixels (NaN if there are none).
    pub mean: f64,
    /// Standard error of that mean, s/√n with the sample standard deviation s (NaN if n < 2).
    pub std_err: f64,
    /// Number of valid pixels.
    pub count: usize,
    /// Mean distance of those pixels from the centre, in pixels (NaN if there are none).
    pub r_px: f64,
}

/// One ring of the profile.
#[derive(Debug, Clone, PartialEq)]
pub struct Ring {
    /// Inner radius in pixels (inclusive).
    pub r_inner_px: f64,
    /// Outer radius in pixels (exclusive).
    pub r_outer_px: f64,
    /// The ring's radius: the mean distance from the centre of its pixels that lie in the image
    /// (whatever their validity) — not the mid radius, which it differs from in the innermost rings
    /// and where the ring leaves the image. The mid radius when no pixel lies in the image.
    pub r_px: f64,
    /// Per-channel statistics.
    pub channels: Vec<RingChannel>,
}

/// A radial profile.
#[derive(Debug, Clone, PartialEq)]
pub struct RadialProfile {
    /// The centre used, `[x, y]` in pixels.
    pub center_px: [f64; 2],
    /// Image scale on the sample surface, mm per pixel.
    pub mm_per_pixel: f64,
    /// The options used.
    pub options: ProfileOptions,
    /// Rings from the centre out; ring k covers [k·width, (k+1)·width) ∩ [0, r_max).
    pub rings: Vec<Ring>,
}

impl RadialProfile {
    /// Ring `k`'s radius in mm: [`Ring::r_px`] × `mm_per_pixel`.
    pub fn r_mm(&self, k: usize) -> Option<f64> {
        self.rings.get(k).map(|r| r.r_px * self.mm_per_pixel)
    }

    /// Number of channels.
    pub fn channels(&self) -> usize {
        self.rings.first().map_or(0, |r| r.channels.len())
    }
}

/// Averages `img` over concentric rings around `center_px` ([x, y] in pixels).
///
/// Only the disc of radius r_max around the centre is visited. Rings that leave the image use the
/// pixels inside it. A pixel-channel is skipped if it is not finite (NaN: clipped everywhere) or if
/// `mask` (e.g. [`crate::HdrImage::clipped`]; same shape as `img`) is non-zero there.
///
/// # Errors
/// [`ImagingError::InvalidOption`] for a non-positive mm per pixel (the ring options are valid by
/// construction, [`ProfileOptions::new`]);
/// [`ImagingError::CenterOutside`] for a non-finite centre; [`ImagingError::ShapeMismatch`] for a mask
/// of another shape.
pub fn radial_profile(
    img: &ImageBuf<f32>,
    center_px: [f64; 2],
    mask: Option<&ImageBuf<u8>>,
    mm_per_pixel: f64,
    opts: &ProfileOptions,
) -> Result<RadialProfile> {
    let positive = |name: &'static str, v: f64| {
        if v.is_finite() && v > 0.0 {
            Ok(())
        } else {
            Err(ImagingError::InvalidOption {
                name,
                value: v,
                reason: "must be finite and > 0",
            })
        }
    };
    positive("mm_per_pixel", mm_per_pixel)?;
    let [cx, cy] = center_px;
    let (w, h, ch) = (img.width(), img.height(), img.channels());
    if !(cx.is_finite() && cy.is_finite()) {
        return Err(ImagingError::CenterOutside {
            x: cx,
            y: cy,
            width: w,
            height: h,
        });
    }
    if let Some(m) = mask {
        check_shape(img, m, || "mask".to_string())?;
    }
    let width = opts.ring_width_px;
    let r_max = opts.r_max_px;
    let n_rings = opts.rings();
    // Per ring: pixel count and Σr over in-image pixels; per ring and channel: n, Σv, Σv², Σr.
    let mut geo = vec![(0usize, 0.0f64); n_rings];
    let mut acc = vec![[0.0f64; 4]; n_rings * ch];
    let y_lo = (cy - r_max).ceil().max(0.0) as usize;
    let y_hi = ((cy + r_max).floor()).min(h as f64 - 1.0);
    if y_hi >= 0.0 {
        for y in y_lo..=(y_hi as usize) {
            let dy = y as f64 - cy;
            let half = (r_max * r_max - dy * dy).max(0.0).sqrt();
            let x_lo = (cx - half).ceil().max(0.0) as usize;
            let x_hi = (cx + half).floor().min(w as f64 - 1.0);
            if x_hi < 0.0 {
                continue;
            }
            let row = img.row(y).unwrap_or(&[]);
            let mrow = mask.and_then(|m| m.row(y));
            for x in x_lo..=(x_hi as usize) {
                let dx = x as f64 - cx;
                let r = (dx * dx + dy * dy).sqrt();
                if r >= r_max {
                    continue;
                }
                let k = ((r / width) as usize).min(n_rings - 1);
                geo[k].0 += 1;
                geo[k].1 += r;
                for c in 0..ch {
                    let v = row[x * ch + c];
                    if !v.is_finite() || mrow.is_some_and(|m| m[x * ch + c] != 0) {
                        continue;
                    }
                    let v = f64::from(v);
                    let a = &mut acc[k * ch + c];
                    a[0] += 1.0;
                    a[1] += v;
                    a[2] += v * v;
                    a[3] += r;
                }
            }
        }
    }
    let rings = (0..n_rings)
        .map(|k| {
            let r_inner = k as f64 * width;
            let r_outer = ((k + 1) as f64 * width).min(r_max);
            let (np, sr) = geo[k];
            let r_px = if np > 0 {
                sr / np as f64
            } else {
                0.5 * (r_inner + r_outer)
            };
            let channels = (0..ch)
                .map(|c| {
                    let [n, s, s2, sr] = acc[k * ch + c];
                    let count = n as usize;
                    let mean = if count > 0 { s / n } else { f64::NAN };
                    let std_err = if count > 1 {
                        ((s2 - s * mean).max(0.0) / (n - 1.0) / n).sqrt()
                    } else {
                        f64::NAN
                    };
                    let r_px = if count > 0 { sr / n } else { f64::NAN };
                    RingChannel {
                        mean,
                        std_err,
                        count,
                        r_px,
                    }
                })
                .collect();
            Ring {
                r_inner_px: r_inner,
                r_outer_px: r_outer,
                r_px,
                channels,
            }
        })
        .collect();
    Ok(RadialProfile {
        center_px,
        mm_per_pixel,
        options: *opts,
        rings,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `--ring-width-px 1e-300` once panicked with "capacity overflow" and `--r-max-px 1e13`
    /// asked for 160 TB; both are now an `InvalidOption` before anything is allocated.
    #[test]
    fn ring_count_is_bounded() {
        let img = ImageBuf::filled(8, 8, 1, 1.0f32).unwrap();
        for (width, r_max) in [
            (1e-300, 300.0),
            (1.0, 1e13),
            (1e-3, 1001.0),
            (1e-300, 1e300),
        ] {
            let err = ProfileOptions::new(width, r_max).unwrap_err();
            assert!(
                matches!(
                    err,
                    ImagingError::InvalidOption {
                        name: "r_max_px / ring_width_px",
                        ..
                    }
                ),
                "{err:?}"
            );
        }
        let opts = ProfileOptions::new(1e-3, 1000.0).unwrap();
        let p = radial_profile(&img, [4.0, 4.0], None, 0.1, &opts).unwrap();
        assert_eq!(p.rings.len(), MAX_RINGS);
    }
}
