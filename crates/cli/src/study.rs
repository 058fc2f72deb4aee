//! `scatterfit study`: the bias study. Rig-twin samples (Monte Carlo, noisy 8-bit brackets) over a
//! grid of reduced albedos α′ and refractive indices η are measured once each and fitted with every
//! forward model and method; the errors of σ′s, σa and α′ against the truth are tabulated per
//! (model, albedo model, method) and plotted, and where each model stops being usable is stated.
//!
//! Every grid point is one channel; three albedos at the same η share a sample. σ′t is the same for
//! all (default 2 mm⁻¹, a mean free path of 0.5 mm, like the paper's materials), so σ′s = α′σ′t and
//! σa = (1 − α′)σ′t. The study owns its output folder (a `.scatterfit-study` marker).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{Context, bail};
use rayon::prelude::*;
use scatterfit_optics::{AlbedoModel, Method, ModelName};
use scatterfit_pipeline::fit::FitSettings;
use scatterfit_pipeline::{Measurement, Overrides, measure_sample};
use scatterfit_report::{Figure, Panel, Series, SeriesStyle};
use serde::Serialize;

use crate::common::cache_dir;
use crate::output::{errln, out, outln};
use crate::twin::{Material, synthesize, write_sample};

/// Arguments of `scatterfit study`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Folder for the samples and the study's tables and plot (created; the study's own).
    #[arg(
        short = 'o',
        long = "output-dir",
        default_value = "scatterfit-study",
        value_name = "DIR"
    )]
    pub output_dir: PathBuf,
    /// Refractive indices η, each in [1, 2.5] (the Monte Carlo tables' range).
    #[arg(long, value_delimiter = ',', default_values_t = [1.0, 1.2, 1.4, 1.6, 2.0, 2.4])]
    pub etas: Vec<f64>,
    /// Reduced albedos α′, each in [0.3, 0.9999].
    #[arg(long, value_delimiter = ',', default_values_t = [0.3, 0.5, 0.7, 0.9, 0.95, 0.98, 0.99, 0.999, 0.9999])]
    pub albedos: Vec<f64>,
    /// Reduced extinction σ′t of every grid point [mm⁻¹, 0.2–20].
    #[arg(long, default_value_t = 2.0, value_name = "MM-1")]
    pub sigma_t_prime: f64,
    /// Small fast samples (256 × 256 px at 0.1 mm/px, a tenth of the photons).
    #[arg(long)]
    pub quick: bool,
    /// Seed of the rig twin.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Samples measured at the same time [1, 256] (default: one per core).
    #[arg(short = 'j', long, value_name = "N", value_parser = clap::value_parser!(u16).range(1..=256))]
    pub jobs: Option<u16>,
    /// Leave out photon beam diffusion (its fits take milliseconds, not microseconds).
    #[arg(long)]
    pub no_pbd: bool,
    /// Use a folder that holds other files than a previous study's.
    #[arg(long)]
    pub force: bool,
    /// Folder for cached Monte Carlo profiles.
    #[arg(long, value_name = "DIR")]
    pub cache_dir: Option<PathBuf>,
    /// Print the rows as JSON.
    #[arg(long)]
    pub json: bool,
    /// No progress bars.
    #[arg(long)]
    pub quiet: bool,
}

/// One fit configuration of the study.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Combo {
    model: ModelName,
    albedo: AlbedoModel,
    method: Method,
}

impl Combo {
    fn label(self) -> String {
        format!(
            "{} + {} α′, {}",
            self.model.name(),
            self.albedo.name(),
            self.method.name()
        )
    }
}

/// One grid point fitted one way.
#[derive(Debug, Clone, Serialize)]
pub struct Row {
    eta: f64,
    albedo_prime: f64,
    model: &'static str,
    albedo_model: &'static str,
    method: &'static str,
    status: String,
    sigma_s_prime_error: Option<f64>,
    sigma_a_error: Option<f64>,
    albedo_prime_error: Option<f64>,
}

const MARKER: &str = ".scatterfit-study";

fn combos(no_pbd: bool) -> Vec<Combo> {
    let mut v = Vec::new();
    for model in [
        ModelName::Dipole,
        ModelName::BetterDipole,
        ModelName::Pbd,
        ModelName::Mc,
    ] {
        if no_pbd && model == ModelName::Pbd {
            continue;
        }
        let albedo = AlbedoModel::default_for(model);
        for method in [Method::Proposed, Method::Existing] {
            v.push(Combo {
                model,
                albedo,
                method,
            });
        }
    }
    // The two biases apart: the dipole's profile with an exact α′, and the exact profile with the
    // dipole's α′.
    v.push(Combo {
        model: ModelName::Dipole,
        albedo: AlbedoModel::Mc,
        method: Method::Proposed,
    });
    v.push(Combo {
        model: ModelName::Mc,
        albedo: AlbedoModel::Diffusion,
        method: Method::Proposed,
    });
    v
}

fn check_args(args: &Args) -> anyhow::Result<()> {
    if args.etas.is_empty() || args.albedos.is_empty() {
        bail!("give at least one η and one α′");
    }
    if let Some(e) = args.etas.iter().find(|e| !(1.0..=2.5).contains(*e)) {
        bail!(
            "--etas: {} is outside [1, 2.5], the range of the Monte Carlo tables",
            crate::numeric::show(*e)
        );
    }
    if let Some(a) = args.albedos.iter().find(|a| !(0.3..=0.9999).contains(*a)) {
        bail!(
            "--albedos: {} is outside [0.3, 0.9999]",
            crate::numeric::show(*a)
        );
    }
    if !(0.2..=20.0).contains(&args.sigma_t_prime) {
        bail!(
            "--sigma-t-prime {}: must lie in [0.2, 20] mm⁻¹",
            crate::numeric::show(args.sigma_t_prime)
        );
    }
    let dir = &args.output_dir;
    if dir.exists()
        && !args.force
        && !dir.join(MARKER).exists()
        && let Some(e) = std::fs::read_dir(dir)?.flatten().next()
    {
        bail!(
            "{} holds {} and was not made by `scatterfit study`; choose another folder with -o or \
             pass --force",
            dir.display(),
            e.file_name().to_string_lossy()
        );
    }
    Ok(())
}

/// Runs `scatterfit study`.
pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    check_args(&args)?;
    let t0 = Instant::now();
    let out = &args.output_dir;
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    scatterfit_io::atomic::write_atomic(
        &out.join(MARKER),
        b"made by `scatterfit study`; it may replace the files in this folder\n",
    )?;
    let quiet = args.quiet || args.json;
    let cache = cache_dir(args.cache_dir.as_deref());
    // Samples: three albedos per η each (the last triple padded with its last albedo).
    let mut samples: Vec<(PathBuf, f64, [f64; 3])> = Vec::new();
    for &eta in &args.etas {
        for chunk in args.albedos.chunks(3) {
            let a: [f64; 3] = std::array::from_fn(|c| chunk[c.min(chunk.len() - 1)]);
            let name = format!(
                "eta{eta:.2}-a{}",
                chunk
                    .iter()
                    .map(|a| format!("{a}"))
                    .collect::<Vec<_>>()
                    .join("_")
            );
            samples.push((out.join("samples").join(name), eta, a));
        }
    }
    if !quiet {
        errln!(
            "study: {} samples ({} η × {} α′) on the {} rig, Monte Carlo cached in {}",
            samples.len(),
            args.etas.len(),
            args.albedos.len(),
            if args.quick { "quick" } else { "paper's" },
            cache
                .as_deref()
                .map_or("no cache".into(), |p| p.display().to_string())
        );
    }
    for (dir, eta, a) in &samples {
        let st = args.sigma_t_prime;
        let m = Material {
            name: dir
                .file_name()
                .map_or_else(|| "sample".into(), |n| n.to_string_lossy().into_owned()),
            sigma_s_prime: a.map(|a| a * st),
            sigma_a: a.map(|a| (1.0 - a) * st),
            eta: *eta,
        };
        let s = synthesize(&m, args.seed, cache.as_deref(), quiet, args.quick)?;
        write_sample(dir, &s)?;
    }
    let synth_s = t0.elapsed().as_secs_f64();
    let combos = combos(args.no_pbd);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.jobs.map_or(0, usize::from))
        .build()?;
    let bar = crate::common::bar(
        samples.len() as u64,
        "fitting {bar:30} {pos}/{len} samples {elapsed}",
        quiet,
    );
    let results: Vec<anyhow::Result<Vec<Row>>> = pool.install(|| {
        samples
            .par_iter()
            .map(|(dir, eta, a)| {
                let r = study_sample(dir, *eta, a, &combos);
                bar.inc(1);
                r
            })
            .collect()
    });
    bar.finish_and_clear();
    let mut rows = Vec::new();
    let mut failed = Vec::new();
    for (r, (dir, ..)) in results.into_iter().zip(&samples) {
        match r {
            Ok(v) => rows.extend(v),
            Err(e) => failed.push(format!(
                "{}: {}",
                dir.display(),
                crate::common::error_text(&e)
            )),
        }
    }
    // A padded triple repeats its last albedo: keep one row per grid point and configuration.
    let mut seen = std::collections::HashSet::new();
    rows.retain(|r| {
        seen.insert(format!(
            "{}|{}|{}|{}|{}",
            r.eta, r.albedo_prime, r.model, r.albedo_model, r.method
        ))
    });
    let summary = summary_markdown(&rows, &combos);
    let csv = rows_csv(&rows);
    for (name, text) in [("study.csv", csv), ("study.md", summary.clone())] {
        let p = out.join(name);
        scatterfit_io::atomic::write_atomic(&p, text.as_bytes())
            .with_context(|| format!("writing {}", p.display()))?;
    }
    scatterfit_report::write_figure(
        &figure(&rows, &combos),
        Some(&out.join("study.svg")),
        Some(&out.join("study.png")),
    )?;
    if args.json {
        crate::output::print_json(&rows)?;
    } else {
        out!("{summary}")?;
        outln!(
            "\ntime: {synth_s:.0} s synthesising, {:.0} s fitting; files: {}/study.md, study.csv, study.png",
            t0.elapsed().as_secs_f64() - synth_s,
            out.display()
        )?;
    }
    if !failed.is_empty() {
        errln!("\n{} sample(s) failed:", failed.len());
        for f in &failed {
            errln!("  {f}");
        }
        return Ok(ExitCode::from(1));
    }
    Ok(ExitCode::SUCCESS)
}

/// Measures one sample and fits it every way.
fn study_sample(
    dir: &Path,
    eta: f64,
    albedos: &[f64; 3],
    combos: &[Combo],
) -> anyhow::Result<Vec<Row>> {
    let truth: serde_json::Value = serde_json::from_str(
        &scatterfit_io::text::read_text_file(&dir.join("truth.json"))
            .context("reading truth.json")?
            .text,
    )?;
    // At η = 1 there is no specular reflection to measure η from (SCI = SCE): the study gives it.
    let overrides = Overrides {
        eta: (eta < 1.02).then_some(eta),
        ..Overrides::default()
    };
    let base: Measurement = measure_sample(dir, &overrides, &|_| {})?;
    let mut rows = Vec::new();
    for combo in combos {
        let settings = FitSettings {
            method: combo.method,
            model: combo.model,
            albedo_model: combo.albedo,
            normalise_with_spectro: false,
            ..base.settings
        };
        let m = base.refit_values_only(settings)?;
        let result = m.to_result(None);
        for (c, ch) in result.channels.as_ref().into_array().iter().enumerate() {
            let t = &truth["channels"][c];
            let (sp, sa) = (
                t["sigma_s_prime"].as_f64().unwrap_or(f64::NAN),
                t["sigma_a"].as_f64().unwrap_or(f64::NAN),
            );
            let rel = |v: Option<f64>, truth: f64| v.map(|v| v / truth - 1.0);
            rows.push(Row {
                eta,
                albedo_prime: albedos[c],
                model: combo.model.name(),
                albedo_model: combo.albedo.name(),
                method: combo.method.name(),
                status: format!("{:?}", ch.status).to_lowercase(),
                sigma_s_prime_error: rel(ch.sigma_s_prime, sp),
                sigma_a_error: rel(ch.sigma_a, sa),
                albedo_prime_error: ch.albedo_prime.map(|a| a - albedos[c]),
            });
        }
    }
    Ok(rows)
}

fn rows_csv(rows: &[Row]) -> String {
    let mut t = String::from(
        "eta,albedo_prime,model,albedo_model,method,status,sigma_s_prime_error,sigma_a_error,albedo_prime_error\n",
    );
    let f = |v: Option<f64>| v.map_or(String::new(), |v| format!("{v:.6}"));
    for r in rows {
        let _ = writeln!(
            t,
            "{},{},{},{},{},{},{},{},{}",
            r.eta,
            r.albedo_prime,
            r.model,
            r.albedo_model,
            r.method,
            r.status,
            f(r.sigma_s_prime_error),
            f(r.sigma_a_error),
            f(r.albedo_prime_error)
        );
    }
    t
}

fn stats(v: impl Iterator<Item = Option<f64>>) -> Option<(f64, f64, usize)> {
    let mut v: Vec<f64> = v.map(|x| x.map_or(f64::INFINITY, f64::abs)).collect();
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    Some((v[v.len() / 2], v[v.len() - 1], v.len()))
}

fn pct(s: Option<(f64, f64, usize)>) -> String {
    match s {
        Some((m, w, _)) if w.is_finite() => format!("{:.2} % / {:.1} %", 100.0 * m, 100.0 * w),
        Some((m, _, _)) if m.is_finite() => format!("{:.2} % / failed", 100.0 * m),
        _ => "failed".into(),
    }
}

/// Per configuration: median / worst |error| over the grid; per model: where it is usable.
fn summary_markdown(rows: &[Row], combos: &[Combo]) -> String {
    let mut t = String::from(
        "| model + albedo model, method | points | σ′s median / worst | σa median / worst | α′ error median / worst |\n\
         |---|---|---|---|---|\n",
    );
    let of = |c: &Combo| {
        rows.iter()
            .filter(|r| {
                r.model == c.model.name()
                    && r.albedo_model == c.albedo.name()
                    && r.method == c.method.name()
            })
            .collect::<Vec<_>>()
    };
    for c in combos {
        let rs = of(c);
        let a = stats(rs.iter().map(|r| r.albedo_prime_error));
        let _ = writeln!(
            t,
            "| {} | {} | {} | {} | {} |",
            c.label(),
            rs.len(),
            pct(stats(rs.iter().map(|r| r.sigma_s_prime_error))),
            pct(stats(rs.iter().map(|r| r.sigma_a_error))),
            a.map_or("—".into(), |(m, w, _)| format!("{m:.2e} / {w:.1e}")),
        );
    }
    // Where each model's proposed method gets σ′s and σa within 5 %: per η, the albedos.
    t.push_str("\nWhere each configuration (proposed method) has σ′s and σa within 5 % (✓), per η and α′:\n\n");
    let etas: Vec<f64> = {
        let mut e: Vec<f64> = rows.iter().map(|r| r.eta).collect();
        e.sort_by(f64::total_cmp);
        e.dedup();
        e
    };
    let albedos: Vec<f64> = {
        let mut a: Vec<f64> = rows.iter().map(|r| r.albedo_prime).collect();
        a.sort_by(f64::total_cmp);
        a.dedup();
        a
    };
    for c in combos.iter().filter(|c| c.method == Method::Proposed) {
        let rs = of(c);
        let _ = writeln!(t, "**{}**\n", c.label());
        let _ = write!(t, "| η \\ α′ |");
        for a in &albedos {
            let _ = write!(t, " {a} |");
        }
        t.push('\n');
        t.push_str(&"|---".repeat(albedos.len() + 1));
        t.push_str("|\n");
        for e in &etas {
            let _ = write!(t, "| {e} |");
            for a in &albedos {
                let cell = rs
                    .iter()
                    .find(|r| r.eta == *e && r.albedo_prime == *a)
                    .map_or("", |r| {
                        let ok = |v: Option<f64>| v.is_some_and(|v| v.abs() <= 0.05);
                        if ok(r.sigma_s_prime_error) && ok(r.sigma_a_error) {
                            "✓"
                        } else {
                            "✗"
                        }
                    });
                let _ = write!(t, " {cell} |");
            }
            t.push('\n');
        }
        t.push('\n');
    }
    t
}

/// Per configuration (proposed method), |σ′s error| against −log₁₀(1 − α′), one line per η.
fn figure(rows: &[Row], combos: &[Combo]) -> Figure {
    let etas: Vec<f64> = {
        let mut e: Vec<f64> = rows.iter().map(|r| r.eta).collect();
        e.sort_by(f64::total_cmp);
        e.dedup();
        e
    };
    let panels = combos
        .iter()
        .filter(|c| c.method == Method::Proposed && c.albedo == AlbedoModel::default_for(c.model))
        .map(|c| {
            let n = etas.len().max(2) as f64 - 1.0;
            let base = match c.model {
                ModelName::Dipole => (200.0, 30.0, 30.0),
                ModelName::BetterDipole => (200.0, 120.0, 0.0),
                ModelName::Pbd => (20.0, 140.0, 40.0),
                ModelName::Mc => (30.0, 70.0, 200.0),
            };
            let series = etas
                .iter()
                .enumerate()
                .map(|(k, &e)| {
                    // Light (η small) to dark (η large) shades of the model's colour.
                    let t = 0.75 - 0.75 * k as f64 / n;
                    let shade = |v: f64| (v + (255.0 - v) * t).round() as u8;
                    let mut pts: Vec<(f64, f64)> = rows
                        .iter()
                        .filter(|r| {
                            r.eta == e
                                && r.model == c.model.name()
                                && r.albedo_model == c.albedo.name()
                                && r.method == "proposed"
                        })
                        .filter_map(|r| {
                            r.sigma_s_prime_error.map(|v| {
                                (-(1.0 - r.albedo_prime).log10(), (100.0 * v.abs()).max(1e-3))
                            })
                        })
                        .collect();
                    pts.sort_by(|a, b| a.0.total_cmp(&b.0));
                    Series {
                        label: format!("η = {e}"),
                        points: pts,
                        errors: None,
                        style: SeriesStyle::Line,
                        colour: Some((shade(base.0), shade(base.1), shade(base.2))),
                    }
                })
                .collect();
            Panel {
                title: c.label(),
                colour: match c.model {
                    ModelName::Dipole => (200, 30, 30),
                    ModelName::BetterDipole => (200, 120, 0),
                    ModelName::Pbd => (20, 140, 40),
                    ModelName::Mc => (30, 70, 200),
                },
                series,
                note: Some("x: −log₁₀(1 − α′) (1 = 0.9, 2 = 0.99, 3 = 0.999)".into()),
            }
        })
        .collect();
    Figure {
        title: "Bias study: |σ′s error| of the proposed method on Monte Carlo rig-twin samples"
            .into(),
        x_label: "−log₁₀(1 − α′)".into(),
        y_label: "|σ′s error| [%]".into(),
        panels,
        log_y: true,
        log_x: false,
    }
}
