//! The result's numbers as renderers take them: the checks on every field a result file holds
//! ([`RendererParameters::from_result`]: documented ranges, failed channels, spectra) and the
//! quantities derived per channel (σ′t, albedo, mean free path, spectral media).

use serde::{Deserialize, Serialize};

use super::*;
use crate::result_json::{ChannelStatus, MeasurementResult};
/// Channel keys as `result.json` writes them (and messages name them).
pub(super) const CHANNEL_NAMES: [&str; 3] = ["r", "g", "b"];
/// Channel labels in the files' tables.
pub(super) const CHANNEL_LABELS: [&str; 3] = ["R", "G", "B"];

/// Documented range of η (relative refractive index; the densest common dielectrics are below 3).
pub const ETA_RANGE: (f64, f64) = (1.0, 4.0);
/// Documented range of σ′s [mm⁻¹]: a mean free path between 1 nm and 1 km (outside, float32 renderers
/// lose the number, and no translucent material is there).
pub const SIGMA_S_RANGE: (f64, f64) = (1e-6, 1e6);
/// Documented range of σa [mm⁻¹].
pub const SIGMA_A_RANGE: (f64, f64) = (0.0, 1e6);
/// Documented range of a reflectance spectrum's wavelengths \[nm\].
pub const WAVELENGTH_RANGE: (f64, f64) = (300.0, 1000.0);

/// A medium given per wavelength for spectral renderers ([`RendererParameters::spectral_medium`]):
/// at the measured spectrum's wavelengths, extended to [`SPECTRAL_RANGE`] with the end values.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SpectralMedium {
    /// Wavelengths \[nm\], increasing.
    pub wavelength_nm: Vec<f64>,
    /// Single-scattering albedo σs/σt (g = 0) whose exact-transport Rd is the measured Rd(λ).
    pub albedo: Vec<f64>,
    /// Extinction σt(λ) [1/L]: the channels' σ′t interpolated linearly in wavelength between the
    /// channels' wavelengths ([`CHANNEL_WAVELENGTHS`]), constant beyond them.
    pub sigma_t: Vec<f64>,
}

/// The wavelengths \[nm\] at which the spectral medium takes each channel's σ′t (R, G, B): near the
/// dominant wavelengths of the sRGB primaries (611, 549, 464 nm, CIE 1931, D65 white).
pub const CHANNEL_WAVELENGTHS: [f64; 3] = [611.0, 549.0, 464.0];

/// The span \[nm\] spectral exports cover: renderers sample 360–830 nm, and a piecewise-linear spectrum
/// is zero outside its points in pbrt, so the measured spectrum is extended with its end values.
pub const SPECTRAL_RANGE: (f64, f64) = (360.0, 830.0);

/// One channel of [`RendererParameters`], in the scene's unit (`L` below).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ChannelParameters {
    /// `ok` or `unconstrained` (see the result file).
    pub status: ChannelStatus,
    /// Absorption coefficient σa [1/L].
    pub sigma_a: f64,
    /// Scattering coefficient σs [1/L] for the phase function's g = 0: the measured σ′s.
    pub sigma_s: f64,
    /// Extinction σt = σa + σs [1/L].
    pub sigma_t: f64,
    /// Single-scattering albedo σs/σt (with g = 0 the reduced albedo α′).
    pub albedo: f64,
    /// Mean free path 1/σt [L, the scene unit] (with g = 0 the transport mean free path 1/σ′t).
    pub mfp: f64,
    /// Effective transport coefficient σtr = √(3σaσ′t) [1/L] (Jensen et al. 2001, §2.4).
    pub sigma_tr: f64,
    /// Diffusion length 1/σtr [L, the scene unit]: how far light spreads sideways before it is
    /// absorbed; `None` for σa = 0 (no absorption, unbounded).
    pub diffusion_length: Option<f64>,
    /// Total diffuse reflectance Rd of the channel from the spectrophotometer (linear sRGB), when the
    /// result has it.
    pub rd_total: Option<f64>,
    /// The total diffuse reflectance exact transport renders from this channel's σ′s, σa and η
    /// ([`ExportOptions::exact_rd`]), when the exporter was given it.
    #[serde(default)]
    pub rd_exact_transport: Option<f64>,
}

/// The three channels of [`RendererParameters`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ParameterChannels {
    /// Red.
    pub r: ChannelParameters,
    /// Green.
    pub g: ChannelParameters,
    /// Blue.
    pub b: ChannelParameters,
}

impl ParameterChannels {
    /// The channels in R, G, B order.
    pub fn as_array(&self) -> [&ChannelParameters; 3] {
        [&self.r, &self.g, &self.b]
    }
}

/// Where the numbers came from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Provenance {
    /// `proposed` or `existing`.
    pub method: String,
    /// The forward model of the profile fit.
    pub model: String,
    /// How α′ was obtained from the spectrophotometer's Rd.
    pub albedo_model: String,
    /// Where η came from.
    pub eta_source: String,
    /// The scatterfit version that measured the result.
    pub measured_with: String,
    /// The channels the result's data checks did not pass, and why
    /// (`MeasurementResult::untrusted`): a renderer's user must know the numbers are not trusted.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub not_trusted: Option<String>,
}

/// The measured diffuse reflectance spectrum (the spectrophotometer's SCE) carried into an export:
/// the result file's own type.
pub use crate::result_json::RdSpectrum as ReflectanceSpectrum;

/// The renderer-neutral export ([`Format::Json`]): every quantity a renderer may want, per channel, in
/// the scene's unit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RendererParameters {
    /// Always [`JSON_FORMAT_TAG`].
    pub format: String,
    /// Always [`JSON_FORMAT_VERSION`].
    pub format_version: u32,
    /// The sample's name.
    pub name: String,
    /// The identifier the scene-file exports use for this material ([`MaterialNames::id`]).
    #[serde(default)]
    pub id: String,
    /// The length unit L of every coefficient (L⁻¹) and length (L).
    pub unit: SceneUnit,
    /// Relative refractive index η (material / air).
    pub eta: f64,
    /// Henyey–Greenstein asymmetry of the phase function: 0 (see `conventions`).
    pub g: f64,
    /// Per-channel parameters (linear sRGB channels).
    pub channels: ParameterChannels,
    /// The spectrophotometer's diffuse reflectance spectrum, when the result carries it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rd_spectrum: Option<ReflectanceSpectrum>,
    /// The medium per wavelength for spectral renderers, when the result has a spectrum and the
    /// caller gave its exact-transport albedos ([`ExportOptions::spectral_albedo`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spectral_medium: Option<SpectralMedium>,
    /// The measurement the numbers come from.
    pub source: Provenance,
    /// The conventions, in words, for a reader without this documentation.
    pub conventions: String,
}

/// Checks that `value` lies in `range` (inclusive) and is finite.
pub(super) fn in_range(
    field: String,
    value: f64,
    range: (f64, f64),
    unit: &str,
) -> Result<f64, ExportError> {
    if value.is_finite() && value >= range.0 && value <= range.1 {
        Ok(value)
    } else {
        Err(ExportError::OutOfRange {
            field,
            value: value.to_string(),
            range: format!("[{}, {}]{unit}", num(range.0), num(range.1)),
        })
    }
}

/// Checks the result's spectrum, if any: at least two points, wavelengths increasing within
/// [`WAVELENGTH_RANGE`], reflectances in [0, 1].
pub(super) fn checked_spectrum(
    result: &MeasurementResult,
) -> Result<Option<ReflectanceSpectrum>, ExportError> {
    let Some(s) = &result.rd_spectrum else {
        return Ok(None);
    };
    if s.wavelength_nm.len() != s.rd.len() || s.rd.len() < 2 {
        return Err(ExportError::OutOfRange {
            field: "rd_spectrum".into(),
            value: format!(
                "{} wavelengths and {} values",
                s.wavelength_nm.len(),
                s.rd.len()
            ),
            range: "(two or more wavelengths, one value each)".into(),
        });
    }
    let mut last = f64::NEG_INFINITY;
    for (k, (&wl, &rd)) in s.wavelength_nm.iter().zip(&s.rd).enumerate() {
        in_range(
            format!("rd_spectrum.wavelength_nm[{k}]"),
            wl,
            WAVELENGTH_RANGE,
            " nm",
        )?;
        if wl <= last {
            return Err(ExportError::OutOfRange {
                field: format!("rd_spectrum.wavelength_nm[{k}]"),
                value: wl.to_string(),
                range: format!("(above the previous wavelength, {last} nm)"),
            });
        }
        last = wl;
        in_range(format!("rd_spectrum.rd[{k}]"), rd, (0.0, 1.0), "")?;
    }
    Ok(Some(s.clone()))
}

impl RendererParameters {
    /// The parameters of `result` in `unit`, and warnings for channels the data do not constrain.
    ///
    /// # Errors
    /// [`ExportError::FailedChannel`] for the first channel that failed or lacks σ′s or σa;
    /// [`ExportError::OutOfRange`] for the first number outside its documented range.
    pub fn from_result(
        result: &MeasurementResult,
        unit: SceneUnit,
    ) -> Result<(Self, Vec<String>), ExportError> {
        Self::from_result_with(result, &ExportOptions::new(unit))
    }

    /// [`RendererParameters::from_result`] with the exact-transport figures of `options`.
    ///
    /// # Errors
    /// As [`RendererParameters::from_result`]; also [`ExportError::OutOfRange`] for an
    /// `exact_rd` value outside [0, 1].
    pub fn from_result_with(
        result: &MeasurementResult,
        options: &ExportOptions,
    ) -> Result<(Self, Vec<String>), ExportError> {
        let unit = options.unit;
        let mut warnings = Vec::new();
        let channels = result.channels.as_ref().into_array();
        in_range("eta".into(), result.eta, ETA_RANGE, "")?;
        let mut checked = [(0.0, 0.0, None); 3];
        for (k, (name, c)) in CHANNEL_NAMES.iter().zip(channels).enumerate() {
            let (Some(sp), Some(sa)) = (c.sigma_s_prime, c.sigma_a) else {
                return Err(ExportError::FailedChannel {
                    channel: name,
                    status: if c.status == ChannelStatus::Failed {
                        "failed"
                    } else {
                        "ok, but σ′s or σa missing"
                    },
                    problem: c.problem.clone(),
                });
            };
            if c.status == ChannelStatus::Failed {
                return Err(ExportError::FailedChannel {
                    channel: name,
                    status: "failed",
                    problem: c.problem.clone(),
                });
            }
            let field = |f: &str| format!("channels.{name}.{f}");
            let sp = in_range(field("sigma_s_prime"), sp.value, SIGMA_S_RANGE, " mm^-1")?;
            let sa = in_range(field("sigma_a"), sa.value, SIGMA_A_RANGE, " mm^-1")?;
            let rd = match c.rd_total {
                Some(rd) => Some(in_range(field("rd_total"), rd, (0.0, 1.0), "")?),
                None => None,
            };
            checked[k] = (sp, sa, rd);
            if c.status == ChannelStatus::Unconstrained {
                let what = if c.unconstrained.is_empty() {
                    "some parameters".to_string()
                } else {
                    c.unconstrained
                        .iter()
                        .map(|p| p.name())
                        .collect::<Vec<_>>()
                        .join(", ")
                };
                warnings.push(format!(
                    "channel {name} is unconstrained (the data do not constrain {what}): its values \
                     are the solver's end point, not a measurement; exported anyway"
                ));
            }
        }
        if let Some(exact) = options.exact_rd {
            for (name, v) in CHANNEL_NAMES.iter().zip(exact) {
                in_range(format!("exact_rd.{name}"), v, (0.0, 1.0), "")?;
            }
        }
        let rd_spectrum = checked_spectrum(result)?;
        let spectral_albedo = match (&rd_spectrum, &options.spectral_albedo) {
            (Some(spec), Some(a)) => {
                if a.len() != spec.rd.len() {
                    return Err(ExportError::OutOfRange {
                        field: "spectral_albedo".into(),
                        value: format!("{} values", a.len()),
                        range: format!("(one per wavelength of rd_spectrum: {})", spec.rd.len()),
                    });
                }
                for (k, &v) in a.iter().enumerate() {
                    in_range(format!("spectral_albedo[{k}]"), v, (0.0, 1.0), "")?;
                }
                Some(a.clone())
            }
            _ => None,
        };
        let k = unit.mm_per_unit();
        let channel = |j: usize| {
            let (sp, sa, rd) = checked[j];
            let (sp, sa) = (sp * k, sa * k);
            let sigma_t = sa + sp;
            // σtr = √(3σaσ′t) (Jensen et al. 2001, §2.4).
            let sigma_tr = (3.0 * sa * sigma_t).sqrt();
            ChannelParameters {
                status: channels[j].status,
                sigma_a: sa,
                sigma_s: sp,
                sigma_t,
                albedo: sp / sigma_t,
                mfp: 1.0 / sigma_t,
                sigma_tr,
                diffusion_length: (sigma_tr > 0.0).then(|| 1.0 / sigma_tr),
                rd_total: rd,
                rd_exact_transport: options.exact_rd.map(|e| e[j]),
            }
        };
        let params = Self {
            format: JSON_FORMAT_TAG.to_string(),
            format_version: JSON_FORMAT_VERSION,
            name: result.name.clone(),
            id: MaterialNames::new(&result.name).id,
            unit,
            eta: result.eta,
            g: 0.0,
            channels: ParameterChannels {
                r: channel(0),
                g: channel(1),
                b: channel(2),
            },
            spectral_medium: rd_spectrum
                .as_ref()
                .zip(spectral_albedo)
                .map(|(spec, albedo)| {
                    let sigma_t = checked.map(|(sp, sa, _)| (sp + sa) * k);
                    spectral_medium(spec, &albedo, sigma_t)
                }),
            rd_spectrum,
            source: Provenance {
                method: result.method.to_string(),
                model: result.model.to_string(),
                albedo_model: result
                    .albedo_model
                    .map_or_else(String::new, |a| a.to_string()),
                eta_source: result
                    .eta_source
                    .map_or_else(String::new, |e| e.to_string()),
                measured_with: result.version.clone(),
                not_trusted: result.untrusted(),
            },
            conventions: format!(
                "linear sRGB channels; coefficients per {u} ({u}^-1), lengths in {u}; sigma_s is the \
                 measured reduced scattering coefficient sigma_s' with an isotropic phase function \
                 (g = 0); albedo = sigma_s/sigma_t; mfp = 1/sigma_t; diffusion_length = 1/sigma_tr \
                 with sigma_tr = sqrt(3 sigma_a sigma_t); eta is relative to air, smooth boundary; \
                 rd_exact_transport is the total diffuse reflectance a volumetric path tracer renders \
                 from these coefficients (compare with rd_total, the measured one)",
                u = unit.symbol()
            ),
        };
        Ok((params, warnings))
    }

    /// The channels' three values of `f`, R, G, B.
    pub(super) fn per_channel(&self, f: impl Fn(&ChannelParameters) -> f64) -> [f64; 3] {
        self.channels.as_array().map(f)
    }
}

/// The spectral medium of a measured spectrum, its albedos and the channels' σ′t (R, G, B), extended
/// to [`SPECTRAL_RANGE`].
pub(super) fn spectral_medium(
    spec: &ReflectanceSpectrum,
    albedo: &[f64],
    sigma_t: [f64; 3],
) -> SpectralMedium {
    // σ′t at the channels' wavelengths, ascending in λ (B, G, R); linear between, constant beyond.
    let knots = [
        (CHANNEL_WAVELENGTHS[2], sigma_t[2]),
        (CHANNEL_WAVELENGTHS[1], sigma_t[1]),
        (CHANNEL_WAVELENGTHS[0], sigma_t[0]),
    ];
    let at = |wl: f64| -> f64 {
        if wl <= knots[0].0 {
            return knots[0].1;
        }
        for w in knots.windows(2) {
            let ((l0, v0), (l1, v1)) = (w[0], w[1]);
            if wl <= l1 {
                return v0 + (v1 - v0) * (wl - l0) / (l1 - l0);
            }
        }
        knots[2].1
    };
    let mut wavelength_nm = spec.wavelength_nm.clone();
    let mut albedo = albedo.to_vec();
    if let (Some(&first), Some(&a0)) = (wavelength_nm.first(), albedo.first())
        && first > SPECTRAL_RANGE.0
    {
        wavelength_nm.insert(0, SPECTRAL_RANGE.0);
        albedo.insert(0, a0);
    }
    if let (Some(&last), Some(&a1)) = (wavelength_nm.last(), albedo.last())
        && last < SPECTRAL_RANGE.1
    {
        wavelength_nm.push(SPECTRAL_RANGE.1);
        albedo.push(a1);
    }
    let sigma_t = wavelength_nm.iter().map(|&wl| at(wl)).collect();
    SpectralMedium {
        wavelength_nm,
        albedo,
        sigma_t,
    }
}
