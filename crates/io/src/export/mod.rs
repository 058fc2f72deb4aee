//! Exports of a measurement (`result.json`) to the material formats renderers read: pbrt-v4, Mitsuba 3,
//! Blender (Cycles) and a renderer-neutral JSON.
//!
//! Pure string building from a [`MeasurementResult`]: no files are touched here (the CLI writes the text
//! atomically). Every format carries the same physics, converted to the scene's length unit.
//!
//! # Conventions shared by every format
//! - **Scene unit** ([`SceneUnit`]): renderers read coefficients per scene unit. `mm` writes them per
//!   millimetre (as measured), `m` per metre (×1000); lengths (mean free paths) follow.
//! - **Reduced coefficients, g = 0.** The measurement gives σ′s = σs(1 − g), not σs and g apart: a
//!   diffuse reflectance profile depends on them (to first order) only through σ′s, the similarity
//!   relation of transport theory (Wyman, Patterson & Wilson 1989, "Similarity relations for the
//!   interaction parameters in radiation transport", J. Appl. Phys. 66; its higher orders in Zhao et al.
//!   2014, "High-order similarity relations in radiative transfer", SIGGRAPH). So every export writes
//!   σs = σ′s with an isotropic phase function (g = 0): the medium has exactly the measured σ′s, σa and
//!   α′, it is the medium our Monte Carlo tables and forward models describe, and it is what pbrt does
//!   with Jensen et al. 2001's measured media (pbrt-v4 `SubsurfaceMaterial::Create` forces g = 0 for
//!   its named, reduced-coefficient media). A renderer given a g ≠ 0 must get σs = σ′s/(1 − g).
//! - **η** is the relative index of the material against air; the boundary is smooth.
//! - Colour channels are linear sRGB (the RGB of every channel-wise quantity in scatterfit).
//! - **The model behind the numbers** ([`ModelNote`]): α′ is the albedo whose total diffuse
//!   reflectance, in the result's albedo model, is the measured Rd. A renderer that transports light
//!   with another model renders another Rd from the same α′; every header says which model the numbers
//!   come from, what the target renders with, and — when the caller supplies exact transport's Rd
//!   ([`ExportOptions::exact_rd`]) — by how much the rendered total will differ from the measured one.
//!
//! # Checked input
//! [`RendererParameters::from_result`] refuses every number outside its documented range
//! ([`ExportError::OutOfRange`]), so no export carries `NaN`, `inf` or a value a renderer's float32
//! parser turns into one: η ∈ [1, 4]; σ′s ∈ [10⁻⁶, 10⁶] mm⁻¹; σa ∈ [0, 10⁶] mm⁻¹; Rd ∈ [0, 1]; a
//! reflectance spectrum's wavelengths increasing within [300, 1000] nm with values in [0, 1].
//!
//! # Names and text
//! A result's name and provenance fields are free text. [`MaterialNames`] turns the name into
//! identifiers that are never empty, stable (the same name always gives the same identifiers) and
//! unique (a 32-bit hash of the full name is part of each; "pink plastic" and "pink-plastic" differ),
//! and into a Blender material name within Blender's 63-byte limit. Free text is written through one
//! escaping function per context — [`one_line`] (comment lines), [`xml_comment`], [`python_literal`],
//! [`python_docstring_text`] — so no name or field can end a comment, break a string or make a file
//! ill-formed (property-tested below).
//!
//! # The formats
//! - [`Format::Pbrt`]: pbrt-v4 named materials: a `subsurface` material from the measured reflectance
//!   and mean free path (`"reflectance"`, `"mfp"`: pbrt inverts its own BSSRDF for the albedo, so the
//!   colour is the measured one), the same material from the coefficients (`"sigma_a"`, `"sigma_s"`),
//!   and the coefficients as a `homogeneous` named medium behind a `dielectric` boundary for volumetric
//!   path tracing (`HomogeneousMedium::Create` in `src/pbrt/media.cpp`); the header gives the
//!   integrator settings. Parameter names from pbrt-v4 `src/pbrt/materials.cpp`,
//!   `SubsurfaceMaterial::Create`.
//! - [`Format::Mitsuba`]: a Mitsuba 3 scene fragment: a `dielectric` BSDF (`int_ior` = η, `ext_ior` = 1)
//!   and a `homogeneous` medium (`sigma_t`, `albedo`, `scale`, an `hg` phase with g = 0; names from the
//!   plugin documentation of `src/media/homogeneous.cpp`) to reference as a shape's boundary and
//!   interior.
//! - [`Format::Blender`]: a bpy script that sets a Principled BSDF (Blender ≥ 4.0, Cycles Random Walk
//!   (Skin)); see [`BlenderValues`] for the mapping and where it is approximate.
//! - [`Format::Json`]: [`RendererParameters`], every derived quantity per channel.
//!
//! # Layout
//! One file per renderer — `pbrt.rs`, `mitsuba.rs`, `blender.rs`, `json.rs` — each turning a
//! [`RendererParameters`] into its text; this file holds what they share: the formats and units, the
//! result's checks ([`RendererParameters::from_result`]), names and escaping, the model notes, the
//! provenance line and coefficient table every header carries, and number formatting.

use serde::{Deserialize, Serialize};

use crate::result_json::{ChannelStatus, MeasurementResult};

mod blender;
mod json;
mod mitsuba;
mod pbrt;

pub use blender::{BLENDER_MAX_ALBEDO, BlenderValues, blender_script};
pub use json::{JSON_FORMAT_TAG, JSON_FORMAT_VERSION, json};
pub use mitsuba::{
    MitsubaVariant, RAY_EPSILON, mitsuba_fragment, mitsuba_fragment_for, ray_offset_fraction,
    roulette_depth,
};
pub use pbrt::{pbrt_material, pbrt_max_depth};
pub use result_spectrum::extended_reflectance;

/// The measured reflectance spectrum as written for renderers.
mod result_spectrum {
    use super::{ReflectanceSpectrum, SPECTRAL_RANGE};

    /// `spec` extended to [`SPECTRAL_RANGE`] with its end values (pbrt's piecewise-linear spectra are
    /// zero outside their points; renderers sample 360–830 nm).
    pub fn extended_reflectance(spec: &ReflectanceSpectrum) -> ReflectanceSpectrum {
        let mut s = spec.clone();
        if let (Some(&first), Some(&r0)) = (s.wavelength_nm.first(), s.rd.first())
            && first > SPECTRAL_RANGE.0
        {
            s.wavelength_nm.insert(0, SPECTRAL_RANGE.0);
            s.rd.insert(0, r0);
        }
        if let (Some(&last), Some(&r1)) = (s.wavelength_nm.last(), s.rd.last())
            && last < SPECTRAL_RANGE.1
        {
            s.wavelength_nm.push(SPECTRAL_RANGE.1);
            s.rd.push(r1);
        }
        s
    }
}

/// Channel keys as `result.json` writes them (and messages name them).
const CHANNEL_NAMES: [&str; 3] = ["r", "g", "b"];
/// Channel labels in the files' tables.
const CHANNEL_LABELS: [&str; 3] = ["R", "G", "B"];

/// Documented range of η (relative refractive index; the densest common dielectrics are below 3).
pub const ETA_RANGE: (f64, f64) = (1.0, 4.0);
/// Documented range of σ′s [mm⁻¹]: a mean free path between 1 nm and 1 km (outside, float32 renderers
/// lose the number, and no translucent material is there).
pub const SIGMA_S_RANGE: (f64, f64) = (1e-6, 1e6);
/// Documented range of σa [mm⁻¹].
pub const SIGMA_A_RANGE: (f64, f64) = (0.0, 1e6);
/// Documented range of a reflectance spectrum's wavelengths \[nm\].
pub const WAVELENGTH_RANGE: (f64, f64) = (300.0, 1000.0);

/// A target format of `scatterfit export`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum Format {
    /// pbrt-v4 scene-file fragment (`.pbrt`).
    Pbrt,
    /// Mitsuba 3 XML scene fragment (`.xml`).
    Mitsuba,
    /// Blender Python (bpy) script (`.py`).
    Blender,
    /// Renderer-neutral JSON (`.json`).
    Json,
}

impl Format {
    /// Every format.
    pub const ALL: [Format; 4] = [Format::Pbrt, Format::Mitsuba, Format::Blender, Format::Json];

    /// The file extension an output of this format must have (without the dot).
    pub fn extension(self) -> &'static str {
        match self {
            Format::Pbrt => "pbrt",
            Format::Mitsuba => "xml",
            Format::Blender => "py",
            Format::Json => "json",
        }
    }

    /// The name used on the command line (`--to`).
    pub fn name(self) -> &'static str {
        match self {
            Format::Pbrt => "pbrt",
            Format::Mitsuba => "mitsuba",
            Format::Blender => "blender",
            Format::Json => "json",
        }
    }
}

/// The length unit of the target scene: coefficients are written per this unit.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[non_exhaustive]
pub enum SceneUnit {
    /// One scene unit is one millimetre (coefficients in mm⁻¹, as measured).
    #[serde(rename = "mm")]
    Millimetre,
    /// One scene unit is one metre (coefficients in m⁻¹).
    #[serde(rename = "m")]
    Metre,
}

impl SceneUnit {
    /// Millimetres per scene unit: the factor from mm⁻¹ to per-scene-unit coefficients.
    pub fn mm_per_unit(self) -> f64 {
        match self {
            SceneUnit::Millimetre => 1.0,
            SceneUnit::Metre => 1000.0,
        }
    }

    /// The unit's symbol, `mm` or `m`.
    pub fn symbol(self) -> &'static str {
        match self {
            SceneUnit::Millimetre => "mm",
            SceneUnit::Metre => "m",
        }
    }

    /// The unit's name in words.
    pub fn word(self) -> &'static str {
        match self {
            SceneUnit::Millimetre => "millimetre",
            SceneUnit::Metre => "metre",
        }
    }
}

/// Why a result cannot be exported.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ExportError {
    /// A channel has no parameters (its fit failed): no material can be made from the result.
    #[error(
        "channel {channel} has no parameters (status {status}{}): nothing to export; measure that \
         channel again (or repair its colour reading) and export the new result",
        problem.as_ref().map(|p| format!(": {}", one_line(p))).unwrap_or_default()
    )]
    FailedChannel {
        /// `r`, `g` or `b`.
        channel: &'static str,
        /// The channel's status as written in the result (`failed`, or `ok` with values missing).
        status: &'static str,
        /// The channel's `problem`, when the result gives one.
        problem: Option<String>,
    },
    /// A number of the result lies outside the range the exports document (or is not finite).
    #[error(
        "`{field}` = {value} is outside its range {range}: no renderer file is written from it; \
         correct the result file or measure the sample again"
    )]
    OutOfRange {
        /// The field, as a path in the result file (`channels.r.sigma_a`).
        field: String,
        /// The value as read.
        value: String,
        /// The documented range, with its unit.
        range: String,
    },
}

/// An export: the text to write and what the user should know about it.
#[derive(Debug, Clone, PartialEq)]
pub struct Export {
    /// The file's contents.
    pub text: String,
    /// Warnings for the user (unconstrained channels, model mismatch, fallbacks), one sentence each.
    pub warnings: Vec<String>,
}

/// What the caller knows beyond the result: the scene unit, and exact transport's total Rd.
#[derive(Debug, Clone, PartialEq)]
pub struct ExportOptions {
    /// The scene's length unit.
    pub unit: SceneUnit,
    /// Per channel, the total diffuse reflectance that exact transport (a volumetric path tracer:
    /// Mitsuba's or pbrt's `volpath`) gives a half-space of the exported medium, Rd_exact(α′, η) —
    /// from the Monte Carlo tables (`scatterfit_mc`), which this crate does not depend on. `None`
    /// when unknown (then the headers quote the benchmark's figures instead of this material's).
    pub exact_rd: Option<[f64; 3]>,
    /// At each wavelength of the result's `rd_spectrum`, the single-scattering albedo whose exact
    /// transport total Rd(α′, η) is the measured Rd(λ) (the Monte Carlo tables' inversion, from the
    /// caller): the spectral medium's albedo. `None` without a spectrum (or where the tables do not
    /// reach); then no spectral medium is written.
    pub spectral_albedo: Option<Vec<f64>>,
    /// The kind of Mitsuba variant a Mitsuba fragment is for (RGB by default).
    pub mitsuba_variant: MitsubaVariant,
}

impl ExportOptions {
    /// Options with `unit` and no exact-transport figures.
    pub fn new(unit: SceneUnit) -> Self {
        Self {
            unit,
            exact_rd: None,
            spectral_albedo: None,
            mitsuba_variant: MitsubaVariant::Rgb,
        }
    }
}

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
fn in_range(field: String, value: f64, range: (f64, f64), unit: &str) -> Result<f64, ExportError> {
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
fn checked_spectrum(
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
            let sp = in_range(field("sigma_s_prime"), sp, SIGMA_S_RANGE, " mm^-1")?;
            let sa = in_range(field("sigma_a"), sa, SIGMA_A_RANGE, " mm^-1")?;
            let rd = match c.rd_total {
                Some(rd) => Some(in_range(field("rd_total"), rd, (0.0, 1.0), "")?),
                None => None,
            };
            checked[k] = (sp, sa, rd);
            if c.status == ChannelStatus::Unconstrained {
                let what = if c.unconstrained.is_empty() {
                    "some parameters".to_string()
                } else {
                    one_line(&c.unconstrained.join(", "))
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
    fn per_channel(&self, f: impl Fn(&ChannelParameters) -> f64) -> [f64; 3] {
        self.channels.as_array().map(f)
    }
}

/// The spectral medium of a measured spectrum, its albedos and the channels' σ′t (R, G, B), extended
/// to [`SPECTRAL_RANGE`].
fn spectral_medium(
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

/// Exports `result` as `format` with coefficients per `unit`.
///
/// # Errors
/// [`ExportError::FailedChannel`] when a channel has no parameters, [`ExportError::OutOfRange`] for
/// a number outside its documented range.
pub fn export(
    result: &MeasurementResult,
    format: Format,
    unit: SceneUnit,
) -> Result<Export, ExportError> {
    export_with(result, format, &ExportOptions::new(unit))
}

/// [`export`] with the caller's [`ExportOptions`] (exact transport's Rd for the model notes).
///
/// # Errors
/// As [`export`].
pub fn export_with(
    result: &MeasurementResult,
    format: Format,
    options: &ExportOptions,
) -> Result<Export, ExportError> {
    let (params, mut warnings) = RendererParameters::from_result_with(result, options)?;
    let renderers: &[Renderer] = match format {
        Format::Pbrt => &[Renderer::PbrtVolpath, Renderer::PbrtSubsurface],
        Format::Mitsuba => &[Renderer::MitsubaVolpath],
        Format::Blender => &[Renderer::Cycles],
        Format::Json => &[],
    };
    // pbrt's coefficient subsurface material is only the second route when the result has the
    // reflectance the default route uses: its note stays in the header then.
    let has_reflectance = params.rd_spectrum.is_some()
        || params
            .channels
            .as_array()
            .iter()
            .all(|c| c.rd_total.is_some());
    for r in renderers {
        if *r == Renderer::PbrtSubsurface && has_reflectance {
            continue;
        }
        if let Some(note) = ModelNote::new(&params, *r) {
            warnings.push(note.warning());
        }
    }
    let text = match format {
        Format::Pbrt => pbrt_material(&params),
        Format::Mitsuba => {
            warnings.extend(mitsuba::ray_offset_warning(&params));
            if options.mitsuba_variant == MitsubaVariant::Spectral
                && params.spectral_medium.is_none()
            {
                let why = if params.rd_spectrum.is_some() {
                    "the result's measured spectrum could not be turned into albedos (η outside \
                     the Monte Carlo tables' 1.0–2.5)"
                } else {
                    "the result has no measured reflectance spectrum (rd_spectrum, written by \
                     `scatterfit measure`)"
                };
                warnings.push(format!(
                    "{why}: the fragment's medium is the RGB one, which spectral variants render \
                     shifted in colour"
                ));
            }
            mitsuba_fragment_for(&params, options.mitsuba_variant)
        }
        Format::Blender => {
            warnings.extend(blender::base_colour_warnings(&params));
            blender_script(&params, &BlenderValues::new(&params))
        }
        Format::Json => json(&params),
    };
    Ok(Export { text, warnings })
}

/// What a target renders a material with: the light transport its numbers meet.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Renderer {
    /// Mitsuba 3's `volpath` on the `homogeneous` medium: exact transport.
    MitsubaVolpath,
    /// pbrt-v4's `volpath` on the `homogeneous` medium: exact transport.
    PbrtVolpath,
    /// pbrt-v4's `subsurface` material from σa, σs: its tabulated photon beam diffusion BSSRDF
    /// (scatterfit's `pbd` model is pbrt's evaluation of it).
    PbrtSubsurface,
    /// Blender Cycles' Random Walk (Skin) from Base Color and radius: its own volumetric walk.
    Cycles,
}

impl Renderer {
    /// The renderer and its transport, in words.
    pub fn describe(self) -> &'static str {
        match self {
            Renderer::MitsubaVolpath => "Mitsuba's volpath (exact volumetric transport)",
            Renderer::PbrtVolpath => "pbrt's volpath on the medium (exact volumetric transport)",
            Renderer::PbrtSubsurface => {
                "pbrt's subsurface material from sigma_a, sigma_s (its photon beam diffusion BSSRDF, \
                 scatterfit's `pbd` model)"
            }
            Renderer::Cycles => "Blender Cycles (its own random walk, colour from Base Color)",
        }
    }

    /// The (profile model, albedo model) a result must have to share this renderer's transport.
    fn shared_models(self) -> (&'static str, &'static str) {
        match self {
            Renderer::MitsubaVolpath | Renderer::PbrtVolpath | Renderer::Cycles => ("mc", "mc"),
            Renderer::PbrtSubsurface => ("pbd", "diffusion"),
        }
    }
}

/// The model whose total Rd(α′, η) gave α′: the Monte Carlo tables for `albedo_model = mc`, the
/// profile model's own for `diffusion` (the classical dipole when the profile model is `mc`; as the
/// pipeline's `albedo_model_for`).
fn albedo_source(model: &str, albedo_model: &str) -> String {
    match (albedo_model, model) {
        ("mc", _) => "mc".into(),
        ("diffusion", "mc") => "dipole".into(),
        ("diffusion", m) => m.into(),
        ("", _) => "unknown".into(),
        (a, _) => a.into(),
    }
}

/// A result whose numbers come from a model its target renderer does not share: what the header
/// says and what is warned on stderr.
#[derive(Debug, Clone, PartialEq)]
pub struct ModelNote {
    /// The target.
    pub renderer: Renderer,
    /// The model whose total Rd gave α′ (`dipole`, `pbd`, …, `mc`).
    pub albedo_from: String,
    /// The profile model that gave σ′s.
    pub profile_from: String,
    /// Per channel (exact-transport renderers, when known): the rendered total Rd's relative
    /// deviation from the measured Rd, (Rd_exact(α′, η) − Rd) / Rd.
    pub deviation: Option<[f64; 3]>,
}

impl ModelNote {
    /// The note for `params` rendered by `renderer`, or `None` when the result's models are the
    /// renderer's.
    pub fn new(params: &RendererParameters, renderer: Renderer) -> Option<Self> {
        let s = &params.source;
        let albedo_from = albedo_source(&s.model, &s.albedo_model);
        let (model, albedo) = renderer.shared_models();
        if s.model == model && s.albedo_model == albedo {
            return None;
        }
        let exact = matches!(renderer, Renderer::MitsubaVolpath | Renderer::PbrtVolpath);
        let deviation = if exact {
            let c = params.channels.as_array();
            match c.map(|c| c.rd_exact_transport.zip(c.rd_total)) {
                [Some((e0, m0)), Some((e1, m1)), Some((e2, m2))]
                    if m0 > 0.0 && m1 > 0.0 && m2 > 0.0 =>
                {
                    Some([e0 / m0 - 1.0, e1 / m1 - 1.0, e2 / m2 - 1.0])
                }
                _ => None,
            }
        } else {
            None
        };
        Some(Self {
            renderer,
            albedo_from,
            profile_from: if s.model.is_empty() {
                "unknown".into()
            } else {
                s.model.clone()
            },
            deviation,
        })
    }

    /// The deviations as "R −44 %, G −12 %, B +3 %".
    fn deviation_text(&self) -> Option<String> {
        self.deviation.map(|d| {
            CHANNEL_LABELS
                .iter()
                .zip(d)
                .map(|(l, x)| format!("{l} {:+.1} %", 100.0 * x))
                .collect::<Vec<_>>()
                .join(", ")
        })
    }

    /// One sentence for stderr.
    pub fn warning(&self) -> String {
        let (model, albedo) = self.renderer.shared_models();
        let what = match (self.renderer, self.deviation_text()) {
            (Renderer::MitsubaVolpath | Renderer::PbrtVolpath, Some(d)) => format!(
                "its diffuse reflectance Rd will differ from the measured one by {d}"
            ),
            (Renderer::MitsubaVolpath | Renderer::PbrtVolpath, None) => {
                "its colour will differ from the measured one (dipole-fitted demo materials: up to \
                 −44 % per channel, BENCHMARKS.md)"
                    .into()
            }
            (Renderer::PbrtSubsurface, _) => {
                "the `-coefficients` material's total reflectance follows pbrt's diffusion model, not \
                 the measurement (the default material, from reflectance and mfp, keeps the measured \
                 colour)"
                    .into()
            }
            (Renderer::Cycles, _) => {
                "the colour is the measured Base Color either way, but the translucency (radius) \
                 follows the fitted model"
                    .into()
            }
        };
        format!(
            "these parameters come from the `{}` profile fit with α′ from the `{}` total Rd, a model \
             {} does not share: {what}; measure with `--model {model} --albedo-model {albedo}` for \
             this renderer",
            self.profile_from,
            self.albedo_from,
            self.renderer.describe(),
        )
    }

    /// The header's lines (plain text, to be put in the format's comment syntax).
    pub fn header_lines(&self) -> Vec<String> {
        let (model, albedo) = self.renderer.shared_models();
        let mut lines = vec![format!(
            "MODEL WARNING for {}: these parameters come from the `{}` profile fit with",
            self.renderer.describe(),
            self.profile_from,
        )];
        lines.push(format!(
            "alpha' from the `{}` total Rd, a model this renderer does not share.",
            self.albedo_from
        ));
        match (self.renderer, self.deviation_text()) {
            (Renderer::MitsubaVolpath | Renderer::PbrtVolpath, d) => {
                lines.push(match d {
                    Some(d) => format!(
                        "Exact transport renders this alpha' with a diffuse reflectance Rd (the \
                         specular R0 excluded) off the measured one by {d}."
                    ),
                    None => "Exact transport renders another total reflectance from this alpha' \
                             (dipole fits of the demo's materials: up to -44 % per channel)."
                        .into(),
                });
                if self.profile_from != "mc" {
                    lines.push(format!(
                        "sigma_s' comes from the `{}` profile, not exact transport: the glow's \
                         reach differs too.",
                        self.profile_from
                    ));
                }
            }
            (Renderer::PbrtSubsurface, _) => lines.push(
                "The `-coefficients` material renders pbrt's diffusion Rd of this alpha'; the \
                 default material (reflectance + mfp) keeps the measured colour."
                    .into(),
            ),
            (Renderer::Cycles, _) => lines.push(
                "Base Color is the measured Rd either way; the radius (translucency) follows the \
                 fitted model."
                    .into(),
            ),
        }
        // No double hyphen: the lines also go into XML comments, where `--` is forbidden.
        lines.push(format!(
            "For this renderer measure with model = \"{model}\" and albedo_model = \"{albedo}\" \
             (sample.toml's [fit], or measure's flags of those names)."
        ));
        lines
    }
}

/// The model notes of `params` for each of `renderers`, as header lines (empty when none applies),
/// or one line saying the models agree.
fn model_header(params: &RendererParameters, renderers: &[Renderer]) -> Vec<String> {
    let mut lines = Vec::new();
    for r in renderers {
        match ModelNote::new(params, *r) {
            Some(note) => lines.extend(note.header_lines()),
            None => lines.push(format!(
                "Model: the numbers come from the model {} shares (profile `{}`, albedo `{}`).",
                r.describe(),
                params.source.model,
                params.source.albedo_model
            )),
        }
    }
    lines
}

/// One line naming how the result was measured (free text made single-line).
fn provenance_line(params: &RendererParameters) -> String {
    let s = &params.source;
    let or_unknown = |t: &str| {
        if t.is_empty() {
            "unknown".to_string()
        } else {
            one_line(t)
        }
    };
    format!(
        "Measured with scatterfit {} (method {}, profile model {}, albedo model {}, eta from {}).",
        or_unknown(&s.measured_with),
        or_unknown(&s.method),
        or_unknown(&s.model),
        or_unknown(&s.albedo_model),
        or_unknown(&s.eta_source),
    )
}

/// The per-channel coefficients as aligned comment lines starting with `prefix`.
fn channel_table_comment(params: &RendererParameters, prefix: &str) -> String {
    let u = params.unit.symbol();
    let exact = params
        .channels
        .as_array()
        .iter()
        .all(|c| c.rd_exact_transport.is_some());
    let mut header = vec![
        "channel".to_string(),
        format!("sigma_a [1/{u}]"),
        format!("sigma_s' [1/{u}]"),
        format!("sigma_t [1/{u}]"),
        "albedo".to_string(),
        format!("1/sigma_t [{u}]"),
        "Rd measured".to_string(),
    ];
    if exact {
        header.push("Rd exact transport".to_string());
    }
    let mut rows = vec![header];
    for (label, c) in CHANNEL_LABELS.iter().zip(params.channels.as_array()) {
        let mut row = vec![
            label.to_string(),
            num(c.sigma_a),
            num(c.sigma_s),
            num(c.sigma_t),
            format!("{:.4}", c.albedo),
            num(c.mfp),
            c.rd_total
                .map(|r| format!("{r:.4}"))
                .unwrap_or_else(|| "-".into()),
        ];
        if exact {
            row.push(
                c.rd_exact_transport
                    .map(|r| format!("{r:.4}"))
                    .unwrap_or_default(),
            );
        }
        if c.status == ChannelStatus::Unconstrained {
            row.push("(unconstrained)".into());
        }
        rows.push(row);
    }
    let columns = rows.iter().map(Vec::len).max().unwrap_or(0);
    let widths: Vec<usize> = (0..columns)
        .map(|k| {
            rows.iter()
                .map(|r| r.get(k).map_or(0, |c| c.chars().count()))
                .max()
                .unwrap_or(0)
        })
        .collect();
    let mut s = String::new();
    for row in rows {
        let cells: Vec<String> = row
            .iter()
            .zip(&widths)
            .map(|(cell, &w)| format!("{cell:<w$}"))
            .collect();
        s.push_str(prefix);
        s.push_str(cells.join("  ").trim_end());
        s.push('\n');
    }
    s
}

/// The largest of three per-channel values (0 if none is positive).
fn largest(values: [f64; 3]) -> f64 {
    values.iter().copied().fold(0.0_f64, f64::max)
}

/// Three per-channel values, each formatted by `format`, joined by `separator`.
fn joined(values: [f64; 3], format: fn(f64) -> String, separator: &str) -> String {
    values.map(format).join(separator)
}

/// A number as renderers' parsers read it: 7 significant digits (beyond any measurement's precision
/// and f32's), shortest form, plain decimal between 1e-4 and 1e7 and exponent notation outside.
/// Every number reaching it is finite ([`RendererParameters::from_result`] checks them); a
/// non-finite one would be written `0` rather than a token no parser reads.
pub fn num(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return "0".into();
    }
    let rounded: f64 = format!("{x:.6e}").parse().unwrap_or(x);
    let a = rounded.abs();
    if (1e-4..1e7).contains(&a) {
        format!("{rounded}")
    } else {
        format!("{rounded:e}")
    }
}

/// The names a material gets in the exports, all derived from the result's name.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct MaterialNames {
    /// An identifier valid as an XML `id`, a pbrt name and a Python identifier: ASCII letters, digits
    /// and `_`, starting with a letter, at most 52 characters: a slug of the name (≤ 40 characters,
    /// `material` when nothing is left) and `_` and [`name_hash`]. Never empty; stable; different
    /// names give different identifiers (up to a 32-bit hash collision, ≈ 10⁻⁹ for any two names).
    pub id: String,
    /// The material's name in Blender: the name itself when it is a clean Blender name (1–63 bytes
    /// of UTF-8, no control or non-characters, and not itself ending like a hashed name), otherwise
    /// its first bytes (whole characters, cleaned) and ` #` and the hash, within 63 bytes. So two
    /// different names never share a Blender material, and the same name finds its material again
    /// (Blender truncates longer names, which made a new material on every run).
    pub blender: String,
    /// The name for comments: one line, every character safe in every format's comment.
    pub display: String,
}

/// Blender's limit on ID names in bytes (`MAX_ID_NAME` − 3 = 63 in Blender 4.x and 5.0).
pub const BLENDER_NAME_BYTES: usize = 63;

impl MaterialNames {
    /// The names of a material called `name`.
    pub fn new(name: &str) -> Self {
        let hash = name_hash(name);
        let mut slug = String::new();
        for ch in name.chars() {
            let c = if ch.is_ascii_alphanumeric() { ch } else { '_' };
            if !(c == '_' && (slug.is_empty() || slug.ends_with('_'))) {
                slug.push(c);
            }
            if slug.len() >= 40 {
                break;
            }
        }
        let slug = slug.trim_end_matches('_');
        let id = if slug.is_empty() {
            format!("material_{hash}")
        } else if slug.starts_with(|c: char| c.is_ascii_digit()) {
            format!("m_{slug}_{hash}")
        } else {
            format!("{slug}_{hash}")
        };
        let clean = !name.is_empty()
            && name.len() <= BLENDER_NAME_BYTES
            && name.chars().all(|c| !unsafe_char(c))
            && !looks_hashed(name);
        let blender = if clean {
            name.to_string()
        } else {
            let suffix = format!(" #{hash}");
            let mut head = String::new();
            for ch in one_line(name).chars() {
                if head.len() + ch.len_utf8() + suffix.len() > BLENDER_NAME_BYTES {
                    break;
                }
                head.push(ch);
            }
            format!("{head}{suffix}")
        };
        let display = if name.is_empty() {
            "(unnamed)".to_string()
        } else {
            one_line(name)
        };
        Self {
            id,
            blender,
            display,
        }
    }
}

/// True for a name ending like the Blender names [`MaterialNames`] makes for unclean names (` #` and
/// eight lower-case hex digits).
fn looks_hashed(name: &str) -> bool {
    let b = name.as_bytes();
    b.len() >= 10
        && &b[b.len() - 10..b.len() - 8] == b" #"
        && b[b.len() - 8..]
            .iter()
            .all(|c| c.is_ascii_digit() || (b'a'..=b'f').contains(c))
}

/// Eight lower-case hex digits of a 64-bit FNV-1a hash of the name's UTF-8 bytes, mixed by the
/// SplitMix64 finaliser (Steele, Lea & Flood 2014) so that every bit depends on every byte. Stable
/// across versions and platforms (no `std` hasher, whose output may change).
pub fn name_hash(name: &str) -> String {
    // FNV-1a, 64 bits (Fowler, Noll & Vo; offset basis and prime from the reference).
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in name.as_bytes() {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    // SplitMix64's finaliser.
    h = (h ^ (h >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    h = (h ^ (h >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    h ^= h >> 31;
    format!("{:08x}", h >> 32)
}

/// The identifier of a material called `name` ([`MaterialNames::id`]).
pub fn identifier(name: &str) -> String {
    MaterialNames::new(name).id
}

/// A character no export writes as it is inside free text: control characters (C0, DEL, C1), line
/// and paragraph separators, Unicode non-characters (U+FDD0–U+FDEF and the last two code points of
/// every plane: U+FFFE/U+FFFF make XML ill-formed) and the bidirectional controls that can make a
/// line display differently from what it is.
fn unsafe_char(c: char) -> bool {
    let u = c as u32;
    c.is_control()
        || matches!(u, 0x2028 | 0x2029 | 0xFDD0..=0xFDEF)
        || (u & 0xFFFE) == 0xFFFE
        || matches!(u, 0x202A..=0x202E | 0x2066..=0x2069 | 0x200E | 0x200F | 0x061C)
}

/// Free text as one line safe in every format's comments and strings of this module: whitespace
/// controls (tab, newline, carriage return, form feed, NEL, line and paragraph separators) become a
/// space, every other `unsafe_char` U+FFFD (�).
pub fn one_line(text: &str) -> String {
    text.chars()
        .map(|c| match c {
            '\t' | '\n' | '\r' | '\u{b}' | '\u{c}' | '\u{85}' | '\u{2028}' | '\u{2029}' => ' ',
            c if unsafe_char(c) => '\u{fffd}',
            c => c,
        })
        .collect()
}

/// `text` with every line longer than `width` characters broken at spaces, continuation lines
/// indented like the line they continue (a word longer than the width stays whole).
fn wrap(text: &str, width: usize) -> String {
    let mut out = Vec::new();
    for line in text.split('\n') {
        let indent: String = line.chars().take_while(|c| *c == ' ').collect();
        let mut current = String::new();
        for word in line.trim_start_matches(' ').split(' ') {
            let len = current.chars().count();
            if len > indent.len() && len + 1 + word.chars().count() > width {
                out.push(std::mem::take(&mut current));
            }
            if current.is_empty() {
                current.push_str(&indent);
            } else {
                current.push(' ');
            }
            current.push_str(word);
        }
        out.push(current);
    }
    out.join("\n")
}

/// Text safe inside an XML comment (`<!-- … -->`): [`one_line`] line by line (our own newlines kept),
/// no `--` (forbidden in comments) and no `-` at the end (it would make `--->`).
pub fn xml_comment(text: &str) -> String {
    let lines: Vec<String> = text.split('\n').map(one_line).collect();
    let mut s = lines.join("\n");
    while s.contains("--") {
        s = s.replace("--", "- -");
    }
    if s.ends_with('-') {
        s.push(' ');
    }
    s
}

/// A Python string literal for `text`, in pure ASCII: `\\`, `\"`, `\n`, `\r`, `\t`, `\xNN` for the
/// other control characters, `\uXXXX`/`\UXXXXXXXX` for every non-ASCII character. Python reads it back
/// as exactly `text` (Python Language Reference, §2.4.1 "String and Bytes literals").
pub fn python_literal(text: &str) -> String {
    let mut s = String::with_capacity(text.len() + 2);
    s.push('"');
    for c in text.chars() {
        match c {
            '\\' => s.push_str("\\\\"),
            '"' => s.push_str("\\\""),
            '\n' => s.push_str("\\n"),
            '\r' => s.push_str("\\r"),
            '\t' => s.push_str("\\t"),
            c if (c as u32) < 0x20 || c as u32 == 0x7f => {
                s.push_str(&format!("\\x{:02x}", c as u32));
            }
            c if c.is_ascii() => s.push(c),
            c if (c as u32) <= 0xFFFF => s.push_str(&format!("\\u{:04x}", c as u32)),
            c => s.push_str(&format!("\\U{:08x}", c as u32)),
        }
    }
    s.push('"');
    s
}

/// Text safe inside a Python triple-quoted docstring: [`one_line`], no backslashes (they would start
/// escapes) and no double quotes (no `"""`, and no `"` before the closing quotes).
pub fn python_docstring_text(text: &str) -> String {
    one_line(text)
        .chars()
        .map(|c| match c {
            '\\' => '/',
            '"' => '\'',
            c => c,
        })
        .collect()
}

/// The result every export test starts from.
#[cfg(test)]
mod fixtures {
    use super::*;
    use crate::result_json::{ChannelResult, Channels, Inputs};

    fn channel(sp: f64, sa: f64, rd: f64) -> ChannelResult {
        ChannelResult {
            status: ChannelStatus::Ok,
            sigma_s_prime: Some(sp),
            sigma_s_prime_stderr: Some(0.01),
            sigma_a: Some(sa),
            sigma_a_stderr: Some(0.001),
            sigma_s_prime_stderr_spectro: None,
            sigma_a_stderr_spectro: None,
            albedo_prime_stderr: None,
            albedo_prime: Some(sp / (sp + sa)),
            rd_total: Some(rd),
            scale: Some(1.0),
            correlation: None,
            unconstrained: vec![],
            fit_time_s: 1e-5,
            iterations: 7,
            termination: "converged".into(),
            mse: Some(1e-6),
            rms_log_residual: Some(0.01),
            chi2_reduced: Some(1.0),
            rings_used: 250,
            rings_inside_spot: 10,
            rings_below_detection: 40,
            rings_invalid: 0,
            problem: None,
            quality: None,
        }
    }

    /// Jensen et al. 2001's marble (pbrt's table, docs/physics.md §1.5): σ′s = 2.19, 2.62, 3.00 and
    /// σa = 0.0021, 0.0041, 0.0071 mm⁻¹; Rd at η = 1.5 from docs/physics.md's computed column.
    pub(super) fn marble() -> MeasurementResult {
        MeasurementResult {
            name: "marble".into(),
            eta: 1.5,
            eta_source: Some(crate::result_json::EtaSource::Given),
            eta_stderr: None,
            spectro_repeatability: None,
            method: scatterfit_optics::Method::Proposed,
            model: scatterfit_optics::ModelName::Dipole,
            albedo_model: Some(scatterfit_optics::AlbedoModel::Diffusion.into()),
            channels: Channels::from_array([
                channel(2.19, 0.0021, 0.8302),
                channel(2.62, 0.0041, 0.7910),
                channel(3.00, 0.0071, 0.7526),
            ]),
            inputs: Inputs::default(),
            version: "0.1.0".into(),
            rd_spectrum: None,
            spectro_port: None,
        }
    }

    pub(super) const SP: [f64; 3] = [2.19, 2.62, 3.00];
    pub(super) const SA: [f64; 3] = [0.0021, 0.0041, 0.0071];

    pub(super) fn close(a: f64, b: f64, rel: f64) -> bool {
        (a - b).abs() <= rel * b.abs().max(1e-300)
    }
}

#[cfg(test)]
mod tests {
    use super::fixtures::{SA, SP, marble};
    use super::*;
    use crate::result_json::AlbedoSource;
    use scatterfit_optics::{AlbedoModel, ModelName};

    #[test]
    fn failed_channel_is_refused_with_its_name_and_problem() {
        let mut r = marble();
        r.channels.b.status = ChannelStatus::Failed;
        r.channels.b.sigma_a = None;
        r.channels.b.problem = Some("out of gamut".into());
        for format in Format::ALL {
            let err = export(&r, format, SceneUnit::Millimetre)
                .unwrap_err()
                .to_string();
            assert!(err.contains("channel b"), "{err}");
            assert!(err.contains("out of gamut"), "{err}");
        }
        // A channel marked ok but without a coefficient is refused too.
        let mut r = marble();
        r.channels.g.sigma_s_prime = None;
        let err = export(&r, Format::Json, SceneUnit::Millimetre)
            .unwrap_err()
            .to_string();
        assert!(err.contains("channel g"), "{err}");
    }

    #[test]
    fn unconstrained_channel_is_exported_with_a_warning() {
        let mut r = marble();
        r.channels.g.status = ChannelStatus::Unconstrained;
        r.channels.g.unconstrained = vec!["sigma_a".into()];
        let e = export(&r, Format::Pbrt, SceneUnit::Millimetre).unwrap();
        let w: Vec<&String> = e
            .warnings
            .iter()
            .filter(|w| w.contains("unconstrained"))
            .collect();
        assert_eq!(w.len(), 1, "{:?}", e.warnings);
        assert!(w[0].contains("channel g"), "{:?}", e.warnings);
        assert!(w[0].contains("sigma_a"));
        assert!(e.text.contains("(unconstrained)"));
    }

    /// Names with quotes, markup and comment terminators stay inert in every format.
    #[test]
    fn hostile_names_are_escaped() {
        let mut r = marble();
        r.name = "a \"b\" <c> & d -- e\\f\n\"\"\"".into();
        let id = identifier(&r.name);
        assert!(id.starts_with("a_b_c_d_e_f_"), "{id}");
        let xml = export(&r, Format::Mitsuba, SceneUnit::Millimetre)
            .unwrap()
            .text;
        let doc = roxmltree::Document::parse(&xml).expect("well-formed XML");
        assert!(
            doc.descendants()
                .any(|n| n.attribute("id") == Some(format!("{id}_medium").as_str()))
        );
        let pbrt = export(&r, Format::Pbrt, SceneUnit::Millimetre)
            .unwrap()
            .text;
        assert!(pbrt.contains(&format!("MakeNamedMaterial \"{id}\"")));
        pbrt::tests::parse(&pbrt).unwrap();
        let py = export(&r, Format::Blender, SceneUnit::Millimetre)
            .unwrap()
            .text;
        check_python(&py, &r.name).unwrap();
        assert_eq!(identifier("123"), format!("m_123_{}", name_hash("123")));
        assert_eq!(identifier("äö"), format!("material_{}", name_hash("äö")));
        assert_eq!(identifier(""), format!("material_{}", name_hash("")));
    }

    /// The issue's collisions: "pink plastic" and "pink-plastic", and non-ASCII names.
    #[test]
    fn similar_names_get_different_ids() {
        let names = [
            "pink plastic",
            "pink-plastic",
            "pink_plastic",
            "äö",
            "ü",
            "",
            " ",
        ];
        let ids: std::collections::HashSet<String> = names.iter().map(|n| identifier(n)).collect();
        assert_eq!(ids.len(), names.len(), "{ids:?}");
        // Stable: a fixed value (changing the hash renames every exported material).
        assert_eq!(name_hash("pink plastic"), name_hash("pink plastic"));
        assert_eq!(
            identifier("marble"),
            format!("marble_{}", name_hash("marble"))
        );
        // A pin: the hash of a name must never change between versions.
        assert_eq!(name_hash(""), "f52a15e9");
    }

    /// Python's reading of the literals `python_literal` writes (the escapes it uses), for the checks.
    fn python_unescape(literal: &str) -> Result<String, String> {
        let inner = literal
            .strip_prefix('"')
            .and_then(|l| l.strip_suffix('"'))
            .ok_or("not a double-quoted literal")?;
        let mut out = String::new();
        let mut it = inner.chars();
        while let Some(c) = it.next() {
            match c {
                '"' => return Err("unescaped quote".into()),
                '\n' | '\r' => return Err("raw newline".into()),
                '\\' => {
                    let e = it.next().ok_or("escape at the end")?;
                    let hex = |it: &mut std::str::Chars, n: usize| -> Result<char, String> {
                        let h: String = it.take(n).collect();
                        u32::from_str_radix(&h, 16)
                            .ok()
                            .and_then(char::from_u32)
                            .ok_or_else(|| format!("bad escape {h}"))
                    };
                    out.push(match e {
                        '\\' => '\\',
                        '"' => '"',
                        'n' => '\n',
                        'r' => '\r',
                        't' => '\t',
                        'x' => hex(&mut it, 2)?,
                        'u' => hex(&mut it, 4)?,
                        'U' => hex(&mut it, 8)?,
                        other => return Err(format!("unknown escape \\{other}")),
                    });
                }
                c if !c.is_ascii() => return Err("non-ASCII in the literal".into()),
                c => out.push(c),
            }
        }
        Ok(out)
    }

    /// Checks a Blender script's Python where free text goes: the module docstring is one triple-quoted
    /// string without backslashes that ends where the code starts, the script has exactly the two
    /// docstrings' four `"""`, and the `"material"`/`"name"` literals read back as the Blender name and
    /// the full name. (CI also runs Python's own `ast.parse` on hostile names: cli/tests/blender.rs.)
    fn check_python(py: &str, name: &str) -> Result<(), String> {
        let body = py.strip_prefix("\"\"\"").ok_or("no docstring")?;
        let end = body.find("\"\"\"").ok_or("docstring not closed")?;
        let doc = &body[..end];
        if doc.contains('\\') {
            return Err("backslash in the docstring".into());
        }
        if !body[end..].starts_with("\"\"\"\n\nimport bpy\n") {
            return Err("the docstring does not end where the code starts".into());
        }
        if py.matches("\"\"\"").count() != 4 {
            return Err("stray triple quotes".into());
        }
        let literal = |key: &str| -> Result<String, String> {
            let at = py
                .find(&format!("\n    \"{key}\": "))
                .ok_or(format!("no {key}"))?;
            let rest = &py[at + key.len() + 9..];
            let line = rest.split('\n').next().unwrap_or_default();
            python_unescape(line.strip_suffix(',').ok_or("no comma")?)
        };
        let names = MaterialNames::new(name);
        if literal("material")? != names.blender {
            return Err("material literal".into());
        }
        if literal("name")? != name {
            return Err("name literal".into());
        }
        Ok(())
    }

    /// A character for the fuzzers: any code point, or one of those that broke a format before.
    fn hostile_char() -> impl Strategy<Value = char> {
        prop_oneof![
            any::<char>(),
            proptest::sample::select(vec![
                '\n',
                '\r',
                '\t',
                '\0',
                '"',
                '\'',
                '\\',
                '-',
                '<',
                '>',
                '&',
                '#',
                '[',
                ']',
                '\u{85}',
                '\u{2028}',
                '\u{2029}',
                '\u{202e}',
                '\u{fffe}',
                '\u{ffff}',
                '\u{1fffe}',
                '\u{fdd0}',
                '\u{7f}',
                '\u{9f}',
                'é',
                '漢',
                '😀',
                ' ',
                '_',
            ]),
        ]
    }

    fn hostile_text(max: usize) -> impl Strategy<Value = String> {
        proptest::collection::vec(hostile_char(), 0..max).prop_map(|v| v.into_iter().collect())
    }

    /// Every number written into a Mitsuba fragment parses finite.
    fn mitsuba_numbers_finite(doc: &roxmltree::Document) -> bool {
        doc.descendants()
            .filter(|n| n.has_tag_name("float") || n.has_tag_name("rgb"))
            .all(|n| {
                n.attribute("value").is_some_and(|v| {
                    v.split(',')
                        .all(|t| t.trim().parse::<f64>().is_ok_and(f64::is_finite))
                })
            })
    }

    /// Checks one export of every format for `r`: XML well-formed with the expected unique ids, pbrt
    /// tokenising into the expected directives, Python's free text in place, JSON reading back.
    fn check_all_formats(r: &MeasurementResult) -> Result<(), TestCaseError> {
        let names = MaterialNames::new(&r.name);
        for unit in [SceneUnit::Millimetre, SceneUnit::Metre] {
            let xml = export(r, Format::Mitsuba, unit).unwrap().text;
            let doc = roxmltree::Document::parse(&xml)
                .map_err(|e| TestCaseError::fail(format!("{e}\n{xml}")))?;
            let ids: Vec<String> = doc
                .descendants()
                .filter_map(|n| n.attribute("id").map(str::to_string))
                .collect();
            prop_assert_eq!(
                ids,
                vec![
                    format!("{}_boundary", names.id),
                    format!("{}_medium", names.id)
                ]
            );
            prop_assert!(mitsuba_numbers_finite(&doc));
            let pbrt = export(r, Format::Pbrt, unit).unwrap().text;
            let directives = pbrt::tests::parse(&pbrt)
                .map_err(|e| TestCaseError::fail(format!("{e}\n{pbrt}")))?;
            prop_assert_eq!(directives.len(), 4);
            prop_assert_eq!(&directives[0].1, &names.id);
            let py = export(r, Format::Blender, unit).unwrap().text;
            check_python(&py, &r.name).map_err(|e| TestCaseError::fail(format!("{e}\n{py}")))?;
            let json = export(r, Format::Json, unit).unwrap().text;
            let back: RendererParameters = serde_json::from_str(&json)
                .map_err(|e| TestCaseError::fail(format!("{e}\n{json}")))?;
            prop_assert_eq!(&back.name, &r.name);
            prop_assert_eq!(&back.id, &names.id);
        }
        Ok(())
    }

    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(256))]

        /// Any name and any version text: every format stays well-formed.
        #[test]
        fn every_format_is_well_formed_for_any_text(
            name in hostile_text(90),
            version in hostile_text(12),
        ) {
            // Method, model, albedo model and η source are enums: only these two are free text.
            let mut r = marble();
            r.name = name;
            r.version = version;
            check_all_formats(&r)?;
        }

        /// Two different names never share an identifier or a Blender material, and identifiers
        /// are well-formed.
        #[test]
        fn different_names_never_collide(a in hostile_text(70), b in hostile_text(70)) {
            prop_assume!(a != b);
            let (na, nb) = (MaterialNames::new(&a), MaterialNames::new(&b));
            prop_assert_ne!(&na.id, &nb.id);
            prop_assert_ne!(&na.blender, &nb.blender);
            for n in [&na, &nb] {
                prop_assert!(!n.id.is_empty() && n.id.len() <= 52);
                prop_assert!(n.id.starts_with(|c: char| c.is_ascii_alphabetic()));
                prop_assert!(n.id.chars().all(|c| c.is_ascii_alphanumeric() || c == '_'));
                prop_assert!(!n.blender.is_empty() && n.blender.len() <= BLENDER_NAME_BYTES);
                prop_assert!(!n.blender.chars().any(unsafe_char));
                prop_assert!(!n.display.chars().any(unsafe_char));
            }
            // Stable.
            prop_assert_eq!(MaterialNames::new(&a), na);
        }

        /// Any numbers: an export either refuses the result with the field named, or writes only
        /// finite numbers.
        #[test]
        fn numbers_out_of_range_are_refused(
            eta in prop_oneof![Just(f64::NAN), Just(f64::INFINITY), -10.0..10.0, Just(1.0), Just(4.0)],
            sp in prop_oneof![Just(f64::NAN), Just(f64::INFINITY), Just(0.0), Just(1e-7), Just(1e300),
                              -1.0..10.0, Just(1e6)],
            sa in prop_oneof![Just(f64::NAN), Just(f64::NEG_INFINITY), Just(0.0), Just(2e6),
                              -1.0..10.0],
            rd in prop_oneof![Just(f64::NAN), Just(-0.1), Just(0.0), Just(1.0), Just(1.5), 0.0..1.0],
        ) {
            let mut r = marble();
            r.eta = eta;
            r.channels.g.sigma_s_prime = Some(sp);
            r.channels.g.sigma_a = Some(sa);
            r.channels.g.rd_total = Some(rd);
            let ok = eta.is_finite() && (1.0..=4.0).contains(&eta)
                && sp.is_finite() && (1e-6..=1e6).contains(&sp)
                && sa.is_finite() && (0.0..=1e6).contains(&sa)
                && rd.is_finite() && (0.0..=1.0).contains(&rd);
            for format in Format::ALL {
                match export(&r, format, SceneUnit::Metre) {
                    Ok(e) => {
                        prop_assert!(ok, "accepted {eta} {sp} {sa} {rd}");
                        prop_assert!(!e.text.contains("NaN"));
                    }
                    Err(e @ ExportError::OutOfRange { .. }) => {
                        prop_assert!(!ok, "{e}");
                        prop_assert!(e.to_string().contains("is outside its range"));
                    }
                    Err(e) => prop_assert!(false, "{e}"),
                }
            }
            if ok {
                check_all_formats(&r)?;
            }
        }
    }

    /// Text escaping: what each function promises.
    #[test]
    fn escaping_functions() {
        assert_eq!(one_line("a\nb\rc\u{2028}d\u{fffe}e"), "a b c d\u{fffd}e");
        assert_eq!(xml_comment("a--b-"), "a- -b- ");
        assert_eq!(xml_comment("---"), "- - - ");
        assert_eq!(
            python_literal("a\"b\\c\nd\u{e9}\u{1f600}\0"),
            r#""a\"b\\c\nd\u00e9\U0001f600\x00""#
        );
        assert_eq!(
            python_unescape(&python_literal("x\"\\\n\u{fffe}")).unwrap(),
            "x\"\\\n\u{fffe}"
        );
        assert_eq!(python_docstring_text("a\"\"\"b\\c\nd"), "a'''b/c d");
    }

    /// Models: a dipole result warns for exact renderers with the rendered-versus-measured figures;
    /// an mc/mc result does not.
    #[test]
    fn model_mismatch_is_warned_and_written() {
        let mut r = marble();
        let options = ExportOptions {
            unit: SceneUnit::Millimetre,
            exact_rd: Some([0.8302 * 0.56, 0.7910, 0.7526 * 1.1]),
            spectral_albedo: None,
            mitsuba_variant: MitsubaVariant::Rgb,
        };
        let e = export_with(&r, Format::Mitsuba, &options).unwrap();
        assert_eq!(e.warnings.len(), 1, "{:?}", e.warnings);
        assert!(
            e.warnings[0].contains("R -44.0 %, G +0.0 %, B +10.0 %"),
            "{}",
            e.warnings[0]
        );
        assert!(e.warnings[0].contains("--model mc --albedo-model mc"));
        assert!(e.text.contains("MODEL WARNING"));
        assert!(e.text.contains("Rd exact transport"));
        // pbrt: the medium's note; the coefficients' subsurface material is only the second route
        // (the default one keeps the measured colour), so its note stays in the header.
        let p = export_with(&r, Format::Pbrt, &options).unwrap();
        assert_eq!(p.warnings.len(), 1, "{:?}", p.warnings);
        assert!(p.text.contains("MODEL WARNING for pbrt's subsurface"));
        r.model = ModelName::Mc;
        r.albedo_model = Some(AlbedoSource::Model(AlbedoModel::Mc));
        let e = export_with(&r, Format::Mitsuba, &options).unwrap();
        assert!(e.warnings.is_empty(), "{:?}", e.warnings);
        assert!(!e.text.contains("MODEL WARNING"));
        assert!(e.text.contains("Model: the numbers come from the model"));
        // pbrt: the medium shares mc; without Rd the coefficients' subsurface material is the
        // default one, and its model is warned of.
        let p = export_with(&r, Format::Pbrt, &options).unwrap();
        assert!(p.warnings.is_empty(), "{:?}", p.warnings);
        let mut no_rd = r.clone();
        no_rd.channels.b.rd_total = None;
        let p = export_with(&no_rd, Format::Pbrt, &options).unwrap();
        assert_eq!(p.warnings.len(), 1, "{:?}", p.warnings);
        assert!(p.warnings[0].contains("pbrt's subsurface"));
        // A pbd/diffusion result shares pbrt's subsurface model, not the volumetric one.
        r.model = ModelName::Pbd;
        r.albedo_model = Some(AlbedoSource::Model(AlbedoModel::Diffusion));
        let p = export_with(&r, Format::Pbrt, &options).unwrap();
        assert_eq!(p.warnings.len(), 1, "{:?}", p.warnings);
        assert!(p.warnings[0].contains("volpath"));
        assert!(
            !p.text.contains("- -"),
            "an XML-escaped flag leaked into pbrt"
        );
    }

    /// With the exact-transport albedos of the spectrum, pbrt and Mitsuba get a medium per
    /// wavelength: σt interpolated between the channels' σ′t, extended to 360–830 nm.
    #[test]
    fn spectral_medium_is_written() {
        let mut r = marble();
        r.rd_spectrum = Some(crate::result_json::RdSpectrum {
            wavelength_nm: vec![400.0, 549.0, 700.0],
            rd: vec![0.75, 0.79, 0.83],
        });
        let options = ExportOptions {
            unit: SceneUnit::Millimetre,
            exact_rd: None,
            spectral_albedo: Some(vec![0.99, 0.995, 0.999]),
            mitsuba_variant: MitsubaVariant::Spectral,
        };
        let (p, _) = RendererParameters::from_result_with(&r, &options).unwrap();
        let m = p.spectral_medium.as_ref().unwrap();
        assert_eq!(m.wavelength_nm, vec![360.0, 400.0, 549.0, 700.0, 830.0]);
        assert_eq!(m.albedo, vec![0.99, 0.99, 0.995, 0.999, 0.999]);
        // Below 464 nm the B channel's σ′t, at 549 nm G's, beyond 611 nm R's.
        let st = SP.iter().zip(SA).map(|(s, a)| s + a).collect::<Vec<_>>();
        assert!(fixtures::close(m.sigma_t[0], st[2], 1e-12));
        assert!(fixtures::close(m.sigma_t[2], st[1], 1e-12));
        assert!(fixtures::close(m.sigma_t[4], st[0], 1e-12));
        let pbrt = export_with(&r, Format::Pbrt, &options).unwrap().text;
        let directives = pbrt::tests::parse(&pbrt).unwrap();
        let spectral = directives
            .iter()
            .find(|d| d.1.ends_with("-medium"))
            .expect("spectral medium");
        assert!(directives.iter().any(|d| d.1.ends_with("-medium-rgb")));
        assert_eq!(spectral.2[1].0, "sigma_a");
        assert_eq!(spectral.2[1].1.len(), 10);
        let xml = export_with(&r, Format::Mitsuba, &options).unwrap().text;
        let doc = roxmltree::Document::parse(&xml).unwrap();
        let id = format!("{}_medium", identifier("marble"));
        let media: Vec<_> = doc
            .descendants()
            .filter(|n| n.has_tag_name("medium"))
            .collect();
        assert_eq!(media.len(), 1);
        let medium = media[0];
        assert_eq!(medium.attribute("id"), Some(id.as_str()));
        let albedo = medium
            .children()
            .find(|n| n.attribute("name") == Some("albedo"))
            .unwrap();
        assert!(
            albedo
                .attribute("value")
                .unwrap()
                .starts_with("360:0.99, 400:0.99")
        );
        // For RGB variants the same result gets the RGB medium, and the header points to the option.
        let rgb = ExportOptions {
            mitsuba_variant: MitsubaVariant::Rgb,
            ..options.clone()
        };
        let xml = export_with(&r, Format::Mitsuba, &rgb).unwrap().text;
        assert!(xml.contains("<rgb name=\"albedo\""));
        assert!(xml.contains("mitsuba-variant spectral"));
        // Asked for spectral without a spectrum: the RGB medium and a warning.
        let mut no_spectrum = r.clone();
        no_spectrum.rd_spectrum = None;
        let e = export_with(&no_spectrum, Format::Mitsuba, &options).unwrap();
        assert!(e.text.contains("<rgb name=\"albedo\""));
        assert!(
            e.warnings
                .iter()
                .any(|w| w.contains("no measured reflectance spectrum"))
        );
        // A wrong count of albedos is refused.
        let bad = ExportOptions {
            spectral_albedo: Some(vec![0.5]),
            ..options
        };
        assert!(export_with(&r, Format::Pbrt, &bad).is_err());
    }

    /// A result's spectrum is checked and goes into pbrt's reflectance as λ/value pairs.
    #[test]
    fn spectrum_is_checked_and_exported() {
        let mut r = marble();
        r.rd_spectrum = Some(crate::result_json::RdSpectrum {
            wavelength_nm: vec![400.0, 550.0, 700.0],
            rd: vec![0.75, 0.79, 0.83],
        });
        let text = export(&r, Format::Pbrt, SceneUnit::Millimetre)
            .unwrap()
            .text;
        assert!(
            text.contains(
                "\"spectrum reflectance\" [ 360 0.75 400 0.75 550 0.79 700 0.83 830 0.83 ]"
            ),
            "{text}"
        );
        pbrt::tests::parse(&text).unwrap();
        r.rd_spectrum.as_mut().unwrap().wavelength_nm[1] = 390.0;
        let err = export(&r, Format::Pbrt, SceneUnit::Millimetre).unwrap_err();
        assert!(
            err.to_string().contains("rd_spectrum.wavelength_nm[1]"),
            "{err}"
        );
        r.rd_spectrum.as_mut().unwrap().wavelength_nm[1] = 550.0;
        r.rd_spectrum.as_mut().unwrap().rd[2] = f64::NAN;
        let err = export(&r, Format::Json, SceneUnit::Millimetre).unwrap_err();
        assert!(err.to_string().contains("rd_spectrum.rd[2]"), "{err}");
    }

    #[test]
    fn numbers_are_short_and_exact_enough() {
        assert_eq!(num(0.0), "0");
        assert_eq!(num(1.5), "1.5");
        assert_eq!(num(2.19 * 1000.0), "2190");
        assert_eq!(num(0.0021 * 1000.0), "2.1");
        assert_eq!(num(7.92e-5), "7.92e-5");
        assert_eq!(num(1.0 / 3.0), "0.3333333");
        assert_eq!(num(2.5e8), "2.5e8");
    }
}
