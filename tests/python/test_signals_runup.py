"""1X from a simulated 0 -> 15000 rpm run-up against `rcbtool unbalance`.

`rcbtool transient --signals` integrates the paper system (SUNDIALS) through a
run-up at 250 rpm/s (60 s of signal, 10 kS/s) with its unbalances, a
keyphasor and 20 nm RMS sensor noise; `rcbtool order` tracks 1X in 50 rpm
bins. Away from the critical speeds (1000-7500 and 11000-15000 rpm) each
bin's 1X must equal the steady unbalance response within 1 % and 1 degree,
and the speed of the 1X peak (parabola through the top three bins) the
steady response's peak within 0.5 %: at 250 rpm/s the run-up's peak lags by
about 0.4 % (at 500 rpm/s 0.7 %), the physics of a sweep, not an error of
the tracking. The integration takes minutes (16 min wall on the shared
2-core machine where it was measured); at --rtol 1e-6 --atol 1e-11,1e-8
(the defaults are 1e-7 and 1e-13,1e-10; 0.6 of the CPU on a 3 s run-up)
the worst bin away from the criticals is within 0.16 % and 0.19 deg with
`order`'s default (the least-squares fit of 8 orders; 0.25 % and 0.3 deg with
--method rev-dft), inside the 1 % and 1 degree asserted, and the peak lag is
0.38 %.
"""

import csv
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[2]
MODEL = REPO / "examples" / "paper_system.ini"
OUTS = ["DA.x", "DA.y", "DB.x"]


def _tool():
    path = os.environ.get("RCBTOOL")
    if not path:
        pytest.skip("RCBTOOL is not set (path to the rcbtool executable)")
    return path


def _run(*args):
    res = subprocess.run([str(a) for a in args], capture_output=True, text=True, timeout=3600)
    assert res.returncode == 0, res.stderr
    return res


def _read(path):
    rows = [r for r in csv.reader(open(path)) if r and not r[0].startswith("#")]
    body = np.array([[float(v) for v in r] for r in rows[1:]])
    # rcbtool's headers carry their SI unit ("DA.x amp [m]"): keyed without it
    return {h.split(" [")[0]: body[:, i] for i, h in enumerate(rows[0])}


def _peak(x, y):
    i = int(np.argmax(y))
    y0, y1, y2 = y[i - 1:i + 2]
    return x[i] + 0.5 * (y0 - y2) / (y0 - 2 * y1 + y2) * (x[i + 1] - x[i - 1]) / 2


def test_runup_1x_matches_unbalance(tmp_path: Path):
    exe = _tool()
    sig, o1, st, ub = (tmp_path / n for n in ("runup.csv", "1x.csv", "sd.csv", "ub.csv"))
    _run(exe, "transient", MODEL, "--out", ",".join(OUTS), "--rpm", 0, "--rpm-end", 15000,
         "--accel", 250, "--dt", 1e-4, "--rtol", 1e-6, "--atol", "1e-11,1e-8",
         "--signals", "--noise", 2e-8, "-o", sig)
    _run(exe, "order", sig, "--kp", "KP", "--outputs", ",".join(OUTS), "--bin-rpm", 50,
         "--rpm-max", 15000, "--stats", st, "-o", o1)
    _run(exe, "unbalance", MODEL, "--out", ",".join(OUTS), "--rpm-min", 0, "--rpm-max", 15000,
         "--points", 15001, "-o", ub)
    o, u, s = _read(o1), _read(ub), _read(st)
    rpm = o["rpm"]
    away = (rpm > 1000) & ((rpm < 7500) | (rpm > 11000))
    for ch in OUTS:
        q = o[f"{ch} re"] + 1j * o[f"{ch} im"]
        h = u[f"{ch} amp"] * np.exp(1j * np.radians(u[f"{ch} phase_deg"]))
        ref = np.interp(rpm, u["rpm"], h.real) + 1j * np.interp(rpm, u["rpm"], h.imag)
        amp = np.abs(q[away]) / np.abs(ref[away]) - 1
        ph = np.degrees(np.angle(q[away] / ref[away]))
        pk, pk_ref = _peak(rpm, np.abs(q)), u["rpm"][np.argmax(np.abs(h))]
        sd = s[f"{ch} 1X sd"]
        print(f"{ch}: {away.sum()} bins away from the criticals: amplitude within "
              f"{100 * np.abs(amp).max():.3f} %, phase within {np.abs(ph).max():.3f} deg; "
              f"1X peak {pk:.1f} rpm vs {pk_ref:.1f} rpm ({100 * (pk / pk_ref - 1):+.3f} %); "
              f"median sd / |1X| {np.median(sd[away] / np.abs(q[away])):.2e}")
        assert np.abs(amp).max() < 0.01 and np.abs(ph).max() < 1.0
        assert abs(pk / pk_ref - 1) < 0.005
        assert np.all(np.isfinite(sd) & (sd > 0))
