"""Calibration of the diagnosis' claims (issue #33): null replicas at the
users' size, under noise librcb did not make.

The truth is the paper rig's inertance computed by ROSS (tests/python/
diag_cases.py, ross_inertance) on the large grid: the 8 responses per forces
at DA.x, DA.y, DB.x, DB.y (32 channels), 1101 lines 50-600 Hz, 10000 rpm.
The model handed to `rcbtool diagnose` is the truth's own INI (nothing is
missing), with the coupling's kt, kr, ct fitted. Each replica draws its
noise with numpy (PCG64, seed = replica number), in one of these forms:

  eq19       the paper's eq. 19 as librcb reads it: f (1 + a r1) + L r2 e^{i phi}
             (r1, r2 uniform in [-1, 1], phi uniform; L = ||f||_2 / n s), declared
             exactly (--noise 10,1)
  literal    eq. 19 read literally on magnitudes: the systematic term real, in
             phase with |f|: (|f| (1 + a r1) + L r2) e^{i arg f}, and a phase noise
             uniform in +-2 deg (declared --noise 10,1, no phase term)
  high       eq. 19 with both factors 20 % above the declared (12 %, 1.2 %)
  phase      eq. 19 and a phase noise uniform in +-2 deg per point; declared
             with its phase term (--noise 10,1,2) when --phase-term is given,
             else as --noise 10,1

For each replica the first candidate's claim is read from --json: a false
alarm is a significant first candidate (a physical or sensor effect claimed
on data that lack none). The detection cases (name@EFFECT) hide an effect in
the ROSS truth (diag_cases.LARGE_CASES: cross = kxy = -kyx = 1.5e7 N/m at
B3, cr = coupling C's rotational damping 0.02 N m s/rad, aniso = B4's kyy
9e7 -> 1e7 N/m) and count the replicas whose first candidate is the right
effect at the right place and "explains". The script prints per case the false alarms out of
R with the one-sided 99 % binomial bound for a 1 % rate, the adequacy test's
rejections, and the chi-square of the model as it is against its
expectation (mean over the replicas), and what the words said.

  .venv/bin/python tools/bench/diag_calibration.py --replicas 100 \
      [--cases eq19-log,eq19-complex,literal-log,high-log,phase-complex] \
      [--jobs 2] [--rcbtool build/tools/rcbtool] [--out out/calibration]
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
import warnings
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "tests" / "python"))
warnings.simplefilter("ignore")

import diag_cases as dc  # noqa: E402

# (noise form, scale, declared noise) per case
CASES = {
    "eq19-log": ("eq19", "log", "10,1"),
    "eq19-complex": ("eq19", "complex", "10,1"),
    "literal-log": ("literal", "log", "10,1"),
    "literal-complex": ("literal", "complex", "10,1,2"),
    "high-log": ("high", "log", "10,1"),
    "high-complex": ("high", "complex", "10,1"),
    "phase-complex": ("phase", "complex", "10,1,2"),
    "phase-log": ("phase", "log", "10,1"),
}
# hidden effects of the detection cases: diag_cases.LARGE_CASES by name
EFFECTS = {"cross": "large_cross_B3", "cr": "large_cr_C", "aniso": "large_aniso_B4"}


def truth(effect, out):
    """The ROSS truth (32 x 1101), with a LARGE_CASES effect hidden; cached."""
    cache = out / f"truth_{effect or 'null'}.npy"
    if cache.exists():
        return np.load(cache)
    edit = None
    if effect:
        edit = next(c for c in dc.LARGE_CASES if c.name == EFFECTS[effect]).model_edit
    H = dc.ross_inertance(dc.BASE_INI, edit, freq=dc.LARGE_FREQ_HZ, ins=dc.LARGE_INS)
    np.save(cache, H)
    return H


def want(effect):
    return None if not effect else next(c for c in dc.LARGE_CASES
                                        if c.name == EFFECTS[effect]).expect[0]


binom_upper = dc.binom_upper
def one(tool, case, H, rep, workdir, params):
    form, scale, noise = CASES[case.split("@")[0]]
    d = Path(workdir) / f"{case.replace('@', '_')}_{rep}"
    d.mkdir(parents=True, exist_ok=True)
    meas, model = d / "meas.uff", d / "model.ini"
    model.write_text(dc.model_ini())
    dc.write_uff(meas, dc.calibration_noise(form, H, 1000 * rep + 7), dc.LARGE_FREQ_HZ, dc.LARGE_INS)
    sc = ["--log"] if scale == "log" else ["--scale", "complex"]
    t0 = time.time()
    res = subprocess.run([tool, "diagnose", str(model), str(meas), "--params", params, *sc,
                          "--noise", noise, "--top", "3", "--json"],
                         capture_output=True, text=True, timeout=900)
    wall = time.time() - t0
    if res.returncode != 0:
        return {"rep": rep, "error": res.stderr.strip()[:400]}
    j = json.loads(res.stdout)
    c0 = j["candidates"][0] if j["candidates"] else {}
    out = {"rep": rep, "wall": wall, "significant": bool(c0.get("significant")),
           "claim": c0.get("claim"), "effect": c0.get("effect"), "place": c0.get("place"),
           "dbic": c0.get("delta_bic"), "chi2": j["adequacy"]["chi2"],
           "expected": j["adequacy"]["expected"], "sd": j["adequacy"]["sd"],
           "adequate": j["adequacy"]["adequate"], "explanation": j.get("explanation", "")}
    for k in ("dispersion", "structure"):
        if k in j:
            out[k] = j[k]
    for p in d.iterdir():
        p.unlink()
    d.rmdir()
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--replicas", type=int, default=100)
    ap.add_argument("--first", type=int, default=0, help="first replica number")
    ap.add_argument("--cases", default="eq19-log,eq19-complex,literal-log,high-log,phase-complex")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--rcbtool", default=str(REPO / "build" / "tools" / "rcbtool"))
    ap.add_argument("--out", default=str(REPO / "out" / "calibration"))
    args = ap.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for case in args.cases.split(","):
            effect = case.split("@")[1] if "@" in case else None
            H = truth(effect, out)
            reps = range(args.first, args.first + args.replicas)
            with ThreadPoolExecutor(args.jobs) as ex:
                res = list(ex.map(lambda r: one(args.rcbtool, case, H, r, tmp, dc.FIT_PARAMS),
                                  reps))
            (out / f"{case}.json").write_text(json.dumps(res, indent=1))
            ok = [r for r in res if "error" not in r]
            fa = sum(r["significant"] for r in ok)
            if effect:  # detections: the right effect, at its place, explains
                eff, place = want(effect)
                fa = sum(r["claim"] == "explains" and r["effect"] == eff and place in r["place"]
                         for r in ok)
            rej = sum(not r["adequate"] for r in ok)
            ratio = np.mean([r["chi2"] / r["expected"] for r in ok]) if ok else float("nan")
            zs = np.mean([(r["chi2"] - r["expected"]) / r["sd"] for r in ok]) if ok else float("nan")
            words = {}
            for r in ok:
                key = (r["claim"], r["effect"]) if r["significant"] else ("none", "")
                words[key] = words.get(key, 0) + 1
            rows.append((case, len(ok), len(res) - len(ok), fa, binom_upper(len(ok)), rej, ratio,
                         zs, np.median([r["wall"] for r in ok]) if ok else float("nan"), words))
            print(f"{case}: {len(ok)} replicas, {fa} {'named' if effect else 'false alarms'} (bound {binom_upper(len(ok))}),"
                  f" {rej} inadequate, chi2/expected {ratio:.4f}", flush=True)
    print("\nfalse alarms: a significant first candidate on null data; for name@EFFECT the "
          "replicas whose first candidate is the hidden effect, at its place, and explains")
    print("\n| case | replicas | failed runs | false alarms (named) | bound (1 %, 99 %) | adequacy "
          "rejections | mean chi2 / expected | mean z of chi2 | median wall s | first "
          "candidates claimed |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for case, n, nerr, fa, bound, rej, ratio, zs, wall, words in rows:
        w = "; ".join(f"{k[0]} {k[1]}: {v}" for k, v in sorted(words.items(), key=lambda x: -x[1])
                      if k[0] != "none") or "-"
        print(f"| {case} | {n} | {nerr} | {fa} | {bound} | {rej} | {ratio:.4f} | {zs:+.2f} | "
              f"{wall:.1f} | {w} |")


if __name__ == "__main__":
    main()
