#!/usr/bin/env bash
# The Python package as a user installs it (issues #27, #36): pyproject.toml at
# the repository root, built by `python -m build` in a fresh venv: the sdist,
# then the wheel from that sdist (scikit-build-core compiles librcb through
# the CMake project inside the sdist, in a temporary directory), so the sdist
# is shown to hold every C source the build reads. `pip install .` and
# `pip install <URL>` run the same backend on the checkout or the unpacked
# archive. The wheel is installed into the venv; then, with no build tree, no
# LIBRCB_PATH, LD_LIBRARY_PATH or PYTHONPATH and from a scratch directory:
#   * import librcb loads the librcb.so shipped inside the package;
#   * one FRF (paper system, 2 outputs x 1 input, 0-500 Hz, 10000 rpm) from
#     librcb.frf equals the C CLI's CSV: the installed `rcbtool` console script,
#     and REF_RCBTOOL (the CI build's rcbtool, other options) when given;
#   * LIBRCB_PATH still overrides: a wrong path is a clear error naming it;
#   * the package's own tests (tests/python/test_package_*.py) pass against the
#     installed package, RCBTOOL the installed console script (those needing
#     dask or pyuff skip here: the pytest stage runs them on the build).
# Needs python3 with venv and PyPI (or a mirror/cache) for build,
# scikit-build-core, numpy, matplotlib and pytest; the system -dev packages of
# docs/python.md.
#
# usage: tests/wheel/test_wheel.sh [REF_RCBTOOL]      exit 0 pass, 1 fail
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
REF=${1:-}
[[ -z $REF ]] || REF=$(realpath "$REF")
PY=${PYTHON3:-python3}
TMP=$(mktemp -d "${TMPDIR:-/tmp}/rcb_wheel.XXXXXX")
trap 'rm -rf "$TMP"' EXIT
unset LIBRCB_PATH LD_LIBRARY_PATH PYTHONPATH RCBTOOL
export OPENBLAS_NUM_THREADS=1 CMAKE_BUILD_PARALLEL_LEVEL=${JOBS:-2}

# pytest at requirements.txt's pin; build as PyPI has it (a frontend only)
PYTEST=$(grep -E '^pytest==' "$ROOT/requirements.txt" || echo pytest)
VPY=$TMP/venv/bin/python
pipq() { "$VPY" -m pip install --quiet --disable-pip-version-check "$@"; }
step() { # WHAT CMD...: CMD's output to a log shown only when it fails
  local what=$1
  shift
  if ! "$@" > "$TMP/step.log" 2>&1; then
    tail -n 40 "$TMP/step.log"
    echo "test_wheel: $what failed (log above)" >&2
    exit 1
  fi
}
"$PY" -m venv "$TMP/venv"
step "pip install build $PYTEST" pipq build "$PYTEST"
step "python -m build (sdist, then the wheel from it)" \
  "$VPY" -m build --outdir "$TMP/dist" "$ROOT"
sdist=("$TMP"/dist/librcb-*.tar.gz)
whl=("$TMP"/dist/librcb-*.whl)
step "pip install ${whl[0]##*/}" pipq "${whl[0]}"
echo "built: ${sdist[0]##*/} ($(du -k "${sdist[0]}" | cut -f1) kB), ${whl[0]##*/} ($(du -k "${whl[0]}" | cut -f1) kB)"
echo "installed: $(cd "$TMP" && "$VPY" -m pip list 2> /dev/null | grep -i '^librcb ')"

cp "$ROOT/examples/paper_system.ini" "$TMP/model.ini"
cd "$TMP"
args=(frf model.ini --out C.A.x,DB.y --in DA.x --fmin 0 --fmax 500 --points 201 --rpm 10000)
"$TMP/venv/bin/rcbtool" "${args[@]}" -o pkg.csv
[[ -z $REF ]] || "$REF" "${args[@]}" -o ref.csv
[[ -x $TMP/venv/bin/rcbplot ]] || { echo "test_wheel: no rcbplot console script" >&2; exit 1; }

"$TMP/venv/bin/python" - "$TMP" "${REF:+ref.csv}" <<'PY'
import os, subprocess, sys
from pathlib import Path
import numpy as np
import librcb

tmp = Path(sys.argv[1])
pkg = Path(librcb.__file__).resolve().parent
lib = Path(librcb.library_path()).resolve()
assert lib.parent == pkg, f"librcb.so loaded from {lib}, not from the package {pkg}"
assert str(tmp) in str(pkg), pkg

m = librcb.Model.from_ini("model.ini")
f = np.linspace(0, 500, 201)
H = librcb.frf(m, ["C.A.x", "DB.y"], ["DA.x"], f, rpm=10000)[:, :, 0]
for name in ["pkg.csv"] + [a for a in sys.argv[2:] if a]:
    d = np.loadtxt(name, delimiter=",", comments="#", skiprows=3)
    assert d.shape == (201, 5), d.shape
    assert np.array_equal(d[:, 0], f), "frequency column"
    C = d[:, 1::2] + 1j * d[:, 2::2]
    err = np.max(np.abs(C - H)) / np.max(np.abs(H))
    assert err < 1e-10, f"{name}: librcb.frf differs from rcbtool by {err:.3g} (max |H|)"
    print(f"  librcb.frf vs {name}: max |difference| / max |H| = {err:.2e}")

# LIBRCB_PATH stays the override: a wrong one is an error that names it
code = "import librcb; librcb.library_version()"
env = dict(os.environ, LIBRCB_PATH=str(tmp / "nosuch.so"))
r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env)
assert r.returncode != 0 and "LIBRCB_PATH" in r.stderr and "not found" in r.stderr, r.stderr
print(f"  library {lib.name} in the package ({lib.stat().st_size} bytes), version "
      f"{librcb.library_version()}; LIBRCB_PATH override checked")
PY

# The package's own tests, on the installed package: pytest from the scratch
# directory puts tests/python on sys.path, never tools/python.
RCBTOOL=$TMP/venv/bin/rcbtool "$VPY" -m pytest -q -p no:cacheprovider \
  "$ROOT"/tests/python/test_package_*.py
echo "test_wheel: passed"
