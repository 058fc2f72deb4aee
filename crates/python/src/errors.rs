//! The library's errors as the package's exceptions (`scatterfit.errors`): bad input
//! (`InputError`, also a `ValueError`; the CLI's exit 2), a measurement that ran and failed
//! (`MeasurementError`, also a `RuntimeError`; exit 1), and results that could not be written
//! (`OutputError`, also an `OSError`). The classes are defined in Python, where a class may have
//! two bases; the message is the library's, its causes joined as the CLI joins them.

use pyo3::prelude::*;

/// Which of the package's exceptions an error becomes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Kind {
    /// Fix the files or the arguments.
    Input,
    /// The measurement ran and failed.
    Measurement,
    /// A result file could not be written.
    Output,
}

impl Kind {
    fn class(self) -> &'static str {
        match self {
            Kind::Input => "InputError",
            Kind::Measurement => "MeasurementError",
            Kind::Output => "OutputError",
        }
    }
}

/// The exception `kind` with `message`.
pub(crate) fn raise(kind: Kind, message: impl Into<String>) -> PyErr {
    let message = message.into();
    Python::attach(|py| {
        match py
            .import("scatterfit.errors")
            .and_then(|m| m.getattr(kind.class()))
            .and_then(|class| class.call1((message.clone(),)))
        {
            Ok(exception) => PyErr::from_value(exception),
            // The compiled module used without its package (never in an installed wheel).
            Err(_) => pyo3::exceptions::PyRuntimeError::new_err(message),
        }
    })
}

/// Bad input: [`Kind::Input`].
pub(crate) fn input(message: impl Into<String>) -> PyErr {
    raise(Kind::Input, message)
}

/// The error and its causes joined by ": ", skipping a cause whose text the message already
/// holds (library errors often name their source in their own message).
pub(crate) fn text(err: &(dyn std::error::Error + 'static)) -> String {
    let mut out = String::new();
    let mut cause: Option<&(dyn std::error::Error + 'static)> = Some(err);
    while let Some(e) = cause {
        let t = e.to_string();
        if !out.contains(&t) {
            if !out.is_empty() {
                out.push_str(": ");
            }
            out.push_str(&t);
        }
        cause = e.source();
    }
    out
}

/// A pipeline error: a failed measurement or bad input, as the CLI's exit codes class them.
pub(crate) fn pipeline(err: &scatterfit_pipeline::PipelineError) -> PyErr {
    let kind = if err.is_measurement_failure() {
        Kind::Measurement
    } else {
        Kind::Input
    };
    raise(kind, text(err))
}

/// Any other library error that means the input was bad (parameters, files, tables).
pub(crate) fn bad_input(err: &(dyn std::error::Error + 'static)) -> PyErr {
    input(text(err))
}
