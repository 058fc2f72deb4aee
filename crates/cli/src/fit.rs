//! `scatterfit fit`: fits a profile a user already has — the profile command's CSV, or any table
//! with `r_mm` and `value_<c>`, `stderr_<c>`, `count_<c>` columns per channel (optionally
//! `limit_<c>`) — given η and, for the proposed method, α′ per channel.

use std::path::PathBuf;
use std::process::ExitCode;

use crate::output::out;
use anyhow::Context;
use scatterfit_io::profile_csv::read_profile_csv;
use scatterfit_io::result_json::write_result_json;
use scatterfit_optics::Rgb;
use scatterfit_pipeline::profile::channel_from_table;
use scatterfit_pipeline::profile_fit::fit_profile;
use scatterfit_pipeline::profile_fit_args::ProfileFitArgs;

/// Arguments of `scatterfit fit`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The profile CSV (channels r, g, b).
    pub profile: PathBuf,
    #[command(flatten)]
    pub fit: ProfileFitArgs,
    /// Also write the result (result.json's shape) to this file (`.json`; checked before the fit;
    /// an existing file only with --force).
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    pub output: Option<PathBuf>,
    /// Replace an existing output file.
    #[arg(long)]
    pub force: bool,
    /// Print the result as JSON.
    #[arg(long)]
    pub json: bool,
}

/// Runs `scatterfit fit`.
pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    if let Some(out) = &args.output {
        crate::common::check_output_file(
            out,
            "-o",
            crate::common::Format {
                extensions: &["json"],
                what: "the result is written as JSON (result.json's shape)",
            },
            &[args.profile.as_path()],
            args.force,
        )?;
    }
    let table = read_profile_csv(&args.profile)?;
    let data = Rgb::from_fn(|c| channel_from_table(&table, c.key()))
        .transpose()
        .with_context(|| format!("{}", args.profile.display()))?;
    let request = args.fit.request(&args.profile);
    let fitted = fit_profile(&data, &request)?;
    let result = fitted.to_result();
    if let Some(out) = &args.output {
        write_result_json(out, &result)?;
    }
    if args.json {
        crate::output::print_json(&result)?;
    } else {
        out!("{}", scatterfit_report::summary_text(&result))?;
    }
    Ok(if fitted.complete() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}
