"""Per-element factors (issue #23) against ROSS: one ShaftElement of shaft B of
examples/paper_system.ini given its own ROSS Material (E and G 40 % lower, or
a denser one) has the same FRFs as librcb's model with
shaft.B.e<k>.stiffness = 0.6 (or shaft.B.e<k>.mass) set through the package,
complex values to 1e-6 relative as the other ROSS comparisons. Each case also
checks that the change moves the FRFs by far more than the tolerance, so the
agreement is not that of two unchanged models.

Needs ROSS (the venv) and the shared library (LIBRCB_PATH, as the package
tests; scripts/dev.sh test sets it)."""

import math
import warnings

import numpy as np
import pytest

import ross_models as rm
from pkg_helpers import PAPER, import_librcb

RTOL = 1e-6  # relative, on each complex value; never loosen
RPM = 3000.0
FREQ = np.linspace(2.0, 600.0, 61)
OUTS = ["DA.x", "DB.y", "C.B.x", "B3.y", "B4.x", "P1.x"]
INS = ["DA.x", "DB.x", "DB.y"]


def _ross_frf(edit):
    model = rm.Model(PAPER.read_text())
    if edit:
        edit(model)
    speed = RPM * math.pi / 30.0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rmod = rm.RossModel(model, speed=speed)
        rows = [rmod.station_dof(o) for o in OUTS]
        cols = [rmod.station_dof(i) for i in INS]
        H = np.empty((len(FREQ), len(OUTS), len(INS)), dtype=complex)
        for n, f in enumerate(FREQ):
            T = rmod.rotor.transfer_matrix(speed=speed, frequency=2.0 * math.pi * f)
            H[n] = T[np.ix_(rows, cols)]
    return H


def _ours(params):
    rcb = import_librcb()
    m = rcb.Model.from_ini(PAPER)
    for name, v in params.items():
        m.set(name, v)
    return rcb.frf(m, OUTS, INS, FREQ, rpm=RPM, kind="receptance")


def _worst(H, ref):
    """Largest relative difference; an exactly zero reference entry is measured
    against the largest response to the same input."""
    scale = np.where(ref != 0, np.abs(ref), np.abs(ref).max(axis=1, keepdims=True))
    return float((np.abs(H - ref) / scale).max())


@pytest.mark.parametrize(
    "k, stiffness, mass",
    [(5, 0.6, 1.0), (2, 0.6, 1.0), (9, 0.6, 1.0), (5, 1.0, 1.5)],
    ids=["e5-stiffness", "e2-stiffness", "e9-stiffness", "e5-mass"],
)
def test_element_factor_frf(k, stiffness, mass):
    params = {f"shaft.B.e{k}.stiffness": stiffness, f"shaft.B.e{k}.mass": mass}
    ours = _ours(params)
    ref = _ross_frf(rm.element_factors_edit("B", k, stiffness=stiffness, mass=mass))
    err = _worst(ours, ref)
    moved = _worst(_ours({}), ref)
    print(f"shaft.B.e{k} stiffness {stiffness} mass {mass}: worst {err:.2e}, "
          f"unchanged model {moved:.2e}")
    assert err <= RTOL, f"worst relative difference {err:.3e}"
    assert moved > 1e3 * RTOL, f"the edit changes the FRFs by {moved:.3e} only"


def test_element_table():
    """The package's element table: k from 1 along z, the z range of each element
    (shaft B: 0.52 to 1.02 m in ten elements of 0.05 m), the factors set."""
    rcb = import_librcb()
    m = rcb.Model.from_ini(PAPER)
    m.set("shaft.B.e5.stiffness", 0.6)
    els = [e for e in m.elements if e.shaft == "B"]
    assert [e.k for e in els] == list(range(1, 11))
    for e in els:
        assert e.param == f"shaft.B.e{e.k}"
        assert e.z0 == pytest.approx(0.52 + 0.05 * (e.k - 1), abs=1e-12)
        assert e.z1 == pytest.approx(0.52 + 0.05 * e.k, abs=1e-12)
        assert e.node1 == e.node0 + 1
        assert (e.stiffness, e.mass) == ((0.6, 1.0) if e.k == 5 else (1.0, 1.0))


def test_element_stiffness_edit_helper():
    """element_stiffness_edit (for diag_cases) is the stiffness-only edit."""
    model = rm.Model(PAPER.read_text())
    rm.element_stiffness_edit("B", 7, 0.6)(model)
    rm.element_mass_edit("B", 7, 2.0)(model)
    sh = next(s for s in model.shafts if s.name == "B")
    assert sh.factors == {6: (0.6, 2.0)}
    with pytest.raises(ValueError):
        rm.element_stiffness_edit("B", 11, 0.6)(model)
