//! The demo's accuracy table as Markdown ([`crate::accuracy`] makes its rows).

use std::fmt::Write as _;

use crate::accuracy::{ChannelRow, MaterialRow};

fn pct(v: Option<f64>) -> String {
    v.map_or("—".into(), |v| format!("{:+.1} %", 100.0 * v))
}

/// The demo's accuracy table as Markdown (`accuracy.md`): per material and channel the truth, each
/// method's value and its error, then the median |error| of each method over the channels. The
/// proposed and existing columns are the measurement's model (named in the header: exact
/// transport, `mc`, by default); the last two are the paper's own fit (the dipole).
pub fn accuracy_markdown(rows: &[MaterialRow]) -> String {
    let model = rows.first().map_or("mc", |r| r.model.as_str());
    let mut t = format!(
        "| Material | η true → found | Ch | σ′s true | σ′s proposed, {model} (error) | σa true | σa proposed, {model} (error) | σ′s existing, {model} (error) | σa existing, {model} (error) | σ′s paper's dipole (error) | σa paper's dipole (error) |\n\
         |---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    let f = |v: Option<f64>| v.map_or("—".into(), scatterfit_io::result_table::sig4);
    for r in rows {
        for (k, c) in r.channels.iter().enumerate() {
            let (name, eta) = if k == 0 {
                (
                    r.name.as_str(),
                    format!("{:.4} → {:.4}", r.eta_true, r.eta_found),
                )
            } else {
                ("", String::new())
            };
            let _ = writeln!(
                t,
                "| {name} | {eta} | {} | {} | {} ({}) | {} | {} ({}) | {} ({}) | {} ({}) | {} ({}) | {} ({}) |",
                c.channel,
                c.sigma_s_prime_true,
                f(c.proposed_sigma_s_prime),
                pct(c.proposed_sigma_s_prime_error),
                c.sigma_a_true,
                f(c.proposed_sigma_a),
                pct(c.proposed_sigma_a_error),
                f(c.existing_sigma_s_prime),
                pct(c.existing_sigma_s_prime_error),
                f(c.existing_sigma_a),
                pct(c.existing_sigma_a_error),
                f(c.paper_sigma_s_prime),
                pct(c.paper_sigma_s_prime_error),
                f(c.paper_sigma_a),
                pct(c.paper_sigma_a_error),
            );
        }
    }
    let median = |get: &dyn Fn(&ChannelRow) -> Option<f64>| -> String {
        let mut v: Vec<f64> = rows
            .iter()
            .flat_map(|r| r.channels.iter())
            .filter_map(get)
            .map(f64::abs)
            .collect();
        if v.is_empty() {
            return "—".into();
        }
        v.sort_by(f64::total_cmp);
        format!("{:.1} %", 100.0 * v[v.len() / 2])
    };
    let _ = writeln!(
        t,
        "\nMedian |error| over the {} channels — the proposed method ({model}): σ′s {}, σa {}; \
         the existing method ({model}): σ′s {}, σa {}; the paper's proposed method with its dipole \
         (Jensen et al. 2001; α′ from the dipole's total): σ′s {}, σa {}.",
        rows.iter().map(|r| r.channels.len()).sum::<usize>(),
        median(&|c| c.proposed_sigma_s_prime_error),
        median(&|c| c.proposed_sigma_a_error),
        median(&|c| c.existing_sigma_s_prime_error),
        median(&|c| c.existing_sigma_a_error),
        median(&|c| c.paper_sigma_s_prime_error),
        median(&|c| c.paper_sigma_a_error),
    );
    t
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(channel: &'static str, proposed: f64) -> ChannelRow {
        ChannelRow {
            channel,
            sigma_s_prime_true: 1.0,
            sigma_a_true: 0.1,
            albedo_prime_true: 1.0 / 1.1,
            proposed_sigma_s_prime: Some(proposed),
            proposed_sigma_a: None,
            proposed_albedo_prime: None,
            existing_sigma_s_prime: None,
            existing_sigma_a: None,
            proposed_sigma_s_prime_error: Some(proposed - 1.0),
            proposed_sigma_a_error: None,
            existing_sigma_s_prime_error: None,
            existing_sigma_a_error: None,
            paper_sigma_s_prime: None,
            paper_sigma_a: None,
            paper_sigma_s_prime_error: None,
            paper_sigma_a_error: None,
        }
    }

    /// One row per channel, η only on the material's first row, errors in percent with a sign,
    /// the median of |error| (of +10 %, −30 %, +20 %: 20 %), and "—" where a method gave nothing.
    #[test]
    fn rows_errors_and_medians() {
        let rows = [MaterialRow {
            name: "wax".into(),
            model: "dipole".into(),
            eta_true: 1.4,
            eta_found: 1.41,
            channels: vec![row("R", 1.1), row("G", 0.7), row("B", 1.2)],
        }];
        let md = accuracy_markdown(&rows);
        let lines: Vec<&str> = md.lines().collect();
        assert!(
            lines[2].starts_with("| wax | 1.4000 → 1.4100 | R | 1 | 1.100 (+10.0 %) |"),
            "{}",
            lines[2]
        );
        assert!(
            lines[3].starts_with("|  |  | G | 1 | 0.7000 (-30.0 %) |"),
            "{}",
            lines[3]
        );
        assert!(
            md.contains("3 channels — the proposed method (dipole): σ′s 20.0 %, σa —;"),
            "{md}"
        );
    }
}
