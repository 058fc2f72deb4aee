"""fit_profile: a profile given as arrays, fitted as `scatterfit fit` fits the same table."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import scatterfit as sf

from conftest import run_cli
from test_measure import without_timings


def read_profile_csv(path: Path):
    t = np.genfromtxt(path, delimiter=",", names=True)
    cols = lambda what: np.stack([t[f"{what}_{c}"] for c in "rgb"], axis=1)  # noqa: E731
    return t["r_mm"], cols("value"), cols("stderr"), cols("count"), cols("limit")


def test_equals_the_cli_fit_of_the_same_table(wood: Path, tmp_path: Path):
    m = sf.measure(wood)
    m.write(tmp_path / "o")
    table = tmp_path / "o" / "profile.csv"
    albedo = [m[c].albedo_prime.value for c in "rgb"]
    args = ["--eta", repr(m.eta), "--albedo", ",".join(repr(a) for a in albedo)]
    done = run_cli("fit", str(table), *args, "--json")
    assert done.returncode == 0, done.stderr
    cli = json.loads(done.stdout)
    r, value, stderr, count, limit = read_profile_csv(table)
    got = sf.fit_profile(
        r, value, stderr, count=count, limit=limit, eta=m.eta, albedo=albedo, name="profile"
    )
    mine, theirs = without_timings(got.to_dict()), without_timings(cli)
    # The CLI names the file it read; the arrays have none.
    theirs["inputs"].pop("profile", None), mine["inputs"].pop("profile", None)
    for c in "rgb":
        for key in ("sigma_s_prime", "sigma_a"):
            ours, cli_value = mine["channels"][c][key], theirs["channels"][c][key]
            for term in ("value", "fit"):
                assert ours[term] == pytest.approx(cli_value[term], rel=1e-9), (c, key, term)
        assert mine["channels"][c]["rings_used"] == theirs["channels"][c]["rings_used"]
    # And close to the measurement it came from (the same rings, no spectrophotometer term).
    for c in "rgb":
        assert got[c].sigma_s_prime.value == pytest.approx(m[c].sigma_s_prime.value, rel=0.02)


def test_one_channel_and_a_model_profile():
    # A dipole profile (point source convolved with a 1 mm spot) fitted back with the dipole.
    r = np.linspace(1.0, 8.0, 60)
    truth = 1.3
    rd = sf.models.profile(r, truth, 0.02, 1.4, model="dipole", spot_diameter_mm=1.0)
    albedo = truth / (truth + 0.02)
    result = sf.fit_profile(r, 1000 * rd, 0.01 * 1000 * rd, eta=1.4, albedo=albedo, model="dipole")
    assert result["r"].sigma_s_prime.value == pytest.approx(truth, rel=1e-3)
    assert result["g"].sigma_a.value == pytest.approx(0.02, rel=1e-3)


def test_bad_arrays_raise_input_error():
    r = np.linspace(1.0, 5.0, 10)
    with pytest.raises(sf.InputError, match="shape"):
        sf.fit_profile(r, np.ones((10, 2)), np.ones((10, 2)), eta=1.4, albedo=0.9)
    with pytest.raises(sf.InputError, match="albedo|α′"):
        sf.fit_profile(r, np.ones(10), np.ones(10), eta=1.4)
    with pytest.raises(sf.InputError, match="eta"):
        sf.fit_profile(r, np.ones(10), np.ones(10), eta=4.0, albedo=0.9)
    with pytest.raises(sf.InputError, match="increase"):
        sf.fit_profile(r[::-1], np.ones(10), np.ones(10), eta=1.4, albedo=0.9)
