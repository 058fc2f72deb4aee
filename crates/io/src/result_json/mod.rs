//! `result.json`: what `scatterfit measure` writes for one sample, and what `render` and `export`
//! read back.
//!
//! The shape follows ARCHITECTURE.md ("The measurement, as files"); the names listed there are stable,
//! the others may grow. Units: mm⁻¹ for coefficients, seconds for times. Channels are keyed `"r"`,
//! `"g"`, `"b"` (linear sRGB). A channel whose fit failed keeps its row with `status = "failed"`, the
//! reason in `problem` and `null` for the values it could not give. Each measured value is one record
//! ([`Estimate`]: the value, its uncertainty terms and their total); a file of an earlier schema is
//! brought to this one when read ([`SCHEMA_VERSION`]).
//!
//! ```json
//! { "schema_version": 2, "name": "pink plastic", "eta": 1.2886, "eta_source": "spectro",
//!   "method": "proposed", "model": "mc", "albedo_model": "mc",
//!   "channels": { "r": { "status": "ok",
//!                        "sigma_s_prime": { "value": 1.979, "fit": 0.004, "spectro": 0.004,
//!                                           "g": 0.0, "model": null, "total": 0.0057 },
//!                        "sigma_a": { "value": 0.000792, "fit": 0.00002, … },
//!                        "albedo_prime": { "value": 0.9996, "spectro": 0.00005, … },
//!                        "rd_total": 0.87, "fit_time_s": 1.2e-5, "iterations": 9, "mse": 0.8, … },
//!                 "g": { … }, "b": { … } },
//!   "inputs": { "profile": "profile.csv", "mm_per_pixel": 0.05, "spot_radius_mm": 0.5, … },
//!   "version": "0.1.0" }
//! ```

use std::fmt;
use std::path::{Path, PathBuf};
use std::str::FromStr;

use scatterfit_optics::{AlbedoModel, Channel, Estimate, Method, ModelName, OpticsError, Rgb};
use serde::{Deserialize, Deserializer, Serialize, Serializer};

mod names;

use names::lenient;
pub use names::{AlbedoSource, EtaSource, ResponseKind};

mod camera;
mod records;
mod schema;

pub use camera::{BackgroundLevel, CameraCorrections, CameraRecord, ExposureRecord};
pub use records::{GFitRecord, GSource, GUncertainty, PortResult, RdSpectrum};
pub use schema::SCHEMA_VERSION;

/// What can go wrong reading or writing a result file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ResultJsonError {
    /// The file could not be read.
    #[error("cannot read {}: {source}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// The file could not be written (an existing file is left untouched).
    #[error("cannot write {}: {source}", path.display())]
    Write {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// The file is not text we read (UTF-16 without BOM, binary data, too large).
    #[error(transparent)]
    Text(crate::text::TextError),
    /// The file is not a scatterfit result, or a field is missing or out of range.
    #[error("{}: {detail}", path.display())]
    Invalid {
        /// The file.
        path: PathBuf,
        /// What was wrong, naming the field, and what to do.
        detail: String,
    },
    /// The result names a forward model scatterfit does not know (a newer scatterfit's, or another
    /// program's). Read it with [`read_result_json_assuming`] to take one of ours instead (`render
    /// --model`).
    #[error(
        "{}: `model` = {}: not a forward model scatterfit knows ({})",
        path.display(),
        crate::escape::token(found),
        ModelName::ALL.map(ModelName::name).join(", ")
    )]
    UnknownModel {
        /// The file.
        path: PathBuf,
        /// The model it names (trimmed; escape it before showing it: `escape::token`).
        found: String,
    },
}

/// How one channel's measurement ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
#[non_exhaustive]
pub enum ChannelStatus {
    /// Parameters found and constrained by the data.
    Ok,
    /// The fit ran, but the data do not constrain every parameter (see `unconstrained`): the
    /// values are the solver's end point, not measurements.
    Unconstrained,
    /// No parameters (see `problem`).
    Failed,
}

impl ChannelStatus {
    /// The name in files and tables: `ok`, `unconstrained`, `failed`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Ok => "ok",
            Self::Unconstrained => "unconstrained",
            Self::Failed => "failed",
        }
    }
}

/// The correlation matrix of a channel's fitted parameters (from the Jacobian at the solution).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Correlation {
    /// The parameters in matrix order, e.g. `["sigma_s_prime", "scale"]`.
    pub parameters: Vec<scatterfit_optics::Parameter>,
    /// Row-major correlation coefficients, `parameters.len()` rows.
    pub matrix: Vec<Vec<f64>>,
}

/// One colour channel of a result.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ChannelResult {
    /// How the measurement of this channel ended.
    pub status: ChannelStatus,
    /// Reduced scattering coefficient σ′s \[mm⁻¹\] with its uncertainty terms, each in mm⁻¹:
    /// `fit` (the profile's noise), `spectro` (the reading's η and α′ at its repeatability,
    /// propagated through refits), `g` (how far the g-aware estimate moves over the stated range of
    /// g; 0 when g was given) and `model` (an approximate model's distance to exact transport on
    /// the same data), and their `total` ([`Estimate::total`]). `None` when the channel has no value.
    pub sigma_s_prime: Option<Estimate>,
    /// Absorption coefficient σa \[mm⁻¹\] with its uncertainty terms, as `sigma_s_prime`.
    pub sigma_a: Option<Estimate>,
    /// Reduced albedo α′ = σ′s/(σ′s + σa) with its uncertainty terms: from the spectrophotometer
    /// (proposed method: `spectro` is the reading's repeatability; behind a spectrophotometer port
    /// `fit` is the part through the port's reading fraction, which depends on the fitted σ′s) or
    /// from the fitted coefficients (existing method).
    pub albedo_prime: Option<Estimate>,
    /// Total diffuse reflectance Rd of the channel from the spectrophotometer (linear sRGB of SCE).
    pub rd_total: Option<f64>,
    /// The profile's fitted (or spectro-normalised) scale k: measured = k · model [relative units
    /// per mm⁻²].
    #[serde(default)]
    pub scale: Option<f64>,
    /// Correlations of the fitted parameters.
    #[serde(default)]
    pub correlation: Option<Correlation>,
    /// Parameters the data do not constrain (empty when every parameter is measured).
    #[serde(default)]
    pub unconstrained: Vec<scatterfit_optics::Parameter>,
    /// Wall time of the fit \[s\].
    #[serde(default)]
    pub fit_time_s: f64,
    /// Levenberg–Marquardt iterations (residual evaluations).
    #[serde(default)]
    pub iterations: usize,
    /// Why the solver stopped (`not_run` for a channel without a fit).
    #[serde(default)]
    pub termination: scatterfit_optics::Termination,
    /// Mean squared difference between the measured profile (in absolute units, divided by the
    /// scale) and the model over the fitted rings [mm⁻⁴] (Choi et al. 2014, Table 2's quantity).
    pub mse: Option<f64>,
    /// Root mean square of ln(measured / model) over the fitted rings (dimensionless; comparable
    /// between samples).
    #[serde(default)]
    pub rms_log_residual: Option<f64>,
    /// The same over the fitted rings' pixels (each ring weighted by the pixels it averages): the
    /// number the fit-quality check judges, so a ring of one corner pixel counts once, not like a
    /// ring of hundreds. Absent in files written before it was recorded.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pixel_rms_log_residual: Option<f64>,
    /// χ² per degree of freedom of the weighted log residuals (1 when the model fits to the noise).
    #[serde(default)]
    pub chi2_reduced: Option<f64>,
    /// Rings the fit used.
    #[serde(default)]
    pub rings_used: usize,
    /// Rings excluded because they lie inside the light spot.
    #[serde(default)]
    pub rings_inside_spot: usize,
    /// Rings excluded because their signal is below what the bracket can detect.
    #[serde(default)]
    pub rings_below_detection: usize,
    /// Rings excluded for having no valid pixel (clipped everywhere, outside the image).
    #[serde(default)]
    pub rings_invalid: usize,
    /// Why the channel failed or what to watch out for.
    #[serde(default)]
    pub problem: Option<String>,
    /// The data checks' verdict on the channel (`crate::quality`); `None` in files written before
    /// the checks, or where no check ran.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub quality: Option<crate::quality::Quality>,
}

/// The three channels, keyed `"r"`, `"g"`, `"b"` in the file.
pub type Channels = Rgb<ChannelResult>;

/// A file the result was made from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FileRef {
    /// The path as given (relative paths are relative to the sample folder).
    pub path: String,
    /// SHA-256 of the file's bytes, lower-case hex.
    pub sha256: String,
}

/// Provenance: the files and options a result was made from.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct Inputs {
    /// The sample folder.
    pub sample_dir: String,
    /// The manifest (`sample.toml`).
    pub manifest: Option<FileRef>,
    /// The spectrophotometer reading.
    pub spectro: Option<FileRef>,
    /// The exposure bracket's frames.
    pub frames: Vec<FileRef>,
    /// An already merged radiance map, when the manifest gave one.
    pub hdr: Option<FileRef>,
    /// The radial profile the fit used, relative to the result file's folder (written beside it).
    pub profile: Option<String>,
    /// Image scale on the sample [mm per pixel].
    pub mm_per_pixel: Option<f64>,
    /// Radius of the light spot the model was convolved with \[mm\].
    pub spot_radius_mm: Option<f64>,
    /// Spot centre [x, y] in pixels.
    pub center_px: Option<[f64; 2]>,
    /// The options the result was made with (method, model, ring limits…), as resolved.
    #[serde(deserialize_with = "lenient_options")]
    pub options: RunOptions,
}

/// The options a result was made with (`inputs.options`), as resolved from the manifest and the
/// command line. Provenance: a key that does not apply is left out of the file.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default)]
// Fields in the file's key order (alphabetical, as the untyped map wrote them).
pub struct RunOptions {
    /// How α′ came from the spectrophotometer's Rd.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub albedo_model: Option<AlbedoModel>,
    /// What the HDR and profile stages found and corrected of a real camera (black level,
    /// exposure times, flat frame, frames without signal, the level under the profile); `None`
    /// in a file without it, or with a record this reader does not know.
    #[serde(
        skip_serializing_if = "Option::is_none",
        deserialize_with = "camera::lenient_camera"
    )]
    pub camera: Option<CameraRecord>,
    /// The bracket's detection limit per channel (R, G, B) [relative radiance]; `null` where
    /// unknown.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub detection_limit: Option<Vec<Option<f64>>>,
    /// The Henyey–Greenstein g the model and the α′ inversion were evaluated at (`[fit] g`; 0:
    /// isotropic scattering assumed).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub g: Option<f64>,
    /// The fitting method.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub method: Option<Method>,
    /// The forward model.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub model: Option<ModelName>,
    /// Whether the profile's scale was fixed by the spectrophotometer.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub normalise_with_spectro: Option<bool>,
    /// Outermost ring \[px\].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub r_max_px: Option<f64>,
    /// Innermost fitted radius \[mm\].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub r_min_mm: Option<f64>,
    /// How the bracket became radiance.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub response: Option<ResponseKind>,
    /// Radius of the light spot \[mm\].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub spot_radius_mm: Option<f64>,
}

/// `inputs.options` of a file: provenance no consumer relies on, so a map of another shape (a
/// foreign writer's) reads as no options rather than refusing the result.
fn lenient_options<'de, D: Deserializer<'de>>(d: D) -> Result<RunOptions, D::Error> {
    let value = serde_json::Value::deserialize(d)?;
    Ok(serde_json::from_value(value).unwrap_or_default())
}

/// A whole result file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MeasurementResult {
    /// The file's schema version ([`SCHEMA_VERSION`] when written by this scatterfit; earlier
    /// files are brought to it when read).
    #[serde(default = "current_schema")]
    pub schema_version: u32,
    /// The sample's name.
    pub name: String,
    /// Relative refractive index η used by the fit.
    pub eta: f64,
    /// Where η came from: `spectro` (SCI − SCE) or `given`; `None` in a file without the key.
    #[serde(default, deserialize_with = "lenient::optional")]
    pub eta_source: Option<EtaSource>,
    /// Standard error of η from the reading's repeatability (`None` when η was given).
    #[serde(default)]
    pub eta_stderr: Option<f64>,
    /// The spectrophotometer's relative repeatability the uncertainties assume.
    #[serde(default)]
    pub spectro_repeatability: Option<f64>,
    /// `proposed` or `existing`.
    #[serde(deserialize_with = "lenient::name")]
    pub method: Method,
    /// The forward model of the profile fit, e.g. `dipole`. A file naming a model scatterfit does
    /// not know is refused by [`read_result_json`] ([`ResultJsonError::UnknownModel`]) unless read
    /// with [`read_result_json_assuming`].
    #[serde(deserialize_with = "lenient::name")]
    pub model: ModelName,
    /// How α′ was obtained, e.g. `diffusion`; `None` in a file without the key.
    #[serde(default, deserialize_with = "lenient::optional")]
    pub albedo_model: Option<AlbedoSource>,
    /// Per-channel results.
    pub channels: Channels,
    /// Provenance.
    #[serde(default)]
    pub inputs: Inputs,
    /// The scatterfit version that wrote the file.
    pub version: String,
    /// The spectrophotometer's diffuse reflectance spectrum (its SCE reading), which the channels'
    /// `rd_total` were integrated from: what spectral renderers need to reproduce the colour
    /// (`scatterfit export` writes it into pbrt's reflectance). Absent when the colour came from
    /// L*a*b* or the result predates the field; never written when absent. With a port
    /// correction (`spectro_port`) the spectrum is corrected like the channels (the pipeline's
    /// `port::correct_spectrum`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rd_spectrum: Option<RdSpectrum>,
    /// The spectrophotometer port's edge-loss correction (`spectro.aperture_mm` in the
    /// manifest): the channels' `rd_total` and `albedo_prime` are then the corrected values. Absent:
    /// the reading was taken as loss-free (no port given). Never written when absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spectro_port: Option<PortResult>,
    /// How the anisotropy g entered the result: given, or a range propagated into the
    /// channels' `*_stderr_g` terms, with the g that were evaluated. Absent in files written before
    /// the term (and by commands that fit no sample); never written when absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub g_uncertainty: Option<GUncertainty>,
}

impl MeasurementResult {
    /// The channels whose data checks did not say ok, and why, on one line (`R suspect: …; B
    /// failed: …`); `None` when every channel is ok (or the result predates the checks). What
    /// every command that reads a result (`export`, `render`, `compare`) warns with.
    pub fn untrusted(&self) -> Option<String> {
        let parts: Vec<String> = self
            .channels
            .iter_channels()
            .filter_map(|(ch, c)| {
                let q = c.quality.as_ref()?;
                (q.verdict != crate::quality::Verdict::Ok).then(|| {
                    format!(
                        "{} {}: {}",
                        ch.name(),
                        q.verdict.name(),
                        crate::escape::one_line(&q.summary())
                    )
                })
            })
            .collect();
        (!parts.is_empty()).then(|| parts.join("; "))
    }

    /// (σ′s, σa) per channel when every channel has both, else the first channel (R, G, B order)
    /// without.
    ///
    /// # Errors
    /// The channel lacking a value.
    pub fn coefficients(&self) -> Result<Rgb<(f64, f64)>, Channel> {
        self.channels
            .as_ref()
            .map_with_channel(|ch, c| match (c.sigma_s_prime, c.sigma_a) {
                (Some(s), Some(a)) => Ok((s.value, a.value)),
                _ => Err(ch),
            })
            .transpose()
    }

    /// The forward model the parameters were fitted with (what `render` renders them with).
    pub fn model(&self) -> ModelName {
        self.model
    }

    /// η with the spectrophotometer's standard error (`eta_stderr`; none when η was given).
    pub fn eta_estimate(&self) -> Estimate {
        Estimate {
            value: self.eta,
            fit: None,
            spectro: self.eta_stderr,
            g: None,
            model: None,
        }
    }
}

fn current_schema() -> u32 {
    SCHEMA_VERSION
}

/// Writes a result atomically as pretty JSON.
///
/// # Errors
/// [`ResultJsonError::Write`].
pub fn write_result_json(path: &Path, result: &MeasurementResult) -> Result<(), ResultJsonError> {
    let mut text = serde_json::to_string_pretty(result).map_err(|e| ResultJsonError::Invalid {
        path: path.to_path_buf(),
        detail: format!("cannot serialise the result: {e}"),
    })?;
    text.push('\n');
    crate::atomic::write_atomic(path, text.as_bytes()).map_err(|source| ResultJsonError::Write {
        path: path.to_path_buf(),
        source,
    })
}

/// Reads a result file and checks what a consumer relies on: η ≥ 1, and every coefficient that is
/// present finite and ≥ 0 (σ′s > 0).
///
/// # Errors
/// [`ResultJsonError`] naming the file and the field.
pub fn read_result_json(path: &Path) -> Result<MeasurementResult, ResultJsonError> {
    let text = crate::text::read_text_file(path).map_err(text_error)?;
    parse_result_json(&text.text, path)
}

/// [`read_result_json`], taking `model` as the result's forward model when the file names one
/// scatterfit does not know (`render --model`); a known model is read as written.
///
/// # Errors
/// As [`read_result_json`], without [`ResultJsonError::UnknownModel`].
pub fn read_result_json_assuming(
    path: &Path,
    model: ModelName,
) -> Result<MeasurementResult, ResultJsonError> {
    let text = crate::text::read_text_file(path).map_err(text_error)?;
    parse_result(&text.text, path, Some(model))
}

/// [`read_result_json`] on the bytes of a file (UTF-8 with or without BOM, UTF-16 with BOM).
///
/// # Errors
/// As [`read_result_json`].
pub fn parse_result_json_bytes(
    bytes: &[u8],
    path: &Path,
) -> Result<MeasurementResult, ResultJsonError> {
    let text = crate::text::decode_text(bytes, path).map_err(text_error)?;
    parse_result_json(&text.text, path)
}

fn text_error(e: crate::text::TextError) -> ResultJsonError {
    match e {
        crate::text::TextError::Io { path, source } => ResultJsonError::Read { path, source },
        other => ResultJsonError::Text(other),
    }
}

/// What a JSON syntax error is, without its position (given separately) and without content.
fn classify_json(e: &serde_json::Error) -> String {
    let text = e.to_string();
    match text.rfind(" at line ") {
        Some(i) => text[..i].to_string(),
        None => text,
    }
}

/// [`read_result_json`] on text already read; `path` names it in errors.
///
/// # Errors
/// As [`read_result_json`].
pub fn parse_result_json(text: &str, path: &Path) -> Result<MeasurementResult, ResultJsonError> {
    parse_result(text, path, None)
}

fn parse_result(
    text: &str,
    path: &Path,
    assume_model: Option<ModelName>,
) -> Result<MeasurementResult, ResultJsonError> {
    let invalid = |detail: String| ResultJsonError::Invalid {
        path: path.to_path_buf(),
        detail,
    };
    // The content rule (RELIABILITY.md, "Inputs"): until the file is recognised as a result (JSON
    // whose top level is an object with `channels`), a message shows nothing of its content.
    const EXPECTED: &str = "expected the JSON that `scatterfit measure` writes (name, eta, method, \
                            model, channels.r/g/b)";
    let value: serde_json::Value = serde_json::from_str(text).map_err(|e| {
        invalid(format!(
            "not a scatterfit result: not valid JSON at line {}, column {} ({}); the file's \
             content is not shown; {EXPECTED}",
            e.line(),
            e.column(),
            crate::escape::redact_quotes(&classify_json(&e), |_| false)
        ))
    })?;
    if value.get("channels").is_none() {
        return Err(invalid(format!(
            "not a scatterfit result: no `channels` at the top level; the file's content is not \
             shown; {EXPECTED}"
        )));
    }
    let shape = |e: serde_json::Error| {
        invalid(format!(
            "not a scatterfit result ({}); {EXPECTED}",
            crate::escape::shorten_quotes(&e.to_string())
        ))
    };
    // A model we do not know is the caller's to decide (render asks for --model), not a malformed
    // file: checked before the typed read.
    let unknown_model = value
        .get("model")
        .and_then(serde_json::Value::as_str)
        .filter(|m| lenient::model(m).is_none())
        .map(|m| m.trim().to_string());
    let mut value = value;
    match (unknown_model, assume_model) {
        (None, _) => {}
        (Some(found), None) => {
            return Err(ResultJsonError::UnknownModel {
                path: path.to_path_buf(),
                found,
            });
        }
        (Some(_), Some(model)) => value["model"] = serde_json::Value::from(model.name()),
    }
    if let serde_json::Value::Object(file) = &mut value {
        schema::upgrade(file).map_err(invalid)?;
    }
    let result: MeasurementResult = serde_json::from_value(value).map_err(shape)?;
    if !(result.eta.is_finite() && result.eta >= 1.0) {
        return Err(invalid(format!(
            "`eta` = {} must be a number ≥ 1 (relative refractive index)",
            crate::escape::number(result.eta)
        )));
    }
    for (ch, c) in result.channels.iter_channels() {
        let name = ch.key();
        for (field, e) in [("sigma_s_prime", c.sigma_s_prime), ("sigma_a", c.sigma_a)] {
            let Some(e) = e else { continue };
            let parts = [
                ("value", Some(e.value)),
                ("fit", e.fit),
                ("spectro", e.spectro),
                ("g", e.g),
                ("model", e.model),
            ];
            for (part, v) in parts {
                if let Some(v) = v
                    && !(v.is_finite() && v >= 0.0)
                {
                    return Err(invalid(format!(
                        "`channels.{name}.{field}.{part}` = {} must be a finite number ≥ 0 [mm⁻¹]",
                        crate::escape::number(v)
                    )));
                }
            }
        }
        if c.sigma_s_prime.is_some_and(|e| e.value == 0.0) {
            return Err(invalid(format!(
                "`channels.{name}.sigma_s_prime.value` = 0: a scattering material needs σ′s > 0"
            )));
        }
        if let Some(a) = c.albedo_prime.map(|e| e.value)
            && !(a.is_finite() && a > 0.0 && a <= 1.0)
        {
            return Err(invalid(format!(
                "`channels.{name}.albedo_prime.value` = {} must lie in (0, 1]",
                crate::escape::number(a)
            )));
        }
    }
    Ok(result)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// An ok channel of σ′s `sp` and σa `sa` with fit terms (the fixture of this module's tests
    /// and of the exports').
    pub(crate) fn channel(sp: f64, sa: f64) -> ChannelResult {
        ChannelResult {
            status: ChannelStatus::Ok,
            sigma_s_prime: Some(scatterfit_optics::Estimate {
                value: sp,
                fit: Some(0.01),
                spectro: None,
                g: None,
                model: None,
            }),
            sigma_a: Some(scatterfit_optics::Estimate {
                value: sa,
                fit: Some(0.001),
                spectro: None,
                g: None,
                model: None,
            }),
            albedo_prime: Some(scatterfit_optics::Estimate {
                value: sp / (sp + sa),
                fit: None,
                spectro: None,
                g: None,
                model: None,
            }),
            rd_total: Some(0.5),
            scale: Some(2.0),
            correlation: None,
            unconstrained: vec![],
            fit_time_s: 1e-5,
            iterations: 7,
            termination: scatterfit_optics::Termination::ConvergedResidual,
            mse: Some(1e-6),
            rms_log_residual: Some(0.01),
            pixel_rms_log_residual: Some(0.01),
            chi2_reduced: Some(1.1),
            rings_used: 250,
            rings_inside_spot: 10,
            rings_below_detection: 40,
            rings_invalid: 0,
            problem: None,
            quality: None,
        }
    }

    fn result() -> MeasurementResult {
        MeasurementResult {
            schema_version: SCHEMA_VERSION,
            name: "pink plastic".into(),
            eta: 1.2886,
            eta_source: Some(EtaSource::Spectro),
            eta_stderr: None,
            spectro_repeatability: None,
            method: Method::Proposed,
            model: ModelName::Dipole,
            albedo_model: Some(AlbedoSource::Model(AlbedoModel::Diffusion)),
            channels: Channels::from_array([
                channel(1.979, 0.000792),
                channel(1.893, 0.0496),
                channel(1.992, 0.0227),
            ]),
            inputs: Inputs::default(),
            version: "0.1.0".into(),
            rd_spectrum: None,
            spectro_port: None,
            g_uncertainty: None,
        }
    }

    #[test]
    fn round_trip_and_coefficients() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("result.json");
        let r = result();
        write_result_json(&path, &r).unwrap();
        let back = read_result_json(&path).unwrap();
        assert_eq!(back, r);
        assert_eq!(back.coefficients().unwrap().g, (1.893, 0.0496));
        // Without a spectrum the file has no `rd_spectrum` key (files stay as they were); with one
        // it round-trips.
        assert!(
            !std::fs::read_to_string(&path)
                .unwrap()
                .contains("rd_spectrum")
        );
        let mut r = result();
        r.rd_spectrum = Some(RdSpectrum {
            wavelength_nm: vec![400.0, 410.0],
            rd: vec![0.5, 0.25],
        });
        write_result_json(&path, &r).unwrap();
        assert_eq!(read_result_json(&path).unwrap(), r);
    }

    /// The meanings are enums in code and today's strings in the file: every name, in every
    /// place, written as the untyped writer wrote it (options in its alphabetical key order, NaN
    /// detection limits as null) and read back to the same value.
    #[test]
    fn names_are_the_files_strings() {
        let mut r = result();
        r.method = Method::Existing;
        r.model = ModelName::BetterDipole;
        r.eta_source = Some(EtaSource::Given);
        r.albedo_model = Some(AlbedoSource::Given);
        r.inputs.options = RunOptions {
            method: Some(Method::Existing),
            model: Some(ModelName::BetterDipole),
            albedo_model: Some(AlbedoModel::Mc),
            camera: Some(CameraRecord {
                background: vec![BackgroundLevel {
                    level: 0.5,
                    relative_to_peak: 1e-4,
                    stderr: 0.01,
                    subtracted: true,
                }],
                corrections: CameraCorrections {
                    exposure_applied: true,
                    ..CameraCorrections::default()
                },
            }),
            normalise_with_spectro: Some(false),
            r_min_mm: Some(1.0),
            r_max_px: Some(300.0),
            spot_radius_mm: Some(0.5),
            response: Some(ResponseKind::Recovered),
            detection_limit: Some(vec![Some(0.25), None, Some(1.0)]),
            g: Some(0.85),
        };
        let v = serde_json::to_value(&r).unwrap();
        assert_eq!(v["method"], "existing");
        assert_eq!(v["model"], "better-dipole");
        assert_eq!(v["eta_source"], "given");
        assert_eq!(v["albedo_model"], "given");
        let options = serde_json::to_string(&r.inputs.options).unwrap();
        assert_eq!(
            options,
            r#"{"albedo_model":"mc","camera":{"background":[{"level":0.5,"relative_to_peak":0.0001,"stderr":0.01,"subtracted":true}],"corrections":{"black_level":null,"exposure":null,"exposure_applied":true,"flat":null}},"detection_limit":[0.25,null,1.0],"g":0.85,"method":"existing","model":"better-dipole","normalise_with_spectro":false,"r_max_px":300.0,"r_min_mm":1.0,"response":"recovered","spot_radius_mm":0.5}"#
        );
        let back = parse_result_json(&v.to_string(), Path::new("r.json")).unwrap();
        assert_eq!(back, r);
        for kind in ResponseKind::ALL {
            assert_eq!(kind.to_string().parse::<ResponseKind>().unwrap(), kind);
        }
        for source in [
            AlbedoSource::Given,
            AlbedoSource::Model(AlbedoModel::Diffusion),
            AlbedoSource::Model(AlbedoModel::Mc),
        ] {
            assert_eq!(source.to_string().parse::<AlbedoSource>().unwrap(), source);
        }
        // The fit command's options: only what applies is written.
        let fit = RunOptions {
            method: Some(Method::Proposed),
            model: Some(ModelName::Dipole),
            normalise_with_spectro: Some(false),
            r_min_mm: Some(1.0),
            ..RunOptions::default()
        };
        assert_eq!(
            serde_json::to_string(&fit).unwrap(),
            r#"{"method":"proposed","model":"dipole","normalise_with_spectro":false,"r_min_mm":1.0}"#
        );
    }

    /// A model scatterfit does not know is a typed error naming it (render turns it into "pass
    /// --model"), and reads with an assumed model; names are read as render always read the model
    /// (blanks and case ignored); an older file without `eta_source`/`albedo_model` (or with them
    /// empty) reads them as unknown.
    #[test]
    fn unknown_models_and_lenient_names() {
        let mut v = serde_json::to_value(result()).unwrap();
        v["model"] = serde_json::json!(" Photon-Tracer ");
        let text = v.to_string();
        match parse_result_json(&text, Path::new("r.json")) {
            Err(ResultJsonError::UnknownModel { found, .. }) => assert_eq!(found, "Photon-Tracer"),
            other => panic!("{other:?}"),
        }
        let err = parse_result_json(&text, Path::new("r.json"))
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("Photon-Tracer") && err.contains("better-dipole"),
            "{err}"
        );
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("result.json");
        std::fs::write(&path, &text).unwrap();
        let r = read_result_json_assuming(&path, ModelName::Pbd).unwrap();
        assert_eq!(r.model(), ModelName::Pbd);
        assert_eq!(r.channels, result().channels);
        // A known model is read as written, whatever is assumed.
        write_result_json(&path, &result()).unwrap();
        let r = read_result_json_assuming(&path, ModelName::Pbd).unwrap();
        assert_eq!(r.model(), ModelName::Dipole);

        let mut v = serde_json::to_value(result()).unwrap();
        v["model"] = serde_json::json!(" Better-Dipole");
        v["method"] = serde_json::json!("EXISTING ");
        v["eta_source"] = serde_json::json!("");
        v.as_object_mut().unwrap().remove("albedo_model");
        let r = parse_result_json(&v.to_string(), Path::new("r.json")).unwrap();
        assert_eq!(
            (r.model, r.method),
            (ModelName::BetterDipole, Method::Existing)
        );
        assert_eq!((r.eta_source, r.albedo_model), (None, None));
        v["method"] = serde_json::json!("guessed");
        let err = parse_result_json(&v.to_string(), Path::new("r.json"))
            .unwrap_err()
            .to_string();
        assert!(err.contains("proposed, existing"), "{err}");
    }

    /// A file written before the schema version (version 1: each value's terms as flat keys
    /// beside it; `scatterfit measure --model dipole` on the quick demo's pink plastic) reads into
    /// one record per value with its terms apart — α′'s `albedo_prime_stderr` as its
    /// spectrophotometer term — and is written back as version 2 with each record's total.
    #[test]
    fn a_version_1_file_reads_into_records() {
        let text = include_str!("../../tests/fixtures/result-v1-dipole.json");
        let flat: serde_json::Value = serde_json::from_str(text).unwrap();
        assert!(flat.get("schema_version").is_none());
        let r = parse_result_json(text, Path::new("result.json")).unwrap();
        assert_eq!(r.schema_version, SCHEMA_VERSION);
        for (ch, c) in r.channels.iter_channels() {
            let f = &flat["channels"][ch.key()];
            let num = |k: &str| f[k].as_f64();
            let record = |e: Option<Estimate>| {
                let e = e.unwrap();
                (Some(e.value), e.fit, e.spectro, e.g, e.model)
            };
            assert_eq!(
                record(c.sigma_s_prime),
                (
                    num("sigma_s_prime"),
                    num("sigma_s_prime_stderr"),
                    num("sigma_s_prime_stderr_spectro"),
                    num("sigma_s_prime_stderr_g"),
                    num("sigma_s_prime_stderr_model")
                )
            );
            assert_eq!(
                record(c.sigma_a),
                (
                    num("sigma_a"),
                    num("sigma_a_stderr"),
                    num("sigma_a_stderr_spectro"),
                    num("sigma_a_stderr_g"),
                    num("sigma_a_stderr_model")
                )
            );
            assert_eq!(
                record(c.albedo_prime),
                (
                    num("albedo_prime"),
                    num("albedo_prime_stderr_fit"),
                    num("albedo_prime_stderr"),
                    num("albedo_prime_stderr_g"),
                    num("albedo_prime_stderr_model")
                )
            );
            // Every term of the dipole's values is there: fit, spectro, g and model.
            assert!(c.sigma_a.unwrap().terms().count() == 4, "{ch:?}");
        }
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("result.json");
        write_result_json(&path, &r).unwrap();
        let written: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
        assert_eq!(written["schema_version"], serde_json::json!(SCHEMA_VERSION));
        let sa = &written["channels"]["g"]["sigma_a"];
        let total = sa["total"].as_f64().unwrap();
        let (fit, spectro, g, model) = (
            sa["fit"].as_f64().unwrap(),
            sa["spectro"].as_f64().unwrap(),
            sa["g"].as_f64().unwrap(),
            sa["model"].as_f64().unwrap(),
        );
        assert!((total - ((fit * fit + spectro * spectro).sqrt() + g + model)).abs() < 1e-15);
        assert!(written["channels"]["g"].get("sigma_a_stderr").is_none());
        assert_eq!(read_result_json(&path).unwrap(), r);
        let mut r = result();
        r.eta_stderr = Some(0.002);
        assert_eq!(r.eta_estimate().total(), Some(0.002));
    }

    /// The minimal hand-written file of ARCHITECTURE.md (only the stable names) is accepted.
    #[test]
    fn minimal_hand_written_file_reads() {
        let text = r#"{ "name": "x", "eta": 1.3, "method": "proposed", "model": "dipole",
          "channels": {
            "r": { "status": "ok", "sigma_s_prime": 1.0, "sigma_s_prime_stderr": null, "sigma_a": 0.01,
                   "sigma_a_stderr": null, "albedo_prime": 0.99, "rd_total": 0.6, "mse": null },
            "g": { "status": "ok", "sigma_s_prime": 1.0, "sigma_s_prime_stderr": null, "sigma_a": 0.02,
                   "sigma_a_stderr": null, "albedo_prime": 0.98, "rd_total": 0.5, "mse": null },
            "b": { "status": "failed", "sigma_s_prime": null, "sigma_s_prime_stderr": null, "sigma_a": null,
                   "sigma_a_stderr": null, "albedo_prime": null, "rd_total": null, "mse": null,
                   "problem": "out of gamut" } },
          "version": "0.1.0" }"#;
        let r = parse_result_json(text, Path::new("hand.json")).unwrap();
        assert_eq!(r.coefficients(), Err(Channel::B));
    }

    #[test]
    fn bad_values_are_refused_with_the_field() {
        let mut r = result();
        r.channels.g.sigma_a = Some(scatterfit_optics::Estimate {
            value: -1.0,
            ..r.channels.g.sigma_a.unwrap_or_default()
        });
        let text = serde_json::to_string(&r).unwrap();
        let err = parse_result_json(&text, Path::new("r.json"))
            .unwrap_err()
            .to_string();
        assert!(err.contains("channels.g.sigma_a"), "{err}");
        let mut r = result();
        r.eta = 0.5;
        let text = serde_json::to_string(&r).unwrap();
        assert!(
            parse_result_json(&text, Path::new("r.json"))
                .unwrap_err()
                .to_string()
                .contains("eta")
        );
        let err = parse_result_json("{}", Path::new("r.json"))
            .unwrap_err()
            .to_string();
        assert!(err.contains("not a scatterfit result"), "{err}");
    }

    /// The content rule: a file that is not a result (a secret, a JSON file of another program)
    /// is refused without a word of its content; a result's wrong value is shown shortened and
    /// with at most 6 significant digits.
    #[test]
    fn content_is_shown_only_for_a_recognised_result() {
        for text in [
            "root:$6$SECRETHASH:19000:0:99999:7:::",
            r#"{"token": "SECRETVALUE"}"#,
            r#"{"eta": "SECRETVALUE"}"#,
            r#"["SECRETVALUE"]"#,
            "\"SECRETVALUE",
        ] {
            let err = parse_result_json(text, Path::new("r.json"))
                .unwrap_err()
                .to_string();
            assert!(!err.contains("SECRET"), "{text}: {err}");
            assert!(
                err.contains("r.json") && err.contains("not a scatterfit result"),
                "{err}"
            );
        }
        let mut v = serde_json::to_value(result()).unwrap();
        v["method"] = serde_json::json!(7);
        v["name"] = serde_json::json!(format!("{}\u{1b}[2J", "n".repeat(100)));
        let err = parse_result_json(&v.to_string(), Path::new("r.json"))
            .unwrap_err()
            .to_string();
        assert!(err.contains("invalid type"), "{err}");
        let mut r = result();
        r.eta = 1e-300;
        let err = parse_result_json(&serde_json::to_string(&r).unwrap(), Path::new("r.json"))
            .unwrap_err()
            .to_string();
        assert!(err.contains("= 1e-300 "), "{err}");
    }
}
