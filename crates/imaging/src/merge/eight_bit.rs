//! The 8-bit merge through a camera response ([`merge`]): a first pass over every reading, then
//! (with an expected-signal floor) the second pass of [`super::refine`].

use rayon::prelude::*;

use super::image::{CLIPPED_HIGH, CLIPPED_LOW, ClippedFill, HdrImage, check_dark};
use super::lut::{Tables, hat_weight_above, merge_row_lut};
use super::options::{MergeOptions, Weighting};
use super::refine::{FirstPass, refine_by_expected_signal};
use crate::ImageBuf;
use crate::error::{ImagingError, Result, check_bracket, check_shape};
use crate::response::ResponseCurve;

/// Merges an 8-bit bracket with a camera response (Debevec & Malik 1997, eq. 6), in parallel over
/// rows with per-channel, per-frame lookup tables of w(z) and w(z)(g(z) − ln Δt_j).
///
/// A response with one channel is applied to every channel of the frames.
///
/// With [`MergeOptions::expected_floor`] (noise-aware weighting only) a second pass leaves out each
/// frame whose *expected* code at a pixel, from the first pass's radiance around it, is below the
/// floor: readings censored at code 0 no longer lift faint pixels (`refine_by_expected_signal`).
///
/// `dark`: an optional dark frame (lens capped, same settings) holding the sensor's black offset and
/// stray light. 8-bit codes are not linear, so it is subtracted in the linearised domain:
/// X = exp g(Z) − exp g(Z_dark) per pixel, and ln E = Σ w(Z)(ln X − ln Δt)/Σ w(Z); a sample with
/// X ≤ 0 counts as clipped low. This assumes the offset does not grow with exposure time (true of
/// the bias, not of dark current in long exposures; use per-exposure darks then).
///
/// # Errors
/// Bracket errors (fewer than 2 frames, one time per frame, positive distinct times, equal shapes),
/// a dark frame of another shape, [`ImagingError::ChannelMismatch`];
/// [`ImagingError::DarkFrameAboveSignal`] (checked before merging) and
/// [`ImagingError::NoValidRadiance`] when fewer than [`MIN_VALID_FRACTION`](crate::merge::MIN_VALID_FRACTION) of a channel's pixels
/// have an estimate.
pub fn merge(
    frames: &[ImageBuf<u8>],
    times_s: &[f64],
    response: &ResponseCurve,
    dark: Option<&ImageBuf<u8>>,
    opts: &MergeOptions,
) -> Result<HdrImage> {
    check_bracket(frames, times_s)?;
    let f0 = &frames[0];
    let (w, h, ch) = (f0.width(), f0.height(), f0.channels());
    if response.channels() != ch && response.channels() != 1 {
        return Err(ImagingError::ChannelMismatch {
            response: response.channels(),
            image: ch,
        });
    }
    if let Some(d) = dark {
        check_shape(f0, d, || "dark frame".to_string())?;
        check_dark(frames, times_s, d)?;
    }
    let g = |c: usize| &response.tables()[if response.channels() == 1 { 0 } else { c }];
    let lin: Vec<Vec<f64>> = (0..ch)
        .map(|c| g(c).iter().map(|v| v.exp()).collect())
        .collect();
    let ln_t: Vec<f64> = times_s.iter().map(|t| t.ln()).collect();
    let weighting = opts.weighting;
    let tables = Tables::new(weighting, &lin, g, times_s);
    let stride = w * ch;
    let mut radiance = vec![0.0f32; w * h * ch];
    let mut mask = vec![0u8; w * h * ch];
    let fill = opts.clipped_fill;
    let clipped_count: usize = radiance
        .par_chunks_mut(stride)
        .zip(mask.par_chunks_mut(stride))
        .enumerate()
        .map_init(
            || vec![0.0f32; stride],
            |den, (y, (out, m))| {
                let rows: Vec<&[u8]> = frames
                    .iter()
                    .map(|f| &f.data()[y * stride..(y + 1) * stride])
                    .collect();
                match dark {
                    None => merge_row_lut(&rows, &tables, out, den),
                    Some(d) => {
                        let drow = &d.data()[y * stride..(y + 1) * stride];
                        for k in 0..stride {
                            let c = k % ch;
                            let zd = drow[k];
                            let xd = lin[c][zd as usize];
                            let (mut nu, mut de) = (0.0f64, 0.0f64);
                            for ((row, lt), t) in rows.iter().zip(&ln_t).zip(times_s) {
                                let z = row[k];
                                match weighting {
                                    Weighting::DebevecHat => {
                                        let wz = hat_weight_above(z, zd);
                                        let x = lin[c][z as usize] - xd;
                                        if wz > 0.0 && x > 0.0 {
                                            nu += wz * (x.ln() - lt);
                                            de += wz;
                                        }
                                    }
                                    Weighting::NoiseOptimal => {
                                        let u = f64::from(tables.w[z as usize]);
                                        let x = tables.x[c][z as usize] - xd;
                                        nu += t * u * x;
                                        de += t * t * u;
                                    }
                                }
                            }
                            let (valid, e) = match weighting {
                                Weighting::DebevecHat => (de > 0.0, (nu / de).exp()),
                                Weighting::NoiseOptimal => (nu > 0.0 && de > 0.0, nu / de),
                            };
                            den[k] = if valid { de as f32 } else { 0.0 };
                            if valid {
                                out[k] = e as f32;
                            }
                        }
                    }
                }
                // Pixel-channels without a usable sample: classify and fill.
                let mut count = 0;
                for k in 0..stride {
                    if den[k] > 0.0 {
                        continue;
                    }
                    count += 1;
                    let c = k % ch;
                    let xd = dark.map_or(0.0, |d| lin[c][d.data()[y * stride + k] as usize]);
                    let (mut flag, mut bound) = (0u8, 0.0f64);
                    for (row, lt) in rows.iter().zip(&ln_t) {
                        let z = row[k];
                        if z == u8::MAX {
                            flag |= CLIPPED_HIGH;
                            // Saturated: E > (X(254) − X_dark)/Δt; the shortest exposure is tightest.
                            let b = ((lin[c][254] - xd).max(0.0)).ln() - lt;
                            bound = bound.max(b.exp());
                        } else {
                            flag |= CLIPPED_LOW;
                        }
                    }
                    m[k] = flag;
                    out[k] = match fill {
                        ClippedFill::Nan => f32::NAN,
                        ClippedFill::LowerBound => bound as f32,
                    };
                }
                count
            },
        )
        .sum();
    if let (Some(floor), Weighting::NoiseOptimal) = (opts.expected_floor, weighting) {
        let x_floor: Vec<f64> = (0..ch)
            .map(|c| lin[c][usize::from(floor[c.min(3)])])
            .collect();
        let pass = FirstPass {
            w,
            ch,
            radiance: &radiance,
            mask: &mask,
        };
        let refined = refine_by_expected_signal(frames, times_s, &tables, dark, &x_floor, &pass);
        radiance = refined;
    }
    HdrImage::from_parts((w, h, ch), radiance, mask, clipped_count)
}
