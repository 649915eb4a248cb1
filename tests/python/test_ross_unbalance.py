"""Unbalance response over a speed range: `rcbtool unbalance` against ROSS's
run_unbalance_response(node, magnitude, phase, frequency), complex values."""

import math

import numpy as np
import pytest

RTOL = 1e-6  # relative, on each complex value; never loosen


def test_unbalance_response(case, rcbtool, record):
    if not case.model.unbalances:
        pytest.skip("model has no unbalance")
    outs, _ = case.channels()
    lo, hi, npts = 300.0, 2.0 * case.rpm, 41  # rpm; > 0 (ROSS is singular at 0)
    res = rcbtool(
        "unbalance", case.path, "--out", ",".join(outs),
        "--rpm-min", lo, "--rpm-max", hi, "--points", npts,
    )
    rpm = np.asarray(res["rpm"])
    np.testing.assert_allclose(rpm, lo + np.arange(npts) * (hi - lo) / (npts - 1), rtol=1e-12)
    assert [ch["output"] for ch in res["channels"]] == outs
    speeds = rpm * math.pi / 30.0
    rmod = case.ross()
    nodes, mags, phases = rmod.unbalance_args()
    if case.tabulated:
        # bearing coefficients change with speed: one ROSS rotor per speed,
        # its bearings interpolated linearly (ROSS itself would fit a spline)
        resp = np.column_stack([
            case.ross(s).rotor.run_unbalance_response(
                nodes, mags, phases, frequency=np.array([s])
            ).forced_resp[:, 0]
            for s in speeds
        ])
    else:
        resp = rmod.rotor.run_unbalance_response(nodes, mags, phases, frequency=speeds).forced_resp
    worst = (0.0, None)
    for ch in res["channels"]:
        ours = np.asarray(ch["re"]) + 1j * np.asarray(ch["im"])
        ref = resp[rmod.station_dof(ch["output"]), :]
        rel = np.abs(ours - ref) / np.abs(ref)
        k = int(np.argmax(rel))
        if rel[k] > worst[0]:
            worst = (rel[k], (ch["output"], rpm[k], ours[k], ref[k]))
        # amplitude and phase columns describe the same phasor
        np.testing.assert_allclose(ch["amp"], np.abs(ref), rtol=RTOL, atol=0)
        dphi = np.angle(np.exp(1j * (np.radians(ch["phase_deg"]) - np.angle(ref))))
        assert np.abs(dphi).max() <= RTOL * 2 * math.pi, ch["output"]
    record(case, "unbalance response", worst[0])
    assert worst[0] <= RTOL, (
        f"worst relative difference {worst[0]:.3e} at {worst[1][0]}, {worst[1][1]} rpm: "
        f"ours {worst[1][2]}, ROSS {worst[1][3]}"
    )
