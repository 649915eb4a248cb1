"""Condition monitoring (issue #16) on ROSS series with hidden changes.

The series (monitor_cases.py) are made outside librcb: ROSS 2.3's matrices of
the paper system at 10000 rpm, the 8 inertances of diag_cases.py at 400
frequencies, eq. 19 noise (10 % random, 1 % systematic), each update its own
seed. `rcbtool monitor` is told neither when nor what changed; it gets the
user's model (the paper system as commissioned), the files in time order, the
noise model, and the same options for every series (MONITOR: the first 10
files averaged into the reference, each update reweighted by its own noise,
up to 8 re-linearisations of the tracked parameters, until converged).

* null (200 files, 190 updates): the instant test's false alarms are within
  the binomial 99 % interval of the rate asked for (alpha 0.01 and 0.05), and
  no CUSUM alarm;
* kt_wear (steady for the 10 commissioning files, then kt -0.1 % per update
  to -10 %): the kt CUSUM alarms falling within WEAR_DELAY updates of the
  start, the instant test stays within its false-alarm interval (a tracked
  parameter's drift is not a new effect), the CUSUMs of kr and ct (unchanged)
  stay silent, and kt's 95 % interval covers the
  truth in at least the lower end of the binomial 99 % interval of 95 %
  coverage;
* cross_B3 (kxy = -kyx = 1.5e7 N/m at B3 from file 37, and cross_B3_r1 .. r5,
  the same change under other noise seeds, for the intervals): no alarm before the
  change beyond the false-alarm interval, the instant test alarms within
  CROSS_DELAY updates of it, and the first candidate of the alarm is the
  cross-coupled stiffness at bearing B3; its 95 % interval covers the truth
  (1.5e7 N/m) on the alarmed updates, and the tracked kt, kr, ct (which did
  not change) are covered by theirs over the series, each at least the
  lower end of the binomial 99 % interval of 95 % coverage, and their
  CUSUMs stay silent;
* probe_DA_x (issue #34: the machine unchanged, DA.x's gain falling to 0.85
  over 70 updates), monitored with --sensors (every probe's gain among the
  candidates), and the null series beside it with the same option: the first alarm names the sensor DA.x before its gain
  has lost 10 %, every TEST alarm names it, its gain's interval covers the
  truth, and the tracked parameters are left alone (no CUSUM alarm);
* mass_DB (0.05 kg appears at disk DB at update 37 and stays): named at once
  with its size, then no CUSUM alarm of the tracked parameters;
* phase_DA_y (issue #34: the machine unchanged, DA.y's phase lagging to -3
  degrees over 50 updates) and swap_DA (DA.x and DA.y exchanged from update
  37), monitored with the measurement chain among the candidates (the
  default): the lag is named as the sensor DA.y (its gain and phase) before
  it reaches 1 degree, its phase interval covers the truth, the machine is
  left alone; the swap is named at once as the two probes swapped, its
  fraction's interval holding 1, and nothing is alarmed before it;
* null_phase (the null series with 2 degrees of phase noise per point, issue
  #14's), monitored with --noise 10,1,2 (the phase term of rcb_monitor_opts):
  false alarms as for null.
* signals (issue #15's path, RCB_MONITOR_ALL=1: about 2 min): 9 tests of 24 s
  of white force on DA.x simulated outside librcb (test_signals_diagnose's
  SciPy discretisation of the truth's matrices), `rcbtool estimate` (H1, with
  --stats), then `rcbtool monitor --sd DIR` on the estimates and their
  per-point sds: 3 commissioning tests, 4 null, 2 with kxy = -kyx = 2e7 N/m
  at B2, every second line written (`estimate --every 2`: neighbouring lines
  of a Hann estimate have correlated errors, docs/signals.md). The null
  updates' alarms stay within the binomial 99 % interval; both changed
  updates alarm and name the cross-coupled stiffness at B2.

The figures (detection delays, false-alarm counts, naming, coverage) are
printed at the end of the run (pytest -rA or -s shows them) and in
docs/monitoring.md.
"""

import json
import math
import os
import subprocess

import pytest

import monitor_cases as mc
from conftest import _rcbtool_path

pytest.importorskip("pyuff")
stats = pytest.importorskip("scipy.stats")

PARAMS = mc.FIT_PARAMS  # coupling.C.kt, kr, ct
NOISE = "10,1"  # eq. 19 A, S (%)
COMMISSION = mc.COMMISSION  # 10 files averaged into the reference
MONITOR = ["--commission", COMMISSION, "--reweight", "--relinearise", 8]
WEAR_DELAY = 5  # updates (0.5 % of kt) at most before the CUSUM alarm
CROSS_DELAY = 1  # updates after the change at most before the TEST alarm
FIGURES = {}


@pytest.fixture(scope="module")
def tool():
    return _rcbtool_path()


_RUNS = {}


def monitor(tool, name, *extra):
    key = (name, *map(str, extra))
    if key not in _RUNS:
        _RUNS[key] = _monitor(tool, name, *extra)
    return _RUNS[key]


def _monitor(tool, name, *extra):
    d, truth, model = mc.series(name)
    noise = NOISE + (f",{truth['phase_deg']:g}" if truth.get("phase_deg") else "")
    cmd = [tool, "monitor", str(model), str(d), "--params", PARAMS, "--noise", noise,
           *map(str, MONITOR), *map(str, extra), "--json"]
    res = subprocess.run(cmd, capture_output=True, text=True, timeout=900,
                         env=dict(os.environ, OPENBLAS_NUM_THREADS="1"))
    assert res.returncode == 0, f"{' '.join(cmd)}: exit {res.returncode}\n{res.stderr[-3000:]}"
    log = json.loads(res.stdout)
    for u in log["updates"]:
        u["index"] = truth["files"].index(u["file"])  # the file's place in the series
    return log, truth


def _alarms(log, key="alarm", lo=0, hi=None):
    return [u for u in log["updates"] if u[key] and lo <= u["index"] < (hi or 10**9)]


@pytest.mark.parametrize("name,alpha", [("null", 0.01), ("null", 0.05), ("null_phase", 0.01),
                                        ("null_phase", 0.05)])
def test_null_false_alarms(tool, name, alpha):
    log, truth = monitor(tool, name, "--alpha", alpha)
    n = len(log["updates"])
    assert n == truth["updates"] - COMMISSION
    assert log["alpha"] == pytest.approx(alpha, rel=1e-9)
    count = len(_alarms(log))
    lo, hi = stats.binom.interval(0.99, n, alpha)
    cusum = len(_alarms(log, "cusum_alarm"))
    key = f"{name} alpha={alpha}"
    FIGURES[key] = (f"{count} TEST alarms in {n} updates (expected {n * alpha:.1f}, 99 % "
                    f"interval [{lo:.0f}, {hi:.0f}]); {cusum} with a CUSUM alarm")
    assert lo <= count <= hi, FIGURES[key]


@pytest.mark.parametrize("name", ["null", "null_phase"])
def test_null_cusum_silent(tool, name):
    log, truth = monitor(tool, name, "--alpha", 0.01)
    cusum = [u["update"] for u in _alarms(log, "cusum_alarm")]
    FIGURES[f"{name} CUSUM"] = f"CUSUM alarms at updates {cusum}"
    assert not cusum, FIGURES[f"{name} CUSUM"]


@pytest.mark.parametrize("name", ["null", "kt_wear"])
def test_drift_test_quiet(tool, name):
    """The drift test (issue #24) on series where no untracked effect changes: at
    most alpha per update (its Bonferroni bound), within the binomial 99 % upper
    bound; on kt_wear a tracked parameter wears 10 % (the drift test's candidates
    are beyond the tracked columns, in each update's own noise with --reweight).
    And kt's CUSUM alarms there are attributed to kt alone (the attribution's
    rule: no candidate explains the accumulated change as well)."""
    log, truth = monitor(tool, name, "--alpha", 0.01)
    ups = log["updates"]
    drift = [u["update"] for u in ups if u["drift"] and u["drift"]["alarm"]]
    hi = stats.binom.ppf(0.99, len(ups), 0.01)
    FIGURES[f"{name} drift"] = f"drift alarms at updates {drift} of {len(ups)} (at most {hi:.0f})"
    assert len(drift) <= hi, FIGURES[f"{name} drift"]
    if name == "kt_wear":
        k = PARAMS.split(",").index("coupling.C.kt")
        # kt alone, except where the instant or drift test points at an untracked
        # candidate in the same update (issue #34 item 3: then "kt, or it: not
        # separable", that candidate the rival)
        named = [u["tracked"][k]["named"] for u in ups if u["tracked"][k]["cusum_alarm"]
                 and not u["alarm"] and not u["drift"]["alarm"]]
        pointed = [(u["tracked"][k]["named"], u["tracked"][k]["rival"]["place"],
                    (u["drift"] if u["drift"]["alarm"] else u["top"][0])["place"])
                   for u in ups if u["tracked"][k]["cusum_alarm"]
                   and (u["alarm"] or u["drift"]["alarm"])]
        assert named and all(v == 1 for v in named), named
        assert all(n == 0 and r == p for n, r, p in pointed), pointed


def test_kt_wear(tool):
    log, truth = monitor(tool, "kt_wear", "--alpha", 0.01)
    k = PARAMS.split(",").index("coupling.C.kt")
    ups = log["updates"]
    first = next((u for u in ups if u["tracked"][k]["cusum_alarm"] < 0), None)
    assert first is not None, "the kt CUSUM never alarmed"
    delay = first["index"] - COMMISSION  # kt changes from file COMMISSION + 1 on
    covered = [u["tracked"][k]["ci_lo"] <= truth["kt"][u["index"]] <= u["tracked"][k]["ci_hi"]
               for u in ups]
    cover = sum(covered) / len(covered)
    c_lo, _ = stats.binom.interval(0.99, len(covered), 0.95)
    tests = len(_alarms(log))
    lo, hi = stats.binom.interval(0.99, len(ups), 0.01)
    wrong_way = [u["update"] for u in ups if u["tracked"][k]["cusum_alarm"] > 0]
    others = {t["name"]: [u["update"] for u in ups if u["tracked"][j]["cusum_alarm"]]
              for j, t in enumerate(log["tracked"]) if j != k}
    FIGURES["kt_wear"] = (f"kt CUSUM alarm (falling) {delay} update(s) into the wear (file "
                          f"{first['index']}, kt "
                          f"{100 * (truth['kt'][first['index']] / truth['kt0'] - 1):+.1f} %); "
                          f"kt 95 % "
                          f"interval covers the truth in {100 * cover:.1f} % of {len(ups)} "
                          f"updates; {tests} TEST alarms (99 % interval at alpha 0.01 "
                          f"[{lo:.0f}, {hi:.0f}]); CUSUM alarms of the unchanged "
                          f"parameters: {others}")
    assert delay <= WEAR_DELAY, FIGURES["kt_wear"]
    assert not any(others.values()), FIGURES["kt_wear"]
    assert not wrong_way, f"kt CUSUM rising at updates {wrong_way}"
    assert sum(covered) >= c_lo, FIGURES["kt_wear"]
    assert tests <= hi, FIGURES["kt_wear"]


def _cross(tool):
    log, truth = monitor(tool, "cross_B3", "--alpha", 0.01)
    change = truth["change_update"]
    before = _alarms(log, hi=change)
    n_before = sum(1 for u in log["updates"] if u["index"] < change)
    lo, hi = stats.binom.interval(0.99, n_before, 0.01)
    after = _alarms(log, lo=change)
    return log, truth, change, before, n_before, hi, after


def test_cross_coupling_B3_detected(tool):
    log, truth, change, before, n_before, hi, after = _cross(tool)
    assert after, "no TEST alarm after the change"
    delay = after[0]["index"] - change
    FIGURES["cross_B3 detection"] = (
        f"change at file {change} (hidden); first TEST alarm at file {after[0]['index']} "
        f"(delay {delay}); {len(after)} of {truth['updates'] - change} updates after it alarm; "
        f"{len(before)} alarms before it in {n_before} updates (99 % interval at alpha 0.01: "
        f"at most {hi:.0f})")
    assert len(before) <= hi, FIGURES["cross_B3 detection"]
    assert 0 <= delay <= CROSS_DELAY, FIGURES["cross_B3 detection"]


def test_cross_coupling_B3_named(tool):
    log, truth, change, before, n_before, hi, after = _cross(tool)
    assert after, "no TEST alarm after the change"
    top = after[0]["top"][0]
    named = sum(u["top"][0]["effect"] == truth["effect"] and
                u["top"][0]["place"] == truth["place"] for u in after)
    FIGURES["cross_B3 naming"] = (
        f"first alarm names {top['effect']} at {top['place']} (size {top['size']}, 95 % "
        f"[{top['ci_lo']}, {top['ci_hi']}], p {top['p_value']}; truth {truth['effect']} at "
        f"{truth['place']}, {truth['cross_kxy']:g} N/m); {named} of {len(after)} alarms "
        f"after the change name it")
    assert top["effect"] == truth["effect"] and top["place"] == truth["place"], \
        FIGURES["cross_B3 naming"]
    assert not top["implausible"], FIGURES["cross_B3 naming"]


def test_cross_coupling_B3_intervals(tool):
    """The cross-coupling's 95 % interval on the alarmed updates that name it,
    and the tracked parameters' on every update, over cross_B3 and its
    CROSS_REPLICAS other noise draws (a coverage is a rate: one series' 23
    alarms share one commissioning), at the binomial 99 % lower end of 95 %;
    no CUSUM alarm in any of them. The mean of (estimate - truth) / stated sd
    is printed: about -0.3 (docs/monitoring.md's limits: a bias of second
    order in the noise, -0.2 at half the noise, -0.7 at twice)."""
    names = ["cross_B3"] + [f"cross_B3_r{r}" for r in range(1, mc.CROSS_REPLICAS + 1)]
    size, z, tracked, cusum, nups = [], [], {}, {}, 0
    for name in names:
        log, truth = monitor(tool, name, "--alpha", 0.01)
        after = _alarms(log, lo=truth["change_update"])
        for u in after:
            top = u["top"][0]
            if top["place"] != truth["place"]:
                continue
            size.append(top["ci_lo"][0] <= truth["cross_kxy"] <= top["ci_hi"][0])
            z.append((top["size"][0] - truth["cross_kxy"]) /
                     ((top["ci_hi"][0] - top["ci_lo"][0]) / (2 * stats.norm.ppf(0.975))))
        ups = log["updates"]
        nups += len(ups)
        for k, b in enumerate(log["tracked"]):
            tracked[b["name"]] = tracked.get(b["name"], 0) + sum(
                u["tracked"][k]["ci_lo"] <= b["baseline"] <= u["tracked"][k]["ci_hi"] for u in ups)
        cusum[name] = [u["update"] for u in _alarms(log, "cusum_alarm")]
    lo_s, _ = stats.binom.interval(0.99, len(size), 0.95)
    lo_t, _ = stats.binom.interval(0.99, nups, 0.95)
    FIGURES["cross_B3 intervals"] = (
        f"{len(names)} series: the cross-coupling's 95 % interval covers {mc.CROSS_B3:g} N/m on "
        f"{sum(size)} of {len(size)} alarms naming it (99 % binomial lower end {lo_s:.0f}), "
        f"mean (estimate - truth) / sd {sum(z) / max(len(z), 1):+.2f}; the tracked parameters' "
        f"cover their unchanged values on {tracked} of {nups} updates (lower end {lo_t:.0f}); "
        f"CUSUM alarms {cusum}")
    assert len(size) >= len(names) * 20, FIGURES["cross_B3 intervals"]
    assert sum(size) >= lo_s, FIGURES["cross_B3 intervals"]
    assert all(v >= lo_t for v in tracked.values()), FIGURES["cross_B3 intervals"]
    assert not any(cusum.values()), FIGURES["cross_B3 intervals"]


def _sensor_named(log, sensor, truth, i):
    """A probe's drift: the first alarm (instant or drift test) and what it
    names, the TEST alarms and those naming sensor first, whether their
    parameter i's 95 % interval holds truth[update] and the binomial 99 %
    lower end of 95 % of them, and the tracked parameters' coverage of their
    unchanged values (count per name, its lower end) and CUSUM alarms."""
    ups = log["updates"]
    first = next((u for u in ups if u["alarm"] or (u["drift"] and u["drift"]["alarm"])), None)
    assert first is not None, f"no alarm on the probe {sensor}"
    named_first = first["top"][0]["place"] if first["alarm"] else first["drift"]["place"]
    tests = _alarms(log)
    named = [u for u in tests if u["top"][0]["place"] == sensor]
    size = [u["top"][0]["ci_lo"][i] <= truth[u["index"]] <= u["top"][0]["ci_hi"][i]
            for u in named]
    lo_s, _ = stats.binom.interval(0.99, max(len(size), 1), 0.95)
    lo_t, _ = stats.binom.interval(0.99, len(ups), 0.95)
    tracked = {b["name"]: sum(u["tracked"][k]["ci_lo"] <= b["baseline"] <= u["tracked"][k]["ci_hi"]
                              for u in ups) for k, b in enumerate(log["tracked"])}
    cusum = [u["update"] for u in _alarms(log, "cusum_alarm")]
    return first, named_first, tests, named, size, lo_s, lo_t, tracked, cusum


def test_drifting_probe_named_as_the_sensor(tool):
    """Issue #34 item 1: DA.x's gain falls linearly to 0.85 over 70 updates
    (the machine unchanged). The first alarm, of the instant or the drift
    test, names the sensor DA.x before its gain has lost 10 %; every alarmed
    update names it first; the gain's 95 % interval covers the truth at the
    binomial 99 % lower end of 95 %; the tracked parameters' CUSUMs stay
    silent and their intervals cover their unchanged values as often."""
    log, truth = monitor(tool, "probe_DA_x", "--alpha", 0.01, "--sensors")
    ups = log["updates"]
    sensor = "sensor " + truth["probe"]
    gain = truth["probe_gain"]
    first, named_first, tests, named, size, lo_s, lo_t, tracked, cusum = _sensor_named(
        log, sensor, [g - 1 for g in gain], 0)
    named = len(named)
    FIGURES["probe_DA_x"] = (
        f"first alarm at file {first['index']} (gain {gain[first['index']]:.4f}) names "
        f"{named_first}; {named} of {len(tests)} TEST alarms name {sensor}; its gain's 95 % "
        f"interval covers the truth on {sum(size)} of {len(size)} (99 % lower end {lo_s:.0f}); "
        f"tracked intervals cover their values on {tracked} of {len(ups)} (lower end "
        f"{lo_t:.0f}); CUSUM alarms at {cusum}")
    assert named_first == sensor, FIGURES["probe_DA_x"]
    assert gain[first["index"]] > 0.90, FIGURES["probe_DA_x"]
    assert named == len(tests), FIGURES["probe_DA_x"]
    assert sum(size) >= lo_s, FIGURES["probe_DA_x"]
    assert all(v >= lo_t for v in tracked.values()), FIGURES["probe_DA_x"]
    assert not cusum, FIGURES["probe_DA_x"]


def _step(log, change, is_truth, size):
    """A step at update index change: the alarms before it and their 99 % bound
    at alpha 0.01, the alarms from it, those whose first candidate is_truth,
    how many of those hold size in their first parameter's 95 % interval and
    the binomial 99 % lower end of 95 % of them, and the CUSUM alarms."""
    before = _alarms(log, hi=change)
    n_before = sum(1 for u in log["updates"] if u["index"] < change)
    _, hi = stats.binom.interval(0.99, n_before, 0.01)
    after = _alarms(log, lo=change)
    named = [u for u in after if is_truth(u["top"][0])]
    held = sum(u["top"][0]["ci_lo"][0] <= size <= u["top"][0]["ci_hi"][0] for u in named)
    lo_s, _ = stats.binom.interval(0.99, max(len(named), 1), 0.95)
    cusum = [u["update"] for u in _alarms(log, "cusum_alarm")]
    return before, hi, after, named, held, lo_s, cusum


def _step_holds(after, named, held, lo_s, before, hi, cusum, n_after):
    """Every one of the n_after updates from the step alarmed naming the truth,
    its size held as often as the bound asks, no more alarms before than the
    bound, no CUSUM alarm."""
    return (len(named) == len(after) == n_after and held >= lo_s and len(before) <= hi
            and not cusum)


def _step_text(after, change, named, what, size, held, lo_s, before, hi, cusum):
    return (f"first TEST alarm at file {after[0]['index'] if after else None} (step at "
            f"{change}); {len(named)} of {len(after)} alarms name {what}, sizes "
            f"{[round(u['top'][0]['size'][0], 4) for u in named[:3]]}...; the interval holds "
            f"{size} on {held} (lower end {lo_s:.0f}); {len(before)} alarms before (bound "
            f"{hi:.0f}); CUSUM alarms at {cusum}")


def test_step_then_quiet(tool):
    """Issue #34 item 2: a point mass of 0.05 kg appears at disk DB at update 37
    (mass_DB, about 125 of its standard errors) and stays. The instant test
    alarms on the first changed update and names the added mass at disk DB, its
    95 % interval holding 0.05 kg on at least the binomial 99 % lower end of 95 %
    of the alarmed updates; no alarm before the change beyond the bound; and no
    CUSUM alarm of the tracked kt, kr, ct after it (the step's leakage into the
    tracked parameters is not a new finding: with --relinearise the tracked step
    is refined jointly with the named effect while the test fires)."""
    log, truth = monitor(tool, "mass_DB", "--alpha", 0.01)
    change = truth["change_update"]
    before, hi, after, named, size, lo_s, cusum = _step(
        log, change, lambda t: t["place"] == truth["place"] and t["effect"] == truth["effect"],
        truth["step_size"])
    FIGURES["mass_DB"] = _step_text(after, change, named, f"{truth['effect']} at "
                                    f"{truth['place']}", f"{truth['step_size']} kg", size,
                                    lo_s, before, hi, cusum)
    assert after and after[0]["index"] == change, FIGURES["mass_DB"]
    assert _step_holds(after, named, size, lo_s, before, hi, cusum, truth["updates"] - change), \
        FIGURES["mass_DB"]


def test_phase_lag_named_as_the_sensor(tool):
    """Issue #34 item 1, a probe's phase: DA.y lags linearly to -3 degrees over
    50 updates (ROSS truth, eq. 19 noise; the machine unchanged). The first
    alarm (instant or drift test) names the sensor DA.y before its lag reaches
    1 degree; every TEST alarm names it, its phase's 95 % interval (rad) holds
    the truth's change at the binomial 99 % lower end of 95 %; the tracked
    parameters are left alone (intervals as often, no CUSUM)."""
    log, truth = monitor(tool, "phase_DA_y", "--alpha", 0.01)
    ups = log["updates"]
    sensor = "sensor " + truth["lag_probe"]
    lag = truth["lag_rad"]
    # the candidate's parameters are the gain and the phase (rad), in that order
    first, named_first, tests, named, size, lo_s, lo_t, tracked, cusum = _sensor_named(
        log, sensor, lag, 1)
    FIGURES["phase_DA_y"] = (
        f"first alarm at file {first['index']} (lag {math.degrees(-lag[first['index']]):.3f} deg) "
        f"names {named_first}; {len(named)} of {len(tests)} TEST alarms name {sensor}; its phase's "
        f"95 % interval covers the truth on {sum(size)} of {len(size)} (99 % lower end "
        f"{lo_s:.0f}); tracked intervals cover their values on {tracked} of {len(ups)} (lower "
        f"end {lo_t:.0f}); CUSUM alarms at {cusum}")
    assert named_first == sensor and -lag[first["index"]] < math.radians(1.0), FIGURES["phase_DA_y"]
    assert len(named) == len(tests) and sum(size) >= lo_s, FIGURES["phase_DA_y"]
    assert all(v >= lo_t for v in tracked.values()) and not cusum, FIGURES["phase_DA_y"]


def test_swapped_probes_named(tool):
    """Issue #34 item 1, a swap: DA.x's and DA.y's cables are exchanged from
    update 37 (ROSS truth, eq. 19 noise; the machine unchanged). No alarm
    before beyond the binomial 99 % bound of alpha 0.01; the instant test
    alarms on the first swapped update and every one after names the two
    probes swapped, the fraction's 95 % interval holding 1 at the binomial
    lower end of 95 %; no CUSUM alarm of the tracked parameters."""
    log, truth = monitor(tool, "swap_DA", "--alpha", 0.01)
    a, b, change = truth["swap"]
    place = f"sensors {a}, {b}"
    before, hi, after, named, size, lo_s, cusum = _step(
        log, change, lambda t: t["place"] == place, 1.0)  # the fraction swapped: 1
    FIGURES["swap_DA"] = _step_text(after, change, named, place, "a fraction of 1", size,
                                    lo_s, before, hi, cusum)
    assert after and after[0]["index"] == change, FIGURES["swap_DA"]
    assert _step_holds(after, named, size, lo_s, before, hi, cusum, truth["updates"] - change), \
        FIGURES["swap_DA"]


def test_sensors_null(tool):
    """The null case beside the drifting probe: with the probes' gains among
    the candidates (--sensors) the null series' instant and drift alarms stay
    within the binomial 99 % bound of alpha 0.01, and no CUSUM alarms."""
    log, truth = monitor(tool, "null", "--alpha", 0.01, "--sensors")
    ups = log["updates"]
    hi = stats.binom.ppf(0.99, len(ups), 0.01)
    tests = [u["update"] for u in _alarms(log)]
    drift = [u["update"] for u in ups if u["drift"] and u["drift"]["alarm"]]
    cusum = [u["update"] for u in _alarms(log, "cusum_alarm")]
    FIGURES["null --sensors"] = (f"TEST alarms at {tests}, drift alarms at {drift} of "
                                 f"{len(ups)} (at most {hi:.0f} each); CUSUM at {cusum}")
    assert len(tests) <= hi and len(drift) <= hi and not cusum, FIGURES["null --sensors"]


SLOW = pytest.mark.skipif(not os.environ.get("RCB_MONITOR_ALL"),
                          reason="slow (9 simulated tests of 24 s, ~2 min): set RCB_MONITOR_ALL=1")


@pytest.fixture(scope="module")
def signals_log(tool, tmp_path_factory):
    pytest.importorskip("scipy.signal")
    import diag_cases as dc
    import numpy as np
    import test_signals_diagnose as tsd

    tmp = tmp_path_factory.mktemp("signals")
    rt = dc.Rcbtool(tool)
    base, cross = tmp / "base.ini", tmp / "cross.ini"
    base.write_text(dc.BASE_INI)
    cross.write_text(dc.set_keys(dc.BASE_INI, "bearing B2", kxy=2e7, kyx=-2e7))
    days = [base] * 7 + [cross] * 2  # 3 commissioning, 4 null updates, 2 changed
    (tmp / "meas").mkdir()
    (tmp / "sd").mkdir()
    for k, ini in enumerate(days):
        f, y = tsd._simulate(rt, ini, seed=300 + k)
        sig = tmp / "sig.csv"
        t = np.arange(len(f)) / tsd.FS
        np.savetxt(sig, np.column_stack([t, f, y]), delimiter=",", fmt="%.12g", comments="",
                   header="# units = N," + ",".join("m" for _ in dc.OUTS) +
                   "\ntime_s,force," + ",".join(dc.OUTS))
        rt.run("estimate", sig, "--input", "force=" + dc.IN, "--outputs", ",".join(dc.OUTS),
               "--nseg", tsd.NSEG, "--rpm", dc.RPM, "--kind", "inertance", "--fmax", 400,
               "--every", 2,
               "--stats", tmp / "sd" / f"day{k}_stats.csv", "-o", tmp / "meas" / f"day{k}.csv")
    res = subprocess.run([tool, "monitor", str(base), str(tmp / "meas"), "--params", PARAMS,
                          "--sd", str(tmp / "sd"), "--commission", "3", "--alpha", "0.01",
                          "--json"], capture_output=True, text=True, timeout=600)
    assert res.returncode == 0, res.stderr
    log = json.loads(res.stdout)
    ups = log["updates"]
    FIGURES["signals"] = (
        f"T/dof per update "
        f"{[round(u['T'] / u['dof'], 3) for u in ups]}, "
        f"T/threshold {[round(u['T'] / u['threshold'], 3) for u in ups]} (4 null, "
        f"then 2 with B2 cross-coupling); named on the changed ones: "
        f"{[(u['top'][0]['effect'], u['top'][0]['place']) for u in ups[4:]]}")
    return ups, dc


@SLOW
def test_signals_change_named(signals_log):
    ups, dc = signals_log
    for u in ups[4:]:
        assert u["alarm"], FIGURES["signals"]
        assert (u["top"][0]["effect"], u["top"][0]["place"]) == (dc.CROSS, "bearing B2"), \
            FIGURES["signals"]


@SLOW
def test_signals_null_silent(signals_log):
    ups, _ = signals_log
    lo, hi = stats.binom.interval(0.99, 4, 0.01)
    assert sum(u["alarm"] for u in ups[:4]) <= hi, FIGURES["signals"]


def teardown_module(module):
    if FIGURES:
        print("\nmonitoring on ROSS series (issue #16):")
        for k, v in FIGURES.items():
            print(f"  {k}: {v}")
