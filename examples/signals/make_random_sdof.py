"""Writes random_sdof.csv: 2 s of random force (N) on a single-degree-of-freedom
system (100 Hz, 5 % damping, 1 kg) and its displacement in um, sampled at
2048 S/s, with 1 % sensor noise. The response comes from SciPy (the exact
zero-order-hold discretisation of m x'' + c x' + k x = f), not from librcb, so
`rcbtool estimate` on it can be checked against the closed form
H(f) = 1 / (k - m w^2 + i c w). Run: python3 make_random_sdof.py (NumPy, SciPy).
"""
import numpy as np
from scipy import signal

fs, T = 2048.0, 2.0
m, fn, zeta = 1.0, 100.0, 0.05
wn = 2 * np.pi * fn
k, c = m * wn**2, 2 * zeta * m * wn
rng = np.random.default_rng(7)
f = 10.0 * rng.standard_normal(int(fs * T))
A, B = np.array([[0, 1], [-k / m, -c / m]]), np.array([[0], [1 / m]])
sysd = signal.cont2discrete((A, B, np.array([[1.0, 0.0]]), np.array([[0.0]])),
                            1 / fs, method="zoh")
_, x, _ = signal.dlsim(sysd, f)
x = x[:, 0]
x += 0.01 * np.std(x) * rng.standard_normal(x.size)
t = np.arange(f.size) / fs
np.savetxt("random_sdof.csv", np.column_stack([t, f, x * 1e6]), delimiter=",", fmt=["%.9g", "%.5e", "%.5e"],
           comments="", header="# units = N,um\ntime_s,force,DA.x")
