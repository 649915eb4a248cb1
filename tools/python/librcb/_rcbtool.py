"""The `rcbtool` console script of the installed package: runs the rcbtool
executable built into the package (librcb/bin/rcbtool, next to librcb.so)
with the same arguments, streams and exit code (os.execv: the process becomes
rcbtool). The same as `python -m librcb._rcbtool ARGS...`."""

import os
import sys
from pathlib import Path

EXE = Path(__file__).resolve().parent / "bin" / "rcbtool"


def main():
    if not EXE.is_file():
        sys.stderr.write(f"rcbtool: {EXE} is not in this installation of librcb (the package "
                         "was not built by its CMake: reinstall with `pip install "
                         "./tools/python` from a checkout)\n")
        return 2
    os.execv(str(EXE), [str(EXE), *sys.argv[1:]])
    return 2  # not reached


if __name__ == "__main__":
    sys.exit(main())
