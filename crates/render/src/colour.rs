//! The subsurface colour method: Choi, Lee & Chin 2014, §4.1, eqs. (3)–(5), after Groenhuis et al.
//! 1983 (their ref. \[9\]) and a colour-rendering model (their ref. \[20\]).
//!
//! Groenhuis' T(d), R(d) and P(g) could not be found outside the seed paper (docs/physics.md §9),
//! so eqs. (3) and (4) are implemented **as printed** there. They describe a layer of thickness d
//! lit from the top, to first order in the optical depth: the unscattered beam is attenuated as
//! 1 − σa x − σ′s P(g) x, a fraction σ′s P(g) dx is sent back from depth x and attenuated again on the
//! way out, and the beam reaching the bottom is partly reflected (F_dr,b) and partly transmitted:
//!
//! ```text
//! T(d) = (1 − σa d − σ′s P(g) d)(1 − F_dr,b)                                               (3)
//! R(d) = (1 − F_dr,t)(∫₀^d (1 − σa x)² σ′s P(g) dx + F_dr,b (1 − σa d − σ′s P(g) d)²)      (4)
//! C_L  = ρd cos θ + ρts/(α d + β)^γ + I cos θ ρs e^{−tan²δ (cos²φ/αx² + sin²φ/αy²)}
//!                                          / (4π αx αy √(cos θi cos θr))                  (5)
//! ```
//!
//! **Where the printed formulas leave their domain** (first order only holds while the unscattered
//! beam lasts): beyond the depth d₀ = 1/(σa + σ′s P) the factor 1 − σa x − σ′s P x would turn
//! negative and the integral of (4) would grow without bound, so T(d) is clamped at 0 for d ≥ d₀ and
//! the integral of (4) runs to min(d, d₀). R(d) then stays in [F_dr,b(1 − F_dr,t)·…, 1 − F_dr,t].
//!
//! **How this renderer uses them** (the paper gives no more detail; our reading, documented):
//! - d is the thickness of the object along the light's path, found by ray casting through the mesh.
//!   A point facing the light shows R(d), d the chord from it into the object along the light; a point
//!   facing away shows T(d) times the translucent term ρts/(αd + β)^γ, d the distance back to where
//!   the light entered (which must itself be lit and unshadowed).
//! - "the pixel value … multiplying the light intensity (C_L) and the result of the colour model":
//!   the diffuse and translucent terms of (5) are multiplied by the channel's R(d) or T(d) and taken
//!   as albedos (radiance = albedo · E/π, the same scale as the dipole method's Ft·E·Rd/π); the
//!   anisotropic specular term (Ward 1992) is a BRDF, white (the surface reflects without colour).
//! - F_dr,t = F_dr,b = F_dr(η) (Jensen's polynomial; both boundaries are material/air), P(g) the
//!   backward-hemisphere integral of Henyey–Greenstein, ½ for g = 0 ([`backward_fraction`]).

use glam::DVec3;
use scatterfit_optics::dipole::f_dr;
use scatterfit_optics::fresnel::r0_from_eta;

use crate::error::{Result, invalid};

/// The coefficients that eq. (5) leaves to experiment, and g, with our defaults (also
/// `scatterfit render`'s flags, whose help texts are given with each field).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "clap", derive(clap::Args))]
pub struct ColourParams {
    /// ρd, diffuse coefficient. Default 1: R(d) already is the layer's albedo.
    #[cfg_attr(
        feature = "clap",
        arg(
            long,
            default_value_t = 1.0,
            help = "ρd, diffuse coefficient of eq. 5 (≥ 0)"
        )
    )]
    pub rho_d: f64,
    /// ρs, specular coefficient; `None` (default) takes the Fresnel reflectance at normal incidence
    /// R₀ = ((η − 1)/(η + 1))², the specular albedo of a smooth dielectric.
    #[cfg_attr(
        feature = "clap",
        arg(
            long,
            help = "ρs, specular coefficient of eq. 5 (≥ 0; default the Fresnel reflectance at normal incidence ((η−1)/(η+1))²)"
        )
    )]
    pub rho_s: Option<f64>,
    /// ρts, translucent coefficient. Default 1: T(d) already is the transmitted fraction.
    #[cfg_attr(
        feature = "clap",
        arg(
            long,
            default_value_t = 1.0,
            help = "ρts, translucent coefficient of eq. 5 (≥ 0)"
        )
    )]
    pub rho_ts: f64,
    /// α [mm⁻¹] of the translucent fall-off (α d + β)^−γ. Default 1 mm⁻¹.
    #[cfg_attr(
        feature = "clap",
        arg(
            long,
            default_value_t = 1.0,
            help = "α of the translucent fall-off (α d + β)^−γ [mm⁻¹, ≥ 0]"
        )
    )]
    pub alpha: f64,
    /// β (dimensionless). Default 1, so the fall-off is 1 at d = 0.
    #[cfg_attr(
        feature = "clap",
        arg(
            long,
            default_value_t = 1.0,
            help = "β of the translucent fall-off (> 0)"
        )
    )]
    pub beta: f64,
    /// γ (dimensionless). Default 1: light through 1 mm is halved by spreading, on top of T(d).
    #[cfg_attr(
        feature = "clap",
        arg(
            long,
            default_value_t = 1.0,
            help = "γ of the translucent fall-off (≥ 0)"
        )
    )]
    pub gamma: f64,
    /// αx, surface slope standard deviation along the tangent (Ward 1992). Default 0.15 (semi-gloss).
    #[cfg_attr(
        feature = "clap",
        arg(
            long,
            default_value_t = 0.15,
            help = "αx, surface slope deviation along the tangent (Ward; > 0)"
        )
    )]
    pub alpha_x: f64,
    /// αy, along the bitangent. Default 0.15 (isotropic, so the tangent frame does not matter).
    #[cfg_attr(
        feature = "clap",
        arg(
            long,
            default_value_t = 0.15,
            help = "αy, surface slope deviation along the bitangent (Ward; > 0)"
        )
    )]
    pub alpha_y: f64,
    /// Henyey–Greenstein anisotropy g of P(g), in (−1, 1). Default 0 (P = ½): the fit measures σ′s
    /// only, which is the isotropic equivalent.
    #[cfg_attr(
        feature = "clap",
        arg(
            long,
            default_value_t = 0.0,
            allow_hyphen_values = true,
            help = "Henyey–Greenstein g of P(g) in eqs. 3–4, in (−1, 1)"
        )
    )]
    pub g: f64,
}

impl Default for ColourParams {
    fn default() -> Self {
        Self {
            rho_d: 1.0,
            rho_ts: 1.0,
            rho_s: None,
            alpha: 1.0,
            beta: 1.0,
            gamma: 1.0,
            alpha_x: 0.15,
            alpha_y: 0.15,
            g: 0.0,
        }
    }
}

/// The largest coefficient of eq. (5) accepted (ρd, ρts, ρs, α, β, γ).
const MAX_COEFFICIENT: f64 = 1000.0;

impl ColourParams {
    /// Checks the domains.
    ///
    /// # Errors
    /// [`crate::RenderError::InvalidOption`] naming the coefficient.
    pub fn validate(&self) -> Result<()> {
        let nonneg = [
            ("rho_d", self.rho_d),
            ("rho_ts", self.rho_ts),
            ("rho_s", self.rho_s.unwrap_or(0.0)),
            ("alpha [mm⁻¹]", self.alpha),
            ("gamma", self.gamma),
        ];
        for (name, v) in nonneg {
            if !(v.is_finite() && v >= 0.0) {
                return Err(invalid(name, v, "must be finite and ≥ 0"));
            }
            // Eq. (5) multiplies these into radiance: beyond MAX_COEFFICIENT every lit pixel is
            // white (or the product overflows to ∞ and NaN, which renders black).
            if v > MAX_COEFFICIENT {
                return Err(invalid(
                    name,
                    v,
                    "must be at most 1000 (eq. 5's coefficients are of order 1; larger ones \
                     overflow the radiance — set the brightness with --exposure)",
                ));
            }
        }
        if !(self.beta.is_finite() && self.beta > 0.0 && self.beta <= MAX_COEFFICIENT) {
            return Err(invalid("beta", self.beta, "must lie in (0, 1000]"));
        }
        for (name, v) in [("alpha_x", self.alpha_x), ("alpha_y", self.alpha_y)] {
            if !(v.is_finite() && v > 0.0) {
                return Err(invalid(name, v, "must be > 0 (a slope deviation)"));
            }
        }
        if !(self.g.is_finite() && self.g > -1.0 && self.g < 1.0) {
            return Err(invalid("g", self.g, "must lie in (−1, 1)"));
        }
        Ok(())
    }
}

/// P(g): the fraction of Henyey–Greenstein scattering into the backward hemisphere,
/// ∫₋₁⁰ ½(1 − g²)(1 + g² − 2gμ)^{−3/2} dμ = (1 − g²)/(2g) · (1/√(1 + g²) − 1/(1 + g)),
/// with the limit ½ − ¾g + O(g²) near g = 0 (derived here; Henyey & Greenstein 1941 for the phase
/// function).
pub fn backward_fraction(g: f64) -> f64 {
    if g.abs() < 1e-4 {
        // Series: ½ − ¾g + g³·(…); the g² term vanishes.
        return 0.5 - 0.75 * g + 0.4375 * g * g * g;
    }
    (1.0 - g * g) / (2.0 * g) * (1.0 / (1.0 + g * g).sqrt() - 1.0 / (1.0 + g))
}

/// One channel's layer optics for eqs. (3) and (4).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Layer {
    /// σa [mm⁻¹].
    pub sigma_a: f64,
    /// σ′s P(g) [mm⁻¹]: the backscattering coefficient.
    pub sigma_back: f64,
    /// F_dr at the top boundary.
    pub f_dr_t: f64,
    /// F_dr at the bottom boundary.
    pub f_dr_b: f64,
}

impl Layer {
    /// The layer of (σ′s, σa) [mm⁻¹] with index η and HG anisotropy g.
    pub fn new(sigma_s_prime: f64, sigma_a: f64, eta: f64, g: f64) -> Self {
        let f = f_dr(eta);
        Self {
            sigma_a,
            sigma_back: sigma_s_prime * backward_fraction(g),
            f_dr_t: f,
            f_dr_b: f,
        }
    }

    /// d₀ = 1/(σa + σ′s P): the depth where the first-order unscattered beam is used up \[mm\].
    pub fn d0(&self) -> f64 {
        1.0 / (self.sigma_a + self.sigma_back)
    }

    /// The unscattered fraction 1 − σa d − σ′s P d, clamped at 0.
    fn beam(&self, d: f64) -> f64 {
        (1.0 - (self.sigma_a + self.sigma_back) * d).max(0.0)
    }

    /// T(d), eq. (3), clamped at 0 beyond d₀.
    pub fn transmittance(&self, d: f64) -> f64 {
        self.beam(d) * (1.0 - self.f_dr_b)
    }

    /// R(d), eq. (4), the integral taken to min(d, d₀); d = ∞ gives the thick-layer limit.
    pub fn reflectance(&self, d: f64) -> f64 {
        let x = d.min(self.d0());
        let sa = self.sigma_a;
        // ∫₀^x (1 − σa t)² dt = (1 − (1 − σa x)³)/(3σa), → x as σa → 0.
        let integral = if sa * x < 1e-6 {
            x * (1.0 - sa * x + sa * sa * x * x / 3.0)
        } else {
            (1.0 - (1.0 - sa * x).powi(3)) / (3.0 * sa)
        };
        let b = self.beam(d);
        (1.0 - self.f_dr_t) * (integral * self.sigma_back + self.f_dr_b * b * b)
    }
}

/// The anisotropic specular term of eq. (5) without I cos θ (Ward 1992, "Measuring and Modeling
/// Anisotropic Reflection", eq. 5): ρs exp(−tan²δ (cos²φ/αx² + sin²φ/αy²))/(4π αx αy √(cos θi cos θr))
/// [sr⁻¹]. `n` the normal, `t` a unit tangent (the αx direction), `l` towards the light, `v` towards
/// the viewer; 0 where either lies below the surface.
pub fn ward_specular(n: DVec3, t: DVec3, l: DVec3, v: DVec3, rho_s: f64, ax: f64, ay: f64) -> f64 {
    let cos_i = n.dot(l);
    let cos_r = n.dot(v);
    if cos_i <= 0.0 || cos_r <= 0.0 {
        return 0.0;
    }
    let h = (l + v).normalize();
    let cos_d = n.dot(h);
    if cos_d <= 0.0 {
        return 0.0;
    }
    let b = n.cross(t);
    let (hx, hy) = (h.dot(t), h.dot(b));
    let sin2 = hx * hx + hy * hy;
    // tan²δ (cos²φ/αx² + sin²φ/αy²) = (hx²/αx² + hy²/αy²)/cos²δ.
    let exponent = if sin2 > 0.0 {
        (hx * hx / (ax * ax) + hy * hy / (ay * ay)) / (cos_d * cos_d)
    } else {
        0.0
    };
    rho_s * (-exponent).exp() / (4.0 * std::f64::consts::PI * ax * ay * (cos_i * cos_r).sqrt())
}

/// ρs: the given value or R₀(η).
pub fn rho_s(params: &ColourParams, eta: f64) -> f64 {
    params.rho_s.unwrap_or_else(|| r0_from_eta(eta))
}

/// The translucent fall-off ρts/(α d + β)^γ of eq. (5).
pub fn translucent_falloff(params: &ColourParams, d: f64) -> f64 {
    params.rho_ts / (params.alpha * d + params.beta).powf(params.gamma)
}

/// A unit tangent at `n` (along the azimuth around the y axis; x where n is vertical).
pub fn tangent(n: DVec3) -> DVec3 {
    DVec3::Y
        .cross(n)
        .try_normalize()
        .unwrap_or_else(|| DVec3::X.cross(n).normalize())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// P(g) against direct numerical integration of the HG phase function over μ ∈ [−1, 0]
    /// (composite Simpson, 20 000 intervals), and its limits P(0) = ½, P(±1) = 0/1.
    #[test]
    fn backward_fraction_matches_quadrature() {
        for g in [-0.9, -0.5, -0.1, -1e-5, 0.0, 1e-5, 0.05, 0.3, 0.7, 0.95] {
            let hg = |mu: f64| 0.5 * (1.0 - g * g) / (1.0 + g * g - 2.0 * g * mu).powf(1.5);
            let n = 20_000;
            let h = 1.0 / n as f64;
            let mut s = hg(-1.0) + hg(0.0);
            for i in 1..n {
                s += hg(-1.0 + i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 };
            }
            let quad = s * h / 3.0;
            assert!((backward_fraction(g) - quad).abs() < 1e-9, "g = {g}");
        }
        assert_eq!(backward_fraction(0.0), 0.5);
        assert!(backward_fraction(0.999_999).abs() < 1e-5);
        assert!((backward_fraction(-0.999_999) - 1.0).abs() < 1e-5);
    }

    /// R(d) against numerical integration of the printed integrand, and T(d) as printed, inside
    /// the domain; clamps outside it.
    #[test]
    fn layer_terms_as_printed() {
        let (sp, sa, eta) = (1.893, 0.0496, 1.2886);
        let layer = Layer::new(sp, sa, eta, 0.0);
        let f = f_dr(eta);
        let d = 0.4;
        let n = 10_000;
        let h = d / n as f64;
        let integrand = |x: f64| (1.0 - sa * x).powi(2) * sp * 0.5;
        let mut s = integrand(0.0) + integrand(d);
        for i in 1..n {
            s += integrand(i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 };
        }
        let beam = 1.0 - sa * d - sp * 0.5 * d;
        let r = (1.0 - f) * (s * h / 3.0 + f * beam * beam);
        assert!((layer.reflectance(d) - r).abs() < 1e-12);
        assert!((layer.transmittance(d) - beam * (1.0 - f)).abs() < 1e-15);
        // Beyond d₀ ≈ 1.0 mm the beam is used up: T = 0, R constant.
        let d0 = layer.d0();
        assert_eq!(layer.transmittance(1.5 * d0), 0.0);
        assert_eq!(
            layer.reflectance(1.5 * d0),
            layer.reflectance(f64::INFINITY)
        );
        assert!((layer.reflectance(d0 * (1.0 - 1e-9)) - layer.reflectance(d0)).abs() < 1e-8);
        // σa → 0: R(∞) → 1 − F_dr,t (everything scattered back before the beam is used up).
        let clear = Layer::new(2.0, 0.0, eta, 0.0);
        assert!((clear.reflectance(f64::INFINITY) - (1.0 - f)).abs() < 1e-12);
        // R(d) never decreases with d and stays in [0, 1].
        let mut last = 0.0;
        for k in 0..200 {
            let r = layer.reflectance(0.01 * k as f64);
            assert!(r >= last - 1e-15 && r <= 1.0);
            last = r;
        }
    }

    /// Ward's lobe integrates (cos-weighted, over the hemisphere of v) to about ρs for a small α at
    /// normal incidence — the normalisation of Ward 1992 (exact as α → 0).
    #[test]
    fn ward_lobe_albedo_is_rho_s() {
        let n = DVec3::Y;
        let t = DVec3::X;
        let l = DVec3::Y;
        let (ax, ay) = (0.08, 0.12);
        let steps = 800;
        let mut sum = 0.0;
        // Integrate over θ ∈ [0, π/2), φ ∈ [0, 2π) (midpoint rule).
        for i in 0..steps {
            let th = (i as f64 + 0.5) / steps as f64 * std::f64::consts::FRAC_PI_2;
            for j in 0..steps {
                let ph = (j as f64 + 0.5) / steps as f64 * std::f64::consts::TAU;
                let v = DVec3::new(th.sin() * ph.cos(), th.cos(), th.sin() * ph.sin());
                let f = ward_specular(n, t, l, v, 1.0, ax, ay);
                sum += f * th.cos() * th.sin();
            }
        }
        let dw = std::f64::consts::FRAC_PI_2 / steps as f64 * std::f64::consts::TAU / steps as f64;
        let albedo = sum * dw;
        assert!((albedo - 1.0).abs() < 0.03, "{albedo}");
    }
}
