//! One channel's outcome of the fit stage: the solver's report and the measured values with their
//! uncertainty terms ([`ChannelFit`]), or why there is none; and how the spectrophotometer's, the g
//! and the model terms join it.

use scatterfit_fit::FitReport;
use scatterfit_optics::{Estimate, Method};
use serde::Serialize;

use crate::anisotropy::record::{GFit, GTerm};

/// Exact transport's fit of a channel measured with an approximate model.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ExactFit {
    /// σ′s \[mm⁻¹\].
    pub sigma_s_prime: f64,
    /// σa \[mm⁻¹\].
    pub sigma_a: f64,
    /// α′.
    pub albedo_prime: f64,
    /// χ² per degree of freedom of its fit to the same rings.
    pub chi2_reduced: f64,
    /// Its fitted scale k (measured = k · model).
    pub scale: f64,
}

/// A fitted channel: the solver's report and the measured values with their uncertainty terms.
#[derive(Debug, Clone, Serialize)]
pub struct ChannelFit {
    /// What the solver did and reached (rings, residuals, correlations, its own standard errors).
    pub report: FitReport,
    /// σ′s \[mm⁻¹\]: the fit's value with the fit's standard error and, once propagated
    /// ([`propagate_spectro`](super::propagate_spectro)), the spectrophotometer's.
    pub sigma_s_prime: Estimate,
    /// σa \[mm⁻¹\], with the same terms.
    pub sigma_a: Estimate,
    /// α′: the spectrophotometer's (proposed method, with its standard error) or the one the
    /// fitted σ′s and σa give (existing method, no spectro term); both with the g term.
    pub albedo_prime: Estimate,
    /// What the user should know about the g term (g where it could not be evaluated, or why
    /// there is none).
    pub g_note: Option<String>,
    /// Why the g term of an unknown g covers only part of its range, or none of it (the `mc`
    /// tables do not answer at some g for this material): the channel is then suspect
    /// ([`crate::checks::fit_reasons`], `g_term_incomplete`). `None` when g is known or the term
    /// is whole.
    pub g_term_gap: Option<String>,
    /// With `g = "fit"`: the fit of g ([`crate::anisotropy::fit`]), determined or not.
    pub g_fit: Option<GFit>,
    /// With an approximate forward model: exact transport's fit of the same data
    /// ([`crate::model_term`]), whose distance from this one is each estimate's `model` term.
    pub exact: Option<ExactFit>,
    /// With an approximate forward model: why exact transport could not be evaluated (the
    /// estimates then have no `model` term and the channel is suspect).
    pub model_note: Option<String>,
}

impl ChannelFit {
    /// The report of a channel fitted with `method`, α′'s standard error from the reading
    /// (`albedo_prime_stderr`, used by the proposed method only); no spectrophotometer term yet.
    pub fn new(report: FitReport, albedo_prime_stderr: Option<f64>) -> Self {
        let estimate = |e: scatterfit_fit::FittedValue| Estimate {
            value: e.value,
            fit: finite(e.stderr),
            spectro: None,
            g: None,
            model: None,
        };
        Self {
            sigma_s_prime: estimate(report.sigma_s_prime),
            sigma_a: estimate(report.sigma_a),
            albedo_prime: Estimate {
                value: report.albedo_prime,
                fit: None,
                // The existing method's α′ comes from its fitted coefficients, not the reading.
                spectro: albedo_prime_stderr.filter(|_| report.method == Method::Proposed),
                g: None,
                model: None,
            },
            g_note: None,
            g_term_gap: None,
            g_fit: None,
            exact: None,
            model_note: None,
            report,
        }
    }
}

/// One channel's outcome: a fit, or why there is none.
#[derive(Debug, Clone, Serialize)]
#[serde(tag = "outcome", rename_all = "snake_case")]
pub enum ChannelOutcome {
    /// The fit ran.
    Fitted(Box<ChannelFit>),
    /// No fit: the spectrophotometer gave no α′, or too few rings.
    NotFitted {
        /// Why.
        problem: String,
    },
}

impl ChannelOutcome {
    /// The fit, if it ran.
    pub fn fit(&self) -> Option<&ChannelFit> {
        match self {
            ChannelOutcome::Fitted(f) => Some(f),
            ChannelOutcome::NotFitted { .. } => None,
        }
    }

    /// The solver's report, if the fit ran.
    pub fn report(&self) -> Option<&FitReport> {
        self.fit().map(|f| &f.report)
    }

    /// σ′s with its uncertainty terms, if the fit ran (see [`ChannelOutcome::is_measurement`]
    /// for whether the data constrain it).
    pub fn sigma_s_prime(&self) -> Option<Estimate> {
        self.fit().map(|f| f.sigma_s_prime)
    }

    /// σa with its uncertainty terms, if the fit ran.
    pub fn sigma_a(&self) -> Option<Estimate> {
        self.fit().map(|f| f.sigma_a)
    }

    /// True when the channel gave parameters the data constrain.
    pub fn is_measurement(&self) -> bool {
        self.report().is_some_and(FitReport::is_measurement)
    }

    /// The same outcome with the spectrophotometer's part of σ′s's and σa's uncertainty
    /// ([`propagate_spectro`](super::propagate_spectro); `None` leaves it unknown).
    #[must_use]
    pub fn with_spectro(mut self, errors: Option<SpectroErrors>) -> Self {
        if let (ChannelOutcome::Fitted(f), Some(e)) = (&mut self, errors) {
            f.sigma_s_prime.spectro = finite(e.sigma_s_prime);
            f.sigma_a.spectro = finite(e.sigma_a);
        }
        self
    }
}

impl ChannelOutcome {
    /// The same outcome with the g term ([`crate::anisotropy`]): `None` (known g) sets every term
    /// to 0; a term sets σ′s's, σa's and α′'s, and for a range without a g with the `mc` model
    /// replaces the values by the middle of the estimates over the range; an error leaves the
    /// terms unknown and says why.
    #[must_use]
    pub fn with_g(mut self, term: Option<std::result::Result<GTerm, String>>) -> Self {
        let ChannelOutcome::Fitted(f) = &mut self else {
            return self;
        };
        match term {
            None => {
                f.sigma_s_prime.g = Some(0.0);
                f.sigma_a.g = Some(0.0);
                f.albedo_prime.g = Some(0.0);
            }
            Some(Err(why)) => {
                f.g_term_gap = Some(why.clone());
                f.g_note = Some(why);
            }
            Some(Ok(t)) => {
                f.g_term_gap.clone_from(&t.note);
                f.sigma_s_prime.g = finite(t.sigma_s_prime);
                f.sigma_a.g = finite(t.sigma_a);
                f.albedo_prime.g = finite(t.albedo_prime);
                if t.centre_applies {
                    f.sigma_s_prime.value = t.centre[0];
                    f.sigma_a.value = t.centre[1];
                    f.albedo_prime.value = t.centre[2];
                }
                f.g_note = t.note;
            }
        }
        self
    }
}

impl ChannelOutcome {
    /// The same outcome with g fitted (`g = "fit"`, [`crate::anisotropy::fit`]): where the data
    /// determine g, the fit at ĝ replaces the report and the values (the spectrophotometer's term
    /// stays the one computed at the settings' g), and the g term is how far the values move over
    /// ĝ ± sd(g); where not, `fallback` — the searched range's term ([`ChannelOutcome::with_g`]).
    /// The fit of g is kept either way, with its reason.
    #[must_use]
    pub fn with_g_fit(
        self,
        fitted: Option<std::result::Result<GFit, String>>,
        fallback: Option<std::result::Result<GTerm, String>>,
    ) -> Self {
        let determined = match &fitted {
            Some(Ok(g)) if g.determined => Some(g.clone()),
            _ => None,
        };
        let Some(g) = determined else {
            let mut out = self.with_g(fallback);
            if let ChannelOutcome::Fitted(f) = &mut out {
                f.g_fit = match fitted {
                    Some(Ok(g)) => Some(g),
                    Some(Err(why)) => {
                        f.g_note = Some(match f.g_note.take() {
                            Some(n) => format!("g could not be fitted: {why}; {n}"),
                            None => format!("g could not be fitted: {why}"),
                        });
                        None
                    }
                    None => None,
                };
            }
            return out;
        };
        let ChannelOutcome::Fitted(mut f) = self else {
            return self;
        };
        if let (Some(report), Some(term)) = (&g.report, g.term) {
            let fresh = ChannelFit::new(report.clone(), f.albedo_prime.spectro);
            let spectro = (f.sigma_s_prime.spectro, f.sigma_a.spectro);
            f.sigma_s_prime = fresh.sigma_s_prime;
            f.sigma_a = fresh.sigma_a;
            f.albedo_prime = fresh.albedo_prime;
            f.sigma_s_prime.spectro = spectro.0;
            f.sigma_a.spectro = spectro.1;
            f.sigma_s_prime.g = finite(term[0]);
            f.sigma_a.g = finite(term[1]);
            f.albedo_prime.g = finite(term[2]);
            f.report = report.clone();
            f.g_note = None;
            f.g_term_gap = None;
        }
        f.g_fit = Some(g);
        ChannelOutcome::Fitted(f)
    }
}

pub(crate) fn finite(v: f64) -> Option<f64> {
    v.is_finite().then_some(v)
}

/// An estimate as a file can hold it (JSON has no NaN): `None` without a finite value, a term that
/// is not finite as unknown.
/// The part of a channel's uncertainty that the spectrophotometer contributes \[mm⁻¹\].
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SpectroErrors {
    /// Standard error of σ′s from η and α′.
    pub sigma_s_prime: f64,
    /// Standard error of σa from η and α′.
    pub sigma_a: f64,
}
