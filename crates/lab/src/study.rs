//! The bias study (`scatterfit study`) as a library: rig-twin samples over a grid of reduced
//! albedos α′ and refractive indices η, each measured once and fitted with every forward model and
//! method; the errors of σ′s, σa and α′ against the sample's truth (`scatterfit_synth::Truth`, the
//! sample's `truth.json`) are tabulated per (model, albedo model, method).
//!
//! Every grid point is one channel; three albedos at the same η share a sample. σ′t is the same for
//! all, so σ′s = α′σ′t and σa = (1 − α′)σ′t. Synthesising the samples is the caller's (it owns the
//! progress display); this module names them ([`samples`]), fits them ([`study_sample`]) and
//! tabulates the rows ([`rows_csv`], [`summary_markdown`]).
//!
//! **The g axis**. Real translucent materials scatter forward (Henyey–Greenstein g ≈
//! 0.7–0.95), and at fixed reduced coefficients both the total diffuse reflectance (hence α′ from
//! the spectrophotometer) and the profile's near field depend on g: the similarity relation
//! σ′s = σs(1 − g) holds only in the far field (Wyman, Patterson & Wilson 1989). A study over a list
//! of g ([`samples`] with `gs`) makes every twin at each g and fits it every way assuming g = 0 —
//! what a manifest without `[fit] g` gets — and once more with the g-aware `mc` model told the
//! twin's g ([`g_given_combo`], `[fit] g` = the truth). Where the `mc` tables do not answer at a
//! (η, g) ([`mc_covers`]: the grid's own coverage, never a list written here) that row says
//! "not covered" and is never extrapolated. [`g_axis_markdown`] tabulates each model over g.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use scatterfit_io::result_json::ChannelStatus;
use scatterfit_optics::{AlbedoModel, Method, ModelName};
use scatterfit_synth::Truth;
use serde::{Deserialize, Serialize};

use scatterfit_pipeline::FitSettings;
use scatterfit_pipeline::anisotropy::GPrior;
use scatterfit_pipeline::{Measurement, Overrides, PipelineError, measure_sample};

/// How a row's fit ended: the channel's status, or not run where the `mc` tables do not cover the
/// twin's (η, g) ([`mc_covers`]). In files the strings `ok`, `unconstrained`, `failed`, `not covered`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RowStatus {
    /// Parameters found and constrained.
    Ok,
    /// The fit ran, but the data do not constrain every parameter.
    Unconstrained,
    /// No parameters.
    Failed,
    /// Not fitted: the `mc` tables do not answer at the twin's (η, g).
    #[serde(rename = "not covered")]
    NotCovered,
}

impl RowStatus {
    /// The name in files.
    pub fn name(self) -> &'static str {
        match self {
            Self::Ok => "ok",
            Self::Unconstrained => "unconstrained",
            Self::Failed => "failed",
            Self::NotCovered => "not covered",
        }
    }
}

impl From<ChannelStatus> for RowStatus {
    fn from(s: ChannelStatus) -> Self {
        match s {
            ChannelStatus::Ok => Self::Ok,
            ChannelStatus::Unconstrained => Self::Unconstrained,
            _ => Self::Failed,
        }
    }
}

impl std::fmt::Display for RowStatus {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// One fit configuration of the study.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Combo {
    /// The forward model.
    pub model: ModelName,
    /// The α′ inversion.
    pub albedo: AlbedoModel,
    /// The paper's method.
    pub method: Method,
    /// The fit is told the twin's g (`[fit] g` = the truth's); otherwise it assumes
    /// g = 0, as a manifest without `[fit] g` does.
    pub g_given: bool,
}

impl Combo {
    /// "model + albedo α′, method" (", g given" when it is), the label of tables and panels.
    pub fn label(self) -> String {
        format!(
            "{} + {} α′, {}{}",
            self.model.name(),
            self.albedo.name(),
            self.method.name(),
            if self.g_given { ", g given" } else { "" }
        )
    }

    /// True when `row` was fitted this way.
    pub fn matches(self, row: &Row) -> bool {
        row.model == self.model
            && row.albedo_model == self.albedo
            && row.method == self.method
            && row.g_given.unwrap_or(false) == self.g_given
    }
}

/// One grid point fitted one way (serialised as `scatterfit study --json` prints it, and as a
/// shard's partial file holds it).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Row {
    /// η of the sample.
    pub eta: f64,
    /// The true α′ of the grid point.
    pub albedo_prime: f64,
    /// The forward model.
    pub model: ModelName,
    /// The α′ inversion.
    pub albedo_model: AlbedoModel,
    /// The method.
    pub method: Method,
    /// The twin's Henyey–Greenstein g; absent in a study without a g axis.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub g: Option<f64>,
    /// Whether the fit was told the twin's g (else it assumed g = 0); absent in a study without a
    /// g axis.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub g_given: Option<bool>,
    /// How the channel's fit ended; [`RowStatus::NotCovered`] where the `mc` tables do not answer
    /// at the sample's (η, g) (no fit, no errors).
    pub status: RowStatus,
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
                g_given: false,
            });
        }
    }
    v.push(Combo {
        model: ModelName::Dipole,
        albedo: AlbedoModel::Mc,
        method: Method::Proposed,
        g_given: false,
    });
    v.push(Combo {
        model: ModelName::Mc,
        albedo: AlbedoModel::Diffusion,
        method: Method::Proposed,
        g_given: false,
    });
    v
}

/// The g-aware exact configuration of a study with a g axis: the `mc` profile with the `mc` α′
/// (both at the twin's g), the proposed method, told the twin's g.
pub fn g_given_combo() -> Combo {
    Combo {
        model: ModelName::Mc,
        albedo: AlbedoModel::Mc,
        method: Method::Proposed,
        g_given: true,
    }
}

/// True when the bundled `mc` tables answer at (η, g) without extrapolating: the grid covers g
/// (a node, or between two nodes it interpolates across) and each node it uses holds η. Asked of
/// the grid itself ([`scatterfit_mc::McGridSet`]), so tables shipped later widen it.
///
/// # Errors
/// [`PipelineError`] when the bundled tables do not parse (a build defect).
pub fn mc_covers(eta: f64, g: f64) -> Result<bool, PipelineError> {
    let grid = scatterfit_mc::bundled_grid()?;
    if !grid.covers(g) {
        return Ok(false);
    }
    // Any α′ inside the tables: what can fail then is η.
    let Ok((lo, hi)) = grid.albedo_prime_range(g) else {
        return Ok(false);
    };
    Ok(grid.rd_total(0.5 * (lo + hi), eta, g).is_ok())
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
    /// The twin's Henyey–Greenstein g in a study with a g axis; `None` without one (the twin is
    /// isotropic and the rows carry no g).
    pub g: Option<f64>,
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

    /// The twin's g (0 without a g axis).
    pub fn twin_g(&self) -> f64 {
        self.g.unwrap_or(0.0)
    }
}

/// True when `gs` asks for a g axis: any g but the isotropic study's single 0.
pub fn has_g_axis(gs: &[f64]) -> bool {
    gs.iter().any(|&g| g != 0.0)
}

/// The samples of the grid under `out`: three albedos per η each, for every g of `gs` (in order;
/// [`has_g_axis`] decides whether the samples carry their g). A twin at g ≠ 0 is named with a
/// `-g<g>` suffix; at g = 0 its name is the isotropic study's.
pub fn samples(out: &Path, etas: &[f64], albedos: &[f64], gs: &[f64]) -> Vec<StudySample> {
    let axis = has_g_axis(gs);
    let mut samples = Vec::new();
    for &g in if axis { gs } else { &[0.0][..] } {
        for &eta in etas {
            for chunk in albedos.chunks(3) {
                let a: [f64; 3] = std::array::from_fn(|c| chunk[c.min(chunk.len() - 1)]);
                let mut name = format!(
                    "eta{eta:.2}-a{}",
                    chunk
                        .iter()
                        .map(|a| format!("{a}"))
                        .collect::<Vec<_>>()
                        .join("_")
                );
                if g != 0.0 {
                    name.push_str(&format!("-g{g}"));
                }
                samples.push(StudySample {
                    dir: out.join("samples").join(name),
                    eta,
                    albedos: a,
                    g: axis.then_some(g),
                });
            }
        }
    }
    samples
}

/// Measures one synthesised sample and fits it every way in `combos`, against its truth.json.
/// A configuration with [`Combo::g_given`] is fitted at the truth's g, or not at all where the
/// `mc` tables do not cover the sample's (η, g) ([`mc_covers`]; rows with status
/// [`RowStatus::NotCovered`]).
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
        let mut settings = FitSettings {
            method: combo.method,
            model: combo.model,
            albedo_model: combo.albedo,
            normalise_with_spectro: false,
            ..base.settings
        };
        if combo.g_given {
            if !mc_covers(eta, truth.g)? {
                rows.extend(sample.albedos.iter().map(|&albedo| Row {
                    eta,
                    albedo_prime: albedo,
                    model: combo.model,
                    albedo_model: combo.albedo,
                    method: combo.method,
                    g: sample.g,
                    g_given: sample.g.map(|_| true),
                    status: RowStatus::NotCovered,
                    sigma_s_prime_error: None,
                    sigma_a_error: None,
                    albedo_prime_error: None,
                }));
                continue;
            }
            // `[fit] g` = the truth's: known, so no g term.
            settings.g = truth.g;
            settings.g_prior = GPrior {
                g: Some(truth.g),
                range: None,
                fit: false,
            };
        }
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
                model: combo.model,
                albedo_model: combo.albedo,
                method: combo.method,
                g: sample.g,
                g_given: sample.g.map(|_| combo.g_given),
                status: ch.status.into(),
                sigma_s_prime_error: rel(ch.sigma_s_prime.map(|e| e.value), t.sigma_s_prime),
                sigma_a_error: rel(ch.sigma_a.map(|e| e.value), t.sigma_a),
                albedo_prime_error: ch.albedo_prime.map(|a| a.value - albedo),
            });
        }
    }
    Ok(rows)
}

/// Keeps one row per grid point and configuration (a padded triple repeats its last albedo).
pub fn dedup(rows: &mut Vec<Row>) {
    let mut seen = std::collections::HashSet::new();
    rows.retain(|r| {
        seen.insert(format!(
            "{}|{}|{}|{}|{}|{:?}|{:?}",
            r.eta, r.albedo_prime, r.model, r.albedo_model, r.method, r.g, r.g_given
        ))
    });
}

/// The rows as `study.csv`; a study with a g axis adds the columns `g` (the twin's) and `g_given`
/// (true when the fit was told it, false when it assumed g = 0).
pub fn rows_csv(rows: &[Row]) -> String {
    let axis = rows.iter().any(|r| r.g.is_some());
    let mut t = String::from(
        "eta,albedo_prime,model,albedo_model,method,status,sigma_s_prime_error,sigma_a_error,albedo_prime_error",
    );
    t.push_str(if axis { ",g,g_given\n" } else { "\n" });
    let f = |v: Option<f64>| v.map_or(String::new(), |v| format!("{v:.6}"));
    for r in rows {
        let _ = write!(
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
        if axis {
            let _ = write!(
                t,
                ",{},{}",
                r.g.map_or(String::new(), |g| g.to_string()),
                r.g_given.map_or(String::new(), |g| g.to_string())
            );
        }
        t.push('\n');
    }
    t
}

/// True when the row's fit was not run because the `mc` tables do not cover its (η, g).
fn not_covered(r: &Row) -> bool {
    r.status == RowStatus::NotCovered
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

/// The cells "points | σ′s median / worst | σa median / worst | α′ error median / worst" of
/// `rows`: statistics over the fitted rows (a failed fit is an infinite error); rows the `mc`
/// tables do not cover are counted apart ("6 (3 not covered)", every cell "not covered" when
/// none is).
fn error_cells(rows: &[&Row]) -> String {
    let fitted: Vec<&Row> = rows.iter().copied().filter(|r| !not_covered(r)).collect();
    let skipped = rows.len() - fitted.len();
    if fitted.is_empty() && skipped > 0 {
        return format!("0 ({skipped} not covered) | not covered | not covered | not covered");
    }
    let points = if skipped > 0 {
        format!("{} ({skipped} not covered)", fitted.len())
    } else {
        fitted.len().to_string()
    };
    let a = stats(fitted.iter().map(|r| r.albedo_prime_error));
    format!(
        "{points} | {} | {} | {}",
        pct(stats(fitted.iter().map(|r| r.sigma_s_prime_error))),
        pct(stats(fitted.iter().map(|r| r.sigma_a_error))),
        a.map_or("—".into(), |(m, w, _)| format!("{m:.2e} / {w:.1e}")),
    )
}

/// `study.md`: per configuration, median / worst |error| over the grid; per model (proposed
/// method), where σ′s and σa are within 5 % (n/c: not covered by the `mc` tables), per η and α′.
pub fn summary_markdown(rows: &[Row], combos: &[Combo]) -> String {
    let mut t = String::from(
        "| model + albedo model, method | points | σ′s median / worst | σa median / worst | α′ error median / worst |\n\
         |---|---|---|---|---|\n",
    );
    let of = |c: &Combo| rows.iter().filter(|r| c.matches(r)).collect::<Vec<_>>();
    for c in combos {
        let rs = of(c);
        let _ = writeln!(t, "| {} | {} |", c.label(), error_cells(&rs));
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
                        if not_covered(r) {
                            "n/c"
                        } else if ok(r.sigma_s_prime_error) && ok(r.sigma_a_error) {
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

/// The g axis of `study.md`: per model, each of its configurations over the twins' g —
/// median / worst |error| of σ′s, σa and α′ — the configurations assuming g = 0 first, then the
/// g-aware `mc` model told the twin's g ("not covered" where the `mc` tables do not answer).
/// `combos` in the order given; `gs` the study's g list.
pub fn g_axis_markdown(rows: &[Row], combos: &[Combo], gs: &[f64]) -> String {
    let mut t = String::from(
        "Each twin is made at the Henyey–Greenstein g of its row; every configuration is fitted \
         assuming g = 0 (what a manifest without `[fit] g` gets) unless it says \"g given\" (the \
         g-aware `mc` model with `[fit] g` = the twin's g). Cells: |error| median / worst over the \
         grid points; \"not covered\": the `mc` tables do not answer at that (η, g), and nothing is \
         extrapolated.\n\n",
    );
    for model in [
        ModelName::Dipole,
        ModelName::BetterDipole,
        ModelName::Pbd,
        ModelName::Mc,
    ] {
        let of_model: Vec<&Combo> = combos.iter().filter(|c| c.model == model).collect();
        if of_model.is_empty() {
            continue;
        }
        let _ = writeln!(t, "**{}**\n", model.name());
        t.push_str(
            "| configuration | twin g | points | σ′s median / worst | σa median / worst | α′ error median / worst |\n\
             |---|---|---|---|---|---|\n",
        );
        for c in of_model {
            for &g in gs {
                let rs: Vec<&Row> = rows
                    .iter()
                    .filter(|r| c.matches(r) && r.g.unwrap_or(0.0) == g)
                    .collect();
                if rs.is_empty() {
                    continue;
                }
                let _ = writeln!(t, "| {} | {g} | {} |", c.label(), error_cells(&rs));
            }
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
        let s = samples(Path::new("o"), &[1.4], &[0.3, 0.5, 0.7, 0.9], &[0.0]);
        assert_eq!(s.len(), 2);
        assert_eq!(s[0].dir, Path::new("o/samples/eta1.40-a0.3_0.5_0.7"));
        assert_eq!(s[1].albedos, [0.9, 0.9, 0.9]);
        assert_eq!(s[1].g, None);
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
        assert!(combos(false).iter().all(|c| !c.g_given));
        assert_eq!(g_given_combo().label(), "mc + mc α′, proposed, g given");
    }

    #[test]
    fn a_g_axis_names_its_twins_and_keeps_the_isotropic_names() {
        assert!(!has_g_axis(&[0.0]));
        assert!(has_g_axis(&[0.0, 0.8]));
        let s = samples(Path::new("o"), &[1.4], &[0.9], &[0.0, 0.8]);
        assert_eq!(s.len(), 2);
        assert_eq!(s[0].dir, Path::new("o/samples/eta1.40-a0.9"));
        assert_eq!(s[0].g, Some(0.0));
        assert_eq!(s[1].dir, Path::new("o/samples/eta1.40-a0.9-g0.8"));
        assert_eq!(s[1].twin_g(), 0.8);
    }

    /// The coverage comes from the grid itself: every node answers inside its own η range and
    /// not beyond it; a g the grid does not cover is refused at every η.
    #[test]
    fn coverage_is_the_grids_own() {
        let grid = scatterfit_mc::bundled_grid().unwrap();
        for set in grid.nodes() {
            let (lo, hi) = set.eta_range();
            assert!(mc_covers(lo, set.g()).unwrap(), "g {} η {lo}", set.g());
            assert!(mc_covers(0.5 * (lo + hi), set.g()).unwrap());
            assert!(
                !mc_covers(hi + 0.05, set.g()).unwrap(),
                "g {} η {}",
                set.g(),
                hi + 0.05
            );
        }
        let uncovered = (0..99)
            .map(|k| f64::from(k) / 100.0)
            .find(|&g| !grid.covers(g));
        if let Some(g) = uncovered {
            assert!(!mc_covers(1.4, g).unwrap(), "g {g}");
        }
    }

    fn row(g: f64, g_given: bool, status: RowStatus, err: Option<f64>) -> Row {
        Row {
            eta: 1.4,
            albedo_prime: 0.9,
            model: ModelName::Mc,
            albedo_model: AlbedoModel::Mc,
            method: Method::Proposed,
            g: Some(g),
            g_given: Some(g_given),
            status,
            sigma_s_prime_error: err,
            sigma_a_error: err,
            albedo_prime_error: err,
        }
    }

    #[test]
    fn the_g_tables_say_not_covered_and_never_count_it_as_a_failure() {
        let rows = vec![
            row(0.5, false, RowStatus::Ok, Some(0.06)),
            row(0.5, true, RowStatus::NotCovered, None),
            row(0.8, false, RowStatus::Ok, Some(0.08)),
            row(0.8, true, RowStatus::Ok, Some(-0.004)),
        ];
        let combos = [
            Combo {
                model: ModelName::Mc,
                albedo: AlbedoModel::Mc,
                method: Method::Proposed,
                g_given: false,
            },
            g_given_combo(),
        ];
        let t = g_axis_markdown(&rows, &combos, &[0.5, 0.8]);
        assert!(t.contains(
            "| mc + mc α′, proposed, g given | 0.5 | 0 (1 not covered) | not covered | not covered | not covered |"
        ));
        assert!(
            t.contains("| mc + mc α′, proposed | 0.8 | 1 | 8.00 % / 8.0 % |"),
            "{t}"
        );
        assert!(t.contains("| mc + mc α′, proposed, g given | 0.8 | 1 | 0.40 % / 0.4 % |"));
        assert!(!t.contains("dipole"));
        let csv = rows_csv(&rows);
        assert!(csv.starts_with("eta,") && csv.lines().next().unwrap().ends_with(",g,g_given"));
        assert!(csv.contains(",not covered,,,,0.5,true\n"), "{csv}");
    }
}
