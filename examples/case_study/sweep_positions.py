"""Is the case study's misfit (docs/case_study.md) a matter of where the accelerometer
and the shaker sit? An Euler-Bernoulli cantilever in NumPy, independent of librcb:
the flat bar 759 x 50.66 x 5.14 mm (steel, E scaled by a fitted factor), clamped at
z = 0, 30 elements, structural damping (a fitted loss factor), a fitted point mass and
a fitted rotational spring (a bracket that holds the slope) at the drive. For the
accelerometer at every second node and the drive at every second node from 0.30 m to
the tip, the four parameters are fitted (scipy.optimize.least_squares, 3 starts) to the
centre line of each run of kept lines, on ln|H_model / H_meas| and half its phase.

usage: python3 sweep_positions.py KEPT_H1.csv   (NumPy, SciPy; about 1 min)
Prints the best placements: the RMS residual and the fitted values.
"""
import sys

import numpy as np
from scipy.optimize import least_squares

L, B, HH, E0, RHO, NE = 0.759, 0.05066, 0.00514, 200e9, 7850.0, 30
A, I, LE = B * HH, B * HH**3 / 12, L / NE


def matrices(escale):
    k = E0 * escale * I / LE**3 * np.array([[12, 6 * LE, -12, 6 * LE],
                                            [6 * LE, 4 * LE**2, -6 * LE, 2 * LE**2],
                                            [-12, -6 * LE, 12, -6 * LE],
                                            [6 * LE, 2 * LE**2, -6 * LE, 4 * LE**2]])
    m = RHO * A * LE / 420 * np.array([[156, 22 * LE, 54, -13 * LE],
                                       [22 * LE, 4 * LE**2, 13 * LE, -3 * LE**2],
                                       [54, 13 * LE, 156, -22 * LE],
                                       [-13 * LE, -3 * LE**2, -22 * LE, 4 * LE**2]])
    n = 2 * (NE + 1)
    K, M = np.zeros((n, n)), np.zeros((n, n))
    for e in range(NE):
        s = slice(2 * e, 2 * e + 4)
        K[s, s] += k
        M[s, s] += m
    return K, M


def inertance(p, ia, idr, freqs):
    escale, mass, eta, krot = p
    K, M = matrices(escale)
    M[2 * idr, 2 * idr] += mass
    K[2 * idr + 1, 2 * idr + 1] += krot
    K, M = (K * (1 + 1j * eta))[2:, 2:], M[2:, 2:]      # clamp: node 0 fixed
    e = np.zeros(len(K))
    e[2 * idr - 2] = 1.0
    return np.array([-(2 * np.pi * f) ** 2 * np.linalg.solve(K - (2 * np.pi * f) ** 2 * M, e)[2 * ia - 2]
                     for f in freqs])


rows = [s for s in open(sys.argv[1], encoding="utf-8").read().splitlines()
        if s and not s.startswith("#")][1:]
h = np.array([[float(v) for v in r.split(",")] for r in rows])
centre = [i for i in range(len(h)) if abs(h[i, 0] - round(h[i, 0] / 10) * 10) < 0.01]
freqs, meas = h[centre, 0], h[centre, 1] + 1j * h[centre, 2]
lo, hi = np.log([0.5, 1e-3, 1e-4, 1e-3]), np.log([2.0, 3.0, 0.5, 1e6])


def residual(q, ia, idr):
    r = inertance(np.exp(q), ia, idr, freqs) / meas
    return np.concatenate([np.log(np.abs(r)), 0.5 * np.angle(r)])


out = []
for ia in range(3, NE, 2):
    for idr in range(12, NE + 1, 2):
        best = None
        for q0 in (np.log([1, 0.1, 0.02, 1.0]), np.log([1, 0.5, 0.02, 100.0]), np.log([1, 0.05, 0.02, 1e4])):
            s = least_squares(residual, q0, args=(ia, idr), bounds=(lo, hi))
            if best is None or s.cost < best.cost:
                best = s
        out.append((np.sqrt(2 * best.cost / best.fun.size), ia, idr, np.exp(best.x)))
out.sort(key=lambda t: t[0])
print(f"{len(out)} placements, {len(freqs)} lines ({', '.join(f'{f:g}' for f in freqs)} Hz)")
print("rms    acc_z_m  drive_z_m  E/E_steel  mass_kg  loss_factor  k_rot_Nm/rad")
for rms, ia, idr, p in out[:5]:
    print(f"{rms:.3f}  {ia * LE:7.3f}  {idr * LE:9.3f}  {p[0]:9.3f}  {p[1]:7.3f}  {p[2]:11.3f}  {p[3]:.3g}")
