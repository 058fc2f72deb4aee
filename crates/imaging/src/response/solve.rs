//! The response's solver numerics: dense least squares by Householder QR, the sparse system by the
//! corrected semi-normal equations, and the monotone solve by Lawson & Hanson's non-negative least
//! squares.

use nalgebra::{DMatrix, DVector};

use super::curve::LEVELS;

/// The least-squares g that never decreases: min |A g − b| subject to g(z) ≥ g(z − 1).
///
/// The unconstrained minimiser is found first (the corrected semi-normal equations,
/// `solve_sparse_least_squares`); when it already rises everywhere it
/// is the answer (the constraint is inactive, so nothing changes for a good bracket). Otherwise g
/// is written as cumulative sums of its increments, g = T d with d(z) = g(z) − g(z − 1) ≥ 0 and
/// the gauge g(128) = 0 built in, and the non-negative least-squares problem min |A T d − b|,
/// d ≥ 0, is solved exactly by Lawson & Hanson's active-set algorithm (Solving Least Squares
/// Problems, 1974, ch. 23) on the triangular factor of A T (255 unknowns), warm-started from the
/// unconstrained increments. Monotone by construction: a dip that noise at low codes would make
/// becomes a flat stretch, and a bracket in the wrong order is found by
/// [`crate::check_bracket_order`], not by the shape of g.
pub(super) fn solve_monotone(a: &SparseRows, b: DVector<f64>) -> Option<DVector<f64>> {
    let g = solve_sparse_least_squares(a, b.clone())?;
    if g.as_slice().windows(2).all(|w| w[1] >= w[0]) {
        return Some(g);
    }
    let a = a.to_dense();
    // g = T d: g(z) = Σ_{k=129..=z} d_k above the gauge, −Σ_{k=z+1..=128} d_k below; d_k is
    // column k − 1 (k = 1..=255).
    let n = LEVELS - 1;
    let mut at = DMatrix::<f64>::zeros(a.nrows(), n);
    for r in 0..a.nrows() {
        // (A T)[r, k−1] = Σ_{z ≥ k} A[r, z] for k > 128, −Σ_{z < k} A[r, z] for k ≤ 128.
        let mut acc = 0.0;
        for z in (129..LEVELS).rev() {
            acc += a[(r, z)];
            at[(r, z - 1)] = acc;
        }
        let mut acc = 0.0;
        for k in 1..=128 {
            acc += a[(r, k - 1)];
            at[(r, k - 1)] = -acc;
        }
    }
    let qr = at.qr();
    let mut qtb = b;
    qr.q_tr_mul(&mut qtb);
    let r = qr.r();
    let c = qtb.rows(0, n).into_owned();
    let start: Vec<bool> = (1..LEVELS).map(|k| g[k] - g[k - 1] > 0.0).collect();
    let d = nnls(&r, &c, &start)?;
    let mut out = DVector::<f64>::zeros(LEVELS);
    for z in 129..LEVELS {
        out[z] = out[z - 1] + d[z - 1];
    }
    for z in (0..128).rev() {
        out[z] = out[z + 1] - d[z];
    }
    Some(out)
}

/// Lawson & Hanson's NNLS, min |R x − c| subject to x ≥ 0, for a square R, starting with the
/// columns flagged in `passive` free (a warm start; the algorithm makes it feasible first).
fn nnls(r: &DMatrix<f64>, c: &DVector<f64>, passive: &[bool]) -> Option<DVector<f64>> {
    let n = r.ncols();
    let mut p: Vec<bool> = passive.to_vec();
    let mut x = DVector::<f64>::zeros(n);
    let tol = 1e-12 * r.amax().max(1.0) * c.amax().max(1.0) * n as f64;
    // Least squares on the passive columns; zeros elsewhere.
    let solve_p = |p: &[bool]| -> Option<DVector<f64>> {
        let cols: Vec<usize> = (0..n).filter(|&j| p[j]).collect();
        let mut s = DVector::<f64>::zeros(n);
        if cols.is_empty() {
            return Some(s);
        }
        let sub = r.select_columns(&cols);
        let sol = solve_least_squares(sub, c.clone())?;
        for (i, &j) in cols.iter().enumerate() {
            s[j] = sol[i];
        }
        Some(s)
    };
    // Make the warm start feasible: drop the columns whose solution is not positive until none is.
    for _ in 0..n {
        let s = solve_p(&p)?;
        let bad: Vec<usize> = (0..n).filter(|&j| p[j] && s[j] <= 0.0).collect();
        if bad.is_empty() {
            x = s;
            break;
        }
        for j in bad {
            p[j] = false;
        }
    }
    // Lawson & Hanson's inner loop: from a feasible x (positive on the passive set but for a
    // column just freed), step toward the passive solution s until it is feasible.
    let inner = |p: &mut Vec<bool>, x: &mut DVector<f64>| -> Option<()> {
        for _ in 0..3 * n {
            let s = solve_p(p)?;
            if (0..n).all(|j| !p[j] || s[j] > 0.0) {
                *x = s;
                return Some(());
            }
            let mut alpha = 1.0f64;
            for j in 0..n {
                if p[j] && s[j] <= 0.0 {
                    alpha = alpha.min(x[j] / (x[j] - s[j]));
                }
            }
            for j in 0..n {
                x[j] += alpha * (s[j] - x[j]);
                if p[j] && x[j] <= tol.min(1e-15) {
                    p[j] = false;
                    x[j] = 0.0;
                }
            }
            // Columns with a non-positive solution that α did not zero (α = 0 when x_j = 0).
            for j in 0..n {
                if p[j] && s[j] <= 0.0 && x[j] <= 0.0 {
                    p[j] = false;
                }
            }
        }
        None
    };
    for _ in 0..3 * n {
        let resid = c - r * &x;
        let w = r.tr_mul(&resid);
        let best = (0..n)
            .filter(|&j| !p[j])
            .max_by(|&i, &j| w[i].total_cmp(&w[j]));
        match best {
            Some(t) if w[t] > tol => {
                p[t] = true;
                inner(&mut p, &mut x)?;
            }
            _ => return Some(x),
        }
    }
    Some(x)
}

/// A matrix stored by rows, each row's non-zeros as (column, value) in increasing column order
/// (Debevec & Malik's system: a data row holds a pixel's few codes, a smoothness row three).
#[derive(Debug, Clone, PartialEq)]
pub(super) struct SparseRows {
    /// Row r's non-zeros are `nz[offsets[r]..offsets[r + 1]]`.
    pub(super) offsets: Vec<usize>,
    pub(super) nz: Vec<(usize, f64)>,
    pub(super) ncols: usize,
}

impl SparseRows {
    /// An empty matrix of `ncols` columns.
    pub(super) fn new(ncols: usize) -> Self {
        Self {
            offsets: vec![0],
            nz: Vec::new(),
            ncols,
        }
    }

    /// Appends a row from its (column, value) pairs, in increasing column order; zeros are
    /// dropped.
    pub(super) fn push_row(&mut self, row: impl IntoIterator<Item = (usize, f64)>) {
        self.nz.extend(row.into_iter().filter(|&(_, v)| v != 0.0));
        self.offsets.push(self.nz.len());
    }

    /// The number of rows.
    pub(super) fn nrows(&self) -> usize {
        self.offsets.len() - 1
    }

    /// The largest |value| (0 for an empty matrix).
    fn amax(&self) -> f64 {
        self.nz.iter().fold(0.0f64, |m, &(_, v)| m.max(v.abs()))
    }

    /// The same matrix, dense (for the active-set solve).
    fn to_dense(&self) -> DMatrix<f64> {
        let mut a = DMatrix::<f64>::zeros(self.nrows(), self.ncols);
        for r in 0..self.nrows() {
            for &(c, v) in &self.nz[self.offsets[r]..self.offsets[r + 1]] {
                a[(r, c)] = v;
            }
        }
        a
    }

    /// The non-zeros of a dense matrix, row by row.
    #[cfg(test)]
    fn from_dense(a: &DMatrix<f64>) -> Self {
        let mut s = Self::new(a.ncols());
        for r in 0..a.nrows() {
            s.push_row(a.row(r).iter().copied().enumerate());
        }
        s
    }
}

/// min |A x − b| for a sparse A (each of Debevec & Malik's rows has a few codes), by the corrected
/// semi-normal equations (Björck 1996, *Numerical Methods for Least Squares Problems*, §6.6.5):
/// AᵀA from the rows' non-zeros and its Cholesky factor R (the triangular factor Householder QR
/// would give, up to signs), x from RᵀR x = Aᵀb, then two steps of refinement with the residual,
/// RᵀR δ = Aᵀ(b − A x), which bring x to QR's accuracy for any A with κ(A)² well below 1/ε.
/// Costs a few milliseconds where a dense QR of the (N·P + 255) × 256 system took a tenth of a
/// second. `None` when A is rank deficient (a pivot of R at or below 10⁻¹² · n · max |A|, as for QR).
pub(super) fn solve_sparse_least_squares(a: &SparseRows, b: DVector<f64>) -> Option<DVector<f64>> {
    let (m, n) = (a.nrows(), a.ncols);
    let scale = a.amax();
    let (offsets, nz) = (&a.offsets, &a.nz);
    let mut ata = DMatrix::<f64>::zeros(n, n);
    for r in 0..m {
        let row = &nz[offsets[r]..offsets[r + 1]];
        for &(i, vi) in row {
            for &(j, vj) in row {
                ata[(i, j)] += vi * vj;
            }
        }
    }
    let at_times = |v: &DVector<f64>| {
        let mut out = DVector::<f64>::zeros(n);
        for r in 0..m {
            for &(i, vi) in &nz[offsets[r]..offsets[r + 1]] {
                out[i] += vi * v[r];
            }
        }
        out
    };
    let chol = nalgebra::linalg::Cholesky::new(ata)?;
    let tol = scale * 1e-12 * n as f64;
    let l = chol.l_dirty();
    if (0..n).any(|i| l[(i, i)].abs().is_nan() || l[(i, i)].abs() <= tol) {
        return None;
    }
    let mut x = chol.solve(&at_times(&b));
    for _ in 0..2 {
        let mut res = b.clone();
        for r in 0..m {
            for &(i, vi) in &nz[offsets[r]..offsets[r + 1]] {
                res[r] -= vi * x[i];
            }
        }
        x += chol.solve(&at_times(&res));
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}

/// min |A x − b| by Householder QR, for the small dense systems (splines, the comb, the active set).
pub(super) fn solve_least_squares(a: DMatrix<f64>, b: DVector<f64>) -> Option<DVector<f64>> {
    let ncols = a.ncols();
    let scale = a.amax();
    let qr = a.qr();
    let mut qtb = b;
    qr.q_tr_mul(&mut qtb);
    let r = qr.r();
    let tol = scale * 1e-12 * ncols as f64;
    if (0..ncols).any(|i| r[(i, i)].abs() <= tol) {
        return None;
    }
    let rhs = qtb.rows(0, ncols).into_owned();
    r.solve_upper_triangular(&rhs)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::response::curve::LEVELS;
    use crate::response::gsolve::hat_weight;

    #[test]
    fn the_semi_normal_equations_give_the_qr_solution() {
        // A Debevec & Malik system from a synthetic gamma-2.2 bracket of 60 pixels × 8 frames (and
        // its monotone solution): the sparse solve agrees with Householder QR to 1e-9.
        let times: Vec<f64> = (0..8).map(|j| 0.01 * 2f64.powi(j)).collect();
        let ln_dt: Vec<f64> = times.iter().map(|t| t.ln()).collect();
        let mut z = Vec::new();
        for i in 0..60 {
            let e = 0.05 * 1.09f64.powi(i);
            for t in &times {
                let x: f64 = (e * t * 20.0).min(1.0);
                z.push((255.0 * x.powf(1.0 / 2.2)).round() as u8);
            }
        }
        let p = ln_dt.len();
        let rows = (z.len() / p) * p + 1 + (LEVELS - 2);
        let mut a = DMatrix::<f64>::zeros(rows, LEVELS);
        let mut b = DVector::<f64>::zeros(rows);
        let mut k = 0;
        for zi in z.chunks(p) {
            for (j, &zz) in zi.iter().enumerate() {
                let w = hat_weight(zz) + 0.1;
                a[(k, usize::from(zz))] = w;
                b[k] = w * (ln_dt[j] + 0.01 * (k % 7) as f64);
                k += 1;
            }
        }
        a[(k, 128)] = 1.0;
        k += 1;
        for zz in 1..LEVELS - 1 {
            let lw = 10.0 * (hat_weight(zz as u8) + 0.1);
            a[(k, zz - 1)] = lw;
            a[(k, zz)] = -2.0 * lw;
            a[(k, zz + 1)] = lw;
            k += 1;
        }
        let qr = solve_least_squares(a.clone(), b.clone()).expect("full rank");
        let sne = solve_sparse_least_squares(&SparseRows::from_dense(&a), b).expect("full rank");
        let worst = (qr - sne).amax();
        assert!(worst < 1e-9, "semi-normal equations off QR by {worst:e}");
    }
}
