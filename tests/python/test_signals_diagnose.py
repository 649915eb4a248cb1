"""Hidden effects found end to end from signals (issue #15).

Truth rotors (tests/python/diag_cases.py): the paper system with a hidden
cross-coupled stiffness at B2, or an added 1.3 kg at disk DB, and a null
truth with nothing hidden. Each is simulated outside librcb (SciPy's exact
first-order-hold discretisation of `rcbtool matrices` of the truth INI at
10000 rpm, 16384 S/s so that the sampling changes the FRF by under 0.2 % up
to 400 Hz): 24 s of white force on DA.x, the displacements of DA, C.A, C.B, DB
in x and y with 2 % sensor noise. `rcbtool estimate` gives the inertances
(H1, 8192-point Hann segments: the 2 Hz lines of diag_cases' 100-400 Hz band),
and `rcbtool diagnose --sd` (the estimate's own standard deviations as
weights: the objective is a chi-square) on the user's model must name the
effect and its place as significant, while the null truth must leave no
significant candidate. Without --sd (unit weights on log10 |H|, BIC from
N ln F) the null truth was called "flexible support at bearing B4" (E0 6.13 %):
the estimation scatter of the weakly coherent lines read as an effect.
"""

import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

signal = pytest.importorskip("scipy.signal")

import diag_cases as dc  # noqa: E402

FS, TSIM, NSEG = 2048.0, 60.0, 16384
CASES = [dc.SIM_CASES[0], dc.SIM_CASES[5], dc.NULL_CASE]  # cross B2, mass DB, null


def _tool():
    path = os.environ.get("RCBTOOL")
    if not path:
        pytest.skip("RCBTOOL is not set (path to the rcbtool executable)")
    return dc.Rcbtool(path)


def _simulate(tool, ini, seed, tsim=None):
    mats = tool.json("matrices", ini, "--rpm", dc.RPM)
    check = tool.json("check", ini)
    M, C, G, K = (np.array(mats[k]) for k in ("M", "C", "G", "K"))
    n = M.shape[0]
    Mi = np.linalg.inv(M)
    A = np.block([[np.zeros((n, n)), np.eye(n)],
                  [-Mi @ K, -Mi @ (C + dc.RPM * np.pi / 30.0 * G)]])

    def dof(ch):
        st, d = ch.rsplit(".", 1)
        node = next(s["node"] for s in check["stations"] if s["name"] == st)
        return next(x["dof"] for x in check["nodes"] if x["node"] == node)[["x", "y"].index(d)]

    # the periodic steady state of the continuous system, line by line:
    # Y(w) = H(w) F(w) at every line of the record's FFT, H from the modal
    # expansion of the state matrix (exact at those lines, so the estimate
    # differs from the model's FRF only by its own scatter and leakage; a
    # time-stepping discretisation changes the FRF, FOH at 16384 S/s by
    # -0.03 % at 150 Hz and -0.2 % at 400 Hz, which the chi-square of 60 s
    # of data reads as damping: dBIC -400 on the null truth)
    B = np.zeros(2 * n)
    B[n:] = Mi[:, dof(dc.IN)]
    lam, V = np.linalg.eig(A)
    b = np.linalg.solve(V, B)
    CV = V[[dof(ch) for ch in dc.OUTS], :]  # displacement rows of the state
    rng = np.random.default_rng(seed)
    N = int((tsim or TSIM) * FS)
    f = 50.0 * rng.standard_normal(N)
    F = np.fft.rfft(f)
    jw = 2j * np.pi * np.fft.rfftfreq(N, 1.0 / FS)
    Y = np.zeros((len(F), len(dc.OUTS)), complex)
    for k in range(2 * n):
        Y += np.outer(b[k] * F / (jw - lam[k]), CV[:, k])
    y = np.fft.irfft(Y, n=N, axis=0)
    y += 0.02 * y.std(axis=0) * rng.standard_normal(y.shape)
    return f, y


@pytest.mark.parametrize("case", CASES, ids=["cross_B2", "mass_DB", "null"])
def test_diagnose_from_signals(tmp_path: Path, case):
    tool = _tool()
    truth = tmp_path / "truth.ini"
    truth.write_text(case.truth_ini(dc.BASE_INI))
    f, y = _simulate(tool, truth, seed=11)
    sig = tmp_path / "sig.csv"
    t = np.arange(len(f)) / FS
    np.savetxt(sig, np.column_stack([t, f, y]), delimiter=",", fmt="%.12g", comments="",
               header="# units = N," + ",".join("m" for _ in dc.OUTS) +
               "\ntime_s,force," + ",".join(dc.OUTS))
    meas = tmp_path / "meas.csv"
    tool.run("estimate", sig, "--input", "force=" + dc.IN, "--outputs", ",".join(dc.OUTS),
             "--nseg", NSEG, "--rpm", dc.RPM, "--kind", "inertance", "--fmax", 400,
             "--stats", tmp_path / "stats.csv", "-o", meas)
    model = tmp_path / "model.ini"
    model.write_text(dc.model_ini())
    d = tool.json("diagnose", model, meas, "--params", dc.FIT_PARAMS, "--log", "--band",
                  "100:400", "--top", 3, "--sd", tmp_path / "stats.csv")
    best = d["candidates"][0]
    print(f"{case.name}: best {best['effect']} at {best['place']}, significant "
          f"{best['significant']}, dBIC {best['delta_bic']:.4g}, E0 {d['error0_pct']:.3g} % "
          f"-> {best['error_pct']:.3g} %, floor {d['floor_pct']:.3g} %")
    if case.expect:
        effect, place = case.expect[0]
        assert best["significant"] and best["effect"] == effect and place in best["place"]
    else:
        assert not any(c["significant"] for c in d["candidates"])
