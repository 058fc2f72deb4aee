//! `scatterfit slurm table|batch|study ARGS... --array N`: writes a Slurm batch script for the user to
//! read and submit (`scatterfit_lab::slurm`: a job array of N shards of the command and a
//! dependent combine job). This file takes the command's own arguments from the command line,
//! checks them and the outputs, and writes the script.

use std::process::ExitCode;

use anyhow::{Context, bail};

use scatterfit_lab::partial::Kind;
use scatterfit_lab::slurm::SlurmSettings;

use crate::output::{errln, outln};

/// The commands `slurm` can shard.
#[derive(Debug, clap::Subcommand)]
pub enum What {
    /// A Monte Carlo table (`scatterfit table`'s arguments; -o FILE is written by the combine job).
    Table {
        #[command(flatten)]
        slurm: SlurmSettings,
        #[command(flatten)]
        args: crate::table::Args,
    },
    /// A batch of samples (`scatterfit batch`'s arguments; -o DIR gets the combine job's summary).
    Batch {
        #[command(flatten)]
        slurm: SlurmSettings,
        #[command(flatten)]
        args: crate::batch::Args,
    },
    /// A bias study (`scatterfit study`'s arguments; the shards write their samples into -o DIR,
    /// the combine job the tables and the figure).
    Study {
        #[command(flatten)]
        slurm: SlurmSettings,
        #[command(flatten)]
        args: crate::study::Args,
    },
}

/// Arguments of `scatterfit slurm`.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(subcommand)]
    pub what: What,
}

/// Runs `scatterfit slurm`.
pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    // The command's tokens as given: `scatterfit slurm <kind> TOKENS…`.
    let argv: Vec<String> = std::env::args().collect();
    let at = argv
        .iter()
        .position(|a| a == "slurm")
        .context("`slurm` not found on the command line")?;
    let tokens = &argv[(at + 2).min(argv.len())..];
    let (kind, slurm, shard, partial_dir, output_flags, fingerprint) = match &args.what {
        What::Table { slurm, args } => {
            let Some(out) = &args.output else {
                bail!("give -o FILE: the table the combine job writes (e.g. -o table.json)");
            };
            crate::common::check_output_file(
                out,
                "-o",
                crate::common::Format {
                    extensions: &["json"],
                    what: "the table is written as JSON",
                },
                &[],
                args.force,
            )?;
            let spec = crate::table::spec_for_shards(args, slurm.array)?;
            (
                Kind::Table,
                slurm,
                &args.shard,
                args.shard.partial_dir.clone(),
                vec!["-o", "--output"],
                Some(crate::shard::fingerprint(&spec)),
            )
        }
        What::Batch { slurm, args } => (
            Kind::Batch,
            slurm,
            &args.shard,
            args.shard.partial_dir.clone(),
            vec!["-o", "--output-dir"],
            None,
        ),
        // The shards need -o (their samples go there): it stays in their command line too.
        What::Study { slurm, args } => (
            Kind::Study,
            slurm,
            &args.shard,
            args.shard.partial_dir.clone(),
            vec![],
            None,
        ),
    };
    let study_out = match &args.what {
        What::Study { args, .. } => Some(args.output_dir.to_string_lossy().into_owned()),
        _ => None,
    };
    if let Some(s) = shard.shard {
        bail!("--shard {s}: the script gives each array task its shard; leave --shard out");
    }
    let Some(partial_dir) = partial_dir else {
        bail!(
            "give --partial-dir DIR: the folder for the shards' partial files and the logs, on a \
             file system every node sees"
        );
    };
    crate::common::check_output_file(
        &slurm.script,
        "--script",
        crate::common::Format {
            extensions: &["sh"],
            what: "the script is a shell script",
        },
        &[],
        slurm.force_script,
    )?;
    let cwd = std::env::current_dir().context("the current folder")?;
    let exe = std::env::current_exe().context("finding the scatterfit binary")?;
    let job = slurm.job(
        kind,
        tokens,
        &output_flags,
        study_out,
        &partial_dir,
        fingerprint,
        exe,
        cwd,
    );
    let (n, name, script) = (job.array, kind.name(), job.script());
    scatterfit_io::atomic::write_atomic(&slurm.script, script.as_bytes())
        .with_context(|| format!("--script {}", slurm.script.display()))?;
    errln!(
        "wrote {}: {n} shards of `scatterfit {name}` and a combine job; read it, then `bash {}`",
        slurm.script.display(),
        slurm.script.display()
    );
    outln!("{}", slurm.script.display())?;
    Ok(ExitCode::SUCCESS)
}
