"""Shared pieces of the librcb Python package tests (tests/python/test_package_*.py).

The package is imported as installed (`pip install .`; the wheel stage of
scripts/dev.sh test runs these tests on the installed wheel); when it is not
installed, from tools/python in this checkout. The shared library comes from LIBRCB_PATH:
  * unset and not found by the package -> the tests are skipped, with the reason;
  * set but not loadable                -> the tests fail (a wrong path must not pass).
"""

import os
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
EXAMPLES = REPO / "examples"
PAPER = EXAMPLES / "paper_system.ini"
WALK = EXAMPLES / "walkthrough"


def import_librcb():
    try:
        import librcb
    except ImportError:
        sys.path.insert(0, str(REPO / "tools" / "python"))
        import librcb
    try:
        librcb.library_version()
    except librcb.LibraryNotFound as e:
        if os.environ.get("LIBRCB_PATH"):
            pytest.fail(f"LIBRCB_PATH is set but the library does not load: {e}")
        pytest.skip("LIBRCB_PATH is not set and librcb.so is not found (set it to the "
                    "shared library CMake built, e.g. build/src/librcb.so)")
    return librcb


@pytest.fixture(scope="session")
def rcb():
    """The librcb package, with its shared library loaded."""
    return import_librcb()


@pytest.fixture(scope="session")
def paper(rcb):
    """The paper's system (examples/paper_system.ini), loaded once."""
    return rcb.Model.from_ini(PAPER)
