"""The exceptions scatterfit raises, in the classes of the command line's exit codes.

- :class:`InputError` (also a :class:`ValueError`): the input was bad — a file, a key, an
  argument; the message names it and says what to do (the CLI's exit 2).
- :class:`MeasurementError` (also a :class:`RuntimeError`): the measurement ran and failed — an
  all-saturated bracket, exposure times in the wrong order, a stopped simulation (exit 1).
- :class:`OutputError` (also an :class:`OSError`): result files could not be written.

A measurement whose data checks call a channel *suspect* is not an exception: it is a value with
a verdict (``Measurement.verdict``, ``Measurement.reasons``). Exporting one warns with
:class:`SuspectResultWarning`.
"""

from __future__ import annotations

__all__ = [
    "ScatterfitError",
    "InputError",
    "MeasurementError",
    "OutputError",
    "SuspectResultWarning",
]


class ScatterfitError(Exception):
    """Base class of every error scatterfit raises."""


class InputError(ScatterfitError, ValueError):
    """Bad input: a file, a key or an argument (the message names it and what to do)."""


class MeasurementError(ScatterfitError, RuntimeError):
    """The measurement ran and failed (or long work was stopped)."""


class OutputError(ScatterfitError, OSError):
    """A result file could not be written."""


class SuspectResultWarning(UserWarning):
    """A result used downstream (exported) although a data check called a channel suspect."""
