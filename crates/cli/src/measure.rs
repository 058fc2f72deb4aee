//! `scatterfit measure`: one sample folder → σ′s, σa and η per channel (the paper's Table 1 row),
//! with the result files written into the folder (or `--output-dir`).

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
use scatterfit_pipeline::{Stage, measure_inputs};

use crate::common::{FitArgs, bar};
use crate::output::{errln, out, outln};

/// Arguments of `scatterfit measure`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The sample folder (holding sample.toml).
    pub dir: PathBuf,
    /// Where to write result.json, result.csv, result.md, profile.csv, fit.svg, fit.png, the page
    /// report.html and, last, result-files.json (default: the sample folder; these files are the
    /// command's own and are replaced). A folder holding another sample's results, or another
    /// sample's folder, is refused without --force.
    #[arg(short = 'o', long = "output-dir", value_name = "DIR")]
    pub output_dir: Option<PathBuf>,
    /// Write into an -o folder that holds another sample's results (or is another sample's folder).
    #[arg(long)]
    pub force: bool,
    #[command(flatten)]
    pub fit: FitArgs,
    /// Print result.json on stdout instead of the summary.
    #[arg(long)]
    pub json: bool,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
}

/// Runs `scatterfit measure`.
pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let overrides = args.fit.overrides()?;
    let out = args.output_dir.clone().unwrap_or_else(|| args.dir.clone());
    // Where the result files go is checked before the measurement (milliseconds, not minutes):
    // writable, not another sample's, and no result file over one of the sample's inputs.
    crate::common::check_output_dir(&out, "-o")?;
    let inputs = scatterfit_pipeline::sample_inputs(&args.dir, overrides.allow_outside_paths)
        .with_context(|| format!("measuring {}", args.dir.display()))?;
    crate::common::refuse_foreign_results(&inputs.manifest.dir, &out, args.force)?;
    let outputs: Vec<PathBuf> = crate::common::RESULT_FILES
        .iter()
        .map(|f| out.join(f))
        .collect();
    crate::common::refuse_outputs_that_are_inputs("measure", &outputs, &inputs.files)?;
    for o in &outputs {
        crate::common::check_destination(o, "-o")?;
    }
    let bar = bar(6, "{msg} {bar:30} {elapsed}", args.quiet || args.json);
    // The inputs resolved above are measured: the manifest is read once, and the one whose
    // outputs were checked is the one measured.
    let m = measure_inputs(&inputs, &overrides, &|stage| {
        let msg = match stage {
            Stage::Spectro => "spectrophotometer",
            Stage::ReadFrame => "reading frames",
            Stage::Merge => "merging",
            Stage::Profile => "profile",
            Stage::Fit => "fitting",
            Stage::Checks => "checks",
            _ => "",
        };
        bar.set_message(msg);
        bar.tick();
    })
    .with_context(|| format!("measuring {}", args.dir.display()))?;
    bar.finish_and_clear();
    for w in &m.spectro.warnings {
        errln!("warning: {w}");
    }
    for p in &m.hdr.dropped_alpha {
        errln!("note: {}: alpha channel ignored", p.display());
    }
    let scatterfit_report::WrittenReport {
        result,
        files: written,
    } = scatterfit_report::write_measurement(&out, &m)?;
    if args.json {
        crate::output::print_json(&result)?;
    } else {
        out!("{}", scatterfit_report::summary_text(&result))?;
        let t = &m.timings;
        outln!(
            "  time: {:.3} s (spectro {:.3}, read {:.3}, merge {:.3}, profile {:.3}, fits {:.4}, \
             checks {:.3})",
            t.total_s,
            t.spectro_s,
            t.read_s,
            t.merge_s,
            t.profile_s,
            t.fit_s,
            t.checks_s
        )?;
        outln!(
            "  wrote {} files in {}: {}",
            written.len(),
            out.display(),
            written
                .iter()
                .filter_map(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
                .collect::<Vec<_>>()
                .join(", ")
        )?;
    }
    // Exit 1 for a channel without constrained parameters, or one the data checks call suspect
    // (the files are written first: the lab looks at fit.png and result.json's `quality`).
    Ok(if scatterfit_report::trusted(&result) && m.complete() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}
