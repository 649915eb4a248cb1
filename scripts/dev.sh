#!/usr/bin/env bash
# librcb developer entry point. Run from anywhere inside the repository.
#
#   ./scripts/dev.sh demo       install what the demo needs (no test toolchain, no
#                               SUNDIALS, no venv), build, run the paper-system demo,
#                               print where rcbtool is
#   ./scripts/dev.sh test       install everything, build with every backend, run every
#                               test: ctest, Python cross-validation against ROSS, the wheel
#                               in a fresh venv, the core configuration (no optional
#                               backend), the aarch64 firmware under qemu (arm), ASan+UBSan
#                               build, valgrind, fuzz replay, lint; ends
#                               with a table of stage times (docs/reliability.md)
#   ./scripts/dev.sh quick      build + the tests labelled neither slow nor long (ctest -LE
#                               "slow|long", pytest -m "not slow"): a developer's suite
#   ./scripts/dev.sh ctest      ctest in the build tree (everything)
#   ./scripts/dev.sh pytest     tests/python against this build (extra arguments to pytest)
#   ./scripts/dev.sh wheel      fresh venv, python -m build (sdist, wheel from it; librcb.so
#                               inside), pip install the wheel, an FRF against rcbtool and the
#                               package's tests, no LIBRCB_PATH (needs PyPI)
#   ./scripts/dev.sh deps       all Debian packages + the pinned Python venv (.venv)
#   ./scripts/dev.sh build      configure + build in build/ (Release; SUNDIALS and the
#                               tests when their packages are installed)
#   ./scripts/dev.sh core       build + ctest with every optional backend OFF (build-core/)
#   ./scripts/dev.sh sanitize   AddressSanitizer + UBSan build and ctest (build-asan/)
#   ./scripts/dev.sh bench      FRF sweep benchmark (C dense/banded; SciPy and ROSS if .venv)
#                               and the monitor's update (tools/bench/bench_monitor)
#   ./scripts/dev.sh bench-fit  identification benchmark (issue #3, Table 3 data, 20 seeds):
#                               rcbtool fit per method vs SciPy least_squares (needs .venv);
#                               extra arguments go to tools/bench/bench_fit.py
#   ./scripts/dev.sh bench-suite  the benchmark suite (issue #6) in one run: the paper sweep
#                               (librcb paths vs SciPy and ROSS), trains of 1e2-1e5 DOF, one fit,
#                               one diagnosis, the targets (needs .venv; about 2 min); writes
#                               out/bench-suite.md, and with --docs docs/benchmarks.md the
#                               published table; extra arguments go to tools/bench/suite.py
#   ./scripts/dev.sh diag-success  diagnosis success rate (issue #4): every hidden-effect case
#                               (truth by ROSS and by rcbtool simulate, a two-effect and a null
#                               case) x SEEDS (default 5) noise seeds, as a table (needs .venv;
#                               several minutes); extra arguments go to tools/bench/diag_success.py
#   ./scripts/dev.sh monitor-replicas  the monitor's rates at 32 x 1101 (issue #34 item 2): null,
#                               drift, wear, step x REPLICAS (default 100) ROSS series, numpy noise
#                               of four forms, every count against its binomial bound (needs .venv;
#                               about 10 s CPU per replica); extra arguments go to
#                               tools/bench/monitor_replicas.py (--cases null,drift --first N)
#   ./scripts/dev.sh monitor-pairs  the wrong "told apart" for each truth the monitor's
#                               catalogue can hold at 32 x 1101 (issue #34 item 2): 36 ROSS-made
#                               truths x 8 commissionings x 25 updates, four noise forms (needs
#                               .venv; about 80 min CPU); extra arguments go to
#                               tools/bench/monitor_pairs.py (--truths B4.kyy,gain.DA.x)
#   ./scripts/dev.sh fuzz       libFuzzer smoke (issue #7): build fuzz/ with clang (ASan+UBSan),
#                               replay the seed corpora, then fuzz each harness FUZZ_SECONDS
#                               (default 30) s; needs clang and libclang-rt-dev (not in `test`)
#   ./scripts/dev.sh valgrind   memcheck on the CLI runs of the examples (check, frf, unbalance,
#                               modes, fit, compare, diagnose on examples/walkthrough): no error,
#                               no definite leak (part of `test`)
#   ./scripts/dev.sh lint       cppcheck (warning, portability, performance) and clang-tidy
#                               (.clang-tidy) on src/, tools/rcbtool/ and examples/, one file
#                               per process, JOBS at a time (the analyzer shallow on the CLI and
#                               examples; part of `test`; about 1-3 min
#                               on 2 cores)
#   ./scripts/dev.sh cross      the embedded presets cross-built for aarch64 and armhf (Debian
#                               multiarch; installs what is missing unless that would upgrade
#                               host packages), firmware example under qemu-user diffed against
#                               the native run, C tests not labelled slow/long/threads
#   ./scripts/dev.sh cross-chroot  `cross` inside a Debian 12 root made in .chroot/bookworm
#                               (mmdebstrap or debootstrap; root; for hosts that are not
#                               Debian 12 or must not change): nothing is installed on the host
#   ./scripts/dev.sh wheel-manylinux  the self-contained wheel: built in a Debian 11 root,
#                               auditwheel repair (its libraries inside, manylinux_2_31), tested
#                               in a second root with only python3 and pip (root; out/manylinux/;
#                               WHEEL_ARCH=arm64: the aarch64 wheel under qemu-user-static)
#   ./scripts/dev.sh arm        `cross` for aarch64, light (part of `test`): the library and
#                               examples/firmware cross-built, the example under qemu-aarch64
#                               against the native embedded figures; on the host, else in the
#                               cached root of cross-chroot, else SKIPPED with the reason
#   ./scripts/dev.sh embedded   the "embedded" CMake preset (static, -Os, no optional backend,
#                               build-embedded/): build and print the library size
#
# Environment: CI=true turns warnings into errors; RCB_BUILD_DIR (default build)
# and RCB_VENV (default .venv) move the build tree and the venv;
# RCB_SKIP_SANITIZE=1 leaves the sanitizer build out of `test`; JOBS sets the
# build parallelism (default: all processors).
set -euo pipefail

ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$ROOT"

BUILD_DIR=${RCB_BUILD_DIR:-build}
[[ $BUILD_DIR == /* ]] || BUILD_DIR=$ROOT/$BUILD_DIR
VENV=${RCB_VENV:-.venv}
JOBS=${JOBS:-$(nproc 2>/dev/null || echo 2)}
CI=${CI:-false}
MODEL=examples/paper_system.ini

# What the demo needs (issue #17: the first hour installs no test toolchain):
# compiler, CMake, LAPACK, the sparse and NLopt backends, inih: 98 packages,
# ~490 MB on a fresh Debian 12 where everything took 297 packages, ~1.3 GB,
# plus the 1.3 GB venv. No SUNDIALS: Debian's libsundials-dev pulls PETSc,
# MPI and hypre by its own Depends (162 packages, ~475 MB more), and the demo
# runs no time integration. No Python: the demo draws no picture (matplotlib
# for `rcbtool compare --plot` comes with the venv of `test`).
# libopenblas0-serial: the serial OpenBLAS that rcbtool, the tests and the
# benchmarks run on (cmake/RcbSerialBlas.cmake; the system's default BLAS
# stays the alternatives' choice).
DEB_DEMO=(build-essential cmake pkg-config libopenblas-dev libopenblas0-serial liblapacke-dev
  libsuitesparse-dev libnlopt-dev libinih-dev libfftw3-dev)
# The rest, for `test` (and `deps`): SUNDIALS, cmocka, the Python venv's
# prerequisites, sanitizer/fuzzer runtime, valgrind, linters.
DEB_TEST=(libsundials-dev libcmocka-dev libkissfft-dev python3-venv python3-pip
  clang libclang-rt-14-dev valgrind cppcheck clang-tidy)
DEB_PACKAGES=("${DEB_DEMO[@]}" "${DEB_TEST[@]}")

say() { printf '\n==> %s\n' "$*"; }
die() { printf 'dev.sh: %s\n' "$*" >&2; exit 1; }

as_root() {
  if [[ $(id -u) -eq 0 ]]; then "$@"; else sudo "$@"; fi
}

deb_installed() { dpkg-query -W -f='${Status}' "$1" 2> /dev/null | grep -q 'install ok installed'; }

# Debian packages (default: all of DEB_PACKAGES): install only the missing
# ones; apt-get update only then.
deps_debian() {
  local want=("$@")
  ((${#want[@]})) || want=("${DEB_PACKAGES[@]}")
  if ! command -v dpkg-query > /dev/null; then
    echo "not a Debian system: install the equivalents of: ${want[*]}"
    return 0
  fi
  local missing=() p
  for p in "${want[@]}"; do
    deb_installed "$p" || missing+=("$p")
  done
  if ((${#missing[@]} == 0)); then
    echo "Debian packages: all present"
    return 0
  fi
  say "installing Debian packages: ${missing[*]}"
  as_root apt-get update
  as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends \
    "${missing[@]}"
}

# The pinned Python venv for the cross-validation; pip runs only when
# requirements.txt changed since the last successful install (stamp file).
deps_python() {
  [[ -f requirements.txt ]] || die "requirements.txt missing at $ROOT"
  if [[ ! -x $VENV/bin/python ]]; then
    say "creating the Python venv $VENV"
    rm -rf "$VENV"
    python3 -m venv "$VENV"
  fi
  local stamp=$VENV/.requirements.sha256 want
  want=$(sha256sum requirements.txt | cut -d' ' -f1)
  if [[ -f $stamp && $(cat "$stamp") == "$want" ]]; then
    echo "Python venv $VENV: up to date"
    return 0
  fi
  say "installing requirements.txt into $VENV"
  "$VENV/bin/python" -m pip install --quiet --upgrade pip
  # --no-compile: no byte-compiling of every installed module (plotly alone is
  # thousands); Python compiles what is imported, when it is (issue #27)
  "$VENV/bin/python" -m pip install --quiet --no-compile -r requirements.txt
  echo "$want" > "$stamp"
}

cmd_deps() {
  say "dependencies"
  deps_debian
  deps_python
}

# configure_build DIR [cmake options...]
configure_build() {
  local dir=$1
  shift
  local opts=(-DCMAKE_BUILD_TYPE=Release -DRCB_WARNINGS_AS_ERRORS=OFF)
  [[ $CI == true ]] && opts+=(-DRCB_WARNINGS_AS_ERRORS=ON)
  mkdir -p "$dir"
  cmake -S . -B "$dir" "${opts[@]}" "$@" > "$dir/configure.log" 2>&1 ||
    { cat "$dir/configure.log"; die "cmake configure failed in $dir"; }
  cmake --build "$dir" -j "$JOBS"
}

# The build with what is installed: SUNDIALS and the tests when their packages
# are there (after `test` or `deps`), else without (a fresh machine after the
# demo's packages). `test` builds with everything, ON explicitly.
cmd_build() {
  local sundials=ON tests=ON
  if [[ ${1:-} != full ]] && command -v dpkg-query > /dev/null; then
    deb_installed libsundials-dev || sundials=OFF
    deb_installed libcmocka-dev || tests=OFF
  fi
  say "build ($BUILD_DIR, Release, SUNDIALS $sundials, tests $tests, warnings as errors: $CI)"
  configure_build "$BUILD_DIR" -DRCB_WITH_SUNDIALS=$sundials -DRCB_BUILD_TESTS=$tests \
    -DRCB_TEST_VENV="$(cd "$ROOT" && realpath -m "$VENV")"
}

# The rcbtool executable of a build tree (tools/rcbtool/rcbtool or tools/rcbtool).
rcbtool_exe() {
  if [[ -f $BUILD_DIR/tools/rcbtool/rcbtool ]]; then
    echo "$BUILD_DIR/tools/rcbtool/rcbtool"
  else
    echo "$BUILD_DIR/tools/rcbtool"
  fi
}
rcbtool() { "$(rcbtool_exe)" "$@"; }

cmd_demo() {
  say "dependencies of the demo"
  deps_debian "${DEB_DEMO[@]}"
  cmd_build
  [[ -x $(rcbtool_exe) && -f $(rcbtool_exe) ]] || die "rcbtool was not built"
  local out=out/demo
  mkdir -p "$out"
  say "the paper's system: $MODEL"
  rcbtool check "$MODEL"

  say "damped modes at standstill and at 10000 rpm"
  local rpm
  for rpm in 0 10000; do
    echo "$rpm rpm:"
    rcbtool modes "$MODEL" --rpm "$rpm" --modes 8 | awk -F, '
      NR == 1 { for (j = 1; j <= NF; j++) c[$j] = j
                printf "  %4s %10s %8s %8s  %s\n", "mode", "fd_hz", "zeta", "logdec", "whirl"; next }
      { printf "  %4s %10.2f %8.4f %8.4f  %s\n", $c["mode"], $c["fd_hz"], $c["zeta"],
               $c["logdec"], $c["whirl"] }'
  done

  say "Campbell diagram 0-20000 rpm (first 6 modes), critical speeds"
  rcbtool campbell "$MODEL" --rpm-min 0 --rpm-max 20000 --points 81 --modes 6 \
    -o "$out/campbell.csv"
  rcbtool campbell "$MODEL" --rpm-min 0 --rpm-max 20000 --points 81 --modes 6 --json \
    -o "$out/campbell.json"
  # Damped frequencies (Hz) every 5000 rpm, from the fd*_hz columns.
  awk -F, '/^#/ { next }
    !h { h = 1; for (j = 1; j <= NF; j++) if ($j ~ /^fd[0-9]+_hz$/) fd[++n] = j
                     printf "  %7s", "rpm"; for (k = 1; k <= n; k++) printf " %9s", "fd" k "_hz"
                     print ""; next }
    $1 ~ /^[0-9.]+$/ && ($1 % 5000) == 0 && n {
      printf "  %7.0f", $1; for (k = 1; k <= n; k++) printf " %9.2f", $fd[k]; print "" }' \
    "$out/campbell.csv"
  # "critical_rpm": [a, b, ...] of the JSON, without Python
  tr -d '\n' < "$out/campbell.json" | grep -o '"critical_rpm": *\[[^]]*\]' |
    sed 's/.*\[//; s/\]//' | tr ',' '\n' |
    awk '{ if ($1 != "") { s = s (n++ ? ", " : "") sprintf("%.0f", $1) } }
      END { print "1X critical speeds (rpm):", (n ? s : "none in range") }'

  say "FRF at 10000 rpm, coupling hubs per disk-A force, 0-500 Hz"
  rcbtool frf "$MODEL" --out C.A.x,C.A.y,C.B.x,C.B.y --in DA.x --fmin 0 --fmax 500 \
    --points 2001 --rpm 10000 -o "$out/frf.csv"
  awk -F, '/^#/ { next }
    !h { h = 1; for (j = 2; j <= NF; j += 2) { n[j] = $j; sub(/ re( \[.*\])?$/, "", n[j]) }
         next }
    { for (j = 2; j <= NF; j += 2) { a = sqrt($j * $j + $(j + 1) * $(j + 1));
        if (a > pk[j]) { pk[j] = a; f[j] = $1 } } }
    END { for (j = 2; j in n; j += 2)
            printf "  %-14s peak |H| = %.3e m/N at %.2f Hz\n", n[j], pk[j], f[j] }' \
    "$out/frf.csv"

  say "unbalance response 0-20000 rpm (UA at DA phase 0, UB at DB phase 90 deg)"
  rcbtool unbalance "$MODEL" --out DA.x,DA.y,DB.x,DB.y --rpm-min 0 --rpm-max 20000 \
    --points 401 -o "$out/unbalance.csv"
  awk -F, '/^#/ { next }
    !h { h = 1; for (j = 2; j <= NF; j += 2) { n[j] = $j; sub(/ amp( \[.*\])?$/, "", n[j]) }
         next }
    { for (j = 2; j <= NF; j += 2) if ($j > pk[j]) { pk[j] = $j; r[j] = $1 } }
    END { for (j = 2; j in n; j += 2)
            printf "  %-6s max amplitude %.3e m at %.0f rpm\n", n[j], pk[j], r[j] }' \
    "$out/unbalance.csv"

  say "identification (paper section 8): fit the coupling to noisy measured FRFs"
  # Measured inertances (eq. 19 noise 10 %, 1 %) from the true system, written
  # as UFF58 with the test's node numbers; a model whose coupling starts at
  # 1/10 of the truth, with the same node map in its [uff] section.
  rcbtool simulate "$MODEL" --frf --out C.A.x,C.A.y,C.B.x,C.B.y --in DA.x --fmin 200 \
    --fmax 400 --points 201 --rpm 10000 --kind inertance --noise 10,1 --seed 1 \
    --map 10=C.A,11=C.B,4=DA -o "$out/measured.uff"
  sed -e 's/^kt = 46.095e3/kt = 4609.5/' -e 's/^kr = 220.76 /kr = 22.076 /' \
    -e 's/^ct = 10.949 /ct = 1.0949 /' -e 's/^cr = 10.949e-6/cr = 1.0949e-6/' "$MODEL" \
    > "$out/start.ini"
  printf '\n[uff]\nmap = 10 C.A, 11 C.B, 4 DA\n' >> "$out/start.ini"
  rcbtool fit "$out/start.ini" "$out/measured.uff" --log --noise 10,1 \
    --params coupling.C.kt,coupling.C.kr,coupling.C.ct,coupling.C.cr -o "$out/fitted.ini" |
    sed -n '1,/^converged/p' | sed 's/^/  /'
  echo "  (true values: kt 46095 N/m, kr 220.76 N m/rad, ct 10.949 N s/m, cr 1.0949e-05 N m s/rad)"

  say "diagnosis (issue #4): examples/walkthrough, a model that does not match its machine"
  local wk=examples/walkthrough P=coupling.C.kt,coupling.C.kr,coupling.C.ct
  rm -f "$out/history.jsonl"
  echo "-- rcbtool compare: where does the model fail?"
  rcbtool compare "$wk/model.ini" "$wk/measured.uff" | sed -n '3,12p' | sed 's/^/  /'
  echo "-- rcbtool fit: the best the model can do as it is"
  rcbtool fit "$wk/model.ini" "$wk/measured.uff" --params "$P" --log --noise 10,1 \
    --history "$out/history.jsonl" | grep -E '^(error|objective|note|noise|UNSURE)' |
    sed 's/^/  /'
  echo "-- rcbtool diagnose: which physical effect is missing, and where?"
  rcbtool diagnose "$wk/model.ini" "$wk/measured.uff" --params "$P" --log --noise 10,1 \
    --top 5 --apply 1 -o "$out/model2.ini" --history "$out/history.jsonl" | sed 's/^/  /'
  echo "-- rcbtool fit on the model with the effect added"
  rcbtool fit "$out/model2.ini" "$wk/measured.uff" --params "$P,bearing.B2.kcross:-7e7:7e7" \
    --noise 10,1 --history "$out/history.jsonl" | grep -E '^(bearing|error|objective|noise)' |
    sed 's/^/  /'
  echo "-- rcbtool history: the error falling"
  rcbtool history "$out/history.jsonl" | sed 's/^/  /'
  echo "  (the data were made with bearing B2 cross-coupled: kxy = 2e7, kyx = -2e7 N/m;"
  echo "   see examples/walkthrough/README.md)"
  echo
  echo "full tables (CSV, JSON, UFF, fitted models, history) in $out/"
  local exe rel
  exe=$(rcbtool_exe)
  rel=${exe#"$ROOT"/}
  echo
  echo "rcbtool is built at $rel; for the README's examples, from $ROOT:"
  echo "  export PATH=\$PWD/$(dirname "$rel"):\$PATH"
}

run_ctest() {
  local dir=$1
  shift
  (cd "$dir" && OPENBLAS_NUM_THREADS=1 ctest --output-on-failure -j "$JOBS" "$@")
}

cmd_core() {
  local dir=$BUILD_DIR-core
  say "core configuration: SuiteSparse, NLopt, SUNDIALS, threads, FFTW OFF ($dir)"
  configure_build "$dir" -DRCB_WITH_SUITESPARSE=OFF -DRCB_WITH_NLOPT=OFF \
    -DRCB_WITH_SUNDIALS=OFF -DRCB_WITH_THREADS=OFF -DRCB_WITH_FFTW=OFF
  # What this stage proves: the library builds and computes without any
  # optional backend (the fallbacks behind every #if RCB_WITH_*), which every
  # test not labelled slow exercises. The slow ones (whole diagnoses, the doc
  # commands) run the same code above the backends and run in the ctest stage
  # (issue #27: they were minutes here, twice). The allocation-failure walks
  # fail every allocation, each in a process forked there (tests/rcb_test_util.h).
  run_ctest "$dir" -LE slow
}

cmd_sanitize() {
  local dir=$BUILD_DIR-asan
  say "AddressSanitizer + UBSan build ($dir)"
  configure_build "$dir" -DCMAKE_BUILD_TYPE=Debug -DRCB_ENABLE_SANITIZERS=ON
  # The tests labelled "slow" (many full fits) run in the Release builds only.
  # The allocation-failure walks fail every 13th allocation here (every one in
  # the Release and core builds): each is a fork, and a fork copies ASan's
  # shadow mappings (10 ms of system time: 107 s for test_alloc_fail's 10300;
  # every 7th took 41 s of the stage beside the others).
  ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 RCB_ALLOC_WALK_STRIDE=13 \
    UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 run_ctest "$dir" -LE slow
}

# The Python tests import the package from tools/python (PYTHONPATH: no
# install, so no build of the wheel here) with this build's library through
# LIBRCB_PATH; the installed package is the `wheel` stage's. --durations
# prints the slowest tests (where the minutes go). Extra arguments go to pytest.
cmd_pytest() {
  say "Python cross-validation (tests/python, against ROSS) and the librcb package"
  local rc=0
  [[ -f $BUILD_DIR/src/librcb.so ]] || die "$BUILD_DIR/src/librcb.so was not built (RCB_BUILD_SHARED=ON)"
  RCBTOOL=$(rcbtool_exe) LIBRCB_PATH=$BUILD_DIR/src/librcb.so OPENBLAS_NUM_THREADS=1 \
    PYTHONPATH=$ROOT/tools/python${PYTHONPATH:+:$PYTHONPATH} \
    "$VENV/bin/python" -m pytest tests/python -q --durations=15 --durations-min=5 "$@" || rc=$?
  if ((rc == 5)); then
    echo "dev.sh: WARNING: pytest collected no test in tests/python" >&2
  elif ((rc != 0)); then
    die "Python cross-validation failed (pytest exit $rc)"
  fi
}

# The package as a user installs it (issues #27, #36): fresh venv, python -m
# build at the root (the sdist, then the wheel from it: scikit-build-core,
# librcb.so inside), the wheel installed, one FRF against the C CLI and the
# package's tests, with no build tree and no LIBRCB_PATH (tests/wheel).
cmd_wheel() {
  say "Python wheel: fresh venv, python -m build (sdist -> wheel), FRF vs rcbtool, package tests"
  local ref
  ref=$(rcbtool_exe)
  [[ -x $ref && -f $ref ]] || ref=
  PYTHON3=python3 JOBS=$JOBS tests/wheel/test_wheel.sh ${ref:+"$ref"}
}

cmd_ctest() {
  say "C tests (ctest, $BUILD_DIR)"
  run_ctest "$BUILD_DIR"
}

# The ctest stage of `test` (issue #27): with the sanitizer stage to come, the
# tests it does not run in full (labels slow and release, tests/CMakeLists.txt);
# every other test runs there, in the same configuration with ASan and UBSan,
# so once per configuration. Everything when the sanitizer stage is skipped.
cmd_ctest_stage() {
  if [[ ${RCB_SKIP_SANITIZE:-0} == 1 ]]; then
    cmd_ctest
  else
    say "C tests (ctest, $BUILD_DIR): labels slow|release; the others in the sanitizer stage"
    run_ctest "$BUILD_DIR" -L "slow|release"
  fi
}

# Stage times (issue #27): run_stage NAME CMD... runs CMD in a subshell with
# errexit on, records its seconds (wall, and CPU: user + system of the stage's
# processes, from the shell's `times`, which holds on a loaded machine),
# its result, adds NAME to FAILED when it fails, and returns 0: never call it
# as a condition (`run_stage ... ||` would turn errexit off inside CMD).
# stage_table prints the times.
STAGE_NAMES=()
STAGE_SECS=()
STAGE_CPU=()
STAGE_RESULTS=()
FAILED=()
stage_done() { # NAME SECONDS RC CPU_SECONDS [SKIP_REASON]
  STAGE_NAMES+=("$1")
  STAGE_SECS+=("$2")
  STAGE_CPU+=("${4:-0}")
  if (($3 == 0)); then
    STAGE_RESULTS+=(ok)
  elif (($3 == STAGE_SKIPPED)) && [[ -n ${5:-} ]]; then
    STAGE_RESULTS+=("SKIPPED: $5")
  else
    STAGE_RESULTS+=("FAILED (exit $3)")
    FAILED+=("$1")
  fi
}
# A stage that cannot run here (not a failure of the code: no root, a host
# that must not change) calls stage_skip REASON: it exits STAGE_SKIPPED and
# the table shows "SKIPPED: REASON" instead of ok, so it never passes silently.
STAGE_SKIPPED=77
stage_skip() {
  printf 'dev.sh: SKIPPED: %s\n' "$1" >&2
  [[ -z ${STAGE_SKIP_FILE:-} ]] || printf '%s' "$1" > "$STAGE_SKIP_FILE"
  exit "$STAGE_SKIPPED"
}
# CPU seconds (rounded) of a `times` output: the shell's and its children's
# user and system times ("0m1.250s 0m0.031s" per line).
cpu_secs() {
  awk '{ for (i = 1; i <= 2; i++) { split($i, a, /[ms]/); s += a[1] * 60 + a[2] } }
       END { printf "%d\n", s + 0.5 }' "$1" 2> /dev/null || echo 0
}
run_stage() {
  local name=$1 t=$SECONDS rc cpuf skipf
  shift
  cpuf=$(mktemp)
  skipf=$(mktemp)
  set +e
  (
    trap 'times > "$cpuf"' EXIT
    set -e
    STAGE_SKIP_FILE=$skipf
    "$@"
  )
  rc=$?
  set -e
  stage_done "$name" $((SECONDS - t)) $rc "$(cpu_secs "$cpuf")" "$(cat "$skipf")"
  rm -f "$cpuf" "$skipf"
}
run_stage_bg() {
  local name=$1 log=$BUILD_DIR/stage-$1.log
  shift
  rm -f "$log" "$log.rc" "$log.cpu" "$log.skip"
  (
    t=$SECONDS
    set +e
    (
      trap 'times > "$log.cpu"' EXIT
      set -e
      STAGE_SKIP_FILE=$log.skip
      "$@"
    ) > "$log" 2>&1
    echo "$? $((SECONDS - t)) $(cpu_secs "$log.cpu")" > "$log.rc"
  ) &
  BG_PID=$!
}
stage_wait() { # NAME PID
  local log=$BUILD_DIR/stage-$1.log rc=1 secs=0 cpu=0
  wait "$2" || true
  [[ -f $log.rc ]] && read -r rc secs cpu < "$log.rc"
  cat "$log"
  stage_done "$1 (bg)" "$secs" "$rc" "$cpu" "$(cat "$log.skip" 2> /dev/null)"
}
stage_table() {
  local i total=0 cpu=0 np
  np=$(nproc 2> /dev/null || echo 1)
  say "stage times (s; $np processors, JOBS=$JOBS, load average" \
    "$(cut -d' ' -f1-3 /proc/loadavg 2> /dev/null) at the end)"
  printf '  %-14s %7s %7s  %s\n' stage wall cpu result
  for i in "${!STAGE_NAMES[@]}"; do
    printf '  %-14s %7d %7d  %s\n' "${STAGE_NAMES[$i]}" "${STAGE_SECS[$i]}" "${STAGE_CPU[$i]}" \
      "${STAGE_RESULTS[$i]}"
    total=$((total + STAGE_SECS[i]))
    cpu=$((cpu + STAGE_CPU[i]))
  done
  printf '  %-14s %7d %7d  (stages marked bg ran beside the others)\n' "sum of stages" "$total" "$cpu"
  printf '  %-14s %7d %7s  (%d min %02d s; the CPU seconds over %d processors: %d s at the least)\n' \
    wall $((SECONDS - STAGE_T0)) "" $(((SECONDS - STAGE_T0) / 60)) $(((SECONDS - STAGE_T0) % 60)) \
    "$np" $((cpu / np))
}
STAGE_T0=$SECONDS

# Every stage runs even when one fails, so one run shows every failure, then
# the table of stage times. What each stage proves: docs/reliability.md,
# "Stages of ./scripts/dev.sh test". pytest is one process on one core for its
# whole run (ROSS and rcbtool one at a time, one BLAS thread): it runs in the
# background beside the other stages, which use the other core, and its output
# is printed when it ends; RCB_TEST_SERIAL=1 runs it in line instead.
cmd_test() {
  local stage pytest_pid= venv_pid
  run_stage deps deps_debian
  ((${#FAILED[@]} == 0)) || { stage_table; die "dependencies failed"; }
  # the venv (pip: the network and the disk, 60-90 s in a fresh clone) is
  # made beside the build (the compilers); ctest's doc test and pytest need it
  mkdir -p "$BUILD_DIR"
  run_stage_bg venv deps_python
  venv_pid=$BG_PID
  run_stage build cmd_build full
  stage_wait venv "$venv_pid"
  ((${#FAILED[@]} == 0)) || { stage_table; die "the build or the Python venv failed"; }
  # issue #36: arm, the aarch64 library and firmware example under qemu; in
  # the background (mostly apt, the Debian root and qemu: 1-5 min of wall,
  # 40-110 s of CPU) beside the others
  local stages=(ctest wheel core) arm_pid=
  if [[ ${RCB_TEST_SERIAL:-0} == 1 ]]; then
    stages=(ctest pytest wheel core arm)
  else
    say "pytest and arm start in the background (their output comes when they end)"
    run_stage_bg pytest cmd_pytest
    pytest_pid=$BG_PID
    run_stage_bg arm cmd_arm
    arm_pid=$BG_PID
  fi
  [[ ${RCB_SKIP_SANITIZE:-0} == 1 ]] || stages+=(sanitize)
  # issue #7: valgrind on the CLI, a libFuzzer smoke (FUZZ_SECONDS per harness)
  stages+=(valgrind fuzz_smoke)
  # issue #7: static analysis, clean (cppcheck and clang-tidy)
  stages+=(lint)
  for stage in "${stages[@]}"; do
    if [[ $stage == ctest ]]; then
      run_stage ctest cmd_ctest_stage
    else
      run_stage "$stage" "cmd_$stage"
    fi
  done
  if [[ -n $arm_pid ]]; then
    say "arm (ran in the background)"
    stage_wait arm "$arm_pid"
  fi
  if [[ -n $pytest_pid ]]; then
    say "pytest (ran in the background)"
    stage_wait pytest "$pytest_pid"
  fi
  stage_table
  ((${#FAILED[@]} == 0)) || die "FAILED stages: ${FAILED[*]}"
  say "all tests passed"
}

# A developer's suite in under 3 minutes on 2 cores (issue #27): the build,
# the C tests labelled neither slow nor long (ctest -LE "slow|long"), and the
# Python tests not marked slow (pytest -m "not slow": the ROSS references of
# the small models, the package API; tests/python/conftest.py marks the slow
# files). `test` runs everything.
cmd_quick() {
  run_stage build cmd_build
  ((${#FAILED[@]} == 0)) || { stage_table; die "the build failed"; }
  run_stage ctest run_ctest "$BUILD_DIR" -LE "slow|long"
  run_stage pytest cmd_pytest -m "not slow"
  stage_table
  ((${#FAILED[@]} == 0)) || die "FAILED stages: ${FAILED[*]}"
  say "quick suite passed (./scripts/dev.sh test runs everything)"
}

cmd_bench() {
  cmd_build
  local bench=$BUILD_DIR/tools/bench/bench_frf
  [[ -x $bench ]] || die "$bench was not built (RCB_BUILD_TOOLS=ON, tools/bench)"
  say "machine"
  lscpu | grep -E '^(Model name|CPU\(s\)|Thread\(s\) per core)' || true
  echo "load average (1, 5, 15 min): $(cut -d' ' -f1-3 /proc/loadavg 2> /dev/null)"
  say "librcb FRF sweep (one core: OPENBLAS_NUM_THREADS=1)"
  OPENBLAS_NUM_THREADS=1 "$bench" "$MODEL"
  say "where the banded time goes: zgbsv against an inline band LU"
  OPENBLAS_NUM_THREADS=1 "$BUILD_DIR/tools/bench/bench_band_lu" "$MODEL"
  say "condition monitoring (rcb_monitor): create, arena, ms per update, 8 x 400"
  OPENBLAS_NUM_THREADS=1 "$BUILD_DIR/tools/bench/bench_monitor" "$MODEL"
  if [[ -x $VENV/bin/python ]]; then
    say "reference: SciPy solve loop and ROSS run_freq_response on the same model"
    OPENBLAS_NUM_THREADS=1 "$VENV/bin/python" tools/bench/bench_frf_ref.py \
      --rcbtool "$(rcbtool_exe)" "$MODEL"
  else
    echo "(no $VENV: run ./scripts/dev.sh deps for the SciPy/ROSS comparison)"
  fi
}

cmd_bench_fit() {
  cmd_build
  [[ -x $(rcbtool_exe) && -f $(rcbtool_exe) ]] || die "rcbtool was not built"
  [[ -x $VENV/bin/python ]] || die "no $VENV: run ./scripts/dev.sh deps (NumPy, SciPy)"
  say "machine"
  lscpu | grep -E '^(Model name|CPU\(s\)|Thread\(s\) per core)' || true
  echo "load average (1, 5, 15 min): $(cut -d' ' -f1-3 /proc/loadavg 2> /dev/null)"
  say "identification: librcb (rcbtool fit) vs SciPy least_squares (one core)"
  OPENBLAS_NUM_THREADS=1 "$VENV/bin/python" tools/bench/bench_fit.py \
    --rcbtool "$(rcbtool_exe)" --model "$MODEL" "$@"
}

# The benchmark suite (issue #6): tools/bench/suite.py prints the machine, the
# versions, the commit and every figure as Markdown; never fails on a time.
cmd_bench_suite() {
  cmd_build
  [[ -x $(rcbtool_exe) && -f $(rcbtool_exe) ]] || die "rcbtool was not built"
  [[ -x $VENV/bin/python ]] || die "no $VENV: run ./scripts/dev.sh deps (NumPy, SciPy, ROSS)"
  say "benchmark suite: librcb vs SciPy and ROSS, trains, fit, diagnosis (one core)"
  OPENBLAS_NUM_THREADS=1 "$VENV/bin/python" tools/bench/suite.py --build "$BUILD_DIR" "$@"
}

# Diagnosis success rate (issue #4): tools/bench/diag_success.py prints the table
# that docs/diagnosis.md quotes; never fails on a miss (the tests assert).
cmd_diag_success() {
  cmd_build
  [[ -x $(rcbtool_exe) && -f $(rcbtool_exe) ]] || die "rcbtool was not built"
  [[ -x $VENV/bin/python ]] || die "no $VENV: run ./scripts/dev.sh deps (NumPy, ROSS, pyuff)"
  say "diagnosis success rate: hidden effects x ${SEEDS:-5} seeds (one core)"
  OPENBLAS_NUM_THREADS=1 "$VENV/bin/python" tools/bench/diag_success.py \
    --rcbtool "$(rcbtool_exe)" --seeds "${SEEDS:-5}" "$@"
}

# The monitor's rates by replicas (issue #34 item 2): tools/bench/monitor_replicas.py
# prints the table docs/monitoring.md quotes; never fails on a count (it reports).
# A monitor benchmark of tools/bench (WHAT: its words; SCRIPT: its file) on
# the built library, one core, nice; the rest of the arguments go to it.
monitor_bench() {
  local what=$1 script=$2
  shift 2
  cmd_build
  [[ -x $VENV/bin/python ]] || die "no $VENV: run ./scripts/dev.sh deps (NumPy, ROSS)"
  say "monitor $what at 32 x 1101 (one core, nice)"
  OPENBLAS_NUM_THREADS=1 LIBRCB_PATH=$BUILD_DIR/src/librcb.so nice -n 10 "$VENV/bin/python" \
    "tools/bench/$script" "$@"
}

cmd_monitor_replicas() {
  monitor_bench "rates: ${REPLICAS:-100} replicas per case" monitor_replicas.py \
    --replicas "${REPLICAS:-100}" "$@"
}

cmd_monitor_pairs() {
  monitor_bench "naming: every truth of monitor_pairs.py" monitor_pairs.py \
    --blocks "${BLOCKS:-8}" "$@"
}


# libFuzzer smoke: every seed replayed, then FUZZ_SECONDS of fuzzing per
# harness on a scratch copy of the corpus (fuzz/corpus stays as committed).
# Not part of `test`: it needs clang with its runtime (Debian: clang,
# libclang-rt-14-dev) and takes FUZZ_SECONDS x 4 plus a build.
cmd_fuzz() {
  local dir=$BUILD_DIR-fuzz secs=${FUZZ_SECONDS:-30} t rc=0
  command -v clang > /dev/null ||
    die "fuzz needs clang and its runtime (Debian: apt-get install clang libclang-rt-14-dev)"
  say "libFuzzer build ($dir, clang, ASan+UBSan)"
  mkdir -p "$dir"
  CC=clang cmake -S . -B "$dir" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DRCB_BUILD_FUZZERS=ON \
    -DRCB_BUILD_TESTS=OFF -DRCB_BUILD_TOOLS=OFF -DRCB_BUILD_SHARED=OFF \
    -DRCB_WITH_SUITESPARSE=OFF -DRCB_WITH_NLOPT=OFF -DRCB_WITH_SUNDIALS=OFF \
    > "$dir/configure.log" 2>&1 || { cat "$dir/configure.log"; die "cmake configure failed in $dir"; }
  cmake --build "$dir" -j "$JOBS"
  mkdir -p "$dir/crashes"
  # the harnesses at once (each one process on one core, for a fixed
  # time: together they take the time of one); each writes its own log. The
  # state harnesses' seeds are whole states (7 kB, 50-58 kB): their own max_len
  local pids=() t_of=()
  say "fuzz_ini, fuzz_csv, fuzz_signals_csv, fuzz_uff, fuzz_strtod, fuzz_monitor_state, fuzz_monitor_image, fuzz_rcbtool_state, fuzz_history at once: replay fuzz/corpus/NAME, then ${secs} s each"
  for t in ini csv signals_csv uff strtod monitor_state monitor_image rcbtool_state history; do
    rm -rf "$dir/work_$t"
    cp -r "fuzz/corpus/$t" "$dir/work_$t"
    (
      UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1 "$dir/fuzz/fuzz_$t" -runs=0 \
        "fuzz/corpus/$t" > "$dir/replay_$t.log" 2>&1 &&
        UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1 "$dir/fuzz/fuzz_$t" "$dir/work_$t" \
          -max_total_time="$secs" -max_len="$([[ $t == monitor_image ]] && echo 131072 || { [[ $t == *state ]] && echo 65536 || echo 8192; })" \
          -timeout=10 -rss_limit_mb=2048 \
          -artifact_prefix="$dir/crashes/fuzz_${t}-" -print_final_stats=1 > "$dir/fuzz_$t.log" 2>&1
    ) &
    pids+=($!)
    t_of+=("$t")
  done
  for i in "${!pids[@]}"; do
    t=${t_of[$i]}
    wait "${pids[$i]}" || rc=1
    echo "fuzz_$t: replay: $(tail -n 1 "$dir/replay_$t.log")"
    grep -E '^stat::number_of_executed_units|^SUMMARY' "$dir/fuzz_$t.log" 2> /dev/null || true
  done
  ((rc == 0)) || die "a fuzzer failed: see $dir/fuzz_*.log and $dir/crashes/ (reproduce: $dir/fuzz/fuzz_NAME FILE)"
  say "fuzz smoke passed (crash-free, ${secs} s per harness)"
}

# The fuzz stage of `test`: shorter runs (FUZZ_SECONDS, default 5 s each: the
# harnesses at once on 2 cores; `fuzz` gives each 30 s).
cmd_fuzz_smoke() { FUZZ_SECONDS=${FUZZ_SECONDS:-5} cmd_fuzz; }

# valgrind memcheck on small CLI runs of the examples, in the Release build.
# Exit 99 on any memcheck error or definite leak (OpenBLAS on one thread:
# its thread pool's buffers are "possibly lost" by design).
cmd_valgrind() {
  local exe W=examples/walkthrough P=coupling.C.kt,coupling.C.kr,coupling.C.ct t0=$SECONDS
  local out=$BUILD_DIR/valgrind rc=0
  command -v valgrind > /dev/null || die "valgrind missing (Debian: apt-get install valgrind)"
  exe=$(rcbtool_exe)
  [[ -x $exe && -f $exe ]] || die "rcbtool was not built: run ./scripts/dev.sh build"
  mkdir -p "$out"
  say "valgrind memcheck on the CLI ($exe)"
  vg() {
    local name=$1
    shift
    if OPENBLAS_NUM_THREADS=1 valgrind -q --error-exitcode=99 --leak-check=full \
      --errors-for-leak-kinds=definite --show-leak-kinds=definite \
      --log-file="$out/$name.log" "$exe" "$@" > "$out/$name.out" 2>&1; then
      printf '  %-10s clean\n' "$name"
    else
      printf '  %-10s FAILED (exit %d): see %s\n' "$name" "$?" "$out/$name.log"
      rc=1
    fi
  }
  vg check check "$MODEL"
  vg frf frf "$W/model.ini" --out DA.x,DB.y --in DA.x --fmax 500 --points 50 --rpm 10000 \
    -o "$out/frf.csv"
  vg unbalance unbalance "$W/model.ini" --out DA.x,DB.y --rpm-max 20000 --points 50 \
    -o "$out/unbalance.csv"
  vg modes modes "$W/model.ini" --rpm 10000 --modes 6 -o "$out/modes.csv"
  vg compare compare "$W/model.ini" "$W/measured.uff"
  vg fit fit "$W/model.ini" "$W/measured.uff" --params "$P" --log --noise 10,1 --max-iter 5 \
    --starts 1
  vg diagnose diagnose "$W/model.ini" "$W/measured.uff" --params "$P" --log --noise 10,1 \
    --band 200:400 --refits 1 --top 3
  ((rc == 0)) || die "valgrind found errors or leaks ($((SECONDS - t0)) s)"
  say "valgrind: no error, no definite leak ($((SECONDS - t0)) s)"
}

# Static analysis: cppcheck and clang-tidy on the library and the CLI, from
# a configure-only tree's compile_commands.json. Suppressions with their
# reasons: .cppcheck-suppressions and .clang-tidy.
cmd_lint() {
  local dir=$BUILD_DIR-lint t0=$SECONDS rc=0
  command -v cppcheck > /dev/null && command -v clang-tidy > /dev/null ||
    die "lint needs cppcheck and clang-tidy (Debian: apt-get install cppcheck clang-tidy)"
  mkdir -p "$dir"
  cmake -S . -B "$dir" -DCMAKE_BUILD_TYPE=Release -DCMAKE_EXPORT_COMPILE_COMMANDS=ON \
    > "$dir/configure.log" 2>&1 || { cat "$dir/configure.log"; die "cmake configure failed in $dir"; }
  say "cppcheck (warning, portability, performance)"
  cppcheck --project="$dir/compile_commands.json" --enable=warning,portability,performance \
    --inline-suppr --suppressions-list=.cppcheck-suppressions --error-exitcode=1 -q \
    -j "$JOBS" --file-filter="$ROOT/src/*" --file-filter="$ROOT/tools/rcbtool/*" \
    --file-filter="$ROOT/examples/*" \
    --template='{file}:{line}: {severity}: {message} [{id}]' || rc=1
  say "cppcheck done ($((SECONDS - t0)) s); clang-tidy (.clang-tidy), $JOBS files at a time"
  # One file per process so the slow files (the analyzer's path search) do not
  # hold a batch back; examples/consumer is not in the database (an
  # out-of-tree project): clang-tidy borrows examples/firmware's flags.
  # The library (src/, what firmware links) gets the analyzer's full depth;
  # the CLI and the examples its shallow mode (-analyzer-config mode=shallow:
  # a smaller inlining budget, the same checks), every other check the same.
  # The analyzer is 97 % of clang-tidy's time, and its full depth on the
  # CLI's 60 files was a third of the lint stage (issue #27: 164 of 491 s).
  {
    find src -name '*.c' -print0 | sort -z |
      xargs -0 -P "$JOBS" -n 1 clang-tidy -p "$dir" --quiet || rc=1
    find tools/rcbtool examples -name '*.c' -print0 | sort -z |
      xargs -0 -P "$JOBS" -n 1 clang-tidy -p "$dir" --quiet --extra-arg=-Xclang \
        --extra-arg=-analyzer-config --extra-arg=-Xclang --extra-arg=mode=shallow || rc=1
  } > "$dir/clang-tidy.log" 2>&1
  grep -E ': (warning|error):' "$dir/clang-tidy.log" || true
  ((rc == 0)) || die "lint found problems ($((SECONDS - t0)) s; clang-tidy: $dir/clang-tidy.log)"
  say "lint clean ($((SECONDS - t0)) s)"
}

# The embedded preset (CMakePresets.json): static, MinSizeRel, no backend.
cmd_embedded() {
  say "embedded preset (build-embedded: static, -Os, no SuiteSparse/NLopt/SUNDIALS)"
  cmake --preset embedded > /dev/null
  cmake --build --preset embedded -j "$JOBS"
  local lib=build-embedded/src/librcb.a
  [[ -f $lib ]] || die "$lib was not built"
  say "library size"
  ls -l "$lib" | awk '{ printf "  %s: %d bytes on disk\n", $NF, $5 }'
  size -t "$lib" | awk 'END { printf "  code (text) %d bytes, data %d, bss %d: total %d bytes\n", $1, $2, $3, $4 }'
  # examples/firmware is built in this preset too (no tests, no cmocka): run it
  local fw=build-embedded/examples/firmware/firmware_example
  [[ -x $fw ]] || die "$fw was not built"
  say "examples/firmware on the embedded library"
  OPENBLAS_NUM_THREADS=1 "$fw" | tail -n 1 | sed 's/^/  /'
}

# ARM, cross-compiled on Debian multiarch and run under qemu-user (issue #27):
# for each target (aarch64 = Debian arm64, armhf), install what is missing
# (crossbuild-essential, qemu-user, the target's -dev packages), build the
# preset embedded-<target> (warnings are errors), run examples/firmware under
# qemu and diff its figures against the native run (the init line, arena sizes
# from the pointer width, apart), then the C tests labelled neither slow, long
# nor threads. CROSS_TARGETS (default "aarch64 armhf") picks the targets.
# CROSS_LIGHT=1 (the `arm` stage of `test`, issue #36): the library and the
# firmware example only (RCB_BUILD_TESTS=OFF, no cmocka), no ctest.
declare -A CROSS_DEBARCH=([aarch64]=arm64 [armhf]=armhf)
declare -A CROSS_QEMU=([aarch64]=qemu-aarch64 [armhf]=qemu-arm)
declare -A CROSS_TRIPLET=([aarch64]=aarch64-linux-gnu [armhf]=arm-linux-gnueabihf)

# Foreign-architecture packages must carry the host's versions of the shared
# ones (libc6, libgcc...): when the host is behind its archive, apt would
# upgrade host packages to install them. That is left to the administrator:
# the simulation is checked first and nothing is installed then: exit
# CROSS_WOULD_UPGRADE (the `arm` stage of `test` tells that from a failure).
# cross_deps ARCH [light]: light leaves out cmocka (no tests are built).
CROSS_WOULD_UPGRADE=3
cross_want() { # ARCH [light]
  printf '%s\n' "crossbuild-essential-$1" qemu-user "liblapacke-dev:$1" "libopenblas-dev:$1" \
    "libinih-dev:$1" "libkissfft-dev:$1"
  [[ ${2:-} == light ]] || echo "libcmocka-dev:$1"
}
cross_deps() {
  local arch=$1 missing=() p plan want added=0
  mapfile -t want < <(cross_want "$arch" "${2:-}")
  for p in "${want[@]}"; do deb_installed "$p" || missing+=("$p"); done
  ((${#missing[@]})) || return 0
  if ! dpkg --print-foreign-architectures | grep -qx "$arch"; then
    say "dpkg --add-architecture $arch"
    as_root dpkg --add-architecture "$arch"
    added=1
  fi
  # A mirror caught mid-sync fails one index (seen: bookworm-security's armhf
  # Packages): go on with the indexes apt has; the simulation below decides.
  as_root apt-get update ||
    echo "dev.sh: apt-get update reported errors (above): going on with the indexes it has"
  plan=$(as_root apt-get -s install --no-install-recommends "${missing[@]}" 2>&1) ||
    { echo "$plan" | tail -n 20; die "apt cannot install: ${missing[*]}"; }
  if grep -E '^(Inst [^ ]+ \[|Remv )' <<< "$plan"; then
    # the architecture this run added goes again: the host is as it was
    local undone=
    if ((added)); then
      as_root dpkg --remove-architecture "$arch" || true
      undone=" (this run's dpkg --add-architecture $arch is undone)"
    fi
    printf 'dev.sh: %s\n' "installing ${missing[*]} would upgrade or remove the host packages above (the host is behind its archive): upgrade the host first (apt-get upgrade), then run cross again$undone" >&2
    exit "$CROSS_WOULD_UPGRADE"
  fi
  say "installing: ${missing[*]}"
  as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends \
    "${missing[@]}"
}

cmd_cross() {
  local targets=(${CROSS_TARGETS:-aarch64 armhf}) t dir fw native=build-embedded/firmware.out
  command -v dpkg-query > /dev/null || die "cross needs Debian multiarch (dpkg, apt)"
  for t in "${targets[@]}"; do
    [[ -n ${CROSS_DEBARCH[$t]:-} ]] || die "unknown cross target $t (aarch64, armhf)"
  done
  # The native embedded build first (the reference figures): on a fresh machine
  # nothing of it is there yet (not even cmake).
  deps_debian build-essential cmake pkg-config libopenblas-dev liblapacke-dev libinih-dev \
    libkissfft-dev
  say "native embedded build (the reference figures)"
  cmake --preset embedded > /dev/null
  cmake --build --preset embedded -j "$JOBS"
  OPENBLAS_NUM_THREADS=1 build-embedded/examples/firmware/firmware_example > "$native"
  local light= tests=ON
  [[ ${CROSS_LIGHT:-0} != 1 ]] || light=light tests=OFF
  for t in "${targets[@]}"; do
    cross_deps "${CROSS_DEBARCH[$t]}" $light
    dir=build-embedded-$t
    say "embedded-$t: cross build (${CROSS_TRIPLET[$t]}, warnings as errors, tests $tests)"
    cmake --preset "embedded-$t" -DRCB_BUILD_TESTS=$tests > /dev/null
    cmake --build --preset "embedded-$t" -j "$JOBS"
    size "$dir/src/librcb.a" | awk 'NR > 1 { t += $1 } END { printf "  library text %d bytes\n", t }'
    say "embedded-$t: examples/firmware under ${CROSS_QEMU[$t]}, against the native figures"
    fw=$dir/examples/firmware/firmware_example
    OPENBLAS_NUM_THREADS=1 "${CROSS_QEMU[$t]}" -L "/usr/${CROSS_TRIPLET[$t]}" "$fw" > "$dir/firmware.out"
    grep '^init:' "$native" "$dir/firmware.out" | sed 's/^/  /'
    diff <(grep -v '^init:' "$native") <(grep -v '^init:' "$dir/firmware.out") ||
      die "embedded-$t: the firmware example's figures differ from the native run (above)"
    echo "  the same figures as the native run (apart from the init line)"
    [[ -z $light ]] || continue
    say "embedded-$t: C tests under qemu (ctest -LE 'slow|long|threads')"
    (cd "$dir" && ctest -N -L threads | sed -n 's/^ *Test *#[0-9]*: /  skipped under qemu-user (its user mode hangs or crashes in guest pthread_create, qemu 7.2): /p')
    run_ctest "$dir" -LE "slow|long|threads"
  done
  say "cross: ${targets[*]} passed${light:+ (CROSS_LIGHT: library and firmware example, no ctest)}"
}

# `cross` in a Debian 12 root, for a host that is not Debian 12 or whose
# packages must not change (multiarch would upgrade them, see cross_deps):
# mmdebstrap (or debootstrap) makes a minbase bookworm root in RCB_CHROOT
# (default .chroot/bookworm, git-ignored; about 100 s for the root, 1.9 GB
# with the cross packages), the working tree (tracked and untracked files, not
# the ignored ones) is copied to its /src, /proc, /dev and /dev/pts are mounted, and
# `./scripts/dev.sh cross` runs there as root, installing what it needs inside
# the root only. The mounts are undone on every exit. Needs root on the host.
CHROOT=${RCB_CHROOT:-$ROOT/.chroot/bookworm}
CHROOT_MIRROR=${RCB_CHROOT_MIRROR:-http://deb.debian.org/debian}

# chroot_umount DIR / chroot_mount DIR: /proc, /dev and /dev/pts of a root.
chroot_umount() {
  local m
  for m in "$1/dev/pts" "$1/dev" "$1/proc"; do
    if mountpoint -q "$m"; then umount "$m" || umount -l "$m"; fi
  done
}
chroot_mount() {
  cp -L /etc/resolv.conf "$1/etc/resolv.conf"
  mount -t proc proc "$1/proc"
  mount --bind /dev "$1/dev"
  mount --bind /dev/pts "$1/dev/pts"
}
# chroot_run DIR CMD...: CMD as root in DIR, with a clean environment
# (PATH, HOME, LANG, CI, JOBS; more as VAR=value before CMD). pip there uses
# the host's CA bundle (copied in: a proxy or mirror the host trusts) and the
# host's PIP_INDEX_URL / PIP_EXTRA_INDEX_URL when set.
chroot_run() {
  local dir=$1 pipenv=()
  shift
  if [[ -f /etc/ssl/certs/ca-certificates.crt ]]; then
    cp /etc/ssl/certs/ca-certificates.crt "$dir/etc/rcb-host-ca.crt"
    pipenv+=(PIP_CERT=/etc/rcb-host-ca.crt)
  fi
  [[ -z ${PIP_INDEX_URL:-} ]] || pipenv+=("PIP_INDEX_URL=$PIP_INDEX_URL")
  [[ -z ${PIP_EXTRA_INDEX_URL:-} ]] || pipenv+=("PIP_EXTRA_INDEX_URL=$PIP_EXTRA_INDEX_URL")
  chroot "$dir" /usr/bin/env -i PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin \
    HOME=/root LANG=C.UTF-8 CI="$CI" JOBS="$JOBS" "${pipenv[@]}" "$@"
}
# chroot_copy_tree DIR: the working tree (tracked and untracked files, not
# the ignored ones) to DIR.
chroot_copy_tree() {
  mkdir -p "$1"
  git ls-files -z --cached --others --exclude-standard |
    xargs -0 -r sh -c 'for f; do [ -e "$f" ] && printf "%s\0" "$f"; done' sh |
    tar --null -T - -cf - | tar -xf - -C "$1"
}

# chroot_make SUITE DIR [PACKAGE...]: a minbase Debian SUITE root in DIR
# (SUITE, -updates, -security; CHROOT_ARCH=arm64 etc. for a foreign one, which
# needs qemu-user-static), with the PACKAGEs and what they depend on (their
# Recommends are left out by debootstrap and, told so, by mmdebstrap).
chroot_make() {
  local suite=$1 dir=$2 sec=${CHROOT_MIRROR%/debian}/debian-security opts=()
  shift 2
  # CHROOT_SECURITY=0: without the -security suite (a mirror that lacks it
  # for an architecture: here bullseye-security arm64 answered 404)
  [[ ${CHROOT_SECURITY:-1} != 0 ]] || sec=
  if (($#)); then
    opts+=("--include=$(
      IFS=,
      echo "$*"
    )")
    command -v mmdebstrap > /dev/null && opts+=(--aptopt='APT::Install-Recommends "false"')
  fi
  [[ -z ${CHROOT_ARCH:-} ]] || opts+=("--arch=$CHROOT_ARCH")
  say "Debian $suite root in $dir (minbase; $suite, -updates${sec:+, -security}${CHROOT_ARCH:+; $CHROOT_ARCH})${*:+ with $*}"
  mkdir -p "$dir"
  if command -v mmdebstrap > /dev/null; then
    mmdebstrap --variant=minbase --mode=root "${opts[@]}" "$suite" "$dir" \
      "deb $CHROOT_MIRROR $suite main" "deb $CHROOT_MIRROR $suite-updates main" \
      ${sec:+"deb $sec $suite-security main"}
  elif command -v debootstrap > /dev/null; then
    debootstrap --variant=minbase "${opts[@]}" "$suite" "$dir" "$CHROOT_MIRROR"
    printf 'deb %s %s main\ndeb %s %s-updates main\n' \
      "$CHROOT_MIRROR" "$suite" "$CHROOT_MIRROR" "$suite" > "$dir/etc/apt/sources.list"
    [[ -z $sec ]] || printf 'deb %s %s-security main\n' "$sec" "$suite" >> "$dir/etc/apt/sources.list"
    chroot "$dir" sh -c 'apt-get update && DEBIAN_FRONTEND=noninteractive apt-get -y upgrade'
  else
    die "needs mmdebstrap or debootstrap (Debian/Ubuntu: apt-get install mmdebstrap; Fedora: dnf install mmdebstrap)"
  fi
}

cmd_cross_chroot() {
  [[ $(id -u) -eq 0 ]] || die "cross-chroot needs root (debootstrap, mount, chroot): sudo ./scripts/dev.sh cross-chroot"
  command -v git > /dev/null || die "cross-chroot needs git (it copies the files git knows of)"
  [[ -x $CHROOT/usr/bin/apt-get ]] || chroot_make bookworm "$CHROOT"
  trap 'chroot_umount "$CHROOT"' EXIT
  say "the working tree to $CHROOT/src"
  # the last copy goes, its builds stay: a file gone from the tree must not
  # linger there (src/ is globbed); tar keeps the mtimes, so builds stay current
  [[ ! -d $CHROOT/src ]] ||
    find "$CHROOT/src" -mindepth 1 -maxdepth 1 ! -name 'build-embedded*' -exec rm -rf {} +
  chroot_copy_tree "$CHROOT/src"
  chroot_mount "$CHROOT"
  chroot_run "$CHROOT" CROSS_TARGETS="${CROSS_TARGETS:-aarch64 armhf}" CROSS_LIGHT="${CROSS_LIGHT:-0}" \
    bash -c 'cd /src && ./scripts/dev.sh cross'
  say "cross-chroot: passed (the builds are in $CHROOT/src/build-embedded-*)"
}

# The self-contained wheel (issue #36 item 1): the package built in a Debian
# 11 root (glibc 2.31), repaired by auditwheel (the shared libraries it links
# copied into the wheel, tag manylinux_2_31), then installed into a fresh copy
# of a second Debian 11 root that holds only python3 and its venv/pip: import,
# an FRF against a closed form, one fit, import times (tests/wheel/
# manylinux_*.sh, docs/python.md). Roots cached in .chroot/ (git-ignored):
# bullseye-<arch>-wheel (build-essential and the -dev packages below, about
# 0.9 GB) and bullseye-<arch>-python (about 0.2 GB). The repaired wheel goes
# to out/manylinux/. WHEEL_ARCH=arm64 makes the aarch64 wheel the same way in
# arm64 roots, run under qemu-user-static through binfmt_misc. Needs root on
# the host, mmdebstrap or debootstrap and PyPI.
MANYLINUX_SUITE=${RCB_MANYLINUX_SUITE:-bullseye}
# libopenblas-serial-dev: the -dev's serial variant, so that the only
# libopenblas.so.0 in the root (and in the wheel) is the serial one
DEB_WHEEL=(build-essential pkg-config libopenblas-serial-dev libopenblas-dev liblapacke-dev
  libsuitesparse-dev libnlopt-dev libinih-dev libfftw3-dev python3-venv)
cmd_wheel_manylinux() {
  [[ $(id -u) -eq 0 ]] || die "wheel-manylinux needs root (debootstrap, mount, chroot): sudo ./scripts/dev.sh wheel-manylinux"
  command -v git > /dev/null || die "wheel-manylinux needs git (it copies the files git knows of)"
  local host suite=$MANYLINUX_SUITE arch
  host=$(dpkg --print-architecture 2> /dev/null || uname -m | sed 's/x86_64/amd64/; s/aarch64/arm64/')
  arch=${WHEEL_ARCH:-$host}
  local broot=$ROOT/.chroot/$suite-$arch-wheel croot=$ROOT/.chroot/$suite-$arch-python
  local out=$ROOT/out/manylinux run t0=$SECONDS whl qemu
  run=$croot-run
  if [[ $arch != "$host" ]]; then
    qemu=$(case $arch in arm64) echo aarch64 ;; armhf) echo arm ;; *) echo "$arch" ;; esac)
    grep -qs enabled "/proc/sys/fs/binfmt_misc/qemu-$qemu" ||
      die "WHEEL_ARCH=$arch runs the roots under qemu through binfmt_misc: apt-get install qemu-user-static, then (without systemd-binfmt) cat /usr/lib/binfmt.d/qemu-$qemu.conf > /proc/sys/fs/binfmt_misc/register"
  fi
  export CHROOT_ARCH=$arch
  if [[ ! -x $broot/usr/bin/python3 || $(cat "$broot/.rcb-packages" 2> /dev/null) != "${DEB_WHEEL[*]}" ]]; then
    rm -rf "$broot"
    chroot_make "$suite" "$broot" "${DEB_WHEEL[@]}"
    echo "${DEB_WHEEL[*]}" > "$broot/.rcb-packages"
  fi
  trap "chroot_umount '$broot'; chroot_umount '$run'" EXIT
  say "wheel-manylinux: python -m build and auditwheel repair in $broot (Debian $suite, $arch)"
  rm -rf "$broot/src"
  chroot_copy_tree "$broot/src"
  chroot_mount "$broot"
  chroot_run "$broot" bash /src/tests/wheel/manylinux_build.sh /src /src/wheelhouse
  chroot_umount "$broot"
  mkdir -p "$out"
  whl=("$broot"/src/wheelhouse/*.whl)
  cp "${whl[0]}" "$out/"
  cp "$broot/src/wheelhouse/auditwheel-show.txt" "$out/auditwheel-show-$arch.txt"
  [[ -x $croot/usr/bin/python3 ]] || chroot_make "$suite" "$croot" python3-venv
  say "wheel-manylinux: ${whl[0]##*/} into a fresh copy of $croot (python3 and pip only)"
  rm -rf "$run"
  cp -a "$croot" "$run"
  mkdir -p "$run/test"
  cp "${whl[0]}" tests/wheel/manylinux_test.sh tests/wheel/manylinux_check.py \
    tests/wheel/requirements-manylinux-test.txt examples/paper_system.ini "$run/test/"
  chroot_mount "$run"
  chroot_run "$run" OPENBLAS_NUM_THREADS=1 bash /test/manylinux_test.sh "/test/${whl[0]##*/}"
  chroot_umount "$run"
  rm -rf "$run"
  say "wheel-manylinux: passed in $((SECONDS - t0)) s (the wheel: $out/${whl[0]##*/})"
}

# The `arm` stage of `test` (issue #36): `cross` for aarch64 in its light form
# (CROSS_LIGHT=1: the native embedded build, the aarch64 library and
# examples/firmware cross-built, no tests, the example under qemu-aarch64
# diffed against the native figures), on the host when its arm64 packages are
# there or install without changing a host package, else in the cached Debian
# root of `cross-chroot`. When neither can be (no root, the host would change
# and no root is cached, not Debian, RCB_SKIP_ARM=1) it is skipped with the
# reason in the stage table: never a failure for lack of root, never a silent
# pass. The full qemu ctest of both targets is `cross`, behind CI_CROSS=1 (.ci/run).
cmd_arm() {
  local want=() missing=() p rc why
  [[ ${RCB_SKIP_ARM:-0} != 1 ]] || stage_skip "RCB_SKIP_ARM=1"
  export CROSS_TARGETS=aarch64 CROSS_LIGHT=1
  if command -v dpkg-query > /dev/null && command -v apt-get > /dev/null; then
    mapfile -t want < <(cross_want arm64 light)
    for p in "${want[@]}"; do deb_installed "$p" || missing+=("$p"); done
    if ((${#missing[@]} == 0)); then
      cmd_cross
      return
    fi
    if [[ $(id -u) -ne 0 ]] && ! sudo -n true 2> /dev/null; then
      why="installing ${missing[*]} needs root (not root, and no sudo without a password)"
    else
      set +e
      (
        set -e
        cross_deps arm64 light
      )
      rc=$?
      set -e
      case $rc in
        0)
          cmd_cross
          return
          ;;
        "$CROSS_WOULD_UPGRADE") why="installing the arm64 packages would upgrade or remove host packages (listed above)" ;;
        *) die "arm: installing the arm64 packages failed (exit $rc, above)" ;;
      esac
    fi
  else
    why="not a Debian multiarch host (no dpkg-query/apt-get)"
  fi
  # cross-chroot makes the root when it is not there (mmdebstrap or
  # debootstrap; 66 s here, 1.6 GB with the packages, once per RCB_CHROOT)
  if [[ $(id -u) -eq 0 ]] && { [[ -x $CHROOT/usr/bin/apt-get ]] ||
    command -v mmdebstrap > /dev/null || command -v debootstrap > /dev/null; }; then
    say "arm: $why: in the Debian root $CHROOT"
    (cmd_cross_chroot) # a subshell: its EXIT trap (the mounts) is its own
    return
  fi
  if [[ $(id -u) -ne 0 ]]; then
    why+="; the Debian root of cross-chroot needs root"
  else
    why+="; no Debian root in $CHROOT and neither mmdebstrap nor debootstrap to make one"
  fi
  stage_skip "$why"
}

usage() { awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$ROOT/scripts/dev.sh"; }

case ${1:-} in
  deps) cmd_deps ;;
  build) cmd_build ;;
  demo) cmd_demo ;;
  test) cmd_test ;;
  quick) cmd_quick ;;
  wheel) cmd_wheel ;;
  pytest) shift; cmd_pytest "$@" ;;
  ctest) cmd_ctest ;;
  core) cmd_core ;;
  sanitize) cmd_sanitize ;;
  bench) cmd_bench ;;
  bench-fit) shift; cmd_bench_fit "$@" ;;
  bench-suite) shift; cmd_bench_suite "$@" ;;
  diag-success) shift; cmd_diag_success "$@" ;;
  monitor-replicas) shift; cmd_monitor_replicas "$@" ;;
  monitor-pairs) shift; cmd_monitor_pairs "$@" ;;
  fuzz) cmd_fuzz ;;
  fuzz-smoke) cmd_fuzz_smoke ;;
  valgrind) cmd_valgrind ;;
  lint) cmd_lint ;;
  embedded) cmd_embedded ;;
  cross) cmd_cross ;;
  cross-chroot) cmd_cross_chroot ;;
  wheel-manylinux) cmd_wheel_manylinux ;;
  arm)
    run_stage arm cmd_arm
    stage_table
    ((${#FAILED[@]} == 0)) || exit 1
    ;;
  -h | --help | help) usage ;;
  *) usage >&2; exit 2 ;;
esac
