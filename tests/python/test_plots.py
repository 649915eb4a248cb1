"""rcbtool compare --plot: the overlay and residual-map pictures are written
by tools/python/rcb_plots.py and are not blank (pixel variance), for FRF and
unbalance data; a clear error when Python has no matplotlib."""

import os
import subprocess
import sys
from pathlib import Path

import pytest

matplotlib = pytest.importorskip("matplotlib")

REPO = Path(__file__).resolve().parent.parent.parent
MODEL = REPO / "examples" / "paper_system.ini"
SCRIPT = REPO / "tools" / "python" / "rcb_plots.py"


def _exe():
    path = os.environ.get("RCBTOOL")
    if not path:
        pytest.skip("RCBTOOL is not set (path to the rcbtool executable)")
    if not (Path(path).is_file() and os.access(path, os.X_OK)):
        pytest.fail(f"RCBTOOL={path!r} is set but is not an executable file")
    return path


def _run(*args, env=None):
    e = dict(os.environ)
    e.update(env or {})
    res = subprocess.run([_exe(), *map(str, args)], capture_output=True, text=True,
                         timeout=300, env=e)
    return res


def _not_blank(png):
    from matplotlib import image

    img = image.imread(str(png))
    assert img.ndim == 3 and img.shape[0] > 300 and img.shape[1] > 500, img.shape
    gray = img[..., :3].mean(axis=2)
    assert gray.var() > 1e-3, f"{png} looks blank (pixel variance {gray.var():.2e})"
    # ink on at least 2 % of the pixels: curves, text, a colour map
    assert (gray < 0.9).mean() > 0.02


@pytest.fixture(scope="module")
def softer_model(tmp_path_factory):
    """The paper system with the coupling's kt halved (the 'wrong' model)."""
    d = tmp_path_factory.mktemp("cmp")
    text = MODEL.read_text().replace("kt = 46.095e3 ", "kt = 23.0e3 ")
    assert "kt = 23.0e3 " in text
    p = d / "soft.ini"
    p.write_text(text)
    return p


@pytest.mark.parametrize("kind", ["frf", "unbalance"])
def test_plots_rendered(tmp_path, softer_model, kind):
    meas = tmp_path / "meas.csv"
    if kind == "frf":
        sim = ["--frf", "--out", "C.A.x,C.A.y,C.B.x,DB.y", "--in", "DA.x", "--fmin", 5,
               "--fmax", 400, "--points", 400, "--rpm", 3000, "--kind", "inertance"]
    else:
        sim = ["--unbalance", "--out", "DA.x,DA.y,DB.x,DB.y", "--rpm-min", 300,
               "--rpm-max", 18300, "--points", 301]
    r = _run("simulate", MODEL, *sim, "--noise", "5,0.5", "--seed", 1, "-o", meas)
    assert r.returncode == 0, r.stderr
    prefix = tmp_path / "run"
    r = _run("compare", softer_model, meas, "--plot", prefix,
             env={"RCB_PYTHON": sys.executable, "RCB_PLOTS": str(SCRIPT)})
    assert r.returncode == 0, r.stderr
    assert "peaks" in r.stdout
    for suffix in ("_overlay.png", "_residual_map.png"):
        _not_blank(Path(str(prefix) + suffix))
    assert Path(str(prefix) + "_compare.json").is_file()


def test_script_found_without_env(tmp_path, softer_model):
    """rcbtool finds rcb_plots.py by itself (next to it, share/rcb, or the source tree)."""
    meas = tmp_path / "m.csv"
    r = _run("simulate", MODEL, "--unbalance", "--out", "DA.x", "--rpm-min", 300,
             "--rpm-max", 9000, "--points", 50, "-o", meas)
    assert r.returncode == 0, r.stderr
    env = {"RCB_PYTHON": sys.executable, "RCB_PLOTS": ""}
    r = _run("compare", softer_model, meas, "--plot", tmp_path / "p", env=env)
    assert r.returncode == 0, r.stderr
    _not_blank(tmp_path / "p_overlay.png")


def test_missing_matplotlib(tmp_path, softer_model):
    """A Python without matplotlib: exit 5 and a message that says what to do."""
    meas = tmp_path / "m.csv"
    r = _run("simulate", MODEL, "--unbalance", "--out", "DA.x", "--rpm-min", 300,
             "--rpm-max", 9000, "--points", 20, "-o", meas)
    assert r.returncode == 0, r.stderr
    fake = tmp_path / "nompl"
    fake.mkdir()
    (fake / "matplotlib.py").write_text("raise ImportError('hidden for the test')\n")
    wrapper = tmp_path / "py.sh"
    wrapper.write_text(f"#!/bin/sh\nPYTHONPATH={fake} exec {sys.executable} \"$@\"\n")
    wrapper.chmod(0o755)
    r = _run("compare", softer_model, meas, "--plot", tmp_path / "q",
             env={"RCB_PYTHON": str(wrapper), "RCB_PLOTS": str(SCRIPT)})
    assert r.returncode == 5, (r.returncode, r.stderr)
    assert "matplotlib" in r.stderr and "RCB_PYTHON" in r.stderr
    assert not (tmp_path / "q_overlay.png").exists()
    r = _run("compare", softer_model, meas, "--plot", tmp_path / "q",
             env={"RCB_PYTHON": str(tmp_path / "no-such-python"), "RCB_PLOTS": str(SCRIPT)})
    assert r.returncode == 5 and "no-such-python" in r.stderr, r.stderr


@pytest.fixture(scope="module")
def test_signals(tmp_path_factory):
    """A short simulated random test (0.5 s, force at DA.x) and a run-up with
    a keyphasor, both from rcbtool transient --signals."""
    d = tmp_path_factory.mktemp("sig")
    rnd, run = d / "random.csv", d / "runup.csv"
    r = _run("transient", MODEL, "--out", "DA.x,DB.x", "--rpm", 3000, "--t-end", 0.5, "--dt",
             1 / 2048, "--rtol", 1e-4, "--atol", "1e-10,1e-7", "--signals", "--force", "random",
             "--force-at", "DA.x", "-o", rnd)
    if r.returncode == 4 and "without SUNDIALS" in r.stderr:
        pytest.skip("librcb built without SUNDIALS")
    assert r.returncode == 0, r.stderr
    r = _run("transient", MODEL, "--out", "DA.x,DA.y", "--rpm", 500, "--rpm-end", 6000,
             "--accel", 2000, "--signals", "-o", run)
    assert r.returncode == 0, r.stderr
    return rnd, run


def test_estimate_and_order_plots(tmp_path, test_signals):
    """estimate --plot (FRF with coherence) and order --plot (Bode and polar):
    pictures not blank, their directories made, no temporary left."""
    rnd, run = test_signals
    env = {"RCB_PYTHON": sys.executable, "RCB_PLOTS": str(SCRIPT)}
    est = tmp_path / "pics" / "est.png"
    r = _run("estimate", rnd, "--input", "force=DA.x", "--outputs", "DA.x,DB.x", "--nseg", 256,
             "--rpm", 3000, "--stats", tmp_path / "st.csv", "-o", tmp_path / "h1.csv",
             "--plot", est, env=env)
    assert r.returncode == 0, r.stderr
    _not_blank(est)
    ordp = tmp_path / "pics" / "order.png"
    r = _run("order", run, "--kp", "KP", "--outputs", "DA.x,DA.y", "-o", tmp_path / "1x.csv",
             "--plot", ordp, env=env)
    assert r.returncode == 0, r.stderr
    _not_blank(ordp)
    assert sorted(p.name for p in (tmp_path / "pics").iterdir()) == ["est.png", "order.png"]


def test_estimate_plot_failure_writes_nothing(tmp_path, test_signals):
    """A plot that fails (no such Python) or names an input: exit 5, no output
    file of the run, the input untouched."""
    rnd, run = test_signals
    env = {"RCB_PYTHON": str(tmp_path / "no-such-python"), "RCB_PLOTS": str(SCRIPT)}
    out, st, png = tmp_path / "h1.csv", tmp_path / "st.csv", tmp_path / "e.png"
    r = _run("estimate", rnd, "--input", "force=DA.x", "--outputs", "DA.x", "--nseg", 256,
             "--stats", st, "-o", out, "--plot", png, env=env)
    assert r.returncode == 5 and "no-such-python" in r.stderr, r.stderr
    assert "no output file was written" in r.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == []
    before = run.read_bytes()
    r = _run("order", run, "--kp", "KP", "--outputs", "DA.x", "-o", tmp_path / "1x.csv",
             "--plot", run, env={"RCB_PYTHON": sys.executable, "RCB_PLOTS": str(SCRIPT)})
    assert r.returncode == 5, r.stderr
    assert run.read_bytes() == before and not (tmp_path / "1x.csv").exists()

@pytest.mark.parametrize("ext", ["png", "svg"])
def test_monitor_trend_plot(tmp_path, ext):
    """rcbtool monitor --plot: the trend picture (png rendered and not blank; svg
    in its format); a plot that cannot be drawn leaves no log and no picture."""
    days = tmp_path / "days"
    days.mkdir()
    for k in range(5):
        res = _run("simulate", MODEL, "--frf", "--out", "C.A.x,C.A.y,C.B.x,C.B.y", "--in", "DA.x",
                   "--fmin", 100, "--fmax", 400, "--points", 61, "--rpm", 10000, "--kind",
                   "inertance", "--noise", "10,1", "--seed", k + 1, "-o", days / f"d{k}.csv")
        assert res.returncode == 0, res.stderr
    env = {"RCB_PYTHON": sys.executable}
    pic, log = tmp_path / "out" / f"trend.{ext}", tmp_path / "log.json"
    res = _run("monitor", MODEL, days, "--params", "coupling.C.kt", "--noise", "10,1",
               "--commission", 2, "--log", log, "--plot", pic, env=env)
    assert res.returncode == 0, res.stderr
    assert log.is_file() and pic.is_file()
    if ext == "png":
        _not_blank(pic)
    else:
        assert pic.read_text().lstrip().startswith("<?xml") and "<svg" in pic.read_text()
    assert not [p for p in pic.parent.iterdir() if p != pic], "temporaries left"
    pic.unlink()
    log.unlink()
    res = _run("monitor", MODEL, days, "--params", "coupling.C.kt", "--noise", "10,1",
               "--commission", 2, "--log", log, "--plot", pic,
               env={"RCB_PYTHON": sys.executable, "RCB_PLOTS": str(tmp_path / "none.py")})
    assert res.returncode == 5 and "plotting script" in res.stderr, res.stderr
    assert not log.exists() and not pic.exists()
