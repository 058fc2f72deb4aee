#!/usr/bin/env bash
# The Python package's tests (crates/python/tests, pytest), in the virtual environment that holds
# Mitsuba (.ci/venv, made by .ci/run's provisioning, or here when missing): the compiled module is
# built into it by `maturin develop` with the workspace's dev profile (optimised; it reuses the
# workspace's compiled crates, so only PyO3 and the module itself compile: ~20 s), then pytest runs
# every test against the CLI that `cargo test` built (target/debug/scatterfit), the real Mitsuba
# included (SCATTERFIT_REQUIRE_MITSUBA=1 makes its absence a failure, not a skip), and mypy on the
# package's types (SCATTERFIT_REQUIRE_MYPY=1 likewise).
#
# Run it from the repository root after `cargo build -p scatterfit` (or `cargo test --workspace`):
#   bash .ci/python-test.sh
set -euo pipefail
cd "$(dirname "$0")/.."

VENV="$PWD/.ci/venv"
MATURIN_VERSION=1.16.0
PYTEST_VERSION=9.2.0
NUMPY_VERSION=2.4.6
MYPY_VERSION=2.4.1
if [ ! -x "$VENV/bin/python" ]; then
  python3 -m venv "$VENV"
fi
if ! "$VENV/bin/python" -c "import maturin, pytest, numpy, mypy, sys; sys.exit(pytest.__version__ != '${PYTEST_VERSION}')" 2>/dev/null; then
  "$VENV/bin/pip" install --no-cache-dir --disable-pip-version-check --quiet \
    "maturin==${MATURIN_VERSION}" "pytest==${PYTEST_VERSION}" "numpy==${NUMPY_VERSION}" \
    "mypy==${MYPY_VERSION}"
fi

echo "== maturin develop (the scatterfit Python package into .ci/venv)"
start=$(date +%s)
VIRTUAL_ENV="$VENV" PATH="$VENV/bin:$PATH" "$VENV/bin/maturin" develop --quiet --profile dev \
  --manifest-path crates/python/Cargo.toml
echo "built and installed in $(( $(date +%s) - start )) s"

echo "== pytest crates/python/tests"
# (HOME inside the venv for the tests only: Dr.Jit makes a cache folder in $HOME when mitsuba is
# imported; rustup and cargo above need the real one.)
HOME="$VENV" SCATTERFIT_CLI="${SCATTERFIT_CLI:-$PWD/target/debug/scatterfit}" \
  "$VENV/bin/python" -m pytest -q -p no:cacheprovider crates/python/tests
