//! `scatterfit`: the command-line tool.
//!
//! `main` is glue: parse the arguments, run one subcommand, print errors with their causes, and map
//! the outcome to the exit code documented in `ARCHITECTURE.md`: 0 success, 1 a measurement that
//! failed (the tool ran, the sample did not yield parameters), 2 bad usage or bad input; 130 after
//! Ctrl-C (temporary files removed first). A closed stdout (`| head`) drops what was still to be
//! printed and keeps the command's own exit code (`output`).

// Every print goes through `output`'s fallible writers: `println!` panics on a closed pipe.
#![deny(clippy::print_stdout, clippy::print_stderr)]

mod batch;
mod batch_set;
mod bench;
mod combine;
mod common;
mod compare;
mod demo;
mod export;
mod fit;
mod interrupt;
mod measure;
mod merge;
mod numeric;
mod output;
mod profile;
mod render;
mod runner;
mod shard;
mod simulate;
mod slurm;
mod spectro;
mod study;
mod study_set;
mod synth;
mod table;
mod twin;

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
    /// Measure a sample folder: σ′s, σa and η per RGB channel (spectro → HDR → profile → fit).
    ///
    /// Real cameras: frames whose times are out of order, or a frame far off its time, are refused
    /// (exit 1, naming the frames); the camera response is recovered monotone (a good bracket is
    /// never refused for a dip at low codes); shutter times are estimated from the frames and used
    /// when off by more than 1 %; linear 16-bit and RAW frames (DNG, CR2, CR3, NEF, ARW, RAF, …) lose
    /// their black level (camera.black_level, else the RAW metadata, else the frame's far corners);
    /// veiling glare is fitted beyond the profile and subtracted (camera.background); camera.flat
    /// divides out vignetting; camera.spot_profile = "gaussian" or camera.spot_image sets the spot's
    /// shape for the fit. result.json's inputs.options.camera says what was found and corrected.
    Measure(measure::Args),
    /// Fit a radial profile you already have (a profile CSV), given η and α′.
    Fit(fit::Args),
    /// Measure many sample folders in parallel; summary.csv / summary.md like the paper's Table 1.
    Batch(batch::Args),
    /// Both methods (proposed, existing) on the same data: Table 2 and Figure 6 of the paper.
    Compare(compare::Args),
    /// Spectrophotometer stage: η from SCI−SCE, colour, Rd and reduced albedo α′ per RGB channel.
    Spectro(spectro::Args),
    /// Monte Carlo photon transport (MCML physics) in a slab or half-space.
    Simulate(simulate::Args),
    /// Build (or show) a cached Monte Carlo profile table Rd(α′, r) for one η and g.
    Table(table::Args),
    /// Add up the partial files of a sharded run (`--shard K/N`) into the one-machine result.
    Combine(combine::Args),
    /// Write a Slurm script: a job array of `table`, `batch` or `study` shards and a dependent
    /// combine job.
    Slurm(slurm::Args),
    /// Merge an exposure bracket into an HDR radiance map (Debevec & Malik 1997).
    ///
    /// The frames' order is checked first (a longer exposure that is darker than its neighbour is
    /// refused, naming both files); the recovered response is monotone by construction; shutter
    /// times are estimated from the frames and used when off by more than 1 %; RAW frames (DNG and
    /// the vendors' formats) are merged as linear data less the black level in their metadata;
    /// linear 16-bit frames with a pedestal lose the black level found in the far corners.
    Merge(merge::Args),
    /// Radial profile Rd(r) around the light spot of a radiance map.
    Profile(profile::Args),
    /// The rig twin: write a synthetic sample folder (Monte Carlo spectro reading and bracket).
    ///
    /// Besides the paper's rig, the twin has other cameras (--camera: 8-bit tone curves, linear
    /// 16-bit, DNG raw) and a real rig's effects (--glare, --vignetting with a flat frame,
    /// --exposure-error, --gaussian-spot, --spot-image), each off by default.
    Synth(synth::Args),
    /// The bias study: rig-twin samples over α′ and η (and g, with --g) fitted with every model and
    /// method.
    Study(study::Args),
    /// Export a measured result as a pbrt-v4, Mitsuba 3, Blender or JSON material.
    Export(export::Args),
    /// Render measured parameters on a mesh by the paper's two methods; validate against the profile.
    Render(render::Args),
    /// Measure the speed of the hot paths on this machine.
    Bench(bench::Args),
}

fn main() -> ExitCode {
    interrupt::install();
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(err) => {
            // clap prints help/version to stdout with success, usage errors to stderr.
            let code = if err.use_stderr() { 2 } else { 0 };
            let _ = err.print();
            return ExitCode::from(code);
        }
    };
    match run(cli).and_then(|code| output::flush_stdout().map(|()| code)) {
        Ok(code) => code,
        Err(err) => {
            output::errln!("error: {}", common::error_text(&err));
            ExitCode::from(if common::is_measurement_failure(&err) {
                1
            } else {
                2
            })
        }
    }
}

/// The user's `--force`: besides each command's own meaning, files scatterfit did not write may be
/// replaced (`scatterfit_safefs::ledger`).
fn force(command: &Command) -> bool {
    match command {
        Command::Demo(a) => a.force,
        Command::Measure(a) => a.force,
        Command::Fit(a) => a.force,
        Command::Batch(a) => a.samples.force,
        Command::Compare(a) => a.samples.force,
        Command::Spectro(a) => a.force,
        Command::Simulate(a) => a.force,
        Command::Table(a) => a.force,
        Command::Combine(a) => a.force,
        Command::Slurm(a) => match &a.what {
            slurm::What::Table { slurm, .. }
            | slurm::What::Batch { slurm, .. }
            | slurm::What::Study { slurm, .. } => slurm.force_script,
        },
        Command::Merge(a) => a.force,
        Command::Profile(a) => a.force,
        Command::Synth(a) => a.force,
        Command::Study(a) => a.force,
        Command::Export(a) => a.force,
        Command::Render(a) => a.force,
        Command::Bench(_) => false,
    }
}

fn run(cli: Cli) -> anyhow::Result<ExitCode> {
    // One output policy for every command: a file is replaced only if scatterfit wrote it.
    scatterfit_io::atomic::guard_outputs(force(&cli.command));
    match cli.command {
        Command::Demo(args) => demo::run(args),
        Command::Measure(args) => measure::run(args),
        Command::Fit(args) => fit::run(args),
        Command::Batch(args) => batch::run(args),
        Command::Compare(args) => compare::run(args),
        Command::Spectro(args) => spectro::run(args),
        Command::Simulate(args) => simulate::run(args),
        Command::Table(args) => table::run(args),
        Command::Combine(args) => combine::run(args),
        Command::Slurm(args) => slurm::run(args),
        Command::Merge(args) => merge::run(args),
        Command::Profile(args) => profile::run(args),
        Command::Synth(args) => synth::run(args),
        Command::Study(args) => study::run(args),
        Command::Export(args) => export::run(args),
        Command::Render(args) => render::run(args),
        Command::Bench(args) => bench::run(args),
    }
}
