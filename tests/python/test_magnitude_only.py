"""Magnitude-only data (issue #35 item 4): a CSV with 'CH mag' (or 'CH dB')
columns and no phase is read as channels of magnitudes only; fit, compare and
diagnose run on the magnitude scales, and what needs the phase refuses the
file (fit --scale complex, the monitor) or leaves its part out and says so
(diagnose's placement; compare's FRAC, phase error, CSAC/CSF).

The data: inertances of the ROSS rotor (diag_cases.ross_inertance, checked
against ROSS's transfer matrix) with the paper's eq. 19 noise, written by
numpy twice: re/im columns, and the magnitudes alone. On the log10 scale the
objective uses |H| only, so the fits of the two files must agree to rounding.
"""

import json
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

import diag_cases as dc


def _rcbtool():
    path = os.environ.get("RCBTOOL")
    if not path:
        pytest.skip("RCBTOOL is not set (path to the rcbtool executable)")
    return path


def _run(*args):
    return subprocess.run([_rcbtool(), *[str(a) for a in args]], capture_output=True,
                          text=True, timeout=600)


def _write(path, H, form):
    """numpy.savetxt of the inertances: form 're' (re/im), 'mag' or 'dB'."""
    names = [f"{o}/{dc.IN}" for o in dc.OUTS]
    if form == "re":
        cols = [c for h in H for c in (h.real, h.imag)]
        head = [f"{n} {p}" for n in names for p in ("re", "im")]
    elif form == "mag":
        cols, head = [np.abs(h) for h in H], [f"{n}_mag" for n in names]
    else:
        cols, head = [20 * np.log10(np.abs(h)) for h in H], [f"{n} dB" for n in names]
    np.savetxt(path, np.column_stack([dc.FREQ_HZ, *cols]), delimiter=",", fmt="%.17g",
               header=f"# kind = inertance\n# rpm = {dc.RPM:g}\nfreq_hz," + ",".join(head),
               comments="")


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("magonly")
    H = dc.add_noise(dc.ross_inertance(dc.BASE_INI), *dc.NOISE, seed=3)
    model = tmp / "model.ini"
    model.write_text(dc.model_ini())
    out = {"model": model, "H": H}
    for form in ("re", "mag", "dB"):
        out[form] = tmp / f"meas_{form}.csv"
        _write(out[form], H, form)
    return out


def _fit(files, meas, *extra):
    res = _run("fit", files["model"], meas, "--params", dc.FIT_PARAMS, "--json", *extra)
    assert res.returncode == 0, res.stderr
    return json.loads(res.stdout)


def _values(fit):
    return np.array([p["fitted"] for p in fit["params"]])


@pytest.mark.parametrize("scale", ["log10", "linear", "db"])
def test_fit_on_magnitudes_equals_the_complex_file(files, scale):
    full = _fit(files, files["re"], "--scale", scale)
    mag = _fit(files, files["mag"], "--scale", scale)
    a, b = _values(full), _values(mag)
    rel = np.max(np.abs(a - b) / np.abs(a))
    print(f"--scale {scale}: fitted {a} (re/im) vs {b} (mag only): max rel diff {rel:.1e}; "
          f"error {full['error_pct']:.6g} % vs {mag['error_pct']:.6g} %")
    assert rel < 1e-9, (a, b)
    assert abs(full["error_pct"] - mag["error_pct"]) < 1e-9 * full["error_pct"]


def test_db_columns_read_as_magnitudes(files):
    a, b = _values(_fit(files, files["mag"], "--scale", "log10")), \
        _values(_fit(files, files["dB"], "--scale", "log10"))
    assert np.max(np.abs(a - b) / np.abs(a)) < 1e-9, (a, b)


def test_complex_scale_refused(files):
    res = _run("fit", files["model"], files["mag"], "--params", dc.FIT_PARAMS, "--scale",
               "complex")
    assert res.returncode == 2, res.stderr
    assert f"'{files['mag']}' holds magnitudes only (8 of 8 channels" in res.stderr, res.stderr
    assert "--scale complex (Re and Im) needs the phase" in res.stderr
    assert "fit on --scale log10, linear or db" in res.stderr
    res = _run("diagnose", files["model"], files["mag"], "--params", dc.FIT_PARAMS, "--scale",
               "complex", "--log")
    assert res.returncode == 2
    assert "--scale complex (Re and Im) needs the phase" in res.stderr, res.stderr


def test_compare_on_magnitudes(files):
    full = json.loads(_run("compare", files["model"], files["re"], "--json").stdout)
    res = _run("compare", files["model"], files["mag"], "--json")
    assert res.returncode == 0, res.stderr
    mag = json.loads(res.stdout)
    for key in ("error_pct", "log_rms"):
        assert mag["summary"][key] == pytest.approx(full["summary"][key], rel=1e-12), key
    assert mag["summary"]["phase_rms_deg"] is None and mag["summary"]["frac_mean"] is None
    assert full["summary"]["phase_rms_deg"] is not None
    res = _run("compare", files["model"], files["mag"])
    assert res.returncode == 0, res.stderr
    assert "magnitudes only" in res.stdout + res.stderr, res.stdout


def test_diagnose_says_placement_needs_phase(files):
    res = _run("diagnose", files["model"], files["mag"], "--params", dc.FIT_PARAMS, "--log",
               "--noise", f"{dc.NOISE[0]:g},{dc.NOISE[1]:g}", "--json")
    assert res.returncode == 0, res.stderr
    d = json.loads(res.stdout)
    assert ("placement fits equivalent loads on the complex scale and so needs the phase, and 8 "
            "of the 8 measured channels hold magnitudes only") in d["explanation"], d["explanation"]


def test_monitor_and_uff_refuse(files, tmp_path: Path):
    res = _run("convert", files["mag"], tmp_path / "o.uff")
    assert res.returncode != 0
    assert "holds magnitudes only: a dataset 58 FRF record is complex" in res.stderr, res.stderr
    assert not (tmp_path / "o.uff").exists()
    res = _run("convert", files["mag"], tmp_path / "o.csv")  # CSV keeps them: mag columns
    assert res.returncode == 0, res.stderr
    head = [ln for ln in open(tmp_path / "o.csv") if ln.startswith("freq_hz")][0]
    assert head.strip().split(",")[1] == "DA.x/DA.x mag"
