//! Stage 1: the spectrophotometer — η from SCI − SCE and, per linear-sRGB channel, the diffuse
//! reflectance Rd and the reduced albedo α′ (Choi, Lee & Chin 2014, §3.2; the physics is in
//! `scatterfit_optics::spectro`).

use std::path::{Path, PathBuf};

use scatterfit_io::manifest::SampleManifest;
pub use scatterfit_io::result_json::EtaSource;
use scatterfit_optics::colour::{Lab, Observer};
use scatterfit_optics::spectro::{SpectroAnalysis, SpectroOptions, analyse};
use scatterfit_optics::{Channel, Estimate, ModelFamily, Rgb};
use serde::Serialize;

use crate::error::{PipelineError, Result};

/// What the spectrophotometer stage gives the fit.
#[derive(Debug, Clone, Serialize)]
pub struct SpectroStage {
    /// The reading's file, when there is one.
    pub file: Option<PathBuf>,
    /// SHA-256 of the reading file's bytes as [`spectro_stage`] read and parsed them (lower-case
    /// hex); `None` without a file, or for a reading analysed in memory ([`from_analysis`]).
    #[serde(skip)]
    pub file_sha256: Option<String>,
    /// The full analysis of the reading (η per wavelength, colour, …), when there is a reading.
    pub analysis: Option<SpectroAnalysis>,
    /// η used by the fit.
    pub eta: f64,
    /// Measured (SCI − SCE, Schlick at 8°) or given.
    pub eta_source: EtaSource,
    /// Rd per channel (linear sRGB).
    pub rd: Rgb<f64>,
    /// α′ per channel, `None` where Rd cannot be inverted (see `problems`).
    pub albedo_prime: Rgb<Option<f64>>,
    /// Why a channel has no α′.
    pub problems: Rgb<Option<String>>,
    /// Things the user should know.
    pub warnings: Vec<String>,
    /// The reading's uncertainty and what it does to η and α′.
    pub uncertainty: SpectroUncertainty,
}

/// The spectrophotometer's uncertainty, propagated: a reading scaled by 1 ± ε (the same relative
/// error on SCI and SCE at every wavelength — a re-placed sample, the white calibration) moves Rd
/// by ±εRd and the specular part SCI − SCE by ±ε(SCI − SCE), hence η, together (one error, so
/// the two effects are correlated, not added in quadrature); α′ follows from both. The fit
/// propagates the two perturbed readings to σ′s and σa by refitting (`fit::propagate_spectro`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SpectroUncertainty {
    /// ε, the relative standard deviation of a reading.
    pub repeatability: f64,
    /// Standard error of η: half the spread of η at specular × (1 ± ε); `None` when η is given.
    pub eta_stderr: Option<f64>,
    /// η at the specular part × (1 − ε) and × (1 + ε) (η itself when given).
    pub eta_pm: [f64; 2],
    /// Rd per channel × (1 − ε), × (1 + ε).
    pub rd_pm: Rgb<[f64; 2]>,
    /// α′ per channel of the readings × (1 − ε) and × (1 + ε): at (Rd₋, η₋) and (Rd₊, η₊); `None`
    /// where it cannot be inverted.
    pub albedo_pm: Rgb<[Option<f64>; 2]>,
    /// Standard error of α′ per channel, |α′(Rd₊, η₊) − α′(Rd₋, η₋)|/2 (first-order propagation
    /// by central differences at ±1 standard deviation).
    pub albedo_prime_stderr: Rgb<Option<f64>>,
}

impl SpectroUncertainty {
    /// Nothing to propagate: η, Rd and α′ taken as exact (given by the user, not read).
    pub fn none(eta: f64, rd: Rgb<f64>, albedo_prime: Rgb<Option<f64>>) -> Self {
        Self {
            repeatability: 0.0,
            eta_stderr: None,
            eta_pm: [eta; 2],
            rd_pm: rd.map(|r| [r; 2]),
            albedo_pm: albedo_prime.map(|a| [a; 2]),
            albedo_prime_stderr: Rgb::default(),
        }
    }
}

impl SpectroStage {
    /// Known values, not a reading: η and, per channel, Rd and α′ given by the user (`scatterfit
    /// fit`), without uncertainty. A channel without α′ is one the proposed method cannot fit.
    pub fn given(eta: f64, rd: Rgb<f64>, albedo_prime: Rgb<Option<f64>>) -> SpectroStage {
        SpectroStage {
            file: None,
            file_sha256: None,
            analysis: None,
            eta,
            eta_source: EtaSource::Given,
            rd,
            albedo_prime,
            problems: Rgb::default(),
            warnings: Vec::new(),
            uncertainty: SpectroUncertainty::none(eta, rd, albedo_prime),
        }
    }

    /// η with the reading's standard error (none when η was given).
    pub fn eta_estimate(&self) -> Estimate {
        Estimate {
            value: self.eta,
            fit: None,
            spectro: self.uncertainty.eta_stderr,
            g: None,
            model: None,
        }
    }

    /// Channel `c`'s α′ with the reading's standard error; `None` where Rd cannot be inverted.
    pub fn albedo_prime_estimate(&self, c: Channel) -> Option<Estimate> {
        self.albedo_prime[c].map(|value| Estimate {
            value,
            fit: None,
            spectro: self.uncertainty.albedo_prime_stderr[c],
            g: None,
            model: None,
        })
    }

    /// The same reading with α′ from another model's total Rd(α′, η).
    pub fn with_albedo_model(&self, albedo: &dyn ModelFamily) -> SpectroStage {
        self.with_rd(self.rd, albedo)
    }

    /// The same reading with Rd replaced per channel (the port correction, `crate::port`): α′ and
    /// the uncertainty's perturbed readings follow from the new Rd (the reading's relative error ε
    /// applies to it unchanged, the correction being a factor).
    pub fn with_rd(&self, rd: Rgb<f64>, albedo: &dyn ModelFamily) -> SpectroStage {
        from_rd(
            Reading {
                file: self.file.clone(),
                file_sha256: self.file_sha256.clone(),
                analysis: self.analysis.clone(),
                rd,
                eta: self.eta,
                eta_source: self.eta_source,
                warnings: self.warnings.clone(),
                repeatability: self.uncertainty.repeatability,
                eta_pm: self.uncertainty.eta_pm,
            },
            albedo,
        )
    }
}

impl SpectroStage {
    /// As [`SpectroStage::with_rd`], with the perturbed readings given per channel where they are
    /// not Rd × (1 ∓ ε): the port correction's (`crate::port::correct_port`) corrected Rd of the
    /// readings × (1 ∓ ε) at η∓, which move more than ε·Rd. α′'s perturbed values and standard
    /// error follow from them; a channel with `None` keeps Rd × (1 ∓ ε).
    pub fn with_corrected_rd(
        &self,
        rd: Rgb<f64>,
        rd_pm: Rgb<Option<[f64; 2]>>,
        albedo: &dyn ModelFamily,
    ) -> SpectroStage {
        let mut stage = self.with_rd(rd, albedo);
        let u = &mut stage.uncertainty;
        for c in Channel::ALL {
            let Some(pm) = rd_pm[c] else { continue };
            u.rd_pm[c] = pm;
            u.albedo_pm[c] =
                std::array::from_fn(|k| albedo.albedo_from_rd(pm[k], u.eta_pm[k], ISOTROPIC).ok());
            u.albedo_prime_stderr[c] = match u.albedo_pm[c] {
                [Some(a0), Some(a1)] => Some(0.5 * (a1 - a0).abs()),
                _ => None,
            };
        }
        stage
    }
}

/// What the stage is computed from.
struct Reading {
    file: Option<PathBuf>,
    file_sha256: Option<String>,
    analysis: Option<SpectroAnalysis>,
    rd: Rgb<f64>,
    eta: f64,
    eta_source: EtaSource,
    warnings: Vec<String>,
    repeatability: f64,
    eta_pm: [f64; 2],
}

/// η at the specular part × (1 ∓ ε) by the same Schlick inversion at 8° as the summary η (Choi et
/// al. 2014, eq. 6, `optics::fresnel`); η itself for both when it was given or cannot be perturbed.
fn eta_pm(analysis: &SpectroAnalysis, repeatability: f64) -> [f64; 2] {
    if analysis.eta_source == scatterfit_optics::spectro::EtaSource::Given {
        return [analysis.eta; 2];
    }
    let at = |f: f64| {
        scatterfit_optics::fresnel::eta_from_specular_schlick(
            analysis.specular_mean * f,
            scatterfit_optics::fresnel::D8_VIEWING_ANGLE_DEG,
        )
        .unwrap_or(analysis.eta)
    };
    [at(1.0 - repeatability), at(1.0 + repeatability)]
}

/// Reads and analyses the reading of `manifest` (or its L\*a\*b\* with a given η). `eta` overrides
/// the measured η; `albedo` is the model whose total Rd(α′, η) is inverted for α′ (the paper: the
/// dipole's closed form, eq. 1).
///
/// # Errors
/// [`PipelineError::SpectroCsv`] for an unreadable or malformed CSV; [`PipelineError::Spectro`] when
/// the reading gives no η (no specular reflection: a failed measurement) or does not cover
/// 400–700 nm; [`PipelineError::Input`] for a bad η.
pub fn spectro_stage(
    manifest: &SampleManifest,
    eta: Option<f64>,
    albedo: &dyn ModelFamily,
) -> Result<SpectroStage> {
    let eta = eta.or(manifest.spectro.eta);
    if let Some(e) = eta
        && !(e.is_finite() && e >= 1.0)
    {
        return Err(PipelineError::Input(format!(
            "η = {e}: the relative refractive index must be a number ≥ 1"
        )));
    }
    let lab = manifest.spectro.lab.map(|[l, a, b]| {
        let observer = match manifest.spectro.lab_observer {
            Some(2) => Observer::TwoDegree,
            _ => Observer::TenDegree,
        };
        (Lab { l, a, b }, observer)
    });
    let repeatability = manifest
        .spectro
        .repeatability
        .unwrap_or(scatterfit_io::manifest::DEFAULT_SPECTRO_REPEATABILITY);
    match &manifest.spectro.file {
        Some(file) => {
            let path = manifest.resolve(file);
            let (reading, read) = scatterfit_io::spectro::read_spectro_file(&path)?;
            let analysis = analyse(&reading, &SpectroOptions { lab, eta }).map_err(|source| {
                PipelineError::Spectro {
                    file: path.clone(),
                    source,
                }
            })?;
            let mut stage = from_analysis(analysis, &path, repeatability, albedo);
            stage.file_sha256 = Some(read.sha256);
            Ok(stage)
        }
        None => {
            let eta = eta.ok_or_else(|| {
                PipelineError::Input("without a spectro file, η must be given (spectro.eta)".into())
            })?;
            let (lab, observer) = lab.ok_or_else(|| {
                PipelineError::Input("without a spectro file, give spectro.lab".into())
            })?;
            let rd = Rgb::from_array(scatterfit_optics::colour::lab_to_linear_srgb(lab, observer));
            Ok(from_rd(
                Reading {
                    file: None,
                    file_sha256: None,
                    analysis: None,
                    rd,
                    eta,
                    eta_source: EtaSource::Given,
                    warnings: Vec::new(),
                    repeatability,
                    eta_pm: [eta; 2],
                },
                albedo,
            ))
        }
    }
}

/// The stage from a reading's analysis ([`analyse`]; `path` names the reading in messages and the
/// result); `repeatability` is the reading's relative standard deviation
/// ([`SpectroUncertainty`]).
pub fn from_analysis(
    analysis: SpectroAnalysis,
    path: &Path,
    repeatability: f64,
    albedo: &dyn ModelFamily,
) -> SpectroStage {
    // The analysis keeps its channels in an array, R, G, B.
    let rd = Rgb::from_fn(|c| analysis.channels[c.index()].rd_total);
    let source = EtaSource::from(analysis.eta_source);
    let warnings = analysis.warnings.clone();
    let eta = analysis.eta;
    let eta_pm = eta_pm(&analysis, repeatability);
    from_rd(
        Reading {
            file: Some(path.to_path_buf()),
            file_sha256: None,
            analysis: Some(analysis),
            rd,
            eta,
            eta_source: source,
            warnings,
            repeatability,
            eta_pm,
        },
        albedo,
    )
}

/// The Henyey–Greenstein g α′ is inverted at: 0, an isotropic medium with σs = σ′s (what the
/// measurement assumes; the diffusion dipoles do not depend on it).
const ISOTROPIC: f64 = 0.0;

/// A reading beyond the totals a tabulated albedo model holds, in words with what to do (the bare
/// table bound says neither which end nor why); `None` for any other error.
fn beyond_the_totals(rd: f64, e: &scatterfit_optics::OpticsError) -> Option<String> {
    let scatterfit_optics::OpticsError::OutOfTable {
        name: "rd_total",
        min,
        max,
        ..
    } = *e
    else {
        return None;
    };
    Some(if rd < min {
        format!(
            "Rd is below {min:.4}, the lowest total its tables hold (at their lowest α′): the \
             channel absorbs more than they cover (the tables start at α′ 0.01) — use an albedo model without tables (`--albedo-model dipole`)"
        )
    } else {
        format!(
            "Rd is above {max:.4}, the highest total its tables hold (at their highest α′): more \
             than a non-absorbing material at this η reflects — check the reading (SCE, not SCI; \
             fractions, not percent) and η"
        )
    })
}

fn from_rd(reading: Reading, albedo: &dyn ModelFamily) -> SpectroStage {
    let Reading {
        file,
        file_sha256,
        analysis,
        rd,
        eta,
        eta_source,
        warnings,
        repeatability,
        eta_pm,
    } = reading;
    // The paper's eq. (1) (the dipole's total diffuse reflectance, inverted) or the same
    // inversion with another model's total.
    let inverted = rd.map_with_channel(|c, rd| {
        albedo.albedo_from_rd(rd, eta, ISOTROPIC).map_err(|e| {
            format!(
                "channel {}: α′ from Rd = {rd:.4} by the {} total: {}",
                c.name(),
                albedo.name(),
                beyond_the_totals(rd, &e).unwrap_or_else(|| e.to_string())
            )
        })
    });
    let albedo_prime = inverted.as_ref().map(|r| r.as_ref().ok().copied());
    let problems = inverted.map(std::result::Result::err);
    let rd_pm = rd.map(|r| [r * (1.0 - repeatability), r * (1.0 + repeatability)]);
    let albedo_pm = rd_pm.map(|rd_pm| {
        std::array::from_fn(|k| albedo.albedo_from_rd(rd_pm[k], eta_pm[k], ISOTROPIC).ok())
    });
    let albedo_prime_stderr = albedo_pm.map(|pm| match pm {
        [Some(a0), Some(a1)] => Some(0.5 * (a1 - a0).abs()),
        _ => None,
    });
    let eta_stderr =
        (eta_source != EtaSource::Given).then_some(0.5 * (eta_pm[1] - eta_pm[0]).abs());
    SpectroStage {
        file,
        file_sha256,
        analysis,
        eta,
        eta_source,
        rd,
        albedo_prime,
        problems,
        warnings,
        uncertainty: SpectroUncertainty {
            repeatability,
            eta_stderr,
            eta_pm,
            rd_pm,
            albedo_pm,
            albedo_prime_stderr,
        },
    }
}
