"""The forward models over NumPy arrays: the radial profile Rd(r), the total diffuse reflectance
Rd(α′) and its inverse — the physics the fit compares a measurement with.

Models (``model=``): ``"mc"`` — exact transport, the Monte Carlo tables shipped with scatterfit
(η 1.0–2.5; g-aware); ``"dipole"`` — Jensen et al. 2001, the paper's; ``"better-dipole"`` —
d'Eon 2012; ``"pbd"`` — photon beam diffusion (Habel et al. 2013). Arguments broadcast against
each other as NumPy arrays do; every length is in mm, every coefficient in mm⁻¹.
"""

from __future__ import annotations

from typing import Any, Optional

import numpy as np

from . import _scatterfit

__all__ = ["profile", "rd_total", "albedo_from_rd"]


def _flat(*arrays: Any) -> tuple:
    """The arguments broadcast to one shape, flattened to contiguous float64, and that shape."""
    b = np.broadcast_arrays(*[np.asarray(a, dtype=np.float64) for a in arrays])
    shape = b[0].shape
    return tuple(np.ascontiguousarray(a.reshape(-1)) for a in b), shape


def profile(
    r_mm: Any,
    sigma_s_prime: Any,
    sigma_a: Any,
    eta: Any,
    g: Any = 0.0,
    *,
    model: str = "mc",
    spot_diameter_mm: Optional[float] = None,
) -> np.ndarray:
    """Diffuse reflectance Rd(r) [mm⁻²] at radius ``r_mm`` from a point of incidence (or, with
    ``spot_diameter_mm``, a uniform disk of that diameter) on a half-space with σ′s, σa [mm⁻¹],
    relative index η and Henyey–Greenstein g.

    Raises
    ------
    InputError
        A parameter out of range, or out of the model's coverage (the message names the element).
    """
    (r, s, a, n, gg), shape = _flat(r_mm, sigma_s_prime, sigma_a, eta, g)
    out = _scatterfit.profile(r, s, a, n, gg, model=model, spot_diameter_mm=spot_diameter_mm)
    return out.reshape(shape)


def rd_total(albedo_prime: Any, eta: Any, g: Any = 0.0, *, model: str = "mc") -> np.ndarray:
    """Total diffuse reflectance Rd of a half-space with reduced albedo α′ = σ′s/(σ′s + σa),
    relative index η and g (what a d/8 spectrophotometer reads, SCE)."""
    (x, n, gg), shape = _flat(albedo_prime, eta, g)
    return _scatterfit.rd_total(x, n, gg, model=model).reshape(shape)


def albedo_from_rd(rd: Any, eta: Any, g: Any = 0.0, *, model: str = "mc") -> np.ndarray:
    """The reduced albedo α′ whose total diffuse reflectance is ``rd`` (the inverse of
    :func:`rd_total`; the spectrophotometer's α′ of the proposed method)."""
    (x, n, gg), shape = _flat(rd, eta, g)
    return _scatterfit.albedo_from_rd(x, n, gg, model=model).reshape(shape)
