"""Fleet-scale batch (examples/python/fleet_dask.py): one fit per measurement
file on a dask.distributed LocalCluster of 2 worker processes; each machine's
hidden coupling values are recovered within the noise."""

import importlib.util
import json
import os

import pytest

from pkg_helpers import REPO, rcb  # noqa: F401  (fixture)

distributed = pytest.importorskip("distributed")


def _example():
    spec = importlib.util.spec_from_file_location(
        "fleet_dask", REPO / "examples" / "python" / "fleet_dask.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_fleet_fits_on_a_local_cluster(rcb, tmp_path, monkeypatch):
    fleet = _example()
    files = fleet.make_fleet(tmp_path, 4, seed=7, points=61)
    assert len(files) == 4
    truth = json.loads((tmp_path / "truth.json").read_text())
    # the workers import the same package and load the same library
    pkg = os.path.dirname(os.path.dirname(rcb.__file__))
    monkeypatch.setenv("PYTHONPATH", pkg + os.pathsep + os.environ.get("PYTHONPATH", ""))
    monkeypatch.setenv("LIBRCB_PATH", rcb.library_path())
    monkeypatch.setenv("OPENBLAS_NUM_THREADS", "1")
    from dask.distributed import Client, LocalCluster
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                      dashboard_address=None) as cluster, Client(cluster) as client:
        results = fleet.run_fleet(client, files)
        workers = {w for w in client.scheduler_info()["workers"]}
    assert len(workers) == 2
    assert [r["file"] for r in results] == [p.name for p in files]
    for r in results:
        hidden = truth[r["file"]]
        for name, value in hidden.items():
            # 10 % random + 1 % systematic noise: a few % at most on kt, kr
            assert r["values"][name] == pytest.approx(value, rel=0.05), (r["file"], name)
        assert r["error_pct"] < r["error0_pct"] or r["error0_pct"] < 1.5 * r["floor_pct"]
        assert r["error_pct"] < 1.5 * r["floor_pct"] and not r["unsure"]


def test_fleet_monitor_streams_results(rcb, tmp_path, monkeypatch):
    """Monitoring (issue #16) on a LocalCluster of 2 workers: each machine's
    files travel as bytes (the workers run in another directory and are never
    given a path), results arrive through as_completed. Four machines of 8
    days (3 commissioning): nothing, two coupling wears, a cross-coupling at B3
    from a day in the second half (librcb's own simulate, eq. 19 noise: the plumbing;
    tests/python/test_monitor_ross.py tests the statistics on ROSS data)."""
    fleet = _example()
    machines = fleet.make_monitor_fleet(tmp_path / "fleet", 4, 8, seed=3, points=101)
    truth = json.loads((tmp_path / "fleet" / "truth.json").read_text())
    pkg = os.path.abspath(os.path.dirname(os.path.dirname(rcb.__file__)))
    monkeypatch.setenv("PYTHONPATH", pkg + os.pathsep + os.environ.get("PYTHONPATH", ""))
    monkeypatch.setenv("LIBRCB_PATH", os.path.abspath(rcb.library_path()))
    monkeypatch.setenv("OPENBLAS_NUM_THREADS", "1")
    work = tmp_path / "elsewhere"
    work.mkdir()
    monkeypatch.chdir(work)  # relative paths would not resolve on the workers
    from dask.distributed import Client, LocalCluster
    seen = []
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                      dashboard_address=None) as cluster, Client(cluster) as client:
        results = fleet.run_monitor_fleet(client, machines, on_result=seen.append)
    assert sorted(r["machine"] for r in seen) == [m.name for m in machines]
    assert [r["machine"] for r in results] == [m.name for m in machines]
    for r in results:
        t = truth[r["machine"]]
        assert r["updates"] == 5 and r["memory"] > 0
        if t["kind"] == "cross":
            assert r["first_alarm"] is not None and r["first_alarm"] >= t["day"], (r, t)
            assert r["named"] == "bearing cross-coupled stiffness at bearing B3", r
        elif t["kind"] == "none":
            assert r["first_alarm"] is None and r["first_cusum"] is None, (r, t)
        else:  # wear: kt's CUSUM notices it falling (the last kt is below the design's)
            assert r["first_cusum"] is not None and r["kt_ci"][1] < 46095.0, (r, t)
