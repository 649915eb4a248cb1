"""Meas: measured (or simulated) FRFs / unbalance responses (an rcb_meas handle),
read and written as UFF dataset 58 (ASCII or binary 58b) or CSV by the library."""

import ctypes
import math
from pathlib import Path

import numpy as np

from . import _lib
from .model import RPM, Handle

KINDS = ("receptance", "mobility", "inertance")
TYPES = ("frf", "unbalance")
_UFF_EXT = (".uff", ".unv", ".uf")


def kind_code(kind):
    if isinstance(kind, int):
        return kind
    try:
        return KINDS.index(kind)
    except ValueError:
        raise ValueError(f"kind {kind!r}: expected one of {', '.join(KINDS)}") from None


def _uff_array(mapping):
    """{node: station} -> (ctypes array of rcb_uff_node, keep-alive list)."""
    items = sorted((int(k), str(v)) for k, v in (mapping or {}).items())
    keep = [s.encode() for _, s in items]
    arr = (_lib.UffNode * max(len(items), 1))()
    for i, ((node, _), s) in enumerate(zip(items, keep)):
        arr[i].node = node
        arr[i].station = s
    return len(items), arr, keep


class Meas(Handle):
    """A measurement: one abscissa (Hz for FRFs, rpm for unbalance responses at
    this edge), channels "RESP/REF" of complex values in SI."""

    _destroy = "rcb_meas_destroy"
    _errmsg = "rcb_meas_errmsg"

    def __init__(self):
        super().__init__()
        self._create("rcb_meas_create", None)

    # ---- construction -----------------------------------------------------
    @classmethod
    def from_arrays(cls, x, data, responses, references=None, kind="receptance",
                    rpm=None):
        """Build a measurement from arrays.

        x: frequencies in Hz (FRFs, references given) or rotor speeds in rpm
        (unbalance responses, references None); data: complex, (nchannels, npoints);
        responses/references: channel names per row ("DA.x", "C.B.y");
        rpm: rotor speed of an FRF test, None for a synchronous FRF.
        """
        ms = cls()
        L = _lib.lib()
        x = np.ascontiguousarray(x, dtype=float)
        data = np.asarray(data, dtype=complex)
        if data.ndim == 1:
            data = data[None, :]
        frf = references is not None
        scale = 2 * math.pi if frf else RPM
        xr = np.ascontiguousarray(x * scale)
        speed = (-1.0 if rpm is None else float(rpm) * RPM) if frf else 0.0
        ms.check(L.rcb_meas_set_grid(ms.handle, 0 if frf else 1, len(xr), xr.ctypes.data,
                                     speed), "rcb_meas_set_grid")
        if data.shape != (len(responses), len(xr)):
            raise ValueError(f"data has shape {data.shape}, expected "
                             f"({len(responses)}, {len(xr)}) (channels, points)")
        for c, resp in enumerate(responses):
            row = np.ascontiguousarray(data[c])
            ref = references[c].encode() if frf else None
            ms.check(L.rcb_meas_add_channel(ms.handle, resp.encode(), ref,
                                            kind_code(kind) if frf else 0, row.ctypes.data),
                     "rcb_meas_add_channel")
        return ms

    @classmethod
    def read(cls, path, uff_map=None, model=None):
        """Read UFF58 (.uff/.unv/.uf, ASCII or binary) or CSV (.csv).
        uff_map {node: station}; default: the model's [uff] map when a model is given.
        It also names a CSV's stations written as node numbers ("2.x/11.x_re")."""
        path = Path(path)
        ms = cls()
        L = _lib.lib()
        if uff_map is None and model is not None:
            uff_map = model.uff_map
        n, arr, _keep = _uff_array(uff_map)
        if path.suffix.lower() == ".csv":
            ms.check(L.rcb_meas_read_csv_map(ms.handle, str(path).encode(), n, arr),
                     "rcb_meas_read_csv_map")
        else:
            ms.check(L.rcb_meas_read_uff(ms.handle, str(path).encode(), n, arr),
                     "rcb_meas_read_uff")
        return ms

    @classmethod
    def from_bytes(cls, data, suffix=".uff", uff_map=None, model=None):
        """Read a measurement held in memory (the bytes of a UFF58 or CSV file,
        e.g. sent to a Dask worker): written to a private temporary file that
        the library reads, then removed. suffix: ".uff" or ".csv" (the format)."""
        import os
        import tempfile

        fd, tmp = tempfile.mkstemp(suffix=suffix, prefix="librcb-meas-")
        try:
            with os.fdopen(fd, "wb") as f:
                f.write(data)
            return cls.read(tmp, uff_map=uff_map, model=model)
        finally:
            os.unlink(tmp)

    def write(self, path, uff_map=None, model=None, binary=False):
        """Write UFF58 (by extension .uff/.unv/.uf; binary 58b if asked) or CSV.
        Stations of the channels without a node number in uff_map (or the model's
        [uff] map) get the next free numbers; the map used is returned."""
        path = Path(path)
        L = _lib.lib()
        if path.suffix.lower() == ".csv":
            self.check(L.rcb_meas_write_csv(self.handle, str(path).encode()),
                       "rcb_meas_write_csv")
            return None
        if path.suffix.lower() not in _UFF_EXT:
            raise ValueError(f"{path}: expected .uff, .unv, .uf or .csv")
        mapping = dict(uff_map if uff_map is not None else (model.uff_map if model else {}))
        have = set(mapping.values())
        nxt = max(mapping, default=0) + 1
        for st in self.stations():
            if st not in have:
                mapping[nxt] = st
                have.add(st)
                nxt += 1
        n, arr, _keep = _uff_array(mapping)
        self.check(L.rcb_meas_write_uff(self.handle, str(path).encode(), int(bool(binary)), n,
                                        arr), "rcb_meas_write_uff")
        return mapping

    # ---- contents ---------------------------------------------------------
    @property
    def type(self):
        return TYPES[_lib.lib().rcb_meas_get_type(self.handle)]

    @property
    def n_points(self):
        return int(_lib.lib().rcb_meas_point_count(self.handle))

    @property
    def x_si(self):
        """Abscissa, rad/s (excitation frequency or rotor speed)."""
        n = self.n_points
        p = _lib.lib().rcb_meas_grid(self.handle)
        return np.ctypeslib.as_array(p, shape=(n,)).copy() if n else np.zeros(0)

    @property
    def x(self):
        """Abscissa at the edge: Hz for FRFs, rpm for unbalance responses."""
        return self.x_si / (2 * math.pi if self.type == "frf" else RPM)

    @property
    def rpm(self):
        """Rotor speed of an FRF test, rpm (None: synchronous; None for unbalance)."""
        if self.type != "frf":
            return None
        s = _lib.lib().rcb_meas_speed(self.handle)
        return None if s < 0 else s / RPM

    def _channels(self):
        L = _lib.lib()
        info = _lib.MeasChannelInfo()
        for i in range(L.rcb_meas_channel_count(self.handle)):
            self.check(L.rcb_meas_channel(self.handle, i, ctypes.byref(info)))
            yield info

    @property
    def channels(self):
        """List of (response, reference or None, kind) per channel."""
        return [(_lib.text(c.response), _lib.text(c.reference), KINDS[c.kind])
                for c in self._channels()]

    def names(self):
        return [r if ref is None else f"{r}/{ref}" for r, ref, _ in self.channels]

    def stations(self):
        """Station names of every response and reference, in order of appearance."""
        out = []
        for r, ref, _ in self.channels:
            for s in (r, ref):
                if s:
                    st = s.rsplit(".", 1)[0]
                    if st not in out:
                        out.append(st)
        return out

    @property
    def data(self):
        """Values, complex (nchannels, npoints), SI (a copy)."""
        n = self.n_points
        rows = []
        for c in self._channels():
            buf = (ctypes.c_double * (2 * n)).from_address(c.data)
            rows.append(np.frombuffer(buf, dtype=np.complex128, count=n).copy())
        return np.array(rows).reshape(len(rows), n)

    def convert(self, kind):
        """Convert every FRF channel to kind (receptance, mobility, inertance)."""
        self.check(_lib.lib().rcb_meas_convert(self.handle, kind_code(kind)), "rcb_meas_convert")
        return self

    def add_noise(self, beta_a, beta_s, seed=1):
        """The paper's eq. 19 noise (random beta_a %, systematic beta_s %), seeded."""
        self.check(_lib.lib().rcb_meas_add_noise(self.handle, float(beta_a), float(beta_s),
                                                 int(seed)), "rcb_meas_add_noise")
        return self

    def __repr__(self):
        if not self._h:
            return "<librcb.Meas closed>"
        return (f"<librcb.Meas {self.type}: {len(self.channels)} channels x "
                f"{self.n_points} points>")


def read_meas(path, uff_map=None, model=None):
    """Read a measurement file (UFF58 or CSV); see Meas.read."""
    return Meas.read(path, uff_map=uff_map, model=model)
