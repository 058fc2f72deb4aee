//! Filters in log exposure that remove what a bracket cannot see: a ripple of g with the period
//! of the bracket's exposure ratio (Grossberg & Nayar 2003's fractal ambiguity). The spline refit
//! with knots [`AMBIGUITY_KNOT_STEP`] periods apart, and the comb that averages g over one period.

use nalgebra::{DMatrix, DVector};

use super::curve::LEVELS;
use super::gsolve::hat_weight;
use super::solve::solve_least_squares;

/// Knot spacing of the response's final smoothing, in units of ln k (k: the bracket's median ratio
/// of consecutive exposure times): knots 1.2 ln k apart in log exposure barely follow a ripple of
/// period ln k, which the bracket's data cannot see (see [`recover_response`](crate::response::recover_response)). Measured on the twin's camera sweep
/// (BENCHMARKS.md): 1.2 and 1.5 remove most of the ripple; 2 bends the S-curve; 1.2 keeps the
/// S-curve's toe within 0.5 % from code 30 up, where 1.5 bends it by 0.9 %.
pub const AMBIGUITY_KNOT_STEP: f64 = 1.2;

/// The bracket's period in ln exposure: the median step between consecutive distinct ln Δt (the
/// period of the response's "fractal ambiguity", docs/physics.md §7.1a); `None` with fewer than two
/// distinct times.
fn bracket_period(ln_dt: &[f64]) -> Option<f64> {
    let mut steps: Vec<f64> = ln_dt
        .windows(2)
        .map(|w| (w[1] - w[0]).abs())
        .filter(|d| *d > 1e-9)
        .collect();
    if steps.is_empty() {
        return None;
    }
    steps.sort_by(f64::total_cmp);
    Some(steps[steps.len() / 2])
}

/// Least squares min |A x − b| by Householder QR (A has full column rank or `None`).
/// The recovered g refitted with a cubic regression spline whose knots lie a fixed step apart in
/// log exposure, `knot_step` times ln k (k: the bracket's median ratio of consecutive exposure
/// times), so that it cannot follow an oscillation of period ln k in ln X.
///
/// Why: with exposure times in a constant ratio k the data of the Debevec–Malik system cannot see
/// a perturbation of g that is periodic in ln X with period ln k — it shifts every frame's reading
/// of a pixel alike (Grossberg & Nayar 2003, "Determining the camera response from images: what
/// is knowable?", IEEE PAMI 25(11), §5, the "fractal ambiguity"); only the smoothness rows hold it,
/// and the merged radiance inherits it as a ripple of the same period in ln E (BENCHMARKS.md, "the
/// response recovery and the sweep"). A response smooth on the scale of ln k (here: a spline in z
/// with knots where g crosses levels ln k·`knot_step` apart, so dense where g is steep) has no
/// such component, while the smooth tone curves of real cameras are followed. Rows are weighted by
/// the hat weight (the recovery's confidence in each code); codes 0 and 255 keep their values,
/// clamped to stay monotone. `None` (keep g) when the spline would not rise everywhere or the
/// bracket has fewer than two distinct times.
pub(super) fn smooth_in_log_exposure(
    g: &[f64; LEVELS],
    ln_dt: &[f64],
    knot_step: f64,
) -> Option<[f64; LEVELS]> {
    let period = bracket_period(ln_dt)?;
    let delta = knot_step * period;
    let (lo, hi) = (g[1], g[LEVELS - 2]);
    if (hi - lo).is_nan() || hi - lo <= delta {
        return None;
    }
    // Interior knots in z where g crosses lo + kΔ.
    let mut knots = Vec::new();
    let mut level = lo + delta;
    while level < hi - 0.5 * delta {
        let z = (1..LEVELS - 1).find(|&z| g[z] >= level)?;
        let z0 = z - 1;
        let f = if g[z] > g[z0] {
            (level - g[z0]) / (g[z] - g[z0])
        } else {
            0.0
        };
        let k = z0 as f64 + f.clamp(0.0, 1.0);
        if knots.last().is_none_or(|&last: &f64| k > last + 1.0) {
            knots.push(k);
        }
        level += delta;
    }
    // Truncated-power cubic basis on x = z/255.
    let basis = |z: f64| -> Vec<f64> {
        let x = z / 255.0;
        let mut b = vec![1.0, x, x * x, x * x * x];
        b.extend(knots.iter().map(|k| (x - k / 255.0).max(0.0).powi(3)));
        b
    };
    let m = 4 + knots.len();
    let rows: Vec<usize> = (1..LEVELS - 1).collect();
    let mut a = DMatrix::<f64>::zeros(rows.len(), m);
    let mut b = DVector::<f64>::zeros(rows.len());
    for (r, &z) in rows.iter().enumerate() {
        let w = hat_weight(z as u8).max(1.0).sqrt();
        for (c, v) in basis(z as f64).into_iter().enumerate() {
            a[(r, c)] = w * v;
        }
        b[r] = w * g[z];
    }
    let coef = solve_least_squares(a, b)?;
    let mut out = *g;
    for (z, v) in out.iter_mut().enumerate().take(LEVELS - 1).skip(1) {
        *v = basis(z as f64)
            .iter()
            .zip(coef.iter())
            .map(|(x, c)| x * c)
            .sum();
    }
    if out[1..LEVELS - 1].windows(2).any(|w| w[1] < w[0]) {
        return None;
    }
    out[0] = g[0].min(out[1]);
    out[LEVELS - 1] = g[LEVELS - 1].max(out[LEVELS - 2]);
    let g128 = out[128];
    for v in &mut out {
        *v -= g128;
    }
    Some(out)
}

/// The lowest code [`comb_in_log_exposure`] filters (below it the curve is the toe's business and
/// ln z is too coarse).
const COMB_LO: usize = 10;

/// Removes from the response every component periodic in log exposure with the bracket's period
/// P = ln k (and its harmonics): the data of Debevec & Malik's system cannot see such a component
/// (Grossberg & Nayar 2003, "What is the space of camera response functions?", CVPR, and "Modeling
/// the space of camera response functions", IEEE PAMI 26(10) 2004 — the "fractal ambiguity";
/// docs/physics.md §7.1a), so whatever of it the solution holds is noise, and it reaches the
/// merged radiance as a ripple of period ln k in ln E — on the twin's camera sweep ±1–1.5 % on gamma 2.2
/// and the log curve at 15 e⁻, seen in the profile as a ring-to-ring alternation where the profile
/// falls by ln k every two rings and as a slow ripple where it falls slowly (BENCHMARKS.md).
///
/// How: the curve as ln z against u = ln X (on a grid P/32 fine, from code [`COMB_LO`] to 254,
/// extended beyond both ends by a parabola plus a sinusoid of period P fitted over the two end
/// periods, so that the ripple goes on to the ends) is filtered by a moving
/// average over exactly one period — whose transfer function is zero at the frequencies 1/P, 2/P,
/// … — applied with Tukey's twicing (2S − S∘S, Tukey 1977, *Exploratory Data Analysis*, ch. 16),
/// which keeps those zeros and reduces the average's bias on a curved tone curve from
/// P²/24·(ln z)″ to fourth order (a gamma curve's ln z is linear in u and is not moved at all).
/// The filtered curve is inverted back to g(z) on codes [`COMB_LO`]..=254; codes below keep their
/// values (capped to stay monotone). Its bias on a true curve is < 0.07 % in X on codes 20–240 of
/// gamma 2.2, sRGB, the log curve and a filmic S-curve; on the S-curve's shoulder (codes 244–250,
/// where ln z bends sharply) up to 0.8 %, codes the merge weights by ≤ 0.1 (the hat's upper half).
/// Codes 230–254 must be filtered all the same: through a log curve they span a whole period.
///
/// A curve of three periods or fewer (a linear 8-bit camera spans ln 25 = 3.2 in ln X: 2.6
/// periods at steps of 3.5×) leaves too little for the moving average and its end fits: there the
/// periodic part is fitted over the whole span — a cubic in u plus the first two harmonics of
/// period P, by least squares — and the harmonics are taken off (a cubic bends no true curve
/// over so short a span; measured on a linear camera at 3.5× and 4× steps: the profile's worst
/// shape error 6.6 % and 4.1 % before, 1.1 % after, BENCHMARKS.md "Real cameras").
///
/// `None` (keep g) when the bracket has fewer than two distinct times, the curve spans less than
/// [`SHORT_COMB_MIN_PERIODS`] periods, or the result would not rise.
pub(super) fn comb_in_log_exposure(g: &[f64; LEVELS], ln_dt: &[f64]) -> Option<[f64; LEVELS]> {
    let period = bracket_period(ln_dt)?;
    let (z_lo, z_hi) = (COMB_LO, LEVELS - 2);
    let (u_lo, u_hi) = (g[z_lo], g[z_hi]);
    let span = u_hi - u_lo;
    if span.is_nan()
        || span < SHORT_COMB_MIN_PERIODS * period
        || g[z_lo..=z_hi].windows(2).any(|w| w[1] < w[0])
    {
        return None;
    }
    // ln z at u by linear interpolation of the inverse of g (g non-decreasing on z_lo..=z_hi).
    let ln_code = |u: f64| -> f64 {
        let k = (z_lo..=z_hi)
            .find(|&z| g[z] >= u)
            .unwrap_or(z_hi)
            .max(z_lo + 1);
        let (g0, g1) = (g[k - 1], g[k]);
        let f = if g1 > g0 {
            ((u - g0) / (g1 - g0)).clamp(0.0, 1.0)
        } else {
            1.0
        };
        ((k - 1) as f64 + f).ln()
    };
    let per = 32usize;
    let h = period / per as f64;
    let n_in = ((u_hi - u_lo) / h).floor() as usize + 1;
    if span <= 3.0 * period {
        // Too few periods for the moving average and its end fits (a linear 8-bit camera spans
        // ln 25 = 3.2 in ln X: 2.6 periods of a bracket with k = 3.5): the periodic part is
        // fitted over the whole span instead — a cubic in u plus the first two harmonics of
        // period P by least squares — and the harmonics taken off.
        let tau = std::f64::consts::TAU / period;
        let o = 0.5 * (u_lo + u_hi);
        let basis = |u: f64| {
            let x = (u - o) / period;
            [
                1.0,
                x,
                x * x,
                x * x * x,
                (tau * u).sin(),
                (tau * u).cos(),
                (2.0 * tau * u).sin(),
                (2.0 * tau * u).cos(),
            ]
        };
        let mut design = DMatrix::<f64>::zeros(n_in, 8);
        let mut rhs = DVector::<f64>::zeros(n_in);
        for i in 0..n_in {
            let u = u_lo + i as f64 * h;
            for (c, v) in basis(u).into_iter().enumerate() {
                design[(i, c)] = v;
            }
            rhs[i] = ln_code(u);
        }
        let c = solve_least_squares(design, rhs)?;
        // On the span, ln z less the harmonics; half a period beyond each end, the cubic alone
        // (so that the end codes' crossings exist).
        let pad = per / 2;
        let u_at = |i: usize| u_lo + (i as f64 - pad as f64) * h;
        let mut filtered: Vec<f64> = (0..n_in + 2 * pad)
            .map(|i| {
                let u = u_at(i);
                let b = basis(u);
                if (u_lo..=u_hi).contains(&u) {
                    ln_code(u) - (4..8).map(|k| b[k] * c[k]).sum::<f64>()
                } else {
                    (0..4).map(|k| b[k] * c[k]).sum::<f64>()
                }
            })
            .collect();
        for i in 1..filtered.len() {
            filtered[i] = filtered[i].max(filtered[i - 1]);
        }
        return invert_filtered(g, &filtered, &u_at, h, z_lo, z_hi);
    }
    // Extensions beyond both ends: a parabola plus a sinusoid of period P, fitted over the two
    // end periods, so that the ripple continues and the average still cancels it there.
    let tau = std::f64::consts::TAU / period;
    // Centred on the fitted span's middle `o`, in units of P, for a well-conditioned fit.
    let basis = |u: f64, o: f64| {
        let x = (u - o) / period;
        [1.0, x, x * x, (tau * u).sin(), (tau * u).cos()]
    };
    let fit = |a: f64, b: f64| -> Option<(DVector<f64>, f64)> {
        let (m, o) = (64usize, 0.5 * (a + b));
        let mut design = DMatrix::<f64>::zeros(m + 1, 5);
        let mut rhs = DVector::<f64>::zeros(m + 1);
        for i in 0..=m {
            let u = a + (b - a) * i as f64 / m as f64;
            for (c, v) in basis(u, o).into_iter().enumerate() {
                design[(i, c)] = v;
            }
            rhs[i] = ln_code(u);
        }
        Some((solve_least_squares(design, rhs)?, o))
    };
    let end_lo = fit(u_lo, u_lo + 2.0 * period)?;
    let end_hi = fit(u_hi - 2.0 * period, u_hi)?;
    let extend = |(c, o): &(DVector<f64>, f64), u: f64| -> f64 {
        basis(u, *o).iter().zip(c.iter()).map(|(x, k)| x * k).sum()
    };
    let pad = 2 * per;
    let total = n_in + 2 * pad;
    let u_at = |i: usize| u_lo + (i as f64 - pad as f64) * h;
    let f: Vec<f64> = (0..total)
        .map(|i| {
            let u = u_at(i);
            if u < u_lo {
                extend(&end_lo, u)
            } else if u > u_hi {
                extend(&end_hi, u)
            } else {
                ln_code(u)
            }
        })
        .collect();
    // One period's moving average (trapezoid over per + 1 points), where the window fits.
    let average = |v: &[f64]| -> Vec<f64> {
        let half = per / 2;
        (0..v.len())
            .map(|i| {
                if i < half || i + half >= v.len() {
                    return v[i];
                }
                let w = &v[i - half..=i + half];
                let inner: f64 = w[1..w.len() - 1].iter().sum();
                (inner + 0.5 * (w[0] + w[w.len() - 1])) / per as f64
            })
            .collect()
    };
    // The extensions kept monotone (a parabola may turn over within a period of a shoulder).
    let mut f = f;
    for i in (0..pad).rev() {
        f[i] = f[i].min(f[i + 1]);
    }
    for i in pad + n_in..total {
        f[i] = f[i].max(f[i - 1]);
    }
    let s1 = average(&f);
    let s2 = average(&s1);
    // Twicing can dip by a hair where the curve flattens (a shoulder): kept non-decreasing.
    let mut filtered: Vec<f64> = s1.iter().zip(&s2).map(|(a, b)| 2.0 * a - b).collect();
    for i in 1..filtered.len() {
        filtered[i] = filtered[i].max(filtered[i - 1]);
    }
    invert_filtered(g, &filtered, &u_at, h, z_lo, z_hi)
}

/// How many of the bracket's periods ln k the curve spans over the codes the comb filters.
pub(super) fn spans_periods(g: &[f64; LEVELS], ln_dt: &[f64]) -> Option<f64> {
    let period = bracket_period(ln_dt)?;
    Some((g[LEVELS - 2] - g[COMB_LO]) / period)
}

/// The spans, in periods of the bracket, below which [`comb_in_log_exposure`] leaves a curve as it
/// is (too little of it to tell a period from a trend).
const SHORT_COMB_MIN_PERIODS: f64 = 1.5;

/// Back from a filtered ln z on the grid u_at(i) (step `h`) to g on codes `z_lo..=z_hi`: for each
/// code the u where the filtered ln z crosses ln z; codes below keep theirs (capped to stay
/// monotone), code 255 at least code 254's; the gauge g(128) = 0. `None` when a crossing is not
/// found or the result would not rise.
fn invert_filtered(
    g: &[f64; LEVELS],
    filtered: &[f64],
    u_at: &dyn Fn(usize) -> f64,
    h: f64,
    z_lo: usize,
    z_hi: usize,
) -> Option<[f64; LEVELS]> {
    let mut out = *g;
    for (z, v) in out.iter_mut().enumerate().take(z_hi + 1).skip(z_lo) {
        let target = (z as f64).ln();
        let k = filtered.iter().position(|&y| y >= target)?;
        if k == 0 {
            return None;
        }
        let (y0, y1) = (filtered[k - 1], filtered[k]);
        let t = if y1 > y0 {
            (target - y0) / (y1 - y0)
        } else {
            0.0
        };
        *v = u_at(k - 1) + t * h;
    }
    for z in (0..z_lo).rev() {
        out[z] = out[z].min(out[z + 1]);
    }
    out[LEVELS - 1] = g[LEVELS - 1].max(out[LEVELS - 2]);
    if out[1..LEVELS - 1].windows(2).any(|w| w[1] < w[0]) {
        return None;
    }
    let g128 = out[128];
    for v in &mut out {
        *v -= g128;
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// g(z) = ln T⁻¹(z/255) of a tone curve T (bisection), gauge g(128) = 0; code 0 a step below 1.
    fn true_g(t: impl Fn(f64) -> f64) -> [f64; LEVELS] {
        let inv = |v: f64| {
            let (mut lo, mut hi) = (0.0f64, 1.0f64);
            for _ in 0..80 {
                let mid = 0.5 * (lo + hi);
                if t(mid) < v { lo = mid } else { hi = mid }
            }
            0.5 * (lo + hi)
        };
        let mut g = [0.0; LEVELS];
        for (z, v) in g.iter_mut().enumerate().skip(1) {
            *v = inv(z as f64 / 255.0).ln();
        }
        g[0] = g[1] - 1.0;
        let g128 = g[128];
        g.map(|v| v - g128)
    }

    /// The spline keeps the smooth tone curves of the twin's camera sweep (sRGB, log, the filmic S-curve)
    /// within 0.5 % in X on codes 30–250, the codes above the detection limit (measured: 0.03 %,
    /// 0.05 %, 0.46 %), and cuts a 1 % ripple of period ln k in ln X (the fractal ambiguity of
    /// Grossberg & Nayar 2003) to under 0.5 % on codes 20–230 (measured: 0.35 %, 0.13 %, 0.45 %):
    /// without the refit the ripple stays whole (the test's `worst(&rippled) > 0.9 %`). (At the top end, codes 240–254, the spline's last segment
    /// follows the last half-period: 2 % at code 250 for a 1 % ripple; the merge fades those
    /// codes out.)
    #[test]
    fn the_spline_removes_the_invisible_ripple_and_keeps_the_curve() {
        let times: Vec<f64> = (0..13)
            .map(|j| (1.0f64 / 600.0) * (1800.0f64).powf(j as f64 / 12.0))
            .collect();
        let ln_dt: Vec<f64> = times.iter().map(|t| t.ln()).collect();
        let period = (ln_dt[1] - ln_dt[0]).abs();
        let srgb = |s: f64| {
            if s <= 0.003_130_8 {
                12.92 * s
            } else {
                1.055 * s.powf(1.0 / 2.4) - 0.055
            }
        };
        let log = |s: f64| (500.0 * s).ln_1p() / 501f64.ln();
        let aces = |x: f64| x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14);
        let s_curve = |s: f64| aces(4.0 * s) / aces(4.0);
        let curves: [(&str, &dyn Fn(f64) -> f64); 3] =
            [("srgb", &srgb), ("log", &log), ("s-curve", &s_curve)];
        for (name, t) in curves {
            let truth = true_g(t);
            let worst = |g: &[f64; LEVELS]| {
                (30..=250)
                    .map(|z| ((g[z] - g[128]) - (truth[z] - truth[128])).abs())
                    .fold(0.0f64, f64::max)
            };
            let kept = smooth_in_log_exposure(&truth, &ln_dt, AMBIGUITY_KNOT_STEP).unwrap();
            let at = (30..=250)
                .max_by(|&a, &b| {
                    let d = |z: usize| ((kept[z] - kept[128]) - (truth[z] - truth[128])).abs();
                    d(a).total_cmp(&d(b))
                })
                .unwrap_or(0);
            eprintln!(
                "{name}: the curve moved by {:.5} at most (code {at})",
                worst(&kept)
            );
            assert!(
                worst(&kept) < 5e-3,
                "{name}: the curve moved by {}",
                worst(&kept)
            );
            let mut rippled = truth;
            for (r, t) in rippled.iter_mut().zip(&truth).take(LEVELS - 1).skip(1) {
                *r += 0.01 * (std::f64::consts::TAU * t / period).sin();
            }
            assert!(worst(&rippled) > 9e-3, "{name}");
            let smoothed = smooth_in_log_exposure(&rippled, &ln_dt, AMBIGUITY_KNOT_STEP).unwrap();
            let left = (20..=230)
                .map(|z| ((smoothed[z] - smoothed[128]) - (truth[z] - truth[128])).abs())
                .fold(0.0f64, f64::max);
            eprintln!("{name}: a 1 % ripple left at {left:.5} on codes 20–230");
            assert!(left < 5e-3, "{name}: ripple left {left}");
        }
    }

    /// The comb in log exposure (`comb_in_log_exposure`): on four tone curves it moves the true
    /// curve by < 0.1 % on codes 20–240 (its bias), and it removes a 1.5 % ripple of period ln k in
    /// ln X — invisible to the data; the sweep's gamma 2.2 and log channels carried ±1–1.5 % of it
    /// after the spline — to < 0.2 % there (the S-curve: 0.5 %, see below).
    #[test]
    fn the_comb_removes_the_ripple_of_the_brackets_period() {
        let times: Vec<f64> = (0..13)
            .map(|j| (1.0f64 / 600.0) * (1800.0f64).powf(j as f64 / 12.0))
            .collect();
        let ln_dt: Vec<f64> = times.iter().map(|t| t.ln()).collect();
        let period = (ln_dt[1] - ln_dt[0]).abs();
        let gamma = |s: f64| s.powf(1.0 / 2.2);
        let srgb = |s: f64| {
            if s <= 0.003_130_8 {
                12.92 * s
            } else {
                1.055 * s.powf(1.0 / 2.4) - 0.055
            }
        };
        let log = |s: f64| (500.0 * s).ln_1p() / 501f64.ln();
        let aces = |x: f64| x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14);
        let s_curve = |s: f64| aces(4.0 * s) / aces(4.0);
        let curves: [(&str, &dyn Fn(f64) -> f64); 4] = [
            ("gamma 2.2", &gamma),
            ("srgb", &srgb),
            ("log", &log),
            ("s-curve", &s_curve),
        ];
        for (name, t) in curves {
            let truth = true_g(t);
            let off = |g: &[f64; LEVELS]| {
                (20..=240)
                    .map(|z| ((g[z] - g[128]) - (truth[z] - truth[128])).abs())
                    .fold(0.0f64, f64::max)
            };
            let kept = comb_in_log_exposure(&truth, &ln_dt).unwrap();
            let mut rippled = truth;
            for (r, t) in rippled.iter_mut().zip(&truth).take(LEVELS - 1).skip(1) {
                *r += 0.015 * (std::f64::consts::TAU * t / period).sin();
            }
            let combed = comb_in_log_exposure(&rippled, &ln_dt).unwrap();
            eprintln!(
                "{name}: the true curve moved by {:.5}; a 1.5 % ripple: {:.5} before the comb, \
                 {:.5} after (codes 20–240, ln X)",
                off(&kept),
                off(&rippled),
                off(&combed)
            );
            assert!(
                off(&kept) < 1e-3,
                "{name}: the curve moved by {}",
                off(&kept)
            );
            let at = (20..=240usize)
                .max_by(|&a, &b| {
                    let d = |z: usize| ((combed[z] - combed[128]) - (truth[z] - truth[128])).abs();
                    d(a).total_cmp(&d(b))
                })
                .unwrap_or(0);
            eprintln!("{name}: largest left at code {at}");
            // Toward the S-curve's shoulder (code ~200) its slope d ln z/d ln X falls fast, so the
            // ripple in ln z is not periodic there: 0.5 % is left.
            let bound = if name == "s-curve" { 6e-3 } else { 2e-3 };
            assert!(off(&combed) < bound, "{name}: ripple left {}", off(&combed));
            assert!(off(&rippled) > 0.014, "{name}");
        }
    }

    /// The comb on a curve of fewer than three periods (its whole-span fit): a linear camera and
    /// gamma 1.1 in a bracket of 7 frames 3.5× apart (2.6 and 2.8 periods in ln X) — the true curve
    /// is moved by < 0.2 % in X on codes 20–240, and a 2 % ripple of period ln 3.5 (with a 0.5 %
    /// second harmonic) is left at < 0.3 %; under 1.5 periods (a 2-frame bracket 40× apart) the
    /// curve is kept as it is.
    #[test]
    fn the_comb_holds_the_ripple_of_a_wide_bracket() {
        let times: Vec<f64> = (0..7).map(|j| 3.5f64.powi(j) / 600.0).collect();
        let ln_dt: Vec<f64> = times.iter().map(|t| t.ln()).collect();
        let period = 3.5f64.ln();
        let linear = |s: f64| s;
        let gamma = |s: f64| s.powf(1.0 / 1.1);
        let curves: [(&str, &dyn Fn(f64) -> f64); 2] = [("linear", &linear), ("gamma 1.1", &gamma)];
        for (name, t) in curves {
            let truth = true_g(t);
            let periods = spans_periods(&truth, &ln_dt).unwrap();
            assert!((1.5..=3.0).contains(&periods), "{name}: {periods}");
            let off = |g: &[f64; LEVELS]| {
                (20..=240)
                    .map(|z| ((g[z] - g[128]) - (truth[z] - truth[128])).abs())
                    .fold(0.0f64, f64::max)
            };
            let kept = comb_in_log_exposure(&truth, &ln_dt).unwrap();
            let mut rippled = truth;
            for (r, t) in rippled.iter_mut().zip(&truth).take(LEVELS - 1).skip(1) {
                let phase = std::f64::consts::TAU * t / period;
                *r += 0.02 * (phase + 0.4).sin() + 0.005 * (2.0 * phase).cos();
            }
            let combed = comb_in_log_exposure(&rippled, &ln_dt).unwrap();
            eprintln!(
                "{name} ({periods:.2} periods): the true curve moved by {:.5}; the ripple {:.5} \
                 before, {:.5} after",
                off(&kept),
                off(&rippled),
                off(&combed)
            );
            assert!(off(&kept) < 2e-3, "{name}: moved by {}", off(&kept));
            assert!(off(&rippled) > 0.018, "{name}");
            assert!(off(&combed) < 3e-3, "{name}: left {}", off(&combed));
        }
        let two = [(1.0f64 / 600.0).ln(), (40.0f64 / 600.0).ln()];
        let truth = true_g(linear);
        assert!(spans_periods(&truth, &two).unwrap() < 1.5);
        assert!(comb_in_log_exposure(&truth, &two).is_none());
    }
}
