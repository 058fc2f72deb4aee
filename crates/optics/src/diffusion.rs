//! Pieces shared by the improved-diffusion models ([`crate::better_dipole`], [`crate::pbd`]): the
//! boundary constants of d'Eon's boundary condition ([`Boundary`]), the exitance of one
//! real/virtual source pair with its derivatives, a Gauss–Legendre quadrature on doubling panels for
//! radial integrals, and the inversion of a total Rd(α′) for α′ ([`invert_total`]).
//!
//! The pair term (pbrt-v4 `BeamDiffusionMS` integrand, docs/physics.md §2.1 and §3), with σtr² =
//! s2:
//! ```text
//! E = K·Φ + c_E·Ψ,  K = c_φ/D
//! Φ = e^{−σtr d_r}/d_r − e^{−σtr d_v}/d_v                      (fluence, 4πD φ_D)
//! Ψ = z_r(1 + σtr d_r)e^{−σtr d_r}/d_r³ − z_v(1 + σtr d_v)e^{−σtr d_v}/d_v³   (4π E·n)
//! ```
//! The 1/(4π) is left to the caller. σtr = √(σa/D) has an infinite derivative at σa = 0, but E does
//! not: we differentiate in s2 = σtr², where ∂Φ/∂s2 = −(e^{−σtr d_r} − e^{−σtr d_v})/(2σtr) has the
//! finite limit (d_v − d_r)/2 (evaluated stably by [`exp_diff_over_sigma`]) and
//! ∂[(1 + σd)e^{−σd}]/∂s2 = −d²e^{−σd}/2.

use crate::dual::{Dual, Real};
use crate::error::{OpticsError, Result, eta_at_least_one};
use crate::fresnel::{FRESNEL_MOMENT_MAX_ETA, fresnel_moment1, fresnel_moment2};

/// The boundary constants of one η: A, C_φ, C_E.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Boundary {
    /// A = (1 + 3C₂)/(1 − 2C₁).
    pub a: f64,
    /// C_φ = ¼(1 − 2C₁).
    pub c_phi: f64,
    /// C_E = ½(1 − 3C₂).
    pub c_e: f64,
}

impl Boundary {
    /// The constants for η, refusing η outside [1, [`FRESNEL_MOMENT_MAX_ETA`]].
    pub(crate) fn new(eta: f64) -> Result<Self> {
        eta_at_least_one(eta)?;
        if eta > FRESNEL_MOMENT_MAX_ETA {
            return Err(OpticsError::InvalidParameter {
                name: "eta",
                value: eta,
                reason: "the improved-diffusion models (better dipole, photon beam diffusion) use \
                         pbrt's Fresnel-moment polynomials, which are fitted for 1 ≤ η ≤ 2.5; use the \
                         classical dipole or the Monte Carlo model for larger η",
            });
        }
        let (c1, c2) = (fresnel_moment1(eta), fresnel_moment2(eta));
        Ok(Self {
            a: (1.0 + 3.0 * c2) / (1.0 - 2.0 * c1),
            c_phi: 0.25 * (1.0 - 2.0 * c1),
            c_e: 0.5 * (1.0 - 3.0 * c2),
        })
    }
}

/// Refuses a reduced albedo outside [0, 1].
pub(crate) fn check_albedo(albedo_prime: f64) -> Result<()> {
    if (0.0..=1.0).contains(&albedo_prime) {
        Ok(())
    } else {
        Err(OpticsError::InvalidParameter {
            name: "albedo_prime",
            value: albedo_prime,
            reason: "the reduced albedo must lie in [0, 1]",
        })
    }
}

/// Solves total(α′) = rd for α′ ∈ [0, 1] where total rises from 0 to `max` = total(1), in
/// u = √(1 − α′); `RdOutOfModelRange` outside (0, max].
pub(crate) fn invert_total(
    model: &'static str,
    rd: f64,
    eta: f64,
    max: f64,
    total: impl Fn(f64) -> f64,
) -> Result<f64> {
    if !(rd.is_finite() && rd > 0.0 && rd <= max) {
        return Err(OpticsError::RdOutOfModelRange {
            model,
            rd,
            eta,
            max,
        });
    }
    if rd == max {
        return Ok(1.0);
    }
    let f = |u: f64| total(1.0 - u * u) - rd;
    let u =
        crate::roots::bracketed_root(f, 0.0, 1.0, 1e-13).ok_or(OpticsError::RdOutOfModelRange {
            model,
            rd,
            eta,
            max,
        })?;
    Ok(1.0 - u * u)
}

/// (e^{−σa} − e^{−σb})/σ for σ ≥ 0, computed without cancellation (`expm1`); b − a at σ = 0.
#[inline(always)]
pub(crate) fn exp_diff_over_sigma(sigma: f64, a: f64, b: f64) -> f64 {
    if sigma == 0.0 {
        b - a
    } else {
        (-sigma * a).exp() * -(-sigma * (b - a)).exp_m1() / sigma
    }
}

/// The inputs of one source pair: s2 = σtr², K = c_φ/D, depths z_r > 0 > z_v, distances d_r, d_v.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Pair<T> {
    pub s2: T,
    pub k: T,
    pub z_r: T,
    pub z_v: T,
    pub d_r: T,
    pub d_v: T,
}

/// The pair term E = K·Φ + c_E·Ψ on `f64` or on [`Dual`] (analytic partials in s2, K, z and d,
/// combined with the inputs' derivatives by the chain rule).
pub(crate) trait PairTerm: Real {
    /// E for the pair `p`; `sigma_tr` = √(s2) (passed in, computed once per model) and the constant c_E.
    fn pair_term(p: &Pair<Self>, sigma_tr: f64, c_e: f64) -> Self;
    /// The `f64` or [`Dual`] view of a dual quantity (`f64` drops the derivatives).
    fn from_dual(d: Dual) -> Self;
    /// The value (derivatives dropped).
    fn value(&self) -> f64;
}

impl PairTerm for f64 {
    #[inline(always)]
    fn pair_term(p: &Pair<f64>, sigma_tr: f64, c_e: f64) -> f64 {
        let e_r = (-sigma_tr * p.d_r).exp();
        let e_v = (-sigma_tr * p.d_v).exp();
        let phi = e_r / p.d_r - e_v / p.d_v;
        let d_r3 = p.d_r * p.d_r * p.d_r;
        let d_v3 = p.d_v * p.d_v * p.d_v;
        let psi = p.z_r * (1.0 + sigma_tr * p.d_r) * e_r / d_r3
            - p.z_v * (1.0 + sigma_tr * p.d_v) * e_v / d_v3;
        p.k * phi + c_e * psi
    }
    #[inline(always)]
    fn from_dual(d: Dual) -> f64 {
        d.v
    }
    #[inline(always)]
    fn value(&self) -> f64 {
        *self
    }
}

impl PairTerm for Dual {
    #[inline(always)]
    fn pair_term(p: &Pair<Dual>, sigma_tr: f64, c_e: f64) -> Dual {
        let (d_r, d_v, z_r, z_v, s2, k) = (p.d_r.v, p.d_v.v, p.z_r.v, p.z_v.v, p.s2.v, p.k.v);
        // e_v = e_r e^{−σ(dv − dr)}: one expm1 gives both e_v and the stable (e_r − e_v)/σ.
        let e_r = (-sigma_tr * d_r).exp();
        let m1 = (-sigma_tr * (d_v - d_r)).exp_m1();
        let e_v = e_r + e_r * m1;
        let exp_diff = if sigma_tr == 0.0 {
            d_v - d_r
        } else {
            -e_r * m1 / sigma_tr
        };
        let h_r = (1.0 + sigma_tr * d_r) * e_r;
        let h_v = (1.0 + sigma_tr * d_v) * e_v;
        let (ir, iv) = (1.0 / d_r, 1.0 / d_v);
        let (ir2, iv2) = (ir * ir, iv * iv);
        let (ir3, iv3) = (ir2 * ir, iv2 * iv);
        let phi = e_r * ir - e_v * iv;
        let psi = z_r * h_r * ir3 - z_v * h_v * iv3;
        // Partials of Φ and Ψ (module docs); ∂h/∂d = −s2·d·e.
        let dphi_ds2 = -0.5 * exp_diff;
        let dphi_ddr = -h_r * ir2;
        let dphi_ddv = h_v * iv2;
        let dpsi_ds2 = -0.5 * (z_r * e_r * ir - z_v * e_v * iv);
        let dpsi_dzr = h_r * ir3;
        let dpsi_dzv = -h_v * iv3;
        let dpsi_ddr = -z_r * (s2 * e_r * ir2 + 3.0 * h_r * ir3 * ir);
        let dpsi_ddv = z_v * (s2 * e_v * iv2 + 3.0 * h_v * iv3 * iv);
        let de_ds2 = k * dphi_ds2 + c_e * dpsi_ds2;
        let de_ddr = k * dphi_ddr + c_e * dpsi_ddr;
        let de_ddv = k * dphi_ddv + c_e * dpsi_ddv;
        let de_dzr = c_e * dpsi_dzr;
        let de_dzv = c_e * dpsi_dzv;
        let mut d = [0.0; 2];
        for (j, dj) in d.iter_mut().enumerate() {
            *dj = phi * p.k.d[j]
                + de_ds2 * p.s2.d[j]
                + de_ddr * p.d_r.d[j]
                + de_ddv * p.d_v.d[j]
                + de_dzr * p.z_r.d[j]
                + de_dzv * p.z_v.d[j];
        }
        Dual {
            v: k * phi + c_e * psi,
            d,
        }
    }
    #[inline(always)]
    fn from_dual(d: Dual) -> Dual {
        d
    }
    #[inline(always)]
    fn value(&self) -> f64 {
        self.v
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The dual pair term's derivatives agree with central differences of the f64 term, including
    /// through s2 where σtr is small.
    #[test]
    fn pair_term_partials_match_finite_differences() {
        let mk = |x: [f64; 6]| {
            [
                Dual::variable(x[0], 0),
                Dual::constant(x[1]),
                Dual::constant(x[2]),
                Dual::constant(x[3]),
                Dual::constant(x[4]),
                Dual::constant(x[5]),
            ]
        };
        let base = [0.04, 0.8, 0.9, -2.1, 1.3, 2.4];
        for which in 0..6 {
            for s2 in [0.04, 1e-6] {
                let mut x = base;
                x[0] = s2;
                // Put the variable in slot `which` (direction 0).
                let mut v = mk(x);
                v[0] = Dual::constant(x[0]);
                v[which] = Dual::variable(x[which], 0);
                let p = Pair {
                    s2: v[0],
                    k: v[1],
                    z_r: v[2],
                    z_v: v[3],
                    d_r: v[4],
                    d_v: v[5],
                };
                let got = Dual::pair_term(&p, x[0].sqrt(), 0.37);
                let f = |x: [f64; 6]| {
                    f64::pair_term(
                        &Pair {
                            s2: x[0],
                            k: x[1],
                            z_r: x[2],
                            z_v: x[3],
                            d_r: x[4],
                            d_v: x[5],
                        },
                        x[0].sqrt(),
                        0.37,
                    )
                };
                // Relative step 1e-3 at tiny s2 (the value is O(1): a smaller step drowns in rounding).
                let h = if which == 0 && s2 < 1e-3 { 1e-3 } else { 1e-6 } * x[which].abs();
                let (mut xp, mut xm) = (x, x);
                xp[which] += h;
                xm[which] -= h;
                let fd = (f(xp) - f(xm)) / (2.0 * h);
                assert!(
                    (got.d[0] - fd).abs() <= 1e-6 * fd.abs().max(1e-3),
                    "slot {which}, s2 {s2}: {} vs {fd}",
                    got.d[0]
                );
                assert!((got.v - f(x)).abs() <= 1e-14 * f(x).abs());
            }
        }
    }

    #[test]
    fn exp_diff_is_stable() {
        assert_eq!(exp_diff_over_sigma(0.0, 1.0, 3.0), 2.0);
        let s = 1e-12;
        assert!((exp_diff_over_sigma(s, 1.0, 3.0) - 2.0).abs() < 1e-10);
        let s = 0.7;
        let want = ((-s * 1.0f64).exp() - (-s * 3.0f64).exp()) / s;
        assert!((exp_diff_over_sigma(s, 1.0, 3.0) - want).abs() < 1e-15);
    }
}
