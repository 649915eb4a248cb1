"""Draws the case study's picture (docs/img/case_study.png): the measured H1 of the
ARTS-Lab cantilever (every line, grey; the lines kept at coherence >= 0.99, with
+-2 sd bars from `rcbtool estimate --stats`), the model before and after the fit
(`rcbtool frf` of each), and the coherence below.

usage: python3 plot_case_study.py H1.csv STATS.csv H1_KEPT.csv STATS_KEPT.csv
                                  MODEL_FRF.csv FITTED_FRF.csv OUT.png
(NumPy, matplotlib). The CSVs are as rcbtool writes them.
"""
import sys

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def _read(path):
    rows = [s for s in open(path, encoding="utf-8").read().splitlines() if s and not s.startswith("#")]
    return np.array([[float(v) for v in r.split(",")] for r in rows[1:]])


h1, st, hk, sk, mod, fit, out = sys.argv[1:8]
H, S, HK, SK, M0, M1 = (_read(p) for p in (h1, st, hk, sk, mod, fit))
fig, (ax, axc) = plt.subplots(2, 1, figsize=(8, 6), sharex=True,
                              gridspec_kw={"height_ratios": [3, 1]})
ax.semilogy(H[:, 0], np.hypot(H[:, 1], H[:, 2]), color="0.75", lw=0.8,
            label="H1, every line (19 averages)")
mag = np.hypot(HK[:, 1], HK[:, 2])
ax.errorbar(HK[:, 0], mag, yerr=2 * SK[:, 2], fmt="o", ms=4, color="C0",
            label="lines with coherence >= 0.99, +-2 sd")
ax.semilogy(M0[:, 0], np.hypot(M0[:, 1], M0[:, 2]), "C3--", lw=1, label="model as built")
ax.semilogy(M1[:, 0], np.hypot(M1[:, 1], M1[:, 2]), "C2-", lw=1, label="model fitted")
ax.set_ylabel("|ACC.x / DRV.x|, m/(N s^2)")
ax.set_ylim(1e-3, 1e2)
ax.legend(fontsize=8, loc="upper left")
ax.set_title("ARTS-Lab cantilever, shaker test 1 (100 + 120 + 150 Hz sines)")
axc.plot(S[:, 0], S[:, 1], color="0.4", lw=0.8)
axc.plot(SK[:, 0], SK[:, 1], "o", ms=3, color="C0")
axc.set_ylabel("coherence")
axc.set_xlabel("frequency, Hz")
axc.set_ylim(0, 1.05)
fig.tight_layout()
fig.savefig(out, dpi=110)
print(f"wrote {out}")
