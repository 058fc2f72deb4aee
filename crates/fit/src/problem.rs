//! The least-squares problems for the `levenberg-marquardt` crate, and the starting point.
//!
//! Residuals are in log space of the profile, weighted by each ring's relative standard error
//! σᵢ = sᵢ/yᵢ (the delta-method standard deviation of ln yᵢ):
//!
//! ```text
//! eᵢ = (ln k + ln m(rᵢ; σ′s, σa) − ln yᵢ) / σᵢ
//! ```
//!
//! with m the model (convolved with the spot when it is a disk) and k the profile's scale. ln k
//! enters linearly, so it is eliminated exactly (variable projection, Golub & Pereyra 1973): for
//! any shape the best ln k is the weighted mean of ln yᵢ − ln mᵢ, and the solver varies only the
//! coefficients. That makes the paper's proposed method what it says — one unknown, σ′s — and
//! saves the solver a direction in which nothing is hard. The unknowns are logarithms, so every
//! coefficient stays positive:
//! - proposed (Choi et al. 2014, eq. 2): x = (ln σ′s), σa = σ′s(1/α′ − 1) with α′ from the
//!   spectrophotometer; k projected;
//! - proposed, normalised with the spectrophotometer: x = (ln σ′s); k such that the measured and
//!   the modelled profile carry the same flux over the fitted rings, Σ Aᵢyᵢ = k Σ Aᵢmᵢ (Aᵢ the ring
//!   areas), the model's own total being the spectrophotometer's Rd;
//! - existing (Jensen et al. 2001): x = (ln σ′t, ln σtr) (see [`physical`] for why not
//!   (ln σ′s, ln σa)); k projected.
//!
//! The Jacobian is analytic (the models' derivatives through the chain rule, plus the derivative of
//! the projected ln k); residuals and Jacobian are computed once per parameter set in `set_params`
//! (ARCHITECTURE.md, "Code conventions": cache shared work). Standard errors come from the full
//! problem's Jacobian (ln k as a free column), whose covariance restricted to the coefficients
//! equals the projected problem's.

use levenberg_marquardt::LeastSquaresProblem;
use nalgebra::{DMatrix, DVector, Dyn, Owned};
use scatterfit_optics::{ModelFamily, OpticalProperties, ProfileSample};

use crate::spot::SpotKernel;

/// The range of coefficients [mm⁻¹] the solver may visit; outside it a trial point gets a penalty
/// residual (and is rejected by the trust region).
pub(crate) const COEFF_RANGE: (f64, f64) = (1e-9, 1e6);

/// A residual that makes any trial point worse than any real one.
const PENALTY: f64 = 1e10;

/// Which parameters are free.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Unknowns {
    /// x = (ln σ′s); σa = c σ′s with c = 1/α′ − 1; k free (projected).
    Proposed { c: f64 },
    /// x = (ln σ′s); σa = c σ′s; k from the flux over the fitted rings, `flux` = Σ Aᵢ yᵢ.
    Normalised { c: f64, flux: f64 },
    /// x = (ln σ′t, ln σtr); k free (projected).
    Existing,
}

impl Unknowns {
    /// Unknowns of the measurement, the scale included when it is fitted.
    pub(crate) fn count(self) -> usize {
        self.solver_count() + usize::from(self.scale_free())
    }

    /// Unknowns the solver varies.
    pub(crate) fn solver_count(self) -> usize {
        match self {
            Unknowns::Proposed { .. } | Unknowns::Normalised { .. } => 1,
            Unknowns::Existing => 2,
        }
    }

    /// Whether k is fitted (else fixed by the spectrophotometer).
    pub(crate) fn scale_free(self) -> bool {
        !matches!(self, Unknowns::Normalised { .. })
    }
}

/// The data a problem is fitted to (one channel's selected rings).
#[derive(Clone, Copy)]
pub(crate) struct Data<'a> {
    pub r: &'a [f64],
    pub ln_y: &'a [f64],
    /// 1/σᵢ.
    pub w: &'a [f64],
    /// Ring areas 2πrᵢΔrᵢ [mm²] (flux weights of the normalised method).
    pub area: &'a [f64],
}

/// The model side of a problem.
#[derive(Clone, Copy)]
pub(crate) struct Forward<'a> {
    pub model: &'a dyn ModelFamily,
    pub eta: f64,
    /// The spot convolution, or `None` for a point of incidence.
    pub kernel: Option<&'a SpotKernel>,
}

/// The model along the solver's unknowns at the data's radii, as arrays: mᵢ and ∂mᵢ/∂xⱼ.
#[derive(Debug, Clone, Default)]
pub(crate) struct Evaluated {
    pub m: Vec<f64>,
    pub d: [Vec<f64>; 2],
}

/// Scratch space of [`Forward::eval`].
#[derive(Debug, Clone, Default)]
pub(crate) struct Scratch {
    samples: Vec<ProfileSample>,
    values: Vec<f64>,
    derivs: [Vec<f64>; 2],
}

impl Forward<'_> {
    /// The model (convolved when there is a kernel) at radii `r` into `out`: values, and the
    /// derivatives along the first `q` unknowns, ∂m/∂xⱼ = ∂m/∂σ′s·chain[j][0] + ∂m/∂σa·chain[j][1].
    /// The derivatives are combined at the nodes before the convolution (it is linear), so a
    /// one-unknown fit convolves two arrays, not three.
    pub(crate) fn eval(
        &self,
        props: &OpticalProperties,
        chain: &[[f64; 2]; 2],
        q: usize,
        r: &[f64],
        scratch: &mut Scratch,
        out: &mut Evaluated,
    ) {
        let n = r.len();
        out.m.resize(n, 0.0);
        for d in out.d.iter_mut().take(q) {
            d.resize(n, 0.0);
        }
        let points = self.kernel.map_or(r, |k| k.nodes());
        scratch.samples.resize(points.len(), ZERO);
        self.model.eval(props, points, &mut scratch.samples);
        let combine = |s: &ProfileSample, j: usize| {
            s.d_sigma_s_prime * chain[j][0] + s.d_sigma_a * chain[j][1]
        };
        match self.kernel {
            None => {
                for (i, s) in scratch.samples.iter().enumerate() {
                    out.m[i] = s.rd;
                    for j in 0..q {
                        out.d[j][i] = combine(s, j);
                    }
                }
            }
            Some(k) => {
                scratch.values.clear();
                scratch.values.extend(scratch.samples.iter().map(|s| s.rd));
                for j in 0..q {
                    let d = &mut scratch.derivs[j];
                    d.clear();
                    d.extend(scratch.samples.iter().map(|s| combine(s, j)));
                }
                // The value with the first derivative in one pass over the rows.
                let [d0, d1] = &mut out.d;
                if q == 0 {
                    k.apply(&scratch.values, &mut out.m);
                } else {
                    k.apply_pair(&scratch.values, &scratch.derivs[0], &mut out.m, d0);
                }
                if q == 2 {
                    k.apply(&scratch.derivs[1], d1);
                }
            }
        }
    }
}

pub(crate) const ZERO: ProfileSample = ProfileSample {
    rd: 0.0,
    d_sigma_s_prime: 0.0,
    d_sigma_a: 0.0,
};

/// The physical coefficients at a solver vector x, and per unknown xⱼ the derivatives
/// (∂σ′s/∂xⱼ, ∂σa/∂xⱼ) for the chain rule.
///
/// The existing method's unknowns are x = (ln σ′t, ln σtr), not (ln σ′s, ln σa): far from the
/// source the dipole's shape depends on σtr alone and near it on σ′t (through zr and zv), so these
/// two are nearly independent, where σ′s and σa lie in a long curved valley. σa = σtr²/(3σ′t),
/// σ′s = σ′t − σa (Jensen et al. 2001, σtr = √(3σaσ′t)).
pub(crate) fn physical(unknowns: Unknowns, x: &[f64]) -> Physical {
    match unknowns {
        Unknowns::Proposed { c } | Unknowns::Normalised { c, .. } => {
            let sp = x[0].exp();
            Physical {
                sigma_s_prime: sp,
                sigma_a: c * sp,
                chain: [[sp, c * sp], [0.0, 0.0]],
            }
        }
        Unknowns::Existing => {
            let (st, tr) = (x[0].exp(), x[1].exp());
            let sa = tr * tr / (3.0 * st);
            Physical {
                sigma_s_prime: st - sa,
                sigma_a: sa,
                chain: [[st + sa, -sa], [-2.0 * sa, 2.0 * sa]],
            }
        }
    }
}

/// The solver vector for given coefficients.
pub(crate) fn solver_x(unknowns: Unknowns, sigma_s_prime: f64, sigma_a: f64) -> Vec<f64> {
    match unknowns {
        Unknowns::Proposed { .. } | Unknowns::Normalised { .. } => vec![sigma_s_prime.ln()],
        Unknowns::Existing => {
            let st = sigma_s_prime + sigma_a;
            vec![st.ln(), 0.5 * (3.0 * sigma_a * st).ln()]
        }
    }
}

/// What [`physical`] returns.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Physical {
    pub sigma_s_prime: f64,
    pub sigma_a: f64,
    /// chain[j] = (∂σ′s/∂xⱼ, ∂σa/∂xⱼ).
    pub chain: [[f64; 2]; 2],
}

/// A least-squares problem: one channel, one method.
pub(crate) struct Problem<'a> {
    pub data: Data<'a>,
    pub forward: Forward<'a>,
    pub unknowns: Unknowns,
    x: DVector<f64>,
    res: DVector<f64>,
    jac: DMatrix<f64>,
    /// d ln mᵢ/dxⱼ (before the projection of k).
    g: DMatrix<f64>,
    ev: Evaluated,
    scratch: Scratch,
    /// ln k at the current parameters.
    pub ln_k: f64,
    /// d ln k/dxⱼ at the current parameters.
    dlnk: [f64; 2],
    /// Whether the current point is a real evaluation (not a penalty).
    pub valid: bool,
}

impl<'a> Problem<'a> {
    pub(crate) fn new(
        data: Data<'a>,
        forward: Forward<'a>,
        unknowns: Unknowns,
        x0: &[f64],
    ) -> Self {
        let (n, q) = (data.r.len(), unknowns.solver_count());
        let mut problem = Self {
            data,
            forward,
            unknowns,
            x: DVector::from_column_slice(x0),
            res: DVector::zeros(n),
            jac: DMatrix::zeros(n, q),
            g: DMatrix::zeros(n, q),
            ev: Evaluated::default(),
            scratch: Scratch::default(),
            ln_k: 0.0,
            dlnk: [0.0; 2],
            valid: false,
        };
        let x = problem.x.clone();
        problem.set_params(&x);
        problem
    }

    /// The current solver vector.
    pub(crate) fn params_slice(&self) -> &[f64] {
        self.x.as_slice()
    }

    /// d ln k / dx₀ at the current parameters.
    pub(crate) fn dlnk_dx0(&self) -> f64 {
        self.dlnk[0]
    }

    /// The model at the current parameters, at the data's radii (mm⁻², unscaled).
    pub(crate) fn model_values(&self) -> &[f64] {
        &self.ev.m
    }

    /// The weighted residuals at the current parameters.
    pub(crate) fn residual_vector(&self) -> &DVector<f64> {
        &self.res
    }

    /// JᵀJ of the full problem at the current parameters, J's columns being the coefficients'
    /// wᵢ·d ln mᵢ/dxⱼ and, when k is fitted, the column wᵢ of ln k (for the normalised method, the
    /// solver's own Jacobian: its k is not free). Summed directly: J has only two or three
    /// columns, and a general matrix product of 300 × 3 costs more than the sums.
    pub(crate) fn full_jtj(&self) -> DMatrix<f64> {
        let (n, q) = self.g.shape();
        let w = &self.data.w[..n];
        if !self.unknowns.scale_free() {
            return self.jac.tr_mul(&self.jac);
        }
        let g = self.g.as_slice();
        let col = |c: usize| &g[c * n..(c + 1) * n];
        let mut jtj = DMatrix::zeros(q + 1, q + 1);
        for a in 0..q {
            for b in a..q {
                let v: f64 = (0..n).map(|i| w[i] * w[i] * col(a)[i] * col(b)[i]).sum();
                jtj[(a, b)] = v;
                jtj[(b, a)] = v;
            }
            let v: f64 = (0..n).map(|i| w[i] * w[i] * col(a)[i]).sum();
            jtj[(a, q)] = v;
            jtj[(q, a)] = v;
        }
        jtj[(q, q)] = w.iter().map(|w| w * w).sum();
        jtj
    }

    fn penalise(&mut self) {
        self.res.fill(PENALTY);
        self.jac.fill(0.0);
        self.valid = false;
    }
}

impl LeastSquaresProblem<f64, Dyn, Dyn> for Problem<'_> {
    type ResidualStorage = Owned<f64, Dyn>;
    type JacobianStorage = Owned<f64, Dyn, Dyn>;
    type ParameterStorage = Owned<f64, Dyn>;

    fn set_params(&mut self, x: &DVector<f64>) {
        self.x.copy_from(x);
        let phys = physical(self.unknowns, x.as_slice());
        let (sp, sa) = (phys.sigma_s_prime, phys.sigma_a);
        let (lo, hi) = COEFF_RANGE;
        let in_range = |v: f64| v.is_finite() && (lo..=hi).contains(&v);
        let sa_ok = match self.unknowns {
            // σa = cσ′s may be exactly 0 (α′ = 1).
            Unknowns::Proposed { .. } | Unknowns::Normalised { .. } => sa.is_finite() && sa <= hi,
            Unknowns::Existing => in_range(sa),
        };
        if !in_range(sp) || !sa_ok {
            return self.penalise();
        }
        let Ok(props) = OpticalProperties::new(sp, sa, self.forward.eta) else {
            return self.penalise();
        };
        let q = self.unknowns.solver_count();
        self.forward.eval(
            &props,
            &phys.chain,
            q,
            self.data.r,
            &mut self.scratch,
            &mut self.ev,
        );
        // g = d ln m/dx and the scale: projected (weighted mean) or from the flux. Plain slices
        // and one pass per quantity, so the loops vectorise (this is the fit's hot path).
        let n = self.ev.m.len();
        let (w, ln_y, m) = (&self.data.w[..n], &self.data.ln_y[..n], &self.ev.m[..n]);
        let res = &mut self.res.as_mut_slice()[..n];
        // Keep ln m in the residual slot until ln k is known.
        for (r, &mi) in res.iter_mut().zip(m) {
            *r = mi.ln();
        }
        let (mut sw, mut sd) = (0.0, 0.0);
        for i in 0..n {
            let w2 = w[i] * w[i];
            sw += w2;
            sd += w2 * (ln_y[i] - res[i]);
        }
        // A model value that is not finite and > 0 has no finite logarithm, and the weights are
        // > 0: one such value makes the sum non-finite (the check costs no pass of its own).
        if !sd.is_finite() {
            return self.penalise();
        }
        let g = self.g.as_mut_slice();
        let mut sg = [0.0; 2];
        for (j, sgj) in sg.iter_mut().enumerate().take(q) {
            let (gj, dj) = (&mut g[j * n..(j + 1) * n], &self.ev.d[j][..n]);
            let mut s = 0.0;
            for i in 0..n {
                let gij = dj[i] / m[i];
                gj[i] = gij;
                s += w[i] * w[i] * gij;
            }
            *sgj = s;
        }
        let (ln_k, dlnk) = match self.unknowns {
            Unknowns::Normalised { flux, .. } => {
                let area = &self.data.area[..n];
                let fm: f64 = area.iter().zip(m).map(|(a, mi)| a * mi).sum();
                let fg: f64 = area
                    .iter()
                    .zip(&self.ev.d[0][..n])
                    .map(|(a, d)| a * d)
                    .sum();
                (flux.ln() - fm.ln(), [-fg / fm, 0.0])
            }
            _ => (sd / sw, [-sg[0] / sw, -sg[1] / sw]),
        };
        self.ln_k = ln_k;
        self.dlnk = dlnk;
        for i in 0..n {
            res[i] = w[i] * (ln_k + res[i] - ln_y[i]);
        }
        let jac = self.jac.as_mut_slice();
        for (j, dk) in dlnk.iter().enumerate().take(q) {
            let (jj, gj) = (&mut jac[j * n..(j + 1) * n], &g[j * n..(j + 1) * n]);
            for i in 0..n {
                jj[i] = w[i] * (gj[i] + dk);
            }
        }
        self.valid = true;
    }

    fn params(&self) -> DVector<f64> {
        self.x.clone()
    }

    fn residuals(&self) -> Option<DVector<f64>> {
        Some(self.res.clone())
    }

    fn jacobian(&self) -> Option<DMatrix<f64>> {
        Some(self.jac.clone())
    }
}

/// σ′t grid of the start search: 10⁻³ … 10³ mm⁻¹, three points per decade.
fn sigma_t_grid() -> impl Iterator<Item = f64> {
    (0..=18).map(|i| 10f64.powf(-3.0 + i as f64 / 3.0))
}

/// At most this many rings (spread evenly) are used by the start search: the proposed method's
/// one-dimensional search needs few (Levenberg–Marquardt refines it on every ring); the existing
/// method's has competing valleys and needs the shape in more detail (with 8 rings it picks the
/// wrong valley in the demo's existing-method column: median σ′s error 35 % → 70 %).
const START_RINGS_PROPOSED: usize = 8;
const START_RINGS_EXISTING: usize = 16;

/// A starting point that needs no hand tuning: a grid search of σ′t (and σtr for the existing
/// method) on a subsample of the rings with the scale eliminated as in the solver, refined by
/// golden-section search in ln σ′t.
/// The proposed method's one-dimensional search uses the point model (cheap; Levenberg–Marquardt
/// then corrects for the spot from a nearby start); the existing method's two-dimensional search
/// has competing valleys and uses the spot-convolved model on a coarse node grid (a/4), since
/// near the spot the point model's shape error would pick the wrong one. Returns x₀ for
/// `unknowns`, best first (several for the existing method).
pub(crate) fn start(data: &Data<'_>, forward: &Forward<'_>, unknowns: Unknowns) -> Vec<Vec<f64>> {
    let n = data.r.len();
    let rings = match unknowns {
        Unknowns::Existing => START_RINGS_EXISTING,
        _ => START_RINGS_PROPOSED,
    };
    let step = n.div_ceil(rings).max(1);
    let idx: Vec<usize> = (0..n).step_by(step).collect();
    let r: Vec<f64> = idx.iter().map(|&i| data.r[i]).collect();
    let ln_y: Vec<f64> = idx.iter().map(|&i| data.ln_y[i]).collect();
    let w2: Vec<f64> = idx.iter().map(|&i| data.w[i] * data.w[i]).collect();
    let mut ev = Evaluated::default();
    let sub_kernel = match (unknowns, forward.kernel) {
        (Unknowns::Existing, Some(k)) => {
            SpotKernel::new(k.radius_mm(), &r, 0.25 * k.radius_mm()).ok()
        }
        _ => None,
    };
    let search = Forward {
        model: forward.model,
        eta: forward.eta,
        kernel: sub_kernel.as_ref(),
    };
    let mut scratch = Scratch::default();
    // Cost and best ln k of the shape (α′, σ′t).
    let r_last = r.last().copied().unwrap_or(0.0);
    let mut cost = |alpha: f64, sigma_t: f64| -> (f64, f64) {
        // e^{−σtr r} would underflow (and subnormal arithmetic is slow): no such profile was
        // measured.
        if sigma_t * (3.0 * (1.0 - alpha)).max(0.0).sqrt() * r_last > 600.0 {
            return (f64::INFINITY, 0.0);
        }
        let Ok(props) =
            OpticalProperties::new(alpha * sigma_t, (1.0 - alpha) * sigma_t, forward.eta)
        else {
            return (f64::INFINITY, 0.0);
        };
        search.eval(&props, &[[0.0; 2]; 2], 0, &r, &mut scratch, &mut ev);
        let (mut sw, mut swd) = (0.0, 0.0);
        for (m, &w) in ev.m.iter_mut().zip(&w2) {
            if !(*m > 0.0 && m.is_finite()) {
                return (f64::INFINITY, 0.0);
            }
            // ln m in place: used twice below.
            *m = m.ln();
            sw += w;
        }
        for ((ln_m, &ly), &w) in ev.m.iter().zip(&ln_y).zip(&w2) {
            swd += w * (ly - ln_m);
        }
        let ln_k = swd / sw;
        let c =
            ev.m.iter()
                .zip(&ln_y)
                .zip(&w2)
                .map(|((ln_m, &ly), &w)| w * (ln_k + ln_m - ly).powi(2))
                .sum();
        (c, ln_k)
    };
    let fixed_alpha = match unknowns {
        Unknowns::Proposed { c } | Unknowns::Normalised { c, .. } => Some(1.0 / (1.0 + c)),
        Unknowns::Existing => None,
    };
    let Some(alpha) = fixed_alpha else {
        // Existing: σtr from the far field's log-slope; for each σ′t of the grid the best σtr near
        // that estimate (the valley floor); every local minimum of that profile along σ′t is a
        // candidate basin, refined in σ′t. The dipole's (σ′t, σtr) landscape has two valleys for
        // some materials (one at large σ′t, where zr, zv → 0), so the solver runs from each.
        let tr0 = sigma_tr_from_slope(data.r, data.ln_y, data.w);
        let mut floor = |ln_st: f64| -> (f64, f64) {
            let st = ln_st.exp();
            let (ln_tr, c) = golden(
                |ln_tr| {
                    let tr = ln_tr.exp();
                    let sa = tr * tr / (3.0 * st);
                    if sa >= st {
                        return f64::INFINITY;
                    }
                    cost(1.0 - sa / st, st).0
                },
                tr0.ln() - 0.7,
                tr0.ln() + 0.7,
                14,
            );
            (c, ln_tr)
        };
        let grid: Vec<f64> = sigma_t_grid().map(f64::ln).collect();
        let costs: Vec<f64> = grid.iter().map(|&g| floor(g).0).collect();
        let step = 10f64.ln() / 3.0;
        let mut basins: Vec<(f64, f64, f64)> = (0..grid.len())
            .filter(|&i| {
                (i == 0 || costs[i] <= costs[i - 1])
                    && (i + 1 == grid.len() || costs[i] <= costs[i + 1])
                    && costs[i].is_finite()
            })
            .map(|i| {
                let (ln_st, _) = golden(|g| floor(g).0, grid[i] - step, grid[i] + step, 10);
                let (c, ln_tr) = floor(ln_st);
                (c, ln_st, ln_tr)
            })
            .collect();
        basins.sort_by(|a, b| a.0.total_cmp(&b.0));
        return basins
            .iter()
            .take(MAX_BASINS)
            .map(|&(_, ln_st, ln_tr)| vec![ln_st, ln_tr])
            .collect();
    };
    // The grid is centred on σ′t = σtr/√(3(1 − α′)) with σtr from the far field's log-slope
    // (Jensen et al. 2001, §2.4), spanning a factor 4.6 either way, and walks outward while the
    // best point is on its edge (a poor slope estimate costs a few evaluations, not a wrong start).
    let step = 10f64.ln() / 3.0;
    let (lo_lim, hi_lim) = (1e-3f64.ln(), 1e3f64.ln());
    let centre = if alpha < 1.0 - 1e-12 {
        let tr0 = sigma_tr_from_slope(data.r, data.ln_y, data.w);
        (tr0 / (3.0 * (1.0 - alpha)).sqrt())
            .ln()
            .clamp(lo_lim, hi_lim)
    } else {
        0.0
    };
    let mut grid: Vec<(f64, f64)> = (-2..=2)
        .map(|i| centre + step * f64::from(i))
        .filter(|g| (lo_lim..=hi_lim).contains(g))
        .map(|g| (g, cost(alpha, g.exp()).0))
        .collect();
    loop {
        let i = (0..grid.len())
            .min_by(|&a, &b| grid[a].1.total_cmp(&grid[b].1))
            .unwrap_or(0);
        let next = if i == 0 && grid.len() > 1 {
            Some(grid[0].0 - step)
        } else if i + 1 == grid.len() {
            Some(grid[i].0 + step)
        } else {
            None
        };
        match next.filter(|g| (lo_lim..=hi_lim).contains(g)) {
            Some(g) => {
                let c = cost(alpha, g.exp()).0;
                if i == 0 {
                    grid.insert(0, (g, c));
                } else {
                    grid.push((g, c));
                }
                if c >= grid[if i == 0 { 1 } else { grid.len() - 2 }].1 {
                    break;
                }
            }
            None => break,
        }
    }
    let best_i = (0..grid.len())
        .min_by(|&a, &b| grid[a].1.total_cmp(&grid[b].1))
        .unwrap_or(0);
    let best = (grid[best_i].1, grid[best_i].0.exp());
    let (_, st0) = best;
    // Golden-section refinement of ln σ′t within one grid step either side.
    let (ln_st, _) = golden(
        |ln_st| cost(alpha, ln_st.exp()).0,
        st0.ln() - step,
        st0.ln() + step,
        8,
    );
    vec![vec![(alpha * ln_st.exp()).ln()]]
}

/// Most starting points the existing method's solver runs from.
const MAX_BASINS: usize = 3;

/// Golden-section search for the minimum of `f` on [a, b] with `iterations` shrinking steps;
/// returns (argmin, min).
fn golden(mut f: impl FnMut(f64) -> f64, mut a: f64, mut b: f64, iterations: usize) -> (f64, f64) {
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let mut x1 = b - g * (b - a);
    let mut x2 = a + g * (b - a);
    let (mut f1, mut f2) = (f(x1), f(x2));
    for _ in 0..iterations {
        if f1 < f2 {
            b = x2;
            x2 = x1;
            f2 = f1;
            x1 = b - g * (b - a);
            f1 = f(x1);
        } else {
            a = x1;
            x1 = x2;
            f1 = f2;
            x2 = a + g * (b - a);
            f2 = f(x2);
        }
    }
    if f1 < f2 { (x1, f1) } else { (x2, f2) }
}

/// σtr from the log-slope of the outer half of the profile: a weighted linear fit of
/// ln y = a − σtr r − 2 ln r, the dipole's far field Rd ∝ e^{−σtr r}/r² (Jensen et al. 2001, eq. 4
/// for r ≫ zv, σtr r ≫ 1). A starting value only; floored at 10⁻³ mm⁻¹.
fn sigma_tr_from_slope(r: &[f64], ln_y: &[f64], w: &[f64]) -> f64 {
    let n = r.len();
    let (mut s, mut sx, mut sy, mut sxx, mut sxy) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for i in n / 2..n {
        let (x, y, ww) = (r[i], ln_y[i] + 2.0 * r[i].ln(), w[i] * w[i]);
        s += ww;
        sx += ww * x;
        sy += ww * y;
        sxx += ww * x * x;
        sxy += ww * x * y;
    }
    let slope = (s * sxy - sx * sy) / (s * sxx - sx * sx);
    if slope.is_finite() {
        (-slope).max(1e-3)
    } else {
        0.1
    }
}
