//! The fit stage: σ′s and σa per channel from the radial profile and the spectrophotometer's η
//! and α′ ([`fit_stage`]; Levenberg–Marquardt in `scatterfit_fit`), the spectrophotometer's part of
//! their uncertainty ([`propagate_spectro`]), the g term ([`crate::anisotropy::with_g_term`])
//! and a channel's line of the result file ([`channel_result`]). Every function takes the
//! [`FitPlan`]: the settings, the options and the models made once.

use scatterfit_fit::{ChannelInput, ProfileData};
use scatterfit_io::result_json::{ChannelResult, ChannelStatus, Correlation};
use scatterfit_optics::{Channel, Estimate, Method, Rgb};

use crate::anisotropy::record::AlbedoAtG;
use crate::settings::FitPlan;
use crate::spectro::SpectroStage;

pub mod background;
pub mod outcome;
mod spectro_term;

use outcome::finite;
pub use outcome::{ChannelFit, ChannelOutcome, ExactFit, SpectroErrors};
pub use spectro_term::propagate_spectro;

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
    plan: &FitPlan,
) -> Rgb<ChannelOutcome> {
    profiles.as_ref().map_with_channel(|c, data| {
        let albedo = spectro.albedo_prime[c];
        if plan.settings.method == Method::Proposed && albedo.is_none() {
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
        match scatterfit_fit::fit_channel(data, &input, &plan.model, &plan.options) {
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

/// The two-parameter fit (σ′s and σa both free: the existing method, not normalised) of every
/// channel on the same rings with the same model — the profile's own reading of α′, which the
/// data's cross-checks hold against the spectrophotometer's (`crate::checks::evidence`). `None`
/// when the plan's method is the existing one already.
pub fn free_fits(
    profiles: &Rgb<ProfileData>,
    spectro: &SpectroStage,
    plan: &FitPlan,
) -> Option<Rgb<ChannelOutcome>> {
    if plan.settings.method != Method::Proposed {
        return None;
    }
    let mut free = *plan;
    free.settings.method = Method::Existing;
    free.settings.normalise_with_spectro = false;
    free.options.method = Method::Existing;
    free.options.normalise_with_spectro = false;
    Some(fit_stage(profiles, spectro, &free))
}

/// [`fit_stage`], then [`propagate_spectro`] and the g term ([`crate::anisotropy::with_g_term`]) into the outcomes:
/// the channels with every uncertainty term the measurement knows.
pub fn fit_and_propagate(
    profiles: &Rgb<ProfileData>,
    spectro: &SpectroStage,
    plan: &FitPlan,
) -> Rgb<ChannelOutcome> {
    let fits = fit_stage(profiles, spectro, plan);
    let errors = propagate_spectro(profiles, spectro, plan, &fits);
    let fits = fits.zip(errors).map(|(f, e)| f.with_spectro(e));
    crate::anisotropy::with_g_term(profiles, spectro, plan, fits, AlbedoAtG::FromRd)
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
