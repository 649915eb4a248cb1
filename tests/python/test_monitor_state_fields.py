"""`rcbtool monitor --state` against state files no rcbtool writes (issue #34 item 7).

A series of 5 files made with `rcbtool simulate` (paper system, 4 inertances x 61
lines, eq. 19 noise 10/1 %): a state after 3 updates, then copies of it with one
field patched and every CRC made again (the library's state inside the file and
the file's own), so that only the field checks can refuse them:

* in the library's state: an infinite CUSUM, an infinite reference sum and
  weight, an update count of 2^64 - 1, an update count of 0 with 3 updates in
  the drift ring, a cut-short state (its length and CRC made again);
* in rcbtool's records: an update numbered out of order, a candidate with 1000
  parameters, 4 updates in the library's state for 3 records;

each refused with exit 3 and a message naming the file and the field, the
state's bytes left as they were; and the null case: the untouched copy takes
the 4th file and gives the one-shot run's log.
"""

import json
import math
import os
import struct
import subprocess
import zlib
from pathlib import Path

import pytest

from conftest import EXAMPLES, _rcbtool_path

MODEL = EXAMPLES / "paper_system.ini"
OPTS = ["--params", "coupling.C.kt,coupling.C.ct", "--noise", "10,1"]
ENV = dict(os.environ, OPENBLAS_NUM_THREADS="1")

# rcb_monitor.h's layout of the library's state (version 3)
L_LEN, L_UPDATES, L_CUS_UP, L_REF_SUM, L_REF_W = 8, 56, 72, 88, 96


def run(*args):
    return subprocess.run([str(a) for a in args], capture_output=True, text=True,
                          timeout=120, env=ENV)


class Container:
    """rcbtool's state file (cmd_monitor_state.c, io_state): the offsets of
    the library's state and of each record's fields."""

    def __init__(self, data):
        self.data = bytearray(data)
        self.pos = 16
        assert data[:16] == b"RCBTOOL-MONSTATE"
        assert self.u64() == 5  # the format version this test knows
        for _ in range(self.u64()):  # the settings' options
            self.string()
        for _ in range(self.u64()):  # the commissioning files' names
            self.string()
        self.u64()  # the set-up: type, points, speed, channels
        n = self.u64()
        self.pos += 8
        nch = self.u64()
        self.pos += 8 * n
        for _ in range(nch):
            self.string(), self.string()
            self.pos += 8 + 16 * n
        self.nblob_at = self.pos
        self.nblob = self.u64()
        self.blob = self.pos
        self.pos += self.nblob
        self.nrec_at = self.pos
        self.rec = []
        for _ in range(self.u64()):
            self.string()
            self.pos += 8  # the file's hash
            self.rec.append(self.pos)  # the result: update first
            self.result()
        assert self.pos == len(data) - 4

    def u64(self):
        v = struct.unpack_from("<Q", self.data, self.pos)[0]
        self.pos += 8
        return v

    def string(self):
        has, n = self.u64(), self.u64()
        self.pos += n if has else 0

    def result(self):
        self.pos += 8 * 10  # update .. cusum_alarm
        ntop = self.u64()
        self.pos += ntop * 8 * 16
        ntracked = self.u64()
        self.pos += ntracked * 8 * 24
        self.pos += 8 * 10  # the drift test .. apart_p

    def put(self, off, fmt, value):
        struct.pack_into(fmt, self.data, off, value)

    def lib(self, off, fmt, value):
        """A field of the library's state, its CRC made again."""
        self.put(self.blob + off, fmt, value)

    def seal(self):
        b = self.blob
        n = struct.unpack_from("<I", self.data, b + L_LEN)[0]
        self.put(b + n - 4, "<I", zlib.crc32(bytes(self.data[b:b + n - 4])))
        self.put(len(self.data) - 4, "<I", zlib.crc32(bytes(self.data[:-4])))
        return bytes(self.data)


@pytest.fixture(scope="module")
def series(tmp_path_factory):
    tool = _rcbtool_path()
    tmp = tmp_path_factory.mktemp("state_fields")
    files = []
    for k in range(5):
        f = tmp / f"m{k}.csv"
        res = run(tool, "simulate", MODEL, "--frf", "--out", "C.A.x,C.A.y,C.B.x,C.B.y", "--in",
                  "DA.x", "--fmin", "100", "--fmax", "400", "--points", "61", "--rpm", "10000",
                  "--kind", "inertance", "--noise", "10,1", "--seed", str(k + 1), "-o", f)
        assert res.returncode == 0, res.stderr
        files.append(f)
    state = tmp / "s.rcbmon"
    res = run(tool, "monitor", MODEL, *files[:4], *OPTS, "--state", state)
    assert res.returncode == 0, res.stderr
    oneshot = run(tool, "monitor", MODEL, *files, *OPTS, "--json")
    assert oneshot.returncode == 0, oneshot.stderr
    return tool, tmp, files, state.read_bytes(), json.loads(oneshot.stdout)


def refused(series, name, patch, words):
    tool, tmp, files, good, _ = series
    c = Container(good)
    assert len(c.rec) == 3 and c.nblob > 0
    patch(c)
    path = tmp / f"{name}.rcbmon"
    path.write_bytes(c.seal())
    before = path.read_bytes()
    res = run(tool, "monitor", MODEL, "--state", path, files[4])
    assert res.returncode == 3, f"{name}: exit {res.returncode}\n{res.stderr}"
    assert str(path) in res.stderr, res.stderr
    for w in words:
        assert w in res.stderr, f"{name}: '{w}' not in: {res.stderr}"
    assert "another" not in res.stderr, res.stderr
    assert path.read_bytes() == before  # nothing written
    return res.stderr


def test_infinite_cusum(series):
    refused(series, "cusum_inf", lambda c: c.lib(L_CUS_UP, "<d", math.inf),
            ["tracked parameter 1 (coupling.C.kt)", "CUSUM S+ = inf", "expected finite >= 0"])


def test_infinite_reference(series):
    def patch(c):
        c.lib(L_REF_SUM, "<d", math.inf)
        c.lib(L_REF_W, "<d", math.inf)
    refused(series, "ref_inf", patch, ["reference sum = inf", "expected finite"])


def test_update_count_wraps(series):
    refused(series, "updates_max", lambda c: c.lib(L_UPDATES, "<Q", 2**64 - 1),
            ["update count 18446744073709551615", "RCB_MONITOR_MAX_UPDATES"])


def test_update_count_zero_with_ring(series):
    refused(series, "updates_zero", lambda c: c.lib(L_UPDATES, "<Q", 0),
            ["drift window holds 3 updates in its sums, the monitor 0"])


def test_truncated_library_state(series):
    """Cut 8 bytes short, its length and CRC made for the shorter content:
    truncated, not 'another model' ('1 tracked parameters ...')."""
    def patch(c):
        b, n = c.blob, c.nblob
        del c.data[b + n - 8:b + n]
        c.put(b + L_LEN, "<I", n - 8)
        c.put(c.nblob_at, "<Q", n - 8)
    err = refused(series, "cut", patch, ["truncated"])
    assert "tracked parameters" not in err


def test_record_out_of_order(series):
    refused(series, "rec_order", lambda c: c.put(c.rec[1], "<Q", 7),
            ["update 2: numbered 7", "not a state rcbtool writes"])


def test_record_parameter_count(series):
    # the first ranked candidate's np: update .. cusum_alarm, ntop, index, effect
    refused(series, "rec_np", lambda c: c.put(c.rec[0] + 8 * 13, "<Q", 1000),
            ["update 1: candidate 1", "1000 parameters"])


def test_records_and_update_count(series):
    refused(series, "rec_count", lambda c: c.lib(L_UPDATES, "<Q", 4),
            ["3 updates' records, the monitor's state 4 updates"])


def test_untouched_copy_continues(series):
    """The null case: the same patching and sealing with no field changed
    loads, and the 4th update's log is the one-shot run's."""
    tool, tmp, files, good, oneshot = series
    path = tmp / "same.rcbmon"
    path.write_bytes(Container(good).seal())
    assert path.read_bytes() == good
    res = run(tool, "monitor", MODEL, "--state", path, files[4], "--json")
    assert res.returncode == 0, res.stderr
    assert json.loads(res.stdout)["updates"] == oneshot["updates"]


def _settings(data):
    """The settings' options of a state file and the offset where they end."""
    pos, out = 24, []  # after "RCBTOOL-MONSTATE" and the version
    n = struct.unpack_from("<Q", data, pos)[0]
    pos += 8
    for _ in range(n):
        has, ln = struct.unpack_from("<QQ", data, pos)
        pos += 16
        out.append(bytes(data[pos:pos + ln]).decode() if has else None)
        pos += ln if has else 0
    return out, pos


def _with_settings(data, opts):
    """The state file with its settings' options replaced, every CRC made again."""
    _, end = _settings(data)
    body = struct.pack("<Q", len(opts)) + b"".join(
        struct.pack("<QQ", 1, len(o.encode())) + o.encode() for o in opts)
    return Container(bytes(data[:24]) + body + bytes(data[end:])).seal()


def test_sensors_choice_kept(series):
    """The probes' gains are candidates by default (rcbtool monitor, issue #34)
    and a new state stores the choice; a state that names neither --sensors nor
    --no-sensors was written while the gains were asked for, and continues as
    the series without them (the one-shot --no-sensors run's log)."""
    tool, tmp, files, good, _ = series
    assert "--sensors" in _settings(good)[0]
    state = tmp / "nosens.rcbmon"
    res = run(tool, "monitor", MODEL, *files[:4], *OPTS, "--no-sensors", "--state", state)
    assert res.returncode == 0, res.stderr
    opts = _settings(state.read_bytes())[0]
    assert "--no-sensors" in opts and "--sensors" not in opts
    old = tmp / "old.rcbmon"
    old.write_bytes(_with_settings(state.read_bytes(), [o for o in opts if o != "--no-sensors"]))
    assert "--no-sensors" not in _settings(old.read_bytes())[0]
    oneshot = run(tool, "monitor", MODEL, *files, *OPTS, "--no-sensors", "--json")
    assert oneshot.returncode == 0, oneshot.stderr
    res = run(tool, "monitor", MODEL, "--state", old, files[4], "--json")
    assert res.returncode == 0, res.stderr
    assert json.loads(res.stdout)["updates"] == json.loads(oneshot.stdout)["updates"]
    both = run(tool, "monitor", MODEL, *files, *OPTS, "--sensors", "--no-sensors")
    assert both.returncode == 2 and "--no-sensors" in both.stderr, both.stderr
