"""The forward models over arrays: shapes and broadcasting, and the physics against MCML
(data/reference/mcml_profiles.csv: the original MCML C code, 2·10⁶ photons per case) and
against energy conservation (the profile integrates to the total)."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
import pytest

import scatterfit as sf

from conftest import ROOT

MCML = ROOT / "data" / "reference" / "mcml_profiles.csv"


def mcml_cases():
    """{(η, α′): (Rd_total, r_mm array, Rd(r) array)} at σ′t = 1 mm⁻¹, g = 0."""
    rows = [r for r in csv.reader(l for l in MCML.open() if not l.startswith("#"))]
    cases = {}
    for eta, a, total, _spec, r, rd in rows[1:]:
        key = (float(eta), float(a))
        entry = cases.setdefault(key, (float(total), [], []))
        entry[1].append(float(r))
        entry[2].append(float(rd))
    return {k: (t, np.array(r)[:-1], np.array(v)[:-1]) for k, (t, r, v) in cases.items()}


def test_broadcasting_and_dtypes():
    r = np.linspace(0.5, 5, 7)
    sp = np.array([[0.5], [1.0], [2.0]])
    out = sf.models.profile(r, sp, 0.01, 1.4, model="dipole")
    assert out.shape == (3, 7) and out.dtype == np.float64
    # Each row is the profile of that σ′s alone.
    for k in range(3):
        assert np.array_equal(out[k], sf.models.profile(r, float(sp[k, 0]), 0.01, 1.4, model="dipole"))
    assert sf.models.profile(1.0, 1.0, 0.01, 1.4).shape == ()
    assert sf.models.rd_total([[0.5, 0.9]], [1.0, 1.4]).shape == (1, 2)
    # Integer and list inputs are taken as float64.
    assert sf.models.rd_total([1], 1, model="dipole").dtype == np.float64


@pytest.mark.parametrize("eta", [1.0, 1.4, 2.0])
def test_mc_totals_match_mcml(eta):
    for (e, a), (total, _, _) in mcml_cases().items():
        if e != eta:
            continue
        got = float(sf.models.rd_total(a, eta, model="mc"))
        # MCML's own noise at 2·10⁶ photons is ≤ 3.5·10⁻⁴ (√(Rd(1−Rd)/N)); the tables' ≤ 1·10⁻³.
        assert got == pytest.approx(total, abs=2e-3), (eta, a)


def test_mc_profile_matches_mcml_between_1_and_5_transport_lengths():
    for (eta, a), (_, r, rd) in mcml_cases().items():
        if a < 0.9:
            continue
        sel = (r > 1.0) & (r < 5.0)
        model = sf.models.profile(r[sel], a, 1.0 - a, eta, model="mc")
        # MCML's bin noise (the file's note): relative 1/√(N 2πr dr Rd), N = 2·10⁶, dr = 0.05 mm;
        # within 4 of its standard errors plus 2 % for the tables' own accuracy.
        noise = rd[sel] / np.sqrt(2e6 * 2 * np.pi * r[sel] * 0.05 * rd[sel])
        assert np.all(np.abs(model - rd[sel]) < 4 * noise + 0.02 * rd[sel]), (eta, a)


@pytest.mark.parametrize("model", ["dipole", "better-dipole", "mc"])
def test_the_profile_integrates_to_the_total(model):
    # ∫ 2πr Rd(r) dr over the surface is the total diffuse reflectance (energy conservation):
    # a check of the profile against the model's own total through an independent quadrature.
    sp, sa, eta = 1.0, 0.05, 1.4
    r = np.concatenate([np.geomspace(1e-4, 0.1, 400), np.linspace(0.1, 60, 20000)[1:]])
    rd = sf.models.profile(r, sp, sa, eta, model=model)
    integral = np.trapezoid(2 * np.pi * r * rd, r)
    total = float(sf.models.rd_total(sp / (sp + sa), eta, model=model))
    assert integral == pytest.approx(total, rel=0.03)


@pytest.mark.parametrize("model", ["dipole", "mc"])
def test_albedo_from_rd_inverts_rd_total(model):
    a = np.array([0.3, 0.6, 0.9, 0.99, 0.999])
    eta = np.array([[1.0], [1.4], [2.0]])
    rd = sf.models.rd_total(a, eta, model=model)
    assert rd.shape == (3, 5)
    assert np.all(np.diff(rd, axis=1) > 0)
    assert np.allclose(sf.models.albedo_from_rd(rd, eta, model=model), a, rtol=1e-6, atol=1e-9)


def test_bad_parameters_raise_input_error():
    with pytest.raises(sf.InputError, match="element 1"):
        sf.models.profile([1.0, 2.0], [1.0, -1.0], 0.1, 1.4, model="dipole")
    with pytest.raises(sf.InputError, match="dipole"):
        sf.models.rd_total(0.5, 1.4, model="diffusion-theory")
    with pytest.raises(sf.InputError):
        sf.models.profile([-1.0], 1.0, 0.1, 1.4)
    with pytest.raises(sf.InputError, match="η|eta"):
        sf.models.profile([1.0], 1.0, 0.1, 9.0, model="mc")
    with pytest.raises(ValueError):
        # A shape mismatch NumPy cannot broadcast.
        sf.models.rd_total([0.5, 0.6], [1.0, 1.2, 1.4])
