//! `scatterfit synth`: the rig twin writes a sample folder exactly like a real one — spectro.csv,
//! 13 PNG exposures with exposures.csv, sample.toml — made with the Monte Carlo engine, plus
//! truth.json with what the tool should find.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
use scatterfit_lab::twin::SynthSummary;
use scatterfit_lab::twin_settings::{MaterialSettings, RigSettings, twin_files};
use scatterfit_synth::RigSpec;

use crate::common::{CacheArgs, check_output_files};
use crate::output::out;
use crate::twin::{synthesize_on, write_sample_with};

/// Arguments of `scatterfit synth`.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub material: MaterialSettings,
    /// Folder to write (created; checked before the Monte Carlo runs; existing files are not
    /// overwritten without --force).
    #[arg(short = 'o', long = "output-dir", value_name = "DIR")]
    pub output_dir: PathBuf,
    /// Seed of the Monte Carlo runs, the spot position, the gains and the camera noise, 0 to
    /// 2⁶⁴ − 1.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// The forward model written into the manifest's `[fit]` (how `measure` will fit this sample;
    /// the sample itself is always made by Monte Carlo).
    #[arg(long, value_enum)]
    pub model: Option<scatterfit_optics::ModelName>,
    /// The albedo model written into the manifest's `[fit]`.
    #[arg(long, value_enum)]
    pub albedo_model: Option<scatterfit_optics::AlbedoModel>,
    #[command(flatten)]
    pub rig: RigSettings,
    /// Veiling glare: stray light spread over the frame, as a fraction of the spot's central
    /// radiance, in [0, 0.1] (a lens: 1e-4 to 1e-3; the profile's far tail is 1e-5).
    #[arg(long, value_name = "F", default_value_t = 0.0, value_parser = crate::numeric::parse_finite)]
    pub glare: f64,
    /// Vignetting: the frame's corner receives this fraction less light, in [0, 0.9]; a flat frame
    /// (flat.png, camera.flat) is written with it.
    #[arg(long, value_name = "V", default_value_t = 0.0, value_parser = crate::numeric::parse_finite)]
    pub vignetting: f64,
    /// Shutter error: each frame's true exposure differs from its nominal time by a random factor
    /// exp(ε), ε with this standard deviation, in [0, 0.3] (0.03 = 3 %); the files keep the nominal
    /// times.
    #[arg(long, value_name = "S", default_value_t = 0.0, value_parser = crate::numeric::parse_finite)]
    pub exposure_error: f64,
    /// A Gaussian beam (the spot's 1/e² diameter is the rig's 1 mm) instead of a uniform disk;
    /// the manifest says `spot_profile = "gaussian"`.
    #[arg(long)]
    pub gaussian_spot: bool,
    /// Also write spot.png, the spot on a thin opaque white target, and name it as
    /// `camera.spot_image` (the fit's kernel is then measured, not assumed).
    #[arg(long)]
    pub spot_image: bool,
    /// The spectrophotometer's measuring port: the diameter of the aperture it measures through
    /// [mm, 1 to 100] (common: 4, 8, 25). The reading is then what that port collects (the Monte
    /// Carlo engine lights the port's disc uniformly and tallies what leaves inside the aperture:
    /// light that spreads beyond it is lost, the edge loss) and the manifest's `[spectro]` names
    /// the port, so that `measure` corrects for it. Default: a loss-free reading.
    #[arg(long, value_name = "MM", value_parser = crate::numeric::parse_finite)]
    pub aperture_mm: Option<f64>,
    /// The diameter of the disc the instrument lights [mm, 1 to 100], when it is not the
    /// aperture's (e.g. 14 for an 8 mm aperture lit over 14 mm).
    #[arg(long, value_name = "MM", requires = "aperture_mm", value_parser = crate::numeric::parse_finite)]
    pub illuminated_mm: Option<f64>,
    /// Overwrite existing files in the folder.
    #[arg(long)]
    pub force: bool,
    #[command(flatten)]
    pub cache: CacheArgs,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
    /// Print the truth as JSON.
    #[arg(long)]
    pub json: bool,
}

/// The rig the flags describe.
fn rig_from(args: &Args) -> anyhow::Result<RigSpec> {
    let settings = RigSettings {
        effects: scatterfit_synth::rig::RigEffects {
            glare: args.glare,
            vignetting: args.vignetting,
            exposure_error: args.exposure_error,
            gaussian_spot: args.gaussian_spot,
            spot_image: args.spot_image,
        },
        ..args.rig.clone()
    };
    Ok(settings.rig()?)
}

/// Runs `scatterfit synth`.
pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let m = args.material.material()?;
    crate::common::check_output_dir(&args.output_dir, "-o")?;
    let rig = rig_from(&args)?;
    let port = scatterfit_lab::twin_settings::port(args.aperture_mm, args.illuminated_mm)?;
    let names = twin_files(&rig, args.rig.camera.as_deref() == Some("dng"));
    check_output_files(&args.output_dir, &names, args.force)?;
    let cache = args.cache.dir();
    let mut sample = synthesize_on(
        &m,
        &rig,
        args.seed,
        cache.as_deref(),
        args.quiet || args.json,
    )?;
    if let Some(port) = &port {
        if !(args.quiet || args.json) {
            crate::output::errln!(
                "tracing the reading through the port ({} mm aperture lit over {} mm)…",
                port.aperture_mm(),
                port.illuminated_mm()
            );
        }
        sample = sample
            .read_through_port(port)
            .with_context(|| format!("the port reading of {}", m.name))?;
    }
    write_sample_with(
        &args.output_dir,
        &sample,
        scatterfit_io::manifest::FitSection {
            model: args.model,
            albedo_model: args.albedo_model,
            ..Default::default()
        },
    )?;
    let summary = SynthSummary {
        output_dir: &args.output_dir,
        truth: &sample.truth,
    };
    if args.json {
        crate::output::print_json(&summary)?;
    } else {
        out!("{}", summary.text(&sample, &rig))?;
    }
    Ok(ExitCode::SUCCESS)
}
