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

use scatterfit_optics::{AlbedoModel, ModelName};

use crate::fit::{ChannelOutcome, FitSettings};
use crate::measure::Measurement;

pub use crate::fit::ExactFit;

/// Whether `settings` use an approximate model for the profile or for α′.
pub fn is_approximate(settings: &FitSettings) -> bool {
    settings.model != ModelName::Mc || settings.albedo_model != AlbedoModel::Mc
}

/// `settings` with exact transport for the profile and for α′ (method, g, spot and rings as
/// chosen).
pub fn exact_settings(settings: &FitSettings) -> FitSettings {
    FitSettings {
        model: ModelName::Mc,
        albedo_model: AlbedoModel::Mc,
        ..*settings
    }
}

impl Measurement {
    /// The measurement with every fitted channel's `model` term (module docs): nothing changes
    /// with exact transport itself; with an approximate model the same data are fitted again
    /// with the `mc` tables (values only) and |approximate − exact| is the term of σ′s, σa and α′.
    /// Where exact transport cannot be evaluated (outside the tables' η or α′, a refit that does
    /// not converge) the channel keeps no term and a note that says why.
    #[must_use]
    pub fn with_model_term(mut self) -> Self {
        if !is_approximate(&self.settings) {
            return self;
        }
        let exact = self.refit_values_only(exact_settings(&self.settings));
        // The data's cross-checks from exact transport's fits (an approximate model's own error
        // would read as a disagreement between the profile and the reading).
        if let Ok(x) = &exact
            && let Ok(data) = x.profile.rgb_data()
            && let Ok((model, _)) = crate::measure::families(&x.settings)
        {
            self.evidence =
                crate::checks::evidence::gather(&data, &x.spectro, &x.settings, &model, &x.fits);
        }
        let exact = exact.as_ref().map(|m| &m.fits).map_err(ToString::to_string);
        apply(&mut self.fits, exact, self.settings.model);
        self
    }
}

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
