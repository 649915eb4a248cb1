"""pytest fixtures for the ROSS cross-validation of librcb.

RCBTOOL (environment) is the path of the rcbtool executable to test:
  * unset            -> every test that needs rcbtool is skipped, with the reason;
  * set but missing  -> those tests fail (a wrong path must not pass silently).

Models are read from examples/<name>.ini when the file exists and also from
the INI strings in ross_models.py (written to a temporary directory), so the
comparison covers both the shipped examples and the variants described there.
"""

import functools
import importlib.util
import json
import os
import subprocess
import sys
import warnings
from pathlib import Path

import pytest

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import ross_models as rm  # noqa: E402

REPO = HERE.parent.parent
EXAMPLES = REPO / "examples"


def _rcbtool_path():
    path = os.environ.get("RCBTOOL")
    if path is None or path == "":
        pytest.skip("RCBTOOL is not set (path to the rcbtool executable to cross-validate)")
    p = Path(path)
    if not (p.is_file() and os.access(p, os.X_OK)):
        pytest.fail(f"RCBTOOL={path!r} is set but is not an executable file")
    return str(p)


@pytest.fixture(scope="session")
def rcbtool():
    """Callable: rcbtool(*args) -> parsed JSON of `rcbtool args... --json`."""
    exe = _rcbtool_path()

    def run(*args):
        cmd = [exe, *[str(a) for a in args], "--json"]
        res = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
        if res.returncode != 0:
            pytest.fail(
                f"{' '.join(cmd)} exited with {res.returncode}\nstderr: {res.stderr.strip()}"
            )
        try:
            return json.loads(res.stdout)
        except json.JSONDecodeError as e:
            pytest.fail(f"{' '.join(cmd)}: output is not JSON ({e}):\n{res.stdout[:2000]}")

    return run


def _free_free(text):
    """The same model with every [bearing ...] section removed."""
    out, skip = [], False
    for line in text.splitlines():
        s = line.strip()
        if s.startswith("["):
            skip = s[1:].lower().startswith("bearing")
        if not skip:
            out.append(line)
    return "\n".join(out) + "\n"


def _model_cases():
    cases = []
    for name, text in rm.MODELS.items():
        ex = EXAMPLES / f"{name}.ini"
        if ex.is_file():
            cases.append(pytest.param(("example", name, ex.read_text()), id=f"{name}-example"))
        cases.append(pytest.param(("inline", name, text), id=f"{name}-inline"))
    ex = EXAMPLES / "paper_freefree.ini"
    if ex.is_file():
        cases.append(
            pytest.param(("example", "paper_freefree", ex.read_text()), id="paper_freefree-example")
        )
    cases.append(
        pytest.param(
            ("inline", "paper_freefree", _free_free(rm.PAPER_SYSTEM_INI)),
            id="paper_freefree-inline",
        )
    )
    return cases


MODEL_CASES = _model_cases()

# Rotor speed of each comparison (rpm): high enough for the gyroscopic terms
# to matter, away from the criticals of the models.
SPEED_RPM = {
    "paper_system": 3000.0,
    "paper_freefree": 3000.0,
    "two_disk_aniso": 6000.0,
    "cross_coupled": 4500.0,
}


class Case:
    """One model: its INI file on disk, the parsed Python model, ROSS rotors."""

    def __init__(self, origin, name, text, path):
        self.origin = origin
        self.name = name
        self.text = text
        self.path = path
        self.model = rm.Model(text)
        self.rpm = SPEED_RPM[name]
        self._ross = {}
        self._H = {}
        # speed-dependent bearings: the ROSS rotor is rebuilt for each speed
        self.tabulated = any(
            ("speed_rpm" in d or "speed" in d) for _, _, d in self.model.bearings
        )

    @property
    def speed(self):
        """Rotor speed, rad/s."""
        return self.rpm * 3.141592653589793 / 30.0

    def ross(self, speed=None):
        """RossModel built for a rotor speed (rad/s; it selects tabulated bearings)."""
        s = self.speed if speed is None else speed
        key = round(s, 12) if self.tabulated else None
        if key not in self._ross:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                self._ross[key] = rm.RossModel(self.model, speed=s)
        return self._ross[key]

    def transfer(self, speed, w):
        """ROSS transfer_matrix(speed, frequency=w) (rad/s), cached."""
        key = (round(speed, 12), round(w, 12))
        if key not in self._H:
            self._H[key] = self.ross(speed).rotor.transfer_matrix(speed=speed, frequency=w)
        return self._H[key]

    def channels(self):
        """A few output channels and inputs naming stations of the model."""
        st = list(self.model.stations)
        disks = [d[0] for d in self.model.disks]
        outs = []
        for i, s in enumerate(st):
            outs.append(f"{s}.{('x', 'y', 'rx', 'ry')[i % 4]}")
        ins = [f"{disks[0]}.x"] if disks else [f"{st[0]}.x"]
        if len(disks) > 1:
            ins.append(f"{disks[1]}.y")
        cpl = [c[0] for c in self.model.couplings]
        if cpl:
            outs += [f"{cpl[0]}.{self.model.couplings[0][2][0]}.x", f"{cpl[0]}.ry"]
            ins.append(f"{cpl[0]}.{self.model.couplings[0][2][0]}.y")
        return outs, ins


@pytest.fixture(scope="session", params=MODEL_CASES)
def case(request, tmp_path_factory):
    origin, name, text = request.param
    if origin == "example":
        path = EXAMPLES / f"{name}.ini"
    else:
        path = tmp_path_factory.mktemp("models") / f"{name}.ini"
        path.write_text(text)
    return Case(origin, name, text, path)


# ---- external data sets: not in the repository -----------------------------
# tools/data/get_data.py gets them (a pinned commit, SHA-256 checked) and says
# where they are; a test that reads one is skipped, with the command, without it.

@functools.lru_cache(maxsize=None)
def _locate_data_set(name):
    spec = importlib.util.spec_from_file_location(
        "rcb_get_data", REPO / "tools" / "data" / "get_data.py")
    getter = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(getter)
    found, partial = getter.locate(name)
    return found, partial, getter.how_to_get(name)


@pytest.fixture(scope="session")
def data_set():
    """data_set(NAME) -> the directory holding the external data set NAME, every
    file's SHA-256 checked (searched in $RCB_DATA_DIR/NAME, ../shared/data/NAME
    beside the repository, ~/.cache/librcb/NAME); the test is skipped, with the
    reason and the command that gets it, when it is absent, and fails when a
    directory holds the set's files but not the pinned ones."""

    def get(name):
        found, partial, how = _locate_data_set(name)
        if found is None:
            wrong = [b for _, bad in partial for b in bad if "SHA-256" in b]
            if wrong:
                pytest.fail(f"data set '{name}': not the pinned files: {'; '.join(wrong)} "
                            f"(run `python3 tools/data/get_data.py {name}`)")
            pytest.skip(how)
        return found

    return get


# ---- measured differences, printed at the end of the run ------------------

MEASURED = {}


@pytest.fixture(scope="session")
def record():
    """record(case, quantity, value): keep the max relative difference measured."""

    def rec(c, quantity, value):
        key = (f"{c.name}-{c.origin}", quantity)
        MEASURED[key] = max(MEASURED.get(key, 0.0), float(value))

    return rec


def pytest_terminal_summary(terminalreporter):
    if not MEASURED:
        return
    tr = terminalreporter
    tr.section("ROSS cross-validation: max relative differences")
    for (model, quantity), v in sorted(MEASURED.items()):
        tr.write_line(f"{model:28s} {quantity:26s} {v:.3e}")


# ---- the slow files, left out of `./scripts/dev.sh quick` ------------------
# pytest -m "not slow" (dev.sh quick) leaves these out; every other run, and
# `dev.sh test`, runs them. They compute ROSS truths on the diagnosis grids and
# run whole rcbtool diagnoses, fits and time integrations: minutes in all
# (docs/reliability.md, "Stages of ./scripts/dev.sh test": figures and commands).
SLOW_FILES = {
    "test_diag_claims.py", "test_diag_ross.py", "test_monitor_ross.py",
    "test_signals_diagnose.py", "test_signals_paper.py", "test_signals_runup.py",
    "test_signals_transient.py", "test_signals_scipy.py", "test_ross_runup.py",
    "test_package_dask.py", "test_plots.py", "test_ross_bridge.py",
    "test_diag_place.py", "test_monitor_state.py", "test_monitor_baseline.py",
    "test_monitor_replicas.py", "test_diag_calibration.py", "test_diag_large_effects.py", "test_diag_shaft.py",
    "test_diag_neighbours.py",
}
# single tests of the other files that took 74-123 s each under a load of ~9
# on 2 cores (about a tenth of that quiet): ROSS rotors rebuilt per speed
# (synchronous FRF, unbalance of the speed-dependent bearings), damped modes.
SLOW_TESTS = {
    "test_ross_frf.py::test_frf_synchronous", "test_ross_modes.py::test_damped_modes",
    "test_ross_unbalance.py::test_unbalance_response",
    "test_diag_white_level.py::test_white_far_above_declared_with_a_probe",
    "test_diag_white_level.py::test_white_far_above_declared_nothing_missing",
}


def pytest_configure(config):
    config.addinivalue_line("markers", "slow: minutes of ROSS truth, diagnoses or time "
                            "integration; left out by `dev.sh quick` (-m 'not slow')")


def pytest_collection_modifyitems(config, items):
    for item in items:
        if (item.path.name in SLOW_FILES
                or f"{item.path.name}::{item.originalname}" in SLOW_TESTS):
            item.add_marker(pytest.mark.slow)
