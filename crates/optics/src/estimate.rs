//! [`Estimate`]: a measured value with the standard errors of its independent sources.
//!
//! A measured σ′s is uncertain for more than one reason: the profile's noise (the fit's standard
//! error, from its Jacobian), the spectrophotometer's repeatability (its η and α′, propagated by
//! refits) and, when the anisotropy g is not known exactly, g. Each is kept apart, so a
//! report can print "value ± fit ± spectro ± g" and a program can weigh them, and
//! [`Estimate::total`] combines them (the standard errors in quadrature, the g term's bound
//! linearly).

use serde::{Deserialize, Serialize};

/// A value and the standard errors of its independent sources of uncertainty, in the value's unit.
///
/// A term is `None` when that source is unknown or does not apply (no spectrophotometer reading,
/// a refit that did not converge); it is never a stand-in zero. A term of `Some(0.0)` means the
/// source was evaluated and contributes nothing (a reading declared exact).
///
/// ```
/// use scatterfit_optics::Estimate;
///
/// let sigma_s_prime = Estimate::new(1.979).with_fit(0.004).with_spectro(0.003);
/// assert!((sigma_s_prime.total().unwrap() - 0.005).abs() < 1e-12);
/// assert_eq!(Estimate::new(1.0).total(), None);
/// ```
///
/// As a file's record (serde) it is `{"value", "fit", "spectro", "g", "model", "total"}`, every
/// term present (`null` when unknown); `total` is [`Estimate::total`], written for the file's
/// readers and recomputed, not read, when the record is read back.
#[derive(Debug, Clone, Copy, PartialEq, Default, Deserialize)]
pub struct Estimate {
    /// The value.
    pub value: f64,
    /// Standard error from the profile's noise: the fit's (JᵀJ)⁻¹ at the solution, scaled by
    /// max(1, χ²_red) (`scatterfit_fit::FitReport`).
    pub fit: Option<f64>,
    /// Standard error from the spectrophotometer: its η and α′ at the reading's repeatability,
    /// propagated to the value by refits (`scatterfit_pipeline::fit::propagate_spectro`).
    pub spectro: Option<f64>,
    /// The part from the anisotropy g of the phase function, when g is not known exactly: how
    /// far the estimate of the g-aware exact model (the `mc` tables over g, for the
    /// profile and the α′ inversion) moves over the stated range of g — the largest deviation from
    /// the estimate at the values' g, or half the spread when the values are the middle of the
    /// range (`scatterfit_pipeline::anisotropy`). A bound-like half-width rather than a standard
    /// deviation: a g anywhere in the range gives an estimate within it. `Some(0.0)` when g was
    /// given (known); `None` when it could not be evaluated (the tables do not reach the data)
    /// or was not asked for.
    pub g: Option<f64>,
    /// The part from an approximate forward model (a diffusion dipole, photon beam diffusion):
    /// how far the estimate moves to exact transport's (the `mc` tables' profile and α′) on the
    /// same data, |approximate − exact| (`scatterfit_pipeline::model_term`). Like the g term a
    /// bounded systematic, added linearly. `None` with the exact model itself, or where exact
    /// transport could not be evaluated (the channel is then suspect).
    #[serde(default)]
    pub model: Option<f64>,
}

impl Serialize for Estimate {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeStruct;
        let mut r = s.serialize_struct("Estimate", 6)?;
        r.serialize_field("value", &self.value)?;
        r.serialize_field("fit", &self.fit)?;
        r.serialize_field("spectro", &self.spectro)?;
        r.serialize_field("g", &self.g)?;
        r.serialize_field("model", &self.model)?;
        r.serialize_field("total", &self.total())?;
        r.end()
    }
}

impl Estimate {
    /// A value with no known uncertainty yet.
    #[must_use]
    pub fn new(value: f64) -> Self {
        Self {
            value,
            ..Self::default()
        }
    }

    /// The same value with the fit's standard error.
    #[must_use]
    pub fn with_fit(self, stderr: f64) -> Self {
        Self {
            fit: Some(stderr),
            ..self
        }
    }

    /// The same value with the anisotropy's term ([`Estimate::g`]).
    #[must_use]
    pub fn with_g(self, term: f64) -> Self {
        Self {
            g: Some(term),
            ..self
        }
    }

    /// The same value with the spectrophotometer's standard error.
    #[must_use]
    pub fn with_spectro(self, stderr: f64) -> Self {
        Self {
            spectro: Some(stderr),
            ..self
        }
    }

    /// The same value with an approximate model's term ([`Estimate::model`]).
    #[must_use]
    pub fn with_model(self, term: f64) -> Self {
        Self {
            model: Some(term),
            ..self
        }
    }

    /// The known terms, in the order fit, spectro, g, model.
    pub fn terms(&self) -> impl Iterator<Item = f64> {
        [self.fit, self.spectro, self.g, self.model]
            .into_iter()
            .flatten()
    }

    /// The total uncertainty: the standard errors added in quadrature, then the g term added
    /// linearly, √(fit² + spectro²) + g.
    ///
    /// Quadrature is right for fit and spectro because they are independent standard errors: the
    /// profile's noise is the camera's (shot and read noise of the bracket), the spectrophotometer's
    /// is a separate instrument's reading. (Within the spectrophotometer's term, η and α′ are *not*
    /// independent — one reading moves both — which is why that term is propagated as one, never as
    /// an η part and an α′ part added here.) `pipeline/tests/uncertainty.rs` and
    /// `cli/tests/measure.rs` check that sum against brute force and against the truth.
    ///
    /// The g term is not a standard error but the half-width of a bounded systematic: for a g
    /// anywhere in the stated range the g-aware estimate lies within it, and each such estimate
    /// carries the statistical error of its own fit. The interval that covers the truth is the
    /// range of the estimates widened by that error — a linear sum (the worst case of a bounded
    /// systematic and a random error; a quadrature sum lets the bar fall short of the end of the
    /// range it claims to cover). Measured on rig twins over g ∈ {0, 0.5, 0.8, 0.9, 0.95}: the
    /// linear sum covers 89 % of 180 values (81–100 % per g), the quadrature sum 81 % (BENCHMARKS.md,
    /// "The g term: coverage when g is not known"). An approximate model's term
    /// ([`Estimate::model`]) is a systematic of the same kind and is added linearly too. `None`
    /// when no term is known: the uncertainty is then unknown, not zero.
    pub fn total(&self) -> Option<f64> {
        if self.fit.is_none() && self.spectro.is_none() && self.g.is_none() && self.model.is_none()
        {
            return None;
        }
        let statistical = [self.fit, self.spectro]
            .into_iter()
            .flatten()
            .map(|t| t * t)
            .sum::<f64>()
            .sqrt();
        Some(statistical + self.g.unwrap_or(0.0) + self.model.unwrap_or(0.0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The total is the quadrature sum of exactly the known standard errors plus the g term
    /// (3-4-5, then + 12: every term counts, none twice).
    #[test]
    fn total_adds_known_terms() {
        let e = Estimate {
            value: 7.0,
            fit: Some(3.0),
            spectro: Some(4.0),
            g: Some(12.0),
            model: None,
        };
        assert_eq!(e.total(), Some(17.0));
        // An approximate model's term is a bounded systematic like g's: added linearly.
        assert_eq!(e.with_model(2.0).total(), Some(19.0));
        assert_eq!(Estimate::new(7.0).with_model(0.25).total(), Some(0.25));
        assert_eq!(Estimate::new(7.0).with_g(0.5).total(), Some(0.5));
        assert_eq!(
            Estimate::new(7.0).with_fit(3.0).with_spectro(4.0).total(),
            Some(5.0)
        );
        assert_eq!(Estimate::new(7.0).with_spectro(0.5).total(), Some(0.5));
        assert_eq!(Estimate::new(7.0).with_fit(0.0).total(), Some(0.0));
        assert_eq!(Estimate::new(7.0).total(), None);
        assert_eq!(e.terms().collect::<Vec<_>>(), [3.0, 4.0, 12.0]);
    }
}
