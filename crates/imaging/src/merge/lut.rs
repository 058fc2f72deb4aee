//! The 8-bit merge's per-code lookup tables (hat or noise-optimal weights, linearised values) and
//! the row kernel that accumulates a frame's readings through them.

use super::options::Weighting;
use crate::response::{LEVELS, hat_weight};

/// The paper's hat over the code range above a dark frame's code `zd`: w = min(z − zd, 255 − z) for
/// zd < z < 255, else 0 (Debevec & Malik 1997, eq. 4 with Z_min = zd, Z_max = 255, the same
/// stretching as [`merge_linear_u16`]'s hat over [dark, saturation]). With zd = 0 this is
/// [`hat_weight`].
pub(super) fn hat_weight_above(z: u8, zd: u8) -> f64 {
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
pub(super) struct Tables {
    pub(super) w: [f32; LEVELS],
    pub(super) v: Vec<[f32; LEVELS]>,
    /// Linear values X_c(z) used by the noise-aware weighting (X_c(0) = 0).
    pub(super) x: Vec<[f64; LEVELS]>,
    pub(super) a: Vec<f32>,
    pub(super) b: Vec<f32>,
    pub(super) d: Vec<f32>,
    pub(super) log: bool,
}

impl Tables {
    pub(super) fn new<'a>(
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
pub(super) fn noise_weight() -> [f64; LEVELS] {
    std::array::from_fn(|z| hat_weight(z.max(128) as u8) / 127.0)
}

/// Merges one row with the lookup tables: `out` receives the estimate where there is one and `den`
/// the denominator sums (0 where there is no estimate). Four pixels at a time, pixel-major.
pub(super) fn merge_row_lut(rows: &[&[u8]], t: &Tables, out: &mut [f32], den: &mut [f32]) {
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
