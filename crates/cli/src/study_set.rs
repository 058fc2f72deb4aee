//! A bias study's rows as one set: the tables (`study.md`, `study.csv`) and the figure
//! (`study.png`) made of them — by `scatterfit study` itself, and by `scatterfit combine` from the
//! partial files of `study --shard K/N` (each a round-robin slice of the grid's samples).

use std::path::Path;
use std::process::ExitCode;

use anyhow::{Context, bail};
use scatterfit_lab::study::{
    Combo, Row, combos, dedup, g_axis_markdown, g_given_combo, has_g_axis, rows_csv,
    summary_markdown,
};
use serde::{Deserialize, Serialize};

use crate::output::{errln, out, outln};

/// What a study computes from (every shard's the same; the partial files' run fingerprint).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct StudyConfig {
    /// η of the grid.
    pub etas: Vec<f64>,
    /// α′ of the grid.
    pub albedos: Vec<f64>,
    /// σ′t of every point [mm⁻¹].
    pub sigma_t_prime: f64,
    /// The quick rig.
    pub quick: bool,
    /// The twins' g.
    pub g: Vec<f64>,
    /// The twin's seed.
    pub seed: u64,
    /// The twins' photon scale.
    pub photon_scale: f64,
    /// Photon beam diffusion left out.
    pub no_pbd: bool,
}

/// A shard's part of a study: its rows (in the order of its samples) and failures.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct StudyPart {
    /// The rows of the shard's samples.
    pub rows: Vec<Row>,
    /// The samples that failed, with why.
    pub failed: Vec<String>,
    /// Seconds synthesising.
    pub synth_s: f64,
    /// Seconds fitting.
    pub fit_s: f64,
}

/// The configurations a study of `config` fits.
fn study_combos(config: &StudyConfig) -> Vec<Combo> {
    let mut c = combos(config.no_pbd);
    if has_g_axis(&config.g) {
        c.push(g_given_combo());
    }
    c
}

/// The study from its shards' partial files (`scatterfit combine`), written into `out`. Rows are
/// put in the one-machine study's order: by the twin's g, η and α′ as the grid lists them, then
/// the configuration.
///
/// # Errors
/// A damaged partial file, or the files cannot be written.
pub fn combine(
    out: &Path,
    config_json: &serde_json::Value,
    partials: &[std::path::PathBuf],
    json: bool,
) -> anyhow::Result<ExitCode> {
    let config: StudyConfig =
        serde_json::from_value(config_json.clone()).context("the study's configuration")?;
    let all = study_combos(&config);
    let (mut rows, mut failed, mut synth_s, mut fit_s) = (Vec::new(), Vec::new(), 0.0, 0.0);
    for path in partials {
        let part = crate::shard::read::<StudyPart>(path)?.data;
        for r in part.rows {
            if !all.iter().any(|c| c.matches(&r)) {
                bail!(
                    "{}: a row fitted with {} + {} α′, {}, which this study does not fit",
                    path.display(),
                    r.model,
                    r.albedo_model,
                    r.method
                );
            }
            rows.push(r);
        }
        failed.extend(part.failed);
        synth_s += part.synth_s;
        fit_s += part.fit_s;
    }
    // The one-machine order: samples by g, η, then albedo triple (the grid's order), each
    // sample's rows by configuration.
    let pos = |v: &[f64], x: f64| v.iter().position(|&y| y == x).unwrap_or(usize::MAX);
    let combo_pos = |r: &Row| all.iter().position(|c| c.matches(r)).unwrap_or(usize::MAX);
    let gs = config.g.clone();
    rows.sort_by_key(|r| {
        (
            r.g.map_or(0, |g| pos(&gs, g)),
            pos(&config.etas, r.eta),
            pos(&config.albedos, r.albedo_prime) / 3,
            combo_pos(r),
            pos(&config.albedos, r.albedo_prime),
        )
    });
    write(out, &config, rows, &failed, synth_s, fit_s, json)
}

/// Writes study.csv, study.md, study.svg and study.png for `rows` into `out`, prints the summary,
/// lists the failures; exit 1 if any.
///
/// # Errors
/// The files cannot be written.
pub fn write(
    out: &Path,
    config: &StudyConfig,
    mut rows: Vec<Row>,
    failed: &[String],
    synth_s: f64,
    fit_s: f64,
    json: bool,
) -> anyhow::Result<ExitCode> {
    let g_axis = has_g_axis(&config.g);
    let assuming_g_0 = combos(config.no_pbd);
    let combos = study_combos(config);
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    // A padded triple repeats its last albedo: keep one row per grid point and configuration.
    dedup(&mut rows);
    let twins = format!(
        "Twins: the {} rig, seed {}, {}× the default Monte Carlo photons (a twin's own noise goes as \
         1/√ of that; at α′ ≥ 0.999 it reaches σ′s and σa at 1–2.5 % with the default, \
         `--photon-scale` raises it).\n\n",
        if config.quick { "quick" } else { "paper's" },
        config.seed,
        config.photon_scale
    );
    let summary = if g_axis {
        let mut t = format!(
            "## The g axis (twins at g = {})\n\n{}",
            config
                .g
                .iter()
                .map(|g| g.to_string())
                .collect::<Vec<_>>()
                .join(", "),
            g_axis_markdown(&rows, &combos, &config.g)
        );
        for &g in &config.g {
            let at: Vec<Row> = rows.iter().filter(|r| r.g == Some(g)).cloned().collect();
            t.push_str(&format!(
                "## Twins at g = {g}: every configuration\n\n{}",
                summary_markdown(&at, &combos)
            ));
        }
        t
    } else {
        summary_markdown(&rows, &combos)
    };
    // The figure: the first g's twins fitted assuming g = 0 (the isotropic study's figure without --g).
    let first_g: Vec<Row> = rows
        .iter()
        .filter(|r| r.g.is_none_or(|g| g == config.g[0]) && r.g_given != Some(true))
        .cloned()
        .collect();
    let csv = rows_csv(&rows);
    for (name, text) in [
        ("study.csv", csv),
        ("study.md", format!("{twins}{summary}")),
    ] {
        let p = out.join(name);
        scatterfit_io::atomic::write_atomic(&p, text.as_bytes())
            .with_context(|| format!("writing {}", p.display()))?;
    }
    let mut figure = scatterfit_lab::study_figure::study_figure(&first_g, &assuming_g_0);
    if g_axis {
        // Say which twins the figure shows: study.md has the g axis's tables.
        figure.title = format!(
            "{} at g = {}, fitted assuming g = 0 (the g axis: study.md)",
            figure.title, config.g[0]
        );
    }
    scatterfit_report::write_figure(
        &figure,
        Some(&out.join("study.svg")),
        Some(&out.join("study.png")),
    )?;
    if json {
        crate::output::print_json(&rows)?;
    } else {
        out!("{summary}")?;
        outln!(
            "\ntime: {synth_s:.0} s synthesising, {fit_s:.0} s fitting; files: {}/study.md, study.csv, study.png",
            out.display()
        )?;
    }
    if !failed.is_empty() {
        errln!("\n{} sample(s) failed:", failed.len());
        for f in failed {
            errln!("  {f}");
        }
        return Ok(ExitCode::from(1));
    }
    Ok(ExitCode::SUCCESS)
}
