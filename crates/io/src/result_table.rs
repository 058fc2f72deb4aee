//! Results as tables shaped like Choi, Lee & Chin (2014): Table 1 (optical properties per material
//! and channel, with fitting time) and Table 2 (mean squared errors, existing vs proposed), as CSV
//! and Markdown.

use std::fmt::Write as _;

use scatterfit_optics::{Channel, Estimate};

use crate::result_json::{ChannelResult, ChannelStatus, MeasurementResult};

fn num(v: Option<f64>, digits: usize) -> String {
    match v {
        Some(x) if x.is_finite() => format!("{x:.digits$}"),
        _ => String::new(),
    }
}

/// A coefficient for people: 4 significant figures, scientific below 10⁻³.
pub fn sig4(v: f64) -> String {
    if !v.is_finite() {
        return "—".into();
    }
    let a = v.abs();
    if a != 0.0 && !(1e-3..1e4).contains(&a) {
        format!("{v:.3e}")
    } else {
        let decimals = if a == 0.0 {
            3
        } else {
            (3 - a.log10().floor() as i32).max(0) as usize
        };
        format!("{v:.decimals$}")
    }
}

/// "value ± fit" (the fit's standard error only), or the reason there is none.
fn with_fit_error(c: &ChannelResult, v: Option<Estimate>, name: &str) -> String {
    value_with_errors(
        c,
        v.map(|e| Estimate {
            spectro: None,
            g: None,
            ..e
        }),
        name,
    )
}

/// "value ± fit" or, when the spectrophotometer's part is known, "value ± fit ± spectro", then
/// " ± g" when the anisotropy's part is known; "failed" or "unconstrained" where there is
/// no measurement (`name` is the parameter's name in `unconstrained`).
pub fn value_with_errors(c: &ChannelResult, v: Option<Estimate>, name: &str) -> String {
    if c.status == ChannelStatus::Failed {
        return "failed".into();
    }
    if c.unconstrained.iter().any(|u| u.name() == name) {
        return "unconstrained".into();
    }
    // The systematic terms, each named: the anisotropy's and an approximate model's.
    let g = |e: &Estimate| {
        e.g.map_or(String::new(), |g| format!(" ± {} g", sig4(g)))
            + &e.model
                .map_or(String::new(), |m| format!(" ± {} model", sig4(m)))
    };
    match v {
        Some(
            e @ Estimate {
                value,
                fit: Some(fit),
                spectro: Some(spectro),
                ..
            },
        ) => format!(
            "{} ± {} ± {}{}",
            sig4(value),
            sig4(fit),
            sig4(spectro),
            g(&e)
        ),
        Some(
            e @ Estimate {
                value,
                fit: Some(fit),
                ..
            },
        ) => format!("{} ± {}{}", sig4(value), sig4(fit), g(&e)),
        Some(e) => format!("{}{}", sig4(e.value), g(&e)),
        None => "—".into(),
    }
}

/// σ′s and σa of a channel as "value ± fit ± spectro" ([`value_with_errors`]).
pub fn sigma_cells(c: &ChannelResult) -> [String; 2] {
    [
        value_with_errors(c, c.sigma_s_prime, "sigma_s_prime"),
        value_with_errors(c, c.sigma_a, "sigma_a"),
    ]
}

/// The lines under a table that say what its ± mean (empty when no result carries the
/// spectrophotometer's part or the g term), with how g entered each result.
pub fn errors_note(results: &[MeasurementResult]) -> String {
    let mut t = spectro_errors_note(results);
    if results.iter().any(|r| {
        r.channels
            .iter()
            .any(|c| c.sigma_s_prime.is_some_and(|e| e.model.is_some()))
    }) {
        t.push_str(
            "± … model: an approximate forward model's part — how far the estimate moves to exact \
             transport's (the Monte Carlo tables) on the same data; a bound, not a standard error: \
             add it to the quadrature sum of the others for the total.\n",
        );
    }
    let with_g: Vec<&MeasurementResult> = results
        .iter()
        .filter(|r| r.g_uncertainty.is_some())
        .collect();
    if with_g.is_empty() {
        return t;
    }
    t.push_str(
        "± … g: the anisotropy's part — how far the estimate moves over the range of the \
         Henyey–Greenstein g, from the g-aware `mc` model (0 where g was given); a bound, \
         not a standard error: add it to the quadrature sum of the others for the total.\n",
    );
    if with_g.iter().any(|r| {
        r.g_uncertainty
            .as_ref()
            .is_some_and(|g| g.source == crate::result_json::GSource::Fit)
    }) {
        t.push_str(
            "Where g is fitted from the profile (g = \"fit\"), a channel whose g the data determine \
             has its values at the fitted g and ± g is how far they move over its standard error; \
             elsewhere ± g is the searched range's term.\n",
        );
    }
    let descriptions: Vec<String> = with_g
        .iter()
        .filter_map(|r| r.g_uncertainty.as_ref().map(|g| g.describe()))
        .collect();
    if descriptions.iter().all(|d| *d == descriptions[0]) {
        // (Not capitalised: the sentence starts with the symbol g, which "G" — the green
        // channel in these tables — would misread.)
        t.push_str(&format!("Anisotropy: {}.\n", descriptions[0]));
    } else {
        for (r, d) in with_g.iter().zip(&descriptions) {
            t.push_str(&format!("g ({}): {d}.\n", crate::escape::one_line(&r.name)));
        }
    }
    t
}

/// The line on the fit and spectrophotometer terms.
fn spectro_errors_note(results: &[MeasurementResult]) -> String {
    let eps: Vec<f64> = results
        .iter()
        .filter(|r| {
            r.channels
                .iter()
                .any(|c| c.sigma_s_prime.is_some_and(|e| e.spectro.is_some()))
        })
        .filter_map(|r| r.spectro_repeatability)
        .collect();
    let Some(&e) = eps.first() else {
        return String::new();
    };
    let all_same = eps.iter().all(|&x| x == e);
    let port = if results.iter().any(|r| r.spectro_port.is_some()) {
        "; behind a spectrophotometer port carried through its reading fraction"
    } else {
        ""
    };
    format!(
        "Errors: value ± fit (the profile's noise, from the fit's Jacobian{port}) ± \
         spectrophotometer (η and α′ at the reading's repeatability of {}, propagated by refits); \
         add them in quadrature for the total.\n",
        if all_same {
            format!("{:.2} %", 100.0 * e)
        } else {
            "spectro.repeatability".into()
        }
    )
}

/// The lines under a table that say how the spectrophotometer's port was handled: per
/// result with a port, what it read of Rd per channel (the correction applied); when no result
/// names a port, one line saying the readings were taken as loss-free.
pub fn port_note(results: &[MeasurementResult]) -> String {
    let mut t = String::new();
    for r in results {
        if let Some(p) = &r.spectro_port {
            let pct = p
                .reading_fraction
                .iter()
                .map(|f| f.map_or("—".into(), |f| format!("{:.1}", 100.0 * f)))
                .collect::<Vec<_>>()
                .join(" / ");
            t.push_str(&format!(
                "Spectrophotometer port ({}): {} mm aperture lit over {} mm read {pct} % of Rd (R / G \
                 / B); Rd and α′ corrected from the fitted profile, so the fit's error reaches α′ \
                 and σa through the port's reading fraction (α′ ± fit ± spectro).\n",
                crate::escape::one_line(&r.name),
                diameter(p.aperture_mm),
                diameter(p.illuminated_mm)
            ));
            if let Some([lo, hi]) = r.g_uncertainty.as_ref().and_then(|g| g.range) {
                t.push_str(&format!(
                    "  The ± g term (g in {lo}–{hi}) keeps this correction's Rd; the port's \
                     reading fraction itself changes with g (2–9 % between g = 0 and 0.8 at α′ ≥ \
                     0.99 behind an 8 mm port), so here the term understates: state [fit] g if \
                     it is known.\n"
                ));
            }
            for (ch, problem) in p.problems.iter_channels() {
                if let Some(problem) = problem {
                    t.push_str(&format!(
                        "  {} left as read: {}\n",
                        ch.name(),
                        crate::escape::one_line(problem)
                    ));
                }
            }
        }
    }
    if t.is_empty() && !results.is_empty() {
        t.push_str(
            "Spectrophotometer readings taken as loss-free (no spectro.aperture_mm): a port \
             under-reads Rd of materials whose light travels millimetres, and σa then comes out \
             high.\n",
        );
    }
    t
}

/// A port diameter as written (up to 4 significant digits, no trailing zeros).
fn diameter(v: f64) -> String {
    let s = format!("{v:.3}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// Table 1 as CSV: one row per material and channel.
pub fn table1_csv(results: &[MeasurementResult]) -> String {
    let mut t = String::from(
        "material,channel,status,sigma_s_prime_mm-1,sigma_s_prime_stderr,sigma_a_mm-1,sigma_a_stderr,\
         albedo_prime,rd_total,eta,method,model,fit_time_s,iterations,mse_mm-4,rms_log_residual,\
         chi2_reduced,rings_used,rings_inside_spot,rings_below_detection,problem,\
         sigma_s_prime_stderr_spectro,sigma_a_stderr_spectro,albedo_prime_stderr,eta_stderr,\
         sigma_s_prime_stderr_g,sigma_a_stderr_g,albedo_prime_stderr_g,albedo_prime_stderr_fit,\
         sigma_s_prime_stderr_model,sigma_a_stderr_model,albedo_prime_stderr_model\n",
    );
    // The table is flat: one column per value and per term of its record.
    let value = |e: Option<Estimate>| e.map(|e| e.value);
    let term = |e: Option<Estimate>, t: fn(&Estimate) -> Option<f64>| e.as_ref().and_then(t);
    for r in results {
        for (ch, c) in r.channels.iter_channels() {
            let name = ch.name();
            let (sp, sa, ap) = (c.sigma_s_prime, c.sigma_a, c.albedo_prime);
            let status = c.status.name();
            let _ = writeln!(
                t,
                "{},{name},{status},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
                csv_text(&r.name),
                num(value(sp), 6),
                num(term(sp, |e| e.fit), 6),
                num(value(sa), 8),
                num(term(sa, |e| e.fit), 8),
                num(value(ap), 6),
                num(c.rd_total, 6),
                num(Some(r.eta), 4),
                r.method,
                r.model,
                num(Some(c.fit_time_s), 7),
                c.iterations,
                num(c.mse, 8),
                num(c.rms_log_residual, 5),
                num(c.chi2_reduced, 3),
                c.rings_used,
                c.rings_inside_spot,
                c.rings_below_detection,
                csv_text(c.problem.as_deref().unwrap_or("")),
                num(term(sp, |e| e.spectro), 6),
                num(term(sa, |e| e.spectro), 8),
                num(term(ap, |e| e.spectro), 6),
                num(r.eta_stderr, 6),
                num(term(sp, |e| e.g), 6),
                num(term(sa, |e| e.g), 8),
                num(term(ap, |e| e.g), 6),
                num(term(ap, |e| e.fit), 6),
                num(term(sp, |e| e.model), 6),
                num(term(sa, |e| e.model), 8),
                num(term(ap, |e| e.model), 6),
            );
        }
    }
    t
}

/// A text cell: quoted where needed, and never a spreadsheet formula ([`crate::escape::csv_cell`]:
/// a name starting with `=`, `+`, `-` or `@` gets a leading `'`).
fn csv_text(s: &str) -> String {
    crate::escape::csv_cell(s)
}

/// Table 1 as Markdown: Material | Color | σ′s | σa | η | fitting time, as the paper prints it,
/// with standard errors.
pub fn table1_markdown(results: &[MeasurementResult]) -> String {
    let mut t = String::from(
        "| Material | Color | σ′s [mm⁻¹] | σa [mm⁻¹] | η | α′ | Fitting time [µs] | MSE [mm⁻⁴] |\n\
         |---|---|---|---|---|---|---|---|\n",
    );
    for r in results {
        for (ch, c) in r.channels.iter_channels() {
            let name = ch.name();
            // The name is the user's text: `|`, line breaks and raw HTML must not break the table.
            let material = if ch == Channel::R {
                crate::escape::markdown_cell(&r.name)
            } else {
                String::new()
            };
            let eta = match (ch, r.eta_stderr) {
                (Channel::G, Some(e)) => format!("{:.4} ± {}", r.eta, sig4(e)),
                (Channel::G, None) => format!("{:.4}", r.eta),
                _ => String::new(),
            };
            let time = if c.status == ChannelStatus::Failed && c.iterations == 0 {
                "—".into()
            } else {
                format!("{:.0}", c.fit_time_s * 1e6)
            };
            let [sp, sa] = sigma_cells(c);
            let _ = writeln!(
                t,
                "| {material} | {name} | {sp} | {sa} | {eta} | {} | {time} | {} |",
                // Behind a spectrophotometer port α′ has a fit term too, first as in the σ
                // columns (value ± fit ± spectro).
                match c.albedo_prime {
                    Some(Estimate {
                        value: a,
                        fit,
                        spectro: Some(e),
                        g,
                        ..
                    }) => {
                        let f = fit.map_or(String::new(), |f| format!(" ± {}", sig4(f)));
                        let g = g.map_or(String::new(), |g| format!(" ± {} g", sig4(g)));
                        format!("{a:.5}{f} ± {}{g}", sig4(e))
                    }
                    Some(Estimate { value: a, g, .. }) => {
                        let g = g.map_or(String::new(), |g| format!(" ± {} g", sig4(g)));
                        format!("{a:.5}{g}")
                    }
                    None => "—".into(),
                },
                c.mse.map_or("—".into(), sig4),
            );
        }
    }
    let notes: Vec<String> = results
        .iter()
        .flat_map(|r| {
            r.channels.iter_channels().filter_map(move |(n, c)| {
                c.problem.as_ref().map(|p| {
                    format!(
                        "- {} {n}: {}",
                        crate::escape::markdown_cell(&r.name),
                        crate::escape::markdown_cell(p)
                    )
                })
            })
        })
        .collect();
    let errors = errors_note(results);
    if !errors.is_empty() {
        t.push('\n');
        t.push_str(&errors);
    }
    let port = port_note(results);
    if !port.is_empty() {
        t.push('\n');
        t.push_str(&port);
    }
    if !notes.is_empty() {
        t.push('\n');
        t.push_str(&notes.join("\n"));
        t.push('\n');
    }
    t
}

/// Table 2 as Markdown: per material, MSE of the existing and the proposed method per channel, with
/// fit times and parameters beside (pairs of results of the same sample).
pub fn table2_markdown(pairs: &[(MeasurementResult, MeasurementResult)]) -> String {
    // Downstream honesty: a sample whose data checks did not pass is said so above the table.
    let mut t = String::new();
    for (existing, proposed) in pairs {
        for (method, r) in [("existing", existing), ("proposed", proposed)] {
            if let Some(why) = r.untrusted() {
                let _ = writeln!(
                    t,
                    "> **Warning — not trusted:** {} ({method} method): {}\n",
                    crate::escape::markdown_cell(&r.name),
                    crate::escape::markdown_cell(&why)
                );
            }
        }
    }
    t.push_str(
        "| Material | Color | σ′s existing | σa existing | MSE existing | fit µs | σ′s proposed | σa proposed | MSE proposed | fit µs |\n\
         |---|---|---|---|---|---|---|---|---|---|\n",
    );
    for (existing, proposed) in pairs {
        for ch in Channel::ALL {
            let name = ch.name();
            let (e, p) = (&existing.channels[ch], &proposed.channels[ch]);
            let material = if ch == Channel::R {
                crate::escape::markdown_cell(&existing.name)
            } else {
                String::new()
            };
            let _ = writeln!(
                t,
                "| {material} | {name} | {} | {} | {} | {:.0} | {} | {} | {} | {:.0} |",
                with_fit_error(e, e.sigma_s_prime, "sigma_s_prime"),
                with_fit_error(e, e.sigma_a, "sigma_a"),
                e.mse.map_or("—".into(), sig4),
                e.fit_time_s * 1e6,
                with_fit_error(p, p.sigma_s_prime, "sigma_s_prime"),
                with_fit_error(p, p.sigma_a, "sigma_a"),
                p.mse.map_or("—".into(), sig4),
                p.fit_time_s * 1e6,
            );
        }
    }
    t
}

/// Table 2 as CSV.
pub fn table2_csv(pairs: &[(MeasurementResult, MeasurementResult)]) -> String {
    let mut t = String::from(
        "material,channel,sigma_s_prime_existing,sigma_a_existing,mse_existing,fit_time_s_existing,\
         status_existing,sigma_s_prime_proposed,sigma_a_proposed,mse_proposed,fit_time_s_proposed,status_proposed\n",
    );
    let status = |c: &ChannelResult| c.status.name();
    for (e, p) in pairs {
        for ch in Channel::ALL {
            let name = ch.name();
            let (ce, cp) = (&e.channels[ch], &p.channels[ch]);
            let _ = writeln!(
                t,
                "{},{name},{},{},{},{},{},{},{},{},{},{}",
                csv_text(&e.name),
                num(ce.sigma_s_prime.map(|e| e.value), 6),
                num(ce.sigma_a.map(|e| e.value), 8),
                num(ce.mse, 8),
                num(Some(ce.fit_time_s), 7),
                status(ce),
                num(cp.sigma_s_prime.map(|e| e.value), 6),
                num(cp.sigma_a.map(|e| e.value), 8),
                num(cp.mse, 8),
                num(Some(cp.fit_time_s), 7),
                status(cp),
            );
        }
    }
    t
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn significant_figures() {
        assert_eq!(sig4(1.979), "1.979");
        assert_eq!(sig4(0.0496), "0.04960");
        assert_eq!(sig4(0.000792), "7.920e-4");
        assert_eq!(sig4(12.5), "12.50");
        assert_eq!(sig4(f64::NAN), "—");
    }

    #[test]
    fn csv_quotes_problems() {
        assert_eq!(csv_text("a, b"), "\"a, b\"");
        assert_eq!(csv_text("plain"), "plain");
    }

    /// The port's line under the table: what it read per channel, a channel left as read, and —
    /// only when a g range was propagated (g not given) — that the g term keeps the correction's
    /// Rd and so understates; no port: the loss-free sentence.
    #[test]
    fn the_port_note_says_what_was_corrected_and_what_the_g_term_misses() {
        let json = r#"{ "name": "s", "eta": 1.3, "method": "proposed", "model": "mc",
          "channels": {
            "r": { "status": "ok", "sigma_s_prime": 1.0, "sigma_a": 0.01, "albedo_prime": 0.99 },
            "g": { "status": "ok", "sigma_s_prime": 1.0, "sigma_a": 0.02, "albedo_prime": 0.98 },
            "b": { "status": "ok", "sigma_s_prime": 1.0, "sigma_a": 0.03, "albedo_prime": 0.97 } },
          "spectro_port": { "aperture_mm": 8, "illuminated_mm": 14,
            "rd_read": { "r": 0.5, "g": 0.4, "b": 0.3 },
            "reading_fraction": { "r": 0.871, "g": 0.98, "b": null },
            "problems": { "r": null, "g": null, "b": "the fit did not converge" } },
          "g_uncertainty": { "source": "default_range", "g": 0.0, "range": [0.0, 0.95] },
          "version": "0.1.0" }"#;
        let r =
            crate::result_json::parse_result_json(json, std::path::Path::new("r.json")).unwrap();
        let note = port_note(std::slice::from_ref(&r));
        assert!(
            note.contains("8 mm aperture lit over 14 mm read 87.1 / 98.0 / — %"),
            "{note}"
        );
        assert!(
            note.contains("B left as read: the fit did not converge"),
            "{note}"
        );
        assert!(
            note.contains("g in 0–0.95") && note.contains("understates"),
            "{note}"
        );
        let mut given = r.clone();
        given.g_uncertainty.as_mut().unwrap().range = None;
        assert!(!port_note(std::slice::from_ref(&given)).contains("understates"));
        let mut no_port = r;
        no_port.spectro_port = None;
        assert!(port_note(&[no_port]).contains("loss-free"));
    }

    /// A hostile sample name cannot make a formula in result.csv, break a row of result.md or
    /// inject HTML into it; the tables keep their shape.
    #[test]
    fn hostile_names_stay_cells() {
        let json = r#"{ "name": "n", "eta": 1.3, "method": "proposed", "model": "dipole",
          "channels": {
            "r": { "status": "ok", "sigma_s_prime": 1.0, "sigma_a": 0.01, "albedo_prime": 0.99 },
            "g": { "status": "ok", "sigma_s_prime": 1.0, "sigma_a": 0.02, "albedo_prime": 0.98 },
            "b": { "status": "ok", "sigma_s_prime": 1.0, "sigma_a": 0.03, "albedo_prime": 0.97 } },
          "version": "0.1.0" }"#;
        let mut r =
            crate::result_json::parse_result_json(json, std::path::Path::new("r.json")).unwrap();
        for name in [
            "=HYPERLINK(\"http://evil\",\"x\")",
            "+cmd|' /C calc'!A0",
            "@SUM(1)",
            "a|b\n| x | y |<img src=x onerror=alert(1)>",
        ] {
            r.name = name.into();
            r.channels.g.problem = Some(format!("{name} problem"));
            let csv = table1_csv(std::slice::from_ref(&r));
            let mut rows = csv::Reader::from_reader(csv.as_bytes());
            for row in rows.records() {
                let row = row.unwrap();
                assert_eq!(row.len(), 32, "{csv}");
                assert!(!row[0].starts_with(['=', '+', '-', '@']), "{csv}");
            }
            let md = table1_markdown(std::slice::from_ref(&r));
            for line in md.lines().filter(|l| l.starts_with('|')) {
                let cells = line.replace("\\|", "").matches('|').count();
                assert_eq!(cells, 9, "{line}");
            }
            assert!(!md.contains("<img"), "{md}");
        }
    }
}
