"""Issue #33 item 4: neighbouring shaft elements told apart. A loss of bending
stiffness of one element scores much as its neighbours do, and of the elements
only the best scored is refitted, so it could be named one element off at a
far larger size: ROSS's shaft B element 8 at 0.6 on the 8 x 151 grid (one
drive at DA) was found as element 7 at 0.787, "explains", error 5.95 % against
the floor 5.77 % (seed 1; 5.99 and 5.62 % on seeds 2 and 3). When the leading
candidate sits at a node or an element where the equivalent loads place the
misfit, or next to it, the candidates of its kind at the neighbouring places
and in the placement's span are now refitted too (src/diagnose/neighbours.c),
and the data choose by the one rule.

Asserted: the element of the truth is named first, or, if the data cannot
separate it from a neighbour (BIC within 10), the words say so and name both;
never another element alone. On the users' grid (32 x 1101, drives at DA and
DB), where it was already named right, and on the 8 x 151 grid, where it was
not. Null cases beside them: the truth is the model itself, and the first
candidate is not significant.

Truth by ROSS (diag_cases.ross_inertance, ross_models.element_stiffness_edit:
E and G of the element x 0.6, density and Poisson's ratio kept); noise eq. 19
as declared, drawn by numpy (diag_cases.calibration_noise). The model handed to
`rcbtool diagnose` is the stated one (kt, kr, ct fitted, --log, --noise 10,1).
"""

import json
import re
import subprocess
import warnings

import pytest

import diag_cases as dc
import ross_models as rm

warnings.simplefilter("ignore")

ELEMENT = 8      # shaft B element 8, z = 0.870-0.920 m
FACTOR = 0.6     # E and G
SEEDS = (1, 2)   # noise seeds of the element cases
NULL_SEEDS = (1, 2)
LARGE = dict(freq=dc.LARGE_FREQ_HZ, ins=dc.LARGE_INS)
SMALL = dict(freq=dc.FREQ_HZ, ins=(dc.IN,))


@pytest.fixture(scope="module")
def exe():
    from conftest import _rcbtool_path
    return _rcbtool_path()


def _diagnose(exe, tmp, H, grid, tag, seed):
    meas, model = tmp / f"{tag}_{seed}.uff", tmp / "model.ini"
    model.write_text(dc.model_ini())
    dc.write_uff(meas, dc.calibration_noise("eq19", H, seed), grid["freq"], grid["ins"])
    noise = f"{dc.NOISE[0]:g},{dc.NOISE[1]:g}"
    res = subprocess.run([exe, "diagnose", str(model), str(meas), "--params", dc.FIT_PARAMS,
                          "--log", "--noise", noise, "--top", "12", "--json"],
                         capture_output=True, text=True, timeout=900)
    assert res.returncode == 0, res.stderr
    return json.loads(res.stdout)


def _words(d, n=5):
    return [(c["effect"], c["place"], c["claim"], round(c.get("delta_bic") or 0.0, 1),
             c.get("fitted")) for c in d["candidates"][:n]]


def _element(c):
    """The element number of an element-stiffness candidate, else None."""
    m = re.match(r"shaft B element (\d+) ", c["place"])
    return int(m.group(1)) if c["effect"] == dc.ELEMENT and m else None


def _named_at_its_element(d):
    """The first candidate is element ELEMENT's stiffness, near FACTOR; or it
    is a neighbour and the words say the data cannot separate the two, naming
    element ELEMENT as the rival (BIC within 10)."""
    c0, c1 = d["candidates"][0], d["candidates"][1]
    assert c0["significant"], _words(d)
    if _element(c0) == ELEMENT:
        fitted = {k: float(v) for k, v in dc._FITTED.findall(c0["fitted"])}
        assert abs(fitted[f"shaft.B.e{ELEMENT}.stiffness"] / FACTOR - 1) < 0.03, c0["fitted"]
        assert c0["claim"] == "explains", (_words(d), d["explanation"])
        return "own"
    # a neighbour first: only as a rival the data cannot separate
    assert _element(c0) is not None and abs(_element(c0) - ELEMENT) == 1, _words(d)
    assert _element(c1) == ELEMENT, _words(d)
    assert abs(c0["delta_bic"] - c1["delta_bic"]) <= 10, _words(d)
    assert "cannot separate" in d["explanation"], d["explanation"]
    assert f"shaft B element {ELEMENT} " in d["explanation"], d["explanation"]
    return "rival"


@pytest.mark.parametrize("grid", ["large", "small"])
def test_element_named_at_its_own_element(exe, tmp_path, grid):
    g = LARGE if grid == "large" else SMALL
    H = dc.ross_inertance(dc.BASE_INI, rm.element_stiffness_edit("B", ELEMENT, FACTOR), **g)
    for seed in SEEDS:
        d = _diagnose(exe, tmp_path, H, g, f"e{ELEMENT}_{grid}", seed)
        how = _named_at_its_element(d)
        print(grid, "seed", seed, how, "floor", round(d["floor_pct"], 3),
              json.dumps(_words(d, 3)))
        # the neighbour that once took its place is refitted and ranked behind
        near = [c for c in d["candidates"] if _element(c) in (ELEMENT - 1, ELEMENT + 1)]
        assert any(c["refitted"] for c in near), _words(d, 12)


@pytest.mark.parametrize("grid", ["large", "small"])
def test_element_null(exe, tmp_path, grid):
    g = LARGE if grid == "large" else SMALL
    H = dc.ross_inertance(dc.BASE_INI, None, **g)
    for seed in NULL_SEEDS:
        d = _diagnose(exe, tmp_path, H, g, f"null_{grid}", seed)
        c0 = d["candidates"][0]
        print(grid, "null seed", seed, json.dumps(_words(d, 1)))
        assert not c0["significant"], (seed, _words(d))
