//! The settings of a merge a user asks for by its flags (`scatterfit merge`): the bracket's
//! exposure times, a known response or dark frame, the response recovery's λ and sample count
//! (Debevec & Malik 1997, eqs. 3 and 6), the 16-bit saturation, the fill of pixels clipped in every
//! exposure and the 8-bit weighting — checked before any frame is read, then turned into the HDR
//! stage's [`HdrInputs`]. Also where the merge's outputs go ([`MergeSettings::check_outputs`]).

use std::path::{Path, PathBuf};

use scatterfit_imaging::{ClippedFill, Weighting};
use scatterfit_io::bracket::BracketError;
use scatterfit_io::escape::number as show;

use crate::hdr::HdrInputs;
use crate::outputs::{Format, OutputError, check_output_file};

/// What to store for a pixel-channel clipped in every exposure (it is always counted and reported).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Fill {
    /// NaN: the profile and spot finder skip it.
    Nan,
    /// The largest radiance the data prove (saturated) or 0 (dark).
    LowerBound,
}

impl From<Fill> for ClippedFill {
    fn from(f: Fill) -> Self {
        match f {
            Fill::Nan => ClippedFill::Nan,
            Fill::LowerBound => ClippedFill::LowerBound,
        }
    }
}

/// How 8-bit samples are weighted across the bracket.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum WeightingChoice {
    /// Chosen from the bracket: noise-optimal, unless the paper's hat explains the frames clearly
    /// better (processed JPEGs, phones, scanned film; BENCHMARKS.md, "Real brackets").
    Auto,
    /// Noise-aware linear-domain average (Robertson et al. 2003 / Granados et al. 2010): unbiased for
    /// dim pixels (BENCHMARKS.md, "dim pixels").
    NoiseOptimal,
    /// The paper's hat on ln E (Debevec & Malik 1997, eq. 6), as OpenCV's MergeDebevec.
    DebevecHat,
}

/// A merge's settings besides its frames and outputs (`scatterfit merge`'s flags).
#[derive(Debug, Clone)]
#[cfg_attr(feature = "clap", derive(clap::Args))]
pub struct MergeSettings {
    /// Exposure times: a CSV with header `file,time_s` (paths relative to the CSV's folder; times in
    /// seconds, `0.01` or `1/100`). Without it, times come from each file's EXIF ExposureTime.
    #[cfg_attr(feature = "clap", arg(long, value_name = "CSV"))]
    pub exposures: Option<PathBuf>,
    /// A known camera response (CSV `z,g_r,g_g,g_b`, as written by --response-out) instead of
    /// recovering one. 8-bit frames only.
    #[cfg_attr(feature = "clap", arg(long, value_name = "CSV"))]
    pub response: Option<PathBuf>,
    /// A dark frame (lens capped, same settings), subtracted before merging.
    #[cfg_attr(feature = "clap", arg(long, value_name = "IMAGE"))]
    pub dark: Option<PathBuf>,
    /// Smoothness weight λ of the response recovery (Debevec & Malik 1997, eq. 3), in [0, 10⁶]
    /// (dimensionless; OpenCV's default 10).
    #[cfg_attr(feature = "clap", arg(long, default_value_t = 10.0, value_parser = scatterfit_io::flags::parse_finite))]
    pub lambda: f64,
    /// Sample pixels per channel for the response recovery: a count from ⌈256/(P − 1)⌉ for P frames
    /// (22 for 13; Debevec & Malik's N(P − 1) ≥ 256, fewer leave the curve undetermined) to 1000
    /// (more only cost time: the solve grows as N·P). Default 100, or that minimum when larger.
    #[cfg_attr(feature = "clap", arg(long, value_parser = scatterfit_io::flags::parse_size))]
    pub samples: Option<usize>,
    /// 16-bit frames: raw value at and above which a sample counts as saturated, 2 to 65535.
    #[cfg_attr(feature = "clap", arg(long, default_value_t = u16::MAX, value_parser = clap::value_parser!(u16).range(2..)))]
    pub saturation: u16,
    /// Value stored for pixels clipped in every exposure.
    #[cfg_attr(feature = "clap", arg(long, value_enum, default_value_t = Fill::Nan))]
    pub clipped_fill: Fill,
    /// Sample weighting of 8-bit brackets.
    #[cfg_attr(feature = "clap", arg(long, value_enum, default_value_t = WeightingChoice::Auto))]
    pub weighting: WeightingChoice,
}

/// Why a merge's settings or outputs are refused before any work.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum MergeSettingsError {
    /// A number out of its range: the flag, the value and the rule.
    #[error("{flag} {value}: {rule}")]
    Range {
        /// The flag.
        flag: &'static str,
        /// The value given, as shown in messages.
        value: String,
        /// The valid range and why.
        rule: String,
    },
    /// The exposures CSV cannot be read.
    #[error(transparent)]
    Exposures(#[from] BracketError),
    /// `--response-out` and `-o` name one file.
    #[error("--response-out and -o are the same file {}; choose two files", .0.display())]
    SameOutputs(PathBuf),
    /// An output refused.
    #[error(transparent)]
    Output(#[from] OutputError),
}

/// Where a merge writes, checked ([`MergeSettings::check_outputs`]).
#[derive(Debug, Clone)]
pub struct MergeOutputs {
    /// The camera response's CSV.
    pub response_out: PathBuf,
    /// Whether the response is written: it is recovered, or `--response-out` was given.
    pub writes_response: bool,
}

/// The response CSV beside a radiance map: `<name>.response.csv`.
pub fn default_response_out(output: &Path) -> PathBuf {
    let stem = output
        .file_stem()
        .map_or_else(|| "radiance".into(), |s| s.to_string_lossy().into_owned());
    output.with_file_name(format!("{stem}.response.csv"))
}

impl MergeSettings {
    /// Checks every number before any file is read: λ and the sample count (its lower bound
    /// follows from the number of `frames`, Debevec & Malik's N(P − 1) ≥ 256).
    ///
    /// # Errors
    /// [`MergeSettingsError::Range`], naming the flag.
    pub fn check_numbers(&self, frames: usize) -> Result<(), MergeSettingsError> {
        if !(0.0..=1e6).contains(&self.lambda) {
            return Err(MergeSettingsError::Range {
                flag: "--lambda",
                value: show(self.lambda),
                rule: "the smoothness weight must lie in [0, 1e6] (Debevec & Malik 1997, eq. 3; \
                       default 10)"
                    .into(),
            });
        }
        let Some(samples) = self.samples else {
            return Ok(());
        };
        let min = scatterfit_imaging::min_response_samples(frames.max(2));
        let max = scatterfit_imaging::MAX_RESPONSE_SAMPLES;
        if (min..=max).contains(&samples) {
            return Ok(());
        }
        Err(MergeSettingsError::Range {
            flag: "--samples",
            value: show(samples as f64),
            rule: format!(
                "the response recovery takes {min} to {max} sample pixels per channel for {frames} \
                 frames: with N samples and P frames Debevec & Malik's N(P − 1) ≥ 256 must hold, or \
                 the curve is undetermined; more than {max} only cost time"
            ),
        })
    }

    /// Checks the settings and the outputs before any frame is read: the numbers (unless a known
    /// response is given), then `output` (`.exr` or `.hdr`) and the response CSV (`response_out`,
    /// else [`default_response_out`]; when it is written) — neither an input (the `images`, the
    /// CSVs, the dark frame, the frames the exposures CSV lists), nor the same file, nor an
    /// existing file unless `force`.
    ///
    /// # Errors
    /// The first problem.
    pub fn check_outputs(
        &self,
        images: &[PathBuf],
        output: &Path,
        response_out: Option<&Path>,
        force: bool,
    ) -> Result<MergeOutputs, MergeSettingsError> {
        let mut inputs: Vec<&Path> = images.iter().map(PathBuf::as_path).collect();
        inputs.extend(self.exposures.as_deref());
        inputs.extend(self.response.as_deref());
        inputs.extend(self.dark.as_deref());
        // Frame paths listed in the CSV are inputs too.
        let listed = match &self.exposures {
            Some(csv) => scatterfit_io::bracket::read_exposures_csv(csv)?,
            None => Vec::new(),
        };
        inputs.extend(listed.iter().map(|e| e.path.as_path()));
        let frames = if images.is_empty() {
            listed.len()
        } else {
            images.len()
        };
        if self.response.is_none() {
            self.check_numbers(frames)?;
        }
        let map = Format {
            extensions: &["exr", "hdr"],
            what: "the radiance map is written as OpenEXR or Radiance HDR",
        };
        check_output_file(output, "-o", map, &inputs, force)?;
        let given = response_out.is_some();
        let response_out =
            response_out.map_or_else(|| default_response_out(output), Path::to_path_buf);
        let identity = scatterfit_io::inputs::identity;
        if identity(&response_out) == identity(output) {
            return Err(MergeSettingsError::SameOutputs(output.to_path_buf()));
        }
        let writes_response = self.response.is_none() || given;
        if writes_response {
            let csv = Format {
                extensions: &["csv"],
                what: "the camera response is written as CSV",
            };
            check_output_file(&response_out, "--response-out", csv, &inputs, force)?;
        }
        Ok(MergeOutputs {
            response_out,
            writes_response,
        })
    }

    /// The HDR stage's inputs for `images` and these settings, with the memory budget \[bytes\]
    /// (the sample count is set once the frames are counted).
    pub fn hdr_inputs(&self, images: Vec<PathBuf>, budget: u64) -> HdrInputs {
        let mut inputs = HdrInputs::new(self.exposures.clone(), images);
        inputs.response.clone_from(&self.response);
        inputs.dark.clone_from(&self.dark);
        inputs.lambda = self.lambda;
        inputs.saturation = self.saturation;
        inputs.clipped_fill = self.clipped_fill.into();
        inputs.weighting_auto = self.weighting == WeightingChoice::Auto;
        inputs.weighting = match self.weighting {
            WeightingChoice::Auto | WeightingChoice::NoiseOptimal => Weighting::NoiseOptimal,
            WeightingChoice::DebevecHat => Weighting::DebevecHat,
        };
        inputs.memory_budget = Some(budget);
        inputs
    }
}
