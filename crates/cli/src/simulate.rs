//! `scatterfit simulate`: Monte Carlo photon transport (MCML physics) in a slab or half-space.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use crate::output::{errln, out, outln};
use anyhow::Context;
use scatterfit_mc::{Simulation, SimulationReport};
use scatterfit_pipeline::monte_carlo::SimulateSettings;

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

/// The simulation the flags describe, checked ([`SimulateSettings::configure`]: the ranges, the
/// tallies' memory, the expected work).
fn configure(args: &Args) -> anyhow::Result<Simulation> {
    let settings = SimulateSettings {
        sigma_s_prime: args.sigma_s_prime,
        sigma_a: args.sigma_a,
        eta: args.eta,
        g: args.g,
        thickness_mm: args.thickness_mm,
        photons: args.photons,
        seed: args.seed,
        beam: args.beam.clone(),
        incidence_deg: args.incidence_deg,
        r_max_mm: args.r_max_mm,
        bins: args.bins,
        angle_bins: args.angle_bins,
        allow_eta_below_one: args.allow_eta_below_one,
        max_interactions: args.work.max_interactions,
        memory_budget: args.memory.budget(),
    };
    Ok(settings.configure(rayon::current_num_threads())?)
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
