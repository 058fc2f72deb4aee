"""The package's functions: measure, batch, fit_profile, simulate, spectro, export, load."""

from __future__ import annotations

import json
import os
import warnings
from dataclasses import dataclass
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from . import _scatterfit
from ._progress import ProgressArg, progress_callback
from .errors import InputError, MeasurementError, SuspectResultWarning
from .result import Measurement, Result

__all__ = [
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
]

PathLike = Union[str, "os.PathLike[str]"]
GArg = Union[float, str, None]


def measure(
    folder: PathLike,
    *,
    method: Optional[str] = None,
    model: Optional[str] = None,
    albedo_model: Optional[str] = None,
    eta: Optional[float] = None,
    g: GArg = None,
    g_range: Optional[Tuple[float, float]] = None,
    normalise_with_spectro: Optional[bool] = None,
    allow_outside_paths: bool = False,
    progress: ProgressArg = True,
) -> Measurement:
    """Measure one sample folder (its ``sample.toml``), as ``scatterfit measure`` does.

    Parameters
    ----------
    folder
        The sample folder.
    method
        ``"proposed"`` (α′ from the spectrophotometer, σ′s fitted; the paper's) or
        ``"existing"`` (σ′s and σa both fitted). Default: the manifest's, else ``"proposed"``.
    model
        The forward model: ``"mc"`` (exact transport, the default), ``"dipole"`` (the paper's),
        ``"better-dipole"``, ``"pbd"``. With an approximate model the same data are fitted again
        exactly and the distance joins every value's error bar as its ``model`` term.
    albedo_model
        How α′ comes from the spectrophotometer's Rd: ``"mc"`` or ``"diffusion"``.
    eta
        A known relative refractive index instead of the one measured from SCI − SCE.
    g
        The Henyey–Greenstein g if known (a number in (−1, 1)), or ``"fit"``.
    g_range
        The range of g when it is not known, ``(low, high)``.
    normalise_with_spectro
        Fix the profile's scale by the spectrophotometer's Rd.
    allow_outside_paths
        Allow the manifest to name files outside the sample folder.
    progress
        A progress bar for work that takes more than 2 s (tqdm's when installed, else lines on
        stderr); ``False`` for none, or your own ``callable(done, total)``.

    Returns
    -------
    Measurement
        η and per channel σ′s, σa, α′ [mm⁻¹] with their uncertainty terms, the verdict of the
        data checks with its reasons, and the profile as arrays. A *suspect* channel is a value
        with a verdict, not an exception.

    Raises
    ------
    InputError
        The folder, the manifest, a file or an argument is wrong (the message says which).
    MeasurementError
        The measurement ran and failed (e.g. every frame saturated).
    KeyboardInterrupt
        Ctrl-C: the measurement stops before its next stage (stages take up to a second or so on
        a rig sample); a :func:`batch` stops starting samples, and its running ones stop likewise.
    """
    callback, close = progress_callback(progress, "measuring", "stages")
    try:
        handle = _scatterfit.measure(
            os.fspath(folder),
            method=method,
            model=model,
            albedo_model=albedo_model,
            eta=eta,
            normalise_with_spectro=normalise_with_spectro,
            g=g,
            g_range=g_range,
            allow_outside_paths=allow_outside_paths,
            progress=callback,
        )
    finally:
        close()
    return Measurement(handle)


@dataclass(frozen=True)
class BatchFailure:
    """A sample of a batch that has no measurement: its folder, the class of the error
    (``"input"`` or ``"measurement"``) and the message."""

    folder: str
    kind: str
    message: str

    def error(self) -> Exception:
        """The exception :func:`measure` would have raised."""
        cls = InputError if self.kind == "input" else MeasurementError
        return cls(f"{self.folder}: {self.message}")


def batch(
    folders: Sequence[PathLike],
    *,
    jobs: Optional[int] = None,
    progress: ProgressArg = True,
    **options: Any,
) -> Tuple[List[Measurement], List[BatchFailure]]:
    """Measure many sample folders in parallel, as ``scatterfit batch`` does.

    ``jobs`` samples are measured at once (default: one per core, fewer when the machine's memory
    budget needs it); ``options`` are :func:`measure`'s. One bad sample never raises for the
    rest: it is returned among the failures.

    Returns
    -------
    (measurements, failures)
        The measurements in the folders' order, and a :class:`BatchFailure` per sample that has
        none.
    """
    callback, close = progress_callback(progress, "measuring", "samples")
    try:
        items = _scatterfit.batch(
            [os.fspath(f) for f in folders], jobs=jobs, progress=callback, **options
        )
    finally:
        close()
    measured: List[Measurement] = []
    failed: List[BatchFailure] = []
    for folder, handle, error in items:
        if handle is not None:
            measured.append(Measurement(handle))
        else:
            assert error is not None, "the compiled module returns a measurement or an error"
            kind, message = error
            failed.append(BatchFailure(os.fspath(folder), kind, message))
    return measured, failed


def _rgb(name: str, value: Any) -> Optional[Tuple[float, float, float]]:
    if value is None:
        return None
    a = np.asarray(value, dtype=float).reshape(-1)
    if a.size == 1:
        a = np.repeat(a, 3)
    if a.size != 3:
        raise InputError(f"{name}: one number, or three (R, G, B); got {a.size}")
    return (float(a[0]), float(a[1]), float(a[2]))


def fit_profile(
    r_mm: Any,
    value: Any,
    stderr: Any,
    *,
    eta: float,
    albedo: Any = None,
    rd: Any = None,
    count: Any = None,
    limit: Any = None,
    method: str = "proposed",
    model: str = "mc",
    g: GArg = None,
    g_range: Optional[Tuple[float, float]] = None,
    spot_diameter_mm: float = 1.0,
    r_min_mm: Optional[float] = None,
    normalise_with_spectro: bool = False,
    name: str = "profile",
) -> Result:
    """Fit a radial profile you already have, as ``scatterfit fit`` does.

    Parameters
    ----------
    r_mm
        Ring radii [mm], increasing, shape (n,).
    value, stderr
        The profile and its standard errors: shape (n, 3) for channels R, G, B, or (n,) for one
        channel (fitted as all three; read ``result["r"]``). Relative units: the fit has a scale.
    eta
        Relative refractive index η, in [1, 3].
    albedo
        Reduced albedo α′ per channel (or one for all); the proposed method needs it or ``rd``.
    rd
        The spectrophotometer's total diffuse reflectance per channel, to invert α′ from.
    count
        Pixels per ring, same shape as ``value`` (default: 1 each).
    limit
        Detection limit per ring, same shape as ``value``: rings below it are not fitted
        (default: none known; only rings with a value ≤ 0 are left out).
    method, model, g, g_range, normalise_with_spectro
        As :func:`measure`.
    spot_diameter_mm
        The light spot's diameter [mm]; the model is convolved with it.
    r_min_mm
        The innermost fitted radius [mm] (default: the spot's diameter).

    Returns
    -------
    Result
        As ``scatterfit fit --json`` prints it.
    """
    r = np.ascontiguousarray(r_mm, dtype=np.float64)
    if r.ndim != 1:
        raise InputError(f"r_mm: a 1-D array of radii, got shape {r.shape}")

    def columns(what: str, a: Any) -> np.ndarray:
        a = np.asarray(a, dtype=np.float64)
        if a.ndim == 1:
            a = np.repeat(a[:, None], 3, axis=1)
        if a.shape != (r.size, 3):
            raise InputError(f"{what}: shape {a.shape}, expected ({r.size},) or ({r.size}, 3)")
        return np.ascontiguousarray(a)

    text, _complete = _scatterfit.fit_profile(
        r,
        columns("value", value),
        columns("stderr", stderr),
        eta=float(eta),
        albedo=_rgb("albedo", albedo),
        rd=_rgb("rd", rd),
        count=None if count is None else columns("count", count),
        limit=None if limit is None else columns("limit", limit),
        method=method,
        model=model,
        g=g,
        g_range=g_range,
        spot_diameter_mm=float(spot_diameter_mm),
        r_min_mm=r_min_mm,
        normalise_with_spectro=normalise_with_spectro,
        name=name,
    )
    return Result.from_json(text)


def simulate(
    sigma_s_prime: float,
    sigma_a: float,
    eta: float,
    *,
    g: float = 0.0,
    thickness_mm: Optional[float] = None,
    photons: int = 100_000,
    seed: int = 1,
    r_max_mm: float = 10.0,
    bins: int = 100,
    beam: str = "pencil",
    beam_radius_mm: Optional[float] = None,
    max_interactions: float = 1e12,
    progress: ProgressArg = True,
) -> Dict[str, Any]:
    """Monte Carlo ground truth: photons through a half-space (or a slab of ``thickness_mm``)
    with σ′s, σa [mm⁻¹], Henyey–Greenstein g and relative index η, as ``scatterfit simulate``.

    Returns
    -------
    dict
        ``r_mm`` (bin centres), ``r_edges_mm``, ``rd`` and ``rd_stderr`` [mm⁻²] as arrays;
        ``rd_total``, ``transmittance``, ``absorbed`` as (value, standard error) pairs;
        ``specular``, ``photons``, ``interactions``, ``seed``. The same seed gives the same numbers.

    ``beam`` is ``"pencil"``, or ``"disk"`` / ``"gaussian"`` with ``beam_radius_mm``. A run
    expected to take more than ``max_interactions`` photon interactions (about 10¹² is hours on
    two cores) is refused before it starts, with its estimate.

    Raises
    ------
    InputError
        A parameter out of range (the message says which and why), or more work than
        ``max_interactions`` or tallies beyond the memory budget.
    KeyboardInterrupt
        Ctrl-C: the simulation stops within a wave of photons (about 10⁸ interactions).
    """
    for name, value, low in (("photons", photons, 1), ("seed", seed, 0), ("bins", bins, 1)):
        if isinstance(value, bool) or int(value) != value or not low <= int(value) < 2**64:
            raise InputError(f"{name}={value!r}: a whole number from {low} to 2**64 - 1")
    callback, close = progress_callback(progress, "simulating", "photons")
    try:
        return _scatterfit.simulate(
            float(sigma_s_prime),
            float(sigma_a),
            float(eta),
            g=float(g),
            thickness_mm=thickness_mm,
            photons=int(photons),
            seed=int(seed),
            r_max_mm=float(r_max_mm),
            bins=int(bins),
            beam=beam,
            beam_radius_mm=beam_radius_mm,
            max_interactions=float(max_interactions),
            progress=callback,
        )
    finally:
        close()


def spectro(
    path: Optional[PathLike] = None,
    *,
    wavelengths_nm: Any = None,
    sci: Any = None,
    sce: Any = None,
    lab: Optional[Tuple[float, float, float]] = None,
    observer: int = 10,
    eta: Optional[float] = None,
) -> Dict[str, Any]:
    """The spectrophotometer stage, as ``scatterfit spectro``: η from SCI − SCE (Schlick), the
    colour, and per channel Rd and α′.

    Give a CSV file (``path``: columns wavelength_nm, SCI, SCE), or the spectrum as arrays
    (``wavelengths_nm``, ``sci``, ``sce``; reflectances as fractions). ``lab`` is a measured
    L*a*b* (D65; ``observer`` 2 or 10 degrees) to use for the colour; ``eta`` a known η.

    Returns
    -------
    dict
        ``eta``, ``channels`` (per channel ``rd``, ``albedo_prime``, …), the colour, warnings —
        ``scatterfit spectro --json``'s fields.
    """
    if path is not None:
        if wavelengths_nm is not None or sci is not None or sce is not None:
            raise InputError("give a file or the arrays wavelengths_nm, sci, sce, not both")
        text, _ = _scatterfit.spectro_file(os.fspath(path), lab=lab, observer=observer, eta=eta)
    else:
        if wavelengths_nm is None or sci is None or sce is None:
            raise InputError("give a spectrophotometer CSV file, or wavelengths_nm, sci and sce")
        as_list = lambda a: [float(v) for v in np.asarray(a, dtype=float).reshape(-1)]  # noqa: E731
        text, _ = _scatterfit.spectro_arrays(
            as_list(wavelengths_nm), as_list(sci), as_list(sce), lab=lab, observer=observer, eta=eta
        )
    return json.loads(text)


def _result_json(result: Union[Result, Mapping[str, Any], PathLike]) -> Tuple[str, str]:
    """``result.json``'s text of a result, a dict or a file, and how to name it in messages."""
    if isinstance(result, Result):
        return result.to_json(), repr(result.name)
    if isinstance(result, Mapping):
        return json.dumps(result), "the result"
    path = os.fspath(result)
    return _scatterfit.read_result(path), path


def load(path: PathLike) -> Result:
    """Read a ``result.json`` (older schema versions are upgraded)."""
    return Result.from_json(_scatterfit.read_result(os.fspath(path)))


def export(
    result: Union[Result, Mapping[str, Any], PathLike],
    to: str = "json",
    *,
    scale: str = "mm",
    mitsuba_variant: str = "rgb",
    allow_suspect: bool = False,
) -> str:
    """A result as a material renderers read, as ``scatterfit export``.

    Parameters
    ----------
    result
        A :class:`Result` or :class:`Measurement`, ``result.json``'s dict, or its path.
    to
        ``"mitsuba"`` (Mitsuba 3 XML), ``"pbrt"`` (pbrt-v4), ``"blender"`` (a bpy script) or
        ``"json"`` (renderer-neutral).
    scale
        The scene's unit: ``"mm"`` or ``"m"`` (the coefficients are scaled to it).
    mitsuba_variant
        ``"rgb"`` or ``"spectral"`` (Mitsuba's variants).
    allow_suspect
        Export without a warning although a channel's data checks failed.

    Returns
    -------
    str
        The file's text.

    Warns
    -----
    SuspectResultWarning
        A channel is suspect (its numbers are not trusted), unless ``allow_suspect``.
    """
    text, source = _result_json(result)
    out, notes, untrusted = _scatterfit.export(
        text, to=to, scale=scale, mitsuba_variant=mitsuba_variant, source=source
    )
    _warn_exported(source, notes, untrusted, allow_suspect)
    return out


def _warn_exported(
    source: str, notes: List[str], untrusted: Optional[str], allow_suspect: bool
) -> None:
    """The export's notes as warnings, and a :class:`SuspectResultWarning` for a result whose
    channels did not all pass the data checks (unless ``allow_suspect``); at the caller's
    caller."""
    for note in notes:
        warnings.warn(note, UserWarning, stacklevel=3)
    if untrusted and not allow_suspect:
        warnings.warn(
            f"{source}: not every channel passed the measurement's data checks ({untrusted}); "
            "the numbers are not trusted (allow_suspect=True to use them anyway)",
            SuspectResultWarning,
            stacklevel=3,
        )


def _mitsuba_objects(
    result: Union[Result, Mapping[str, Any], PathLike],
    allow_suspect: bool,
    mitsuba_variant: str = "rgb",
) -> Dict[str, Any]:
    """The Mitsuba export's boundary, medium and integrator as ``load_dict`` dicts."""
    text, source = _result_json(result)
    out, notes, untrusted = _scatterfit.mitsuba_dict(
        text, mitsuba_variant=mitsuba_variant, source=source
    )
    _warn_exported(source, notes, untrusted, allow_suspect)
    objects: Dict[str, Any] = json.loads(out)
    return objects


def _spectra_as_pairs(d: Dict[str, Any]) -> Dict[str, Any]:
    """A spectrum's (wavelength, value) pairs as tuples, as ``load_dict`` documents them."""
    for v in d.values():
        if isinstance(v, dict):
            if v.get("type") == "spectrum" and isinstance(v.get("value"), list):
                v["value"] = [tuple(p) for p in v["value"]]
            else:
                _spectra_as_pairs(v)
    return d


def mitsuba_dict(
    result: Union[Result, Mapping[str, Any], PathLike],
    *,
    shape: Optional[Mapping[str, Any]] = None,
    mitsuba_variant: str = "rgb",
    allow_suspect: bool = False,
) -> Dict[str, Any]:
    """The material as a Mitsuba 3 shape dict that ``mitsuba.load_dict`` accepts as it is: the
    shape (default ``{"type": "sphere"}``; pass your own, e.g. with a ``to_world``) with the
    export's dielectric boundary as its ``bsdf`` and its homogeneous medium as its
    ``interior``, in millimetres. The same objects and numbers as ``export(result, "mitsuba")``
    (the library gives both). Render it with :func:`mitsuba_integrator`'s integrator
    (``volpathmis``). ``mitsuba_variant="spectral"`` gives the medium per wavelength from the
    measured spectrum, for Mitsuba's spectral variants (as ``export``'s option).
    """
    objects = _mitsuba_objects(result, allow_suspect, mitsuba_variant)
    d: Dict[str, Any] = dict(shape) if shape is not None else {"type": "sphere"}
    d["bsdf"] = _spectra_as_pairs(objects["bsdf"])
    d["interior"] = _spectra_as_pairs(objects["interior"])
    return d


def mitsuba_integrator(result: Union[Result, Mapping[str, Any], PathLike]) -> Dict[str, Any]:
    """The integrator the Mitsuba export recommends for this material (its header), as a dict:
    ``volpathmis`` with unbounded depth and the Russian-roulette depth the medium needs."""
    integrator: Dict[str, Any] = _mitsuba_objects(result, True)["integrator"]
    return integrator

