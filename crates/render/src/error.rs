//! The renderer's errors.

use std::path::PathBuf;

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
    /// Parameters named neither an existing file nor a published set.
    #[error(
        "{spec}: no such file, and not a published material; give a result.json of `scatterfit \
         measure` or one of: {}, and {}",
        published.join(", "),
        existing.join(", ")
    )]
    UnknownParameters {
        /// What was given.
        spec: String,
        /// The published sets of the proposed method (Table 1).
        published: Vec<String>,
        /// The existing method's published sets.
        existing: Vec<String>,
    },
    /// A result fitted with a model this version does not know, and no model given instead.
    #[error(
        "{spec}: the parameters were fitted with a model render does not know (`{model}`); pass \
         --model dipole|better-dipole|pbd|mc"
    )]
    UnknownModel {
        /// The result file.
        spec: String,
        /// The model's name as the file has it (escaped).
        model: String,
    },
    /// A result whose channel has no σ′s or σa: the measurement failed there.
    #[error(
        "{spec}: channel {channel} has no σ′s/σa (status {status}{}); render needs all three \
         channels — re-run the measurement or fix that channel",
        problem.as_deref().map(|p| format!(": {p}")).unwrap_or_default()
    )]
    FailedChannel {
        /// The result file.
        spec: String,
        /// `r`, `g` or `b`.
        channel: &'static str,
        /// The channel's status.
        status: String,
        /// Why, as the result says.
        problem: Option<String>,
    },
    /// A validation against the measured profile needs a result, not published parameters.
    #[error(
        "--profile needs a result.json (its fitted scales and measured profile); `{source_name}` is \
         a published parameter set"
    )]
    NotAResult {
        /// Where the parameters came from.
        source_name: String,
    },
    /// A result or measured profile lacks what the validation needs.
    #[error("{}: {detail}", file.display())]
    Measurement {
        /// The result or profile file.
        file: PathBuf,
        /// What is missing, and what to do.
        detail: String,
    },
    /// The material of a parameter set could not be made.
    #[error("{name}")]
    Material {
        /// The parameter set.
        name: String,
        /// Why.
        source: Box<RenderError>,
    },
    /// The measurement's geometry (scale, spot, profile radius) cannot be rendered.
    #[error("the measurement geometry")]
    Geometry(#[source] Box<RenderError>),
    /// A mesh file the renderer refuses.
    #[error("mesh {}", path.display())]
    MeshFile {
        /// The file.
        path: PathBuf,
        /// Why.
        source: Box<RenderError>,
    },
    /// An output could not be written.
    #[error("writing {}", path.display())]
    Write {
        /// The file.
        path: PathBuf,
        /// Why.
        source: Box<dyn std::error::Error + Send + Sync>,
    },
    /// The Monte Carlo model family (its tables) is unavailable.
    #[error(transparent)]
    Mc(#[from] scatterfit_mc::McError),
    /// A result file could not be read.
    #[error(transparent)]
    ResultJson(#[from] scatterfit_io::result_json::ResultJsonError),
    /// A mesh file could not be read.
    #[error(transparent)]
    MeshRead(#[from] scatterfit_io::mesh::MeshError),
    /// A profile CSV could not be read.
    #[error(transparent)]
    ProfileCsv(#[from] scatterfit_io::profile_csv::ProfileCsvError),
    /// An image file could not be written.
    #[error(transparent)]
    ImageFile(#[from] scatterfit_io::image_files::ImageFileError),
    /// A file named by a result lies outside its folder.
    #[error(transparent)]
    InputPath(#[from] scatterfit_io::inputs::InputPathError),
    /// A result set could not be read, or names other files than those found.
    #[error(transparent)]
    ResultSet(#[from] scatterfit_io::result_set::ResultSetError),
}

impl RenderError {
    /// True for a measurement that failed (a result with a channel without parameters), as opposed
    /// to bad input or options: the CLI's exit code 1.
    pub fn is_measurement_failure(&self) -> bool {
        matches!(self, RenderError::FailedChannel { .. })
    }
}

/// `Result` with [`RenderError`].
pub type Result<T> = std::result::Result<T, RenderError>;

pub(crate) fn invalid(
    name: &'static str,
    value: impl ToString,
    reason: &'static str,
) -> RenderError {
    let text = value.to_string();
    // A huge or tiny float prints in full (1e300 as 301 digits): shown in scientific notation.
    let value = match text.parse::<f64>() {
        Ok(v) if text.len() > 16 && v.is_finite() => format!("{v:.4e}"),
        _ => text,
    };
    RenderError::InvalidOption {
        name,
        value,
        reason,
    }
}
