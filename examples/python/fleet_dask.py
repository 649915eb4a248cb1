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

Monitoring (issue #16, --monitor): each machine has a series of measurements
over time (machine_NNN/day_DDD.uff); a task commissions an rcb_monitor on the
machine's first file and runs every later file through it (librcb.Monitor).
The files travel as bytes inside the task, not as paths (the workers need no
shared file system), and the results are printed as they arrive
(dask.distributed.as_completed), one line per machine: its first alarm, the
effect named and the last tracked kt with its interval.

    # 8 synthetic machines of 16 days each (hidden: some couplings wear, one
    # bearing develops cross-coupling), monitored on 2 worker processes:
    python examples/python/fleet_dask.py --monitor --make 8 --days 16 --dir fleet_mon

    # throughput (machines/s) against the number of workers, as a figure:
    python examples/python/fleet_dask.py --monitor --make 8 --days 16 --dir fleet_mon \
        --scaling 1,2 --figure fleet_throughput.png
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


# ---- monitoring a fleet (issue #16) ------------------------------------------

MON_PARAMS = ["coupling.C.kt", "coupling.C.ct"]  # tracked on every machine
MON_OUTPUTS = ["DA.x", "DA.y", "C.A.x", "C.A.y", "C.B.x", "C.B.y", "DB.x", "DB.y"]
MON_MAP = {3: "DA", 10: "C.A", 11: "C.B", 16: "DB"}
MON_NOISE = (10.0, 1.0)
MON_BAND_HZ = (100.0, 400.0)
MON_COMMISSION = 3  # days averaged into the reference (the shared noise of one day is large)


def _hidden_change(i, days, rng):
    """What happens to machine i after the commissioning days: nothing,
    coupling wear (kt falls linearly to -2..-8 % by the last day), or
    cross-coupling kcross at bearing B3 (1.5e7 N/m) from a day in the second half."""
    kind = ("none", "wear", "wear", "cross")[i % 4]
    if kind == "wear":
        return {"kind": kind, "kt_loss": float(rng.uniform(0.02, 0.08))}
    if kind == "cross":
        first = max(MON_COMMISSION, days // 2)
        return {"kind": kind, "day": int(rng.integers(first, days)), "kcross": 1.5e7}
    return {"kind": kind}


def _kt_factor(h, d, days):
    """kt / kt0 of a wearing machine on day d (steady while commissioning)."""
    k = max(d - MON_COMMISSION + 1, 0) / max(days - MON_COMMISSION, 1)
    return 1.0 - h["kt_loss"] * k


def make_monitor_fleet(folder, n, days, design=DESIGN, seed=1, points=151):
    """n machines, each a folder machine_NNN of day_DDD.uff files (the 8
    inertances per a force at DA, 100-400 Hz, eq. 19 noise seeded per file)
    with a hidden change (_hidden_change); truth.json holds them."""
    import librcb as rcb

    folder = Path(folder)
    rng = np.random.default_rng(seed)
    f = np.linspace(*MON_BAND_HZ, points)
    truth = {}
    with rcb.Model.from_ini(design) as base:
        kt0 = base.get("coupling.C.kt")
        for i in range(n):
            name = f"machine_{i:03d}"
            (folder / name).mkdir(parents=True, exist_ok=True)
            h = truth[name] = _hidden_change(i, days, rng)
            for d in range(days):
                m = base.copy()
                if h["kind"] == "wear":
                    m.set("coupling.C.kt", kt0 * _kt_factor(h, d, days))
                if h["kind"] == "cross" and d >= h["day"]:
                    m.set("bearing.B3.kcross", h["kcross"])
                with rcb.simulate(m, MON_OUTPUTS, ["DA.x"], f, rpm=RPM, kind="inertance",
                                  noise=MON_NOISE, seed=seed * 1000003 + 1000 * i + d) as ms:
                    ms.write(folder / name / f"day_{d:03d}.uff", uff_map=MON_MAP)
                m.close()
    (folder / "truth.json").write_text(json.dumps(truth, indent=1))
    return sorted(p for p in folder.glob("machine_*") if p.is_dir())


def machine_payload(machine_dir):
    """(name, [bytes of each day's file, in time order]): what a task carries."""
    files = sorted(Path(machine_dir).glob("day_*.uff"))
    return Path(machine_dir).name, [p.read_bytes() for p in files]


def _commissioning(rcb, days):
    """The first MON_COMMISSION days averaged, as one Meas."""
    ms = [rcb.Meas.from_bytes(b, uff_map=MON_MAP) for b in days[:MON_COMMISSION]]
    try:
        first = ms[0]
        resp = [r for r, _, _ in first.channels]
        refs = [ref for _, ref, _ in first.channels]
        mean = sum(m.data for m in ms) / len(ms)
        return rcb.Meas.from_arrays(first.x, mean, resp, refs, kind=first.channels[0][2],
                                    rpm=first.rpm)
    finally:
        for m in ms:
            m.close()


def monitor_machine(name, days, design_text, alpha=1e-3):
    """One task: commission on the first days' bytes (averaged), update with
    the others. Runs on a worker; returns plain data."""
    import librcb as rcb

    t0 = time.perf_counter()
    out = {"machine": name, "updates": len(days) - MON_COMMISSION, "first_alarm": None,
           "first_cusum": None, "named": None}
    with rcb.Model.from_ini(design_text, name="design.ini") as model, \
            _commissioning(rcb, days) as setup, \
            rcb.Monitor(model, setup, MON_PARAMS, noise=MON_NOISE, alpha=alpha,
                        setup_averages=MON_COMMISSION, reweight=True,
                        relinearise=8) as mon:  # as the ROSS series (docs/monitoring.md)
        for d, data in enumerate(days[MON_COMMISSION:], start=MON_COMMISSION):
            with rcb.Meas.from_bytes(data, uff_map=MON_MAP) as ms:
                r = mon.update(ms)
            if r["alarm"] and out["first_alarm"] is None:
                out["first_alarm"] = d
                out["named"] = f"{r['top'][0]['effect']} at {r['top'][0]['place']}"
            if r["cusum_alarm"] and out["first_cusum"] is None:
                out["first_cusum"] = d
        kt = r["tracked"][0]
        out.update(kt=kt["value"], kt_ci=(kt["ci_lo"], kt["ci_hi"]), memory=mon.memory)
    out["seconds"] = time.perf_counter() - t0
    return out


def run_monitor_fleet(client, machines, design=DESIGN, on_result=None):
    """One monitor task per machine, the files sent as bytes; results are
    handed to on_result as they complete (as_completed) and returned sorted."""
    from dask.distributed import as_completed

    text = Path(design).read_text()
    futures = [client.submit(monitor_machine, *machine_payload(m), text, pure=False)
               for m in machines]
    results = []
    for fut in as_completed(futures):
        r = fut.result()
        results.append(r)
        if on_result:
            on_result(r)
    return sorted(results, key=lambda r: r["machine"])


def _monitor_line(r, truth=None):
    t = (truth or {}).get(r["machine"], {})
    hidden = {"wear": lambda: f"kt -{100 * t['kt_loss']:.1f} % by the last day",
              "cross": lambda: f"kcross at B3 from day {t['day']}"}.get(t.get("kind"),
                                                                     lambda: "nothing")()
    alarm = (f"TEST day {r['first_alarm']}: {r['named']}" if r["first_alarm"] else "no TEST")
    cus = f"CUSUM day {r['first_cusum']}" if r["first_cusum"] else "no CUSUM"
    print(f"{r['machine']}  {alarm:58s} {cus:14s} kt {r['kt']:.5g} "
          f"[{r['kt_ci'][0]:.5g}, {r['kt_ci'][1]:.5g}]  (hidden: {hidden})  "
          f"{r['seconds']:.2f} s", flush=True)


def _local_client(workers):
    from dask.distributed import Client, LocalCluster

    # one thread per process: each update is a single-threaded C computation
    cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                           dashboard_address=None)
    return Client(cluster), cluster


def throughput(machines, workers_list, repeat=1):
    """{workers: (machines/s, seconds inside the tasks)} on local clusters, the
    best of `repeat` runs; not timed: the cluster start and a warm-up run of
    one machine per worker (importing librcb, loading the library)."""
    out = {}
    for w in workers_list:
        client, cluster = _local_client(w)
        try:
            client.wait_for_workers(w)
            run_monitor_fleet(client, machines[:w])
            best = (0.0, 0.0)
            for _ in range(repeat):
                t0 = time.perf_counter()
                res = run_monitor_fleet(client, machines)
                rate = len(machines) / (time.perf_counter() - t0)
                if rate > best[0]:
                    best = (rate, sum(r["seconds"] for r in res))
            out[w] = best
        finally:
            client.close()
            cluster.close()
    return out


def throughput_figure(rates, path, title):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    w = sorted(rates)
    fig, ax = plt.subplots(figsize=(5, 3.4))
    ax.plot(w, [rates[k] for k in w], "o-", label="measured")
    ax.plot(w, [rates[w[0]] * k / w[0] for k in w], "k--", lw=0.8, label="linear scaling")
    ax.set_xticks(w)
    ax.set_xlabel("Dask worker processes (1 thread each)")
    ax.set_ylabel("machines monitored per second")
    ax.set_title(title, fontsize=8)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main_monitor(a):
    machines = (make_monitor_fleet(a.dir, a.make, a.days, seed=a.seed) if a.make
                else sorted(p for p in Path(a.dir).glob("machine_*") if p.is_dir()))
    if not machines:
        raise SystemExit(f"no machine_* folders in {a.dir} (use --make N)")
    tf = Path(a.dir) / "truth.json"
    truth = json.loads(tf.read_text()) if tf.is_file() else {}
    if a.scaling:
        import os

        ws = [int(x) for x in a.scaling.split(",")]
        load = os.getloadavg()[0]  # other work on the machine shares its cores
        runs = throughput(machines, ws, repeat=a.repeat)
        rates = {w: runs[w][0] for w in ws}
        for w in ws:
            print(f"{w} worker(s): {rates[w]:.2f} machines/s ({runs[w][1]:.2f} s inside the "
                  f"tasks, {len(machines) / rates[w]:.2f} s wall)")
        if a.figure:
            days = len(list(machines[0].glob("day_*.uff")))
            throughput_figure(rates, a.figure, f"{len(machines)} machines x {days} days, "
                              f"8 channels x 151 frequencies\n{os.cpu_count()} cores, "
                              f"load average {load:.1f} before the run (other work)")
            print(f"wrote {a.figure}")
        return 0
    t0 = time.perf_counter()
    if a.scheduler:
        from dask.distributed import Client
        client, cluster = Client(a.scheduler), None
    else:
        client, cluster = _local_client(a.workers)
    try:
        results = run_monitor_fleet(client, machines, on_result=lambda r: _monitor_line(r, truth))
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    wall = time.perf_counter() - t0
    print(f"{len(results)} machines in {wall:.1f} s wall "
          f"({sum(r['seconds'] for r in results):.1f} s of monitoring)")
    if a.json:
        Path(a.json).write_text(json.dumps(results, indent=1))
    return 0


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
    ap.add_argument("--monitor", action="store_true",
                    help="monitor series of measurements (machine_NNN/day_DDD.uff)")
    ap.add_argument("--days", type=int, default=16, help="--monitor --make: days per machine")
    ap.add_argument("--scaling", help="--monitor: throughput for these worker counts, e.g. 1,2")
    ap.add_argument("--repeat", type=int, default=1, help="--scaling: best of N runs")
    ap.add_argument("--figure", help="--scaling: write the throughput figure here")
    a = ap.parse_args(argv)
    if a.monitor:
        return main_monitor(a)

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
