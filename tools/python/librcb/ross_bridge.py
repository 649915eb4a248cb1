"""Bridge between ROSS (ross-rotordynamics 2.3) rotors and librcb INI models.

Pure Python: it reads and writes the INI *text* (the format of
examples/paper_system.ini and docs/rcbtool.md) and needs neither the shared
library nor the ctypes layer. ROSS is an optional dependency, imported only by
the functions that build or read ROSS objects::

    from librcb import ross_bridge
    text = ross_bridge.rotor_to_ini(ross.compressor_example(), name="compressor")
    rotor = ross_bridge.ini_to_rotor("examples/paper_system.ini", speed=314.16)

ROSS -> INI (`rotor_to_ini`, `convert_rotor`)
---------------------------------------------
* Shaft elements: one INI ``[shaft]`` per run of consecutive elements sharing
  material, shear factor and proportional damping (alpha -> damping_mass 1/s,
  beta -> damping_stiffness s); runs are joined by ``rigid`` couplings with
  no gap, which tie all four DOFs (the same node, as in ROSS). Equal
  consecutive elements share one ``segment`` line.
* Shear: the INI holds one ``shear_factor`` per shaft and librcb computes
  ``phi = 12 E Ie / (G kappa A L^2)`` with ``G = E / (2 (1 + poisson))``. The
  bridge writes the factor that reproduces ROSS's own ``phi`` of every element
  (ROSS computes Cowper's kappa per element and may take ``G_s`` from the
  material rather than from Poisson's ratio). A ROSS material with a Poisson
  ratio outside librcb's 0 <= nu < 0.5 (ROSS derives it from ``G_s``) is
  written with poisson = 0 and the ratio of the two shear moduli folded into
  the shear factor: the matrices are the same. ``shear_effects=False`` ->
  ``shear_factor = 0``.
* Layered elements (several shaft elements on the same nodes, as in ROSS's
  compressor example, where sleeves add mass): each extra layer becomes its own
  ``[shaft]`` tied to the main line by a ``rigid`` coupling at every node, so
  its matrices add on the same DOFs exactly as ROSS adds them.
* Tapered elements (odl != odr or idl != idr): ROSS uses a conical
  formulation that librcb lacks. ``tapered="error"`` (default) raises
  NotImplementedError; ``tapered="uniform"`` writes a uniform element with the
  mean diameters (an approximation, reported in a comment).
* ``rotary_inertia=False`` / ``gyroscopic=False``: librcb's element always has
  both: NotImplementedError. Non-zero ``axial_force`` or ``torque``:
  NotImplementedError.
* Disks -> ``[disk]`` with mass, Id, Ip (kg, kg m^2). Point masses on shaft
  nodes -> ``[disk]`` with Id = Ip = 0 (isotropic mx = my only).
* Bearings and seals (every BearingElement subclass except magnetic bearings)
  -> ``[bearing]`` with kxx..cyy. ROSS tabulates coefficients against
  "frequency"; in its analyses (modal, transfer_matrix/FRF, unbalance) ROSS
  evaluates them at the *rotor speed* (``K(frequency=speed)``), so a ROSS table
  is a table against speed, which is what librcb's ``speed`` key means
  (rad/s). Between table points ROSS fits a smoothing cubic spline
  (scipy UnivariateSpline) while librcb interpolates linearly (clamped at the
  ends): the two agree at the table points; pass ``speeds=`` to resample
  ROSS's spline on a finer grid, or ``speed=`` to freeze the coefficients at
  one speed.
* A bearing with ``n_link`` to a pedestal node that carries a point mass and a
  constant, diagonal support bearing to ground -> one ``[bearing]`` with
  pedestal_mass (kg), pedestal_kxx, pedestal_kyy (N/m), pedestal_cxx,
  pedestal_cyy (N s/m).
* Couplings (CouplingElement) -> ``nelson_crandall_2`` (``_1`` without
  damping) with kt, kr, ct, cr and the hub inertias (as disks when the two
  sides differ). Anisotropic couplings raise NotImplementedError.
* Not representable, NotImplementedError naming the element: MultiRotor
  (gears, parallel shafts), CoAxialRotor, GearElement, MagneticBearingElement
  (controller), bearing mass coefficients, links between shaft nodes, and
  axial/torsional coefficients (kzz, czz, mzz, a coupling's z terms) unless
  ``drop_axial=True`` (librcb is lateral only; they do not touch the lateral
  DOFs, so dropping them leaves the lateral dynamics unchanged).

INI -> ROSS (`ini_to_rotor`, `IniRotor`)
----------------------------------------
Shaft segments -> ShaftElements (shear, rotary inertia and gyroscopics on,
ROSS's phi overwritten with the INI shear factor), disks -> DiskElement,
bearings -> BearingElement (speed tables -> ROSS ``frequency`` tables, or
constants at ``speed``), pedestals -> n_link node + PointMass + support
bearing, nelson_crandall_1/2 couplings -> CouplingElement, ``rigid`` couplings
with no gap -> the same ROSS node (layers and material changes). Kramer
couplings (which tie translations only) and rigid couplings across a gap have
no ROSS element: NotImplementedError. ROSS rotors carry no unbalance; the
``IniRotor`` helper keeps the node map and the unbalances for analyses.

ROSS is 6 DOF/node [x, y, z, alpha, beta, theta]; the lateral DOFs of ROSS
node n are 6 n + (0, 1, 3, 4) = librcb's [x, y, rot_x, rot_y].
Units are SI throughout (m, kg, N/m, N s/m, rad/s).
"""

import math
import re
from pathlib import Path

import numpy as np

__all__ = [
    "rotor_to_ini",
    "convert_rotor",
    "ini_to_rotor",
    "IniRotor",
    "Model",
    "parse_ini",
    "annulus",
    "LATERAL",
]

LATERAL = (0, 1, 3, 4)  # ROSS local indices of x, y, alpha (rot_x), beta (rot_y)
BEARING_KEYS = ("kxx", "kxy", "kyx", "kyy", "cxx", "cxy", "cyx", "cyy")
PEDESTAL_KEYS = ("pedestal_mass", "pedestal_kxx", "pedestal_kyy", "pedestal_cxx", "pedestal_cyy")

# --------------------------------------------------------------------------
# INI parsing (independent of the C loader)
# --------------------------------------------------------------------------


def parse_ini(text):
    """Return a list of (kind, name, {key: [values...]}) in file order.

    Comments start with ';' or '#' (at line start or after whitespace);
    repeated keys accumulate (``segment``). Keys are lower-cased.
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
        if cur is None:
            raise ValueError(f"INI: key outside a section: {raw!r}")
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


def _read_text(ini_text_or_path):
    """INI text from a text or a path (str with no newline, or Path)."""
    if isinstance(ini_text_or_path, Path) or (
        isinstance(ini_text_or_path, str) and "\n" not in ini_text_or_path
    ):
        return Path(ini_text_or_path).read_text()
    return ini_text_or_path


def annulus(density, outer_d, inner_d, width):
    """Mass (kg), Id (kg m^2, about a diameter through the centre), Ip (kg m^2)."""
    ro, ri = outer_d / 2.0, inner_d / 2.0
    m = density * math.pi * (ro**2 - ri**2) * width
    ip = 0.5 * m * (ro**2 + ri**2)
    idd = m * (3.0 * (ro**2 + ri**2) + width**2) / 12.0
    return m, idd, ip


class Shaft:
    """One [shaft] section: elements (L, od, id) and node positions z (m)."""

    def __init__(self, name, d):
        self.name = name
        self.material = d["material"][-1]
        self.start = _f(d, "start", 0.0)
        self.kappa = _f(d, "shear_factor", 0.0)
        self.alpha = _f(d, "damping_mass", 0.0)
        self.beta = _f(d, "damping_stiffness", 0.0)
        self.elements = []  # (L, od, id)
        # per-element factors (librcb's shaft.NAME.e<k>.stiffness | mass):
        # local element index (0-based, z order) -> (factor on E and G, on rho);
        # the ROSS builder gives such an element its own Material
        self.factors = {}
        for j, key in enumerate(("element_stiffness", "element_mass")):
            for line in d.get(key, []):  # pairs "k factor", k from 1
                vals = _floats(line)
                for k, f in zip(vals[0::2], vals[1::2]):
                    fk = list(self.factors.get(int(k) - 1, (1.0, 1.0)))
                    fk[j] = f
                    self.factors[int(k) - 1] = tuple(fk)
        for seg in d.get("segment", []):
            length, od, idd, n = _floats(seg)
            n = int(n)
            for _ in range(n):
                self.elements.append((length / n, od, idd))
        # shaft-wide factors (librcb's shaft.NAME.stiffness | mass), on top of
        # the element factors: every element then gets its own Material
        sk, sm = _f(d, "stiffness_factor", 1.0), _f(d, "mass_factor", 1.0)
        if sk != 1.0 or sm != 1.0:
            for k in range(len(self.elements)):
                fk, fm = self.factors.get(k, (1.0, 1.0))
                self.factors[k] = (fk * sk, fm * sm)
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
        tol = 1e-9 * (self.z[-1] - self.z[0]) + 1e-12  # as the C loader
        for i, z in enumerate(self.z):
            if abs(z - zz) <= tol:
                return i
        raise ValueError(f"z = {zz} m is not a node of shaft {self.name}")


class Model:
    """The INI model, in plain Python (parsed independently of the C loader)."""

    def __init__(self, text):
        text = _read_text(text)
        self.name = ""
        self.materials = {}
        self.shafts = []
        self.disks = []
        self.bearings = []
        self.couplings = []
        self.unbalances = []
        self.stations = {}
        secs = parse_ini(text)
        for kind, name, d in secs:
            if kind == "model":
                self.name = d.get("name", [""])[-1]
            elif kind == "material":
                self.materials[name] = (_f(d, "density"), _f(d, "young"), _f(d, "poisson"))
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
        """'A 0.20' | 'A start' | 'A end' | station name -> (shaft, local node index)."""
        parts = spec.split()
        if len(parts) == 1:
            return self.stations[parts[0]]
        sname, where = parts
        return (sname, self._shaft[sname].node_at(where))

    def z_of(self, place):
        sname, i = place
        return self._shaft[sname].z[i]

    @staticmethod
    def speed_table(d):
        """Speeds (rad/s) of a tabulated bearing, or None."""
        if "speed_rpm" in d:
            return np.array(_floats(d["speed_rpm"][-1])) * math.pi / 30.0
        if "speed" in d:
            return np.array(_floats(d["speed"][-1]))
        return None

    @staticmethod
    def bearing_coefs(d, speed):
        """Coefficients (dict) at rotor speed (rad/s), linear interpolation, clamped."""
        table = Model.speed_table(d)
        out = {}
        for k in BEARING_KEYS:
            vals = _floats(d[k][-1]) if k in d else [0.0]
            if len(vals) == 1 or table is None:
                out[k] = vals[0]
            else:
                out[k] = float(np.interp(speed, table, vals))
        return out


# --------------------------------------------------------------------------
# INI -> ROSS
# --------------------------------------------------------------------------


def _union_find(n):
    parent = list(range(n))

    def find(a):
        while parent[a] != a:
            parent[a] = parent[parent[a]]
            a = parent[a]
        return a

    def union(a, b):
        a, b = find(a), find(b)
        if a != b:
            parent[max(a, b)] = min(a, b)

    return find, union


class IniRotor:
    """A ROSS rotor built from an INI model, with the node map.

    ``rotor`` is the ross.Rotor; ``node_keys[n]`` is (shaft, z) of ROSS node n
    (first INI shaft meeting there); ``node_of[(shaft, i)]`` the ROSS node of
    local node i of an INI shaft. ``speed`` (rad/s): None keeps speed tables
    as ROSS frequency tables (ROSS then splines them); a number freezes every
    bearing at its linearly interpolated value at that speed (librcb's rule),
    so that analyses at that speed compare exactly.
    ``override_shear=False`` keeps ROSS's own (Cowper) shear factor.
    """

    def __init__(self, model, speed=None, override_shear=True):
        import ross as rs

        if not isinstance(model, Model):
            model = Model(model)
        self.model = model
        self._number_nodes()
        mats = {
            name: rs.Material(name="rcb_" + re.sub(r"\W", "_", name), rho=rho, E=E, Poisson=nu)
            for name, (rho, E, nu) in model.materials.items()
        }
        shaft_els = []
        for sh in model.shafts:
            for i, (L, od, idd) in enumerate(sh.elements):
                mat = mats[sh.material]
                if i in sh.factors:  # its own Material: E (G follows) and rho scaled
                    fk, fm = sh.factors[i]
                    rho, E, nu = model.materials[sh.material]
                    mat = rs.Material(name=f"{mat.name}_{sh.name}_e{i + 1}", rho=fm * rho,
                                      E=fk * E, Poisson=nu)
                el = rs.ShaftElement(
                    L=L, idl=idd, odl=od, material=mat, n=self.node_of[(sh.name, i)],
                    shear_effects=sh.kappa > 0, rotary_inertia=True, gyroscopic=True,
                    alpha=sh.alpha, beta=sh.beta,
                )
                if sh.kappa > 0 and override_shear:
                    el.kappa = sh.kappa
                    el.phi = 12 * mat.E * el.Ie / (mat.G_s * sh.kappa * el.A * el.L**2)
                shaft_els.append(el)
        for c in self.flexible:
            shaft_els.append(self._coupling(c))
        # main line first at each node, so that ROSS takes node positions from it
        shaft_els.sort(key=lambda e: e.n)
        disks = [
            rs.DiskElement(n=self.node_of[at], m=m, Id=idd, Ip=ip, tag=name)
            for name, at, m, idd, ip in model.disks
        ]
        bearings, pmasses = [], []
        n_link = len(self.node_keys)
        for name, at, d in model.bearings:
            kw = self._bearing_kwargs(d, speed)
            ped = {k: _f(d, k, 0.0) for k in PEDESTAL_KEYS}
            if not any(ped.values()):
                bearings.append(rs.BearingElement(n=self.node_of[at], tag=name, **kw))
                continue
            bearings.append(rs.BearingElement(n=self.node_of[at], n_link=n_link, tag=name, **kw))
            bearings.append(
                rs.BearingElement(
                    n=n_link, kxx=ped["pedestal_kxx"], kyy=ped["pedestal_kyy"],
                    cxx=ped["pedestal_cxx"], cyy=ped["pedestal_cyy"], tag=name + "_support",
                )
            )
            if ped["pedestal_mass"] > 0:
                pmasses.append(rs.PointMass(n=n_link, m=ped["pedestal_mass"], tag=name + "_pedestal"))
            self.pedestal_node[name] = n_link
            n_link += 1
        self.rotor = rs.Rotor(shaft_els, disks, bearings, pmasses, tag=model.name or None)

    def _number_nodes(self):
        """ROSS node numbers: INI nodes tied by gap-free rigid couplings merge;
        the merged nodes, sorted by z, must form one chain along the axis."""
        m = self.model
        flat, base = [], {}
        for sh in m.shafts:
            base[sh.name] = len(flat)
            flat.extend((sh.name, i) for i in range(len(sh.z)))
        find, union = _union_find(len(flat))
        self.flexible = []
        for c in m.couplings:
            name, a, b, d = c
            typ = d["model"][-1].strip()
            za, zb = m.z_of(a), m.z_of(b)
            if typ == "rigid":
                if abs(za - zb) > 1e-9 * max(1.0, abs(za)):
                    raise NotImplementedError(
                        f"coupling {name}: a rigid coupling across a gap ({zb - za:g} m) "
                        "has no ROSS element"
                    )
                union(base[a[0]] + a[1], base[b[0]] + b[1])
            elif typ in ("nelson_crandall_1", "nelson_crandall_2"):
                self.flexible.append(c)
            else:
                raise NotImplementedError(
                    f"coupling {name}: model {typ} ties translations only; ROSS has no such element"
                )
        roots = {}
        for k, (sname, i) in enumerate(flat):
            r = find(k)
            roots.setdefault(r, (m.z_of((sname, i)), sname))
        order = sorted(roots, key=lambda r: (roots[r][0], r))
        num = {r: n for n, r in enumerate(order)}
        self.node_of = {key: num[find(k)] for k, key in enumerate(flat)}
        self.node_keys = [(roots[r][1], roots[r][0]) for r in order]
        self.pedestal_node = {}
        spans = {}
        for sh in m.shafts:
            for i in range(len(sh.elements)):
                spans.setdefault((self.node_of[(sh.name, i)], self.node_of[(sh.name, i + 1)]), sh.name)
        for name, a, b, _ in self.flexible:
            spans.setdefault((self.node_of[a], self.node_of[b]), name)
        for (na, nb), who in spans.items():
            if nb != na + 1:
                raise NotImplementedError(
                    f"{who}: joins ROSS nodes {na} and {nb}; ROSS needs one chain of nodes along "
                    "the axis (parallel or co-axial shafts cannot be represented)"
                )

    def _coupling(self, c):
        import ross as rs

        name, a, b, d = c
        typ = d["model"][-1].strip()
        if "hub_density" in d:
            m, idd, ip = annulus(
                _f(d, "hub_density"), 2 * _f(d, "hub_outer_radius"),
                2 * _f(d, "hub_inner_radius"), 0.5 * _f(d, "hub_thickness"),
            )
        else:
            m, idd, ip = _f(d, "hub_mass", 0.0), _f(d, "hub_id", 0.0), _f(d, "hub_ip", 0.0)
        kt, kr = _f(d, "kt", 0.0), _f(d, "kr", 0.0)
        ct, cr = (_f(d, "ct", 0.0), _f(d, "cr", 0.0)) if typ == "nelson_crandall_2" else (0.0, 0.0)
        # ROSS replaces Id = 0 by Ip/2; only matters for massless hubs.
        return rs.CouplingElement(
            m_l=m, m_r=m, Ip_l=ip, Ip_r=ip, Id_l=idd, Id_r=idd,
            kt_x=kt, kt_y=kt, kr_x=kr, kr_y=kr, ct_x=ct, ct_y=ct, cr_x=cr, cr_y=cr,
            L=self.model.z_of(b) - self.model.z_of(a), n=self.node_of[a], tag=name,
        )

    @staticmethod
    def _bearing_kwargs(d, speed):
        table = Model.speed_table(d)
        if table is None or speed is not None:
            return Model.bearing_coefs(d, 0.0 if speed is None else speed)
        kw = {"frequency": table}
        for k in BEARING_KEYS:
            vals = _floats(d[k][-1]) if k in d else [0.0]
            kw[k] = np.full(len(table), vals[0]) if len(vals) == 1 else np.array(vals)
        return kw

    # ---- helpers -------------------------------------------------------

    def ross_node(self, shaft, z):
        """ROSS node of the INI node at (shaft, z)."""
        return self.node_of[(shaft, self.model._shaft[shaft].node_at(z))]

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
        """ROSS indices of the lateral DOFs of the shaft nodes, node by node."""
        return np.array([6 * n + k for n in range(len(self.node_keys)) for k in LATERAL])

    def station_dof(self, spec):
        """ROSS global index of a channel 'STATION.DIR' or '#N.DIR' (N = ROSS node)."""
        st, _, direction = spec.rpartition(".")
        k = {"x": 0, "y": 1, "rx": 3, "ry": 4}[direction]
        if st.startswith("#"):
            return 6 * int(st[1:]) + k
        return 6 * self.node_of[self.model.stations[st]] + k

    def unbalance_args(self):
        """(nodes, magnitudes kg m, phases rad) for ROSS's run_unbalance_response."""
        nodes, mags, phases = [], [], []
        for _, at, amount, phase in self.model.unbalances:
            nodes.append(self.node_of[at])
            mags.append(amount)
            phases.append(phase)
        return nodes, mags, phases


def ini_to_rotor(ini_text_or_path, speed=None):
    """ROSS Rotor of a librcb INI model (text or path); see IniRotor."""
    return IniRotor(Model(_read_text(ini_text_or_path)), speed=speed).rotor


# --------------------------------------------------------------------------
# ROSS -> INI
# --------------------------------------------------------------------------


def _num(x):
    """Shortest text that reads back as the same double."""
    x = float(x)
    return "0" if x == 0 else repr(x)


def _clean(tag, default):
    s = re.sub(r"\W+", "_", str(tag if tag is not None else default)).strip("_")
    return s or default


class _Names:
    """Unique INI section names (station names share one namespace)."""

    def __init__(self):
        self.used = set()

    def __call__(self, tag, default):
        base = _clean(tag, default)
        if base[0].isdigit():
            base = default + "_" + base
        name, k = base, 2
        while name.lower() in self.used:
            name, k = f"{base}_{k}", k + 1
        self.used.add(name.lower())
        return name


class RotorConversion:
    """Result of convert_rotor: ``ini`` (text), ``node_place[n]`` = (shaft, z)
    of ROSS shaft node n, ``pedestal_of[n_link]`` = bearing name, and
    ``notes`` (approximations made)."""

    def __init__(self, ini, node_place, pedestal_of, notes):
        self.ini = ini
        self.node_place = node_place
        self.pedestal_of = pedestal_of
        self.notes = notes

    def node_index(self, nodes_table):
        """ROSS node of each row of rcbtool's node table (shaft, z), or None."""
        lookup = {}
        for n, (s, z) in self.node_place.items():
            lookup.setdefault(s, []).append((z, n))
        out = []
        for nd in nodes_table:
            cand = [n for z, n in lookup.get(nd["shaft"], []) if abs(z - nd["z"]) <= 1e-9 * max(1, abs(z))]
            out.append(cand[0] if cand else None)
        return out


def _check_rotor_kind(rotor):
    import ross as rs

    for cls in ("MultiRotor", "CoAxialRotor"):
        klass = getattr(rs, cls, None)
        if klass is not None and isinstance(rotor, klass):
            raise NotImplementedError(
                f"{cls}: librcb models one line of shafts; gear-coupled or co-axial shafts "
                "cannot be represented"
            )


def _material_entry(mat, names, materials, notes):
    """INI material name and its shear modulus (Pa) as librcb will compute it."""
    nu = float(mat.Poisson)
    nu_ini = nu if 0.0 <= nu < 0.5 else 0.0
    key = (float(mat.rho), float(mat.E), nu_ini)
    if key not in materials:
        name = names(getattr(mat, "name", None), "mat")
        extra = ""
        if nu_ini != nu:
            extra = f"  ; ROSS Poisson {nu:g} (from G_s) is outside 0..0.5: folded into shear_factor"
            notes.append(f"material {name}: poisson {nu:g} written as 0, G ratio in the shear factors")
        materials[key] = (
            name,
            f"[material {name}]\ndensity = {_num(mat.rho)}  ; kg/m^3\n"
            f"young = {_num(mat.E)}  ; Pa\npoisson = {_num(nu_ini)}{extra}\n",
        )
    return materials[key][0], float(mat.E) / (2.0 * (1.0 + nu_ini))


def _element_props(el, tapered, notes):
    """(L, od, id, kappa_ini-ready phi data) of a ROSS shaft element, checked."""
    tag = el.tag
    if not el.rotary_inertia or not el.gyroscopic:
        raise NotImplementedError(
            f"shaft element {tag}: rotary_inertia={el.rotary_inertia}, gyroscopic={el.gyroscopic}; "
            "librcb's Timoshenko element always has rotary inertia and gyroscopic terms"
        )
    if float(np.max(np.abs(el.axial_force))) != 0 or float(np.max(np.abs(el.torque))) != 0:
        raise NotImplementedError(f"shaft element {tag}: axial force / torque have no librcb equivalent")
    od, idd = el.odl, el.idl
    if el.odl != el.odr or el.idl != el.idr:
        if tapered != "uniform":
            raise NotImplementedError(
                f"shaft element {tag}: tapered (odl {el.odl:g}, odr {el.odr:g}, idl {el.idl:g}, "
                f"idr {el.idr:g} m); librcb has uniform elements only: refine it in ROSS or pass "
                "tapered='uniform' (mean diameters, an approximation)"
            )
        od, idd = 0.5 * (el.odl + el.odr), 0.5 * (el.idl + el.idr)
        notes.append(f"shaft element {tag}: tapered, written with mean diameters")
    return float(el.L), float(od), float(idd)


def _kappa_ini(el, L, od, idd, G_ini):
    """Shear factor giving librcb the same phi as ROSS's element."""
    if not el.shear_effects or el.phi == 0:
        return 0.0
    A = math.pi * (od**2 - idd**2) / 4.0
    Ie = math.pi * (od**4 - idd**4) / 64.0
    return 12.0 * el.material.E * Ie / (G_ini * A * L**2 * float(el.phi))


def _same(a, b, rel=1e-9):
    return abs(a - b) <= rel * max(abs(a), abs(b), 1e-300)


def _element_key(el, tapered, names, materials, notes):
    """((L, od, id), (material, shear factor, alpha, beta)) of a ROSS shaft element."""
    L, od, idd = _element_props(el, tapered, notes)
    mat, G_ini = _material_entry(el.material, names, materials, notes)
    return (L, od, idd), (mat, _kappa_ini(el, L, od, idd, G_ini), float(el.alpha), float(el.beta))


def _continues(run, n, key):
    """Does element n with properties key extend run (same shaft in the INI)?"""
    return (
        run is not None and run.nodes[-1] == n and key[0] == run.key[0]
        and _same(key[1], run.key[1]) and key[2:] == run.key[2:]
    )


class _ShaftRun:
    """Consecutive ROSS elements written as one INI [shaft]."""

    def __init__(self, name, key, z0, n0):
        self.name, self.key, self.z0, self.n0 = name, key, z0, n0
        self.els = []  # (L, od, id)
        self.nodes = [n0]

    def text(self):
        mat, kappa, alpha, beta = self.key
        out = [
            f"[shaft {self.name}]",
            f"material = {mat}",
            f"start = {_num(self.z0)}  ; m",
            f"shear_factor = {_num(kappa)}  ; - (reproduces ROSS's phi)",
        ]
        if alpha:
            out.append(f"damping_mass = {_num(alpha)}  ; 1/s (ROSS alpha)")
        if beta:
            out.append(f"damping_stiffness = {_num(beta)}  ; s (ROSS beta)")
        i = 0
        while i < len(self.els):
            j = i
            while j + 1 < len(self.els) and self.els[j + 1] == self.els[i]:
                j += 1
            L, od, idd = self.els[i]
            k = j - i + 1
            total = L * k if k > 1 else L
            out.append(f"segment = {_num(total)} {_num(od)} {_num(idd)} {k}  ; m, m, m, -")
            i = j + 1
        return "\n".join(out) + "\n"


def _coef_value(el, key, speed):
    arr = np.atleast_1d(np.asarray(getattr(el, key), dtype=float))
    if speed is None or arr.size == 1:
        return arr
    return np.array([float(getattr(el, key + "_interpolated")(speed))])


def _bearing_lines(el, speed, speeds):
    """INI key lines for a bearing's kxx..cyy (constant or a speed table)."""
    freq = getattr(el, "frequency", None)
    tab = freq is not None and np.size(freq) > 1 and speed is None
    lines = []
    if tab:
        grid = np.asarray(freq, dtype=float) if speeds is None else np.asarray(speeds, dtype=float)
        lines.append("speed = " + " ".join(_num(s) for s in grid) + "  ; rad/s (ROSS frequency)")
    for k in BEARING_KEYS:
        if tab and speeds is not None:
            vals = np.array([float(getattr(el, k + "_interpolated")(s)) for s in grid])
        else:
            vals = _coef_value(el, k, speed)
        if np.all(vals == 0):
            continue
        if np.all(vals == vals[0]):
            vals = vals[:1]
        unit = "N/m" if k[0] == "k" else "N s/m"
        lines.append(f"{k} = " + " ".join(_num(v) for v in vals) + f"  ; {unit}")
    return lines


def _check_bearing(el, drop_axial):
    import ross as rs

    tag = el.tag
    mag = getattr(rs, "MagneticBearingElement", None)
    if mag is not None and isinstance(el, mag):
        raise NotImplementedError(
            f"bearing {tag}: magnetic bearing with a controller has no librcb equivalent"
        )
    for k in ("mxx", "mxy", "myx", "myy"):
        if np.any(np.asarray(getattr(el, k, 0.0), dtype=float) != 0):
            raise NotImplementedError(f"bearing {tag}: mass coefficient {k} has no librcb equivalent")
    for k in ("kzz", "czz", "mzz"):
        if not drop_axial and np.any(np.asarray(getattr(el, k, 0.0), dtype=float) != 0):
            raise NotImplementedError(
                f"bearing {tag}: axial coefficient {k} (librcb is lateral only; "
                "drop_axial=True leaves it out)"
            )


def convert_rotor(rotor, name=None, *, tapered="error", drop_axial=False, speed=None,
                  speeds=None, node_stations=False):
    """Convert a ROSS Rotor (or the path of a file written by ``Rotor.save``).

    name: [model] name (default: the rotor's tag). tapered: "error" |
    "uniform". drop_axial: leave out axial/torsional coefficients instead of
    raising. speed (rad/s): freeze tabulated bearings at ROSS's interpolated
    value at that speed. speeds (rad/s): resample tabulated bearings on this
    grid with ROSS's own interpolant. node_stations: add a [station nN] probe
    at every ROSS shaft node n. Returns a RotorConversion.
    """
    import ross as rs

    if isinstance(rotor, (str, Path)):
        rotor = rs.Rotor.load(str(rotor))
    _check_rotor_kind(rotor)
    if tapered not in ("error", "uniform"):
        raise ValueError(f"tapered = {tapered!r}; expected 'error' or 'uniform'")
    gear = getattr(rs, "GearElement", None)
    names = _Names()
    notes, materials = [], {}
    pos = {n: float(z) for n, z in zip(rotor.nodes, rotor.nodes_pos)}

    # ---- shaft line: main element at each n, the others are layers
    by_n = {}
    for el in rotor.shaft_elements:
        by_n.setdefault(int(el.n), []).append(el)
    runs, layers, couplings, ties = [], [], [], []
    node_place = {}
    cur = None
    for n in sorted(by_n):
        els = by_n[n]
        cpl = [e for e in els if isinstance(e, rs.CouplingElement)]
        if cpl:
            if len(els) > 1:
                raise NotImplementedError(
                    f"coupling {cpl[0].tag}: shares nodes {n}-{n + 1} with other elements"
                )
            couplings.append((cpl[0], cur, n))
            cur = None
            continue
        geo, key = _element_key(els[0], tapered, names, materials, notes)
        if not _continues(cur, n, key):
            prev = cur
            cur = _ShaftRun(names(None, f"S{len(runs) + 1}"), key, pos[n], n)
            runs.append(cur)
            if prev is not None and prev.nodes[-1] == n:
                ties.append((prev.name, cur.name, pos[n]))
            if prev is None and couplings and couplings[-1][2] == n - 1 and len(couplings[-1]) == 3:
                couplings[-1] = couplings[-1] + (cur,)
        cur.els.append(geo)
        cur.nodes.append(n + 1)
        for rank, el in enumerate(els[1:], start=1):
            layers.append((rank, n, el))
    for run in runs:
        for n in run.nodes:
            node_place.setdefault(n, (run.name, pos[n]))

    # ---- layers: one [shaft] per run of the same rank and properties, tied at every node
    lay_runs = []
    open_by_rank = {}
    for rank, n, el in layers:
        geo, key = _element_key(el, tapered, names, materials, notes)
        if not _same(geo[0], pos[n + 1] - pos[n]):
            raise ValueError(f"shaft element {el.tag}: L = {geo[0]} m differs from its nodes' spacing")
        run = open_by_rank.get(rank)
        if not _continues(run, n, key):
            run = _ShaftRun(names(None, f"S{len(runs) + len(lay_runs) + 1}"), key, pos[n], n)
            lay_runs.append(run)
            open_by_rank[rank] = run
        run.els.append(geo)
        run.nodes.append(n + 1)

    out = [f"[model]\nname = {name or getattr(rotor, 'tag', None) or 'ROSS rotor'}\n"]
    out.append(
        "; Converted from a ROSS Rotor by librcb.ross_bridge. Units: SI (m, kg, N/m, N s/m, Pa).\n"
        "; ROSS node n sits at the z (m) written in each 'at' key.\n"
    )
    out.extend(text for _, text in materials.values())
    out.extend(r.text() for r in runs + lay_runs)

    def at(n):
        if n not in node_place:
            raise NotImplementedError(f"ROSS node {n} is not a shaft node")
        s, z = node_place[n]
        return f"at = {s} {_num(z)}  ; ROSS node {n}"

    for a, b, z in ties:
        out.append(
            f"[coupling {names(None, 'R')}]\nmodel = rigid  ; same node in ROSS (property change)\n"
            f"between = {a} end, {b} start\n"
        )
    for run in lay_runs:
        for n in run.nodes:
            s, z = node_place[n]
            out.append(
                f"[coupling {names(None, 'T')}]\nmodel = rigid  ; layered ROSS element on node {n}\n"
                f"between = {run.name} {_num(z)}, {s} {_num(z)}\n"
            )
    for item in couplings:
        el = item[0]
        if len(item) < 4 or item[1] is None:
            raise NotImplementedError(f"coupling {el.tag}: must join two shaft elements")
        left, right = item[1], item[3]
        out.append(_coupling_text(el, names, left, right, drop_axial))

    # ---- disks and point masses
    for el in rotor.disk_elements:
        if gear is not None and isinstance(el, gear):
            raise NotImplementedError(f"gear element {el.tag}: gears have no librcb equivalent")
        out.append(
            f"[disk {names(el.tag, 'D')}]\n{at(int(el.n))}\nmass = {_num(el.m)}  ; kg\n"
            f"Id = {_num(el.Id)}  ; kg m^2\nIp = {_num(el.Ip)}  ; kg m^2\n"
        )
    pm_at = {}
    for el in rotor.point_mass_elements:
        if el.mx != el.my:
            raise NotImplementedError(f"point mass {el.tag}: mx != my; librcb masses are isotropic")
        pm_at.setdefault(int(el.n), []).append(el)

    # ---- bearings, seals, pedestals
    links = {}
    for el in rotor.bearing_elements:
        if el.n_link is not None:
            links.setdefault(int(el.n_link), []).append(el)
    supports = {}
    for el in rotor.bearing_elements:
        if int(el.n) in links and el.n_link is None:
            supports.setdefault(int(el.n), []).append(el)
    pedestal_of = {}
    for el in rotor.bearing_elements:
        _check_bearing(el, drop_axial)
        if int(el.n) in links:
            continue  # a pedestal's support: written with its bearing
        bname = names(el.tag, "B")
        kind = "seal" if isinstance(el, rs.SealElement) else type(el).__name__
        lines = [f"[bearing {bname}]", f"; ROSS {kind}", at(int(el.n))]
        lines += _bearing_lines(el, speed, speeds)
        if el.n_link is not None:
            p = int(el.n_link)
            if p in node_place:
                raise NotImplementedError(f"bearing {el.tag}: links two shaft nodes ({el.n}, {p})")
            lines += _pedestal_lines(el, p, links, supports, pm_at)
            pedestal_of[p] = bname
        out.append("\n".join(lines) + "\n")
    for n, pms in pm_at.items():
        if n in pedestal_of:
            continue
        for el in pms:
            out.append(
                f"[disk {names(el.tag, 'P')}]\n; ROSS PointMass\n{at(n)}\nmass = {_num(el.mx)}  ; kg\n"
                "Id = 0  ; kg m^2\nIp = 0  ; kg m^2\n"
            )
    if node_stations:
        for n in sorted(node_place):
            out.append(f"[station {names(None, f'n{n}')}]\n{at(n)}\n")
    if notes:
        out.insert(2, "".join(f"; NOTE: {t}\n" for t in notes))
    return RotorConversion("\n".join(out), node_place, pedestal_of, notes)


def _pedestal_lines(el, p, links, supports, pm_at):
    if len(links[p]) != 1:
        raise NotImplementedError(f"pedestal node {p}: more than one bearing links to it")
    sup = supports.get(p, [])
    if len(sup) > 1:
        raise NotImplementedError(f"pedestal node {p}: more than one support bearing")
    lines = []
    m = 0.0
    for pm in pm_at.get(p, []):
        if pm.mx != pm.my:
            raise NotImplementedError(f"point mass {pm.tag}: mx != my")
        m += float(pm.mx)
    if m:
        lines.append(f"pedestal_mass = {_num(m)}  ; kg")
    if sup:
        s = sup[0]
        for k in ("kxy", "kyx", "cxy", "cyx"):
            if np.any(np.asarray(getattr(s, k), dtype=float) != 0):
                raise NotImplementedError(f"support bearing {s.tag}: cross-coupled {k} on a pedestal")
        for k, unit in (("kxx", "N/m"), ("kyy", "N/m"), ("cxx", "N s/m"), ("cyy", "N s/m")):
            vals = np.atleast_1d(np.asarray(getattr(s, k), dtype=float))
            if np.any(vals != vals[0]):
                raise NotImplementedError(f"support bearing {s.tag}: speed-dependent {k} on a pedestal")
            if vals[0]:
                lines.append(f"pedestal_{k} = {_num(vals[0])}  ; {unit}")
    return lines


def _coupling_text(el, names, left, right, drop_axial):
    tag = el.tag
    for a, b in (("kt_x", "kt_y"), ("kr_x", "kr_y"), ("ct_x", "ct_y"), ("cr_x", "cr_y")):
        if getattr(el, a) != getattr(el, b):
            raise NotImplementedError(f"coupling {tag}: {a} != {b}; librcb couplings are isotropic")
    if not drop_axial:
        for k in ("kt_z", "kr_z", "ct_z", "cr_z"):
            if getattr(el, k) != 0:
                raise NotImplementedError(
                    f"coupling {tag}: axial/torsional {k} (drop_axial=True leaves it out)"
                )
    cname = names(tag, "C")
    damped = el.ct_x != 0 or el.cr_x != 0
    lines = [
        f"[coupling {cname}]",
        f"model = {'nelson_crandall_2' if damped else 'nelson_crandall_1'}",
        f"between = {left.name} end, {right.name} start",
        f"kt = {_num(el.kt_x)}  ; N/m",
        f"kr = {_num(el.kr_x)}  ; N m/rad",
    ]
    if damped:
        lines += [f"ct = {_num(el.ct_x)}  ; N s/m", f"cr = {_num(el.cr_x)}  ; N m s/rad"]
    left_hub = (el.m_l, el.Id_l, el.Ip_l)
    right_hub = (el.m_r, el.Id_r, el.Ip_r)
    text = ""
    if left_hub == right_hub:
        lines += [
            f"hub_mass = {_num(el.m_l)}  ; kg, each station",
            f"hub_Id = {_num(el.Id_l)}  ; kg m^2",
            f"hub_Ip = {_num(el.Ip_l)}  ; kg m^2",
        ]
    else:
        for side, (m, idd, ip), where in (("l", left_hub, f"{left.name} end"),
                                          ("r", right_hub, f"{right.name} start")):
            text += (
                f"[disk {names(None, cname + '_hub_' + side)}]\nat = {where}\nmass = {_num(m)}  ; kg\n"
                f"Id = {_num(idd)}  ; kg m^2\nIp = {_num(ip)}  ; kg m^2\n"
            )
    return "\n".join(lines) + "\n" + text


def rotor_to_ini(rotor, name=None, **kw):
    """librcb INI text of a ROSS Rotor (or a ``Rotor.save`` file); see convert_rotor."""
    return convert_rotor(rotor, name=name, **kw).ini
