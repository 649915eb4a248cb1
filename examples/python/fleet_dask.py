#!/usr/bin/env python3
"""Fleet-scale batch: one fit per measurement file, in parallel on Dask.

A fleet of machines of one design (examples/paper_system.ini), each with its own
flexible coupling: every night each machine's measured FRFs (UFF58) are fitted to
identify its coupling stiffnesses kt (N/m) and kr (N m/rad), which drift as the
coupling wears. Each fit is one task on a dask.distributed cluster; workers run
the fits through the librcb Python package (the C library does the work).

    # make 20 synthetic machines (hidden coupling values, 10 % + 1 % noise), then
    # fit them on a local cluster of 2 worker processes:
    python examples/python/fleet_dask.py --make 20 --dir fleet --workers 2

    # on a real cluster: start `dask scheduler` on a host and `dask worker
    # tcp://HOST:8786` on each node (LIBRCB_PATH set there, librcb installed),
    # with the files on a file system every worker sees:
    python examples/python/fleet_dask.py --dir /shared/fleet --scheduler tcp://HOST:8786

Output: one line per machine (fitted values, error %, the noise floor, UNSURE
when the fit cannot be trusted) and, when the hidden truth is known (synthetic
fleet), the relative error of each fitted value. --json FILE writes all results.
"""

import argparse
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[2]
DESIGN = REPO / "examples" / "paper_system.ini"
PARAMS = {"coupling.C.kt": (1e3, 1e7), "coupling.C.kr": (1.0, 1e5)}  # bounds, SI
OUTPUTS = ["C.A.x", "C.A.y", "C.B.x", "C.B.y"]
INPUTS = ["DA.x"]
RPM = 10000.0          # test speed, rpm
BAND_HZ = (200.0, 400.0)
NOISE = (10.0, 1.0)    # eq. 19 noise: random %, systematic %


def make_fleet(folder, n, design=DESIGN, seed=1, points=101):
    """Write n synthetic machines: machine_NNN.uff (measured inertances with
    noise seeded per machine) from the design with kt, kr drawn log-uniformly
    within a factor 3 of the design values; truth.json holds the hidden values."""
    import librcb as rcb

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(seed)
    truth = {}
    design_model = rcb.Model.from_ini(design)
    f = np.linspace(*BAND_HZ, points)
    for i in range(n):
        m = design_model.copy()
        hidden = {}
        for name in PARAMS:
            hidden[name] = m.get(name) * math.exp(rng.uniform(-math.log(3), math.log(3)))
            m.set(name, hidden[name])
        path = folder / f"machine_{i:03d}.uff"
        with rcb.simulate(m, OUTPUTS, INPUTS, f, rpm=RPM, kind="inertance", noise=NOISE,
                          seed=seed * 100003 + i) as meas:
            meas.write(path, uff_map={10: "C.A", 11: "C.B", 4: "DA"})
        truth[path.name] = hidden
        m.close()
    (folder / "truth.json").write_text(json.dumps(truth, indent=1))
    return sorted(folder.glob("machine_*.uff"))


def fit_machine(meas_path, design_text, uff_map=None):
    """One task: fit the design's coupling to one machine's file. Runs on a
    worker; returns plain data (picklable), never librcb objects."""
    import librcb as rcb

    t0 = time.perf_counter()
    with rcb.Model.from_ini(design_text, name="design.ini") as model, \
            rcb.Meas.read(meas_path, uff_map=uff_map or {10: "C.A", 11: "C.B", 4: "DA"}) as meas:
        res = rcb.fit(model, meas, PARAMS, log=True, noise=NOISE, band=BAND_HZ)
        res.model.close()
    return {"file": Path(meas_path).name, "values": res.values,
            "stderr": {p["name"]: p["stderr"] for p in res.params},
            "error0_pct": res.report["error0_pct"], "error_pct": res.report["error_pct"],
            "floor_pct": res.report["floor_pct"], "unsure": res.report["unsure"],
            "evaluations": res.report["evaluations"], "seconds": time.perf_counter() - t0}


def run_fleet(client, files, design=DESIGN):
    """Submit one fit per file to a dask.distributed Client; results in file order."""
    text = Path(design).read_text()
    futures = client.map(fit_machine, [str(p) for p in files], design_text=text,
                         pure=False)
    return client.gather(futures)


def _report(results, truth):
    print(f"{'machine':16s} {'kt (N/m)':>12s} {'kr (N m/rad)':>13s} {'error %':>8s} "
          f"{'floor %':>8s} {'kt err %':>9s} {'kr err %':>9s}  s")
    for r in results:
        t = truth.get(r["file"], {})
        v = r["values"]
        errs = [100 * (v[k] / t[k] - 1) if k in t else math.nan for k in PARAMS]
        print(f"{r['file']:16s} {v['coupling.C.kt']:12.5g} {v['coupling.C.kr']:13.5g} "
              f"{r['error_pct']:8.3f} {r['floor_pct']:8.3f} {errs[0]:9.2f} {errs[1]:9.2f}"
              f"  {r['seconds']:.2f}{'  UNSURE' if r['unsure'] else ''}")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--dir", default="fleet", help="folder of machine_*.uff files")
    ap.add_argument("--make", type=int, default=0, help="first write N synthetic machines")
    ap.add_argument("--seed", type=int, default=1, help="seed of the synthetic fleet")
    g = ap.add_mutually_exclusive_group()
    g.add_argument("--scheduler", help="address of a running scheduler, tcp://HOST:8786")
    g.add_argument("--workers", type=int, default=2, help="local cluster: worker processes")
    ap.add_argument("--json", help="write every result to this file")
    a = ap.parse_args(argv)

    from dask.distributed import Client, LocalCluster

    files = (make_fleet(a.dir, a.make, seed=a.seed) if a.make
             else sorted(Path(a.dir).glob("machine_*.uff")))
    if not files:
        ap.error(f"no machine_*.uff in {a.dir} (use --make N)")
    t0 = time.perf_counter()
    if a.scheduler:
        client, cluster = Client(a.scheduler), None
    else:  # one thread per process: each fit is a single-threaded C computation
        cluster = LocalCluster(n_workers=a.workers, threads_per_worker=1, processes=True,
                               dashboard_address=None)
        client = Client(cluster)
    try:
        results = run_fleet(client, files)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    wall = time.perf_counter() - t0
    tf = Path(a.dir) / "truth.json"
    _report(results, json.loads(tf.read_text()) if tf.is_file() else {})
    busy = sum(r["seconds"] for r in results)
    print(f"{len(results)} fits in {wall:.1f} s wall ({busy:.1f} s of fitting; "
          f"{sum(r['unsure'] for r in results)} unsure)")
    if a.json:
        Path(a.json).write_text(json.dumps(results, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
