//! The fit stage: σ′s and σa per channel from the radial profile and the spectrophotometer's η
//! and α′ ([`fit_stage`]; Levenberg–Marquardt in `scatterfit_fit`), the spectrophotometer's part of
//! their uncertainty ([`propagate_spectro`]), the g term ([`with_g_term`], [`crate::anisotropy`])
//! and a channel's line of the result file ([`channel_result`]).

//! Stage 4: the fit per channel, and its conversion into the result file's shape.

use scatterfit_fit::{ChannelInput, FitOptions, FitReport, PreparedFit, ProfileData, Start};
use scatterfit_io::result_json::{ChannelResult, ChannelStatus, Correlation};
use scatterfit_optics::{Channel, Estimate, Method, ModelFamily, Rgb};

use crate::anisotropy::plan::GPlan;
use crate::anisotropy::record::AlbedoAtG;
use crate::anisotropy::term::propagate_g;
use crate::settings::FitSettings;
use crate::spectro::SpectroStage;

pub mod outcome;

use outcome::finite;
pub use outcome::{ChannelFit, ChannelOutcome, ExactFit, SpectroErrors};

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
            let fitted = crate::anisotropy::fit::fit_g_channels(
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
