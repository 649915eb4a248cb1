"""H1 from 60 s of simulated random excitation of the paper system.

The signals are simulated outside librcb: the state-space model of the
paper system at 3000 rpm (M, C, G, K from `rcbtool matrices`) is
discretised exactly for a piecewise-linear force by SciPy
(cont2discrete, first-order hold) and driven by 60 s of Gaussian white
force samples at 4096 samples/s on DA.x; sensor noise (5 % of each
response's RMS) is added to the displacements DA.x, DB.x and DA.y.

`rcbtool estimate` (H1, Hann, 4096-point segments, 50 % overlap: 119
averages) must put the model FRF inside the 95 % band its coherence
predicts at >= 90 % of the lines from 5 to 400 Hz. The model FRF is
`rcbtool frf` seen through the sampling: a piecewise-linear force has the
spectrum of its samples times sinc^2(w T / 2), and the sampled response
sums the images, so the reference is sum_k H(w + k ws) sinc^2((w + k ws) T/2)
(k = -3..3), which the raw model FRF is also compared against.
"""

import json
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

signal = pytest.importorskip("scipy.signal")

REPO = Path(__file__).resolve().parents[2]
MODEL = REPO / "examples" / "paper_system.ini"
FS, TSIM, RPM, NSEG = 4096.0, 60.0, 3000.0, 4096
OUTS = ["DA.x", "DB.x", "DA.y"]


def _tool():
    path = os.environ.get("RCBTOOL")
    if not path:
        pytest.skip("RCBTOOL is not set (path to the rcbtool executable)")
    return path


def _json(exe, *args):
    res = subprocess.run([exe, *map(str, args), "--json"], capture_output=True, text=True,
                         timeout=600)
    assert res.returncode == 0, res.stderr
    return json.loads(res.stdout)


def _dof(check, ch):
    st, d = ch.rsplit(".", 1)
    node = next(s["node"] for s in check["stations"] if s["name"] == st)
    return next(n["dof"] for n in check["nodes"] if n["node"] == node)[["x", "y"].index(d)]


def _simulate(exe):
    mats = _json(exe, "matrices", MODEL, "--rpm", RPM)
    check = _json(exe, "check", MODEL)
    M, C, G, K = (np.array(mats[k]) for k in ("M", "C", "G", "K"))
    n = M.shape[0]
    Mi = np.linalg.inv(M)
    omega = RPM * np.pi / 30.0  # `rcbtool matrices` prints G, the matrix Omega multiplies
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-Mi @ K, -Mi @ (C + omega * G)]])
    B = np.zeros((2 * n, 1))
    B[n:, 0] = Mi[:, _dof(check, "DA.x")]
    Cm = np.zeros((len(OUTS), 2 * n))
    for i, ch in enumerate(OUTS):
        Cm[i, _dof(check, ch)] = 1.0
    Ad, Bd, Cd, Dd, _ = signal.cont2discrete((A, B, Cm, np.zeros((len(OUTS), 1))), 1 / FS,
                                             method="foh")
    rng = np.random.default_rng(2026)
    N = int(TSIM * FS)
    f = 50.0 * rng.standard_normal(N)
    x = np.zeros(2 * n)
    y = np.empty((N, len(OUTS)))
    bd = Bd[:, 0]
    for k in range(N):
        y[k] = Cd @ x + Dd[:, 0] * f[k]
        x = Ad @ x + bd * f[k]
    y += 0.05 * y.std(axis=0) * rng.standard_normal(y.shape)
    return f, y


def _read(path):
    rows = [r.split(",") for r in Path(path).read_text().splitlines() if not r.startswith("#")]
    head, body = rows[0], np.array([[float(v) for v in r] for r in rows[1:]])
    return {h: body[:, i] for i, h in enumerate(head)}


def model_through_sampling(exe, fr, outs, fs, rpm, model=MODEL, inp="DA.x"):
    """The model FRFs outs/inp (receptance) at lines fr (Hz) as a sampled record
    sees them when the force is linear between its samples (fs, S/s): images
    k = -3..3 weighted by sinc^2; and the raw model FRFs (k = 0)."""
    ref = {ch: np.zeros(len(fr), complex) for ch in outs}
    raw = {}
    # rcbtool frf takes an even grid: sweep each image's lines exactly
    for k in range(-3, 4):
        fq = fr + k * fs
        lo, hi = np.abs(fq).min(), np.abs(fq).max()
        d = _json(exe, "frf", model, "--out", ",".join(outs), "--in", inp, "--rpm", rpm,
                  "--fmin", lo, "--fmax", hi, "--points", len(fr))
        for c in d["channels"]:
            hh = np.array(c["re"]) + 1j * np.array(c["im"])
            if k < 0:  # H(-w) = conj(H(w)): the grid runs backwards
                hh = np.conj(hh[::-1])
            ref[c["output"]] += hh * np.sinc(fq / fs) ** 2
            if k == 0:
                raw[c["output"]] = hh
    return ref, raw


def test_h1_paper_system_60s(tmp_path: Path):
    exe = _tool()
    f, y = _simulate(exe)
    sig = tmp_path / "random.csv"
    t = np.arange(len(f)) / FS
    np.savetxt(sig, np.column_stack([t, f, y]), delimiter=",", fmt="%.17g", comments="",
               header="# units = N,m,m,m\ntime_s,force," + ",".join(OUTS))
    out, stats = tmp_path / "h1.csv", tmp_path / "stats.csv"
    res = subprocess.run([exe, "estimate", sig, "--input", "force=DA.x", "--outputs",
                          ",".join(OUTS), "--nseg", str(NSEG), "--rpm", str(RPM), "--fmax", "400",
                          "--stats", stats, "-o", out], capture_output=True, text=True,
                         timeout=600)
    assert res.returncode == 0, res.stderr
    h, s = _read(out), _read(stats)
    fr = h["freq_hz"]
    band = fr >= 5.0
    ref, raw = model_through_sampling(exe, fr, OUTS, FS, RPM)
    for ch in OUTS:
        est = h[f"{ch}/DA.x re"] + 1j * h[f"{ch}/DA.x im"]
        sd = s[f"{ch}/DA.x sd"]
        r95 = np.sqrt(-2 * np.log(0.05)) * sd
        inside = np.mean(np.abs(est - ref[ch])[band] <= r95[band])
        inside_raw = np.mean(np.abs(est - raw[ch])[band] <= r95[band])
        coh = s[f"{ch}/DA.x coh"][band]
        print(f"{ch}: inside the 95 % band at {100 * inside:.1f} % of {band.sum()} lines "
              f"(raw model FRF {100 * inside_raw:.1f} %), coherence median {np.median(coh):.3f}")
        assert inside >= 0.90, f"{ch}: {inside:.3f}"
