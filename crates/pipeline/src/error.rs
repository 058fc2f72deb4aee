//! The pipeline's error: a stage that could not run. Each variant says whether the input was bad
//! (exit 2: fix the files or the options) or the measurement ran and failed (exit 1).

use std::path::PathBuf;

use scatterfit_imaging::ImagingError;
use scatterfit_io::bracket::BracketError;
use scatterfit_io::image_files::ImageFileError;
use scatterfit_io::manifest::ManifestError;
use scatterfit_io::profile_csv::ProfileCsvError;
use scatterfit_io::response_csv::ResponseCsvError;
use scatterfit_io::spectro::SpectroCsvError;
use scatterfit_optics::OpticsError;

/// Why a stage of the pipeline could not run.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PipelineError {
    /// The sample manifest is missing or wrong.
    #[error(transparent)]
    Manifest(#[from] ManifestError),
    /// The spectrophotometer CSV is missing or wrong.
    #[error(transparent)]
    SpectroCsv(#[from] SpectroCsvError),
    /// The spectrophotometer reading cannot give η or colour.
    #[error("{}: {source}", file.display())]
    Spectro {
        /// The reading.
        file: PathBuf,
        /// What the optics stage said.
        source: OpticsError,
    },
    /// The exposure bracket is missing or inconsistent.
    #[error("reading the exposure bracket: {0}")]
    Bracket(#[from] BracketError),
    /// The dark frame is unreadable.
    #[error("reading the dark frame: {0}")]
    DarkFrame(#[source] ImageFileError),
    /// The dark frame's size, channels or bit depth differ from the bracket's frames.
    #[error(transparent)]
    DarkFrameShape(BracketError),
    /// The flat frame (`camera.flat`) is unreadable.
    #[error("reading the flat frame (camera.flat): {0}")]
    FlatFrame(#[source] ImageFileError),
    /// The flat frame's size, channels or bit depth differ from the bracket's frames.
    #[error("the flat frame (camera.flat) does not match the bracket: {0}")]
    FlatFrameShape(#[source] BracketError),
    /// An image file is unreadable.
    #[error(transparent)]
    Image(#[from] ImageFileError),
    /// A camera response CSV is wrong.
    #[error(transparent)]
    ResponseCsv(#[from] ResponseCsvError),
    /// A profile CSV is wrong.
    #[error(transparent)]
    ProfileCsv(#[from] ProfileCsvError),
    /// Pixel work failed: response recovery, merge, spot finding.
    #[error("{context}: {source}")]
    Imaging {
        /// What was being done (and, where useful, what to do).
        context: String,
        /// The imaging error.
        source: ImagingError,
    },
    /// A file named by the manifest (or by the exposures CSV) resolves outside the sample folder
    /// (the input path policy, `scatterfit_io::inputs`).
    #[error(transparent)]
    InputPath(#[from] scatterfit_io::inputs::InputPathError),
    /// An option or a combination of inputs the pipeline cannot use.
    #[error("{0}")]
    Input(String),
    /// Not measured: the caller stopped the work before this sample started
    /// ([`crate::BatchRequest::stop_when`]).
    #[error("not measured: the batch was stopped before this sample started")]
    Interrupted,
}

/// The forward-model factory's failure (the Monte Carlo tables shipped with scatterfit do not load)
/// as bad input, as the commands report it.
impl From<scatterfit_mc::McError> for PipelineError {
    fn from(e: scatterfit_mc::McError) -> Self {
        PipelineError::Input(format!("the Monte Carlo tables: {e}"))
    }
}

impl PipelineError {
    /// True when the tool ran and the measurement failed (exit 1); false for bad input or usage
    /// (exit 2). Pixel work that fails on valid files — a response that cannot be recovered, a spot
    /// that is not there — is a failed measurement; a spectrophotometer reading without specular
    /// reflection is too.
    pub fn is_measurement_failure(&self) -> bool {
        match self {
            PipelineError::Imaging { source, .. } => source.is_failed_measurement(),
            PipelineError::Spectro { source, .. } => matches!(source, OpticsError::Specular { .. }),
            PipelineError::Interrupted => true,
            _ => false,
        }
    }
}

/// Result with [`PipelineError`].
pub type Result<T> = std::result::Result<T, PipelineError>;
