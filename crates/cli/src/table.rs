//! `scatterfit table`: builds (or shows) a cached Monte Carlo table for one η and g — the table the
//! `mc` forward model uses (`scatterfit_mc::McTable`: a white Monte Carlo run smoothed per albedo;
//! the tables shipped with scatterfit for g = 0 are such tables, `McTableSpec::shipped`) — and can
//! write it to a file.

use std::path::PathBuf;
use std::process::ExitCode;

use crate::output::{errln, out};
use anyhow::{Context, bail};
use scatterfit_mc::{McTableSpec, TableSummary};
use scatterfit_pipeline::monte_carlo::TableSettings;

/// Arguments of `scatterfit table`. Every number is checked before any work (exit 2 when out of
/// range); the build's expected work and memory are checked against `--max-interactions` and
/// `--max-memory-mib` before it starts.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub table: TableSettings,
    /// Cache folder (default: $SCATTERFIT_CACHE, else $XDG_CACHE_HOME/scatterfit, else ~/.cache/scatterfit).
    #[arg(long)]
    pub cache_dir: Option<PathBuf>,
    /// Also write the table to this file (`.json`, the compact form of the shipped tables: no raw
    /// profiles; checked before the build; an existing file only with --force).
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    pub output: Option<PathBuf>,
    /// Replace an existing output file; with --shard, redo a shard whose partial file is there but
    /// does not match.
    #[arg(long)]
    pub force: bool,
    #[command(flatten)]
    pub work: crate::numeric::WorkArgs,
    #[command(flatten)]
    pub memory: crate::numeric::MemoryArgs,
    #[command(flatten)]
    pub shard: crate::shard::ShardArgs,
    /// Print the table summary as JSON.
    #[arg(long)]
    pub json: bool,
    /// No progress bar and no cost estimate on stderr.
    #[arg(long)]
    pub quiet: bool,
}

/// The spec of a table split into `shards` shards (`scatterfit slurm table`), checked as
/// `scatterfit table --shard K/N` checks it.
///
/// # Errors
/// As [`TableSettings::spec`].
pub fn spec_for_shards(args: &Args, shards: u64) -> anyhow::Result<McTableSpec> {
    let settings = TableSettings {
        max_interactions: args.work.max_interactions,
        memory_budget: args.memory.budget(),
        ..args.table.clone()
    };
    Ok(settings.spec(shards, rayon::current_num_threads())?)
}

/// Runs `scatterfit table`.
pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let spec = spec_for_shards(&args, args.shard.shard.map_or(1, |s| s.count()))?;
    if let Some((shard, dir)) = args.shard.get()? {
        return run_shard(&args, &spec, shard, dir);
    }
    let dir = match crate::common::cache_dir(args.cache_dir.as_deref()) {
        Some(d) => d,
        None => bail!("no cache folder: pass --cache-dir or set SCATTERFIT_CACHE"),
    };
    if let Some(out) = &args.output {
        crate::common::check_output_file(
            out,
            "-o",
            crate::common::Format {
                extensions: &["json"],
                what: "the table is written as JSON",
            },
            &[],
            args.force,
        )?;
    }
    let cached = dir.join(spec.file_name()).is_file();
    if !cached {
        // The table is written there once built: find out now, not after the build.
        crate::common::check_output_dir(&dir, "--cache-dir")?;
    }
    let cost = spec.cost_estimate()?;
    let expected_s = cost.seconds(rayon::current_num_threads());
    if !args.quiet && !cached && expected_s > 10.0 {
        errln!(
            "expected work: {:.1e} interactions, about {} on {} threads",
            cost.interactions,
            crate::numeric::describe_seconds(expected_s),
            rayon::current_num_threads()
        );
    }
    let bar = crate::common::bar(0, crate::common::PHOTONS_BAR, args.quiet);
    let (table, status, path) =
        scatterfit_mc::McTable::load_or_build(&spec, &dir, &|done, total| {
            bar.set_length(total);
            bar.set_position(done);
        })
        .with_context(|| format!("building the table in {}", dir.display()))?;
    bar.finish_and_clear();
    let summary = TableSummary::new(&table, &spec, status, path, args.output.clone());
    if let Some(out) = &args.output {
        write_compact(&table, out)?;
    }
    if args.json {
        crate::output::print_json(&summary)?;
    } else {
        out!("{}", summary.text())?;
    }
    Ok(ExitCode::SUCCESS)
}

/// Writes `table` to `out` (-o) in the compact form of the shipped tables (no raw profiles).
///
/// # Errors
/// The file cannot be written.
pub fn write_compact(table: &scatterfit_mc::McTable, out: &std::path::Path) -> anyhow::Result<()> {
    let json = serde_json::to_vec(&table.clone().compact())
        .context("the table does not serialise (a defect)")?;
    scatterfit_io::atomic::write_atomic(out, &json).with_context(|| format!("-o {}", out.display()))
}

/// `scatterfit table --shard K/N`: the shard's part of the table's white run, written as a partial
/// file (exact sums, `scatterfit_mc::white::WhitePartial`); `scatterfit combine` makes the table.
fn run_shard(
    args: &Args,
    spec: &McTableSpec,
    shard: scatterfit_mc::Shard,
    dir: &std::path::Path,
) -> anyhow::Result<ExitCode> {
    if let Some(out) = &args.output {
        bail!(
            "-o {}: with --shard the table is written by `scatterfit combine PARTIALS... -o {}` \
             once every shard is done; leave -o out here",
            out.display(),
            out.display()
        );
    }
    let job = crate::shard::Job::new(dir, crate::shard::Kind::Table, shard, spec);
    let white = spec.white()?;
    if job.done::<scatterfit_mc::white::WhitePartial>(args.force, |p| {
        p.spec == white && p.shard == shard
    })? {
        if !args.quiet {
            errln!(
                "shard {shard}: {} is there and matches; nothing to do",
                job.path.display()
            );
        }
        return Ok(ExitCode::SUCCESS);
    }
    let t0 = std::time::Instant::now();
    let bar = crate::common::bar(0, crate::common::PHOTONS_BAR, args.quiet);
    let part = scatterfit_mc::McTable::build_shard(spec, shard, &|done, total| {
        bar.set_length(total);
        bar.set_position(done);
    })?;
    bar.finish_and_clear();
    let photons = white.shard_photons(shard);
    job.write(&part, std::env::args().collect())?;
    if !args.quiet {
        errln!(
            "shard {shard}: {photons} of {} photons in {:.1} s; {}",
            white.photons(),
            t0.elapsed().as_secs_f64(),
            job.path.display()
        );
    }
    Ok(ExitCode::SUCCESS)
}
