//! The Mitsuba 3 export ([`Format::Mitsuba`](super::Format::Mitsuba)): a scene fragment with a
//! `dielectric` boundary and a `homogeneous` medium.

use super::{
    MaterialNames, Renderer, RendererParameters, channel_table_comment, joined, largest,
    model_header, num, provenance_line, wrap, xml_comment,
};

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
    mitsuba_fragment_for(params, MitsubaVariant::Rgb)
}

/// Which of Mitsuba's variants a fragment is for: it decides the medium `<id>_medium` holds
/// (`--mitsuba-variant`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[non_exhaustive]
pub enum MitsubaVariant {
    /// RGB variants (`scalar_rgb`, `llvm_ad_rgb`, …): the channels' coefficients as RGB.
    #[default]
    #[cfg_attr(feature = "clap", value(help = "RGB variants"))]
    Rgb,
    /// Spectral variants (`scalar_spectral`, …): the medium per wavelength from the measured spectrum
    /// ([`RendererParameters::spectral_medium`]); the RGB medium when the result has no spectrum.
    #[cfg_attr(feature = "clap", value(help = "Spectral variants"))]
    Spectral,
}

/// [`mitsuba_fragment`] for `variant`'s kind of Mitsuba.
pub fn mitsuba_fragment_for(params: &RendererParameters, variant: MitsubaVariant) -> String {
    let spectral = variant == MitsubaVariant::Spectral && params.spectral_medium.is_some();
    let names = MaterialNames::new(&params.name);
    let id = &names.id;
    let u = params.unit.symbol();
    let chans = params.channels.as_array();
    let rr = roulette_depth(largest(chans.map(|c| c.albedo)));
    let mfp = num(shortest_mfp(params));
    let offset_fraction = ray_offset_fraction(params);
    let mut s = String::from("<?xml version=\"1.0\" encoding=\"utf-8\"?>\n<!--\n");
    let mut header = format!(
        "  scatterfit export for Mitsuba 3: \"{display}\"\n\
         \x20 {provenance}\n\
         \x20 Scene unit: 1 scene unit = 1 {u}. The medium's extinction is sigma_t = scale * rgb(sigma_t) per\n\
         \x20 {u}: the colour is normalised to a largest component of 1 (RGB values must lie in [0, 1] in\n\
         \x20 spectral variants) and its magnitude is `scale`. For a scene in another unit multiply `scale` by\n\
         \x20 the length of that unit in {u}.\n\
         \x20 albedo = sigma_s / sigma_t with sigma_s the measured reduced scattering coefficient sigma_s'\n\
         \x20 and an isotropic phase function (g = 0): the measurement gives sigma_s' = sigma_s (1 - g) only,\n\
         \x20 and a diffusive material looks the same for every (sigma_s, g) with that sigma_s'.\n\
         \x20 Channels are linear sRGB. eta is relative to air; the boundary is smooth.\n\n",
        display = names.display,
        provenance = provenance_line(params),
    );
    for line in model_header(params, &[Renderer::MitsubaVolpath]) {
        header.push_str("  ");
        header.push_str(&line);
        header.push('\n');
    }
    header.push('\n');
    s.push_str(&xml_comment(&wrap(&header, 100)));
    s.push_str(&xml_comment(&channel_table_comment(params, "  ")));
    s.push_str(&xml_comment(&wrap(&format!(
        "\n  HOW TO USE. Include this file in a scene (its ids are unique to this material's name, so\n\
         \x20 several materials' fragments can be included in one scene) and give a shape both refs:\n\
         \x20   <include filename=\"this-file.xml\"/>\n\
         \x20   <shape type=\"...\">\n\
         \x20       <ref id=\"{id}_boundary\"/>\n\
         \x20       <ref name=\"interior\" id=\"{id}_medium\"/>\n\
         \x20   </shape>\n\
         \x20 Rendered so, with this fragment's variant kind, materials measured with the mc model showed \
         their measured reflectance within 3 % (the demo's seven materials, BENCHMARKS.md).\n\
         \x20 Integrator: volpathmis with max_depth -1 and rr_depth {rr}:\n\
         \x20   <integrator type=\"volpathmis\"><integer name=\"max_depth\" value=\"-1\"/>\n\
         \x20       <integer name=\"rr_depth\" value=\"{rr}\"/></integrator>\n\
         \x20 (volpathmis, not volpath: volpath samples distances with one channel's sigma_t, which in a\n\
         \x20 chromatic medium leaves heavy-tailed weights on long paths — skin R 4.5 % low at 8192 spp,\n\
         \x20 marble B 19 % high at 2048 — where volpathmis's spectral MIS stays within 0.6 %.\n\
         \x20 Russian roulette only once the albedo has taken the throughput below 1e-3: Mitsuba's\n\
         \x20 roulette survival is capped at 0.95 per scattering, which at albedos near 1 leaves the long\n\
         \x20 paths carrying much of the diffuse reflectance to rare, heavy samples: short renders too dark.)\n\
         \x20 LIGHTS: the medium renders BLACK under point, spot and directional emitters: they are delta\n\
         \x20 lights, and no path through the smooth dielectric boundary can connect to them (the medium's\n\
         \x20 sample_emitters is off for the same reason). Light it with area emitters or an environment\n\
         \x20 (constant, envmap); Mitsuba 3 has no BSSRDF material to fall back on.\n\
         \x20 SCENE UNIT AND RAY OFFSETS: Mitsuba offsets every ray leaving a surface by about \
         1e-4 (1 + |p|) scene units (float32 `RayEpsilon`), which shifts the first scattering deeper \
         and darkens the material. Here the shortest mean free path 1/sigma_t is {mfp} {u}; for an \
         object about 1 scene unit from the origin the offset is {pct} of it{verdict}. In metre \
         scenes a 0.2 mm mean free path rendered 17-23 % dark (BENCHMARKS.md): export in \
         millimetres (the default scale) and build the scene in millimetres when you can.\n\
         \x20 SPECTRAL VARIANTS (scalar_spectral, llvm_spectral, ...) turn each RGB into a smooth spectrum;\n\
         \x20 a medium's reflectance is not linear in its coefficients, so a strongly coloured material\n\
         \x20 renders shifted in colour ({shift} per channel for the demo's materials, BENCHMARKS.md);\n\
         \x20 the RGB variants (scalar_rgb, llvm_rgb) render the channels exactly.{spectral_note}\n",
        spectral_note = if spectral {
            "\n\x20 THIS FRAGMENT IS FOR SPECTRAL VARIANTS: its medium is given per wavelength, the albedo\n\
             \x20 inverted from the MEASURED reflectance spectrum with exact transport (within 1 % of the\n\
             \x20 measured colour for the demo's materials), sigma_t' interpolated between the channels.\n\
             \x20 RGB variants render it wrong: export without the spectral variant option for them."
        } else if params.spectral_medium.is_some() {
            "\n\x20 This fragment is for RGB variants; for a spectral variant export it again with the\n\
             \x20 option `mitsuba-variant spectral`: its medium is then given per wavelength from the\n\
             \x20 measured reflectance spectrum and renders the measured colour."
        } else {
            "\n\x20 The result has no measured spectrum (rd_spectrum, written by `scatterfit measure`), so\n\
             \x20 no per-wavelength medium can be written for spectral variants."
        },
        pct = format_percent(offset_fraction),
        verdict = if offset_fraction > 0.01 {
            ": ABOVE 1 %, expect a visibly dark render; use a millimetre scene"
        } else {
            " (negligible)"
        },
        shift = MITSUBA_SPECTRAL_SHIFT,
    ), 100)));
    s.push_str("-->\n");
    let material = mitsuba_material(params, variant);
    s.push_str("<scene version=\"3.0.0\">\n");
    material.boundary.write_xml(&mut s, 1);
    material.medium.write_xml(&mut s, 1);
    s.push_str("</scene>\n");
    s
}

/// The objects a Mitsuba 3 export describes: the boundary, the medium inside it, and the integrator
/// its header recommends. The XML fragment ([`mitsuba_fragment_for`]) writes the first two as
/// elements; [`MitsubaObject::to_dict`] gives each as the dictionary `mitsuba.load_dict` takes.
#[derive(Debug, Clone, PartialEq)]
pub struct MitsubaMaterial {
    /// The `dielectric` BSDF `<id>_boundary`: `int_ior` = η, `ext_ior` = 1.
    pub boundary: MitsubaObject,
    /// The `homogeneous` medium `<id>_medium` (RGB, or per wavelength for spectral variants).
    pub medium: MitsubaObject,
    /// `volpathmis` with unbounded depth and the Russian-roulette depth the albedo needs
    /// ([`roulette_depth`]).
    pub integrator: MitsubaObject,
}

/// One Mitsuba 3 scene object: a plugin instance with its properties, as an XML element and as a
/// `load_dict` dictionary describe it (Mitsuba 3 documentation, "File format" and
/// `mitsuba.load_dict`). Numbers are written as the export writes them (`num`), so the dictionary
/// holds exactly the XML's values.
#[derive(Debug, Clone, PartialEq)]
pub struct MitsubaObject {
    /// The element's tag: `bsdf`, `medium`, `phase` or `integrator`.
    pub tag: &'static str,
    /// The plugin (the element's `type`).
    pub plugin: &'static str,
    /// The id a scene refers to it by.
    pub id: Option<String>,
    /// The properties, in the order they are written; a nested object's name is its tag.
    pub properties: Vec<(&'static str, MitsubaProperty)>,
}

/// A property of a [`MitsubaObject`].
#[derive(Debug, Clone, PartialEq)]
pub enum MitsubaProperty {
    /// `<float>`.
    Float(f64),
    /// `<integer>`.
    Integer(i64),
    /// `<boolean>`.
    Boolean(bool),
    /// `<rgb>`: linear sRGB.
    Rgb([f64; 3]),
    /// `<spectrum>`: (wavelength \[nm\], value) pairs.
    Spectrum(Vec<(f64, f64)>),
    /// A nested object (the medium's phase function).
    Object(MitsubaObject),
}

impl MitsubaObject {
    fn new(tag: &'static str, plugin: &'static str, id: Option<String>) -> Self {
        Self {
            tag,
            plugin,
            id,
            properties: Vec::new(),
        }
    }

    fn with(mut self, name: &'static str, value: MitsubaProperty) -> Self {
        self.properties.push((name, value));
        self
    }

    /// Appends the element to `out`, indented by `depth` × 4 spaces.
    fn write_xml(&self, out: &mut String, depth: usize) {
        let pad = "    ".repeat(depth);
        let id = self
            .id
            .as_ref()
            .map_or_else(String::new, |id| format!(" id=\"{id}\""));
        out.push_str(&format!(
            "{pad}<{} type=\"{}\"{id}>\n",
            self.tag, self.plugin
        ));
        let inner = "    ".repeat(depth + 1);
        for (name, value) in &self.properties {
            let (tag, text) = match value {
                MitsubaProperty::Float(x) => ("float", num(*x)),
                MitsubaProperty::Integer(n) => ("integer", n.to_string()),
                MitsubaProperty::Boolean(b) => ("boolean", b.to_string()),
                MitsubaProperty::Rgb(v) => ("rgb", joined(*v, num, ", ")),
                MitsubaProperty::Spectrum(pairs) => (
                    "spectrum",
                    pairs
                        .iter()
                        .map(|(l, x)| format!("{}:{}", num(*l), num(*x)))
                        .collect::<Vec<_>>()
                        .join(", "),
                ),
                MitsubaProperty::Object(o) => {
                    o.write_xml(out, depth + 1);
                    continue;
                }
            };
            out.push_str(&format!(
                "{inner}<{tag} name=\"{name}\" value=\"{text}\"/>\n"
            ));
        }
        out.push_str(&format!("{pad}</{}>\n", self.tag));
    }

    /// The object as the dictionary `mitsuba.load_dict` takes: `{"type": plugin, name: value,
    /// …}`, an RGB as `{"type": "rgb", "value": [r, g, b]}`, a spectrum as `{"type": "spectrum",
    /// "value": [[λ, v], …]}`, a nested object under its tag. The id is left out (a dictionary
    /// nests the object where it is used).
    #[must_use]
    pub fn to_dict(&self) -> serde_json::Value {
        use serde_json::{Value, json};
        // The number as the XML writes it.
        let n = |x: f64| -> Value {
            num(x)
                .parse::<f64>()
                .ok()
                .and_then(serde_json::Number::from_f64)
                .map_or(Value::Null, Value::Number)
        };
        let mut d = serde_json::Map::new();
        d.insert("type".into(), json!(self.plugin));
        for (name, value) in &self.properties {
            let v = match value {
                MitsubaProperty::Float(x) => n(*x),
                MitsubaProperty::Integer(i) => json!(i),
                MitsubaProperty::Boolean(b) => json!(b),
                MitsubaProperty::Rgb(v) => json!({"type": "rgb", "value": v.map(n)}),
                MitsubaProperty::Spectrum(pairs) => json!({
                    "type": "spectrum",
                    "value": pairs.iter().map(|(l, x)| json!([n(*l), n(*x)])).collect::<Vec<_>>(),
                }),
                MitsubaProperty::Object(o) => o.to_dict(),
            };
            d.insert((*name).into(), v);
        }
        Value::Object(d)
    }
}

/// The boundary, the medium and the integrator of the export for `variant`
/// ([`mitsuba_fragment_for`] writes the first two).
#[must_use]
pub fn mitsuba_material(params: &RendererParameters, variant: MitsubaVariant) -> MitsubaMaterial {
    use MitsubaProperty::{Boolean, Float, Integer, Object, Rgb, Spectrum};
    let spectral = variant == MitsubaVariant::Spectral && params.spectral_medium.is_some();
    let id = MaterialNames::new(&params.name).id;
    let chans = params.channels.as_array();
    let boundary = MitsubaObject::new("bsdf", "dielectric", Some(format!("{id}_boundary")))
        .with("int_ior", Float(params.eta))
        .with("ext_ior", Float(1.0));
    let mut medium = MitsubaObject::new("medium", "homogeneous", Some(format!("{id}_medium")));
    medium = match (&params.spectral_medium, spectral) {
        (Some(m), true) => {
            // σt normalised like the RGB one, its magnitude in `scale`.
            let scale = m.sigma_t.iter().copied().fold(0.0_f64, f64::max);
            let pairs = |v: &[f64], k: f64| -> Vec<(f64, f64)> {
                m.wavelength_nm
                    .iter()
                    .zip(v)
                    .map(|(l, x)| (*l, x / k))
                    .collect()
            };
            medium
                .with("sigma_t", Spectrum(pairs(&m.sigma_t, scale)))
                .with("scale", Float(scale))
                .with("albedo", Spectrum(pairs(&m.albedo, 1.0)))
        }
        _ => {
            let scale = largest(chans.map(|c| c.sigma_t));
            medium
                .with("sigma_t", Rgb(chans.map(|c| c.sigma_t / scale)))
                .with("scale", Float(scale))
                .with("albedo", Rgb(chans.map(|c| c.albedo)))
        }
    };
    let medium = medium.with("sample_emitters", Boolean(false)).with(
        "phase",
        Object(MitsubaObject::new("phase", "hg", None).with("g", Float(0.0))),
    );
    let rr = roulette_depth(largest(chans.map(|c| c.albedo)));
    let integrator = MitsubaObject::new("integrator", "volpathmis", None)
        .with("max_depth", Integer(-1))
        .with("rr_depth", Integer(i64::try_from(rr).unwrap_or(i64::MAX)));
    MitsubaMaterial {
        boundary,
        medium,
        integrator,
    }
}

/// The shortest mean free path 1/σt of the channels [scene units].
fn shortest_mfp(params: &RendererParameters) -> f64 {
    params
        .per_channel(|c| c.mfp)
        .into_iter()
        .fold(f64::INFINITY, f64::min)
}

/// Mitsuba's ray-spawn offset for an object about 1 scene unit from the origin, (1 + 1) ·
/// [`RAY_EPSILON`] scene units, as a fraction of the shortest mean free path. Measured (BENCHMARKS.md):
/// a half-space of mean free path 0.2 mm rendered 17–23 % dark in a metre scene (offset 0.45 mean
/// free paths at the origin) and right in a millimetre one.
pub fn ray_offset_fraction(params: &RendererParameters) -> f64 {
    2.0 * RAY_EPSILON / shortest_mfp(params)
}

/// A warning when Mitsuba's ray offset is above 1 % of the shortest mean free path (metre scenes of
/// materials with sub-millimetre mean free paths).
pub(super) fn ray_offset_warning(params: &RendererParameters) -> Option<String> {
    let f = ray_offset_fraction(params);
    (f > 0.01).then(|| {
        format!(
            "in a {} scene Mitsuba offsets rays leaving a surface by about {} {u} (an object 1 {u} \
             from the origin), {} of this material's shortest mean free path ({} {u}): it will render \
             dark (a 0.2 mm mean free path rendered 17-23 % dark in metres); export with --scale mm \
             and build the scene in millimetres",
            params.unit.word(),
            num(2.0 * RAY_EPSILON),
            format_percent(f),
            num(shortest_mfp(params)),
            u = params.unit.symbol(),
        )
    })
}

/// Mitsuba 3's ray-spawn epsilon for float32 variants, `math::RayEpsilon` = 1500 · 2⁻²⁴ (drjit
/// `Epsilon` for float is 2⁻²⁴): rays leaving a surface at p start (1 + max |p_i|) · this further.
pub const RAY_EPSILON: f64 = 1500.0 / 16_777_216.0;

/// What the header says of Mitsuba's spectral shift (measured on the demo's materials,
/// BENCHMARKS.md "exports").
const MITSUBA_SPECTRAL_SHIFT: &str = "+13 % to -42 %";

/// A fraction as a short percentage (`0.03 %`, `12 %`).
fn format_percent(x: f64) -> String {
    let p = 100.0 * x;
    if p >= 10.0 {
        format!("{p:.0} %")
    } else {
        // Two significant digits.
        let digits = (1 - p.log10().floor() as i32).max(0) as usize;
        format!("{p:.digits$} %")
    }
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

#[cfg(test)]
mod tests {
    use super::super::fixtures::{SA, SP, close, marble};
    use super::super::{Format, SceneUnit, export};

    /// The dictionaries `load_dict` takes hold every property the XML fragment writes, with the
    /// same values (read back from the XML text), and the integrator the header recommends.
    #[test]
    fn the_dictionaries_hold_the_fragments_values() {
        let r = marble();
        for unit in [SceneUnit::Millimetre, SceneUnit::Metre] {
            let exported = export(&r, Format::Mitsuba, unit).unwrap();
            let material = exported.mitsuba.expect("the Mitsuba objects");
            let doc = roxmltree::Document::parse(&exported.text).expect("well-formed XML");
            for (tag, object) in [("bsdf", &material.boundary), ("medium", &material.medium)] {
                let element = doc.descendants().find(|n| n.has_tag_name(tag)).unwrap();
                let dict = object.to_dict();
                assert_eq!(dict["type"].as_str(), element.attribute("type"));
                let mut compared = 0;
                for child in element
                    .descendants()
                    .filter(|n| n.attribute("name").is_some())
                {
                    let name = child.attribute("name").unwrap();
                    let text = child.attribute("value").unwrap();
                    // The phase function's properties sit in its own dictionary.
                    let value = if child.parent().is_some_and(|p| p.has_tag_name("phase")) {
                        &dict["phase"][name]
                    } else {
                        &dict[name]
                    };
                    match child.tag_name().name() {
                        "float" => assert_eq!(value.as_f64(), text.parse().ok(), "{name}"),
                        "boolean" => assert_eq!(value.as_bool(), text.parse().ok(), "{name}"),
                        "rgb" => {
                            let xml: Vec<f64> =
                                text.split(',').map(|t| t.trim().parse().unwrap()).collect();
                            let got: Vec<f64> = value["value"]
                                .as_array()
                                .unwrap()
                                .iter()
                                .map(|v| v.as_f64().unwrap())
                                .collect();
                            assert_eq!(value["type"], "rgb");
                            assert_eq!(got, xml, "{name}");
                        }
                        other => panic!("unexpected property <{other}>"),
                    }
                    compared += 1;
                }
                assert!(compared >= 2, "{tag}: {compared} properties compared");
            }
            assert_eq!(material.medium.to_dict()["phase"]["type"], "hg");
            let integrator = material.integrator.to_dict();
            assert_eq!(integrator["type"], "volpathmis");
            assert_eq!(integrator["max_depth"], -1);
            let rr = integrator["rr_depth"].as_i64().unwrap();
            assert!(
                exported
                    .text
                    .contains(&format!("<integer name=\"rr_depth\" value=\"{rr}\"/>")),
                "the header recommends rr_depth {rr}"
            );
        }
    }

    /// The Mitsuba medium must give back σt = σa + σ′s and α = σ′s/σt per channel through
    /// `scale · rgb(sigma_t)`, with the RGB within [0, 1].
    #[test]
    fn mitsuba_medium_reproduces_the_coefficients() {
        let r = marble();
        let id = super::super::identifier("marble");
        for (unit, k) in [(SceneUnit::Millimetre, 1.0), (SceneUnit::Metre, 1000.0)] {
            let text = export(&r, Format::Mitsuba, unit).unwrap().text;
            let doc = roxmltree::Document::parse(&text).expect("well-formed XML");
            let medium = doc
                .descendants()
                .find(|n| n.has_tag_name("medium"))
                .unwrap();
            assert_eq!(medium.attribute("type"), Some("homogeneous"));
            assert_eq!(
                medium.attribute("id"),
                Some(format!("{id}_medium").as_str())
            );
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
            assert_eq!(
                bsdf.attribute("id"),
                Some(format!("{id}_boundary").as_str())
            );
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
}
