"""Where the diagnosis places what no candidate explains (issue #23 item 3).

An effect outside the catalogue: a seal (a spring with cross-coupling and a
damper to ground) at station P1, shaft A z = 0.30 m (model node #6), where
the model has no bearing; the catalogue has bearings' coefficients at the
bearings only. Truth by ROSS 2.3 (the INI with a [bearing S1] section at
A 0.30, built by the bridge), eq. 19 noise 10/1 %, one seed, 8 x 151
(diag_cases' small grid). Asserted, against `rcbtool diagnose --json`
("places": node, share_pct, chi2, dof, adequate, in_span; the explanation):

* a large seal (kxx = kyy = 3e6 N/m, kxy = -kyx = 2e6 N/m, 200 N s/m; the
  fit of the model as it is runs off): a force at node #6 alone leaves the
  noise (its chi-square within the 1 % limit), the text says the effect sits
  there, and no candidate claims to explain it;
* a moderate seal (5e5 / 3e5 N/m): no node leaves the noise alone; the
  span the text gives holds node #6;
* the null case (nothing hidden): the model passes the adequacy test and
  nothing is placed.

Large effects at catalogue places (issue #23 item 5), the same grid and
noise: each must be named at its place, explain the data (the adequacy
test of the model with it), and its fitted size hold the truth within 5 %.
The score at the nominal model cannot rank them (B2 kyy 9e7 -> 2e6 N/m
scores 5 %, rank 35; B3 kcross 5e7 N/m 2.7 %); the equivalent loads place
the misfit and every one-parameter candidate there is fitted from a grid
across its bounds. The mass, pedestal and element cases run with
RCB_DIAG_ALL=1 (about 1 min more).

Measured (2 shared cores): ROSS about 10 s per truth, diagnose 3-25 s CPU.
"""

import json
import os

import pytest

import diag_cases as dc
from conftest import _rcbtool_path

pytest.importorskip("pyuff")

SEED = 1
SEAL_NODE = 6  # A 0.30 in the paper system (nodes every 0.05 m from A 0.0)
DRIVE_NODE = 4  # DA (A 0.20), where the one measured force (dc.IN, DA.x) acts


def _seal_ini(k, kc, c=200.0):
    """The paper system with a seal at A 0.30 (N/m, N/m, N s/m)."""
    return dc.BASE_INI.rstrip("\n") + (
        f"\n\n[bearing S1]\nat = A 0.30\nkxx = {k:g}\nkyy = {k:g}\nkxy = {kc:g}\n"
        f"kyx = {-kc:g}\ncxx = {c:g}\ncyy = {c:g}\n")


@pytest.fixture(scope="module")
def tool():
    return dc.Rcbtool(_rcbtool_path())


def _diagnose(tool, tmp_path, truth_ini):
    case = dc.ClaimCase("place", "", [], "place", grid="small")
    H = dc.ross_inertance(truth_ini)
    meas = tmp_path / "meas.uff"
    dc.write_uff(meas, dc.noisy(case, H, SEED))
    model = tmp_path / "model.ini"
    model.write_text(dc.model_ini())
    res = tool.run("diagnose", model, meas, "--params", dc.FIT_PARAMS, "--log", "--noise",
                   "10,1", "--top", 6, "--json")
    d = json.loads(res.stdout)
    print("\n", d["explanation"], "\n", d["places"][:4])
    return d


def test_large_seal_sits_at_its_node(tool, tmp_path):
    d = _diagnose(tool, tmp_path, _seal_ini(3e6, 2e6))
    assert not d["adequacy"]["adequate"]
    best = d["places"][0]
    assert best["node"] == SEAL_NODE, d["places"][:3]
    assert best["adequate"], best  # a force there leaves the noise alone
    assert best["chi2"] <= best["dof"] + 2.326 * (2 * best["dof"]) ** 0.5
    others = [p for p in d["places"] if p["node"] != SEAL_NODE]
    assert all(p["chi2"] > best["chi2"] + 10 for p in others if not p["in_span"])
    assert f"node #{SEAL_NODE})" in d["explanation"] and "sits there" in d["explanation"]
    assert not [c for c in d["candidates"] if c["claim"] == "explains"], d["candidates"][:2]


def test_moderate_seal_span_holds_its_node(tool, tmp_path):
    d = _diagnose(tool, tmp_path, _seal_ini(5e5, 3e5))
    assert not d["adequacy"]["adequate"]
    span = [p["node"] for p in d["places"] if p["in_span"]]
    assert SEAL_NODE in span, d["places"]
    assert all(d["places"][k]["node"] in span for k in range(1))  # the best is in it
    assert "along a span" in d["explanation"]
    assert not [c for c in d["candidates"] if c["claim"] == "explains"], d["candidates"][:2]
    # one excitation point (DA.x, node #4): that node alone is flagged, and
    # the words say the span holds it (issue #33: a force at the drive takes
    # any misfit shaped like the response to the drive)
    assert [p["node"] for p in d["places"] if p["at_drive"]] == [DRIVE_NODE], d["places"]
    if any(p["in_span"] and p["at_drive"] for p in d["places"]):
        assert f"the only excitation point (node #{DRIVE_NODE})" in d["explanation"]
    if d["places"][0]["at_drive"]:
        assert "cannot place it" in d["explanation"] and "Placed by" not in d["explanation"]


def test_null_places_nothing(tool, tmp_path):
    d = _diagnose(tool, tmp_path, dc.BASE_INI)
    assert d["adequacy"]["adequate"], d["adequacy"]
    assert d["places"] == []
    assert "Placed" not in d["explanation"]


# (name, model_edit, effect, place, parameter, truth): ROSS truth on 8 x 151
LARGE = [
    ("aniso_B2", dc.bearing_keys("B2", kyy=2e6), dc.STIFF, "bearing B2", "bearing.B2.kyy", 2e6),
    ("cross_B3", dc.bearing_keys("B3", kxy=5e7, kyx=-5e7), dc.CROSS, "bearing B3",
     "bearing.B3.kcross", 5e7),
    ("mass_DA", dc.point_mass_edit("A 0.20", 1.3), dc.MASS, "disk DA", "disk.DA.mass",
     None),  # the disk's 0.967 kg + 1.3 kg, checked below
    ("pedestal_B2", dc.bearing_keys("B2", **dc.PEDESTAL_B4), dc.PEDESTAL, "bearing B2",
     "bearing.B2.pedestal_k", 5e6),
    ("crack_B5", dc._element_stiffness_edit("B", 4, 0.15), dc.ELEMENT, "shaft B element 5",
     "shaft.B.e5.stiffness", 0.15),
]
SLOW_LARGE = {"mass_DA", "pedestal_B2", "crack_B5"}


@pytest.mark.parametrize("name,edit,effect,place,param,truth", [
    pytest.param(*c, marks=pytest.mark.skipif(
        c[0] in SLOW_LARGE and not os.environ.get("RCB_DIAG_ALL"),
        reason="slow: set RCB_DIAG_ALL=1")) for c in LARGE], ids=[c[0] for c in LARGE])
def test_large_effect_named(tool, tmp_path, name, edit, effect, place, param, truth):
    case = dc.ClaimCase(name, "", [], "large", model_edit=edit, grid="small")
    meas = dc.claim_measurement(case, tmp_path, SEED)
    model = tmp_path / "model.ini"
    model.write_text(dc.model_ini())
    d = tool.json("diagnose", model, meas, "--params", dc.FIT_PARAMS, "--log", "--noise",
                  "10,1", "--top", 4)
    c0 = d["candidates"][0]
    print(f"\n{name}: {c0['effect']} at {c0['place']} [{c0['claim']}] {c0['fitted']}; "
          f"error {d['error0_pct']:.2f} -> {c0['error_pct']:.2f} % (floor {d['floor_pct']:.2f})")
    assert c0["effect"] == effect and place in c0["place"], c0
    assert c0["claim"] == "explains" and c0["adequate"], c0
    fitted = dict((k, float(v)) for k, v in dc._FITTED.findall(c0["fitted"]))
    want = truth if truth is not None else 0.9667 + 1.3  # kg: DA's own mass + the point mass
    assert abs(fitted[param] / want - 1) < 0.05, (fitted, want)
