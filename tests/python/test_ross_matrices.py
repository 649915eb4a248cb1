"""Assembled lateral matrices M, C, G, K of librcb against ROSS, entry by entry.

ROSS is 6 DOF/node [x, y, z, alpha, beta, theta]; its lateral DOFs
(0, 1, 3, 4 of each node) are decoupled from the axial/torsional ones
(checked below), so the lateral sub-block of ROSS's global matrices is the
matrix librcb assembles. DOFs are matched through the node table that
`rcbtool matrices` prints: (shaft, z) -> ROSS node along the shaft-element list.
"""

import numpy as np
import pytest

RTOL = 1e-6  # of the matrix's max abs entry; never loosen


@pytest.fixture(scope="module")
def mats(case, rcbtool):
    return rcbtool("matrices", case.path, "--rpm", case.rpm)


def _ross_full(case):
    r = case.ross().rotor
    s = case.speed
    return {"M": r.M(), "C": r.C(s), "G": r.G(), "K": r.K(s)}


def test_node_table_matches_ross(case, mats):
    rmod = case.ross()
    nodes = mats["nodes"]
    assert len(nodes) == len(rmod.node_keys), "node count differs from ROSS"
    ours, ross = rmod.lateral_map(nodes)
    assert mats["ndof"] == 4 * len(nodes), "a ROSS comparison needs 4 independent DOFs/node"
    assert sorted(ours.tolist()) == list(range(mats["ndof"])), "DOF indices not a permutation"
    # librcb numbers nodes shaft by shaft in INI order, along z, like ROSS's list
    assert [rmod.ross_node(n["shaft"], n["z"]) for n in nodes] == list(range(len(nodes)))


def test_ross_lateral_block_is_decoupled(case):
    """Lateral rows have no entry in axial/torsional columns (ROSS 2.3)."""
    rmod = case.ross()
    lat = rmod.lateral_dofs()
    other = np.setdiff1d(np.arange(rmod.rotor.ndof), lat)
    for name, a in _ross_full(case).items():
        assert np.all(a[np.ix_(lat, other)] == 0), name
        assert np.all(a[np.ix_(other, lat)] == 0), name


@pytest.mark.parametrize("which", ["M", "C", "G", "K"])
def test_matrix_entrywise(case, mats, which, record):
    rmod = case.ross()
    ours_idx, ross_idx = rmod.lateral_map(mats["nodes"])
    n = mats["ndof"]
    ours = np.array(mats[which], dtype=float)
    assert ours.shape == (n, n)
    full = _ross_full(case)[which]
    ref = np.zeros((n, n))
    ref[np.ix_(ours_idx, ours_idx)] = full[np.ix_(ross_idx, ross_idx)]
    scale = np.abs(ref).max()
    assert scale > 0
    diff = np.abs(ours - ref)
    rel = diff.max() / scale
    record(case, f"matrix {which}", rel)
    if rel > RTOL:
        i, j = np.unravel_index(np.argmax(diff), diff.shape)
        inv = {int(o): int(r) for o, r in zip(ours_idx, ross_idx)}
        bad = np.argwhere(diff > RTOL * scale)
        pytest.fail(
            f"{which}: max |ours - ROSS| / max|ROSS| = {rel:.3e} at our ({i},{j}) = ROSS "
            f"({inv[i]},{inv[j]}) [node {inv[i] // 6} dof {inv[i] % 6}, node {inv[j] // 6} "
            f"dof {inv[j] % 6}]: ours {ours[i, j]!r}, ROSS {ref[i, j]!r}; "
            f"{len(bad)} entries off, first: {bad[:8].tolist()}"
        )


def test_comparison_sees_shear_factor(case, mats):
    """Sensitivity: with ROSS's own (Cowper) shear factor instead of the INI
    one, K differs by far more than the tolerance, so the override is what
    makes the two agree (and a shear-term error in librcb would be caught)."""
    import warnings

    import ross_models as rm

    if all(s.kappa == 0 for s in case.model.shafts):
        pytest.skip("no shear in this model")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        own = rm.RossModel(case.model, speed=case.speed, override_shear=False)
    ours_idx, ross_idx = own.lateral_map(mats["nodes"])
    n = mats["ndof"]
    ref = np.zeros((n, n))
    ref[np.ix_(ours_idx, ours_idx)] = own.rotor.K(case.speed)[np.ix_(ross_idx, ross_idx)]
    rel = np.abs(np.array(mats["K"]) - ref).max() / np.abs(ref).max()
    assert rel > 100 * RTOL
    kappas = {round(el.kappa, 12) for el in case.ross().rotor.shaft_elements if hasattr(el, "phi") and el.phi}
    assert kappas <= {round(s.kappa, 12) for s in case.model.shafts}
