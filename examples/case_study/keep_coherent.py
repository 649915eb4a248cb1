"""Keeps the lines of an `rcbtool estimate` FRF (CSV) and its --stats file where the
coherence is at least a threshold: a stepped- or multi-sine test measures the FRF at
the lines its force excites, and everywhere else H1 is noise divided by noise.
rcbtool has no coherence mask (yet); compare would pair noise "peaks" with modes.

usage: python3 keep_coherent.py H1.csv STATS.csv MIN_COH H1_OUT.csv STATS_OUT.csv
The '#' lines and the header are kept as they are; only rows are dropped.
"""
import sys


def split(path):
    lines = open(path, encoding="utf-8").read().splitlines()
    head = [s for s in lines if s.startswith("#")]
    rest = [s for s in lines if s and not s.startswith("#")]
    return head, rest[0], rest[1:]


h1, stats, cmin, h1_out, stats_out = sys.argv[1], sys.argv[2], float(sys.argv[3]), sys.argv[4], sys.argv[5]
hh, hcols, hrows = split(h1)
sh, scols, srows = split(stats)
icoh = [c.strip() for c in scols.split(",")].index(next(c for c in scols.split(",") if c.endswith(" coh")))
keep = [i for i, r in enumerate(srows) if float(r.split(",")[icoh]) >= cmin]
if len(hrows) != len(srows):
    sys.exit(f"{h1} has {len(hrows)} lines, {stats} {len(srows)}: not the same estimate")
for path, head, cols, rows in ((h1_out, hh, hcols, hrows), (stats_out, sh, scols, srows)):
    with open(path, "w", encoding="utf-8") as f:
        f.write("\n".join(head + [cols] + [rows[i] for i in keep]) + "\n")
print(f"kept {len(keep)} of {len(srows)} lines with coherence >= {cmin}:",
      " ".join(f"{float(srows[i].split(',')[0]):g}" for i in keep))
