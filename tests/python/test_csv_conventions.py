"""FRF CSV files as lab scripts write them (issue #35 item 3), read by rcbtool.

`rcbtool simulate` writes a canonical CSV ("DA.x/DB.y re", "... im"). numpy
and pandas then write the same FRFs in the conventions lab scripts use:

* pandas, "_re"/"_im" suffixes and stations as node numbers ("1.x/2.y_re"),
  read through --map NODE=STATION;
* pandas, "_mag"/"_phase_deg" (degrees, np.degrees(np.angle(H)));
* numpy.savetxt, "_re" columns first, then "_im" (pairs not adjacent);
* numpy.savetxt, "_amp"/"_phase [deg]" and node numbers.

`rcbtool convert` of each must give the values of the canonical file (re/im:
the same doubles, pandas and numpy write the shortest repr that round-trips;
mag/phase: within 4 ulp-ish, 1e-15 relative, the cost of cos/sin of degrees),
and `rcbtool compare` against the model the same measured values and the same
summary. Ambiguous or unreadable files are refused with exit 3 and a message
naming file:line: a channel given both as re/im and mag/phase, a bare
"_phase" (radians or degrees?), a node number the map does not name, numpy's
default "# " header, pandas' index column.
"""

import json
import subprocess

import numpy as np
import pytest

from conftest import EXAMPLES, _rcbtool_path

pd = pytest.importorskip("pandas")

MODEL = EXAMPLES / "paper_system.ini"
NODES = {"DA": 1, "DB": 2, "C.A": 3}
MAP = ",".join(f"{n}={s}" for s, n in NODES.items())
HEAD = "# kind = receptance\n# rpm = 3000\n"


@pytest.fixture(scope="module")
def exe():
    return _rcbtool_path()


def run(exe, *args, code=0):
    res = subprocess.run([exe, *map(str, args)], capture_output=True, text=True, timeout=300)
    assert res.returncode == code, f"{args}: exit {res.returncode}\n{res.stderr}"
    return res


def read(path):
    """(freq, {channel: complex array}) of a canonical CSV (re/im columns)."""
    df = pd.read_csv(path, comment="#")
    names = [c[:-3] for c in df.columns[1::2]]
    assert all(c.endswith(" re") for c in df.columns[1::2])
    return df.iloc[:, 0].to_numpy(), {
        n: df.iloc[:, 1 + 2 * k].to_numpy() + 1j * df.iloc[:, 2 + 2 * k].to_numpy()
        for k, n in enumerate(names)
    }


def numeric(ch):
    """'DA.x/C.A.y' -> '1.x/3.y' (stations as the lab's node numbers)."""
    out = []
    for part in ch.split("/"):
        st, d = part.rsplit(".", 1)
        out.append(f"{NODES[st]}.{d}")
    return "/".join(out)


@pytest.fixture(scope="module")
def canon(exe, tmp_path_factory):
    d = tmp_path_factory.mktemp("conv")
    path = d / "canon.csv"
    run(exe, "simulate", MODEL, "--frf", "--out", "DA.x,DB.y,C.A.x", "--in", "DA.x,DB.y",
        "--fmin", 5, "--fmax", 200, "--points", 41, "--rpm", 3000, "--noise", "10,1",
        "-o", path)  # noise: a comparison whose summary is not all zeros
    f, h = read(path)
    assert len(h) == 6 and len(f) == 41
    return d, path, f, h


def write(path, text_or_df, header=HEAD):
    with open(path, "w") as fh:
        fh.write(header)
        if isinstance(text_or_df, str):
            fh.write(text_or_df)
        else:
            text_or_df.to_csv(fh, index=False)


def pandas_re_im(f, h):
    cols = {"freq_hz": f}
    for ch, v in h.items():
        cols[numeric(ch) + "_re"] = v.real
        cols[numeric(ch) + "_im"] = v.imag
    return pd.DataFrame(cols)


def pandas_mag_phase(f, h):
    cols = {"freq_hz": f}
    for ch, v in h.items():
        cols[ch + "_mag"] = np.abs(v)
        cols[ch + "_phase_deg"] = np.degrees(np.angle(v))
    return pd.DataFrame(cols)


def numpy_split(f, h):
    """savetxt: every _re column, then every _im column (not adjacent)."""
    names = list(h)
    data = np.column_stack([f] + [h[n].real for n in names] + [h[n].imag for n in names])
    header = ",".join(["freq_hz"] + [n + "_re" for n in names] + [n + "_im" for n in names])
    from io import StringIO

    buf = StringIO()
    np.savetxt(buf, data, delimiter=",", header=header, comments="", fmt="%.17g")
    return buf.getvalue()


def numpy_amp_phase(f, h):
    names = list(h)
    cols, head = [f], ["freq_hz"]
    for n in names:
        cols += [np.abs(h[n]), np.degrees(np.angle(h[n]))]
        head += [numeric(n) + "_amp", numeric(n) + "_phase [deg]"]
    from io import StringIO

    buf = StringIO()
    np.savetxt(buf, np.column_stack(cols), delimiter=",", header=",".join(head), comments="",
               fmt="%.17g")
    return buf.getvalue()


CONVENTIONS = {  # name: (writer, exact re/im, needs --map)
    "pandas_re_im_nodes": (pandas_re_im, True, True),
    "pandas_mag_phase_deg": (pandas_mag_phase, False, False),
    "numpy_re_then_im": (numpy_split, True, False),
    "numpy_amp_phase_nodes": (numpy_amp_phase, False, True),
}


@pytest.mark.parametrize("name", list(CONVENTIONS))
def test_convention_reads_as_canonical(exe, canon, name):
    d, cpath, f, h = canon
    writer, exact, needs_map = CONVENTIONS[name]
    src, out = d / f"{name}.csv", d / f"{name}_out.csv"
    write(src, writer(f, h))
    mapping = ["--map", MAP] if needs_map else []
    if needs_map:  # without the map: refused, naming the node and the option
        res = run(exe, "convert", src, out, code=3)
        assert f"{name}.csv:3: column 2" in res.stderr and "--map 1=STATION" in res.stderr
    run(exe, "convert", src, out, *mapping)
    f2, h2 = read(out)
    assert np.array_equal(f2, f)
    assert list(h2) == list(h)  # the same channels, in the same order
    for ch in h:
        if exact:
            assert np.array_equal(h2[ch], h[ch]), ch
        else:
            np.testing.assert_allclose(h2[ch], h[ch], rtol=1e-15, atol=0, err_msg=ch)

    # rcbtool compare: the same measured values and the same summary
    def cmp(path, *extra):
        return json.loads(run(exe, "compare", MODEL, path, "--json", *extra).stdout)

    a, b = cmp(cpath), cmp(src, *mapping)
    assert len(a["channels"]) == len(b["channels"]) == 6
    for ca, cb in zip(a["channels"], b["channels"]):
        assert (ca["response"], ca["reference"]) == (cb["response"], cb["reference"])
        ma = np.array(ca["meas_re"]) + 1j * np.array(ca["meas_im"])
        mb = np.array(cb["meas_re"]) + 1j * np.array(cb["meas_im"])
        if exact:
            assert np.array_equal(ma, mb)
        else:
            np.testing.assert_allclose(mb, ma, rtol=1e-15, atol=0)
    if exact:
        assert a["summary"] == b["summary"]
    else:
        assert b["summary"]["error_pct"] == pytest.approx(a["summary"]["error_pct"], abs=1e-9)


REFUSED = {
    # a channel given both ways: which pair to read is ambiguous
    "both_pairs": ("freq_hz,DA.x/DA.x_re,DA.x/DA.x_im,DA.x/DA.x_mag,DA.x/DA.x_phase_deg\n"
                   "10,1,2,3,4\n", "both_pairs.csv:3: channel DA.x/DA.x is given both as re/im "
                   "and as mag/phase (columns 2 and 4): ambiguous"),
    # np.angle gives radians: a bare _phase is not read as degrees
    "bare_phase": ("freq_hz,DA.x/DA.x_mag,DA.x/DA.x_phase\n10,1,0.5\n",
                   "bare_phase.csv:3: column 3 'DA.x/DA.x_phase': a phase without the unit "
                   "degrees"),
    "unmapped_node": ("freq_hz,1.x/9.y_re,1.x/9.y_im\n10,1,2\n",
                      "station '9' is a number, not a model station, and the node map has no "
                      "entry for it"),
    "numpy_default_header": ("# freq_hz,DA.x/DA.x_re,DA.x/DA.x_im\n10,1,2\n",
                             "numpy_default_header.csv:4: the line starts with a number"),
    "pandas_index": (",freq_hz,DA.x/DA.x_re,DA.x/DA.x_im\n0,10,1,2\n",
                     "pandas_index.csv:3: the first column has no name"),
}


@pytest.mark.parametrize("name", list(REFUSED))
def test_refused_with_message(exe, tmp_path, name):
    text, msg = REFUSED[name]
    src = tmp_path / f"{name}.csv"
    write(src, text)
    res = run(exe, "convert", src, tmp_path / "out.csv", "--map", MAP, code=3)
    assert msg in res.stderr, res.stderr
    assert not (tmp_path / "out.csv").exists()
