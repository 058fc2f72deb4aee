//! `scatterfit fit`: fits a profile a user already has — the profile command's CSV, or any table
//! with `r_mm` and `value_<c>`, `stderr_<c>`, `count_<c>` columns per channel (optionally
//! `limit_<c>`) — given η and, for the proposed method, α′ per channel.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
use scatterfit_io::profile_csv::read_profile_csv;
use scatterfit_io::result_json::write_result_json;
use scatterfit_optics::{Method, ModelName, Rgb};
use scatterfit_pipeline::profile::channel_from_table;
use scatterfit_pipeline::profile_fit::{ProfileFitRequest, fit_profile};

use crate::common::{parse_g, parse_g_range, parse_rgb};
use crate::output::out;

/// Arguments of `scatterfit fit`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The profile CSV (channels r, g, b).
    pub profile: PathBuf,
    /// Relative refractive index η, in [1, 3].
    #[arg(long, value_parser = crate::numeric::parse_finite)]
    pub eta: f64,
    /// Reduced albedo α′ per channel R,G,B, each in (0, 1] (the proposed method needs it or --rd).
    #[arg(long, value_name = "R,G,B", value_parser = parse_rgb)]
    pub albedo: Option<[f64; 3]>,
    /// The spectrophotometer's total diffuse reflectance Rd per channel R,G,B, each in (0, 1].
    /// Without --albedo, α′ is inverted from it through --model at --eta and g; with --albedo,
    /// the two must agree through that model within 0.01 in Rd. Default: the model's Rd of the
    /// given α′.
    #[arg(long, value_name = "R,G,B", value_parser = parse_rgb)]
    pub rd: Option<[f64; 3]>,
    /// The fitting method.
    #[arg(long, value_enum, default_value_t = Method::Proposed)]
    pub method: Method,
    /// The forward model (mc, exact transport, by default; dipole is the paper's).
    #[arg(long, value_enum, default_value_t = ModelName::Mc)]
    pub model: ModelName,
    /// Diameter of the light spot \[mm\], in (0, 20]; the model is convolved with it.
    #[arg(long, default_value_t = 1.0, value_name = "MM", value_parser = crate::numeric::parse_finite)]
    pub spot_diameter_mm: f64,
    /// Innermost fitted radius \[mm\], in [0, 1000) (default: the spot diameter).
    #[arg(long, value_name = "MM", value_parser = crate::numeric::parse_finite)]
    pub r_min_mm: Option<f64>,
    /// Proposed method: fix the profile's scale by the spectrophotometer's Rd.
    #[arg(long)]
    pub normalise_with_spectro: bool,
    /// The material's Henyey–Greenstein g, known or assumed, in (−1, 1): the model is evaluated at
    /// it (as the manifest's `[fit] g`). Alone, g is known and its error term is 0. Or `fit`
    /// (needs --model mc): g fitted per channel from the profile within --g-range (default: what
    /// the `mc` tables cover at η, 0–0.95), printed with its standard error where the data
    /// determine it (sd(g) ≤ 0.05, the minimum inside the range); elsewhere "not determined" and
    /// the range's ± g term.
    #[arg(long, value_name = "G|fit", value_parser = parse_g)]
    pub g: Option<scatterfit_io::manifest::GSetting>,
    /// The range LO,HI (0 ≤ LO ≤ HI ≤ 0.95) the material's g lies in (as `[fit] g_range`),
    /// propagated into σ′s, σa and α′ as a separate "± g" term from the g-aware `mc` model; with
    /// --g the values are at that g, without it the middle of the estimates over the range.
    /// Neither --g nor --g-range: the values at g = 0 and the term over 0–0.95 (g not stated is g
    /// not known). With --albedo and no --rd, α′ is held fixed over the range (the term is then the
    /// profile's part only); give --rd to have α′ follow g.
    #[arg(long, value_name = "LO,HI", value_parser = parse_g_range)]
    pub g_range: Option<[f64; 2]>,
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
    let request = ProfileFitRequest {
        name: args
            .profile
            .file_stem()
            .map_or_else(|| "profile".into(), |s| s.to_string_lossy().into_owned()),
        profile_file: Some(args.profile.to_string_lossy().into_owned()),
        eta: args.eta,
        albedo_prime: args.albedo.map(Rgb::from_array),
        rd: args.rd.map(Rgb::from_array),
        method: args.method,
        model: args.model,
        spot_diameter_mm: args.spot_diameter_mm,
        r_min_mm: args.r_min_mm,
        normalise_with_spectro: args.normalise_with_spectro,
        g_prior: scatterfit_pipeline::anisotropy::GPrior::from_setting(args.g, args.g_range),
    };
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
