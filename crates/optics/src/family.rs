//! The one vocabulary of forward models: a [`ProfileModel`] is Rd(r) for one parameter set; a
//! [`ModelFamily`] is a named model (the classical dipole, the better dipole, photon beam diffusion —
//! [`crate::DiffusionModel`] — or, in the `mc` crate, the Monte Carlo tables) that builds profiles,
//! evaluates them on the fit's hot path, and gives its total diffuse reflectance Rd(α′, η, g) and the
//! inverse α′(Rd, η, g) — the spectrophotometer's albedo "by the same physics".
//!
//! The fit, the renderer and the library take `&dyn ModelFamily`; a name becomes a family in one
//! place, `scatterfit_mc::family`.

use serde::Serialize;

use crate::error::Result;
use crate::names::ModelName;
use crate::properties::OpticalProperties;

/// Rd(r) and its partial derivatives in σ′s and σa at one radius.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ProfileSample {
    /// Radially resolved diffuse reflectance Rd(r) [mm⁻²].
    pub rd: f64,
    /// ∂Rd/∂σ′s [mm⁻² / mm⁻¹ = mm⁻¹].
    pub d_sigma_s_prime: f64,
    /// ∂Rd/∂σa [mm⁻¹].
    pub d_sigma_a: f64,
}

impl ProfileSample {
    /// NaN everywhere: what [`ModelFamily::eval`] writes where a model cannot evaluate a parameter
    /// set (the fit treats it as a point it may not visit).
    pub const NAN: ProfileSample = ProfileSample {
        rd: f64::NAN,
        d_sigma_s_prime: f64::NAN,
        d_sigma_a: f64::NAN,
    };

    /// Zero everywhere (a buffer's initial value).
    pub const ZERO: ProfileSample = ProfileSample {
        rd: 0.0,
        d_sigma_s_prime: 0.0,
        d_sigma_a: 0.0,
    };
}

/// A radially resolved diffuse reflectance model Rd(r) of a half-space lit by a pencil beam at
/// normal incidence, for one set of optical properties (built per parameter set, like
/// [`crate::dipole::Dipole::new`], usually by [`ModelFamily::profile`]).
pub trait ProfileModel: Send + Sync {
    /// Rd(r) [mm⁻²] at radius `r_mm` ≥ 0 \[mm\] from the point of incidence.
    fn rd(&self, r_mm: f64) -> f64;
    /// Rd and its partial derivatives ∂Rd/∂σ′s, ∂Rd/∂σa at every radius of `radii_mm`, written to
    /// `out` (the shorter of the two sets the count). Derivatives are analytic (never finite
    /// differences).
    fn profile_with_derivatives_into(&self, radii_mm: &[f64], out: &mut [ProfileSample]);
    /// Total diffuse reflectance ∫₀^∞ 2πr Rd(r) dr \[1\] (excluding the specular reflection).
    fn rd_total(&self) -> f64;
}

/// A named forward model: builds a [`ProfileModel`] per parameter set, and knows its own total
/// diffuse reflectance and its inverse. Stateless per evaluation, shared between threads.
pub trait ModelFamily: Send + Sync {
    /// The model's name (as in the manifest, `result.json` and `--model`).
    fn name(&self) -> ModelName;

    /// The model for `props` (its σ′s, σa, η and g).
    ///
    /// # Errors
    /// Where the model does not cover the parameters: `InvalidParameter` (η > 2.5 for the improved
    /// diffusion models), `OutOfTable` (α′ or η outside the Monte Carlo tables),
    /// `AnisotropyMismatch` (a g the tables were not made for), `AnisotropyNotTabulated` (a g the
    /// Monte Carlo grid neither holds nor interpolates).
    fn profile(&self, props: &OpticalProperties) -> Result<Box<dyn ProfileModel>>;

    /// Rd and ∂Rd/∂σ′s, ∂Rd/∂σa for `props` at every radius of `radii_mm`, into `out`; NaN
    /// ([`ProfileSample::NAN`]) everywhere when the model cannot evaluate `props`. The fit's hot path
    /// (one call per Levenberg–Marquardt iteration): a family may override it to build its model
    /// without a heap allocation.
    fn eval(&self, props: &OpticalProperties, radii_mm: &[f64], out: &mut [ProfileSample]) {
        match self.profile(props) {
            Ok(m) => m.profile_with_derivatives_into(radii_mm, out),
            Err(_) => out.fill(ProfileSample::NAN),
        }
    }

    /// Total diffuse reflectance Rd(α′, η, g) of the model (excluding the specular reflection).
    ///
    /// # Errors
    /// `InvalidParameter` for α′ outside [0, 1], η or g outside the model's range; `OutOfTable`
    /// outside the Monte Carlo tables.
    fn rd_total(&self, albedo_prime: f64, eta: f64, g: f64) -> Result<f64>;

    /// The reduced albedo α′ whose total diffuse reflectance is `rd` at η and g: the inverse of
    /// [`ModelFamily::rd_total`] (monotonic for every model).
    ///
    /// # Errors
    /// `RdOutOfRange`/`RdOutOfModelRange`/`OutOfTable` for an Rd the model cannot produce,
    /// `InvalidParameter` for η or g outside its range.
    fn albedo_from_rd(&self, rd: f64, eta: f64, g: f64) -> Result<f64>;
}

/// A family evaluated at one Henyey–Greenstein g: every parameter set it is given is taken at `g`
/// ([`OpticalProperties::with_g`]), and its totals and their inverse at `g` whatever g they are asked
/// for. How a known or assumed g (the manifest's `[fit] g`) reaches a fit that builds its parameter
/// sets from (σ′s, σa, η) alone. The diffusion dipoles ignore g; photon beam diffusion and the Monte
/// Carlo tables use it.
#[derive(Clone, Copy)]
pub struct AtG<'a> {
    family: &'a dyn ModelFamily,
    g: f64,
}

impl<'a> AtG<'a> {
    /// `family` at asymmetry `g`.
    ///
    /// # Errors
    /// [`crate::OpticsError::InvalidParameter`] for g outside (−1, 1) or not finite.
    pub fn new(family: &'a dyn ModelFamily, g: f64) -> Result<Self> {
        crate::error::check_g(g)?;
        Ok(Self { family, g })
    }

    /// The g every evaluation uses.
    pub fn g(&self) -> f64 {
        self.g
    }
}

impl ModelFamily for AtG<'_> {
    fn name(&self) -> ModelName {
        self.family.name()
    }

    fn profile(&self, props: &OpticalProperties) -> Result<Box<dyn ProfileModel>> {
        self.family.profile(&props.with_g(self.g)?)
    }

    fn eval(&self, props: &OpticalProperties, radii_mm: &[f64], out: &mut [ProfileSample]) {
        match props.with_g(self.g) {
            Ok(p) => self.family.eval(&p, radii_mm, out),
            Err(_) => out.fill(ProfileSample::NAN),
        }
    }

    fn rd_total(&self, albedo_prime: f64, eta: f64, _g: f64) -> Result<f64> {
        self.family.rd_total(albedo_prime, eta, self.g)
    }

    fn albedo_from_rd(&self, rd: f64, eta: f64, _g: f64) -> Result<f64> {
        self.family.albedo_from_rd(rd, eta, self.g)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::DiffusionModel;

    /// `AtG` gives every parameter set its g: photon beam diffusion (which uses g) at g = 0.6
    /// through the wrapper equals the model given g = 0.6 directly, and differs from g = 0; totals
    /// and the inversion are taken at the wrapper's g whatever g they are asked for; a bad g is
    /// refused.
    #[test]
    fn at_g_gives_its_g_to_every_evaluation() {
        let pbd = DiffusionModel::Pbd;
        let at = AtG::new(&pbd, 0.6).unwrap();
        assert_eq!(at.name(), ModelName::Pbd);
        assert_eq!(at.g(), 0.6);
        let p = OpticalProperties::new(1.2, 0.05, 1.4).unwrap();
        let radii = [0.3, 1.0, 3.0];
        let (mut a, mut b, mut c) = (
            [ProfileSample::ZERO; 3],
            [ProfileSample::ZERO; 3],
            [ProfileSample::ZERO; 3],
        );
        at.eval(&p, &radii, &mut a);
        pbd.eval(&p.with_g(0.6).unwrap(), &radii, &mut b);
        pbd.eval(&p, &radii, &mut c);
        assert_eq!(a, b);
        assert_ne!(a, c);
        let direct = pbd.profile(&p.with_g(0.6).unwrap()).unwrap();
        assert_eq!(at.profile(&p).unwrap().rd(1.0), direct.rd(1.0));
        let rd = pbd.rd_total(0.9, 1.4, 0.6).unwrap();
        assert_eq!(at.rd_total(0.9, 1.4, 0.0).unwrap(), rd);
        assert_eq!(
            at.albedo_from_rd(rd, 1.4, 0.0).unwrap(),
            pbd.albedo_from_rd(rd, 1.4, 0.6).unwrap()
        );
        assert!(AtG::new(&pbd, 1.0).is_err());
        assert!(AtG::new(&pbd, f64::NAN).is_err());
    }
}
