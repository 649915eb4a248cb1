#!/usr/bin/env bash
# The Python package as a user installs it (issue #27): a fresh venv,
# `pip install ./tools/python` (scikit-build-core builds librcb through the
# repository's CMake, in a temporary directory), then, with no build tree, no
# LIBRCB_PATH, LD_LIBRARY_PATH or PYTHONPATH and from a scratch directory:
#   * import librcb loads the librcb.so shipped inside the package;
#   * one FRF (paper system, 2 outputs x 1 input, 0-500 Hz, 10000 rpm) from
#     librcb.frf equals the C CLI's CSV: the installed `rcbtool` console script,
#     and REF_RCBTOOL (the CI build's rcbtool, other options) when given;
#   * LIBRCB_PATH still overrides: a wrong path is a clear error naming it.
# Needs python3 with venv and PyPI (or a mirror/cache) for scikit-build-core,
# numpy and matplotlib; the system -dev packages of docs/python.md.
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

"$PY" -m venv "$TMP/venv"
if ! "$TMP/venv/bin/python" -m pip install --quiet --disable-pip-version-check \
  "$ROOT/tools/python" > "$TMP/pip.log" 2>&1; then
  tail -n 40 "$TMP/pip.log"
  echo "test_wheel: pip install ./tools/python failed (log above)" >&2
  exit 1
fi
echo "installed: $(cd "$TMP" && "$TMP/venv/bin/python" -m pip list 2> /dev/null | grep -i '^librcb ')"

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
echo "test_wheel: passed"
