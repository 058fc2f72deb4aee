//! `measure_sample`: a sample folder in, the paper's Table 1 row out — the one place the stages
//! are assembled: [`crate::settings`] (what to fit with) → [`crate::spectro`] (η, α′) →
//! [`crate::hdr`] (the bracket merged) → [`crate::profile`] (the spot and its rings) →
//! [`crate::port`] (the spectrophotometer port's edge loss) → [`crate::fit`] (σ′s, σa per channel,
//! with the spectrophotometer's and the g terms) → [`crate::model_term`] (an approximate model's
//! error) → [`crate::checks`] (the image checks and the data's cross-checks). The refits
//! ([`Measurement::refit_with`]) rerun the stages after the profile with other settings.

use std::path::Path;
use std::time::Instant;

use scatterfit_optics::Method;
use scatterfit_optics::port::Port;

use crate::checks::evidence::{Evidence, gather};
use crate::checks::findings::SampleChecks;
use crate::checks::{image_checks, spot_scale};
use crate::error::{PipelineError, Result};
use crate::fit::background::keep_levels_that_fit;
use crate::fit::{fit_and_propagate, fit_stage, free_fits};
use crate::hdr::inputs::HdrInputs;
use crate::hdr::radiance_map::read_radiance_map;
use crate::hdr::read_and_merge;
use crate::hdr::spot_image::spot_kernel_from_image;
use crate::measurement::{Measurement, Stage, Timings};
use crate::model_term;
use crate::port::{correct_port, port_of, propagate_fit_through_port};
use crate::profile::{ProfileSettings, profile_stage_with};
use crate::samples::{SampleInputs, sample_inputs};
use crate::settings::{FitPlan, FitSettings, Overrides, fit_plan};
use crate::spectro::spectro_stage;

/// Measures the sample in folder `dir` (its `sample.toml`): [`sample_inputs`], then
/// [`measure_inputs`].
///
/// # Errors
/// [`PipelineError`] for bad input (exit 2) or a stage that failed (exit 1, see
/// [`PipelineError::is_measurement_failure`]). Channels that cannot be fitted are not errors: they
/// are [`ChannelOutcome::NotFitted`](crate::ChannelOutcome::NotFitted) in the result.
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
    let plan = fit_plan(&manifest, overrides)?;
    begin(Stage::Spectro)?;
    let spectro = spectro_stage(&manifest, overrides.eta, &plan.albedo)?;
    let spectro_s = t0.elapsed().as_secs_f64();
    let hdr = match &manifest.camera.hdr {
        Some(p) => read_radiance_map(&manifest.resolve(p))?,
        None => {
            let inputs = HdrInputs::from_manifest(&manifest);
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
    let plan = match &manifest.camera.spot_image {
        Some(p) => {
            let (scale, diameter) = (
                manifest.camera.mm_per_pixel.unwrap_or(f64::NAN),
                manifest.camera.spot_diameter_mm.unwrap_or(1.0),
            );
            let spot = spot_kernel_from_image(&manifest.resolve(p), &hdr, scale, diameter)?;
            plan.with_spot(spot)?
        }
        None => plan,
    };
    // A level the profile stage subtracted stays subtracted only where exact transport prefers it.
    let profile = keep_levels_that_fit(profile, &hdr.detection_limit, &spectro, &plan);
    let profile_s = t_profile.elapsed().as_secs_f64();
    let data = profile.rgb_data()?;
    begin(Stage::Fit)?;
    let t_fit = Instant::now();
    let port = port_of(
        manifest.spectro.aperture_mm,
        manifest.spectro.illuminated_mm,
    )?;
    let (spectro, port) = match port {
        Some(p) => {
            let (mut s, c) = correct_port(&data, &spectro, &plan, p);
            if let Some([lo, hi]) = plan.settings.g_prior.propagated_range() {
                // The g term refits at each g from the Rd corrected here, at the values' g; the
                // port's F is not recomputed at each g (BENCHMARKS.md, "The port's
                // conditioning"): say so rather than let the term look complete.
                s.warnings.push(format!(
                    "the port correction used F of the model at g = {}; the ± g term (g in \
                     {lo}–{hi}) keeps that corrected Rd, but F itself changes with g (by 2–9 % \
                     between g = 0 and 0.8 at α′ ≥ 0.99 behind an 8 mm port), so with a port the \
                     g term understates; give [fit] g if it is known",
                    plan.settings.g
                ));
            }
            (s, Some(c))
        }
        None => (spectro, None),
    };
    let fits = fit_and_propagate(&data, &spectro, &plan);
    let fits = match &port {
        Some(c) => propagate_fit_through_port(&data, &spectro, &plan, c, fits),
        None => fits,
    };
    // With an approximate model the evidence comes from exact transport's fits
    // (`Measurement::with_model_term`): the model's own error would confound it.
    let evidence = if plan.settings.is_approximate() {
        Evidence::default()
    } else {
        gather(&spectro, &fits, free_fits(&data, &spectro, &plan).as_ref())
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
        settings: plan.settings,
        spectro,
        hdr,
        profile,
        fits,
        port,
        timings,
        evidence,
        image_checks: SampleChecks::default(),
    }
    .with_model_term();
    m.timings.fit_s = t_fit.elapsed().as_secs_f64();
    begin(Stage::Checks)?;
    let t_checks = Instant::now();
    m.image_checks = image_checks(&m);
    m.evidence.spot_scale = spot_scale(&m);
    m.timings.checks_s = t_checks.elapsed().as_secs_f64();
    m.timings.total_s = t0.elapsed().as_secs_f64();
    Ok(m)
}

impl Measurement {
    /// The same sample fitted with another method (the spectrophotometer stage, the merge and the
    /// profile are reused): what `compare` needs.
    ///
    /// # Errors
    /// [`PipelineError::Input`] as [`fit_settings`](crate::fit_settings).
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
        let plan = FitPlan::new(settings)?;
        let t = Instant::now();
        let data = self.profile.rgb_data()?;
        // The port correction depends on the model: start again from the reading.
        let (spectro, port) = match &self.port {
            Some(p) => {
                let port = Port::new(p.illuminated_mm, p.aperture_mm).map_err(|e| {
                    PipelineError::Input(format!("the spectrophotometer port: {e}"))
                })?;
                let read = p.read.with_albedo_model(&plan.albedo);
                let (s, c) = correct_port(&data, &read, &plan, port);
                (s, Some(c))
            }
            None => (self.spectro.with_albedo_model(&plan.albedo), None),
        };
        let fits = if propagate {
            let fits = fit_and_propagate(&data, &spectro, &plan);
            match &port {
                Some(c) => propagate_fit_through_port(&data, &spectro, &plan, c, fits),
                None => fits,
            }
        } else {
            fit_stage(&data, &spectro, &plan)
        };
        let evidence = if propagate && !settings.is_approximate() {
            gather(&spectro, &fits, free_fits(&data, &spectro, &plan).as_ref())
        } else {
            Evidence::default()
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
            m.evidence.spot_scale = spot_scale(&m);
        }
        m.timings.fit_s = t.elapsed().as_secs_f64();
        Ok(m)
    }

    /// The measurement with every fitted channel's `model` term (module docs): nothing changes
    /// with exact transport itself; with an approximate model the same data are fitted again
    /// with the `mc` tables (values only) and |approximate − exact| is the term of σ′s, σa and α′.
    /// Where exact transport cannot be evaluated (outside the tables' η or α′, a refit that does
    /// not converge) the channel keeps no term and a note that says why.
    #[must_use]
    pub fn with_model_term(mut self) -> Self {
        if !self.settings.is_approximate() {
            return self;
        }
        let exact = self.refit_values_only(self.settings.exact());
        // The data's cross-checks from exact transport's fits (an approximate model's own error
        // would read as a disagreement between the profile and the reading).
        if let Ok(x) = &exact
            && let Ok(data) = x.profile.rgb_data()
            && let Ok(plan) = FitPlan::new(x.settings)
        {
            self.evidence = gather(
                &x.spectro,
                &x.fits,
                free_fits(&data, &x.spectro, &plan).as_ref(),
            );
        }
        let exact = exact.as_ref().map(|m| &m.fits).map_err(ToString::to_string);
        model_term::apply(&mut self.fits, exact, self.settings.model);
        self
    }
}
