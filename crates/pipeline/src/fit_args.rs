//! What a user overrides of the manifests' `[fit]` by flags (`scatterfit measure`, `batch`,
//! `compare`): the method, the forward model, the albedo model, a known η, the normalisation by
//! the spectrophotometer, what is known of the Henyey–Greenstein g, and the input path policy —
//! checked and turned into the pipeline's [`Overrides`].

use scatterfit_io::escape::number as show;
#[cfg(feature = "clap")]
use scatterfit_io::flags::{parse_finite, parse_g, parse_g_range};
use scatterfit_io::manifest::GSetting;
use scatterfit_optics::{AlbedoModel, Method, ModelName};

use crate::Overrides;
use crate::anisotropy::GPrior;

/// The relative refractive index a user may give in place of the measured one.
pub const ETA_RANGE: std::ops::RangeInclusive<f64> = 1.0..=3.0;

/// A flag's value refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum FitArgsError {
    /// `--eta` outside [`ETA_RANGE`].
    #[error("--eta {}: the relative refractive index must lie in [1, 3]", show(*.0))]
    Eta(f64),
}

/// Checks a known η given by `--eta` (`measure`, `batch`, `compare`, `spectro`).
///
/// # Errors
/// [`FitArgsError::Eta`] outside [`ETA_RANGE`].
pub fn check_eta(eta: Option<f64>) -> Result<(), FitArgsError> {
    match eta {
        Some(e) if !ETA_RANGE.contains(&e) => Err(FitArgsError::Eta(e)),
        _ => Ok(()),
    }
}

/// The flags shared by `measure`, `batch` and `compare`: what overrides the manifests' `[fit]`
/// (their help is the field's text).
#[derive(Debug, Clone, Default)]
#[cfg_attr(feature = "clap", derive(clap::Args))]
pub struct FitArgs {
    /// The fitting method (default: the manifest's `fit.method`, else proposed).
    #[cfg_attr(feature = "clap", arg(long, value_enum))]
    pub method: Option<Method>,
    /// The forward model (default: the manifest's `fit.model`, else mc — exact transport; `dipole`
    /// is the paper's, whose bias reaches tens of percent: its error then joins the bars as the
    /// ± model term).
    #[cfg_attr(feature = "clap", arg(long, value_enum))]
    pub model: Option<ModelName>,
    /// How α′ comes from the spectrophotometer's Rd (default: the manifest's `fit.albedo_model`,
    /// else mc for the mc model and diffusion otherwise).
    #[cfg_attr(feature = "clap", arg(long, value_enum))]
    pub albedo_model: Option<AlbedoModel>,
    /// A known η instead of the one measured from SCI − SCE, in [1, 3].
    #[cfg_attr(feature = "clap", arg(long, value_parser = parse_finite))]
    pub eta: Option<f64>,
    /// Proposed method: fix the profile's scale by the spectrophotometer's Rd instead of fitting it.
    #[cfg_attr(feature = "clap", arg(long))]
    pub normalise_with_spectro: bool,
    /// The material's Henyey–Greenstein g, known or assumed (replaces the manifest's `[fit] g`
    /// and `g_range`): the `mc` model is evaluated at it and its ± g term is 0 (the tables cover
    /// g 0–0.95; another g is refused naming what they hold). Or `fit` (needs --model mc): g
    /// fitted per channel from the profile within --g-range, printed with its standard error
    /// only where the data determine it. Without --g and --g-range, the manifest's keys; with
    /// neither there, the values at g = 0 and a ± g term over 0–0.95 (g not stated is g not known).
    #[cfg_attr(feature = "clap", arg(long, value_name = "G|fit", value_parser = parse_g))]
    pub g: Option<GSetting>,
    /// The range LO,HI (0 ≤ LO ≤ HI ≤ 0.95) the material's g lies in (replaces `[fit] g_range`):
    /// propagated into σ′s, σa and α′ as the ± g term; with --g the values are at that g, without
    /// it the middle of the estimates over the range.
    #[cfg_attr(feature = "clap", arg(long, value_name = "LO,HI", value_parser = parse_g_range))]
    pub g_range: Option<[f64; 2]>,
    /// Let a manifest name files outside its sample folder (`../dark.png`, an absolute path, a
    /// link that leaves the folder). Without it they are refused before any work: whoever can
    /// write a manifest could otherwise make scatterfit read any file you can.
    #[cfg_attr(feature = "clap", arg(long))]
    pub allow_outside_paths: bool,
}

impl FitArgs {
    /// The pipeline's overrides.
    ///
    /// # Errors
    /// An η outside [`ETA_RANGE`].
    pub fn overrides(&self) -> Result<Overrides, FitArgsError> {
        check_eta(self.eta)?;
        Ok(Overrides {
            method: self.method,
            model: self.model,
            albedo_model: self.albedo_model,
            eta: self.eta,
            normalise_with_spectro: self.normalise_with_spectro.then_some(true),
            g: (self.g.is_some() || self.g_range.is_some())
                .then(|| GPrior::from_setting(self.g, self.g_range)),
            allow_outside_paths: self.allow_outside_paths,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn eta_outside_one_to_three_is_refused_by_name() {
        assert!(check_eta(None).is_ok());
        assert!(check_eta(Some(1.5)).is_ok());
        let err = check_eta(Some(0.5)).unwrap_err();
        assert_eq!(
            err.to_string(),
            "--eta 0.5: the relative refractive index must lie in [1, 3]"
        );
        assert!(check_eta(Some(f64::NAN)).is_err());
        let args = FitArgs {
            eta: Some(3.5),
            ..FitArgs::default()
        };
        assert!(args.overrides().is_err());
        let args = FitArgs {
            g_range: Some([0.7, 0.9]),
            ..FitArgs::default()
        };
        assert!(args.overrides().unwrap().g.is_some());
    }
}
