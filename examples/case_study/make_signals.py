"""Writes signals.csv (the case study's data, docs/case_study.md) from the ARTS-Lab
cantilever test's LabVIEW file data/data_I/test_1/data_set_1_downsampled_by_16.lvm
(repository PujaChowdhury/Dataset-4-Univariate-signal-with-non-stationarity,
CC BY-SA 4.0; see README.md beside this file). get_data.py downloads that file
and runs this script; neither file is in this repository.

What it changes, and nothing else:
- keeps the first 10 s (32000 of the file's 63041 samples at 3200 S/s);
- drops the drive voltage column (not a mechanical signal);
- keeps the values as the file has them (load cell in pounds-force, accelerometer
  in g: the header's Y_Unit_Label 'Pounds' and 'g'), stated in the '# units' line
  as lbf and g, which rcbtool reads and converts to N and m/s^2 itself;
- keeps the time axis as the exact sample times (the file rounds them to 1e-6 s).

Run: python3 make_signals.py PATH/TO/data_set_1_downsampled_by_16.lvm [OUT.csv]
(standard library only; OUT.csv defaults to signals.csv in the current directory;
written to a temporary file and renamed).
"""
import os
import sys

KEEP_S = 10.0
DT = 1.953125e-5 * 16                     # s: the header's Delta_X x the factor 16


def main(argv):
    if not 2 <= len(argv) <= 3:
        sys.exit("usage: make_signals.py FILE.lvm [OUT.csv]")
    src, out = argv[1], argv[2] if len(argv) > 2 else "signals.csv"
    with open(src, encoding="latin-1") as f:
        lines = f.read().split("\n")
    try:
        start = next(i for i, s in enumerate(lines) if s.startswith("X_Value")) + 1
    except StopIteration:
        sys.exit(f"{src}: no 'X_Value' header line: not the LabVIEW file expected")
    n = int(round(KEEP_S / DT))
    rows = ["# units = lbf,g", "time_s,force,ACC.x"]
    for i, s in enumerate(lines[start:start + n]):
        v = s.split()
        if len(v) < 4:
            sys.exit(f"{src}:{start + i + 1}: expected 4 columns (time, voltage, force, "
                     f"acceleration), found {len(v)}")
        # time: the exact sample time (the file's is rounded to 1e-6 s); force in lbf
        # and acceleration in g, as recorded
        rows.append("%.9g,%.7g,%.7g" % (i * DT, float(v[2]), float(v[3])))
    if len(rows) - 2 < n:
        sys.exit(f"{src}: {len(rows) - 2} samples, fewer than the {n} of {KEEP_S:g} s")
    tmp = out + ".tmp"
    with open(tmp, "w", encoding="ascii", newline="\n") as f:
        f.write("\n".join(rows) + "\n")
    os.replace(tmp, out)
    print(f"{out}: {n} samples at {1 / DT:.3f} S/s")


if __name__ == "__main__":
    main(sys.argv)
