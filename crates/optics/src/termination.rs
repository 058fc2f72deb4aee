//! [`Termination`]: why a profile fit's solver stopped.

use std::fmt;

use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// Why the Levenberg–Marquardt solver of a profile fit stopped (the `levenberg-marquardt` crate's
/// `TerminationReason`, Moré 1978's criteria, as `scatterfit_fit` reports it and `result.json`
/// records it).
///
/// In a file it is a name, [`Termination::key`] (`converged_residual`, `evaluation_limit`, …);
/// [`Termination::Other`] is the solver's own words. Files written before the names held the
/// sentence of [`fmt::Display`] (`converged (residual tolerance)`); those read back as the same
/// variant, and a text that is neither as [`Termination::Other`].
#[derive(Debug, Clone, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum Termination {
    /// Converged: the relative reduction of the residuals below `ftol`.
    ConvergedResidual,
    /// Converged: the relative step below `xtol`.
    ConvergedStep,
    /// Converged: both tolerances met.
    ConvergedResidualAndStep,
    /// Converged: the gradient orthogonal to the residuals (`gtol`).
    ConvergedOrthogonal,
    /// Converged: the residuals are zero.
    ConvergedResidualsZero,
    /// Not converged: the limit of residual evaluations was reached.
    EvaluationLimit,
    /// Not converged: a residual, the Jacobian or a step was not finite (the model left its domain).
    NonFinite,
    /// Stopped: a tolerance cannot be met at machine precision.
    NoImprovement,
    /// The solver's criterion was met on a model that answered non-finite values: not a
    /// convergence.
    NonFiniteModel,
    /// No fit was run (a channel without data to fit).
    #[default]
    NotRun,
    /// Another reason, in the solver's words.
    Other(String),
}

/// The named variants with their file names and sentences.
const NAMED: [(Termination, &str, &str); 10] = [
    (
        Termination::ConvergedResidual,
        "converged_residual",
        "converged (residual tolerance)",
    ),
    (
        Termination::ConvergedStep,
        "converged_step",
        "converged (step tolerance)",
    ),
    (
        Termination::ConvergedResidualAndStep,
        "converged_residual_and_step",
        "converged (residual and step tolerances)",
    ),
    (
        Termination::ConvergedOrthogonal,
        "converged_orthogonal",
        "converged (gradient orthogonal to residuals)",
    ),
    (
        Termination::ConvergedResidualsZero,
        "converged_residuals_zero",
        "converged (residuals zero)",
    ),
    (
        Termination::EvaluationLimit,
        "evaluation_limit",
        "did not converge: evaluation limit reached (raise the patience or check the data)",
    ),
    (
        Termination::NonFinite,
        "non_finite",
        "did not converge: non-finite values (the model left its domain)",
    ),
    (
        Termination::NoImprovement,
        "no_improvement",
        "stopped: no improvement possible (a tolerance at machine precision)",
    ),
    (
        Termination::NonFiniteModel,
        "non_finite_model",
        "stopped on non-finite model values (the parameters left the model's domain)",
    ),
    (Termination::NotRun, "not_run", "no fit was run"),
];

impl Termination {
    /// Whether the solver converged.
    pub fn is_converged(&self) -> bool {
        matches!(
            self,
            Self::ConvergedResidual
                | Self::ConvergedStep
                | Self::ConvergedResidualAndStep
                | Self::ConvergedOrthogonal
                | Self::ConvergedResidualsZero
        )
    }

    /// The name in files (`converged_residual`, …); [`Termination::Other`]'s text as it is.
    pub fn key(&self) -> &str {
        match self {
            Self::Other(text) => text,
            named => NAMED
                .iter()
                .find(|(t, _, _)| t == named)
                .map_or("", |(_, key, _)| key),
        }
    }

    /// The variant a file's text names: a key, a sentence of [`fmt::Display`] (files written
    /// before the keys; the non-finite and no-improvement sentences named the solver's detail in
    /// the parentheses), an empty text ([`Termination::NotRun`]), else [`Termination::Other`].
    pub fn from_file(text: &str) -> Self {
        let text = text.trim();
        if text.is_empty() {
            return Self::NotRun;
        }
        if let Some((t, _, _)) = NAMED
            .iter()
            .find(|(_, key, sentence)| *key == text || *sentence == text)
        {
            return t.clone();
        }
        if text.starts_with("did not converge: non-finite") {
            Self::NonFinite
        } else if text.starts_with("stopped: no improvement possible") {
            Self::NoImprovement
        } else {
            Self::Other(text.to_string())
        }
    }
}

impl fmt::Display for Termination {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Other(text) => f.write_str(text),
            named => f.write_str(
                NAMED
                    .iter()
                    .find(|(t, _, _)| t == named)
                    .map_or("", |(_, _, sentence)| sentence),
            ),
        }
    }
}

impl Serialize for Termination {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.key())
    }
}

impl<'de> Deserialize<'de> for Termination {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        Ok(Self::from_file(&String::deserialize(d)?))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every named variant round-trips through its key and through its sentence, and only the
    /// converged ones say so.
    #[test]
    fn names_and_sentences_round_trip() {
        for (t, key, sentence) in NAMED {
            assert_eq!(t.key(), key);
            assert_eq!(t.to_string(), sentence);
            assert_eq!(Termination::from_file(key), t);
            assert_eq!(Termination::from_file(sentence), t);
            let json = serde_json::to_string(&t).unwrap();
            assert_eq!(json, format!("\"{key}\""));
            assert_eq!(serde_json::from_str::<Termination>(&json).unwrap(), t);
            assert_eq!(t.is_converged(), key.starts_with("converged"), "{key}");
        }
    }

    /// The texts earlier files hold: the solver's detail in the sentence, an empty text for a
    /// channel without a fit, and anything else kept as written.
    #[test]
    fn earlier_texts_read() {
        assert_eq!(
            Termination::from_file(
                "did not converge: non-finite jacobian (the model left its domain)"
            ),
            Termination::NonFinite
        );
        assert_eq!(
            Termination::from_file(
                "stopped: no improvement possible (gtol tolerance at machine precision)"
            ),
            Termination::NoImprovement
        );
        assert_eq!(Termination::from_file(""), Termination::NotRun);
        let other = Termination::from_file("stopped: WrongDimensions(\"jacobian\")");
        assert_eq!(other.key(), "stopped: WrongDimensions(\"jacobian\")");
        assert!(!other.is_converged());
    }
}
