"""Text input speed (issue #25): the whole `rcbtool estimate` from a CSV,
against SciPy + np.loadtxt on the same file, and against the same samples
from a WAV file.

The record: 60 s, 8 channels (a force and 7 responses) at 2048 S/s, a time
column, written by np.savetxt with its default '%.18e' (28 MB) and with
'%.6g' (the time column '%.10g', so that it stays evenly spaced; 12 MB);
the WAV holds the same doubles as 64-bit floats. Each program does the same
job: H1 of the 7 responses to the force, with coherence, 4096-point Hann
segments, 50 % overlap (rcbtool's defaults; SciPy: welch(x), csd(x, y),
welch(y) per response, as scipy.signal.coherence calls them). Times are the
best of --repeat runs of the whole process (rcbtool) or of load + estimate
(SciPy), as wall clock and as CPU time (user + sys: on a shared machine the
steadier figure; the ratios use it); the rcbtool runs are interleaved. Also checks that the '%.18e' CSV and the WAV give the
same output bytes (the CSV numbers read back exactly).

    python tools/bench/bench_csv.py build/tools/rcbtool [--repeat 5]
"""

import argparse
import os
import resource
import subprocess
import tempfile
import time

import numpy as np
import scipy
from scipy import signal
from scipy.io import wavfile

FS = 2048.0
NAMES = ["force", "DA.x", "DA.y", "DB.x", "DB.y", "DC.x", "DC.y", "DD.x"]
UNITS = ["N"] + ["um"] * 7


def make_record(seconds):
    n = int(seconds * FS)
    rng = np.random.default_rng(25)
    f = 10.0 * rng.standard_normal(n)
    ys = []
    for _ in range(7):
        h = rng.standard_normal(32) * np.exp(-np.arange(32) / 8.0)
        ys.append(1e-3 * np.convolve(f, h, "same") + 1e-4 * rng.standard_normal(n))
    return np.arange(n) / FS, np.column_stack([f] + ys)


def write_files(d, t, x):
    header = "# units = " + ",".join(UNITS) + "\ntime_s," + ",".join(NAMES)
    data = np.column_stack([t, x])
    paths = {"csv %.18e": os.path.join(d, "e18.csv"), "csv %.6g": os.path.join(d, "g6.csv"),
             "wav float64": os.path.join(d, "sig.wav")}
    np.savetxt(paths["csv %.18e"], data, delimiter=",", header=header, comments="")
    np.savetxt(paths["csv %.6g"], data, delimiter=",", header=header, comments="",
               fmt=["%.10g"] + ["%.6g"] * 8)
    wavfile.write(paths["wav float64"], int(FS), x)
    return paths


def rcbtool_run(exe, path, out):
    cmd = [exe, "estimate", path, "--input", "force=DA.x", "--outputs", ",".join(NAMES[1:]),
           "-o", out]
    if path.endswith(".wav"):
        cmd += ["--wav-names", ",".join(NAMES), "--wav-units", ",".join(UNITS),
                "--wav-scale", ",".join(["1"] * 8)]
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True, capture_output=True)
    t1 = time.perf_counter()
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    return t1 - t0, (r1.ru_utime + r1.ru_stime) - (r0.ru_utime + r0.ru_stime)


def scipy_run(path):
    c0 = time.process_time()
    t0 = time.perf_counter()
    data = np.loadtxt(path, delimiter=",", skiprows=2)
    x = data[:, 1]
    kw = dict(fs=FS, window="hann", nperseg=4096, noverlap=2048)
    _, pxx = signal.welch(x, **kw)
    for i in range(2, data.shape[1]):
        _, pxy = signal.csd(x, data[:, i], **kw)
        _, pyy = signal.welch(data[:, i], **kw)
        _h1, _coh = pxy / pxx, np.abs(pxy) ** 2 / (pxx * pyy)
    return time.perf_counter() - t0, time.process_time() - c0


def best(runs):
    """(best wall time, best CPU time) over runs of (wall, cpu)."""
    runs = list(runs)
    return min(r[0] for r in runs), min(r[1] for r in runs)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("rcbtool")
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--seconds", type=float, default=60.0)
    a = ap.parse_args()
    with tempfile.TemporaryDirectory() as d:
        paths = write_files(d, *make_record(a.seconds))
        outs = {label: os.path.join(d, "out_" + os.path.basename(p) + ".csv")
                for label, p in paths.items()}
        runs = {label: [] for label in paths}
        for _ in range(a.repeat):  # interleaved, so that the machine's load falls on all
            for label, p in paths.items():
                runs[label].append(rcbtool_run(a.rcbtool, p, outs[label]))
        rcb = {label: best(r) for label, r in runs.items()}
        sp = {label: best(scipy_run(p) for _ in range(max(1, a.repeat // 2)))
              for label, p in paths.items() if label.startswith("csv")}
        same = open(outs["csv %.18e"], "rb").read() == open(outs["wav float64"], "rb").read()
        print(f"record: {a.seconds:g} s, 8 channels at {FS:g} S/s; best of {a.repeat} "
              f"(SciPy: of {max(1, a.repeat // 2)}); SciPy {scipy.__version__}, "
              f"NumPy {np.__version__}")
        print("wall s / CPU s (user + sys) of the whole run; ratios of CPU time")
        for label, p in paths.items():
            mb = os.path.getsize(p) / 1e6
            w, c = rcb[label]
            line = f"{label:12s} {mb:5.1f} MB  rcbtool estimate {w:.3f} / {c:.3f} s"
            if label in sp:
                line += (f"  SciPy+loadtxt {sp[label][0]:.3f} / {sp[label][1]:.3f} s  "
                         f"({sp[label][1] / c:.1f}x faster, goal 3x)  "
                         f"{c / rcb['wav float64'][1]:.2f}x the WAV run (goal <= 2)")
            print(line)
        print(f"'%.18e' CSV and WAV give the same output bytes: {same}")
        if not same:
            raise SystemExit(1)


if __name__ == "__main__":
    main()
