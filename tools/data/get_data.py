"""Gets librcb's external data sets: measured files that are not in the repository
(librcb does not redistribute them; each keeps its own licence). Each set is
downloaded from a public repository at a pinned commit, every file checked against
its SHA-256; the files made from them (a cut, a conversion) are made by the script
the table below names and checked the same way. The sets, their sources and
licences: tools/data/README.md.

  python3 tools/data/get_data.py NAME               download (or copy, see below), check, make
  python3 tools/data/get_data.py NAME --from PATH   use copies you have: a file, or a
                                                    directory holding the files (e.g. a
                                                    clone's data/), checked the same way
  python3 tools/data/get_data.py NAME --where       print the directory holding NAME
  python3 tools/data/get_data.py --list             the sets, and where each is found

A set is looked for, in this order, in $RCB_DATA_DIR/NAME, in ../shared/data/NAME
beside the repository (a copy placed once for every checkout on a machine, e.g. one
without network) and in ~/.cache/librcb/NAME; the first holding every file with the
right SHA-256 is used, and nothing is written. Otherwise the getter writes into
$RCB_DATA_DIR/NAME (default ~/.cache/librcb/NAME), taking each file from --from, else
from a checked copy in one of those places, else from GitHub; a file already there
with the right SHA-256 is kept. Every file is written under a temporary name,
checked, then renamed.

Standard library only. Exit 0 done, 1 a download failed or a file is not the
pinned one, 2 usage (or --where: the set is not found).
"""
import hashlib
import os
import shutil
import subprocess
import sys
import urllib.error
import urllib.parse
import urllib.request
from collections import namedtuple
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
GETTER = "python3 tools/data/get_data.py"

# A file of the source repository: its path there, SHA-256, size (bytes).
Src = namedtuple("Src", "path sha256 size")
# A file made here: its name, SHA-256, the script (from the repository root), its
# inputs (names of Src files), extra arguments after the output path.
Made = namedtuple("Made", "name sha256 script inputs extra")
Set = namedtuple("Set", "what licence repo commit files made")

DATASETS = {
    "arts_cantilever": Set(
        what="ARTS-Lab steel cantilever, shaker test 1 (docs/case_study.md, "
             "tests/python/test_case_study.py)",
        licence="CC BY-SA 4.0, https://creativecommons.org/licenses/by-sa/4.0/",
        repo="PujaChowdhury/Dataset-4-Univariate-signal-with-non-stationarity",
        commit="06a0d36fb448ca58ed0ce365d2464b442fa3638e",
        files=[Src("data/data_I/test_1/data_set_1_downsampled_by_16.lvm",
                   "8c27a9a81e362773195c895709e9ca9a63477862b48cdb46b87e2e53e8091b66", 2488460)],
        made=[Made("signals.csv",
                   "efb89a50e5eb1bceff3f9721b240266c52249b8b914c8ce8561da4ce99bc1d99",
                   "examples/case_study/make_signals.py",
                   ["data_set_1_downsampled_by_16.lvm"], [])]),
    "vendor_uff": Set(
        what="pyuff's test files: UFF exports of acquisition systems "
             "(tests/python/test_vendor_uff.py)",
        licence="MIT, https://github.com/ladisk/pyuff/blob/master/LICENSE",
        repo="ladisk/pyuff",
        commit="44a12caa81907e2303956dbbb4fbc7267fb77881",
        files=[
            Src("LICENSE",
                "785728aac6aafa01d646810606f368ae38be457956296fe0eab0e57687f7841b", 1116),
            Src("data/binary8byte.uff",
                "2f6f15f9513372f16c6039efd11f96889f494638b0fd9a3bb19c6a4dc4d0be5d", 2936),
            Src("data/time-history-not-all-columns-filled.uff",
                "4d7c3d571b2e628583ed89e59e183c3051dd3c636c25db4919c51b67d7c68a53", 1373),
            Src("data/non_ascii_header.uff",
                "0d1c7951c620c6f3ae19d36099dfa1b8c46c20981ab5b6ddf2302a0bf0f61d12", 1007),
            Src("data/sample_dataset58_psd.uff",
                "7e9d7d20e05022ce51270d91008575580f2964b6059ab338e814ee9bada7f948", 127098),
            Src("data/dataset_milestone_in_header.uff",
                "21cca2068c25dd6083550f2506ddf20c522e1ff2bd454194a2b8863e3ea58391", 1549),
            Src("data/MPSTD#Set001_2024_10_08_10_27_07.uff",
                "62523c43d1bf8845d8745e0adb0e61088df683125fd312adf1a13dc2e0481b33", 3560724),
        ],
        made=[Made("MPSTD_excerpt.uff",
                   "709d42d67b3f53a4561f60e29ac4f9fb000a859f33390f502020f060815cac93",
                   "tools/data/make_excerpt.py",
                   ["MPSTD#Set001_2024_10_08_10_27_07.uff"], ["2048"])]),
}


def names(ds):
    """The file names a set's directory holds."""
    return [Path(f.path).name for f in ds.files] + [m.name for m in ds.made]


def search_dirs(name):
    """Where a set is looked for, in order."""
    dirs = []
    if os.environ.get("RCB_DATA_DIR"):
        dirs.append(Path(os.environ["RCB_DATA_DIR"]) / name)
    dirs += [ROOT.parent / "shared" / "data" / name, Path.home() / ".cache" / "librcb" / name]
    return dirs


def write_dir(name):
    """Where the getter writes a set."""
    base = os.environ.get("RCB_DATA_DIR") or Path.home() / ".cache" / "librcb"
    return Path(base) / name


def sha256(path):
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def checked(path, want):
    return path.is_file() and sha256(path) == want


def problems(name, d):
    """What is missing or wrong in directory d for set `name` ([] when complete)."""
    ds = DATASETS[name]
    out = []
    for fname, want in zip(names(ds), [f.sha256 for f in ds.files] + [m.sha256 for m in ds.made]):
        p = d / fname
        if not p.is_file():
            out.append(f"{p}: absent")
        elif sha256(p) != want:
            out.append(f"{p}: SHA-256 {sha256(p)}, expected {want}")
    return out


def locate(name):
    """(the first directory holding the whole set checked, or None; the directories
    that hold part of it, with what is wrong there)."""
    partial = []
    for d in search_dirs(name):
        if not d.is_dir():
            continue
        bad = problems(name, d)
        if not bad:
            return d, partial
        if len(bad) < len(names(DATASETS[name])) or any("SHA-256" in b for b in bad):
            partial.append((d, bad))
    return None, partial


def how_to_get(name):
    """One line: where the set was looked for and the command that gets it."""
    ds = DATASETS[name]
    where = ", ".join(str(d) for d in search_dirs(name))
    return (f"the data set '{name}' ({ds.licence}; not in the repository) is not in {where}: "
            f"get it with `{GETTER} {name}` (without a network: `--from` a clone of "
            f"https://github.com/{ds.repo} at {ds.commit[:10]}; tools/data/README.md)")


def fail(msg):
    print(f"get_data.py: {msg}", file=sys.stderr)
    sys.exit(1)


def candidates(ds, f, src):
    """Where --from PATH may hold source file f: in a directory, under its name or
    its path in the source repository (from the clone's root, or from the folder
    beside it, e.g. data/ for a LICENSE at the root); a file, for a file of that
    name or when the set has only one."""
    if src is None:
        return []
    src, base = Path(src), Path(f.path).name
    if src.is_dir():
        return [src / base, src / f.path, src.parent / f.path]
    return [src] if src.name == base or len(ds.files) == 1 else []


def fetch(name, f, dest, src):
    """Puts source file f of set `name` at dest, checked: from --from, else a checked
    copy in the places searched, else GitHub."""
    ds = DATASETS[name]
    tmp = dest.with_name(dest.name + ".part")
    given = [p for p in candidates(ds, f, src) if p.is_file()]
    copies = [d / dest.name for d in search_dirs(name) if d != dest.parent]
    if given:
        print(f"copying {given[0]}")
        origin = str(given[0])
        try:
            shutil.copyfile(given[0], tmp)
        except OSError as e:
            fail(f"cannot copy {given[0]}: {e.strerror}")
    elif any(checked(p, f.sha256) for p in copies):
        origin = str(next(p for p in copies if checked(p, f.sha256)))
        print(f"copying {origin}")
        shutil.copyfile(origin, tmp)
    else:
        url = (f"https://raw.githubusercontent.com/{ds.repo}/{ds.commit}/"
               + urllib.parse.quote(f.path))
        origin = url
        print(f"downloading {url} ({f.size} bytes)")
        try:
            with urllib.request.urlopen(url, timeout=60) as r, open(tmp, "wb") as out:
                shutil.copyfileobj(r, out)
        except (urllib.error.URLError, OSError) as e:
            tmp.unlink(missing_ok=True)
            fail(f"could not download {url}: {getattr(e, 'reason', e)}\n"
                 f"  no network? get the file another way (git clone "
                 f"https://github.com/{ds.repo}, file {f.path} at commit {ds.commit})\n"
                 f"  and run: {GETTER} {name} --from THAT_FILE_OR_ITS_DIRECTORY")
    got = sha256(tmp)
    if got != f.sha256:
        tmp.unlink()
        fail(f"{origin}: SHA-256 {got}, expected {f.sha256} (not {f.path} of commit "
             f"{ds.commit[:10]}): nothing written")
    os.replace(tmp, dest)
    print(f"{dest}: SHA-256 checked")


def make(m, d):
    """Makes file m in directory d with its script, checked."""
    out = d / m.name
    tmp = out.with_name(out.name + ".part")
    args = [str(d / i) for i in m.inputs] + [str(tmp)] + m.extra
    subprocess.run([sys.executable, str(ROOT / m.script), *args], check=True)
    got = sha256(tmp)
    if got != m.sha256:
        tmp.unlink()
        fail(f"{m.script} made {m.name} with SHA-256 {got}, expected {m.sha256}: "
             "nothing written (a changed script, or a Python that formats numbers otherwise)")
    os.replace(tmp, out)
    print(f"{out}: made by {m.script}, SHA-256 checked")


def get(name, src):
    ds = DATASETS[name]
    found, _ = locate(name)
    if found is not None:
        print(f"{found}: present, SHA-256 of {len(names(ds))} files checked")
        return found
    d = write_dir(name)
    d.mkdir(parents=True, exist_ok=True)
    if src is not None and not Path(src).exists():
        fail(f"--from {src}: no such file or directory")
    for f in ds.files:
        dest = d / Path(f.path).name
        if checked(dest, f.sha256):
            print(f"{dest}: present, SHA-256 checked")
        else:
            fetch(name, f, dest, src)
    for m in ds.made:
        if checked(d / m.name, m.sha256):
            print(f"{d / m.name}: present, SHA-256 checked")
        else:
            make(m, d)
    return d


def usage():
    print(__doc__.split("\n\n")[1], file=sys.stderr)
    sys.exit(2)


def main(argv):
    args = argv[1:]
    if args == ["--list"]:
        for name, ds in DATASETS.items():
            found, _ = locate(name)
            print(f"{name}: {ds.what}; {ds.licence}; "
                  + (f"present in {found}" if found else "absent (" + how_to_get(name) + ")"))
        return
    if not args or args[0] not in DATASETS:
        if args and not args[0].startswith("-"):
            print(f"get_data.py: no data set '{args[0]}' (known: {', '.join(DATASETS)})",
                  file=sys.stderr)
        usage()
    name, rest = args[0], args[1:]
    if rest == ["--where"]:
        found, partial = locate(name)
        if found is None:
            for d, bad in partial:
                print(f"get_data.py: {d} holds part of it: {'; '.join(bad)}", file=sys.stderr)
            print(f"get_data.py: {how_to_get(name)}", file=sys.stderr)
            sys.exit(2)
        print(found)
    elif not rest or (len(rest) == 2 and rest[0] == "--from"):
        get(name, rest[1] if rest else None)
    else:
        usage()


if __name__ == "__main__":
    main(sys.argv)
