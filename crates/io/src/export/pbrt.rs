//! The pbrt-v4 export ([`Format::Pbrt`](super::Format::Pbrt)): a `subsurface` named material and the
//! same coefficients as a `homogeneous` named medium behind a `dielectric` boundary.

use super::{
    ChannelParameters, RendererParameters, SceneUnit, channel_table_comment, joined, num,
    provenance_line,
};

/// A pbrt-v4 scene-file fragment: a `subsurface` named material (pbrt's tabulated photon-beam-diffusion
/// BSSRDF; docs/physics.md §2) and, for pbrt's volumetric path tracer, a `homogeneous` named medium
/// with the same coefficients behind a `dielectric` named material.
///
/// Units: pbrt reads `sigma_a`, `sigma_s` per scene unit and multiplies them by `scale`
/// (pbrt-v4 `SubsurfaceMaterial::GetBSSRDF`, `HomogeneousMedium`); we write them per `params.unit` and
/// `scale` = 1, so a scene in yet another unit sets `scale` to the length of its unit in
/// `params.unit` (e.g. 0.01 for centimetres with coefficients per metre).
pub fn pbrt_material(params: &RendererParameters) -> String {
    let name = pbrt_string(&params.name);
    let u = params.unit.symbol();
    let chans = params.channels.as_array();
    let rgb = |f: fn(&ChannelParameters) -> f64| format!("[ {} ]", joined(chans.map(f), num, " "));
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

#[cfg(test)]
mod tests {
    use super::super::fixtures::{SA, SP, close, marble};
    use super::super::{Format, export};
    use super::*;

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
}
