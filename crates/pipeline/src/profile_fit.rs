//! Fitting a profile a user already has (`scatterfit fit`): the three channels of a profile table
//! with η and, for the proposed method, α′ given rather than read — no spectrophotometer, so no
//! spectrophotometer part in the uncertainties.

use scatterfit_fit::ProfileData;
use scatterfit_io::result_json::{AlbedoSource, Inputs, MeasurementResult, RunOptions};
use scatterfit_optics::{AlbedoModel, Method, ModelFamily, ModelName, Rgb};

use crate::anisotropy::AlbedoAtG;
use crate::error::Result;
use crate::fit::{ChannelOutcome, FitSettings, channel_result, fit_stage, with_g_term};
use crate::spectro::SpectroStage;

/// What to fit a given profile with.
#[derive(Debug, Clone, PartialEq)]
pub struct ProfileFitRequest {
    /// The result's name (e.g. the profile file's stem).
    pub name: String,
    /// The profile file, as recorded in the result's `inputs.profile`.
    pub profile_file: Option<String>,
    /// The relative refractive index η.
    pub eta: f64,
    /// α′ per channel (the proposed method needs it).
    pub albedo_prime: Option<Rgb<f64>>,
    /// The spectrophotometer's Rd per channel (for normalising with it); default: the model's
    /// total Rd of the given α′.
    pub rd: Option<Rgb<f64>>,
    /// proposed | existing.
    pub method: Method,
    /// The forward model.
    pub model: ModelName,
    /// The light spot's diameter \[mm\]; the model is convolved with it.
    pub spot_diameter_mm: f64,
    /// The innermost fitted radius \[mm\] (default: the spot's diameter).
    pub r_min_mm: Option<f64>,
    /// Fix the profile's scale by Rd (proposed method).
    pub normalise_with_spectro: bool,
    /// What is known about g (`--g`, `--g-range`): the values' g and the g term, as for
    /// a measurement ([`crate::anisotropy`]). With `rd` the term's α′ is inverted from it at each
    /// g; without, α′ is held at the given value and the term is the profile's part only.
    pub g_prior: crate::anisotropy::GPrior,
}

/// A given profile, fitted.
#[derive(Debug, Clone)]
pub struct ProfileFit {
    /// What was asked.
    pub request: ProfileFitRequest,
    /// The fit settings used.
    pub settings: FitSettings,
    /// The given η, α′ and Rd, as the fit took them.
    pub spectro: SpectroStage,
    /// Per channel: σ′s, σa with the fit's standard errors, the report, or why not fitted.
    pub fits: Rgb<ChannelOutcome>,
}

/// Fits the three channels of `profile` as `request` says.
///
/// # Errors
/// [`crate::PipelineError::Input`] when the model cannot be loaded. Channels that cannot be fitted
/// are [`ChannelOutcome::NotFitted`].
pub fn fit_profile(profile: &Rgb<ProfileData>, request: &ProfileFitRequest) -> Result<ProfileFit> {
    request.g_prior.check()?;
    crate::measure::check_g_fit(&request.g_prior, request.model)?;
    let g = crate::measure::values_g(&request.g_prior)?;
    // A g — or an η at that g — the Monte Carlo tables do not cover is refused here, before any
    // fit, as a manifest's g is (the family itself would only answer NaN, and every channel's fit
    // would fail obscurely). η is probed with a model at a mid albedo: the tables' η range does
    // not depend on it.
    if request.model == scatterfit_optics::ModelName::Mc {
        let grid = scatterfit_mc::bundled_grid()?;
        grid.albedo_prime_range(g)
            .map_err(|e| crate::PipelineError::Input(e.to_string()))?;
        let probe = scatterfit_optics::OpticalProperties::new(0.9, 0.1, request.eta)
            .and_then(|p| p.with_g(g))
            .map_err(|e| crate::PipelineError::Input(format!("--eta {}: {e}", request.eta)))?;
        grid.profile(&probe).map_err(|e| {
            crate::PipelineError::Input(format!(
                "--eta {}: the `mc` tables at g = {g} do not reach it ({e}); they cover {}",
                request.eta,
                grid.coverage()
            ))
        })?;
    }
    let model = scatterfit_optics::AtG::new(scatterfit_mc::family(request.model)?, g)
        .map_err(|e| crate::PipelineError::Input(format!("g: {e}")))?;
    let model = &model;
    let albedo = request.albedo_prime.map_or(Rgb::default(), |a| a.map(Some));
    let rd = request.rd.unwrap_or_else(|| {
        albedo.map(|a| {
            a.map_or(f64::NAN, |a| {
                model.rd_total(a, request.eta, g).unwrap_or(f64::NAN)
            })
        })
    });
    let spectro = SpectroStage::given(request.eta, rd, albedo);
    let settings = FitSettings {
        method: request.method,
        model: request.model,
        albedo_model: AlbedoModel::Diffusion,
        spot_radius_mm: 0.5 * request.spot_diameter_mm,
        spot: crate::fit::SpotShape::Disk,
        r_min_mm: request.r_min_mm,
        normalise_with_spectro: request.normalise_with_spectro,
        g,
        g_prior: request.g_prior,
    };
    let fits = fit_stage(profile, &spectro, &settings, model);
    let albedo_at_g = if request.rd.is_some() {
        AlbedoAtG::FromRd
    } else {
        AlbedoAtG::Fixed
    };
    let fits = with_g_term(profile, &spectro, &settings, fits, albedo_at_g);
    Ok(ProfileFit {
        request: request.clone(),
        settings,
        spectro,
        fits,
    })
}

impl ProfileFit {
    /// True when every channel gave constrained parameters.
    pub fn complete(&self) -> bool {
        self.fits.iter().all(ChannelOutcome::is_measurement)
    }

    /// The result in `result.json`'s shape: η and α′ `given`, no input hashes.
    pub fn to_result(&self) -> MeasurementResult {
        let s = &self.settings;
        MeasurementResult {
            name: self.request.name.clone(),
            eta: self.request.eta,
            eta_source: Some(crate::spectro::EtaSource::Given),
            eta_stderr: None,
            spectro_repeatability: None,
            method: s.method,
            model: s.model,
            albedo_model: Some(AlbedoSource::Given),
            channels: self.fits.as_ref().map_with_channel(|c, outcome| {
                // The fit's own checks (no image here: the residuals and the ranges).
                let mut r = channel_result(outcome, &self.spectro, c);
                r.quality = Some(crate::checks::Quality::from_reasons(
                    crate::checks::fit_reasons(outcome, self.request.eta),
                ));
                r
            }),
            inputs: Inputs {
                profile: self.request.profile_file.clone(),
                spot_radius_mm: Some(s.spot_radius_mm),
                options: RunOptions {
                    method: Some(s.method),
                    model: Some(s.model),
                    normalise_with_spectro: Some(s.normalise_with_spectro),
                    r_min_mm: Some(s.r_min_mm()),
                    g: Some(s.g),
                    ..RunOptions::default()
                },
                ..Inputs::default()
            },
            version: env!("CARGO_PKG_VERSION").into(),
            rd_spectrum: None,
            spectro_port: None,
            g_uncertainty: Some(crate::measure::g_record(s, &self.fits)),
        }
    }
}
