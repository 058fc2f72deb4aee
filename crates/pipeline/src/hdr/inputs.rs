//! What the HDR stage merges and how ([`HdrInputs`]), from a caller's options or a sample's
//! manifest ([`HdrInputs::from_manifest`]).

use std::path::PathBuf;

use scatterfit_imaging::{ClippedFill, Weighting};
use scatterfit_io::manifest::{AutoOrNone, BlackLevelSetting, ExposureCorrection, SampleManifest};

use crate::error::Result;

/// The black level of linear frames.
#[derive(Debug, Clone, PartialEq, Default)]
pub enum BlackLevel {
    /// From a dark frame when given, else the RAW file's metadata, else the far corners
    /// ([`crate::camera::estimate_black_level`]).
    #[default]
    Auto,
    /// None (the frames are black-subtracted already).
    None,
    /// Given per channel \[DN\] (one value for all channels is repeated).
    Given(Vec<f64>),
}

/// What to merge and how.
#[derive(Debug, Clone, PartialEq)]
pub struct HdrInputs {
    /// The frames (may be empty when `exposures` lists them).
    pub images: Vec<PathBuf>,
    /// `exposures.csv` (file,time_s), or `None` for EXIF times.
    pub exposures: Option<PathBuf>,
    /// A known response CSV (8-bit only).
    pub response: Option<PathBuf>,
    /// A dark frame.
    pub dark: Option<PathBuf>,
    /// Smoothness λ of the response recovery.
    pub lambda: f64,
    /// Sample pixels per channel for the response recovery; `None` for
    /// [`default_response_samples`](super::default_response_samples) of the bracket's frame count (what `measure` uses).
    pub samples: Option<usize>,
    /// 16-bit saturation value.
    pub saturation: u16,
    /// True when `saturation` was stated (`camera.saturation`): it then overrides the clipping
    /// plateau found in the frames and a RAW file's white level; 8-bit frames are refused with it.
    pub saturation_given: bool,
    /// What to store for pixel-channels clipped in every exposure.
    pub clipped_fill: ClippedFill,
    /// 8-bit sample weighting when `weighting_auto` is false.
    pub weighting: Weighting,
    /// 8-bit brackets (without a dark frame): choose the weighting from the bracket — the
    /// noise-aware one unless the paper's hat explains the frames clearly better
    /// (`merge::AUTO_HAT_MARGIN`). Default true.
    pub weighting_auto: bool,
    /// Memory budget in bytes that the decoded frames are checked against before any is decoded;
    /// `None` for the environment's ([`scatterfit_io::budget::memory_budget_bytes`]).
    pub memory_budget: Option<u64>,
    /// The black level of linear frames (default auto).
    pub black_level: BlackLevel,
    /// Whether exposure times are estimated from the frames and used (default auto).
    pub exposure_correction: ExposureCorrection,
    /// A flat frame (vignetting), divided out of the radiance.
    pub flat: Option<PathBuf>,
}

impl HdrInputs {
    /// Defaults (λ = 10, the bracket's default sample count, 65535 saturation, NaN fill, noise-optimal weighting, the
    /// environment's memory budget) for a bracket listed in `exposures`.
    pub fn new(exposures: Option<PathBuf>, images: Vec<PathBuf>) -> Self {
        Self {
            images,
            exposures,
            response: None,
            dark: None,
            lambda: 10.0,
            samples: None,
            saturation: u16::MAX,
            saturation_given: false,
            clipped_fill: ClippedFill::Nan,
            weighting: Weighting::NoiseOptimal,
            weighting_auto: true,
            memory_budget: None,
            black_level: BlackLevel::Auto,
            exposure_correction: ExposureCorrection::Auto,
            flat: None,
        }
    }

    /// The merge's inputs as a sample's manifest names them (`[camera]`: the frames or their
    /// exposures CSV, a response, a dark frame, a flat frame, the black level, the saturation and
    /// the exposure correction), the paths resolved against the sample folder. Pixels dark in
    /// every frame are kept as 0 (evidence of radiance below the first code, so far rings are not
    /// averaged over their brighter pixels only); pixels saturated in every frame are masked out
    /// by the profile stage.
    pub fn from_manifest(manifest: &SampleManifest) -> Self {
        let camera = &manifest.camera;
        let mut inputs = Self::new(
            camera.exposures.as_ref().map(|p| manifest.resolve(p)),
            camera
                .images
                .iter()
                .flatten()
                .map(|p| manifest.resolve(p))
                .collect(),
        );
        inputs.response = camera.response.as_ref().map(|p| manifest.resolve(p));
        inputs.dark = camera.dark.as_ref().map(|p| manifest.resolve(p));
        inputs.flat = camera.flat.as_ref().map(|p| manifest.resolve(p));
        inputs.exposure_correction = camera.exposure_correction.unwrap_or_default();
        if let Some(s) = camera.saturation {
            inputs.saturation = s;
            inputs.saturation_given = true;
        }
        inputs.black_level = match camera.black_level {
            None | Some(BlackLevelSetting::Mode(AutoOrNone::Auto)) => BlackLevel::Auto,
            Some(BlackLevelSetting::Mode(AutoOrNone::None)) => BlackLevel::None,
            Some(BlackLevelSetting::One(v)) => BlackLevel::Given(vec![v]),
            Some(BlackLevelSetting::PerChannel(v)) => BlackLevel::Given(v.to_vec()),
        };
        inputs.clipped_fill = ClippedFill::LowerBound;
        inputs
    }

    /// Every input file named (for "is this output one of the inputs?" checks), frames listed in
    /// the exposures CSV included.
    ///
    /// # Errors
    /// [`PipelineError::Bracket`](crate::PipelineError::Bracket) when the exposures CSV cannot be read.
    pub fn input_files(&self) -> Result<Vec<PathBuf>> {
        let mut v = self.images.clone();
        v.extend(self.exposures.clone());
        v.extend(self.response.clone());
        v.extend(self.dark.clone());
        v.extend(self.flat.clone());
        if let Some(csv) = &self.exposures {
            v.extend(
                scatterfit_io::bracket::read_exposures_csv(csv)?
                    .into_iter()
                    .map(|e| e.path),
            );
        }
        Ok(v)
    }
}
