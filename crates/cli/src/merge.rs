//! `scatterfit merge`: an exposure bracket → an HDR radiance map (Debevec & Malik 1997).
//!
//! The pipeline's HDR stage (`scatterfit_pipeline::hdr`) reads the frames (in parallel), recovers
//! the camera response (or takes a known one) and merges; this command checks its flags and
//! outputs first, shows the reading's progress, checks the merge's memory, saves the radiance map
//! (EXR or HDR) and the response (CSV), and prints the summary
//! (`scatterfit_pipeline::radiance::MergeSummary`). 8-bit frames use a response curve;
//! 16-bit frames are merged as linear data (raw or linear TIFF).

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use crate::output::{errln, out};
use anyhow::{Context, bail};
use scatterfit_imaging::{ClippedFill, Weighting};
use scatterfit_io::image_files::write_radiance;
use scatterfit_io::response_csv::{ResponseTable, write_response_csv};
use scatterfit_pipeline::hdr::{self, HdrInputs, HdrStage};
use scatterfit_pipeline::radiance::MergeSummary;

/// What to store for a pixel-channel clipped in every exposure (it is always counted and reported).
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Fill {
    /// NaN: the profile and spot finder skip it.
    Nan,
    /// The largest radiance the data prove (saturated) or 0 (dark).
    LowerBound,
}

/// How 8-bit samples are weighted across the bracket.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum WeightingArg {
    /// Chosen from the bracket: noise-optimal, unless the paper's hat explains the frames clearly
    /// better (processed JPEGs, phones, scanned film; BENCHMARKS.md, "Real brackets").
    Auto,
    /// Noise-aware linear-domain average (Robertson et al. 2003 / Granados et al. 2010): unbiased for
    /// dim pixels (BENCHMARKS.md, "dim pixels").
    NoiseOptimal,
    /// The paper's hat on ln E (Debevec & Malik 1997, eq. 6), as OpenCV's MergeDebevec.
    DebevecHat,
}

/// Arguments of `scatterfit merge`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The frames of the bracket (PNG, TIFF or JPEG; 8- or 16-bit; grey or RGB; or camera RAW: DNG,
    /// CR2, CR3, NEF, ARW, RAF, ORF, RW2, PEF, …, whose times come from their metadata). May be
    /// omitted when --exposures lists them.
    pub images: Vec<PathBuf>,
    /// Exposure times: a CSV with header `file,time_s` (paths relative to the CSV's folder; times in
    /// seconds, `0.01` or `1/100`). Without it, times come from each file's EXIF ExposureTime.
    #[arg(long, value_name = "CSV")]
    pub exposures: Option<PathBuf>,
    /// A known camera response (CSV `z,g_r,g_g,g_b`, as written by --response-out) instead of
    /// recovering one. 8-bit frames only.
    #[arg(long, value_name = "CSV")]
    pub response: Option<PathBuf>,
    /// A dark frame (lens capped, same settings), subtracted before merging.
    #[arg(long, value_name = "IMAGE")]
    pub dark: Option<PathBuf>,
    /// Smoothness weight λ of the response recovery (Debevec & Malik 1997, eq. 3), in [0, 10⁶]
    /// (dimensionless; OpenCV's default 10).
    #[arg(long, default_value_t = 10.0, value_parser = crate::numeric::parse_finite)]
    pub lambda: f64,
    /// Sample pixels per channel for the response recovery: a count from ⌈256/(P − 1)⌉ for P frames
    /// (22 for 13; Debevec & Malik's N(P − 1) ≥ 256, fewer leave the curve undetermined) to 1000
    /// (more only cost time: the solve grows as N·P). Default 100, or that minimum when larger.
    #[arg(long, value_parser = crate::numeric::parse_size)]
    pub samples: Option<usize>,
    /// 16-bit frames: raw value at and above which a sample counts as saturated, 2 to 65535.
    #[arg(long, default_value_t = u16::MAX, value_parser = clap::value_parser!(u16).range(2..))]
    pub saturation: u16,
    /// Value stored for pixels clipped in every exposure.
    #[arg(long, value_enum, default_value_t = Fill::Nan)]
    pub clipped_fill: Fill,
    /// Sample weighting of 8-bit brackets.
    #[arg(long, value_enum, default_value_t = WeightingArg::Auto)]
    pub weighting: WeightingArg,
    /// The radiance map to write (.exr: 32-bit float, PIZ lossless; .hdr: Radiance RGBE); checked
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

fn default_response_out(output: &Path) -> PathBuf {
    let stem = output
        .file_stem()
        .map_or_else(|| "radiance".into(), |s| s.to_string_lossy().into_owned());
    output.with_file_name(format!("{stem}.response.csv"))
}

/// The pipeline's inputs for these flags and the memory budget \[bytes\] (the sample count is set
/// once the frames are counted).
fn hdr_inputs(args: &Args, budget: u64) -> HdrInputs {
    let mut inputs = HdrInputs::new(args.exposures.clone(), args.images.clone());
    inputs.response.clone_from(&args.response);
    inputs.dark.clone_from(&args.dark);
    inputs.lambda = args.lambda;
    inputs.saturation = args.saturation;
    inputs.clipped_fill = fill(args.clipped_fill);
    inputs.weighting_auto = args.weighting == WeightingArg::Auto;
    inputs.weighting = match args.weighting {
        WeightingArg::Auto | WeightingArg::NoiseOptimal => Weighting::NoiseOptimal,
        WeightingArg::DebevecHat => Weighting::DebevecHat,
    };
    inputs.memory_budget = Some(budget);
    inputs
}

/// Reads the bracket (with a progress bar unless `quiet`), notes dropped alpha channels, checks the
/// merge's memory against the budget and merges, through the pipeline's HDR stage.
fn read_and_merge(args: &Args, quiet: bool) -> anyhow::Result<HdrStage> {
    let budget = args.memory.budget();
    let mut inputs = hdr_inputs(args, budget);
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
    inputs.samples = Some(
        args.samples
            .unwrap_or_else(|| hdr::default_response_samples(read.frames.len())),
    );
    Ok(hdr::merge_frames(read, &inputs)?)
}

fn fill(f: Fill) -> ClippedFill {
    match f {
        Fill::Nan => ClippedFill::Nan,
        Fill::LowerBound => ClippedFill::LowerBound,
    }
}

/// Checks every number before any file is read: λ and the sample count (its lower bound follows
/// from the number of frames, known from the list or the exposures CSV).
fn check_numbers(args: &Args, frames: usize) -> anyhow::Result<()> {
    use crate::numeric::ensure;
    ensure(
        (0.0..=1e6).contains(&args.lambda),
        "--lambda",
        args.lambda,
        "the smoothness weight must lie in [0, 1e6] (Debevec & Malik 1997, eq. 3; default 10)",
    )?;
    let Some(samples) = args.samples else {
        return Ok(());
    };
    let min = scatterfit_imaging::min_response_samples(frames.max(2));
    let max = scatterfit_imaging::MAX_RESPONSE_SAMPLES;
    ensure(
        (min..=max).contains(&samples),
        "--samples",
        samples,
        &format!(
            "the response recovery takes {min} to {max} sample pixels per channel for {frames} \
             frames: with N samples and P frames Debevec & Malik's N(P − 1) ≥ 256 must hold, or \
             the curve is undetermined; more than {max} only cost time"
        ),
    )
}

/// Runs `scatterfit merge`.
pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let mut inputs: Vec<&Path> = args.images.iter().map(PathBuf::as_path).collect();
    inputs.extend(args.exposures.as_deref());
    inputs.extend(args.response.as_deref());
    inputs.extend(args.dark.as_deref());
    // Frame paths listed in the CSV are inputs too.
    let listed = match &args.exposures {
        Some(csv) => scatterfit_io::bracket::read_exposures_csv(csv)?,
        None => Vec::new(),
    };
    inputs.extend(listed.iter().map(|e| e.path.as_path()));
    let frames = if args.images.is_empty() {
        listed.len()
    } else {
        args.images.len()
    };
    if args.response.is_none() {
        check_numbers(&args, frames)?;
    }
    crate::common::check_output_file(
        &args.output,
        "-o",
        crate::common::Format {
            extensions: &["exr", "hdr"],
            what: "the radiance map is written as OpenEXR or Radiance HDR",
        },
        &inputs,
        args.force,
    )?;
    let response_out = args
        .response_out
        .clone()
        .unwrap_or_else(|| default_response_out(&args.output));
    if crate::common::identity(&response_out) == crate::common::identity(&args.output) {
        bail!(
            "--response-out and -o are the same file {}; choose two files",
            args.output.display()
        );
    }
    let writes_response = args.response.is_none() || args.response_out.is_some();
    if writes_response {
        crate::common::check_output_file(
            &response_out,
            "--response-out",
            crate::common::Format {
                extensions: &["csv"],
                what: "the camera response is written as CSV",
            },
            &inputs,
            args.force,
        )?;
    }

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
