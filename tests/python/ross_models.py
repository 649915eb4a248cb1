"""Build the same rotor models in ROSS (ross-rotordynamics 2.3) as librcb.

The model is read from librcb's INI format (the contract in the README /
issue #2) by a small parser written here, independently of the C loader, and
turned into ROSS elements:

* each shaft segment -> ``n`` ShaftElements of length L/n, with shear,
  rotary inertia and gyroscopics on; ROSS computes its own (Cowper) shear
  factor, so ``kappa`` and ``phi = 12 E Ie / (G_s kappa A L^2)`` are
  overwritten with the INI ``shear_factor`` exactly as ROSS's ``__init__``
  computes them (``shear_factor = 0`` -> ``shear_effects=False``, phi = 0);
  proportional damping ``alpha = damping_mass`` (1/s) and
  ``beta = damping_stiffness`` (s): ROSS's element C = alpha M + beta K;
* disks -> DiskElement(n, m, Id, Ip) (explicit or annulus from geometry);
* bearings -> BearingElement(n, kxx, cxx, kyy, cyy, kxy, kyx, cxy, cyx);
  speed tables are interpolated linearly here, at the requested speed, and
  the ROSS rotor is built for that speed (ROSS itself would fit a spline);
* nelson_crandall_1/2 couplings -> CouplingElement placed in the shaft
  element list between the two shafts (the coupling must join the end of
  one shaft to the start of the next shaft in INI order).

ROSS is 6 DOF/node [x, y, z, alpha, beta, theta]; the lateral DOFs of ROSS
node n are 6 n + (0, 1, 3, 4). The ROSS nodes are numbered along the shaft
element list: shaft 1's nodes, then (through the coupling element) shaft 2's.
``RossModel.node_keys`` gives (shaft name, z) of every ROSS node so that it
can be matched with the node table printed by ``rcbtool matrices``.

Units are SI throughout (m, kg, N/m, N s/m, rad/s).
"""

import math
import re

import numpy as np

LATERAL = (0, 1, 3, 4)  # ROSS local indices of x, y, alpha (rot_x), beta (rot_y)


# --------------------------------------------------------------------------
# INI parsing (independent of the C loader)
# --------------------------------------------------------------------------


def parse_ini(text):
    """Return a list of (kind, name, {key: [values...]}) in file order.

    Comments start with ';' or '#' (at line start or after whitespace);
    repeated keys accumulate (``segment``).
    """
    sections = []
    cur = None
    for raw in text.splitlines():
        line = re.split(r"(?:^|\s)[;#]", raw, maxsplit=1)[0].strip()
        if not line:
            continue
        if line.startswith("["):
            head = line.strip("[]").strip()
            parts = head.split(None, 1)
            kind = parts[0].lower()
            name = parts[1].strip() if len(parts) > 1 else ""
            cur = {}
            sections.append((kind, name, cur))
            continue
        key, _, val = line.partition("=")
        cur.setdefault(key.strip().lower(), []).append(val.strip())
    return sections


def _f(d, key, default=None):
    if key not in d:
        if default is None:
            raise KeyError(key)
        return default
    return float(d[key][-1])


def _floats(s):
    return [float(t) for t in s.replace(",", " ").split()]


def annulus(density, outer_d, inner_d, width):
    """Mass (kg), Id (kg m^2, about a diameter through the centre), Ip (kg m^2)."""
    ro, ri = outer_d / 2.0, inner_d / 2.0
    m = density * math.pi * (ro**2 - ri**2) * width
    ip = 0.5 * m * (ro**2 + ri**2)
    idd = m * (3.0 * (ro**2 + ri**2) + width**2) / 12.0
    return m, idd, ip


class Shaft:
    def __init__(self, name, d):
        self.name = name
        self.material = d["material"][-1]
        self.start = _f(d, "start", 0.0)
        self.kappa = _f(d, "shear_factor", 0.0)
        self.alpha = _f(d, "damping_mass", 0.0)
        self.beta = _f(d, "damping_stiffness", 0.0)
        self.elements = []  # (L, od, id)
        for seg in d.get("segment", []):
            length, od, idd, n = _floats(seg)
            n = int(n)
            for _ in range(n):
                self.elements.append((length / n, od, idd))
        z = [self.start]
        for el in self.elements:
            z.append(z[-1] + el[0])
        self.z = z

    def node_at(self, where):
        """Local node index of 'start' | 'end' | z (m)."""
        if where == "start":
            return 0
        if where == "end":
            return len(self.z) - 1
        zz = float(where)
        for i, z in enumerate(self.z):
            if abs(z - zz) < 1e-9:
                return i
        raise ValueError(f"z = {zz} m is not a node of shaft {self.name}")


class Model:
    """The INI model, in plain Python."""

    def __init__(self, text):
        self.materials = {}
        self.shafts = []
        self.disks = []
        self.bearings = []
        self.couplings = []
        self.unbalances = []
        self.stations = {}
        secs = parse_ini(text)
        for kind, name, d in secs:
            if kind == "material":
                self.materials[name] = (
                    _f(d, "density"),
                    _f(d, "young"),
                    _f(d, "poisson"),
                )
            elif kind == "shaft":
                self.shafts.append(Shaft(name, d))
        self._shaft = {s.name: s for s in self.shafts}
        for kind, name, d in secs:
            if kind == "disk":
                at = self.place(d["at"][-1])
                if "mass" in d:
                    m, idd, ip = _f(d, "mass"), _f(d, "id"), _f(d, "ip")
                else:
                    m, idd, ip = annulus(
                        _f(d, "density"),
                        _f(d, "outer_diameter"),
                        _f(d, "inner_diameter", 0.0),
                        _f(d, "width"),
                    )
                self.disks.append((name, at, m, idd, ip))
                self.stations[name] = at
            elif kind == "bearing":
                self.bearings.append((name, self.place(d["at"][-1]), d))
                self.stations[name] = self.place(d["at"][-1])
            elif kind == "coupling":
                a, b = [s.strip() for s in d["between"][-1].split(",")]
                self.couplings.append((name, self.place(a), self.place(b), d))
                self.stations[name] = self.place(a)
                self.stations[name + "." + self.place(a)[0]] = self.place(a)
                self.stations[name + "." + self.place(b)[0]] = self.place(b)
            elif kind == "station":
                self.stations[name] = self.place(d["at"][-1])
        for kind, name, d in secs:
            if kind == "unbalance":
                at = d["at"][-1]
                place = self.stations[at] if at in self.stations else self.place(at)
                self.unbalances.append(
                    (name, place, _f(d, "amount"), math.radians(_f(d, "phase_deg", 0.0)))
                )
                self.stations.setdefault(name, place)

    def place(self, spec):
        """'A 0.20' | 'A start' | 'A end' -> (shaft name, local node index)."""
        sname, where = spec.split()
        return (sname, self._shaft[sname].node_at(where))

    @staticmethod
    def bearing_coefs(d, speed):
        """Coefficients (dict) at rotor speed (rad/s), linear interpolation, clamped."""
        table = None
        if "speed_rpm" in d:
            table = np.array(_floats(d["speed_rpm"][-1])) * math.pi / 30.0
        elif "speed" in d:
            table = np.array(_floats(d["speed"][-1]))
        out = {}
        for k in ("kxx", "kxy", "kyx", "kyy", "cxx", "cxy", "cyx", "cyy"):
            vals = _floats(d[k][-1]) if k in d else [0.0]
            if len(vals) == 1 or table is None:
                out[k] = vals[0]
            else:
                out[k] = float(np.interp(speed, table, vals))
        return out


class RossModel:
    """A ROSS rotor built from a Model, with the node map."""

    def __init__(self, model, speed=0.0, override_shear=True):
        """override_shear=False keeps ROSS's own (Cowper) shear factor: only
        to show that the comparison would notice it."""
        import ross as rs

        self.model = model
        mats = {}
        for name, (rho, E, nu) in model.materials.items():
            mats[name] = rs.Material(
                name="rcb_" + re.sub(r"\W", "_", name), rho=rho, E=E, Poisson=nu
            )
        elements = []
        self.node_keys = []  # ROSS node -> (shaft name, z)
        self.first_node = {}  # shaft name -> ROSS node of its local node 0
        couplings = {c[1][0]: c for c in model.couplings}  # keyed by side-a shaft
        for si, sh in enumerate(model.shafts):
            self.first_node[sh.name] = len(self.node_keys)
            self.node_keys.extend((sh.name, z) for z in sh.z)
            mat = mats[sh.material]
            for L, od, idd in sh.elements:
                el = rs.ShaftElement(
                    L=L,
                    idl=idd,
                    odl=od,
                    material=mat,
                    shear_effects=sh.kappa > 0,
                    rotary_inertia=True,
                    gyroscopic=True,
                    alpha=sh.alpha,
                    beta=sh.beta,
                )
                if sh.kappa > 0 and override_shear:
                    el.kappa = sh.kappa
                    el.phi = (
                        12 * mat.E * el.Ie / (mat.G_s * sh.kappa * el.A * el.L**2)
                    )
                elements.append(el)
            if si + 1 < len(model.shafts):
                c = couplings.get(sh.name)
                nxt = model.shafts[si + 1]
                if (
                    c is None
                    or c[1][1] != len(sh.z) - 1
                    or c[2] != (nxt.name, 0)
                ):
                    raise ValueError(
                        "ROSS builder: shafts must be chained end -> start by couplings"
                    )
                elements.append(self._coupling(c, nxt.start - sh.z[-1]))
        disks = []
        for name, (sname, i), m, idd, ip in model.disks:
            disks.append(rs.DiskElement(n=self.first_node[sname] + i, m=m, Id=idd, Ip=ip, tag=name))
        bearings = []
        for name, (sname, i), d in model.bearings:
            k = model.bearing_coefs(d, speed)
            bearings.append(
                rs.BearingElement(
                    n=self.first_node[sname] + i,
                    kxx=k["kxx"],
                    kyy=k["kyy"],
                    kxy=k["kxy"],
                    kyx=k["kyx"],
                    cxx=k["cxx"],
                    cyy=k["cyy"],
                    cxy=k["cxy"],
                    cyx=k["cyx"],
                    tag=name,
                )
            )
        self.rotor = rs.Rotor(elements, disks, bearings)
        assert self.rotor.ndof == 6 * len(self.node_keys)

    @staticmethod
    def _coupling(c, gap):
        import ross as rs

        name, _, _, d = c
        typ = d["model"][-1].strip()
        if typ not in ("nelson_crandall_1", "nelson_crandall_2"):
            raise ValueError(f"ROSS builder: coupling model {typ} has no ROSS element")
        if "hub_density" in d:
            m, idd, ip = annulus(
                _f(d, "hub_density"),
                2 * _f(d, "hub_outer_radius"),
                2 * _f(d, "hub_inner_radius"),
                0.5 * _f(d, "hub_thickness"),
            )
        else:
            m, idd, ip = _f(d, "hub_mass", 0.0), _f(d, "hub_id", 0.0), _f(d, "hub_ip", 0.0)
        kt, kr = _f(d, "kt", 0.0), _f(d, "kr", 0.0)
        ct, cr = (_f(d, "ct", 0.0), _f(d, "cr", 0.0)) if typ == "nelson_crandall_2" else (0.0, 0.0)
        # ROSS replaces Id = 0 by Ip/2; only matters for massless hubs.
        return rs.CouplingElement(
            m_l=m, m_r=m, Ip_l=ip, Ip_r=ip, Id_l=idd, Id_r=idd,
            kt_x=kt, kt_y=kt, kr_x=kr, kr_y=kr,
            ct_x=ct, ct_y=ct, cr_x=cr, cr_y=cr,
            L=gap, tag=name,
        )

    # ---- helpers -------------------------------------------------------

    def ross_node(self, shaft, z):
        for i, (s, zz) in enumerate(self.node_keys):
            if s == shaft and abs(zz - z) < 1e-9:
                return i
        raise KeyError((shaft, z))

    def lateral_map(self, nodes_table):
        """Pairs (ours, ross) of DOF indices from rcbtool's "nodes" table."""
        ours, ross = [], []
        for nd in nodes_table:
            n = self.ross_node(nd["shaft"], nd["z"])
            for k in range(4):
                ours.append(nd["dof"][k])
                ross.append(6 * n + LATERAL[k])
        return np.array(ours), np.array(ross)

    def lateral_dofs(self):
        """ROSS indices of all lateral DOFs, node by node."""
        return np.array([6 * n + k for n in range(len(self.node_keys)) for k in LATERAL])

    def station_dof(self, spec):
        """ROSS global index of a channel 'STATION.DIR' or '#N.DIR' (N = ROSS node)."""
        st, _, direction = spec.rpartition(".")
        k = {"x": 0, "y": 1, "rx": 3, "ry": 4}[direction]
        if st.startswith("#"):
            return 6 * int(st[1:]) + k
        sname, i = self.model.stations[st]
        return 6 * (self.first_node[sname] + i) + k

    def unbalance_args(self):
        nodes, mags, phases = [], [], []
        for _, (sname, i), amount, phase in self.model.unbalances:
            nodes.append(self.first_node[sname] + i)
            mags.append(amount)
            phases.append(phase)
        return nodes, mags, phases


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
