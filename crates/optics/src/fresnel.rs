//! Fresnel reflectance of a smooth dielectric boundary, Schlick's approximation, and the refractive
//! index from a specular reflectance measured by a d/8 spectrophotometer.
//!
//! Conventions: `eta` is the relative index n_transmitted / n_incident (for light arriving from air
//! onto a material, η = n_material); angles are measured from the surface normal.

use crate::error::{OpticsError, Result};

/// The viewing angle of a d/8 (di:8°, de:8°) sphere spectrophotometer such as the Konica Minolta
/// CM-600d used by Choi, Lee & Chin (2014, §3.1) \[degrees\].
pub const D8_VIEWING_ANGLE_DEG: f64 = 8.0;

/// Exact unpolarised Fresnel reflectance of a smooth dielectric boundary.
///
/// `cos_theta_i` is the cosine of the incidence angle (its absolute value is used) and `eta` the
/// relative index n_t/n_i. Returns 1 under total internal reflection.
/// Source: Born & Wolf, *Principles of Optics*, §1.5.2, eqs. (21a)–(21b) for r_s and r_p;
/// unpolarised R = (r_s² + r_p²)/2 (as `FrDielectric` in pbrt-v4 `util/scattering.h`).
pub fn fresnel_dielectric(cos_theta_i: f64, eta: f64) -> f64 {
    let cos_i = cos_theta_i.abs().min(1.0);
    // Snell's law: sin θt = sin θi / η.
    let sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    // Born & Wolf (21a), (21b) with η = n_t/n_i.
    let r_s = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    let r_p = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    0.5 * (r_s * r_s + r_p * r_p)
}

/// Normal-incidence reflectance R₀ = ((η − 1)/(η + 1))² (Fresnel at θ = 0; Schlick 1994, eq. (24)).
pub fn r0_from_eta(eta: f64) -> f64 {
    let r = (eta - 1.0) / (eta + 1.0);
    r * r
}

/// Schlick's approximation R(θ) = R₀ + (1 − R₀)(1 − cos θ)⁵ (Schlick 1994, eq. (24)).
pub fn schlick(cos_theta: f64, r0: f64) -> f64 {
    let m = 1.0 - cos_theta.abs().min(1.0);
    let m2 = m * m;
    r0 + (1.0 - r0) * m2 * m2 * m
}

/// Inverse of R₀ = ((η − 1)/(η + 1))²: η = (1 + √R₀)/(1 − √R₀) for a material in air.
///
/// # Errors
/// [`OpticsError::Specular`] unless 0 ≤ R₀ < 1.
pub fn eta_from_r0(r0: f64) -> Result<f64> {
    if !(r0.is_finite() && (0.0..1.0).contains(&r0)) {
        return Err(OpticsError::Specular {
            specular: r0,
            reason: "a normal-incidence reflectance must lie in [0, 1)",
        });
    }
    let s = r0.sqrt();
    Ok((1.0 + s) / (1.0 - s))
}

/// η from a specular reflectance `specular` seen at `theta_deg`, by inverting Schlick's approximation
/// (Choi, Lee & Chin 2014, §3.2, after Schlick 1994): R₀ = (R − (1 − cos θ)⁵)/(1 − (1 − cos θ)⁵),
/// then [`eta_from_r0`]. At the d/8 angle (1 − cos 8°)⁵ ≈ 8.7 × 10⁻¹¹, so R₀ ≈ R.
///
/// # Errors
/// [`OpticsError::Specular`] if the reflectance is not positive or gives R₀ outside [0, 1).
pub fn eta_from_specular_schlick(specular: f64, theta_deg: f64) -> Result<f64> {
    check_specular(specular)?;
    let m = 1.0 - theta_deg.to_radians().cos();
    let c = m.powi(5);
    eta_from_r0((specular - c) / (1.0 - c))
}

/// η from a specular reflectance `specular` seen at `theta_deg`, by inverting the exact unpolarised
/// Fresnel reflectance [`fresnel_dielectric`] (monotonic in η for θ below Brewster's angle), with a
/// bracketed root finder on η ∈ [1, 100].
///
/// # Errors
/// [`OpticsError::Specular`] if the reflectance is not positive or not reachable for η ≤ 100.
pub fn eta_from_specular_exact(specular: f64, theta_deg: f64) -> Result<f64> {
    check_specular(specular)?;
    let cos_theta = theta_deg.to_radians().cos();
    let f = |eta: f64| fresnel_dielectric(cos_theta, eta) - specular;
    crate::roots::bracketed_root(f, 1.0, 100.0, 1e-13).ok_or(OpticsError::Specular {
        specular,
        reason: "no dielectric with 1 ≤ η ≤ 100 reflects this much at this angle",
    })
}

/// Largest η for which the Fresnel-moment polynomials [`fresnel_moment1`] and [`fresnel_moment2`]
/// are trusted: on [1, 2.5] they stay within 0.0025 of the exact moments (at η = 2.4: 0.43114 vs
/// 0.43144 and 0.26919 vs 0.26772); at η = 2.6 the second is 0.0033 off and at η = 3 the first is
/// 0.118 off (0.578 vs 0.460), so the models built on them refuse larger η.
pub const FRESNEL_MOMENT_MAX_ETA: f64 = 2.5;

/// First Fresnel moment C₁(η) ≈ ∫₀¹ F_r(μ) μ dμ of the internal reflectance (light inside a medium of
/// index η meeting a boundary to air), as pbrt's polynomial fit (pbrt-v3 `core/bssrdf.cpp`
/// `FresnelMoment1`, pbrt-v4 `util/scattering.cpp`; docs/physics.md §2.1):
/// −4.61686 + 11.1136η − 10.4646η² + 5.11455η³ − 1.27198η⁴ + 0.12746η⁵.
/// At η = 1 it gives 0.00217 instead of 0 (a fit artefact that pbrt keeps; so do we, to stay pbrt's
/// model). Trusted for 1 ≤ η ≤ [`FRESNEL_MOMENT_MAX_ETA`].
pub fn fresnel_moment1(eta: f64) -> f64 {
    let (e2, e3, e4, e5) = (eta * eta, eta * eta * eta, eta.powi(4), eta.powi(5));
    -4.61686 + 11.1136 * eta - 10.4646 * e2 + 5.11455 * e3 - 1.27198 * e4 + 0.12746 * e5
}

/// Second Fresnel moment C₂(η) ≈ ∫₀¹ F_r(μ) μ² dμ of the internal reflectance, pbrt's polynomial fit
/// (pbrt-v3 `core/bssrdf.cpp` `FresnelMoment2`; docs/physics.md §2.1):
/// −547.033 + 45.3087/η³ − 218.725/η² + 458.843/η + 404.557η − 189.519η² + 54.9327η³ − 9.00603η⁴
/// + 0.63942η⁵ (−0.00221 at η = 1, kept as pbrt does). Trusted for 1 ≤ η ≤ [`FRESNEL_MOMENT_MAX_ETA`].
pub fn fresnel_moment2(eta: f64) -> f64 {
    let (e2, e3, e4, e5) = (eta * eta, eta * eta * eta, eta.powi(4), eta.powi(5));
    let (r1, r2, r3) = (1.0 / eta, 1.0 / e2, 1.0 / e3);
    -547.033 + 45.3087 * r3 - 218.725 * r2 + 458.843 * r1 + 404.557 * eta - 189.519 * e2
        + 54.9327 * e3
        - 9.00603 * e4
        + 0.63942 * e5
}

fn check_specular(specular: f64) -> Result<()> {
    if !specular.is_finite() || specular <= 0.0 {
        return Err(OpticsError::Specular {
            specular,
            reason: "it must be > 0 (a dielectric surface always reflects some light specularly)",
        });
    }
    if specular >= 1.0 {
        return Err(OpticsError::Specular {
            specular,
            reason: "it must be < 1",
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// docs/physics.md §5: η = 1.5 → R₀ = 0.04; at 8° Schlick 0.04000000, exact 0.04000629.
    #[test]
    fn schlick_and_exact_at_8_degrees_match_reference() {
        let cos8 = 8f64.to_radians().cos();
        assert!((r0_from_eta(1.5) - 0.04).abs() < 1e-15);
        assert!((schlick(cos8, 0.04) - 0.040_000_00).abs() < 5e-9);
        assert!((fresnel_dielectric(cos8, 1.5) - 0.040_006_29).abs() < 5e-9);
    }

    /// docs/physics.md §5: R₀ for other indices.
    #[test]
    fn r0_reference_vectors() {
        for (eta, r0) in [
            (1.33, 0.020059),
            (1.40, 0.027778),
            (1.45, 0.033736),
            (1.55, 0.046521),
        ] {
            assert!((r0_from_eta(eta) - r0).abs() < 6e-7, "η = {eta}");
        }
    }

    /// docs/physics.md §5: measured specular → η through Schlick, and exact inversion of 0.04 at
    /// 8°.
    #[test]
    fn specular_to_eta_reference_vectors() {
        for (spec, eta) in [
            (0.02, 1.32943),
            (0.03, 1.41898),
            (0.05, 1.57601),
            (0.04, 1.5),
        ] {
            let got = eta_from_specular_schlick(spec, D8_VIEWING_ANGLE_DEG).unwrap();
            assert!((got - eta).abs() < 6e-6, "{spec}: {got} vs {eta}");
        }
        let exact = eta_from_specular_exact(0.04, D8_VIEWING_ANGLE_DEG).unwrap();
        assert!((exact - 1.499951).abs() < 1e-6, "{exact}");
    }

    /// docs/physics.md §5: Schlick's error grows off-normal (η = 1.5).
    #[test]
    fn schlick_error_off_normal_matches_reference() {
        for (deg, s, e) in [(45.0_f64, 0.04207, 0.05024), (60.0, 0.07000, 0.08919)] {
            let c = deg.to_radians().cos();
            assert!((schlick(c, 0.04) - s).abs() < 6e-6);
            assert!((fresnel_dielectric(c, 1.5) - e).abs() < 6e-6);
        }
    }

    /// Total internal reflection beyond the critical angle, and energy limits.
    #[test]
    fn total_internal_reflection_and_limits() {
        // From glass (1.5) to air: η = 1/1.5, critical angle 41.8°.
        assert_eq!(fresnel_dielectric(45f64.to_radians().cos(), 1.0 / 1.5), 1.0);
        assert!(fresnel_dielectric(40f64.to_radians().cos(), 1.0 / 1.5) < 1.0);
        assert_eq!(fresnel_dielectric(0.7, 1.0), 0.0);
        assert!(
            (fresnel_dielectric(0.0, 1.5) - 1.0).abs() < 1e-12,
            "grazing incidence"
        );
    }

    #[test]
    fn bad_specular_is_an_error() {
        for bad in [0.0, -0.01, 1.0, f64::NAN] {
            assert!(eta_from_specular_schlick(bad, 8.0).is_err(), "{bad}");
            assert!(eta_from_specular_exact(bad, 8.0).is_err(), "{bad}");
        }
    }

    /// docs/physics.md §2.1: pbrt's Fresnel-moment polynomials at η = 1.33, 1.5 and their η = 1
    /// artefact; and they stay near the exact moments ∫F μⁱ dμ (computed here by Simpson's rule on
    /// the exact Fresnel formula, an independent route) up to `FRESNEL_MOMENT_MAX_ETA`.
    #[test]
    fn fresnel_moments_match_reference() {
        for (eta, m1, m2) in [
            (1.33, 0.236477, 0.108551),
            (1.5, 0.298297, 0.154203),
            (1.0, 0.00217, -0.00221),
        ] {
            assert!((fresnel_moment1(eta) - m1).abs() < 6e-6, "C1({eta})");
            assert!((fresnel_moment2(eta) - m2).abs() < 6e-6, "C2({eta})");
        }
        let exact = |eta: f64, i: i32| {
            let n = 20_000;
            let f = |mu: f64| fresnel_dielectric(mu, 1.0 / eta) * mu.powi(i);
            let h = 1.0 / n as f64;
            (0..n).map(|k| f((k as f64 + 0.5) * h) * h).sum::<f64>()
        };
        for k in 0..=30 {
            let eta = 1.0 + 0.05 * k as f64;
            let (e1, e2) = (exact(eta, 1), exact(eta, 2));
            assert!((fresnel_moment1(eta) - e1).abs() < 0.0025, "C1({eta})");
            assert!((fresnel_moment2(eta) - e2).abs() < 0.0025, "C2({eta})");
        }
        assert!(
            (fresnel_moment1(3.0) - exact(3.0, 1)).abs() > 0.1,
            "the fit fails at η = 3"
        );
    }
}
