#!/usr/bin/env python3
"""The step's size against its stated interval over many noise draws
(issue #34; docs/monitoring.md's limits, docs/benchmarks.md).

tests/python/monitor_cases.py's cross_B3 series (kxy = -kyx = 1.5e7 N/m at
bearing B3 from update 37 of 60, ROSS 2.3's matrices, eq. 19 noise) made
again with --seeds other noise seeds (seed0 190000 + 1000 s, no other
series' draws) and the noise times --scale, then `rcbtool monitor` with the
ROSS tests' options (commissioning 10 files, --reweight, --relinearise 8,
alpha 0.01, --noise 10,1; the level measured from the commissioning). Per
series and over all: the alarms naming B3's cross-coupling, the mean and sd
of z = (estimate - truth) / (stated 95 % half-width / 1.96), and how many
intervals hold the truth.

  OPENBLAS_NUM_THREADS=1 .venv/bin/python tools/bench/monitor_step_bias.py \\
      --rcbtool build/tools/rcbtool --seeds 12 --scale 1 --out out/step_bias
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "tests" / "python"))

import monitor_cases as mc  # noqa: E402


def run(tool, d, model):
    truth = json.loads((d / "truth.json").read_text())
    cmd = [tool, "monitor", str(model), str(d), "--params", mc.FIT_PARAMS, "--noise", "10,1",
           "--commission", str(mc.COMMISSION), "--reweight", "--relinearise", "8",
           "--alpha", "0.01", "--json"]
    res = subprocess.run(cmd, capture_output=True, text=True,
                         env=dict(os.environ, OPENBLAS_NUM_THREADS="1"))
    if res.returncode:
        sys.exit(f"{' '.join(cmd)}: exit {res.returncode}\n{res.stderr[-2000:]}")
    z = []
    for u in json.loads(res.stdout)["updates"]:
        top = u["top"][0] if u["top"] else None
        if (not u["alarm"] or truth["files"].index(u["file"]) < truth["change_update"]
                or top["place"] != truth["place"]):
            continue
        sd = (top["ci_hi"][0] - top["ci_lo"][0]) / 3.92  # the stated 95 % interval's sd
        z.append((top["size"][0] - truth["cross_kxy"]) / sd)
    return z


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rcbtool", default=str(REPO / "build" / "tools" / "rcbtool"))
    ap.add_argument("--seeds", type=int, default=12, help="noise draws (series)")
    ap.add_argument("--scale", type=float, default=1.0, help="the noise times this")
    ap.add_argument("--out", default=str(REPO / "out" / "step_bias"))
    a = ap.parse_args()
    mc.NOISE = tuple(x * a.scale for x in mc.NOISE)
    out = Path(a.out) / f"x{a.scale:g}"
    truth = None
    allz, means = [], []
    for s in range(a.seeds):
        d = out / f"s{s}"
        if not (d / "cross_B3" / "truth.json").is_file():
            truth = truth or mc.Truth()
            mc.SERIES["cross_B3"].seed0 = 190000 + 1000 * s
            mc.write_series(d, ["cross_B3"], truth)
        z = run(a.rcbtool, d / "cross_B3", d / "model.ini")
        allz += z
        means.append(statistics.mean(z) if z else float("nan"))
        print(f"seed {s}: {len(z)} alarms naming B3, mean z {means[-1]:+.3f}, "
              f"sd {statistics.pstdev(z) if z else float('nan'):.3f}, "
              f"covered {sum(abs(x) <= 1.96 for x in z)}", flush=True)
    print(f"noise x {a.scale:g}, {a.seeds} series: {len(allz)} alarms, mean z "
          f"{statistics.mean(allz):+.3f} (series means' sd {statistics.pstdev(means):.3f}), sd "
          f"{statistics.pstdev(allz):.3f}, covered {sum(abs(x) <= 1.96 for x in allz)} of "
          f"{len(allz)}")


if __name__ == "__main__":
    main()
