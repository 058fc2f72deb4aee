"""scatterfit: how light travels inside translucent materials, measured.

From a spectrophotometer reading (SCI and SCE) and an HDR photograph of a light spot on the
sample, scatterfit finds per colour channel the reduced scattering coefficient σ′s, the absorption
coefficient σa (mm⁻¹) and the refractive index η (Choi, Lee & Chin 2014), with exact transport by
default and every uncertainty term apart. This package is the Rust library behind a Python API.

>>> import scatterfit
>>> m = scatterfit.measure("samples/pink-plastic")          # doctest: +SKIP
>>> m["r"].sigma_a.value, m["r"].sigma_a.total, m.verdict    # doctest: +SKIP

Functions: :func:`measure`, :func:`batch`, :func:`fit_profile`, :func:`simulate`,
:func:`spectro`, :func:`export`, :func:`mitsuba_dict`, :func:`load`; the forward models are in
:mod:`scatterfit.models`; errors in :mod:`scatterfit.errors`.
"""

from . import errors, models
from ._scatterfit import __version__
from .api import (
    BatchFailure,
    batch,
    export,
    fit_profile,
    load,
    measure,
    mitsuba_dict,
    mitsuba_integrator,
    simulate,
    spectro,
)
from .errors import (
    InputError,
    MeasurementError,
    OutputError,
    ScatterfitError,
    SuspectResultWarning,
)
from .result import ChannelResult, Measurement, Reason, Result, Value

__all__ = [
    "__version__",
    "measure",
    "batch",
    "BatchFailure",
    "fit_profile",
    "simulate",
    "spectro",
    "export",
    "mitsuba_dict",
    "mitsuba_integrator",
    "load",
    "models",
    "errors",
    "Measurement",
    "Result",
    "ChannelResult",
    "Value",
    "Reason",
    "ScatterfitError",
    "InputError",
    "MeasurementError",
    "OutputError",
    "SuspectResultWarning",
]
