"""Hidden effects found end to end from signals (issue #15).

Truth rotors (tests/python/diag_cases.py): the paper system with a hidden
cross-coupled stiffness at B2, or an added 1.3 kg at disk DB, and a null
truth with nothing hidden. Each is simulated outside librcb (SciPy's exact
first-order-hold discretisation of `rcbtool matrices` of the truth INI at
10000 rpm, 16384 S/s so that the sampling changes the FRF by under 0.2 % up
to 400 Hz): 24 s of white force on DA.x, the displacements of DA, C.A, C.B, DB
in x and y with 2 % sensor noise. `rcbtool estimate` gives the inertances
(H1, 8192-point Hann segments: the 2 Hz lines of diag_cases' 100-400 Hz band),
and `rcbtool diagnose` on the user's model must name the effect and its place
as significant, while the null truth should leave no significant candidate:
it does not yet (strict xfail below), and that is the missing piece.
"""

import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

signal = pytest.importorskip("scipy.signal")

import diag_cases as dc  # noqa: E402

FS, TSIM, NSEG = 16384.0, 24.0, 8192
# the null truth is not silent yet: diagnose takes no per-point sd (only fit
# --sd does), and its unweighted BIC calls the estimation scatter of the
# weakly coherent channels an effect (flexible support at B4, E0 6 %)
NULL_XFAIL = pytest.param(dc.NULL_CASE, marks=pytest.mark.xfail(
    strict=True, reason="diagnose has no --sd: the unweighted BIC names the scatter"))
CASES = [dc.SIM_CASES[0], dc.SIM_CASES[5], NULL_XFAIL]  # cross B2, mass DB, null


def _tool():
    path = os.environ.get("RCBTOOL")
    if not path:
        pytest.skip("RCBTOOL is not set (path to the rcbtool executable)")
    return dc.Rcbtool(path)


def _simulate(tool, ini, seed):
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

    B = np.zeros((2 * n, 1))
    B[n:, 0] = Mi[:, dof(dc.IN)]
    Cm = np.zeros((len(dc.OUTS), 2 * n))
    for i, ch in enumerate(dc.OUTS):
        Cm[i, dof(ch)] = 1.0
    Ad, Bd, Cd, Dd, _ = signal.cont2discrete((A, B, Cm, np.zeros((len(dc.OUTS), 1))), 1 / FS,
                                             method="foh")
    rng = np.random.default_rng(seed)
    N = int(TSIM * FS)
    f = 50.0 * rng.standard_normal(N)
    # x_{k+1} = Ad x_k + Bd f_k: in the eigenbasis of Ad, a first-order recursion
    # per mode (lfilter), exact and fast
    lam, V = np.linalg.eig(Ad)
    b = np.linalg.solve(V, Bd[:, 0])
    z = np.empty((N, 2 * n), complex)
    for k in range(2 * n):
        z[:, k] = signal.lfilter([0.0, b[k]], [1.0, -lam[k]], f)
    y = (z @ (Cd @ V).T).real + np.outer(f, Dd[:, 0])
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
                  "100:400", "--top", 3)
    best = d["candidates"][0]
    print(f"{case.name}: best {best['effect']} at {best['place']}, significant "
          f"{best['significant']}, E0 {d['error0_pct']:.3g} %")
    if case.expect:
        effect, place = case.expect[0]
        assert best["significant"] and best["effect"] == effect and place in best["place"]
    else:
        assert not any(c["significant"] for c in d["candidates"])
