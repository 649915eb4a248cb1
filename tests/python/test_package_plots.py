"""librcb Python package: every picture renders to a PNG that is not blank,
from the API and from the command-line entry (python -m librcb plot)."""

import os
import subprocess
import sys

import numpy as np
import pytest

from pkg_helpers import PAPER, REPO, paper, rcb  # noqa: F401  (fixtures)

matplotlib = pytest.importorskip("matplotlib")
matplotlib.use("Agg")


def _check_png(path, min_std=0.02):
    """The file is a PNG with real content: pixel values vary, and not only
    along one edge (a blank canvas with a frame would fail)."""
    import matplotlib.image as mpimg
    assert path.is_file() and path.stat().st_size > 5000
    img = mpimg.imread(path)[..., :3]
    assert img.shape[0] > 300 and img.shape[1] > 300
    assert img.std() > min_std
    h, w = img.shape[:2]
    centre = img[h // 4: 3 * h // 4, w // 4: 3 * w // 4]
    assert centre.std() > min_std / 2


def _save(fig, path):
    import matplotlib.pyplot as plt
    fig.savefig(path, dpi=80)
    plt.close(fig)
    _check_png(path)


def test_campbell_png(rcb, paper, tmp_path):
    from librcb import plots
    cb = rcb.campbell(paper, np.linspace(0, 20000, 41), n=6)
    _save(plots.campbell_figure(cb), tmp_path / "campbell.png")
    assert plots.forward_critical_rpm(cb)  # the paper system has forward criticals


def test_mode_shapes_png(rcb, paper, tmp_path):
    from librcb import plots
    md = rcb.modes(paper, 10000, n=4)
    _save(plots.mode_shapes_figure(md, stations=paper.stations), tmp_path / "modes.png")
    # the per-node whirl rule of the picture agrees with the library's mode whirl
    for k in range(len(md)):
        w = plots.node_whirl(md.node_shape(k))
        moving = np.abs(md.node_shape(k)).max(axis=1) > 1e-3
        if md.whirl[k] != "mixed":
            assert set(w[moving]) == {1 if md.whirl[k] == "forward" else -1}


def test_frf_png(rcb, paper, tmp_path):
    from librcb import plots
    f = np.linspace(0, 500, 201)
    H = rcb.frf(paper, ["C.A.x", "C.B.x"], ["DA.x"], f, rpm=10000)
    _save(plots.frf_figure(f, H, ["C.A.x", "C.B.x"], ["DA.x"], rpm=10000),
          tmp_path / "frf.png")


def test_unbalance_png(rcb, paper, tmp_path):
    from librcb import plots
    r = np.linspace(0, 20000, 101)
    Q = rcb.unbalance(paper, ["DA.x", "DB.x"], r)
    _save(plots.unbalance_figure(r, Q, ["DA.x", "DB.x"], critical_rpm=[9032.0]),
          tmp_path / "unbalance.png")


def test_meas_png(rcb, paper, tmp_path):
    from librcb import plots
    ms = rcb.simulate(paper, ["C.A.x"], ["DA.x"], np.linspace(100, 400, 61), rpm=10000,
                      kind="inertance", noise=(10, 1))
    _save(plots.meas_figure(ms), tmp_path / "meas.png")


@pytest.mark.parametrize("args", [
    ["campbell", str(PAPER), "--rpm-max", "20000", "--points", "21"],
    ["modes", str(PAPER), "--rpm", "10000", "--modes", "3"],
    ["frf", str(PAPER), "--out", "C.A.x", "--in", "DA.x", "--fmax", "500", "--points", "101",
     "--rpm", "10000", "--kind", "mobility"],
    ["unbalance", str(PAPER), "--out", "DA.x,DA.y", "--rpm-max", "20000", "--points", "81"],
    ["meas", str(REPO / "examples" / "walkthrough" / "measured.uff"), "--model",
     str(REPO / "examples" / "walkthrough" / "model.ini")],
], ids=["campbell", "modes", "frf", "unbalance", "meas"])
def test_command_line(rcb, tmp_path, args):
    out = tmp_path / f"{args[0]}.png"
    env = dict(os.environ, MPLBACKEND="Agg")
    pkg_dir = os.path.dirname(os.path.dirname(rcb.__file__))
    env["PYTHONPATH"] = pkg_dir + os.pathsep + env.get("PYTHONPATH", "")
    res = subprocess.run([sys.executable, "-m", "librcb", "plot", *args, "-o", str(out)],
                         capture_output=True, text=True, env=env, timeout=300)
    assert res.returncode == 0, res.stderr
    _check_png(out)


def test_command_line_error_names_the_line(rcb, tmp_path):
    bad = tmp_path / "bad.ini"
    bad.write_text("[shaft A]\nmaterial = nosuch\n")
    env = dict(os.environ, PYTHONPATH=os.path.dirname(os.path.dirname(rcb.__file__)))
    res = subprocess.run([sys.executable, "-m", "librcb", "plot", "modes", str(bad), "-o",
                          str(tmp_path / "x.png")], capture_output=True, text=True, env=env)
    assert res.returncode == 1 and "bad.ini:" in res.stderr
