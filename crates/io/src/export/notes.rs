//! What every export header says besides the numbers: the model note (the fitted model against
//! the renderer's transport, with exact transport's Rd), the provenance line and the coefficient
//! table.

use super::*;
/// The model whose total Rd(α′, η) gave α′: the Monte Carlo tables for `albedo_model = mc`, the
/// profile model's own for `diffusion` (the classical dipole when the profile model is `mc`; as the
/// pipeline's `albedo_model_for`).
pub(super) fn albedo_source(model: &str, albedo_model: &str) -> String {
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
pub(super) fn model_header(params: &RendererParameters, renderers: &[Renderer]) -> Vec<String> {
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
pub(super) fn provenance_line(params: &RendererParameters) -> String {
    let s = &params.source;
    let or_unknown = |t: &str| {
        if t.is_empty() {
            "unknown".to_string()
        } else {
            one_line(t)
        }
    };
    let mut line = format!(
        "Measured with scatterfit {} (method {}, profile model {}, albedo model {}, eta from {}).",
        or_unknown(&s.measured_with),
        or_unknown(&s.method),
        or_unknown(&s.model),
        or_unknown(&s.albedo_model),
        or_unknown(&s.eta_source),
    );
    if let Some(why) = &s.not_trusted {
        line.push_str(&format!(
            " WARNING: not every channel passed the measurement's data checks, so these numbers \
             are not trusted: {}.",
            one_line(why)
        ));
    }
    line
}

/// The per-channel coefficients as aligned comment lines starting with `prefix`.
pub(super) fn channel_table_comment(params: &RendererParameters, prefix: &str) -> String {
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
pub(super) fn largest(values: [f64; 3]) -> f64 {
    values.iter().copied().fold(0.0_f64, f64::max)
}

/// Three per-channel values, each formatted by `format`, joined by `separator`.
pub(super) fn joined(values: [f64; 3], format: fn(f64) -> String, separator: &str) -> String {
    values.map(format).join(separator)
}
