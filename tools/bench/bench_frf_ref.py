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

The pieces are functions (PaperSweep, import_ross_quietly, ross_fixed_loop,
ross_freq_response) that tools/bench/suite.py reuses.

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


def frf_channels(doc):
    """(points, outputs, inputs) complex array from ``rcbtool frf --json``."""
    H = np.empty((len(doc["freq_hz"]), len(OUTS), len(INS)), dtype=complex)
    for ch in doc["channels"]:
        H[:, OUTS.index(ch["output"]), INS.index(ch["input"])] = (
            np.array(ch["re"]) + 1j * np.array(ch["im"]))
    return H


def rel_dev(H, ref):
    """max |H - ref| / max |ref| over all entries."""
    return float(np.max(np.abs(H - ref)) / np.max(np.abs(ref)))


class PaperSweep:
    """The benchmark problem on rcbtool's assembled matrices (M, C, G, K)."""

    def __init__(self, exe, path, points=2000, fmax=500.0, rpm=10000.0):
        import ross_models

        self.exe, self.path, self.points, self.fmax, self.rpm = exe, path, points, fmax, rpm
        self.speed = rpm * math.pi / 30.0  # rad/s
        self.f_hz = np.linspace(0.0, fmax, points)
        self.w = 2.0 * math.pi * self.f_hz  # rad/s
        mats = rcbtool_json(exe, "matrices", path, "--rpm", rpm)
        self.M, C, G, self.K = (np.array(mats[k], dtype=float) for k in ("M", "C", "G", "K"))
        self.n = self.M.shape[0]
        with open(path) as fh:
            self.model = ross_models.Model(fh.read())
        self.out_rows = [our_row(self.model, mats["nodes"], s) for s in OUTS]
        in_rows = [our_row(self.model, mats["nodes"], s) for s in INS]
        self.B = np.zeros((self.n, len(INS)), dtype=complex)
        for j, r in enumerate(in_rows):
            self.B[r, j] = 1.0
        self.D = C + self.speed * G

    def scipy_sweep(self):
        """(points, outputs, inputs): one scipy.linalg.solve per frequency."""
        H = np.empty((self.points, len(OUTS), len(INS)), dtype=complex)
        for i, wi in enumerate(self.w):
            X = scipy.linalg.solve(self.K - wi * wi * self.M + 1j * wi * self.D, self.B,
                                   check_finite=False)
            H[i] = X[self.out_rows, :]
        return H

    def rcbtool_frf(self, *extra):
        """``rcbtool frf --json`` on the same grid: (seconds of the whole run, H)."""
        t0 = time.perf_counter()
        doc = rcbtool_json(self.exe, "frf", self.path, "--out", ",".join(OUTS),
                           "--in", ",".join(INS), "--fmin", 0, "--fmax", self.fmax,
                           "--points", self.points, *extra)
        return time.perf_counter() - t0, frf_channels(doc)


def import_ross_quietly():
    """Import ROSS outside any timing; its ccp dependency talks about REFPROP
    on import (from Python and from C), so file descriptors 1 and 2 are
    silenced meanwhile. Also silences LinAlgWarning (ROSS's matrix is singular
    at 0 Hz through its axial and torsional DOFs)."""
    import warnings

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
    warnings.simplefilter("ignore", scipy.linalg.LinAlgWarning)


def ross_rotor(model, speed):
    """The model as a ROSS rotor (tests/python/ross_models.py), speed rad/s."""
    import ross_models

    return ross_models.RossModel(model, speed=speed)


def ross_fixed_loop(rm, speed, w):
    """ROSS ``transfer_matrix(speed, frequency)`` at each w (rad/s): seconds per
    frequency and H (len(w), outputs, inputs)."""
    rows = [rm.station_dof(s) for s in OUTS]
    cols = [rm.station_dof(s) for s in INS]
    H = np.empty((len(w), len(OUTS), len(INS)), dtype=complex)
    t0 = time.perf_counter()
    for i, wi in enumerate(w):
        H[i] = rm.rotor.transfer_matrix(speed=speed, frequency=wi)[np.ix_(rows, cols)]
    return (time.perf_counter() - t0) / len(w), H


def ross_freq_response(rm, w):
    """ROSS ``run_freq_response`` (Omega = omega, all DOFs; run once: ROSS caches
    it): seconds, H (len(w), outputs, inputs), peak RSS before and after, MB."""
    rows = [rm.station_dof(s) for s in OUTS]
    cols = [rm.station_dof(s) for s in INS]
    rss0 = rss_mb()
    t0 = time.perf_counter()
    res = rm.rotor.run_freq_response(speed_range=w)
    secs = time.perf_counter() - t0
    H = np.transpose(res.freq_resp[np.ix_(rows, cols)], (2, 0, 1))
    return secs, H, rss0, rss_mb()


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

    p = PaperSweep(a.rcbtool, a.model, a.points, a.fmax, a.rpm)
    print(f"model {a.model}: {p.n} DOFs; {a.points} frequencies 0-{a.fmax:g} Hz, "
          f"{len(OUTS)} outputs x {len(INS)} inputs, {a.rpm:g} rpm")
    t_scipy, H = best_of(p.scipy_sweep, a.repeats)
    print(f"SciPy solve loop:        {1e3 * t_scipy:9.1f} ms/sweep "
          f"{1e6 * t_scipy / a.points:9.1f} us/frequency (best of {a.repeats})")

    # The same sweep through rcbtool (process start, parsing and JSON output included).
    t_tool, Hr = p.rcbtool_frf("--rpm", a.rpm)
    print(f"rcbtool frf (whole run): {1e3 * t_tool:9.1f} ms; "
          f"max |H_rcb - H_scipy| / max|H| = {rel_dev(Hr, H):.1e}")

    if a.no_ross:
        return 0
    import_ross_quietly()
    rm = ross_rotor(p.model, p.speed)
    t_ross, _, rss0, rss1 = ross_freq_response(rm, p.w)
    print(f"ROSS run_freq_response:  {1e3 * t_ross:9.1f} ms/sweep "
          f"(Omega = omega, all DOFs); peak RSS {rss0:.0f} -> {rss1:.0f} MB")

    if a.ross_fixed_points > 0:
        # Not at 0 Hz: ROSS's axial and torsional DOFs make its matrix singular there.
        idx = np.linspace(1, a.points - 1, a.ross_fixed_points).astype(int)
        t_fixed, Hf = ross_fixed_loop(rm, p.speed, p.w[idx])
        worst = float(np.max(np.abs(Hf - H[idx]))) / np.max(np.abs(H))
        print(f"ROSS transfer_matrix loop (fixed speed): {1e3 * t_fixed:.1f} ms/frequency "
              f"-> {t_fixed * a.points:.1f} s per {a.points}-point sweep "
              f"(timed on {len(idx)}); max |H_ross - H_scipy| / max|H| = {worst:.1e}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
