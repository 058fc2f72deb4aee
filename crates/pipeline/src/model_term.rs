//! An approximate forward model's error, measured on the data and carried in the error bar.
//!
//! The diffusion dipoles (Jensen et al. 2001; d'Eon 2012) and photon beam diffusion (Habel et al.
//! 2013) are approximations to radiative transport; on the paper rig's twins the dipole's σ′s is
//! off by up to −77 % (red aluminium) while the Monte Carlo tables (exact transport, the `mc`
//! model) are within 0.4 % median (BENCHMARKS.md, "the bias study"). The profile's noise and the
//! spectrophotometer's repeatability do not contain that error, so a bar built from them alone
//! covers the approximate model's own answer, not the material. Here the same profile and the
//! same reading are fitted again with exact transport (the `mc` profile and α′ from the `mc`
//! total, everything else as chosen), and |approximate − exact| becomes each estimate's `model`
//! term ([`scatterfit_optics::Estimate::model`]): a bounded systematic, added linearly like the g
//! term. The truth lies within exact transport's own noise of the exact estimate, and where the
//! approximate value is smaller (the dipole's σ′s at −77 %) its noise terms, being relative, are
//! smaller too; so the term also carries the part of the exact estimate's noise that the
//! approximate one's terms do not ([`model_term`]): the total bar is then |approximate − exact|
//! plus the larger of the two noises. The verdict also compares the two fits' χ²/dof on the same rings
//! ([`crate::checks::model_reasons`]): a model whose residuals are many times exact transport's
//! does not describe the profile.

use scatterfit_optics::ModelName;

use crate::fit::outcome::{ChannelOutcome, ExactFit};

/// Each fitted channel of `fits` with its `model` term from exact transport's fits of the same
/// data (`exact`, or why they could not be made): |approximate − exact| of σ′s, σa and α′ and
/// exact transport's fit beside it ([`ExactFit`]); a channel without a usable exact fit gets a
/// note saying why instead.
pub fn apply(
    fits: &mut scatterfit_optics::Rgb<ChannelOutcome>,
    exact: Result<&scatterfit_optics::Rgb<ChannelOutcome>, String>,
    model: ModelName,
) {
    for c in scatterfit_optics::Channel::ALL {
        let ChannelOutcome::Fitted(f) = &mut fits[c] else {
            continue;
        };
        let x = match &exact {
            Ok(m) => match &m[c] {
                ChannelOutcome::Fitted(x) if x.report.converged => Ok(x),
                ChannelOutcome::Fitted(x) => Err(format!(
                    "the exact fit did not converge ({})",
                    x.report.termination
                )),
                ChannelOutcome::NotFitted { problem } => Err(problem.clone()),
            },
            Err(e) => Err(e.clone()),
        };
        match x {
            Ok(x) => {
                f.sigma_s_prime.model = Some(model_term(&f.sigma_s_prime, &x.sigma_s_prime));
                f.sigma_a.model = Some(model_term(&f.sigma_a, &x.sigma_a));
                f.albedo_prime.model = Some(model_term(&f.albedo_prime, &x.albedo_prime));
                f.exact = Some(ExactFit {
                    sigma_s_prime: x.sigma_s_prime.value,
                    sigma_a: x.sigma_a.value,
                    albedo_prime: x.albedo_prime.value,
                    chi2_reduced: x.report.chi2_reduced,
                    scale: x.report.scale.value,
                });
            }
            Err(e) => {
                f.model_note = Some(format!(
                    "the {model} model's error could not be measured against exact transport \
                     (the mc tables) on this channel: {e}"
                ));
            }
        }
    }
}

/// The `model` term of an approximate estimate `a` against exact transport's `x` on the same data:
/// |a − x|, plus how far the exact estimate's noise exceeds the approximate one's (0 when it does
/// not). The approximate noise is √(fit² + spectro²) of `a`; the exact one is the exact fit's own
/// fit term (the approximate's scaled by |x/a| where the exact fit has none) with the
/// spectrophotometer's term scaled by |x/a| (exact transport's values are fitted without that
/// propagation, `Measurement::refit_values_only`; the reading's relative error moves both fits
/// alike). The total, noise + `model`, is then |a − x| + max(noise of a, noise of x): the bar of
/// the exact estimate moved to the approximate value.
pub fn model_term(a: &scatterfit_optics::Estimate, x: &scatterfit_optics::Estimate) -> f64 {
    let distance = (a.value - x.value).abs();
    let ratio = if a.value != 0.0 {
        (x.value / a.value).abs()
    } else {
        1.0
    };
    let (fit, spectro) = (a.fit.unwrap_or(0.0), a.spectro.unwrap_or(0.0));
    let noise_a = fit.hypot(spectro);
    let noise_x = x.fit.unwrap_or(fit * ratio).hypot(spectro * ratio);
    let extra = noise_x - noise_a;
    if extra.is_finite() && extra > 0.0 {
        distance + extra
    } else {
        distance
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use scatterfit_optics::Estimate;

    /// Worked by hand: a dipole σ′s of 0.5 ± 0.005 (fit) ± 0.003 (spectro) against exact
    /// transport's 2.0 ± 0.012 (fit, no spectro term): the exact noise is √(0.012² + (0.003·4)²)
    /// = 0.016971, the approximate 0.005831, so the term is 1.5 + 0.011140; an approximate value
    /// above the exact one with the larger noise keeps the bare distance.
    #[test]
    fn the_term_carries_the_exact_estimates_larger_noise() {
        let a = Estimate {
            fit: Some(0.005),
            spectro: Some(0.003),
            ..Estimate::new(0.5)
        };
        let x = Estimate {
            fit: Some(0.012),
            ..Estimate::new(2.0)
        };
        let want = 1.5 + (0.012f64.hypot(0.012) - 0.005f64.hypot(0.003));
        assert!(
            (model_term(&a, &x) - want).abs() < 1e-12,
            "{}",
            model_term(&a, &x)
        );
        let above = Estimate {
            fit: Some(0.05),
            spectro: Some(0.03),
            ..Estimate::new(3.0)
        };
        assert!((model_term(&above, &x) - 1.0).abs() < 1e-12);
        // No exact fit term: the approximate one scaled by |x/a| (4): 0.02 ⊕ 0.012.
        let bare = Estimate::new(2.0);
        let want = 1.5 + (0.02f64.hypot(0.012) - 0.005f64.hypot(0.003));
        assert!((model_term(&a, &bare) - want).abs() < 1e-12);
    }
}
