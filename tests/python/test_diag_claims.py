"""What the diagnosis may claim (issue #23), on truth data from ROSS.

The cases (diag_cases.CLAIM_CASES; the paper system, ROSS 2.3 inertances,
eq. 19 noise 10/1 % + 2 degrees of phase noise, one seed):

* claim_crack_B: one element of shaft B between B3 and DB (B 0.72-0.77 m)
  with E and G x 0.6;
* claim_hub25_C: coupling C's hubs 0.25 kg per side with the inertia of a
  steel ring 40/17 mm x 31 mm;
* claim_probe_DBy: the rotor exactly as modelled, every DB.y channel read
  0.8 exp(-i 4 deg) after the noise;
* claim_two: the crack and kxy = -kyx = 2e7 N/m at B2, in two rounds;
* claim_weak: a cross-coupled stiffness at B3 near the detection limit;
* claim_null: nothing hidden.

Asserted, against the JSON of `rcbtool diagnose --json` of issue #23 (top
level "adequacy": {"chi2", "dof", "limit", "adequate"} of the model as it is,
and "misfit": {"sensors": [{"response", "share_pct", "ratio"}, ...]}; per
candidate "claim" in explains | improves | none, "adequate", "significant"):
the done-when of the issue per case (see each test), and for every case the
rule: no candidate claims "explains" unless it is significant and adequate,
and the first one, when it claims so, is adequate again after --apply 1 and
`rcbtool fit` (the next `diagnose` of the applied model says so).

Without "adequacy" in that JSON (rcbtool before issue #23) every test that
reads it skips, with the reason. The grid of each case and why: see
docs/diagnosis_claims_before.md. The fit after --apply runs with --starts 1:
its start is the candidate's refit; random restarts only cost time here.

Cost (2 shared cores, one BLAS thread): 23 s of CPU while the fields are
absent (the ROSS checks; a first ROSS rotor in a process costs about 10 s);
65 s of CPU (156 s wall) with the fields injected into today's diagnose
output by a scratch plugin, every rcbtool run included.
"""

import math
import re

import numpy as np
import pytest

import diag_cases as dc
from conftest import _rcbtool_path

pytest.importorskip("pyuff")

SEED = 1
CHAIN = (dc.SENSOR, "sensor sign", "swapped sensors")  # effects on the measurement chain
CASES = {c.name: c for c in dc.CLAIM_CASES}


@pytest.fixture(scope="module", autouse=True)
def _one_blas_thread():
    """ROSS's truth is 1101 small solves: BLAS threads on shared cores make
    them 10-15 x slower, never faster."""
    try:
        from threadpoolctl import threadpool_limits
    except ImportError:
        yield
        return
    with threadpool_limits(1):
        yield


@pytest.fixture(scope="module")
def tool():
    return dc.TimedRcbtool(_rcbtool_path())


@pytest.fixture(scope="module")
def claims(tool, tmp_path_factory):
    """Skips unless `rcbtool diagnose --json` has the fields of issue #23
    (checked on a small set made by rcbtool simulate: about 1 s)."""
    tmp = tmp_path_factory.mktemp("probe_json")
    model = dc.REPO / "examples" / "paper_system.ini"
    meas = tmp / "m.csv"
    tool.run("simulate", model, "--frf", "--out", "DA.x,DB.y", "--in", "DA.x", "--fmin", 100,
             "--fmax", 400, "--points", 31, "--rpm", 10000, "--kind", "inertance", "--noise",
             "10,1", "--seed", 1, "-o", meas)
    d = tool.json("diagnose", model, meas, "--params", "coupling.C.kt", "--log", "--noise",
                  "10,1", "--refits", 1, "--top", 1)
    if "adequacy" not in d:
        pytest.skip('rcbtool diagnose --json has no "adequacy" yet (issue #23: the claims, '
                    "the adequacy test and the misfit by sensor are being added)")
    return True


# --------------------------------------------------------------------------
# helpers
# --------------------------------------------------------------------------


def _rounds(tool, tmp_path, case, rounds=1):
    meas = dc.claim_measurement(case, tmp_path, SEED)
    model = tmp_path / "model.ini"
    model.write_text(dc.model_ini())
    steps, params = [], dc.FIT_PARAMS
    for r in range(rounds):
        s = dc.claim_round(tool, tmp_path, meas, model, params, tag=f"r{r + 1}", fit=False)
        s["meas"] = meas
        d = s["diag"]
        c0 = d["candidates"][0] if d["candidates"] else {}
        e1 = c0.get("error_pct")
        print(f"\n{case.name} round {r + 1} ({case.grid}): {c0.get('effect')} at "
              f"{c0.get('place')} [{c0.get('claim')}] error {d['error0_pct']:.2f} -> "
              f"{math.nan if e1 is None else e1:.2f} % (floor {d['floor_pct']:.2f}); "
              f"adequacy {d.get('adequacy')}; diagnose {s['cpu_s']:.1f} s CPU\n"
              f"  {d['explanation']}")
        _rule(tool, case, s)
        steps.append(s)
        if s["applied"] is None:
            break
        model, params = s["applied"], s["params"]
    return steps


def _rule(tool, case, step):
    """No "explains" claim while the error after apply is above the floor by
    the adequacy test."""
    d = step["diag"]
    assert set(d["adequacy"]) >= {"chi2", "dof", "limit", "adequate"}, d["adequacy"]
    for c in d["candidates"]:
        assert c["claim"] in ("explains", "improves", "none"), c
        if c["claim"] == "explains":
            assert c["significant"] and c["adequate"], (case.name, c)
    c0 = d["candidates"][0] if d["candidates"] else None
    if c0 and c0["claim"] == "explains" and step["applied"] is not None:
        nxt = tool.json("diagnose", step["applied"], step["meas"], "--params", step["params"],
                        *dc.log_flag(step["params"]), "--noise", "10,1", "--top", 1,
                        "--refits", 1)
        assert nxt["adequacy"]["adequate"], (case.name, c0, nxt["adequacy"])
        step["after"] = nxt


def _explains(d):
    return [c for c in d["candidates"] if c["claim"] == "explains"]


_POS = re.compile(r"(\d+\.\d+)(?:\s*(?:-|to|\.\.)\s*(\d+\.\d+))?\s*m\b")
_NODE = re.compile(r"#(\d+)")
SPAN_NODES = (14, 17)  # B3 is node #14, DB node #17 (shaft A holds #0-#10)


def _in_span(text, span=dc.CRACK_SPAN):
    """TEXT names shaft B and, between B3 and DB (0.67-0.82 m), a span in m
    ("0.72-0.77 m", within the ends) or a position ("z = 0.72 m", strictly
    inside: a point at B3 itself is not the span), or nodes (#15-#16 within
    #14-#17, one node strictly inside); or names B3 and DB."""
    shaft, lo, hi = span
    if f"shaft {shaft}" not in text:
        return False
    if "B3" in text and "DB" in text:
        return True
    eps = 1e-6
    for a, b in _POS.findall(text):
        if b and lo - eps <= float(a) <= hi + eps and lo - eps <= float(b) <= hi + eps:
            return True
        if not b and lo + eps < float(a) < hi - eps:
            return True
    nodes = [int(n) for n in _NODE.findall(text)]
    a, b = SPAN_NODES
    if len(nodes) == 1:
        return a < nodes[0] < b
    return len(nodes) > 1 and all(a <= n <= b for n in nodes)


def _is(c, effect, place):
    return c["effect"] == effect and place in c["place"]


# --------------------------------------------------------------------------
# the cases
# --------------------------------------------------------------------------


def test_hub25_moves_the_modes():
    """The hub of claim_hub25_C in ROSS: at 3000 rpm the first two pairs of
    modes move from 150/162 Hz to 120/133 Hz (the issue's 158/168 Hz is not
    what ROSS or rcbtool modes give for the model; 120/133 Hz is)."""
    rm = dc.rm
    speed = 3000.0 * math.pi / 30.0
    got = {}
    for name, edit in (("model", None), ("hub25", dc.hub_ring_edit(*dc.HUB25))):
        m = rm.Model(dc.BASE_INI)
        if edit:
            edit(m)
        lam, _, _ = rm.lateral_roots(rm.RossModel(m, speed=speed), speed)
        f = lam.imag / (2 * math.pi)
        got[name] = f[(f > 50) & (f < 200)]
    assert np.allclose(got["model"][[0, 2]], [150.3, 161.6], atol=0.5), got
    assert np.allclose(got["hub25"][[0, 2]], [120.3, 133.4], atol=0.5), got
    m, idd, ip = dc.HUB25
    assert (m, round(idd, 8), round(ip, 8)) == (0.25, 4.954e-5, 5.903e-5)


def test_truth_edits():
    """The crack is one ROSS element and nothing else (factor 1 gives the
    model's inertances bit for bit; 0.6 changes them), and the probe edit
    touches the DB.y rows only, on either grid."""
    base = dc.ross_inertance(dc.BASE_INI, check=False)
    same = dc.ross_inertance(dc.BASE_INI, dc._element_stiffness_edit("B", 4, 1.0), check=False)
    assert np.array_equal(same, base)
    crack = dc.ross_inertance(dc.BASE_INI, dc.CRACK_B)  # checked against transfer_matrix
    assert np.linalg.norm(crack - base) > 0.1 * np.linalg.norm(base)
    edit = dc.probe_edit("DB.y", dc.PROBE_GAIN)
    for nin in (1, len(dc.LARGE_INS)):
        data = np.ones((nin * len(dc.OUTS), 3), dtype=complex)
        got = edit(data)
        rows = [q * len(dc.OUTS) + dc.OUTS.index("DB.y") for q in range(nin)]
        assert np.all(got[rows] == dc.PROBE_GAIN)
        assert np.all(np.delete(got, rows, axis=0) == 1.0)
        assert np.all(data == 1.0)  # a copy


def test_crack_in_shaft_B(tool, claims, tmp_path):
    """Named as an element stiffness of shaft B between B3 and DB, or honestly
    not explained, with the span named."""
    case = CASES["claim_crack_B"]
    (s,) = _rounds(tool, tmp_path, case)
    d = s["diag"]
    assert d["error0_pct"] > dc.AT_FLOOR * d["floor_pct"], d  # the crack is visible
    c0 = d["candidates"][0]
    named = c0["effect"] == dc.ELEMENT and _in_span(c0["place"])
    honest = not _explains(d) and _in_span(d["explanation"])
    assert named or honest, (c0, d["explanation"])


def test_large_hub(tool, claims, tmp_path):
    """Named (hub mass and inertia at coupling C), claimed as the explanation,
    and at the floor after apply + fit."""
    case = CASES["claim_hub25_C"]
    (s,) = _rounds(tool, tmp_path, case)
    d = s["diag"]
    c0 = d["candidates"][0]
    assert _is(c0, dc.HUB, "coupling C"), c0
    assert c0["claim"] == "explains", c0
    fit = tool.json("fit", s["applied"], s["meas"], "--params", s["params"],
                    *dc.log_flag(s["params"]), "--noise", "10,1", "--starts", 1)
    assert fit["error_pct"] < dc.AT_FLOOR * fit["floor_pct"], fit


def test_bad_probe(tool, claims, tmp_path):
    """The channel named (a sensor's gain and phase at DB.y first, or the
    misfit concentrated on DB.y), no edit of the model claims to explain, and
    the model as it is is not called adequate. On the small grid the error
    of the model as it is, 5.39 %, is under the floor (5.77 %): only a test
    against the noise model can see the probe (one channel in eight 20 % low
    where the random noise is +-10 %)."""
    case = CASES["claim_probe_DBy"]
    (s,) = _rounds(tool, tmp_path, case)
    d = s["diag"]
    assert not d["adequacy"]["adequate"], d["adequacy"]
    c0 = d["candidates"][0]
    sensors = d.get("misfit", {}).get("sensors", [])
    assert _is(c0, dc.SENSOR, "DB.y") or (sensors and sensors[0]["response"] == "DB.y"), \
        (c0, sensors[:3])
    # with the sensor family: the gain at DB.y named, and it explains the data
    assert _is(c0, dc.SENSOR, "DB.y") and c0["claim"] == "explains", c0
    assert "sensor.DB.y.gain = 0.8" in c0["fitted"] or "sensor.DB.y.gain = 0.79" in c0["fitted"], c0
    edits = [c for c in _explains(d) if c["effect"] not in CHAIN]
    assert not edits, edits
    if c0["effect"] in CHAIN:  # the model untouched: --apply of a sensor refuses
        assert s["applied"] is None, s["applied"]


def test_swapped_probes(tool, claims, tmp_path):
    """C.B.x and C.B.y swapped on a rotor exactly as modelled: the swap named
    first, explaining the data, and --apply refuses it (the model untouched)."""
    case = CASES["claim_swap_CB"]
    (s,) = _rounds(tool, tmp_path, case)
    c0 = s["diag"]["candidates"][0]
    assert _is(c0, dc.SWAP, "C.B"), c0
    assert c0["claim"] == "explains" and c0["chain"], c0
    assert s["applied"] is None, s["applied"]


def test_two_effects_two_rounds(tool, claims, tmp_path):
    """The crack and the cross-coupling at B2: one found per round, either order."""
    case = CASES["claim_two"]
    steps = _rounds(tool, tmp_path, case, 2)
    assert len(steps) == 2, "round 1 applied nothing"
    firsts = [s["diag"]["candidates"][0] for s in steps]
    for c in firsts:
        assert c["significant"], c

    def which(c):
        if c["effect"] == dc.ELEMENT and _in_span(c["place"]):
            return "crack"
        if _is(c, dc.CROSS, "bearing B2"):
            return "cross"
        return None

    assert sorted(map(which, firsts), key=str) == ["crack", "cross"], firsts


def test_weak_effect(tool, claims, tmp_path):
    """Near the detection limit: found and significant, or not significant
    and nothing claims to explain."""
    case = CASES["claim_weak"]
    (s,) = _rounds(tool, tmp_path, case)
    d = s["diag"]
    c0 = d["candidates"][0]
    if c0["significant"]:
        assert _is(c0, dc.CROSS, "bearing B3"), c0
    else:
        assert not _explains(d), d["candidates"]


def test_null_silent(tool, claims, tmp_path):
    case = CASES["claim_null"]
    (s,) = _rounds(tool, tmp_path, case)
    d = s["diag"]
    assert not [c for c in d["candidates"] if c["significant"]], d["candidates"]
    assert d["adequacy"]["adequate"], d["adequacy"]
