//! `scatterfit batch`: many sample folders, measured in parallel; every good sample's result files
//! are written into its folder as soon as it is done, failures are listed at the end (exit 1 if
//! any), and summary.csv / summary.md (Table 1's shape) gather the good ones; index.html shows them
//! all, linked to their report.html, with the failures and their messages.

use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Mutex;

use scatterfit_io::result_json::MeasurementResult;

use crate::common::{FitArgs, SamplesArgs};
use crate::output::{out, outln};

/// Arguments of `scatterfit batch`.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub samples: SamplesArgs,
    /// Where to write summary.csv, summary.md and index.html (the command's own files, replaced on
    /// each run; checked before any sample is measured). Each sample's result files (result.json,
    /// .csv, .md, profile.csv, fit.svg, fit.png, report.html) go into its own folder and are
    /// replaced, as with `measure`.
    #[arg(
        short = 'o',
        long = "output-dir",
        value_name = "DIR",
        default_value = "."
    )]
    pub output_dir: PathBuf,
    #[command(flatten)]
    pub fit: FitArgs,
    /// Print the results as a JSON array.
    #[arg(long)]
    pub json: bool,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
}

/// Runs `scatterfit batch`.
pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let overrides = args.fit.overrides()?;
    crate::common::check_output_dir(&args.output_dir, "-o")?;
    let shared: Vec<PathBuf> = scatterfit_report::tables::TABLE1_FILES
        .iter()
        .chain([&scatterfit_report::html::INDEX_PAGE])
        .map(|f| args.output_dir.join(f))
        .collect();
    let (dirs, misspelt) = crate::common::samples_for(
        "batch",
        &args.samples.dirs,
        &crate::common::RESULT_FILES,
        &shared,
        &args.output_dir,
        args.samples.force,
        overrides.allow_outside_paths,
        args.quiet || args.json,
    )?;
    let write_errors = Mutex::new(Vec::<(PathBuf, String)>::new());
    let outcomes = crate::runner::measure_many(
        &dirs,
        &overrides,
        args.samples.jobs.count(),
        args.quiet || args.json,
        &|dir, r| {
            if let Ok(m) = r
                && let Err(e) = scatterfit_report::write_measurement(dir, m)
                && let Ok(mut w) = write_errors.lock()
            {
                w.push((dir.to_path_buf(), crate::common::error_text(&e.into())));
            }
        },
    )?;
    let mut results: Vec<MeasurementResult> = Vec::new();
    let mut result_dirs: Vec<PathBuf> = Vec::new();
    let mut failed: Vec<(PathBuf, String)> = write_errors.into_inner().unwrap_or_default();
    // The samples without a result (not measured, or their files not written), for the index.
    let mut not_measured: Vec<(PathBuf, String)> = failed.clone();
    not_measured.extend(misspelt.iter().cloned());
    let samples = dirs.len() + misspelt.len();
    failed.extend(misspelt);
    for o in &outcomes {
        match &o.result {
            Ok(m) => {
                let r = m.to_result(Some("profile.csv"));
                if !m.complete() {
                    let why: Vec<String> = r
                        .channels
                        .iter()
                        .filter_map(|c| c.problem.clone())
                        .collect();
                    failed.push((o.dir.clone(), why.join("; ")));
                } else if !scatterfit_report::trusted(&r) {
                    failed.push((o.dir.clone(), scatterfit_report::suspect_text(&r)));
                }
                results.push(r);
                result_dirs.push(o.dir.clone());
            }
            Err(e) => {
                let why = crate::common::error_text(e);
                not_measured.push((o.dir.clone(), why.clone()));
                failed.push((o.dir.clone(), why));
            }
        }
    }
    std::fs::create_dir_all(&args.output_dir)?;
    scatterfit_report::write_table1(&args.output_dir, &results)?;
    let index = scatterfit_report::html::write_results_index(
        &args.output_dir,
        "scatterfit batch",
        "One row per sample: its verdict (the data checks per channel), η, σ′s and σa per channel; \
         the sample's name opens its report.",
        &results,
        &result_dirs,
        &not_measured,
        &scatterfit_report::tables::TABLE1_FILES,
    )?;
    if args.json {
        crate::output::print_json(&results)?;
    } else {
        for r in &results {
            out!("{}", scatterfit_report::summary_text(r))?;
        }
        outln!(
            "\n{} of {} samples measured completely with every check ok; summary: {} and {}",
            samples - failed.len(),
            samples,
            args.output_dir.join("summary.csv").display(),
            args.output_dir.join("summary.md").display()
        )?;
        outln!("index: {}", index.display())?;
    }
    Ok(crate::common::list_failures(
        "failed, are incomplete or suspect",
        &failed,
    ))
}
