"""Vendor UFF files (issue #25 item 1): what librcb reads of them, what it
skips and why, and the refusals that name the function type and the verb.

Real files from pyuff's test data (MIT), the external data set vendor_uff: not
in the repository, got by `python3 tools/data/get_data.py vendor_uff` (a pinned
commit, SHA-256 checked; tools/data/README.md says what each file exercises).
The tests that read them are skipped, with that command, when the set is absent.
A 5-channel recording of an acquisition front end is written here by pyuff (an
independent writer; these tests need no fetched file and always run): force and
two responses in x and y, one axial (direction 3) and one scalar (direction 0)
accelerometer, one response labelled in a unit librcb does not know.
"""

import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

signal = pytest.importorskip("scipy.signal")


@pytest.fixture(scope="module")
def vendor(data_set):
    """The directory of pyuff's files (the test is skipped, with the command that
    gets them, when absent)."""
    return data_set("vendor_uff")


def _rcbtool():
    path = os.environ.get("RCBTOOL")
    if not path:
        pytest.skip("RCBTOOL is not set (path to the rcbtool executable)")
    return path


def _run(*args):
    return subprocess.run([_rcbtool(), *[str(a) for a in args]], capture_output=True,
                          text=True, timeout=120)


def test_scalar_channel_keeps_its_file_name(vendor, tmp_path: Path):
    """binary8byte.uff: one acceleration record (g) at direction 0. A signal
    verb needs no model direction (issue #35 item 2): the channel is read as
    '#1', its file name, and the message lists it; convert names it a time
    record."""
    res = _run("estimate", vendor / "binary8byte.uff", "--input", "f", "--outputs", "a",
               "-o", tmp_path / "h.csv")
    assert res.returncode == 3, res.stderr
    assert "skipped" not in res.stderr, res.stderr
    assert "binary8byte.uff: no channel 'f' in the file; it holds '#1'" in res.stderr
    res = _run("convert", vendor / "binary8byte.uff", tmp_path / "o.csv")
    assert res.returncode == 3
    assert ("record 1 is function type 1 (time response; a time record: rcbtool estimate "
            "and order read it)") in res.stderr, res.stderr
    assert not (tmp_path / "o.csv").exists()


def test_utf8_superscript_two_is_a_unit(vendor):
    """HBM catman's 'm/s²' (UTF-8) is an acceleration; before, 'not a unit
    librcb knows'. The record is scalar (direction 0): read as '#0'."""
    res = _run("estimate", vendor / "time-history-not-all-columns-filled.uff", "--input", "f",
               "--outputs", "a", "-o", "unused.csv")
    assert res.returncode == 3
    assert "not a unit" not in res.stderr, res.stderr
    assert "no channel 'f' in the file; it holds '#0'" in res.stderr, res.stderr


def test_axial_accelerometers_mapped_by_direction(vendor, tmp_path: Path):
    """MPSTD_excerpt.uff (an acquisition system's 58b export, cut to 2048
    samples by make_excerpt.py): four accelerometers on their own axis
    (direction 3, '1+Z', '2+Z', '3+Z', '1+Z' again). Before issue #35 all four
    were skipped; now they keep their file names, a map entry NODE.z names
    the model channel, and the fourth record (node 1, z again) is skipped
    with a warning (estimate: not read as hits, the counts differ)."""
    pyuff = pytest.importorskip("pyuff")
    sets = pyuff.UFF(str(vendor / "MPSTD_excerpt.uff")).read_sets()
    assert [(d["rsp_node"], d["rsp_dir"]) for d in sets] == [(1, 3), (2, 3), (3, 3), (1, 3)]
    res = _run("estimate", vendor / "MPSTD_excerpt.uff", "--input", "f", "--outputs", "a",
               "-o", tmp_path / "h.csv")
    assert res.returncode == 3
    assert "it holds '#1.z', '#2.z', '#3.z'" in res.stderr, res.stderr
    # estimate reads a channel's several records as hits when every channel has as
    # many; here only node 1 z repeats, so each channel's first record is kept
    assert ("channel '#1.z' has 2 records, '#2.z' has 1: not read as the hits of an impact "
            "test") in res.stderr, res.stderr
    res = _run("estimate", vendor / "MPSTD_excerpt.uff", "--map", "1.z=DA.x,2.z=DA.y,3=DB",
               "--input", "f", "--outputs", "a", "-o", tmp_path / "h.csv")
    assert res.returncode == 3
    assert "it holds 'DA.x', 'DA.y', 'DB.z'" in res.stderr, res.stderr
    # a channel kept under its file name is named in the FRFs only through a map
    res = _run("estimate", vendor / "MPSTD_excerpt.uff", "--input", "#1.z", "--outputs", "#2.z",
               "-o", tmp_path / "h.csv")
    assert res.returncode == 2
    assert ("channel '#1.z' keeps its file name, which is not a model channel") in res.stderr
    assert "--map 1.z=STATION.DIR" in res.stderr, res.stderr


def test_milestone_header_record_cut_short(vendor, tmp_path: Path):
    """dataset_milestone_in_header.uff (pyuff's test of a > 4 GB file's
    header): record 7 claims 2508876 samples, the file holds the first 42 and
    the closing '-1'; pyuff reads the 42. Before: "record 7 claims 2508876
    points, but the ... bytes left ... hold at most ...". The header is read
    as written (node 1, x, sound pressure in Pa); the record is named cut
    short, and --allow-truncated reads its 42 samples, as pyuff does."""
    pyuff = pytest.importorskip("pyuff")
    d = pyuff.UFF(str(vendor / "dataset_milestone_in_header.uff")).read_sets(0)
    assert d["num_pts"] == 2508876 and len(d["data"]) == 42
    args = ["estimate", vendor / "dataset_milestone_in_header.uff", "--input", "f",
            "--outputs", "a", "-o", tmp_path / "h.csv"]
    res = _run(*args)
    assert res.returncode == 3
    assert ("dataset_milestone_in_header.uff:9: dataset 58 record 1 ('#1.x'): record 7 claims "
            "2508876 samples, but the record holds 42 before its closing '-1'") in res.stderr
    assert "--allow-truncated" in res.stderr, res.stderr
    res = _run(*args, "--allow-truncated")
    assert res.returncode == 3
    assert "record 7 claims 2508876 samples, the record holds 42: read cut short" in res.stderr
    assert "no channel 'f' in the file; it holds '#1.x'" in res.stderr, res.stderr


def test_psd_refusal_names_the_function_type(vendor, tmp_path: Path):
    for cmd in (["convert", vendor / "sample_dataset58_psd.uff", tmp_path / "o.csv"],
                ["estimate", vendor / "sample_dataset58_psd.uff", "--input", "f", "--outputs",
                 "a", "-o", tmp_path / "o.csv"]):
        res = _run(*cmd)
        assert res.returncode == 3
        assert ("record 1 is function type 9 (power spectral density; no rcbtool command "
                "reads it)") in res.stderr, res.stderr


def _front_end(path, fs, n, seed=11):
    """Node 2 x force (N), node 1 x response (g), node 1 y response
    (labelled 'furlong', data type 8: mm in truth), node 1 z (axial, m/s²
    Latin-1), node 5 scalar acceleration (direction 0)."""
    pyuff = pytest.importorskip("pyuff")
    rng = np.random.default_rng(seed)
    f = 10.0 * rng.standard_normal(n)
    b, a = signal.iirpeak(120.0, 6.0, fs=fs)
    ax = signal.lfilter(b, a, f) * 0.2 + 0.01 * rng.standard_normal(n)  # g
    dy = signal.lfilter(b, a, f) * 1e-3 + 1e-5 * rng.standard_normal(n)  # "furlong" (mm)
    az = rng.standard_normal(n)
    sc = rng.standard_normal(n)
    rows = [(2, 1, f, 13, "N"), (1, 1, ax, 12, "g"), (1, 2, dy, 8, "furlong"),
            (1, 3, az, 12, "m/s\u00b2"), (5, 0, sc, 12, "m/s2")]
    sets = [pyuff.prepare_58(func_type=1, rsp_node=node, rsp_dir=d, ref_node=0, ref_dir=0,
                             data=x, x=np.arange(n) / fs, abscissa_spec_data_type=17,
                             ordinate_spec_data_type=typ, ordinate_axis_units_lab=lab,
                             orddenom_spec_data_type=0, z_axis_spec_data_type=0, binary=0)
            for node, d, x, typ, lab in rows]
    # ASCII: pyuff 2.5.8 drops the first set of a binary (58b) write
    pyuff.UFF(str(path)).write_sets(sets, mode="overwrite")
    back = [d for d in pyuff.UFF(str(path)).read_sets() if "data" in d]
    assert len(back) == len(rows)
    return back[0]["data"].real, back[2]["data"].real * 1e-3


def test_front_end_recording_reads_what_the_model_uses(tmp_path: Path):
    fs, n = 1024.0, 16384
    path = tmp_path / "fe.uff"
    fm, dm = _front_end(path, fs, n)
    args = ["estimate", path, "--map", "1=DA,2=DB", "--input", "DB.x=DA.x", "--outputs",
            "DA.y", "--nseg", "512"]
    res = _run(*args, "-o", tmp_path / "h.csv")
    assert res.returncode == 3
    assert "units label 'furlong' of channel 'DA.y' is not one librcb knows" in res.stderr
    # the known units of its data type's quantity are listed
    assert "(displacement, as its data type says: m, mm, um, mil, in" in res.stderr
    assert "--units 'DA.y=UNIT'" in res.stderr, res.stderr
    res = _run(*args, "--units", "DA.y=mm", "--stats", tmp_path / "s.csv",
               "-o", tmp_path / "h.csv")
    assert res.returncode == 0, res.stderr
    assert "warning:" not in res.stderr, res.stderr  # z and the scalar kept, not used
    kw = dict(fs=fs, window="hann", nperseg=512, noverlap=256)
    _, pxx = signal.welch(fm, **kw)
    _, pxy = signal.csd(fm, dm, **kw)
    rows = [ln.split(",") for ln in open(tmp_path / "h.csv") if ln[0].isdigit()]
    head = [ln for ln in open(tmp_path / "h.csv") if ln.startswith("freq")][0].strip().split(",")
    h = np.array([[float(v) for v in r] for r in rows])
    got = h[:, head.index("DA.y/DA.x re")] + 1j * h[:, head.index("DA.y/DA.x im")]
    ref = (pxy / pxx)[1:]
    err = np.max(np.abs(got - ref)) / np.max(np.abs(ref))
    print(f"front-end recording, DA.y in mm by --units: H1 vs SciPy {err:.2e}")
    assert err < 1e-10


def test_frf_of_scalar_channels_is_skipped_with_the_reason(vendor, tmp_path: Path):
    """An FRF between two direction-0 channels: the model has no such channel;
    the message gives file:line and the direction (before: 'unknown response
    direction code 0', as for a corrupt file)."""
    res = _run("convert", vendor / "non_ascii_header.uff", tmp_path / "o.csv")
    assert res.returncode == 3
    assert ("non_ascii_header.uff:8: dataset 58 record 1: its response is scalar "
            "(direction 0)") in res.stderr, res.stderr
    assert not (tmp_path / "o.csv").exists()


def _frf_other_directions(path):
    """Three FRFs as an acquisition system exports them (written by pyuff, an
    independent writer; stand-ins with the corpus's field values): the force
    at node 2 is scalar (direction 0), the responses node 1 z (direction 3),
    node 1 -z (direction -3) and node 1 x, inertance in (m/s^2)/N."""
    pyuff = pytest.importorskip("pyuff")
    f = np.linspace(10.0, 200.0, 20)
    w = 2 * np.pi * f
    h = -w**2 / (1e5 - 2.0 * w**2 + 1j * 30.0 * w)  # inertance of a 2 kg oscillator
    rows = [(1, 3, h), (1, 1, 0.5 * h), (3, -3, 0.25 * h)]
    sets = [pyuff.prepare_58(func_type=4, rsp_node=node, rsp_dir=d, ref_node=2, ref_dir=0,
                             data=y, x=f, abscissa_spec_data_type=18,
                             ordinate_spec_data_type=12, orddenom_spec_data_type=13,
                             z_axis_spec_data_type=0, binary=0)
            for node, d, y in rows]
    pyuff.UFF(str(path)).write_sets(sets, mode="overwrite")
    return f, h


def _csv_channels(path):
    head = [ln for ln in open(path) if ln.startswith("freq")][0].strip().split(",")
    rows = np.array([[float(v) for v in ln.split(",")] for ln in open(path) if ln[0].isdigit()])
    return {head[k][:-3]: rows[:, k] + 1j * rows[:, k + 1] for k in range(1, len(head), 2)}


def test_frf_of_other_directions_read_through_the_map(tmp_path: Path):
    """Item 2 of issue #35: an FRF whose response is an accelerometer's own z
    and whose reference is scalar reads as the model channels the map entries
    name ("1.z=DA.y", "2.s=DB.x"; a negative direction flips the sign as
    always); without them each record is skipped with a warning naming the
    entry that would read it."""
    path = tmp_path / "fe.uff"
    _, h = _frf_other_directions(path)
    res = _run("convert", path, tmp_path / "o.csv", "--map", "1=DA,2=DB")
    assert res.returncode == 3
    assert ("fe.uff:8: dataset 58 record 1: skipped: its response (node 1) is axial (direction "
            "3, z); the model's channels are x, y, rx, ry: the map entry 1.z=DA.DIR (DIR one of "
            "them; rcbtool --map) would read it") in res.stderr, res.stderr
    assert "its reference (node 2) is scalar (direction 0)" in res.stderr
    assert "the map entry 2.s=DB.DIR" in res.stderr, res.stderr
    assert "a map entry NODE.DIR=STATION.DIR, e.g. rcbtool --map 1.z=DA.x" in res.stderr
    res = _run("convert", path, tmp_path / "o.csv", "--map", "1=DA,1.z=DA.y,2.s=DB.x,3.z=C.A.x")
    assert res.returncode == 0, res.stderr
    assert "skipped" not in res.stderr, res.stderr
    got = _csv_channels(tmp_path / "o.csv")
    assert sorted(got) == ["C.A.x/DB.x", "DA.x/DB.x", "DA.y/DB.x"]
    assert np.allclose(got["DA.y/DB.x"], h, rtol=1e-5)
    assert np.allclose(got["DA.x/DB.x"], 0.5 * h, rtol=1e-5)
    assert np.allclose(got["C.A.x/DB.x"], -0.25 * h, rtol=1e-5)  # direction -3: sign flipped
    # written back as UFF, the entries give the nodes and directions of the file
    res = _run("convert", tmp_path / "o.csv", tmp_path / "back.uff", "--map",
               "1=DA,1.z=DA.y,2.s=DB.x,3.z=C.A.x")
    assert res.returncode == 0, res.stderr
    pyuff = pytest.importorskip("pyuff")
    back = sorted((d["rsp_node"], d["rsp_dir"], d["ref_node"], d["ref_dir"])
                  for d in pyuff.UFF(str(tmp_path / "back.uff")).read_sets())
    assert back == [(1, 1, 2, 0), (1, 3, 2, 0), (3, 3, 2, 0)], back


@pytest.mark.parametrize("entry, said", [
    ("1.q=DA.x", "file direction 'q': expected x, y, z, rx, ry, rz (UFF 1 to 6) or s"),
    ("1.z=DA.z", "model direction 'z': expected x, y, rx or ry"),
    ("1.z=DA", "expected NODE.DIR=STATION.DIR (e.g. 1.z=DA.x)"),
    ("1.z=DA.x,1.z=DB.x", "1.z appears twice"),
    ("1.z=DA.x,2.s=DA.x", "1.z and 2.s both map to DA.x"),
    ("x.z=DA.x", "the UFF node must be a whole number"),
])
def test_map_entry_refusals(tmp_path: Path, entry, said):
    path = tmp_path / "fe.uff"
    _frf_other_directions(path)
    res = _run("convert", path, tmp_path / "o.csv", "--map", entry)
    assert res.returncode == 2, res.stderr
    assert said in res.stderr, res.stderr


def test_front_end_scalar_channel_mapped(tmp_path: Path):
    """The scalar accelerometer of the front-end recording (node 5, direction
    0; skipped before issue #35) read through the map entry 5.s=DB.y: its H1
    against the force is SciPy's from the values pyuff reads back."""
    pyuff = pytest.importorskip("pyuff")
    fs, n = 1024.0, 16384
    path = tmp_path / "fe.uff"
    _front_end(path, fs, n)
    back = [d for d in pyuff.UFF(str(path)).read_sets() if "data" in d]
    fm, sc = back[0]["data"].real, back[4]["data"].real
    res = _run("estimate", path, "--map", "1=DA,2=DB,5.s=DB.y", "--input", "DB.x=DA.x",
               "--outputs", "DB.y", "--nseg", "512", "--units", "DA.y=mm",
               "-o", tmp_path / "h.csv")
    assert res.returncode == 0, res.stderr
    kw = dict(fs=fs, window="hann", nperseg=512, noverlap=256)
    _, pxx = signal.welch(fm, **kw)
    _, pxy = signal.csd(fm, sc, **kw)
    got = _csv_channels(tmp_path / "h.csv")["DB.y/DA.x"]
    ref = (pxy / pxx)[1:]
    err = np.max(np.abs(got - ref)) / np.max(np.abs(ref))
    print(f"front-end scalar channel through 5.s=DB.y: H1 vs SciPy {err:.2e}")
    assert err < 1e-10
