#!/usr/bin/env python3
"""Where the monitor's noise sds are taken, measured (issue #34 item 1: the
probes' gains at the users' size).

Truth: monitor_replicas.py's ROSS null inertances (32 channels x 1101 lines,
cached by a run of it in --truth-dir), optionally thinned to --lines lines and
--channels; noise drawn here by numpy in eq. 19's form (10 %, 1 % unless
--ba/--bs), the reference the average of --navg files (inf: the clean truth).

--numpy: no monitor. Each probe's gain direction (its column is the model's
values on its channels), whitened by eq. 19's declared sds taken at the
commissioning values (as the monitor did before) or at the truth, and the
x^2 of the whitened change along it, averaged over --commissionings
commissionings x 5 updates (expected 1).

Without --numpy: librcb.Monitor (kt, kr, ct tracked, alpha 0.01, --reweight
unless --plain, --relinearise 8, the gains unless --no-sensors) on one
commissioning and --updates null updates: the instant test's mean T against
its degrees of freedom and its alarms.

    OPENBLAS_NUM_THREADS=1 LIBRCB_PATH=build/src/librcb.so \\
      .venv/bin/python tools/bench/monitor_noise_weights.py --numpy [--lines 400] [--navg 40]
    ... tools/bench/monitor_noise_weights.py --navg 1 --lines 400 --channels 0-7 --seed 5200
"""

import argparse
import json
import math
import os
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "tests" / "python"))
sys.path.insert(0, str(REPO / "tools" / "python"))
sys.path.insert(0, str(REPO / "tools" / "bench"))


def noise(H, ba, bs, rng):
    """Eq. 19: H (1 + ba r1) + ||H_c|| / n bs r2 e^{i phi}, r1, r2 uniform in [-1, 1]."""
    level = np.sqrt(np.sum(np.abs(H) ** 2, axis=1, keepdims=True)) / H.shape[1]
    r1, r2 = rng.uniform(-1, 1, H.shape), rng.uniform(-1, 1, H.shape)
    return H * (1 + ba * r1) + level * bs * r2 * np.exp(2j * math.pi * rng.uniform(0, 1, H.shape))


def gain_x2(H, probe, e0, v, ref, ba, bs, f0):
    """Mean over the probes of the whitened change's x^2 along each gain
    direction, the sds (eq. 19, declared) at ref, the radial frame of e0."""
    lev = bs * np.sqrt(np.sum(np.abs(ref) ** 2, axis=1, keepdims=True)) / H.shape[1]
    u = e0 / np.abs(e0)
    vr = ((ba * np.abs(ref)) ** 2 / 3 + lev ** 2 / 6) * f0
    vt = np.broadcast_to(lev ** 2 / 6 * f0, vr.shape)

    def white(x):
        g = np.conj(u) * x
        return g.real / np.sqrt(vr), g.imag / np.sqrt(vt)

    (rr, ri), (gr, gi) = white(v - e0), white(H)
    return np.mean([np.sum(gr[m] * rr[m] + gi[m] * ri[m]) ** 2 / np.sum(gr[m] ** 2 + gi[m] ** 2)
                    for m in (probe == p for p in np.unique(probe))])


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--numpy", action="store_true")
    ap.add_argument("--ba", type=float, default=10.0, help="eq. 19 beta_a, %%")
    ap.add_argument("--bs", type=float, default=1.0, help="eq. 19 beta_s, %%")
    ap.add_argument("--navg", type=float, default=10, help="files averaged (inf: clean)")
    ap.add_argument("--lines", type=int, default=1101)
    ap.add_argument("--channels", default="0-31", help="e.g. 0-7 (the 8 responses per DA.x)")
    ap.add_argument("--updates", type=int, default=40)
    ap.add_argument("--commissionings", type=int, default=40, help="--numpy: references drawn")
    ap.add_argument("--seed", type=int, default=7000)
    ap.add_argument("--plain", action="store_true", help="no --reweight")
    ap.add_argument("--no-sensors", action="store_true")
    ap.add_argument("--truth-dir", default=str(REPO / "out" / "monitor_replicas"))
    a = ap.parse_args()
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    import diag_cases as dc
    import monitor_replicas as mr

    H = mr.truth(a.truth_dir)["null"][0]
    lo, hi = (int(x) for x in a.channels.split("-"))
    ch = np.arange(lo, hi + 1)
    idx = np.linspace(0, H.shape[1] - 1, a.lines).round().astype(int)
    H, freq = H[ch][:, idx], mr.FREQ[idx]
    resp = [o for _ in mr.INS for o in dc.OUTS]
    refs = [i for i in mr.INS for _ in dc.OUTS]
    resp, refs = [resp[i] for i in ch], [refs[i] for i in ch]
    probe = np.array([dc.OUTS.index(r) for r in resp])
    ba, bs = a.ba / 100, a.bs / 100
    finite = math.isfinite(a.navg)
    f0 = 1 + 1 / a.navg if finite else 1.0
    rng = np.random.default_rng(a.seed)

    def ref():
        return np.mean([noise(H, ba, bs, rng) for _ in range(int(a.navg))], axis=0) \
            if finite else H.copy()

    if a.numpy:
        at_e0, at_truth = [], []
        for _ in range(a.commissionings):
            e0 = ref()
            for _ in range(5):
                v = noise(H, ba, bs, rng)
                at_e0.append(gain_x2(H, probe, e0, v, e0, ba, bs, f0))
                at_truth.append(gain_x2(H, probe, e0, v, H, ba, bs, f0))
        print(json.dumps({"channels": len(ch), "lines": a.lines, "ba": a.ba, "bs": a.bs,
                          "navg": a.navg, "gain_x2_sd_at_commissioning": float(np.mean(at_e0)),
                          "gain_x2_sd_at_truth": float(np.mean(at_truth)),
                          "draws": len(at_e0)}))
        return 0
    import librcb as rcb

    ini = Path(a.truth_dir) / "model.ini"
    ini.write_text(dc.BASE_INI)
    model = rcb.Model.from_ini(ini)
    e0 = ref()

    def meas(d):
        return rcb.Meas.from_arrays(freq, d, resp, refs, kind="inertance", rpm=dc.RPM)

    with meas(e0) as setup:
        mon = rcb.Monitor(model, setup, mr.PARAMS, noise=(a.ba, a.bs), alpha=mr.ALPHA,
                          setup_averages=a.navg, reweight=not a.plain, relinearise=8,
                          sensors=not a.no_sensors)
    T, alarms = [], 0
    for _ in range(a.updates):
        with meas(noise(H, ba, bs, rng)) as m:
            r = mon.update(m)
        T.append(r["T"])
        alarms += r["alarm"]
    mon.close()
    print(json.dumps({"channels": len(ch), "lines": a.lines, "navg": a.navg,
                      "sensors": not a.no_sensors, "reweight": not a.plain, "dof": r["dof"],
                      "mean_T": float(np.mean(T)), "alarms": alarms, "updates": a.updates}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
