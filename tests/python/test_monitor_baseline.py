"""Which objective gives an unbiased commissioning baseline (issue #24 item 2).

The commissioning files of a monitored machine are noisy measurements of it;
the baseline's tracked values come from a fit on one of them. The null series
of monitor_cases.py (ROSS 2.3, the paper system at 10000 rpm, 8 inertances x
400 lines, eq. 19 noise 10 % random and 1 % systematic, each file its own
seed) are NFILES independent measurements of a machine whose kt, kr, ct are
the model's own (the truth). Each is fitted with `rcbtool fit --params
kt,kr,ct --noise 10,1` on --scale log10 (rcbtool fit's default) and on
--scale complex, starting at the truth.

Asserted, on the NFILES (24) fits: the complex fits' mean error is within 4
standard errors of the mean of zero for every parameter and their 95 %
intervals cover the truth at least as often as the lower end of the binomial
99 % interval of 95 % allows; the log10 fits' mean error is within 4 standard
errors of the mean too (E[log10 |1 + e|] < 0 for the proportional noise e is
taken off the data since issue #33), and every parameter's rms error is more
than 3 times the complex fits': without the phase the magnitudes determine
the coupling's parameters far less well. The figures are printed (pytest -s) and in docs/monitoring.md.
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

NFILES = int(os.environ.get("RCB_BASELINE_FILES", "24"))
PARAMS = mc.FIT_PARAMS.split(",")
ENV = dict(os.environ, OPENBLAS_NUM_THREADS="1")
FIGURES = {}


def fit(tool, model, meas, scale):
    res = subprocess.run([tool, "fit", str(model), str(meas), "--params", ",".join(PARAMS),
                          "--noise", "10,1", "--scale", scale, "--json"], capture_output=True,
                         text=True, timeout=300, env=ENV)
    assert res.returncode == 0, res.stderr[-2000:]
    return {p["name"]: p for p in json.loads(res.stdout)["params"]}


@pytest.fixture(scope="module")
def fits():
    tool = _rcbtool_path()
    d, truth, model = mc.series("null")
    files = [d / f for f in truth["files"][:NFILES]]
    return {scale: [fit(tool, model, f, scale) for f in files] for scale in ("log10", "complex")}


def summary(rows, name):
    """(mean relative error, its standard error, rms relative error, coverage) of one
    parameter over the fits."""
    t = rows[0][name]["start"]  # the fit starts at the truth
    err = [(r[name]["fitted"] - t) / t for r in rows]
    mean = sum(err) / len(err)
    sd = math.sqrt(sum((e - mean) ** 2 for e in err) / (len(err) - 1))
    rms = math.sqrt(sum(e * e for e in err) / len(err))
    cover = sum(r[name]["ci95"][0] <= t <= r[name]["ci95"][1] for r in rows)
    return mean, sd / math.sqrt(len(err)), rms, cover


def figures(fits):
    for scale in ("log10", "complex"):
        for name in PARAMS:
            mean, sem, rms, cover = summary(fits[scale], name)
            FIGURES[f"{scale} {name}"] = (
                f"mean error {100 * mean:+.4f} % ({mean / sem:+.1f} standard errors of the "
                f"mean), rms {100 * rms:.4f} %, 95 % interval covers the truth in {cover} of "
                f"{NFILES}")


def test_complex_unbiased_and_covering(fits):
    """The complex fits: mean error within 4 standard errors of 0, intervals covering."""
    figures(fits)
    lo, _ = stats.binom.interval(0.99, NFILES, 0.95)
    for name in PARAMS:
        mean, sem, rms, cover = summary(fits["complex"], name)
        assert abs(mean) < 4 * sem, FIGURES[f"complex {name}"]
        assert cover >= lo, FIGURES[f"complex {name}"]


def test_log10_unbiased_but_scattered(fits):
    """The log10 fits: every parameter's mean error within 4 standard errors of the mean
    of zero (issue #33: the declared noise's mean on the log scale, E log10(1 + A/100 r1),
    is taken off the data, rcb_fit_log_bias; before, kt's mean error was -0.088 %, -5.0
    standard errors of the mean), and every parameter's rms error more than 3 times the
    complex fits' (a variance ratio of 9: F(n-1, n-1) exceeds it with probability 8e-7 for
    n = 24): without the phase the magnitudes determine the coupling far less well."""
    figures(fits)
    for name in PARAMS:
        mean, sem, rms, cover = summary(fits["log10"], name)
        assert abs(mean) < 4 * sem, FIGURES[f"log10 {name}"]
        assert rms > 3 * summary(fits["complex"], name)[2], FIGURES


def wear_run(tool, scale, tmp, series="kt_wear"):
    """@p series monitored from a baseline fitted on its first file on @p scale, the
    fit's standard errors given as --baseline-sd."""
    d, truth, model = mc.series(series)
    base = tmp / f"base_{scale}.ini"
    res = subprocess.run([tool, "fit", str(model), str(d / truth["files"][0]), "--params",
                          ",".join(PARAMS), "--noise", "10,1", "--scale", scale, "--json",
                          "-o", str(base)], capture_output=True, text=True, timeout=300,
                         env=ENV)
    assert res.returncode == 0, res.stderr[-2000:]
    sd = {p["name"]: p["stderr"] for p in json.loads(res.stdout)["params"]}
    res = subprocess.run([tool, "monitor", str(base), str(d), "--params", ",".join(PARAMS),
                          "--noise", "10,1", "--commission", str(mc.COMMISSION), "--reweight",
                          "--relinearise", "8", "--alpha", "0.01", "--baseline-sd",
                          ",".join(f"{sd[n]:.9g}" for n in PARAMS), "--json"],
                         capture_output=True, text=True, timeout=600, env=ENV)
    assert res.returncode == 0, res.stderr[-2000:]
    log = json.loads(res.stdout)
    ups = log["updates"]
    kt = [truth["kt"][truth["files"].index(u["file"])] for u in ups]
    k = PARAMS.index("coupling.C.kt")
    out = {
        "n": len(ups), "tests": sum(u["alarm"] for u in ups),
        "cusum_others": {n: [u["update"] for u in ups if u["tracked"][j]["cusum_alarm"]]
                         for j, n in enumerate(PARAMS) if j != k},
        "cusum_kt": [u["update"] for u in ups if u["tracked"][k]["cusum_alarm"]],
        "value": sum(u["tracked"][k]["ci_lo"] <= t <= u["tracked"][k]["ci_hi"]
                     for u, t in zip(ups, kt)),
        "change": sum(u["tracked"][k]["change_lo"] <= t - truth["kt0"] <= u["tracked"][k]["change_hi"]
                      for u, t in zip(ups, kt)),
    }
    FIGURES[f"{series} from a {scale} baseline"] = (
        f"{out['tests']} TEST alarms in {out['n']} updates; CUSUM alarms of kr, ct at "
        f"{out['cusum_others']}; kt's value interval (baseline sd {sd['coupling.C.kt']:.3g} N/m) "
        f"covers the truth in {out['value']}, its change interval the true change in "
        f"{out['change']}")
    return out


def test_wear_from_fitted_baseline(tmp_path):
    """kt_wear (kt -0.1 % per update) monitored from a baseline fitted on its first
    file with --scale complex, its standard errors carried (--baseline-sd): TEST
    alarms within the binomial 99 % interval at alpha 0.01, no CUSUM alarm of the
    unchanged kr and ct, and kt's value and change intervals each covering the truth
    at least as often as the binomial 99 % lower end of 95 % allows. The log10
    baseline's run is printed beside it."""
    tool = _rcbtool_path()
    out = wear_run(tool, "complex", tmp_path)
    wear_run(tool, "log10", tmp_path)
    _, hi = stats.binom.interval(0.99, out["n"], 0.01)
    lo, _ = stats.binom.interval(0.99, out["n"], 0.95)
    msg = FIGURES["kt_wear from a complex baseline"]
    assert out["tests"] <= hi, msg
    assert not any(out["cusum_others"].values()), msg
    assert out["value"] >= lo and out["change"] >= lo, msg


def test_null_from_fitted_baseline(tmp_path):
    """The null series (190 updates) from a baseline fitted on its first file with
    --scale complex: TEST alarms within the binomial 99 % interval at alpha 0.01, no
    CUSUM alarm (its false-alarm rate holds with a baseline that is itself an
    estimate), and kt's value interval covering the truth and its change interval
    the true change (0) at least as often as the binomial 99 % lower end of 95 %."""
    tool = _rcbtool_path()
    out = wear_run(tool, "complex", tmp_path, "null")
    _, hi = stats.binom.interval(0.99, out["n"], 0.01)
    lo, _ = stats.binom.interval(0.99, out["n"], 0.95)
    msg = FIGURES["null from a complex baseline"] + f"; kt's CUSUM at {out['cusum_kt']}"
    assert out["tests"] <= hi, msg
    assert not any(out["cusum_others"].values()) and not out["cusum_kt"], msg
    assert out["value"] >= lo and out["change"] >= lo, msg


@pytest.mark.parametrize("series", ["kt_wear", "null", "cross_B3"])
def test_log10_baseline_holds(tmp_path, series):
    """Issue #34 item 4: the baseline fitted as the README does it (rcbtool fit's
    default log10 scale, --noise 10,1), its standard errors carried: on the
    wear, the null and the step (cross_B3, the step's own alarms aside) series
    the TEST alarms stay within the binomial 99 % bound at alpha 0.01 where
    nothing new appears, and kt's change interval covers the true change at
    least as often as the binomial 99 % lower end of 90 % allows (the aim:
    90 % over null, wear and step series; the baseline's error enters the
    change through the curvature, rcb_monitor_tracked.change_lo). Before
    (issue #34): 15 TEST alarms in 100 updates and 38 % coverage on the wear."""
    tool = _rcbtool_path()
    out = wear_run(tool, "log10", tmp_path, series)
    d, truth, _ = mc.series(series)
    n_quiet = out["n"] if series != "cross_B3" else truth["change_update"] - mc.COMMISSION
    _, hi = stats.binom.interval(0.99, max(n_quiet, 1), 0.01)
    lo, _ = stats.binom.interval(0.99, out["n"], 0.90)
    msg = FIGURES[f"{series} from a log10 baseline"]
    if series != "cross_B3":
        assert out["tests"] <= hi, msg
    assert out["change"] >= lo, msg
    assert not any(out["cusum_others"].values()), msg


def teardown_module(module):
    if FIGURES:
        print(f"\ncommissioning fits on {NFILES} files of the ROSS null series:")
        for k, v in FIGURES.items():
            print(f"  {k}: {v}")
