"""Condition monitoring (issue #16) on ROSS series with hidden changes.

The series (monitor_cases.py) are made outside librcb: ROSS 2.3's matrices of
the paper system at 10000 rpm, the 8 inertances of diag_cases.py at 400
frequencies, eq. 19 noise (10 % random, 1 % systematic) and 2 degrees of
phase noise per point, each update its own seed. `rcbtool monitor` is told
neither when nor what changed; it gets the user's model (the paper system as
commissioned), the files in time order and the noise model.

* null (200 files): the instant test's false alarms are within the binomial
  99 % interval of the rate asked for (alpha 0.01 and 0.05), and no CUSUM alarm;
* kt_wear (kt -0.1 % per update, to -10 % at update 100): the kt CUSUM alarms
  falling within WEAR_DELAY updates, the instant test stays at its false-alarm
  rate (a tracked parameter's drift is not a new effect), and kt's 95 %
  interval covers the truth in >= 95 % of the updates;
* cross_B3 (kxy = -kyx = 1.5e7 N/m at B3 from update 37): no alarm before the
  change beyond the false-alarm rate, the instant test alarms within
  CROSS_DELAY updates of it, and the first candidate of the alarm is the
  cross-coupled stiffness at bearing B3.

The figures (detection delays, false-alarm counts, naming, coverage) are
printed at the end of the run (pytest -rA or -s shows them) and in
docs/monitoring.md.
"""

import json
import os
import subprocess

import pytest

import monitor_cases as mc
from conftest import _rcbtool_path

pytest.importorskip("pyuff")
stats = pytest.importorskip("scipy.stats")

PARAMS = mc.FIT_PARAMS  # coupling.C.kt, kr, ct
NOISE = "10,1,2"  # eq. 19 A, S and the phase noise in degrees
COMMISSION = 1
WEAR_DELAY = 10  # updates (1 % of kt) at most before the CUSUM alarm
CROSS_DELAY = 1  # updates after the change at most before the TEST alarm
FIGURES = {}


@pytest.fixture(scope="module")
def tool():
    return _rcbtool_path()


def monitor(tool, name, *extra):
    d, truth, model = mc.series(name)
    cmd = [tool, "monitor", str(model), str(d), "--params", PARAMS, "--noise", NOISE,
           "--commission", str(COMMISSION), *map(str, extra), "--json"]
    res = subprocess.run(cmd, capture_output=True, text=True, timeout=900,
                         env=dict(os.environ, OPENBLAS_NUM_THREADS="1"))
    assert res.returncode == 0, f"{' '.join(cmd)}: exit {res.returncode}\n{res.stderr[-3000:]}"
    log = json.loads(res.stdout)
    for u in log["updates"]:
        u["index"] = truth["files"].index(u["file"])  # the file's place in the series
    return log, truth


def _alarms(log, key="alarm", lo=0, hi=None):
    return [u for u in log["updates"] if u[key] and lo <= u["index"] < (hi or 10**9)]


@pytest.mark.parametrize("alpha", [0.01, 0.05])
def test_null_false_alarms(tool, alpha):
    log, truth = monitor(tool, "null", "--alpha", alpha)
    n = len(log["updates"])
    assert n == truth["updates"] - COMMISSION
    assert log["alpha"] == pytest.approx(alpha, rel=1e-9)
    count = len(_alarms(log))
    lo, hi = stats.binom.interval(0.99, n, alpha)
    cusum = len(_alarms(log, "cusum_alarm"))
    FIGURES[f"null alpha={alpha}"] = (f"{count} TEST alarms in {n} updates (expected "
                                      f"{n * alpha:.1f}, 99 % interval [{lo:.0f}, {hi:.0f}]); "
                                      f"{cusum} with a CUSUM alarm")
    assert lo <= count <= hi, FIGURES[f"null alpha={alpha}"]
    assert cusum == 0, FIGURES[f"null alpha={alpha}"]


def test_kt_wear(tool):
    log, truth = monitor(tool, "kt_wear", "--alpha", 0.01)
    k = PARAMS.split(",").index("coupling.C.kt")
    ups = log["updates"]
    first = next((u for u in ups if u["tracked"][k]["cusum_alarm"] < 0), None)
    assert first is not None, "the kt CUSUM never alarmed"
    delay = first["index"]  # the drift starts at file 1
    covered = [u["tracked"][k]["ci_lo"] <= truth["kt"][u["index"]] <= u["tracked"][k]["ci_hi"]
               for u in ups]
    cover = sum(covered) / len(covered)
    tests = len(_alarms(log))
    lo, hi = stats.binom.interval(0.99, len(ups), 0.01)
    wrong_way = [u["update"] for u in ups if u["tracked"][k]["cusum_alarm"] > 0]
    FIGURES["kt_wear"] = (f"kt CUSUM alarm (falling) at file {delay} (kt "
                          f"{100 * (truth['kt'][delay] / truth['kt0'] - 1):+.1f} %); kt 95 % "
                          f"interval covers the truth in {100 * cover:.1f} % of {len(ups)} "
                          f"updates; {tests} TEST alarms (99 % interval at alpha 0.01 "
                          f"[{lo:.0f}, {hi:.0f}])")
    assert delay <= WEAR_DELAY, FIGURES["kt_wear"]
    assert not wrong_way, f"kt CUSUM rising at updates {wrong_way}"
    assert cover >= 0.95, FIGURES["kt_wear"]
    assert tests <= hi, FIGURES["kt_wear"]


def test_cross_coupling_B3(tool):
    log, truth = monitor(tool, "cross_B3", "--alpha", 0.01)
    change = truth["change_update"]
    before = _alarms(log, hi=change)
    n_before = sum(1 for u in log["updates"] if u["index"] < change)
    lo, hi = stats.binom.interval(0.99, n_before, 0.01)
    after = _alarms(log, lo=change)
    assert after, "no TEST alarm after the change"
    first = after[0]
    delay = first["index"] - change
    top = first["top"][0]
    named = top["effect"] == truth["effect"] and top["place"] == truth["place"]
    # every alarm after the change names it
    named_all = sum(u["top"][0]["effect"] == truth["effect"] and
                    u["top"][0]["place"] == truth["place"] for u in after)
    FIGURES["cross_B3"] = (f"change at file {change} (hidden); first TEST alarm at file "
                           f"{first['index']} (delay {delay}); named: {top['effect']} at "
                           f"{top['place']} (size {top['size']} N/m, 95 % "
                           f"[{top['ci_lo']}, {top['ci_hi']}]; truth {truth['cross_kxy']:g}); "
                           f"{len(before)} alarms before the change in {n_before} updates "
                           f"(99 % interval [{lo:.0f}, {hi:.0f}]); {len(after)} of "
                           f"{truth['updates'] - change} after it alarm, {named_all} "
                           f"of them name B3 cross-coupling")
    assert len(before) <= hi, FIGURES["cross_B3"]
    assert 0 <= delay <= CROSS_DELAY, FIGURES["cross_B3"]
    assert named, FIGURES["cross_B3"]


def teardown_module(module):
    if FIGURES:
        print("\nmonitoring on ROSS series (issue #16):")
        for k, v in FIGURES.items():
            print(f"  {k}: {v}")
