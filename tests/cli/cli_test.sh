#!/bin/sh
# Command-line tests of rcbtool: exit codes, messages, output files, JSON.
# usage: cli_test.sh RCBTOOL EXAMPLES_DIR CASE   (exit 0 pass, 1 fail, 77 skip)
set -u
T=$1
EX=$2
CASE=$3
MODEL=$EX/paper_system.ini
W=$(mktemp -d "${TMPDIR:-/tmp}/rcbtool_cli.XXXXXX") || exit 1
trap 'rm -rf "$W"' EXIT

fail() { echo "FAIL [$CASE]: $*"; echo "--- stdout:"; head -c 2000 "$W/out"; echo "--- stderr:"; cat "$W/err"; exit 1; }

# run ARGS...: stdout to $W/out, stderr to $W/err, exit code in $RC
run() { "$T" "$@" >"$W/out" 2>"$W/err"; RC=$?; }
expect_rc() { [ "$RC" -eq "$1" ] || fail "exit code $RC, expected $1"; }
err_has() { grep -F -q -- "$1" "$W/err" || fail "stderr does not mention '$1'"; }
out_has() { grep -F -q -- "$1" "$W/out" || fail "stdout does not contain '$1'"; }
out_empty() { [ ! -s "$W/out" ] || fail "stdout should be empty"; }
json_ok() {
  python3 -c 'import json,sys; json.load(open(sys.argv[1]))' "$W/out" || fail "stdout is not valid JSON"
}
usage() { run "$@"; expect_rc 2; out_empty; }

case $CASE in
# ---- usage errors: exit 2, a message saying what is expected ----
usage_no_args) usage; err_has "usage: rcbtool <command>" ;;
usage_unknown_command) usage frobnicate "$MODEL"; err_has "unknown command 'frobnicate'"; err_has "expected one of" ;;
usage_missing_model) usage modes; err_has "missing the model file" ;;
usage_unknown_option)
  usage frf "$MODEL" --out DA.x --in DA.x --fmax 100 --bogus 3
  err_has "unknown option '--bogus'"; err_has "--fmax HZ"; err_has "rcbtool frf --help" ;;
usage_missing_value) usage frf "$MODEL" --out DA.x --in DA.x --fmax; err_has "option --fmax expects a value (HZ)" ;;
usage_missing_required) usage frf "$MODEL" --out DA.x --fmax 100; err_has "option --in is required" ;;
usage_fmin_gt_fmax)
  usage frf "$MODEL" --out DA.x --in DA.x --fmin 200 --fmax 100
  err_has "expected fmin <= fmax" ;;
usage_rpm_min_gt_max) usage campbell "$MODEL" --rpm-min 5000 --rpm-max 100; err_has "expected rpm-min <= rpm-max" ;;
usage_campbell_flat_range) usage campbell "$MODEL" --rpm-min 100 --rpm-max 100 --points 3; err_has "expected rpm-min < rpm-max" ;;
usage_points_zero)
  usage frf "$MODEL" --out DA.x --in DA.x --fmax 100 --points 0
  err_has "option --points expects a whole number >= 1" ;;
usage_bad_number) usage modes "$MODEL" --rpm fast; err_has "expects a finite number" ;;
usage_negative_speed) usage modes "$MODEL" --rpm -10; err_has "expects a value >= 0" ;;
usage_bad_choice)
  usage frf "$MODEL" --out DA.x --in DA.x --fmax 100 --kind velocity
  err_has "receptance | mobility | inertance" ;;
usage_rpm_and_synchronous) usage frf "$MODEL" --out DA.x --in DA.x --fmax 1 --rpm 1 --synchronous; err_has "exclude each other" ;;
usage_unknown_channel)
  usage frf "$MODEL" --out DA.x,NOPE.y --in DA.x --fmax 100
  err_has "NOPE"; err_has "rcbtool check" ;;
usage_bad_direction) usage unbalance "$MODEL" --out DA.z --rpm-max 100; err_has "expected x, y, rx or ry" ;;
usage_empty_channel) usage unbalance "$MODEL" --out DA.x,,DA.y --rpm-max 100; err_has "empty channel name" ;;
usage_extra_argument) usage check "$MODEL" "$MODEL"; err_has "unexpected argument" ;;
usage_repeated_option) usage modes "$MODEL" --rpm 1 --rpm 2; err_has "given twice" ;;

# ---- help and version: exit 0, on stdout ----
help_commands)
  run help; expect_rc 0
  for c in check matrices frf unbalance modes campbell; do out_has "  $c "; done
  for c in check matrices frf unbalance modes campbell; do
    run "$c" --help; expect_rc 0; out_has "usage: rcbtool $c MODEL.ini"
    run help "$c"; expect_rc 0; out_has "usage: rcbtool $c MODEL.ini"
  done ;;
version) run --version; expect_rc 0; out_has "rcbtool 0." ;;

# ---- bad input: exit 3, the message names the file ----
missing_model) run check "$W/no_such_model.ini"; expect_rc 3; out_empty; err_has "no_such_model.ini" ;;
bad_model)
  printf '[material steel]\ndensity = 7800\nyoung = 2e11\npoisson = 0.3\n[shaft A]\nmaterial = unobtanium\nsegment = 1 0.02 0 4\n' >"$W/bad.ini"
  run check "$W/bad.ini"; expect_rc 3; out_empty
  grep -E -q 'bad\.ini:[0-9]+' "$W/err" || fail "message does not name file:line" ;;

# ---- check ----
check_paper)
  run check "$MODEL"; expect_rc 0
  for s in DA DB B1 B2 B3 B4 C.A C.B; do
    grep -q "^$s," "$W/out" || fail "station $s missing from the station table"
  done
  out_has "node,shaft,z_m,dof_x,dof_y,dof_rx,dof_ry" ;;
check_json)
  run check "$MODEL" --json; expect_rc 0; json_ok
  python3 - "$W/out" <<'EOF' || fail "check JSON content"
import json, sys
d = json.load(open(sys.argv[1]))
names = {s["name"] for s in d["stations"]}
assert {"DA", "DB", "B1", "B2", "B3", "B4", "C.A", "C.B"} <= names, names
# issue #2: shafts of 10 elements each, one node per element end, 4 DOF/node
assert d["n_nodes"] == 22 and len(d["nodes"]) == 22, d["n_nodes"]
assert d["ndof"] == 88
EOF
  ;;

# ---- output: exit 5, nothing left behind, the model never overwritten ----
output_unwritable)
  run check "$MODEL" -o "$W/no/such/dir/out.csv"; expect_rc 5; out_empty
  err_has "out.csv"
  [ ! -e "$W/no/such/dir/out.csv" ] || fail "a file was written" ;;
output_onto_directory)
  mkdir "$W/d" "$W/d/target"
  run check "$MODEL" -o "$W/d/target"; expect_rc 5
  [ "$(ls -A "$W/d")" = "target" ] || fail "temporary file left: $(ls -A "$W/d")"
  [ -z "$(ls -A "$W/d/target")" ] || fail "wrote into the directory" ;;
output_over_model)
  cp "$MODEL" "$W/model.ini"; ln -s "$W/model.ini" "$W/link.ini"
  run check "$W/model.ini" -o "$W/model.ini"; expect_rc 5
  run check "$W/model.ini" -o "$W/link.ini"; expect_rc 5
  cmp -s "$MODEL" "$W/model.ini" || fail "the model file was modified"
  stray=$(ls -A "$W" | grep -v -x -e err -e out -e link.ini -e model.ini)
  [ -z "$stray" ] || fail "stray files: $stray" ;;
output_file_ok)
  mkdir "$W/d"
  run check "$MODEL"; expect_rc 0; cp "$W/out" "$W/stdout.csv"
  run check "$MODEL" -o "$W/d/check.csv"; expect_rc 0; out_empty
  cmp -s "$W/stdout.csv" "$W/d/check.csv" || fail "-o FILE differs from stdout"
  [ "$(ls -A "$W/d")" = "check.csv" ] || fail "stray files: $(ls -A "$W/d")"
  echo old >"$W/d/check.csv"
  run check "$MODEL" -o "$W/d/check.csv"; expect_rc 0
  cmp -s "$W/stdout.csv" "$W/d/check.csv" || fail "existing file not replaced" ;;
stdout_full)
  [ -c /dev/full ] || exit 77
  "$T" check "$MODEL" >/dev/full 2>"$W/err"; RC=$?; expect_rc 5
  "$T" check "$MODEL" -o /dev/full 2>"$W/err"; RC=$?; expect_rc 5
  [ -c /dev/full ] || fail "/dev/full was replaced" ;;

# ---- every command's JSON parses ----
json_matrices)
  run matrices "$MODEL" --rpm 1000 --json; expect_rc 0; json_ok
  python3 - "$W/out" <<'EOF' || fail "matrices JSON content"
import json, sys
d = json.load(open(sys.argv[1]))
n = d["ndof"]
assert n == 88 and len(d["nodes"]) == 22
for k in "MCGK":
    A = d[k]
    assert len(A) == n and all(len(r) == n for r in A), k
M, G = d["M"], d["G"]
# M symmetric positive on the diagonal, G skew-symmetric (gyroscopic): the
# row-major JSON must not be transposed or shuffled on the way out
mmax = max(abs(x) for r in M for x in r)
gmax = max(abs(x) for r in G for x in r)
assert gmax > 0
for i in range(n):
    assert M[i][i] > 0
    for j in range(n):
        assert abs(M[i][j] - M[j][i]) <= 1e-12 * mmax
        assert abs(G[i][j] + G[j][i]) <= 1e-12 * gmax
EOF
  ;;
json_frf)
  run frf "$MODEL" --out DA.x,C.A.y --in DA.x,DB.y --fmin 10 --fmax 200 --points 7 --rpm 1500 --json
  expect_rc 0; json_ok
  python3 - "$W/out" <<'EOF' || fail "frf JSON content"
import json, sys
d = json.load(open(sys.argv[1]))
# f_i = fmin + i (fmax - fmin)/(N - 1)
assert d["freq_hz"] == [10 + i * 190 / 6 for i in range(7)] or \
    max(abs(a - (10 + i * 190 / 6)) for i, a in enumerate(d["freq_hz"])) < 1e-12
assert d["rpm"] == 1500 and d["kind"] == "receptance"
ch = [(c["output"], c["input"]) for c in d["channels"]]
assert ch == [("DA.x", "DA.x"), ("DA.x", "DB.y"), ("C.A.y", "DA.x"), ("C.A.y", "DB.y")], ch
assert all(len(c["re"]) == 7 and len(c["im"]) == 7 for c in d["channels"])
EOF
  ;;
json_unbalance) run unbalance "$MODEL" --out DA.x,DA.y --rpm-min 100 --rpm-max 6000 --points 5 --json; expect_rc 0; json_ok ;;
json_modes) run modes "$MODEL" --rpm 3000 --modes 4 --json; expect_rc 0; json_ok ;;
json_campbell) run campbell "$MODEL" --rpm-max 6000 --points 5 --modes 4 --json; expect_rc 0; json_ok ;;

# ---- CSV shapes ----
csv_frf_header)
  run frf "$MODEL" --out DA.x --in DB.y --fmax 100 --points 3; expect_rc 0
  [ "$(head -1 "$W/out")" = "freq_hz,DA.x/DB.y re,DA.x/DB.y im" ] || fail "header: $(head -1 "$W/out")"
  [ "$(wc -l <"$W/out")" -eq 4 ] || fail "expected 3 data rows" ;;
campbell_one_speed)
  run campbell "$MODEL" --rpm-min 100 --rpm-max 100 --points 1 --modes 2 --json; expect_rc 0; json_ok
  python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); assert d["rpm"]==[100] and d["critical_rpm"]==[]' "$W/out" ||
    fail "one-speed Campbell" ;;
csv_campbell_sections)
  run campbell "$MODEL" --rpm-max 6000 --points 4 --modes 2; expect_rc 0
  [ "$(head -1 "$W/out")" = "rpm,fd1_hz,fd2_hz,logdec1,logdec2,whirl1,whirl2" ] || fail "header"
  out_has "critical_rpm,mode" ;;

# ---- units at the edge: rpm and Hz are converted consistently ----
rpm_hz_consistency)
  # A synchronous FRF at f Hz spins the rotor at 60 f rpm: same numbers as --rpm 60f.
  run frf "$MODEL" --out DA.x,DA.y --in DA.x,DB.y --fmin 40 --fmax 40 --points 1 --synchronous --json
  expect_rc 0; cp "$W/out" "$W/sync.json"
  run frf "$MODEL" --out DA.x,DA.y --in DA.x,DB.y --fmin 40 --fmax 40 --points 1 --rpm 2400 --json
  expect_rc 0
  python3 - "$W/sync.json" "$W/out" <<'EOF' || fail "synchronous FRF differs from --rpm 60 f"
import json, sys
a, b = (json.load(open(p)) for p in sys.argv[1:3])
assert a["rpm"] is None and a["synchronous"] is True and b["rpm"] == 2400
for ca, cb in zip(a["channels"], b["channels"]):
    for x, y in zip(ca["re"] + ca["im"], cb["re"] + cb["im"]):
        assert abs(x - y) <= 1e-10 * max(abs(x), abs(y), 1e-30), (x, y)
EOF
  ;;
unbalance_identity)
  # Paper eqs. 3-4: Q = H(W, W) F with F_x = me W^2 e^{i phase}, F_y = -i F_x.
  # The model (issue #2): 15e-5 kg m at DA (phase 0) and at DB (phase 90 deg).
  run unbalance "$MODEL" --out DA.x,DB.y --rpm-min 3000 --rpm-max 3000 --points 1 --json
  expect_rc 0; cp "$W/out" "$W/unb.json"
  run frf "$MODEL" --out DA.x,DB.y --in DA.x,DA.y,DB.x,DB.y --fmin 50 --fmax 50 --points 1 --rpm 3000 --json
  expect_rc 0
  python3 - "$W/unb.json" "$W/out" <<'EOF' || fail "unbalance response differs from H F"
import cmath, json, math, sys
u, h = (json.load(open(p)) for p in sys.argv[1:3])
W = 3000 * math.pi / 30
fa = 15e-5 * W * W
fb = 15e-5 * W * W * cmath.exp(1j * math.pi / 2)
F = {"DA.x": fa, "DA.y": -1j * fa, "DB.x": fb, "DB.y": -1j * fb}
for c in u["channels"]:
    q = sum(complex(k["re"][0], k["im"][0]) * F[k["input"]]
            for k in h["channels"] if k["output"] == c["output"])
    got = complex(c["re"][0], c["im"][0])
    assert abs(got - q) <= 1e-8 * abs(q), (c["output"], got, q)
    assert abs(c["amp"][0] - abs(q)) <= 1e-8 * abs(q)
    assert abs(c["phase_deg"][0] - math.degrees(cmath.phase(q))) < 1e-6
EOF
  ;;

# ---- progress goes to stderr only ----
progress_stderr)
  run frf "$MODEL" --out DA.x --in DA.x --fmax 100 --points 5; expect_rc 0; cp "$W/out" "$W/quiet.csv"
  run frf "$MODEL" --out DA.x --in DA.x --fmax 100 --points 5 --progress; expect_rc 0
  cmp -s "$W/quiet.csv" "$W/out" || fail "--progress changed stdout"
  err_has "frf: 5/5 frequencies"
  run frf "$MODEL" --out DA.x --in DA.x --fmax 100 --points 5; expect_rc 0
  [ ! -s "$W/err" ] || fail "progress printed to a non-terminal without --progress" ;;

*) echo "unknown test case '$CASE'"; exit 1 ;;
esac
exit 0
