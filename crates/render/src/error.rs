//! The renderer's errors.

/// What can go wrong setting up a render. Numerical outcomes (noise, clamped formulas) are reported
/// in [`crate::RenderStats`], not raised.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RenderError {
    /// A mesh is unusable (empty, index out of range, non-finite coordinate, …).
    #[error("invalid mesh: {0}")]
    InvalidMesh(String),
    /// An option or parameter is out of its domain.
    #[error("invalid {name} = {value}: {reason}")]
    InvalidOption {
        /// The option.
        name: &'static str,
        /// Its value, as text.
        value: String,
        /// Its domain, and what to do.
        reason: &'static str,
    },
    /// Optical properties refused by `scatterfit-optics`.
    #[error(transparent)]
    Optics(#[from] scatterfit_optics::OpticsError),
    /// A channel's parameters outside what the chosen profile model covers.
    #[error(
        "the {model} model cannot take channel {channel} (σ′s = {sigma_s_prime}, σa = {sigma_a} \
         mm⁻¹, η = {eta}): {source}"
    )]
    Profile {
        /// The profile model.
        model: scatterfit_optics::ModelName,
        /// The channel.
        channel: scatterfit_optics::Channel,
        /// σ′s [mm⁻¹].
        sigma_s_prime: f64,
        /// σa [mm⁻¹].
        sigma_a: f64,
        /// η.
        eta: f64,
        /// Why.
        source: scatterfit_optics::OpticsError,
    },
    /// An image could not be built (zero size).
    #[error("image: {0}")]
    Image(#[from] scatterfit_imaging::ShapeError),
    /// A radial profile of a rendered image failed.
    #[error(transparent)]
    Imaging(#[from] scatterfit_imaging::ImagingError),
    /// The caption font could not be parsed.
    #[error("caption font: {0}")]
    Font(String),
}

/// `Result` with [`RenderError`].
pub type Result<T> = std::result::Result<T, RenderError>;

pub(crate) fn invalid(
    name: &'static str,
    value: impl ToString,
    reason: &'static str,
) -> RenderError {
    RenderError::InvalidOption {
        name,
        value: value.to_string(),
        reason,
    }
}
