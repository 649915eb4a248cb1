"""Campbell data: `rcbtool campbell` (the first N damped modes by increasing
frequency, at each speed) against ROSS's run_modal at the same speeds, lateral
roots only (ross_models.lateral_roots), with --max-zeta 1 (every root, as
ROSS). The 1X critical speeds are linear interpolations on rcbtool's own speed
grid, so they are checked for consistency with the (ROSS-checked) curves, not
against ROSS's critical-speed search."""

import math

import numpy as np

import ross_models as rm

RTOL = 1e-6  # relative; never loosen
NMODES = 30


def test_campbell(case, rcbtool, record):
    lo, hi, npts = 500.0, 2.0 * case.rpm, 4
    res = rcbtool(
        "campbell", case.path, "--rpm-min", lo, "--rpm-max", hi, "--points", npts,
        "--modes", NMODES, "--max-zeta", 1,
    )
    rpm = np.asarray(res["rpm"], dtype=float)
    np.testing.assert_allclose(rpm, lo + np.arange(npts) * (hi - lo) / (npts - 1), rtol=1e-12)
    worst_f = worst_ld = 0.0
    for i, n in enumerate(rpm):
        s = n * math.pi / 30.0
        ref, big, _ = rm.lateral_roots(case.ross(s), s)
        n_sure = int(np.sum(ref.imag > 2 * rm.IM_FLOOR * big))  # see test_ross_modes.py
        n_wanted = int(np.sum(ref.imag > rm.IM_FLOOR * big))
        fd = [v for v in res["fd_hz"][i] if v is not None]
        ld = [v for v in res["logdec"][i] if v is not None]
        assert min(NMODES, n_sure) <= len(fd) <= min(NMODES, n_wanted + 1)
        for j, (f, d) in enumerate(zip(fd, ld)):
            lam = ref[int(np.argmin(np.abs(ref.imag - 2 * math.pi * f)))]
            ld_ref = rm.logdec_of(lam)
            ef = abs(f - lam.imag / (2 * math.pi)) / (lam.imag / (2 * math.pi))
            ed = abs(d - ld_ref) / abs(ld_ref)
            worst_f, worst_ld = max(worst_f, ef), max(worst_ld, ed)
            assert ef <= RTOL, f"{n} rpm mode {j + 1}: fd {f} Hz, ROSS {lam.imag / 2 / math.pi}"
            assert ed <= RTOL, f"{n} rpm mode {j + 1}: logdec {d}, ROSS {ld_ref}"
    record(case, "campbell fd", worst_f)
    record(case, "campbell logdec", worst_ld)
    # each 1X crossing lies between two grid speeds where wd - Omega changes sign
    fd = np.array([[np.nan if v is None else v for v in row] for row in res["fd_hz"]])
    for c, m in zip(res["critical_rpm"], res["critical_mode"]):
        g = fd[:, m - 1] * 60.0 - rpm  # rpm units
        k = np.searchsorted(rpm, c) - 1
        k = min(max(k, 0), npts - 2)
        assert g[k] * g[k + 1] <= 0
        expect = rpm[k] + (rpm[k + 1] - rpm[k]) * g[k] / (g[k] - g[k + 1])
        assert abs(c - expect) <= 1e-9 * expect
