"""Line by line: the noise `rcbtool estimate --stats` states against the residual a
fitted model leaves (docs/case_study.md).

usage: python3 residual_table.py COMPARE.json STATS.csv
COMPARE.json: `rcbtool compare MODEL MEAS --sd STATS --json -o COMPARE.json` of the
fitted model; STATS.csv: the --stats file of the same lines. Prints, at the centre of
each run of kept lines (the line of highest coherence within 1.5 Hz), the frequency,
the coherence, |H| measured, its sd (of Re and of Im), |H| of the model, the complex
residual |H_model - H_meas| in sd, and the magnitude's residual ||H_model| - |H_meas||
in sd (what a fit on log10 |H| sees); then the medians of both over every line.
Standard library only.
"""
import json
import statistics
import sys

cmp_path, stats_path = sys.argv[1], sys.argv[2]
c = json.load(open(cmp_path, encoding="utf-8"))
ch = c["channels"][0]
rows = [s for s in open(stats_path, encoding="utf-8").read().splitlines()
        if s and not s.startswith("#")][1:]
coh = [float(r.split(",")[1]) for r in rows]
sd = [float(r.split(",")[2]) for r in rows]
x = c["x"]
if len(x) != len(rows):
    sys.exit(f"{cmp_path} has {len(x)} lines, {stats_path} {len(rows)}")
meas = [complex(a, b) for a, b in zip(ch["meas_re"], ch["meas_im"])]
model = [complex(a, b) for a, b in zip(ch["model_re"], ch["model_im"])]
ratio = [abs(m - h) / s for m, h, s in zip(model, meas, sd)]
mratio = [abs(abs(m) - abs(h)) / s for m, h, s in zip(model, meas, sd)]
print(f"{'f_Hz':>7} {'coh':>8} {'|H|_meas':>9} {'sd':>9} {'|H|_model':>9} "
      f"{'resid/sd':>9} {'mag/sd':>9}   ({ch['response']}/{ch['reference']}, {ch['kind']})")
for i, f in enumerate(x):
    near = [j for j, g in enumerate(x) if abs(g - f) <= 1.5]
    if max(near, key=lambda j: coh[j]) != i:
        continue
    print(f"{f:7.1f} {coh[i]:8.5f} {abs(meas[i]):9.4g} {sd[i]:9.2g} {abs(model[i]):9.4g} "
          f"{ratio[i]:9.3g} {mratio[i]:9.3g}")
print(f"median over all {len(x)} lines: complex residual / sd {statistics.median(ratio):.3g}, "
      f"magnitude residual / sd {statistics.median(mratio):.3g}; "
      f"sd / |H| {statistics.median(s / abs(h) for s, h in zip(sd, meas)):.2e}")
