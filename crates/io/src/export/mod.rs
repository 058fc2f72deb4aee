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
//!
//! # The formats
//! - [`Format::Pbrt`]: a pbrt-v4 `subsurface` named material (`"rgb sigma_a"`, `"rgb sigma_s"`,
//!   `"float scale"`, `"float eta"`, `"float g"`; parameter names from pbrt-v4
//!   `src/pbrt/materials.cpp`, `SubsurfaceMaterial::Create`), plus the same coefficients as a
//!   `homogeneous` named medium and a `dielectric` boundary for volumetric path tracing
//!   (`HomogeneousMedium::Create` in `src/pbrt/media.cpp`).
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
//! result's checks ([`RendererParameters::from_result`]), the provenance line and coefficient table
//! every header carries, and the number and identifier formatting.

use serde::{Deserialize, Serialize};

use crate::result_json::{ChannelStatus, MeasurementResult};

mod blender;
mod json;
mod mitsuba;
mod pbrt;

pub use blender::{BLENDER_MAX_ALBEDO, BlenderValues, blender_script};
pub use json::{JSON_FORMAT_TAG, JSON_FORMAT_VERSION, json};
pub use mitsuba::{mitsuba_fragment, roulette_depth};
pub use pbrt::pbrt_material;

/// Channel keys as `result.json` writes them (and messages name them).
const CHANNEL_NAMES: [&str; 3] = ["r", "g", "b"];
/// Channel labels in the files' tables.
const CHANNEL_LABELS: [&str; 3] = ["R", "G", "B"];

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
        problem.as_ref().map(|p| format!(": {p}")).unwrap_or_default()
    )]
    FailedChannel {
        /// `r`, `g` or `b`.
        channel: &'static str,
        /// The channel's status as written in the result (`failed`, or `ok` with values missing).
        status: &'static str,
        /// The channel's `problem`, when the result gives one.
        problem: Option<String>,
    },
}

/// An export: the text to write and what the user should know about it.
#[derive(Debug, Clone, PartialEq)]
pub struct Export {
    /// The file's contents.
    pub text: String,
    /// Warnings for the user (unconstrained channels, fallbacks), one sentence each.
    pub warnings: Vec<String>,
}

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
    /// Diffusion length 1/σtr [L, the scene unit]: how far light spreads sideways before it is absorbed; `None` for
    /// σa = 0 (no absorption, unbounded).
    pub diffusion_length: Option<f64>,
    /// Total diffuse reflectance Rd of the channel from the spectrophotometer (linear sRGB), when the
    /// result has it.
    pub rd_total: Option<f64>,
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
    /// The length unit L of every coefficient (L⁻¹) and length (L).
    pub unit: SceneUnit,
    /// Relative refractive index η (material / air).
    pub eta: f64,
    /// Henyey–Greenstein asymmetry of the phase function: 0 (see `conventions`).
    pub g: f64,
    /// Per-channel parameters (linear sRGB channels).
    pub channels: ParameterChannels,
    /// The measurement the numbers come from.
    pub source: Provenance,
    /// The conventions, in words, for a reader without this documentation.
    pub conventions: String,
}

impl RendererParameters {
    /// The parameters of `result` in `unit`, and warnings for channels the data do not constrain.
    ///
    /// # Errors
    /// [`ExportError::FailedChannel`] for the first channel that failed or lacks σ′s or σa.
    pub fn from_result(
        result: &MeasurementResult,
        unit: SceneUnit,
    ) -> Result<(Self, Vec<String>), ExportError> {
        let mut warnings = Vec::new();
        let channels = result.channels.as_array();
        for (name, c) in CHANNEL_NAMES.iter().zip(channels) {
            let missing = c.sigma_s_prime.is_none() || c.sigma_a.is_none();
            if c.status == ChannelStatus::Failed || missing {
                return Err(ExportError::FailedChannel {
                    channel: name,
                    status: if c.status == ChannelStatus::Failed {
                        "failed"
                    } else {
                        "ok, but σ′s or σa missing"
                    },
                    problem: c.problem.clone(),
                });
            }
            if c.status == ChannelStatus::Unconstrained {
                let what = if c.unconstrained.is_empty() {
                    "some parameters".to_string()
                } else {
                    c.unconstrained.join(", ")
                };
                warnings.push(format!(
                    "channel {name} is unconstrained (the data do not constrain {what}): its values \
                     are the solver's end point, not a measurement; exported anyway"
                ));
            }
        }
        let k = unit.mm_per_unit();
        let channel = |c: &crate::result_json::ChannelResult| {
            // Checked above: both present.
            let (sp, sa) = (
                c.sigma_s_prime.unwrap_or_default() * k,
                c.sigma_a.unwrap_or_default() * k,
            );
            let sigma_t = sa + sp;
            // σtr = √(3σaσ′t) (Jensen et al. 2001, §2.4).
            let sigma_tr = (3.0 * sa * sigma_t).sqrt();
            ChannelParameters {
                status: c.status,
                sigma_a: sa,
                sigma_s: sp,
                sigma_t,
                albedo: sp / sigma_t,
                mfp: 1.0 / sigma_t,
                sigma_tr,
                diffusion_length: (sigma_tr > 0.0).then(|| 1.0 / sigma_tr),
                rd_total: c.rd_total,
            }
        };
        let [r, g, b] = channels;
        let params = Self {
            format: JSON_FORMAT_TAG.to_string(),
            format_version: JSON_FORMAT_VERSION,
            name: result.name.clone(),
            unit,
            eta: result.eta,
            g: 0.0,
            channels: ParameterChannels {
                r: channel(r),
                g: channel(g),
                b: channel(b),
            },
            source: Provenance {
                method: result.method.clone(),
                model: result.model.clone(),
                albedo_model: result.albedo_model.clone(),
                eta_source: result.eta_source.clone(),
                measured_with: result.version.clone(),
            },
            conventions: format!(
                "linear sRGB channels; coefficients per {u} ({u}^-1), lengths in {u}; sigma_s is the \
                 measured reduced scattering coefficient sigma_s' with an isotropic phase function \
                 (g = 0); albedo = sigma_s/sigma_t; mfp = 1/sigma_t; diffusion_length = 1/sigma_tr \
                 with sigma_tr = sqrt(3 sigma_a sigma_t); eta is relative to air, smooth boundary",
                u = unit.symbol()
            ),
        };
        Ok((params, warnings))
    }
}

/// Exports `result` as `format` with coefficients per `unit`.
///
/// # Errors
/// [`ExportError::FailedChannel`] when a channel has no parameters.
pub fn export(
    result: &MeasurementResult,
    format: Format,
    unit: SceneUnit,
) -> Result<Export, ExportError> {
    let (params, mut warnings) = RendererParameters::from_result(result, unit)?;
    let text = match format {
        Format::Pbrt => pbrt_material(&params),
        Format::Mitsuba => mitsuba_fragment(&params),
        Format::Blender => {
            warnings.extend(blender::base_colour_warnings(&params));
            blender_script(&params, &BlenderValues::new(&params))
        }
        Format::Json => json(&params),
    };
    Ok(Export { text, warnings })
}

/// One line naming how the result was measured.
fn provenance_line(params: &RendererParameters) -> String {
    let s = &params.source;
    let or_unknown = |t: &str| {
        if t.is_empty() {
            "unknown".to_string()
        } else {
            t.to_string()
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
    let header = [
        "channel".to_string(),
        format!("sigma_a [1/{u}]"),
        format!("sigma_s' [1/{u}]"),
        format!("sigma_t [1/{u}]"),
        "albedo".to_string(),
        format!("1/sigma_t [{u}]"),
        "Rd".to_string(),
    ];
    let mut rows = vec![header];
    for (label, c) in CHANNEL_LABELS.iter().zip(params.channels.as_array()) {
        rows.push([
            label.to_string(),
            num(c.sigma_a),
            num(c.sigma_s),
            num(c.sigma_t),
            format!("{:.4}", c.albedo),
            num(c.mfp),
            format!(
                "{}{}",
                c.rd_total
                    .map(|r| format!("{r:.4}"))
                    .unwrap_or_else(|| "-".into()),
                if c.status == ChannelStatus::Unconstrained {
                    "  (unconstrained)"
                } else {
                    ""
                }
            ),
        ]);
    }
    let widths: Vec<usize> = (0..rows[0].len())
        .map(|k| rows.iter().map(|r| r[k].chars().count()).max().unwrap_or(0))
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
pub fn num(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return if x.is_finite() {
            "0".into()
        } else {
            x.to_string()
        };
    }
    let rounded: f64 = format!("{x:.6e}").parse().unwrap_or(x);
    let a = rounded.abs();
    if (1e-4..1e7).contains(&a) {
        format!("{rounded}")
    } else {
        format!("{rounded:e}")
    }
}

/// An identifier usable as an XML id (and in most scene languages): ASCII letters, digits and `_`,
/// not starting with a digit; `material` when nothing is left.
pub fn identifier(name: &str) -> String {
    let mut id = String::new();
    for ch in name.chars() {
        let c = if ch.is_ascii_alphanumeric() { ch } else { '_' };
        if !(c == '_' && id.ends_with('_')) {
            id.push(c);
        }
    }
    let id = id.trim_matches('_').to_string();
    if id.is_empty() {
        "material".into()
    } else if id.starts_with(|c: char| c.is_ascii_digit()) {
        format!("m_{id}")
    } else {
        id
    }
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
            eta_source: "given".into(),
            eta_stderr: None,
            spectro_repeatability: None,
            method: "proposed".into(),
            model: "dipole".into(),
            albedo_model: "diffusion".into(),
            channels: Channels::from_array([
                channel(2.19, 0.0021, 0.8302),
                channel(2.62, 0.0041, 0.7910),
                channel(3.00, 0.0071, 0.7526),
            ]),
            inputs: Inputs::default(),
            version: "0.1.0".into(),
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
    use super::fixtures::marble;
    use super::*;

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
        assert_eq!(e.warnings.len(), 1);
        assert!(e.warnings[0].contains("channel g"), "{:?}", e.warnings);
        assert!(e.warnings[0].contains("sigma_a"));
        assert!(e.text.contains("(unconstrained)"));
    }

    /// Names with quotes, markup and comment terminators stay inert in every format.
    #[test]
    fn hostile_names_are_escaped() {
        let mut r = marble();
        r.name = "a \"b\" <c> & d -- e\\f\n\"\"\"".into();
        let xml = export(&r, Format::Mitsuba, SceneUnit::Millimetre)
            .unwrap()
            .text;
        let doc = roxmltree::Document::parse(&xml).expect("well-formed XML");
        assert!(
            doc.descendants()
                .any(|n| n.attribute("id") == Some("a_b_c_d_e_f_medium"))
        );
        let pbrt = export(&r, Format::Pbrt, SceneUnit::Millimetre)
            .unwrap()
            .text;
        assert!(pbrt.contains("MakeNamedMaterial \"a 'b' <c> & d -- e/f '''\""));
        let py = export(&r, Format::Blender, SceneUnit::Millimetre)
            .unwrap()
            .text;
        // One docstring: exactly two triple quotes in the whole script's header docstring.
        assert_eq!(py.matches("\"\"\"").count(), 4, "{py}");
        assert!(py.contains(r#""material": "a \"b\" <c> & d -- e\\f\n\"\"\"""#));
        assert_eq!(identifier("123"), "m_123");
        assert_eq!(identifier("äö"), "material");
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
