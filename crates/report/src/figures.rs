//! The figures of a measurement, built from its data for `crate::plot`: the fit (Figure 4 of Choi
//! et al. 2014: measured profile and fitted model per channel, log scale) and the comparison of
//! methods (their Figure 6: measured, existing, proposed).

use scatterfit_fit::{FitReport, model_profile};
use scatterfit_io::result_json::MeasurementResult;
use scatterfit_io::result_table::sig4;
use scatterfit_optics::{Channel, OpticalProperties};
use scatterfit_pipeline::Measurement;

use crate::plot::{Figure, Panel, Series, SeriesStyle};

/// A channel's colour in the plots: Okabe & Ito's (2008) vermillion, bluish green and blue, told
/// apart with the common colour-vision deficiencies (each panel is also titled with its channel).
fn colour(c: Channel) -> (u8, u8, u8) {
    crate::html::CHANNEL_COLOURS[c.index()]
}

/// The measured rings of channel `c`: used ones with error bars, excluded ones apart.
fn measured_series(m: &Measurement, c: Channel, report: Option<&FitReport>) -> Vec<Series> {
    let rings = &m.profile.profile.rings;
    let used: std::collections::HashSet<usize> = report
        .map(|r| r.fitted.iter().map(|f| f.index).collect())
        .unwrap_or_default();
    let (mut inc, mut err, mut exc) = (Vec::new(), Vec::new(), Vec::new());
    for (k, ring) in rings.iter().enumerate() {
        let Some(r_mm) = m.profile.profile.r_mm(k) else {
            continue;
        };
        // The profile's channels are the image's: R, G, B in that order.
        let Some(ch) = ring.channels.get(c.index()) else {
            continue;
        };
        if !(ch.mean.is_finite() && ch.mean > 0.0) {
            continue;
        }
        if used.contains(&k) {
            inc.push((r_mm, ch.mean));
            err.push(if ch.std_err.is_finite() {
                ch.std_err
            } else {
                0.0
            });
        } else {
            exc.push((r_mm, ch.mean));
        }
    }
    vec![
        Series {
            label: "measured (fitted rings)".into(),
            points: inc,
            errors: Some(err),
            style: SeriesStyle::Measured,
            colour: None,
        },
        Series {
            label: "not fitted (spot, below detection)".into(),
            points: exc,
            errors: None,
            style: SeriesStyle::Excluded,
            colour: None,
        },
    ]
}

/// The model of a fitted channel × its scale over every ring radius (in the profile's units).
fn model_series(
    m: &Measurement,
    report: &FitReport,
    label: &str,
    style: SeriesStyle,
) -> Option<Series> {
    let model = scatterfit_pipeline::family(m.settings.model).ok()?;
    let props =
        OpticalProperties::new(report.sigma_s_prime.value, report.sigma_a.value, report.eta)
            .ok()?;
    let radii: Vec<f64> = (0..m.profile.profile.rings.len())
        .filter_map(|k| m.profile.profile.r_mm(k))
        .filter(|r| *r > 0.0)
        .collect();
    let spot = m.settings.options().ok()?.spot;
    let values = model_profile(model, &props, spot, &radii).ok()?;
    Some(Series {
        label: label.into(),
        points: radii
            .iter()
            .zip(values)
            .map(|(&r, v)| (r, v * report.scale.value))
            .collect(),
        errors: None,
        style,
        colour: None,
    })
}

/// Figure 4's shape: per channel, the measured profile and the fitted model.
pub fn fit_figure(m: &Measurement, result: &MeasurementResult) -> Figure {
    let panels = Channel::ALL
        .map(|c| {
            let report = m.fits[c].report();
            let mut series = measured_series(m, c, report);
            if let Some(r) = report
                && let Some(s) = model_series(
                    m,
                    r,
                    &format!("{} fit ({})", result.model, result.method),
                    SeriesStyle::Line,
                )
            {
                series.push(s);
            }
            let ch = &result.channels[c];
            let note = match (ch.sigma_s_prime, ch.sigma_a) {
                (Some(sp), Some(sa)) => format!(
                    "σ′s = {} mm⁻¹, σa = {} mm⁻¹, α′ = {}{}",
                    sig4(sp.value),
                    sig4(sa.value),
                    ch.albedo_prime
                        .map_or("—".into(), |a| format!("{:.4}", a.value)),
                    if ch.unconstrained.is_empty() {
                        ""
                    } else {
                        " (unconstrained)"
                    }
                ),
                _ => ch.problem.clone().unwrap_or_else(|| "not fitted".into()),
            };
            Panel {
                title: format!("{} channel", c.name()),
                colour: colour(c),
                series,
                note: Some(note),
            }
        })
        .to_vec();
    Figure {
        title: format!(
            "{} — radial profile and {} fit ({} method, η = {:.4}{})",
            result.name,
            // The default, `mc`, in words: a reader of the figure need not know the flag.
            match result.model {
                scatterfit_optics::ModelName::Mc => "exact-transport (mc)".to_string(),
                m => m.to_string(),
            },
            result.method,
            result.eta,
            g_in_title(result.g_uncertainty.as_ref())
        ),
        x_label: "r [mm]".into(),
        y_label: "Rd(r) [relative]".into(),
        panels,
        log_y: true,
        log_x: false,
    }
}

/// The anisotropy the fit assumed, for a figure's title: ", g = 0.85" where the values are at a
/// g ≠ 0, ", g fitted" or ", g in 0.7–0.95" (values the middle of a range); nothing at g = 0.
fn g_in_title(u: Option<&scatterfit_io::result_json::GUncertainty>) -> String {
    use scatterfit_io::result_json::GSource;
    match u {
        Some(u) if u.source == GSource::Fit => ", g fitted".into(),
        Some(u) => match (u.g, u.range) {
            (Some(g), _) if g != 0.0 => format!(", g = {g}"),
            (None, Some([lo, hi])) => format!(", g in {lo}–{hi}"),
            _ => String::new(),
        },
        None => String::new(),
    }
}

/// Figure 6's shape: per channel, the measured profile with the existing and the proposed fits
/// (both measurements are of the same sample; the profile is the proposed one's).
pub fn compare_figure(existing: &Measurement, proposed: &Measurement, name: &str) -> Figure {
    let panels = Channel::ALL
        .map(|c| {
            let rp = proposed.fits[c].report();
            let re = existing.fits[c].report();
            let mut series = measured_series(proposed, c, rp);
            if let Some(r) = re
                && let Some(s) = model_series(
                    existing,
                    r,
                    "existing (σ′s, σa fitted)",
                    SeriesStyle::DashedLine,
                )
            {
                series.push(s);
            }
            if let Some(r) = rp
                && let Some(s) =
                    model_series(proposed, r, "proposed (α′ from spectro)", SeriesStyle::Line)
            {
                series.push(s);
            }
            let mse = |r: Option<&FitReport>| r.map_or("—".into(), |r| sig4(r.mse));
            Panel {
                title: format!("{} channel", c.name()),
                colour: colour(c),
                series,
                note: Some(format!(
                    "MSE existing {}, proposed {} mm⁻⁴",
                    mse(re),
                    mse(rp)
                )),
            }
        })
        .to_vec();
    Figure {
        title: format!("{name} — measured profile, existing and proposed methods"),
        x_label: "r [mm]".into(),
        y_label: "Rd(r) [relative]".into(),
        panels,
        log_y: true,
        log_x: false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use scatterfit_io::result_json::{GSource, GUncertainty};

    fn record(source: GSource, g: Option<f64>, range: Option<[f64; 2]>) -> GUncertainty {
        GUncertainty {
            source,
            g,
            range,
            evaluated: Vec::new(),
            not_covered: None,
            fitted: None,
        }
    }

    /// The fit figure's title says which g the values are at: a given g ≠ 0, a range's middle, a
    /// fit; nothing for g = 0 (given, or the default range's values).
    #[test]
    fn the_title_names_the_g_assumed() {
        assert_eq!(g_in_title(None), "");
        assert_eq!(
            g_in_title(Some(&record(GSource::Given, Some(0.7), None))),
            ", g = 0.7"
        );
        assert_eq!(
            g_in_title(Some(&record(GSource::Given, Some(0.0), None))),
            ""
        );
        assert_eq!(
            g_in_title(Some(&record(
                GSource::DefaultRange,
                Some(0.0),
                Some([0.0, 0.95])
            ))),
            ""
        );
        assert_eq!(
            g_in_title(Some(&record(GSource::Range, None, Some([0.7, 0.95])))),
            ", g in 0.7–0.95"
        );
        assert_eq!(
            g_in_title(Some(&record(GSource::Fit, None, Some([0.0, 0.95])))),
            ", g fitted"
        );
    }
}
