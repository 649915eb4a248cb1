"""Estimator throughput: librcb (bench_signals) against SciPy in one run.

The same job on the same sizes: 1 force + 3 responses, 60 s at 51200 S/s,
4096-point Hann segments, 50 % overlap, and what H1, coherence and the sd
need: Gxx, the three Gxy and the three Gyy (SciPy: welch(x), csd(x, y_i),
welch(y_i), the calls scipy.signal.coherence makes). Prints samples per
second (all four channels) for both and the ratio.

    python tools/bench/bench_signals.py build/tools/bench/bench_signals [seconds]
"""

import re
import subprocess
import sys
import time

import numpy as np
import scipy
from scipy import signal


def main():
    exe = sys.argv[1]
    secs = float(sys.argv[2]) if len(sys.argv) > 2 else 60.0
    fs = 51200.0
    n = int(secs * fs)
    rng = np.random.default_rng(1)
    x = rng.standard_normal((4, n))
    x[1:] += 0.5 * x[0]
    kw = dict(fs=fs, window="hann", nperseg=4096, noverlap=2048)
    best = np.inf
    for _ in range(3):
        t0 = time.perf_counter()
        _, pxx = signal.welch(x[0], **kw)
        for i in range(1, 4):
            _, pxy = signal.csd(x[0], x[i], **kw)
            _, pyy = signal.welch(x[i], **kw)
            _h1, _coh = pxy / pxx, np.abs(pxy) ** 2 / (pxx * pyy)
        best = min(best, time.perf_counter() - t0)
    scipy_rate = 4 * n / best
    out = subprocess.run([exe, str(secs)], capture_output=True, text=True, check=True).stdout
    print(out, end="")
    rcb_rate = float(re.search(r"s, ([0-9.e+]+) samples/s \(all 4", out).group(1))
    print(f"SciPy {scipy.__version__} welch/csd: {best:.3f} s (best of 3), "
          f"{scipy_rate:.3g} samples/s (all 4 channels)")
    print(f"librcb / SciPy throughput: {rcb_rate / scipy_rate:.1f}x (goal: 5x)")


if __name__ == "__main__":
    main()
