//! The bias study's figure (`scatterfit study`'s study.svg and study.png): per configuration
//! (proposed method, each model with its own α′ inversion), |σ′s error| against −log₁₀(1 − α′), one
//! line per η. The rows come from [`crate::study`].

use crate::study::{Combo, Row, distinct};
use scatterfit_optics::{AlbedoModel, Method, ModelName};

use scatterfit_report::plot::{Figure, Panel, Series, SeriesStyle};

/// Each model's colour (the darkest shade of its lines).
fn model_colour(model: ModelName) -> (u8, u8, u8) {
    match model {
        ModelName::Dipole => (200, 30, 30),
        ModelName::BetterDipole => (200, 120, 0),
        ModelName::Pbd => (20, 140, 40),
        ModelName::Mc => (30, 70, 200),
    }
}

/// The study's figure of `rows` for `combos`.
pub fn study_figure(rows: &[Row], combos: &[Combo]) -> Figure {
    let etas = distinct(rows, |r| r.eta);
    let panels = combos
        .iter()
        .filter(|c| c.method == Method::Proposed && c.albedo == AlbedoModel::default_for(c.model))
        .map(|c| {
            let n = etas.len().max(2) as f64 - 1.0;
            let base = model_colour(c.model);
            let base = (f64::from(base.0), f64::from(base.1), f64::from(base.2));
            let series = etas
                .iter()
                .enumerate()
                .map(|(k, &e)| {
                    // Light (η small) to dark (η large) shades of the model's colour.
                    let t = 0.75 - 0.75 * k as f64 / n;
                    let shade = |v: f64| (v + (255.0 - v) * t).round() as u8;
                    let mut pts: Vec<(f64, f64)> = rows
                        .iter()
                        .filter(|r| r.eta == e && c.matches(r))
                        .filter_map(|r| {
                            r.sigma_s_prime_error.map(|v| {
                                (-(1.0 - r.albedo_prime).log10(), (100.0 * v.abs()).max(1e-3))
                            })
                        })
                        .collect();
                    pts.sort_by(|a, b| a.0.total_cmp(&b.0));
                    Series {
                        label: format!("η = {e}"),
                        errors: None,
                        // A line needs two points: a one-albedo study shows its points as markers.
                        style: if pts.len() > 1 {
                            SeriesStyle::Line
                        } else {
                            SeriesStyle::Measured
                        },
                        points: pts,
                        colour: Some((shade(base.0), shade(base.1), shade(base.2))),
                    }
                })
                .collect();
            Panel {
                title: c.label(),
                colour: model_colour(c.model),
                series,
                note: Some("x: −log₁₀(1 − α′) (1 = 0.9, 2 = 0.99, 3 = 0.999)".into()),
            }
        })
        .collect();
    Figure {
        title: "Bias study: |σ′s error| of the proposed method on Monte Carlo rig-twin samples"
            .into(),
        x_label: "−log₁₀(1 − α′)".into(),
        y_label: "|σ′s error| [%]".into(),
        panels,
        log_y: true,
        log_x: false,
    }
}
