"""Build the same rotor models in ROSS (ross-rotordynamics 2.3) as librcb.

The INI parser (independent of the C loader) and the ROSS builder live in the
package's ROSS bridge, ``librcb.ross_bridge`` (tools/python/librcb); this
module keeps the names the cross-validation tests use, the INI variants the
examples do not cover, and the ROSS-side damped-mode helpers.

* each shaft segment -> ``n`` ShaftElements of length L/n, with shear,
  rotary inertia and gyroscopics on, ROSS's phi overwritten with the INI
  ``shear_factor``; proportional damping alpha = damping_mass (1/s),
  beta = damping_stiffness (s);
* disks -> DiskElement; bearings -> BearingElement, speed tables interpolated
  linearly here at the requested speed (the ROSS rotor is built per speed);
* nelson_crandall_1/2 couplings -> CouplingElement.

ROSS is 6 DOF/node [x, y, z, alpha, beta, theta]; the lateral DOFs of ROSS
node n are 6 n + (0, 1, 3, 4). ``RossModel.node_keys`` gives (shaft name, z)
of every ROSS node. Units are SI throughout (m, kg, N/m, N s/m, rad/s).
"""

import math
import sys
from pathlib import Path

import numpy as np

try:
    from librcb import ross_bridge
except ImportError:  # package not installed: use the repository's source
    sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "tools" / "python"))
    from librcb import ross_bridge

LATERAL = ross_bridge.LATERAL
Model = ross_bridge.Model
parse_ini = ross_bridge.parse_ini
annulus = ross_bridge.annulus


def RossModel(model, speed=0.0, override_shear=True):
    """A ROSS rotor built from a Model for one rotor speed (rad/s; it selects
    tabulated bearings), with the node map (ross_bridge.IniRotor).
    override_shear=False keeps ROSS's own (Cowper) shear factor: only to show
    that the comparison would notice it."""
    return ross_bridge.IniRotor(model, speed=speed, override_shear=override_shear)


def element_factors_edit(shaft, k, stiffness=1.0, mass=1.0):
    """model_edit (as those of diag_cases.py): element k (counted from 1 in z
    order, librcb's shaft.SHAFT.e<k>) of shaft SHAFT gets its own ROSS Material
    with E (and so G) times `stiffness` and density times `mass`; librcb's
    shaft.SHAFT.e<k>.stiffness and .mass are the same model."""

    def edit(model):
        sh = next(s for s in model.shafts if s.name == shaft)
        if not 1 <= k <= len(sh.elements):
            raise ValueError(f"shaft {shaft} has elements 1 to {len(sh.elements)}, not {k}")
        fk, fm = sh.factors.get(k - 1, (1.0, 1.0))
        sh.factors[k - 1] = (fk * stiffness, fm * mass)

    return edit


def element_stiffness_edit(shaft, k, factor):
    """model_edit: element k of shaft SHAFT with E and G times factor (a crack,
    wear, a loose shrink fit): librcb's shaft.SHAFT.e<k>.stiffness = factor."""
    return element_factors_edit(shaft, k, stiffness=factor)


def element_mass_edit(shaft, k, factor):
    """model_edit: element k of shaft SHAFT with its density times factor:
    librcb's shaft.SHAFT.e<k>.mass = factor."""
    return element_factors_edit(shaft, k, mass=factor)


# --------------------------------------------------------------------------
# The models, as INI text in librcb's format. Used when examples/ lacks the
# file, and always for the variants the examples do not cover.
# --------------------------------------------------------------------------

PAPER_SYSTEM_INI = """
[model]
name = paper system (Tapia & Cavalca, issue #2 reconstruction)
[material steel]
density = 7759.255      ; kg/m^3
young = 1.936e11        ; Pa
poisson = 0.3
[shaft A]
material = steel
start = 0.0
shear_factor = 0.9
damping_mass = 15.691          ; 1/s
damping_stiffness = 22.989e-6  ; s
segment = 0.50 0.017 0.0 10
[shaft B]
material = steel
start = 0.52
shear_factor = 0.9
damping_mass = 15.691
damping_stiffness = 22.989e-6
segment = 0.50 0.017 0.0 10
[disk DA]
at = A 0.20
density = 6303.235
outer_diameter = 0.090
inner_diameter = 0.017
width = 0.025
[disk DB]
at = B 0.82
density = 6303.235
outer_diameter = 0.090
inner_diameter = 0.017
width = 0.025
[bearing B1]
at = A 0.05
kxx = 5e7
kyy = 7e7
cxx = 500
cyy = 700
[bearing B2]
at = A 0.35
kxx = 7e7
kyy = 9e7
cxx = 300
cyy = 500
[bearing B3]
at = B 0.67
kxx = 5e7
kyy = 7e7
cxx = 500
cyy = 700
[bearing B4]
at = B 0.97
kxx = 7e7
kyy = 9e7
cxx = 300
cyy = 500
[coupling C]
model = nelson_crandall_2
between = A end, B start
kt = 46.095e3
kr = 220.76
ct = 10.949
cr = 10.949e-6
hub_density = 2758.219
hub_inner_radius = 0.006
hub_outer_radius = 0.017
hub_thickness = 0.043115
[unbalance UA]
at = DA
amount = 15e-5
phase_deg = 0
[unbalance UB]
at = DB
amount = 15e-5
phase_deg = 90
"""

# Single shaft, two segments (solid, then hollow), two disks (one explicit,
# one from geometry), strongly anisotropic bearings; run at speed so that
# the gyroscopic terms matter.
TWO_DISK_ANISO_INI = """
[model]
name = two disks, anisotropic bearings
[material steel]
density = 7810
young = 2.11e11
poisson = 0.3
[shaft S]
material = steel
start = 0.0
shear_factor = 0.8
damping_stiffness = 1e-5
segment = 0.60 0.030 0.0 12
segment = 0.40 0.040 0.010 8
[disk D1]
at = S 0.25
mass = 12.0
Id = 0.06
Ip = 0.11
[disk D2]
at = S 0.80
density = 7810
outer_diameter = 0.30
inner_diameter = 0.040
width = 0.05
[bearing BL]
at = S 0.0
kxx = 1e7
kyy = 4e7
cxx = 200
cyy = 900
[bearing BR]
at = S 1.0
kxx = 3e7
kyy = 8e6
cxx = 1000
cyy = 150
[unbalance U1]
at = D1
amount = 2e-4
phase_deg = 30
[unbalance U2]
at = D2
amount = 1e-4
phase_deg = -60
[station P1]
at = S 0.45
"""

# Cross-coupled (fluid-film-like) bearing coefficients: kxy = -kyx,
# cxy and cyx non-zero, mass- and stiffness-proportional damping.
CROSS_COUPLED_INI = """
[model]
name = cross-coupled bearings
[material steel]
density = 7850
young = 2.05e11
poisson = 0.29
[shaft R]
material = steel
start = 0.1
shear_factor = 0.886
damping_mass = 2.0
damping_stiffness = 3e-6
segment = 0.15 0.05 0.0 3
segment = 0.50 0.07 0.0 10
segment = 0.15 0.05 0.0 3
[disk D]
at = R 0.5
density = 7850
outer_diameter = 0.35
inner_diameter = 0.07
width = 0.06
[bearing J1]
at = R 0.15
kxx = 2.5e7
kxy = 1.2e7
kyx = -1.2e7
kyy = 3.5e7
cxx = 4e3
cxy = 800
cyx = 600
cyy = 6e3
[bearing J2]
at = R 0.85
kxx = 2.0e7
kxy = -0.9e7
kyx = 0.9e7
kyy = 3.0e7
cxx = 3e3
cxy = -500
cyx = 700
cyy = 4.5e3
[unbalance U]
at = D
amount = 5e-4
phase_deg = 45
"""

MODELS = {
    "paper_system": PAPER_SYSTEM_INI,
    "two_disk_aniso": TWO_DISK_ANISO_INI,
    "cross_coupled": CROSS_COUPLED_INI,
}


# --------------------------------------------------------------------------
# Damped modes on the ROSS side
# --------------------------------------------------------------------------

# librcb's documented floor (rcb_modes_compute): a root oscillates when
# Im(lambda) > 1e-7 max|lambda| (max over the lateral roots).
IM_FLOOR = 1e-7


def lateral_roots(rmod, speed, whirl=False):
    """ROSS's lateral roots with Im > 0 at rotor speed (rad/s), sorted by Im.

    Returns (lam, big, whirls): big = max |lambda| over all lateral roots;
    whirls (if asked) are ROSS's 'forward' | 'backward' | 'mixed' per root.
    ROSS's eigenproblem also holds the axial and torsional DOFs; the blocks
    are decoupled, so an oscillating root is purely lateral or has no lateral
    motion, and the latter are dropped by their eigenvectors.
    """
    r = rmod.rotor
    if whirl:
        md = r.run_modal(speed, num_modes=2 * r.ndof, sparse=False)
        lam, vec = np.asarray(md.evalues), np.asarray(md.evectors)
    else:
        lam, vec = r._eigen(speed, sparse=False, sorted_=False)
        lam, vec = np.asarray(lam), np.asarray(vec)
    vec = vec[: r.ndof, :]
    lat = rmod.lateral_dofs()
    frac = np.linalg.norm(vec[lat, :], axis=0) / np.linalg.norm(vec, axis=0)
    # degenerate real roots (free-free rigid-body motion: 0 and -damping_mass
    # in every direction) may mix; oscillating roots must not
    osc = lam.imag > 1e-9 * np.abs(lam).max()
    if not np.all((frac[osc] > 1 - 1e-8) | (frac[osc] < 1e-8)):
        raise AssertionError("ROSS: lateral and axial/torsional motion mixed in a mode")
    is_lat = frac > 0.5
    big = np.abs(lam[is_lat]).max()
    keep = np.flatnonzero(is_lat & (lam.imag > 0))
    keep = keep[np.argsort(lam[keep].imag, kind="stable")]
    whirls = None
    if whirl:
        assert keep.max() < len(md.shapes)
        whirls = [md.shapes[k].whirl.lower() for k in keep]
    return lam[keep], big, whirls


def zeta_of(lam):
    return -lam.real / abs(lam)


def logdec_of(lam):
    z = zeta_of(lam)
    return 2 * math.pi * z / math.sqrt(1 - z * z)
