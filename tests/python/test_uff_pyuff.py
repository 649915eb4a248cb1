"""UFF dataset 58 against an independent implementation: PyPI pyuff.

* pyuff writes FRFs (ASCII 58 and binary 58b, several channels, known
  values, displacement/velocity/acceleration over force, even and uneven
  abscissa, negative directions); `rcbtool convert X.uff X.csv` must give
  the same numbers (and the receptance identities when asked to convert).
* `rcbtool simulate` writes UFF (ASCII and binary); pyuff reads it and the
  values must equal `rcbtool frf --json` / `rcbtool unbalance --json`.

Note: pyuff 2.5's binary writer must be used in 'add' mode on a fresh file
(its 'overwrite' mode truncates the ASCII header of the first binary record).
"""

import csv
import math
import subprocess

import numpy as np
import pytest

from conftest import EXAMPLES, _rcbtool_path

pyuff = pytest.importorskip("pyuff")

MODEL = EXAMPLES / "paper_system.ini"
MAP = "1=DA,2=C.A,3=C.B,10=DB"
FREQ = np.linspace(10.0, 50.0, 9)  # Hz; min and increment exact in E13.5
# (response node, direction, reference node, direction) -> our channel names
CHANNELS = [
    ((1, 1, 10, 1), "DA.x", "DB.x", 1.0),
    ((2, -2, 10, 1), "C.A.y", "DB.x", -1.0),  # -Y response: sign flipped
    ((3, 4, 10, -2), "C.B.rx", "DB.y", -1.0),  # -Y reference: sign flipped
    ((1, 5, 10, 5), "DA.ry", "DB.ry", 1.0),
]
KIND = {8: "receptance", 11: "mobility", 12: "inertance"}
POWER = {8: 0, 11: 1, 12: 2}  # (i w)^k times receptance


@pytest.fixture(scope="module")
def exe():
    return _rcbtool_path()


def run(exe, *args, code=0):
    res = subprocess.run([exe, *map(str, args)], capture_output=True, text=True, timeout=300)
    assert res.returncode == code, f"{args}: exit {res.returncode}\n{res.stderr}"
    return res


def values(k, f):
    """Known complex values of channel k (m/N-ish magnitudes, both signs)."""
    return (k + 1) * 1e-6 * np.exp(1j * (0.3 * k + f / 17.0)) * (1.0 + f / 10.0) - 2e-7j


def write_pyuff(path, binary, spec, uneven=False, specs=None):
    if path.exists():
        path.unlink()
    u = pyuff.UFF(str(path))
    for k, ((rn, rd, fn, fd), _, _, _) in enumerate(CHANNELS):
        s = specs[k] if specs else spec
        d = pyuff.prepare_58(
            binary=binary, func_type=4, rsp_node=rn, rsp_dir=rd, ref_node=fn, ref_dir=fd,
            data=values(k, FREQ), x=FREQ, id1=f"channel {k}",
            abscissa_spacing=0 if uneven else 1, abscissa_spec_data_type=18,
            ordinate_spec_data_type=s, orddenom_spec_data_type=13,
        )
        u._write_set(d, "add")  # see the module note on pyuff's overwrite mode


def read_csv(path):
    meta, rows = {}, []
    with open(path) as fh:
        for line in fh:
            if line.startswith("#"):
                key, _, val = line[1:].partition("=")
                meta[key.strip()] = val.strip()
            else:
                rows.append(line.rstrip("\n"))
    table = list(csv.reader(rows))
    header, data = table[0], np.array([[float(v) for v in r] for r in table[1:]])
    return meta, header, data


@pytest.mark.parametrize("binary", [0, 1], ids=["ascii", "binary"])
@pytest.mark.parametrize("spec", [8, 11, 12], ids=["displacement", "velocity", "acceleration"])
def test_pyuff_to_csv(exe, tmp_path, binary, spec):
    uff, out = tmp_path / "p.uff", tmp_path / "p.csv"
    write_pyuff(uff, binary, spec)
    run(exe, "convert", uff, out, "--map", MAP)
    meta, header, data = read_csv(out)
    assert meta["kind"] == KIND[spec]
    assert header[0] == "freq_hz"
    np.testing.assert_allclose(data[:, 0], FREQ, rtol=1e-15)
    # pyuff's ASCII doubles are %20.11e: 12 significant digits
    rtol = 1e-15 if binary else 6e-12
    for k, (_, resp, ref, sign) in enumerate(CHANNELS):
        assert header[1 + 2 * k] == f"{resp}/{ref} re"
        assert header[2 + 2 * k] == f"{resp}/{ref} im"
        got = data[:, 1 + 2 * k] + 1j * data[:, 2 + 2 * k]
        want = sign * values(k, FREQ)
        assert np.all(np.abs(got - want) <= rtol * np.abs(want)), (resp, got, want)


@pytest.mark.parametrize("binary", [0, 1], ids=["ascii", "binary"])
def test_pyuff_mixed_kinds_uneven_to_receptance(exe, tmp_path, binary):
    """Records of different kinds, uneven abscissa: --kind receptance divides
    each by its (i w)^k."""
    uff, out = tmp_path / "m.uff", tmp_path / "m.csv"
    specs = [8, 11, 12, 12]
    write_pyuff(uff, binary, None, uneven=True, specs=specs)
    res = run(exe, "convert", uff, out, "--map", MAP, code=3)
    assert "differ in kind" in res.stderr
    run(exe, "convert", uff, out, "--map", MAP, "--kind", "receptance")
    meta, header, data = read_csv(out)
    assert meta["kind"] == "receptance"
    # uneven ASCII abscissa is E13.5 in pyuff's files: these values are exact there
    np.testing.assert_allclose(data[:, 0], FREQ, rtol=1e-15)
    w = 2 * math.pi * FREQ
    rtol = 1e-14 if binary else 6e-12
    for k, (_, resp, ref, sign) in enumerate(CHANNELS):
        got = data[:, 1 + 2 * k] + 1j * data[:, 2 + 2 * k]
        want = sign * values(k, FREQ) / (1j * w) ** POWER[specs[k]]
        assert np.all(np.abs(got - want) <= rtol * np.abs(want)), (resp, got, want)


OUTS, INS = ["DA.x", "C.A.y", "C.B.rx"], ["DA.x", "C.B.y"]
NODE = {"DA": 1, "C.A": 2, "C.B": 3}
DIRS = {"x": 1, "y": 2, "rx": 4, "ry": 5}


def node_dir(ch):
    st, _, d = ch.rpartition(".")
    return NODE[st], DIRS[d]


@pytest.mark.parametrize("binary", [0, 1], ids=["ascii", "binary"])
def test_simulate_uff_read_by_pyuff(exe, tmp_path, binary):
    uff = tmp_path / "s.uff"
    grid = ["--fmin", 200, "--fmax", 400, "--points", 41, "--rpm", 10000]
    ch = ["--out", ",".join(OUTS), "--in", ",".join(INS)]
    run(exe, "simulate", MODEL, "--frf", *ch, *grid, "--map", "1=DA,2=C.A,3=C.B",
        "-o", uff, *(["--binary"] if binary else []))
    ref = run(exe, "frf", MODEL, *ch, *grid, "--json").stdout
    import json

    ref = json.loads(ref)
    sets = pyuff.UFF(str(uff)).read_sets()
    sets = sets if isinstance(sets, list) else [sets]
    assert len(sets) == len(ref["channels"])
    rtol = 1e-15 if binary else 5e-13  # our ASCII doubles are E20.12
    for s, c in zip(sets, ref["channels"]):
        assert s["func_type"] == 4
        assert (s["rsp_node"], s["rsp_dir"]) == node_dir(c["output"])
        assert (s["ref_node"], s["ref_dir"]) == node_dir(c["input"])
        assert s["ordinate_spec_data_type"] == 8 and s["orddenom_spec_data_type"] == 13
        assert s["z_axis_value"] == 10000.0
        np.testing.assert_allclose(s["x"], ref["freq_hz"], rtol=1e-12)
        want = np.array(c["re"]) + 1j * np.array(c["im"])
        assert np.all(np.abs(s["data"] - want) <= rtol * np.abs(want)), c["output"]


@pytest.mark.parametrize("binary", [0, 1], ids=["ascii", "binary"])
def test_simulate_unbalance_read_by_pyuff(exe, tmp_path, binary):
    import json

    uff = tmp_path / "u.uff"
    grid = ["--rpm-min", 300, "--rpm-max", 18300, "--points", 31]
    run(exe, "simulate", MODEL, "--unbalance", "--out", "C.A.x,C.B.y", *grid,
        "--map", "2=C.A,3=C.B", "-o", uff, *(["--binary"] if binary else []))
    ref = json.loads(run(exe, "unbalance", MODEL, "--out", "C.A.x,C.B.y", *grid, "--json").stdout)
    sets = pyuff.UFF(str(uff)).read_sets()
    rtol = 1e-15 if binary else 5e-13
    for s, c in zip(sets, ref["channels"]):
        assert s["func_type"] == 1 and s["ref_node"] == 0
        assert (s["rsp_node"], s["rsp_dir"]) == node_dir(c["output"])
        assert s["abscissa_spec_data_type"] == 19  # rpm (issue #17)
        np.testing.assert_allclose(s["x"], ref["rpm"], rtol=1e-12)
        want = np.array(c["re"]) + 1j * np.array(c["im"])
        assert np.all(np.abs(s["data"] - want) <= rtol * np.abs(want)), c["output"]


def test_simulate_runup_speeds_exact(exe, tmp_path):
    """A run-up grid in whole rpm (0..10000 by 50) is written in rpm (type 19):
    pyuff reads the speeds exactly. In Hz the step 0.8333.. Hz does not fit the
    E13.6 fields (the last speed came back as 10000.002 rpm)."""
    uff = tmp_path / "r.uff"
    run(exe, "simulate", MODEL, "--unbalance", "--out", "DA.x", "--rpm-min", 0,
        "--rpm-max", 10000, "--points", 201, "--map", "1=DA", "-o", uff)
    s = pyuff.UFF(str(uff)).read_sets()
    s = s[0] if isinstance(s, list) else s
    assert s["abscissa_spec_data_type"] == 19
    np.testing.assert_allclose(s["x"], np.linspace(0.0, 10000.0, 201), rtol=1e-14, atol=0)


def test_simulate_rotation_labels(exe, tmp_path):
    """A rotation response over a moment is labelled rad over N m, a
    translation over a force m over N (not "Acceleration m/s^2" for all)."""
    uff = tmp_path / "l.uff"
    run(exe, "simulate", MODEL, "--frf", "--out", "DA.rx,DA.x", "--in", "DB.ry",
        "--fmin", 100, "--fmax", 200, "--points", 5, "--kind", "inertance",
        "--map", "1=DA,10=DB", "-o", uff)
    sets = pyuff.UFF(str(uff)).read_sets()
    lab = {s["rsp_dir"]: s for s in sets}
    assert lab[4]["ordinate_axis_units_lab"].strip() == "rad/s^2"
    assert lab[1]["ordinate_axis_units_lab"].strip() == "m/s^2"
    for s in sets:
        assert s["orddenom_axis_units_lab"].strip() == "N m"


# ---- issue #17: what another tool's file leaves out is not read silently ----

SPEED_CH = [("DA.x", "DA.x", 1, 1, 1, 1), ("DA.y", "DA.x", 1, 2, 1, 1)]


def write_speed_in_text_only(exe, path, nodes=(1, 1)):
    """FRFs of the model at 10000 rpm, written by pyuff as another tool does:
    the speed only in the ID text, z axis of type 0 (unknown), z value 0."""
    import json

    f = np.linspace(100.0, 300.0, 21)
    ref = json.loads(run(exe, "frf", MODEL, "--out", "DA.x,DA.y", "--in", "DA.x",
                         "--fmin", 100, "--fmax", 300, "--points", 21, "--rpm", 10000,
                         "--json").stdout)
    if path.exists():
        path.unlink()
    u = pyuff.UFF(str(path))
    for k, c in enumerate(ref["channels"]):
        d = pyuff.prepare_58(
            func_type=4, rsp_node=nodes[k], rsp_dir=1 + k, ref_node=1, ref_dir=1,
            data=np.array(c["re"]) + 1j * np.array(c["im"]), x=f,
            id1="run 7", id2="speed 10000 rpm", abscissa_spacing=1,
            abscissa_spec_data_type=18, ordinate_spec_data_type=8,
            orddenom_spec_data_type=13, z_axis_spec_data_type=0, z_axis_value=0.0)
        u._write_set(d, "add")


def test_speed_only_in_text_header(exe, tmp_path):
    uff = tmp_path / "other.uff"
    write_speed_in_text_only(exe, uff)
    import json

    def summary(r):
        return json.loads(r.stdout)["summary"]

    # before: read as 0 rpm without a word (error 8.2 %, FRAC nan)
    r = run(exe, "compare", MODEL, uff, "--map", "1=DA", "--json")
    assert "does not state the test speed" in r.stderr and "reads as 0 rpm" in r.stderr
    assert summary(r)["error_pct"] > 1.0
    # --rpm states it: the model at 10000 rpm is the data (error ~ 0), no warning
    r = run(exe, "compare", MODEL, uff, "--map", "1=DA", "--rpm", 10000, "--json")
    assert summary(r)["error_pct"] < 1e-6 and "warning" not in r.stderr
    # the model's [test] rpm states it too
    model = tmp_path / "m.ini"
    model.write_text(MODEL.read_text() + "\n[test]\nrpm = 10000\n")
    r = run(exe, "compare", model, uff, "--map", "1=DA", "--json")
    assert summary(r)["error_pct"] < 1e-6 and "[test] rpm = 10000" in r.stderr
    # a fit at 0 rpm names the channel and the cause instead of "infinite"
    r = run(exe, "fit", MODEL, uff, "--map", "1=DA", "--params", "coupling.C.kt",
            code=4)
    assert "channel DA.y/DA.x" in r.stderr and "read as 0 rpm" in r.stderr


def test_unmapped_node_warned(exe, tmp_path):
    """Node 2 (DA.y's record) is not in the map: read as model node #2, warned;
    --map adds to the model's [uff] map instead of replacing it."""
    uff = tmp_path / "nodes.uff"
    write_speed_in_text_only(exe, uff, nodes=(1, 2))
    r = run(exe, "compare", MODEL, uff, "--map", "1=DA", "--rpm", 10000)
    assert "UFF node 2 is not in the node map" in r.stderr
    model = tmp_path / "m.ini"
    model.write_text(MODEL.read_text() + "\n[uff]\nmap = 2 DA\n")
    # the model maps node 2; the option maps node 1 to the same station: the
    # option's entry replaces the model's, node 2 is unmapped again
    r = run(exe, "compare", model, uff, "--map", "1=DA", "--rpm", 10000)
    assert "UFF node 2 is not in the node map" in r.stderr
    model.write_text(MODEL.read_text() + "\n[uff]\nmap = 2 P1\n")
    r = run(exe, "compare", model, uff, "--map", "1=DA", "--rpm", 10000)
    assert "not in the node map" not in r.stderr  # both maps used
