"""librcb Python package: model responses exported as UFF dataset 58 through
the library's writer, read back by pyuff (an independent reader), values equal."""

import math

import numpy as np
import pytest

from pkg_helpers import paper, rcb  # noqa: F401  (fixtures)

pyuff = pytest.importorskip("pyuff")


def _records(path):
    uff = pyuff.UFF(str(path))
    return [r for r in uff.read_sets() if r.get("type") == 58]


@pytest.mark.parametrize("binary", [False, True], ids=["ascii", "binary58b"])
def test_frf_export_read_by_pyuff(rcb, paper, tmp_path, binary):
    f = np.linspace(0, 500, 126)
    outs, ins = ["C.A.x", "C.B.y", "DB.x"], ["DA.x", "DA.y"]
    path = tmp_path / "frf.uff"
    mp = rcb.export_uff(path, paper, outs, ins, f, rpm=10000, kind="inertance",
                        binary=binary, uff_map={10: "C.A", 11: "C.B", 4: "DA"})
    node_of = {v: k for k, v in mp.items()}
    H = rcb.frf(paper, outs, ins, f, rpm=10000, kind="inertance")
    recs = _records(path)
    assert len(recs) == len(outs) * len(ins)
    dirs = {"x": 1, "y": 2}
    seen = 0
    for o, out in enumerate(outs):
        st, d = out.rsplit(".", 1)
        for i, inp in enumerate(ins):
            rst, rd = inp.rsplit(".", 1)
            r = next(r for r in recs if r["rsp_node"] == node_of[st] and
                     abs(r["rsp_dir"]) == dirs[d] and r["ref_node"] == node_of[rst] and
                     abs(r["ref_dir"]) == dirs[rd])
            sign = np.sign(r["rsp_dir"]) * np.sign(r["ref_dir"])
            np.testing.assert_allclose(r["x"], f, rtol=1e-12, atol=1e-12)
            np.testing.assert_allclose(sign * r["data"], H[:, o, i], rtol=1e-12)
            assert r["func_type"] == 4  # frequency response function
            seen += 1
    assert seen == 6


def test_unbalance_export_read_by_pyuff(rcb, paper, tmp_path):
    rpm = np.linspace(1000, 15000, 29)
    path = tmp_path / "unb.uff"
    mp = rcb.export_uff(path, paper, ["DA.x", "DB.y"], rpm=rpm)
    Q = rcb.unbalance(paper, ["DA.x", "DB.y"], rpm)
    recs = _records(path)
    assert len(recs) == 2
    node_of = {v: k for k, v in mp.items()}
    for c, (st, d) in enumerate((("DA", 1), ("DB", 2))):
        r = next(r for r in recs if r["rsp_node"] == node_of[st] and abs(r["rsp_dir"]) == d)
        # abscissa in rpm in the file (type 19): this grid of whole rpm is exact
        assert r["abscissa_spec_data_type"] == 19
        np.testing.assert_allclose(r["x"], rpm, rtol=1e-14)
        np.testing.assert_allclose(np.sign(r["rsp_dir"]) * r["data"], Q[:, c], rtol=1e-12)
    assert all(math.isfinite(abs(v)) for v in Q.ravel())
