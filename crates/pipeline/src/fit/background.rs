//! Whether a constant level under the profile is a lens's veiling glare or the material's own
//! tail: exact transport decides.
//!
//! The profile stage fits its far field with a level plus a decaying tail
//! (`profile::estimate_background`, y = b + A e^{−s r}/r^p) and subtracts a significant level. For a
//! material whose light spreads further than the frame (α′ → 1: whole milk's red, σa 0.0011 mm⁻¹,
//! has a diffusion length of 11 mm; a 256-pixel frame at 0.1 mm/px reaches 18 mm), that model
//! cannot tell the tail at the corners from a level, and subtracting it steepens the profile: the
//! quick twins of whole milk, marble and apple read σ′s +33, +14 and +12 % in red, `ok`. Exact
//! transport's profile (the `mc` model) describes the tail: the rings are fitted both ways — σ′s
//! and σa both free, the profile's own shape, before any port correction of the reading — and the
//! level is kept subtracted only where the fit of the rings less the level is the better one
//! (reduced χ² of each, on its own rings). A lens's glare at 10⁻⁴–10⁻³ of the spot's radiance
//! leaves the far rings flat far above any tail, which the fit of the rings as measured cannot
//! follow, so it stays subtracted.

use scatterfit_fit::ProfileData;
use scatterfit_optics::{Channel, Rgb};

use super::fit_stage;
use super::outcome::ChannelOutcome;
use crate::profile::ProfileStage;
use crate::settings::FitPlan;
use crate::spectro::SpectroStage;

/// The profile stage with the level added back (`ProfileStage::with_levels_restored`) in every
/// channel where exact transport fits the rings as measured at least as well as the rings less the
/// level; unchanged where no level was subtracted, or where a fit could not be made.
/// `merge_limits` are the merge's detection limits (before the level raised them).
pub fn keep_levels_that_fit(
    stage: ProfileStage,
    merge_limits: &[f64],
    spectro: &SpectroStage,
    plan: &FitPlan,
) -> ProfileStage {
    let subtracted: Vec<usize> = (0..stage.background.len())
        .filter(|&c| stage.background[c].subtracted)
        .collect();
    if subtracted.is_empty() {
        return stage;
    }
    // The profile's own shape decides: σ′s and σa both free (the existing method), so neither
    // the reading's α′ nor a port's correction of it, which comes after, enters.
    let mut settings = plan.settings.exact();
    settings.method = scatterfit_optics::Method::Existing;
    settings.normalise_with_spectro = false;
    let Ok(exact) = FitPlan::new(settings) else {
        return stage;
    };
    let restored = stage.with_levels_restored(&subtracted, merge_limits);
    let (Ok(less), Ok(measured)) = (stage.rgb_data(), restored.rgb_data()) else {
        return stage;
    };
    let chi2 = |data: &Rgb<ProfileData>| -> Rgb<Option<f64>> {
        fit_stage(data, spectro, &exact).map(|o: ChannelOutcome| {
            o.report()
                .filter(|r| r.converged && r.chi2_reduced.is_finite())
                .map(|r| r.chi2_reduced)
        })
    };
    let (with_level_less, as_measured) = (chi2(&less), chi2(&measured));
    let restore: Vec<usize> = subtracted
        .into_iter()
        .filter(|&c| {
            Channel::ALL.get(c).is_some_and(|&ch| {
                matches!(
                    (with_level_less[ch], as_measured[ch]),
                    (Some(a), Some(b)) if b <= a
                )
            })
        })
        .collect();
    if restore.is_empty() {
        stage
    } else {
        stage.with_levels_restored(&restore, merge_limits)
    }
}
