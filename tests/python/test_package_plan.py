"""librcb.plan, the Python face of rcb_plan (issue #23 item 6): which test
would tell two rival effects apart.

The paper system measured at DA.x per DA.x (200-400 Hz, 10000 rpm, the
layout of docs/diagnosis.md's example, written by `rcbtool simulate`):

* librcb.plan gives the same figures as `rcbtool plan --json` on the same
  layout (two front ends of one library call: their arguments, units and
  the candidates' order);
* its verdict is the one rule: separable exactly when the separating
  chi-square is above 10 (librcb.claim's rcb_evidence_separable threshold);
* B3 kxx against B4 kxx cannot be separated on DA.x alone (a principal angle
  of a few degrees), and the best channel to add is measured at B3.
"""

import json
import subprocess

import pytest

from conftest import _rcbtool_path
from pkg_helpers import PAPER, rcb  # noqa: F401  (the package, skipped without its library)


@pytest.fixture(scope="module")
def layout(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("plan")
    meas = tmp / "layout_da.csv"
    subprocess.run([str(_rcbtool_path()), "simulate", str(PAPER), "--frf",
                    "--out", "DA.x", "--in", "DA.x", "--fmin", "200", "--fmax", "400",
                    "--points", "201", "--rpm", "10000", "-o", str(meas)], check=True,
                   capture_output=True)
    return PAPER, meas


def test_plan_matches_the_cli_and_the_rule(rcb, layout):
    librcb = rcb
    model_path, meas_path = layout
    model = librcb.Model.from_ini(str(model_path))
    meas = librcb.read_meas(str(meas_path), model=model)
    p = librcb.plan(model, meas, ("bearing.B3.kxx", "bearing.B4.kxx"), noise=(10, 1))
    cli = json.loads(subprocess.run(
        [str(_rcbtool_path()), "plan", str(model_path), str(meas_path), "--between",
         "bearing.B3.kxx", "bearing.B4.kxx", "--noise", "10,1", "--top", "5", "--json"],
        check=True, capture_output=True, text=True).stdout)
    print(p["angle_deg"], p["chi2_sep"], p["candidates"][:2])
    assert p["angle_deg"] == pytest.approx(cli["angle_deg"], rel=1e-9)
    assert p["chi2_sep"] == pytest.approx(cli["chi2_sep"], rel=1e-9)
    assert p["separable"] == (p["chi2_sep"] > 10.0) == cli["separable"]
    assert not p["separable"] and 0 < p["angle_deg"] < 20
    assert [p["params"][0]["name"], p["params"][0]["side"]] == ["bearing.B3.kxx", "A"]
    for a, b in zip(p["candidates"][:5], cli["candidates"][:5]):
        assert (a["response"], a["reference"]) == (b["response"], b["reference"])
        assert a["gain"] == pytest.approx(b["gain"], rel=1e-9)
    best = p["candidates"][0]
    assert "B3" in best["response"] + best["reference"] and best["chi2_after"] > 10.0
