//! `scatterfit profile`: the radial profile Rd(r) around the light spot of a radiance map.
//!
//! Reads an EXR or HDR radiance map, finds the spot centre (or takes `--center`), averages concentric
//! rings, and writes `r_mm,r_px,value_<c>,stderr_<c>,count_<c>[,limit_<c>]` per channel (see
//! `scatterfit_io::profile_csv`). Pixels stored as NaN (clipped in every exposure) are skipped. The
//! work is `scatterfit_pipeline::profile::profile_stage`.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, bail};
use scatterfit_io::image_files::read_radiance;
use scatterfit_io::profile_csv::write_profile_csv;
use scatterfit_pipeline::profile::{CenterSource, ProfileSettings, profile_stage};
use serde::Serialize;

/// Arguments of `scatterfit profile`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The radiance map (EXR or Radiance HDR), e.g. from `scatterfit merge`.
    pub radiance: PathBuf,
    /// Image scale on the sample surface [mm per pixel].
    #[arg(long, value_name = "MM")]
    pub mm_per_pixel: f64,
    /// Spot centre `X,Y` in pixels (pixel centres at integers); found automatically if omitted.
    #[arg(long, value_name = "X,Y", value_parser = parse_center)]
    pub center: Option<[f64; 2]>,
    /// Outer radius of the profile [px] (the paper's cut-off is 300).
    #[arg(long, default_value_t = 300.0, value_name = "PX")]
    pub r_max_px: f64,
    /// Ring width [px].
    #[arg(long, default_value_t = 1.0, value_name = "PX")]
    pub ring_width_px: f64,
    /// The bracket's detection limit per channel R,G,B (relative radiance, as `scatterfit merge`
    /// prints it): written as `limit_<c>` columns so that `scatterfit fit` leaves out rings below it.
    #[arg(long, value_name = "R,G,B", value_parser = crate::common::parse_rgb)]
    pub detection_limit: Option<[f64; 3]>,
    /// The profile CSV to write.
    #[arg(short, long, value_name = "CSV")]
    pub output: PathBuf,
    /// Print the summary as JSON.
    #[arg(long)]
    pub json: bool,
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

/// The summary `scatterfit profile` prints.
#[derive(Debug, Serialize)]
pub struct Summary {
    /// The radiance map read.
    pub radiance: PathBuf,
    /// Spot centre `[x, y]` [px].
    pub center_px: [f64; 2],
    /// `found` or `given`.
    pub center_source: String,
    /// Pixels in the spot region (found centres only).
    pub spot_pixels: usize,
    /// Rings written.
    pub rings: usize,
    /// Rings with no valid pixel in some channel.
    pub empty_rings: usize,
    /// Image scale [mm/px].
    pub mm_per_pixel: f64,
    /// Outermost ring radius [mm].
    pub r_max_mm: f64,
    /// The CSV written.
    pub output: PathBuf,
}

/// Runs `scatterfit profile`.
pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    if !(args.mm_per_pixel.is_finite() && args.mm_per_pixel > 0.0) {
        bail!(
            "--mm-per-pixel {} must be a positive number (image scale on the sample, mm per pixel)",
            args.mm_per_pixel
        );
    }
    crate::common::refuse_overwrite(&args.output, "output", &[args.radiance.as_path()])?;
    let image = read_radiance(&args.radiance)?;
    let limits = args.detection_limit.map_or_else(Vec::new, |l| l.to_vec());
    let stage = profile_stage(
        &image,
        None,
        &limits,
        &ProfileSettings {
            mm_per_pixel: args.mm_per_pixel,
            r_max_px: args.r_max_px,
            ring_width_px: args.ring_width_px,
            center_px: args.center,
        },
    )
    .with_context(|| format!("{}", args.radiance.display()))?;
    let table = stage.to_table();
    write_profile_csv(&args.output, &table)?;
    let profile = &stage.profile;
    let summary = Summary {
        radiance: args.radiance.clone(),
        center_px: stage.center.xy(),
        center_source: match stage.center_source {
            CenterSource::Found => "found",
            CenterSource::Given => "given",
        }
        .into(),
        spot_pixels: stage.center.spot_pixels,
        rings: profile.rings.len(),
        empty_rings: profile
            .rings
            .iter()
            .filter(|r| r.channels.iter().any(|c| c.count == 0))
            .count(),
        mm_per_pixel: args.mm_per_pixel,
        r_max_mm: table.r_mm.last().copied().unwrap_or(f64::NAN),
        output: args.output.clone(),
    };
    if args.json {
        crate::output::print_json(&summary)?;
    } else {
        println!(
            "centre   ({:.3}, {:.3}) px, {}{}",
            summary.center_px[0],
            summary.center_px[1],
            summary.center_source,
            if stage.center_source == CenterSource::Found {
                format!(" ({} spot pixels)", summary.spot_pixels)
            } else {
                String::new()
            }
        );
        println!(
            "rings    {} × {} px, out to {:.3} mm ({} with an empty channel)",
            summary.rings, args.ring_width_px, summary.r_max_mm, summary.empty_rings
        );
        println!("wrote    {}", summary.output.display());
    }
    Ok(ExitCode::SUCCESS)
}
