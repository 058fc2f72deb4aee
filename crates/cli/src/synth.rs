//! `scatterfit synth`: the rig twin writes a sample folder exactly like a real one — spectro.csv,
//! 13 PNG exposures with exposures.csv, sample.toml — made with the Monte Carlo engine, plus
//! truth.json with what the tool should find.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, bail};
use scatterfit_io::sample_folder::file_names;
use scatterfit_synth::{RigSpec, materials};
use serde::Serialize;

use crate::common::{cache_dir, check_output_files, parse_rgb, shutter};
use crate::output::outln;
use crate::twin::{Material, synthesize, write_sample_with};

/// Arguments of `scatterfit synth`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// A built-in material: the seven of Choi et al. 2014 (pink-plastic, blue-coating, brown-leather,
    /// nephrite, wood-tile, sulfur, red-aluminum) or Jensen et al. 2001's (apple, chicken1,
    /// chicken2, cream, ketchup, marble, potato, skimmilk, skin1, skin2, wholemilk; η = 1.3).
    #[arg(long, value_name = "NAME", conflicts_with_all = ["sigma_s_prime", "sigma_a"])]
    pub material: Option<String>,
    /// Reduced scattering coefficient per channel R,G,B [mm⁻¹, each in (0, 100]].
    #[arg(long, value_name = "R,G,B", value_parser = parse_rgb, requires_all = ["sigma_a", "eta"])]
    pub sigma_s_prime: Option<[f64; 3]>,
    /// Absorption coefficient per channel R,G,B [mm⁻¹, each in (0, 100]].
    #[arg(long, value_name = "R,G,B", value_parser = parse_rgb, requires = "sigma_s_prime")]
    pub sigma_a: Option<[f64; 3]>,
    /// Relative refractive index η, in [1, 3] (overrides the material's).
    #[arg(long, value_parser = crate::numeric::parse_finite)]
    pub eta: Option<f64>,
    /// Sample name (default: the material's, or "synthetic").
    #[arg(long)]
    pub name: Option<String>,
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
    pub model: Option<crate::common::ModelArg>,
    /// The albedo model written into the manifest's `[fit]`.
    #[arg(long, value_enum)]
    pub albedo_model: Option<crate::common::AlbedoModelArg>,
    /// A small fast sample (256 × 256 px at 0.1 mm/px, a tenth of the photons) for trying the tool
    /// and for tests; not for accuracy studies.
    #[arg(long)]
    pub quick: bool,
    /// Overwrite existing files in the folder.
    #[arg(long)]
    pub force: bool,
    /// Folder for cached Monte Carlo profiles (default: $SCATTERFIT_CACHE, the XDG cache, ~/.cache).
    #[arg(long, value_name = "DIR")]
    pub cache_dir: Option<PathBuf>,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
    /// Print the truth as JSON.
    #[arg(long)]
    pub json: bool,
}

fn material_from(args: &Args) -> anyhow::Result<Material> {
    let m = match (&args.material, args.sigma_s_prime, args.sigma_a) {
        (Some(name), _, _) => {
            let m = materials::by_name(name).with_context(|| {
                let names: Vec<&str> = materials::all().map(|m| m.name).collect();
                format!(
                    "--material {name}: unknown; built-in materials: {}",
                    names.join(", ")
                )
            })?;
            Material {
                name: m.name.into(),
                sigma_s_prime: m.sigma_s_prime,
                sigma_a: m.sigma_a,
                eta: args.eta.unwrap_or(m.eta),
            }
        }
        (None, Some(sp), Some(sa)) => Material {
            name: "synthetic".into(),
            sigma_s_prime: sp,
            sigma_a: sa,
            eta: args.eta.context("--eta is required with --sigma-s-prime")?,
        },
        _ => bail!(
            "say what to synthesise: --material NAME, or --sigma-s-prime R,G,B --sigma-a R,G,B --eta X"
        ),
    };
    for (what, v) in [
        ("--sigma-s-prime", m.sigma_s_prime),
        ("--sigma-a", m.sigma_a),
    ] {
        if let Some(x) = v.iter().find(|x| !(**x > 0.0 && **x <= 100.0)) {
            bail!(
                "{what}: {} is outside (0, 100] mm⁻¹",
                crate::numeric::show(*x)
            );
        }
    }
    if !(1.0..=3.0).contains(&m.eta) {
        bail!("--eta {}: the rig twin takes η in [1, 3]", m.eta);
    }
    Ok(Material {
        name: args.name.clone().unwrap_or(m.name),
        ..m
    })
}

#[derive(Serialize)]
struct Summary<'a> {
    output_dir: &'a std::path::Path,
    truth: &'a scatterfit_synth::Truth,
}

/// Runs `scatterfit synth`.
pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let m = material_from(&args)?;
    crate::common::check_output_dir(&args.output_dir, "-o")?;
    let rig = if args.quick {
        RigSpec::quick()
    } else {
        RigSpec::paper()
    };
    check_output_files(
        &args.output_dir,
        &file_names(rig.times_s.len(), true),
        args.force,
    )?;
    let cache = cache_dir(args.cache_dir.as_deref());
    let sample = synthesize(
        &m,
        args.seed,
        cache.as_deref(),
        args.quiet || args.json,
        args.quick,
    )?;
    write_sample_with(
        &args.output_dir,
        &sample,
        scatterfit_io::manifest::FitSection {
            model: args.model.map(Into::into),
            albedo_model: args.albedo_model.map(Into::into),
            ..Default::default()
        },
    )?;
    if args.json {
        crate::output::print_json(&Summary {
            output_dir: &args.output_dir,
            truth: &sample.truth,
        })?;
    } else {
        outln!(
            "wrote {} ({} exposures {}–{} s, {}×{} px at {} mm/px, spot ⌀ {} mm)",
            args.output_dir.display(),
            sample.bracket.times_s.len(),
            shutter(sample.bracket.times_s[0]),
            shutter(*sample.bracket.times_s.last().unwrap_or(&0.0)),
            rig.width,
            rig.height,
            rig.mm_per_pixel,
            2.0 * rig.spot_radius_mm
        )?;
        outln!("truth    η = {:.4}", sample.truth.eta)?;
        for (name, c) in ["R", "G", "B"].iter().zip(&sample.truth.channels) {
            outln!(
                "  {name}  σ′s = {:<8} σa = {:<10} α′ = {:.5}  Rd(MC) = {:.4} ± {:.4}  ({} photons)",
                c.sigma_s_prime,
                c.sigma_a,
                c.albedo_prime,
                c.rd_total,
                c.rd_total_stderr,
                c.photons
            )?;
        }
        outln!(
            "measure it with: scatterfit measure {}",
            args.output_dir.display()
        )?;
    }
    Ok(ExitCode::SUCCESS)
}
