"""One run-up through the first critical speed: `rcbtool transient` (CVODE BDF,
librcb) against ROSS's run_time_response (Newmark, average acceleration) on
the paper system, both from rest, the same speed ramp and unbalance forcing
(ROSS's unbalance_force_over_time: me (W^2 cos + alpha sin), as librcb).

librcb's equation of motion is M q'' + (C + W G) q' + K q = f: it has no
angular-acceleration stiffness alpha Ksdt, which ROSS adds in run-ups, so
ROSS runs here with Ksdt = 0 (same equations, two integrators).
Measured: max difference 2.2e-4 of the peak amplitude; ~17 s (ROSS's Newmark).
"""

import math
import warnings

import numpy as np
import ross_models as rm

RPM0, RPM1, ACCEL = 8000.0, 10500.0, 4800.0  # rpm, rpm, rad/s^2
DT_ROSS = 1e-5  # s, Newmark step
DT_OUT = 1e-4  # s, samples compared
TOL = 2e-3  # of the peak amplitude (measured 2.2e-4: Newmark's period error)


def test_runup_against_ross(rcbtool, tmp_path):
    text = rm.PAPER_SYSTEM_INI
    path = tmp_path / "paper.ini"
    path.write_text(text)
    w0, w1 = RPM0 * math.pi / 30.0, RPM1 * math.pi / 30.0
    t_end = (w1 - w0) / ACCEL
    res = rcbtool(
        "transient", path, "--out", "DA.x,DA.y", "--rpm", RPM0, "--rpm-end", RPM1,
        "--accel", ACCEL * 30.0 / math.pi, "--dt", DT_OUT, "--rtol", 1e-8,
    )
    t_ours = np.asarray(res["t"])
    ours = {ch["output"]: np.asarray(ch["q"]) for ch in res["channels"]}

    model = rm.Model(text)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rmod = rm.RossModel(model, speed=0.5 * (w0 + w1))
    rotor = rmod.rotor
    n = int(round(t_end / DT_ROSS))
    t = np.linspace(0.0, n * DT_ROSS, n + 1)
    speed = w0 + ACCEL * t
    nodes, mags, phases = rmod.unbalance_args()
    F = rotor.unbalance_force_over_time(nodes, mags, phases, speed, t).T
    zero = np.zeros((rotor.ndof, rotor.ndof))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        resp = rotor.run_time_response(speed, F, t, Ksdt=zero)
    yout = np.asarray(resp.yout)
    step = int(round(DT_OUT / DT_ROSS))
    k = min(len(t_ours), yout[::step].shape[0])
    np.testing.assert_allclose(t_ours[:k], t[::step][:k], atol=1e-9)
    worst = 0.0
    for ch in ("DA.x", "DA.y"):
        ref = yout[::step, rmod.station_dof(ch)][:k]
        err = np.max(np.abs(ours[ch][:k] - ref)) / np.max(np.abs(ref))
        worst = max(worst, err)
        # the peak of the envelope and where it happens
        assert abs(np.max(np.abs(ours[ch][:k])) / np.max(np.abs(ref)) - 1) < TOL, ch
    print(f"run-up {RPM0:g}-{RPM1:g} rpm at {ACCEL:g} rad/s^2: max difference "
          f"{worst:.3e} of the peak (DA.x, DA.y)")
    assert worst < TOL
