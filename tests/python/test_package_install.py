"""`pip install ./tools/python` works against the built library: installed into
a scratch target, the package imports from there, loads the library through
LIBRCB_PATH, and carries the rcbplot console script."""

import os
import shutil
import subprocess
import sys

import pytest

from pkg_helpers import REPO, rcb  # noqa: F401  (fixture)


def test_pip_install_and_import(rcb, tmp_path):
    src = tmp_path / "src"
    # a copy, so that setuptools' build/ and egg-info stay out of the checkout
    shutil.copytree(REPO / "tools" / "python", src,
                    ignore=shutil.ignore_patterns("build", "*.egg-info", "__pycache__"))
    target = tmp_path / "site"
    res = subprocess.run([sys.executable, "-m", "pip", "install", "--quiet", "--no-deps",
                          "--no-build-isolation", "--no-index", "--target", str(target),
                          str(src)], capture_output=True, text=True, timeout=300)
    assert res.returncode == 0, res.stdout + res.stderr
    assert (target / "librcb" / "_lib.py").is_file()
    assert (target / "bin" / "rcbplot").is_file()
    env = dict(os.environ, PYTHONPATH=str(target), LIBRCB_PATH=rcb.library_path())
    code = ("import librcb, sys; m = librcb.Model.from_ini(sys.argv[1]); "
            "print(librcb.__file__); print(m.dofs, librcb.library_version())")
    res = subprocess.run([sys.executable, "-c", code, str(REPO / "examples" /
                                                        "paper_system.ini")],
                         capture_output=True, text=True, env=env, cwd=tmp_path, timeout=120)
    assert res.returncode == 0, res.stderr
    where, info = res.stdout.split("\n")[:2]
    assert where.startswith(str(target))
    assert info.split()[0] == "88"
    # a wrong LIBRCB_PATH is a clear error, not a crash
    env["LIBRCB_PATH"] = str(tmp_path / "nosuch.so")
    res = subprocess.run([sys.executable, "-c", code, "x"], capture_output=True, text=True,
                         env=env, cwd=tmp_path, timeout=120)
    assert res.returncode != 0 and "LIBRCB_PATH" in res.stderr and "not found" in res.stderr
