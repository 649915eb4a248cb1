"""`rcbtool monitor --state` (issue #24): a series monitored one run at a time.

The series is monitor_cases.py's cross_B3 (ROSS 2.3, paper system at 10000 rpm,
8 inertances x 400 lines, eq. 19 noise 10/1 %; kxy = -kyx = 1.5e7 N/m at B3
from file 37; the first 41 files), made outside librcb. The options are test_monitor_ross's
(10 files averaged into the reference, reweighted, up to 8 re-linearisations,
alpha 0.01).

* restart in the middle: the series run as a state (files 0-35, then 36, 37
  and 38 one run each, the change among them, then 39-40) gives the same log,
  number for number (JSON with 17 digits), as the one-shot replay of the 60
  files, and the same alarm and naming at the change;
* the log rebuilt from the state alone (no new file) is that log too;
* refusals, each leaving the state's bytes as they were: the same content
  under another name, a setting given again, another baseline model, a
  damaged state (one byte changed: its CRC), a file that is not a state, and
  a batch with an unreadable measurement in its middle (nothing of the batch
  is kept).
"""

import json
import os
import shutil
import subprocess

import pytest

import monitor_cases as mc
from conftest import _rcbtool_path

pytest.importorskip("pyuff")

PARAMS = mc.FIT_PARAMS
OPTS = ["--params", PARAMS, "--noise", "10,1", "--commission", str(mc.COMMISSION),
        "--reweight", "--relinearise", "8", "--alpha", "0.01"]
ENV = dict(os.environ, OPENBLAS_NUM_THREADS="1")


def run(*args, ok=True):
    res = subprocess.run([str(a) for a in args], capture_output=True, text=True, timeout=600,
                         env=ENV)
    if ok:
        assert res.returncode == 0, f"{args}: exit {res.returncode}\n{res.stderr[-2000:]}"
    return res


@pytest.fixture(scope="module")
def case(tmp_path_factory):
    tool = _rcbtool_path()
    d, truth, model = mc.series("cross_B3")
    tmp = tmp_path_factory.mktemp("state")
    files = [d / f for f in truth["files"][:41]]
    # the files are copied so that the state's names are this test's own
    for f in files:
        shutil.copy(f, tmp / f.name)
    files = [tmp / f.name for f in files]
    oneshot = json.loads(run(tool, "monitor", model, *files, *OPTS, "--json").stdout)
    state = tmp / "s.rcbmon"
    run(tool, "monitor", model, *files[:36], *OPTS, "--state", state)
    for f in files[36:39]:
        run(tool, "monitor", model, "--state", state, f)
    log = tmp / "log.json"
    staged = json.loads(run(tool, "monitor", model, "--state", state, *files[39:], "--json",
                            "--log", log).stdout)
    return tool, model, files, truth, oneshot, state, staged, log, tmp


def test_restart_equals_replay(case):
    tool, model, files, truth, oneshot, state, staged, log, tmp = case
    assert len(staged["updates"]) == len(files) - mc.COMMISSION
    assert staged["updates"] == oneshot["updates"]
    assert staged == oneshot
    assert json.loads(log.read_text()) == oneshot
    # the change (file 37) was among the one-file runs: alarmed and named there
    first = next(u for u in staged["updates"] if u["alarm"] and
                 u["file"] >= truth["files"][truth["change_update"]])
    assert first["file"] == truth["files"][truth["change_update"]]
    assert (first["top"][0]["effect"], first["top"][0]["place"]) == (truth["effect"],
                                                                     truth["place"])


def test_log_rebuilt_from_state(case):
    tool, model, files, truth, oneshot, state, staged, log, tmp = case
    before = state.read_bytes()
    res = run(tool, "monitor", model, "--state", state, "--json")
    assert json.loads(res.stdout) == oneshot
    csv = tmp / "log.csv"
    run(tool, "monitor", model, "--state", state, "--log", csv)
    rows = [r for r in csv.read_text().splitlines() if r and not r.startswith("#")]
    assert len(rows) == 1 + len(oneshot["updates"])  # header + one row per update
    assert state.read_bytes() == before  # nothing new: the same state


def _refused(args, state, code, words):
    before = state.read_bytes()
    res = run(*args, ok=False)
    assert res.returncode == code, res.stderr
    for w in words:
        assert w in res.stderr, res.stderr
    assert state.read_bytes() == before
    # no temporary left (the commissioning image beside the state is no temporary)
    assert not [p for p in state.parent.iterdir()
                if p.name.startswith(state.name + ".") and p.name != state.name + ".image"]


def test_refusals(case):
    tool, model, files, truth, oneshot, state, staged, log, tmp = case
    again = tmp / "again.uff"
    shutil.copy(files[20], again)
    _refused([tool, "monitor", model, "--state", state, again], state, 3,
             ["content of update 11", "m0020.uff", "taken once"])
    _refused([tool, "monitor", model, "--state", state, "--alpha", "0.05", again], state, 2,
             ["--alpha cannot be given again"])
    other = tmp / "other.ini"
    assert "kt = 46.095e3" in model.read_text()
    other.write_text(model.read_text().replace("kt = 46.095e3", "kt = 46.1e3"))
    fresh = tmp / "fresh.uff"
    shutil.copy(files[-1], fresh)
    with open(fresh, "a") as fp:
        fp.write("\n")  # another content, the same measurement
    _refused([tool, "monitor", other, "--state", state, fresh], state, 3,
             ["another baseline model"])
    bad = tmp / "bad.rcbmon"
    b = bytearray(state.read_bytes())
    b[len(b) // 2] ^= 0x10
    bad.write_bytes(bytes(b))
    _refused([tool, "monitor", model, "--state", bad, fresh], bad, 3, ["CRC-32"])
    notstate = tmp / "hello.rcbmon"
    notstate.write_text("hello\n")
    _refused([tool, "monitor", model, "--state", notstate, fresh], notstate, 3,
             ["not a monitor state"])
    broken = tmp / "broken.uff"
    broken.write_text("hello\n")
    _refused([tool, "monitor", model, "--state", state, fresh, broken], state, 3, ["broken.uff"])
