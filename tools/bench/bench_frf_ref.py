#!/usr/bin/env python3
"""Reference timings for the FRF sweep benchmark (tools/bench/bench_frf.c).

Same problem as bench_frf: the model's FRF at 2000 frequencies 0-500 Hz,
outputs C.A.x, C.A.y, C.B.x, C.B.y, inputs DA.x, DA.y, rotor at 10000 rpm.

1. SciPy: the assembled matrices from ``rcbtool matrices --json`` and a plain
   loop of ``scipy.linalg.solve`` (one LU per frequency, both inputs as
   right-hand sides); checked against ``rcbtool frf`` on the same grid.
2. ROSS 2.3 ``run_freq_response`` on the same rotor (built by
   tests/python/ross_models.py). Note: ROSS spins the rotor at the excitation
   frequency (Omega = omega) and returns all DOFs, so it is not the same
   problem; it is timed because it is what a ROSS user would call. A ROSS
   fixed-speed loop (``transfer_matrix(speed, frequency)``, which re-assembles
   the matrices at every call) is timed on a subset and compared with
   librcb's values.

usage: bench_frf_ref.py --rcbtool build/tools/rcbtool/rcbtool MODEL.ini
Run it with OPENBLAS_NUM_THREADS=1 for one-core figures.
"""

import argparse
import json
import math
import os
import resource
import subprocess
import sys
import time

import numpy as np
import scipy.linalg

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "tests", "python"))

OUTS = ["C.A.x", "C.A.y", "C.B.x", "C.B.y"]
INS = ["DA.x", "DA.y"]
DIRS = {"x": 0, "y": 1, "rx": 2, "ry": 3}


def rss_mb():
    """Peak resident memory of this process so far, MB."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def rcbtool_json(exe, *args):
    res = subprocess.run([exe, *map(str, args), "--json"], check=True,
                         capture_output=True, text=True)
    return json.loads(res.stdout)


def our_row(model, nodes, spec):
    """Matrix row of channel 'STATION.DIR' in rcbtool's matrices."""
    station, _, d = spec.rpartition(".")
    shaft, i = model.stations[station]
    z = next(s for s in model.shafts if s.name == shaft).z[i]
    for nd in nodes:
        if nd["shaft"] == shaft and abs(nd["z"] - z) < 1e-9:
            return nd["dof"][DIRS[d]]
    raise KeyError(spec)


def best_of(fn, repeats):
    best = math.inf
    out = None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("model")
    ap.add_argument("--rcbtool", required=True)
    ap.add_argument("--points", type=int, default=2000)
    ap.add_argument("--fmax", type=float, default=500.0, help="Hz")
    ap.add_argument("--rpm", type=float, default=10000.0)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--ross-fixed-points", type=int, default=100,
                    help="frequencies for the ROSS fixed-speed loop (0: skip)")
    ap.add_argument("--no-ross", action="store_true")
    a = ap.parse_args()

    import ross_models

    speed = a.rpm * math.pi / 30.0  # rad/s
    f_hz = np.linspace(0.0, a.fmax, a.points)
    w = 2.0 * math.pi * f_hz

    mats = rcbtool_json(a.rcbtool, "matrices", a.model, "--rpm", a.rpm)
    M, C, G, K = (np.array(mats[k], dtype=float) for k in ("M", "C", "G", "K"))
    n = M.shape[0]
    with open(a.model) as fh:
        model = ross_models.Model(fh.read())
    out_rows = [our_row(model, mats["nodes"], s) for s in OUTS]
    in_rows = [our_row(model, mats["nodes"], s) for s in INS]
    B = np.zeros((n, len(INS)), dtype=complex)
    for j, r in enumerate(in_rows):
        B[r, j] = 1.0
    D = C + speed * G

    def scipy_sweep():
        H = np.empty((a.points, len(OUTS), len(INS)), dtype=complex)
        for i, wi in enumerate(w):
            X = scipy.linalg.solve(K - wi * wi * M + 1j * wi * D, B,
                                   check_finite=False)
            H[i] = X[out_rows, :]
        return H

    print(f"model {a.model}: {n} DOFs; {a.points} frequencies 0-{a.fmax:g} Hz, "
          f"{len(OUTS)} outputs x {len(INS)} inputs, {a.rpm:g} rpm")
    t_scipy, H = best_of(scipy_sweep, a.repeats)
    print(f"SciPy solve loop:        {1e3 * t_scipy:9.1f} ms/sweep "
          f"{1e6 * t_scipy / a.points:9.1f} us/frequency (best of {a.repeats})")

    # The same sweep through rcbtool (process start, parsing and JSON output included).
    t0 = time.perf_counter()
    frf = rcbtool_json(a.rcbtool, "frf", a.model, "--out", ",".join(OUTS),
                       "--in", ",".join(INS), "--fmin", 0, "--fmax", a.fmax,
                       "--points", a.points, "--rpm", a.rpm)
    t_tool = time.perf_counter() - t0
    peak = np.abs(H).max()
    worst = 0.0
    for ch in frf["channels"]:
        h = np.array(ch["re"]) + 1j * np.array(ch["im"])
        ref = H[:, OUTS.index(ch["output"]), INS.index(ch["input"])]
        worst = max(worst, float(np.max(np.abs(h - ref)) / peak))
    print(f"rcbtool frf (whole run): {1e3 * t_tool:9.1f} ms; "
          f"max |H_rcb - H_scipy| / max|H| = {worst:.1e}")

    if a.no_ross:
        return 0
    import warnings

    # Import outside the timings; ROSS's ccp dependency talks about REFPROP on
    # import (from Python and from C), so silence file descriptors 1 and 2.
    sys.stdout.flush()
    sys.stderr.flush()
    saved = [os.dup(1), os.dup(2)]
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, 1)
        os.dup2(devnull, 2)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            import ross  # noqa: F401
        sys.stdout.flush()
        sys.stderr.flush()
    finally:
        os.dup2(saved[0], 1)
        os.dup2(saved[1], 2)
        for fd in (*saved, devnull):
            os.close(fd)
    # ROSS warns that its matrix is singular at 0 Hz (axial/torsional DOFs).
    warnings.simplefilter("ignore", scipy.linalg.LinAlgWarning)

    rm = ross_models.RossModel(model, speed=speed)
    rss0 = rss_mb()
    t0 = time.perf_counter()
    rm.rotor.run_freq_response(speed_range=w)
    t_ross = time.perf_counter() - t0
    print(f"ROSS run_freq_response:  {1e3 * t_ross:9.1f} ms/sweep "
          f"(Omega = omega, all DOFs); peak RSS {rss0:.0f} -> {rss_mb():.0f} MB")

    if a.ross_fixed_points > 0:
        # Not at 0 Hz: ROSS's axial and torsional DOFs make its matrix singular there.
        idx = np.linspace(1, a.points - 1, a.ross_fixed_points).astype(int)
        rows = [rm.station_dof(s) for s in OUTS]
        cols = [rm.station_dof(s) for s in INS]
        t0 = time.perf_counter()
        worst = 0.0
        for i in idx:
            Hr = rm.rotor.transfer_matrix(speed=speed, frequency=w[i])
            worst = max(worst, float(np.max(np.abs(Hr[np.ix_(rows, cols)] - H[i]))) / peak)
        t_fixed = (time.perf_counter() - t0) / len(idx)
        print(f"ROSS transfer_matrix loop (fixed speed): {1e3 * t_fixed:.1f} ms/frequency "
              f"-> {t_fixed * a.points:.1f} s per {a.points}-point sweep "
              f"(timed on {len(idx)}); max |H_ross - H_scipy| / max|H| = {worst:.1e}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
