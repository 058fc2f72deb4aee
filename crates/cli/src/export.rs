//! `scatterfit export`: a measured result (`result.json`) as a material renderers read — pbrt-v4,
//! Mitsuba 3, Blender (bpy script) or renderer-neutral JSON.
//!
//! The formats and their conventions are `scatterfit_io::export`'s (ARCHITECTURE.md, "io: exports");
//! this file parses the arguments, checks the output path, writes atomically or prints to stdout.
//! A result with a failed channel exports nothing (exit 1, the channel named); unconstrained channels
//! are exported with a warning on stderr.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use crate::output::errln;
use anyhow::{Context, bail};
use scatterfit_io::export::{
    ExportError, ExportOptions, Format, MitsubaVariant, SceneUnit, export_with,
};
use scatterfit_io::result_json::{MeasurementResult, read_result_json};

/// Arguments of `scatterfit export`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The result to export, as `scatterfit measure` writes it (result.json).
    pub result: PathBuf,
    /// Target format: pbrt (pbrt-v4 subsurface material + homogeneous medium, .pbrt), mitsuba
    /// (Mitsuba 3 XML fragment: dielectric boundary + homogeneous medium, .xml), blender (bpy script
    /// setting a Principled BSDF, Blender ≥ 4.0, .py), json (renderer-neutral, .json).
    #[arg(long, value_enum, value_name = "FORMAT")]
    pub to: FormatArg,
    /// Length unit of the target scene: coefficients are written per mm (mm⁻¹, as measured) or per
    /// metre (m⁻¹ = 1000 × mm⁻¹), mean free paths in that unit.
    #[arg(long, value_enum, default_value = "mm", value_name = "UNIT")]
    pub scale: UnitArg,
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
    pub mitsuba_variant: VariantArg,
    /// Replace an existing output file.
    #[arg(long)]
    pub force: bool,
    /// No warnings or confirmation on stderr/stdout (errors are still printed).
    #[arg(short, long)]
    pub quiet: bool,
}

/// `--to`.
#[derive(Debug, Clone, Copy, clap::ValueEnum)]
pub enum FormatArg {
    /// pbrt-v4 (.pbrt).
    Pbrt,
    /// Mitsuba 3 (.xml).
    Mitsuba,
    /// Blender ≥ 4.0 bpy script (.py).
    Blender,
    /// Renderer-neutral JSON (.json).
    Json,
}

impl From<FormatArg> for Format {
    fn from(f: FormatArg) -> Self {
        match f {
            FormatArg::Pbrt => Format::Pbrt,
            FormatArg::Mitsuba => Format::Mitsuba,
            FormatArg::Blender => Format::Blender,
            FormatArg::Json => Format::Json,
        }
    }
}

/// `--mitsuba-variant`.
#[derive(Debug, Clone, Copy, clap::ValueEnum)]
pub enum VariantArg {
    /// RGB variants.
    Rgb,
    /// Spectral variants.
    Spectral,
}

/// `--scale`.
#[derive(Debug, Clone, Copy, clap::ValueEnum)]
pub enum UnitArg {
    /// One scene unit is one millimetre.
    Mm,
    /// One scene unit is one metre.
    M,
}

impl From<UnitArg> for SceneUnit {
    fn from(u: UnitArg) -> Self {
        match u {
            UnitArg::Mm => SceneUnit::Millimetre,
            UnitArg::M => SceneUnit::Metre,
        }
    }
}

/// Runs `scatterfit export`.
pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let format = Format::from(args.to);
    let unit = SceneUnit::from(args.scale);
    if let Some(out) = &args.output {
        check_output(out, format, &args.result, args.force)?;
        crate::common::check_output_folder(out, "-o")?;
    }
    // The error's message already includes its cause; flatten it so `{:#}` does not repeat it.
    let result = read_result_json(&args.result).map_err(|e| anyhow::anyhow!("{e}"))?;
    let options = ExportOptions {
        unit,
        exact_rd: exact_transport_rd(&result),
        spectral_albedo: spectral_albedo(&result),
        mitsuba_variant: match args.mitsuba_variant {
            VariantArg::Rgb => MitsubaVariant::Rgb,
            VariantArg::Spectral => MitsubaVariant::Spectral,
        },
    };
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
    Ok(ExitCode::SUCCESS)
}

/// Exact transport's total diffuse reflectance Rd_exact(α′, η) of each channel's exported medium (a
/// half-space with the result's σ′s, σa, g = 0 and η), from the Monte Carlo tables shipped with
/// scatterfit: what Mitsuba's and pbrt's volumetric path tracers render, which the export's header
/// compares with the measured Rd. `None` when the tables do not cover the result (η outside 1.0–2.5)
/// or a channel has no coefficients (the export then refuses it anyway).
fn exact_transport_rd(result: &MeasurementResult) -> Option<[f64; 3]> {
    let mc = scatterfit_mc::family(scatterfit_optics::ModelName::Mc).ok()?;
    let rd = result.coefficients().ok()?.map(|(sp, sa)| {
        let rd = mc.rd_total(sp / (sp + sa), result.eta, 0.0).ok()?;
        (rd.is_finite() && (0.0..=1.0).contains(&rd)).then_some(rd)
    });
    Some(rd.transpose()?.into_array())
}

/// The single-scattering albedo whose exact-transport total Rd is the measured Rd(λ), at each
/// wavelength of the result's spectrum (the Monte Carlo tables' inversion): the spectral medium's
/// albedo. Rd(λ) beyond what the tables reach at this η (a nearly black band, Rd below the lowest
/// tabulated albedo's; or above the highest's) takes that end albedo: the light it misplaces is at
/// most the lowest albedo's Rd (a few 10⁻³ at most). `None` without a spectrum or where the tables do
/// not cover η (1.0–2.5).
fn spectral_albedo(result: &MeasurementResult) -> Option<Vec<f64>> {
    let spec = result.rd_spectrum.as_ref()?;
    let mc = scatterfit_mc::family(scatterfit_optics::ModelName::Mc).ok()?;
    let eta = result.eta;
    let reach = |grid: &[f64]| {
        grid.iter().copied().find_map(|a| {
            mc.rd_total(a, eta, 0.0)
                .ok()
                .filter(|rd| rd.is_finite())
                .map(|rd| (a, rd))
        })
    };
    let (a_lo, rd_lo) = reach(&[1e-3, 0.01, 0.02, 0.05, 0.1, 0.2, 0.3, 0.5])?;
    let (a_hi, rd_hi) = reach(&[0.9999, 0.9995, 0.999, 0.995, 0.99])?;
    spec.rd
        .iter()
        .map(|&rd| {
            if rd <= rd_lo {
                Some(a_lo)
            } else if rd >= rd_hi {
                Some(a_hi)
            } else {
                mc.albedo_from_rd(rd, eta, 0.0).ok()
            }
        })
        .collect()
}

/// Refuses an output whose extension does not match the format, an existing file without `--force`,
/// and the input itself (inputs are never overwritten).
fn check_output(out: &Path, format: Format, input: &Path, force: bool) -> anyhow::Result<()> {
    let want = format.extension();
    let ext = out
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    if ext.as_deref() != Some(want) {
        bail!(
            "output {}: a {} export is written to a .{want} file; name it e.g. `{}`",
            out.display(),
            format.name(),
            out.with_extension(want).display()
        );
    }
    crate::common::check_destination(out, "output")?;
    if out.exists() {
        // The same file by resolved path, or by device and inode (a hard link).
        if crate::common::same_file(out, input) {
            bail!(
                "output {} is the input result; write the export to another file",
                out.display()
            );
        }
        if !force {
            bail!(
                "output {} exists; pass --force to replace it, or choose another name",
                out.display()
            );
        }
        if out.is_dir() {
            bail!("output {} is a folder; name a file", out.display());
        }
    }
    Ok(())
}
