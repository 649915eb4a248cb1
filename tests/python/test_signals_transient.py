"""FRFs from a simulated test: `rcbtool transient --signals --force` (issue #15).

`rcbtool transient` integrates the paper system at 3000 rpm (SUNDIALS CVODE,
with its unbalance running) under an external force at DA.x and writes the
force beside the displacements DA.x, DB.x, DA.y (Gaussian sensor noise
2e-6 m RMS); `rcbtool estimate` makes H1 with coherence and per-line
standard deviations, and the model FRF must lie inside the 95 % band the
coherence predicts at >= 90 % of the lines (the band from the F distribution
of nd averages, see _coverage).

* random: band-limited white force (50 N RMS samples every 1/2048 s, linear
  between them), 16 s (not the 60 s of the issue's done-when figure: the
  integrator stops at every kink of the force, about 4 s of CPU per second
  of signal at --rtol 1e-4, so 60 s would take 4 min; the 60 s figure from
  SciPy-simulated signals is test_signals_paper.py), 2048-point Hann
  segments (1 Hz lines, 31 averages), 5-400 Hz. The reference is `rcbtool
  frf` seen through the sampling: a force linear between its samples has
  the spectrum of its samples times sinc^2(w T / 2), and the sampled
  response sums the images (model_through_sampling).
* impact: at standstill (hits one per second at 3000 rpm start at the same
  shaft angle, so the 1X response is coherent with them: 40x off at 50 Hz),
  8 half-sine hammer pulses (500 N, 3 ms), one per 1 s block, force and
  exponential window (force-exp, no overlap: 8 averages), 5-300 Hz. The
  exponential window exp(-t/tau) on every channel turns the estimate into
  the FRF at s = i w + 1/tau (added damping 1/tau), so the reference is the
  model's H(s) = [K + s (C + Omega G) + s^2 M]^-1 from `rcbtool matrices`
  at those s, through the sampling as above.
"""

import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

from test_signals_paper import MODEL, _json, _read, model_through_sampling

fdist = pytest.importorskip("scipy.stats").f

FS, RPM = 2048.0, 3000.0
RPM_IMPACT = 0.0  # a standstill test: hits in step with the 1X would correlate with it
OUTS = ["DA.x", "DB.x", "DA.y"]
# random: loose tolerances (4 s of CPU per second of signal); impact: tight,
# as BDF's numerical damping at --rtol 1e-4 moved the 150 Hz peak by 0.75 %
# (20 sd at a coherence of 1.00000); 3e-4 % at --rtol 1e-6
TOL_RANDOM = ["--rtol", "1e-4", "--atol", "1e-10,1e-7"]
TOL_IMPACT = ["--rtol", "1e-6"]


def _tool():
    path = os.environ.get("RCBTOOL")
    if not path:
        pytest.skip("RCBTOOL is not set (path to the rcbtool executable)")
    return path


def _run(exe, *args):
    res = subprocess.run([exe, *map(str, args)], capture_output=True, text=True, timeout=1200)
    assert res.returncode == 0, res.stderr
    return res


def _simulate(exe, tmp, t_end, tol, *force, rpm=RPM):
    sig = tmp / "signals.csv"
    _run(exe, "transient", MODEL, "--out", ",".join(OUTS), "--rpm", rpm, "--t-end", t_end,
         "--dt", 1.0 / FS, *tol, "--signals", "--noise", 2e-6, "--seed", 3, "--force-at",
         "DA.x", *force, "-o", sig)
    head = [ln for ln in sig.read_text().splitlines()[:3]]
    assert head[1] == "# units = V,N,m,m,m" and head[2] == "time_s,KP,force," + ",".join(OUTS)
    return sig


def _estimate(exe, tmp, sig, *opts, rpm=RPM):
    out, stats = tmp / "h1.csv", tmp / "stats.csv"
    _run(exe, "estimate", sig, "--input", "force=DA.x", "--outputs", ",".join(OUTS), "--rpm",
         rpm, "--fmax", 400, "--kind", "receptance", "--stats", stats, "-o", out, *opts)
    return _read(out), _read(stats)


def _nd(segments, nseg, overlap):
    """Independent averages of Hann segments overlapping by `overlap` samples
    (the estimate's own correction, Bendat & Piersol eq. 11.107); the
    force-exp segments do not overlap here: nd = segments."""
    if overlap == 0:
        return float(segments)
    w = 0.5 - 0.5 * np.cos(2 * np.pi * np.arange(nseg) / nseg)
    step, ovl = nseg - overlap, 1.0
    for lag in range(step, nseg, step):
        ovl += 2 * (np.dot(w[:-lag], w[lag:]) / np.dot(w, w)) ** 2
    return segments / ovl


def _coverage(h, s, ref, band, nd):
    """Share of lines where the reference lies inside the 95 % band: with
    the per-component sd estimated from the coherence of nd averages (the
    residual power over nd - 1), |dH|^2 / (2 sd^2) is distributed as
    F(2, 2 (nd - 1)) (Goodman; the normal-theory radius sqrt(-2 ln 0.05) sd =
    2.45 sd holds for large nd only: 2.73 sd at nd = 8, 2.51 sd at nd = 29)."""
    worst = 1.0
    k95 = np.sqrt(2 * fdist.ppf(0.95, 2, 2 * (nd - 1)))
    for ch in OUTS:
        est = h[f"{ch}/DA.x re"] + 1j * h[f"{ch}/DA.x im"]
        r95 = k95 * s[f"{ch}/DA.x sd"]
        inside = np.mean(np.abs(est - ref[ch])[band] <= r95[band])
        print(f"{ch}: inside the 95 % band at {100 * inside:.1f} % of {band.sum()} lines, "
              f"coherence median {np.median(s[f'{ch}/DA.x coh'][band]):.3f}")
        worst = min(worst, inside)
    return worst


def test_random_force_h1(tmp_path: Path):
    exe = _tool()
    sig = _simulate(exe, tmp_path, 16.0, TOL_RANDOM, "--force", "random", "--force-amp", 50)
    h, s = _estimate(exe, tmp_path, sig, "--nseg", 2048)
    fr = h["freq_hz"]
    nd = _nd(31, 2048, 1024)  # 16 s, 2048-point segments, 50 % overlap
    ref, raw = model_through_sampling(exe, fr, OUTS, FS, RPM)
    worst = _coverage(h, s, ref, fr >= 5.0, nd)
    assert worst >= 0.90
    # the test can fail: the model without the sampling's images is outside
    # the band near 400 Hz (sinc^2 = 0.88 there) on DA.x
    assert _coverage(h, s, raw, fr >= 300.0, nd) < 0.5


def _h_of_s(exe, fr, sigma, rpm):
    """Model receptances OUTS/DA.x at s = i w + sigma through the sampling."""
    mats = _json(exe, "matrices", MODEL, "--rpm", rpm)
    check = _json(exe, "check", MODEL)
    M, C, G, K = (np.array(mats[k]) for k in ("M", "C", "G", "K"))
    D = C + rpm * np.pi / 30.0 * G

    def dof(ch):
        st, d = ch.rsplit(".", 1)
        node = next(x["node"] for x in check["stations"] if x["name"] == st)
        return next(n["dof"] for n in check["nodes"] if n["node"] == node)[["x", "y"].index(d)]

    e = np.zeros(M.shape[0])
    e[dof("DA.x")] = 1.0
    rows = [dof(ch) for ch in OUTS]
    ref = np.zeros((len(OUTS), len(fr)), complex)
    for i, f in enumerate(fr):
        for k in range(-3, 4):
            fq = f + k * FS
            sv = 2j * np.pi * fq + sigma
            ref[:, i] += np.linalg.solve(K + sv * D + sv * sv * M, e)[rows] * np.sinc(fq / FS) ** 2
    return {ch: ref[o] for o, ch in enumerate(OUTS)}


def test_impact_h1(tmp_path: Path):
    exe = _tool()
    hits, block = 8, 2048  # 1 s blocks
    sig = _simulate(exe, tmp_path, hits * block / FS - 1.0 / FS, TOL_IMPACT, "--force",
                    "impact", "--hits", hits, "--pulse", 0.003, "--force-amp", 500,
                    rpm=RPM_IMPACT)
    exp_end = 0.01
    # --no-detrend: a segment's mean is part of an impact response (removing
    # it moved the lines below 20 Hz by 1-4 %)
    h, s = _estimate(exe, tmp_path, sig, "--nseg", block, "--overlap", 0, "--window",
                     "force-exp", "--exp-end", exp_end, "--no-detrend", rpm=RPM_IMPACT)
    fr = h["freq_hz"]
    band = (fr >= 5.0) & (fr <= 300.0)
    tau = (block - 1) / FS / -np.log(exp_end)  # the window ends at exp_end
    ref = _h_of_s(exe, fr, 1.0 / tau, RPM_IMPACT)
    assert _coverage(h, s, ref, band, float(hits)) >= 0.90
    # the test can fail: without the window's added damping 1/tau the model
    # leaves the band around the resonances
    assert _coverage(h, s, _h_of_s(exe, fr, 0.0, RPM_IMPACT), band, float(hits)) < 0.90
