"""Shared fixtures: the scatterfit CLI (to compare with) and rig-twin sample folders it writes."""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[3]


def cli_path() -> Path:
    """The CLI built from this checkout: $SCATTERFIT_CLI, else target/debug or target/release."""
    given = os.environ.get("SCATTERFIT_CLI")
    if given:
        return Path(given)
    for profile in ("debug", "release"):
        p = ROOT / "target" / profile / "scatterfit"
        if p.is_file():
            return p
    raise RuntimeError(
        "no scatterfit binary: build it with `cargo build -p scatterfit` or set SCATTERFIT_CLI"
    )


def run_cli(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess:
    return subprocess.run(
        [str(cli_path()), *args], cwd=cwd, capture_output=True, text=True, timeout=600
    )


@pytest.fixture(scope="session")
def twins(tmp_path_factory) -> Path:
    """Quick rig twins (wood tile, pink plastic), written once by `scatterfit synth --quick`."""
    root = tmp_path_factory.mktemp("twins")
    for material in ("wood-tile", "pink-plastic"):
        done = run_cli("synth", "--material", material, "--quick", "-o", str(root / material))
        assert done.returncode == 0, done.stderr
    return root


@pytest.fixture
def wood(twins: Path, tmp_path: Path) -> Path:
    """A private copy of the wood-tile twin (tests may write into it)."""
    dst = tmp_path / "wood-tile"
    shutil.copytree(twins / "wood-tile", dst)
    return dst
