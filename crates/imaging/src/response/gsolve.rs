//! Debevec & Malik's least-squares system for one channel (their appendix `gsolve`, with the hat
//! weight of eq. 4), solved in g alone after eliminating each pixel's ln E.

use nalgebra::DVector;

use super::curve::LEVELS;
use super::samples::MAX_RESPONSE_SAMPLES;
use super::solve::{SparseRows, solve_monotone};
use crate::error::{ImagingError, Result};

/// The paper's hat weight, Debevec & Malik 1997, eq. (4) with Z_min = 0, Z_max = 255:
/// w(z) = z − Z_min for z ≤ ½(Z_min + Z_max), Z_max − z otherwise. So w(0) = w(255) = 0 (clipped codes
/// carry no weight) and w(127) = w(128) = 127.
pub fn hat_weight(z: u8) -> f64 {
    let z = f64::from(z);
    if z <= 127.5 { z } else { 255.0 - z }
}

/// One channel's solution of the Debevec–Malik system.
#[derive(Debug, Clone, PartialEq)]
pub struct ChannelSolution {
    /// g(0..=255) in the gauge g(128) = 0.
    pub g: [f64; LEVELS],
    /// ln E_i of each sample pixel (same gauge); NaN for a pixel with no unclipped sample.
    pub ln_e: Vec<f64>,
    /// Root mean square of the weighted data residuals w(Z_ij)(g(Z_ij) − ln E_i − ln Δt_j).
    pub rms_residual: f64,
}

/// Solves Debevec & Malik's least-squares system for one channel (the paper's appendix `gsolve`,
/// docs/physics.md §7.1): unknowns g(0..=255) and ln E_i; data rows w(Z_ij)(g(Z_ij) − ln E_i) = w(Z_ij) ln Δt_j,
/// the gauge row g(128) = 0, and smoothness rows λ w(z)(g(z−1) − 2g(z) + g(z+1)) = 0 for z = 1..=254,
/// with the hat weight [`hat_weight`].
///
/// `z` holds the code values row by row: pixel i's value in frame j is `z[i * ln_dt.len() + j]`;
/// `ln_dt[j]` = ln Δt_j.
///
/// The ln E_i are eliminated exactly (variable projection: for fixed g each ln E_i is the weighted
/// mean Σ_j w²(g − ln Δt)/Σ_j w², and each pixel's block of rows is projected onto the complement of
/// its weight vector), leaving a sparse (N·P + 255) × 256 problem in g, solved by the corrected
/// semi-normal equations (`solve_sparse_least_squares`: to Householder QR's accuracy at a few
/// per cent of its cost) — the same minimiser as the full (N·P + 257) × (256 + N) system.
///
/// # Errors
/// [`ImagingError::InvalidOption`] for a bad λ or mismatched lengths, [`ImagingError::SolveFailed`] if
/// the system is rank deficient.
pub fn gsolve(z: &[u8], ln_dt: &[f64], lambda: f64, channel: usize) -> Result<ChannelSolution> {
    let p = ln_dt.len();
    if p < 2 {
        return Err(ImagingError::TooFewFrames { got: p });
    }
    if !z.len().is_multiple_of(p) {
        return Err(ImagingError::InvalidOption {
            name: "z",
            value: z.len() as f64,
            reason: "length must be a multiple of the number of exposures",
        });
    }
    if !(lambda.is_finite() && lambda >= 0.0) {
        return Err(ImagingError::InvalidOption {
            name: "lambda",
            value: lambda,
            reason: "must be finite and ≥ 0",
        });
    }
    let n = z.len() / p;
    if n > MAX_RESPONSE_SAMPLES {
        return Err(ImagingError::SampleCount {
            samples: n,
            frames: p,
            min: 1,
            max: MAX_RESPONSE_SAMPLES,
        });
    }
    let rows = n * p + 1 + (LEVELS - 2);
    let mut a = SparseRows::new(LEVELS);
    let mut b = DVector::<f64>::zeros(rows);
    let mut k = 0;
    let mut w = vec![0.0; p];
    // One row's values by code, accumulated as a dense row would be, and the codes it touches.
    let mut row = [0.0f64; LEVELS];
    let mut touched: Vec<usize> = Vec::with_capacity(p);
    for i in 0..n {
        let zi = &z[i * p..(i + 1) * p];
        for j in 0..p {
            w[j] = hat_weight(zi[j]);
        }
        let norm2: f64 = w.iter().map(|v| v * v).sum();
        if norm2 == 0.0 {
            // No unclipped sample: the pixel carries no information about g.
            continue;
        }
        // Row block W S g − W ℓ, projected by (I − u uᵀ), u = w/|w|, which removes ln E_i exactly.
        // Projected row j: w_j e_{Z_j} − (w_j/|w|²) Σ_m w_m² e_{Z_m};  rhs likewise with ln Δt.
        let s_rhs: f64 = (0..p).map(|m| w[m] * w[m] * ln_dt[m]).sum::<f64>() / norm2;
        touched.clear();
        touched.extend(zi.iter().map(|&v| usize::from(v)));
        touched.sort_unstable();
        touched.dedup();
        for j in 0..p {
            if w[j] == 0.0 {
                // The projected row is zero.
                a.push_row([]);
                k += 1;
                continue;
            }
            row[usize::from(zi[j])] += w[j];
            let f = w[j] / norm2;
            for m in 0..p {
                row[usize::from(zi[m])] -= f * w[m] * w[m];
            }
            a.push_row(touched.iter().map(|&c| (c, std::mem::take(&mut row[c]))));
            b[k] = w[j] * ln_dt[j] - w[j] * s_rhs;
            k += 1;
        }
    }
    // Gauge g(128) = 0 (appendix: A(k,129) = 1).
    a.push_row([(128, 1.0)]);
    k += 1;
    // Smoothness, eq. (3): λ w(z) [g(z−1) − 2 g(z) + g(z+1)] = 0, z = 1..=254.
    for zz in 1..LEVELS - 1 {
        let lw = lambda * hat_weight(zz as u8);
        a.push_row([(zz - 1, lw), (zz, -2.0 * lw), (zz + 1, lw)]);
        k += 1;
    }
    debug_assert_eq!(k, rows);
    debug_assert_eq!(a.nrows(), rows);
    let g_vec = solve_monotone(&a, b).ok_or(ImagingError::SolveFailed {
        channel,
        reason: "the system is rank deficient (too few distinct code values among the samples?)",
    })?;
    let mut g = [0.0; LEVELS];
    g.copy_from_slice(g_vec.as_slice());
    // The gauge row holds to rounding error (~1e-11); make it exact. Shifting g by a constant leaves
    // every other residual unchanged (ln E below shifts with it).
    let g128 = g[128];
    for v in &mut g {
        *v -= g128;
    }
    if g.iter().any(|v| !v.is_finite()) {
        return Err(ImagingError::SolveFailed {
            channel,
            reason: "solution is not finite",
        });
    }
    Ok(ChannelSolution::with_g(g, z, ln_dt))
}

impl ChannelSolution {
    /// The solution for a given g: each pixel's ln E_i (the hat-weighted mean of eq. 6 with
    /// weights w², as in [`gsolve`]'s elimination) and the weighted data residual.
    pub(super) fn with_g(g: [f64; LEVELS], z: &[u8], ln_dt: &[f64]) -> Self {
        let p = ln_dt.len();
        let n = z.len() / p;
        let mut ln_e = Vec::with_capacity(n);
        let (mut ss, mut cnt) = (0.0, 0usize);
        for i in 0..n {
            let zi = &z[i * p..(i + 1) * p];
            let (mut num, mut den) = (0.0, 0.0);
            for j in 0..p {
                let wj = hat_weight(zi[j]);
                num += wj * wj * (g[zi[j] as usize] - ln_dt[j]);
                den += wj * wj;
            }
            if den == 0.0 {
                ln_e.push(f64::NAN);
                continue;
            }
            let le = num / den;
            for j in 0..p {
                let r = hat_weight(zi[j]) * (g[zi[j] as usize] - le - ln_dt[j]);
                ss += r * r;
                cnt += 1;
            }
            ln_e.push(le);
        }
        let rms_residual = if cnt > 0 {
            (ss / cnt as f64).sqrt()
        } else {
            0.0
        };
        ChannelSolution {
            g,
            ln_e,
            rms_residual,
        }
    }
}
