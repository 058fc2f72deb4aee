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
//! term. The verdict also compares the two fits' χ²/dof on the same rings
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
                let term = |a: f64, b: f64| (a - b).abs();
                f.sigma_s_prime.model = Some(term(f.sigma_s_prime.value, x.sigma_s_prime.value));
                f.sigma_a.model = Some(term(f.sigma_a.value, x.sigma_a.value));
                f.albedo_prime.model = Some(term(f.albedo_prime.value, x.albedo_prime.value));
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
