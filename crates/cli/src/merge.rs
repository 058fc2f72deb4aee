//! `scatterfit merge`: an exposure bracket → an HDR radiance map (Debevec & Malik 1997).
//!
//! The pipeline's HDR stage (`scatterfit_pipeline::hdr`) reads the frames (in parallel), recovers
//! the camera response (or takes a known one) and merges; this command checks its flags and
//! outputs first, shows the reading's progress, checks the merge's memory, saves the radiance map
//! (EXR or HDR) and the response (CSV), and prints the summary
//! (`scatterfit_pipeline::radiance::MergeSummary`). 8-bit frames use a response curve;
//! 16-bit frames are merged as linear data (raw or linear TIFF).

use std::path::PathBuf;
use std::process::ExitCode;

use crate::output::{errln, out};
use anyhow::Context;
use scatterfit_io::image_files::write_radiance;
use scatterfit_io::response_csv::{ResponseTable, write_response_csv};
use scatterfit_pipeline::hdr::{self, HdrStage};
use scatterfit_pipeline::merge_settings::{MergeOutputs, MergeSettings};
use scatterfit_pipeline::radiance::MergeSummary;

/// Arguments of `scatterfit merge`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The frames of the bracket (PNG, TIFF or JPEG; 8- or 16-bit; grey or RGB; or camera RAW: DNG,
    /// CR2, CR3, NEF, ARW, RAF, ORF, RW2, PEF, …, whose times come from their metadata). May be
    /// omitted when --exposures lists them.
    pub images: Vec<PathBuf>,
    #[command(flatten)]
    pub settings: MergeSettings,
    /// The radiance map to write (.exr: 32-bit float, uncompressed; .hdr: Radiance RGBE); checked
    /// with --response-out before any work; existing files only with --force.
    #[arg(short, long, value_name = "FILE")]
    pub output: PathBuf,
    /// Where to save the camera response (.csv; default: beside the output, `<name>.response.csv`).
    /// Written after the radiance map, so a map that cannot be written leaves no response behind.
    #[arg(long, value_name = "CSV")]
    pub response_out: Option<PathBuf>,
    /// Replace existing output files.
    #[arg(long)]
    pub force: bool,
    #[command(flatten)]
    pub memory: crate::numeric::MemoryArgs,
    /// Print the summary as JSON.
    #[arg(long)]
    pub json: bool,
}

/// Reads the bracket (with a progress bar unless `quiet`), notes dropped alpha channels, checks the
/// merge's memory against the budget and merges, through the pipeline's HDR stage.
fn read_and_merge(args: &Args, quiet: bool) -> anyhow::Result<HdrStage> {
    let budget = args.memory.budget();
    let mut inputs = args.settings.hdr_inputs(args.images.clone(), budget);
    let bar = crate::common::bar(
        args.images.len() as u64,
        "reading frames {bar:30} {pos}/{len} {elapsed}",
        quiet,
    );
    let read = hdr::read_frames(&inputs, &|_| bar.inc(1))?;
    bar.finish_and_clear();
    for path in &read.dropped_alpha {
        errln!("note: {}: alpha channel ignored", path.display());
    }
    // The merge's own allocations (radiance f32 + clipping mask + the encoded file), beside the
    // frames already read, before any is made.
    crate::numeric::check_memory(
        &format!("merging {} frames of {}", read.frames.len(), read.image),
        read.decoded_bytes() + read.samples_per_frame() * (4 + 1 + 4),
        budget,
    )?;
    // Unset, the merge takes the default for the frames it keeps (a frame without signal is
    // left out first, and fewer frames need more sample pixels).
    inputs.samples = args.settings.samples;
    Ok(hdr::merge_frames(read, &inputs)?)
}

/// Runs `scatterfit merge`.
pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let MergeOutputs {
        response_out,
        writes_response,
    } = args.settings.check_outputs(
        &args.images,
        &args.output,
        args.response_out.as_deref(),
        args.force,
    )?;

    let stage = read_and_merge(&args, args.json)?;
    // The radiance map first: if it cannot be written, no response CSV is left without it.
    write_radiance(&args.output, &stage.hdr.radiance).context("saving the radiance map")?;
    let response_written = match &stage.response {
        Some(curve) if writes_response => {
            let table = ResponseTable {
                g: curve.tables().iter().map(|t| t.to_vec()).collect(),
            };
            write_response_csv(&response_out, &table)?;
            Some(response_out)
        }
        _ => None,
    };

    let summary = MergeSummary::new(&stage, args.output.clone(), response_written);
    if args.json {
        crate::output::print_json(&summary)?;
    } else {
        out!("{}", summary.text())?;
    }
    Ok(ExitCode::SUCCESS)
}
