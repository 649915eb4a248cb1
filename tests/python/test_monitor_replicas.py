"""The monitor's rates with replicas on ROSS-made series (issue #24, "Done
when"): a step, and wear of a tracked parameter from a baseline fitted on noisy
data, each with a restart (save, a new monitor, load) in the middle of every
replica. The null and the untracked drift are test_monitor_drift.py's.

Truth: ROSS 2.3's matrices of the paper system at the monitoring series' set-up
(monitor_cases.Truth: 8 inertances x 400 lines, 100-399.25 Hz, 10000 rpm; K
affine in kt, checked against a third build to 1e-12; the cross-coupled
kxy = -kyx = 1.5e7 N/m at bearing B3). The clean inertances are computed once
and cached (<tmp>/rcb_monitor_replicas-<key>.npz, keyed by this file,
monitor_cases.py, diag_cases.py, test_monitor_drift.py and the ROSS version);
each replica adds eq. 19 noise (10 % random, 1 % systematic) with its own seeds
(test_monitor_drift._eq19). The options are the documented procedure's
(docs/monitoring.md): COMMISSION files averaged into the reference, reweighted,
up to 8 re-linearisations, alpha 0.01.

* step: STEP_REPLICAS replicas of STEP_ONSET null updates, the restart, then
  the cross-coupling at B3 for STEP_AFTER updates, from the model as it is.
  Asserted: the instant test's false alarms over the null updates within the
  binomial 99 % upper bound at alpha; detection delay: the alarm on the first
  changed update in at least the binomial 1 % quantile of 90 % of replicas;
  first attribution: that alarm's first candidate the cross-coupled stiffness
  at B3, in at least the same bound; interval coverage: its 95 % interval holds
  1.5e7 N/m in at least the binomial 1 % quantile of 95 %. The first replica
  is also run without the restart: the results are equal, number for number.
* wear from a fitted baseline: WEAR_REPLICAS replicas, each its own baseline
  (`rcb.fit` of kt, kr, ct on one noisy file, scale complex, the documented
  commissioning), its standard errors given as baseline_sd (the CUSUM's
  allowance for the baseline's error and the values' intervals); kt falls
  WEAR_RATE per update (0.05 %, the issue's rate) for WEAR_UPDATES updates, the
  restart after half of them. Asserted: CUSUM false alarms of the unchanged
  kr and ct: replicas with any within the binomial 99 % upper bound at twice
  (two parameters) the documented per-parameter bound alpha + 2 n / ARL0
  (Siegmund's ARL0 at the default k = 0.5, h = 8, computed here); instant
  false alarms over all updates within the binomial 99 % upper bound at alpha;
  detection delay: kt's CUSUM alarm within WEAR_DELAY updates, and the first
  attribution: that alarm "kt falling" named alone (the attribution's
  named == 1), each in at least the binomial 1 % quantile of 90 %; interval
  coverage: kt's value interval at the last update holds the truth, and its
  change interval the true change, each in at least the binomial 1 % quantile
  of 95 %.

The figures are printed (pytest -s) and in docs/monitoring.md; more replicas:
RCB_STEP_REPLICAS, RCB_WEAR_REPLICAS.
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
import test_monitor_drift as td  # noqa: E402  (eq. 19 draws, the measurement wrapper)

pytest.importorskip("ross")
rcb = pytest.importorskip("librcb")

PARAMS, COMMISSION, ALPHA = td.PARAMS, td.COMMISSION, td.ALPHA  # the drift test's set-up
OPTS = dict(noise=mc.NOISE, setup_averages=COMMISSION, alpha=ALPHA, relinearise=8,
            reweight=True)
STEP_REPLICAS = int(os.environ.get("RCB_STEP_REPLICAS", "16"))
STEP_ONSET = 6  # null updates before the step (the restart after them)
STEP_AFTER = 2  # updates with the cross-coupling
WEAR_REPLICAS = int(os.environ.get("RCB_WEAR_REPLICAS", "12"))
WEAR_RATE = 0.0005  # kt's fall per update, of its nominal value
WEAR_UPDATES = 30
WEAR_DELAY = 5  # updates, test_monitor_ross's
CUSUM_K, CUSUM_H = 0.5, 8.0  # the library's defaults (rcb_monitor_opts)
FIGURES = {}


def _key():
    import ross

    h = hashlib.sha256()
    for p in (Path(__file__), HERE / "monitor_cases.py", HERE / "diag_cases.py",
              HERE / "test_monitor_drift.py"):
        h.update(p.read_bytes())
    h.update(ross.__version__.encode())
    return h.hexdigest()[:12]


@pytest.fixture(scope="module")
def truth(tmp_path_factory):
    """Clean inertances: H0 (as commissioned), Hx (cross-coupled at B3), Hw[u]
    (kt at KT0 (1 - WEAR_RATE u), u = 0 .. WEAR_UPDATES); and the user's model."""
    path = Path(tempfile.gettempdir()) / f"rcb_monitor_replicas-{_key()}.npz"
    if path.is_file():
        z = np.load(path)
        H0, Hx, Hw = z["H0"], z["Hx"], z["Hw"]
    else:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            t = mc.Truth()
        H0, Hx = t.inertance(mc.KT0, None), t.inertance(mc.KT0, "cross_B3")
        Hw = np.array([t.inertance(mc.KT0 * (1 - WEAR_RATE * u), None)
                       for u in range(WEAR_UPDATES + 1)])
        tmp = path.with_suffix(f".{os.getpid()}.npz")
        np.savez(tmp, H0=H0, Hx=Hx, Hw=Hw)
        os.replace(tmp, path)
    ini = tmp_path_factory.mktemp("replicas") / "model.ini"
    ini.write_text(mc.model_ini())
    return H0, Hx, Hw, ini


def _commission(H, seed):
    return np.mean([td._eq19(H, seed + i) for i in range(COMMISSION)], axis=0)


def _run(mon, make_mon, series, restart_at):
    """Updates of @p series (noisy arrays); at @p restart_at the state is saved,
    another monitor, make_mon(mon), made from the same model and set-up, loads it
    and goes on (None: no restart). The results, and the monitor in use at the end."""
    out = []
    for u, data in enumerate(series):
        if u == restart_at:
            state = mon.save_state()
            mon = make_mon(mon)
            mon.load_state(state)
        with td._meas(data) as ms:
            out.append(mon.update(ms))
    return out, mon


def test_step_with_restart(truth):
    H0, Hx, _, ini = truth
    with rcb.Model.from_ini(ini) as m:
        with td._meas(_commission(H0, 500000)) as setup:
            # two monitors made alike: every replica restarts from one into the other
            pair = [rcb.Monitor(m, setup, PARAMS, **OPTS) for _ in range(2)]
            mon = pair[0]
            fresh = mon.save_state()

            def make(old):
                return pair[1] if old is pair[0] else pair[0]
            false, n0, caught, first_ok, cover, R = 0, 0, 0, 0, 0, STEP_REPLICAS
            for rep in range(R):
                series = [td._eq19(H0 if u < STEP_ONSET else Hx, 510000 + 1000 * rep + u)
                          for u in range(STEP_ONSET + STEP_AFTER)]
                mon.load_state(fresh)
                res, mon = _run(mon, make, series, STEP_ONSET)
                if rep == 0:  # the restart changes nothing
                    mon.load_state(fresh)
                    same, mon = _run(mon, make, series, None)
                    assert same == res
                false += sum(r["alarm"] for r in res[:STEP_ONSET])
                n0 += STEP_ONSET
                r = res[STEP_ONSET]
                caught += bool(r["alarm"])
                top = r["top"][0] if r["alarm"] and r["top"] else None
                named = top is not None and (top["effect"], top["place"]) == (dc.CROSS,
                                                                              "bearing B3")
                first_ok += named
                cover += named and top["ci_lo"][0] <= mc.CROSS_B3 <= top["ci_hi"][0]
            for x in pair:
                x.close()
    hi = stats.binom.ppf(0.99, n0, ALPHA)
    lo90, lo95 = stats.binom.ppf(0.01, R, 0.9), stats.binom.ppf(0.01, R, 0.95)
    FIGURES["step"] = (f"{R} replicas, restart before the step: {false} instant alarms in {n0} "
                       f"null updates (99 % bound {hi:.0f}); alarm on the first changed update "
                       f"in {caught}, named cross-coupling at B3 in {first_ok} (bound {lo90:.0f}); "
                       f"its interval holds 1.5e7 N/m in {cover} (bound {lo95:.0f})")
    print(FIGURES["step"])
    assert false <= hi, FIGURES["step"]
    assert caught >= lo90 and first_ok >= lo90, FIGURES["step"]
    assert cover >= lo95, FIGURES["step"]


def _arl0(k, h):
    """Siegmund's in-control average run length of a one-sided CUSUM on N(0, 1)."""
    b = h + 1.166
    return (math.exp(2 * k * b) - 2 * k * b - 1) / (2 * k * k)


@pytest.fixture(scope="module")
def wear(truth):
    """The wear replicas' figures (computed once for the two tests below)."""
    H0, _, Hw, ini = truth
    R, n = WEAR_REPLICAS, WEAR_UPDATES
    kt_last = mc.KT0 * (1 - WEAR_RATE * n)
    others, tests, delays, firsts, value, change, zbase = 0, 0, [], 0, 0, 0, []
    told_bad = 0
    with rcb.Model.from_ini(ini) as m:
        # The intervals are judged against librcb's own kt for ROSS's clean
        # inertances (the pseudo-truth, at commissioning and at the last
        # update): they state the estimate's scatter, not the two codes'
        # model difference, which is printed (kt about -0.005 %: larger than
        # a baseline's standard error, so against ROSS's kt the value interval
        # covered 10 of 16 at 40 updates).
        star = []
        for H in (H0, Hw[n]):
            with td._meas(H) as ms:
                fp = rcb.fit(m, ms, PARAMS, scale="complex", noise=mc.NOISE[:2], starts=1)
            star.append(fp.params[0]["value"])
            fp.model.close()
        kt0_star, kt_last_star = star
        for rep in range(R):
            with td._meas(td._eq19(H0, 600000 + rep)) as ms:
                fr = rcb.fit(m, ms, PARAMS, scale="complex", noise=mc.NOISE[:2], starts=1)
            sd = [p["stderr"] for p in fr.params]
            zbase.append((fr.params[0]["value"] - kt0_star) / sd[0])
            with td._meas(_commission(H0, 610000 + 100 * rep)) as setup:
                def make(old=None):
                    if old is not None:
                        old.close()
                    return rcb.Monitor(fr.model, setup, PARAMS, baseline_sd=sd, **OPTS)
                series = [td._eq19(Hw[u], 620000 + 1000 * rep + u) for u in range(1, n + 1)]
                res, mon = _run(make(), make, series, n // 2)
                mon.close()
            fr.model.close()
            others += any(t["cusum_alarm"] for r in res for t in r["tracked"][1:])
            tests += sum(r["alarm"] for r in res)
            first = next((r for r in res if r["tracked"][0]["cusum_alarm"]), None)
            delays.append(None if first is None else first["update"])
            t = first["tracked"][0] if first else None
            firsts += t is not None and t["cusum_alarm"] < 0 and t["named"] == 1
            # "told apart" wrongly (issue #34 item 2: the truth is kt, tracked): an
            # instant alarm's first candidate named alone, a candidate told apart
            # from kt, or kr or ct named alone
            told_bad += any((r["alarm"] and r.get("separable")) or
                            any(tr["cusum_alarm"] and ((j > 0 and tr["named"] == 1) or
                                                       tr["named"] == -1)
                                for j, tr in enumerate(r["tracked"])) for r in res)
            t = res[-1]["tracked"][0]
            value += t["ci_lo"] <= kt_last_star <= t["ci_hi"]
            change += t["change_lo"] <= kt_last_star - kt0_star <= t["change_hi"]
    p_other = min(1.0, 2 * (ALPHA + 2 * n / _arl0(CUSUM_K, CUSUM_H)))
    b = dict(hi_o=stats.binom.ppf(0.99, R, p_other), hi_t=stats.binom.ppf(0.99, R * n, ALPHA),
             lo90=stats.binom.ppf(0.01, R, 0.9), lo95=stats.binom.ppf(0.01, R, 0.95))
    in_time = sum(d is not None and d <= WEAR_DELAY for d in delays)
    zrms = math.sqrt(sum(z * z for z in zbase) / R)
    FIGURES["wear"] = (f"{R} replicas x {n} updates, kt -{100 * WEAR_RATE:g} %/update from a "
                       f"fitted baseline with baseline_sd, restart at {n // 2}: kr/ct CUSUM "
                       f"alarms in {others} replicas (99 % bound {b['hi_o']:.0f} at "
                       f"{p_other:.4f}); {tests} instant alarms (bound {b['hi_t']:.0f}); kt CUSUM "
                       f"within {WEAR_DELAY} updates in {in_time}, a wrong 'told apart' in "
                       f"{told_bad} (99 % bound at 5 %: {stats.binom.ppf(0.99, R, 0.05):.0f}), "
                       f"first message 'kt falling' "
                       f"alone in {firsts} (bound {b['lo90']:.0f}); delays {delays}; kt value "
                       f"interval holds librcb's kt for the clean data in {value}, change "
                       f"interval its change in {change} (bound {b['lo95']:.0f}); the baselines' "
                       f"kt error in their standard errors: rms {zrms:.2f}; librcb's kt for "
                       f"ROSS's clean data: {100 * (kt0_star / mc.KT0 - 1):+.4f} % at "
                       f"commissioning, {100 * (kt_last_star / kt_last - 1):+.4f} % at the end")
    print(FIGURES["wear"])
    return dict(b, others=others, tests=tests, in_time=in_time, firsts=firsts, value=value,
                change=change, told_bad=told_bad, hi_told=stats.binom.ppf(0.99, R, 0.05))


def test_wear_from_fitted_baseline_with_restart(wear):
    w = wear
    assert w["others"] <= w["hi_o"], FIGURES["wear"]
    assert w["tests"] <= w["hi_t"], FIGURES["wear"]
    assert w["in_time"] >= w["lo90"] and w["firsts"] >= w["lo90"], FIGURES["wear"]
    assert w["change"] >= w["lo95"], FIGURES["wear"]
    assert w["told_bad"] <= w["hi_told"], FIGURES["wear"]


def test_wear_value_interval_coverage(wear):
    """kt's value interval (the baseline's sd carried) holds librcb's kt for the
    clean data at the last update in at least the binomial 1 % quantile of 95 %
    of replicas."""
    assert wear["value"] >= wear["lo95"], FIGURES["wear"]


ANTI_DRAWS = int(os.environ.get("RCB_ANTI_DRAWS", "16"))


def test_step_size_weights_at_the_fit(truth):
    """Eq. 19's proportional noise weighed at the update's fitted moduli, not
    its own noisy ones (monitor_gls.c, fitted_abs): antithetic draws. The
    commissioning is COMMISSION / 2 pairs H0 + n, H0 - n (their mean is H0
    exactly); each of ANTI_DRAWS draws n of eq. 19 noise on the cross-coupled truth Hx is
    given as Hx + n and Hx - n, and Hx itself once. Half their difference in
    sizes of the B3 cross-coupling is the estimate's first-order error (its
    rms in standard errors of the noise-free update's interval: about 1, a
    little less since the commissioning's share is declared and not there);
    their mean minus the noise-free size is its second-order error: -0.217
    standard errors (spread 0.027 over the draws) with the sds at |v|, +0.007
    (0.185) at the fitted moduli (2026-12-06). Asserted:
    the mean second-order error within +-0.12 standard errors, and the rms
    first-order error in [0.75, 1.3]."""
    H0, Hx, _, ini = truth
    files = []
    for i in range(COMMISSION // 2):
        n = td._eq19(H0, 600000 + i) - H0
        files += [H0 + n, H0 - n]

    def size(mon, data):
        with td._meas(data) as ms:
            r = mon.update(ms)
        top = r["top"][0]
        assert r["alarm"] and top["place"] == "bearing B3", top
        return top["size"][0], (top["ci_hi"][0] - top["ci_lo"][0]) / (2 * stats.norm.ppf(0.975))

    with rcb.Model.from_ini(ini) as m, td._meas(np.mean(files, axis=0)) as setup:
        mon = rcb.Monitor(m, setup, PARAMS, **OPTS)
        try:
            x0, sd0 = size(mon, Hx)
            first, second = [], []
            for j in range(ANTI_DRAWS):
                n = td._eq19(Hx, 610000 + j) - Hx
                xp, xm = size(mon, Hx + n)[0], size(mon, Hx - n)[0]
                first.append((xp - xm) / 2 / sd0)
                second.append(((xp + xm) / 2 - x0) / sd0)
        finally:
            mon.close()
    mean2 = float(np.mean(second))
    rms1 = float(np.sqrt(np.mean(np.square(first))))
    FIGURES["weights at the fit"] = (
        f"{ANTI_DRAWS} antithetic draws on the B3 step: size {x0:.6g} N/m noise-free (sd "
        f"{sd0:.4g}); second-order error {mean2:+.3f} sd (spread {np.std(second):.3f}), "
        f"first-order rms {rms1:.3f} sd")
    print(FIGURES["weights at the fit"])
    assert abs(mean2) <= 0.12, FIGURES["weights at the fit"]
    assert 0.75 <= rms1 <= 1.3, FIGURES["weights at the fit"]
