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
//! [`RendererParameters`] into its text; what they share is in `params.rs` (the result's checks,
//! [`RendererParameters::from_result`], and the derived quantities), `notes.rs` (the model notes,
//! the provenance line and coefficient table every header carries) and `names.rs` (names,
//! escaping, number formatting); this file holds the formats, units, errors and [`export`].

use serde::{Deserialize, Serialize};

use crate::result_json::{ChannelStatus, MeasurementResult};

mod blender;
mod json;
mod mitsuba;
mod names;
mod notes;
mod params;
mod pbrt;

use names::*;
use notes::*;
use params::*;

pub use blender::{BLENDER_MAX_ALBEDO, BlenderValues, blender_script};
pub use json::{JSON_FORMAT_TAG, JSON_FORMAT_VERSION, json};
pub use mitsuba::{
    MitsubaMaterial, MitsubaObject, MitsubaProperty, MitsubaVariant, RAY_EPSILON, mitsuba_fragment,
    mitsuba_fragment_for, mitsuba_material, ray_offset_fraction, roulette_depth,
};
pub use names::{
    BLENDER_NAME_BYTES, MaterialNames, identifier, name_hash, num, one_line, python_docstring_text,
    python_literal, xml_comment,
};
pub use notes::ModelNote;
pub use params::{
    CHANNEL_WAVELENGTHS, ChannelParameters, ETA_RANGE, ParameterChannels, Provenance,
    ReflectanceSpectrum, RendererParameters, SIGMA_A_RANGE, SIGMA_S_RANGE, SPECTRAL_RANGE,
    SpectralMedium, WAVELENGTH_RANGE,
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

/// A target format of `scatterfit export` (`--to`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[non_exhaustive]
pub enum Format {
    /// pbrt-v4 scene-file fragment (`.pbrt`).
    #[cfg_attr(feature = "clap", value(help = "pbrt-v4 (.pbrt)"))]
    Pbrt,
    /// Mitsuba 3 XML scene fragment (`.xml`).
    #[cfg_attr(feature = "clap", value(help = "Mitsuba 3 (.xml)"))]
    Mitsuba,
    /// Blender Python (bpy) script (`.py`).
    #[cfg_attr(feature = "clap", value(help = "Blender ≥ 4.0 bpy script (.py)"))]
    Blender,
    /// Renderer-neutral JSON (`.json`).
    #[cfg_attr(feature = "clap", value(help = "Renderer-neutral JSON (.json)"))]
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

/// The length unit of the target scene: coefficients are written per this unit (`--scale`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[non_exhaustive]
pub enum SceneUnit {
    /// One scene unit is one millimetre (coefficients in mm⁻¹, as measured).
    #[serde(rename = "mm")]
    #[cfg_attr(
        feature = "clap",
        value(name = "mm", help = "One scene unit is one millimetre")
    )]
    Millimetre,
    /// One scene unit is one metre (coefficients in m⁻¹).
    #[serde(rename = "m")]
    #[cfg_attr(
        feature = "clap",
        value(name = "m", help = "One scene unit is one metre")
    )]
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
    /// For [`Format::Mitsuba`], the objects the fragment describes, with the integrator its
    /// header recommends ([`MitsubaObject::to_dict`] gives `mitsuba.load_dict`'s dictionaries).
    pub mitsuba: Option<MitsubaMaterial>,
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
    let mut mitsuba = None;
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
            mitsuba = Some(mitsuba_material(&params, options.mitsuba_variant));
            mitsuba_fragment_for(&params, options.mitsuba_variant)
        }
        Format::Blender => {
            warnings.extend(blender::base_colour_warnings(&params));
            blender_script(&params, &BlenderValues::new(&params))
        }
        Format::Json => json(&params),
    };
    Ok(Export {
        text,
        warnings,
        mitsuba,
    })
}

/// What a target renders a material with: the light transport its numbers meet.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Renderer {
    /// Mitsuba 3's `volpathmis` (or `volpath`) on the `homogeneous` medium: exact transport.
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
            Renderer::MitsubaVolpath => "Mitsuba's volpathmis (exact volumetric transport)",
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

/// The result every export test starts from.
#[cfg(test)]
mod fixtures {
    use super::*;
    use crate::result_json::{ChannelResult, Channels, Inputs};

    fn channel(sp: f64, sa: f64, rd: f64) -> ChannelResult {
        ChannelResult {
            rd_total: Some(rd),
            scale: Some(1.0),
            chi2_reduced: Some(1.0),
            ..crate::result_json::tests::channel(sp, sa)
        }
    }

    /// Jensen et al. 2001's marble (pbrt's table, docs/physics.md §1.5): σ′s = 2.19, 2.62, 3.00 and
    /// σa = 0.0021, 0.0041, 0.0071 mm⁻¹; Rd at η = 1.5 from docs/physics.md's computed column.
    pub(super) fn marble() -> MeasurementResult {
        MeasurementResult {
            schema_version: crate::result_json::SCHEMA_VERSION,
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
            g_uncertainty: None,
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
        r.channels.g.unconstrained = vec![scatterfit_optics::Parameter::SigmaA];
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

    /// The collisions seen in practice: "pink plastic" and "pink-plastic", and non-ASCII names.
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
            r.channels.g.sigma_s_prime = Some(scatterfit_optics::Estimate { value: sp, ..r.channels.g.sigma_s_prime.unwrap_or_default() });
            r.channels.g.sigma_a = Some(scatterfit_optics::Estimate { value: sa, ..r.channels.g.sigma_a.unwrap_or_default() });
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
