//! The light spot: a uniform disk of radius a instead of the point of incidence the diffusion
//! models assume. The measured profile is the model convolved with the disk,
//!
//! ```text
//! m(r) = (1/πa²) ∫_{|y|<a} Rd(|x − y|) dy,   |x| = r
//!      = (2/πa²) ∫ Rd(s) · s θ(s; r) ds,     θ = arccos((s² + r² − a²)/(2sr)) ∈ [0, π]
//! ```
//!
//! (the second line counts, for each distance s from the point of incidence, the arc 2sθ of the
//! circle |u| = s that lies inside the disk of radius a around x). The model is evaluated on nodes
//! spaced h near the spot and at most a fraction [`NODE_SPACING_RELATIVE`] of their radius further
//! out (a diffusion profile varies on the scale of r there, so the fit evaluates the model about
//! 2.5× less often than on a uniform grid), and interpolated between them by cubic Hermite
//! polynomials whose slopes are the three-point derivative of the non-uniform grid (so the
//! interpolant is exact for quadratics; the slope at s = 0 is 0, where a radial profile is even).
//! The convolution is then a fixed linear map from node values to ring values: a banded matrix
//! computed once per profile geometry. A fit costs one model evaluation at the nodes and one sparse
//! product per iteration, derivatives included (the map is linear).
//!
//! The integral per matrix entry is done by Gauss–Legendre quadrature on each node interval; where
//! θ has a square-root end point (s = |r − a| and s = r + a) the interval is mapped by s = s₀ ± Δv²,
//! which makes the integrand smooth.

use scatterfit_optics::numerics::quadrature::{GL8_AS_W, GL8_AS_X};

use crate::error::{Result, check};

/// Gauss–Legendre nodes and weights on [0, 1], 8 points: Abramowitz & Stegun's table 25.4
/// (`scatterfit_optics::numerics::quadrature`) mapped from [−1, 1].
const GL8: [(f64, f64); 8] = {
    const X: [f64; 4] = GL8_AS_X;
    const W: [f64; 4] = GL8_AS_W;
    let mut out = [(0.0, 0.0); 8];
    let mut i = 0;
    while i < 4 {
        out[2 * i] = (0.5 - 0.5 * X[i], 0.5 * W[i]);
        out[2 * i + 1] = (0.5 + 0.5 * X[i], 0.5 * W[i]);
        i += 1;
    }
    out
};

/// Far from the centre, nodes are at most this fraction of their radius apart (cubic Hermite
/// interpolation of e^{−σr} then errs by ≈ (σ·0.025 r)⁴/384: 2e-5 at σr = 10).
pub const NODE_SPACING_RELATIVE: f64 = 0.025;

/// Nodes from 0: spacing h, growing to `NODE_SPACING_RELATIVE`·s beyond s = h/ε, until two nodes
/// past `s_end` (so every interval up to `s_end` has its four-node stencil).
fn node_grid(h: f64, s_end: f64) -> Vec<f64> {
    // Exact multiples of h while the spacing is h (breaks at a ± r then fall on nodes exactly).
    let s_uniform = h / NODE_SPACING_RELATIVE;
    let mut v: Vec<f64> = (0..)
        .map(|k| k as f64 * h)
        .take_while(|&s| s < s_uniform.min(s_end + 3.0 * h))
        .collect();
    let mut past = v.iter().filter(|&&s| s >= s_end).count();
    while past < 2 {
        let s = *v.last().unwrap_or(&0.0);
        v.push(s + h.max(NODE_SPACING_RELATIVE * s));
        if s + h.max(NODE_SPACING_RELATIVE * s) >= s_end {
            past += 1;
        }
    }
    v
}

/// The weights of f(s) on the nodes k − 1 … k + 2 (index of the first returned), s in
/// [nodes[k], nodes[k + 1]]: cubic Hermite with slopes from the three-point derivative, exact for
/// quadratics on a non-uniform grid (mₖ = −h₁/(h₀(h₀+h₁)) fₖ₋₁ + (h₁−h₀)/(h₀h₁) fₖ + h₀/(h₁(h₀+h₁)) fₖ₊₁,
/// h₀ = sₖ − sₖ₋₁, h₁ = sₖ₊₁ − sₖ), and slope 0 at s = 0 (an even function).
#[inline]
fn hermite_weights(nodes: &[f64], k: usize, s: f64) -> [f64; 4] {
    let d = nodes[k + 1] - nodes[k];
    let t = ((s - nodes[k]) / d).clamp(0.0, 1.0);
    let (t2, t3) = (t * t, t * t * t);
    let (h00, h10, h01, h11) = (
        2.0 * t3 - 3.0 * t2 + 1.0,
        t3 - 2.0 * t2 + t,
        -2.0 * t3 + 3.0 * t2,
        t3 - t2,
    );
    // Slope weights at node j over (j − 1, j, j + 1).
    let slope = |j: usize| -> [f64; 3] {
        if j == 0 {
            return [0.0; 3];
        }
        let (h0, h1) = (nodes[j] - nodes[j - 1], nodes[j + 1] - nodes[j]);
        [
            -h1 / (h0 * (h0 + h1)),
            (h1 - h0) / (h0 * h1),
            h0 / (h1 * (h0 + h1)),
        ]
    };
    let (mk, mk1) = (slope(k), slope(k + 1));
    // Nodes k − 1, k, k + 1, k + 2.
    [
        d * h10 * mk[0],
        h00 + d * (h10 * mk[1] + h11 * mk1[0]),
        h01 + d * (h10 * mk[2] + h11 * mk1[1]),
        d * h11 * mk1[2],
    ]
}

/// One row of the convolution map: ring value = Σ weights[j] · f(node first + j).
#[derive(Debug, Clone, PartialEq)]
struct Row {
    first: usize,
    weights: Vec<f64>,
}

/// The linear map from model values at uniform nodes to spot-convolved values at ring radii.
#[derive(Debug, Clone, PartialEq)]
pub struct SpotKernel {
    radius_mm: f64,
    nodes: Vec<f64>,
    rows: Vec<Row>,
}

impl SpotKernel {
    /// The map for a uniform disk of radius `radius_mm` and the ring radii `r_mm`, with node
    /// spacing `h_mm` near the spot (the model must vary little over h; a/8 or the ring spacing,
    /// whichever is smaller, is plenty), growing to [`NODE_SPACING_RELATIVE`] of the radius further
    /// out.
    ///
    /// # Errors
    /// `InvalidInput` for a radius or spacing that is not finite and > 0, or a ring radius < 0.
    pub fn new(radius_mm: f64, r_mm: &[f64], h_mm: f64) -> Result<Self> {
        check(
            radius_mm.is_finite() && radius_mm > 0.0,
            "spot radius [mm]",
            radius_mm,
            "must be finite and > 0",
        )?;
        check(
            h_mm.is_finite() && h_mm > 0.0,
            "node spacing [mm]",
            h_mm,
            "must be finite and > 0",
        )?;
        if let Some(&r) = r_mm.iter().find(|r| !(r.is_finite() && **r >= 0.0)) {
            check(false, "ring radius [mm]", r, "must be finite and ≥ 0")?;
        }
        let a = radius_mm;
        let r_hi = r_mm.iter().fold(0.0f64, |m, &r| m.max(r)) + a;
        let nodes = node_grid(h_mm, r_hi);
        let rows = r_mm.iter().map(|&r| row(r, a, &nodes)).collect();
        Ok(Self {
            radius_mm,
            nodes,
            rows,
        })
    }

    /// The map for a spot of any radial shape given as a mixture of uniform disks
    /// ([`crate::radial_spot::RadialSpot`]): Σ_k w_k × (the disk map of radius a_k), on one node
    /// grid reaching the outer disk. [`SpotKernel::radius_mm`] is then the radius of the disk with
    /// the spot's second moment (for the start search's coarse kernel).
    ///
    /// # Errors
    /// As [`SpotKernel::new`].
    pub fn from_disks(
        spot: &crate::radial_spot::RadialSpot,
        r_mm: &[f64],
        h_mm: f64,
    ) -> Result<Self> {
        let outer = spot.outer_radius_mm();
        let mut k = Self::new(outer, r_mm, h_mm)?;
        for (i, &r) in r_mm.iter().enumerate() {
            let mut w = vec![0.0f64; k.nodes.len()];
            let (mut lo, mut hi) = (usize::MAX, 0usize);
            for (a, weight) in spot.disks() {
                if weight == 0.0 {
                    continue;
                }
                let part = row(r, a, &k.nodes);
                for (j, v) in part.weights.iter().enumerate() {
                    w[part.first + j] += weight * v;
                }
                lo = lo.min(part.first);
                hi = hi.max(part.first + part.weights.len());
            }
            k.rows[i] = if lo < hi {
                Row {
                    first: lo,
                    weights: w[lo..hi].to_vec(),
                }
            } else {
                Row {
                    first: 0,
                    weights: Vec::new(),
                }
            };
        }
        k.radius_mm = spot.equivalent_radius_mm();
        Ok(k)
    }

    /// Spot radius \[mm\].
    pub fn radius_mm(&self) -> f64 {
        self.radius_mm
    }

    /// The radii \[mm\] at which the model must be evaluated.
    pub fn nodes(&self) -> &[f64] {
        &self.nodes
    }

    /// Number of rings (rows).
    pub fn rings(&self) -> usize {
        self.rows.len()
    }

    /// The convolved value at ring `i` from node values `f` (one per node): Σⱼ Kᵢⱼ f(sⱼ).
    #[inline]
    pub fn apply_row(&self, i: usize, f: &[f64]) -> f64 {
        let row = &self.rows[i];
        row.weights
            .iter()
            .zip(&f[row.first..])
            .map(|(&w, &v)| w * v)
            .sum()
    }

    /// Every row: `out[i]` = Σⱼ Kᵢⱼ f(sⱼ) (the hot path of a fit: one contiguous dot product
    /// per ring).
    pub fn apply(&self, f: &[f64], out: &mut [f64]) {
        for (row, o) in self.rows.iter().zip(out.iter_mut()) {
            *o = dot(&row.weights, &f[row.first..row.first + row.weights.len()]);
        }
    }

    /// [`SpotKernel::apply`] to two node arrays at once (a model and its derivative: each row's
    /// weights are read once for both).
    pub fn apply_pair(&self, f: &[f64], g: &[f64], out_f: &mut [f64], out_g: &mut [f64]) {
        for ((row, of), og) in self.rows.iter().zip(out_f.iter_mut()).zip(out_g.iter_mut()) {
            let end = row.first + row.weights.len();
            (*of, *og) = dot2(&row.weights, &f[row.first..end], &g[row.first..end]);
        }
    }

    /// Keeps only the rows whose index is in `keep` (ascending), in that order.
    pub fn select_rows(&self, keep: &[usize]) -> Self {
        Self {
            radius_mm: self.radius_mm,
            nodes: self.nodes.clone(),
            rows: keep.iter().map(|&i| self.rows[i].clone()).collect(),
        }
    }
}

/// Σ aᵢbᵢ with four independent partial sums (a sequential sum cannot be reordered by the
/// compiler, so it neither vectorises nor pipelines; measured 2× faster on the fit's rows).
#[inline]
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    let (a, b) = (&a[..n], &b[..n]);
    let mut acc = [0.0; 4];
    let (ca, cb) = (a.chunks_exact(4), b.chunks_exact(4));
    let (ra, rb) = (ca.remainder(), cb.remainder());
    for (x, y) in ca.zip(cb) {
        for k in 0..4 {
            acc[k] += x[k] * y[k];
        }
    }
    let tail: f64 = ra.iter().zip(rb).map(|(x, y)| x * y).sum();
    (acc[0] + acc[1]) + (acc[2] + acc[3]) + tail
}

/// (Σ wᵢaᵢ, Σ wᵢbᵢ), as [`dot`] with the weights loaded once.
#[inline]
fn dot2(w: &[f64], a: &[f64], b: &[f64]) -> (f64, f64) {
    let n = w.len().min(a.len()).min(b.len());
    let (w, a, b) = (&w[..n], &a[..n], &b[..n]);
    let (mut acc_a, mut acc_b) = ([0.0; 4], [0.0; 4]);
    let (cw, ca, cb) = (w.chunks_exact(4), a.chunks_exact(4), b.chunks_exact(4));
    let (rw, ra, rb) = (cw.remainder(), ca.remainder(), cb.remainder());
    for ((x, y), z) in cw.zip(ca).zip(cb) {
        for k in 0..4 {
            acc_a[k] += x[k] * y[k];
            acc_b[k] += x[k] * z[k];
        }
    }
    let (mut ta, mut tb) = (0.0, 0.0);
    for ((x, y), z) in rw.iter().zip(ra).zip(rb) {
        ta += x * y;
        tb += x * z;
    }
    (
        (acc_a[0] + acc_a[1]) + (acc_a[2] + acc_a[3]) + ta,
        (acc_b[0] + acc_b[1]) + (acc_b[2] + acc_b[3]) + tb,
    )
}

/// The weights of the ring at radius r: K_j = (2/πa²) ∫ B_j(s) s θ(s) ds.
fn row(r: f64, a: f64, nodes: &[f64]) -> Row {
    let n = nodes.len();
    let s_lo = (r - a).max(0.0);
    let s_hi = r + a;
    let theta = |s: f64| -> f64 {
        if r <= 0.0 || s <= 0.0 {
            return if s < a { std::f64::consts::PI } else { 0.0 };
        }
        let c = (s * s + r * r - a * a) / (2.0 * s * r);
        c.clamp(-1.0, 1.0).acos()
    };
    // Break points: node boundaries inside (s_lo, s_hi), the ends, and a − r (θ's kink inside the
    // spot).
    let mut breaks = vec![s_lo, s_hi];
    if r > 0.0 && r < a {
        breaks.push(a - r);
    }
    breaks.extend(nodes.iter().copied().filter(|&s| s > s_lo && s < s_hi));
    breaks.sort_by(f64::total_cmp);
    breaks.dedup_by(|x, y| (*x - *y).abs() <= 1e-14 * (1.0 + y.abs()));
    // The interval holding s: nodes[k] ≤ s < nodes[k + 1].
    let interval = |s: f64| nodes.partition_point(|&x| x <= s).clamp(1, n - 2) - 1;
    let first = interval(s_lo).saturating_sub(1);
    let last = (interval(s_hi) + 2).min(n - 1);
    let mut w = vec![0.0; last + 1 - first];
    let norm = 2.0 / (std::f64::consts::PI * a * a);
    // Points where θ(s) behaves like a square root: r + a always, |r − a| when r > 0.
    let mut singular = vec![s_hi];
    if r > 0.0 {
        singular.push((r - a).abs());
    }
    let mut add = |s: f64, weight: f64| {
        if weight == 0.0 {
            return;
        }
        let k = interval(s);
        for (q, c) in hermite_weights(nodes, k, s).iter().enumerate() {
            if *c == 0.0 {
                continue;
            }
            // Node k − 1 + q (for k = 0 the first weight is 0: the slope at s = 0 is 0).
            let j = (k + q).saturating_sub(1).min(n - 1);
            w[j - first] += weight * c;
        }
    };
    for seg in breaks.windows(2) {
        let (u0, u1) = (seg[0], seg[1]);
        let len = u1 - u0;
        if len <= 0.0 {
            continue;
        }
        // A square-root point at or just beyond an end (closer than twice the segment's length)
        // makes plain Gauss–Legendre inaccurate: substitute s = p ± w² around it, smooth in w.
        // (A singular point that coincides with a break up to rounding counts as that break.)
        let tol = 1e-12 * (1.0 + u1);
        let left = singular
            .iter()
            .copied()
            .find(|&p| p <= u0 + tol && u0 - p < 2.0 * len);
        let right = singular
            .iter()
            .copied()
            .find(|&p| p >= u1 - tol && p - u1 < 2.0 * len);
        let parts: Vec<(f64, f64, Option<f64>, Option<f64>)> = match (left, right) {
            (Some(p), Some(q)) => {
                let m = 0.5 * (u0 + u1);
                vec![(u0, m, Some(p), None), (m, u1, None, Some(q))]
            }
            (l, r) => vec![(u0, u1, l, r)],
        };
        for (p0, p1, l, r) in parts {
            match (l, r) {
                (Some(p), _) => {
                    let (w0, w1) = ((p0 - p).max(0.0).sqrt(), (p1 - p).max(0.0).sqrt());
                    for &(v, gw) in &GL8 {
                        let x = w0 + (w1 - w0) * v;
                        let s = p + x * x;
                        add(s, norm * gw * (w1 - w0) * 2.0 * x * s * theta(s));
                    }
                }
                (None, Some(q)) => {
                    let (w0, w1) = ((q - p1).max(0.0).sqrt(), (q - p0).max(0.0).sqrt());
                    for &(v, gw) in &GL8 {
                        let x = w0 + (w1 - w0) * v;
                        let s = q - x * x;
                        add(s, norm * gw * (w1 - w0) * 2.0 * x * s * theta(s));
                    }
                }
                (None, None) => {
                    for &(v, gw) in &GL8 {
                        let s = p0 + (p1 - p0) * v;
                        add(s, norm * gw * (p1 - p0) * s * theta(s));
                    }
                }
            }
        }
    }
    // Trim zero weights at both ends.
    let lead = w.iter().take_while(|&&x| x == 0.0).count();
    let trail = w.iter().rev().take_while(|&&x| x == 0.0).count();
    let weights = w[lead..w.len() - trail.min(w.len() - lead)].to_vec();
    Row {
        first: first + lead,
        weights,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Disk average of f(|x − y|) over |y| < a by brute-force polar quadrature (midpoint rule on a
    /// fine grid): an independent check of the arc-length formula and the node interpolation.
    fn brute_force(f: impl Fn(f64) -> f64, r: f64, a: f64) -> f64 {
        let (nr, nphi) = (400, 800);
        let mut sum = 0.0;
        for i in 0..nr {
            let rho = a * (i as f64 + 0.5) / nr as f64;
            for j in 0..nphi {
                let phi = std::f64::consts::PI * (j as f64 + 0.5) / nphi as f64;
                let d = (r * r + rho * rho - 2.0 * r * rho * phi.cos())
                    .max(0.0)
                    .sqrt();
                sum += f(d) * rho;
            }
        }
        // ∫ρ dρ dφ over half the disk, times 2, over πa².
        2.0 * sum * (a / nr as f64) * (std::f64::consts::PI / nphi as f64)
            / (std::f64::consts::PI * a * a)
    }

    fn apply(k: &SpotKernel, f: impl Fn(f64) -> f64) -> Vec<f64> {
        let values: Vec<f64> = k.nodes().iter().map(|&s| f(s)).collect();
        (0..k.rings()).map(|i| k.apply_row(i, &values)).collect()
    }

    /// Constants and quadratics are reproduced exactly (the Hermite interpolant with three-point
    /// slopes is exact for quadratics, uniform or not):
    /// the disk average of 1 is 1 and of |x − y|² is r² + a²/2.
    #[test]
    fn exact_for_constants_and_quadratics() {
        let a = 0.5;
        let radii = [0.0, 0.1, 0.3, 0.5, 0.5001, 0.7, 1.0, 2.37, 10.0, 37.5];
        let k = SpotKernel::new(a, &radii, 0.05).unwrap();
        for (i, m) in apply(&k, |_| 1.0).iter().enumerate() {
            assert!((m - 1.0).abs() < 1e-9, "r = {}: {m}", radii[i]);
        }
        for (i, m) in apply(&k, |s| s * s).iter().enumerate() {
            let r = radii[i];
            let want = r * r + 0.5 * a * a;
            assert!(
                (m - want).abs() < 1e-9 * (1.0 + want),
                "r = {r}: {m} vs {want}"
            );
        }
    }

    /// A profile with structure on the node scale (a dipole-like e^{−σd}/d³ shape, σ = 1.5 mm⁻¹)
    /// against brute force 2-D quadrature, inside and outside the spot: within 2e-4 out to σr = 10
    /// (about five decades below the peak, where a bracket stops detecting), within 1.5e-3 at σr = 21
    /// (the interpolant's slopes are three-point differences, so its error grows like (σΔ)³ with
    /// the node spacing Δ = 0.025 r).
    #[test]
    fn matches_brute_force_on_a_peaked_profile() {
        let a = 0.5;
        let f = |s: f64| {
            let z: f64 = 0.4;
            let d = (s * s + z * z).sqrt();
            z * (1.5 * d + 1.0) * (-1.5 * d).exp() / (d * d * d)
        };
        let radii = [0.0, 0.25, 0.5, 0.75, 1.0, 1.5, 3.0, 6.7, 14.0];
        let k = SpotKernel::new(a, &radii, 0.025).unwrap();
        for (i, m) in apply(&k, f).iter().enumerate() {
            let want = brute_force(f, radii[i], a);
            let tol = if radii[i] * 1.5 <= 10.0 { 2e-4 } else { 1.5e-3 };
            assert!(
                ((m - want) / want).abs() < tol,
                "r = {}: {m} vs {want}",
                radii[i]
            );
        }
    }

    #[test]
    fn refuses_bad_geometry() {
        assert!(SpotKernel::new(0.0, &[1.0], 0.1).is_err());
        assert!(SpotKernel::new(0.5, &[1.0], f64::NAN).is_err());
        assert!(SpotKernel::new(0.5, &[-1.0], 0.1).is_err());
    }
}
