//! The Blender export ([`Format::Blender`](super::Format::Blender)): a bpy script setting a Principled
//! BSDF (Cycles Random Walk (Skin)); [`BlenderValues`] documents the mapping and where it is
//! approximate.

use super::{
    CHANNEL_LABELS, CHANNEL_NAMES, MaterialNames, Renderer, RendererParameters, joined, largest,
    model_header, num, provenance_line, python_docstring_text, python_literal,
};

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
/// - **Subsurface Radius · Subsurface Scale = ℓ = (1/σ′t)/√(3(1 − α′d))** per channel, where α′d is
///   the classical dipole's albedo of Base Color at η (`scatterfit_optics::dipole::albedo_from_rd`,
///   the inversion Cycles itself makes): Cycles then recovers exactly our mean free path 1/σ′t,
///   whatever the result's albedo model. For a result whose α′ came from the dipole (α′d = α′) this is
///   the diffusion length 1/σtr = 1/√(3σaσ′t). (α′d is capped at [`BLENDER_MAX_ALBEDO`].) The radius is
///   written normalised to a largest component of 1 and its magnitude, in scene units, is the
///   Subsurface Scale — Blender's own split (a colour-like radius and a distance). 1/σ′t itself would
///   be the wrong length here: Cycles would read it as a diffusion length √(3(1 − α′)) times too short
///   (18× at α′ = 0.999).
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
    /// The length Cycles reads as the diffusion length, ℓ = (1/σ′t)/√(3(1 − α′d)) per channel [scene
    /// units] (= radius · scale; 1/σtr for a dipole-albedo result).
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
        let base_color = chans.map(|c| {
            c.rd_total
                .unwrap_or_else(|| scatterfit_optics::dipole::rd_total(c.albedo, params.eta))
        });
        // α′d: the classical dipole's albedo of Base Color, as Cycles inverts it (Jensen et al. 2001,
        // eq. 5 with the Fdr polynomial); the channel's α′ where Rd cannot be inverted (Rd = 0).
        let alpha_d = [0, 1, 2].map(|k| {
            scatterfit_optics::dipole::albedo_from_rd(base_color[k], params.eta)
                .unwrap_or(chans[k].albedo)
                .min(BLENDER_MAX_ALBEDO)
        });
        // ℓ = (1/σ′t)/√(3(1 − α′d)): Cycles' 1/σ′t = ℓ √(3(1 − α′d)) is then ours.
        let diffusion_length = [0, 1, 2].map(|k| mfp[k] / (3.0 * (1.0 - alpha_d[k])).sqrt());
        let scale = largest(diffusion_length);
        Self {
            base_color,
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
    let names = MaterialNames::new(&params.name);
    let triple = |x: [f64; 3]| format!("({})", joined(x, py_num, ", "));
    let mut rows = String::new();
    for (k, label) in CHANNEL_LABELS.iter().enumerate() {
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
    let model_notes: String = model_header(params, &[Renderer::Cycles])
        .iter()
        .map(|l| super::wrap(&python_docstring_text(l), 100) + "\n")
        .collect();
    format!(
        r#""""scatterfit export for Blender (Cycles, Principled BSDF, Blender 4.0 or newer): {title}

{provenance}
Scene unit: 1 Blender unit = 1 {u}. Run with `blender --python THIS.py` or from the Text Editor;
it creates (or updates) the material {blender_name} and leaves assigning it to objects to you.

| channel | Base Color = Rd (linear sRGB) | radius * scale [{u}] | Subsurface Radius | 1/sigma_t' [{u}] | sigma_a [1/{u}] | sigma_s' [1/{u}] |
|---|---|---|---|---|---|---|
{rows}
Subsurface Scale = {scale} {u}; IOR = Subsurface IOR = eta = {ior} (relative to air).
Subsurface Weight = 1, Subsurface Anisotropy = 0, Roughness = 0 (smooth), method Random Walk (Skin).

Mapping: in Random Walk (Skin) mode Cycles reads Subsurface Radius * Scale as a diffusion length and
recovers the mean free path 1/sigma_t' from it with the classical dipole's albedo of Base Color and
Subsurface IOR (Jensen et al. 2001); the radius is chosen so that this gives scatterfit's 1/sigma_t'
(for a result whose albedo came from the dipole it is the diffusion length 1/sigma_tr). Base Color
is the measured diffuse reflectance Rd.
Approximate: Cycles derives the walk's single-scattering albedo from Base Color with its own fit
(Chiang, Kutz & Burley 2016), lower than exact transport behind a Fresnel boundary needs; measured with
Blender 4.2 and 5.0, renders come out 6-9 % darker in total reflectance at eta 1.4 (albedos 0.8-0.95),
1-13 % darker for the demo's seven materials (11-13 % at eta 1.9-2.4), and less translucent (the glow
beyond a shadow edge decays 1.25-1.7x faster) than the measured material. Base Color carries the
colour, so this holds whatever model the result was measured with. For exact transport use the
Mitsuba or pbrt volumetric export.
{model_notes}"""

import bpy

VALUES = {{
    "material": {material},
    "name": {full_name},
    "base_color": {base},
    "subsurface_radius": {radius},
    "subsurface_scale": {scale},
    "ior": {ior},
}}


def apply(values=VALUES):
    """Creates or updates the material `values["material"]` and returns it."""
    mat = bpy.data.materials.get(values["material"]) or bpy.data.materials.new(values["material"])
    if bpy.app.version < (5, 0, 0):
        # Blender 5.0 deprecates Material.use_nodes (removed in 6.0): materials always use nodes.
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
        title = python_docstring_text(&format!("\"{}\"", names.display)),
        provenance = python_docstring_text(&provenance_line(params)),
        blender_name = python_docstring_text(&format!("\"{}\"", names.blender)),
        material = python_literal(&names.blender),
        full_name = python_literal(&params.name),
        base = triple(v.base_color),
        radius = triple(v.subsurface_radius),
        scale = py_num(v.subsurface_scale),
        ior = py_num(v.ior),
    )
}

/// A warning for each channel without `rd_total` in the result, whose base colour [`BlenderValues`]
/// takes from the classical dipole instead.
pub(super) fn base_colour_warnings(params: &RendererParameters) -> Vec<String> {
    let mut warnings = Vec::new();
    for (name, c) in CHANNEL_NAMES.iter().zip(params.channels.as_array()) {
        if c.rd_total.is_none() {
            warnings.push(format!(
                "channel {name} has no rd_total in the result: its Blender base colour is the \
                 classical dipole's Rd(α′ = {:.4}, η) instead of the measured one",
                c.albedo
            ));
        }
    }
    warnings
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

#[cfg(test)]
mod tests {
    use super::super::fixtures::{SA, SP, close, marble};
    use super::super::{Format, SceneUnit, export};
    use super::*;

    /// Blender: radius · scale = 1/σtr in scene units for a result whose Rd is the dipole's
    /// (docs/physics.md §1.5: the marble's 1/σtr is 8.509, 5.566, 3.951 mm; its Rd is the dipole's
    /// at η = 1.5 to 4 digits), base colour = the measured Rd.
    #[test]
    fn blender_values_and_script() {
        let mut r = marble();
        for (k, c) in [&mut r.channels.r, &mut r.channels.g, &mut r.channels.b]
            .into_iter()
            .enumerate()
        {
            c.rd_total = Some(scatterfit_optics::dipole::rd_total(
                SP[k] / (SP[k] + SA[k]),
                1.5,
            ));
        }
        for (unit, k) in [(SceneUnit::Millimetre, 1.0), (SceneUnit::Metre, 1000.0)] {
            let (p, _) = RendererParameters::from_result(&r, unit).unwrap();
            let v = BlenderValues::new(&p);
            for (c, want_mm) in [8.509, 5.566, 3.951].into_iter().enumerate() {
                let got_mm = v.subsurface_radius[c] * v.subsurface_scale * k;
                assert!((got_mm - want_mm).abs() < 5e-4, "{got_mm}");
                let sigma_tr = (3.0 * SA[c] * (SA[c] + SP[c])).sqrt();
                assert!(close(got_mm, 1.0 / sigma_tr, 1e-9), "{got_mm}");
                assert!(v.subsurface_radius[c] <= 1.0);
            }
            assert_eq!(v.base_color, p.per_channel(|c| c.rd_total.unwrap()));
            let text = export(&r, Format::Blender, unit).unwrap().text;
            assert!(text.contains("\"subsurface_scale\": "));
            assert!(text.contains("bsdf.subsurface_method = \"RANDOM_WALK_SKIN\""));
            assert!(text.contains("\"material\": \"marble\""));
            assert!(text.contains("if bpy.app.version < (5, 0, 0):"), "{text}");
            assert!(text.contains(&format!("1 Blender unit = 1 {}", unit.symbol())));
        }
        // σa = 0: the length comes from Base Color's dipole albedo, finite.
        let mut r = marble();
        r.channels.g.sigma_a = Some(scatterfit_optics::Estimate {
            value: 0.0,
            ..r.channels.g.sigma_a.unwrap_or_default()
        });
        let (p, _) = RendererParameters::from_result(&r, SceneUnit::Millimetre).unwrap();
        let v = BlenderValues::new(&p);
        assert!(v.subsurface_scale.is_finite());
        let alpha_d = scatterfit_optics::dipole::albedo_from_rd(0.7910, 1.5).unwrap();
        assert!(close(
            v.diffusion_length[1],
            1.0 / 2.62 / (3.0 * (1.0 - alpha_d)).sqrt(),
            1e-9
        ));
        // A black channel (Rd = 0) and σa = 0 with Rd = 1: still finite.
        r.channels.g.rd_total = Some(1.0);
        r.channels.b.rd_total = Some(0.0);
        let (p, _) = RendererParameters::from_result(&r, SceneUnit::Millimetre).unwrap();
        let v = BlenderValues::new(&p);
        assert!(v.diffusion_length.iter().all(|l| l.is_finite() && *l > 0.0));
    }

    /// Cycles' own inversion: with Base Color = Rd and radius · scale = ℓ, Cycles sets 1/σ′t =
    /// ℓ √(3(1 − α′d(Rd))); that must be the result's 1/σ′t for any albedo model (here an α′ whose Rd
    /// is not the dipole's, as `albedo_model = mc` gives).
    #[test]
    fn cycles_recovers_our_mean_free_path() {
        let mut r = marble();
        r.channels.r.rd_total = Some(0.6);
        let (p, _) = RendererParameters::from_result(&r, SceneUnit::Millimetre).unwrap();
        let v = BlenderValues::new(&p);
        for k in 0..3 {
            let a = scatterfit_optics::dipole::albedo_from_rd(v.base_color[k], 1.5).unwrap();
            let mfp = v.diffusion_length[k] * (3.0 * (1.0 - a)).sqrt();
            assert!(close(mfp, 1.0 / (SA[k] + SP[k]), 1e-12), "{k}");
        }
    }

    /// Blender names: the name itself when clean, a hashed one within 63 bytes otherwise, written as
    /// an ASCII Python literal.
    #[test]
    fn blender_names_fit_and_stay_apart() {
        let long = "é".repeat(40);
        let mut r = marble();
        r.name = long.clone();
        let text = export(&r, Format::Blender, SceneUnit::Millimetre)
            .unwrap()
            .text;
        let names = MaterialNames::new(&long);
        assert!(names.blender.len() <= 63, "{}", names.blender);
        assert!(
            names
                .blender
                .ends_with(&format!(" #{}", super::super::name_hash(&long)))
        );
        assert!(text.contains(&format!("\"material\": {}", python_literal(&names.blender))));
        assert!(text.is_ascii() || !text.contains("\"material\": \"é"));
        assert_eq!(MaterialNames::new("marble").blender, "marble");
        // A clean name that looks hashed gets its own hash: it cannot take another's material.
        let tricky = format!("x #{}", super::super::name_hash("x\n"));
        assert_ne!(
            MaterialNames::new(&tricky).blender,
            MaterialNames::new("x\n").blender
        );
    }

    /// Without rd_total the base colour falls back to the dipole's Rd, with a warning: at the marble's
    /// R channel α′ = 0.999042, η = 1.5, docs/physics.md §1.3 gives 0.83019146.
    #[test]
    fn blender_base_colour_falls_back_to_the_dipole() {
        let mut r = marble();
        r.channels.r.rd_total = None;
        let e = export(&r, Format::Blender, SceneUnit::Millimetre).unwrap();
        let w: Vec<&String> = e
            .warnings
            .iter()
            .filter(|w| w.contains("rd_total"))
            .collect();
        assert_eq!(w.len(), 1, "{:?}", e.warnings);
        assert!(w[0].contains("channel r"));
        let (p, _) = RendererParameters::from_result(&r, SceneUnit::Millimetre).unwrap();
        assert!((BlenderValues::new(&p).base_color[0] - 0.83019146).abs() < 1e-7);
    }
}
