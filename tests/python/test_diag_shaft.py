"""Issue #33 item 4: a section or material change along a whole shaft is named
as such (shaft.S.stiffness, the candidate "a change of section or material
along shaft S"), not as an added diametral inertia several times a disk's own.

Truth by ROSS on the users' grid (32 x 1101): the paper rig with E (and so G)
x 0.85 on every element of shaft B, each element given its own ROSS Material
through the bridge's element factors (density and Poisson's ratio kept, so the
shear factor is unchanged); noise drawn by numpy (diag_cases.calibration_noise,
eq. 19 as declared). The model handed to `rcbtool diagnose` is the stated one
(kt, kr, ct fitted, --log, --noise 10,1). A null case beside it: the truth is
the model itself (three noise seeds), and the first candidate is not
significant, nor is any shaft-wide candidate.
"""

import json
import re
import subprocess
import warnings

import pytest

import diag_cases as dc
import ross_models as rm

warnings.simplefilter("ignore")

FACTOR = 0.85  # E and G of all of shaft B
N_ELEMENTS_B = 10  # examples/paper_system.ini: segment = 0.50 0.017 0.0 10
SEED = 4242


def _shaft_b_section(model):
    """model_edit: E and G x FACTOR on every element of shaft B (librcb's
    shaft.B.stiffness = FACTOR)."""
    for k in range(1, N_ELEMENTS_B + 1):
        rm.element_stiffness_edit("B", k, FACTOR)(model)


@pytest.fixture(scope="module")
def exe():
    from conftest import _rcbtool_path
    return _rcbtool_path()


def _diagnose(exe, tmp, H, tag, seed=SEED, top=5):
    meas, model = tmp / f"{tag}.uff", tmp / "model.ini"
    model.write_text(dc.model_ini())
    dc.write_uff(meas, dc.calibration_noise("eq19", H, seed), dc.LARGE_FREQ_HZ, dc.LARGE_INS)
    noise = f"{dc.NOISE[0]:g},{dc.NOISE[1]:g}"
    res = subprocess.run([exe, "diagnose", str(model), str(meas), "--params", dc.FIT_PARAMS,
                          "--log", "--noise", noise, "--top", str(top), "--json"],
                         capture_output=True, text=True, timeout=900)
    assert res.returncode == 0, res.stderr
    return json.loads(res.stdout)


def _words(d):
    return [(c["effect"], c["place"], c["claim"], c.get("fitted"), c.get("error_pct"))
            for c in d["candidates"][:5]]


def test_shaft_section_named(exe, tmp_path):
    H = dc.ross_inertance(dc.BASE_INI, _shaft_b_section, freq=dc.LARGE_FREQ_HZ,
                          ins=dc.LARGE_INS)
    d = _diagnose(exe, tmp_path, H, "shaft_b")
    c0 = d["candidates"][0]
    print("shaft B x", FACTOR, "floor", d["floor_pct"], json.dumps(_words(d), indent=1), d["explanation"][:300])
    assert c0["effect"] == "shaft section or material (stiffness)", _words(d)
    assert c0["place"] == "shaft B", _words(d)
    assert c0["claim"] == "explains", (_words(d), d["explanation"])
    fitted = {k: float(v) for k, v in dc._FITTED.findall(c0["fitted"])}
    assert abs(fitted["shaft.B.stiffness"] / FACTOR - 1) < 0.03, c0["fitted"]
    assert c0["error_pct"] <= dc.AT_FLOOR * d["floor_pct"], (c0["error_pct"], d["floor_pct"])


SPAN = (3, 7)  # elements of shaft B whose E and G are x FACTOR: z = 0.62-0.87 m


def _shaft_b_span(model):
    """model_edit: E and G x FACTOR on elements 3-7 of shaft B (librcb's
    shaft.B.e3-7.stiffness = FACTOR)."""
    for k in range(SPAN[0], SPAN[1] + 1):
        rm.element_stiffness_edit("B", k, FACTOR)(model)


_SPAN_PLACE = re.compile(r"shaft B elements (\d+)-(\d+) ")


@pytest.mark.parametrize("seed", [SEED, 1])
def test_shaft_span_named(exe, tmp_path, seed):
    """A change along part of a shaft (issue #33 item 4): before, the
    whole-shaft stiffness was first, 0.871, "improves" (5.71 %, its residual
    structured: chi-square 53021 above the limit 35413, seed 4242; the
    baseline runs off, kr 221 -> 0.225). Now the span is searched for and
    named: a span holding elements 3-7 (or one the data cannot separate from
    such a span, the words then saying so), its factor within 3 % of 0.85, at
    the floor."""
    H = dc.ross_inertance(dc.BASE_INI, _shaft_b_span, freq=dc.LARGE_FREQ_HZ,
                          ins=dc.LARGE_INS)
    d = _diagnose(exe, tmp_path, H, f"span_{seed}", seed=seed, top=8)
    c0 = d["candidates"][0]
    print("shaft B e3-7 x", FACTOR, "seed", seed, "floor", d["floor_pct"],
          json.dumps(_words(d), indent=1), d["explanation"][:300])
    assert c0["effect"] == "shaft section or material (stiffness)", _words(d)
    where = _SPAN_PLACE.match(c0["place"])
    assert where, _words(d)
    a, b = int(where.group(1)), int(where.group(2))
    if (a, b) != SPAN:  # only as a rival the data cannot separate from the truth's span
        assert "cannot separate" in d["explanation"], (_words(d), d["explanation"])
        assert "elements 3-7" in d["explanation"], d["explanation"]
    assert c0["claim"] == "explains", (_words(d), d["explanation"])
    assert f"between z = 0.620 and 0.870 m (elements 3-7" in d["explanation"] or (a, b) != SPAN
    fitted = re.search(rf"shaft\.B\.e{a}-{b}\.stiffness = ([-+0-9.eE]+)", c0["fitted"])
    assert fitted and abs(float(fitted.group(1)) / FACTOR - 1) < 0.03, c0["fitted"]
    assert c0["error_pct"] <= dc.AT_FLOOR * d["floor_pct"], (c0["error_pct"], d["floor_pct"])


# Seeds of the null case. Seed SEED (4242) is a false alarm of the catalogue
# as it was before the shaft-wide candidates (the same on the parent commit's
# rcbtool, eq. 19 on --log): an added diametral inertia at node #5 said to
# explain (error 5.65 % against the floor 5.77 %), the calibration of item 2,
# not this file's concern; seeds 1-5 were clean on both.
NULL_SEEDS = (1, 2, 3)


def test_shaft_null(exe, tmp_path):
    H = dc.ross_inertance(dc.BASE_INI, None, freq=dc.LARGE_FREQ_HZ, ins=dc.LARGE_INS)
    for seed in NULL_SEEDS:
        d = _diagnose(exe, tmp_path, H, f"null_{seed}", seed=seed, top=40)
        c0 = d["candidates"][0]
        print("null seed", seed, "floor", d["floor_pct"], json.dumps(_words(d)[:1]))
        assert not c0["significant"], (seed, _words(d))
        assert not any(c["significant"] for c in d["candidates"]
                       if c["effect"].startswith("shaft section")), seed
        # nothing points to a shaft: no span searched for, none laid out
        assert not any(" elements " in c["place"] for c in d["candidates"]), seed
