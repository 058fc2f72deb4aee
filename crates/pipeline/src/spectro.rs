//! Stage 1: the spectrophotometer — η from SCI − SCE and, per linear-sRGB channel, the diffuse
//! reflectance Rd and the reduced albedo α′ (Choi, Lee & Chin 2014, §3.2; the physics is in
//! `scatterfit_optics::spectro`).

use std::path::{Path, PathBuf};

use scatterfit_fit::ProfileModel;
use scatterfit_io::manifest::SampleManifest;
use scatterfit_optics::colour::{Lab, Observer};
use scatterfit_optics::spectro::{SpectroAnalysis, SpectroOptions, SpectroReading, analyse};
use serde::Serialize;

use crate::error::{PipelineError, Result};

/// What the spectrophotometer stage gives the fit.
#[derive(Debug, Clone, Serialize)]
pub struct SpectroStage {
    /// The reading's file, when there is one.
    pub file: Option<PathBuf>,
    /// The full analysis of the reading (η per wavelength, colour, …), when there is a reading.
    pub analysis: Option<SpectroAnalysis>,
    /// η used by the fit.
    pub eta: f64,
    /// `spectro` (SCI − SCE, Schlick at 8°) or `given`.
    pub eta_source: &'static str,
    /// Rd per channel (linear sRGB).
    pub rd: [f64; 3],
    /// α′ per channel, `None` where Rd cannot be inverted (see `problems`).
    pub albedo_prime: [Option<f64>; 3],
    /// Why a channel has no α′.
    pub problems: [Option<String>; 3],
    /// Things the user should know.
    pub warnings: Vec<String>,
}

impl SpectroStage {
    /// The same reading with α′ from another model's total Rd(α′, η).
    pub fn with_albedo_model(&self, albedo: &dyn ProfileModel) -> SpectroStage {
        from_rd(
            self.file.clone(),
            self.analysis.clone(),
            self.rd,
            self.eta,
            self.eta_source,
            self.warnings.clone(),
            albedo,
        )
    }
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
    albedo: &dyn ProfileModel,
) -> Result<SpectroStage> {
    let eta = eta.or(manifest.spectro.eta);
    let lab = manifest.spectro.lab.map(|[l, a, b]| {
        let observer = match manifest.spectro.lab_observer {
            Some(2) => Observer::TwoDegree,
            _ => Observer::TenDegree,
        };
        (Lab { l, a, b }, observer)
    });
    match &manifest.spectro.file {
        Some(file) => {
            let path = manifest.resolve(file);
            let reading = scatterfit_io::spectro::read_spectro_csv(&path)?;
            from_reading(&reading, &path, lab, eta, albedo)
        }
        None => {
            let eta = eta.ok_or_else(|| {
                PipelineError::Input("without a spectro file, η must be given (spectro.eta)".into())
            })?;
            let (lab, observer) = lab.ok_or_else(|| {
                PipelineError::Input("without a spectro file, give spectro.lab".into())
            })?;
            let rd = scatterfit_optics::colour::lab_to_linear_srgb(lab, observer);
            Ok(from_rd(None, None, rd, eta, "given", Vec::new(), albedo))
        }
    }
}

/// The stage from a reading already in memory (`path` names it in messages).
///
/// # Errors
/// As [`spectro_stage`].
pub fn from_reading(
    reading: &SpectroReading,
    path: &Path,
    lab: Option<(Lab, Observer)>,
    eta: Option<f64>,
    albedo: &dyn ProfileModel,
) -> Result<SpectroStage> {
    if let Some(e) = eta
        && !(e.is_finite() && e >= 1.0)
    {
        return Err(PipelineError::Input(format!(
            "η = {e}: the relative refractive index must be a number ≥ 1"
        )));
    }
    let analysis = analyse(reading, &SpectroOptions { lab, eta }).map_err(|source| {
        PipelineError::Spectro {
            file: path.to_path_buf(),
            source,
        }
    })?;
    let rd = std::array::from_fn(|c| analysis.channels[c].rd_total);
    let source = match analysis.eta_source {
        scatterfit_optics::spectro::EtaSource::Given => "given",
        _ => "spectro",
    };
    let warnings = analysis.warnings.clone();
    let eta = analysis.eta;
    Ok(from_rd(
        Some(path.to_path_buf()),
        Some(analysis),
        rd,
        eta,
        source,
        warnings,
        albedo,
    ))
}

fn from_rd(
    file: Option<PathBuf>,
    analysis: Option<SpectroAnalysis>,
    rd: [f64; 3],
    eta: f64,
    eta_source: &'static str,
    warnings: Vec<String>,
    albedo: &dyn ProfileModel,
) -> SpectroStage {
    let names = ["R", "G", "B"];
    let mut albedo_prime = [None; 3];
    let mut problems: [Option<String>; 3] = Default::default();
    for c in 0..3 {
        // The paper's eq. (1) (the dipole's total diffuse reflectance, inverted) or the same
        // inversion with another model's total.
        match albedo.albedo_from_rd(rd[c], eta) {
            Ok(a) => albedo_prime[c] = Some(a),
            Err(e) => {
                problems[c] = Some(format!(
                    "channel {}: α′ from Rd = {:.4} by the {} total: {e}",
                    names[c],
                    rd[c],
                    albedo.name()
                ));
            }
        }
    }
    SpectroStage {
        file,
        analysis,
        eta,
        eta_source,
        rd,
        albedo_prime,
        problems,
        warnings,
    }
}
