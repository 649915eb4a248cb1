#!/usr/bin/env bash
# ctest driver (test "install_consumer"): install a librcb build tree into a
# scratch prefix, build this consumer against it with find_package(rcb) and
# find_package(librcb), with pkg-config rcb (shared) and pkg-config librcb
# (static, the firmware-style link), run each as it is and in the caller's
# memory (--arena: the allocator hooks), and check the printed values against
# the closed form below, and the hooks' counts: every allocation through them,
# and in the static links (the C heap counted by --wrap) none from librcb.a.
#
# usage: run_consumer_test.sh CMAKE BUILD_DIR WORK_DIR [C_COMPILER]
set -euo pipefail
cmake_cmd=$1
build_dir=$2
work=$3
cc=${4:-cc}
here=$(cd "$(dirname "$0")" && pwd)

rm -rf "$work"
mkdir -p "$work"
prefix=$work/prefix
"$cmake_cmd" --install "$build_dir" --prefix "$prefix" > "$work/install.log"
# The installed rcbtool (when built) must find the installed library by itself.
if [[ -e $prefix/bin/rcbtool ]]; then
  env -u LD_LIBRARY_PATH "$prefix/bin/rcbtool" --version
fi

# 1. CMake package: rcb::rcb (shared) and rcb::rcb_static.
"$cmake_cmd" -S "$here" -B "$work/build" -DCMAKE_PREFIX_PATH="$prefix" \
  -DCMAKE_C_COMPILER="$cc" -DCMAKE_BUILD_TYPE=Release > "$work/configure.log"
"$cmake_cmd" --build "$work/build" > "$work/build.log"
runs=("$work/build/rcb_consumer")
[[ -x $work/build/rcb_consumer_static ]] && runs+=("$work/build/rcb_consumer_static")

# 1a. The same package under the project's name: find_package(librcb).
"$cmake_cmd" -S "$here" -B "$work/build-librcb" -DCMAKE_PREFIX_PATH="$prefix" -DRCB_PACKAGE=librcb \
  -DCMAKE_C_COMPILER="$cc" -DCMAKE_BUILD_TYPE=Release > "$work/configure-librcb.log" 2>&1 ||
  { cat "$work/configure-librcb.log"; echo "FAIL: find_package(librcb 0.1) does not find the package"; exit 1; }
"$cmake_cmd" --build "$work/build-librcb" > "$work/build-librcb.log"
runs+=("$work/build-librcb/rcb_consumer")
[[ -x $work/build-librcb/rcb_consumer_static ]] && runs+=("$work/build-librcb/rcb_consumer_static")

# 1b. A shared-library consumer on a machine without the static library's
# dependencies (issue #17): NLopt and SUNDIALS made unfindable. find_package(rcb)
# still succeeds, rcb::rcb links, and rcb::rcb_static is left out.
cfg=$(find "$prefix" -name rcbConfig.cmake | head -n 1)
if [[ -f $(dirname "$cfg")/rcbTargets.cmake ]]; then
  "$cmake_cmd" -S "$here" -B "$work/build-nodeps" -DCMAKE_PREFIX_PATH="$prefix" \
    -DCMAKE_DISABLE_FIND_PACKAGE_NLopt=ON -DCMAKE_DISABLE_FIND_PACKAGE_SUNDIALS=ON \
    -DCMAKE_C_COMPILER="$cc" -DCMAKE_BUILD_TYPE=Release > "$work/configure-nodeps.log" 2>&1 ||
    { cat "$work/configure-nodeps.log"; echo "FAIL: find_package(rcb) needs NLopt/SUNDIALS for the shared library"; exit 1; }
  "$cmake_cmd" --build "$work/build-nodeps" > "$work/build-nodeps.log"
  runs+=("$work/build-nodeps/rcb_consumer")
fi
if [[ -f $(dirname "$cfg")/rcbTargets.cmake && -f $(dirname "$cfg")/rcbStaticTargets.cmake ]] &&
  grep -Eq '^set\(RCB_WITH_(NLOPT|SUNDIALS) ON\)' "$cfg"; then
  [[ ! -e $work/build-nodeps/rcb_consumer_static ]] ||
    { echo "FAIL: rcb::rcb_static defined without its dependencies"; exit 1; }
  # 1c. asking for the static library then fails, naming what is missing
  if "$cmake_cmd" -S "$here/../firmware" -B "$work/fw-nodeps" -DCMAKE_PREFIX_PATH="$prefix" \
    -DCMAKE_DISABLE_FIND_PACKAGE_NLopt=ON -DCMAKE_DISABLE_FIND_PACKAGE_SUNDIALS=ON \
    -DCMAKE_C_COMPILER="$cc" > "$work/fw-nodeps.log" 2>&1; then
    echo "FAIL: COMPONENTS static found without NLopt/SUNDIALS"; exit 1
  fi
  grep -Eq 'NLopt|SUNDIALS' "$work/fw-nodeps.log" ||
    { cat "$work/fw-nodeps.log"; echo "FAIL: the static refusal does not name the package"; exit 1; }
fi

# 1d. examples/firmware on its own (its own project(), the static library),
# asking for find_package(librcb 0.1 COMPONENTS static): the component is
# passed on to rcb (1c asks rcb itself).
if [[ -f $(dirname "$cfg")/rcbStaticTargets.cmake ]]; then
  "$cmake_cmd" -S "$here/../firmware" -B "$work/fw" -DCMAKE_PREFIX_PATH="$prefix" -DRCB_PACKAGE=librcb \
    -DCMAKE_C_COMPILER="$cc" -DCMAKE_BUILD_TYPE=Release > "$work/fw-configure.log" 2>&1 ||
    { cat "$work/fw-configure.log"; echo "FAIL: examples/firmware does not configure on its own"; exit 1; }
  "$cmake_cmd" --build "$work/fw" > "$work/fw-build.log"
  OPENBLAS_NUM_THREADS=1 "$work/fw/firmware_example" | tee "$work/fw.out" | tail -n 1
  grep -q "OK: drift and fault alarmed on time and named, intervals covering, no allocation in the loop" "$work/fw.out" ||
    { echo "FAIL: examples/firmware (standalone) did not print its OK line"; exit 1; }
  # its memory: all through the allocator hooks (the arena), none from the C heap
  if [[ $(uname -s) == Linux ]]; then
    grep '^heap: ' "$work/fw.out" || { echo "FAIL: examples/firmware counts no C heap call"; exit 1; }
    grep -q '^heap: 0 calls' "$work/fw.out" ||
      { echo "FAIL: examples/firmware: librcb.a called the C heap with the hooks set"; exit 1; }
  fi
fi

# 1e. The installed rcbtool runs the installed plotting script
# (<prefix>/share/rcb/rcb_plots.py), not the source tree's: a stand-in
# interpreter records the script it is given.
if [[ -e $prefix/bin/rcbtool ]]; then
  [[ -f $prefix/share/rcb/rcb_plots.py ]] || { echo "FAIL: rcb_plots.py not installed"; exit 1; }
  printf '#!/bin/sh\necho "$1" > "%s"\n' "$work/plots_script" > "$work/fake_python"
  chmod +x "$work/fake_python"
  wk=$here/../walkthrough
  env -u RCB_PLOTS RCB_PYTHON="$work/fake_python" "$prefix/bin/rcbtool" compare \
    "$wk/model.ini" "$wk/measured.uff" --plot "$work/walk" > /dev/null
  got=$(cat "$work/plots_script")
  [[ $got -ef $prefix/share/rcb/rcb_plots.py ]] ||
    { echo "FAIL: the installed rcbtool ran '$got', not $prefix/share/rcb/rcb_plots.py"; exit 1; }
  echo "installed rcbtool: plotting script $got"
fi

# 2. pkg-config: rcb, shared (rpath to the scratch prefix), and librcb (the
# same module under the project's name), --static, as a firmware build links:
# librcb.a into the program, the C heap wrapped and counted.
pcfile=$(find "$prefix" -name rcb.pc | head -n 1)
PKG_CONFIG_PATH=$(dirname "$pcfile")
export PKG_CONFIG_PATH
libdir=$(pkg-config --variable=libdir rcb)
[[ $(pkg-config --modversion librcb) == "$(pkg-config --modversion rcb)" ]] ||
  { echo "FAIL: pkg-config librcb is not rcb's version"; exit 1; }
if [[ -f $libdir/librcb.so ]]; then
  # shellcheck disable=SC2046
  "$cc" -std=c11 -O2 -o "$work/consumer_pc" "$here/main.c" \
    $(pkg-config --cflags --libs rcb) -lm -Wl,-rpath,"$libdir"
  runs+=("$work/consumer_pc")
fi
if [[ -f $libdir/librcb.a ]]; then
  # shellcheck disable=SC2046
  "$cc" -std=c11 -O2 -DRCB_EXAMPLE_COUNT_HEAP -o "$work/consumer_pc_static" "$here/main.c" \
    $(pkg-config --static --cflags librcb) "$(pkg-config --variable=libdir librcb)/librcb.a" \
    $(pkg-config --static --libs-only-l librcb | sed 's/-lrcb//') -lm \
    -Wl,--wrap=malloc,--wrap=calloc,--wrap=realloc,--wrap=free
  runs+=("$work/consumer_pc_static")
fi

# Closed form. The shaft (EI -> 48 EI/L^3 ~ 4.9e7 N/m at mid-span) is ~2400
# times stiffer than the two bearings in parallel (2k = 2e4 N/m), so the
# first mode is the rigid shaft bouncing on its bearings (disk at mid-span:
# translation and tilt decouple by symmetry), and
#   f1 = sqrt(2k / (m_disk + rho pi d^2/4 L)) / (2 pi)            (Hz)
# with the whole shaft mass moving (a consistent mass matrix keeps rigid
# translation exact). The receptance of the disk, x to x, below f1:
#   H(w) = 1 / (2k - w^2 m_total)                                 (m/N)
# Shaft flexibility shifts both by ~2k/(48EI/L^3) ~ 4e-4: assert to 1 %.
expected=$(awk 'BEGIN {
  pi = 3.14159265358979; rho = 7850; d = 0.05; L = 0.4; md = 10; k = 1e4; f = 2;
  mt = md + rho * pi * d * d / 4 * L; w = 2 * pi * f;
  printf "%.9g %.9g", sqrt(2 * k / mt) / (2 * pi), 1 / (2 * k - w * w * mt) }')
read -r f1_ref h_ref <<< "$expected"
echo "closed form: f1 = $f1_ref Hz, H(2 Hz) = $h_ref m/N"

# Each program twice: as it is (malloc) and with --arena (the hooks). With
# --arena every allocation goes through the hooks and comes back (frees =
# allocs > 0); a static link with the C heap wrapped (*_static, Linux) prints
# heap_calls: above 0 as it is (librcb.a's mallocs are counted: the wrap
# works), 0 with --arena (nothing in librcb.a goes around the hooks).
key() { awk -v k="$1" '$1 == k { print $2 }' <<< "$2"; }
status=0
for exe in "${runs[@]}"; do
  for mode in "" --arena; do
    out=$("$exe" $mode)
    f1=$(key f1_hz "$out")
    h=$(key h_dx_dx_m_per_n "$out")
    verdict=$(awk -v a="$f1" -v b="$f1_ref" -v c="$h" -v e="$h_ref" 'BEGIN {
      if (a == "" || c == "") { print "FAIL missing output"; exit }
      ra = (a - b) / b; rc = (c - e) / e; if (ra < 0) ra = -ra; if (rc < 0) rc = -rc;
      printf "%s f1 rel.err %.2e, H rel.err %.2e", (ra < 0.01 && rc < 0.01) ? "ok" : "FAIL", ra, rc }')
    allocs=$(key arena_allocs "$out")
    frees=$(key arena_frees "$out")
    heap=$(key heap_calls "$out")
    if [[ -n $mode ]]; then
      if ((${allocs:-0} == 0 || ${frees:--1} != ${allocs:-0})); then
        verdict="FAIL arena: ${allocs:-no} allocations, ${frees:-no} frees through the hooks"
      else
        verdict+=", arena $allocs allocations = frees, $(key arena_bytes "$out") bytes"
      fi
    fi
    if [[ $exe == *_static && $(uname -s) == Linux ]]; then
      if [[ -z $heap ]]; then
        verdict="FAIL the static link counts no C heap call (heap_calls missing)"
      elif [[ -z $mode ]] && ((heap == 0)); then
        verdict="FAIL heap_calls 0 without --arena: the --wrap counter counts nothing"
      elif [[ -n $mode ]] && ((heap != 0)); then
        verdict="FAIL $heap calls of the C heap with the hooks set: librcb went around them"
      else
        verdict+=", C heap calls from the static objects $heap"
      fi
    fi
    echo "$(basename "$(dirname "$exe")")/$(basename "$exe")${mode:+ $mode}: f1 = $f1 Hz, H = $h m/N: $verdict"
    [[ $verdict == ok* ]] || status=1
  done
done
exit $status
