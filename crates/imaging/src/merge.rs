//! HDR merge of an exposure bracket into a per-channel radiance map.
//!
//! 8-bit: by default the noise-aware linear-domain estimate E = Σ_j w_j Δt_j X(Z_j)/Σ_j w_j Δt_j²
//! (Robertson, Borman & Stevenson 2003; see [`Weighting::NoiseOptimal`]), or the paper's
//! ln E = Σ_j w(Z_j)(g(Z_j) − ln Δt_j) / Σ_j w(Z_j) with the hat weight (Debevec & Malik 1997, eq. 6;
//! [`Weighting::DebevecHat`]). Saturated samples carry no weight. A pixel-channel
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

/// The least fraction of a channel's pixels that must have a radiance estimate (and, with a dark
/// frame, rise above it in the longest exposure) for a merge to count as a measurement: 0.1 %, a disc
/// of 87 px radius in a 24-MP frame. Below it the merge is refused
/// ([`ImagingError::NoValidRadiance`], [`ImagingError::DarkFrameAboveSignal`]) instead of returning
/// a map of NaN that looks like a result.
pub const MIN_VALID_FRACTION: f64 = 1e-3;

/// The least number of pixels out of `total` that [`MIN_VALID_FRACTION`] asks for (at least 1).
fn min_valid(total: usize) -> usize {
    ((MIN_VALID_FRACTION * total as f64).ceil() as usize).max(1)
}

/// Refuses a dark frame at or above the signal: per channel, fewer than [`min_valid`] pixels of the
/// longest exposure above the dark frame.
fn check_dark<T: Copy + PartialOrd>(
    frames: &[ImageBuf<T>],
    times_s: &[f64],
    dark: &ImageBuf<T>,
) -> Result<()> {
    let longest = (0..frames.len())
        .max_by(|&a, &b| times_s[a].total_cmp(&times_s[b]))
        .unwrap_or(0);
    let (f, ch) = (&frames[longest], dark.channels());
    let total = f.width() * f.height();
    for channel in 0..ch {
        let above = f
            .data()
            .iter()
            .zip(dark.data())
            .skip(channel)
            .step_by(ch)
            .filter(|(v, d)| v > d)
            .count();
        if above < min_valid(total) {
            return Err(ImagingError::DarkFrameAboveSignal {
                channel,
                above,
                total,
            });
        }
    }
    Ok(())
}

/// Refuses a merge in which (nearly) every pixel of a channel is clipped in every exposure.
fn check_valid(mask: &ImageBuf<u8>) -> Result<()> {
    let ch = mask.channels();
    let total = mask.width() * mask.height();
    for channel in 0..ch {
        let (mut valid, mut saturated, mut dark) = (0usize, 0usize, 0usize);
        for &m in mask.data().iter().skip(channel).step_by(ch) {
            match m {
                0 => valid += 1,
                m if m & CLIPPED_HIGH != 0 => saturated += 1,
                _ => dark += 1,
            }
        }
        if valid < min_valid(total) {
            return Err(ImagingError::NoValidRadiance {
                channel,
                valid,
                total,
                saturated,
                dark,
                advice: if saturated >= dark {
                    "the bracket is overexposed: add shorter exposures (or dim the light) so that \
                     every pixel is below saturation in at least one frame"
                } else {
                    "the bracket is too dark: add longer exposures (or more light), and check that \
                     the dark frame is darker than the scene"
                },
            });
        }
    }
    Ok(())
}

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

/// How [`merge`] weights the samples of a pixel-channel across the bracket.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum Weighting {
    /// Noise-aware, the default: the maximum-likelihood estimate of Robertson, Borman & Stevenson
    /// 2003 (J. Electronic Imaging 12(2), §3), E = Σ_j w_j Δt_j X(Z_j) / Σ_j w_j Δt_j², averaged in the
    /// *linear* domain X = exp g(Z), with inverse-variance weights w_j = Δt_j²·u(Z_j) (Granados et
    /// al. 2010, CVPR, "Optimal HDR reconstruction with linear digital cameras": w_j = Δt_j²/σ²_j,
    /// here with a noise σ constant in the linear signal), so each frame counts by Δt² and a short
    /// frame's noisy low codes barely move the estimate. u(z) = 1 up to code 128 and the upper half
    /// of the paper's hat above, (255 − z)/127, which fades out codes near the clip where the tone
    /// curve is compressed (a choice of ours, measured in BENCHMARKS.md); saturated codes (255) are
    /// dropped; a code-0 sample counts as X = 0 (it is a censored reading, evidence
    /// that the exposure was at most the first code's), so dark frames no longer bias dim pixels
    /// upwards as dropping them would (what the censoring at code 0 still leaves — a frame within
    /// a few noise σ of black averages high — goes with [`MergeOptions::expected_floor`]). A
    /// pixel-channel with no sample above code 0 (or above the dark level) has no estimate.
    #[default]
    NoiseOptimal,
    /// The paper's hat, Debevec & Malik 1997 eq. (6): ln E = Σ w(Z)(g(Z) − ln Δt)/Σ w(Z) with
    /// w = [`crate::hat_weight`] (codes 0 and 255 dropped). Biased high for pixels whose brightest
    /// frame stays at a low code (noisy low codes are kept, zero codes dropped); see BENCHMARKS.md.
    DebevecHat,
}

/// Options of [`merge`]. Its fields are public: two enums, every combination valid (nothing to
/// check, unlike [`LinearMergeOptions`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct MergeOptions {
    /// Value of pixel-channels clipped in every exposure.
    pub clipped_fill: ClippedFill,
    /// Sample weighting (default [`Weighting::NoiseOptimal`]).
    pub weighting: Weighting,
    /// The expected-signal floor of [`Weighting::NoiseOptimal`] (default `None`: every frame
    /// counts): per channel (channel c uses entry min(c, 3)) a code below which a frame's reading
    /// of a pixel is left out of the merge *because of the signal it is expected to have*, not the
    /// code it shows. See [`merge`]'s second pass.
    pub expected_floor: Option<[u8; 4]>,
}

/// Options of [`merge_linear_u16`]; built through [`LinearMergeOptions::new`], so always valid.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinearMergeOptions {
    saturation: u16,
    clipped_fill: ClippedFill,
}

impl LinearMergeOptions {
    /// Options with the raw value at and above which a sample counts as saturated (many sensors
    /// clip below 65535, e.g. 4095 × 16 for 12-bit data; default 65535) and the value of
    /// pixel-channels clipped in every exposure.
    ///
    /// # Errors
    /// [`ImagingError::InvalidOption`] for a saturation below 2 (the hat weight needs a range).
    pub fn new(saturation: u16, clipped_fill: ClippedFill) -> Result<Self> {
        if saturation < 2 {
            return Err(ImagingError::InvalidOption {
                name: "saturation",
                value: f64::from(saturation),
                reason: "must be ≥ 2",
            });
        }
        Ok(Self {
            saturation,
            clipped_fill,
        })
    }

    /// The saturation level [raw value], ≥ 2.
    pub fn saturation(&self) -> u16 {
        self.saturation
    }

    /// The value of pixel-channels clipped in every exposure.
    pub fn clipped_fill(&self) -> ClippedFill {
        self.clipped_fill
    }
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
/// [`ImagingError::NoValidRadiance`] when fewer than [`MIN_VALID_FRACTION`] of a channel's pixels
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
    let clipped = ImageBuf::new(w, h, ch, mask)?;
    check_valid(&clipped)?;
    Ok(HdrImage {
        radiance: ImageBuf::new(w, h, ch, radiance)?,
        clipped,
        clipped_count,
    })
}

/// The half-width \[px\] of the square window over which [`refine_by_expected_signal`] averages the
/// first pass's radiance to predict each frame's signal: 5 × 5 pixels, so that a pixel's own
/// readings make up 1/25 of its prediction (see there).
const EXPECTED_SIGNAL_RADIUS: usize = 2;

/// The first pass of [`merge`], read by the second.
struct FirstPass<'a> {
    w: usize,
    ch: usize,
    radiance: &'a [f32],
    mask: &'a [u8],
}

/// The second pass of [`merge`] with an expected-signal floor ([`MergeOptions::expected_floor`]):
/// frame j's reading of a pixel-channel counts only if the signal it is *expected* to have,
/// Ê·Δt_j (plus the dark frame's X), reaches the floor code's X_c(floor), where Ê is the first
/// pass's radiance averaged over the (2·[`EXPECTED_SIGNAL_RADIUS`] + 1)² window around the pixel
/// (valid pixels only); the longest exposure always counts (it is the best the pixel has). Then
/// E = Σ_kept Δt_j u_j X_j / Σ_kept Δt_j² u_j as in the first pass.
///
/// Why: a frame whose signal is within a few noise σ of black reads code 0 for every negative
/// excursion of its noise (read noise is symmetric about the signal, the code is not), so its
/// mean linearised reading is biased *upward* — on a log curve at 15 e⁻ read noise the merged
/// radiance of a flat field was +1.6 % high where the longest frame expects code 40 and +10.9 %
/// at code 20 (BENCHMARKS.md, "Real cameras"). Choosing the frames by their *own* codes (drop the
/// zeros, or the codes below a threshold) would truncate the same noise from the other side. A
/// sample's variance — hence its weight — is a function of the unknown irradiance, not of the noisy
/// reading (Granados, Ajdin, Wand, Theobalt, Seidel & Lensch 2010, "Optimal HDR reconstruction with
/// linear digital cameras", CVPR, §4, evaluate it at the current estimate and iterate; Hasinoff,
/// Durand & Freeman 2010, "Noise-optimal capture for high dynamic range photography", CVPR, model
/// each frame's noise from the expected signal); here the weight is 0 or the first pass's. A
/// pixel's own first-pass estimate would still correlate the choice with the pixel's own noise
/// (the longest frame dominates it: where that frame read
/// high, a shorter frame gets in and pulls the estimate down: a bias of order −0.1 σ per pixel near
/// each frame's floor, by a Gaussian calculation); averaged over 25 pixels the pixel's own share,
/// and so that bias, is 25 times smaller. Measured (a flat field through a log curve, 15 e⁻ read
/// noise, the longest frame at code 40, floor 30): +1.7 % with every frame, +0.27 % with the floor
/// (`tests/merge.rs`).
/// A pixel-channel left without a usable sample keeps its first-pass value.
fn refine_by_expected_signal(
    frames: &[ImageBuf<u8>],
    times_s: &[f64],
    tables: &Tables,
    dark: Option<&ImageBuf<u8>>,
    x_floor: &[f64],
    pass: &FirstPass<'_>,
) -> Vec<f32> {
    let (w, ch) = (pass.w, pass.ch);
    let stride = w * ch;
    let h = pass.radiance.len() / stride.max(1);
    let r = EXPECTED_SIGNAL_RADIUS;
    let t_max = times_s.iter().copied().fold(0.0f64, f64::max);
    // Per frame and code, Δt·u(z) and Δt²·u(z) (the products the sums below are made of, formed
    // once), and per frame, channel and code Δt·u(z)·X_c(z), the numerator's term without a
    // dark frame.
    let u: [f64; LEVELS] = std::array::from_fn(|z| f64::from(tables.w[z]));
    let tu: Vec<[f64; LEVELS]> = times_s
        .iter()
        .map(|&t| std::array::from_fn(|z| t * u[z]))
        .collect();
    let ttu: Vec<[f64; LEVELS]> = times_s
        .iter()
        .map(|&t| std::array::from_fn(|z| t * t * u[z]))
        .collect();
    let tux: Vec<Vec<[f64; LEVELS]>> = tu
        .iter()
        .map(|tu_j| {
            (0..ch)
                .map(|c| std::array::from_fn(|z| tu_j[z] * tables.x[c][z]))
                .collect()
        })
        .collect();
    let mut out = pass.radiance.to_vec();
    out.par_chunks_mut(stride)
        .enumerate()
        .for_each(|(y, row_out)| {
            let row = y * stride..(y + 1) * stride;
            let rows: Vec<&[u8]> = frames.iter().map(|f| &f.data()[row.clone()]).collect();
            let dark_row = dark.map(|d| &d.data()[row.clone()]);
            // Window sums of the valid first-pass radiance: rows y − r ..= y + r, then along x.
            let (y0, y1) = (y.saturating_sub(r), (y + r).min(h - 1));
            let mut col_sum = vec![0.0f64; stride];
            let mut col_n = vec![0u32; stride];
            for yy in y0..=y1 {
                let base = yy * stride;
                let (m, v) = (
                    &pass.mask[base..base + stride],
                    &pass.radiance[base..base + stride],
                );
                for k in 0..stride {
                    if m[k] == 0 {
                        let v = f64::from(v[k]);
                        if v.is_finite() {
                            col_sum[k] += v;
                            col_n[k] += 1;
                        }
                    }
                }
            }
            let mask_row = &pass.mask[row.clone()];
            // ê per pixel-channel of the row: the window's mean valid radiance, or −1 where the
            // pixel-channel keeps its first-pass value (flagged, or no positive mean around it).
            let mut e_hat = vec![-1.0f64; stride];
            for x in 0..w {
                let (x0, x1) = (x.saturating_sub(r), (x + r).min(w - 1));
                for c in 0..ch {
                    let k = x * ch + c;
                    if mask_row[k] != 0 {
                        continue;
                    }
                    let (mut s, mut n) = (0.0f64, 0u32);
                    for xx in x0..=x1 {
                        s += col_sum[xx * ch + c];
                        n += col_n[xx * ch + c];
                    }
                    if n == 0 || s <= 0.0 {
                        continue;
                    }
                    e_hat[k] = s / f64::from(n);
                }
            }
            match (dark_row, ch) {
                (None, 1) => {
                    refine_pixels::<1>(&rows, times_s, t_max, &tux, &ttu, x_floor, &e_hat, row_out)
                }
                (None, 3) => {
                    refine_pixels::<3>(&rows, times_s, t_max, &tux, &ttu, x_floor, &e_hat, row_out)
                }
                (None, 4) => {
                    refine_pixels::<4>(&rows, times_s, t_max, &tux, &ttu, x_floor, &e_hat, row_out)
                }
                _ => {
                    for (k, &e) in e_hat.iter().enumerate() {
                        if e <= 0.0 {
                            continue;
                        }
                        let c = k % ch;
                        let xd = dark_row.map_or(0.0, |d| tables.x[c][usize::from(d[k])]);
                        let (mut nu, mut de) = (0.0f64, 0.0f64);
                        for (j, (zs, &t)) in rows.iter().zip(times_s).enumerate() {
                            if e * t + xd < x_floor[c] && t < t_max {
                                continue;
                            }
                            let z = usize::from(zs[k]);
                            nu += tu[j][z] * (tables.x[c][z] - xd);
                            de += ttu[j][z];
                        }
                        if nu > 0.0 && de > 0.0 {
                            row_out[k] = (nu / de) as f32;
                        }
                    }
                }
            }
        });
    out
}

/// One row of [`refine_by_expected_signal`] without a dark frame, `N` channels: a pixel's channels
/// summed together frame by frame (independent sums, each in the order of the frames, so each
/// value is the one a channel-by-channel loop gives: Σ Δt·u·X over the frames kept, over
/// Σ Δt²·u). `e_hat` is −1 where a pixel-channel keeps its first-pass value.
fn refine_pixels<const N: usize>(
    rows: &[&[u8]],
    times_s: &[f64],
    t_max: f64,
    tux: &[Vec<[f64; LEVELS]>],
    ttu: &[[f64; LEVELS]],
    x_floor: &[f64],
    e_hat: &[f64],
    row_out: &mut [f32],
) {
    let floor: [f64; N] = std::array::from_fn(|c| x_floor[c]);
    for (x, (e, out)) in e_hat
        .chunks_exact(N)
        .zip(row_out.chunks_exact_mut(N))
        .enumerate()
    {
        let active: [bool; N] = std::array::from_fn(|c| e[c] > 0.0);
        if !active.iter().any(|&a| a) {
            continue;
        }
        let (mut nu, mut de) = ([0.0f64; N], [0.0f64; N]);
        for ((zs, &t), (tx, tt)) in rows.iter().zip(times_s).zip(tux.iter().zip(ttu)) {
            let z = &zs[x * N..(x + 1) * N];
            let shorter = t < t_max;
            for c in 0..N {
                // Left out: expected below the floor, unless the longest exposure.
                let left_out = e[c] * t < floor[c] && shorter;
                if active[c] && !left_out {
                    let zi = usize::from(z[c]);
                    nu[c] += tx[c][zi];
                    de[c] += tt[zi];
                }
            }
        }
        for c in 0..N {
            if active[c] && nu[c] > 0.0 && de[c] > 0.0 {
                out[c] = (nu[c] / de[c]) as f32;
            }
        }
    }
}

/// The paper's hat over the code range above a dark frame's code `zd`: w = min(z − zd, 255 − z) for
/// zd < z < 255, else 0 (Debevec & Malik 1997, eq. 4 with Z_min = zd, Z_max = 255, the same
/// stretching as [`merge_linear_u16`]'s hat over [dark, saturation]). With zd = 0 this is
/// [`hat_weight`].
fn hat_weight_above(z: u8, zd: u8) -> f64 {
    if z <= zd || z == u8::MAX {
        0.0
    } else {
        f64::from((z - zd).min(u8::MAX - z))
    }
}

/// Lookup tables of [`merge`] (all fit in L1). Frame j adds to a pixel-channel's numerator
/// a_j·v_c(z) + b_j·w(z) and to its denominator d_j·w(z); the estimate is then exp(num/den) in the
/// log domain ([`Weighting::DebevecHat`]: w = hat, v_c = w·g_c, a = 1, b = −ln Δt, d = 1) or
/// num/den in the linear domain ([`Weighting::NoiseOptimal`]: w = u, v_c = u·X_c, a = Δt, b = 0,
/// d = Δt², with u(z) the per-code inverse noise variance and X_c(0) = 0).
struct Tables {
    w: [f32; LEVELS],
    v: Vec<[f32; LEVELS]>,
    /// Linear values X_c(z) used by the noise-aware weighting (X_c(0) = 0).
    x: Vec<[f64; LEVELS]>,
    a: Vec<f32>,
    b: Vec<f32>,
    d: Vec<f32>,
    log: bool,
}

impl Tables {
    fn new<'a>(
        weighting: Weighting,
        lin: &[Vec<f64>],
        g: impl Fn(usize) -> &'a [f64; LEVELS],
        times_s: &[f64],
    ) -> Self {
        let ch = lin.len();
        match weighting {
            Weighting::DebevecHat => Self {
                w: std::array::from_fn(|z| hat_weight(z as u8) as f32),
                v: (0..ch)
                    .map(|c| std::array::from_fn(|z| (hat_weight(z as u8) * g(c)[z]) as f32))
                    .collect(),
                x: Vec::new(),
                a: vec![1.0; times_s.len()],
                b: times_s.iter().map(|t| -t.ln() as f32).collect(),
                d: vec![1.0; times_s.len()],
                log: true,
            },
            Weighting::NoiseOptimal => {
                let x: Vec<[f64; LEVELS]> = lin
                    .iter()
                    .map(|l| std::array::from_fn(|z| if z == 0 { 0.0 } else { l[z] }))
                    .collect();
                let u = noise_weight();
                Self {
                    w: std::array::from_fn(|z| u[z] as f32),
                    v: x.iter()
                        .map(|xc| std::array::from_fn(|z| (u[z] * xc[z]) as f32))
                        .collect(),
                    x,
                    a: times_s.iter().map(|&t| t as f32).collect(),
                    b: vec![0.0; times_s.len()],
                    d: times_s.iter().map(|&t| (t * t) as f32).collect(),
                    log: false,
                }
            }
        }
    }
}

/// Per-code weight u(z) of the noise-aware merge: 1/σ²_X with a noise constant in the linear signal
/// (read noise before the tone curve), so u = 1, times the upper half of the paper's hat
/// (Debevec & Malik 1997, eq. 4) to fade out codes near saturation: u = min(1, (255 − z)/127).
fn noise_weight() -> [f64; LEVELS] {
    std::array::from_fn(|z| hat_weight(z.max(128) as u8) / 127.0)
}

/// Merges one row with the lookup tables: `out` receives the estimate where there is one and `den`
/// the denominator sums (0 where there is no estimate). Four pixels at a time, pixel-major.
fn merge_row_lut(rows: &[&[u8]], t: &Tables, out: &mut [f32], den: &mut [f32]) {
    #[inline(always)]
    fn finish(log: bool, nu: f32, d: f32) -> (f32, f32) {
        if log {
            if d > 0.0 {
                ((nu / d).exp(), d)
            } else {
                (0.0, 0.0)
            }
        } else if nu > 0.0 && d > 0.0 {
            (nu / d, d)
        } else {
            (0.0, 0.0)
        }
    }
    fn go<const N: usize>(rows: &[&[u8]], t: &Tables, out: &mut [f32], den: &mut [f32]) {
        let Some(v) = t.v.first_chunk::<N>() else {
            return;
        };
        let w_lut = &t.w;
        let coef: Vec<(f32, f32, f32)> =
            (0..rows.len()).map(|j| (t.a[j], t.b[j], t.d[j])).collect();
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
            for (row, &(ca, cb, cd)) in rows.iter().zip(&coef) {
                let Some(z) = row.get(base..base + PX * N) else {
                    continue;
                };
                for p in 0..PX {
                    for c in 0..N {
                        let zi = z[p * N + c] as usize;
                        let wv = w_lut[zi];
                        a[p][c] += ca * v[c][zi] + cb * wv;
                        dd[p][c] += cd * wv;
                    }
                }
            }
            for p in 0..PX {
                for c in 0..N {
                    let i = p * N + c;
                    (nu[i], d[i]) = finish(t.log, a[p][c], dd[p][c]);
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
            for (row, &(ca, cb, cd)) in rows.iter().zip(&coef) {
                let Some(z) = row.get(base..base + N) else {
                    continue;
                };
                for c in 0..N {
                    let zi = z[c] as usize;
                    let wv = w_lut[zi];
                    a[c] += ca * v[c][zi] + cb * wv;
                    dd[c] += cd * wv;
                }
            }
            for c in 0..N {
                (nu[c], d[c]) = finish(t.log, a[c], dd[c]);
            }
        }
    }
    match t.v.len() {
        1 => go::<1>(rows, t, out, den),
        3 => go::<3>(rows, t, out, den),
        4 => go::<4>(rows, t, out, den),
        ch => {
            out.fill(0.0);
            den.fill(0.0);
            for (j, row) in rows.iter().enumerate() {
                for (k, &z) in row.iter().enumerate() {
                    let wv = t.w[z as usize];
                    out[k] += t.a[j] * t.v[k % ch][z as usize] + t.b[j] * wv;
                    den[k] += t.d[j] * wv;
                }
            }
            for (nu, d) in out.iter_mut().zip(den.iter_mut()) {
                (*nu, *d) = finish(t.log, *nu, *d);
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
/// Bracket errors, a dark frame of another shape,
/// [`ImagingError::DarkFrameAboveSignal`], [`ImagingError::NoValidRadiance`] (as [`merge`]).
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
    let clipped = ImageBuf::new(w, h, ch, mask)?;
    check_valid(&clipped)?;
    Ok(HdrImage {
        radiance: ImageBuf::new(w, h, ch, radiance)?,
        clipped,
        clipped_count,
    })
}

/// Merges a linear bracket whose values carry a black level (raw files, linear 16-bit frames of a
/// camera that does not subtract it): the noise-aware linear-domain estimate of [`merge`]'s
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
    let clipped = ImageBuf::new(w, h, ch, mask)?;
    check_valid(&clipped)?;
    Ok(HdrImage {
        radiance: ImageBuf::new(w, h, ch, radiance)?,
        clipped,
        clipped_count,
    })
}
