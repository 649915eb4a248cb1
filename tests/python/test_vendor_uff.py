"""Vendor UFF files (issue #25 item 1): what librcb reads of them, what it
skips and why, and the refusals that name the function type and the verb.

tests/data/vendor_uff holds real files from pyuff's test data (MIT; its
README says what each exercises). A 5-channel recording of an acquisition
front end is written here by pyuff (an independent writer): force and two responses in
x and y, one axial (direction 3) and one scalar (direction 0) accelerometer,
one response labelled in a unit librcb does not know.
"""

import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

signal = pytest.importorskip("scipy.signal")

DATA = Path(__file__).resolve().parent.parent / "data" / "vendor_uff"


def _rcbtool():
    path = os.environ.get("RCBTOOL")
    if not path:
        pytest.skip("RCBTOOL is not set (path to the rcbtool executable)")
    return path


def _run(*args):
    return subprocess.run([_rcbtool(), *[str(a) for a in args]], capture_output=True,
                          text=True, timeout=120)


def test_scalar_channel_is_skipped_not_read_as_keyphasor(tmp_path: Path):
    """binary8byte.uff: one acceleration record (g) at direction 0. It is
    skipped with a warning that says why (it was read as a bare-station
    channel, a keyphasor's form), and convert names it a time record."""
    res = _run("estimate", DATA / "binary8byte.uff", "--input", "f", "--outputs", "a",
               "-o", tmp_path / "h.csv")
    assert res.returncode == 3, res.stderr
    assert "record 1 ('#1', acceleration): skipped: scalar (direction 0)" in res.stderr
    assert "no usable time record: all 1 were skipped" in res.stderr
    res = _run("convert", DATA / "binary8byte.uff", tmp_path / "o.csv")
    assert res.returncode == 3
    assert ("record 1 is function type 1 (time response; a time record: rcbtool estimate "
            "and order read it)") in res.stderr, res.stderr
    assert not (tmp_path / "o.csv").exists()


def test_utf8_superscript_two_is_a_unit():
    """HBM catman's 'm/s²' (UTF-8) is an acceleration; before, 'not a unit
    librcb knows'. The record is scalar (direction 0), so skipped."""
    res = _run("estimate", DATA / "time-history-not-all-columns-filled.uff", "--input", "f",
               "--outputs", "a", "-o", "unused.csv")
    assert res.returncode == 3
    assert "not a unit" not in res.stderr, res.stderr
    assert "('#0', acceleration): skipped: scalar (direction 0)" in res.stderr, res.stderr


def test_psd_refusal_names_the_function_type(tmp_path: Path):
    for cmd in (["convert", DATA / "sample_dataset58_psd.uff", tmp_path / "o.csv"],
                ["estimate", DATA / "sample_dataset58_psd.uff", "--input", "f", "--outputs",
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
    assert "('DA.z', acceleration): skipped: axial (direction 3, z)" in res.stderr
    assert "('#5', acceleration): skipped: scalar (direction 0)" in res.stderr
    assert res.stderr.count("warning:") == 2, res.stderr
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


def test_frf_of_scalar_channels_is_skipped_with_the_reason(tmp_path: Path):
    """An FRF between two direction-0 channels: the model has no such channel;
    the message gives file:line and the direction (before: 'unknown response
    direction code 0', as for a corrupt file)."""
    res = _run("convert", DATA / "non_ascii_header.uff", tmp_path / "o.csv")
    assert res.returncode == 3
    assert ("non_ascii_header.uff:8: dataset 58 record 1: its response is scalar "
            "(direction 0)") in res.stderr, res.stderr
    assert not (tmp_path / "o.csv").exists()
