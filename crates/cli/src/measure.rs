//! `scatterfit measure`: one sample folder → σ′s, σa and η per channel (the paper's Table 1 row),
//! with the result files written into the folder (or `--output-dir`).

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
use scatterfit_pipeline::{Stage, measure_sample};
use serde::Serialize;

use crate::common::{FitArgs, bar};
use crate::output::{errln, out, outln};
use scatterfit_io::manifest::MethodName;

/// Arguments of `scatterfit measure`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The sample folder (holding sample.toml).
    pub dir: PathBuf,
    /// Where to write result.json, result.csv, result.md, profile.csv, fit.svg and fit.png
    /// (default: the sample folder; these files are the command's own and are replaced).
    #[arg(short = 'o', long = "output-dir", value_name = "DIR")]
    pub output_dir: Option<PathBuf>,
    #[command(flatten)]
    pub fit: FitArgs,
    /// Print result.json on stdout instead of the summary.
    #[arg(long)]
    pub json: bool,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
}

#[derive(Serialize)]
struct Timing {
    timings: scatterfit_pipeline::Timings,
}

/// Runs `scatterfit measure`.
pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let overrides = args.fit.overrides()?;
    let out = args.output_dir.clone().unwrap_or_else(|| args.dir.clone());
    // Where the result files go is checked before the measurement (milliseconds, not minutes).
    crate::common::check_output_dir(&out, "-o")?;
    let bar = bar(5, "{msg} {bar:30} {elapsed}", args.quiet || args.json);
    let m = measure_sample(&args.dir, &overrides, &|stage| {
        let msg = match stage {
            Stage::Spectro => "spectrophotometer",
            Stage::ReadFrame => "reading frames",
            Stage::Merge => "merging",
            Stage::Profile => "profile",
            Stage::Fit => "fitting",
            _ => "",
        };
        bar.set_message(msg);
        bar.tick();
    })
    .with_context(|| format!("measuring {}", args.dir.display()))?;
    bar.finish_and_clear();
    for w in &m.spectro.warnings {
        errln!("warning: {w}");
    }
    for p in &m.hdr.dropped_alpha {
        errln!("note: {}: alpha channel ignored", p.display());
    }
    let (result, written) = crate::report::write_measurement(&out, &m)?;
    if args.json {
        crate::output::print_json(&result)?;
    } else {
        out!("{}", crate::report::summary_text(&result))?;
        let t = &m.timings;
        outln!(
            "  time: {:.3} s (spectro {:.3}, read {:.3}, merge {:.3}, profile {:.3}, fits {:.4})",
            t.total_s,
            t.spectro_s,
            t.read_s,
            t.merge_s,
            t.profile_s,
            t.fit_s
        )?;
        outln!(
            "  wrote {} files in {}: {}",
            written.len(),
            out.display(),
            written
                .iter()
                .filter_map(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
                .collect::<Vec<_>>()
                .join(", ")
        )?;
    }
    let _ = Timing { timings: m.timings };
    Ok(if m.complete() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

/// Contributes the fit figures to `scatterfit bench fit`: one channel's fit on a 300-ring profile
/// (0.05 mm rings of a rig-twin sample's radial profile) — the proposed method with the spot
/// convolved (the default), with a point spot, and the existing method — as the median of many
/// runs on one thread; and a whole sample (13 × 1 MP exposures read, response recovered, merged,
/// profiled, three fits, result files and plots written) as the median of three runs.
pub fn bench(args: &crate::bench::Args) -> anyhow::Result<Vec<crate::bench::Figure>> {
    use std::time::Instant;

    use scatterfit_fit::{ChannelInput, DipoleModel, FitOptions, PreparedFit, Spot};
    use scatterfit_synth::materials::by_name;

    use crate::bench::Figure;

    let temp = tempfile::tempdir()?;
    let dir = temp.path().join("wood-tile");
    let m = by_name("wood-tile").context("the built-in material")?;
    let material = crate::twin::Material {
        name: m.name.into(),
        sigma_s_prime: m.sigma_s_prime,
        sigma_a: m.sigma_a,
        eta: m.eta,
    };
    let cache = crate::common::cache_dir(None);
    let sample = crate::twin::synthesize(&material, 1, cache.as_deref(), true, args.quick)?;
    crate::twin::write_sample(&dir, &sample)?;
    let overrides = scatterfit_pipeline::Overrides::default();
    let mut totals = Vec::new();
    let mut last = None;
    for _ in 0..3 {
        let t0 = Instant::now();
        let meas = measure_sample(&dir, &overrides, &|_| {})?;
        crate::report::write_measurement(&dir, &meas)?;
        totals.push(t0.elapsed().as_secs_f64());
        last = Some(meas);
    }
    totals.sort_by(f64::total_cmp);
    let meas = last.context("three runs")?;
    let data = meas.profile.channel_data(1)?;
    let rings = data.rings().len();
    let input = ChannelInput {
        eta: meas.spectro.eta,
        albedo_prime: meas.spectro.albedo_prime[1],
        rd_total: Some(meas.spectro.rd[1]),
    };
    let reps = if args.quick { 200 } else { 2_000 };
    let mut figures = Vec::new();
    let cases = [
        (
            "proposed, spot disk convolved (default)",
            MethodName::Proposed,
            true,
        ),
        ("proposed, point spot", MethodName::Proposed, false),
        (
            "existing (σ′s, σa), spot disk convolved",
            MethodName::Existing,
            true,
        ),
    ];
    for (label, method, disk) in cases {
        let mut opts = FitOptions::new(match method {
            MethodName::Proposed => scatterfit_fit::Method::Proposed,
            MethodName::Existing => scatterfit_fit::Method::Existing,
        });
        if !disk {
            opts.spot = Spot::Point;
        }
        let prepared = PreparedFit::new(&data, &input, &DipoleModel, &opts)?;
        let n = if method == MethodName::Existing {
            reps / 10
        } else {
            reps
        };
        let mut times: Vec<f64> = (0..n)
            .map(|_| {
                let t0 = Instant::now();
                std::hint::black_box(prepared.solve());
                t0.elapsed().as_secs_f64()
            })
            .collect();
        times.sort_by(f64::total_cmp);
        let used = prepared.selected().r_mm.len();
        figures.push(Figure {
            name: format!("fit one channel: {label}"),
            value: times[times.len() / 2] * 1e6,
            unit: "µs".into(),
            note: format!("median of {n}; {rings}-ring profile, {used} fitted; one thread"),
        });
    }
    let px = sample.truth.rig.width * sample.truth.rig.height;
    figures.push(Figure {
        name: "measure a whole sample (read, merge, profile, 3 fits, files, plots)".into(),
        value: totals[1],
        unit: "s".into(),
        note: format!(
            "median of 3; 13 × {:.1} MP 8-bit PNG; {} threads",
            px as f64 / 1e6,
            rayon::current_num_threads()
        ),
    });
    Ok(figures)
}
