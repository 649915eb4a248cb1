"""Gets the case study's data (docs/case_study.md): the ARTS-Lab cantilever test's
file, downloaded from GitHub at a pinned commit and checked against its SHA-256,
and signals.csv made from it by make_signals.py (checked too). Neither file is
part of librcb (the data are CC BY-SA 4.0: source, licence and citation in
README.md beside this script). The same as `python3 tools/data/get_data.py
arts_cantilever`, which gets every external data set (tools/data/README.md).

Where: found in $RCB_DATA_DIR/arts_cantilever/, ../shared/data/arts_cantilever/
beside the repository or ~/.cache/librcb/arts_cantilever/, in that order; written
to $RCB_DATA_DIR/arts_cantilever/ (default ~/.cache/librcb/arts_cantilever/),
outside the source tree.

  python3 examples/case_study/get_data.py              download (2.5 MB), check, cut
  python3 examples/case_study/get_data.py --from FILE  use a copy of the .lvm you have
                                                       (e.g. from a git clone), checked
  python3 examples/case_study/get_data.py --where      print the directory holding it

Exit 0 done, 1 download failed or wrong file, 2 usage (or --where: not found).
"""
import importlib.util
import sys
from pathlib import Path

spec = importlib.util.spec_from_file_location(
    "get_data", Path(__file__).resolve().parents[2] / "tools" / "data" / "get_data.py")
getter = importlib.util.module_from_spec(spec)
spec.loader.exec_module(getter)

if __name__ == "__main__":
    getter.main([sys.argv[0], "arts_cantilever", *sys.argv[1:]])
