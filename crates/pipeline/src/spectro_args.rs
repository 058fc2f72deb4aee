//! What a user gives the spectrophotometer stage by flags (`scatterfit spectro`): a measured
//! L\*a\*b\* with its observer in place of the colour from the SCE spectrum, and a known η in place
//! of the one from SCI − SCE — checked and turned into the stage's [`SpectroOptions`].

use scatterfit_io::escape::number as show;
#[cfg(feature = "clap")]
use scatterfit_io::flags::parse_finite;
use scatterfit_optics::colour::{Lab, Observer};
use scatterfit_optics::spectro::SpectroOptions;

use crate::fit_args::{FitArgsError, check_eta};

/// A flag's value refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SpectroArgsError {
    /// `--lab` or `--observer` out of range: what to give.
    #[error("{0}")]
    Refused(String),
    /// `--eta` out of range.
    #[error(transparent)]
    Eta(#[from] FitArgsError),
}

/// The spectrophotometer stage's flags (their help is given with each field).
#[derive(Debug, Clone, Default)]
#[cfg_attr(feature = "clap", derive(clap::Args))]
pub struct SpectroArgs {
    /// A measured L\*a\*b\* (D65) for the colour instead of the SCE spectrum: L\* in [0, 100], a\*
    /// and b\* finite.
    #[cfg_attr(feature = "clap", arg(long, num_args = 3, value_names = ["L", "A", "B"], allow_negative_numbers = true, help = "Measured L*a*b* (D65) to use for the colour instead of the SCE spectrum: L* in [0, 100], a* and b* finite"))]
    pub lab: Option<Vec<f64>>,
    /// The observer of `lab`: 10 (the instrument default) or 2 \[degrees\].
    #[cfg_attr(
        feature = "clap",
        arg(
            long,
            default_value_t = 10,
            value_name = "2|10",
            help = "Observer of --lab: 10 (the instrument default) or 2"
        )
    )]
    pub observer: u32,
    /// A known η to use instead of the one measured from SCI − SCE (e.g. for matte samples), in
    /// [1, 3].
    #[cfg_attr(feature = "clap", arg(long, value_parser = parse_finite))]
    pub eta: Option<f64>,
}

impl SpectroArgs {
    /// The measured L\*a\*b\* and its observer in degrees, as given (for the report).
    pub fn lab_given(&self) -> Option<(Lab, u32)> {
        match self.lab.as_deref() {
            Some(&[l, a, b]) => Some((Lab { l, a, b }, self.observer)),
            _ => None,
        }
    }

    /// The stage's options.
    ///
    /// # Errors
    /// `--lab` not three numbers, L\* outside [0, 100] or a\*, b\* not finite; an observer other
    /// than 2 or 10; η outside [1, 3].
    pub fn options(&self) -> Result<SpectroOptions, SpectroArgsError> {
        let refuse = |text: String| Err(SpectroArgsError::Refused(text));
        let lab = match self.lab.as_deref() {
            None => None,
            Some(&[l, a, b]) => {
                if !(0.0..=100.0).contains(&l) || !a.is_finite() || !b.is_finite() {
                    return refuse(format!(
                        "--lab {} {} {}: L* must lie in 0..100 and a*, b* be finite numbers",
                        show(l),
                        show(a),
                        show(b)
                    ));
                }
                let Some(observer) = Observer::from_degrees(self.observer) else {
                    return refuse(format!("--observer {}: use 2 or 10", self.observer));
                };
                Some((Lab { l, a, b }, observer))
            }
            Some(_) => return refuse("--lab takes three numbers: L* a* b*".into()),
        };
        check_eta(self.eta)?;
        Ok(SpectroOptions { lab, eta: self.eta })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lab_observer_and_eta_are_checked_by_flag() {
        let mut args = SpectroArgs {
            lab: Some(vec![50.0, 10.0, -5.0]),
            observer: 10,
            eta: Some(1.5),
        };
        let options = args.options().unwrap();
        assert_eq!(options.eta, Some(1.5));
        assert_eq!(options.lab.unwrap().1, Observer::TenDegree);
        args.observer = 5;
        assert_eq!(
            args.options().unwrap_err().to_string(),
            "--observer 5: use 2 or 10"
        );
        args.observer = 2;
        args.lab = Some(vec![120.0, 0.0, 0.0]);
        assert!(
            args.options()
                .unwrap_err()
                .to_string()
                .contains("L* must lie in 0..100")
        );
        args.lab = None;
        args.eta = Some(0.9);
        assert!(
            args.options()
                .unwrap_err()
                .to_string()
                .starts_with("--eta 0.9")
        );
    }
}
