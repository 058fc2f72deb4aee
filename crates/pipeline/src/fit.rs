//! Stage 4: the fit per channel, and its conversion into the result file's shape.

use scatterfit_fit::{ChannelInput, FitOptions, FitReport, PreparedFit, ProfileData, Spot, Start};
use scatterfit_io::result_json::{ChannelResult, ChannelStatus, Correlation};
use scatterfit_optics::{AlbedoModel, Channel, Estimate, Method, ModelFamily, ModelName, Rgb};
use serde::Serialize;

use crate::anisotropy::{AlbedoAtG, GPlan, GPrior, GTerm, propagate_g};
use crate::error::{PipelineError, Result};
use crate::spectro::SpectroStage;

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

    /// The innermost fitted radius \[mm\]: the given one, else the spot's diameter.
    pub fn r_min_mm(&self) -> f64 {
        self.r_min_mm.unwrap_or(2.0 * self.spot_radius_mm)
    }
}

/// Exact transport's fit of a channel measured with an approximate model.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ExactFit {
    /// σ′s \[mm⁻¹\].
    pub sigma_s_prime: f64,
    /// σa \[mm⁻¹\].
    pub sigma_a: f64,
    /// α′.
    pub albedo_prime: f64,
    /// χ² per degree of freedom of its fit to the same rings.
    pub chi2_reduced: f64,
    /// Its fitted scale k (measured = k · model).
    pub scale: f64,
}

/// A fitted channel: the solver's report and the measured values with their uncertainty terms.
#[derive(Debug, Clone, Serialize)]
pub struct ChannelFit {
    /// What the solver did and reached (rings, residuals, correlations, its own standard errors).
    pub report: FitReport,
    /// σ′s \[mm⁻¹\]: the fit's value with the fit's standard error and, once propagated
    /// ([`propagate_spectro`]), the spectrophotometer's.
    pub sigma_s_prime: Estimate,
    /// σa \[mm⁻¹\], with the same terms.
    pub sigma_a: Estimate,
    /// α′: the spectrophotometer's (proposed method, with its standard error) or the one the
    /// fitted σ′s and σa give (existing method, no spectro term); both with the g term.
    pub albedo_prime: Estimate,
    /// What the user should know about the g term (g where it could not be evaluated, or why
    /// there is none).
    pub g_note: Option<String>,
    /// Why the g term of an unknown g covers only part of its range, or none of it (the `mc`
    /// tables do not answer at some g for this material): the channel is then suspect
    /// ([`crate::checks::fit_reasons`], `g_term_incomplete`). `None` when g is known or the term
    /// is whole.
    pub g_term_gap: Option<String>,
    /// With `g = "fit"`: the fit of g ([`crate::anisotropy_fit`]), determined or not.
    pub g_fit: Option<crate::anisotropy_fit::GFit>,
    /// With an approximate forward model: exact transport's fit of the same data
    /// ([`crate::model_term`]), whose distance from this one is each estimate's `model` term.
    pub exact: Option<ExactFit>,
    /// With an approximate forward model: why exact transport could not be evaluated (the
    /// estimates then have no `model` term and the channel is suspect).
    pub model_note: Option<String>,
}

impl ChannelFit {
    /// The report of a channel fitted with `method`, α′'s standard error from the reading
    /// (`albedo_prime_stderr`, used by the proposed method only); no spectrophotometer term yet.
    pub fn new(report: FitReport, albedo_prime_stderr: Option<f64>) -> Self {
        let estimate = |e: scatterfit_fit::FittedValue| Estimate {
            value: e.value,
            fit: finite(e.stderr),
            spectro: None,
            g: None,
            model: None,
        };
        Self {
            sigma_s_prime: estimate(report.sigma_s_prime),
            sigma_a: estimate(report.sigma_a),
            albedo_prime: Estimate {
                value: report.albedo_prime,
                fit: None,
                // The existing method's α′ comes from its fitted coefficients, not the reading.
                spectro: albedo_prime_stderr.filter(|_| report.method == Method::Proposed),
                g: None,
                model: None,
            },
            g_note: None,
            g_term_gap: None,
            g_fit: None,
            exact: None,
            model_note: None,
            report,
        }
    }
}

/// One channel's outcome: a fit, or why there is none.
#[derive(Debug, Clone, Serialize)]
#[serde(tag = "outcome", rename_all = "snake_case")]
pub enum ChannelOutcome {
    /// The fit ran.
    Fitted(Box<ChannelFit>),
    /// No fit: the spectrophotometer gave no α′, or too few rings.
    NotFitted {
        /// Why.
        problem: String,
    },
}

impl ChannelOutcome {
    /// The fit, if it ran.
    pub fn fit(&self) -> Option<&ChannelFit> {
        match self {
            ChannelOutcome::Fitted(f) => Some(f),
            ChannelOutcome::NotFitted { .. } => None,
        }
    }

    /// The solver's report, if the fit ran.
    pub fn report(&self) -> Option<&FitReport> {
        self.fit().map(|f| &f.report)
    }

    /// σ′s with its uncertainty terms, if the fit ran (see [`ChannelOutcome::is_measurement`]
    /// for whether the data constrain it).
    pub fn sigma_s_prime(&self) -> Option<Estimate> {
        self.fit().map(|f| f.sigma_s_prime)
    }

    /// σa with its uncertainty terms, if the fit ran.
    pub fn sigma_a(&self) -> Option<Estimate> {
        self.fit().map(|f| f.sigma_a)
    }

    /// True when the channel gave parameters the data constrain.
    pub fn is_measurement(&self) -> bool {
        self.report().is_some_and(FitReport::is_measurement)
    }

    /// The same outcome with the spectrophotometer's part of σ′s's and σa's uncertainty
    /// ([`propagate_spectro`]; `None` leaves it unknown).
    #[must_use]
    pub fn with_spectro(mut self, errors: Option<SpectroErrors>) -> Self {
        if let (ChannelOutcome::Fitted(f), Some(e)) = (&mut self, errors) {
            f.sigma_s_prime.spectro = finite(e.sigma_s_prime);
            f.sigma_a.spectro = finite(e.sigma_a);
        }
        self
    }
}

impl ChannelOutcome {
    /// The same outcome with the g term ([`crate::anisotropy`]): `None` (known g) sets every term
    /// to 0; a term sets σ′s's, σa's and α′'s, and for a range without a g with the `mc` model
    /// replaces the values by the middle of the estimates over the range; an error leaves the
    /// terms unknown and says why.
    #[must_use]
    pub fn with_g(mut self, term: Option<std::result::Result<GTerm, String>>) -> Self {
        let ChannelOutcome::Fitted(f) = &mut self else {
            return self;
        };
        match term {
            None => {
                f.sigma_s_prime.g = Some(0.0);
                f.sigma_a.g = Some(0.0);
                f.albedo_prime.g = Some(0.0);
            }
            Some(Err(why)) => {
                f.g_term_gap = Some(why.clone());
                f.g_note = Some(why);
            }
            Some(Ok(t)) => {
                f.g_term_gap.clone_from(&t.note);
                f.sigma_s_prime.g = finite(t.sigma_s_prime);
                f.sigma_a.g = finite(t.sigma_a);
                f.albedo_prime.g = finite(t.albedo_prime);
                if t.centre_applies {
                    f.sigma_s_prime.value = t.centre[0];
                    f.sigma_a.value = t.centre[1];
                    f.albedo_prime.value = t.centre[2];
                }
                f.g_note = t.note;
            }
        }
        self
    }
}

impl ChannelOutcome {
    /// The same outcome with g fitted (`g = "fit"`, [`crate::anisotropy_fit`]): where the data
    /// determine g, the fit at ĝ replaces the report and the values (the spectrophotometer's term
    /// stays the one computed at the settings' g), and the g term is how far the values move over
    /// ĝ ± sd(g); where not, `fallback` — the searched range's term ([`ChannelOutcome::with_g`]).
    /// The fit of g is kept either way, with its reason.
    #[must_use]
    pub fn with_g_fit(
        self,
        fitted: Option<std::result::Result<crate::anisotropy_fit::GFit, String>>,
        fallback: Option<std::result::Result<GTerm, String>>,
    ) -> Self {
        let determined = match &fitted {
            Some(Ok(g)) if g.determined => Some(g.clone()),
            _ => None,
        };
        let Some(g) = determined else {
            let mut out = self.with_g(fallback);
            if let ChannelOutcome::Fitted(f) = &mut out {
                f.g_fit = match fitted {
                    Some(Ok(g)) => Some(g),
                    Some(Err(why)) => {
                        f.g_note = Some(match f.g_note.take() {
                            Some(n) => format!("g could not be fitted: {why}; {n}"),
                            None => format!("g could not be fitted: {why}"),
                        });
                        None
                    }
                    None => None,
                };
            }
            return out;
        };
        let ChannelOutcome::Fitted(mut f) = self else {
            return self;
        };
        if let (Some(report), Some(term)) = (&g.report, g.term) {
            let fresh = ChannelFit::new(report.clone(), f.albedo_prime.spectro);
            let spectro = (f.sigma_s_prime.spectro, f.sigma_a.spectro);
            f.sigma_s_prime = fresh.sigma_s_prime;
            f.sigma_a = fresh.sigma_a;
            f.albedo_prime = fresh.albedo_prime;
            f.sigma_s_prime.spectro = spectro.0;
            f.sigma_a.spectro = spectro.1;
            f.sigma_s_prime.g = finite(term[0]);
            f.sigma_a.g = finite(term[1]);
            f.albedo_prime.g = finite(term[2]);
            f.report = report.clone();
            f.g_note = None;
            f.g_term_gap = None;
        }
        f.g_fit = Some(g);
        ChannelOutcome::Fitted(f)
    }
}

fn finite(v: f64) -> Option<f64> {
    v.is_finite().then_some(v)
}

/// An estimate as a file can hold it (JSON has no NaN): `None` without a finite value, a term that
/// is not finite as unknown.
fn finite_estimate(e: Estimate) -> Option<Estimate> {
    let term = |t: Option<f64>| t.filter(|t| t.is_finite());
    finite(e.value).map(|value| Estimate {
        value,
        fit: term(e.fit),
        spectro: term(e.spectro),
        g: term(e.g),
        model: term(e.model),
    })
}

/// Fits the three channels of a profile with the spectrophotometer's η and α′ (one after the
/// other: microseconds each, not worth threads). The outcomes carry the fit's standard errors;
/// [`propagate_spectro`] adds the spectrophotometer's.
pub fn fit_stage(
    profiles: &Rgb<ProfileData>,
    spectro: &SpectroStage,
    settings: &FitSettings,
    model: &dyn ModelFamily,
) -> Rgb<ChannelOutcome> {
    let opts = match settings.options() {
        Ok(o) => o,
        Err(e) => {
            return Rgb::from_fn(|_| ChannelOutcome::NotFitted {
                problem: e.to_string(),
            });
        }
    };
    profiles.as_ref().map_with_channel(|c, data| {
        let albedo = spectro.albedo_prime[c];
        if settings.method == Method::Proposed && albedo.is_none() {
            return ChannelOutcome::NotFitted {
                problem: spectro.problems[c]
                    .clone()
                    .unwrap_or_else(|| format!("channel {}: no reduced albedo", c.name())),
            };
        }
        let input = ChannelInput {
            eta: spectro.eta,
            albedo_prime: albedo,
            rd_total: Some(spectro.rd[c]),
        };
        match scatterfit_fit::fit_channel(data, &input, model, &opts) {
            Ok(r) => ChannelOutcome::Fitted(Box::new(ChannelFit::new(
                r,
                spectro.uncertainty.albedo_prime_stderr[c],
            ))),
            Err(e) => ChannelOutcome::NotFitted {
                problem: format!("channel {}: {e}", c.name()),
            },
        }
    })
}

/// [`fit_stage`], then [`propagate_spectro`] and the g term ([`with_g_term`]) into the outcomes:
/// the channels with every uncertainty term the measurement knows.
pub fn fit_and_propagate(
    profiles: &Rgb<ProfileData>,
    spectro: &SpectroStage,
    settings: &FitSettings,
    model: &dyn ModelFamily,
) -> Rgb<ChannelOutcome> {
    let fits = fit_stage(profiles, spectro, settings, model);
    let errors = propagate_spectro(profiles, spectro, settings, model, &fits);
    let fits = fits.zip(errors).map(|(f, e)| f.with_spectro(e));
    with_g_term(profiles, spectro, settings, fits, AlbedoAtG::FromRd)
}

/// The outcomes with the g term of `settings.g_prior` ([`crate::anisotropy`]; 0 when g is
/// known). A plan that cannot be made (the tables cover no g of the range) leaves the terms
/// unknown, with the reason in each channel's note.
pub fn with_g_term(
    profiles: &Rgb<ProfileData>,
    spectro: &SpectroStage,
    settings: &FitSettings,
    fits: Rgb<ChannelOutcome>,
    albedo_at_g: AlbedoAtG,
) -> Rgb<ChannelOutcome> {
    match GPlan::new(&settings.g_prior, settings.g) {
        Ok(None) => fits.map(|f| f.with_g(None)),
        Ok(Some(plan)) if settings.g_prior.fit => {
            let terms = propagate_g(profiles, spectro, settings, &fits, &plan, albedo_at_g);
            let fitted = crate::anisotropy_fit::fit_g_channels(
                profiles,
                spectro,
                settings,
                &fits,
                plan.range,
                albedo_at_g,
            );
            fits.zip(fitted)
                .zip(terms)
                .map(|((f, g), t)| f.with_g_fit(g, t))
        }
        Ok(Some(plan)) => {
            let terms = propagate_g(profiles, spectro, settings, &fits, &plan, albedo_at_g);
            fits.zip(terms).map(|(f, t)| f.with_g(t))
        }
        Err(e) => fits.map(|f| f.with_g(Some(Err(e.to_string())))),
    }
}

/// The part of a channel's uncertainty that the spectrophotometer contributes \[mm⁻¹\].
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SpectroErrors {
    /// Standard error of σ′s from η and α′.
    pub sigma_s_prime: f64,
    /// Standard error of σa from η and α′.
    pub sigma_a: f64,
}

/// Propagates the spectrophotometer's uncertainty ([`SpectroStage::uncertainty`]) to σ′s and σa:
/// each fitted channel is refitted at the two perturbed readings — × (1 − ε) and × (1 + ε), which
/// move Rd (hence α′) and η together — from the fit's own solution as the start, and the standard
/// error is half the difference of the two refits (central differences at ±1 standard deviation:
/// first-order error propagation, no derivative of the fit itself needed; `tests/uncertainty.rs`
/// checks it against the spread of refits of many randomly scaled readings). The existing method
/// does not use α′: only its η moves. `None` for a channel that was not fitted, or when a perturbed
/// α′ cannot be inverted or a refit does not converge (the uncertainty is then unknown, not zero).
pub fn propagate_spectro(
    profiles: &Rgb<ProfileData>,
    spectro: &SpectroStage,
    settings: &FitSettings,
    model: &dyn ModelFamily,
    fits: &Rgb<ChannelOutcome>,
) -> Rgb<Option<SpectroErrors>> {
    let Ok(opts) = settings.options() else {
        return Rgb::default();
    };
    let u = &spectro.uncertainty;
    let proposed = settings.method == Method::Proposed;
    fits.as_ref()
        .zip(profiles.as_ref())
        .map_with_channel(|c, (outcome, data)| {
            let report = outcome.report().filter(|r| r.converged)?;
            if u.repeatability == 0.0 {
                return Some(SpectroErrors {
                    sigma_s_prime: 0.0,
                    sigma_a: 0.0,
                });
            }
            let start = Some(Start {
                sigma_s_prime: report.sigma_s_prime.value,
                sigma_a: Some(report.sigma_a.value),
                scale: None,
            });
            let input = |k: usize| -> Option<ChannelInput> {
                Some(ChannelInput {
                    eta: u.eta_pm[k],
                    albedo_prime: if proposed {
                        Some(u.albedo_pm[c][k]?)
                    } else {
                        spectro.albedo_prime[c]
                    },
                    rd_total: Some(u.rd_pm[c][k]),
                })
            };
            let values = |r: FitReport| {
                r.converged
                    .then_some((r.sigma_s_prime.value, r.sigma_a.value))
            };
            // One preparation (rings, spot kernel) for both refits.
            let lo_fit =
                PreparedFit::new(data, &input(0)?, model, &FitOptions { start, ..opts }).ok()?;
            let hi = values(lo_fit.with_input(&input(1)?, start).ok()?.solve())?;
            let lo = values(lo_fit.solve())?;
            Some(SpectroErrors {
                sigma_s_prime: 0.5 * (hi.0 - lo.0).abs(),
                sigma_a: 0.5 * (hi.1 - lo.1).abs(),
            })
        })
}

/// Channel `c`'s row of `result.json`: the outcome's estimates as they are (one record of a value
/// and its terms each), with the spectrophotometer's Rd (and, for a channel that was not fitted,
/// its α′).
pub fn channel_result(
    outcome: &ChannelOutcome,
    spectro: &SpectroStage,
    c: Channel,
) -> ChannelResult {
    let rd_total = Some(spectro.rd[c]);
    match outcome {
        ChannelOutcome::NotFitted { problem } => ChannelResult {
            status: ChannelStatus::Failed,
            sigma_s_prime: None,
            sigma_a: None,
            albedo_prime: spectro.albedo_prime[c].map(|value| Estimate {
                spectro: spectro.uncertainty.albedo_prime_stderr[c],
                ..Estimate::new(value)
            }),
            rd_total,
            scale: None,
            correlation: None,
            unconstrained: Vec::new(),
            fit_time_s: 0.0,
            iterations: 0,
            termination: scatterfit_optics::Termination::NotRun,
            mse: None,
            rms_log_residual: None,
            pixel_rms_log_residual: None,
            chi2_reduced: None,
            rings_used: 0,
            rings_inside_spot: 0,
            rings_below_detection: 0,
            rings_invalid: 0,
            problem: Some(problem.clone()),
            quality: None,
        },
        ChannelOutcome::Fitted(f) => {
            let r = &f.report;
            let status = if !r.converged {
                ChannelStatus::Failed
            } else if r.unconstrained.is_empty() {
                ChannelStatus::Ok
            } else {
                ChannelStatus::Unconstrained
            };
            let problem = if !r.converged {
                Some(format!("the fit failed: {}", r.termination))
            } else if !r.unconstrained.is_empty() {
                Some(format!(
                    "the profile does not constrain {} (standard error of its logarithm above {}): \
                     the values are the solver's end point, not a measurement",
                    r.unconstrained
                        .iter()
                        .map(|p| p.name())
                        .collect::<Vec<_>>()
                        .join(" and "),
                    scatterfit_fit::UNCONSTRAINED_SD_LN
                ))
            } else {
                None
            };
            // The g term's note joins the fit's.
            let problem = match (problem, &f.g_note) {
                (Some(p), Some(n)) => Some(format!("{p}; {n}")),
                (p, n) => p.or_else(|| n.clone()),
            };
            ChannelResult {
                status,
                sigma_s_prime: finite_estimate(f.sigma_s_prime),
                sigma_a: finite_estimate(f.sigma_a),
                albedo_prime: finite_estimate(f.albedo_prime),
                rd_total,
                scale: finite(r.scale.value),
                // JSON has no NaN: a singular fit has no correlation matrix.
                correlation: r
                    .correlation
                    .iter()
                    .flatten()
                    .all(|v| v.is_finite())
                    .then(|| Correlation {
                        parameters: r.parameters.clone(),
                        matrix: r.correlation.clone(),
                    }),
                unconstrained: r.unconstrained.clone(),
                fit_time_s: r.fit_time_s,
                iterations: r.evaluations,
                termination: r.termination.clone(),
                mse: finite(r.mse),
                rms_log_residual: finite(r.rms_log_residual),
                pixel_rms_log_residual: finite(r.pixel_rms_log_residual),
                chi2_reduced: finite(r.chi2_reduced),
                rings_used: r.rings_used,
                rings_inside_spot: r.rings_inside_spot,
                rings_below_detection: r.rings_below_detection,
                rings_invalid: r.rings_invalid,
                problem,
                quality: None,
            }
        }
    }
}
