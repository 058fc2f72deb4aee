//! `scatterfit`: the command-line tool.
//!
//! `main` is glue: parse the arguments, run one subcommand, print errors with their causes, and map
//! the outcome to the exit code documented in `ARCHITECTURE.md`: 0 success, 1 a measurement that
//! failed (the tool ran, the sample did not yield parameters), 2 bad usage or bad input.

mod bench;
mod demo;
mod merge;
mod output;
mod profile;
mod render;
mod simulate;
mod spectro;
mod table;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

/// Measure how light travels inside translucent materials and hand renderers the numbers.
///
/// Units: millimetres and mm⁻¹ everywhere.
#[derive(Debug, Parser)]
#[command(name = "scatterfit", version, about, long_about = None, propagate_version = true)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Run the pipeline on built-in example measurements.
    Demo(demo::Args),
    /// Spectrophotometer stage: η from SCI−SCE, colour, Rd and reduced albedo α′ per RGB channel.
    Spectro(spectro::Args),
    /// Monte Carlo photon transport (MCML physics) in a slab or half-space.
    Simulate(simulate::Args),
    /// Build (or show) a cached Monte Carlo profile table Rd(α′, r) for one η and g.
    Table(table::Args),
    /// Merge an exposure bracket into an HDR radiance map (Debevec & Malik 1997).
    Merge(merge::Args),
    /// Radial profile Rd(r) around the light spot of a radiance map.
    Profile(profile::Args),
    /// Render measured parameters on a mesh by the paper's two methods; validate against the profile.
    Render(render::Args),
    /// Measure the speed of the hot paths on this machine.
    Bench(bench::Args),
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(err) => {
            // clap prints help/version to stdout with success, usage errors to stderr.
            let code = if err.use_stderr() { 2 } else { 0 };
            let _ = err.print();
            return ExitCode::from(code);
        }
    };
    match run(cli) {
        Ok(code) => code,
        Err(err) => {
            eprintln!("error: {err:#}");
            ExitCode::from(2)
        }
    }
}

fn run(cli: Cli) -> anyhow::Result<ExitCode> {
    match cli.command {
        Command::Demo(args) => demo::run(args),
        Command::Spectro(args) => spectro::run(args),
        Command::Simulate(args) => simulate::run(args),
        Command::Table(args) => table::run(args),
        Command::Merge(args) => merge::run(args),
        Command::Profile(args) => profile::run(args),
        Command::Render(args) => render::run(args),
        Command::Bench(args) => bench::run(args),
    }
}
