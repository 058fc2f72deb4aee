//! Fitting a profile a user already has (`scatterfit fit`): the three channels of a profile table
//! with η and, for the proposed method, α′ given rather than read — no spectrophotometer, so no
//! spectrophotometer part in the uncertainties.

use scatterfit_fit::ProfileData;
use scatterfit_io::result_json::{AlbedoSource, Inputs, MeasurementResult, RunOptions};
use scatterfit_optics::{AlbedoModel, Method, ModelFamily, ModelName, Rgb};

use crate::anisotropy::record::AlbedoAtG;
use crate::anisotropy::with_g_term;
use crate::error::Result;
use crate::fit::outcome::ChannelOutcome;
use crate::fit::{channel_result, fit_stage};
use crate::settings::{FitPlan, FitSettings};
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
    /// α′ per channel (the proposed method needs it, or `rd` to invert it from).
    pub albedo_prime: Option<Rgb<f64>>,
    /// The spectrophotometer's total diffuse reflectance Rd per channel. Without `albedo_prime`,
    /// α′ is inverted from it through the fit's model at η and g (as a measurement inverts the
    /// spectrophotometer's Rd); with it, the two must agree through that model
    /// ([`MAX_RD_DISAGREEMENT`]). Default: the model's total Rd of the given α′.
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
    pub g_prior: crate::anisotropy::plan::GPrior,
}

/// How far (absolute, in Rd) a given Rd may lie from the fit model's total Rd of the given α′
/// before the two are refused as contradictory: 1 % of full reflectance, about what a d/8
/// instrument's repeatability and the models' own spread near α′ = 1 allow; a pair further apart
/// is two different materials' numbers or two different albedo models, and either way one of
/// them would be silently ignored.
pub const MAX_RD_DISAGREEMENT: f64 = 0.01;

impl ProfileFitRequest {
    /// The request's own rules, checked before any fit: η in [1, 3], a spot diameter in
    /// (0, 20] mm, α′ in (0, 1] and Rd in (0, 1] per channel, the innermost radius in [0, 1000) mm,
    /// and α′ or Rd given for the proposed method (which holds α′ fixed).
    ///
    /// # Errors
    /// [`crate::PipelineError::Input`] naming the value and the rule.
    pub fn check(&self) -> Result<()> {
        let bad = |what: &str, v: f64, rule: &str| {
            Err(crate::PipelineError::Input(format!(
                "{what} {}: {rule}",
                scatterfit_io::escape::number(v)
            )))
        };
        if !(self.eta.is_finite() && (1.0..=3.0).contains(&self.eta)) {
            return bad(
                "eta",
                self.eta,
                "the relative refractive index must lie in [1, 3]",
            );
        }
        if !(self.spot_diameter_mm > 0.0 && self.spot_diameter_mm <= 20.0) {
            return bad(
                "spot diameter",
                self.spot_diameter_mm,
                "must lie in (0, 20] mm",
            );
        }
        if self.method == Method::Proposed && self.albedo_prime.is_none() && self.rd.is_none() {
            return Err(crate::PipelineError::Input(
                "the proposed method needs the reduced albedo α′ per channel (from `scatterfit \
                 spectro`; `--albedo R,G,B`, in Python `albedo=`), or the spectrophotometer's Rd \
                 per channel to invert it from (`--rd R,G,B`, `rd=`); or fit with the existing \
                 method (`--method existing`)"
                    .into(),
            ));
        }
        if let Some(a) = self.albedo_prime
            && let Some(v) = a
                .into_array()
                .into_iter()
                .find(|v| !(*v > 0.0 && *v <= 1.0))
        {
            return bad("albedo", v, "outside (0, 1] (a reduced albedo σ′s/σ′t)");
        }
        if let Some(rd) = self.rd
            && let Some(v) = rd
                .into_array()
                .into_iter()
                .find(|v| !(*v > 0.0 && *v <= 1.0))
        {
            return bad(
                "rd",
                v,
                "outside (0, 1] (a diffuse reflectance, a fraction)",
            );
        }
        if let Some(r) = self.r_min_mm
            && !(0.0..1000.0).contains(&r)
        {
            return bad(
                "r_min_mm",
                r,
                "the innermost fitted radius must lie in [0, 1000) mm",
            );
        }
        Ok(())
    }
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
    request.check()?;
    request.g_prior.check()?;
    crate::settings::check_g_fit(&request.g_prior, request.model)?;
    let g = crate::settings::values_g(&request.g_prior)?;
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
    let albedo = given_albedo(request, model, g)?;
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
        spot: crate::settings::SpotShape::Disk,
        r_min_mm: request.r_min_mm,
        normalise_with_spectro: request.normalise_with_spectro,
        g,
        g_prior: request.g_prior,
    };
    let albedo_at_g = if request.rd.is_some() {
        AlbedoAtG::FromRd
    } else {
        AlbedoAtG::Fixed
    };
    // Options the rings refuse leave every channel not fitted, saying why: no g term.
    let mut fits = match FitPlan::new(settings) {
        Ok(plan) => with_g_term(
            profile,
            &spectro,
            &plan,
            fit_stage(profile, &spectro, &plan),
            albedo_at_g,
        ),
        Err(e) => Rgb::from_fn(|_| ChannelOutcome::NotFitted {
            problem: e.to_string(),
        }),
    };
    // An approximate model's error: the same rings fitted again with exact transport (α′ as
    // given, or inverted from the given Rd through the `mc` total), |approximate − exact| the
    // `model` term of each estimate (crate::model_term).
    if request.model != ModelName::Mc {
        let exact = exact_fits(profile, request, &settings, g);
        crate::model_term::apply(
            &mut fits,
            exact.as_ref().map_err(Clone::clone),
            request.model,
        );
    }
    Ok(ProfileFit {
        request: request.clone(),
        settings,
        spectro,
        fits,
    })
}

/// The profile fitted with exact transport (values only), everything else as `settings`.
fn exact_fits(
    profile: &Rgb<ProfileData>,
    request: &ProfileFitRequest,
    settings: &FitSettings,
    g: f64,
) -> std::result::Result<Rgb<ChannelOutcome>, String> {
    let model = scatterfit_optics::AtG::new(
        scatterfit_mc::family(ModelName::Mc).map_err(|e| e.to_string())?,
        g,
    )
    .map_err(|e| e.to_string())?;
    let exact_request = ProfileFitRequest {
        model: ModelName::Mc,
        ..request.clone()
    };
    let albedo = given_albedo(&exact_request, &model, g).map_err(|e| e.to_string())?;
    let rd = request.rd.unwrap_or_else(|| {
        albedo.map(|a| {
            a.map_or(f64::NAN, |a| {
                model.rd_total(a, request.eta, g).unwrap_or(f64::NAN)
            })
        })
    });
    let spectro = SpectroStage::given(request.eta, rd, albedo);
    let plan = FitPlan::new(settings.exact()).map_err(|e| e.to_string())?;
    Ok(fit_stage(profile, &spectro, &plan))
}

/// α′ per channel from the request: as given, inverted from the given Rd through `model` at η
/// and g, or checked against the given Rd where both are given.
fn given_albedo(
    request: &ProfileFitRequest,
    model: &dyn ModelFamily,
    g: f64,
) -> Result<Rgb<Option<f64>>> {
    let eta = request.eta;
    let input = |m: String| crate::PipelineError::Input(m);
    match (request.albedo_prime, request.rd) {
        (None, None) => Ok(Rgb::default()),
        (Some(a), None) => Ok(a.map(Some)),
        (None, Some(rd)) => rd
            .map_with_channel(|c, rd| {
                model.albedo_from_rd(rd, eta, g).map(Some).map_err(|e| {
                    input(format!(
                        "--rd: channel {}: no reduced albedo of the {} model gives Rd {rd} at \
                         η {eta}, g {g} ({e})",
                        c.name(),
                        request.model.name()
                    ))
                })
            })
            .transpose(),
        (Some(a), Some(rd)) => {
            for (c, (a, rd)) in a.zip(rd).iter_channels() {
                let modelled = model
                    .rd_total(*a, eta, g)
                    .map_err(|e| input(format!("--albedo: channel {}: α′ {a}: {e}", c.name())))?;
                if (modelled - rd).abs() > MAX_RD_DISAGREEMENT {
                    return Err(input(format!(
                        "--albedo and --rd disagree in channel {}: the {} model's total Rd of \
                         α′ {a} at η {eta}, g {g} is {modelled:.4}, --rd says {rd:.4} (more than \
                         {MAX_RD_DISAGREEMENT} apart). Give one of them: α′ is inverted from \
                         --rd when --albedo is absent",
                        c.name(),
                        request.model.name()
                    )));
                }
            }
            Ok(a.map(Some))
        }
    }
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
            schema_version: scatterfit_io::result_json::SCHEMA_VERSION,
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
                let mut reasons = crate::checks::fit_reasons(outcome, self.request.eta);
                reasons.extend(crate::checks::model_reasons(outcome, s.model));
                r.quality = Some(crate::checks::Quality::from_reasons(reasons));
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
            g_uncertainty: Some(crate::result::g_record(s, &self.fits)),
        }
    }
}
