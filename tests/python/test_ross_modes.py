"""Damped modes at a speed: `rcbtool modes --rpm` against ROSS's run_modal
(lateral roots only; see ross_models.lateral_roots).

Each librcb mode must match a ROSS root (wd, logdec, wn, zeta to 1e-6
relative; whirl where ROSS calls it forward or backward, i.e. every node's
orbit turns that way), and no ROSS root that passes librcb's documented
filters (Im > 1e-7 max|lambda|, zeta <= --max-zeta) may be missing below the
highest librcb frequency. Run with --max-zeta 1 (every root, as ROSS) and with
the CLI default 0.99."""

import numpy as np
import pytest

import ross_models as rm

RTOL = 1e-6  # relative; never loosen
NMODES = 40


@pytest.mark.parametrize("max_zeta", [1.0, 0.99])
def test_damped_modes(case, rcbtool, record, max_zeta):
    res = rcbtool("modes", case.path, "--rpm", case.rpm, "--modes", NMODES,
                  "--max-zeta", max_zeta)
    modes = res["modes"]
    ross, big, ross_whirl = rm.lateral_roots(case.ross(), case.speed, whirl=True)
    floor = rm.IM_FLOOR * big
    wanted = (rm.zeta_of(ross) <= max_zeta) & (ross.imag > floor)
    # roots within a factor 2 of the floor may fall either side of it
    sure = wanted & (ross.imag > 2 * floor)
    assert int(sure.sum()) > 0
    assert min(NMODES, int(sure.sum())) <= len(modes) <= min(NMODES, int(wanted.sum()) + 1)
    worst_wd = worst_ld = worst_lam = 0.0
    used, whirl_checked = set(), 0
    for m in modes:
        lam = complex(m["re"], m["im"])
        k = int(np.argmin(np.abs(ross - lam)))
        assert k not in used, f"two librcb modes match ROSS root {ross[k]}"
        used.add(k)
        ref = ross[k]
        worst_lam = max(worst_lam, abs(lam - ref) / abs(ref))
        wd = abs(m["wd"] - ref.imag) / ref.imag
        ld = abs(m["logdec"] - rm.logdec_of(ref)) / abs(rm.logdec_of(ref))
        worst_wd, worst_ld = max(worst_wd, wd), max(worst_ld, ld)
        assert wd <= RTOL, f"wd {m['wd']} vs ROSS {ref.imag} ({wd:.3e})"
        assert ld <= RTOL, f"logdec {m['logdec']} vs ROSS {rm.logdec_of(ref)} ({ld:.3e})"
        assert abs(m["fd_hz"] - ref.imag / (2 * np.pi)) <= RTOL * m["fd_hz"]
        assert abs(m["wn"] - abs(ref)) <= RTOL * abs(ref)
        assert abs(m["zeta"] - rm.zeta_of(ref)) <= RTOL * abs(rm.zeta_of(ref))
        assert m["zeta"] <= max_zeta
        if ross_whirl[k] in ("forward", "backward"):
            assert m["whirl"] == ross_whirl[k], (
                f"mode wd {m['wd']}: whirl {m['whirl']}, ROSS {ross_whirl[k]}"
            )
            whirl_checked += 1
    top = max(m["wd"] for m in modes)
    missing = [k for k in np.flatnonzero(sure) if ross[k].imag < top * (1 - 1e-6) and k not in used]
    assert not missing, f"ROSS roots missing from rcbtool: {ross[missing]}"
    assert whirl_checked > 0
    tag = "" if max_zeta == 1.0 else f" (max-zeta {max_zeta})"
    record(case, "modes wd" + tag, worst_wd)
    record(case, "modes logdec" + tag, worst_ld)
    record(case, "modes eigenvalue" + tag, worst_lam)
