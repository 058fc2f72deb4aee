"""The package's types reach a type checker: mypy reads the stubs of the compiled module and the
package's annotations (py.typed), and finds a wrong argument in a user's code."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

import scatterfit


def mypy(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    try:
        import mypy  # noqa: F401
    except ImportError:
        if os.environ.get("SCATTERFIT_REQUIRE_MYPY") == "1":
            raise
        pytest.skip("no mypy in this Python")
    return subprocess.run(
        [sys.executable, "-m", "mypy", "--no-incremental", "--cache-dir", os.devnull, *args],
        cwd=cwd,
        capture_output=True,
        text=True,
        timeout=300,
    )


def test_a_user_mistake_is_seen_and_the_package_checks_clean(tmp_path: Path):
    user = tmp_path / "user.py"
    user.write_text(
        textwrap.dedent(
            """
            import numpy as np
            import scatterfit as sf

            m: sf.Measurement = sf.measure("folder")
            value: float = m["r"].sigma_a.value if m["r"].sigma_a else 0.0
            rd: np.ndarray = sf.models.rd_total(0.9, 1.4)
            sf.simulate(1.0, 0.1, 1.4, photons="many")
            """
        )
    )
    done = mypy(str(user), cwd=tmp_path)
    assert done.returncode == 1, done.stdout + done.stderr
    errors = [l for l in done.stdout.splitlines() if ": error:" in l]
    assert len(errors) == 1 and '"photons"' in errors[0], done.stdout
    package = Path(scatterfit.__file__).parent
    done = mypy("-p", "scatterfit", "--ignore-missing-imports", cwd=package.parent)
    assert done.returncode == 0, done.stdout + done.stderr
