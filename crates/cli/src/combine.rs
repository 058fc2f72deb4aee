//! `scatterfit combine PARTIALS... -o OUT`: adds up the partial files of a sharded run (`--shard
//! K/N` of `table`, `batch` or `study`) into what the run on one machine gives — for a table the same bytes
//! (its tallies are exact sums, rounded once), for a batch the same summary and index.
//!
//! The set is checked first, naming the file: every file a partial of one run (same kind,
//! fingerprint and scatterfit version), shards 1…N each exactly once.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
use serde::de::IgnoredAny;

use crate::output::{errln, out};
use crate::shard::{Kind, Partial};

/// Arguments of `scatterfit combine`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The partial files of one run (all N shards; e.g. `partials/table-*.json`).
    #[arg(required = true, value_name = "PARTIALS")]
    pub partials: Vec<PathBuf>,
    /// What to write: a table's `.json` file (the form `scatterfit table -o` writes), a batch's
    /// folder for summary.csv, summary.md and index.html, or a study's folder for study.md,
    /// study.csv and study.png (the shards' -o, where their samples are).
    #[arg(short = 'o', long = "output", value_name = "OUT")]
    pub output: PathBuf,
    /// Replace an existing table file.
    #[arg(long)]
    pub force: bool,
    /// Cache folder a combined table is also stored in, as `scatterfit table` stores it (default:
    /// $SCATTERFIT_CACHE, else $XDG_CACHE_HOME/scatterfit, else ~/.cache/scatterfit).
    #[arg(long)]
    pub cache_dir: Option<PathBuf>,
    /// Print the result as JSON (a table's summary; a batch's results).
    #[arg(long)]
    pub json: bool,
    /// Nothing on stderr but errors.
    #[arg(long)]
    pub quiet: bool,
}

/// Runs `scatterfit combine`.
pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let t0 = std::time::Instant::now();
    let parts = crate::shard::check_set(&args.partials)?;
    let kind = parts[0].kind;
    let code = match kind {
        Kind::Table => combine_table(&args, parts)?,
        Kind::Batch => crate::batch_set::combine(&args.output, &args.partials, args.json)?,
        Kind::Study => {
            crate::study_set::combine(&args.output, &parts[0].inputs, &args.partials, args.json)?
        }
    };
    if !args.quiet {
        errln!(
            "combined {} shards of a {} in {:.2} s",
            args.partials.len(),
            kind.name(),
            t0.elapsed().as_secs_f64()
        );
    }
    Ok(code)
}

/// The table from the checked set: each file's sums read straight into their type (no
/// intermediate JSON tree: a shipped-size partial is ~10 MB).
fn combine_table(args: &Args, parts: Vec<Partial<IgnoredAny>>) -> anyhow::Result<ExitCode> {
    crate::common::check_output_file(
        &args.output,
        "-o",
        crate::common::Format {
            extensions: &["json"],
            what: "the table is written as JSON",
        },
        &args
            .partials
            .iter()
            .map(PathBuf::as_path)
            .collect::<Vec<_>>(),
        args.force,
    )?;
    let (inputs, count) = (parts[0].inputs.clone(), parts[0].shard.count());
    drop(parts);
    let (spec, table) = scatterfit_lab::partial::combine_table(&inputs, count, &args.partials)?;
    crate::table::write_compact(&table, &args.output)?;
    // Also where `scatterfit table` keeps it, so that the tool finds it as if built here.
    let cached =
        crate::common::cache_dir(args.cache_dir.as_deref()).map(|d| d.join(spec.file_name()));
    if let Some(path) = &cached {
        table
            .save(path)
            .with_context(|| format!("storing the table in the cache: {}", path.display()))?;
    }
    let summary = scatterfit_mc::TableSummary::new(
        &table,
        &spec,
        scatterfit_mc::cache::CacheStatus::Built,
        cached.unwrap_or_else(|| args.output.clone()),
        Some(args.output.clone()),
    );
    if args.json {
        crate::output::print_json(&summary)?;
    } else {
        out!("{}", summary.text())?;
    }
    Ok(ExitCode::SUCCESS)
}
