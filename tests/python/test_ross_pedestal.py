"""Flexible supports against ROSS: bearings on pedestals (a point mass on a
support bearing to ground, linked with ``BearingElement(n=shaft node,
n_link=pedestal node)``), built by the ROSS bridge from the same INI keys
(pedestal_mass, pedestal_kxx, ...). FRFs of `rcbtool frf --rpm` against
ROSS's Rotor.transfer_matrix(speed, frequency), complex, on shaft stations
and on the pedestals themselves (channels "B2.ped.x")."""

import math
import warnings

import numpy as np

import ross_models as rm

RTOL = 1e-8  # relative, on each complex value

# The paper system with an anisotropic, damped pedestal under B2 and a light
# undamped one under B4, at 10000 rpm (gyroscopic and coupling terms on).
EXTRA = {
    "B2": "pedestal_mass = 10\npedestal_kxx = 3e7\npedestal_kyy = 5e7\n"
    "pedestal_cxx = 500\npedestal_cyy = 800\n",
    "B4": "pedestal_mass = 2.5\npedestal_kxx = 1e8\npedestal_kyy = 1e8\n",
}
RPM = 10000.0


def _model_text():
    text = rm.PAPER_SYSTEM_INI
    for b, extra in EXTRA.items():
        head = f"[bearing {b}]\n"
        assert head in text
        text = text.replace(head, head + extra)
    return text


def _ross_index(ross, spec):
    """ROSS global DOF of a channel; a pedestal's x, y are those ROSS gave
    its link node (after the shaft nodes, 3 DOFs each), read from the
    support bearing's dof_global_index."""
    st, _, direction = spec.rpartition(".")
    if st.endswith(".ped"):
        name, n = st[:-4], ross.pedestal_node[st[:-4]]
        sup = [b for b in ross.rotor.bearing_elements if b.tag == name + "_support"]
        return sup[0].dof_global_index[f"{direction}_{n}"]
    return ross.station_dof(spec)


def test_frf_pedestals_vs_ross(rcbtool, tmp_path):
    text = _model_text()
    path = tmp_path / "pedestals.ini"
    path.write_text(text)
    outs = ["DA.x", "DB.y", "B2.ped.x", "B2.ped.y", "B4.ped.x", "C.A.x", "B2.ry"]
    ins = ["DA.x", "B2.ped.y"]
    fmin, fmax, npts = 5.0, 800.0, 41
    res = rcbtool(
        "frf", path, "--out", ",".join(outs), "--in", ",".join(ins), "--fmin", fmin,
        "--fmax", fmax, "--points", npts, "--kind", "receptance", "--rpm", RPM,
    )
    speed = RPM * math.pi / 30.0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ross = rm.RossModel(rm.Model(text), speed=speed)
    assert set(ross.pedestal_node) == {"B2", "B4"}
    worst = (0.0, None)
    for i, f in enumerate(res["freq_hz"]):
        w = 2 * math.pi * f
        H = ross.rotor.transfer_matrix(speed=speed, frequency=w)
        for ch in res["channels"]:
            h = complex(ch["re"][i], ch["im"][i])
            ref = H[_ross_index(ross, ch["output"]), _ross_index(ross, ch["input"])]
            rel = abs(h - ref) / abs(ref)
            if rel > worst[0]:
                worst = (rel, (ch["output"], ch["input"], f, h, ref))
    print(f"pedestals vs ROSS: worst relative difference {worst[0]:.3e}")
    assert worst[0] <= RTOL, (
        f"worst relative difference {worst[0]:.3e} at {worst[1][0]}/{worst[1][1]}, "
        f"{worst[1][2]} Hz: ours {worst[1][3]}, ROSS {worst[1][4]}"
    )
    assert np.isfinite(worst[0])
