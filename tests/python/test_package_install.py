"""The package's entry points and its LIBRCB_PATH override, from tools/python.
`pip install .` itself (pyproject.toml at the root: scikit-build-core compiling
librcb.so into the package, from an sdist) is tested in a fresh venv by
tests/wheel/test_wheel.sh, the `wheel` stage of scripts/dev.sh test: it needs
PyPI and a minute of compiling."""

import os
import subprocess
import sys
import tomllib

from pkg_helpers import REPO, rcb  # noqa: F401  (fixture)

PKG = REPO / "tools" / "python"


def test_console_scripts_exist(rcb):
    scripts = tomllib.loads((REPO / "pyproject.toml").read_text())["project"]["scripts"]
    assert set(scripts) == {"rcbplot", "rcbtool"}
    for target in scripts.values():
        module, func = target.split(":")
        code = f"import {module} as m; assert callable(m.{func})"
        res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                             env=dict(os.environ, PYTHONPATH=str(PKG)), timeout=120)
        assert res.returncode == 0, res.stderr


def test_wrong_librcb_path_is_a_clear_error(rcb, tmp_path):
    code = ("import librcb, sys; m = librcb.Model.from_ini(sys.argv[1]); "
            "print(m.dofs)")
    paper = str(REPO / "examples" / "paper_system.ini")
    env = dict(os.environ, PYTHONPATH=str(PKG), LIBRCB_PATH=os.path.abspath(rcb.library_path()))
    res = subprocess.run([sys.executable, "-c", code, paper], capture_output=True,
                         text=True, env=env, cwd=tmp_path, timeout=120)
    assert res.returncode == 0 and res.stdout.split() == ["88"], res.stderr
    env["LIBRCB_PATH"] = str(tmp_path / "nosuch.so")
    res = subprocess.run([sys.executable, "-c", code, paper], capture_output=True,
                         text=True, env=env, cwd=tmp_path, timeout=120)
    assert res.returncode != 0 and "LIBRCB_PATH" in res.stderr and "not found" in res.stderr
