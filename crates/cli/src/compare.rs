//! `scatterfit compare`: both methods on the same data — the proposed (α′ from the
//! spectrophotometer, σ′s fitted) and the existing (σ′s and σa fitted) — per channel: parameters,
//! fit time and MSE (the paper's Table 2 shape), and a plot per sample shaped like its Figure 6
//! (compare.svg, compare.png in the sample folder); index.html lists the samples with links to
//! their plots.

use std::path::PathBuf;
use std::process::ExitCode;

use scatterfit_io::result_table::table2_markdown;

use crate::common::{FitArgs, SamplesArgs};
use crate::output::{out, outln};

/// Arguments of `scatterfit compare`.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub samples: SamplesArgs,
    /// Where to write compare.csv, compare.md and index.html (the command's own files, replaced
    /// on each run; checked before any sample is measured). Each sample's plot (compare.svg,
    /// compare.png) goes into its own folder and is replaced.
    #[arg(
        short = 'o',
        long = "output-dir",
        value_name = "DIR",
        default_value = "."
    )]
    pub output_dir: PathBuf,
    #[command(flatten)]
    pub fit: FitArgs,
    /// Print the pairs of results as JSON.
    #[arg(long)]
    pub json: bool,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
    /// Exit 0 when a sample's data checks found a channel suspect (the warning is still printed
    /// and written above compare.md's table).
    #[arg(long)]
    pub allow_suspect: bool,
}

/// Runs `scatterfit compare`.
pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let overrides = args.fit.overrides()?;
    crate::common::check_output_dir(&args.output_dir, "-o")?;
    let shared: Vec<PathBuf> = scatterfit_report::tables::TABLE2_FILES
        .iter()
        .chain([&scatterfit_report::html::INDEX_PAGE])
        .map(|f| args.output_dir.join(f))
        .collect();
    let (dirs, misspelt) = crate::common::samples_for(
        "compare",
        &args.samples.dirs,
        &["compare.svg", "compare.png"],
        &shared,
        &args.output_dir,
        args.samples.force,
        overrides.allow_outside_paths,
        args.quiet || args.json,
    )?;
    let crate::runner::Comparison {
        pairs,
        dirs: pair_dirs,
        mut failed,
        ..
    } = crate::runner::compare_dirs(
        &dirs,
        &overrides,
        args.samples.jobs.count(),
        args.quiet || args.json,
        false,
        false,
    )?;
    failed.extend(misspelt);
    std::fs::create_dir_all(&args.output_dir)?;
    scatterfit_report::write_table2(&args.output_dir, &pairs)?;
    let proposed: Vec<_> = pairs.iter().map(|(_, p)| p.clone()).collect();
    let index = scatterfit_report::html::write_results_index(
        &args.output_dir,
        "scatterfit compare",
        "One row per sample, the proposed method's values (α′ from the spectrophotometer, σ′s \
         fitted); Figure 6 compares them with the existing method's fit; compare.md has both.",
        &proposed,
        &pair_dirs,
        &failed,
        &scatterfit_report::tables::TABLE2_FILES,
    )?;
    if args.json {
        crate::output::print_json(&pairs)?;
    } else {
        out!("{}", table2_markdown(&pairs))?;
        outln!(
            "\nplots: compare.svg / compare.png in each sample folder; tables: {} and {}",
            args.output_dir.join("compare.csv").display(),
            args.output_dir.join("compare.md").display()
        )?;
        outln!("index: {}", index.display())?;
    }
    let code = crate::common::list_failures("failed", &failed);
    let mut honest = std::process::ExitCode::SUCCESS;
    for ((existing, proposed), dir) in pairs.iter().zip(&pair_dirs) {
        for r in [existing, proposed] {
            let c = crate::common::suspect_exit(dir, r, args.allow_suspect);
            if c != std::process::ExitCode::SUCCESS {
                honest = c;
            }
        }
    }
    Ok(if code == std::process::ExitCode::SUCCESS {
        honest
    } else {
        code
    })
}
