"""The figures of docs/diagnosis_claims_before.md: today's `rcbtool diagnose`
on the issue #23 cases (diag_cases.CLAIM_CASES), one noise seed, on the grid
each case runs on in test_diag_claims.py and, with --grids small,large, on
both (the grid choice).

  RCBTOOL=build/tools/rcbtool .venv/bin/python tests/python/claims_before.py \
      [--cases NAME,...] [--grids small,large] [--starts N] [--out DIR]

Per case and grid: the first candidate, its words (the `explanation` JSON
field), E0, the error after `diagnose --apply 1` + `rcbtool fit` of the
applied model (fit with --starts N, default 1: it starts at the
candidate's refit; 8 starts, the CLI's default, took over 600 s of wall on
the shared machine for the large hub), the floor, the CPU
and wall seconds of diagnose and of fit (user + sys of the child, as
/usr/bin/time); two rounds for claim_two; on claim_probe_DBy the per-channel
error % of `rcbtool compare` of the model as it is. One JSON file per run in
DIR (default out/claims_before), and the markdown table on stdout.
"""

import argparse
import json
import os
import sys
import time
import warnings
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
warnings.simplefilter("ignore")

import diag_cases as dc  # noqa: E402


def on_grid(case, grid):
    if grid == case.grid:
        return case
    return dc.ClaimCase(case.name, case.what, case.expect, case.kind, case.model_edit, grid=grid,
                        after_noise=case.after_noise)


def run(tool, case, workdir, starts):
    workdir.mkdir(parents=True, exist_ok=True)
    t0 = time.process_time()
    meas = dc.claim_measurement(case, workdir)
    truth_cpu = time.process_time() - t0
    model = workdir / "model.ini"
    model.write_text(dc.model_ini())
    rounds = 2 if case.kind == "two" else 1
    out = {"case": case.name, "grid": case.grid, "what": case.what, "truth_cpu_s": truth_cpu,
           "rounds": []}
    params = dc.FIT_PARAMS
    for r in range(rounds):
        n0 = len(tool.times)
        step = dc.claim_round(tool, workdir, meas, model, params, tag=f"r{r + 1}", starts=starts)
        d, c0 = step["diag"], step["diag"]["candidates"][0]
        fit = step["fit"]
        fit_times = [t for t in tool.times[n0:] if t[0] == "fit"]
        out["rounds"].append({
            "first": {k: c0[k] for k in ("effect", "place", "fitted", "error_pct", "delta_bic",
                                         "significant")},
            "top": [(c["effect"], c["place"], c["error_pct"], c["delta_bic"], c["significant"])
                    for c in d["candidates"]],
            "explanation": d["explanation"], "error0_pct": d["error0_pct"],
            "floor_pct": d["floor_pct"], "diag_cpu_s": step["cpu_s"], "diag_wall_s": step["wall_s"],
            "fit_error_pct": fit and fit["error_pct"],
            "fit_floor_pct": fit and fit.get("floor_pct"),
            "fit_starts": fit and fit.get("starts"),
            "fit_cpu_s": fit_times[-1][1] if fit else None,
            "fit_wall_s": fit_times[-1][2] if fit else None,
            "diag_json_keys": sorted(d),
        })
        if step["applied"] is None:
            break
        model, params = step["applied"], step["params"]
    if case.kind == "probe":
        cmp = tool.json("compare", workdir / "model.ini", meas)
        out["compare"] = [(c["response"], c["reference"], c["error_pct"], c["phase_rms_deg"])
                          for c in cmp["channels"]]
    return out


def table(results):
    rows = ["| case | grid | truth | round | first candidate | words (`explanation`) | E0 % | "
            "E after apply + fit % | floor % | diagnose CPU / wall s | fit CPU / wall s |",
            "|---|---|---|---|---|---|---|---|---|---|---|"]
    for res in results:
        for k, r in enumerate(res["rounds"]):
            f = r["first"]
            sig = "significant" if f["significant"] else "not significant"
            fit = "-" if r["fit_error_pct"] is None else f"{r['fit_error_pct']:.2f}"
            ft = ("-" if r["fit_cpu_s"] is None else
                  f"{r['fit_cpu_s']:.1f} / {r['fit_wall_s']:.1f} ({r['fit_starts']} starts)")
            words = r["explanation"].replace("|", "\\|")
            rows.append(f"| {res['case']} | {res['grid']} | {res['what']} | {k + 1} | "
                        f"{f['effect']} at {f['place']} ({sig}, dBIC {f['delta_bic']:.1f}) | "
                        f"{words} | {r['error0_pct']:.2f} | {fit} | {r['floor_pct']:.2f} | "
                        f"{r['diag_cpu_s']:.1f} / {r['diag_wall_s']:.1f} | {ft} |")
    return "\n".join(rows)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--cases", default=",".join(c.name for c in dc.CLAIM_CASES))
    ap.add_argument("--grids", default="")
    ap.add_argument("--starts", type=int, default=1)
    ap.add_argument("--out", default="out/claims_before")
    ap.add_argument("--table-only", action="store_true")
    a = ap.parse_args()
    out = Path(a.out)
    if a.table_only:
        results = [json.loads(p.read_text()) for p in sorted(out.glob("*.json"))]
        print(table(results))
        return
    try:
        from threadpoolctl import threadpool_limits

        threadpool_limits(1)  # 2 cores shared: BLAS threads only slow ROSS's solves
    except ImportError:
        pass
    tool = dc.TimedRcbtool(os.environ.get("RCBTOOL", "build/tools/rcbtool/rcbtool"))
    results = []
    for name in a.cases.split(","):
        case = next(c for c in dc.CLAIM_CASES if c.name == name)
        for grid in (a.grids.split(",") if a.grids else [case.grid]):
            c = on_grid(case, grid)
            res = run(tool, c, out / f"{name}_{grid}", a.starts)
            (out / f"{name}_{grid}.json").write_text(json.dumps(res, indent=1))
            results.append(res)
            print(table([res]).splitlines()[-1], flush=True)
    print(table(results))


if __name__ == "__main__":
    main()
