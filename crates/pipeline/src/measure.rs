//! `measure_sample`: a sample folder in, the paper's Table 1 row out — spectro → η, α′; bracket →
//! HDR → profile; the fit per channel.

use std::path::{Path, PathBuf};
use std::time::Instant;

use scatterfit_fit::ProfileData;
use scatterfit_io::manifest::{
    AlbedoModelName, MethodName, ModelName, SampleManifest, read_manifest,
};
use scatterfit_io::result_json::{Channels, FileRef, Inputs, MeasurementResult};
use serde::Serialize;
use sha2::{Digest, Sha256};

use crate::error::{PipelineError, Result};
use crate::fit::{
    ChannelOutcome, FitSettings, SpectroErrors, albedo_model_for, channel_result, fit_stage,
    model_for, propagate_spectro,
};
use crate::hdr::{HdrInputs, HdrStage, read_and_merge, read_radiance_map};
use crate::profile::{ProfileSettings, ProfileStage, profile_stage};
use crate::spectro::{SpectroStage, spectro_stage};

/// Options that override the manifest's `[fit]` (from the command line).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Overrides {
    /// proposed | existing.
    pub method: Option<MethodName>,
    /// The forward model.
    pub model: Option<ModelName>,
    /// How α′ comes from the spectrophotometer.
    pub albedo_model: Option<AlbedoModelName>,
    /// η instead of the measured one.
    pub eta: Option<f64>,
    /// Fix the scale by the spectrophotometer.
    pub normalise_with_spectro: Option<bool>,
}

/// A stage of [`measure_sample`], for progress reports.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum Stage {
    /// Reading and analysing the spectrophotometer file.
    Spectro,
    /// Reading the frames (called per frame).
    ReadFrame,
    /// Recovering the response and merging.
    Merge,
    /// Spot and rings.
    Profile,
    /// Fitting the channels.
    Fit,
}

/// Everything a measurement produced.
#[derive(Debug, Clone)]
pub struct Measurement {
    /// The manifest.
    pub manifest: SampleManifest,
    /// Fit settings used.
    pub settings: FitSettings,
    /// Spectrophotometer stage.
    pub spectro: SpectroStage,
    /// The merged bracket.
    pub hdr: HdrStage,
    /// Spot and rings.
    pub profile: ProfileStage,
    /// Per channel.
    pub fits: Vec<ChannelOutcome>,
    /// Per channel, the spectrophotometer's part of the uncertainty ([`propagate_spectro`]).
    pub spectro_errors: Vec<Option<SpectroErrors>>,
    /// Wall times per stage [s].
    pub timings: Timings,
}

/// Wall times per stage [s].
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct Timings {
    /// Spectro stage.
    pub spectro_s: f64,
    /// Reading frames.
    pub read_s: f64,
    /// Response recovery and merge.
    pub merge_s: f64,
    /// Spot centre and profile.
    pub profile_s: f64,
    /// The three fits (start search + solver).
    pub fit_s: f64,
    /// The whole measurement.
    pub total_s: f64,
}

/// Resolves the fit settings from the manifest and the overrides.
///
/// # Errors
/// [`PipelineError::Input`] for a model that is not available or normalisation with the existing
/// method.
pub fn fit_settings(manifest: &SampleManifest, o: &Overrides) -> Result<FitSettings> {
    let method = o.method.or(manifest.fit.method).unwrap_or_default();
    let model = o.model.or(manifest.fit.model).unwrap_or_default();
    model_for(model)?;
    let albedo_model =
        o.albedo_model
            .or(manifest.fit.albedo_model)
            .unwrap_or(if model == ModelName::Mc {
                AlbedoModelName::Mc
            } else {
                AlbedoModelName::Diffusion
            });
    let normalise = o
        .normalise_with_spectro
        .or(manifest.fit.normalise_with_spectro)
        .unwrap_or(false);
    if normalise && method == MethodName::Existing {
        return Err(PipelineError::Input(
            "normalising with the spectrophotometer applies to the proposed method only".into(),
        ));
    }
    Ok(FitSettings {
        method,
        model,
        albedo_model,
        spot_radius_mm: 0.5 * manifest.camera.spot_diameter_mm.unwrap_or(1.0),
        r_min_mm: manifest.fit.r_min_mm,
        normalise_with_spectro: normalise,
    })
}

/// Measures the sample in folder `dir` (its `sample.toml`).
///
/// # Errors
/// [`PipelineError`] for bad input (exit 2) or a stage that failed (exit 1, see
/// [`PipelineError::is_measurement_failure`]). Channels that cannot be fitted are not errors: they
/// are [`ChannelOutcome::NotFitted`] in the result.
pub fn measure_sample(
    dir: &Path,
    overrides: &Overrides,
    progress: &(dyn Fn(Stage) + Sync),
) -> Result<Measurement> {
    let t0 = Instant::now();
    let manifest = read_manifest(dir)?;
    let settings = fit_settings(&manifest, overrides)?;
    let model = model_for(settings.model)?;
    progress(Stage::Spectro);
    let albedo = albedo_model_for(settings.albedo_model, settings.model)?;
    let spectro = spectro_stage(&manifest, overrides.eta, albedo)?;
    let spectro_s = t0.elapsed().as_secs_f64();
    let hdr = match &manifest.camera.hdr {
        Some(p) => read_radiance_map(&manifest.resolve(p))?,
        None => {
            let mut inputs = HdrInputs::new(
                manifest
                    .camera
                    .exposures
                    .as_ref()
                    .map(|p| manifest.resolve(p)),
                manifest
                    .camera
                    .images
                    .iter()
                    .flatten()
                    .map(|p| manifest.resolve(p))
                    .collect(),
            );
            inputs.response = manifest
                .camera
                .response
                .as_ref()
                .map(|p| manifest.resolve(p));
            inputs.dark = manifest.camera.dark.as_ref().map(|p| manifest.resolve(p));
            // Pixels dark in every frame are evidence of radiance below the first code: keep them
            // as 0 so far rings are not averaged over their brighter pixels only; pixels saturated
            // everywhere are masked out by the profile stage.
            inputs.clipped_fill = scatterfit_imaging::ClippedFill::LowerBound;
            let stage = read_and_merge(&inputs, &|_| progress(Stage::ReadFrame))?;
            progress(Stage::Merge);
            stage
        }
    };
    let t_profile = Instant::now();
    progress(Stage::Profile);
    let profile = profile_stage(
        &hdr.hdr.radiance,
        Some(&hdr.hdr.clipped),
        &hdr.detection_limit,
        &ProfileSettings {
            mm_per_pixel: manifest.camera.mm_per_pixel.unwrap_or(f64::NAN),
            r_max_px: manifest.fit.r_max_px.unwrap_or(300.0),
            ring_width_px: 1.0,
            center_px: manifest.camera.center_px,
        },
    )?;
    let profile_s = t_profile.elapsed().as_secs_f64();
    let channels = profile.profile.channels();
    if channels != 3 {
        return Err(PipelineError::Input(format!(
            "the radiance map has {channels} channel(s); σ′s and σa per colour need RGB images"
        )));
    }
    progress(Stage::Fit);
    let t_fit = Instant::now();
    let data: Vec<ProfileData> = (0..3)
        .map(|c| profile.channel_data(c))
        .collect::<Result<_>>()?;
    let fits = fit_stage(&data, &spectro, &settings, model);
    let spectro_errors = propagate_spectro(&data, &spectro, &settings, model, &fits);
    let fit_s = t_fit.elapsed().as_secs_f64();
    let timings = Timings {
        spectro_s,
        read_s: hdr.read_s,
        merge_s: hdr.merge_s,
        profile_s,
        fit_s,
        total_s: t0.elapsed().as_secs_f64(),
    };
    Ok(Measurement {
        manifest,
        settings,
        spectro,
        hdr,
        profile,
        fits,
        spectro_errors,
        timings,
    })
}

impl Measurement {
    /// The same sample fitted with another method (the spectrophotometer stage, the merge and the
    /// profile are reused): what `compare` needs.
    ///
    /// # Errors
    /// [`PipelineError::Input`] as [`fit_settings`].
    pub fn refit(&self, method: MethodName) -> Result<Measurement> {
        let mut settings = self.settings;
        settings.method = method;
        if method == MethodName::Existing {
            settings.normalise_with_spectro = false;
        }
        self.refit_with(settings)
    }

    /// The same sample with other fit settings — model, albedo model, method — reusing the merge
    /// and the profile; α′ is recomputed from the spectrophotometer's Rd by the albedo model (what
    /// the bias study needs).
    ///
    /// # Errors
    /// [`PipelineError::Input`] when a model cannot be loaded.
    pub fn refit_with(&self, settings: FitSettings) -> Result<Measurement> {
        self.refit_inner(settings, true)
    }

    /// [`Measurement::refit_with`] without the spectrophotometer's uncertainty (no refits at the
    /// perturbed readings; `spectro_errors` all `None`): for studies that compare values only —
    /// with PBD the propagation would triple the fitting time.
    ///
    /// # Errors
    /// As [`Measurement::refit_with`].
    pub fn refit_values_only(&self, settings: FitSettings) -> Result<Measurement> {
        self.refit_inner(settings, false)
    }

    fn refit_inner(&self, settings: FitSettings, propagate: bool) -> Result<Measurement> {
        let model = model_for(settings.model)?;
        let albedo = albedo_model_for(settings.albedo_model, settings.model)?;
        let spectro = self.spectro.with_albedo_model(albedo);
        let t = Instant::now();
        let data: Vec<ProfileData> = (0..3)
            .map(|c| self.profile.channel_data(c))
            .collect::<Result<_>>()?;
        let fits = fit_stage(&data, &spectro, &settings, model);
        let spectro_errors = if propagate {
            propagate_spectro(&data, &spectro, &settings, model, &fits)
        } else {
            vec![None; fits.len()]
        };
        let mut timings = self.timings;
        timings.fit_s = t.elapsed().as_secs_f64();
        Ok(Measurement {
            manifest: self.manifest.clone(),
            settings,
            spectro,
            hdr: self.hdr.clone(),
            profile: self.profile.clone(),
            fits,
            spectro_errors,
            timings,
        })
    }

    /// True when every channel gave constrained parameters.
    pub fn complete(&self) -> bool {
        self.fits.iter().all(ChannelOutcome::is_measurement)
    }

    /// The result file's content. `profile_file` is the profile CSV's name as written beside the
    /// result (recorded in `inputs.profile`).
    pub fn to_result(&self, profile_file: Option<&str>) -> MeasurementResult {
        let m = &self.manifest;
        let mut files = Vec::new();
        let mut file_ref = |p: &Path| -> Option<FileRef> {
            let full = m.resolve(p);
            let r = hash_file(&full).map(|sha256| FileRef {
                path: p.to_string_lossy().into_owned(),
                sha256,
            });
            files.push(full);
            r
        };
        let manifest_ref = file_ref(Path::new(scatterfit_io::manifest::MANIFEST_NAME));
        let spectro_ref = m.spectro.file.as_deref().and_then(&mut file_ref);
        let hdr_ref = m.camera.hdr.as_deref().and_then(&mut file_ref);
        let frames: Vec<FileRef> = self
            .hdr
            .frames
            .iter()
            .filter_map(|f| {
                let rel = f.file.strip_prefix(&m.dir).unwrap_or(&f.file).to_path_buf();
                file_ref(&rel)
            })
            .collect();
        let channels = Channels::from_array(std::array::from_fn(|c| {
            channel_result(
                &self.fits[c],
                &self.spectro,
                c,
                self.spectro_errors.get(c).and_then(Option::as_ref),
            )
        }));
        MeasurementResult {
            name: m.display_name(),
            eta: self.spectro.eta,
            eta_source: self.spectro.eta_source.into(),
            eta_stderr: self.spectro.uncertainty.eta_stderr,
            spectro_repeatability: Some(self.spectro.uncertainty.repeatability),
            method: self.settings.method.as_str().into(),
            model: self.settings.model.as_str().into(),
            albedo_model: self.settings.albedo_model.as_str().into(),
            channels,
            inputs: Inputs {
                sample_dir: m.dir.to_string_lossy().into_owned(),
                manifest: manifest_ref,
                spectro: spectro_ref,
                frames,
                hdr: hdr_ref,
                profile: profile_file.map(str::to_string),
                mm_per_pixel: m.camera.mm_per_pixel,
                spot_radius_mm: Some(self.settings.spot_radius_mm),
                center_px: Some(self.profile.center.xy()),
                options: serde_json::json!({
                    "method": self.settings.method.as_str(),
                    "model": self.settings.model.as_str(),
                    "albedo_model": self.settings.albedo_model.as_str(),
                    "normalise_with_spectro": self.settings.normalise_with_spectro,
                    "r_min_mm": self.settings.r_min_mm(),
                    "r_max_px": m.fit.r_max_px.unwrap_or(300.0),
                    "spot_radius_mm": self.settings.spot_radius_mm,
                    "response": self.hdr.response_kind,
                    "detection_limit": self.profile.detection_limit,
                }),
            },
            version: env!("CARGO_PKG_VERSION").into(),
            rd_spectrum: rd_spectrum(self.spectro.analysis.as_ref()),
        }
    }
}

/// The SCE spectrum the channels' Rd came from (issue 18: spectral renderers need it), when the
/// colour came from the spectrum rather than a measured L*a*b*.
fn rd_spectrum(
    analysis: Option<&scatterfit_optics::spectro::SpectroAnalysis>,
) -> Option<scatterfit_io::result_json::RdSpectrum> {
    let a = analysis?;
    (a.colour_source == scatterfit_optics::spectro::ColourSource::SceSpectrum).then(|| {
        scatterfit_io::result_json::RdSpectrum {
            wavelength_nm: a.spectral.iter().map(|p| p.wavelength_nm).collect(),
            rd: a.spectral.iter().map(|p| p.sce).collect(),
        }
    })
}

/// SHA-256 of a file's bytes, lower-case hex (`None` when it cannot be read).
pub fn hash_file(path: &Path) -> Option<String> {
    let bytes = std::fs::read(path).ok()?;
    let digest = Sha256::digest(&bytes);
    Some(digest.iter().map(|b| format!("{b:02x}")).collect())
}

/// The sample folders among `paths`: each path that holds a `sample.toml`, or, for a folder that
/// does not, its immediate sub-folders that do (so `batch samples/` works on a folder of samples).
pub fn sample_dirs(paths: &[PathBuf]) -> Vec<PathBuf> {
    let manifest = scatterfit_io::manifest::MANIFEST_NAME;
    let mut out = Vec::new();
    for p in paths {
        if p.join(manifest).is_file() || !p.is_dir() {
            out.push(p.clone());
            continue;
        }
        let mut subs: Vec<PathBuf> = std::fs::read_dir(p)
            .into_iter()
            .flatten()
            .flatten()
            .map(|e| e.path())
            .filter(|d| d.join(manifest).is_file())
            .collect();
        subs.sort();
        if subs.is_empty() {
            out.push(p.clone());
        } else {
            out.extend(subs);
        }
    }
    out
}
