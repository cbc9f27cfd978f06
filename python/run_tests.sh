#!/usr/bin/env bash
# Installs the Python package into a new virtual environment, as a user does, and runs its
# tests there:
#
#   python/run_tests.sh [VENV_DIR]                 from source: `pip install ./python`
#   python/run_tests.sh --wheel WHEEL [VENV_DIR]   a built wheel (scripts/build/wheel)
#
# (VENV_DIR: default a new temporary directory.) With --wheel, pip installs the wheel and the
# test dependencies as binary wheels only, with no Rust toolchain, C compiler or cmake on PATH;
# the script then checks that the extension links no library outside the C library (no libhdf5)
# and imports it with an empty PATH, before pytest runs.
#
# The tests that compare with the command line need its binary: `cargo build --release`
# first (CI's `cargo test --release` builds it); with TILTNOISE_BIN=/abs/path/tiltnoise they
# fail instead of being skipped when it is missing. From source, CARGO_TARGET_DIR is
# honoured, so a previous build of the crates is reused. Exits non-zero when pytest fails or
# collects no test (pytest's exit code 5).
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
wheel=""
if [ "${1:-}" = "--wheel" ]; then
  wheel="$(cd "$(dirname "${2:?--wheel needs the wheel file}")" && pwd)/$(basename "$2")"
  shift 2
fi
venv="${1:-$(mktemp -d)/venv}"
python3 -m venv "$venv"
"$venv/bin/pip" install --quiet --disable-pip-version-check --upgrade pip
# h5py: the comparisons of HDF5 files with the command line's; mypy: the stubs against the
# module (mypy.stubtest); matplotlib: the example figure; gwpy: the budget's ASDs read as
# gwpy FrequencySeries. Without them those tests are skipped.
test_deps=(pytest hypothesis numpy scipy h5py mypy matplotlib gwpy)
if [ -z "$wheel" ]; then
  "$venv/bin/pip" install --quiet "$here" "${test_deps[@]}"
else
  # PATH without the directories of cargo, rustc, cc, gcc and cmake: nothing may be built.
  bare_path=""
  IFS=: read -r -a dirs <<<"$PATH"
  for d in "${dirs[@]}"; do
    skip=""
    for tool in cargo rustc cc gcc cmake; do
      if [ -x "$d/$tool" ]; then skip=1; fi
    done
    if [ -z "$skip" ]; then bare_path="${bare_path:+$bare_path:}$d"; fi
  done
  PATH="$bare_path" "$venv/bin/pip" install --quiet --disable-pip-version-check \
    --only-binary :all: "$wheel" "${test_deps[@]}"
  ext=$("$venv/bin/python" -c 'import tiltnoise._tiltnoise as m; print(m.__file__)')
  # Only the C library's own objects (and the dynamic loader): no libhdf5, no libpython.
  if others=$(ldd "$ext" | grep -vE '^\s*(linux-vdso|/lib64/ld-linux|lib(c|m|dl|pthread|rt|gcc_s|util)\.so)'); then
    echo "python/run_tests.sh: $ext links libraries outside the C library:" >&2
    echo "$others" >&2
    exit 1
  fi
  env -i "$venv/bin/python" -c 'import tiltnoise; tiltnoise.Model().modes()'
  echo "wheel $(basename "$wheel"): installed without a compiler, imported with an empty PATH"
fi
# From outside the source tree, so that the installed package is imported and not
# python/tiltnoise/ (which holds no extension, or a stale one from `maturin develop`).
cd "$(mktemp -d)"
"$venv/bin/pytest" "$here/tests" -ra -p no:cacheprovider
