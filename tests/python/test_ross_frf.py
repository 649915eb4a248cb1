"""FRFs at a fixed rotor speed: `rcbtool frf --rpm` against ROSS's
Rotor.transfer_matrix(speed, frequency) (NOT run_freq_response, which spins
the rotor at the excitation frequency), compared as complex numbers."""

import math

import numpy as np
import pytest

RTOL = 1e-6  # relative, on each complex value; never loosen


def _sweep(case):
    # avoid 0 Hz: ROSS's axial/torsional rigid-body modes make it singular there
    if case.name == "paper_system" or case.name == "paper_freefree":
        return 2.0, 600.0, 61
    return 5.0, 1500.0, 61


def _compare(case, rcbtool, record, extra, speed_of, label, kind="receptance"):
    outs, ins = case.channels()
    fmin, fmax, npts = _sweep(case)
    res = rcbtool(
        "frf", case.path, "--out", ",".join(outs), "--in", ",".join(ins),
        "--fmin", fmin, "--fmax", fmax, "--points", npts, "--kind", kind, *extra,
    )
    freq = np.asarray(res["freq_hz"])
    expect = fmin + np.arange(npts) * (fmax - fmin) / (npts - 1)
    np.testing.assert_allclose(freq, expect, rtol=1e-12)
    assert res["kind"] == kind
    assert len(res["channels"]) == len(outs) * len(ins)
    worst = (0.0, None)
    for i, f in enumerate(freq):
        w = 2 * math.pi * f
        s = speed_of(w)
        rmod = case.ross(s)
        H = case.transfer(s, w)
        fac = {"receptance": 1.0, "mobility": 1j * w, "inertance": -(w**2)}[kind]
        for ch in res["channels"]:
            h = complex(ch["re"][i], ch["im"][i])
            jin = rmod.station_dof(ch["input"])
            ref = fac * H[rmod.station_dof(ch["output"]), jin]
            if ref == 0:
                # exactly uncoupled pair (x-y at standstill, isotropic parts):
                # measured against the largest response to the same input
                rel = abs(h) / abs(fac * H[rmod.lateral_dofs(), jin]).max()
            else:
                rel = abs(h - ref) / abs(ref)
            if rel > worst[0]:
                worst = (rel, (ch["output"], ch["input"], f, h, ref))
    record(case, label, worst[0])
    assert worst[0] <= RTOL, (
        f"{label}: worst relative difference {worst[0]:.3e} at "
        f"{worst[1][0]}/{worst[1][1]}, {worst[1][2]} Hz: ours {worst[1][3]}, ROSS {worst[1][4]}"
    )


def test_frf_fixed_speed(case, rcbtool, record):
    _compare(case, rcbtool, record, ["--rpm", case.rpm], lambda w: case.speed, "FRF fixed speed")


def test_frf_standstill(case, rcbtool, record):
    _compare(case, rcbtool, record, ["--rpm", 0], lambda w: 0.0, "FRF standstill")


def test_frf_synchronous(case, rcbtool, record):
    _compare(case, rcbtool, record, ["--synchronous"], lambda w: w, "FRF synchronous")


@pytest.mark.parametrize("kind", ["mobility", "inertance"])
def test_frf_kinds(case, rcbtool, record, kind):
    _compare(case, rcbtool, record, ["--rpm", case.rpm], lambda w: case.speed, f"FRF {kind}", kind)
