//! The pbrt-v4 export ([`Format::Pbrt`](super::Format::Pbrt)): `subsurface` named materials (from the
//! measured reflectance and mean free path, and from the coefficients) and the coefficients as a
//! `homogeneous` named medium behind a `dielectric` boundary.

use super::{
    ChannelParameters, MaterialNames, Renderer, RendererParameters, SceneUnit,
    channel_table_comment, joined, largest, model_header, num, one_line, provenance_line, wrap,
};

/// The `maxdepth` pbrt's `volpath` integrator needs for the medium of `params`: the number of
/// scattering events after which a path survives absorption with probability below 10⁻⁶ at the
/// largest albedo, α^N < 10⁻⁶, doubled for the surface events (internal reflections at the
/// dielectric boundary count as depth in pbrt) and at least 100. pbrt ends absorbed paths by itself
/// (its delta tracking terminates a path at an absorption event), so a deep limit costs nothing for
/// the paths that do not need it; pbrt's default of 5 cuts a translucent material's paths, which need
/// hundreds of scatterings (a medium at α′ = 0.99 rendered 76 % too dark). 10⁶ for α = 1.
pub fn pbrt_max_depth(params: &RendererParameters) -> u64 {
    let albedo = largest(params.per_channel(|c| c.albedo));
    if albedo >= 1.0 {
        return 1_000_000;
    }
    let n = (1e-6_f64.ln() / albedo.ln()).ceil();
    (2.0 * n).clamp(100.0, 1e6) as u64
}

/// A pbrt-v4 scene-file fragment to `Include` after `WorldBegin`: three named materials — `"<id>"`, a
/// `subsurface` material from the measured reflectance and mean free path (pbrt inverts its own
/// photon-beam-diffusion BSSRDF per wavelength for the albedo: the measured colour), `"<id>-
/// coefficients"`, the same from σa and σs, and `"<id>-boundary"`, a `dielectric` for the
/// `homogeneous` named medium `"<id>-medium"` (exact transport with the `volpath` integrator). The
/// header gives the integrator line ([`pbrt_max_depth`]), the lights each route works with, what
/// spectral rendering does to the colour, and the model notes.
///
/// Units: pbrt reads `sigma_a`, `sigma_s` per scene unit and multiplies them by `scale`, and
/// multiplies `mfp` by `scale` too (pbrt-v4 `SubsurfaceMaterial::GetBSSRDF`, `HomogeneousMedium`);
/// we write them per `params.unit` and `scale` = 1.
pub fn pbrt_material(params: &RendererParameters) -> String {
    let names = MaterialNames::new(&params.name);
    let id = &names.id;
    let u = params.unit.symbol();
    let chans = params.channels.as_array();
    let rgb = |f: fn(&ChannelParameters) -> f64| format!("[ {} ]", joined(chans.map(f), num, " "));
    let (sigma_a, sigma_s, mfp) = (rgb(|c| c.sigma_a), rgb(|c| c.sigma_s), rgb(|c| c.mfp));
    let reflectance = reflectance_parameter(params);
    let depth = pbrt_max_depth(params);
    let eta = num(params.eta);
    let mut s = String::new();
    let header = format!(
        "scatterfit export for pbrt-v4: \"{display}\"\n\
         {provenance}\n\
         Scene unit: 1 scene unit = 1 {u}. sigma_a, sigma_s are per {u}, mfp in {u}; \"scale\" multiplies\n\
         sigma_a, sigma_s and mfp: keep 1 in a {u} scene (for another unit see the end of this header).\n\
         sigma_s is the measured reduced scattering coefficient sigma_s' with g = 0: the measurement\n\
         gives sigma_s' = sigma_s (1 - g) only, and a diffusive material looks the same for every\n\
         (sigma_s, g) with that sigma_s' (similarity relation); pbrt does the same for its measured media.\n\
         Channels are linear sRGB. eta is relative to air; the boundary is smooth.\n\
         \n\
         HOW TO USE. Include this file INSIDE the world block, i.e. after WorldBegin (MakeNamedMaterial\n\
         and MakeNamedMedium are world-block directives):   Include \"this-file.pbrt\"\n\
         Three routes, by light type:\n\
         1. NamedMaterial \"{id}\": pbrt's subsurface BSSRDF from the measured reflectance and mean free\n\
         \x20  path 1/sigma_t'; pbrt inverts its own diffusion model per wavelength for the albedo, so the\n\
         \x20  rendered colour is the measured one within pbrt's BSSRDF sampling (-0.3 to -2.2 % at\n\
         \x20  eta <= 1.3, down to -11 % at eta 2.4; BENCHMARKS.md), whatever model measured it. Works\n\
         \x20  with every light, point, spot and distant lights included: use it for delta lights.\n\
         2. NamedMaterial \"{id}-coefficients\": the same BSSRDF from sigma_a, sigma_s; its total\n\
         \x20  reflectance is pbrt's diffusion model's for this albedo, not the measured one.\n\
         3. Exact volumetric transport (slower): before WorldBegin write\n\
         \x20    Integrator \"volpath\" \"integer maxdepth\" [ {depth} ]\n\
         \x20  (pbrt's default maxdepth 5 stops a translucent medium's paths after 5 of the hundreds of\n\
         \x20  scatterings it needs: ~80 % too dark and grey. {depth} = 2 ceil(ln 1e-6 / ln albedo_max):\n\
         \x20  absorption ends paths long before it; surface bounces count as depth too), then\n\
         \x20    AttributeBegin\n\
         \x20      MediumInterface \"{id}-medium\" \"\"\n\
         \x20      NamedMaterial \"{id}-boundary\"\n\
         \x20      Shape ...\n\
         \x20    AttributeEnd\n\
         {spectral_route}\
         \x20  The medium renders BLACK under point, spot and distant lights: they are delta lights, and\n\
         \x20  no path through the smooth dielectric boundary can connect to them. Light it with area\n\
         \x20  lights or an infinite (environment) light, or use route 1.\n\
         \n\
         SPECTRAL RENDERING. pbrt renders spectrally: it turns each RGB into a smooth spectrum, and a\n\
         medium's reflectance is not linear in sigma, so a strongly coloured material given by RGB\n\
         coefficients (route 2, and route 3's RGB medium) renders shifted in colour: {shift} per\n\
         channel for the demo's materials (BENCHMARKS.md).{spectral_fix}\n\
         Route 1 uplifts the reflectance itself (a bounded colour pbrt reproduces){spectrum_note}.\n\
         \n",
        spectral_route = if params.spectral_medium.is_some() {
            format!(
                "\x20  \"{id}-medium\" is the medium per wavelength: its albedo inverted from the MEASURED\n\
                 \x20  reflectance spectrum with exact transport, so pbrt renders the material's own spectrum\n\
                 \x20  (within 1 % of the measured colour for the demo's materials); sigma_t' interpolated\n\
                 \x20  between the channels. \"{id}-medium-rgb\" is the RGB one (shifted in colour, below).\n"
            )
        } else {
            String::new()
        },
        display = names.display,
        provenance = provenance_line(params),
        shift = PBRT_SPECTRAL_SHIFT,
        spectral_fix = if params.spectral_medium.is_some() {
            " Route 3's medium here is given per wavelength\nfrom the measured spectrum and does not shift."
        } else {
            " A result with its measured spectrum (rd_spectrum,\nwritten by `scatterfit measure`) gets a medium per wavelength that does not shift."
        },
        spectrum_note = if params.rd_spectrum.is_some() {
            "; here it is the measured spectrum, so pbrt renders the material's own spectrum"
        } else {
            ""
        },
    );
    for line in header.lines() {
        push_comment(&mut s, line);
    }
    for line in model_header(params, &[Renderer::PbrtSubsurface, Renderer::PbrtVolpath]) {
        push_comment(&mut s, &line);
    }
    push_comment(&mut s, "");
    s.push_str(&channel_table_comment(params, "# "));
    push_comment(&mut s, "");
    push_comment(
        &mut s,
        &format!(
            "Another scene unit: set \"scale\" to the length of that unit in {u} (e.g. {}) in every\n\
             material and medium below, and write mfp's route-1 \"scale\" as its inverse.",
            match params.unit {
                SceneUnit::Millimetre => "10 for centimetres, 1000 for metres",
                SceneUnit::Metre => "0.01 for centimetres, 0.001 for millimetres",
            }
        ),
    );
    s.push('\n');
    let main_is_reflectance = reflectance.is_some();
    if let Some(refl) = &reflectance {
        s.push_str(&format!(
            "MakeNamedMaterial \"{id}\"\n    \"string type\" [ \"subsurface\" ]\n    {refl}\n    \
             \"rgb mfp\" {mfp}\n    \"float scale\" [ 1 ]\n    \"float eta\" [ {eta} ]\n    \
             \"float g\" [ 0 ]\n\n"
        ));
    } else {
        push_comment(
            &mut s,
            "(No measured reflectance in the result: route 1 is the coefficients' material.)",
        );
    }
    let coefficient_names: Vec<String> = if main_is_reflectance {
        vec![format!("{id}-coefficients")]
    } else {
        vec![id.clone(), format!("{id}-coefficients")]
    };
    for name in coefficient_names {
        s.push_str(&format!(
            "MakeNamedMaterial \"{name}\"\n    \"string type\" [ \"subsurface\" ]\n    \
             \"rgb sigma_a\" {sigma_a}\n    \"rgb sigma_s\" {sigma_s}\n    \"float scale\" [ 1 ]\n    \
             \"float eta\" [ {eta} ]\n    \"float g\" [ 0 ]\n\n"
        ));
    }
    if let Some(m) = &params.spectral_medium {
        let pairs = |v: &[f64]| -> String {
            m.wavelength_nm
                .iter()
                .zip(v)
                .map(|(l, x)| format!("{} {}", num(*l), num(*x)))
                .collect::<Vec<_>>()
                .join(" ")
        };
        let sa: Vec<f64> = m
            .sigma_t
            .iter()
            .zip(&m.albedo)
            .map(|(t, a)| t * (1.0 - a))
            .collect();
        let ss: Vec<f64> = m
            .sigma_t
            .iter()
            .zip(&m.albedo)
            .map(|(t, a)| t * a)
            .collect();
        s.push_str(&format!(
            "MakeNamedMedium \"{id}-medium\"\n    \"string type\" [ \"homogeneous\" ]\n    \
             \"spectrum sigma_a\" [ {} ]\n    \"spectrum sigma_s\" [ {} ]\n    \
             \"float scale\" [ 1 ]\n    \"float g\" [ 0 ]\n\n",
            pairs(&sa),
            pairs(&ss)
        ));
    }
    let rgb_medium = if params.spectral_medium.is_some() {
        format!("{id}-medium-rgb")
    } else {
        format!("{id}-medium")
    };
    s.push_str(&format!(
        "MakeNamedMedium \"{rgb_medium}\"\n    \"string type\" [ \"homogeneous\" ]\n    \
         \"rgb sigma_a\" {sigma_a}\n    \"rgb sigma_s\" {sigma_s}\n    \"float scale\" [ 1 ]\n    \
         \"float g\" [ 0 ]\n\
         MakeNamedMaterial \"{id}-boundary\"\n    \"string type\" [ \"dielectric\" ]\n    \
         \"float eta\" [ {eta} ]\n"
    ));
    s
}

/// What the header says of pbrt's spectral shift of the coefficient routes (measured on the demo's
/// seven materials measured with the mc model, BENCHMARKS.md "exports").
const PBRT_SPECTRAL_SHIFT: &str = "from +4 % to -40 % (red aluminium's red)";

/// Route 1's reflectance parameter: the measured spectrum when the result has it (pbrt reads
/// `"spectrum reflectance" [ λ v λ v … ]`, λ in nm), else the channels' Rd as RGB; `None` without
/// either.
fn reflectance_parameter(params: &RendererParameters) -> Option<String> {
    if let Some(spec) = &params.rd_spectrum {
        let spec = super::extended_reflectance(spec);
        let pairs: Vec<String> = spec
            .wavelength_nm
            .iter()
            .zip(&spec.rd)
            .map(|(l, r)| format!("{} {}", num(*l), num(*r)))
            .collect();
        return Some(format!("\"spectrum reflectance\" [ {} ]", pairs.join(" ")));
    }
    let rd = params.channels.as_array().map(|c| c.rd_total);
    match rd {
        [Some(r), Some(g), Some(b)] => Some(format!(
            "\"rgb reflectance\" [ {} ]",
            joined([r, g, b], num, " ")
        )),
        _ => None,
    }
}

/// Appends `text` as pbrt comment lines (`# …`), each line made safe by [`one_line`]: a comment ends
/// at the line's end, so no character of free text may start a new line.
fn push_comment(s: &mut String, text: &str) {
    for line in wrap(text, 98).split('\n') {
        let line = one_line(line);
        if line.is_empty() {
            s.push_str("#\n");
        } else {
            s.push_str("# ");
            s.push_str(line.trim_end());
            s.push('\n');
        }
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::super::fixtures::{SA, SP, close, marble};
    use super::super::{Format, export};
    use super::*;

    /// A token of pbrt's scene language (pbrt-v4 `src/pbrt/parser.cpp`, `Tokenizer::Next`).
    #[derive(Debug, Clone, PartialEq)]
    pub(crate) enum Token {
        /// A double-quoted string, unescaped.
        Str(String),
        /// `[` or `]`.
        Bracket(char),
        /// Anything else: a directive or a number.
        Word(String),
    }

    /// pbrt's tokenizer, as a checker: comments run from `#` to the end of the line (`\n` or `\r`);
    /// strings are double-quoted, may not contain a raw newline, and take backslash escapes; `[`, `]`
    /// stand alone; other tokens end at whitespace, a quote, a bracket or a comment. Returns the
    /// tokens, or why the text is not pbrt.
    pub(crate) fn tokenize(text: &str) -> Result<Vec<Token>, String> {
        let mut out = Vec::new();
        let mut it = text.chars().peekable();
        while let Some(c) = it.next() {
            match c {
                ' ' | '\t' | '\n' | '\r' => {}
                '#' => {
                    while let Some(&n) = it.peek() {
                        if n == '\n' || n == '\r' {
                            break;
                        }
                        it.next();
                    }
                }
                '"' => {
                    let mut s = String::new();
                    loop {
                        match it.next() {
                            None => return Err("unterminated string".into()),
                            Some('"') => break,
                            Some('\n') => return Err("newline in a string".into()),
                            Some('\\') => match it.next() {
                                Some(e) => s.push(e),
                                None => return Err("escape at the end".into()),
                            },
                            Some(ch) => s.push(ch),
                        }
                    }
                    out.push(Token::Str(s));
                }
                '[' | ']' => out.push(Token::Bracket(c)),
                _ => {
                    let mut w = String::from(c);
                    while let Some(&n) = it.peek() {
                        if n.is_whitespace() || matches!(n, '"' | '[' | ']' | '#') {
                            break;
                        }
                        w.push(n);
                        it.next();
                    }
                    out.push(Token::Word(w));
                }
            }
        }
        Ok(out)
    }

    /// The directives of a pbrt fragment as (directive, name, parameters): checks the grammar this
    /// export uses — `MakeNamedMaterial`/`MakeNamedMedium` "name", then `"type name" [ values ]` —
    /// and that every number parses finite. Returns why not, otherwise.
    pub(crate) type Directive = (String, String, Vec<(String, Vec<Token>)>);

    pub(crate) fn parse(text: &str) -> Result<Vec<Directive>, String> {
        let tokens = tokenize(text)?;
        let mut out: Vec<Directive> = Vec::new();
        let mut i = 0;
        while i < tokens.len() {
            let Token::Word(d) = &tokens[i] else {
                return Err(format!("expected a directive, got {:?}", tokens[i]));
            };
            if d != "MakeNamedMaterial" && d != "MakeNamedMedium" {
                return Err(format!("unexpected directive {d}"));
            }
            let Some(Token::Str(name)) = tokens.get(i + 1) else {
                return Err(format!("{d} without a name"));
            };
            i += 2;
            let mut params = Vec::new();
            while let Some(Token::Str(decl)) = tokens.get(i) {
                let mut parts = decl.split_whitespace();
                let (Some(ty), Some(pname), None) = (parts.next(), parts.next(), parts.next())
                else {
                    return Err(format!("bad parameter declaration {decl:?}"));
                };
                if tokens.get(i + 1) != Some(&Token::Bracket('[')) {
                    return Err(format!("{decl}: no ["));
                }
                i += 2;
                let mut values = Vec::new();
                loop {
                    match tokens.get(i) {
                        Some(Token::Bracket(']')) => break,
                        Some(Token::Word(w)) => {
                            let v: f64 =
                                w.parse().map_err(|_| format!("{decl}: bad number {w}"))?;
                            if !v.is_finite() {
                                return Err(format!("{decl}: {w}"));
                            }
                            if ty == "string" {
                                return Err(format!("{decl}: number in a string parameter"));
                            }
                            values.push(Token::Word(w.clone()));
                        }
                        Some(t @ Token::Str(_)) if ty == "string" => values.push(t.clone()),
                        other => return Err(format!("{decl}: unexpected {other:?}")),
                    }
                    i += 1;
                }
                i += 1;
                let want = match ty {
                    "rgb" => Some(3),
                    "float" | "string" => Some(1),
                    "spectrum" => None,
                    _ => return Err(format!("unknown type {ty}")),
                };
                if want.is_some_and(|n| n != values.len()) {
                    return Err(format!("{decl}: {} values", values.len()));
                }
                params.push((pname.to_string(), values));
            }
            out.push((d.clone(), name.clone(), params));
        }
        Ok(out)
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
        let id = MaterialNames::new("marble").id;
        for (unit, k) in [(SceneUnit::Millimetre, 1.0), (SceneUnit::Metre, 1000.0)] {
            let text = export(&r, Format::Pbrt, unit).unwrap().text;
            let sa = pbrt_values(&text, "rgb sigma_a");
            let ss = pbrt_values(&text, "rgb sigma_s");
            let mfp = pbrt_values(&text, "rgb mfp");
            for c in 0..3 {
                assert!(close(sa[c], SA[c] * k, 1e-6), "{text}");
                assert!(close(ss[c], SP[c] * k, 1e-6), "{text}");
                assert!(close(mfp[c], 1.0 / ((SA[c] + SP[c]) * k), 1e-6), "{text}");
            }
            assert_eq!(
                pbrt_values(&text, "rgb reflectance"),
                vec![0.8302, 0.7910, 0.7526]
            );
            assert_eq!(pbrt_values(&text, "float eta"), vec![1.5]);
            assert_eq!(pbrt_values(&text, "float g"), vec![0.0]);
            assert_eq!(pbrt_values(&text, "float scale"), vec![1.0]);
            let directives = parse(&text).unwrap();
            let names: Vec<&str> = directives.iter().map(|d| d.1.as_str()).collect();
            assert_eq!(
                names,
                [
                    id.clone(),
                    format!("{id}-coefficients"),
                    format!("{id}-medium"),
                    format!("{id}-boundary")
                ]
            );
            assert!(text.contains("\"string type\" [ \"homogeneous\" ]"));
            assert!(text.contains(&format!("1 scene unit = 1 {}", unit.symbol())));
            assert!(text.contains("after WorldBegin"));
            // α′ = 2.19/2.1921 = 0.999042: 2 ⌈ln 1e-6 / ln α′⌉ = 2 · 14415.
            assert!(
                text.contains("Integrator \"volpath\" \"integer maxdepth\" [ 28830 ]"),
                "{text}"
            );
            assert!(text.contains("BLACK under point, spot and distant lights"));
        }
    }

    #[test]
    fn max_depth_follows_the_albedo() {
        let mut r = marble();
        for c in [&mut r.channels.r, &mut r.channels.g, &mut r.channels.b] {
            c.sigma_s_prime = Some(scatterfit_optics::Estimate {
                value: 0.6,
                ..c.sigma_s_prime.unwrap_or_default()
            });
            c.sigma_a = Some(scatterfit_optics::Estimate {
                value: 0.4,
                ..c.sigma_a.unwrap_or_default()
            });
        }
        let (p, _) = RendererParameters::from_result(&r, SceneUnit::Millimetre).unwrap();
        // 2 ⌈ln 1e-6 / ln 0.6⌉ = 2 · 28 = 56 → the floor of 100.
        assert_eq!(pbrt_max_depth(&p), 100);
        r.channels.g.sigma_a = Some(scatterfit_optics::Estimate {
            value: 0.0,
            ..r.channels.g.sigma_a.unwrap_or_default()
        });
        let (p, _) = RendererParameters::from_result(&r, SceneUnit::Millimetre).unwrap();
        assert_eq!(pbrt_max_depth(&p), 1_000_000);
    }

    /// Without Rd the default material is the coefficients' one.
    #[test]
    fn without_reflectance_the_coefficients_name_the_material() {
        let mut r = marble();
        r.channels.g.rd_total = None;
        let text = export(&r, Format::Pbrt, SceneUnit::Millimetre)
            .unwrap()
            .text;
        let directives = parse(&text).unwrap();
        let id = MaterialNames::new("marble").id;
        assert_eq!(directives[0].1, id);
        assert!(directives[0].2.iter().any(|p| p.0 == "sigma_a"));
        assert!(!text.contains("reflectance\" ["));
    }

    #[test]
    fn tokenizer_catches_what_it_should() {
        assert!(parse("MakeNamedMaterial \"a\n\" \"float eta\" [ 1 ]").is_err());
        assert!(parse("# x\nMakeNamedMaterial \"a\" \"float eta\" [ 1 ]").is_ok());
        assert!(parse("# x\rMakeNamedMaterial").is_err());
        assert!(parse("MakeNamedMaterial \"a\" \"float eta\" [ NaN ]").is_err());
        assert!(parse("MakeNamedMaterial \"a\" \"rgb x\" [ 1 2 ]").is_err());
    }
}
