//! `measure_sample`: a sample folder in, the paper's Table 1 row out — spectro → η, α′; bracket →
//! HDR → profile; the fit per channel.

use std::path::Path;
use std::time::Instant;

use scatterfit_io::manifest::{AutoOrNone, BlackLevelSetting, SampleManifest};
use scatterfit_io::result_json::{AlbedoSource, FileRef, Inputs, MeasurementResult, RunOptions};
use scatterfit_mc::{albedo_family, family};
use scatterfit_optics::{AlbedoModel, AtG, Estimate, Method, ModelName, Rgb};
use serde::Serialize;

use crate::anisotropy::{GPlan, GPrior, known_g_record};
use crate::error::{PipelineError, Result};
use crate::fit::{
    ChannelOutcome, FitSettings, SpotShape, channel_result, fit_and_propagate, fit_stage,
};
use crate::hdr::BlackLevel;
use crate::hdr::{HdrInputs, HdrStage, read_and_merge, read_radiance_map};
use crate::profile::{ProfileSettings, ProfileStage, profile_stage_with};
use crate::samples::{SampleInputs, sample_inputs};
use crate::spectro::{SpectroStage, spectro_stage};

/// Options that override the manifest's `[fit]` (from the command line, or a program). Every
/// option unset means "as the manifest says"; choose with the setters:
///
/// ```
/// use scatterfit_pipeline::{Method, ModelName, Overrides};
///
/// let exact = Overrides::default().model(ModelName::Mc);
/// let existing = Overrides::default().method(Method::Existing).eta(1.45);
/// assert_eq!(exact.model, Some(ModelName::Mc));
/// assert_eq!(existing.eta, Some(1.45));
/// ```
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
    /// What is known about g instead of the manifest's `[fit] g` and `[fit] g_range` (both
    /// replaced; `--g`, `--g-range`).
    pub g: Option<GPrior>,
    /// Allow the manifest to name files outside the sample folder (the input path policy,
    /// `scatterfit_io::inputs`; `--allow-outside-paths`).
    pub allow_outside_paths: bool,
}

impl Overrides {
    /// The fitting method (proposed | existing).
    #[must_use]
    pub fn method(self, method: Method) -> Self {
        Self {
            method: Some(method),
            ..self
        }
    }

    /// The forward model.
    #[must_use]
    pub fn model(self, model: ModelName) -> Self {
        Self {
            model: Some(model),
            ..self
        }
    }

    /// How α′ comes from the spectrophotometer (default: the model's own, [`AlbedoModel::default_for`]).
    #[must_use]
    pub fn albedo_model(self, albedo_model: AlbedoModel) -> Self {
        Self {
            albedo_model: Some(albedo_model),
            ..self
        }
    }

    /// A known η instead of the measured one.
    #[must_use]
    pub fn eta(self, eta: f64) -> Self {
        Self {
            eta: Some(eta),
            ..self
        }
    }

    /// Fix the profile's scale by the spectrophotometer's Rd (proposed method only).
    #[must_use]
    pub fn normalise_with_spectro(self, normalise: bool) -> Self {
        Self {
            normalise_with_spectro: Some(normalise),
            ..self
        }
    }

    /// Let the manifest name files outside the sample folder (`scatterfit_io::inputs`).
    #[must_use]
    pub fn allow_outside_paths(self, allow: bool) -> Self {
        Self {
            allow_outside_paths: allow,
            ..self
        }
    }
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
    /// Checking the image and the bracket against the fits ([`crate::checks::image_checks`]).
    Checks,
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
    /// Per channel: σ′s, σa and α′ with their uncertainty terms, the solver's report, or why the
    /// channel was not fitted.
    pub fits: Rgb<ChannelOutcome>,
    /// The port's edge-loss correction (`spectro.aperture_mm` given; `spectro` is then the
    /// corrected stage and the correction keeps the reading), or `None`: the reading was taken as
    /// loss-free.
    pub port: Option<crate::port::PortCorrection>,
    /// Wall times per stage \[s\].
    pub timings: Timings,
    /// What the data's redundancy says (the profile's own α′; [`crate::checks::evidence`]).
    pub evidence: crate::checks::evidence::Evidence,
    /// The checks of the image, the bracket and the manifest that no fit enters
    /// ([`crate::checks::image_checks`]): made once, when the measurement is made, and kept by
    /// its refits; [`Measurement::quality`] adds the fits' own checks to them.
    pub image_checks: crate::checks::SampleChecks,
}

/// Wall times per stage \[s\].
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
    /// The checks of the image and the bracket ([`crate::checks::image_checks`]) and the spot's
    /// scale against the fits ([`crate::checks::evidence::spot_scale`]).
    pub checks_s: f64,
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
    // The spot: a disk (the paper's), or a Gaussian of that 1/e² diameter; a spot
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
    // What is known about g: an override replaces both manifest keys.
    let g_prior =
        o.g.unwrap_or_else(|| GPrior::from_setting(manifest.fit.g, manifest.fit.g_range));
    g_prior.check()?;
    check_g_fit(&g_prior, model)?;
    let settings = FitSettings {
        method,
        model,
        albedo_model,
        spot,
        spot_radius_mm,
        r_min_mm: manifest.fit.r_min_mm,
        normalise_with_spectro: normalise,
        g: values_g(&g_prior)?,
        g_prior,
    };
    families(&settings)?;
    Ok(settings)
}

/// `g = "fit"` needs the g-aware `mc` model (the diffusion dipoles do not depend on g, and
/// photon beam diffusion's g enters only its near field).
///
/// # Errors
/// [`PipelineError::Input`] naming `fit.g` and what to do.
pub fn check_g_fit(prior: &GPrior, model: ModelName) -> Result<()> {
    if prior.fit && model != ModelName::Mc {
        return Err(PipelineError::Input(format!(
            "fit.g = \"fit\": fitting g needs the g-aware Monte Carlo model, not {model}; set \
             fit.model = \"mc\" (or --model mc), or give g as a number or a fit.g_range"
        )));
    }
    Ok(())
}

/// The g the values are computed at: the given g; for a range without a g (or `g = "fit"`: the
/// range searched) the covered g nearest its middle ([`GPlan::nominal_g`]); else 0.
///
/// # Errors
/// [`PipelineError::Input`] for a range the `mc` tables cover nowhere.
pub fn values_g(prior: &GPrior) -> Result<f64> {
    values_g_on(scatterfit_mc::bundled_grid()?, prior)
}

/// [`values_g`] on another grid of tables.
///
/// # Errors
/// As [`values_g`].
pub fn values_g_on(grid: &scatterfit_mc::McGridSet, prior: &GPrior) -> Result<f64> {
    match (
        prior.g,
        prior
            .range
            .or(prior.propagated_range().filter(|_| prior.fit)),
    ) {
        (Some(g), _) => Ok(g),
        (None, Some(range)) => GPlan::nominal_g(grid, range).ok_or_else(|| {
            PipelineError::Input(format!(
                "fit.g_range = [{}, {}]: the `mc` tables cover no g in it ({}); give a range \
                     that reaches one of them (or a g)",
                range[0],
                range[1],
                grid.coverage()
            ))
        }),
        (None, None) => Ok(0.0),
    }
}

/// The profile model and the albedo model of `settings`, both at its g.
///
/// # Errors
/// [`PipelineError::Input`] for a g the Monte Carlo tables do not cover when either model is `mc`.
pub(crate) fn families(settings: &FitSettings) -> Result<(AtG<'static>, AtG<'static>)> {
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

/// Measures the sample in folder `dir` (its `sample.toml`): [`sample_inputs`], then
/// [`measure_inputs`].
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
    measure_sample_until(dir, overrides, progress, &|| false)
}

/// [`measure_sample`], stopped when `stop` answers true: it is asked before each stage, and a
/// stopped measurement is [`PipelineError::Interrupted`] (a caller's Ctrl-C: the Python package's
/// `measure` returns within a stage).
///
/// # Errors
/// As [`measure_sample`], and [`PipelineError::Interrupted`].
pub fn measure_sample_until(
    dir: &Path,
    overrides: &Overrides,
    progress: &(dyn Fn(Stage) + Sync),
    stop: &(dyn Fn() -> bool + Sync),
) -> Result<Measurement> {
    let t0 = Instant::now();
    let inputs = sample_inputs(dir, overrides.allow_outside_paths)?;
    measure_from(&inputs, overrides, progress, stop, t0)
}

/// Measures a sample whose manifest and inputs [`sample_inputs`] already resolved (a caller that
/// checked its outputs against them first reads the manifest once).
///
/// # Errors
/// As [`measure_sample`].
pub fn measure_inputs(
    inputs: &SampleInputs,
    overrides: &Overrides,
    progress: &(dyn Fn(Stage) + Sync),
) -> Result<Measurement> {
    measure_inputs_until(inputs, overrides, progress, &|| false)
}

/// [`measure_inputs`], stopped before a stage when `stop` answers true ([`measure_sample_until`]).
///
/// # Errors
/// As [`measure_inputs`], and [`PipelineError::Interrupted`].
pub fn measure_inputs_until(
    inputs: &SampleInputs,
    overrides: &Overrides,
    progress: &(dyn Fn(Stage) + Sync),
    stop: &(dyn Fn() -> bool + Sync),
) -> Result<Measurement> {
    measure_from(inputs, overrides, progress, stop, Instant::now())
}

fn measure_from(
    inputs: &SampleInputs,
    overrides: &Overrides,
    progress: &(dyn Fn(Stage) + Sync),
    stop: &(dyn Fn() -> bool + Sync),
    t0: Instant,
) -> Result<Measurement> {
    // Each stage is announced, unless the caller asked to stop before it.
    let begin = |stage: Stage| -> Result<()> {
        if stop() {
            return Err(PipelineError::Interrupted);
        }
        progress(stage);
        Ok(())
    };
    let manifest = inputs.manifest.clone();
    let settings = fit_settings(&manifest, overrides)?;
    let (model, albedo) = families(&settings)?;
    let (model, albedo) = (&model, &albedo);
    begin(Stage::Spectro)?;
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
            // A real camera: black level, shutter times, flat frame.
            inputs.flat = manifest.camera.flat.as_ref().map(|p| manifest.resolve(p));
            inputs.exposure_correction = manifest.camera.exposure_correction.unwrap_or_default();
            if let Some(s) = manifest.camera.saturation {
                inputs.saturation = s;
                inputs.saturation_given = true;
            }
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
            begin(Stage::Merge)?;
            stage
        }
    };
    let t_profile = Instant::now();
    begin(Stage::Profile)?;
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
    let data = profile.rgb_data()?;
    begin(Stage::Fit)?;
    let t_fit = Instant::now();
    let port = crate::port::port_of(
        manifest.spectro.aperture_mm,
        manifest.spectro.illuminated_mm,
    )?;
    let (spectro, port) = match port {
        Some(p) => {
            let (mut s, c) =
                crate::port::correct_port(&data, &spectro, &settings, model, albedo, p);
            if let Some([lo, hi]) = settings.g_prior.propagated_range() {
                // The g term refits at each g from the Rd corrected here, at the values' g; the
                // port's F is not recomputed at each g (BENCHMARKS.md, "The port's
                // conditioning"): say so rather than let the term look complete.
                s.warnings.push(format!(
                    "the port correction used F of the model at g = {}; the ± g term (g in \
                     {lo}–{hi}) keeps that corrected Rd, but F itself changes with g (by 2–9 % \
                     between g = 0 and 0.8 at α′ ≥ 0.99 behind an 8 mm port), so with a port the \
                     g term understates; give [fit] g if it is known",
                    settings.g
                ));
            }
            (s, Some(c))
        }
        None => (spectro, None),
    };
    let fits = fit_and_propagate(&data, &spectro, &settings, model);
    let fits = match &port {
        Some(c) => crate::port::propagate_fit_through_port(
            &data, &spectro, &settings, model, albedo, c, fits,
        ),
        None => fits,
    };
    // With an approximate model the evidence comes from exact transport's fits
    // (`Measurement::with_model_term`): the model's own error would confound it.
    let evidence = if crate::model_term::is_approximate(&settings) {
        crate::checks::evidence::Evidence::default()
    } else {
        crate::checks::evidence::gather(&data, &spectro, &settings, model, &fits)
    };
    let timings = Timings {
        spectro_s,
        read_s: hdr.read_s,
        merge_s: hdr.merge_s,
        profile_s,
        ..Timings::default()
    };
    // An approximate model's error joins the bars (crate::model_term).
    let mut m = Measurement {
        manifest,
        settings,
        spectro,
        hdr,
        profile,
        fits,
        port,
        timings,
        evidence,
        image_checks: crate::checks::SampleChecks::default(),
    }
    .with_model_term();
    m.timings.fit_s = t_fit.elapsed().as_secs_f64();
    begin(Stage::Checks)?;
    let t_checks = Instant::now();
    m.image_checks = crate::checks::image_checks(&m);
    m.evidence.spot_scale = crate::checks::evidence::spot_scale(&m);
    m.timings.checks_s = t_checks.elapsed().as_secs_f64();
    m.timings.total_s = t0.elapsed().as_secs_f64();
    Ok(m)
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
    /// perturbed readings; every estimate's `spectro` term `None`): for studies that compare
    /// values only —
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
        let data = self.profile.rgb_data()?;
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
        let fits = if propagate {
            let fits = fit_and_propagate(&data, &spectro, &settings, model);
            match &port {
                Some(c) => crate::port::propagate_fit_through_port(
                    &data, &spectro, &settings, model, albedo, c, fits,
                ),
                None => fits,
            }
        } else {
            fit_stage(&data, &spectro, &settings, model)
        };
        let evidence = if propagate && !crate::model_term::is_approximate(&settings) {
            crate::checks::evidence::gather(&data, &spectro, &settings, model, &fits)
        } else {
            crate::checks::evidence::Evidence::default()
        };
        let mut m = Measurement {
            manifest: self.manifest.clone(),
            settings,
            spectro,
            hdr: self.hdr.clone(),
            profile: self.profile.clone(),
            fits,
            port,
            timings: self.timings,
            evidence,
            image_checks: self.image_checks.clone(),
        };
        if propagate {
            m = m.with_model_term();
            m.evidence.spot_scale = crate::checks::evidence::spot_scale(&m);
        }
        m.timings.fit_s = t.elapsed().as_secs_f64();
        Ok(m)
    }

    /// True when every channel gave constrained parameters.
    pub fn complete(&self) -> bool {
        self.fits.iter().all(ChannelOutcome::is_measurement)
    }

    /// η with the spectrophotometer's standard error (none when η was given).
    pub fn eta(&self) -> Estimate {
        self.spectro.eta_estimate()
    }

    /// The data checks' verdict per channel ([`crate::checks::quality`]): the fits' checks and
    /// the sample's, with the image checks made at measurement ([`Measurement::image_checks`]).
    pub fn quality(&self) -> Rgb<crate::checks::Quality> {
        crate::checks::quality(self)
    }

    /// The result file's content. `profile_file` is the profile CSV's name as written beside the
    /// result (recorded in `inputs.profile`). The inputs' SHA-256 hashes are those the stages
    /// recorded of the bytes they read and measured (the manifest, the spectrophotometer file, the
    /// radiance map, each frame); no file is read here, so a file replaced after the measurement
    /// is recorded as it was measured.
    pub fn to_result(&self, profile_file: Option<&str>) -> MeasurementResult {
        let m = &self.manifest;
        let record = |path: &Path, sha256: Option<&String>| -> Option<FileRef> {
            sha256.map(|sha256| FileRef {
                path: path.to_string_lossy().into_owned(),
                sha256: sha256.clone(),
            })
        };
        // Paths relative to the sample folder, as the manifest names them.
        let relative = |p: &Path| p.strip_prefix(&m.dir).unwrap_or(p).to_path_buf();
        let manifest_ref = m
            .read_from
            .as_ref()
            .and_then(|f| record(&relative(&f.path), Some(&f.sha256)));
        let spectro_ref = m
            .spectro
            .file
            .as_deref()
            .and_then(|p| record(p, self.spectro.file_sha256.as_ref()));
        let hdr_ref = m
            .camera
            .hdr
            .as_deref()
            .and_then(|p| record(p, self.hdr.radiance_file.as_ref().map(|f| &f.sha256)));
        let frames: Vec<FileRef> = self
            .hdr
            .frames
            .iter()
            .filter_map(|f| record(&relative(&f.file), Some(&f.sha256)))
            .collect();
        let quality = crate::checks::quality(self);
        let channels = self.fits.as_ref().map_with_channel(|c, outcome| {
            let mut r = channel_result(outcome, &self.spectro, c);
            r.quality = Some(quality[c].clone());
            r
        });
        let s = &self.settings;
        MeasurementResult {
            schema_version: scatterfit_io::result_json::SCHEMA_VERSION,
            name: m.display_name(),
            eta: self.spectro.eta,
            eta_source: Some(self.spectro.eta_source),
            eta_stderr: self.spectro.uncertainty.eta_stderr,
            spectro_repeatability: Some(self.spectro.uncertainty.repeatability),
            method: s.method,
            model: s.model,
            albedo_model: Some(AlbedoSource::Model(s.albedo_model)),
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
                options: RunOptions {
                    method: Some(s.method),
                    model: Some(s.model),
                    albedo_model: Some(s.albedo_model),
                    normalise_with_spectro: Some(s.normalise_with_spectro),
                    g: Some(s.g),
                    r_min_mm: Some(s.r_min_mm()),
                    r_max_px: Some(m.fit.r_max_px.unwrap_or(300.0)),
                    spot_radius_mm: Some(s.spot_radius_mm),
                    response: Some(self.hdr.response_kind),
                    // JSON has no NaN: an unknown limit is null.
                    detection_limit: Some(
                        self.profile
                            .detection_limit
                            .iter()
                            .map(|v| v.is_finite().then_some(*v))
                            .collect(),
                    ),
                    camera: Some(serde_json::json!({
                        "corrections": self.hdr.corrections,
                        "background": self.profile.background,
                    })),
                },
            },
            version: env!("CARGO_PKG_VERSION").into(),
            // The spectrum as the port let the instrument read it, corrected like the channels.
            rd_spectrum: rd_spectrum(self.spectro.analysis.as_ref()).map(|s| {
                self.port
                    .as_ref()
                    .and_then(|p| crate::port::correct_spectrum(&s, &p.reading_fraction))
                    .unwrap_or(s)
            }),
            g_uncertainty: Some(g_record(s, &self.fits)),
            spectro_port: self
                .port
                .as_ref()
                .map(|p| scatterfit_io::result_json::PortResult {
                    aperture_mm: p.aperture_mm,
                    illuminated_mm: p.illuminated_mm,
                    rd_read: p.read.rd,
                    reading_fraction: p.reading_fraction,
                    problems: p.problems.clone(),
                }),
        }
    }
}

/// The result's record of how g entered ([`scatterfit_io::result_json::GUncertainty`]), with
/// each channel's fit of g for `g = "fit"` (from `fits`).
pub fn g_record(
    settings: &FitSettings,
    fits: &Rgb<ChannelOutcome>,
) -> scatterfit_io::result_json::GUncertainty {
    match GPlan::new(&settings.g_prior, settings.g) {
        Ok(Some(plan)) => {
            let mut record = plan.record(&settings.g_prior);
            if settings.g_prior.fit {
                record.fitted = Some(fits.as_ref().map(|f| {
                    f.fit()
                        .and_then(|f| f.g_fit.as_ref())
                        .map(crate::anisotropy_fit::GFit::record)
                }));
            }
            record
        }
        Ok(None) => known_g_record(settings.g),
        // No plan: the range, nothing evaluated (the channels' notes say why).
        Err(e) => scatterfit_io::result_json::GUncertainty {
            source: settings.g_prior.source(),
            g: Some(settings.g),
            range: settings.g_prior.propagated_range(),
            evaluated: Vec::new(),
            not_covered: Some(e.to_string()),
            fitted: None,
        },
    }
}

/// The SCE spectrum the channels' Rd came from (spectral renderers need it), when the
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
/// regular file, larger than the memory budget): for a file that is not otherwise read, such as
/// `batch`'s check of a sample's inputs against the hashes its `result.json` recorded. A
/// measurement's own inputs are hashed as they are read (`Measurement::to_result`).
pub fn hash_file(path: &Path) -> Option<String> {
    let bytes =
        scatterfit_safefs::read::read_limited(path, scatterfit_io::budget::memory_budget_bytes())
            .ok()?;
    Some(scatterfit_io::digest::sha256_hex(&bytes))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A range in a grid's gap is refused naming what the tables cover (the grid's own
    /// description, so it follows new tables), not a list written into the message. The shipped
    /// grid has no gap in 0–0.95 since the g 0.3/0.5/0.7 tables (2026-11-27), so the grid here is
    /// the shipped one without them: g = 0 and 0.8–0.95.
    #[test]
    fn a_range_the_tables_miss_names_what_they_cover() {
        let grid = scatterfit_mc::bundled_grid()
            .unwrap()
            .with_nodes(|g| g == 0.0 || g >= 0.8)
            .unwrap();
        let prior = GPrior {
            g: None,
            range: Some([0.3, 0.6]),
            fit: false,
        };
        let message = values_g_on(&grid, &prior).unwrap_err().to_string();
        assert!(message.contains("[0.3, 0.6]"), "{message}");
        assert!(message.contains(&grid.coverage()), "{message}");
        assert!(message.contains("0.95"), "{message}");
        // The shipped grid answers it; a range reaching a covered g is accepted on both.
        assert!(values_g(&prior).is_ok());
        let reaching = GPrior {
            g: None,
            range: Some([0.3, 0.85]),
            fit: false,
        };
        assert!(values_g_on(&grid, &reaching).is_ok());
    }
}
