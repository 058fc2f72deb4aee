//! `scatterfit simulate`: Monte Carlo photon transport (MCML physics) in a slab or half-space.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use crate::output::{errln, out, outln};
use anyhow::Context;
use scatterfit_mc::SimulationReport;
use scatterfit_pipeline::monte_carlo::SimulateSettings;

/// Arguments of `scatterfit simulate`. Every number is checked before any work (exit 2 when out of
/// range); the run's memory and expected work are checked against `--max-memory-mib` and
/// `--max-interactions` before it starts.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub sim: SimulateSettings,
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

/// Runs `scatterfit simulate`.
pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    // The settings, checked ([`SimulateSettings::configure`]: the ranges, the tallies' memory, the
    // expected work).
    let settings = SimulateSettings {
        memory_budget: args.memory.budget(),
        ..args.sim.clone()
    };
    let sim = settings.configure(rayon::current_num_threads())?;
    let s = &args.sim;
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
    let bar = crate::common::bar(s.photons, crate::common::PHOTONS_BAR, args.quiet);
    let start = Instant::now();
    let result = sim.run_with_progress(&|done| bar.set_position(done));
    let elapsed = start.elapsed().as_secs_f64();
    bar.finish_and_clear();
    let rate = s.photons as f64 / elapsed.max(1e-9);
    let report = SimulationReport {
        sigma_s_prime: s.sigma_s_prime,
        sigma_a: s.sigma_a,
        eta: s.eta,
        g: s.g,
        thickness_mm: s.thickness_mm,
        beam: &s.beam,
        incidence_deg: s.incidence_deg,
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
