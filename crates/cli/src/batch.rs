//! `scatterfit batch`: many sample folders, measured in parallel; every good sample's result files
//! are written into its folder as soon as it is done, failures are listed at the end (exit 1 if
//! any), and summary.csv / summary.md (Table 1's shape) gather the good ones; index.html shows them
//! all, linked to their report.html, with the failures and their messages.
//!
//! A sample whose result files are one complete set (`result-files.json`) and whose `result.json`
//! records the hashes its input files still have — and the options given here — is not measured
//! again (its result is reused) unless `--force`. With `--shard K/N` the command measures every Nth
//! sample (round-robin over the sorted list) and writes their results into a partial file;
//! `scatterfit combine` makes the summary and the index of all.

use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Mutex;

use scatterfit_report::batch_set::{BatchPlan, plan_batch};
use serde::Serialize;

use crate::batch_set::{Entry, summarise};
use crate::common::{FitArgs, SamplesArgs};
use crate::output::errln;

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
    #[command(flatten)]
    pub shard: crate::shard::ShardArgs,
    /// Print the results as a JSON array.
    #[arg(long)]
    pub json: bool,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
}

/// What a batch's shards have in common (the partial files' run fingerprint).
#[derive(Serialize)]
struct BatchInputs {
    samples: Vec<PathBuf>,
    misspelt: Vec<PathBuf>,
    overrides: String,
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
    let quiet = args.quiet || args.json;
    let misspelt_dirs: Vec<PathBuf> = misspelt.iter().map(|(d, _)| d.clone()).collect();
    let job = match args.shard.get()? {
        Some((shard, dir)) => {
            let inputs = BatchInputs {
                samples: dirs.clone(),
                misspelt: misspelt_dirs.clone(),
                overrides: format!("{overrides:?}"),
            };
            let job = crate::shard::Job::new(dir, crate::shard::Kind::Batch, shard, &inputs);
            if job.done::<Vec<Entry>>(args.samples.force, |_| true)? {
                if !quiet {
                    errln!(
                        "shard {shard}: {} is there and matches; nothing to do",
                        job.path.display()
                    );
                }
                return Ok(ExitCode::SUCCESS);
            }
            Some((shard, job))
        }
        None => None,
    };
    let owned = |i: usize| job.as_ref().is_none_or(|(shard, _)| shard.owns(i));
    let BatchPlan { mut entries, todo } =
        plan_batch(&dirs, &misspelt, &overrides, args.samples.force, &owned);
    let reused = entries.iter().filter(|e| e.reused).count();
    if reused > 0 && !quiet {
        errln!(
            "{reused} sample(s) not measured again: their result files match their inputs (--force \
             measures them again)"
        );
    }
    let todo_dirs: Vec<PathBuf> = todo.iter().map(|(_, d)| d.clone()).collect();
    let write_errors = Mutex::new(Vec::<(PathBuf, String)>::new());
    let outcomes = crate::runner::measure_many(
        &todo_dirs,
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
    let write_errors = write_errors.into_inner().unwrap_or_default();
    for o in &outcomes {
        let dir = &o.dir;
        let i = todo
            .iter()
            .find(|(_, d)| d == dir)
            .map_or(usize::MAX, |(i, _)| *i);
        let written = write_errors
            .iter()
            .find(|(d, _)| d == dir)
            .map(|(_, e)| e.clone());
        entries.push(match (&o.result, written) {
            (Ok(m), None) => {
                Entry::with_result(i, dir.clone(), m.to_result(Some("profile.csv")), false)
            }
            (Ok(_), Some(e)) => Entry::failed(i, dir.clone(), e),
            (Err(e), _) => Entry::failed(i, dir.clone(), crate::common::error_text(e)),
        });
    }
    entries.sort_by_key(|e| e.index);
    if let Some((shard, job)) = job {
        job.write(&entries, std::env::args().collect())?;
        if !quiet {
            errln!(
                "shard {shard}: {} sample(s), {} failed, incomplete or suspect; {} (the summary: \
                 `scatterfit combine`)",
                entries.len(),
                entries.iter().filter(|e| e.failure.is_some()).count(),
                job.path.display()
            );
        }
        // A failed sample is the combined run's news (exit 1 there): the shard itself succeeded,
        // so that a job array's dependent combine step runs.
        return Ok(ExitCode::SUCCESS);
    }
    summarise(&args.output_dir, &entries, args.json)
}
