//! HDR merge of an exposure bracket into a per-channel radiance map (Debevec & Malik 1997, eq. 6).
//!
//! ln E = Σ_j w(Z_j)(g(Z_j) − ln Δt_j) / Σ_j w(Z_j), per pixel and channel, with the hat weight
//! ([`crate::hat_weight`]), so clipped samples (code 0 or the maximum) carry no weight. A pixel-channel
//! clipped in *every* exposure has no estimate: it is flagged in [`HdrImage::clipped`] and its
//! radiance is set by [`ClippedFill`] (NaN by default, never a made-up number).
//!
//! Radiance is relative: for an 8-bit merge it is in the response's gauge (E = 1 gives code 128 in a
//! 1 s exposure with a recovered curve); for a 16-bit linear merge it is digital numbers per second.

use rayon::prelude::*;

use crate::ImageBuf;
use crate::error::{ImagingError, Result, check_bracket, check_shape};
use crate::response::{LEVELS, ResponseCurve, hat_weight};

/// Mask bit: the pixel-channel was at the low clip (code 0, or not above the dark frame) in some
/// exposure and has no usable sample.
pub const CLIPPED_LOW: u8 = 1;
/// Mask bit: the pixel-channel was saturated (the maximum code) in some exposure and has no usable
/// sample.
pub const CLIPPED_HIGH: u8 = 2;

/// The radiance given to a pixel-channel that is clipped in every exposure (always also flagged).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum ClippedFill {
    /// NaN: downstream code (the radial profile, the spot finder) skips it, and it survives a round
    /// trip through a float file without a separate mask. The default.
    #[default]
    Nan,
    /// The largest radiance the data prove it has: for a saturated pixel, the radiance that would
    /// give the highest unclipped code in the shortest saturated exposure
    /// (exp(g(254) − ln Δt) for 8-bit); for a pixel dark in every frame, 0.
    LowerBound,
}

/// Options of [`merge`].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct MergeOptions {
    /// Value of pixel-channels clipped in every exposure.
    pub clipped_fill: ClippedFill,
}

/// Options of [`merge_linear_u16`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinearMergeOptions {
    /// Raw value at and above which a sample counts as saturated (many sensors clip below 65535,
    /// e.g. 4095 × 16 for 12-bit data). Default 65535.
    pub saturation: u16,
    /// Value of pixel-channels clipped in every exposure.
    pub clipped_fill: ClippedFill,
}

impl Default for LinearMergeOptions {
    fn default() -> Self {
        Self {
            saturation: u16::MAX,
            clipped_fill: ClippedFill::Nan,
        }
    }
}

/// A merged radiance map and its clipping mask.
#[derive(Debug, Clone, PartialEq)]
pub struct HdrImage {
    /// Relative radiance E per pixel and channel (linear, not log).
    pub radiance: ImageBuf<f32>,
    /// Per pixel and channel: 0 if the radiance is an estimate, else [`CLIPPED_LOW`] |
    /// [`CLIPPED_HIGH`] bits saying why there is none.
    pub clipped: ImageBuf<u8>,
    /// Number of flagged pixel-channels (non-zero entries of `clipped`).
    pub clipped_count: usize,
}

impl HdrImage {
    /// True if pixel-channel `(x, y, c)` has a radiance estimate (not clipped everywhere).
    pub fn is_valid(&self, x: usize, y: usize, c: usize) -> bool {
        self.clipped
            .pixel(x, y)
            .and_then(|p| p.get(c))
            .is_some_and(|&m| m == 0)
    }
}

/// Merges an 8-bit bracket with a camera response (Debevec & Malik 1997, eq. 6), in parallel over
/// rows with per-channel, per-frame lookup tables of w(z) and w(z)(g(z) − ln Δt_j).
///
/// A response with one channel is applied to every channel of the frames.
///
/// `dark`: an optional dark frame (lens capped, same settings) holding the sensor's black offset and
/// stray light. 8-bit codes are not linear, so it is subtracted in the linearised domain:
/// X = exp g(Z) − exp g(Z_dark) per pixel, and ln E = Σ w(Z)(ln X − ln Δt)/Σ w(Z); a sample with
/// X ≤ 0 counts as clipped low. This assumes the offset does not grow with exposure time (true of
/// the bias, not of dark current in long exposures; use per-exposure darks then).
///
/// # Errors
/// Bracket errors (fewer than 2 frames, one time per frame, positive distinct times, equal shapes),
/// a dark frame of another shape, [`ImagingError::ChannelMismatch`].
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
    }
    let g = |c: usize| &response.tables()[if response.channels() == 1 { 0 } else { c }];
    // Lookup tables (all fit in L1): w(z) and, per channel, w(z)·g_c(z); frame j adds
    // w(g − ln Δt_j) = wg_c(z) − ln Δt_j · w(z).
    let w_lut: [f32; LEVELS] = std::array::from_fn(|z| hat_weight(z as u8) as f32);
    let wg_lut: Vec<[f32; LEVELS]> = (0..ch)
        .map(|c| std::array::from_fn(|z| (hat_weight(z as u8) * g(c)[z]) as f32))
        .collect();
    let ln_t32: Vec<f32> = times_s.iter().map(|t| t.ln() as f32).collect();
    let lin: Vec<Vec<f64>> = (0..ch)
        .map(|c| g(c).iter().map(|v| v.exp()).collect())
        .collect();
    let ln_t: Vec<f64> = times_s.iter().map(|t| t.ln()).collect();
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
                    None => merge_row_lut(&rows, &w_lut, &wg_lut, &ln_t32, out, den),
                    Some(d) => {
                        let drow = &d.data()[y * stride..(y + 1) * stride];
                        for k in 0..stride {
                            let c = k % ch;
                            let xd = lin[c][drow[k] as usize];
                            let (mut nu, mut de) = (0.0f64, 0.0f64);
                            for (row, lt) in rows.iter().zip(&ln_t) {
                                let z = row[k];
                                let wz = hat_weight(z);
                                let x = lin[c][z as usize] - xd;
                                if wz > 0.0 && x > 0.0 {
                                    nu += wz * (x.ln() - lt);
                                    de += wz;
                                }
                            }
                            den[k] = de as f32;
                            if de > 0.0 {
                                out[k] = (nu / de).exp() as f32;
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
    Ok(HdrImage {
        radiance: ImageBuf::new(w, h, ch, radiance)?,
        clipped: ImageBuf::new(w, h, ch, mask)?,
        clipped_count,
    })
}

/// Merges one row with the lookup tables: `out` receives exp(Σ w(g − ln Δt)/Σ w) where Σ w > 0 and
/// `den` the sums Σ w. Works in blocks of 256 pixels so the running sums stay in L1 while the frames
/// stream through.
fn merge_row_lut(
    rows: &[&[u8]],
    w_lut: &[f32; LEVELS],
    wg_lut: &[[f32; LEVELS]],
    ln_t: &[f32],
    out: &mut [f32],
    den: &mut [f32],
) {
    fn go<const N: usize>(
        rows: &[&[u8]],
        w_lut: &[f32; LEVELS],
        wg_lut: &[[f32; LEVELS]],
        ln_t: &[f32],
        out: &mut [f32],
        den: &mut [f32],
    ) {
        let Some(wg) = wg_lut.first_chunk::<N>() else {
            return;
        };
        // Pixel-major, four pixels at a time: the 4·N sums stay in registers while the P samples of
        // each are read, and the four independent dependency chains hide the add latency.
        const PX: usize = 4;
        let whole = out.len() / (PX * N) * (PX * N);
        let (out_a, out_b) = out.split_at_mut(whole);
        let (den_a, den_b) = den.split_at_mut(whole);
        for (k, (nu, d)) in out_a
            .chunks_exact_mut(PX * N)
            .zip(den_a.chunks_exact_mut(PX * N))
            .enumerate()
        {
            let base = k * PX * N;
            let mut a = [[0.0f32; N]; PX];
            let mut dd = [[0.0f32; N]; PX];
            for (row, &lt) in rows.iter().zip(ln_t) {
                let Some(z) = row.get(base..base + PX * N) else {
                    continue;
                };
                for p in 0..PX {
                    for c in 0..N {
                        let zi = z[p * N + c] as usize;
                        let wv = w_lut[zi];
                        a[p][c] += wg[c][zi] - lt * wv;
                        dd[p][c] += wv;
                    }
                }
            }
            for p in 0..PX {
                for c in 0..N {
                    let i = p * N + c;
                    d[i] = dd[p][c];
                    nu[i] = if dd[p][c] > 0.0 {
                        (a[p][c] / dd[p][c]).exp()
                    } else {
                        0.0
                    };
                }
            }
        }
        // The last few pixels of the row, one at a time.
        for (k, (nu, d)) in out_b
            .chunks_exact_mut(N)
            .zip(den_b.chunks_exact_mut(N))
            .enumerate()
        {
            let base = whole + k * N;
            let mut a = [0.0f32; N];
            let mut dd = [0.0f32; N];
            for (row, &lt) in rows.iter().zip(ln_t) {
                let Some(z) = row.get(base..base + N) else {
                    continue;
                };
                for c in 0..N {
                    let zi = z[c] as usize;
                    let wv = w_lut[zi];
                    a[c] += wg[c][zi] - lt * wv;
                    dd[c] += wv;
                }
            }
            for c in 0..N {
                d[c] = dd[c];
                nu[c] = if dd[c] > 0.0 {
                    (a[c] / dd[c]).exp()
                } else {
                    0.0
                };
            }
        }
    }
    match wg_lut.len() {
        1 => go::<1>(rows, w_lut, wg_lut, ln_t, out, den),
        3 => go::<3>(rows, w_lut, wg_lut, ln_t, out, den),
        4 => go::<4>(rows, w_lut, wg_lut, ln_t, out, den),
        ch => {
            out.fill(0.0);
            den.fill(0.0);
            for (row, &lt) in rows.iter().zip(ln_t) {
                for (k, &z) in row.iter().enumerate() {
                    let wv = w_lut[z as usize];
                    out[k] += wg_lut[k % ch][z as usize] - lt * wv;
                    den[k] += wv;
                }
            }
            for (nu, &d) in out.iter_mut().zip(den.iter()) {
                if d > 0.0 {
                    *nu = (*nu / d).exp();
                }
            }
        }
    }
}

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
/// Bracket errors, a dark frame of another shape, [`ImagingError::InvalidOption`] for saturation < 2.
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
    }
    let sat = opts.saturation;
    if sat < 2 {
        return Err(ImagingError::InvalidOption {
            name: "saturation",
            value: f64::from(sat),
            reason: "must be ≥ 2",
        });
    }
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
    Ok(HdrImage {
        radiance: ImageBuf::new(w, h, ch, radiance)?,
        clipped: ImageBuf::new(w, h, ch, mask)?,
        clipped_count,
    })
}
