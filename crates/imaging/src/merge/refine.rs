//! The second pass of the 8-bit merge: a frame's reading counts only where the signal it is
//! expected to have reaches the floor code.

use rayon::prelude::*;

use super::lut::Tables;
use crate::ImageBuf;
use crate::response::LEVELS;

/// The half-width \[px\] of the square window over which [`refine_by_expected_signal`] averages the
/// first pass's radiance to predict each frame's signal: 5 × 5 pixels, so that a pixel's own
/// readings make up 1/25 of its prediction (see there).
pub(super) const EXPECTED_SIGNAL_RADIUS: usize = 2;

/// The first pass of [`merge`], read by the second.
pub(super) struct FirstPass<'a> {
    pub(super) w: usize,
    pub(super) ch: usize,
    pub(super) radiance: &'a [f32],
    pub(super) mask: &'a [u8],
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
pub(super) fn refine_by_expected_signal(
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
pub(super) fn refine_pixels<const N: usize>(
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
