//! The smoother that turns a noisy Monte Carlo radial profile into a smooth, differentiable one.
//!
//! Model, per albedo a (optical radius ρ = σt r, u = ln ρ):
//! ```text
//! ln R̂(ρ; a) = S(u) − κ₀(a)·ρ,      S(u) = Σₘ βₘ Bₘ(u)
//! ```
//! with Bₘ the uniform cubic B-splines on knots spaced h in u, and κ₀ the decay constant of the
//! transport equation's slowest mode (Case & Zweifel 1967, ch. 4: the root of (a/2κ)ln((1+κ)/(1−κ)) = 1
//! for isotropic scattering), so that far from the source, where R̂ ∝ ρ^p e^{−κ₀ρ}, S is linear in u.
//! The coefficients are a penalised least-squares fit (P-spline, Eilers & Marx 1996, Statist. Sci.
//! 11:89): Σⱼ (ln Āⱼ(β) − yⱼ)²/σⱼ² + λ Σₘ (Δ²βₘ)², where Āⱼ is the model averaged over annulus j
//! exactly as the Monte Carlo tally averages it (3-point Gauss–Legendre in u per bin), yⱼ = ln R̂ⱼ +
//! σⱼ²/2 (the second-order correction of E[ln X] for a noisy X) and σⱼ the bin's relative standard
//! error, averaged over five neighbouring bins so that the weights do not follow the noise. Only the
//! bins out to where that averaged relative error first exceeds [`SmoothParams::max_rel_se`] enter;
//! beyond them the second-difference penalty continues S linearly in u (a power law times e^{−κ₀ρ}),
//! and the table records that last radius as the end of the data. Solved by Gauss–Newton from the
//! linear fit at bin centres (a few iterations; the normal equations are 50 × 50).

use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

/// Knobs of the smoother.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SmoothParams {
    /// Knot spacing h in u = ln ρ.
    pub knot_spacing: f64,
    /// Penalty weight λ on squared second differences of the coefficients (in χ² units).
    pub lambda: f64,
    /// Bins are used where the (neighbour-averaged) relative standard error stays below this.
    pub max_rel_se: f64,
}

impl Default for SmoothParams {
    fn default() -> Self {
        Self {
            knot_spacing: 0.25,
            lambda: 3.0,
            max_rel_se: 0.15,
        }
    }
}

/// κ₀(a) and dκ₀/da: the decay constant of the asymptotic (diffusion) mode of the one-speed transport
/// equation with isotropic scattering at σt = 1, root of a·artanh(κ)/κ = 1 in (0, 1) (Case & Zweifel
/// 1967, eq. 4.19 context). For Henyey–Greenstein g ≠ 0 we use the isotropic root at the reduced
/// albedo a′ = a(1 − g)/(1 − ag) scaled by σ′t/σt = 1 − ag (the similarity relation) — only a
/// coordinate for the smoother, which absorbs the difference.
pub fn kappa0(a: f64, g: f64) -> (f64, f64) {
    let (scale, ap, dap_da) = if g == 0.0 {
        (1.0, a, 1.0)
    } else {
        let den = 1.0 - a * g;
        (den, a * (1.0 - g) / den, (1.0 - g) / (den * den))
    };
    let (k, dk) = kappa_iso(ap);
    if g == 0.0 {
        (k, dk)
    } else {
        // d/da [(1 − ag) κ(a′)] = −g κ + (1 − ag) κ′ a′′.
        (scale * k, -g * k + scale * dk * dap_da)
    }
}

/// Isotropic κ₀(a) and its derivative, a ∈ (0, 1). For a ≥ 0.25 Newton on
/// F(κ) = artanh(κ)/κ − 1/a from the diffusion value √(3(1 − a)) (clamped below 1); below, κ is within
/// 1e-3 of 1 and not resolvable that way, so Newton runs on L = ln(1 − κ) for
/// G(L) = (a/2)(ln(2 − e^L) − L) − (1 − e^L), from the asymptote L = ln 2 − 2/a. The derivative from
/// a·artanh(κ) = κ: dκ/da = −(κ/a)/(a/(1 − κ²) − 1), with 1 − κ² = ε(2 − ε), ε = 1 − κ.
fn kappa_iso(a: f64) -> (f64, f64) {
    if a >= 1.0 {
        return (0.0, f64::NEG_INFINITY);
    }
    let (k, eps) = if a >= 0.25 {
        let mut k = (3.0 * (1.0 - a)).sqrt().min(0.999);
        // F = (artanh(κ)/κ − 1) − (1 − a)/a: both parts are small near a = 1, so the first comes from
        // its series Σ κ²ⁿ/(2n + 1) there (κ < 0.3), keeping κ to full precision.
        let target = (1.0 - a) / a;
        let excess = |k: f64| {
            if k < 0.3 {
                let (k2, mut term, mut sum) = (k * k, 1.0, 0.0);
                for n in 1..40 {
                    term *= k2;
                    sum += term / (2 * n + 1) as f64;
                }
                sum
            } else {
                k.atanh() / k - 1.0
            }
        };
        for _ in 0..100 {
            let at = k.atanh();
            let f = excess(k) - target;
            let df = 1.0 / (k * (1.0 - k * k)) - at / (k * k);
            let mut next = k - f / df;
            if !(next > 0.0 && next < 1.0) {
                next = if next <= 0.0 {
                    0.5 * k
                } else {
                    0.5 * (k + 1.0)
                };
            }
            let done = (next - k).abs() <= 1e-15 * k;
            k = next;
            if done {
                break;
            }
        }
        (k, 1.0 - k)
    } else {
        let mut l = std::f64::consts::LN_2 - 2.0 / a;
        for _ in 0..100 {
            let e = l.exp();
            let g = 0.5 * a * ((2.0 - e).ln() - l) - (1.0 - e);
            let dg = -a / (2.0 - e) + e;
            let next = l - g / dg;
            let done = (next - l).abs() <= 1e-14 * l.abs();
            l = next;
            if done {
                break;
            }
        }
        (-l.exp_m1(), l.exp())
    };
    let one_minus_k2 = eps * (2.0 - eps);
    (k, -(k / a) / (a / one_minus_k2 - 1.0))
}

/// Uniform cubic B-splines on [u₀, u₀ + n·h] (n intervals, n + 3 functions), extended linearly
/// outside (value and slope at the ends).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Knots {
    /// Start u₀.
    pub u0: f64,
    /// Spacing h.
    pub h: f64,
    /// Number of intervals n.
    pub intervals: usize,
}

/// The spline and its u-derivative at u: the first function index and the 4 weights of each.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Basis {
    pub first: usize,
    pub w: [f64; 4],
    pub dw: [f64; 4],
}

impl Knots {
    /// Knots spaced about `h` covering [u_lo, u_hi] exactly.
    pub fn covering(u_lo: f64, u_hi: f64, h: f64) -> Self {
        let intervals = ((u_hi - u_lo) / h).ceil().max(1.0) as usize;
        Self {
            u0: u_lo,
            h: (u_hi - u_lo) / intervals as f64,
            intervals,
        }
    }

    /// Number of basis functions.
    pub fn len(&self) -> usize {
        self.intervals + 3
    }

    /// Never empty (at least 4 functions).
    pub fn is_empty(&self) -> bool {
        false
    }

    /// Weights at u; outside the range, S(u) = S(end) + S′(end)(u − end).
    pub(crate) fn basis(&self, u: f64) -> Basis {
        let x = (u - self.u0) / self.h;
        let n = self.intervals as f64;
        let (q, t, ext) = if x < 0.0 {
            (0, 0.0, x)
        } else if x >= n {
            (self.intervals - 1, 1.0, x - n)
        } else {
            let q = (x as usize).min(self.intervals - 1);
            (q, x - q as f64, 0.0)
        };
        let (t2, t3) = (t * t, t * t * t);
        let mut w = [
            (1.0 - t).powi(3) / 6.0,
            (3.0 * t3 - 6.0 * t2 + 4.0) / 6.0,
            (-3.0 * t3 + 3.0 * t2 + 3.0 * t + 1.0) / 6.0,
            t3 / 6.0,
        ];
        let dt = [
            -0.5 * (1.0 - t) * (1.0 - t),
            (9.0 * t2 - 12.0 * t) / 6.0,
            (-9.0 * t2 + 6.0 * t + 3.0) / 6.0,
            0.5 * t2,
        ];
        let inv_h = 1.0 / self.h;
        let dw = dt.map(|d| d * inv_h);
        if ext != 0.0 {
            for (wi, di) in w.iter_mut().zip(dt) {
                *wi += di * ext;
            }
        }
        Basis { first: q, w, dw }
    }
}

/// 3-point Gauss–Legendre on [−1, 1]: nodes 0, ±√(3/5), weights 8/9, 5/9.
const GL3: [(f64, f64); 3] = [
    (-0.774_596_669_241_483_4, 5.0 / 9.0),
    (0.0, 8.0 / 9.0),
    (0.774_596_669_241_483_4, 5.0 / 9.0),
];

/// A smoothed row: coefficients and the optical radius where its data end.
#[derive(Debug, Clone, PartialEq)]
pub struct RowFit {
    /// βₘ.
    pub coefs: Vec<f64>,
    /// Inner edge of the first bin used [mean free paths].
    pub rho_data_min: f64,
    /// Outer edge of the last bin used [mean free paths].
    pub rho_data_max: f64,
    /// χ² of the used bins against the fit, and their number.
    pub chi2: f64,
    /// Bins used.
    pub bins_used: usize,
}

/// Fits one albedo row: `edges` (first 0) and per-bin `rd`, `se` at σt = 1; κ = κ₀(a).
/// Returns `None` when fewer than 4 bins have data.
pub fn fit_row(
    edges: &[f64],
    rd: &[f64],
    se: &[f64],
    kappa: f64,
    knots: &Knots,
    params: &SmoothParams,
) -> Option<RowFit> {
    let bins = rd.len();
    // Relative errors, neighbour-averaged in variance (empty bins count as infinitely noisy).
    let rel2: Vec<f64> = (0..bins)
        .map(|j| {
            if rd[j] > 0.0 {
                (se[j] / rd[j]).powi(2)
            } else {
                f64::INFINITY
            }
        })
        .collect();
    let avg: Vec<f64> = (0..bins)
        .map(|j| {
            let (lo, hi) = (j.saturating_sub(2), (j + 2).min(bins - 1));
            rel2[lo..=hi].iter().sum::<f64>() / (hi - lo + 1) as f64
        })
        .collect();
    // The longest run of consecutive bins (from bin 1: the first, [0, ρ₀), is outside the spline)
    // whose averaged relative error is within bounds: the innermost bins are tiny annuli and can be
    // noisy too.
    let max2 = params.max_rel_se * params.max_rel_se;
    let (mut best, mut start) = ((0, 0), None);
    for j in 1..=bins {
        let ok = avg.get(j).is_some_and(|&v| v <= max2);
        match (ok, start) {
            (true, None) => start = Some(j),
            (false, Some(s)) => {
                if j - s > best.1 - best.0 {
                    best = (s, j);
                }
                start = None;
            }
            _ => {}
        }
    }
    let used: Vec<usize> = (best.0..best.1).filter(|&j| rd[j] > 0.0).collect();
    if used.len() < 4 {
        return None;
    }
    let m = knots.len();
    // Per used bin: quadrature nodes (u, weight·2πρ², basis) and the data.
    struct Bin {
        nodes: [(f64, f64, Basis); 3],
        area: f64,
        y: f64,
        sigma: f64,
    }
    let data: Vec<Bin> = used
        .iter()
        .map(|&j| {
            let (a, b) = (edges[j].ln(), edges[j + 1].ln());
            let (h, c) = (0.5 * (b - a), 0.5 * (a + b));
            let nodes = GL3.map(|(x, w)| {
                let u = c + h * x;
                let rho = u.exp();
                (
                    u,
                    w * h * 2.0 * std::f64::consts::PI * rho * rho,
                    knots.basis(u),
                )
            });
            let rel2 = avg[j];
            Bin {
                nodes,
                area: std::f64::consts::PI * (edges[j + 1].powi(2) - edges[j].powi(2)),
                y: rd[j].ln() + 0.5 * rel2,
                sigma: rel2.sqrt(),
            }
        })
        .collect();
    // Penalty DᵀD (second differences).
    let mut penalty = DMatrix::<f64>::zeros(m, m);
    for i in 0..m - 2 {
        let d = [1.0, -2.0, 1.0];
        for (p, dp) in d.iter().enumerate() {
            for (q, dq) in d.iter().enumerate() {
                penalty[(i + p, i + q)] += params.lambda * dp * dq;
            }
        }
    }
    // Start: linear fit of the point values at the bin's middle node.
    let mut beta = {
        let mut ata = penalty.clone();
        let mut atb = DVector::<f64>::zeros(m);
        for bin in &data {
            let (u, _, basis) = bin.nodes[1];
            let target = bin.y + kappa * u.exp();
            let wgt = 1.0 / (bin.sigma * bin.sigma);
            for p in 0..4 {
                let ip = basis.first + p;
                atb[ip] += wgt * basis.w[p] * target;
                for q in 0..4 {
                    ata[(ip, basis.first + q)] += wgt * basis.w[p] * basis.w[q];
                }
            }
        }
        ata.cholesky()?.solve(&atb)
    };
    // Gauss–Newton on the bin averages.
    let mut chi2 = 0.0;
    for _ in 0..30 {
        let mut jtj = penalty.clone();
        let mut grad = &penalty * &beta;
        chi2 = 0.0;
        for bin in &data {
            let mut total = 0.0;
            let mut dtotal = [0.0; 6];
            let mut idx = [0usize; 6];
            let first = bin.nodes[0].2.first;
            for (k, slot) in idx.iter_mut().enumerate() {
                *slot = first + k;
            }
            for &(u, w, basis) in &bin.nodes {
                let s: f64 = (0..4).map(|p| basis.w[p] * beta[basis.first + p]).sum();
                let f = w * (s - kappa * u.exp()).exp();
                total += f;
                for p in 0..4 {
                    dtotal[basis.first + p - first] += f * basis.w[p];
                }
            }
            let ln_a = (total / bin.area).ln();
            let inv_s = 1.0 / bin.sigma;
            let r = (ln_a - bin.y) * inv_s;
            chi2 += r * r;
            // ∂ ln Ā/∂βₘ = ∫ f Bₘ / ∫ f.
            let span = (bin.nodes[2].2.first - first) + 4;
            for p in 0..span {
                let jp = dtotal[p] / total * inv_s;
                grad[idx[p]] += jp * r;
                for q in 0..span {
                    jtj[(idx[p], idx[q])] += jp * dtotal[q] / total * inv_s;
                }
            }
        }
        let step = jtj.cholesky()?.solve(&(-grad));
        beta += &step;
        if step.amax() < 1e-10 {
            break;
        }
    }
    let last = *used.last().expect("≥ 4 bins");
    Some(RowFit {
        coefs: beta.iter().copied().collect(),
        rho_data_min: edges[used[0]],
        rho_data_max: edges[last + 1],
        chi2,
        bins_used: used.len(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// κ₀ solves its equation; near a = 1 it tends to the diffusion value √(3(1 − a)); its derivative
    /// matches a central difference; low albedo tends to 1.
    #[test]
    fn kappa0_root_and_derivative() {
        for a in [0.05, 0.2, 0.26, 0.3, 0.6, 0.9, 0.99, 0.9999] {
            let (k, dk) = kappa0(a, 0.0);
            // a·artanh(κ) = κ, with artanh(κ) = ½ ln((2 − ε)/ε) evaluated from ε = 1 − κ.
            let eps = 1.0 - k;
            if eps > 1e-12 {
                assert!((a * k.atanh() / k - 1.0).abs() < 1e-10, "a = {a}");
            }
            let h = 1e-6 * (1.0 - a).min(a);
            let fd = (kappa0(a + h, 0.0).0 - kappa0(a - h, 0.0).0) / (2.0 * h);
            assert!(
                (dk - fd).abs() < 1e-6 * fd.abs() + 1e-12,
                "a = {a}: {dk} vs {fd}"
            );
        }
        let a: f64 = 0.99999;
        assert!((kappa0(a, 0.0).0 / (3.0 * (1.0 - a)).sqrt() - 1.0).abs() < 1e-5);
        // Low albedo: 1 − κ ≈ 2e^{−2/a}.
        let a: f64 = 0.05;
        assert!(((1.0 - kappa0(a, 0.0).0) - 2.0 * (-2.0 / a).exp()).abs() < 1e-15);
        let (k1, k2) = (kappa0(0.2, 0.0).0, 2.0f64);
        assert!(((0.5 * ((k2 - (1.0 - k1)) / (1.0 - k1)).ln()) * 0.2 - k1).abs() < 1e-12);
        // g ≠ 0: derivative of the similarity-scaled root.
        let (a, g) = (0.95, 0.8);
        let h = 1e-6;
        let fd = (kappa0(a + h, g).0 - kappa0(a - h, g).0) / (2.0 * h);
        assert!((kappa0(a, g).1 - fd).abs() < 1e-6 * fd.abs());
    }

    /// The B-spline basis sums to 1 (partition of unity), its derivative weights sum to 0, and the
    /// linear extension continues value and slope.
    #[test]
    fn basis_partition_and_extension() {
        let k = Knots::covering(-2.0, 3.0, 0.3);
        for i in 0..200 {
            let u = -2.0 + 5.0 * i as f64 / 199.0;
            let b = k.basis(u);
            assert!((b.w.iter().sum::<f64>() - 1.0).abs() < 1e-14);
            assert!(b.dw.iter().sum::<f64>().abs() < 1e-12);
        }
        let coefs: Vec<f64> = (0..k.len()).map(|m| (m as f64 * 0.7).sin()).collect();
        let s = |u: f64| {
            let b = k.basis(u);
            (0..4).map(|p| b.w[p] * coefs[b.first + p]).sum::<f64>()
        };
        let ds = |u: f64| {
            let b = k.basis(u);
            (0..4).map(|p| b.dw[p] * coefs[b.first + p]).sum::<f64>()
        };
        for u in [-0.5, 1.1, 2.9] {
            let h = 1e-6;
            assert!((ds(u) - (s(u + h) - s(u - h)) / (2.0 * h)).abs() < 1e-7);
        }
        assert!((s(4.0) - (s(3.0) + ds(3.0))).abs() < 1e-12);
        assert!((s(-3.0) - (s(-2.0) - ds(-2.0))).abs() < 1e-12);
    }

    /// Noise-free data of the model's own form (a power law times e^{−κρ}) on log bins is recovered
    /// to 1e-6 through the bin averaging, and beyond the data the fit continues the power law.
    #[test]
    fn recovers_power_law_times_exponential() {
        let kappa = 0.4;
        let truth = |rho: f64| 0.3 * rho.powf(-1.7) * (-kappa * rho).exp();
        let mut edges = vec![0.0];
        edges.extend((0..=120).map(|i| 0.01 * 1.08f64.powi(i)));
        let bins = edges.len() - 1;
        // Exact bin averages by fine quadrature; relative errors 1 % out to ρ = 30, none beyond.
        let (mut rd, mut se) = (vec![0.0; bins], vec![0.0; bins]);
        for j in 0..bins {
            let (a, b) = (edges[j], edges[j + 1]);
            let n = 2000;
            let mut s = 0.0;
            for i in 0..n {
                let r = a + (b - a) * (i as f64 + 0.5) / n as f64;
                s += 2.0 * std::f64::consts::PI * r * truth(r) * (b - a) / n as f64;
            }
            rd[j] = s / (std::f64::consts::PI * (b * b - a * a));
            // 1e-4 relative error: small enough that the σ²/2 log-bias correction (5e-9) is invisible.
            se[j] = if b < 30.0 { 1e-4 * rd[j] } else { rd[j] };
        }
        let knots = Knots::covering(0.01f64.ln(), edges[bins].ln(), 0.25);
        let fit = fit_row(&edges, &rd, &se, kappa, &knots, &SmoothParams::default()).unwrap();
        assert!(fit.rho_data_max < 30.0 && fit.rho_data_max > 25.0);
        for rho in [0.05f64, 0.5, 3.0, 20.0, 60.0, 200.0] {
            let b = knots.basis(rho.ln());
            let s: f64 = (0..4).map(|p| b.w[p] * fit.coefs[b.first + p]).sum();
            let got = (s - kappa * rho).exp();
            let tol = if rho < 30.0 { 1e-6 } else { 1e-5 };
            assert!(
                (got / truth(rho) - 1.0).abs() < tol,
                "ρ = {rho}: {got} vs {}",
                truth(rho)
            );
        }
    }
}
