//! `scatterfit profile`: the radial profile Rd(r) around the light spot of a radiance map.
//!
//! Reads an EXR or HDR radiance map, finds the spot centre (or takes `--center`), averages concentric
//! rings, and writes `r_mm,r_px,value_<c>,stderr_<c>,count_<c>[,limit_<c>]` per channel (see
//! `scatterfit_io::profile_csv`). Pixels stored as NaN (clipped in every exposure) are skipped. The
//! work is `scatterfit_pipeline::profile::profile_stage`.

use std::path::PathBuf;
use std::process::ExitCode;

use crate::output::out;
use anyhow::Context;
use scatterfit_io::image_files::read_radiance_within;
use scatterfit_io::profile_csv::write_profile_csv;
use scatterfit_pipeline::profile::{ProfileSettings, ProfileSummary, profile_stage};

/// Arguments of `scatterfit profile`. Every number is checked before the radiance map is read
/// (exit 2 with the range); the rings' memory (r_max / ring width of them) is checked against the
/// memory budget before anything is allocated.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The radiance map (EXR or Radiance HDR), e.g. from `scatterfit merge`.
    pub radiance: PathBuf,
    /// Image scale on the sample surface [mm per pixel], in (0, 100] (as the manifest's
    /// `camera.mm_per_pixel`).
    #[arg(long, value_name = "MM", value_parser = crate::numeric::parse_finite)]
    pub mm_per_pixel: f64,
    /// Spot centre `X,Y` in pixels (pixel centres at integers), inside the image; found
    /// automatically if omitted.
    #[arg(long, value_name = "X,Y", value_parser = parse_center)]
    pub center: Option<[f64; 2]>,
    /// Outer radius of the profile \[px\], in (0, 10⁶] (the paper's cut-off is 300); at most 10⁶
    /// rings (r_max / ring width).
    #[arg(long, default_value_t = 300.0, value_name = "PX", value_parser = crate::numeric::parse_finite)]
    pub r_max_px: f64,
    /// Ring width \[px\], > 0, with at most 10⁶ rings (r_max / ring width; 1 px gives the paper's
    /// profile).
    #[arg(long, default_value_t = 1.0, value_name = "PX", value_parser = crate::numeric::parse_finite)]
    pub ring_width_px: f64,
    /// The bracket's detection limit per channel R,G,B (relative radiance, each finite and ≥ 0, as
    /// `scatterfit merge` prints it): written as `limit_<c>` columns so that `scatterfit fit` leaves
    /// out rings below it.
    #[arg(long, value_name = "R,G,B", value_parser = crate::common::parse_rgb)]
    pub detection_limit: Option<[f64; 3]>,
    /// The profile CSV to write (`.csv`; checked before any work; an existing file only with
    /// --force).
    #[arg(short, long, value_name = "FILE")]
    pub output: PathBuf,
    /// Replace an existing output file.
    #[arg(long)]
    pub force: bool,
    #[command(flatten)]
    pub memory: crate::numeric::MemoryArgs,
    /// Print the summary as JSON.
    #[arg(long)]
    pub json: bool,
}

/// The largest ring radius accepted \[px\]: beyond any camera sensor's diagonal.
const MAX_R_PX: f64 = 1e6;

/// Memory per ring and channel of the profile and its CSV row \[bytes\] (the ring's statistics, its
/// share of the table, and the text), an upper bound.
const BYTES_PER_RING_CHANNEL: u64 = 160;

/// Checks every number before anything is read: ranges, the ring count, the rings' memory.
fn check_args(args: &Args) -> anyhow::Result<()> {
    use crate::numeric::ensure;
    ensure(
        args.mm_per_pixel > 0.0 && args.mm_per_pixel <= 100.0,
        "--mm-per-pixel",
        args.mm_per_pixel,
        "the image scale must lie in (0, 100] mm per pixel",
    )?;
    ensure(
        args.r_max_px > 0.0 && args.r_max_px <= MAX_R_PX,
        "--r-max-px",
        args.r_max_px,
        "the outer radius must lie in (0, 1e6] px (the paper's is 300)",
    )?;
    ensure(
        args.ring_width_px > 0.0,
        "--ring-width-px",
        args.ring_width_px,
        "the ring width must be > 0 px (1 px gives the paper's profile)",
    )?;
    let rings = (args.r_max_px / args.ring_width_px).ceil();
    ensure(
        rings <= scatterfit_imaging::MAX_RINGS as f64,
        "--ring-width-px",
        args.ring_width_px,
        &format!(
            "--r-max-px {} / --ring-width-px {} makes {rings:.3e} rings, more than 10⁶ — a light \
             spot's profile needs hundreds; widen the rings or reduce r_max",
            crate::numeric::show(args.r_max_px),
            crate::numeric::show(args.ring_width_px)
        ),
    )?;
    if let Some(l) = args.detection_limit
        && let Some(bad) = l.iter().find(|v| !(v.is_finite() && **v >= 0.0))
    {
        anyhow::bail!(
            "--detection-limit: {} is not a radiance ≥ 0 (relative units, as `scatterfit merge` \
             prints it)",
            crate::numeric::show(*bad)
        );
    }
    crate::numeric::check_memory(
        &format!("a profile of {rings} rings × 3 channels"),
        (rings as u64 + 1).saturating_mul(3 * BYTES_PER_RING_CHANNEL),
        args.memory.budget(),
    )
}

fn parse_center(text: &str) -> Result<[f64; 2], String> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    match parts.as_slice() {
        [x, y] => match (x.parse::<f64>(), y.parse::<f64>()) {
            (Ok(x), Ok(y)) if x.is_finite() && y.is_finite() => Ok([x, y]),
            _ => Err(format!(
                "`{text}` is not two numbers; write the centre as X,Y in pixels, e.g. 512.3,498.7"
            )),
        },
        _ => Err(format!(
            "`{text}` is not X,Y; write the centre in pixels, e.g. 512.3,498.7"
        )),
    }
}

/// Runs `scatterfit profile`.
pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    check_args(&args)?;
    crate::common::check_output_file(
        &args.output,
        "-o",
        crate::common::Format {
            extensions: &["csv"],
            what: "the profile is written as CSV",
        },
        &[args.radiance.as_path()],
        args.force,
    )?;
    let budget = args.memory.budget();
    let image = read_radiance_within(&args.radiance, budget)?;
    let limits = args.detection_limit.map_or_else(Vec::new, |l| l.to_vec());
    let settings = ProfileSettings {
        mm_per_pixel: args.mm_per_pixel,
        r_max_px: args.r_max_px,
        ring_width_px: args.ring_width_px,
        center_px: args.center,
    };
    let stage = profile_stage(&image, None, &limits, &settings)
        .with_context(|| format!("{}", args.radiance.display()))?;
    write_profile_csv(&args.output, &stage.to_table())?;
    let summary = ProfileSummary::new(&stage, &settings, args.radiance, args.output);
    if args.json {
        crate::output::print_json(&summary)?;
    } else {
        out!("{}", summary.text())?;
    }
    Ok(ExitCode::SUCCESS)
}
