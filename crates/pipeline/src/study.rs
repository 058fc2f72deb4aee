//! The bias study (`scatterfit study`) as a library: rig-twin samples over a grid of reduced
//! albedos α′ and refractive indices η, each measured once and fitted with every forward model and
//! method; the errors of σ′s, σa and α′ against the sample's truth (`scatterfit_synth::Truth`, the
//! sample's `truth.json`) are tabulated per (model, albedo model, method).
//!
//! Every grid point is one channel; three albedos at the same η share a sample. σ′t is the same for
//! all, so σ′s = α′σ′t and σa = (1 − α′)σ′t. Synthesising the samples is the caller's (it owns the
//! progress display); this module names them ([`samples`]), fits them ([`study_sample`]) and
//! tabulates the rows ([`rows_csv`], [`summary_markdown`]).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use scatterfit_optics::{AlbedoModel, Method, ModelName};
use scatterfit_synth::Truth;
use serde::Serialize;

use crate::fit::FitSettings;
use crate::{Measurement, Overrides, PipelineError, measure_sample};

/// One fit configuration of the study.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Combo {
    /// The forward model.
    pub model: ModelName,
    /// The α′ inversion.
    pub albedo: AlbedoModel,
    /// The paper's method.
    pub method: Method,
}

impl Combo {
    /// "model + albedo α′, method", the label of tables and panels.
    pub fn label(self) -> String {
        format!(
            "{} + {} α′, {}",
            self.model.name(),
            self.albedo.name(),
            self.method.name()
        )
    }

    /// True when `row` was fitted this way.
    pub fn matches(self, row: &Row) -> bool {
        row.model == self.model.name()
            && row.albedo_model == self.albedo.name()
            && row.method == self.method.name()
    }
}

/// One grid point fitted one way (serialised as `scatterfit study --json` prints it).
#[derive(Debug, Clone, Serialize)]
pub struct Row {
    /// η of the sample.
    pub eta: f64,
    /// The true α′ of the grid point.
    pub albedo_prime: f64,
    /// The forward model's name.
    pub model: &'static str,
    /// The α′ inversion's name.
    pub albedo_model: &'static str,
    /// The method's name.
    pub method: &'static str,
    /// The channel's fit status, lower case.
    pub status: String,
    /// σ′s found / true − 1.
    pub sigma_s_prime_error: Option<f64>,
    /// σa found / true − 1.
    pub sigma_a_error: Option<f64>,
    /// α′ found − true.
    pub albedo_prime_error: Option<f64>,
}

/// A study sample that failed.
#[derive(Debug, thiserror::Error)]
pub enum StudyError {
    /// The sample's truth.json could not be read.
    #[error("reading truth.json: {0}")]
    ReadTruth(#[source] scatterfit_io::text::TextError),
    /// The sample's truth.json is not a truth record.
    #[error(transparent)]
    ParseTruth(#[from] serde_json::Error),
    /// Measuring or fitting failed.
    #[error(transparent)]
    Pipeline(#[from] PipelineError),
}

/// Every forward model with its own α′ inversion by both methods (photon beam diffusion left out
/// with `no_pbd`), then the two biases apart: the dipole's profile with an exact α′, and the exact
/// profile with the dipole's α′.
pub fn combos(no_pbd: bool) -> Vec<Combo> {
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

/// One sample of the grid: its folder, η and the α′ of its three channels.
#[derive(Debug, Clone, PartialEq)]
pub struct StudySample {
    /// `<out>/samples/eta<η>-a<α′…>`.
    pub dir: PathBuf,
    /// η.
    pub eta: f64,
    /// α′ per channel (a last triple short of three repeats its last albedo).
    pub albedos: [f64; 3],
}

impl StudySample {
    /// The sample's name (its folder's).
    pub fn name(&self) -> String {
        self.dir
            .file_name()
            .map_or_else(|| "sample".into(), |n| n.to_string_lossy().into_owned())
    }

    /// σ′s per channel for reduced extinction `sigma_t_prime` [mm⁻¹].
    pub fn sigma_s_prime(&self, sigma_t_prime: f64) -> [f64; 3] {
        self.albedos.map(|a| a * sigma_t_prime)
    }

    /// σa per channel for reduced extinction `sigma_t_prime` [mm⁻¹].
    pub fn sigma_a(&self, sigma_t_prime: f64) -> [f64; 3] {
        self.albedos.map(|a| (1.0 - a) * sigma_t_prime)
    }
}

/// The samples of the grid under `out`: three albedos per η each.
pub fn samples(out: &Path, etas: &[f64], albedos: &[f64]) -> Vec<StudySample> {
    let mut samples = Vec::new();
    for &eta in etas {
        for chunk in albedos.chunks(3) {
            let a: [f64; 3] = std::array::from_fn(|c| chunk[c.min(chunk.len() - 1)]);
            let name = format!(
                "eta{eta:.2}-a{}",
                chunk
                    .iter()
                    .map(|a| format!("{a}"))
                    .collect::<Vec<_>>()
                    .join("_")
            );
            samples.push(StudySample {
                dir: out.join("samples").join(name),
                eta,
                albedos: a,
            });
        }
    }
    samples
}

/// Measures one synthesised sample and fits it every way in `combos`, against its truth.json.
///
/// # Errors
/// [`StudyError`]: the truth unreadable, or the measurement or a fit failed.
pub fn study_sample(sample: &StudySample, combos: &[Combo]) -> Result<Vec<Row>, StudyError> {
    let text = scatterfit_io::text::read_text_file(&sample.dir.join("truth.json"))
        .map_err(StudyError::ReadTruth)?;
    let truth: Truth = serde_json::from_str(&text.text)?;
    let eta = sample.eta;
    // At η = 1 there is no specular reflection to measure η from (SCI = SCE): the study gives it.
    let overrides = Overrides {
        eta: (eta < 1.02).then_some(eta),
        ..Overrides::default()
    };
    let base: Measurement = measure_sample(&sample.dir, &overrides, &|_| {})?;
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
        for ((ch, t), &albedo) in result
            .channels
            .iter()
            .zip(&truth.channels)
            .zip(&sample.albedos)
        {
            let rel = |v: Option<f64>, truth: f64| v.map(|v| v / truth - 1.0);
            rows.push(Row {
                eta,
                albedo_prime: albedo,
                model: combo.model.name(),
                albedo_model: combo.albedo.name(),
                method: combo.method.name(),
                status: format!("{:?}", ch.status).to_lowercase(),
                sigma_s_prime_error: rel(ch.sigma_s_prime, t.sigma_s_prime),
                sigma_a_error: rel(ch.sigma_a, t.sigma_a),
                albedo_prime_error: ch.albedo_prime.map(|a| a - albedo),
            });
        }
    }
    Ok(rows)
}

/// Writes a synthesised twin (8-bit bracket) into `dir` as a sample folder with `fit` as its
/// manifest's `[fit]` and no truth.json — what a user's rig would hand the tool; the twin's g (issue
/// 15) is never written into the manifest (`fit` decides what the user states).
///
/// # Errors
/// The folder cannot be written.
pub fn write_twin_folder(
    dir: &Path,
    s: &scatterfit_synth::SyntheticSample,
    fit: scatterfit_io::manifest::FitSection,
    provenance: &str,
) -> Result<(), scatterfit_io::sample_folder::SampleFolderError> {
    let rig = &s.truth.rig;
    let files = scatterfit_io::sample_folder::SampleFiles::new(&s.truth.name, &s.reading)
        .bracket(&s.bracket.frames, &s.bracket.times_s)
        .mm_per_pixel(rig.mm_per_pixel)
        .spot_diameter_mm(2.0 * rig.spot_radius_mm)
        .provenance(provenance)
        .fit(fit);
    scatterfit_io::sample_folder::write_sample_folder(dir, &files).map(|_| ())
}

/// Keeps one row per grid point and configuration (a padded triple repeats its last albedo).
pub fn dedup(rows: &mut Vec<Row>) {
    let mut seen = std::collections::HashSet::new();
    rows.retain(|r| {
        seen.insert(format!(
            "{}|{}|{}|{}|{}",
            r.eta, r.albedo_prime, r.model, r.albedo_model, r.method
        ))
    });
}

/// The rows as `study.csv`.
pub fn rows_csv(rows: &[Row]) -> String {
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

/// The distinct values of `f` over `rows`, ascending.
pub fn distinct(rows: &[Row], f: impl Fn(&Row) -> f64) -> Vec<f64> {
    let mut v: Vec<f64> = rows.iter().map(f).collect();
    v.sort_by(f64::total_cmp);
    v.dedup();
    v
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

/// `study.md`: per configuration, median / worst |error| over the grid; per model (proposed
/// method), where σ′s and σa are within 5 %, per η and α′.
pub fn summary_markdown(rows: &[Row], combos: &[Combo]) -> String {
    let mut t = String::from(
        "| model + albedo model, method | points | σ′s median / worst | σa median / worst | α′ error median / worst |\n\
         |---|---|---|---|---|\n",
    );
    let of = |c: &Combo| rows.iter().filter(|r| c.matches(r)).collect::<Vec<_>>();
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
    t.push_str("\nWhere each configuration (proposed method) has σ′s and σa within 5 % (✓), per η and α′:\n\n");
    let etas = distinct(rows, |r| r.eta);
    let albedos = distinct(rows, |r| r.albedo_prime);
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_names_and_pads_triples() {
        let s = samples(Path::new("o"), &[1.4], &[0.3, 0.5, 0.7, 0.9]);
        assert_eq!(s.len(), 2);
        assert_eq!(s[0].dir, Path::new("o/samples/eta1.40-a0.3_0.5_0.7"));
        assert_eq!(s[1].albedos, [0.9, 0.9, 0.9]);
        assert_eq!(s[1].name(), "eta1.40-a0.9");
        // σ′t = 2: σ′s = 1.8, σa = 0.2 (by hand).
        assert!((s[1].sigma_s_prime(2.0)[0] - 1.8).abs() < 1e-12);
        assert!((s[1].sigma_a(2.0)[0] - 0.2).abs() < 1e-12);
    }

    #[test]
    fn combos_cover_every_model_and_both_biases() {
        assert_eq!(combos(false).len(), 10);
        let no_pbd = combos(true);
        assert_eq!(no_pbd.len(), 8);
        assert!(no_pbd.iter().all(|c| c.model != ModelName::Pbd));
        assert_eq!(no_pbd[6].label(), "dipole + mc α′, proposed");
    }
}
