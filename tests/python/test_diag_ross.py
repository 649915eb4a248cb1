"""Diagnosis (issue #4) on truth data from an implementation that is not ours.

The truth rotors are the paper system with a hidden effect built in ROSS 2.3
(diag_cases.py: cross-coupled bearing, coupling hub masses, coupling
rotational damping, a point mass, bearing anisotropy, bearing damping, a
pedestal); ROSS computes the inertances, eq. 19 noise is added here (the
generator of src/io/noise.c, ported and checked against rcbtool), pyuff
writes UFF 58, and `rcbtool diagnose` runs on the model without the effect.
Asserted: the effect is visible (the model as it is misses the noise floor),
the hidden effect at the right place ranks first and is significant, and
`diagnose --apply 1` followed by `rcbtool fit` brings the error to the noise
floor (below 1.1 x the floor). Two effects hidden at once: two rounds find both.

One noise seed here; tools/bench/diag_success.py (./scripts/dev.sh
diag-success) runs every case over several seeds and prints the success rate.
The two slowest single-effect cases (many candidates refitted) run only with
RCB_DIAG_ALL=1, to keep this file near 2 min of CPU; the report runs them.

Issue #14, the users' size: 32 inertances (forces at DA and DB in x and y),
1101 points 50-600 Hz, eq. 19 noise plus 2 degrees of phase noise (large_*
cases of diag_cases.py): each hidden effect first and at the floor after
apply + fit, the null set silent, and the hub cases whose baseline fit runs off
(0.07 and 0.15 kg per hub; kr onto its bound 1000 x below nominal) named and
reported as such. They run in every test run since the diagnosis of such a set
takes 1.4-3.7 s (3-9 s each with truth, apply and fit; the two run-off cases
40-80 s, most of it `rcbtool fit` of the model as it is crawling to its bound;
2.4 min for the eight).
"""

import os

import numpy as np
import pytest

import diag_cases as dc
from conftest import _rcbtool_path

pytest.importorskip("pyuff")

SEED = 1


@pytest.fixture(scope="module")
def tool():
    return dc.Rcbtool(_rcbtool_path())


def test_noise_is_rcbtools(tool, tmp_path):
    """The Python eq. 19 noise draws what `rcbtool simulate --seed` draws."""
    grid = ["--out", "DA.x,C.B.y", "--in", "DA.x", "--fmin", 100, "--fmax", 400, "--points",
            31, "--rpm", 10000, "--kind", "inertance"]
    model = dc.REPO / "examples" / "paper_system.ini"

    def sim(name, *extra):
        tool.run("simulate", model, "--frf", *grid, *extra, "-o", tmp_path / name)
        rows = [ln for ln in (tmp_path / name).read_text().splitlines() if not ln.startswith("#")]
        a = np.array([[float(v) for v in r.split(",")] for r in rows[1:]])
        return (a[:, 1::2] + 1j * a[:, 2::2]).T

    clean, noisy = sim("c.csv"), sim("n.csv", "--noise", "10,1", "--seed", 7)
    mine = dc.add_noise(clean, 10.0, 1.0, 7)
    assert np.max(np.abs(mine - noisy) / np.abs(noisy)) < 1e-13
    assert np.max(np.abs(noisy - clean) / np.abs(clean)) > 0.05  # the noise is there


def _run(tool, tmp_path, case, rounds):
    H = dc.truth_clean(case)
    meas = tmp_path / "meas.uff"
    dc.write_case_uff(meas, case, H, SEED)
    steps = dc.diagnose_rounds(tool, tmp_path, meas, rounds)
    for k, s in enumerate(steps):
        print(f"{case.name} round {k + 1}: {s['effect']} at {s['place']} ({s['fitted']}); "
              f"error {s['error0_pct']:.3f} -> {s['error_pct']:.3f} % (floor {s['floor_pct']:.3f})")
    # the hidden effect is visible: the model as it is misses the floor
    assert steps[0]["error0_pct"] > dc.AT_FLOOR * steps[0]["floor_pct"], steps[0]
    return steps


SLOW = ("ross_hub_C", "ross_mass_P1")
SINGLE = [
    pytest.param(c, id=c.name, marks=pytest.mark.skipif(
        c.name in SLOW and not os.environ.get("RCB_DIAG_ALL"),
        reason="slow: set RCB_DIAG_ALL=1 (./scripts/dev.sh diag-success runs it)"))
    for c in dc.ROSS_CASES if not c.needs
]


@pytest.mark.parametrize("case", SINGLE)
def test_ross_hidden_effect(tool, tmp_path, case):
    (step,) = _run(tool, tmp_path, case, 1)
    assert dc.found(step, case.expect[0]), (case.what, step)
    assert dc.at_floor(step), step


PEDESTAL = next(c for c in dc.ROSS_CASES if c.needs == "pedestal")


def _need_pedestal(tool, tmp_path):
    if not tool.accepts(dc.pedestal_probe_ini(), tmp_path):
        pytest.skip("the model loader does not accept [bearing] pedestal_mass yet "
                    "(`rcbtool check` rejects it)")


def test_ross_pedestal_frf(tool, tmp_path):
    """Our flexible support (the INI keys) is ROSS's n_link + PointMass pedestal."""
    _need_pedestal(tool, tmp_path)
    ini = tmp_path / "pedestal.ini"
    ini.write_text(dc.pedestal_probe_ini())
    ours = dc.truth_clean(dc.Case("ours", "", [], "rcbtool", truth_ini=lambda t: ini.read_text()),
                          tool, tmp_path)
    ross = dc.truth_clean(PEDESTAL)
    base = dc.ross_inertance(dc.BASE_INI, check=False)
    assert np.max(np.abs(ross - base) / np.abs(base)) > 0.05  # the pedestal matters
    assert np.max(np.abs(ours - ross) / np.abs(ross)) < 1e-6


def test_ross_hidden_pedestal(tool, tmp_path):
    _need_pedestal(tool, tmp_path)
    (step,) = _run(tool, tmp_path, PEDESTAL, 1)
    assert dc.found(step, PEDESTAL.expect[0]), (PEDESTAL.what, step)
    assert dc.at_floor(step), step


def test_two_hidden_effects(tool, tmp_path):
    """B2 cross-coupling and a mass at DB, hidden at once: two rounds of
    diagnose --apply find one each; the error is at the floor after round 2,
    and not after round 1."""
    case = dc.TWO_EFFECT
    steps = _run(tool, tmp_path, case, 2)
    first = [w for w in case.expect if dc.found(steps[0], w)]
    assert len(first) == 1, steps[0]
    (second,) = [w for w in case.expect if w not in first]
    assert dc.found(steps[1], second), steps[1]
    assert not dc.at_floor(steps[0]), steps[0]
    assert dc.at_floor(steps[1]), steps[1]


LARGE_HUBS = [pytest.param(c, id=c.name) for c in dc.LARGE_CASES
              if c.name in ("large_hub_C", "large_hub15_C")]
LARGE = [pytest.param(c, id=c.name) for c in dc.LARGE_CASES
         if c.expect and c.name not in ("large_hub_C", "large_hub15_C")]
LARGE_NULL = next(c for c in dc.LARGE_CASES if not c.expect)


@pytest.mark.parametrize("case", LARGE)
def test_large_hidden_effect(tool, tmp_path, case):
    if case.needs == "pedestal":
        _need_pedestal(tool, tmp_path)
    (step,) = _run(tool, tmp_path, case, 1)
    assert dc.found(step, case.expect[0]), (case.what, step)
    assert dc.at_floor(step), step
    assert "ran far from the nominal model" not in step["explanation"], step


@pytest.mark.parametrize("case", LARGE_HUBS)
def test_large_baseline_runs_off(tool, tmp_path, case):
    """The hub mass shifts every resonance: the fit of the model as it is runs
    off (0.07 kg: kr onto its lower bound, 1000 x below nominal; 0.15 kg: kt
    onto its bound too, error 92 %); the diagnosis says so, names the hub at
    coupling C all the same (0.15 kg: before the pre-fits at the nominal model
    it named a pedestal under B2), and apply + fit reach the floor."""
    H = dc.truth_clean(case)
    meas = tmp_path / "meas.uff"
    dc.write_case_uff(meas, case, H, SEED)
    model = tmp_path / "as_is.ini"
    model.write_text(dc.model_ini())
    # one start, the nominal model's (the random restarts, up to 8, cost 4413
    # sweeps and 120 s of CPU on the 0.07 kg hub, and end on the bound too)
    fit = tool.json("fit", model, meas, "--params", dc.FIT_PARAMS, "--log", "--noise", "10,1",
                    "--starts", 1)
    kr = next(p for p in fit["params"] if p["name"] == "coupling.C.kr")
    assert kr["fitted"] < 0.01 * kr["start"], kr  # the collapse itself
    (step,) = _run(tool, tmp_path, case, 1)
    assert "ran far from the nominal model" in step["explanation"], step
    assert dc.found(step, case.expect[0]), step
    assert dc.at_floor(step), step


def test_large_null_silent(tool, tmp_path):
    H = dc.truth_clean(LARGE_NULL)
    meas = tmp_path / "meas.uff"
    dc.write_case_uff(meas, LARGE_NULL, H, SEED)
    model = tmp_path / "model.ini"
    model.write_text(dc.model_ini())
    d = tool.json("diagnose", model, meas, "--params", dc.FIT_PARAMS, "--log", "--noise", "10,1",
                  "--top", 1)
    assert not d["candidates"][0]["significant"], d["candidates"][0]
    assert d["error0_pct"] < dc.AT_FLOOR * d["floor_pct"], d
