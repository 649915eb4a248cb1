"""The monitor's drift test and the attribution of its CUSUM alarms (issue #24
item 3), with replicas on ROSS-made series.

Truth: ROSS 2.3's matrices of the paper system at the monitoring series'
set-up (monitor_cases.py: 8 inertances x 400 frequencies, 100-399.25 Hz,
10000 rpm), with bearing B4's kyy set on the parsed model (diag_cases.
bearing_keys): two ROSS builds, K affine in kyy (checked against a third
build to 1e-12), and the inertances solved from those matrices at every kyy
the series needs. The untracked drift: B4 kyy falls by DRIFT_SD = 0.215 of
its per-update standard deviation per update (the rate of the issue), from
update ONSET + 1 on; its size reaches 3 standard deviations at update
ONSET + 14. Noise: eq. 19 (10 % random, 1 % systematic), drawn with numpy
(each update its own seed). The commissioning: the average of COMMISSION
files. The clean inertances are cached (<tmp>/rcb_monitor_drift-<key>.npz,
keyed by this file, monitor_cases.py, diag_cases.py and the ROSS version).

Replicas share a monitor per commissioning (GROUPS of them) and start from
its saved fresh state (rcb_monitor_load), so a replica costs its updates
only (a few ms each). Asserted against binomial bounds:

* null: each replica's last drift p-value is a valid p-value (it is
  Bonferroni over candidates and onsets): the replicas below 0.1 are within
  the binomial 99 % upper bound at rate 0.1; the replicas with any drift
  alarm in NULL_UPDATES updates within the bound at the union rate
  NULL_UPDATES x alpha; the replicas with any CUSUM alarm within the bound at
  2 x 3 x NULL_UPDATES / ARL0 (Siegmund's, k 0.5, h 8); each tracked
  parameter's change interval holding 0 at the last update in at least the
  binomial 1 % quantile of 95 %;
* drift: detected and named (a drift alarm on B4 kyy, or the instant test
  naming it first) before its size reaches 3 standard deviations in at least
  80 % of replicas (the count above the binomial 1 % quantile at 0.8);
* first attribution: the first message of a replica is a tracked parameter
  named alone (the issue's "kr falling", 5 of 5 before) in at most 20 %
  (binomial 99 % upper bound), and names B4 kyy (the drift test, the instant
  test's first candidate, or a CUSUM alarm whose attribution gives B4 kyy as
  its rival, not separable or told apart) in at least 30 % (lower bound): kr
  and B4 kyy, and a few added masses at shaft B's nodes, are near collinear on
  these channels, and which of those the accumulated change fits best is
  then the noise's choice (the message says they are not separable).
"""

import hashlib
import math
import os
import sys
import tempfile
import warnings
from pathlib import Path

import numpy as np
import pytest
from scipy import stats

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import diag_cases as dc  # noqa: E402
import monitor_cases as mc  # noqa: E402
import ross_models as rm  # noqa: E402

pytest.importorskip("ross")
rcb = pytest.importorskip("librcb")

PARAMS = mc.FIT_PARAMS.split(",")  # coupling.C.kt, kr, ct
COMMISSION = 10
ALPHA = 0.01
# replicas: RCB_DRIFT_GROUPS commissionings x RCB_DRIFT_REPLICAS (the docs' figures
# were run with more of both: docs/monitoring.md)
GROUPS = int(os.environ.get("RCB_DRIFT_GROUPS", "2"))  # commissionings
DRIFT_SD = 0.215  # B4 kyy's fall per update, its per-update standard deviations
# B4 kyy's per-update standard deviation on this set-up (N/m): the monitor's
# linear standard error of the candidate jointly with the tracked parameters
# (test_sd_of_b4_kyy checks it); the drift's rate is fixed from it so that the
# ROSS data do not depend on the code under test
SD_KYY = 34510.0
# the untracked drifts (issue #34: a bearing other than the tests' own too):
# name -> (bearing, coefficient, its per-update standard deviation, N/m, fixed
# as SD_KYY is and checked by test_sd_of_drift)
DRIFTS = {"B4.kyy": ("B4", "kyy", SD_KYY), "B2.kxx": ("B2", "kxx", 1169.0)}
ONSET = 6  # null updates before the drift
DRIFT_UPDATES = 20  # updates of drift per replica
REPLICAS = int(os.environ.get("RCB_DRIFT_REPLICAS", "10"))  # drift replicas per group
NULL_REPLICAS = 2 * REPLICAS  # null replicas per group
NULL_UPDATES = 32  # a whole window
FIGURES = {}


def _key():
    import ross

    h = hashlib.sha256()
    for p in (Path(__file__), HERE / "monitor_cases.py", HERE / "diag_cases.py"):
        h.update(p.read_bytes())
    h.update(ross.__version__.encode())
    return h.hexdigest()[:12]


def _clean(case="B4.kyy"):
    """Clean inertances (DRIFT_UPDATES + 1, channels, points): the drift's
    bearing coefficient at k0 - j DRIFT_SD sd, j = 0 .. DRIFT_UPDATES, from
    ROSS's matrices."""
    brg, key, sd = DRIFTS[case]
    tag = "" if case == "B4.kyy" else f"-{case}-{sd:.6g}"
    path = Path(tempfile.gettempdir()) / f"rcb_monitor_drift-{_key()}{tag}.npz"
    if path.is_file():
        return np.load(path)["H"]
    k0 = float(dc._bearing(rm.Model(dc.BASE_INI), brg)[key][-1])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        a = mc.RossSystem(None)
        b = mc.RossSystem(dc.bearing_keys(brg, **{key: 0.5 * k0}))
        c = mc.RossSystem(dc.bearing_keys(brg, **{key: 0.8 * k0}))
    kmat = lambda k: a.K + (k - k0) / (-0.5 * k0) * (b.K - a.K)  # noqa: E731
    err = np.max(np.abs(kmat(0.8 * k0) - c.K)) / np.max(np.abs(c.K))
    assert err < 1e-12, f"ROSS K is not affine in {brg} {key} ({err:.3e})"
    H = np.array([mc.inertance(a.M, a.C, kmat(k0 - j * DRIFT_SD * sd), a.G, a.speed,
                               mc.FREQ_HZ, a.rows, a.jin) for j in range(DRIFT_UPDATES + 1)])
    tmp = path.with_suffix(f".{os.getpid()}.npz")
    np.savez(tmp, H=H)
    os.replace(tmp, path)
    return H


def _eq19(H, seed):
    """eq. 19 (10 % random along the value, 1 % systematic of each channel's rms
    level in a random direction), numpy's generator."""
    g = np.random.default_rng(seed)
    ba, bs = mc.NOISE
    r1 = g.uniform(-1, 1, H.shape)
    r2 = g.uniform(-1, 1, H.shape)
    phi = g.uniform(0, 2 * math.pi, H.shape)
    level = np.sqrt(np.sum(np.abs(H) ** 2, axis=1, keepdims=True)) / H.shape[1] * bs / 100
    return H * (1 + ba / 100 * r1) + level * r2 * np.exp(1j * phi)


def _meas(data):
    return rcb.Meas.from_arrays(mc.FREQ_HZ, data, dc.OUTS, [dc.IN] * len(dc.OUTS),
                                kind="inertance", rpm=dc.RPM)


@pytest.fixture(scope="module", params=list(DRIFTS))
def groups(request, tmp_path_factory):
    global _CASE
    _CASE = request.param
    H = _clean(request.param)
    ini = tmp_path_factory.mktemp("drift") / "model.ini"
    ini.write_text(mc.model_ini())
    out = []
    with rcb.Model.from_ini(ini) as m:
        for gi in range(GROUPS):
            avg = np.mean([_eq19(H[0], 900000 + 100 * gi + i) for i in range(COMMISSION)], axis=0)
            with _meas(avg) as setup:
                mon = rcb.Monitor(m, setup, PARAMS, noise=mc.NOISE, setup_averages=COMMISSION,
                                  alpha=ALPHA)
            out.append((mon, mon.save_state()))
    yield H, out
    for mon, _ in out:
        mon.close()


_CASE = "B4.kyy"  # the drift case of the current groups fixture


def _b4(d):
    """Whether d names the drifting coefficient (B4 kyy, or the case's)."""
    brg, key, _ = DRIFTS[_CASE]
    return (d is not None and d["place"] == f"bearing {brg}" and
            d["params"] == f"bearing.{brg}.{key}")


def test_sd_of_drift(groups):
    """The case's sd is the monitor's standard error of the coefficient (a step of
    10 sd, noise-free)."""
    H, gs = groups
    mon, fresh = gs[0]
    mon.load_state(fresh)
    step = int(round(10 / DRIFT_SD))
    if step > DRIFT_UPDATES:
        step = DRIFT_UPDATES
    with _meas(H[step]) as ms:
        r = mon.update(ms)
    c = r["top"][0]
    assert _b4(c), c
    sd = (c["ci_hi"][0] - c["ci_lo"][0]) / (2 * 1.959963984540054)
    print(f"{_CASE}: the monitor's sd {sd:.6g} N/m")
    assert sd == pytest.approx(DRIFTS[_CASE][2], rel=0.02)


def test_null_false_alarms(groups):
    H, gs = groups
    last_p, any_alarm, alarms, n, cusum, cover = [], 0, 0, 0, 0, [0] * len(PARAMS)
    for gi, (mon, fresh) in enumerate(gs):
        for rep in range(NULL_REPLICAS):
            mon.load_state(fresh)
            hit = hit_c = False
            for u in range(NULL_UPDATES):
                with _meas(_eq19(H[0], 1000000 * (gi + 1) + 1000 * rep + u)) as ms:
                    r = mon.update(ms)
                n += 1
                alarms += r["drift"]["alarm"]
                hit |= r["drift"]["alarm"]
                hit_c |= any(t["cusum_alarm"] for t in r["tracked"])
            last_p.append(r["drift"]["p_value"])
            any_alarm += hit
            cusum += hit_c
            # nothing changed: each change interval at the last update holds 0
            for k, t in enumerate(r["tracked"]):
                cover[k] += t["change_lo"] <= 0.0 <= t["change_hi"]
    R = len(last_p)
    below = sum(p < 0.1 for p in last_p)
    # the CUSUMs: per side Siegmund's ARL0 (k 0.5, h 8: 19110 updates), both sides
    # of every tracked parameter over NULL_UPDATES updates
    p_cusum = min(1.0, 2 * len(PARAMS) * NULL_UPDATES / 19110.0)
    FIGURES["null"] = (alarms, n, any_alarm, R, below, cusum, cover)
    print(f"null: {alarms} drift alarms in {n} updates (alpha {ALPHA}); replicas with any: "
          f"{any_alarm} of {R}; last p < 0.1 in {below} of {R}; replicas with a CUSUM alarm "
          f"{cusum} (99 % bound {stats.binom.ppf(0.99, R, p_cusum):.0f}); change intervals "
          f"holding 0 at the last update {cover} of {R}")
    assert below <= stats.binom.ppf(0.99, R, 0.1)
    assert any_alarm <= stats.binom.ppf(0.99, R, min(1.0, NULL_UPDATES * ALPHA))
    assert cusum <= stats.binom.ppf(0.99, R, p_cusum)
    assert min(cover) >= stats.binom.ppf(0.01, R, 0.95)


def _first_message(r):
    """What an update's alarms name: None (no alarm), 'alone' (some tracked
    parameter's CUSUM alarm attributed to it alone: the issue's "kr
    falling"), 'b4' (every alarm names B4 kyy: the drift test, the instant
    test's first candidate, or a CUSUM alarm with B4 kyy as its rival, not
    separable or told apart, or as the rival's not-separable runner-up,
    rival2), else 'other'."""
    msgs = []
    if r["drift"]["alarm"]:
        msgs.append("b4" if _b4(r["drift"]) else "other")
    if r["alarm"] and r["top"]:
        msgs.append("b4" if _b4(r["top"][0]) else "other")
    for t in r["tracked"]:
        if t["cusum_alarm"]:
            msgs.append("alone" if t["named"] == 1 else
                        "b4" if _b4(t["rival"]) or _b4(t.get("rival2")) else "other")
    if not msgs:
        return None
    return "alone" if "alone" in msgs else "b4" if all(m == "b4" for m in msgs) else "other"


def _wrong_told_apart(r):
    """The "told apart" statements of update r that are wrong when the truth is the
    case's drift (issue #34 item 2): the instant test's first candidate named
    alone (the one rule: told apart from the second) when it is not the drift,
    a tracked CUSUM alarm named alone (told apart from every candidate), or its
    rival told apart from the tracked parameter (no not-separable runner-up)
    when that rival is not the drift. (statements, wrong) counts."""
    n = bad = 0
    if r["alarm"] and r.get("separable"):
        n += 1
        bad += not _b4(r["top"][0])
    for t in r["tracked"]:
        if t["cusum_alarm"] and (t["named"] == 1 or (t["named"] == -1 and not t.get("rival2"))):
            n += 1
            bad += t["named"] == 1 or not _b4(t["rival"])
    return n, bad


def test_drift_detected_and_attributed(groups):
    H, gs = groups
    need = int(math.floor(3 / DRIFT_SD))  # updates of drift before its size reaches 3 sd
    detected, delays, R = 0, [], 0
    firsts = {"alone": 0, "b4": 0, "other": 0, None: 0}
    told, told_bad, reps_bad = 0, 0, 0
    for gi, (mon, fresh) in enumerate(gs):
        for rep in range(REPLICAS):
            mon.load_state(fresh)
            R += 1
            first = None
            delay = None
            rep_bad = False
            for u in range(ONSET + DRIFT_UPDATES):
                j = max(0, u - ONSET + 1)  # updates of drift so far
                with _meas(_eq19(H[j], 2000000 * (gi + 1) + 1000 * rep + u)) as ms:
                    r = mon.update(ms)
                if first is None:
                    first = _first_message(r)
                n, bad = _wrong_told_apart(r)
                told, told_bad = told + n, told_bad + bad
                rep_bad = rep_bad or bad > 0
                # detected and named: the drift test, or the instant test's first
                # candidate (the drift test is silent while the instant test fires)
                if delay is None and ((r["drift"]["alarm"] and _b4(r["drift"])) or
                                      (r["alarm"] and r["top"] and _b4(r["top"][0]))):
                    delay = j
            delays.append(delay)
            detected += delay is not None and 0 < delay <= need
            firsts[first] += 1
            reps_bad += rep_bad
    FIGURES["drift"] = (detected, firsts, R, delays)
    print(f"{_CASE} falling {DRIFT_SD} sd per update: detected within {need} updates (3 sd) in "
          f"{detected} of {R}; first message: {firsts['b4']} B4 kyy (alone or not separable "
          f"from a tracked parameter), {firsts['alone']} a tracked parameter alone, "
          f"{firsts['other']} another effect, {firsts[None]} none; delays {delays}")
    # at least 80 % detected in time; the first message, a tracked parameter
    # named alone, in at most 20 %; B4 kyy in the first message in at least 30 %;
    # and (issue #34) named before 5 sd (all DRIFT_UPDATES: 4.3 sd) in at least 80 %
    late = sum(d is not None and 0 < d <= DRIFT_UPDATES for d in delays)
    print(f"{_CASE}: {told} 'told apart' statements, {told_bad} wrong; replicas with a wrong "
          f"one {reps_bad} of {R} (99 % bound at 5 %: {stats.binom.ppf(0.99, R, 0.05):.0f})")
    assert reps_bad <= stats.binom.ppf(0.99, R, 0.05)
    print(f"{_CASE}: named within {DRIFT_UPDATES} updates ({DRIFT_UPDATES * DRIFT_SD:.1f} sd) "
          f"in {late} of {R}")
    assert late >= stats.binom.ppf(0.01, R, 0.8)
    assert detected >= stats.binom.ppf(0.01, R, 0.8)
    assert firsts["alone"] <= stats.binom.ppf(0.99, R, 0.2)
    assert firsts["b4"] >= stats.binom.ppf(0.01, R, 0.3)
