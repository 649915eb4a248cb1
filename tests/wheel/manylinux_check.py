"""The self-contained wheel in a clean root (tests/wheel/manylinux_test.sh):
the installed package against things that could prove it wrong, and where
each shared library it loads comes from.

usage: python manylinux_check.py PAPER_SYSTEM_INI   (from a scratch directory)
"""

import math
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

import librcb

PAPER = Path(sys.argv[1])
VENDORED = ("libopenblas", "liblapack", "libblas", "liblapacke", "libklu", "libamd",
            "libcolamd", "libbtf", "libsuitesparseconfig", "libnlopt", "libinih", "libfftw3",
            "libgfortran", "libquadmath")

# ---- 1. the library and what it loads ----------------------------------------
pkg = Path(librcb.__file__).resolve().parent
lib = Path(librcb.library_path()).resolve()
assert lib.parent == pkg, f"librcb.so loaded from {lib}, not from the package {pkg}"
maps = {line.split()[-1] for line in Path("/proc/self/maps").read_text().splitlines()
        if ".so" in line.split()[-1]}
libs_dir = pkg.parent / "librcb.libs"
ours = sorted(Path(p).name for p in maps if Path(p).parent == libs_dir)
site = pkg.parent
for p in maps:  # never from the system (numpy brings its own libquadmath in numpy.libs)
    name = Path(p).name
    if name.startswith(VENDORED):
        assert Path(p).parent.parent == site, f"{name} loaded from {p}, not from a wheel"
for want in ("libopenblas", "liblapacke", "libklu", "libnlopt", "libinih", "libfftw3",
             "libgfortran"):
    assert any(n.startswith(want) for n in ours), f"no {want} loaded from {libs_dir}: {ours}"
print(f"librcb {librcb.library_version()} from {lib.relative_to(pkg.parent)}; "
      f"{len(ours)} libraries loaded from librcb.libs/: {' '.join(ours)}")

# ---- 2. an FRF against a closed form --------------------------------------------
# A short, very stiff shaft (E = 2.1e14 Pa) with a heavy central disk on two
# equal isotropic bearings at its ends (tests/test_frf.c, rigid rotor): a
# force at the disk excites only the rigid translation,
#   H = 1 / (2k - w^2 m_total + i w 2c),
# up to the shaft's flexibility (k / k_shaft ~ 3e-8: < 1e-5 even at resonance).
k, c, L, d, rho, md = 1e6, 300.0, 0.2, 0.2, 7800.0, 50.0
RIGID = f"""
[material steel]
density = {rho}
young = 2.1e14
poisson = 0.3
[shaft S]
material = steel
start = 0.0
shear_factor = 0.9
segment = {L} {d} 0.0 4
[disk D]
at = S 0.1
mass = {md}
Id = 1.0
Ip = 1.5
[bearing L]
at = S 0.0
kxx = {k}
kyy = {k}
cxx = {c}
cyy = {c}
[bearing R]
at = S {L}
kxx = {k}
kyy = {k}
cxx = {c}
cyy = {c}
"""
m = librcb.Model.from_ini(RIGID, name="<rigid rotor>")
mt = rho * math.pi * d * d / 4 * L + md
f = np.geomspace(10, 400, 40) / (2 * math.pi)  # Hz: w = 10 .. 400 rad/s
H = librcb.frf(m, ["D.x"], ["D.x"], f, rpm=0)[:, 0, 0]
w = 2 * math.pi * f
ref = 1 / (2 * k - w * w * mt + 2j * w * c)
err = np.max(np.abs(H - ref) / np.abs(ref))
assert err < 1e-4, f"rigid rotor: the FRF differs from the closed form by {err:.3g}"
print(f"FRF, rigid rotor on springs, 40 points through resonance: max relative difference "
      f"from 1/(2k - w^2 m + 2i w c) = {err:.1e}")

# ---- 3. the paper system: FRF against numpy, and rcbtool --------------------------
paper = librcb.Model.from_ini(PAPER)
outs, ins, rpm = ["C.A.x", "DB.y"], ["DA.x"], 10000.0
fp = np.linspace(0, 500, 201)
Hp = librcb.frf(paper, outs, ins, fp, rpm=rpm)[:, :, 0]
M, C, G, K = paper.matrices(rpm)
ro = [paper.dof_index(o) for o in outs]
ri = [paper.dof_index(i) for i in ins]
worst = 0.0
for j, fk in enumerate(fp[::20]):
    wk = 2 * math.pi * fk
    Hn = np.linalg.inv(K - wk * wk * M + 1j * wk * (C + rpm * math.pi / 30 * G))[np.ix_(ro, ri)]
    worst = max(worst, np.max(np.abs(Hp[20 * j] - Hn[:, 0])) / np.max(np.abs(Hn)))
assert worst < 1e-9, f"paper system: FRF differs from numpy's inverse by {worst:.3g}"
r = subprocess.run(["rcbtool", "frf", str(PAPER), "--out", ",".join(outs), "--in", ins[0],
                    "--fmin", "0", "--fmax", "500", "--points", "201", "--rpm", "10000",
                    "-o", "cli.csv"], capture_output=True, text=True)
assert r.returncode == 0, r.stderr
dc = np.loadtxt("cli.csv", delimiter=",", comments="#", skiprows=3)
Hc = dc[:, 1::2] + 1j * dc[:, 2::2]
errc = np.max(np.abs(Hc - Hp)) / np.max(np.abs(Hp))
assert errc < 1e-10, f"rcbtool's FRF differs from librcb.frf by {errc:.3g}"
print(f"FRF, paper system (2 x 1, 201 points, 10000 rpm): vs numpy's inverse of the dynamic "
      f"stiffness {worst:.1e}; the rcbtool console script's CSV vs librcb.frf {errc:.1e}")

# ---- 4. one fit: hidden coupling stiffnesses ------------------------------------
truth = paper.copy()
truth.set("coupling.C.kt", 2.5 * paper.get("coupling.C.kt"))
truth.set("coupling.C.kr", 0.4 * paper.get("coupling.C.kr"))
meas = librcb.simulate(truth, ["C.A.x", "C.A.y", "C.B.x", "C.B.y"], ["DA.x"],
                       np.linspace(200, 400, 81), rpm=10000, kind="inertance")
t = time.perf_counter()
res = librcb.fit(paper, meas, ["coupling.C.kt", "coupling.C.kr"])
tfit = time.perf_counter() - t
rel = max(abs(res.values[n] / truth.get(n) - 1) for n in ("coupling.C.kt", "coupling.C.kr"))
assert rel < 1e-5 and res.report["converged"], (res.values, res.report)
print(f"fit of kt, kr from noise-free data (truth x2.5, x0.4): largest relative error "
      f"{rel:.1e}, {tfit:.2f} s")

# ---- 5. import times, each in a fresh interpreter: median and least of 7 -----------
# (the least is the figure a loaded machine disturbs least)
def timed(stmt):
    code = f"import time; t = time.perf_counter(); {stmt}; print(time.perf_counter() - t)"
    runs = [1e3 * float(subprocess.run([sys.executable, "-c", code], capture_output=True,
                                       text=True, check=True).stdout) for _ in range(7)]
    return f"{statistics.median(runs):.0f} ({min(runs):.0f})"


t_np = timed("import numpy")
t_rcb = timed("import librcb")
t_load = timed("import librcb; librcb.library_version()")
print(f"import times (ms, median (least) of 7 fresh interpreters): import numpy {t_np}; "
      f"import librcb {t_rcb} (numpy included); import librcb + loading librcb.so and "
      f"its libraries {t_load}")
print("manylinux_check: passed")
