#!/usr/bin/env bash
# The self-contained wheel, tested where nothing else is (issue #36 item 1;
# run by `./scripts/dev.sh wheel-manylinux` inside a fresh copy of a minimal
# Debian 11 root holding python3 and python3-venv only; docs/python.md):
#   * the root is shown to hold none of the libraries the wheel vendors, no
#     compiler and no -dev package;
#   * a venv (Debian's pip 20.3.4) installs the wheel and, from PyPI, its
#     dependencies numpy and matplotlib (requirements-manylinux-test.txt);
#   * manylinux_check.py: import, an FRF against a closed form, the paper
#     system's FRF against numpy, the rcbtool console script, one fit, and the
#     import times.
# usage: manylinux_test.sh WHEEL          (its folder also holds the check
#                                          script, the pins and paper_system.ini)
set -euo pipefail
WHL=$1
DIR=$(cd "$(dirname "$WHL")" && pwd)
fail() { echo "manylinux_test: $*" >&2; exit 1; }
t0=$SECONDS
echo "root: $(. /etc/os-release && echo "$PRETTY_NAME"), $(ldd --version | head -n1), $(python3 --version)," \
  "$(dpkg-query -W -f='${binary:Package}\n' | wc -l) Debian packages"
vendored='libopenblas|libblas|liblapack|liblapacke|libklu|libamd|libcolamd|libbtf|libsuitesparseconfig|libnlopt|libinih|libfftw3|libgfortran|libquadmath'
if ldconfig -p | grep -E "($vendored)\.so"; then
  fail "the root is not clean: the loader finds the libraries above"
fi
if dpkg-query -W -f='${binary:Package}\n' | grep -E -- '-dev(:|$)|^(gcc|cc|cpp)(-[0-9]+)?(:|$)'; then
  fail "the root is not clean: the packages above are installed"
fi
echo "  none of $(tr '|' ' ' <<< "$vendored") in the loader's cache; no compiler, no -dev package"
python3 -m venv /tmp/venv
VPY=/tmp/venv/bin/python
t=$SECONDS
"$VPY" -m pip install --quiet --disable-pip-version-check -c "$DIR/requirements-manylinux-test.txt" "$WHL" ||
  fail "pip install ${WHL##*/} failed"
echo "pip install ${WHL##*/} (with numpy, matplotlib from PyPI) in $((SECONDS - t)) s ($("$VPY" -m pip --version | cut -d' ' -f1-2))"
cd /tmp
PATH=/tmp/venv/bin:$PATH "$VPY" "$DIR/manylinux_check.py" "$DIR/paper_system.ini"
echo "manylinux_test: passed in $((SECONDS - t0)) s"
