"""simulate: Monte Carlo ground truth as arrays, checked against MCML and conservation."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest

import scatterfit as sf

from test_models import mcml_cases


def test_totals_match_mcml_within_their_standard_errors():
    cases = mcml_cases()
    for eta, a in [(1.4, 0.9), (1.0, 0.99)]:
        total = cases[(eta, a)][0]
        s = sf.simulate(a, 1.0 - a, eta, photons=100_000, seed=3)
        value, stderr = s["rd_total"]
        # MCML's own standard error at 2·10⁶ photons.
        mcml_se = np.sqrt(total * (1 - total) / 2e6)
        assert abs(value - total) < 4 * np.hypot(stderr, mcml_se), (eta, a, value, total)


def test_energy_is_conserved_and_the_seed_repeats():
    s = sf.simulate(1.0, 0.1, 1.4, photons=20_000, seed=7, thickness_mm=0.5)
    parts = s["rd_total"][0] + s["transmittance"][0] + s["absorbed"][0] + s["specular"]
    assert parts == pytest.approx(1.0, abs=1e-9)
    again = sf.simulate(1.0, 0.1, 1.4, photons=20_000, seed=7, thickness_mm=0.5)
    assert np.array_equal(s["rd"], again["rd"])
    assert s["rd"].shape == s["rd_stderr"].shape == s["r_mm"].shape == (100,)
    assert s["r_edges_mm"].shape == (101,)
    # The profile integrates to the total over its bins.
    area = np.pi * np.diff(s["r_edges_mm"] ** 2)
    assert np.sum(s["rd"] * area) <= s["rd_total"][0] + 1e-12


def test_progress_reaches_the_total():
    seen = []
    sf.simulate(1.0, 0.1, 1.4, photons=50_000, progress=lambda d, t: seen.append((d, t)))
    assert seen[-1] == (50_000, 50_000)
    assert all(d <= t for d, t in seen)


def test_bad_parameters_raise_input_error():
    with pytest.raises(sf.InputError, match="σa = 0|sigma_a|absorption"):
        sf.simulate(1.0, 0.0, 1.4)
    with pytest.raises(sf.InputError, match="r_max_mm"):
        sf.simulate(1.0, 0.1, 1.4, r_max_mm=1e-300)
    with pytest.raises(sf.InputError):
        sf.simulate(-1.0, 0.1, 1.4)
    with pytest.raises(sf.InputError, match="beam"):
        sf.simulate(1.0, 0.1, 1.4, beam="laser")
    # Work that would not finish, refused before it starts.
    with pytest.raises(sf.InputError, match="max_interactions"):
        sf.simulate(1.0, 1e-6, 1.4, photons=10**12)
    # Counts that are not counts.
    for photons in (10**30, -5, 2.5, True):
        with pytest.raises(sf.InputError, match="photons"):
            sf.simulate(1.0, 0.1, 1.4, photons=photons)
    with pytest.raises(sf.InputError, match="seed"):
        sf.simulate(1.0, 0.1, 1.4, seed=-1)


def test_ctrl_c_returns_control_during_a_long_simulation():
    # A simulation of about a minute, interrupted by SIGINT after 1 s, in a child interpreter
    # (as a notebook's kernel receives it): KeyboardInterrupt must arrive within seconds.
    code = textwrap.dedent(
        """
        import os, signal, threading, time, scatterfit
        threading.Timer(1.0, lambda: os.kill(os.getpid(), signal.SIGINT)).start()
        t0 = time.monotonic()
        try:
            scatterfit.simulate(1.0, 0.001, 1.4, photons=200_000_000)
        except KeyboardInterrupt:
            print(f"interrupted after {time.monotonic() - t0:.2f} s")
        else:
            print("finished")
        """
    )
    start = time.monotonic()
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=120, env=os.environ
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith("interrupted after"), done.stdout + done.stderr
    seconds = float(done.stdout.split()[2])
    assert seconds < 10.0, done.stdout
    assert time.monotonic() - start < 60
