//! Interpolation weights on a grid of nodes: Catmull-Rom (pbrt's `CatmullRomWeights`) and the
//! cubic Hermite weights with their derivatives and end rules ([`Ends`]) that the tables
//! interpolate by in the albedo and in η.

/// Σₖ w[k]·f(k) over the nonzero weights (index k − 1 relative to the interval start).
pub(super) fn dot4(w: &[f64; 4], f: impl Fn(usize) -> f64) -> f64 {
    (0..4).filter(|&k| w[k] != 0.0).map(|k| w[k] * f(k)).sum()
}

/// Catmull-Rom weights at `x` over the `n` strictly increasing nodes `node(k)` (pbrt-v3's
/// `CatmullRomWeights`, docs/physics.md §2.3): returns (i, w) with x ∈ [node(i), node(i + 1)] and the
/// interpolant Σₖ w[k]·f(i − 1 + k); the end derivatives are one-sided (w[0] or w[3] is then 0).
/// Cubic Hermite with finite-difference derivatives on non-uniform nodes; exact at the nodes.
pub(super) fn catmull_rom_weights(
    n: usize,
    node: impl Fn(usize) -> f64,
    x: f64,
) -> (usize, [f64; 4]) {
    let (i, w, _) = hermite_weights(n, node, x, Ends::Chord);
    (i, w)
}

/// How a cubic Hermite interpolant takes its derivative at the first and last node.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Ends {
    /// The end interval's chord (pbrt's Catmull-Rom): exact for straight lines only.
    Chord,
    /// The parabola through the three end nodes (the second-order one-sided difference, e.g.
    /// Fornberg 1988, Math. Comp. 51:699, table 1): exact for quadratics, so the end interval is
    /// as accurate as an interior one. Used in albedo, where the last interval of the tables
    /// (toward a → 1) spans a wide range of 1 − α′ and Rd(√(1 − a)) is curved: with the chord the
    /// totals were 1–1.5·10⁻³ high at α′ 0.9996–0.9998 for g 0.8–0.9 against adding-doubling,
    /// with the parabola within 2.5·10⁻⁴ (BENCHMARKS.md, "The `mc` model over g").
    Parabola,
}

/// Cubic Hermite weights at `x` over the `n` strictly increasing nodes with Catmull-Rom
/// (finite-difference) derivatives inside and `ends` at the first and last node: (i, w, dw/dx)
/// with x ∈ [node(i), node(i + 1)] and the interpolant Σₖ w[k]·f(i − 1 + k).
pub(super) fn hermite_weights(
    n: usize,
    node: impl Fn(usize) -> f64,
    x: f64,
    ends: Ends,
) -> (usize, [f64; 4], [f64; 4]) {
    // First i with node(i + 1) > x, clamped to the last interval.
    let mut i = 0;
    while i + 2 < n && node(i + 1) <= x {
        i += 1;
    }
    let (x0, x1) = (node(i), node(i + 1));
    let h = x1 - x0;
    let t = ((x - x0) / h).clamp(0.0, 1.0);
    let (t2, t3) = (t * t, t * t * t);
    let inv = 1.0 / h;
    // Value and x-derivative of the four Hermite basis functions: h00, h10 (times h), h01, h11.
    let mut w = [0.0, 2.0 * t3 - 3.0 * t2 + 1.0, -2.0 * t3 + 3.0 * t2, 0.0];
    let mut d = [
        0.0,
        (6.0 * t2 - 6.0 * t) * inv,
        (-6.0 * t2 + 6.0 * t) * inv,
        0.0,
    ];
    // h·f′(x0) as weights on (f(i − 1), f(i), f(i + 1), f(i + 2)).
    let start: [f64; 4] = if i > 0 {
        let c = h / (x1 - node(i - 1));
        [-c, 0.0, c, 0.0]
    } else if ends == Ends::Parabola && n >= 3 {
        // Parabola through x0, x1, x2: h f′(x0) = (1 + c)(f1 − f0) − c r (f2 − f1).
        let h2 = node(i + 2) - x1;
        let (c, r) = (h / (h + h2), h / h2);
        [0.0, -(1.0 + c), 1.0 + c + c * r, -c * r]
    } else {
        [0.0, -1.0, 1.0, 0.0]
    };
    // h·f′(x1) likewise.
    let end: [f64; 4] = if i + 2 < n {
        let c = h / (node(i + 2) - x0);
        [0.0, -c, 0.0, c]
    } else if ends == Ends::Parabola && i > 0 {
        // Parabola through x₋₁, x0, x1: h f′(x1) = (1 + c)(f1 − f0) − c r (f0 − f₋₁).
        let h1 = x0 - node(i - 1);
        let (c, r) = (h / (h1 + h), h / h1);
        [c * r, -(1.0 + c + c * r), 1.0 + c, 0.0]
    } else {
        [0.0, -1.0, 1.0, 0.0]
    };
    let (b0, db0) = (t3 - 2.0 * t2 + t, (3.0 * t2 - 4.0 * t + 1.0) * inv);
    let (b1, db1) = (t3 - t2, (3.0 * t2 - 2.0 * t) * inv);
    for k in 0..4 {
        w[k] += b0 * start[k] + b1 * end[k];
        d[k] += db0 * start[k] + db1 * end[k];
    }
    (i, w, d)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Catmull-Rom weight derivatives match central differences of the weights.
    #[test]
    fn weight_derivatives_match_finite_differences() {
        let nodes = [0.0, 0.3, 0.7, 1.2, 2.0, 2.1];
        for i in 0..100 {
            let x = 0.001 + 2.098 * i as f64 / 99.0;
            let (k, _, d) = hermite_weights(nodes.len(), |j| nodes[j], x, Ends::Chord);
            let h = 1e-7;
            let (kp, wp) = catmull_rom_weights(nodes.len(), |j| nodes[j], x + h);
            let (km, wm) = catmull_rom_weights(nodes.len(), |j| nodes[j], x - h);
            if kp != k || km != k {
                continue;
            }
            for q in 0..4 {
                assert!((d[q] - (wp[q] - wm[q]) / (2.0 * h)).abs() < 1e-6, "x = {x}");
            }
        }
    }

    /// With parabolic ends the interpolant reproduces any quadratic exactly on uniform nodes (as
    /// the albedo nodes are, in √(1 − a)), in the end intervals too — the chord ends do not: that
    /// was their error toward a → 1 — and so does its derivative.
    #[test]
    fn parabolic_ends_are_exact_for_quadratics() {
        let nodes = [0.0, 0.35, 0.7, 1.05, 1.4, 1.75, 2.1];
        let f = |x: f64| 1.0 - 2.5 * x + 3.0 * x * x;
        let mut chord_worst = 0.0f64;
        for i in 0..200 {
            let x = 2.1 * i as f64 / 199.0;
            let (k, w, d) = hermite_weights(nodes.len(), |j| nodes[j], x, Ends::Parabola);
            let val = |w: &[f64; 4]| dot4(w, |q| f(nodes[k + q - 1]));
            assert!((val(&w) - f(x)).abs() < 1e-12, "x = {x}");
            assert!((val(&d) - (-2.5 + 6.0 * x)).abs() < 1e-9, "x = {x}");
            let (_, wc) = catmull_rom_weights(nodes.len(), |j| nodes[j], x);
            chord_worst = chord_worst.max((val(&wc) - f(x)).abs());
        }
        assert!(
            chord_worst > 1e-3,
            "the chord ends were exact: {chord_worst}"
        );
    }
}
