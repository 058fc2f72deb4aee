//! The Mitsuba 3 export ([`Format::Mitsuba`](super::Format::Mitsuba)): a scene fragment with a
//! `dielectric` boundary and a `homogeneous` medium.

use super::{
    RendererParameters, channel_table_comment, identifier, joined, largest, num, provenance_line,
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
    let id = identifier(&params.name);
    let u = params.unit.symbol();
    let chans = params.channels.as_array();
    let scale = largest(chans.map(|c| c.sigma_t));
    let rgb = |v: [f64; 3]| joined(v, num, ", ");
    let sigma_t_rgb = rgb(chans.map(|c| c.sigma_t / scale));
    let albedo_rgb = rgb(chans.map(|c| c.albedo));
    let rr = roulette_depth(largest(chans.map(|c| c.albedo)));
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

#[cfg(test)]
mod tests {
    use super::super::fixtures::{SA, SP, close, marble};
    use super::super::{Format, SceneUnit, export};

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
}
