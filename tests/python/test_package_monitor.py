"""librcb.Monitor (the ctypes layer over rcb_monitor, issue #16).

* An update identical to the commissioning measurement: T = 0 and every
  tracked parameter at its baseline with z = 0 (closed form: no change).
* The same series through the package and through `rcbtool monitor` (the
  other front end, reading the files the package wrote): the same T,
  threshold, tracked values and intervals, and the same candidates' order
  and sizes. The layout of the result struct (8 tracked, 8 candidates of 3
  parameters) is what the ctypes mirror must get right.
* Meas.from_bytes reads what Meas.write wrote.
"""

import json
import math
import os
import subprocess

import numpy as np
import pytest

from pkg_helpers import PAPER, rcb  # noqa: F401  (fixture)

OUTS = ["DA.x", "DA.y", "C.A.x", "C.A.y", "C.B.x", "C.B.y", "DB.x", "DB.y"]
UFF_MAP = {3: "DA", 10: "C.A", 11: "C.B", 16: "DB"}
PARAMS = ["coupling.C.kt", "coupling.C.ct"]


def _series(rcb, tmp_path, n=4):
    f = np.linspace(100, 400, 121)
    paths = []
    with rcb.Model.from_ini(PAPER) as m:
        for k in range(n):
            if k == n - 1:  # the last day: a cross-coupled B3
                m.set("bearing.B3.kcross", 1.5e7)
            with rcb.simulate(m, OUTS, ["DA.x"], f, rpm=10000, kind="inertance",
                              noise=(10, 1), seed=11 + k) as ms:
                p = tmp_path / f"day{k}.uff"
                ms.write(p, uff_map=UFF_MAP)
                paths.append(p)
    return paths


def test_identical_update_is_no_change(rcb, tmp_path):
    p = _series(rcb, tmp_path, 1)[0]
    with rcb.Model.from_ini(PAPER) as m, rcb.Meas.read(p, uff_map=UFF_MAP) as ms, \
            rcb.Monitor(m, ms, PARAMS, noise=(10, 1)) as mon:
        r = mon.update(ms)
        assert r["T"] == 0.0 and not r["alarm"] and r["update"] == 1
        for t, base in zip(r["tracked"], mon.tracked):
            assert t["value"] == pytest.approx(base["baseline"], rel=1e-12) and t["z"] == 0.0
        assert mon.memory > 0


def test_package_and_rcbtool_agree(rcb, tmp_path):
    exe = os.environ.get("RCBTOOL")
    if not exe:
        pytest.skip("RCBTOOL is not set")
    paths = _series(rcb, tmp_path)
    ini = tmp_path / "model.ini"
    ini.write_text(PAPER.read_text() + "\n[uff]\nmap = " +
                   ", ".join(f"{k} {v}" for k, v in UFF_MAP.items()) + "\n")
    res = subprocess.run([exe, "monitor", str(ini), *map(str, paths), "--params",
                          ",".join(PARAMS), "--noise", "10,1", "--alpha", "0.01", "--json"],
                         capture_output=True, text=True, timeout=300)
    assert res.returncode == 0, res.stderr
    cli = json.loads(res.stdout)["updates"]
    with rcb.Model.from_ini(ini) as m, rcb.Meas.from_bytes(paths[0].read_bytes(),
                                                            uff_map=UFF_MAP) as setup, \
            rcb.Monitor(m, setup, PARAMS, noise=(10, 1), alpha=0.01) as mon:
        setup_shape = mon._shape  # channels, points
        py = []
        for p in paths[1:]:
            with rcb.Meas.from_bytes(p.read_bytes(), uff_map=UFF_MAP) as ms:
                py.append(mon.update(ms))
    assert len(py) == len(cli) == 3
    for a, b in zip(py, cli):
        for key in ("T", "threshold", "p_value", "error_pct", "floor_pct"):
            assert a[key] == pytest.approx(b[key], rel=1e-12, abs=1e-300), key
        assert (a["alarm"], a["dof"]) == (b["alarm"], b["dof"])
        for ta, tb in zip(a["tracked"], b["tracked"]):
            for key in ("value", "ci_lo", "ci_hi", "z", "cusum_up", "cusum_down"):
                assert ta[key] == pytest.approx(tb[key], rel=1e-12, abs=1e-12), key
        assert [(c["effect"], c["place"]) for c in a["top"]] == \
            [(c["effect"], c["place"]) for c in b["top"]]
        for ca, cb in zip(a["top"], b["top"]):
            assert ca["size"] == pytest.approx(cb["size"], rel=1e-12)
        # one rule in both (rcb_monitor_named): the first's BIC change -score + dof
        # ln n lower by more than 10 than its closest rival's, the second, and
        # every rival rejected by the test that the first adds to it (apart_p
        # below RCB_MONITOR_APART_ALPHA); a rival not rejected is the second
        assert a["separable"] == b["separable"]
        assert (a["apart_p"] is None) == (b["apart_p"] is None)
        if a["apart_p"] is not None:
            assert a["apart_p"] == pytest.approx(b["apart_p"], rel=1e-9, abs=1e-300)
        if len(a["top"]) >= 2:
            n = 2 * setup_shape[0] * setup_shape[1]
            bic = [-c["score"] + c["dof"] * math.log(n) for c in a["top"]]
            bic_half = bic[1] - bic[0] > 10.0
            assert (a["apart_p"] is not None) == bic_half
            level = rcb._lib.MONITOR_APART_ALPHA
            assert a["separable"] == (bic_half and a["apart_p"] < level)
            if not bic_half or a["apart_p"] < level:  # else the rival not rejected
                assert all(bic[1] <= x for c, x in zip(a["top"][2:], bic[2:])
                           if a["top"][0]["implausible"] or not c["implausible"])
    assert py[-1]["alarm"]  # the cross-coupled day is a change


def test_noise_scale_package_and_rcbtool_agree(rcb, tmp_path):
    """The noise's level measured on the commissioning files (issue #34): the
    package's librcb.monitor.noise_scale on the 3 files equals rcbtool
    monitor --commission 3's (JSON noise_scale) to rounding, and a Monitor
    given it on their average agrees with rcbtool update by update. The
    scale is also the closed form on those files: the scatter whitened by
    the eq. 19 variance written out here."""
    exe = os.environ.get("RCBTOOL")
    if not exe:
        pytest.skip("RCBTOOL is not set")
    paths = _series(rcb, tmp_path, 5)
    ini = tmp_path / "model.ini"
    ini.write_text(PAPER.read_text() + "\n[uff]\nmap = " +
                   ", ".join(f"{k} {v}" for k, v in UFF_MAP.items()) + "\n")
    res = subprocess.run([exe, "monitor", str(ini), *map(str, paths), "--params",
                          ",".join(PARAMS), "--noise", "10,1", "--commission", "3",
                          "--alpha", "0.01", "--json"], capture_output=True, text=True,
                         timeout=300)
    assert res.returncode == 0, res.stderr
    log = json.loads(res.stdout)
    files = []
    for p in paths[:3]:
        with rcb.Meas.from_bytes(p.read_bytes(), uff_map=UFF_MAP) as ms:
            files.append(ms.data)
            x, chans, rpm = ms.x, ms.channels, ms.rpm
    files = np.array(files)
    avg = files.mean(axis=0)
    # closed form: one measurement's radial and tangential variance at the average
    a = 0.01 * np.sqrt(np.sum(np.abs(avg) ** 2, axis=1, keepdims=True)) / avg.shape[1]
    vt = a ** 2 / 6 + 0 * avg.real
    vr = (0.10 * np.abs(avg)) ** 2 / 3 + vt
    d = (files - avg) * np.conj(avg / np.abs(avg))
    chi2 = float(np.sum(d.real ** 2 / vr + d.imag ** 2 / vt))
    with rcb.Model.from_ini(ini) as m, \
            rcb.Meas.from_arrays(x, avg, [c[0] for c in chans], [c[1] for c in chans],
                                 kind=chans[0][2], rpm=rpm) as setup:
        ns = rcb.monitor.noise_scale(setup, files, noise=(10, 1))
        assert ns["dof"] == 2 * avg.size * 2 == log["scatter_dof"]
        assert ns["chi2"] == pytest.approx(chi2, rel=1e-10)
        assert ns["scale"] == pytest.approx(log["noise_scale"], rel=1e-10)
        assert log["noise_scale_from"] == "commissioning scatter"
        with rcb.Monitor(m, setup, PARAMS, noise=(10, 1), alpha=0.01, setup_averages=3,
                         noise_scale=ns["scale"]) as mon:
            for p, b in zip(paths[3:], log["updates"]):
                with rcb.Meas.from_bytes(p.read_bytes(), uff_map=UFF_MAP) as ms:
                    r = mon.update(ms)
                assert r["T"] == pytest.approx(b["T"], rel=1e-9)
                assert r["alarm"] == b["alarm"]


def test_state_restart(rcb, tmp_path):
    """save_state / load_state (issue #24): a second monitor loaded from the first's
    state after 2 updates gives the first's next result exactly; bytes of another
    model are refused."""
    paths = _series(rcb, tmp_path)
    with rcb.Model.from_ini(PAPER) as m, rcb.Meas.read(paths[0], uff_map=UFF_MAP) as setup:
        def make():
            return rcb.Monitor(m, setup, PARAMS, noise=(10, 1), alpha=0.01, baseline_sd=[5.0, 0.01])
        with make() as a, make() as b:
            for p in paths[1:3]:
                with rcb.Meas.read(p, uff_map=UFF_MAP) as ms:
                    a.update(ms)
            state = a.save_state()
            # rcb_monitor.h's layout: header, per tracked, per pair of tracked
            # (version 3), the drift window (264 bytes per rank-space dimension,
            # tracked parameter and scored candidate parameter)
            rest = (len(state) - 108 - 40 * len(PARAMS) - 8 * len(PARAMS) ** 2
                    - 264 * (a.rank[0] + len(PARAMS)))
            assert rest > 0 and rest % 264 == 0
            assert state[:4] == b"RCBM"
            b.load_state(state)
            with rcb.Meas.read(paths[3], uff_map=UFF_MAP) as ms:
                ra, rb = a.update(ms), b.update(ms)
            assert ra == rb and rb["update"] == 3
            t = rb["tracked"][0]
            # the value's variance: the change's and the baseline's share (e_a - g)^T S
            # (e_a - g), S = diag(25, 1e-4), g the curvature's effect of the change
            # (issue #34 item 4): near S's own 25 for changes this small
            share = t["abs_stderr"] ** 2 - t["stderr"] ** 2
            assert 0.5 * 25.0 < share < 2.0 * 25.0, (share, t)
            assert t["ci_hi"] - t["value"] == pytest.approx(1.959963984540054 * t["abs_stderr"],
                                                            rel=1e-9)
            bad = bytearray(state)
            bad[40] ^= 1
            with pytest.raises(rcb.RcbError):
                b.load_state(bytes(bad))


def test_small_setup_refused_without_printing(rcb, capfd):
    """1 channel x 21 points and one tracked parameter: fewer residuals (42) than
    sensitivity columns. It failed with "LAPACK workspace query failed" after
    LAPACK's DORMQR printed to stdout (a query for more reflectors than rows, an
    illegal argument); now refused with what to change, and nothing printed."""
    f = np.linspace(100, 400, 21)
    with rcb.Model.from_ini(PAPER) as m, \
            rcb.simulate(m, ["DA.x"], ["DA.x"], f, rpm=10000, kind="inertance",
                         noise=(10, 1), seed=1) as ms:
        with pytest.raises(rcb.RcbError, match="42 real residuals"):
            rcb.Monitor(m, ms, ["coupling.C.kt"], noise=(10, 1))
    out = capfd.readouterr()
    assert "DORMQR" not in out.out + out.err and out.out == ""


def test_separate_by(rcb, tmp_path):
    """Issue #24 item 3: when a CUSUM alarm's attribution is "kt falling, or <a
    bearing> ...: not separable on these channels", the measurement that would
    separate them is named, by the diagnosis' plan (rcb_monitor_separating), the
    same in Python (`separate_by`) and in rcbtool monitor's JSON and text; and it
    is `rcbtool plan`'s first candidate channel for that pair. A B4 kyy drift
    measured on DB.y per DA.x only (librcb's own model: a unit test of the
    wiring; tests/test_monitor.c checks the named channel separates them)."""
    exe = os.environ.get("RCBTOOL")
    if not exe:
        pytest.skip("RCBTOOL is not set")
    umap = {16: "DB", 3: "DA"}
    f = np.linspace(20, 400, 60)
    paths = []
    with rcb.Model.from_ini(PAPER) as m:
        k0 = m.get("bearing.B4.kyy")
        for k in range(23):  # falling 0.4 % per update from update 6
            m.set("bearing.B4.kyy", k0 * (1 - 0.004 * max(k - 5, 0)))
            with rcb.simulate(m, ["DB.y"], ["DA.x"], f, rpm=10000, kind="receptance",
                              noise=(2, 2), seed=5 + k) as ms:
                paths.append(tmp_path / f"d{k:02d}.uff")
                ms.write(paths[-1], uff_map=umap)
    ini = tmp_path / "model.ini"
    ini.write_text(PAPER.read_text() + "\n[uff]\nmap = 16 DB, 3 DA\n")
    params = ["coupling.C.kt", "coupling.C.kr"]
    args = [exe, "monitor", str(ini), *map(str, paths), "--params", ",".join(params),
            "--noise", "2,2", "--alpha", "0.01"]
    res = subprocess.run(args + ["--json"], capture_output=True, text=True, timeout=300)
    assert res.returncode == 0, res.stderr
    cli = json.loads(res.stdout)["updates"]
    text = subprocess.run(args, capture_output=True, text=True, timeout=300)
    assert text.returncode == 0, text.stderr
    with rcb.Model.from_ini(ini) as m, rcb.Meas.read(paths[0], uff_map=umap) as setup, \
            rcb.Monitor(m, setup, params, noise=(2, 2), alpha=0.01) as mon:
        py = []
        for p in paths[1:]:
            with rcb.Meas.read(p, uff_map=umap) as ms:
                py.append(mon.update(ms))
    named = []
    for a, b in zip(py, cli):
        for k, (ta, tb) in enumerate(zip(a["tracked"], b["tracked"])):
            assert ta["named"] == tb["named"]
            assert ta["cusum_allow"] == pytest.approx(tb["cusum_allow"], rel=1e-12)
            sa, sb = ta["separate_by"], tb["separate_by"]
            assert (sa is None) == (sb is None)
            if ta["named"] != 0 or not ta["cusum_alarm"]:
                assert sa is None  # nothing proposed where the attribution separates
            if sa is not None:
                assert (sa["response"], sa["reference"]) == (sb["response"], sb["reference"])
                for key in ("rpm", "chi2_present", "chi2_after", "level_db"):
                    assert sa[key] == pytest.approx(sb[key], rel=1e-9), key
                assert sa["chi2_present"] <= 10.0 < sa["chi2_after"]  # the plan's verdict
                named.append((a["update"], k, ta["rival"]["params"], sa))
    assert named, "no not-separable attribution in the series"
    update, k, rival, sa = named[0]
    line = next(ln for ln in text.stdout.splitlines() if ln.lstrip().startswith(f"{update} "))
    assert "not separable on these channels" in line
    assert f"{sa['response']} per {sa['reference']} at 10000 rpm would separate them" in line
    # rcbtool plan's first candidate for the pair: the same measurement (one rule)
    others = [p for i, p in enumerate(params) if i != k]
    plan = subprocess.run([exe, "plan", str(ini), str(paths[0]), "--between", rival,
                           ",".join([params[k], *others]), "--noise", "2,2", "--json"],
                          capture_output=True, text=True, timeout=300)
    assert plan.returncode == 0, plan.stderr
    first = json.loads(plan.stdout)["candidates"][0]
    assert (first["response"], first["reference"]) == (sa["response"], sa["reference"])
    assert first["chi2_after"] == pytest.approx(sa["chi2_after"], rel=1e-9)
    # and with another speed, as rcbtool plan --rpm-list
    plan = subprocess.run([exe, "plan", str(ini), str(paths[0]), "--between", rival,
                           ",".join([params[k], *others]), "--noise", "2,2", "--rpm-list",
                           "3000", "--json"], capture_output=True, text=True, timeout=300)
    assert plan.returncode == 0, plan.stderr
    first = json.loads(plan.stdout)["candidates"][0]
    with rcb.Model.from_ini(ini) as m, rcb.Meas.read(paths[0], uff_map=umap) as setup, \
            rcb.Monitor(m, setup, params, noise=(2, 2), alpha=0.01) as mon:
        idx = next(i for i in range(mon.candidate_count())
                   if mon.candidate(i)["params"] == rival)
        s3 = mon.separate_by(k, idx, rpms=[3000])
    assert (first["response"], first["reference"]) == (s3["response"], s3["reference"])
    assert first["rpm"] == pytest.approx(s3["rpm"], rel=1e-9)
    assert s3["chi2_after"] >= sa["chi2_after"] * (1 - 1e-9)


def _b4_series(rcb, outs, rate, n=31, seed=5):
    """B4 kyy falling rate per update from update 6 (librcb's own model, noise
    2 %, 2 %), n measurements of outs per DA.x at 60 lines, 20-400 Hz."""
    f = np.linspace(20, 400, 60)
    with rcb.Model.from_ini(PAPER) as m:
        k0 = m.get("bearing.B4.kyy")
        out = []
        for k in range(n):
            m.set("bearing.B4.kyy", k0 * (1 - rate * max(k - 5, 0)))
            out.append(rcb.simulate(m, outs, ["DA.x"], f, rpm=10000, kind="receptance",
                                    noise=(2, 2), seed=seed + k))
    return out


def _attributions(rcb, meas):
    params = ["coupling.C.kt", "coupling.C.kr"]
    rows = []
    with rcb.Model.from_ini(PAPER) as m, \
            rcb.Monitor(m, meas[0], params, noise=(2, 2), alpha=0.01) as mon:
        for ms in meas[1:]:
            r = mon.update(ms)
            rows += [(r["update"], t) for t in r["tracked"] if t["cusum_alarm"]]
    for ms in meas:
        ms.close()
    return rows


def test_told_apart_only_when_supported(rcb, tmp_path):
    """Issue #24: on one channel (DB.y per DA.x, kt and kr tracked) a B4 kyy drift
    carried on to 30 updates was, from update 22, reported as "bearing B1 kxx
    falling (told apart from kr)": B1 kxx and B4 kyy explain the accumulated change
    within 0.3-1.5 of BIC of each other on that channel (beyond the one rule's 10
    from kr), so the data say "not kr" but not which bearing. A candidate is now
    told apart from a tracked parameter alone only when the runner-up is told apart
    from it too; else both are reported (rival2, "..., or ...: not separable").
    Asserted: no "told apart" claim excludes the truth (B4 kyy is the rival or
    rival2 of every named -1), and such claims occur (the case is exercised);
    counter cases: with DB.x beside DB.y the drift is B4 kyy told apart from
    every other candidate (rival2 None) at the end of the series; with no drift
    there is no CUSUM alarm and so no claim."""
    meas = _b4_series(rcb, ["DB.y"], 0.004)
    paths = []
    for k, ms in enumerate(meas):
        paths.append(tmp_path / f"d{k:02d}.uff")
        ms.write(paths[-1], uff_map={16: "DB", 3: "DA"})
    rows = _attributions(rcb, meas)
    apart = [(u, t) for u, t in rows if t["named"] == -1]
    assert apart, "no told-apart attribution in the one-channel series"
    for u, t in apart:  # (or N other candidates not rejected either: no list to exclude it)
        names = {t["rival"]["params"], t["rival2"] and t["rival2"]["params"]}
        assert "bearing.B4.kyy" in names or t["rivals_open"], (u, t["rival"], t["rival2"])
    assert any(t["rival2"] is not None for u, t in apart)
    exe = os.environ.get("RCBTOOL")
    if exe:  # rcbtool monitor's text says the same
        ini = tmp_path / "model.ini"
        ini.write_text(PAPER.read_text() + "\n[uff]\nmap = 16 DB, 3 DA\n")
        res = subprocess.run([exe, "monitor", str(ini), *map(str, paths), "--params",
                              "coupling.C.kt,coupling.C.kr", "--noise", "2,2", "--alpha",
                              "0.01"], capture_output=True, text=True, timeout=300)
        assert res.returncode == 0, res.stderr
        lines = {int(ln.split()[0]): ln for ln in res.stdout.splitlines()
                 if ln.strip() and ln.split()[0].isdigit()}
        for u, t in apart:
            if t["rival2"] is not None:
                assert (f"{t['rival']['params']} falling, or " in lines[u] and
                        "not separable on these channels; the first told apart from" in
                        lines[u]), lines[u]
        assert "bearing.B1.kxx falling (told apart" not in res.stdout
    # counter case: a second channel separates the bearings
    rows = _attributions(rcb, _b4_series(rcb, ["DB.y", "DB.x"], 0.004))
    last = [t for u, t in rows if u == 30]
    assert last and all(t["named"] == -1 and t["rival"]["params"] == "bearing.B4.kyy" and
                        t["rival2"] is None for t in last), last
    # null: nothing changes, nothing is claimed
    assert not _attributions(rcb, _b4_series(rcb, ["DB.y"], 0.0))
