//! The linear merges of 16-bit and RAW brackets: digital numbers per second, with a dark frame or a
//! black level and the hat over [dark, saturation].

use rayon::prelude::*;

use super::image::{CLIPPED_HIGH, CLIPPED_LOW, ClippedFill, HdrImage, check_dark};
use super::options::LinearMergeOptions;
use crate::ImageBuf;
use crate::error::{ImagingError, Result, check_bracket, check_shape};

/// Merges a linear 16-bit bracket (raw or linear TIFF) with a linear response: E = (v − v_dark)/Δt,
/// combined as ln E = Σ_j w(v_j)(ln(v_j − v_dark) − ln Δt_j)/Σ_j w(v_j) (Debevec & Malik 1997, eq. 6
/// with g = ln), the hat weight stretched to the signal range: w(v) = min(v − v_dark, saturation − v).
/// Radiance is in digital numbers per second.
///
/// `dark`: an optional dark frame, subtracted from the raw values before the logarithm (linear data:
/// this is exact for an offset that does not depend on exposure time). A sample not above the dark
/// value counts as clipped low; saturation is judged on the raw value.
///
/// # Errors
/// Bracket errors, a dark frame of another shape,
/// [`ImagingError::DarkFrameAboveSignal`], [`ImagingError::NoValidRadiance`] (as [`merge`](crate::merge::merge)).
pub fn merge_linear_u16(
    frames: &[ImageBuf<u16>],
    times_s: &[f64],
    dark: Option<&ImageBuf<u16>>,
    opts: &LinearMergeOptions,
) -> Result<HdrImage> {
    check_bracket(frames, times_s)?;
    let f0 = &frames[0];
    let (w, h, ch) = (f0.width(), f0.height(), f0.channels());
    if let Some(d) = dark {
        check_shape(f0, d, || "dark frame".to_string())?;
        check_dark(frames, times_s, d)?;
    }
    let sat = opts.saturation;
    // Hat weight over the signal range [dark, saturation] (called with dark < v < saturation).
    let weight = |v: u16, vd: u16| -> f32 { f32::from((v - vd).min(sat - v)) };
    let ln_t: Vec<f32> = times_s.iter().map(|t| t.ln() as f32).collect();
    let stride = w * ch;
    let mut radiance = vec![0.0f32; w * h * ch];
    let mut mask = vec![0u8; w * h * ch];
    let fill = opts.clipped_fill;
    let clipped_count: usize = radiance
        .par_chunks_mut(stride)
        .zip(mask.par_chunks_mut(stride))
        .enumerate()
        .map(|(y, (out, m))| {
            let range = y * stride..(y + 1) * stride;
            let drow = dark.map(|d| &d.data()[range.clone()]);
            let mut count = 0;
            for k in 0..stride {
                let vd = drow.map_or(0u16, |d| d[k]);
                let (mut nu, mut de) = (0.0f32, 0.0f32);
                let (mut flag, mut bound) = (0u8, 0.0f32);
                for (f, &lt) in frames.iter().zip(&ln_t) {
                    let v = f.data()[range.start + k];
                    if v >= sat {
                        flag |= CLIPPED_HIGH;
                        // Saturated: E > (saturation − 1 − v_dark)/Δt; the shortest exposure is tightest.
                        let b = (f32::from(sat - 1) - f32::from(vd)).max(0.0) / lt.exp();
                        bound = bound.max(b);
                        continue;
                    }
                    if v <= vd {
                        flag |= CLIPPED_LOW;
                        continue;
                    }
                    let wv = weight(v, vd);
                    if wv > 0.0 {
                        nu += wv * (f32::from(v - vd).ln() - lt);
                        de += wv;
                    }
                }
                if de > 0.0 {
                    out[k] = (nu / de).exp();
                } else {
                    count += 1;
                    m[k] = flag.max(CLIPPED_LOW * u8::from(flag == 0));
                    out[k] = match fill {
                        ClippedFill::Nan => f32::NAN,
                        ClippedFill::LowerBound => bound,
                    };
                }
            }
            count
        })
        .sum();
    HdrImage::from_parts((w, h, ch), radiance, mask, clipped_count)
}

/// Merges a linear bracket whose values carry a black level (raw files, linear 16-bit frames of a
/// camera that does not subtract it): the noise-aware linear-domain estimate of [`merge`](crate::merge::merge)'s
/// default, E = Σ_j u_j Δt_j (v_j − b)/Σ_j u_j Δt_j² (Robertson et al. 2003; Granados et al.
/// 2010, with a noise constant in the signal), per channel with its own black level `black[c]`
/// \[DN\]. Values below the black level are kept as the negative readings they are (read noise
/// about a faint signal: dropping them, as a logarithm must, would bias faint pixels upward);
/// u = 1 up to half the range, then fading linearly to 0 at `saturation`; saturated samples
/// (v ≥ saturation) are dropped. A pixel-channel saturated in every frame is flagged
/// [`CLIPPED_HIGH`] and filled per `fill` (its lower bound (saturation − 1 − b)/Δt_min, or NaN).
/// Radiance is in digital numbers per second above black.
///
/// # Errors
/// Bracket errors, [`ImagingError::InvalidOption`] for a black level per channel that is not
/// finite or not below the saturation, [`ImagingError::NoValidRadiance`].
pub fn merge_linear_black(
    frames: &[ImageBuf<u16>],
    times_s: &[f64],
    black: &[f64],
    saturation: u16,
    fill: ClippedFill,
) -> Result<HdrImage> {
    check_bracket(frames, times_s)?;
    let f0 = &frames[0];
    let (w, h, ch) = (f0.width(), f0.height(), f0.channels());
    if black.len() != ch
        || black
            .iter()
            .any(|b| !(b.is_finite() && *b >= 0.0 && *b < f64::from(saturation) - 1.0))
    {
        return Err(ImagingError::InvalidOption {
            name: "black level",
            value: black.first().copied().unwrap_or(f64::NAN),
            reason: "one finite level per channel, ≥ 0 and below the saturation",
        });
    }
    let sat = f64::from(saturation);
    let stride = w * ch;
    let mut radiance = vec![0.0f32; w * h * ch];
    let mut mask = vec![0u8; w * h * ch];
    let t_min = times_s.iter().copied().fold(f64::INFINITY, f64::min);
    let clipped_count: usize = radiance
        .par_chunks_mut(stride)
        .zip(mask.par_chunks_mut(stride))
        .enumerate()
        .map(|(y, (out, m))| {
            let mut count = 0;
            for k in 0..stride {
                let b = black[k % ch];
                let half = 0.5 * (sat - b);
                let (mut nu, mut de) = (0.0f64, 0.0f64);
                for (f, &t) in frames.iter().zip(times_s) {
                    let v = f64::from(f.data()[y * stride + k]);
                    if v >= sat {
                        continue;
                    }
                    let u = ((sat - v) / half).min(1.0);
                    nu += u * t * (v - b);
                    de += u * t * t;
                }
                if de > 0.0 {
                    out[k] = (nu / de) as f32;
                } else {
                    count += 1;
                    m[k] = CLIPPED_HIGH;
                    out[k] = match fill {
                        ClippedFill::Nan => f32::NAN,
                        ClippedFill::LowerBound => ((sat - 1.0 - b).max(0.0) / t_min) as f32,
                    };
                }
            }
            count
        })
        .sum();
    HdrImage::from_parts((w, h, ch), radiance, mask, clipped_count)
}
