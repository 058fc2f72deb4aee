//! The bias study as a run (`scatterfit study`, and `scatterfit combine` of its shards): the
//! study's settings ([`StudyConfig`], also the partial files' run fingerprint), its twins, the
//! fits of every sample with every configuration ([`fit_samples`]), a shard's part
//! ([`StudyPart`]) and the parts put back in the one-machine order ([`combine_parts`]), and the
//! files made of the rows ([`write_study`]: study.csv, study.md, study.svg, study.png). Nothing
//! here prints: the caller shows progress and the summary.

use std::path::{Path, PathBuf};

use rayon::prelude::*;
use scatterfit_io::escape::number as show;
use scatterfit_pipeline::batch::{BatchRequest, JobPlan};
use scatterfit_synth::RigSpec;
use serde::{Deserialize, Serialize};

use crate::study::{
    Combo, Row, StudyError, StudySample, combos, dedup, g_axis_markdown, g_given_combo, has_g_axis,
    rows_csv, samples, study_sample, summary_markdown,
};
use crate::twin_settings::{Material, TwinSettingsError};

/// Why a study cannot run or its files cannot be made.
#[derive(Debug, thiserror::Error)]
pub enum StudyRunError {
    /// A setting out of range, or a partial file that is not this study's: what to change.
    #[error("{0}")]
    Refused(String),
    /// A file or folder cannot be written.
    #[error("{what} {}", path.display())]
    Write {
        /// What was being done (`creating`, `writing`).
        what: &'static str,
        /// The file or folder.
        path: PathBuf,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// The figure cannot be written.
    #[error(transparent)]
    Figure(#[from] scatterfit_report::ReportError),
    /// A twin's rig.
    #[error(transparent)]
    Twin(#[from] TwinSettingsError),
    /// The worker threads cannot start.
    #[error(transparent)]
    Threads(#[from] rayon::ThreadPoolBuildError),
}

/// What a study computes from (every shard's the same; the partial files' run fingerprint), and
/// `scatterfit study`'s flags (their help is the field's text).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[cfg_attr(feature = "clap", derive(clap::Args))]
pub struct StudyConfig {
    /// Refractive indices η, each in [1, 2.5] (the Monte Carlo tables' range).
    #[cfg_attr(feature = "clap", arg(long, value_delimiter = ',', default_values_t = [1.0, 1.2, 1.4, 1.6, 2.0, 2.4]))]
    pub etas: Vec<f64>,
    /// Reduced albedos α′, each in [0.3, 0.9999].
    #[cfg_attr(feature = "clap", arg(long, value_delimiter = ',', default_values_t = [0.3, 0.5, 0.7, 0.9, 0.95, 0.98, 0.99, 0.999, 0.9999]))]
    pub albedos: Vec<f64>,
    /// Reduced extinction σ′t of every grid point [mm⁻¹, 0.2–20].
    #[cfg_attr(
        feature = "clap",
        arg(long, default_value_t = 2.0, value_name = "MM-1")
    )]
    pub sigma_t_prime: f64,
    /// Small fast samples (256 × 256 px at 0.1 mm/px, a tenth of the photons).
    #[cfg_attr(feature = "clap", arg(long))]
    pub quick: bool,
    /// Henyey–Greenstein g of the twins, each in [0, 0.95] (default 0: the isotropic study). Any
    /// g ≠ 0 gives the study a g axis: every twin is made at each g, fitted every way assuming
    /// g = 0 (what a manifest without `[fit] g` gets) and once more with the g-aware `mc` model
    /// told the true g ("g given"; "not covered" where the `mc` tables do not answer at that η
    /// and g); study.md gains a table per model over g. A twin at g costs about 1/(1 − g) times
    /// the Monte Carlo time of one at g = 0 (g = 0.95: 20×).
    #[cfg_attr(feature = "clap", arg(long = "g", value_name = "G", value_delimiter = ',', default_values_t = [0.0]))]
    pub g: Vec<f64>,
    /// Seed of the rig twin.
    #[cfg_attr(feature = "clap", arg(long, default_value_t = 1))]
    pub seed: u64,
    /// The twins' Monte Carlo photons × this factor
    /// ([`crate::twin_settings::PHOTON_SCALE_HELP`]).
    #[cfg_attr(feature = "clap", arg(long, value_name = "FACTOR", default_value_t = 1.0, allow_negative_numbers = true, value_parser = crate::twin_settings::parse_photon_scale, help = crate::twin_settings::PHOTON_SCALE_HELP))]
    pub photon_scale: f64,
    /// Photon beam diffusion left out (on the command line `--no-pbd`, after `-j`: set after
    /// parsing).
    #[cfg_attr(feature = "clap", arg(skip))]
    pub no_pbd: bool,
}

/// A shard's part of a study: its rows (in the order of its samples) and failures.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct StudyPart {
    /// The rows of the shard's samples.
    pub rows: Vec<Row>,
    /// The samples that failed, with why.
    pub failed: Vec<String>,
    /// Seconds synthesising.
    pub synth_s: f64,
    /// Seconds fitting.
    pub fit_s: f64,
}

impl StudyConfig {
    /// Checks the grid: at least one η, α′ and g; η in [1, 2.5] (the Monte Carlo tables' range),
    /// α′ in [0.3, 0.9999], each g in [0, `G_RANGE_MAX`] and given once, σ′t in [0.2, 20] mm⁻¹.
    ///
    /// # Errors
    /// The first value out of range, named by its flag.
    pub fn check(&self) -> Result<(), StudyRunError> {
        let refuse = |text: String| Err(StudyRunError::Refused(text));
        if self.etas.is_empty() || self.albedos.is_empty() || self.g.is_empty() {
            return refuse("give at least one η, one α′ and one g".into());
        }
        if let Some(e) = self.etas.iter().find(|e| !(1.0..=2.5).contains(*e)) {
            return refuse(format!(
                "--etas: {} is outside [1, 2.5], the range of the Monte Carlo tables",
                show(*e)
            ));
        }
        if let Some(a) = self.albedos.iter().find(|a| !(0.3..=0.9999).contains(*a)) {
            return refuse(format!("--albedos: {} is outside [0.3, 0.9999]", show(*a)));
        }
        let g_max = scatterfit_io::manifest::G_RANGE_MAX;
        if let Some(g) = self.g.iter().find(|g| !(0.0..=g_max).contains(*g)) {
            return refuse(format!(
                "--g: {} is outside [0, {g_max}] (the range a g may be stated in)",
                show(*g)
            ));
        }
        if let Some(k) = (1..self.g.len()).find(|&k| self.g[..k].contains(&self.g[k])) {
            return refuse(format!(
                "--g: {} is given twice; give each g once",
                show(self.g[k])
            ));
        }
        if !(0.2..=20.0).contains(&self.sigma_t_prime) {
            return refuse(format!(
                "--sigma-t-prime {}: must lie in [0.2, 20] mm⁻¹",
                show(self.sigma_t_prime)
            ));
        }
        Ok(())
    }

    /// Whether the twins are made at a g ≠ 0 (a g axis).
    pub fn g_axis(&self) -> bool {
        has_g_axis(&self.g)
    }

    /// The configurations fitted assuming g = 0.
    pub fn assuming_g_0(&self) -> Vec<Combo> {
        combos(self.no_pbd)
    }

    /// Every configuration the study fits: those assuming g = 0, and with a g axis the g-aware
    /// one ([`g_given_combo`]).
    pub fn combos(&self) -> Vec<Combo> {
        let mut c = self.assuming_g_0();
        if self.g_axis() {
            c.push(g_given_combo());
        }
        c
    }

    /// The grid's samples in `out` (three albedos per η each, the last triple padded).
    pub fn samples(&self, out: &Path) -> Vec<StudySample> {
        samples(out, &self.etas, &self.albedos, &self.g)
    }

    /// The twin of `sample`: its material (σ′t split by the albedos) and its rig (the quick or
    /// the paper's, at the sample's g, the photons scaled).
    ///
    /// # Errors
    /// A photon scale the twin refuses.
    pub fn twin(&self, sample: &StudySample) -> Result<(Material, RigSpec), StudyRunError> {
        let material = Material {
            name: sample.name(),
            sigma_s_prime: sample.sigma_s_prime(self.sigma_t_prime),
            sigma_a: sample.sigma_a(self.sigma_t_prime),
            eta: sample.eta,
        };
        let mut rig = if self.quick {
            RigSpec::quick()
        } else {
            RigSpec::paper()
        };
        rig.g = sample.twin_g();
        let rig = rig
            .with_photon_scale(self.photon_scale)
            .map_err(TwinSettingsError::from)?;
        Ok((material, rig))
    }
}

/// How many of `samples` are fitted at once for `jobs` asked (0: one per core), within the
/// memory budget (as `batch` plans).
pub fn fit_plan(samples: &[StudySample], jobs: usize) -> JobPlan {
    BatchRequest::new(
        samples.iter().map(|s| s.dir.clone()),
        scatterfit_pipeline::Overrides::default(),
    )
    .jobs(jobs)
    .plan()
}

/// Fits every sample with every configuration of `combos`, `jobs` samples at a time; `done` is
/// called as each sample is finished. One result per sample, in order: a failed sample never stops
/// the others.
///
/// # Errors
/// The worker threads cannot start.
pub fn fit_samples(
    samples: &[StudySample],
    combos: &[Combo],
    jobs: usize,
    done: &(dyn Fn() + Sync),
) -> Result<Vec<Result<Vec<Row>, StudyError>>, StudyRunError> {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(jobs).build()?;
    Ok(pool.install(|| {
        samples
            .par_iter()
            .map(|sample| {
                let r = study_sample(sample, combos);
                done();
                r
            })
            .collect()
    }))
}

/// The shards' parts of one study as the one-machine study's: every row checked to be of a
/// configuration this study fits (`path` names the part's file), then put in the one-machine
/// order — samples by the twin's g, η and albedo triple as the grid lists them, each sample's
/// rows by configuration; failures and times added up.
///
/// # Errors
/// A row of a configuration the study does not fit.
pub fn combine_parts(
    config: &StudyConfig,
    parts: impl IntoIterator<Item = (PathBuf, StudyPart)>,
) -> Result<StudyPart, StudyRunError> {
    let all = config.combos();
    let mut sum = StudyPart {
        rows: Vec::new(),
        failed: Vec::new(),
        synth_s: 0.0,
        fit_s: 0.0,
    };
    for (path, part) in parts {
        for r in part.rows {
            if !all.iter().any(|c| c.matches(&r)) {
                return Err(StudyRunError::Refused(format!(
                    "{}: a row fitted with {} + {} α′, {}, which this study does not fit",
                    path.display(),
                    r.model,
                    r.albedo_model,
                    r.method
                )));
            }
            sum.rows.push(r);
        }
        sum.failed.extend(part.failed);
        sum.synth_s += part.synth_s;
        sum.fit_s += part.fit_s;
    }
    let pos = |v: &[f64], x: f64| v.iter().position(|&y| y == x).unwrap_or(usize::MAX);
    let combo_pos = |r: &Row| all.iter().position(|c| c.matches(r)).unwrap_or(usize::MAX);
    sum.rows.sort_by_key(|r| {
        (
            r.g.map_or(0, |g| pos(&config.g, g)),
            pos(&config.etas, r.eta),
            pos(&config.albedos, r.albedo_prime) / 3,
            combo_pos(r),
            pos(&config.albedos, r.albedo_prime),
        )
    });
    Ok(sum)
}

/// What [`write_study`] made.
#[derive(Debug, Clone)]
pub struct StudyFiles {
    /// The rows, one per grid point and configuration.
    pub rows: Vec<Row>,
    /// The summary's Markdown (study.md without its first paragraph on the twins).
    pub summary: String,
}

/// Writes study.csv, study.md, study.svg and study.png for `rows` into `out` (created); a padded
/// triple's repeated albedo keeps one row per grid point and configuration.
///
/// # Errors
/// The files cannot be written.
pub fn write_study(
    out: &Path,
    config: &StudyConfig,
    mut rows: Vec<Row>,
) -> Result<StudyFiles, StudyRunError> {
    let g_axis = config.g_axis();
    let assuming_g_0 = config.assuming_g_0();
    let combos = config.combos();
    std::fs::create_dir_all(out).map_err(|source| StudyRunError::Write {
        what: "creating",
        path: out.to_path_buf(),
        source,
    })?;
    dedup(&mut rows);
    let twins = format!(
        "Twins: the {} rig, seed {}, {}× the default Monte Carlo photons (a twin's own noise goes as \
         1/√ of that; at α′ ≥ 0.999 it reaches σ′s and σa at 1–2.5 % with the default, \
         `--photon-scale` raises it).\n\n",
        if config.quick { "quick" } else { "paper's" },
        config.seed,
        config.photon_scale
    );
    let summary = if g_axis {
        let mut t = format!(
            "## The g axis (twins at g = {})\n\n{}",
            config
                .g
                .iter()
                .map(|g| g.to_string())
                .collect::<Vec<_>>()
                .join(", "),
            g_axis_markdown(&rows, &combos, &config.g)
        );
        for &g in &config.g {
            let at: Vec<Row> = rows.iter().filter(|r| r.g == Some(g)).cloned().collect();
            t.push_str(&format!(
                "## Twins at g = {g}: every configuration\n\n{}",
                summary_markdown(&at, &combos)
            ));
        }
        t
    } else {
        summary_markdown(&rows, &combos)
    };
    // The figure: the first g's twins fitted assuming g = 0 (the isotropic study's figure without
    // a g axis).
    let first_g: Vec<Row> = rows
        .iter()
        .filter(|r| r.g.is_none_or(|g| g == config.g[0]) && r.g_given != Some(true))
        .cloned()
        .collect();
    for (name, text) in [
        ("study.csv", rows_csv(&rows)),
        ("study.md", format!("{twins}{summary}")),
    ] {
        let path = out.join(name);
        scatterfit_io::atomic::write_atomic(&path, text.as_bytes()).map_err(|source| {
            StudyRunError::Write {
                what: "writing",
                path,
                source,
            }
        })?;
    }
    let mut figure = crate::study_figure::study_figure(&first_g, &assuming_g_0);
    if g_axis {
        // Say which twins the figure shows: study.md has the g axis's tables.
        figure.title = format!(
            "{} at g = {}, fitted assuming g = 0 (the g axis: study.md)",
            figure.title, config.g[0]
        );
    }
    scatterfit_report::write_figure(
        &figure,
        Some(&out.join("study.svg")),
        Some(&out.join("study.png")),
    )?;
    Ok(StudyFiles { rows, summary })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn config() -> StudyConfig {
        StudyConfig {
            etas: vec![1.0, 1.4],
            albedos: vec![0.5, 0.9, 0.99],
            sigma_t_prime: 2.0,
            quick: true,
            g: vec![0.0],
            seed: 1,
            photon_scale: 1.0,
            no_pbd: true,
        }
    }

    #[test]
    fn a_grid_out_of_range_is_refused_naming_the_flag() {
        assert!(config().check().is_ok());
        let e = |c: StudyConfig| c.check().unwrap_err().to_string();
        assert_eq!(
            e(StudyConfig {
                etas: vec![1.3, 3.0],
                ..config()
            }),
            "--etas: 3 is outside [1, 2.5], the range of the Monte Carlo tables"
        );
        assert_eq!(
            e(StudyConfig {
                g: vec![0.5, 0.7, 0.5],
                ..config()
            }),
            "--g: 0.5 is given twice; give each g once"
        );
        assert_eq!(
            e(StudyConfig {
                sigma_t_prime: 0.1,
                ..config()
            }),
            "--sigma-t-prime 0.1: must lie in [0.2, 20] mm⁻¹"
        );
        assert!(
            e(StudyConfig {
                albedos: vec![],
                ..config()
            })
            .starts_with("give at least one")
        );
    }

    #[test]
    fn a_twin_is_the_samples_material_on_the_studys_rig() {
        let c = StudyConfig {
            g: vec![0.0, 0.5],
            photon_scale: 2.0,
            ..config()
        };
        let samples = c.samples(Path::new("out"));
        let at_half = samples.iter().find(|s| s.g == Some(0.5)).unwrap();
        let (m, rig) = c.twin(at_half).unwrap();
        assert_eq!(m.sigma_s_prime, at_half.albedos.map(|a| 2.0 * a));
        assert_eq!(m.eta, at_half.eta);
        assert_eq!(rig.g, 0.5);
        assert_eq!(rig.width, RigSpec::quick().width);
        assert_eq!(c.combos().len(), c.assuming_g_0().len() + 1);
        assert_eq!(config().combos().len(), config().assuming_g_0().len());
    }

    #[test]
    fn parts_are_put_back_in_the_grids_order_and_a_foreign_row_is_refused() {
        let c = config();
        let combos = c.combos();
        let row = |eta: f64, albedo_prime: f64, combo: &Combo| {
            let mut r: Row = serde_json::from_value(serde_json::json!({
                "eta": eta,
                "albedo_prime": albedo_prime,
                "model": combo.model,
                "albedo_model": combo.albedo,
                "method": combo.method,
                "status": "ok",
            }))
            .expect("a row from its required fields");
            r.g_given = None;
            r
        };
        let part = |rows: Vec<Row>| StudyPart {
            rows,
            failed: vec!["x: failed".into()],
            synth_s: 1.0,
            fit_s: 2.0,
        };
        // Shard 2 holds η 1.4, shard 1 η 1.0, each with its configurations in reverse.
        let parts = vec![
            (
                PathBuf::from("2"),
                part(vec![row(1.4, 0.5, &combos[1]), row(1.4, 0.5, &combos[0])]),
            ),
            (
                PathBuf::from("1"),
                part(vec![row(1.0, 0.9, &combos[1]), row(1.0, 0.9, &combos[0])]),
            ),
        ];
        let sum = combine_parts(&c, parts).unwrap();
        let order: Vec<(f64, bool)> = sum
            .rows
            .iter()
            .map(|r| (r.eta, combos[0].matches(r)))
            .collect();
        assert_eq!(
            order,
            [(1.0, true), (1.0, false), (1.4, true), (1.4, false)]
        );
        assert_eq!(sum.failed.len(), 2);
        assert_eq!((sum.synth_s, sum.fit_s), (2.0, 4.0));
        // A row of photon beam diffusion, which a study without it does not fit.
        let pbd = Combo {
            model: scatterfit_optics::ModelName::Pbd,
            ..combos[0]
        };
        let e = combine_parts(
            &c,
            [(PathBuf::from("p.json"), part(vec![row(1.0, 0.5, &pbd)]))],
        )
        .unwrap_err()
        .to_string();
        assert!(e.starts_with("p.json: a row fitted with pbd"), "{e}");
    }
}
