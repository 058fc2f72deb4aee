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
    /// Rd(r) [mm⁻²] at radius `r_mm` ≥ 0 [mm] from the point of incidence.
    fn rd(&self, r_mm: f64) -> f64;
    /// Rd and its partial derivatives ∂Rd/∂σ′s, ∂Rd/∂σa at every radius of `radii_mm`, written to
    /// `out` (the shorter of the two sets the count). Derivatives are analytic (never finite
    /// differences).
    fn profile_with_derivatives_into(&self, radii_mm: &[f64], out: &mut [ProfileSample]);
    /// Total diffuse reflectance ∫₀^∞ 2πr Rd(r) dr [1] (excluding the specular reflection).
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
