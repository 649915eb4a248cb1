#!/usr/bin/env python3
"""Whether the probes' gain estimates are biased by the commissioning's own
noise (issue #34 item 2), on monitor_replicas.py's ROSS null truth (32
channels x 1101 lines, cached by a run of it in out/monitor_replicas).

Each of N commissionings averages 10 files of eq. 19 noise (10 %, 1 %), or
with --no-additive the proportional term alone; the monitor (kt, kr, ct,
--reweight --relinearise 8, the gains among the candidates, noise 10,1 at
scale 1) then takes one noise-free update, whose change is minus the
reference's noise. Printed: how many gains rank among the 8 candidates and
the signs of their estimated changes (unbiased: about half each).

    OPENBLAS_NUM_THREADS=1 LIBRCB_PATH=build/src/librcb.so .venv/bin/python \\
      tools/bench/monitor_gain_frame.py [--no-additive] [--n 20]
"""

import argparse
import math
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "tools" / "bench"))
import monitor_replicas as mr  # noqa: E402
import diag_cases as dc  # noqa: E402  (monitor_replicas put tests/python on the path)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, default=20, help="commissionings")
    ap.add_argument("--no-additive", action="store_true")
    ap.add_argument("--out", default=str(REPO / "out" / "monitor_replicas"))
    args = ap.parse_args()
    import librcb as rcb

    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "model.ini").write_text(dc.BASE_INI)
    model = rcb.Model.from_ini(out / "model.ini")
    H = mr.truth(out)["null"][0]
    level = np.sqrt(np.sum(np.abs(H) ** 2, axis=1, keepdims=True)) / H.shape[1]
    pos = neg = ngain = 0
    for c in range(args.n):
        rng = np.random.default_rng(7700000 + c)
        files = []
        for _ in range(10):
            r1, r2 = rng.uniform(-1, 1, H.shape), rng.uniform(-1, 1, H.shape)
            add = level * 0.01 * r2 * np.exp(2j * math.pi * rng.uniform(0, 1, H.shape))
            files.append(H * (1 + 0.1 * r1) + (0 if args.no_additive else add))
        with mr._meas(rcb, np.mean(files, axis=0)) as setup:
            mon = rcb.Monitor(model, setup, mr.PARAMS, noise=(10, 1), setup_averages=10,
                              alpha=0.01, reweight=True, relinearise=8, noise_scale=1.0,
                              sensors=True)
        with mr._meas(rcb, H) as ms:
            r = mon.update(ms)
        for t in r["top"]:
            if t["params"].startswith("sensor"):
                ngain += 1
                pos += t["size"][0] > 0
                neg += t["size"][0] < 0
        mon.close()
    print(f"{args.n} commissionings ({'no additive' if args.no_additive else 'eq. 19'}): "
          f"gains among the 8 ranked {ngain}, change > 0 {pos}, < 0 {neg}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
