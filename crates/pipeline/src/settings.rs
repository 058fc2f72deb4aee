//! How a sample is fitted: the manifest's `[fit]` and `[camera]` keys and a caller's
//! [`Overrides`] resolved into one [`FitSettings`] — the method, the forward model and the albedo
//! model, the spot, the rings and what is known about g ([`crate::anisotropy::GPrior`]).

use scatterfit_fit::{FitOptions, Spot};
use scatterfit_io::manifest::SampleManifest;
use scatterfit_mc::{albedo_family, family};
use scatterfit_optics::{AlbedoModel, AtG, Method, ModelName};

use crate::anisotropy::plan::{GPlan, GPrior};
use crate::error::{PipelineError, Result};

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

/// How to fit a sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FitSettings {
    /// proposed | existing.
    pub method: Method,
    /// The forward model (`scatterfit_mc::family` makes it).
    pub model: ModelName,
    /// How α′ comes from the spectrophotometer's Rd (`scatterfit_mc::albedo_family`).
    pub albedo_model: AlbedoModel,
    /// Radius of the light spot \[mm\]; the model is convolved with it. For a radial spot
    /// (`spot`), the radius holding 99 % of its power (which sets the default r_min).
    pub spot_radius_mm: f64,
    /// The spot's shape: a uniform disk of `spot_radius_mm`, or a radial profile (a Gaussian, a
    /// measured spot image).
    pub spot: SpotShape,
    /// Innermost fitted radius \[mm\] (default: the spot's diameter).
    pub r_min_mm: Option<f64>,
    /// Fix the profile's scale by the spectrophotometer (proposed only).
    pub normalise_with_spectro: bool,
    /// The Henyey–Greenstein g the model and the α′ inversion are evaluated at: the manifest's
    /// `[fit] g`; for a `[fit] g_range` without a g the covered g nearest the range's middle
    /// ([`GPlan::nominal_g`]); else 0 (`scatterfit_optics::AtG`).
    pub g: f64,
    /// What is known about g (`[fit] g`, `[fit] g_range`): decides the g uncertainty term
    /// ([`crate::anisotropy`]).
    pub g_prior: GPrior,
}

/// The light spot's shape in [`FitSettings`].
// Inline disks keep the settings `Copy` (see `scatterfit_fit::Spot`).
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum SpotShape {
    /// A uniform disk of [`FitSettings::spot_radius_mm`] (the paper's).
    #[default]
    Disk,
    /// A radial spot as a mixture of disks (`camera.spot_profile = "gaussian"`, `camera.spot_image`).
    Radial(scatterfit_fit::RadialSpot),
}

impl FitSettings {
    /// The options of `scatterfit_fit` for these settings.
    ///
    /// # Errors
    /// [`PipelineError::Input`] for a spot radius or r_min the ring selection refuses (the
    /// manifest and the commands check both before).
    pub fn options(&self) -> Result<FitOptions> {
        let mut o = FitOptions::new(self.method);
        o.spot = match self.spot {
            SpotShape::Disk => Spot::Disk {
                radius_mm: self.spot_radius_mm,
            },
            SpotShape::Radial(s) => Spot::Radial(s),
        };
        let selection = scatterfit_fit::RingSelection::for_spot(self.spot_radius_mm);
        o.selection = match self.r_min_mm {
            Some(r) => selection.and_then(|s| s.with_r_min_mm(r)),
            None => selection,
        }
        .map_err(|e| PipelineError::Input(format!("the fitted rings: {e}")))?;
        o.normalise_with_spectro = self.normalise_with_spectro;
        Ok(o)
    }

    /// The spot's half width at half maximum \[mm\]: a disk's radius, a radial spot's
    /// [`RadialSpot::half_maximum_radius`](scatterfit_fit::RadialSpot::half_maximum_radius) (a
    /// Gaussian's 0.589 w, where its 99 % radius, `spot_radius_mm`, is 1.52 w).
    pub fn spot_half_width_mm(&self) -> f64 {
        match self.spot {
            SpotShape::Disk => self.spot_radius_mm,
            SpotShape::Radial(s) => s.half_maximum_radius(),
        }
    }

    /// The innermost fitted radius \[mm\]: the given one, else the spot's diameter.
    pub fn r_min_mm(&self) -> f64 {
        self.r_min_mm.unwrap_or(2.0 * self.spot_radius_mm)
    }
}

/// Resolves the fit settings from the manifest and the overrides.
///
/// # Errors
/// [`PipelineError::Input`] for a model that is not available or normalisation with the existing
/// method.
pub fn fit_settings(manifest: &SampleManifest, o: &Overrides) -> Result<FitSettings> {
    settings_from(manifest, o)
}

/// The manifest's and the overrides' [`FitPlan`]: [`fit_settings`] with what they make.
///
/// # Errors
/// As [`fit_settings`], and [`FitPlan::new`]'s.
pub(crate) fn fit_plan(manifest: &SampleManifest, o: &Overrides) -> Result<FitPlan> {
    FitPlan::new(settings_from(manifest, o)?)
}

/// The fit settings of a manifest and a caller's overrides.
fn settings_from(manifest: &SampleManifest, o: &Overrides) -> Result<FitSettings> {
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

/// Fit settings resolved for the stages, once: the settings, the options of `scatterfit_fit` they
/// make ([`FitSettings::options`]) and the profile and albedo models at their g (`scatterfit_mc::family`, `albedo_family`).
/// Every stage from the port on takes the plan by reference, so none resolves the settings again.
#[derive(Clone, Copy)]
pub struct FitPlan {
    /// What was asked.
    pub settings: FitSettings,
    /// The fit's options for [`FitPlan::settings`] (no start: each fit and refit sets its own).
    pub options: FitOptions,
    /// The forward model at the settings' g.
    pub model: AtG<'static>,
    /// The albedo model (Rd → α′) at the settings' g.
    pub albedo: AtG<'static>,
}

impl FitPlan {
    /// The plan of `settings`.
    ///
    /// # Errors
    /// [`PipelineError::Input`] for a model the tables cannot give at the settings' g, or a spot
    /// radius or r_min the ring selection refuses.
    pub fn new(settings: FitSettings) -> Result<Self> {
        let (model, albedo) = families(&settings)?;
        Ok(Self {
            settings,
            options: settings.options()?,
            model,
            albedo,
        })
    }

    /// The plan with a radial spot (a measured spot image) of `radius_mm` enclosing 99 % of its
    /// power in place of the manifest's spot.
    ///
    /// # Errors
    /// As [`FitPlan::new`]: the ring selection refuses the spot's radius.
    pub fn with_spot(self, spot: scatterfit_fit::RadialSpot) -> Result<Self> {
        let mut settings = self.settings;
        settings.spot = SpotShape::Radial(spot);
        settings.spot_radius_mm = spot.radius_enclosing(0.99);
        Ok(Self {
            settings,
            options: settings.options()?,
            ..self
        })
    }
}

/// The profile model and the albedo model of a [`FitSettings`], at its g.
pub(crate) type Families = (AtG<'static>, AtG<'static>);

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
pub(crate) fn families(settings: &FitSettings) -> Result<Families> {
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

impl FitSettings {
    /// Whether these settings use an approximate model for the profile or for α′ (then
    /// [`crate::model_term`] measures its error against exact transport).
    pub fn is_approximate(&self) -> bool {
        self.model != ModelName::Mc || self.albedo_model != AlbedoModel::Mc
    }

    /// These settings with exact transport for the profile and for α′ (method, g, spot and rings
    /// as chosen).
    #[must_use]
    pub fn exact(&self) -> FitSettings {
        FitSettings {
            model: ModelName::Mc,
            albedo_model: AlbedoModel::Mc,
            ..*self
        }
    }
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
