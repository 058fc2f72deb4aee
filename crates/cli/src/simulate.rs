//! `scatterfit simulate`: Monte Carlo photon transport (MCML physics) in a slab or half-space.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use crate::output::{errln, out, outln};
use anyhow::{Context, bail};
use scatterfit_mc::{Beam, BeamProfile, Layer, RadialGrid, Sample, Simulation, SimulationReport};

/// Arguments of `scatterfit simulate`. Every number is checked before any work (exit 2 when out of
/// range); the run's memory and expected work are checked against `--max-memory-mib` and
/// `--max-interactions` before it starts.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Reduced scattering coefficient σ′s [mm⁻¹]: finite, ≥ 0.
    #[arg(long, allow_hyphen_values = true, value_parser = crate::numeric::parse_finite)]
    pub sigma_s_prime: f64,
    /// Absorption coefficient σa [mm⁻¹]: finite, ≥ 0; > 0 for a half-space (no --thickness-mm),
    /// where a photon without absorption never has to stop.
    #[arg(long, allow_hyphen_values = true, value_parser = crate::numeric::parse_finite)]
    pub sigma_a: f64,
    /// Relative refractive index η of the material (the outside is air, n = 1): 1 to 10 (below 1
    /// with --allow-eta-below-one).
    #[arg(long, allow_hyphen_values = true, value_parser = crate::numeric::parse_finite)]
    pub eta: f64,
    /// Henyey–Greenstein asymmetry g, in (−1, 1); the scattering coefficient is σ′s/(1 − g), so the
    /// work grows like 1/(1 − g) as g → 1.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true, value_parser = crate::numeric::parse_finite)]
    pub g: f64,
    /// Slab thickness \[mm\]: finite, > 0; omit for a half-space.
    #[arg(long, allow_hyphen_values = true, value_parser = crate::numeric::parse_finite)]
    pub thickness_mm: Option<f64>,
    /// Number of photons: a count ≥ 1 (1e6 is fine); the expected work must fit --max-interactions.
    #[arg(long, default_value = "1000000", value_parser = crate::numeric::parse_count)]
    pub photons: u64,
    /// Seed of the random streams, 0 to 2⁶⁴ − 1 (the result is identical for any thread count).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Beam: `pencil`, `disk:R` (uniform disk of radius R mm, R in (0, 1000]) or `gauss:R`
    /// (Gaussian, 1/e² radius R mm, R in (0, 1000]).
    #[arg(long, default_value = "pencil")]
    pub beam: String,
    /// Angle of incidence \[degrees\] in air, in [0, 90) (0 = normal).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true, value_parser = crate::numeric::parse_finite)]
    pub incidence_deg: f64,
    /// Outer radius of the Rd(r) grid \[mm\]: in (0, 10⁶].
    #[arg(long, default_value_t = 10.0, value_parser = crate::numeric::parse_finite)]
    pub r_max_mm: f64,
    /// Number of radial bins (uniform width r_max/bins): a count ≥ 1, within the memory budget
    /// (about 1 KiB per bin; 8 GiB holds 8 million).
    #[arg(long, default_value = "200", value_parser = crate::numeric::parse_size)]
    pub bins: usize,
    /// Also tally reflectance by exit angle in this many bins over [0°, 90°]: a count, 0 (off) or
    /// more, within the memory budget with --bins.
    #[arg(long, default_value = "0", value_parser = crate::numeric::parse_size)]
    pub angle_bins: usize,
    /// Accept η < 1 (a material optically thinner than air).
    #[arg(long)]
    pub allow_eta_below_one: bool,
    #[command(flatten)]
    pub work: crate::numeric::WorkArgs,
    #[command(flatten)]
    pub memory: crate::numeric::MemoryArgs,
    /// Write the result to FILE: `.csv` the profile (r_inner_mm, r_outer_mm, r_mm, rd_per_mm2,
    /// rd_stderr_per_mm2), `.json` the whole result as --json prints it. Checked before the run; an
    /// existing file only with --force.
    #[arg(short = 'o', long = "output", alias = "out", value_name = "FILE")]
    pub output: Option<PathBuf>,
    /// Replace an existing output file.
    #[arg(long)]
    pub force: bool,
    /// Print the whole result as JSON on stdout.
    #[arg(long)]
    pub json: bool,
    /// No progress bar and no cost estimate on stderr.
    #[arg(long)]
    pub quiet: bool,
}

/// Parses `pencil`, `disk:R`, `gauss:R` (R in mm).
fn parse_beam(text: &str) -> anyhow::Result<BeamProfile> {
    let radius = |r: &str| -> anyhow::Result<f64> {
        let v = r
            .trim()
            .parse::<f64>()
            .with_context(|| format!("--beam {text}: `{r}` is not a radius in mm"))?;
        crate::numeric::ensure(
            v > 0.0 && v <= 1000.0,
            "--beam",
            text,
            "the beam radius must lie in (0, 1000] mm",
        )?;
        Ok(v)
    };
    match text.split_once(':') {
        None if text == "pencil" => Ok(BeamProfile::Pencil),
        Some(("disk", r)) => Ok(BeamProfile::Disk { radius: radius(r)? }),
        Some(("gauss", r)) | Some(("gaussian", r)) => {
            Ok(BeamProfile::Gaussian { radius: radius(r)? })
        }
        _ => bail!("--beam {text}: expected pencil, disk:R or gauss:R (R in mm)"),
    }
}

/// Largest η accepted: beyond any solid's (diamond 2.42, germanium in the infrared 4).
const MAX_ETA: f64 = 10.0;

/// Validated configuration from the flags: every range, then the memory of the tallies (before the
/// grid is made) and the expected work (before any photon is traced).
fn configure(args: &Args) -> anyhow::Result<Simulation> {
    let range = |ok: bool, flag: &str, value: f64, rule: &str| -> anyhow::Result<()> {
        if ok {
            Ok(())
        } else {
            bail!("{flag} {}: {rule}", crate::numeric::show(value))
        }
    };
    range(
        args.sigma_s_prime >= 0.0,
        "--sigma-s-prime",
        args.sigma_s_prime,
        "the reduced scattering coefficient must be ≥ 0 mm⁻¹",
    )?;
    range(
        args.sigma_a >= 0.0,
        "--sigma-a",
        args.sigma_a,
        "the absorption coefficient must be ≥ 0 mm⁻¹",
    )?;
    range(
        args.eta > 0.0 && args.eta <= MAX_ETA,
        "--eta",
        args.eta,
        "the relative refractive index must lie in (0, 10]",
    )?;
    if args.eta < 1.0 && !args.allow_eta_below_one {
        bail!(
            "--eta {}: below 1 means the material is optically thinner than air, which is unusual for \
             a solid; pass --allow-eta-below-one if you mean it",
            crate::numeric::show(args.eta)
        );
    }
    range(
        args.g > -1.0 && args.g < 1.0,
        "--g",
        args.g,
        "the Henyey–Greenstein asymmetry must lie in (−1, 1)",
    )?;
    if let Some(t) = args.thickness_mm {
        range(
            t > 0.0,
            "--thickness-mm",
            t,
            "the slab thickness must be > 0 mm (omit it for a half-space)",
        )?;
    }
    range(
        (0.0..90.0).contains(&args.incidence_deg),
        "--incidence-deg",
        args.incidence_deg,
        "the angle of incidence must lie in [0, 90) degrees",
    )?;
    // Below a micrometre the bins' areas (π r², down to 1e-600 mm² for 1e-300) underflow to 0 and
    // the tallies divide by them: NaN. No measurement resolves less than a micrometre.
    range(
        (1e-3..=1e6).contains(&args.r_max_mm),
        "--r-max-mm",
        args.r_max_mm,
        "the outer radius must lie in [1e-3, 1e6] mm (a micrometre to a kilometre)",
    )?;
    if args.photons == 0 {
        bail!("--photons 0: trace at least one photon");
    }
    if args.bins == 0 {
        bail!("--bins 0: the radial grid needs at least one bin");
    }
    let budget = args.memory.budget();
    crate::numeric::check_memory(
        &format!(
            "tallying {} radial and {} angular bins",
            args.bins, args.angle_bins
        ),
        Simulation::tally_memory_bytes(args.bins, args.angle_bins),
        budget,
    )?;
    if args.sigma_a == 0.0 && args.thickness_mm.is_none() {
        bail!(
            "--sigma-a 0 without --thickness-mm: in a half-space a photon without absorption \
             has no finite mean path (it must wander back to the surface), so the simulation would \
             never end; give a slab thickness with --thickness-mm, or a small absorption such as \
             --sigma-a 1e-4 (the run's cost is then estimated and checked before it starts)"
        );
    }
    let thickness = args.thickness_mm.unwrap_or(f64::INFINITY);
    let layer = Layer::from_reduced(
        args.sigma_s_prime,
        args.sigma_a,
        args.g,
        args.eta,
        thickness,
    )
    .context("bad material parameters")?;
    let sample = Sample::slab(layer, 1.0)?;
    let beam = Beam::new(parse_beam(&args.beam)?)
        .context("bad --beam")?
        .with_incidence(args.incidence_deg.to_radians())
        .context("bad --incidence-deg (must lie in [0, 90))")?;
    let grid = RadialGrid::uniform(args.r_max_mm / args.bins as f64, args.bins)?;
    let sim = Simulation::new(sample, beam, grid, args.photons, args.seed)?
        .with_angle_bins(args.angle_bins);
    let cost = sim.cost_estimate();
    if cost.interactions > args.work.max_interactions as f64 {
        bail!(
            "this run is expected to take about {:.1e} interactions ({:.3e} per photon × {} \
             photons; σs = σ′s/(1 − g) = {:.4e} mm⁻¹, σa = {} mm⁻¹{}), about {} on {} threads, \
             more than the work budget of {:.1e} (--max-interactions); use fewer photons, a larger \
             σa{}, a g further from 1, or raise --max-interactions if you mean it",
            cost.interactions,
            cost.interactions_per_photon,
            args.photons,
            layer.sigma_s(),
            args.sigma_a,
            args.thickness_mm
                .map_or_else(|| ", half-space".to_owned(), |t| format!(", {t} mm thick")),
            crate::numeric::describe_seconds(cost.seconds(rayon::current_num_threads())),
            rayon::current_num_threads(),
            args.work.max_interactions as f64,
            if args.thickness_mm.is_some() {
                ", a thinner slab"
            } else {
                ""
            },
        );
    }
    Ok(sim)
}

/// Runs `scatterfit simulate`.
pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let sim = configure(&args)?;
    if let Some(path) = &args.output {
        crate::common::check_output_file(
            path,
            "-o",
            crate::common::Format {
                extensions: &["csv", "json"],
                what: "simulate writes the profile as CSV (.csv) or the whole result as JSON (.json)",
            },
            &[],
            args.force,
        )?;
    }
    let cost = sim.cost_estimate();
    let expected_s = cost.seconds(rayon::current_num_threads());
    if !args.quiet && expected_s > 10.0 {
        errln!(
            "expected work: {:.1e} interactions ({:.3e} per photon), about {} on {} threads",
            cost.interactions,
            cost.interactions_per_photon,
            crate::numeric::describe_seconds(expected_s),
            rayon::current_num_threads()
        );
    }
    let bar = crate::common::bar(args.photons, crate::common::PHOTONS_BAR, args.quiet);
    let start = Instant::now();
    let result = sim.run_with_progress(&|done| bar.set_position(done));
    let elapsed = start.elapsed().as_secs_f64();
    bar.finish_and_clear();
    let rate = args.photons as f64 / elapsed.max(1e-9);
    let report = SimulationReport {
        sigma_s_prime: args.sigma_s_prime,
        sigma_a: args.sigma_a,
        eta: args.eta,
        g: args.g,
        thickness_mm: args.thickness_mm,
        beam: &args.beam,
        incidence_deg: args.incidence_deg,
        elapsed_s: elapsed,
        photons_per_s: rate,
        threads: rayon::current_num_threads(),
        result: &result,
    };
    if let Some(path) = &args.output {
        let is_json = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("json"));
        if is_json {
            crate::output::write_json_file(path, &report)?;
        } else {
            let csv = result.profile_csv();
            scatterfit_io::atomic::write_atomic(path, csv.as_bytes())
                .with_context(|| format!("writing {}", path.display()))?;
        }
    }
    if args.json {
        crate::output::print_json(&report)?;
    } else {
        out!("{}", report.text())?;
        if let Some(p) = &args.output {
            outln!("wrote              {}", p.display())?;
        }
    }
    Ok(ExitCode::SUCCESS)
}
