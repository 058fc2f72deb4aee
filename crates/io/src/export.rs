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

use serde::{Deserialize, Serialize};

use crate::result_json::{ChannelStatus, MeasurementResult};

/// Identifies the renderer-neutral JSON ([`RendererParameters::format`]).
pub const JSON_FORMAT_TAG: &str = "scatterfit-renderer-parameters";
/// Version of the renderer-neutral JSON layout.
pub const JSON_FORMAT_VERSION: u32 = 1;

const CHANNEL_NAMES: [&str; 3] = ["r", "g", "b"];

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
            let blender = BlenderValues::new(&params);
            for (name, c) in CHANNEL_NAMES.iter().zip(params.channels.as_array()) {
                if c.rd_total.is_none() {
                    warnings.push(format!(
                        "channel {name} has no rd_total in the result: its Blender base colour is the \
                         classical dipole's Rd(α′ = {:.4}, η) instead of the measured one",
                        c.albedo
                    ));
                }
            }
            blender_script(&params, &blender)
        }
        Format::Json => json(&params),
    };
    Ok(Export { text, warnings })
}

/// The renderer-neutral JSON text (pretty, newline-terminated).
pub fn json(params: &RendererParameters) -> String {
    // A struct of finite numbers, strings and options always serialises.
    let mut text = serde_json::to_string_pretty(params).unwrap_or_default();
    text.push('\n');
    text
}

/// A pbrt-v4 scene-file fragment: a `subsurface` named material (pbrt's tabulated photon-beam-diffusion
/// BSSRDF; physics.md §2) and, for pbrt's volumetric path tracer, a `homogeneous` named medium with the
/// same coefficients behind a `dielectric` named material.
///
/// Units: pbrt reads `sigma_a`, `sigma_s` per scene unit and multiplies them by `scale`
/// (pbrt-v4 `SubsurfaceMaterial::GetBSSRDF`, `HomogeneousMedium`); we write them per `params.unit` and
/// `scale` = 1, so a scene in yet another unit sets `scale` to the length of its unit in
/// `params.unit` (e.g. 0.01 for centimetres with coefficients per metre).
pub fn pbrt_material(params: &RendererParameters) -> String {
    let name = pbrt_string(&params.name);
    let u = params.unit.symbol();
    let chans = params.channels.as_array();
    let rgb = |f: fn(&ChannelParameters) -> f64| {
        format!(
            "[ {} {} {} ]",
            num(f(chans[0])),
            num(f(chans[1])),
            num(f(chans[2]))
        )
    };
    let (sigma_a, sigma_s) = (rgb(|c| c.sigma_a), rgb(|c| c.sigma_s));
    let mut s = String::new();
    s.push_str(&format!(
        "# scatterfit export for pbrt-v4: \"{name}\"\n\
         # {}\n\
         # Scene unit: 1 scene unit = 1 {u}. sigma_a and sigma_s are per {u} (pbrt reads them per scene\n\
         # unit); \"scale\" multiplies both: for a scene in another unit set it to the length of that\n\
         # unit in {u} (e.g. {example}).\n\
         # sigma_s is the measured reduced scattering coefficient sigma_s' with g = 0: the measurement\n\
         # gives sigma_s' = sigma_s (1 - g) only, and a diffusive material looks the same for every\n\
         # (sigma_s, g) with that sigma_s' (similarity relation); pbrt does the same for its measured media.\n\
         # Channels are linear sRGB. eta is relative to air; the boundary is smooth.\n\
         #\n",
        provenance_line(params),
        example = match params.unit {
            SceneUnit::Millimetre => "10 for centimetres, 1000 for metres",
            SceneUnit::Metre => "0.01 for centimetres, 0.001 for millimetres",
        }
    ));
    s.push_str(&channel_table_comment(params, "# "));
    s.push_str(&format!(
        "#\n\
         # 1. BSSRDF (pbrt's photon beam diffusion; fast). Inside the world block: NamedMaterial \"{name}\"\n\
         MakeNamedMaterial \"{name}\"\n    \"string type\" [ \"subsurface\" ]\n    \"rgb sigma_a\" {sigma_a}\n    \
         \"rgb sigma_s\" {sigma_s}\n    \"float scale\" [ 1 ]\n    \"float eta\" [ {eta} ]\n    \"float g\" [ 0 ]\n\
         \n\
         # 2. Volumetric (exact transport with the volpath integrator; slower):\n\
         #    AttributeBegin\n\
         #      MediumInterface \"{name}-medium\" \"\"\n\
         #      NamedMaterial \"{name}-boundary\"\n\
         #      Shape ...\n\
         #    AttributeEnd\n\
         MakeNamedMedium \"{name}-medium\"\n    \"string type\" [ \"homogeneous\" ]\n    \"rgb sigma_a\" {sigma_a}\n    \
         \"rgb sigma_s\" {sigma_s}\n    \"float scale\" [ 1 ]\n    \"float g\" [ 0 ]\n\
         MakeNamedMaterial \"{name}-boundary\"\n    \"string type\" [ \"dielectric\" ]\n    \"float eta\" [ {eta} ]\n",
        eta = num(params.eta),
    ));
    s
}

/// A Mitsuba 3 XML scene fragment: a `<scene>` holding a `dielectric` BSDF (`int_ior` = η, `ext_ior` = 1)
/// with id `<id>_boundary` and a `homogeneous` medium with id `<id>_medium` (isotropic `hg` phase).
/// A scene `<include>`s it and gives a shape `<ref id="<id>_boundary"/>` and
/// `<ref name="interior" id="<id>_medium"/>`.
///
/// `sigma_t` is written as an RGB colour normalised to a largest component of 1, its magnitude in the
/// medium's `scale` (σt = scale · rgb, per scene unit): Mitsuba's documentation of `homogeneous`
/// notes that RGB values have to lie in [0, 1] (spectral variants refuse others), and `scale` exists for
/// this. `sample_emitters` is off: shadow rays cannot pass the dielectric boundary (the plugin's
/// documentation recommends it for subsurface scattering). The usage comment names the `rr_depth` the
/// integrator needs for this albedo ([`roulette_depth`]).
pub fn mitsuba_fragment(params: &RendererParameters) -> String {
    let id = identifier(&params.name);
    let u = params.unit.symbol();
    let chans = params.channels.as_array();
    let scale = chans.iter().map(|c| c.sigma_t).fold(0.0_f64, f64::max);
    let rgb = |v: [f64; 3]| format!("{}, {}, {}", num(v[0]), num(v[1]), num(v[2]));
    let sigma_t_rgb = rgb(chans.map(|c| c.sigma_t / scale));
    let albedo_rgb = rgb(chans.map(|c| c.albedo));
    let rr = roulette_depth(chans.iter().map(|c| c.albedo).fold(0.0, f64::max));
    let mfp = num(chans.iter().map(|c| c.mfp).fold(f64::INFINITY, f64::min));
    let mut s = String::from("<?xml version=\"1.0\" encoding=\"utf-8\"?>\n<!--\n");
    s.push_str(&xml_comment(&format!(
        "  scatterfit export for Mitsuba 3: \"{}\"\n\
         \x20 {}\n\
         \x20 Scene unit: 1 scene unit = 1 {u}. The medium's extinction is sigma_t = scale * rgb(sigma_t) per\n\
         \x20 {u}: the colour is normalised to a largest component of 1 (RGB values must lie in [0, 1] in\n\
         \x20 spectral variants) and its magnitude is `scale`. For a scene in another unit multiply `scale` by\n\
         \x20 the length of that unit in {u}.\n\
         \x20 albedo = sigma_s / sigma_t with sigma_s the measured reduced scattering coefficient sigma_s'\n\
         \x20 and an isotropic phase function (g = 0): the measurement gives sigma_s' = sigma_s (1 - g) only,\n\
         \x20 and a diffusive material looks the same for every (sigma_s, g) with that sigma_s'.\n\
         \x20 Channels are linear sRGB. eta is relative to air; the boundary is smooth.\n\n",
        params.name,
        provenance_line(params),
    )));
    s.push_str(&xml_comment(&channel_table_comment(params, "  ")));
    s.push_str(&xml_comment(&format!(
        "\n  Use with the volpath integrator, max_depth -1 and rr_depth {rr} (Russian roulette only once\n\
         \x20 the albedo has taken the throughput below 1e-3: Mitsuba's roulette survival is capped at\n\
         \x20 0.95 per scattering, which at albedos near 1 leaves the long paths carrying much of the\n\
         \x20 diffuse reflectance to rare, heavy samples and makes short renders too dark). Mitsuba\n\
         \x20 offsets rays leaving a surface by about 1e-4 (1 + |p|) scene units: keep that well below\n\
         \x20 the mean free path 1/sigma_t ({mfp} {u} here) or low-albedo renders come out dark.\n\
         \x20   <include filename=\"this-file.xml\"/>\n\
         \x20   <shape type=\"...\">\n\
         \x20       <ref id=\"{id}_boundary\"/>\n\
         \x20       <ref name=\"interior\" id=\"{id}_medium\"/>\n\
         \x20   </shape>\n"
    )));
    s.push_str("-->\n");
    s.push_str(&format!(
        "<scene version=\"3.0.0\">\n\
         \x20   <bsdf type=\"dielectric\" id=\"{id}_boundary\">\n\
         \x20       <float name=\"int_ior\" value=\"{eta}\"/>\n\
         \x20       <float name=\"ext_ior\" value=\"1\"/>\n\
         \x20   </bsdf>\n\
         \x20   <medium type=\"homogeneous\" id=\"{id}_medium\">\n\
         \x20       <rgb name=\"sigma_t\" value=\"{sigma_t_rgb}\"/>\n\
         \x20       <float name=\"scale\" value=\"{scale}\"/>\n\
         \x20       <rgb name=\"albedo\" value=\"{albedo_rgb}\"/>\n\
         \x20       <boolean name=\"sample_emitters\" value=\"false\"/>\n\
         \x20       <phase type=\"hg\">\n\
         \x20           <float name=\"g\" value=\"0\"/>\n\
         \x20       </phase>\n\
         \x20   </medium>\n\
         </scene>\n",
        eta = num(params.eta),
        scale = num(scale),
    ));
    s
}

/// The number of scatterings after which the throughput of a path in a medium of single-scattering
/// albedo `albedo` is below 10⁻³, ⌈ln 10⁻³ / ln α⌉ (at least 5, Mitsuba's default `rr_depth`): from
/// there on Russian roulette costs little variance. 100 000 for α = 1 (no absorption).
pub fn roulette_depth(albedo: f64) -> u64 {
    if albedo >= 1.0 {
        return 100_000;
    }
    // Bounded: 1e5 covers α up to 1 − 7e-5.
    ((1e-3_f64.ln() / albedo.ln()).ceil()).clamp(5.0, 100_000.0) as u64
}

/// Largest reduced albedo used for the Blender radius: σa = 0 would make the diffusion length
/// unbounded; Cycles clamps its own dipole inversion at the same value.
pub const BLENDER_MAX_ALBEDO: f64 = 0.999_999;

/// The values [`blender_script`] sets on a Principled BSDF, in the scene's unit.
///
/// # The mapping (Blender ≥ 4.0, Cycles, `subsurface_method = 'RANDOM_WALK_SKIN'`)
/// Cycles does not take σs and σa: it derives a random walk's coefficients from Base Color and the
/// Subsurface Radius (`bssrdf_setup_radius` in `intern/cycles/kernel/closure/bssrdf.h` and
/// `subsurface_random_walk_remap` in `kernel/integrator/subsurface_random_walk.h`):
/// - In Random Walk (Skin) mode the radius (times Subsurface Scale) is read as the **diffusion length
///   ℓ = 1/σtr**: Cycles inverts the classical dipole's total reflectance (Jensen et al. 2001, eq. 5 with
///   the Fdr polynomial and Subsurface IOR — the same formula as `scatterfit_optics::dipole`) for the
///   albedo α′d of Base Color and sets the mean free path 1/σ′t = ℓ·√(3(1 − α′d)).
/// - In plain Random Walk and Christensen–Burley modes it reads the radius as a mean free path scaled by
///   1/(4π) ("to look like the older Cubic/Gaussian/Burley models"), i.e. 1/σ′t = radius/(4π).
///
/// We use the Skin mode, whose radius is a physical quantity the measurement gives:
/// - **Subsurface Radius · Subsurface Scale = ℓ = 1/σtr = 1/√(3σaσ′t)** per channel (α′ capped at
///   [`BLENDER_MAX_ALBEDO`] for σa = 0). The radius is written normalised to a largest component of 1
///   and its magnitude, in scene units, is the Subsurface Scale — Blender's own split (a colour-like
///   radius and a distance). Cycles then recovers our 1/σ′t exactly when Base Color is the dipole's
///   Rd(α′) — results measured with `albedo_model = diffusion` — and within the dipole's albedo bias
///   otherwise. 1/σ′t itself would be the wrong length here: Cycles would read it as a diffusion length
///   √(3(1 − α′)) times too short (18× at α′ = 0.999).
/// - **Base Color = Rd** per channel, the measured total diffuse reflectance in linear sRGB (Blender's
///   default scene-linear space has the sRGB primaries).
/// - Subsurface IOR = IOR = η; Subsurface Anisotropy = 0; Subsurface Weight = 1; Roughness = 0 (a
///   smooth boundary, as in the other exports).
///
/// # Where it is approximate
/// The walk's single-scattering albedo is not α′: Cycles derives it from Base Color with the fit of
/// Chiang, Kutz & Burley 2016 ("Practical and Controllable Subsurface Scattering for Production Path
/// Tracing"), made for its own walk, which gives a lower albedo than exact transport behind a Fresnel
/// boundary needs for the same Rd. Measured with Blender 4.2 on half-spaces (BENCHMARKS.md, "exports"):
/// the rendered total reflectance is 6–9 % below R0 + Rd, and the glow beyond a light edge decays 1.25–
/// 1.7× faster than exact transport (the material looks less translucent). A Blender render of the export
/// is a close match, not a measurement-grade one; the Mitsuba and pbrt volumetric exports are exact.
#[derive(Debug, Clone, PartialEq)]
pub struct BlenderValues {
    /// Base Color (linear sRGB): the measured Rd per channel (or the classical dipole's Rd(α′, η)).
    pub base_color: [f64; 3],
    /// Subsurface Radius, normalised to a largest component of 1.
    pub subsurface_radius: [f64; 3],
    /// Subsurface Scale [scene units]: the largest diffusion length.
    pub subsurface_scale: f64,
    /// Diffusion length ℓ = 1/σtr per channel [scene units] (= radius · scale).
    pub diffusion_length: [f64; 3],
    /// Transport mean free path 1/σ′t per channel [scene units], for reference.
    pub mfp: [f64; 3],
    /// IOR and Subsurface IOR: η.
    pub ior: f64,
}

impl BlenderValues {
    /// The Principled BSDF values for `params` (see the type's documentation).
    pub fn new(params: &RendererParameters) -> Self {
        let chans = params.channels.as_array();
        let mfp = chans.map(|c| c.mfp);
        // ℓ = 1/σtr = (1/σ′t)/√(3(1 − α′)) (Jensen et al. 2001, §2.4), α′ capped.
        let diffusion_length =
            chans.map(|c| c.mfp / (3.0 * (1.0 - c.albedo.min(BLENDER_MAX_ALBEDO))).sqrt());
        let scale = diffusion_length.iter().copied().fold(0.0_f64, f64::max);
        Self {
            base_color: chans.map(|c| {
                c.rd_total
                    .unwrap_or_else(|| scatterfit_optics::dipole::rd_total(c.albedo, params.eta))
            }),
            subsurface_radius: diffusion_length.map(|l| l / scale),
            subsurface_scale: scale,
            diffusion_length,
            mfp,
            ior: params.eta,
        }
    }
}

/// A Blender (≥ 4.0) Python script that creates or updates the material named after the sample with a
/// Principled BSDF set to [`BlenderValues`] (Cycles Random Walk (Skin)); its docstring holds the values as a
/// Markdown table and the mapping in words. Run it with `blender --python FILE` or from the Text Editor.
pub fn blender_script(params: &RendererParameters, v: &BlenderValues) -> String {
    let u = params.unit.symbol();
    let chans = params.channels.as_array();
    let name_literal = python_string(&params.name);
    let triple = |x: [f64; 3]| format!("({}, {}, {})", py_num(x[0]), py_num(x[1]), py_num(x[2]));
    let mut rows = String::new();
    for (k, label) in ["R", "G", "B"].iter().enumerate() {
        rows.push_str(&format!(
            "| {label} | {} | {} | {} | {} | {} | {} |\n",
            num(v.base_color[k]),
            num(v.diffusion_length[k]),
            num(v.subsurface_radius[k]),
            num(v.mfp[k]),
            num(chans[k].sigma_a),
            num(chans[k].sigma_s),
        ));
    }
    format!(
        r#""""scatterfit export for Blender (Cycles, Principled BSDF, Blender 4.0 or newer): {title}

{provenance}
Scene unit: 1 Blender unit = 1 {u}. Run with `blender --python THIS.py` or from the Text Editor;
it creates (or updates) the material and leaves assigning it to objects to you.

| channel | Base Color = Rd (linear sRGB) | 1/sigma_tr [{u}] | Subsurface Radius | 1/sigma_t' [{u}] | sigma_a [1/{u}] | sigma_s' [1/{u}] |
|---|---|---|---|---|---|---|
{rows}
Subsurface Scale = {scale} {u} (the largest diffusion length 1/sigma_tr); IOR = Subsurface IOR = eta =
{ior} (relative to air). Subsurface Weight = 1, Subsurface Anisotropy = 0, Roughness = 0 (smooth),
method Random Walk (Skin).

Mapping: in Random Walk (Skin) mode Cycles reads Subsurface Radius * Scale as the diffusion length
1/sigma_tr and recovers the mean free path 1/sigma_t' from it with the classical dipole's albedo of
Base Color and Subsurface IOR (Jensen et al. 2001) - exactly scatterfit's sigma_t' when the result's
albedo model is the dipole. Base Color is the measured diffuse reflectance Rd.
Approximate: Cycles derives the walk's single-scattering albedo from Base Color with its own fit
(Chiang, Kutz & Burley 2016), lower than exact transport behind a Fresnel boundary needs; measured with
Blender 4.2, renders come out 6-9 % darker in total reflectance and less translucent (the glow beyond
a shadow edge decays 1.25-1.7x faster) than the measured material. For exact transport use the Mitsuba
or pbrt volumetric export.
"""

import bpy

VALUES = {{
    "material": {name_literal},
    "base_color": {base},
    "subsurface_radius": {radius},
    "subsurface_scale": {scale},
    "ior": {ior},
}}


def apply(values=VALUES):
    """Creates or updates the material `values["material"]` and returns it."""
    mat = bpy.data.materials.get(values["material"]) or bpy.data.materials.new(values["material"])
    mat.use_nodes = True
    nodes = mat.node_tree.nodes
    bsdf = next((n for n in nodes if n.type == "BSDF_PRINCIPLED"), None)
    if bsdf is None:
        bsdf = nodes.new("ShaderNodeBsdfPrincipled")
        out = next((n for n in nodes if n.type == "OUTPUT_MATERIAL"), None) or nodes.new(
            "ShaderNodeOutputMaterial"
        )
        mat.node_tree.links.new(bsdf.outputs["BSDF"], out.inputs["Surface"])
    if "Subsurface Weight" not in bsdf.inputs:
        raise RuntimeError(
            "this script needs Blender 4.0 or newer (Principled BSDF with Subsurface Weight/Scale)"
        )
    bsdf.subsurface_method = "RANDOM_WALK_SKIN"
    settings = {{
        "Base Color": (*values["base_color"], 1.0),
        "Subsurface Weight": 1.0,
        "Subsurface Radius": values["subsurface_radius"],
        "Subsurface Scale": values["subsurface_scale"],
        "Subsurface IOR": values["ior"],
        "Subsurface Anisotropy": 0.0,
        "IOR": values["ior"],
        "Roughness": 0.0,
        "Metallic": 0.0,
    }}
    for socket, value in settings.items():
        bsdf.inputs[socket].default_value = value
    return mat


if __name__ == "__main__":
    print("scatterfit: material", repr(apply().name), "set")
"#,
        title = python_docstring_text(&format!("\"{}\"", params.name)),
        provenance = python_docstring_text(&provenance_line(params)),
        base = triple(v.base_color),
        radius = triple(v.subsurface_radius),
        scale = py_num(v.subsurface_scale),
        ior = py_num(v.ior),
    )
}

/// [`num`] as a Python float literal (`1.0`, not `1`).
fn py_num(x: f64) -> String {
    let s = num(x);
    if s.contains(['.', 'e']) {
        s
    } else {
        format!("{s}.0")
    }
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
    for (label, c) in ["R", "G", "B"].iter().zip(params.channels.as_array()) {
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

/// A name safe inside a pbrt double-quoted string and comment: `"` and `\` become `'` and `/`,
/// control characters spaces.
fn pbrt_string(name: &str) -> String {
    name.chars()
        .map(|c| match c {
            '"' => '\'',
            '\\' => '/',
            c if c.is_control() => ' ',
            c => c,
        })
        .collect()
}

/// Text safe inside an XML comment: no `--` (forbidden there) and no control characters but newlines.
fn xml_comment(text: &str) -> String {
    let mut s: String = text
        .chars()
        .map(|c| if c.is_control() && c != '\n' { ' ' } else { c })
        .collect();
    while s.contains("--") {
        s = s.replace("--", "- -");
    }
    s
}

/// A Python string literal for `text` (JSON string syntax is valid Python for these characters).
fn python_string(text: &str) -> String {
    serde_json::to_string(text).unwrap_or_else(|_| "\"material\"".into())
}

/// Text safe inside a Python triple-quoted docstring: no `"""`, no backslashes, no control characters.
fn python_docstring_text(text: &str) -> String {
    let s: String = text
        .chars()
        .map(|c| match c {
            '\\' => '/',
            c if c.is_control() => ' ',
            c => c,
        })
        .collect();
    s.replace("\"\"\"", "'''")
}

#[cfg(test)]
mod tests {
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
        }
    }

    /// Jensen et al. 2001's marble (pbrt's table, physics.md §1.5): σ′s = 2.19, 2.62, 3.00 and
    /// σa = 0.0021, 0.0041, 0.0071 mm⁻¹; Rd at η = 1.5 from physics.md's computed column.
    fn marble() -> MeasurementResult {
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

    const SP: [f64; 3] = [2.19, 2.62, 3.00];
    const SA: [f64; 3] = [0.0021, 0.0041, 0.0071];

    fn close(a: f64, b: f64, rel: f64) -> bool {
        (a - b).abs() <= rel * b.abs().max(1e-300)
    }

    /// The numbers in `[ a b c ]` after `"<key>"` in pbrt text (first occurrence).
    fn pbrt_values(text: &str, key: &str) -> Vec<f64> {
        let at = text.find(&format!("\"{key}\"")).expect(key);
        let rest = &text[at..];
        let open = rest.find('[').unwrap();
        let close = rest.find(']').unwrap();
        rest[open + 1..close]
            .split_whitespace()
            .map(|t| t.trim_matches('"').parse().unwrap())
            .collect()
    }

    #[test]
    fn pbrt_writes_coefficients_per_scene_unit() {
        let r = marble();
        for (unit, k) in [(SceneUnit::Millimetre, 1.0), (SceneUnit::Metre, 1000.0)] {
            let text = export(&r, Format::Pbrt, unit).unwrap().text;
            let sa = pbrt_values(&text, "rgb sigma_a");
            let ss = pbrt_values(&text, "rgb sigma_s");
            for c in 0..3 {
                assert!(close(sa[c], SA[c] * k, 1e-6), "{text}");
                assert!(close(ss[c], SP[c] * k, 1e-6), "{text}");
            }
            assert_eq!(pbrt_values(&text, "float eta"), vec![1.5]);
            assert_eq!(pbrt_values(&text, "float g"), vec![0.0]);
            assert_eq!(pbrt_values(&text, "float scale"), vec![1.0]);
            assert!(
                text.contains(
                    "MakeNamedMaterial \"marble\"\n    \"string type\" [ \"subsurface\" ]"
                )
            );
            assert!(text.contains("\"string type\" [ \"homogeneous\" ]"));
            assert!(text.contains(&format!("1 scene unit = 1 {}", unit.symbol())));
            // Every non-comment line is a directive or a parameter: nothing stray.
            for line in text.lines().filter(|l| !l.trim().is_empty()) {
                let t = line.trim_start();
                assert!(
                    t.starts_with('#') || t.starts_with("Make") || t.starts_with('"'),
                    "{line}"
                );
            }
        }
    }

    /// The Mitsuba medium must give back σt = σa + σ′s and α = σ′s/σt per channel through
    /// `scale · rgb(sigma_t)`, with the RGB within [0, 1].
    #[test]
    fn mitsuba_medium_reproduces_the_coefficients() {
        let r = marble();
        for (unit, k) in [(SceneUnit::Millimetre, 1.0), (SceneUnit::Metre, 1000.0)] {
            let text = export(&r, Format::Mitsuba, unit).unwrap().text;
            let doc = roxmltree::Document::parse(&text).expect("well-formed XML");
            let medium = doc
                .descendants()
                .find(|n| n.has_tag_name("medium"))
                .unwrap();
            assert_eq!(medium.attribute("type"), Some("homogeneous"));
            assert_eq!(medium.attribute("id"), Some("marble_medium"));
            let value = |tag: &str, name: &str| -> Vec<f64> {
                medium
                    .descendants()
                    .find(|n| n.has_tag_name(tag) && n.attribute("name") == Some(name))
                    .unwrap()
                    .attribute("value")
                    .unwrap()
                    .split(',')
                    .map(|t| t.trim().parse().unwrap())
                    .collect()
            };
            let rgb = value("rgb", "sigma_t");
            let scale = value("float", "scale")[0];
            let albedo = value("rgb", "albedo");
            for c in 0..3 {
                assert!((0.0..=1.0).contains(&rgb[c]));
                assert!(close(scale * rgb[c], (SP[c] + SA[c]) * k, 2e-6));
                assert!(close(albedo[c], SP[c] / (SP[c] + SA[c]), 1e-6));
            }
            assert_eq!(value("float", "g"), vec![0.0]);
            let bsdf = doc.descendants().find(|n| n.has_tag_name("bsdf")).unwrap();
            assert_eq!(bsdf.attribute("type"), Some("dielectric"));
            assert_eq!(bsdf.attribute("id"), Some("marble_boundary"));
            let ior = |name: &str| {
                bsdf.children()
                    .find(|n| n.attribute("name") == Some(name))
                    .unwrap()
                    .attribute("value")
                    .unwrap()
                    .to_string()
            };
            assert_eq!(ior("int_ior"), "1.5");
            // α′ = 0.999042 (R): ln(1e-3)/ln(α′) = 7207.6.
            assert!(text.contains("rr_depth 7208"), "{text}");
            assert_eq!(ior("ext_ior"), "1");
        }
    }

    /// Blender: radius · scale = 1/σtr in scene units (physics.md §1.5: the marble's 1/σtr is 8.509,
    /// 5.566, 3.951 mm), base colour = the measured Rd.
    #[test]
    fn blender_values_and_script() {
        let r = marble();
        for (unit, k) in [(SceneUnit::Millimetre, 1.0), (SceneUnit::Metre, 1000.0)] {
            let (p, _) = RendererParameters::from_result(&r, unit).unwrap();
            let v = BlenderValues::new(&p);
            for (c, want_mm) in [8.509, 5.566, 3.951].into_iter().enumerate() {
                let got_mm = v.subsurface_radius[c] * v.subsurface_scale * k;
                assert!((got_mm - want_mm).abs() < 5e-4, "{got_mm}");
                assert!(v.subsurface_radius[c] <= 1.0);
            }
            assert_eq!(v.base_color, [0.8302, 0.7910, 0.7526]);
            let text = export(&r, Format::Blender, unit).unwrap().text;
            assert!(text.contains("\"subsurface_scale\": "));
            assert!(text.contains("bsdf.subsurface_method = \"RANDOM_WALK_SKIN\""));
            assert!(text.contains("\"material\": \"marble\""));
            assert!(text.contains(&format!("1 Blender unit = 1 {}", unit.symbol())));
        }
        // σa = 0: the diffusion length is capped, not infinite.
        let mut r = marble();
        r.channels.g.sigma_a = Some(0.0);
        let (p, _) = RendererParameters::from_result(&r, SceneUnit::Millimetre).unwrap();
        let v = BlenderValues::new(&p);
        assert!(v.subsurface_scale.is_finite());
        assert!(close(
            v.diffusion_length[1],
            1.0 / 2.62 / (3e-6_f64).sqrt(),
            1e-6
        ));
    }

    /// Without rd_total the base colour falls back to the dipole's Rd, with a warning: at the marble's
    /// R channel α′ = 0.999042, η = 1.5, physics.md §1.3 gives 0.83019146.
    #[test]
    fn blender_base_colour_falls_back_to_the_dipole() {
        let mut r = marble();
        r.channels.r.rd_total = None;
        let e = export(&r, Format::Blender, SceneUnit::Millimetre).unwrap();
        assert_eq!(e.warnings.len(), 1, "{:?}", e.warnings);
        assert!(e.warnings[0].contains("channel r"));
        let (p, _) = RendererParameters::from_result(&r, SceneUnit::Millimetre).unwrap();
        assert!((BlenderValues::new(&p).base_color[0] - 0.83019146).abs() < 1e-7);
    }

    /// The JSON round-trips and its quantities are consistent: σt = σa + σs, albedo = σs/σt,
    /// mfp = 1/σt, σtr = √(3σaσt); metres are ×1000 per length⁻¹.
    #[test]
    fn json_is_consistent_and_round_trips() {
        let r = marble();
        let text = export(&r, Format::Json, SceneUnit::Metre).unwrap().text;
        let p: RendererParameters = serde_json::from_str(&text).unwrap();
        assert_eq!(p.format, JSON_FORMAT_TAG);
        assert_eq!(p.unit, SceneUnit::Metre);
        assert!(text.contains("\"unit\": \"m\""));
        for (c, ch) in p.channels.as_array().iter().enumerate() {
            assert!(close(ch.sigma_a, SA[c] * 1000.0, 1e-12));
            assert!(close(ch.sigma_s, SP[c] * 1000.0, 1e-12));
            assert!(close(ch.sigma_t, ch.sigma_a + ch.sigma_s, 1e-12));
            assert!(close(ch.albedo, SP[c] / (SP[c] + SA[c]), 1e-12));
            assert!(close(ch.mfp * ch.sigma_t, 1.0, 1e-12));
            assert!(close(
                ch.sigma_tr,
                (3.0 * ch.sigma_a * ch.sigma_t).sqrt(),
                1e-12
            ));
        }
        // physics.md §1.5: the marble's 1/σtr is 8.509, 5.566, 3.951 mm.
        let (mm, _) = RendererParameters::from_result(&r, SceneUnit::Millimetre).unwrap();
        for (ch, want) in mm.channels.as_array().iter().zip([8.509, 5.566, 3.951]) {
            assert!((ch.diffusion_length.unwrap() - want).abs() < 5e-4);
        }
    }

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
