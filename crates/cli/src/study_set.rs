//! A bias study's rows as one set: the tables (`study.md`, `study.csv`) and the figure
//! (`study.png`) made of them (`scatterfit_lab::study_run::write_study`) — by `scatterfit study`
//! itself, and by `scatterfit combine` from the partial files of `study --shard K/N` (each a
//! round-robin slice of the grid's samples; `scatterfit_lab::study_run::combine_parts`).

use std::path::Path;
use std::process::ExitCode;

use anyhow::Context;
use scatterfit_lab::study::Row;
use scatterfit_lab::study_run::{StudyConfig, StudyPart, combine_parts, write_study};

use crate::output::{errln, out, outln};

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
    let mut parts = Vec::with_capacity(partials.len());
    for path in partials {
        parts.push((path.clone(), crate::shard::read::<StudyPart>(path)?.data));
    }
    let sum = combine_parts(&config, parts)?;
    write(
        out,
        &config,
        sum.rows,
        &sum.failed,
        sum.synth_s,
        sum.fit_s,
        json,
    )
}

/// Writes study.csv, study.md, study.svg and study.png for `rows` into `out`, prints the summary,
/// lists the failures; exit 1 if any.
///
/// # Errors
/// The files cannot be written.
pub fn write(
    out: &Path,
    config: &StudyConfig,
    rows: Vec<Row>,
    failed: &[String],
    synth_s: f64,
    fit_s: f64,
    json: bool,
) -> anyhow::Result<ExitCode> {
    let files = write_study(out, config, rows)?;
    let (rows, summary) = (files.rows, files.summary);
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
