//! `scatterfit export`: a measured result (`result.json`) as a material renderers read — pbrt-v4,
//! Mitsuba 3, Blender (bpy script) or renderer-neutral JSON.
//!
//! The formats and their conventions are `scatterfit_io::export`'s (ARCHITECTURE.md, "io: exports");
//! the exact-transport figures from the Monte Carlo tables are `scatterfit_pipeline::export`'s;
//! this file parses the arguments, checks the output path, writes atomically or prints to stdout.
//! A result with a failed channel exports nothing (exit 1, the channel named); unconstrained channels
//! are exported with a warning on stderr.

use std::path::PathBuf;
use std::process::ExitCode;

use crate::output::errln;
use anyhow::Context;
use scatterfit_io::export::{ExportError, Format, MitsubaVariant, SceneUnit, export_with};
use scatterfit_io::result_json::read_result_json;
use scatterfit_pipeline::export::check_export_output;

/// Arguments of `scatterfit export`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The result to export, as `scatterfit measure` writes it (result.json).
    pub result: PathBuf,
    /// Target format: pbrt (pbrt-v4 subsurface material + homogeneous medium, .pbrt), mitsuba
    /// (Mitsuba 3 XML fragment: dielectric boundary + homogeneous medium, .xml), blender (bpy script
    /// setting a Principled BSDF, Blender ≥ 4.0, .py), json (renderer-neutral, .json).
    #[arg(long, value_enum, value_name = "FORMAT")]
    pub to: Format,
    /// Length unit of the target scene: coefficients are written per mm (mm⁻¹, as measured) or per
    /// metre (m⁻¹ = 1000 × mm⁻¹), mean free paths in that unit.
    #[arg(long, value_enum, default_value = "mm", value_name = "UNIT")]
    pub scale: SceneUnit,
    /// Write to FILE (atomically; its extension must match the format: .pbrt, .xml, .py, .json)
    /// instead of stdout.
    #[arg(short, long, value_name = "FILE")]
    pub output: Option<PathBuf>,
    /// Mitsuba only: the kind of Mitsuba variant the fragment is for. `rgb` (scalar_rgb, llvm_ad_rgb,
    /// …) writes the channels' coefficients; `spectral` (scalar_spectral, …) a medium per wavelength
    /// from the result's measured reflectance spectrum, which spectral variants render in the
    /// measured colour (their uplift of RGB coefficients shifts strongly coloured materials by tens
    /// of per cent).
    #[arg(long, value_enum, default_value = "rgb", value_name = "KIND")]
    pub mitsuba_variant: MitsubaVariant,
    /// Replace an existing output file.
    #[arg(long)]
    pub force: bool,
    /// Exit 0 for a result whose data checks found a channel suspect (the warning is still printed
    /// and written into the file's header).
    #[arg(long)]
    pub allow_suspect: bool,
    /// No warnings or confirmation on stderr/stdout (errors are still printed).
    #[arg(short, long)]
    pub quiet: bool,
}

/// Runs `scatterfit export`.
pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let (format, unit, variant) = (args.to, args.scale, args.mitsuba_variant);
    if let Some(out) = &args.output {
        check_export_output(out, format, &args.result, args.force)?;
    }
    // The error's message already includes its cause; flatten it so `{:#}` does not repeat it.
    let result = read_result_json(&args.result).map_err(|e| anyhow::anyhow!("{e}"))?;
    let options = scatterfit_pipeline::export::export_options(&result, unit, variant);
    let exported = match export_with(&result, format, &options) {
        Ok(e) => e,
        Err(err @ ExportError::FailedChannel { .. }) => {
            return Err(crate::common::MeasurementFailed(format!(
                "{}: {err}",
                args.result.display()
            ))
            .into());
        }
        Err(err) => return Err(anyhow::anyhow!("{}: {err}", args.result.display())),
    };
    if !args.quiet {
        for w in &exported.warnings {
            errln!("warning: {w}");
        }
    }
    match &args.output {
        Some(out) => {
            scatterfit_io::atomic::write_atomic(out, exported.text.as_bytes())
                .with_context(|| format!("writing {}", out.display()))?;
            if !args.quiet {
                errln!(
                    "wrote {} ({} material \"{}\", 1 scene unit = 1 {})",
                    out.display(),
                    format.name(),
                    result.name,
                    unit.symbol()
                );
            }
        }
        // A closed stdout (`| head`) ends the output quietly (crate::output).
        None => crate::output::write_stdout_bytes(exported.text.as_bytes())?,
    }
    Ok(crate::common::suspect_exit(
        &args.result,
        &result,
        args.allow_suspect,
    ))
}
