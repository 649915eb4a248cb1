"""The monitor's noise level measured at commissioning (issue #34, item 2:
noise that differs from the declared formula).

The series here are made outside librcb: ROSS 2.3's matrices of the paper
system (monitor_cases.RossSystem), the 8 inertances of monitor_cases at 400
frequencies, and numpy's eq. 19 draws (diag_cases.add_noise) at 12 % and
1.2 %, 20 % above what the user declares (`--noise 10,1`), the level the
replica benchmark found the monitor failing at (docs/benchmarks.md: 439 TEST
false alarms in 750 null updates at 32 x 1101, bound 14). Nothing changes
in the machine.

* `rcbtool monitor --commission 10` (the default `--noise-scale auto`)
  measures the level on the 10 commissioning files' scatter: 1.2 within 3 %
  (its relative sd here is about sqrt(1 / (2 dof)) = 0.4 %, the whitening at
  the average a little more), printed in the header and in JSON;
* with it, the instant test's false alarms over N null updates stay within
  the binomial 99 % interval of alpha, and the tracked parameters whose CUSUM
  alarms within the binomial 99 % bound of the CUSUM's own rate (2 N / ARL0
  per parameter, Siegmund's ARL0 at k = 0.5, h = 8: at most 1 of 3 here;
  the CUSUM's rate at the users' size is the replica benchmark's);
* the same series with `--noise-scale 1` (the noise as declared, as before)
  has false alarms above that interval: the failure the scale removes (the
  test can fail);
* the null series of monitor_cases (eq. 19 as declared) measures 1 within
  3 %, so a monitor on declared noise is left as it was.
"""

import json
import os
import subprocess

import numpy as np
import pytest

import diag_cases as dc
import monitor_cases as mc
from conftest import _rcbtool_path

pytest.importorskip("pyuff")
stats = pytest.importorskip("scipy.stats")

LEVEL = 1.2  # the noise's level against the declared --noise 10,1
UPDATES = 60
ALPHA = 0.01
ARGS = ["--params", mc.FIT_PARAMS, "--noise", "10,1", "--commission", str(mc.COMMISSION),
        "--reweight", "--relinearise", "8", "--alpha", str(ALPHA), "--json"]


@pytest.fixture(scope="module")
def high(tmp_path_factory):
    """model.ini and a directory of 10 + UPDATES files of the machine as it
    is, eq. 19 noise at LEVEL x 10 %, LEVEL x 1 %."""
    d = tmp_path_factory.mktemp("noise_high")
    a = mc.RossSystem()
    H = mc.inertance(a.M, a.C, a.K, a.G, a.speed, mc.FREQ_HZ, a.rows, a.jin)
    s = d / "series"
    s.mkdir()
    for u in range(mc.COMMISSION + UPDATES):
        m = dc.add_noise(H, LEVEL * mc.NOISE[0], LEVEL * mc.NOISE[1], 8100 + u)
        dc.write_uff(s / mc.file_name(u), m, mc.FREQ_HZ)
    model = d / "model.ini"
    model.write_text(mc.model_ini())
    return model, s


def run(model, series, *extra):
    cmd = [_rcbtool_path(), "monitor", str(model), str(series), *ARGS, *extra]
    res = subprocess.run(cmd, capture_output=True, text=True, timeout=900,
                         env=dict(os.environ, OPENBLAS_NUM_THREADS="1"))
    assert res.returncode == 0, f"{' '.join(cmd)}: exit {res.returncode}\n{res.stderr[-3000:]}"
    return json.loads(res.stdout)


def test_high_noise_measured_and_held(high):
    log = run(*high)
    assert log["noise_scale_from"] == "commissioning scatter"
    assert log["scatter_dof"] == 2 * 8 * 400 * (mc.COMMISSION - 1)
    assert log["noise_scale"] == pytest.approx(LEVEL, rel=0.03)
    n = len(log["updates"])
    assert n == UPDATES
    count = sum(u["alarm"] for u in log["updates"])
    cusum = sum(u["cusum_alarm"] for u in log["updates"])
    # tracked parameters whose CUSUM alarmed, against the rate the CUSUM states:
    # each side's ARL0 by Siegmund's approximation at the library's k = 0.5, h = 8
    alarmed = sum(any(u["tracked"][k]["cusum_alarm"] for u in log["updates"])
                  for k in range(len(log["tracked"])))
    b = 2 * 0.5 * (8.0 + 1.166)
    arl0 = (np.exp(b) - b - 1) / (2 * 0.5 ** 2)
    cbound = stats.binom.ppf(0.99, len(log["tracked"]), min(1.0, 2 * n / arl0))
    lo, hi = stats.binom.interval(0.99, n, ALPHA)
    print(f"noise {LEVEL} x declared: measured {log['noise_scale']:.4f}; {count} TEST alarms "
          f"in {n} (99 % interval [{lo:.0f}, {hi:.0f}]), {cusum} updates with a CUSUM alarm, "
          f"{alarmed} parameters (bound {cbound:.0f} at ARL0 {arl0:.0f} per side)")
    assert count <= hi
    assert alarmed <= cbound


def test_high_noise_as_declared_fails(high):
    """The null case beside it: the same files with the noise as declared."""
    log = run(*high, "--noise-scale", "1")
    assert log["noise_scale_from"] == "option" and log["noise_scale"] == 1
    n = len(log["updates"])
    count = sum(u["alarm"] for u in log["updates"])
    lo, hi = stats.binom.interval(0.99, n, ALPHA)
    print(f"noise {LEVEL} x declared, taken as declared: {count} TEST alarms in {n} "
          f"(99 % interval [{lo:.0f}, {hi:.0f}])")
    assert count > hi


def test_declared_noise_measured_as_one():
    d, truth, model = mc.series("null")
    log = run(model, d)
    print(f"eq. 19 as declared: measured {log['noise_scale']:.4f}")
    assert log["noise_scale_from"] == "commissioning scatter"
    assert log["noise_scale"] == pytest.approx(1.0, rel=0.03)
