"""Analyses through the C library: FRFs, unbalance response, damped modes,
Campbell diagram and critical speeds, simulated measurements.

Edge units: frequencies in Hz, rotor speeds in rpm (converted to rad/s for the
library); results in SI (m/N, m, ...)."""

import ctypes
import math
from dataclasses import dataclass, field

import numpy as np

from . import _lib
from .meas import KINDS, Meas, kind_code
from .model import DIRS, RPM, Handle, Model

SOLVERS = ("auto", "dense", "banded", "sparse")
WHIRL = {-1: "backward", 0: "mixed", 1: "forward"}


class _Frf(Handle):
    """An rcb_frf object; keeps its model alive (the library holds a pointer)."""

    _destroy = "rcb_frf_destroy"
    _errmsg = "rcb_frf_errmsg"

    def __init__(self, model, outputs, inputs=(), solver="auto"):
        super().__init__()
        self.model = model
        self.outputs, out = model._dof_array(outputs)
        self.inputs, inp = model._dof_array(inputs) if inputs else ([], None)
        L = _lib.lib()
        st = L.rcb_frf_create(ctypes.byref(self._h), model.handle, len(self.outputs), out,
                              len(self.inputs), inp, SOLVERS.index(solver), None)
        if st != 0:
            msg = _lib.text(L.rcb_frf_errmsg(self._h)) if self._h else model.errmsg()
            self.close()
            raise _lib.RcbError(st, msg, "rcb_frf_create")


def _as_array(v):
    return np.atleast_1d(np.asarray(v, dtype=float))


def frf(model, outputs, inputs, freqs_hz, rpm=0.0, kind="receptance", solver="auto"):
    """FRFs H between output and input channels.

    outputs, inputs: channel names ("DA.x", "C.B.y", "#4.rx") or comma strings;
    freqs_hz: excitation frequencies, Hz; rpm: rotor speed, rpm, or None for a
    synchronous FRF (rotor speed = excitation frequency);
    kind: receptance (m/N), mobility (m/(N s)) or inertance (m/(N s^2)).
    Returns complex array (nfreq, nout, nin).
    """
    f = _as_array(freqs_hz)
    k = kind_code(kind)
    with _Frf(model, outputs, inputs, solver) as obj:
        nout, nin = len(obj.outputs), len(obj.inputs)
        H = np.zeros((len(f), nout, nin), dtype=complex)
        buf = np.zeros(nout * nin, dtype=complex)
        L = _lib.lib()
        for i, fi in enumerate(f):
            w = 2 * math.pi * fi
            speed = w if rpm is None else float(rpm) * RPM
            obj.check(L.rcb_frf_eval(obj.handle, w, speed, k, buf.ctypes.data), "rcb_frf_eval")
            H[i] = buf.reshape((nout, nin), order="F")
    return H


def unbalance(model, outputs, rpm, solver="auto"):
    """Steady response to the model's unbalances at rotor speeds rpm: complex
    displacement phasors q(t) = Re(Q e^{i Omega t}), m (rad for rotations),
    array (nrpm, nout)."""
    r = _as_array(rpm)
    with _Frf(model, outputs, (), solver) as obj:
        nout = len(obj.outputs)
        Q = np.zeros((len(r), nout), dtype=complex)
        buf = np.zeros(nout, dtype=complex)
        L = _lib.lib()
        for i, ri in enumerate(r):
            obj.check(L.rcb_frf_unbalance(obj.handle, ri * RPM, buf.ctypes.data),
                      "rcb_frf_unbalance")
            Q[i] = buf
    return Q


class _Modes(Handle):
    _destroy = "rcb_modes_destroy"
    _errmsg = "rcb_modes_errmsg"

    def __init__(self, model, max_zeta):
        super().__init__()
        self.model = model
        self._create("rcb_modes_create", model.handle, None)
        if max_zeta is not None:  # None: the library's RCB_MODES_MAX_ZETA_DEFAULT
            self.check(_lib.lib().rcb_modes_set_max_zeta(self.handle, float(max_zeta)),
                       "rcb_modes_set_max_zeta")


@dataclass
class Modes:
    """Damped modes at one rotor speed, sorted by damped frequency."""

    rpm: float
    eigenvalues: np.ndarray  # lambda = -zeta wn + i wd, 1/s
    fd_hz: np.ndarray        # damped natural frequency, Hz
    fn_hz: np.ndarray        # undamped natural frequency |lambda| / 2 pi, Hz
    zeta: np.ndarray         # damping ratio (-)
    logdec: np.ndarray       # logarithmic decrement (-)
    whirl: list              # "forward" | "backward" | "mixed"
    shapes: np.ndarray = None  # (ndof, nmodes) complex, unit largest translation
    node_z: np.ndarray = None  # axial position of each node, m
    node_shaft: list = field(default_factory=list)
    node_dofs: np.ndarray = None  # (nnodes, 4) matrix rows (-1: eliminated)

    def __len__(self):
        return len(self.fd_hz)

    def node_shape(self, k, dirs=("x", "y")):
        """Mode k at every node: complex array (nnodes, len(dirs)) of the
        displacement phasors X, Y (m) or rotations (rad) per node."""
        cols = [DIRS.index(d) for d in dirs]
        out = np.full((len(self.node_z), len(cols)), np.nan, dtype=complex)
        for j, c in enumerate(cols):
            rows = self.node_dofs[:, c]
            ok = rows >= 0
            out[ok, j] = self.shapes[rows[ok], k]
        return out


def modes(model, rpm=0.0, n=10, max_zeta=None, shapes=True):
    """The n lowest damped modes at rotor speed rpm (only oscillating modes;
    damping ratios above max_zeta left out, as rcbtool modes does; None: the
    library's default, RCB_MODES_MAX_ZETA_DEFAULT)."""
    nd = model.dofs
    n = int(n)
    arr = (_lib.Mode * max(n, 1))()
    got = ctypes.c_size_t()
    S = np.zeros((nd, max(n, 1)), dtype=complex, order="F") if shapes else None
    with _Modes(model, max_zeta) as e:
        e.check(_lib.lib().rcb_modes_compute(e.handle, float(rpm) * RPM, n, arr,
                                             ctypes.byref(got),
                                             S.ctypes.data if shapes else None),
                "rcb_modes_compute")
    k = got.value
    ms = arr[:k]
    lam = np.array([complex(m.lam[0], m.lam[1]) for m in ms])
    nodes = model.nodes
    return Modes(
        rpm=float(rpm), eigenvalues=lam,
        fd_hz=np.array([m.wd for m in ms]) / (2 * math.pi),
        fn_hz=np.array([m.wn for m in ms]) / (2 * math.pi),
        zeta=np.array([m.zeta for m in ms]), logdec=np.array([m.logdec for m in ms]),
        whirl=[WHIRL[m.whirl] for m in ms],
        shapes=S[:, :k].copy() if shapes else None,
        node_z=np.array([nd_.z for nd_ in nodes]), node_shaft=[nd_.shaft for nd_ in nodes],
        node_dofs=np.array([nd_.dofs for nd_ in nodes], dtype=int))


@dataclass
class Campbell:
    """Campbell data: the n lowest damped modes at each speed (no mode tracking:
    curves that cross swap columns), and the critical speeds."""

    rpm: np.ndarray           # rotor speeds, rpm
    fd_hz: np.ndarray         # (nspeeds, nmodes) damped frequencies, Hz (NaN: fewer modes)
    logdec: np.ndarray        # (nspeeds, nmodes)
    whirl: np.ndarray         # (nspeeds, nmodes) -1 backward, 0 mixed, 1 forward
    ratio: float              # the excitation line: wd = ratio * Omega (1 for 1X)
    critical_rpm: np.ndarray  # critical speeds, rpm (crossings of the ratio line)
    critical_mode: np.ndarray  # column crossing at each critical speed


def campbell(model, rpm, n=6, max_zeta=None, ratio=1.0, max_crit=64):
    """Campbell diagram over rotor speeds rpm (increasing), n modes, critical
    speeds where a curve crosses wd = ratio * Omega."""
    r = _as_array(rpm)
    s = np.ascontiguousarray(r * RPM)
    ns, n = len(r), int(n)
    wd = np.zeros((n, ns), order="F")
    ld = np.zeros((n, ns), order="F")
    wh = np.zeros((n, ns), dtype=np.intc, order="F")
    L = _lib.lib()
    with _Modes(model, max_zeta) as e:
        e.check(L.rcb_campbell(e.handle, ns, s.ctypes.data, n, wd.ctypes.data, ld.ctypes.data,
                               wh.ctypes.data), "rcb_campbell")
    crit = np.zeros(max_crit)
    mode_of = np.zeros(max_crit, dtype=np.uintp)
    nc = ctypes.c_size_t()
    st = L.rcb_critical_speeds(ns, s.ctypes.data, n, wd.ctypes.data, float(ratio), max_crit,
                               crit.ctypes.data, mode_of.ctypes.data, ctypes.byref(nc))
    if st not in (0, -11):
        _lib.check(st, call="rcb_critical_speeds")
    k = nc.value
    return Campbell(rpm=r, fd_hz=wd.T / (2 * math.pi), logdec=ld.T.copy(), whirl=wh.T.copy(),
                    ratio=float(ratio), critical_rpm=crit[:k] / RPM,
                    critical_mode=mode_of[:k].astype(int))


def simulate(model, outputs, inputs=None, freqs_hz=None, rpm=0.0, kind="receptance",
             noise=None, seed=1, solver="auto"):
    """What a test would measure, as a Meas (write it with .write(path)).

    With inputs: FRFs at freqs_hz (Hz) and rotor speed rpm (None: synchronous),
    channels ordered output-major as rcbtool simulate writes them. Without
    inputs: the unbalance response at rotor speeds rpm (an array, rpm).
    noise: (beta_a, beta_s) in % for the paper's eq. 19 noise, seeded by seed.
    """
    if inputs:
        H = frf(model, outputs, inputs, freqs_hz, rpm=rpm, kind=kind, solver=solver)
        _, nout, nin = H.shape
        outs, ins = model._dof_array(outputs)[0], model._dof_array(inputs)[0]
        data = H.transpose(1, 2, 0).reshape(nout * nin, -1)
        resp = [o for o in outs for _ in ins]
        refs = [i for _ in outs for i in ins]
        ms = Meas.from_arrays(freqs_hz, data, resp, refs, kind=kind, rpm=rpm)
    else:
        Q = unbalance(model, outputs, rpm, solver=solver)
        ms = Meas.from_arrays(rpm, Q.T, model._dof_array(outputs)[0])
    if noise is not None:
        ms.add_noise(noise[0], noise[1], seed)
    return ms


def export_uff(path, model, outputs, inputs=None, freqs_hz=None, rpm=0.0,
               kind="receptance", binary=False, uff_map=None):
    """Write model responses (FRFs or unbalance responses, noise-free) as UFF
    dataset 58 through the library's writer; returns the node map used."""
    with simulate(model, outputs, inputs, freqs_hz, rpm, kind) as ms:
        return ms.write(path, uff_map=uff_map, model=model, binary=binary)


__all__ = ["frf", "unbalance", "modes", "campbell", "simulate", "export_uff", "Modes",
           "Campbell", "KINDS", "SOLVERS", "Model"]
