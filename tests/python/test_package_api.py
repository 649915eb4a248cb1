"""librcb Python package: the API against independent computations (numpy on
the library's own matrices, the analytic structure of the equations) and
known answers (hidden values of synthetic measurements)."""

import math

import numpy as np
import pytest

from pkg_helpers import PAPER, WALK, paper, rcb  # noqa: F401  (fixtures)

RPM = math.pi / 30


def test_model_structure(rcb, paper):
    assert paper.dofs == 88 and paper.n_nodes == 22
    names = [s.name for s in paper.stations]
    assert {"DA", "DB", "B1", "B2", "C.A", "C.B"} <= set(names)
    da = next(s for s in paper.stations if s.name == "DA")
    assert da.kind == "disk" and da.z == pytest.approx(0.2)
    nodes = paper.nodes
    assert nodes[da.node].z == pytest.approx(da.z)
    rows = [r for n in nodes for r in n.dofs if r >= 0]
    assert sorted(set(rows)) == list(range(paper.dofs))  # every matrix row owned by a node
    assert "coupling.C.kt" in paper.params
    assert paper.get("coupling.C.kt") == pytest.approx(46.095e3)


def test_load_error_names_file_and_line(rcb, tmp_path):
    bad = tmp_path / "bad.ini"
    bad.write_text(PAPER.read_text().replace("kt = 46.095e3", "kt = fourty"))
    line = 1 + PAPER.read_text().split("kt = 46.095e3")[0].count("\n")
    with pytest.raises(rcb.RcbError) as e:
        rcb.Model.from_ini(bad)
    assert f"bad.ini:{line}" in str(e.value) and e.value.status == -3
    with pytest.raises(rcb.RcbError, match="<text>:1"):
        rcb.Model.from_ini("[material]\n", name="<text>")
    with pytest.raises(rcb.RcbError):
        rcb.Model.from_ini(tmp_path / "missing.ini")


def test_text_and_copy_are_the_same_model(rcb, paper):
    m2 = rcb.Model.from_ini(PAPER.read_text())
    m3 = paper.copy()
    for a, b, c in zip(paper.matrices(3000), m2.matrices(3000), m3.matrices(3000)):
        np.testing.assert_array_equal(a, b)
        np.testing.assert_allclose(a, c, rtol=1e-15, atol=0)


def test_matrices_structure(paper):
    M, C, G, K = paper.matrices(5000)
    np.testing.assert_allclose(M, M.T, atol=1e-12 * abs(M).max())
    np.testing.assert_allclose(G, -G.T, atol=1e-12 * abs(G).max())
    assert np.all(np.linalg.eigvalsh(M) > 0)


def _dyn(paper, w, rpm):
    M, C, G, K = paper.matrices(rpm)
    return K - w * w * M + 1j * w * (C + rpm * RPM * G)


def test_frf_equals_the_inverse_dynamic_stiffness(rcb, paper):
    """H = [K - w^2 M + i w (C + Omega G)]^-1 from numpy on the same matrices."""
    outs, ins = ["C.A.x", "C.B.y", "DB.rx"], ["DA.x", "DB.y"]
    f = np.array([10.0, 150.3, 321.0, 480.0])
    for kind, p in (("receptance", 0), ("mobility", 1), ("inertance", 2)):
        H = rcb.frf(paper, outs, ins, f, rpm=7000, kind=kind)
        assert H.shape == (4, 3, 2)
        for k, fk in enumerate(f):
            w = 2 * math.pi * fk
            Hn = np.linalg.inv(_dyn(paper, w, 7000))
            ro = [paper.dof_index(o) for o in outs]
            ri = [paper.dof_index(i) for i in ins]
            np.testing.assert_allclose(H[k], (1j * w) ** p * Hn[np.ix_(ro, ri)], rtol=1e-9)


def test_synchronous_frf_spins_at_the_excitation(rcb, paper):
    f = np.array([100.0, 160.0])
    Hs = rcb.frf(paper, ["DA.x"], ["DA.x"], f, rpm=None)
    for k, fk in enumerate(f):
        Hk = rcb.frf(paper, ["DA.x"], ["DA.x"], [fk], rpm=fk * 60)
        assert Hs[k, 0, 0] == pytest.approx(Hk[0, 0, 0], rel=1e-12)


def test_unbalance_equals_solve_with_the_unbalance_force(rcb, paper):
    rpm = np.array([3000.0, 9100.0, 15000.0])
    outs = ["DA.x", "DA.y", "DB.x"]
    Q = rcb.unbalance(paper, outs, rpm)
    for k, r in enumerate(rpm):
        w = r * RPM
        q = np.linalg.solve(_dyn(paper, w, r), paper.unbalance_force(r))
        np.testing.assert_allclose(Q[k], q[[paper.dof_index(o) for o in outs]], rtol=1e-9)
    F = paper.unbalance_force(3000)
    ix, iy = paper.dof_index("DA.x"), paper.dof_index("DA.y")
    assert F[iy] == pytest.approx(-1j * F[ix])  # F_y = -i F_x: forward rotating force


def test_modes_are_the_eigenvalues_of_the_state_space(rcb, paper):
    rpm = 10000.0
    md = rcb.modes(paper, rpm, n=6)
    M, C, G, K = paper.matrices(rpm)
    n = M.shape[0]
    Minv = np.linalg.inv(M)
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-Minv @ K, -Minv @ (C + rpm * RPM * G)]])
    lam = np.linalg.eigvals(A)
    # oscillating roots below the library's default max_zeta 0.99 (the overdamped
    # cluster of the shaft's stiffness-proportional damping is left out)
    lam = lam[(lam.imag > 1e-3) & (-lam.real / abs(lam) < 0.99)]
    lam = lam[np.argsort(lam.imag)][:6]
    np.testing.assert_allclose(md.eigenvalues, lam, rtol=1e-7)
    np.testing.assert_allclose(md.fd_hz, lam.imag / (2 * math.pi), rtol=1e-7)
    np.testing.assert_allclose(md.zeta, -lam.real / abs(lam), rtol=1e-6)
    # shapes: each a right eigenvector of the quadratic problem
    for k in range(6):
        r = (lam[k] ** 2 * M + lam[k] * (C + rpm * RPM * G) + K) @ md.shapes[:, k]
        assert np.linalg.norm(r) < 1e-6 * np.linalg.norm(K @ md.shapes[:, k])
        xy = md.node_shape(k)
        assert np.nanmax(abs(xy)) == pytest.approx(1.0, rel=1e-9)
    assert set(md.whirl) <= {"forward", "backward", "mixed"}
    assert "forward" in md.whirl and "backward" in md.whirl


def test_campbell_critical_speeds_lie_on_1x(rcb, paper):
    r = np.linspace(0, 20000, 81)
    cb = rcb.campbell(paper, r, n=6)
    assert cb.fd_hz.shape == (81, 6)
    md = rcb.modes(paper, 5000, n=6, shapes=False)
    np.testing.assert_allclose(cb.fd_hz[20], md.fd_hz, rtol=1e-9)  # row 20 is 5000 rpm
    assert len(cb.critical_rpm) >= 2
    for c, k in zip(cb.critical_rpm, cb.critical_mode):
        # at a critical speed the crossing mode's frequency equals the speed (1X)
        fd = rcb.modes(paper, c, n=6, shapes=False).fd_hz[k]
        assert fd == pytest.approx(c / 60, rel=2e-3)
    cb2 = rcb.campbell(paper, r, n=6, ratio=2.0)
    assert cb2.critical_rpm[0] == pytest.approx(cb.critical_rpm[0] / 2, rel=0.05)


@pytest.mark.parametrize("ext", [".csv", ".uff"])
def test_meas_write_read_round_trip(rcb, paper, tmp_path, ext):
    f = np.linspace(50, 400, 36)
    ms = rcb.simulate(paper, ["C.A.x", "DB.y"], ["DA.x"], f, rpm=6000, kind="mobility")
    path = tmp_path / f"m{ext}"
    mp = ms.write(path)
    back = rcb.Meas.read(path, uff_map=mp)
    assert back.type == "frf" and back.rpm == pytest.approx(6000)
    assert back.channels == ms.channels
    np.testing.assert_allclose(back.x, f, rtol=1e-12)
    np.testing.assert_allclose(back.data, ms.data, rtol=1e-12)
    H = rcb.frf(paper, ["C.A.x", "DB.y"], ["DA.x"], f, rpm=6000, kind="mobility")
    np.testing.assert_allclose(back.data, H[:, :, 0].T, rtol=1e-12)
    u = rcb.simulate(paper, ["DA.x"], rpm=np.linspace(1000, 5000, 5))
    u.write(tmp_path / "u.csv")
    ub = rcb.Meas.read(tmp_path / "u.csv")
    assert ub.type == "unbalance" and ub.rpm is None
    np.testing.assert_allclose(ub.x, [1000, 2000, 3000, 4000, 5000])
    np.testing.assert_allclose(ub.data[0], rcb.unbalance(paper, ["DA.x"], ub.x)[:, 0],
                               rtol=1e-12)


def test_meas_errors_name_the_file(rcb, tmp_path):
    p = tmp_path / "bad.csv"
    p.write_text("freq_hz,DA.x/DA.x re,DA.x/DA.x im\n1,2\n")
    with pytest.raises(rcb.RcbError, match="bad.csv"):
        rcb.Meas.read(p)


def test_meas_read_csv_node_numbers(rcb, tmp_path):
    """Issue #35: a lab's CSV ("1.x/2.y_re", node numbers) read through uff_map
    to the values of the canonical header; without the map, refused."""
    canon, lab = tmp_path / "c.csv", tmp_path / "lab.csv"
    canon.write_text("freq_hz,DA.x/DB.y re,DA.x/DB.y im\n10,1e-6,-2e-6\n20,3e-6,4e-6\n")
    lab.write_text("freq_hz,1.x/2.y_re,1.x/2.y_im\n10,1e-6,-2e-6\n20,3e-6,4e-6\n")
    a = rcb.Meas.read(canon)
    b = rcb.Meas.read(lab, uff_map={1: "DA", 2: "DB"})
    assert b.channels == a.channels
    assert np.array_equal(b.data, a.data)
    with pytest.raises(rcb.RcbError, match="lab.csv:1: column 2.*station '1' is a number"):
        rcb.Meas.read(lab)


def test_fit_recovers_hidden_coupling(rcb, paper):
    """Noise-free data from hidden kt, kr (x2.5, x0.4): the fit finds them."""
    truth = paper.copy()
    truth.set("coupling.C.kt", 2.5 * paper.get("coupling.C.kt"))
    truth.set("coupling.C.kr", 0.4 * paper.get("coupling.C.kr"))
    f = np.linspace(200, 400, 81)
    meas = rcb.simulate(truth, ["C.A.x", "C.A.y", "C.B.x", "C.B.y"], ["DA.x"], f, rpm=10000,
                        kind="inertance")
    res = rcb.fit(paper, meas, ["coupling.C.kt", "coupling.C.kr"])
    assert paper.get("coupling.C.kt") == pytest.approx(46.095e3)  # the input is not changed
    for name in ("coupling.C.kt", "coupling.C.kr"):
        assert res.values[name] == pytest.approx(truth.get(name), rel=1e-5)
        assert res.model.get(name) == res.values[name]
    assert res.report["error_pct"] < 1e-3 < res.report["error0_pct"]
    assert res.report["converged"] and res.correlation.shape == (2, 2)
    np.testing.assert_allclose(np.diag(res.correlation), 1.0)
    with pytest.raises(rcb.RcbError, match="nosuch"):
        rcb.fit(paper, meas, {"coupling.C.nosuch": (1, 2)})


def test_fit_restarts_from_a_poor_start(rcb, paper):
    """Issue #17: from kt = 20e3 N/m, kr = 500 N m/rad (README's data: C.A.x, C.B.x per
    DA.x, 200-400 Hz, noise 10 %, 1 %) one Gauss-Newton run ends in a local minimum
    (kt ~ 15.6e3, kr ~ 600, above 1.5 x the noise floor); the default starts (8,
    restarts while unsure, as rcbtool fit) reach the truth."""
    f = np.linspace(200, 400, 201)
    meas = rcb.simulate(paper, ["C.A.x", "C.B.x"], ["DA.x"], f, rpm=10000, kind="receptance",
                        noise=(10, 1), seed=1)
    start = paper.copy()
    start.set("coupling.C.kt", 20e3)
    start.set("coupling.C.kr", 500.0)
    one = rcb.fit(start, meas, ["coupling.C.kt", "coupling.C.kr"], noise=(10, 1), starts=1)
    assert one.report["unsure"] and one.report["starts"] == 1
    assert one.report["error_pct"] > 1.5 * one.report["floor_pct"]
    assert one.values["coupling.C.kt"] == pytest.approx(15.6e3, rel=0.05)  # the local minimum
    res = rcb.fit(start, meas, ["coupling.C.kt", "coupling.C.kr"], noise=(10, 1))
    assert not res.report["unsure"] and 1 < res.report["starts"] <= 8
    assert res.values["coupling.C.kt"] == pytest.approx(46.095e3, rel=0.02)
    assert res.values["coupling.C.kr"] == pytest.approx(220.76, rel=0.02)


def test_diagnose_finds_the_walkthrough_effect(rcb):
    """examples/walkthrough: the data were made with bearing B2 cross-coupled,
    kxy = -kyx = 2e7 N/m (its README)."""
    m = rcb.Model.from_ini(WALK / "model.ini")
    meas = rcb.Meas.read(WALK / "measured.uff", model=m)
    with rcb.diagnose(m, meas, ["coupling.C.kt", "coupling.C.kr", "coupling.C.ct"],
                      noise=(10, 1), refits=3) as d:
        best = d.best
        assert best is not None and best["place"] == "bearing B2"
        assert best["params"] == "bearing.B2.kcross"
        assert float(best["fitted"].split("=")[1]) == pytest.approx(2e7, rel=0.05)
        # 8 x 151 is fitted on all points: no refit is left screened only
        assert not any(c["screened_only"] for c in d.candidates)
        # a sensor finding names the options of its next round; a model candidate none
        assert all(bool(c["carry"]) == c["chain"] for c in d.candidates), d.candidates
        assert "B2" in d.explanation
        m2 = d.apply(best["rank"])
    assert m2.get("bearing.B2.kxy") == pytest.approx(2e7, rel=0.05)
    assert m2.get("bearing.B2.kyx") == pytest.approx(-m2.get("bearing.B2.kxy"))
    c = rcb.compare(m2, meas)
    assert c["summary"]["error_pct"] < rcb.compare(m, meas)["summary"]["error_pct"]


def test_handles_close_once(rcb):
    m = rcb.Model.from_ini(PAPER)
    with m:
        assert m.dofs == 88
    m.close()  # twice: no-op
    with pytest.raises(ValueError, match="closed"):
        m.dofs


def test_compare_names_a_low_sensor(rcb, paper):
    """Issue #23: a probe reading 20 % low (DB.y x 0.8) is named in "outliers",
    with the others' range; the same data with the gain right name nothing."""
    outs = ["C.A.x", "C.A.y", "C.B.x", "C.B.y", "DA.x", "DB.y"]
    f = np.linspace(5, 400, 300)
    ok = rcb.simulate(paper, outs, ["DA.x"], f, rpm=3000, kind="inertance", noise=(10, 1),
                      seed=3)
    data = ok.data.copy()
    data[5] *= 0.8
    low = rcb.Meas.from_arrays(f, data, outs, ["DA.x"] * 6, kind="inertance", rpm=3000)
    c = rcb.compare(paper, low)
    assert [o["response"] for o in c["outliers"]] == ["DB.y"]
    o = c["outliers"][0]
    err = [ch["error_pct"] for ch in c["channels"]]
    assert o["reference"] is None and not o["by_chi2"]
    assert o["error_pct"] == pytest.approx(err[5])
    assert o["others_lo"] == min(err[:5]) and o["others_hi"] == max(err[:5])
    assert rcb.compare(paper, ok)["outliers"] == []
