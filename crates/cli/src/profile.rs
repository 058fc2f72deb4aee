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
    #[command(flatten)]
    pub settings: ProfileSettings,
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

/// Runs `scatterfit profile`.
pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    args.settings
        .check(args.detection_limit, args.memory.budget())?;
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
    let settings = args.settings;
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
