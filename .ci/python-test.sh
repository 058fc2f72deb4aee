#!/usr/bin/env bash
# The Python package's tests (crates/python/tests, pytest), in the virtual environment that holds
# Mitsuba (.ci/venv, made by .ci/run's provisioning, or here when missing), against the CLI that
# `cargo test` built (target/debug/scatterfit): the real Mitsuba included
# (SCATTERFIT_REQUIRE_MITSUBA=1 makes its absence a failure, not a skip), and mypy on the package's
# types (SCATTERFIT_REQUIRE_MYPY=1 likewise).
#
# The compiled module is built by cargo with the workspace's own dependency features
# (`cargo build --workspace --lib --tests`: after `cargo test --workspace` only PyO3, rust-numpy and
# the module compile, ~30 s) and put beside the package's Python files in a temporary folder, as
# `maturin develop` would put it in the source tree. maturin itself builds the crate alone, whose
# dependencies resolve to other features than the workspace's, so that it recompiled some forty
# crates (163 s in a CI run); the module it makes is the same code. `pip install ./crates/python`
# (maturin, README.md "Using it from Python") is how a user installs it.
#
# Run it from the repository root (after `cargo test --workspace`, or it builds the tests first):
#   bash .ci/python-test.sh
set -euo pipefail
cd "$(dirname "$0")/.."

VENV="$PWD/.ci/venv"
PYTEST_VERSION=9.2.0
NUMPY_VERSION=2.4.6
MYPY_VERSION=2.4.1
if [ ! -x "$VENV/bin/python" ]; then
  python3 -m venv "$VENV"
fi
if ! "$VENV/bin/python" -c "import pytest, numpy, mypy, sys; sys.exit(pytest.__version__ != '${PYTEST_VERSION}')" 2>/dev/null; then
  "$VENV/bin/pip" install --no-cache-dir --disable-pip-version-check --quiet \
    "pytest==${PYTEST_VERSION}" "numpy==${NUMPY_VERSION}" "mypy==${MYPY_VERSION}"
fi

echo "== the scatterfit Python package (compiled module: cargo, the workspace's features)"
start=$(date +%s)
cargo build --quiet --workspace --lib --tests
package="$(mktemp -d)"
trap 'rm -rf "$package"' EXIT
cp -r crates/python/python/scatterfit "$package/"
rm -f "$package"/scatterfit/*.so
cp target/debug/lib_scatterfit.so "$package/scatterfit/_scatterfit.abi3.so"
echo "built in $(( $(date +%s) - start )) s"

echo "== pytest crates/python/tests"
# (HOME inside the venv for the tests only: Dr.Jit makes a cache folder in $HOME when mitsuba is
# imported; cargo above needs the real one.)
HOME="$VENV" PYTHONPATH="$package" SCATTERFIT_CLI="${SCATTERFIT_CLI:-$PWD/target/debug/scatterfit}" \
  "$VENV/bin/python" -m pytest -q -p no:cacheprovider crates/python/tests
