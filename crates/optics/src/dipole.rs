//! The classical dipole diffusion model of Jensen, Marschner, Levoy & Hanrahan (2001), "A Practical
//! Model for Subsurface Light Transport", SIGGRAPH 2001, §2.3–2.4 — the forward model of Choi, Lee &
//! Chin (2014).
//!
//! Parameters and domains: σ′s > 0 and σa ≥ 0 [mm⁻¹], η ≥ 1. Outputs: the radial profile Rd(r) [mm⁻²]
//! with its analytic derivatives in σ′s and σa (for Levenberg–Marquardt), the total diffuse
//! reflectance Rd(α′, η) = ∫2πr Rd(r) dr, and its inverse α′(Rd, η).
//!
//! ```text
//! σ′t = σa + σ′s,  α′ = σ′s/σ′t,  σtr = √(3σaσ′t),  zr = 1/σ′t,  zv = zr(1 + 4A/3)
//! dr = √(r² + zr²),  dv = √(r² + zv²)
//! Rd(r) = α′/(4π) [zr(σtr dr + 1)e^{−σtr dr}/dr³ + zv(σtr dv + 1)e^{−σtr dv}/dv³]      (Jensen eq. 4)
//! ```

pub use crate::family::ProfileSample;

use crate::error::{OpticsError, Result, eta_at_least_one};
use crate::family::ProfileModel;
use crate::properties::OpticalProperties;

/// Diffuse Fresnel reflectance Fdr(η) = −1.440/η² + 0.710/η + 0.668 + 0.0636η, the fit quoted by
/// Jensen et al. 2001 (eq. 3 context) and Choi et al. 2014 after eq. (1) (originally Egan & Hilgeman
/// 1979 / Groenhuis et al. 1983). It approximates the *internal* diffuse reflectance
/// 2∫₀¹F(μ; 1/η)μ dμ (see [`f_dr_exact`]). The polynomial gives 0.0016 at η = 1, a fit artefact; we set
/// Fdr(1) := 0 (a matched boundary reflects nothing).
pub fn f_dr(eta: f64) -> f64 {
    if eta == 1.0 {
        return 0.0;
    }
    -1.440 / (eta * eta) + 0.710 / eta + 0.668 + 0.0636 * eta
}

/// The exact internal diffuse Fresnel reflectance 2∫₀¹ F(μ; 1/η) μ dμ of light inside a medium of
/// index η meeting a smooth boundary to air (Born & Wolf Fresnel equations integrated over a
/// Lambertian distribution; docs/physics.md §1.2). Integrated with the substitution t = cos
/// θ_transmitted (μ dμ = t dt/η², smooth on [0, 1]) and composite Simpson; the part beyond the
/// critical angle (F = 1) is added in closed form. For η < 1 the roles swap and no total reflection
/// occurs.
pub fn f_dr_exact(eta: f64) -> f64 {
    const N: usize = 400; // Simpson intervals; the integrand is smooth in t, error < 1e-10.
    let inv_eta = 1.0 / eta;
    if eta <= 1.0 {
        // No total internal reflection: integrate directly in μ.
        let g = |mu: f64| crate::fresnel::fresnel_dielectric(mu, inv_eta) * mu;
        return 2.0 * simpson(g, 0.0, 1.0, N);
    }
    // μ ∈ [0, μc): total internal reflection, ∫ μ dμ = μc²/2 with μc² = 1 − 1/η².
    let mu_c2 = 1.0 - inv_eta * inv_eta;
    let g = |t: f64| {
        let mu = (1.0 - (1.0 - t * t) * inv_eta * inv_eta).sqrt();
        crate::fresnel::fresnel_dielectric(mu, inv_eta) * t * inv_eta * inv_eta
    };
    2.0 * (0.5 * mu_c2 + simpson(g, 0.0, 1.0, N))
}

fn simpson<F: Fn(f64) -> f64>(f: F, a: f64, b: f64, n: usize) -> f64 {
    let h = (b - a) / n as f64;
    let mut sum = f(a) + f(b);
    for i in 1..n {
        sum += f(a + i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 };
    }
    sum * h / 3.0
}

/// The boundary coefficient A = (1 + Fdr)/(1 − Fdr) (Jensen et al. 2001, §2.4, after eq. 4).
pub fn a_coefficient(eta: f64) -> f64 {
    let fdr = f_dr(eta);
    (1.0 + fdr) / (1.0 - fdr)
}

/// Total diffuse reflectance of the classical dipole,
/// Rd = (α′/2)(1 + e^{−(4/3)A√(3(1−α′))}) e^{−√(3(1−α′))} (Jensen et al. 2001, eq. 5; the seed's
/// eq. (1) is this formula garbled in extraction). It is the exact integral ∫₀^∞ 2πr Rd(r) dr of
/// [`Dipole::rd`] (docs/physics.md §1.3).
pub fn rd_total(albedo_prime: f64, eta: f64) -> f64 {
    let s = (3.0 * (1.0 - albedo_prime)).max(0.0).sqrt();
    rd_total_of_s(s, 4.0 / 3.0 * a_coefficient(eta))
}

/// Rd in terms of s = √(3(1−α′)) (so α′ = 1 − s²/3) and c = 4A/3: Rd = (1 − s²/3)/2 (1 + e^{−cs}) e^{−s}.
#[inline]
fn rd_total_of_s(s: f64, c: f64) -> f64 {
    0.5 * (1.0 - s * s / 3.0) * (1.0 + (-c * s).exp()) * (-s).exp()
}

/// The reduced albedo α′ whose dipole total diffuse reflectance [`rd_total`] equals `rd` for this η.
///
/// Rd(α′) is strictly increasing from Rd(0) = 0 to Rd(1) = 1, so every rd ∈ (0, 1] has exactly one
/// α′ ∈ (0, 1]. We solve in s = √(3(1−α′)) ∈ [0, √3], where Rd is smooth even at α′ → 1, by Newton's
/// method safeguarded with bisection on the bracket (Press et al., *Numerical Recipes*, §9.4 `rtsafe`).
///
/// # Errors
/// [`OpticsError::RdOutOfRange`] if rd is not in (0, 1]; [`OpticsError::InvalidParameter`] if η < 1.
pub fn albedo_from_rd(rd: f64, eta: f64) -> Result<f64> {
    eta_at_least_one(eta)?;
    if !rd.is_finite() || rd <= 0.0 {
        return Err(OpticsError::RdOutOfRange {
            rd,
            eta,
            hint: "a channel with no diffuse reflectance is black: its albedo is 0 and σa unbounded; \
                   check the colour measurement (dark or out-of-gamut colours give Rd ≤ 0 in sRGB)",
        });
    }
    if rd > 1.0 {
        return Err(OpticsError::RdOutOfRange {
            rd,
            eta,
            hint: "a passive material cannot reflect more than it receives; check the calibration \
                   (white tile) and that the reflectance is a fraction, not a percentage",
        });
    }
    if rd == 1.0 {
        return Ok(1.0);
    }
    let c = 4.0 / 3.0 * a_coefficient(eta);
    // f(s) = Rd(s) − rd is decreasing on [0, √3]: f(0) = 1 − rd > 0, f(√3) = −rd < 0.
    let (mut lo, mut hi) = (0.0_f64, 3f64.sqrt());
    // Start from the large-α′ asymptote Rd ≈ 1 − (1 + c/2)s ... clamped into the bracket.
    let mut s = ((1.0 - rd) / (1.0 + 0.5 * c)).clamp(lo, hi);
    for _ in 0..100 {
        let e_cs = (-c * s).exp();
        let e_s = (-s).exp();
        let q = 1.0 - s * s / 3.0;
        let f = 0.5 * q * (1.0 + e_cs) * e_s - rd;
        // d/ds of ½ q (1 + e^{−cs}) e^{−s}.
        let df = 0.5 * e_s * ((-2.0 * s / 3.0) * (1.0 + e_cs) - q * c * e_cs - q * (1.0 + e_cs));
        if f == 0.0 {
            break;
        }
        if f > 0.0 {
            lo = s;
        } else {
            hi = s;
        }
        let newton = s - f / df;
        let next = if df < 0.0 && newton > lo && newton < hi {
            newton
        } else {
            0.5 * (lo + hi)
        };
        let converged = (next - s).abs() <= 1e-15 * (1.0 + s);
        s = next;
        if converged || hi - lo <= 1e-16 {
            break;
        }
    }
    Ok(1.0 - s * s / 3.0)
}

/// The classical dipole for one set of optical properties, with the shared quantities (α′, σtr, zr,
/// zv and the derivative factors) computed once (ARCHITECTURE.md, "Code conventions": cache shared
/// work per parameter set).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dipole {
    props: OpticalProperties,
    albedo_prime: f64,
    sigma_tr: f64,
    z_r: f64,
    z_v: f64,
    /// zv/zr = 1 + 4A/3.
    k_v: f64,
    /// ∂α′/∂σ′s = σa/σ′t².
    da_dsp: f64,
    /// ∂α′/∂σa = −σ′s/σ′t².
    da_dsa: f64,
}

impl Dipole {
    /// The dipole for `props` (Jensen et al. 2001, §2.4: zr = 1/σ′t, zv = zr + 4AD = zr(1 + 4A/3)).
    pub fn new(props: &OpticalProperties) -> Self {
        let sigma_t = props.sigma_t_prime();
        let k_v = 1.0 + 4.0 / 3.0 * a_coefficient(props.eta());
        let z_r = 1.0 / sigma_t;
        Self {
            da_dsp: props.sigma_a() * z_r * z_r,
            da_dsa: -props.sigma_s_prime() * z_r * z_r,
            props: *props,
            albedo_prime: props.sigma_s_prime() / sigma_t,
            sigma_tr: (3.0 * props.sigma_a() * sigma_t).sqrt(),
            z_r,
            z_v: z_r * k_v,
            k_v,
        }
    }

    /// The optical properties of this dipole.
    pub fn properties(&self) -> &OpticalProperties {
        &self.props
    }

    /// Rd(r) [mm⁻²] at radius `r_mm` from the point of incidence (Jensen et al. 2001, eq. 4).
    #[inline]
    pub fn rd(&self, r_mm: f64) -> f64 {
        let r2 = r_mm * r_mm;
        let source = |z: f64| {
            let d = (r2 + z * z).sqrt();
            z * (self.sigma_tr * d + 1.0) * (-self.sigma_tr * d).exp() / (d * d * d)
        };
        self.albedo_prime
            * std::f64::consts::FRAC_1_PI
            * 0.25
            * (source(self.z_r) + source(self.z_v))
    }

    /// Rd(r) with its analytic partial derivatives in σ′s and σa (differentiating eq. 4 of Jensen et
    /// al. 2001 through α′, zr, zv and σtr; checked against finite differences in the tests).
    ///
    /// With T(z) = z(σtr d + 1)e^{−σtr d}/d³, d = √(r² + z²):
    /// ∂T/∂z = (σtr d + 1)e^{−σtr d}/d³ − z² e^{−σtr d}(σtr²d² + 3σtr d + 3)/d⁵ and
    /// ∂T/∂σtr = −zσtr e^{−σtr d}/d; ∂σtr/∂σ′s = 3σa/(2σtr), ∂σtr/∂σa = 3(σ′t + σa)/(2σtr) (the σtr
    /// factors cancel, so σa = 0 is fine); ∂zr/∂p = −zr², ∂zv/∂p = −k zr²; ∂α′/∂σ′s = σa/σ′t²,
    /// ∂α′/∂σa = −σ′s/σ′t².
    #[inline]
    pub fn rd_with_derivatives(&self, r_mm: f64) -> ProfileSample {
        let r2 = r_mm * r_mm;
        let d_r = (r2 + self.z_r * self.z_r).sqrt();
        let d_v = (r2 + self.z_v * self.z_v).sqrt();
        let e_r = (-self.sigma_tr * d_r).exp();
        let e_v = (-self.sigma_tr * d_v).exp();
        self.sample_from_distances(d_r, d_v, e_r, e_v)
    }

    /// Per source at depth z: (T, ∂T/∂z, −z e^{−σtr d}/d), given d and e = e^{−σtr d} (see
    /// [`Dipole::rd_with_derivatives`] for the formulas).
    #[inline(always)]
    fn source_terms(&self, z: f64, d: f64, e: f64) -> (f64, f64, f64) {
        let inv_d = 1.0 / d;
        let inv_d3 = inv_d * inv_d * inv_d;
        let sd = self.sigma_tr * d;
        let t = z * (sd + 1.0) * e * inv_d3;
        let dt_dz = (sd + 1.0) * e * inv_d3
            - z * z * e * (sd * sd + 3.0 * sd + 3.0) * inv_d3 * inv_d * inv_d;
        (t, dt_dz, -z * e * inv_d)
    }

    /// Rd and its derivatives from the distances to the real and virtual sources and their
    /// exponentials: the chain rule through α′, zr, zv and σtr of [`Dipole::rd_with_derivatives`].
    #[inline(always)]
    fn sample_from_distances(&self, d_r: f64, d_v: f64, e_r: f64, e_v: f64) -> ProfileSample {
        let (t_r, dtr_dz, g_r) = self.source_terms(self.z_r, d_r, e_r);
        let (t_v, dtv_dz, g_v) = self.source_terms(self.z_v, d_v, e_v);
        let s = t_r + t_v;
        let sigma_a = self.props.sigma_a();
        let sigma_t = sigma_a + self.props.sigma_s_prime();
        // Common part of ∂S/∂p through zr and zv (∂zr/∂p = −zr², ∂zv/∂p = −k zr² for both p).
        let ds_z = -self.z_r * self.z_r * (dtr_dz + self.k_v * dtv_dz);
        // Through σtr: (−z e/d)·(3/2)·{σa for σ′s, σ′t + σa for σa}.
        let g = 1.5 * (g_r + g_v);
        let c = std::f64::consts::FRAC_1_PI * 0.25;
        let a = self.albedo_prime;
        ProfileSample {
            rd: c * a * s,
            d_sigma_s_prime: c * (self.da_dsp * s + a * (ds_z + g * sigma_a)),
            d_sigma_a: c * (self.da_dsa * s + a * (ds_z + g * (sigma_t + sigma_a))),
        }
    }

    /// [`Dipole::rd_with_derivatives`] at every radius of `radii_mm`, written to `out` (the shorter of
    /// the two sets the count). This is the hot path of the fit (one call per Levenberg–Marquardt
    /// iteration), so it is arranged for speed: blocks of 8 radii, square roots and exponentials in
    /// their own loops, and every per-dipole constant hoisted into a local. It repeats the arithmetic of
    /// `Dipole::sample_from_distances` rather than calling it because the call, even inlined, measured
    /// slower here (3.95 vs 4.85 µs in `scatterfit bench optics`; BENCHMARKS.md);
    /// `blocked_profile_equals_scalar` pins the two together.
    pub fn profile_with_derivatives_into(&self, radii_mm: &[f64], out: &mut [ProfileSample]) {
        const B: usize = 8;
        let n = radii_mm.len().min(out.len());
        let st = self.sigma_tr;
        let sigma_t = self.props.sigma_t_prime();
        let c = std::f64::consts::FRAC_1_PI * 0.25;
        let (zr, zv, kv) = (self.z_r, self.z_v, self.k_v);
        let z_r2 = zr * zr;
        let (da_dsp, da_dsa) = (self.da_dsp, self.da_dsa);
        let (sa, ap) = (self.props.sigma_a(), self.albedo_prime);
        for (radii, out) in radii_mm[..n].chunks(B).zip(out[..n].chunks_mut(B)) {
            let m = radii.len();
            let (mut dr, mut dv, mut er, mut ev) = ([1.0; B], [1.0; B], [0.0; B], [0.0; B]);
            for i in 0..m {
                let r2 = radii[i] * radii[i];
                dr[i] = (r2 + zr * zr).sqrt();
                dv[i] = (r2 + zv * zv).sqrt();
            }
            for i in 0..m {
                er[i] = (-st * dr[i]).exp();
                ev[i] = (-st * dv[i]).exp();
            }
            for i in 0..m {
                // Per source: T, ∂T/∂z and −z e/d, as in `source_terms`.
                let term = |z: f64, d: f64, e: f64| {
                    let inv_d = 1.0 / d;
                    let inv_d3 = inv_d * inv_d * inv_d;
                    let sd = st * d;
                    let t = z * (sd + 1.0) * e * inv_d3;
                    let dt_dz = (sd + 1.0) * e * inv_d3
                        - z * z * e * (sd * sd + 3.0 * sd + 3.0) * inv_d3 * inv_d * inv_d;
                    (t, dt_dz, -z * e * inv_d)
                };
                let (t_r, dtr_dz, g_r) = term(zr, dr[i], er[i]);
                let (t_v, dtv_dz, g_v) = term(zv, dv[i], ev[i]);
                let s = t_r + t_v;
                let ds_z = -z_r2 * (dtr_dz + kv * dtv_dz);
                let g = 1.5 * (g_r + g_v);
                out[i] = ProfileSample {
                    rd: c * ap * s,
                    d_sigma_s_prime: c * (da_dsp * s + ap * (ds_z + g * sa)),
                    d_sigma_a: c * (da_dsa * s + ap * (ds_z + g * (sigma_t + sa))),
                };
            }
        }
    }

    /// [`Dipole::rd_with_derivatives`] at every radius, without allocating.
    pub fn profile_with_derivatives<'a>(
        &'a self,
        radii_mm: &'a [f64],
    ) -> impl Iterator<Item = ProfileSample> + 'a {
        radii_mm.iter().map(|&r| self.rd_with_derivatives(r))
    }

    /// Total diffuse reflectance ∫2πr Rd(r) dr of this dipole ([`rd_total`]).
    pub fn rd_total(&self) -> f64 {
        rd_total(self.albedo_prime, self.props.eta())
    }
}

/// The trait delegates to the dipole's own methods (the blocked hot path included).
impl ProfileModel for Dipole {
    fn rd(&self, r_mm: f64) -> f64 {
        Dipole::rd(self, r_mm)
    }
    fn profile_with_derivatives_into(&self, radii_mm: &[f64], out: &mut [ProfileSample]) {
        Dipole::profile_with_derivatives_into(self, radii_mm, out);
    }
    fn rd_total(&self) -> f64 {
        Dipole::rd_total(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn props(sigma_a: f64, sigma_s_prime: f64, eta: f64) -> OpticalProperties {
        OpticalProperties::new(sigma_s_prime, sigma_a, eta).unwrap()
    }

    /// docs/physics.md §1.2: Jensen's polynomial Fdr, A, and the exact internal diffuse
    /// reflectance.
    #[test]
    fn fdr_and_a_match_reference_table() {
        let table = [
            (1.3, 0.44446, 0.444763, 2.602064),
            (1.33, 0.47195, 0.472357, 2.790444),
            (1.4, 0.52899, 0.529489, 3.250697),
            (1.5, 0.59635, 0.596733, 3.959497),
        ];
        for (eta, exact, poly, a) in table {
            assert!((f_dr(eta) - poly).abs() < 6e-7, "Fdr({eta})");
            assert!((a_coefficient(eta) - a).abs() < 6e-7, "A({eta})");
            assert!(
                (f_dr_exact(eta) - exact).abs() < 6e-6,
                "exact Fdr({eta}) = {}",
                f_dr_exact(eta)
            );
        }
        assert_eq!(f_dr(1.0), 0.0, "Fdr(1) := 0");
        assert!(f_dr_exact(1.0).abs() < 1e-12);
    }

    /// docs/physics.md §1.4: profile vectors for σa = 0.01, σ′s = 1, η = 1.3.
    #[test]
    fn profile_matches_reference_vectors() {
        let d = Dipole::new(&props(0.01, 1.0, 1.3));
        let table = [
            (0.0, 8.26052859e-02),
            (0.1, 8.13941471e-02),
            (0.5, 5.94555400e-02),
            (1.0, 3.03124265e-02),
            (2.0, 9.02090980e-03),
            (5.0, 1.24995140e-03),
            (10.0, 1.52138599e-04),
        ];
        for (r, want) in table {
            let got = d.rd(r);
            assert!(
                ((got - want) / want).abs() < 1e-8,
                "Rd({r}) = {got}, want {want}"
            );
            assert!(((d.rd_with_derivatives(r).rd - want) / want).abs() < 1e-8);
        }
    }

    /// docs/physics.md §1.3: closed-form totals (which equal scipy's quad of the profile).
    #[test]
    fn closed_form_total_matches_reference() {
        let table = [
            (0.01, 1.0, 1.3, 0.64582663),
            (0.1, 1.0, 1.3, 0.31367921),
            (0.0021, 2.19, 1.5, 0.83019146),
            (0.032, 0.74, 1.3, 0.43595636),
            (0.001, 1.0, 1.3, 0.86397770),
        ];
        for (sa, sp, eta, want) in table {
            let got = Dipole::new(&props(sa, sp, eta)).rd_total();
            assert!(
                (got - want).abs() < 1e-8,
                "σa={sa} σ′s={sp} η={eta}: {got} vs {want}"
            );
        }
    }

    /// docs/physics.md §1.3's η = 1 row (0.08773287) was computed with the raw polynomial Fdr(1) =
    /// 0.0016 (A = 1.003205); with our Fdr(1) := 0 (A = 1) the same formula must give the reference
    /// when fed that A, and a slightly larger value with A = 1.
    #[test]
    fn eta_one_row_uses_raw_polynomial() {
        let s = (3.0f64 * 0.5).sqrt();
        assert!((rd_total_of_s(s, 4.0 / 3.0 * 1.003205) - 0.08773287).abs() < 2e-8);
        assert!(rd_total(0.5, 1.0) > 0.08773287);
    }

    /// The profile integrates to the closed-form total (conservation check of eq. 4 vs eq. 5):
    /// ∫2πr Rd(r) dr on a log-spaced trapezoid out to r where the integrand is negligible.
    #[test]
    fn profile_integrates_to_total() {
        for (sa, sp, eta) in [
            (0.01, 1.0, 1.3),
            (0.5, 0.5, 1.0),
            (0.05, 2.0, 2.4),
            (0.2, 1.5, 1.1),
        ] {
            let d = Dipole::new(&props(sa, sp, eta));
            // Integrate in u = ln r: ∫ 2π r² Rd(r) du, from r = 1e-7 to 2000 mm.
            let (u0, u1, n) = ((1e-7f64).ln(), 2000f64.ln(), 200_000);
            let h = (u1 - u0) / n as f64;
            let f = |u: f64| {
                let r = u.exp();
                2.0 * std::f64::consts::PI * r * r * d.rd(r)
            };
            let mut sum = 0.5 * (f(u0) + f(u1));
            for i in 1..n {
                sum += f(u0 + i as f64 * h);
            }
            let integral = sum * h;
            assert!(
                (integral - d.rd_total()).abs() < 1e-6,
                "{integral} vs {}",
                d.rd_total()
            );
        }
    }

    /// Analytic derivatives agree with central finite differences.
    #[test]
    fn derivatives_match_finite_differences() {
        let cases = [
            (0.01, 1.0, 1.3),
            (0.5, 0.5, 1.0),
            (0.0008, 1.979, 1.2886),
            (1.189, 1.189, 1.9432),
        ];
        for (sa, sp, eta) in cases {
            let d = Dipole::new(&props(sa, sp, eta));
            for r in [0.0, 0.05, 0.3, 1.0, 3.0, 10.0] {
                let got = d.rd_with_derivatives(r);
                let h_sp = 1e-6 * sp;
                let fd_sp = (Dipole::new(&props(sa, sp + h_sp, eta)).rd(r)
                    - Dipole::new(&props(sa, sp - h_sp, eta)).rd(r))
                    / (2.0 * h_sp);
                let h_sa = 1e-6 * sa;
                let fd_sa = (Dipole::new(&props(sa + h_sa, sp, eta)).rd(r)
                    - Dipole::new(&props(sa - h_sa, sp, eta)).rd(r))
                    / (2.0 * h_sa);
                let scale = got.rd.abs().max(1e-300);
                assert!(
                    (got.d_sigma_s_prime - fd_sp).abs() <= 1e-6 * scale.max(fd_sp.abs()) * 10.0,
                    "∂/∂σ′s at r={r}, {sa},{sp},{eta}: {} vs {fd_sp}",
                    got.d_sigma_s_prime
                );
                assert!(
                    (got.d_sigma_a - fd_sa).abs() <= 1e-6 * scale.max(fd_sa.abs()) * 10.0,
                    "∂/∂σa at r={r}, {sa},{sp},{eta}: {} vs {fd_sa}",
                    got.d_sigma_a
                );
            }
        }
    }

    /// The blocked evaluation gives exactly the scalar method's numbers (same arithmetic).
    #[test]
    fn blocked_profile_equals_scalar() {
        let d = Dipole::new(&props(0.05, 1.3, 1.4));
        let radii: Vec<f64> = (0..37).map(|i| 0.13 * i as f64).collect();
        let mut out = vec![
            ProfileSample {
                rd: 0.0,
                d_sigma_s_prime: 0.0,
                d_sigma_a: 0.0
            };
            37
        ];
        d.profile_with_derivatives_into(&radii, &mut out);
        for (r, got) in radii.iter().zip(&out) {
            let want = d.rd_with_derivatives(*r);
            assert!((got.rd - want.rd).abs() <= 1e-15 * want.rd.abs());
            assert!(
                (got.d_sigma_s_prime - want.d_sigma_s_prime).abs()
                    <= 1e-13 * want.d_sigma_s_prime.abs()
            );
            assert!((got.d_sigma_a - want.d_sigma_a).abs() <= 1e-13 * want.d_sigma_a.abs());
        }
    }

    /// σa = 0 (a perfect scatterer) is allowed and its derivatives stay finite.
    #[test]
    fn zero_absorption_has_finite_derivatives() {
        let d = Dipole::new(&props(0.0, 1.0, 1.3));
        let s = d.rd_with_derivatives(1.0);
        assert!(s.rd.is_finite() && s.d_sigma_s_prime.is_finite() && s.d_sigma_a.is_finite());
        assert!(s.d_sigma_a < 0.0, "absorption lowers the profile at 1 mm");
        assert!((d.rd_total() - 1.0).abs() < 1e-15);
    }

    /// docs/physics.md §1.6: inversion vectors at η = 1.3.
    #[test]
    fn inversion_matches_reference_vectors() {
        for (rd, want) in [
            (0.1, 0.59195420),
            (0.3, 0.90057068),
            (0.5, 0.97258193),
            (0.7, 0.99360243),
            (0.9, 0.99948820),
        ] {
            let got = albedo_from_rd(rd, 1.3).unwrap();
            assert!((got - want).abs() < 6e-9, "Rd={rd}: {got} vs {want}");
        }
    }

    /// Rd(α′) is strictly increasing, and the inversion round-trips to 1e-10 over
    /// α′ ∈ [0.01, 0.99999], η ∈ [1, 2.5].
    #[test]
    fn rd_monotonic_and_inversion_round_trips() {
        for i in 0..=30 {
            let eta = 1.0 + 1.5 * i as f64 / 30.0;
            let mut prev = 0.0;
            for j in 0..=400 {
                // Dense near 1, where the inversion is hardest.
                let t = j as f64 / 400.0;
                let alpha = 0.01 + (0.99999 - 0.01) * (1.0 - (1.0 - t).powi(4));
                let rd = rd_total(alpha, eta);
                assert!(rd > prev, "Rd not increasing at α′={alpha}, η={eta}");
                prev = rd;
                let back = albedo_from_rd(rd, eta).unwrap();
                assert!(
                    (back - alpha).abs() < 1e-10,
                    "α′={alpha} η={eta}: got {back}"
                );
            }
        }
    }

    #[test]
    fn inversion_refuses_impossible_reflectance() {
        for bad in [0.0, -0.1, 1.0001, f64::NAN, f64::INFINITY] {
            assert!(
                matches!(
                    albedo_from_rd(bad, 1.3),
                    Err(OpticsError::RdOutOfRange { .. })
                ),
                "{bad}"
            );
        }
        assert!(albedo_from_rd(0.5, 0.9).is_err(), "η < 1");
        assert_eq!(albedo_from_rd(1.0, 1.3).unwrap(), 1.0);
    }

    /// pbrt's Jensen-2001 table (docs/physics.md §1.5): Rd at η = 1.3 and 1.5 computed from its
    /// σ's.
    #[test]
    fn jensen_table_totals() {
        // (σ′s, σa, Rd at η=1.3, Rd at η=1.5), Apple R and Skin1 G, Marble B.
        for (sp, sa, rd13, rd15) in [
            (2.29, 0.0030, 0.8464, 0.8060),
            (0.88, 0.17, 0.2273, 0.2140),
            (3.00, 0.0071, 0.8010, 0.7526),
        ] {
            let a = sp / (sp + sa);
            assert!((rd_total(a, 1.3) - rd13).abs() < 6e-5);
            assert!((rd_total(a, 1.5) - rd15).abs() < 6e-5);
        }
    }
}
