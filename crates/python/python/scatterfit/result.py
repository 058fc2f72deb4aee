"""A measured (or fitted) result as Python objects, over the dict that ``result.json`` holds.

Every value is in millimetres and mm⁻¹. A measured value is a :class:`Value`: the value and its
uncertainty terms apart — ``fit`` (the profile's noise), ``spectro`` (the spectrophotometer's
reading), ``g`` (the anisotropy's range, a bound), ``model`` (an approximate model's distance from
exact transport, a bound) — and ``total``, the bar to quote (``None`` where a term is unknown).
"""

from __future__ import annotations

import copy
import json
import os
from dataclasses import dataclass
from typing import Any, Dict, Iterator, List, Mapping, Optional

import numpy as np

__all__ = ["Value", "Reason", "ChannelResult", "Result", "Measurement"]

CHANNELS = ("r", "g", "b")


@dataclass(frozen=True)
class Value:
    """One measured value and its uncertainty terms (``result.json``'s record).

    Attributes
    ----------
    value
        The value (mm⁻¹ for σ′s and σa; α′ is a fraction).
    fit
        Standard error from the profile's noise (the fit's Jacobian).
    spectro
        Standard error from the spectrophotometer's reading (η and α′ at its repeatability).
    g
        How far the value moves over the range of the anisotropy g when g is not known (a bound).
    model
        An approximate model's distance from exact transport on the same data (a bound; ``None``
        with the exact ``mc`` model).
    total
        The bar to quote: ``fit`` and ``spectro`` in quadrature, plus ``g`` and ``model``.
    ``None`` marks a term that is unknown or does not apply.
    """

    value: float
    fit: Optional[float] = None
    spectro: Optional[float] = None
    g: Optional[float] = None
    model: Optional[float] = None
    total: Optional[float] = None

    @classmethod
    def from_dict(cls, d: Optional[Mapping[str, Any]]) -> Optional["Value"]:
        if d is None:
            return None
        return cls(
            value=d["value"],
            fit=d.get("fit"),
            spectro=d.get("spectro"),
            g=d.get("g"),
            model=d.get("model"),
            total=d.get("total"),
        )

    def __float__(self) -> float:
        return float(self.value)

    def __str__(self) -> str:
        if self.total is None:
            return f"{self.value:.4g}"
        return f"{self.value:.4g} ± {self.total:.2g}"


@dataclass(frozen=True)
class Reason:
    """Why a channel is not ``ok``: the check (``kind``), its ``severity`` and what to check."""

    kind: str
    severity: str
    message: str


class ChannelResult:
    """One colour channel of a result: σ′s, σa and α′ with their terms, the fit's figures and the
    verdict of the data checks."""

    def __init__(self, name: str, d: Mapping[str, Any]) -> None:
        self.name = name
        self._d = d
        #: ``ok``, ``unconstrained`` or ``failed``: whether the fit gave parameters.
        self.status: str = d["status"]
        #: Reduced scattering coefficient σ′s [mm⁻¹].
        self.sigma_s_prime = Value.from_dict(d.get("sigma_s_prime"))
        #: Absorption coefficient σa [mm⁻¹].
        self.sigma_a = Value.from_dict(d.get("sigma_a"))
        #: Reduced albedo α′ = σ′s / (σ′s + σa).
        self.albedo_prime = Value.from_dict(d.get("albedo_prime"))
        #: The spectrophotometer's total diffuse reflectance Rd used.
        self.rd_total: Optional[float] = d.get("rd_total")
        #: Reduced χ² of the fit on its rings.
        self.chi2_reduced: Optional[float] = d.get("chi2_reduced")
        #: Why the channel was not fitted, when it was not.
        self.problem: Optional[str] = d.get("problem")
        quality = d.get("quality") or {}
        #: ``ok``, ``suspect`` or ``failed``: whether the data checks trust the values.
        self.verdict: str = quality.get("verdict") or ("failed" if self.status == "failed" else "ok")
        #: The checks that did not pass, each with what to check.
        self.reasons: List[Reason] = [
            Reason(r["kind"], r["severity"], r["message"]) for r in quality.get("reasons", [])
        ]

    def to_dict(self) -> Dict[str, Any]:
        """The channel as ``result.json`` holds it."""
        return copy.deepcopy(dict(self._d))

    def __repr__(self) -> str:
        return (
            f"<ChannelResult {self.name.upper()}: σ′s={self.sigma_s_prime} mm⁻¹, "
            f"σa={self.sigma_a} mm⁻¹, {self.verdict}>"
        )


class Result:
    """A result: η and per channel σ′s, σa, α′ — what ``result.json`` holds.

    ``result["r"]`` (or ``"g"``, ``"b"``; upper case too) is a :class:`ChannelResult`;
    :meth:`to_dict` is the file's dict; ``verdict`` is the worst channel's.
    """

    def __init__(self, d: Mapping[str, Any]) -> None:
        self._d = d
        #: The sample's name.
        self.name: str = d.get("name", "")
        #: Relative refractive index η.
        self.eta: float = d["eta"]
        #: Its standard error (``None`` when given, not measured).
        self.eta_stderr: Optional[float] = d.get("eta_stderr")
        #: ``proposed`` (α′ from the spectrophotometer, σ′s fitted) or ``existing`` (both fitted).
        self.method: str = d.get("method", "")
        #: The forward model fitted (``mc``: exact transport).
        self.model: str = d.get("model", "")
        self.channels: Dict[str, ChannelResult] = {
            c: ChannelResult(c, d["channels"][c]) for c in CHANNELS
        }

    @classmethod
    def from_json(cls, text: str) -> "Result":
        return cls(json.loads(text))

    def __getitem__(self, channel: str) -> ChannelResult:
        key = channel.lower()
        if key not in self.channels:
            raise KeyError(f"{channel!r}: the channels are 'r', 'g' and 'b'")
        return self.channels[key]

    def __iter__(self) -> Iterator[ChannelResult]:
        return iter(self.channels.values())

    @property
    def verdict(self) -> str:
        """The worst channel verdict: ``ok`` < ``suspect`` < ``failed``."""
        order = ["ok", "suspect", "failed"]
        return max((c.verdict for c in self), key=lambda v: order.index(v) if v in order else 1)

    @property
    def ok(self) -> bool:
        """True when every channel passed the data checks."""
        return self.verdict == "ok"

    @property
    def reasons(self) -> List[Reason]:
        """Every channel's reasons, each message starting with its channel."""
        return [
            Reason(r.kind, r.severity, f"{c.name.upper()}: {r.message}") for c in self for r in c.reasons
        ]

    def sigma_s_prime(self) -> np.ndarray:
        """σ′s per channel R, G, B [mm⁻¹] (NaN where not fitted)."""
        return np.array([c.sigma_s_prime.value if c.sigma_s_prime else np.nan for c in self])

    def sigma_a(self) -> np.ndarray:
        """σa per channel R, G, B [mm⁻¹] (NaN where not fitted)."""
        return np.array([c.sigma_a.value if c.sigma_a else np.nan for c in self])

    def model_profile(self, channel: str, r_mm: Any) -> np.ndarray:
        """The fitted model of ``channel`` at radii ``r_mm`` [mm], in the profile's units (× the
        fit's scale), the light spot taken as a uniform disk of the result's radius: the curve to
        draw beside the measured profile (``fit.png``'s).

        Raises
        ------
        InputError
            The channel has no fitted σ′s and σa.
        """
        from . import models
        from .errors import InputError

        ch = self[channel]
        scale = ch._d.get("scale")
        if ch.sigma_s_prime is None or ch.sigma_a is None or scale is None:
            raise InputError(f"channel {channel!r} was not fitted ({ch.status}): no model to draw")
        inputs = self._d.get("inputs") or {}
        options = inputs.get("options") or {}
        radius = inputs.get("spot_radius_mm")
        return scale * models.profile(
            r_mm,
            ch.sigma_s_prime.value,
            ch.sigma_a.value,
            self.eta,
            options.get("g") or 0.0,
            model=self.model or "mc",
            spot_diameter_mm=2 * radius if radius else None,
        )

    def to_dict(self) -> Dict[str, Any]:
        """The result as ``result.json`` holds it (a copy)."""
        return copy.deepcopy(dict(self._d))

    def to_json(self) -> str:
        """``result.json``'s text."""
        return json.dumps(self._d, ensure_ascii=False)

    def _repr_html_(self) -> str:
        """A table for notebooks: per channel σ′s and σa with their total bars, α′ and the verdict."""
        import html

        def cell(v: Optional[Value]) -> str:
            if v is None:
                return "—"
            bar = "" if v.total is None else f" ± {v.total:.2g}"
            return f"{v.value:.4g}{bar}"

        rows = "".join(
            f"<tr><td>{c.name.upper()}</td><td>{cell(c.sigma_s_prime)}</td><td>{cell(c.sigma_a)}</td>"
            f"<td>{cell(c.albedo_prime)}</td><td>{html.escape(c.verdict)}"
            + "".join(f"<br><small>{html.escape(r.kind)}: {html.escape(r.message)}</small>" for r in c.reasons)
            + "</td></tr>"
            for c in self
        )
        return (
            f"<p><b>{html.escape(self.name)}</b>: η = {self.eta:.4g}, method {html.escape(self.method)}, "
            f"model {html.escape(self.model)}</p><table><tr><th></th><th>σ′s [mm⁻¹]</th>"
            f"<th>σa [mm⁻¹]</th><th>α′</th><th>verdict</th></tr>{rows}</table>"
        )

    def __repr__(self) -> str:
        values = ", ".join(
            f"{c.name.upper()} σ′s={c.sigma_s_prime} σa={c.sigma_a}" for c in self
        )
        return f"<{type(self).__name__} {self.name!r}: η={self.eta:.4g}; {values} [mm⁻¹]; {self.verdict}>"


class Measurement(Result):
    """A sample folder measured: the result, its profile as arrays and its result files.

    ``m.profile`` holds ``r_mm`` (n,) and ``value``, ``stderr``, ``count``, ``limit`` as (n, 3)
    arrays, channels R, G, B in columns (relative radiance; NaN where a ring has no pixels).
    """

    def __init__(self, handle: Any) -> None:
        super().__init__(json.loads(handle.result_json()))
        self._handle = handle
        self._profile: Optional[Dict[str, Any]] = None

    @property
    def profile(self) -> Dict[str, Any]:
        """The radial profile Rd(r): ``r_mm``, ``r_px`` (n,), ``value``, ``stderr``, ``count``,
        ``limit`` (n, 3)."""
        if self._profile is None:
            self._profile = self._handle.profile()
        return self._profile

    @property
    def timings(self) -> Dict[str, float]:
        """Wall time per stage [s]: ``spectro_s``, ``read_s``, ``merge_s``, ``profile_s``,
        ``fit_s``, ``checks_s`` (the image and bracket checks), ``total_s``."""
        return self._handle.timings()

    @property
    def sample_dir(self) -> str:
        """The sample folder measured."""
        return os.fspath(self._handle.sample_dir())

    @property
    def complete(self) -> bool:
        """True when every channel has constrained parameters."""
        return self._handle.complete()

    def write(self, folder: "os.PathLike[str] | str | None" = None, *, force: bool = False) -> List[str]:
        """Write the result files (result.json, result.csv, result.md, profile.csv, fit.svg,
        fit.png, report.html, result-files.json) into ``folder`` (default: the sample folder),
        with ``scatterfit measure -o``'s checks: never over one of the sample's inputs, never into
        another sample's folder or results unless ``force``. Returns the paths written.

        Raises
        ------
        InputError
            The folder is another sample's, or a result file would replace an input.
        OutputError
            A file could not be written.
        """
        folder = None if folder is None else os.fspath(folder)
        return [os.fspath(p) for p in self._handle.write(folder, force)]
