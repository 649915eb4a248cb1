"""Gets the case study's data (docs/case_study.md): downloads the ARTS-Lab
cantilever test's file from GitHub, checks its SHA-256, and writes signals.csv
from it with make_signals.py. Neither file is part of librcb (the data are
CC BY-SA 4.0: source, licence and citation in README.md beside this script).

Where: $RCB_DATA_DIR/arts_cantilever/ (default ~/.cache/librcb/arts_cantilever/),
outside the source tree; docs/case_study.md and tests/python/test_case_study.py
read signals.csv there.

  python3 examples/case_study/get_data.py              download (2.5 MB), check, cut
  python3 examples/case_study/get_data.py --from FILE  use a copy of the .lvm you have
                                                       (e.g. from a git clone), checked

A file already in place with the right SHA-256 is not downloaded again.
Standard library only. Exit 0 done, 1 download failed or wrong file.
"""
import hashlib
import os
import shutil
import subprocess
import sys
import urllib.error
import urllib.request
from pathlib import Path

REPO = "PujaChowdhury/Dataset-4-Univariate-signal-with-non-stationarity"
COMMIT = "06a0d36fb448ca58ed0ce365d2464b442fa3638e"
PATH = "data/data_I/test_1/data_set_1_downsampled_by_16.lvm"
URL = f"https://raw.githubusercontent.com/{REPO}/{COMMIT}/{PATH}"
SHA256 = "8c27a9a81e362773195c895709e9ca9a63477862b48cdb46b87e2e53e8091b66"
SIZE = 2488460                                    # bytes


def data_dir():
    base = os.environ.get("RCB_DATA_DIR") or os.path.join(Path.home(), ".cache", "librcb")
    return Path(base) / "arts_cantilever"


def sha256(path):
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def fail(msg):
    print(f"get_data.py: {msg}", file=sys.stderr)
    sys.exit(1)


def main(argv):
    if len(argv) not in (1, 3) or (len(argv) == 3 and argv[1] != "--from"):
        print(__doc__.split("\n\n")[2], file=sys.stderr)
        sys.exit(2)
    d = data_dir()
    d.mkdir(parents=True, exist_ok=True)
    lvm = d / Path(PATH).name
    tmp = lvm.with_name(lvm.name + ".part")
    if lvm.exists() and sha256(lvm) == SHA256:
        print(f"{lvm}: present, SHA-256 checked")
    else:
        if len(argv) == 3:
            print(f"copying {argv[2]}")
            try:
                shutil.copyfile(argv[2], tmp)
            except OSError as e:
                fail(f"cannot copy {argv[2]}: {e.strerror}")
        else:
            print(f"downloading {URL} ({SIZE} bytes)")
            try:
                with urllib.request.urlopen(URL, timeout=60) as r, open(tmp, "wb") as f:
                    shutil.copyfileobj(r, f)
            except (urllib.error.URLError, OSError) as e:
                tmp.unlink(missing_ok=True)
                fail(f"could not download {URL}: {getattr(e, 'reason', e)}\n"
                     f"  no network? get the file another way (git clone "
                     f"https://github.com/{REPO}, file {PATH} at commit {COMMIT})\n"
                     f"  and run: python3 {sys.argv[0]} --from THAT_FILE")
        got = sha256(tmp)
        if got != SHA256:
            tmp.unlink()
            fail(f"{argv[2] if len(argv) == 3 else URL}: SHA-256 {got}, expected {SHA256} "
                 f"(not the file of commit {COMMIT[:10]}): nothing written")
        os.replace(tmp, lvm)
        print(f"{lvm}: SHA-256 checked")
    make = Path(__file__).resolve().with_name("make_signals.py")
    subprocess.run([sys.executable, str(make), str(lvm), str(d / "signals.csv")], check=True)


if __name__ == "__main__":
    main(sys.argv)
