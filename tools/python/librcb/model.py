"""Model: a finalized rotor-coupling-bearing model (an rcb_model handle)."""

import ctypes
import math
from collections import namedtuple
from pathlib import Path

import numpy as np

from . import _lib
from ._lib import check

RPM = math.pi / 30.0  # rad/s per rpm

Node = namedtuple("Node", "index shaft z dofs")
Node.__doc__ = ("A node: index, owning shaft, axial position z (m), matrix rows of "
                "x, y, rot_x, rot_y (-1 where a constraint removed the DOF).")
Element = namedtuple("Element", "param shaft k node0 node1 z0 z1 outer_d inner_d stiffness mass")
Element.__doc__ = ("A shaft element: the prefix of its parameters ('shaft.B.e5': .stiffness, "
                   ".mass), its shaft, k (from 1 along z), end nodes, z range (m), "
                   "diameters (m), and its stiffness and mass factors (neutral 1).")
Station = namedtuple("Station", "name kind node z")
Station.__doc__ = "A named station: name, kind, node index, axial position z (m)."
STATION_KINDS = ("disk", "bearing", "coupling", "unbalance", "probe", "pedestal")
DIRS = ("x", "y", "rx", "ry")


class Handle:
    """Owner of one opaque library object: destroyed exactly once, by close(),
    the end of a `with` block, or garbage collection."""

    _destroy = None  # name of the rcb_*_destroy function
    _errmsg = None   # name of the rcb_*_errmsg function

    def __init__(self):
        self._h = ctypes.c_void_p()

    def _create(self, fn, *args):
        """Call rcb_X_create(&h, args...); on failure the message comes from the
        half-made object when the library left one, and it is destroyed."""
        L = _lib.lib()
        st = getattr(L, fn)(ctypes.byref(self._h), *args)
        if st != 0:
            msg = _lib.text(getattr(L, self._errmsg)(self._h)) if self._h else ""
            self.close()
            raise _lib.RcbError(st, msg, fn)

    @property
    def handle(self):
        if not self._h:
            raise ValueError(f"{type(self).__name__} is closed")
        return self._h

    def check(self, status, call=""):
        return check(status, getattr(_lib.lib(), self._errmsg), self._h, call)

    def errmsg(self):
        return _lib.text(getattr(_lib.lib(), self._errmsg)(self.handle))

    def close(self):
        if getattr(self, "_h", None):
            getattr(_lib.lib(), self._destroy)(self._h)
            self._h = ctypes.c_void_p()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def __del__(self):
        try:
            self.close()
        except Exception:  # interpreter shutdown: the library may be gone
            pass


class Model(Handle):
    """A rotor model loaded from INI (file or text) and finalized.

    Everything numeric runs in the C library; speeds are given in rpm and
    frequencies in Hz at this edge (SI inside: rad/s), matrices in SI.
    """

    _destroy = "rcb_model_destroy"
    _errmsg = "rcb_model_errmsg"

    def __init__(self):
        super().__init__()
        self._create("rcb_model_create", None)
        self.source = None

    # ---- loading ----------------------------------------------------------
    @classmethod
    def from_ini(cls, source, name=None):
        """Load a model from an INI file path, or from INI text.

        A str containing a newline or starting with '[' / ';' / '#' is taken as
        text; anything else (str or os.PathLike) as a path. Errors raise
        RcbError whose message names FILE:LINE, section and key.
        """
        m = cls()
        L = _lib.lib()
        if isinstance(source, str) and ("\n" in source or source.lstrip()[:1] in "[;#"):
            src = name or "<string>"
            m.check(L.rcb_model_load_string(m.handle, source.encode(), src.encode()),
                    "rcb_model_load_string")
            m.source = src
        else:
            path = Path(source)
            m.check(L.rcb_model_load_file(m.handle, str(path).encode()), "rcb_model_load_file")
            m.source = str(path)
        return m

    def copy(self):
        """An independent model with the same values (through the INI writer)."""
        return Model.from_ini(self.to_ini(), name=self.source or "<copy>")

    def to_ini(self):
        """The model as INI text (17 significant digits: reads back to the same matrices)."""
        st, s = _lib.two_call_string(_lib.lib().rcb_model_write_ini, self.handle)
        self.check(st, "rcb_model_write_ini")
        return s

    def save(self, path):
        Path(path).write_text(self.to_ini())

    # ---- structure --------------------------------------------------------
    @property
    def warnings(self):
        L = _lib.lib()
        n = L.rcb_model_warning_count(self.handle)
        return [_lib.text(L.rcb_model_warning(self.handle, i)) for i in range(n)]

    @property
    def n_nodes(self):
        return int(_lib.lib().rcb_model_node_count(self.handle))

    @property
    def dofs(self):
        """Number of independent DOFs: the matrix size after constraint elimination."""
        return int(_lib.lib().rcb_model_dof_count(self.handle))

    n_dofs = dofs

    @property
    def n_elements(self):
        return int(_lib.lib().rcb_model_element_count(self.handle))

    @property
    def nodes(self):
        """List of Node(index, shaft, z [m], dofs (x, y, rx, ry matrix rows))."""
        L = _lib.lib()
        out = []
        info = _lib.NodeInfo()
        for i in range(self.n_nodes):
            self.check(L.rcb_model_node_info(self.handle, i, ctypes.byref(info)))
            out.append(Node(i, _lib.text(info.shaft), float(info.z), tuple(info.dof)))
        return out

    @property
    def elements(self):
        """List of Element(param, shaft, k, node0, node1, z0, z1 [m], outer_d, inner_d [m],
        stiffness, mass): every shaft element with its parameters
        PARAM.stiffness and PARAM.mass (factors, neutral 1), k from 1 along z."""
        L = _lib.lib()
        out = []
        info = _lib.ElementInfo()
        for i in range(self.n_elements):
            self.check(L.rcb_model_element_info(self.handle, i, ctypes.byref(info)))
            sh = _lib.text(info.shaft)
            out.append(Element(f"shaft.{sh}.e{info.index}", sh, int(info.index), int(info.node0),
                               int(info.node1), float(info.z0), float(info.z1),
                               float(info.outer_d), float(info.inner_d), float(info.stiffness),
                               float(info.mass)))
        return out

    @property
    def node_z(self):
        """Axial positions of the nodes, m."""
        return np.array([n.z for n in self.nodes])

    @property
    def stations(self):
        """List of Station(name, kind, node, z [m]) in definition order."""
        L = _lib.lib()
        nodes = self.nodes
        out = []
        info = _lib.StationInfo()
        for i in range(L.rcb_model_station_count(self.handle)):
            self.check(L.rcb_model_station_info(self.handle, i, ctypes.byref(info)))
            k = int(info.kind)
            out.append(Station(_lib.text(info.name), STATION_KINDS[k] if 0 <= k < len(STATION_KINDS) else k,
                               int(info.node), nodes[info.node].z))
        return out

    @property
    def uff_map(self):
        """The model's [uff] node map: {uff node number: station name}."""
        L = _lib.lib()
        out = {}
        node, st = ctypes.c_long(), ctypes.c_char_p()
        for i in range(L.rcb_model_uff_node_count(self.handle)):
            self.check(L.rcb_model_uff_node(self.handle, i, ctypes.byref(node),
                                            ctypes.byref(st)))
            out[int(node.value)] = _lib.text(st.value)
        return out

    def find_dof(self, spec):
        """Channel "STATION.DIR" -> (node, dir) as a library rcb_dof."""
        d = _lib.Dof()
        self.check(_lib.lib().rcb_model_find_dof(self.handle, spec.encode(), ctypes.byref(d)),
                   "rcb_model_find_dof")
        return d

    def dof_index(self, spec):
        """Matrix row of channel "STATION.DIR"."""
        idx = ctypes.c_size_t()
        self.check(_lib.lib().rcb_model_dof_index(self.handle, self.find_dof(spec),
                                                  ctypes.byref(idx)))
        return int(idx.value)

    def _dof_array(self, specs):
        if isinstance(specs, str):
            specs = [s for s in specs.split(",") if s]
        specs = list(specs)
        arr = (_lib.Dof * max(len(specs), 1))()
        for i, s in enumerate(specs):
            arr[i] = self.find_dof(s)
        return specs, arr

    # ---- parameters -------------------------------------------------------
    @property
    def params(self):
        """Names of every fittable parameter ("coupling.C.kt", ...)."""
        L = _lib.lib()
        buf = ctypes.create_string_buffer(256)
        out = []
        for i in range(L.rcb_model_param_count(self.handle)):
            self.check(L.rcb_model_param_name(self.handle, i, buf, 256))
            out.append(buf.value.decode())
        return out

    def get(self, name):
        """Value of a parameter (SI units of its INI key)."""
        v = ctypes.c_double()
        self.check(_lib.lib().rcb_model_get_param(self.handle, name.encode(), ctypes.byref(v)),
                   "rcb_model_get_param")
        return v.value

    def set(self, name, value):
        """Change a parameter (checked as the loader checks it)."""
        self.check(_lib.lib().rcb_model_set_param(self.handle, name.encode(), float(value)),
                   "rcb_model_set_param")

    def __getitem__(self, name):
        return self.get(name)

    def __setitem__(self, name, value):
        self.set(name, value)

    # ---- matrices ---------------------------------------------------------
    def matrices(self, rpm=0.0):
        """Global (M, C, G, K) at rotor speed rpm (it selects tabulated bearing
        coefficients): n x n arrays, kg, N s/m, (x Omega) N s/m, N/m."""
        n = self.dofs
        mats = [np.zeros((n, n), order="F") for _ in range(4)]
        self.check(_lib.lib().rcb_model_matrices(
            self.handle, float(rpm) * RPM, *[a.ctypes.data for a in mats]), "rcb_model_matrices")
        return tuple(mats)

    def unbalance_force(self, rpm):
        """Unbalance force phasors F (length n, N) at rotor speed rpm."""
        F = np.zeros(self.dofs, dtype=complex)
        self.check(_lib.lib().rcb_model_unbalance_force(self.handle, float(rpm) * RPM,
                                                        F.ctypes.data))
        return F

    def __repr__(self):
        if not self._h:
            return "<librcb.Model closed>"
        return (f"<librcb.Model {self.source!s}: {self.n_nodes} nodes, {self.dofs} DOFs, "
                f"{len(self.stations)} stations>")
