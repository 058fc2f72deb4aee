//! The optics crate's error type.

/// What can go wrong in the optics core: a value outside the domain of a formula.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum OpticsError {
    /// A physical quantity is outside its domain (negative coefficient, η < 1, NaN, …).
    #[error("{name} = {} is invalid: {reason}", short_number(*value))]
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
    /// A name (of a forward model, an albedo model, a method) that is not one of the valid ones.
    #[error("unknown {what} {given:?}: expected one of {expected}")]
    UnknownName {
        /// What was named, e.g. "forward model".
        what: &'static str,
        /// The name given.
        given: String,
        /// The valid names, comma-separated.
        expected: &'static str,
    },
    /// A parameter outside what a tabulated model (the Monte Carlo tables) covers.
    #[error("{name} = {value} is outside the table's range [{min}, {max}]")]
    OutOfTable {
        /// Which coordinate, e.g. `eta` or `rd_total`.
        name: &'static str,
        /// The value asked for.
        value: f64,
        /// The tables' lower limit.
        min: f64,
        /// The tables' upper limit.
        max: f64,
    },
    /// A Henyey–Greenstein g other than the one the Monte Carlo tables were made for.
    #[error(
        "g = {given} but the Monte Carlo tables were made for g = {tables}: build tables for this \
         g (`scatterfit table --g {given}`) or use g = {tables}"
    )]
    AnisotropyMismatch {
        /// The g asked for.
        given: f64,
        /// The tables' g.
        tables: f64,
    },
    /// A Henyey–Greenstein g that the Monte Carlo tables' (η, g) grid neither holds nor
    /// interpolates (`scatterfit_mc::McGridSet`).
    #[error(
        "g = {given} is not covered by the Monte Carlo tables: they hold {tabulated}; use a g \
         they cover (a g above the last node is not extrapolated: the nearest node is the closest \
         the tool can model), or add tables at this g to the build (`cargo run --release -p \
         scatterfit-mc --example build_g_tables -- --out DIR --g {given}`, then listed in \
         crates/mc/src/bundled.rs and the tool rebuilt: crates/mc/tables-g/README.md)"
    )]
    AnisotropyNotTabulated {
        /// The g asked for.
        given: f64,
        /// What the grid covers, in words.
        tabulated: String,
    },
    /// η outside the Monte Carlo tables of a g node the query needs (`scatterfit_mc::McGridSet`:
    /// the nodes at g ≠ 0 span a narrower η range than g = 0's).
    #[error(
        "η = {eta:.4} at g = {g}: the Monte Carlo tables at g = {node} cover η {min}–{max} only \
         (the whole grid: {tabulated}); at this η give a g the tables cover, or use a diffusion \
         model (`--model dipole`), which does not depend on g"
    )]
    EtaNotTabulatedAtG {
        /// The η asked for.
        eta: f64,
        /// The g asked for.
        g: f64,
        /// The g node whose tables do not reach η.
        node: f64,
        /// That node's lowest η.
        min: f64,
        /// That node's highest η.
        max: f64,
        /// What the grid covers, in words.
        tabulated: String,
    },
    /// A spectrum that does not cover the range a colour computation needs.
    #[error("spectrum: {0}")]
    Spectrum(String),
}

/// A number for messages: as written for ordinary magnitudes, in scientific notation beyond them
/// (Display writes 1e300 as 301 digits).
fn short_number(v: f64) -> String {
    if v == 0.0 || !v.is_finite() || (1e-4..1e9).contains(&v.abs()) {
        format!("{v}")
    } else {
        format!("{v:.4e}")
    }
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

/// Checks that the Henyey–Greenstein asymmetry `g` is finite and in (−1, 1).
pub(crate) fn check_g(g: f64) -> Result<f64> {
    if g.is_finite() && g.abs() < 1.0 {
        Ok(g)
    } else {
        Err(OpticsError::InvalidParameter {
            name: "g",
            value: g,
            reason: "the Henyey–Greenstein asymmetry must lie in (−1, 1)",
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
