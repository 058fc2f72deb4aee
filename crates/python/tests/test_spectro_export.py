"""spectro (file and arrays), export to every format, and the Mitsuba dict rendered by Mitsuba 3."""

from __future__ import annotations

import json
import os
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import scatterfit as sf

from conftest import run_cli


def test_spectro_from_a_file_and_from_arrays_agree(wood: Path):
    from_file = sf.spectro(wood / "spectro.csv")
    t = np.genfromtxt(wood / "spectro.csv", delimiter=",", names=True, skip_header=1)
    from_arrays = sf.spectro(wavelengths_nm=t["wavelength_nm"], sci=t["sci"], sce=t["sce"])
    assert from_file == from_arrays
    truth = json.loads((wood / "truth.json").read_text())
    assert from_file["eta"] == pytest.approx(truth["eta"], rel=0.02)
    # The same as the CLI's `spectro --json`.
    done = run_cli("spectro", str(wood / "spectro.csv"), "--json")
    assert done.returncode == 0, done.stderr
    cli = json.loads(done.stdout)
    assert cli["eta"] == from_file["eta"] and cli["channels"] == from_file["channels"]


def test_spectro_bad_input():
    with pytest.raises(sf.InputError, match="CSV file, or"):
        sf.spectro()
    with pytest.raises(sf.InputError):
        sf.spectro(wavelengths_nm=[400, 410], sci=[0.1], sce=[0.1, 0.1])
    with pytest.raises(sf.InputError, match="observer"):
        sf.spectro(wavelengths_nm=[400.0], sci=[0.1], sce=[0.1], lab=(50, 0, 0), observer=5)


@pytest.mark.parametrize("to", ["mitsuba", "pbrt", "blender", "json"])
def test_export_equals_the_cli_export(wood: Path, tmp_path: Path, to: str):
    m = sf.measure(wood)
    m.write(tmp_path / "o")
    result = tmp_path / "o" / "result.json"
    done = run_cli("export", str(result), "--to", to)
    assert done.returncode == 0, done.stderr
    # From the file and from the measurement alike.
    assert sf.export(result, to) == done.stdout
    assert sf.export(m, to) == done.stdout
    with warnings.catch_warnings():
        # Mitsuba's ray offset in a metre scene: the export says so (a note, not the subject here).
        warnings.simplefilter("ignore")
        assert sf.export(m.to_dict(), to, scale="m") != done.stdout


def test_export_of_a_suspect_result_warns(wood: Path):
    d = sf.measure(wood).to_dict()
    d["channels"]["g"]["quality"] = {
        "verdict": "suspect",
        "reasons": [{"kind": "poor_fit", "severity": "suspect", "message": "a test"}],
    }
    with pytest.warns(sf.SuspectResultWarning, match="G suspect"):
        sf.export(d, "json")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sf.export(d, "json", allow_suspect=True)
    failed = json.loads(json.dumps(d))
    failed["channels"]["b"]["sigma_a"] = None
    failed["channels"]["b"]["status"] = "failed"
    with pytest.raises((sf.MeasurementError, sf.InputError)):
        sf.export(failed, "mitsuba", allow_suspect=True)
    with pytest.raises(sf.InputError, match="formats"):
        sf.export(d, "maya")


def _mitsuba(home: Path) -> Any:
    """The `mitsuba` module, or the test skipped (failed with SCATTERFIT_REQUIRE_MITSUBA=1)."""
    try:
        os.environ.setdefault("HOME", str(home))
        import mitsuba as mi
    except ImportError:
        if os.environ.get("SCATTERFIT_REQUIRE_MITSUBA") == "1":
            raise
        pytest.skip("no `mitsuba` package in this Python")
    return mi


def test_mitsuba_dict_renders_with_scalar_rgb(wood: Path):
    mi = _mitsuba(wood)
    mi.set_variant("scalar_rgb")
    m = sf.measure(wood)
    shape = sf.mitsuba_dict(m, shape={"type": "sphere", "radius": 20.0})
    assert shape["interior"]["type"] == "homogeneous"
    # load_dict takes the dict as it is.
    mi.load_dict(shape)
    scene = mi.load_dict(
        {
            "type": "scene",
            "integrator": sf.mitsuba_integrator(m) | {"max_depth": 256},
            "sensor": {
                "type": "perspective",
                "fov": 30,
                "to_world": mi.ScalarTransform4f().look_at(origin=[0, 0, 100], target=[0, 0, 0], up=[0, 1, 0]),
                "film": {"type": "hdrfilm", "width": 8, "height": 8, "rfilter": {"type": "box"}},
                "sampler": {"type": "independent", "sample_count": 16},
            },
            "light": {"type": "constant"},
            "object": shape,
        }
    )
    image = np.array(mi.render(scene))
    assert np.all(np.isfinite(image))
    centre = image[3:5, 3:5].reshape(-1, image.shape[-1]).mean(axis=0)
    # The wood tile reflects red most and blue least (its α′ falls from R to B): the render keeps
    # the channels in order, and the sphere under a white sky is neither black nor brighter than it.
    assert centre[0] > centre[1] > centre[2] > 0.02
    assert centre[0] < 1.05


def test_mitsuba_dict_matches_the_export_and_loads_spectral(wood: Path):
    mi = _mitsuba(wood)
    m = sf.measure(wood)
    # The dict's numbers are the XML fragment's own.
    xml = sf.export(m, "mitsuba")
    d = sf.mitsuba_dict(m)
    assert f'<float name="int_ior" value="{d["bsdf"]["int_ior"]!r}"/>' in xml
    assert f'<float name="scale" value="{d["interior"]["scale"]!r}"/>' in xml
    assert sf.mitsuba_integrator(m)["rr_depth"] >= 1
    # The spectral medium: per-wavelength pairs that a spectral variant loads.
    spectral = sf.mitsuba_dict(m, mitsuba_variant="spectral")
    sigma_t = spectral["interior"]["sigma_t"]
    assert sigma_t["type"] == "spectrum" and len(sigma_t["value"]) > 10
    assert all(isinstance(p, tuple) and len(p) == 2 for p in sigma_t["value"])
    mi.set_variant("scalar_spectral")
    mi.load_dict(spectral)
    with pytest.raises(sf.InputError, match="mitsuba_variant"):
        sf.mitsuba_dict(m, mitsuba_variant="cmyk")
