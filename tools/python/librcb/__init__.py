"""librcb: lateral rotordynamics of rotor-coupling-bearing trains, in Python.

A thin ctypes layer over the C library librcb.so (no physics in Python):

    import librcb as rcb
    m = rcb.Model.from_ini("examples/paper_system.ini")
    H = rcb.frf(m, ["C.A.x"], ["DA.x"], freqs_hz=np.linspace(0, 500, 501), rpm=10000)
    md = rcb.modes(m, rpm=10000, n=8)
    cb = rcb.campbell(m, rpm=np.linspace(0, 20000, 81))
    meas = rcb.Meas.read("measured.uff", model=m)
    res = rcb.fit(m, meas, ["coupling.C.kt", "coupling.C.kr"], noise=(10, 1))
    mon = rcb.Monitor(m, meas, ["coupling.C.kt"], noise=(10, 1)); mon.update(meas2)

Units: SI for every value; frequencies in Hz and rotor speeds in rpm at this
edge (rad/s inside the library). The shared library is found through
$LIBRCB_PATH, next to the package, or the loader's standard names.
"""

from ._lib import LibraryNotFound, RcbError
from .analyses import Campbell, Modes, campbell, export_uff, frf, modes, simulate, unbalance
from .identify import Diagnosis, FitResult, claim, compare, diagnose, fit, plan
from .meas import Meas, read_meas
from .model import Model
from .monitor import Monitor

__version__ = "0.1.0"


def library_version():
    """Version string of the C library actually loaded."""
    from . import _lib
    return _lib.lib().rcb_version_string().decode()


def library_path():
    """File the C library was loaded from."""
    from . import _lib
    _lib.lib()
    return _lib.LIB_PATH


__all__ = ["Model", "Meas", "read_meas", "frf", "unbalance", "modes", "campbell", "simulate",
           "export_uff", "fit", "diagnose", "claim", "plan", "compare", "Modes", "Campbell", "FitResult",
           "Diagnosis", "Monitor", "RcbError", "LibraryNotFound", "library_version", "library_path"]
