//! The fit's error carried through the port's F ([`propagate_fit_through_port`]): behind a port
//! the corrected Rd, and so α′, depend on the fitted σ′s.

use scatterfit_fit::{ChannelInput, ProfileData};
use scatterfit_optics::{ModelFamily, Rgb};

use super::PortCorrection;
use crate::settings::FitPlan;
use crate::spectro::SpectroStage;

/// The fit's error carried through the port's F into σ′s's, σa's and α′'s fit terms (proposed
/// method).
///
/// Behind a port the corrected Rd depends on the fit: F is the port's reading of the *fitted*
/// material, and F grows with σ′t (the light leaves the aperture less), so a fitted σ′s one
/// standard error high gives a larger F, a smaller corrected Rd, a smaller α′ and a larger σa. At
/// α′ → 1 the reading hardly moves with α′ (d ln(Rd·F)/d ln(1 − α′) is −0.011 for pink plastic's
/// red behind an 8 mm port lit over 8 mm, against d ln F/d ln σ′s = +0.37), so with σ′s held σa
/// would move 33 times the fit's relative error; the refit softens it (at fixed data a lower α′
/// is fitted with a lower σ′s), and on the twins σa's term comes out 5–6 times the loss-free s·σa
/// (docs/physics.md §12, BENCHMARKS.md). Here each term is half the spread of the whole measurement in the
/// two worlds of [`PortCorrection::fit_pm`] — the fit's σ′s × (1 ∓ s) at every α′: the corrected
/// Rd of that world, its α′, the refit there (σ′s, σa) and the factor 1 ∓ s on both — first-order
/// propagation by central differences at ±1 standard error, as the spectrophotometer's term
/// (`fit::propagate_spectro`). Without a port the two worlds share α′ and the terms reduce to the
/// loss-free s·σ′s and s·σa. α′ gets a fit term (it had none: without a port it comes from the
/// reading alone). A channel whose perturbed correction, inversion or refit fails keeps its terms;
/// with g fitted (`g = "fit"`, determined) the values are ĝ's and the terms are left as they are.
pub fn propagate_fit_through_port(
    data: &Rgb<ProfileData>,
    spectro: &SpectroStage,
    plan: &FitPlan,
    correction: &PortCorrection,
    fits: Rgb<crate::fit::outcome::ChannelOutcome>,
) -> Rgb<crate::fit::outcome::ChannelOutcome> {
    use crate::fit::outcome::ChannelOutcome;
    use scatterfit_fit::{FitOptions, PreparedFit, Start};
    if plan.settings.method != scatterfit_optics::Method::Proposed {
        return fits;
    }
    let (model, albedo, opts) = (&plan.model, &plan.albedo, plan.options);
    fits.map_with_channel(|c, mut outcome| {
        let ChannelOutcome::Fitted(f) = &mut outcome else {
            return outcome;
        };
        let (Some(pm), true) = (correction.fit_pm[c], f.report.converged) else {
            return outcome;
        };
        if f.g_fit.as_ref().is_some_and(|g| g.determined) {
            return outcome;
        }
        let start = Some(Start {
            sigma_s_prime: f.report.sigma_s_prime.value,
            sigma_a: Some(f.report.sigma_a.value),
            scale: None,
        });
        let input = |k: usize| -> Option<ChannelInput> {
            Some(ChannelInput {
                eta: spectro.eta,
                albedo_prime: Some(albedo.albedo_from_rd(pm.rd[k], spectro.eta, 0.0).ok()?),
                rd_total: Some(pm.rd[k]),
            })
        };
        let values = |k: usize, r: scatterfit_fit::FitReport| {
            r.converged.then_some([
                pm.scale[k] * r.sigma_s_prime.value,
                pm.scale[k] * r.sigma_a.value,
                r.albedo_prime,
            ])
        };
        // One preparation (rings, spot kernel) for both refits, as `fit::propagate_spectro`.
        let worlds = || -> Option<[[f64; 3]; 2]> {
            let lo_fit =
                PreparedFit::new(&data[c], &input(0)?, model, &FitOptions { start, ..opts })
                    .ok()?;
            let hi = values(1, lo_fit.with_input(&input(1)?, start).ok()?.solve())?;
            Some([values(0, lo_fit.solve())?, hi])
        };
        if let Some([lo, hi]) = worlds() {
            let half = |i: usize| Some(0.5 * (hi[i] - lo[i]).abs()).filter(|v| v.is_finite());
            f.sigma_s_prime.fit = half(0).or(f.sigma_s_prime.fit);
            f.sigma_a.fit = half(1).or(f.sigma_a.fit);
            f.albedo_prime.fit = half(2);
        }
        outcome
    })
}
