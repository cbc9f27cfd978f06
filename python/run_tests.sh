#!/usr/bin/env bash
# Builds and installs the Python package into a new virtual environment, exactly as a user
# does (`pip install ./python`), and runs its tests there:
#
#   python/run_tests.sh [VENV_DIR]        (default: a new temporary directory)
#
# The tests that compare with the command line need its binary: `cargo build --release`
# first (CI's `cargo test --release` builds it); with TILTNOISE_BIN=/abs/path/tiltnoise they
# fail instead of being skipped when it is missing. CARGO_TARGET_DIR is
# honoured, so a previous build of the crates is reused. Exits non-zero when pytest fails or
# collects no test (pytest's exit code 5).
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
venv="${1:-$(mktemp -d)/venv}"
python3 -m venv "$venv"
"$venv/bin/pip" install --quiet --upgrade pip
# h5py: the comparisons of HDF5 files with the command line's; mypy: the stubs against the
# module (mypy.stubtest); matplotlib: the example figure; gwpy: the budget's ASDs read as
# gwpy FrequencySeries. Without them those tests are skipped.
"$venv/bin/pip" install --quiet "$here" pytest hypothesis numpy scipy h5py mypy matplotlib gwpy
# From outside the source tree, so that the installed package is imported and not
# python/tiltnoise/ (which holds no extension, or a stale one from `maturin develop`).
cd "$(mktemp -d)"
"$venv/bin/pytest" "$here/tests" -ra -p no:cacheprovider
