//! The optics crate's error type.

/// What can go wrong in the optics core: a value outside the domain of a formula.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum OpticsError {
    /// A physical quantity is outside its domain (negative coefficient, η < 1, NaN, …).
    #[error("{name} = {value} is invalid: {reason}")]
    InvalidParameter {
        /// The quantity's name as the user knows it (e.g. "sigma_a [mm^-1]").
        name: &'static str,
        /// The value given.
        value: f64,
        /// Why it is invalid and what range is accepted.
        reason: &'static str,
    },
    /// A total diffuse reflectance the model cannot produce for this η.
    #[error(
        "diffuse reflectance Rd = {rd:.4} cannot be produced by the dipole model (η = {eta:.4}): \
         it reaches every value in (0, 1] only; {hint}"
    )]
    RdOutOfRange {
        /// The reflectance asked for.
        rd: f64,
        /// The refractive index used.
        eta: f64,
        /// What the user can do about it.
        hint: &'static str,
    },
    /// A total diffuse reflectance outside what a forward model produces at this η.
    #[error(
        "diffuse reflectance Rd = {rd:.6} cannot be produced by the {model} model at η = {eta:.4}: \
         it reaches (0, {max:.6}] only; check the colour measurement (Rd is a fraction, not a \
         percentage, and a black or out-of-gamut channel gives Rd ≤ 0), or choose another model"
    )]
    RdOutOfModelRange {
        /// The model's name, e.g. "better dipole".
        model: &'static str,
        /// The reflectance asked for.
        rd: f64,
        /// The refractive index used.
        eta: f64,
        /// The model's largest total reflectance at this η (at α′ = 1).
        max: f64,
    },
    /// The specular reflectance SCI − SCE cannot give a refractive index.
    #[error("specular reflectance SCI − SCE = {specular:.6} cannot give η: {reason}")]
    Specular {
        /// The (summary) specular reflectance.
        specular: f64,
        /// Why, and what to do.
        reason: &'static str,
    },
    /// A forward-model name that is not one of the diffusion models.
    #[error("unknown forward model {0:?}: expected one of dipole, better-dipole, pbd (or mc)")]
    UnknownModel(String),
    /// A spectrum that does not cover the range a colour computation needs.
    #[error("spectrum: {0}")]
    Spectrum(String),
}

/// Result with [`OpticsError`].
pub type Result<T> = std::result::Result<T, OpticsError>;

/// Checks that `value` is finite and ≥ 0.
pub(crate) fn non_negative(name: &'static str, value: f64) -> Result<f64> {
    if value.is_finite() && value >= 0.0 {
        Ok(value)
    } else {
        Err(OpticsError::InvalidParameter {
            name,
            value,
            reason: "must be a finite number ≥ 0",
        })
    }
}

/// Checks that `eta` is finite and ≥ 1 (a material denser than air).
pub(crate) fn eta_at_least_one(value: f64) -> Result<f64> {
    if value.is_finite() && value >= 1.0 {
        Ok(value)
    } else {
        Err(OpticsError::InvalidParameter {
            name: "eta",
            value,
            reason: "the relative refractive index (material / air) must be finite and ≥ 1",
        })
    }
}
