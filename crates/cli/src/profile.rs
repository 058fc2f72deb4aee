//! `scatterfit profile`: the radial profile Rd(r) around the light spot of a radiance map.
//!
//! Reads an EXR or HDR radiance map, finds the spot centre (or takes `--center`), averages concentric
//! rings, and writes `r_mm,r_px,value_<c>,stderr_<c>,count_<c>` per channel (see
//! `scatterfit_io::profile_csv`). Pixels stored as NaN (clipped in every exposure) are skipped.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, bail};
use scatterfit_imaging::{
    CenterOptions, ProfileOptions, SpotCenter, find_spot_center, radial_profile,
};
use scatterfit_io::image_files::read_radiance;
use scatterfit_io::profile_csv::{ProfileColumn, ProfileTable, write_profile_csv};
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
    crate::merge::refuse_overwrite(&args.output, "output", &[args.radiance.as_path()])?;
    let image = read_radiance(&args.radiance)?;
    let (center, source) = match args.center {
        Some([x, y]) => (
            SpotCenter::given(&image, x, y)
                .with_context(|| format!("--center for {}", args.radiance.display()))?,
            "given",
        ),
        None => (
            find_spot_center(&image, &CenterOptions::default()).with_context(|| {
                format!(
                    "finding the spot centre in {} (or give it with --center X,Y)",
                    args.radiance.display()
                )
            })?,
            "found",
        ),
    };
    let opts = ProfileOptions {
        ring_width_px: args.ring_width_px,
        r_max_px: args.r_max_px,
    };
    let profile = radial_profile(&image, center.xy(), None, args.mm_per_pixel, &opts)
        .context("computing the radial profile (check --ring-width-px and --r-max-px)")?;
    let names: &[&str] = match profile.channels() {
        1 => &["y"],
        3 => &["r", "g", "b"],
        n => bail!(
            "{}: {n} channels; a radiance map has 1 or 3",
            args.radiance.display()
        ),
    };
    let table = ProfileTable {
        r_mm: (0..profile.rings.len())
            .filter_map(|k| profile.r_mm(k))
            .collect(),
        r_px: profile.rings.iter().map(|r| r.r_px).collect(),
        channels: names
            .iter()
            .enumerate()
            .map(|(c, name)| ProfileColumn {
                name: (*name).to_string(),
                value: profile.rings.iter().map(|r| r.channels[c].mean).collect(),
                stderr: profile
                    .rings
                    .iter()
                    .map(|r| r.channels[c].std_err)
                    .collect(),
                count: profile
                    .rings
                    .iter()
                    .map(|r| r.channels[c].count as u64)
                    .collect(),
            })
            .collect(),
    };
    write_profile_csv(&args.output, &table)?;
    let summary = Summary {
        radiance: args.radiance.clone(),
        center_px: center.xy(),
        center_source: source.into(),
        spot_pixels: center.spot_pixels,
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
            if source == "found" {
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
