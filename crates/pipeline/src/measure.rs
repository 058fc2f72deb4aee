//! `measure_sample`: a sample folder in, the paper's Table 1 row out — spectro → η, α′; bracket →
//! HDR → profile; the fit per channel.

use std::path::{Path, PathBuf};
use std::time::Instant;

use scatterfit_fit::ProfileData;
use scatterfit_io::manifest::{AutoOrNone, BlackLevelSetting, SampleManifest, read_manifest};
use scatterfit_io::result_json::{Channels, FileRef, Inputs, MeasurementResult};
use scatterfit_mc::{albedo_family, family};
use scatterfit_optics::{AlbedoModel, AtG, Method, ModelName, Rgb};
use serde::Serialize;
use sha2::{Digest, Sha256};

use crate::error::{PipelineError, Result};
use crate::fit::{
    ChannelOutcome, FitSettings, SpectroErrors, SpotShape, channel_result, fit_stage,
    propagate_spectro,
};
use crate::hdr::BlackLevel;
use crate::hdr::{HdrInputs, HdrStage, read_and_merge, read_radiance_map};
use crate::profile::{ProfileSettings, ProfileStage, profile_stage_with};
use crate::spectro::{SpectroStage, spectro_stage};

/// Options that override the manifest's `[fit]` (from the command line).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Overrides {
    /// proposed | existing.
    pub method: Option<Method>,
    /// The forward model.
    pub model: Option<ModelName>,
    /// How α′ comes from the spectrophotometer.
    pub albedo_model: Option<AlbedoModel>,
    /// η instead of the measured one.
    pub eta: Option<f64>,
    /// Fix the scale by the spectrophotometer.
    pub normalise_with_spectro: Option<bool>,
    /// Allow the manifest to name files outside the sample folder (the input path policy,
    /// `scatterfit_io::inputs`; `--allow-outside-paths`).
    pub allow_outside_paths: bool,
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
    /// The port's edge-loss correction (`spectro.aperture_mm` given; `spectro` is then the
    /// corrected stage and the correction keeps the reading), or `None`: the reading was taken as
    /// loss-free.
    pub port: Option<crate::port::PortCorrection>,
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
    family(model)?;
    let albedo_model = o
        .albedo_model
        .or(manifest.fit.albedo_model)
        .unwrap_or(AlbedoModel::default_for(model));
    let normalise = o
        .normalise_with_spectro
        .or(manifest.fit.normalise_with_spectro)
        .unwrap_or(false);
    if normalise && method == Method::Existing {
        return Err(PipelineError::Input(
            "normalising with the spectrophotometer applies to the proposed method only".into(),
        ));
    }
    // The spot: a disk (the paper's), or a Gaussian of that 1/e² diameter (issue 16); a spot
    // image replaces this once the bracket is merged (measure_sample).
    let diameter = manifest.camera.spot_diameter_mm.unwrap_or(1.0);
    let (spot, spot_radius_mm) = match manifest.camera.spot_profile {
        Some(scatterfit_io::manifest::SpotProfileName::Gaussian) => {
            let s = scatterfit_fit::RadialSpot::gaussian(0.5 * diameter)
                .map_err(|e| PipelineError::Input(format!("camera.spot_profile: {e}")))?;
            (SpotShape::Radial(s), s.radius_enclosing(0.99))
        }
        _ => (SpotShape::Disk, 0.5 * diameter),
    };
    let settings = FitSettings {
        method,
        model,
        albedo_model,
        spot,
        spot_radius_mm,
        r_min_mm: manifest.fit.r_min_mm,
        normalise_with_spectro: normalise,
        g: manifest.fit.g.unwrap_or(0.0),
    };
    families(&settings)?;
    Ok(settings)
}

/// The profile model and the albedo model of `settings`, both at its g (issue 15).
///
/// # Errors
/// [`PipelineError::Input`] for a g the Monte Carlo tables do not cover when either model is `mc`.
fn families(settings: &FitSettings) -> Result<(AtG<'static>, AtG<'static>)> {
    let at = |f| AtG::new(f, settings.g).map_err(|e| PipelineError::Input(format!("fit.g: {e}")));
    let (model, albedo) = (
        at(family(settings.model)?)?,
        at(albedo_family(settings.albedo_model, settings.model)?)?,
    );
    if settings.model == ModelName::Mc || settings.albedo_model == AlbedoModel::Mc {
        scatterfit_mc::bundled_grid()?
            .albedo_prime_range(settings.g)
            .map_err(|e| PipelineError::Input(format!("fit.g: {e}")))?;
    }
    Ok((model, albedo))
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
    let manifest = sample_inputs(dir, overrides.allow_outside_paths)?.manifest;
    let settings = fit_settings(&manifest, overrides)?;
    let (model, albedo) = families(&settings)?;
    let (model, albedo) = (&model, &albedo);
    progress(Stage::Spectro);
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
            // A real camera (issue 16): black level, shutter times, flat frame.
            inputs.flat = manifest.camera.flat.as_ref().map(|p| manifest.resolve(p));
            inputs.exposure_correction = manifest.camera.exposure_correction.unwrap_or_default();
            inputs.black_level = match manifest.camera.black_level {
                None | Some(BlackLevelSetting::Mode(AutoOrNone::Auto)) => BlackLevel::Auto,
                Some(BlackLevelSetting::Mode(AutoOrNone::None)) => BlackLevel::None,
                Some(BlackLevelSetting::One(v)) => BlackLevel::Given(vec![v]),
                Some(BlackLevelSetting::PerChannel(v)) => BlackLevel::Given(v.to_vec()),
            };
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
    let profile = profile_stage_with(
        &hdr.hdr.radiance,
        Some(&hdr.hdr.clipped),
        &hdr.detection_limit,
        &ProfileSettings {
            mm_per_pixel: manifest.camera.mm_per_pixel.unwrap_or(f64::NAN),
            r_max_px: manifest.fit.r_max_px.unwrap_or(300.0),
            ring_width_px: 1.0,
            center_px: manifest.camera.center_px,
        },
        manifest.camera.background.unwrap_or_default(),
    )?;
    let mut settings = settings;
    if let Some(p) = &manifest.camera.spot_image {
        let s = crate::hdr::spot_kernel_from_image(
            &manifest.resolve(p),
            &hdr,
            manifest.camera.mm_per_pixel.unwrap_or(f64::NAN),
        )?;
        settings.spot = SpotShape::Radial(s);
        settings.spot_radius_mm = s.radius_enclosing(0.99);
    }
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
    let port = crate::port::port_of(
        manifest.spectro.aperture_mm,
        manifest.spectro.illuminated_mm,
    )?;
    let (spectro, port) = match port {
        Some(p) => {
            let (s, c) = crate::port::correct_port(&data, &spectro, &settings, model, albedo, p);
            (s, Some(c))
        }
        None => (spectro, None),
    };
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
        port,
        timings,
    })
}

impl Measurement {
    /// The same sample fitted with another method (the spectrophotometer stage, the merge and the
    /// profile are reused): what `compare` needs.
    ///
    /// # Errors
    /// [`PipelineError::Input`] as [`fit_settings`].
    pub fn refit(&self, method: Method) -> Result<Measurement> {
        let mut settings = self.settings;
        settings.method = method;
        if method == Method::Existing {
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
        let (model, albedo) = families(&settings)?;
        let (model, albedo) = (&model, &albedo);
        let t = Instant::now();
        let data: Vec<ProfileData> = (0..3)
            .map(|c| self.profile.channel_data(c))
            .collect::<Result<_>>()?;
        // The port correction depends on the model: start again from the reading.
        let (spectro, port) = match &self.port {
            Some(p) => {
                let port = scatterfit_optics::port::Port::new(p.illuminated_mm, p.aperture_mm)
                    .map_err(|e| {
                        PipelineError::Input(format!("the spectrophotometer port: {e}"))
                    })?;
                let read = p.read.with_albedo_model(albedo);
                let (s, c) =
                    crate::port::correct_port(&data, &read, &settings, model, albedo, port);
                (s, Some(c))
            }
            None => (self.spectro.with_albedo_model(albedo), None),
        };
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
            port,
            timings,
        })
    }

    /// True when every channel gave constrained parameters.
    pub fn complete(&self) -> bool {
        self.fits.iter().all(ChannelOutcome::is_measurement)
    }

    /// The data checks' verdict per channel (R, G, B; [`crate::checks`]).
    pub fn quality(&self) -> [crate::checks::Quality; 3] {
        crate::checks::quality(self)
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
        let mut quality = crate::checks::quality(self).map(Some);
        let channels = Channels::from_array(std::array::from_fn(|c| {
            let mut r = channel_result(
                &self.fits[c],
                &self.spectro,
                c,
                self.spectro_errors.get(c).and_then(Option::as_ref),
            );
            r.quality = quality[c].take();
            r
        }));
        MeasurementResult {
            name: m.display_name(),
            eta: self.spectro.eta,
            eta_source: self.spectro.eta_source.into(),
            eta_stderr: self.spectro.uncertainty.eta_stderr,
            spectro_repeatability: Some(self.spectro.uncertainty.repeatability),
            method: self.settings.method.name().into(),
            model: self.settings.model.name().into(),
            albedo_model: self.settings.albedo_model.name().into(),
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
                    "method": self.settings.method.name(),
                    "model": self.settings.model.name(),
                    "albedo_model": self.settings.albedo_model.name(),
                    "normalise_with_spectro": self.settings.normalise_with_spectro,
                    "r_min_mm": self.settings.r_min_mm(),
                    "r_max_px": m.fit.r_max_px.unwrap_or(300.0),
                    "spot_radius_mm": self.settings.spot_radius_mm,
                    "response": self.hdr.response_kind,
                    "detection_limit": self.profile.detection_limit,
                    "camera": {
                        "corrections": self.hdr.corrections,
                        "background": self.profile.background,
                    },
                }),
            },
            version: env!("CARGO_PKG_VERSION").into(),
            rd_spectrum: rd_spectrum(self.spectro.analysis.as_ref()),
            spectro_port: self
                .port
                .as_ref()
                .map(|p| scatterfit_io::result_json::PortResult {
                    aperture_mm: p.aperture_mm,
                    illuminated_mm: p.illuminated_mm,
                    rd_read: Rgb::from_array(p.read.rd),
                    reading_fraction: p.reading_fraction,
                    problems: p.problems.clone(),
                }),
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

/// SHA-256 of a file's bytes, lower-case hex (`None` when it cannot be read: missing, not a
/// regular file, larger than the memory budget).
pub fn hash_file(path: &Path) -> Option<String> {
    let bytes =
        scatterfit_safefs::read::read_limited(path, scatterfit_io::budget::memory_budget_bytes())
            .ok()?;
    let digest = Sha256::digest(&bytes);
    Some(digest.iter().map(|b| format!("{b:02x}")).collect())
}

/// A sample's manifest and every file a measurement of it reads.
#[derive(Debug, Clone)]
pub struct SampleInputs {
    /// The manifest.
    pub manifest: SampleManifest,
    /// Every input file with where it is named (`sample.toml`, `spectro.file`, `camera.images`,
    /// `exposures.csv line 3`, …), resolved against the sample folder.
    pub files: Vec<(String, PathBuf)>,
}

/// Reads the manifest of the sample `dir` (a folder, or a manifest file) and lists every file a
/// measurement reads — the manifest, the files it names, the frames its exposures CSV lists — each
/// checked against the input path policy (`scatterfit_io::inputs`: inside the sample folder, links
/// that leave it counting as outside, unless `allow_outside`). Cheap: no image is decoded. What
/// `measure_sample` starts with, and what the CLI checks its outputs against before any work.
///
/// # Errors
/// [`PipelineError::InputPath`] for a file outside the folder; the manifest's errors. (An exposures
/// CSV that cannot be read lists no frame; the measurement reports it.)
pub fn sample_inputs(dir: &Path, allow_outside: bool) -> Result<SampleInputs> {
    let manifest_path = if dir.is_dir() {
        dir.join(scatterfit_io::manifest::MANIFEST_NAME)
    } else {
        dir.to_path_buf()
    };
    let folder = manifest_path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let policy = scatterfit_io::inputs::InputPolicy::new(folder, allow_outside)?;
    // The manifest itself: a link that leaves the folder is refused before it is read.
    policy.check(&manifest_path, "the manifest", &manifest_path)?;
    let manifest = read_manifest(dir)?;
    let mut files = vec![("the manifest".to_string(), manifest_path.clone())];
    let m = &manifest;
    let named = [
        ("spectro.file", m.spectro.file.as_ref()),
        ("camera.exposures", m.camera.exposures.as_ref()),
        ("camera.hdr", m.camera.hdr.as_ref()),
        ("camera.response", m.camera.response.as_ref()),
        ("camera.dark", m.camera.dark.as_ref()),
    ];
    for (key, p) in named {
        if let Some(p) = p {
            files.push((format!("`{key}`"), m.resolve(p)));
        }
    }
    for p in m.camera.images.iter().flatten() {
        files.push(("`camera.images`".to_string(), m.resolve(p)));
    }
    for (key, path) in &files {
        policy.check(&manifest_path, key, path)?;
    }
    if m.camera.hdr.is_none()
        && m.camera.images.as_ref().is_none_or(Vec::is_empty)
        && let Some(csv) = &m.camera.exposures
    {
        let csv = m.resolve(csv);
        // An exposures CSV that cannot be read names no frame that could be read; the bracket
        // stage reports it in its turn (after the spectrophotometer's errors, as before).
        let listed = scatterfit_io::bracket::read_exposures_csv(&csv).unwrap_or_default();
        for e in listed {
            let key = format!(
                "the frame on line {} of {}",
                e.line,
                csv.file_name().unwrap_or_default().to_string_lossy()
            );
            policy.check(&csv, &key, &e.path)?;
            files.push((key, e.path));
        }
    }
    Ok(SampleInputs { manifest, files })
}

/// The sample folders found by [`sample_dirs`], and what it did not measure.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SampleDirs {
    /// The sample folders, each once, in the order given (a folder of samples expands to its
    /// sub-folders that hold a `sample.toml`, sorted).
    pub dirs: Vec<PathBuf>,
    /// Paths naming a folder already in `dirs` under another spelling (`a`, `./a`, `a/`, a link to
    /// it): `(path, the one kept)`. Each folder is measured once.
    pub duplicates: Vec<(PathBuf, PathBuf)>,
    /// Folders without a `sample.toml` but with a file that looks like a misspelt one
    /// (`Sample.toml`, `sample.TOML`, `sample.toml.txt`): `(folder, the file)`. Not measured;
    /// to be reported.
    pub misspelt: Vec<(PathBuf, PathBuf)>,
}

/// A file in `dir` whose name looks like a misspelt `sample.toml`.
pub fn misspelt_manifest(dir: &Path) -> Option<PathBuf> {
    let mut found: Vec<PathBuf> = std::fs::read_dir(dir)
        .ok()?
        .flatten()
        .filter(|e| {
            let name = e.file_name().to_string_lossy().to_lowercase();
            let exact = e.file_name() == scatterfit_io::manifest::MANIFEST_NAME;
            !exact
                && (name == "sample.toml"
                    || name.starts_with("sample.toml")
                    || (name.starts_with("sample")
                        && (name.ends_with(".toml") || name.ends_with(".tml"))))
        })
        .map(|e| e.path())
        .collect();
    found.sort();
    found.into_iter().next()
}

/// The sample folders among `paths`: each path that holds a `sample.toml`, or, for a folder that
/// does not, its immediate sub-folders that do (so `batch samples/` works on a folder of samples).
pub fn sample_dirs(paths: &[PathBuf]) -> SampleDirs {
    let manifest = scatterfit_io::manifest::MANIFEST_NAME;
    let mut candidates: Vec<PathBuf> = Vec::new();
    let mut misspelt = Vec::new();
    for p in paths {
        if p.join(manifest).is_file() || !p.is_dir() {
            candidates.push(p.clone());
            continue;
        }
        let mut subs: Vec<PathBuf> = std::fs::read_dir(p)
            .into_iter()
            .flatten()
            .flatten()
            .map(|e| e.path())
            .filter(|d| d.is_dir())
            .collect();
        subs.sort();
        let mut found = Vec::new();
        for d in subs {
            if d.join(manifest).is_file() {
                found.push(d);
            } else if let Some(f) = misspelt_manifest(&d) {
                misspelt.push((d, f));
            }
        }
        if found.is_empty() {
            // Not a folder of samples: measured as given (and its error reported), unless its
            // manifest is misspelt.
            match misspelt_manifest(p) {
                Some(f) => misspelt.push((p.clone(), f)),
                None => candidates.push(p.clone()),
            }
        } else {
            candidates.extend(found);
        }
    }
    let mut out = SampleDirs {
        misspelt,
        ..SampleDirs::default()
    };
    let mut seen: Vec<(PathBuf, PathBuf)> = Vec::new();
    for c in candidates {
        let id = std::fs::canonicalize(&c).unwrap_or_else(|_| c.clone());
        if let Some((_, kept)) = seen.iter().find(|(i, _)| *i == id) {
            out.duplicates.push((c, kept.clone()));
        } else {
            seen.push((id, c.clone()));
            out.dirs.push(c);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One folder named four ways is one sample; misspelt manifests are reported, not skipped.
    #[test]
    fn sample_dirs_measures_each_folder_once_and_reports_misspelt_manifests() {
        let top = tempfile::tempdir().unwrap();
        let t = top.path();
        for (d, m) in [
            ("a", "sample.toml"),
            ("b", "Sample.toml"),
            ("c", "sample.TOML"),
            ("d", "sample.toml.txt"),
            ("e", "notes.txt"),
        ] {
            std::fs::create_dir(t.join(d)).unwrap();
            std::fs::write(t.join(d).join(m), b"").unwrap();
        }
        let a = t.join("a");
        let mut given = vec![
            a.clone(),
            t.join("./a"),
            PathBuf::from(format!("{}/", a.display())),
        ];
        #[cfg(unix)]
        {
            std::os::unix::fs::symlink(&a, t.join("link-to-a")).unwrap();
            given.push(t.join("link-to-a"));
        }
        given.push(t.to_path_buf());
        let found = sample_dirs(&given);
        assert_eq!(found.dirs, vec![a.clone()]);
        // Every other spelling (and the folder of samples, which holds `a` and the link) is a
        // duplicate of the first.
        assert!(found.duplicates.len() >= given.len() - 1, "{found:?}");
        assert!(found.duplicates.iter().all(|(_, kept)| *kept == a));
        let mut misspelt: Vec<String> = found
            .misspelt
            .iter()
            .map(|(_, f)| f.file_name().unwrap().to_string_lossy().into_owned())
            .collect();
        misspelt.sort();
        assert_eq!(misspelt, ["Sample.toml", "sample.TOML", "sample.toml.txt"]);
        // A folder given directly whose manifest is misspelt is reported too.
        let found = sample_dirs(&[t.join("b")]);
        assert!(
            found.dirs.is_empty() && found.misspelt.len() == 1,
            "{found:?}"
        );
    }
}
