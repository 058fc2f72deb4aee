//! The spectrophotometer's part of σ′s's and σa's uncertainty ([`propagate_spectro`]): refits at
//! the reading ± its error.

use scatterfit_fit::{ChannelInput, FitOptions, FitReport, PreparedFit, ProfileData, Start};
use scatterfit_optics::{Method, Rgb};

use super::outcome::{ChannelOutcome, SpectroErrors};
use crate::settings::FitPlan;
use crate::spectro::SpectroStage;

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
    plan: &FitPlan,
    fits: &Rgb<ChannelOutcome>,
) -> Rgb<Option<SpectroErrors>> {
    let u = &spectro.uncertainty;
    let proposed = plan.settings.method == Method::Proposed;
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
            let opts = FitOptions {
                start,
                ..plan.options
            };
            let lo_fit = PreparedFit::new(data, &input(0)?, &plan.model, &opts).ok()?;
            let hi = values(lo_fit.with_input(&input(1)?, start).ok()?.solve())?;
            let lo = values(lo_fit.solve())?;
            Some(SpectroErrors {
                sigma_s_prime: 0.5 * (hi.0 - lo.0).abs(),
                sigma_a: 0.5 * (hi.1 - lo.1).abs(),
            })
        })
}
