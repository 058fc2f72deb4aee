//! d'Eon 2012, "A better dipole" (Eugene d'Eon, technical report; abstract: "modified diffusion
//! asymptotics, improved exitance calculations and consistent boundary conditions"), as docs/physics.md §3
//! writes it. The paper itself was not retrievable; the formulas are docs/physics.md's reconstruction from
//! pbrt-v4's `BeamDiffusionMS` integrand (Habel et al. 2013 build on d'Eon's improved diffusion) and a
//! third-party `BetterDipole` class, so the α′² factor and the exact constants are *unverified against
//! the paper* (docs/physics.md §3, §10 item 2). The model is pbrt's photon-beam integrand evaluated at the
//! single depth zr = 1/σ′t with κ = 1.
//!
//! Parameters and domains: σ′s > 0, σa ≥ 0 [mm⁻¹], 1 ≤ η ≤ [`crate::fresnel::FRESNEL_MOMENT_MAX_ETA`] (the Fresnel
//! moments are pbrt's polynomial fits, [`crate::fresnel::fresnel_moment1`],
//! [`crate::fresnel::fresnel_moment2`]).
//!
//! ```text
//! σ′t = σ′s + σa,  α′ = σ′s/σ′t,  C₁, C₂ = Fresnel moments of η
//! A = (1 + 3C₂)/(1 − 2C₁),  D = (2σa + σ′s)/(3σ′t²)  (Grosjean),  σtr = √(σa/D)
//! zr = 1/σ′t,  zb = 2AD,  zv = −zr − 2zb            (virtual source above the surface)
//! C_φ = ¼(1 − 2C₁),  C_E = ½(1 − 3C₂),  dr = √(r² + zr²),  dv = √(r² + zv²)
//! Rd(r) = α′²/(4π)·[(C_E zr(σtr dr + 1)/dr² + C_φ/D) e^{−σtr dr}/dr
//!                  − (C_E zv(σtr dv + 1)/dv² + C_φ/D) e^{−σtr dv}/dv]
//! ```
//! Total diffuse reflectance, integrating term by term with d dd = r dr
//! (∫2πr e^{−σd}/d dr = 2πe^{−σ|z|}/σ, ∫2πr z(σd + 1)e^{−σd}/d³ dr = 2π sign(z) e^{−σ|z|}):
//! ```text
//! Rd = (α′²/2)·[C_E(e^{−σtr zr} + e^{−σtr|zv|}) + C_φ/D·(e^{−σtr zr} − e^{−σtr|zv|})/σtr]
//! ```
//! which is 1 at α′ = 1 for every η (4AC_φ + 2C_E = 2) and matches docs/physics.md §3's numerically
//! integrated column.
//!
//! Derivatives in σ′s and σa are analytic: forward-mode duals for the parameter chain and analytic
//! partials of the source-pair term (`crate::diffusion`), finite at σa = 0.

use std::f64::consts::PI;

use crate::diffusion::{Boundary, Pair, PairTerm, check_albedo, exp_diff_over_sigma, invert_total};
use crate::dual::{Dual, Real};
use crate::error::Result;
use crate::family::{ProfileModel, ProfileSample};
use crate::properties::OpticalProperties;

/// The boundary coefficient A(η) = (1 + 3C₂)/(1 − 2C₁) of d'Eon's boundary condition (docs/physics.md §3;
/// 2.949348 at η = 1.4, against the classical dipole's 3.250697).
///
/// # Errors
/// `InvalidParameter` for η outside [1, [`crate::fresnel::FRESNEL_MOMENT_MAX_ETA`]].
pub fn a_coefficient(eta: f64) -> Result<f64> {
    Ok(Boundary::new(eta)?.a)
}

/// The better dipole for one set of optical properties, with its parameter-dependent quantities
/// computed once as duals in (σ′s, σa).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BetterDipole {
    props: OpticalProperties,
    bc: Boundary,
    /// σtr (value; its derivatives go through s2 = σtr²).
    sigma_tr: f64,
    /// α′²/(4π), s2 = σtr², K = C_φ/D, zr, zv: duals in (σ′s, σa).
    scale: Dual,
    s2: Dual,
    k: Dual,
    z_r: Dual,
    z_v: Dual,
}

impl BetterDipole {
    /// The better dipole for `props` (formulas in the module documentation).
    ///
    /// # Errors
    /// `InvalidParameter` for η > [`crate::fresnel::FRESNEL_MOMENT_MAX_ETA`].
    pub fn new(props: &OpticalProperties) -> Result<Self> {
        let bc = Boundary::new(props.eta())?;
        let sp = Dual::variable(props.sigma_s_prime(), 0);
        let sa = Dual::variable(props.sigma_a(), 1);
        let st = sp + sa;
        let albedo = sp / st;
        // Grosjean's D = (2σa + σ′s)/(3σ′t²); s2 = σtr² = σa/D.
        let d = (sa * 2.0 + sp) / (st * st * 3.0);
        let s2 = sa / d;
        let z_r = st.recip();
        let z_v = -z_r - d * (4.0 * bc.a);
        Ok(Self {
            props: *props,
            bc,
            sigma_tr: s2.v.sqrt(),
            scale: albedo * albedo * (0.25 / PI),
            s2,
            k: d.recip() * bc.c_phi,
            z_r,
            z_v,
        })
    }

    /// The optical properties of this model.
    pub fn properties(&self) -> &OpticalProperties {
        &self.props
    }

    #[inline(always)]
    fn eval<T: PairTerm>(&self, r_mm: f64) -> T {
        let r2 = r_mm * r_mm;
        let z_r = T::from_dual(self.z_r);
        let z_v = T::from_dual(self.z_v);
        let p = Pair {
            s2: T::from_dual(self.s2),
            k: T::from_dual(self.k),
            z_r,
            z_v,
            d_r: (z_r * z_r + r2).sqrt(),
            d_v: (z_v * z_v + r2).sqrt(),
        };
        T::pair_term(&p, self.sigma_tr, self.bc.c_e) * T::from_dual(self.scale)
    }

    /// Rd(r) [mm⁻²] at `r_mm` from the point of incidence.
    pub fn rd(&self, r_mm: f64) -> f64 {
        self.eval::<f64>(r_mm)
    }

    /// Rd(r) with its analytic partial derivatives in σ′s and σa.
    pub fn rd_with_derivatives(&self, r_mm: f64) -> ProfileSample {
        let v: Dual = self.eval(r_mm);
        ProfileSample {
            rd: v.v,
            d_sigma_s_prime: v.d[0],
            d_sigma_a: v.d[1],
        }
    }

    /// Total diffuse reflectance ∫2πr Rd(r) dr of this model (closed form, module docs).
    pub fn rd_total(&self) -> f64 {
        total_closed_form(self.props.albedo_prime(), &self.bc)
    }
}

impl ProfileModel for BetterDipole {
    fn rd(&self, r_mm: f64) -> f64 {
        BetterDipole::rd(self, r_mm)
    }

    fn profile_with_derivatives_into(&self, radii_mm: &[f64], out: &mut [ProfileSample]) {
        for (r, o) in radii_mm.iter().zip(out.iter_mut()) {
            *o = self.rd_with_derivatives(*r);
        }
    }

    fn rd_total(&self) -> f64 {
        BetterDipole::rd_total(self)
    }
}

/// The closed-form total at σ′t = 1 (it depends on α′ and η only).
fn total_closed_form(albedo_prime: f64, bc: &Boundary) -> f64 {
    let a = albedo_prime;
    let d = (2.0 - a) / 3.0; // (2σa + σ′s)/3 at σ′t = 1
    let sigma = ((1.0 - a).max(0.0) / d).sqrt();
    let (z_r, z_v) = (1.0, 1.0 + 4.0 * bc.a * d); // |zv|
    let e = (-sigma * z_r).exp() + (-sigma * z_v).exp();
    0.5 * a * a * (bc.c_e * e + bc.c_phi / d * exp_diff_over_sigma(sigma, z_r, z_v))
}

/// Total diffuse reflectance Rd(α′, η) of the better dipole (closed form, module docs). Rises from 0
/// at α′ = 0 to 1 at α′ = 1.
///
/// # Errors
/// `InvalidParameter` for α′ outside [0, 1] or η outside [1, [`crate::fresnel::FRESNEL_MOMENT_MAX_ETA`]].
pub fn rd_total(albedo_prime: f64, eta: f64) -> Result<f64> {
    check_albedo(albedo_prime)?;
    Ok(total_closed_form(albedo_prime, &Boundary::new(eta)?))
}

/// The reduced albedo α′ whose better-dipole total [`rd_total`] equals `rd` at this η: the closed
/// form is strictly increasing in α′ from 0 to 1 (checked on a dense grid in the tests), so every
/// rd ∈ (0, 1] has one α′, found by the Illinois bracketed root finder in u = √(1 − α′) (where Rd is
/// smooth up to α′ = 1) to |Δu| < 1e-13, i.e. Rd to ~1e-13.
///
/// # Errors
/// `RdOutOfModelRange` for rd outside (0, 1]; `InvalidParameter` for η outside
/// [1, [`crate::fresnel::FRESNEL_MOMENT_MAX_ETA`]].
pub fn albedo_from_rd(rd: f64, eta: f64) -> Result<f64> {
    let bc = Boundary::new(eta)?;
    invert_total("better dipole", rd, eta, 1.0, |a| total_closed_form(a, &bc))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::OpticsError;

    fn props(sigma_a: f64, sigma_s_prime: f64, eta: f64) -> OpticalProperties {
        OpticalProperties::new(sigma_s_prime, sigma_a, eta).unwrap()
    }

    /// docs/physics.md §3 profile vector (σa = 0.01, σ′s = 1, η = 1.3) and A(1.4) = 2.949348.
    #[test]
    fn profile_matches_reference_vector() {
        let m = BetterDipole::new(&props(0.01, 1.0, 1.3)).unwrap();
        for (r, want) in [
            (0.0, 5.268222e-02),
            (0.1, 5.209892e-02),
            (0.5, 4.120374e-02),
            (1.0, 2.511283e-02),
            (2.0, 9.919188e-03),
            (5.0, 1.445502e-03),
        ] {
            let got = m.rd(r);
            assert!(((got - want) / want).abs() < 1e-6, "Rd({r}) = {got}");
            assert!((m.rd_with_derivatives(r).rd - got).abs() <= 1e-15 * got);
        }
        assert!((a_coefficient(1.4).unwrap() - 2.949348).abs() < 5e-7);
    }

    /// docs/physics.md §3's numerically integrated totals (σ′t = 1, η = 1.0 and 1.4; computed with the
    /// raw Fresnel-moment polynomials, as here), against the closed form and against a quadrature of
    /// the profile (log-spaced trapezoid), which checks the closed form's derivation.
    #[test]
    fn totals_match_reference_table_and_quadrature() {
        let table = [
            (0.5, 1.0, 0.04607),
            (0.8, 1.0, 0.19904),
            (0.9, 1.0, 0.34409),
            (0.95, 1.0, 0.48609),
            (0.99, 1.0, 0.73805),
            (0.999, 1.0, 0.91142),
            (0.5, 1.4, 0.02492),
            (0.8, 1.4, 0.11335),
            (0.9, 1.4, 0.21345),
            (0.95, 1.4, 0.33180),
            (0.99, 1.4, 0.60445),
            (0.999, 1.4, 0.85097),
        ];
        for (a, eta, want) in table {
            let got = rd_total(a, eta).unwrap();
            assert!((got - want).abs() < 6e-6, "α′={a} η={eta}: {got}");
            let m = BetterDipole::new(&props(1.0 - a, a, eta)).unwrap();
            assert_eq!(m.rd_total(), got);
            let (u0, u1, n) = (1e-6f64.ln(), 1e4f64.ln(), 100_000);
            let h = (u1 - u0) / n as f64;
            let f = |u: f64| {
                let r = f64::exp(u);
                2.0 * PI * r * r * m.rd(r)
            };
            let sum: f64 =
                (1..n).map(|i| f(u0 + i as f64 * h)).sum::<f64>() + 0.5 * (f(u0) + f(u1));
            assert!(
                (sum * h - got).abs() < 1e-7,
                "quadrature {} vs {got}",
                sum * h
            );
        }
        for eta in [1.0, 1.3, 2.0, 2.5] {
            assert!((rd_total(1.0, eta).unwrap() - 1.0).abs() < 1e-14);
        }
    }

    /// Analytic derivatives against central finite differences, including tiny σa.
    #[test]
    fn derivatives_match_finite_differences() {
        for (sa, sp, eta) in [
            (0.01, 1.0, 1.3),
            (0.5, 0.5, 1.0),
            (0.0008, 1.979, 1.2886),
            (1.189, 1.189, 2.4),
            (1e-4, 0.9, 1.5),
        ] {
            let m = BetterDipole::new(&props(sa, sp, eta)).unwrap();
            for r in [0.0, 0.05, 0.3, 1.0, 3.0, 10.0] {
                let got = m.rd_with_derivatives(r);
                let f = |sa: f64, sp: f64| BetterDipole::new(&props(sa, sp, eta)).unwrap().rd(r);
                let h_sp = 1e-5 * sp;
                let fd_sp = (f(sa, sp + h_sp) - f(sa, sp - h_sp)) / (2.0 * h_sp);
                let h_sa = 1e-5 * sa.max(1e-3);
                let fd_sa = (f(sa + h_sa, sp) - f(sa - h_sa, sp)) / (2.0 * h_sa);
                let tol = |fd: f64| 1e-6 * fd.abs() + 1e-9 * got.rd;
                assert!(
                    (got.d_sigma_s_prime - fd_sp).abs() <= tol(fd_sp),
                    "∂/∂σ′s r={r} ({sa},{sp},{eta}): {} vs {fd_sp}",
                    got.d_sigma_s_prime
                );
                assert!(
                    (got.d_sigma_a - fd_sa).abs() <= tol(fd_sa),
                    "∂/∂σa r={r} ({sa},{sp},{eta}): {} vs {fd_sa}",
                    got.d_sigma_a
                );
            }
        }
    }

    /// σa = 0: the derivatives are finite and continuous with those at small σa > 0 (σtr = √(σa/D)
    /// has an infinite slope there; the model does not).
    #[test]
    fn zero_absorption_has_finite_derivatives() {
        let at = |sa: f64| {
            BetterDipole::new(&props(sa, 1.0, 1.4))
                .unwrap()
                .rd_with_derivatives(2.0)
        };
        let (s0, s1) = (at(0.0), at(1e-12));
        assert!(s0.d_sigma_a.is_finite() && s0.d_sigma_s_prime.is_finite());
        assert!((s0.d_sigma_a - s1.d_sigma_a).abs() < 1e-5 * s0.d_sigma_a.abs());
        assert!(s0.d_sigma_a < 0.0);
    }

    /// Rd(α′) strictly increases on a dense grid for η ∈ [1, 2.5], and the inversion round-trips.
    #[test]
    fn total_monotonic_and_inversion_round_trips() {
        for i in 0..=15 {
            let eta = 1.0 + 0.1 * i as f64;
            let mut prev = 0.0;
            for j in 1..=400 {
                let t = j as f64 / 400.0;
                let alpha = 1.0 - (1.0 - t).powi(3);
                let rd = rd_total(alpha, eta).unwrap();
                assert!(rd > prev, "not increasing at α′ = {alpha}, η = {eta}");
                prev = rd;
                if alpha > 0.01 && alpha < 1.0 {
                    let back = albedo_from_rd(rd, eta).unwrap();
                    let again = rd_total(back, eta).unwrap();
                    assert!((again - rd).abs() < 1e-12, "α′={alpha} η={eta}: {back}");
                }
            }
        }
    }

    #[test]
    fn bad_input_is_refused() {
        for bad in [0.0, -0.1, 1.0001, f64::NAN] {
            assert!(matches!(
                albedo_from_rd(bad, 1.3),
                Err(OpticsError::RdOutOfModelRange { .. })
            ));
        }
        assert_eq!(albedo_from_rd(1.0, 1.3).unwrap(), 1.0);
        assert!(BetterDipole::new(&props(0.1, 1.0, 2.6)).is_err());
        assert!(rd_total(1.1, 1.3).is_err());
        let e = albedo_from_rd(1.2, 1.3).unwrap_err().to_string();
        assert!(e.contains("better dipole"), "{e}");
    }
}
