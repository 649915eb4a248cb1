#!/usr/bin/env python3
"""Run every command the docs show (issue #17): the fenced ```sh blocks of
README.md and docs/*.md, as written, in a scratch directory that looks like a
fresh clone after `./scripts/dev.sh demo` (the repository's files linked, and
`build` the build tree under test).

The blocks of one page run in order in one bash session (`set -e`), so a page
may build on its earlier blocks; a docs/ page starts with the PATH line of the
README (the README says how to put rcbtool on the PATH, and so do these runs).

A block can be marked on the line before its fence:
  <!-- doc-test: skip REASON -->   never run here (say why: installs, root, hosts,
                                   dev.sh commands that rebuild the tree...)
  <!-- doc-test: venv -->          needs the Python venv: run with --venv DIR only
  <!-- doc-test: sundials -->      needs a build with SUNDIALS (RCB_WITH_SUNDIALS)
  <!-- doc-test: fft -->           needs an FFT backend (RCB_WITH_FFTW or RCB_WITH_KISSFFT)
  <!-- doc-test: matplotlib -->    draws with python3 + matplotlib (rcbtool compare
                                   --plot): run when the python3 on the PATH (the
                                   venv's with --venv) has it
  <!-- doc-test: slow REASON -->   minutes of computation: run with --slow only
  <!-- doc-test: data:NAME/FILE --> reads FILE of the external data set NAME (a
                                   measurement not in the repository): run when
                                   tools/data/get_data.py finds the set, checked
                                   ($RCB_DATA_DIR/NAME, ../shared/data/NAME beside
                                   the repository, ~/.cache/librcb/NAME) and it holds
                                   FILE; the page says how to get it
(several may be combined: <!-- doc-test: venv slow about 2 min -->).
Everything skipped is listed with its reason; a block that fails names its
page and line, with the tail of its output.

usage: doc_commands.py --source DIR --build DIR [--venv DIR] [--slow] [--list]
exit 0 pass, 1 a block failed, 2 usage
"""
import argparse
import functools
import importlib.util
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

FENCE = re.compile(r"^```(\S*)\s*$")
MARK = re.compile(r"^<!--\s*doc-test:\s*((?:(?:(?:skip|venv|sundials|fft|matplotlib|slow)\b|data:\S+)\s*)+)"
                  r"(.*?)\s*-->\s*$")
PATH_LINE = re.compile(r"^export PATH=.*$", re.M)


def blocks(path):
    """(line, lang, mark, reason, text) of every fenced block of a Markdown file."""
    out, lines = [], open(path, encoding="utf-8").read().split("\n")
    i = 0
    while i < len(lines):
        m = FENCE.match(lines[i])
        if not m:
            i += 1
            continue
        start, lang = i + 1, m.group(1)
        mark = MARK.match(lines[i - 1]) if i > 0 else None
        j = i + 1
        while j < len(lines) and not lines[j].startswith("```"):
            j += 1
        out.append((start, lang, set(mark.group(1).split()) if mark else set(),
                    mark.group(2) if mark else "", "\n".join(lines[i + 1:j])))
        i = j + 1
    return out


def scratch_clone(src, build, venv):
    """A directory with the repository's top-level entries linked (a fresh
    clone's view), build -> the build tree, .venv -> the venv when given."""
    d = tempfile.mkdtemp(prefix="rcb_doc_commands.")
    for name in os.listdir(src):
        if name in (".git", "build", ".venv", "out") or name.startswith("build-"):
            continue
        os.symlink(os.path.join(src, name), os.path.join(d, name))
    os.symlink(os.path.abspath(build), os.path.join(d, "build"))
    if venv:
        os.symlink(os.path.abspath(venv), os.path.join(d, ".venv"))
    return d


@functools.lru_cache(maxsize=None)
def data_missing(src, rel):
    """Why the block marked data:NAME/FILE cannot run ("" when it can): the set
    NAME as tools/data/get_data.py finds it (every file's SHA-256 checked)."""
    spec = importlib.util.spec_from_file_location(
        "rcb_get_data", os.path.join(src, "tools", "data", "get_data.py"))
    getter = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(getter)
    name, _, fname = rel.partition("/")
    if name not in getter.DATASETS:
        return f"data:{rel}: no data set '{name}' in tools/data/get_data.py"
    found, _ = getter.locate(name)
    if found is None:
        return getter.how_to_get(name)
    if not os.path.isfile(os.path.join(found, fname)):
        return f"data:{rel}: the data set '{name}' at {found} has no file '{fname}'"
    return ""


def with_option(build, *options):
    """Is any of the CMake options on in the build tree's cache?"""
    try:
        cache = open(os.path.join(build, "CMakeCache.txt"), encoding="utf-8").read()
    except OSError:
        return False
    return any(re.search(rf"^{o}:BOOL=(ON|TRUE|1)$", cache, re.M) for o in options)


def has_matplotlib(venv):
    """Does the python3 these runs find (the venv's first, as in the runs) have matplotlib?"""
    path = os.environ.get("PATH", "")
    if venv:
        path = os.path.join(os.path.abspath(venv), "bin") + os.pathsep + path
    py = shutil.which("python3", path=path)
    return bool(py) and subprocess.run([py, "-c", "import matplotlib"],
                                       capture_output=True).returncode == 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--source", required=True)
    ap.add_argument("--build", required=True)
    ap.add_argument("--venv", help="the Python venv (runs the blocks marked venv)")
    ap.add_argument("--slow", action="store_true", help="run the blocks marked slow")
    ap.add_argument("--list", action="store_true", help="list the blocks, run none")
    ap.add_argument("--timeout", type=float, default=600, help="seconds per page")
    args = ap.parse_args()
    src = os.path.abspath(args.source)
    if args.venv and not os.path.isfile(os.path.join(args.venv, "bin", "python")):
        print(f"note: no venv at {args.venv}: its blocks are skipped")
        args.venv = None
    pages = ["README.md"] + sorted("docs/" + f for f in os.listdir(os.path.join(src, "docs"))
                                   if f.endswith(".md"))
    readme = open(os.path.join(src, "README.md"), encoding="utf-8").read()
    m = PATH_LINE.search(readme)
    if not m:
        print("FAIL: README.md has no 'export PATH=...' line saying where rcbtool is")
        return 1
    path_line = m.group(0)
    sundials = with_option(args.build, "RCB_WITH_SUNDIALS")
    fft = with_option(args.build, "RCB_WITH_FFTW", "RCB_WITH_KISSFFT")
    mpl = has_matplotlib(args.venv)
    ran, skipped, failed = 0, [], []
    for page in pages:
        todo = []
        for line, lang, mark, reason, text in blocks(os.path.join(src, page)):
            if lang != "sh":
                continue
            where = f"{page}:{line}"
            why = []
            if "skip" in mark:
                why.append("never here: " + (reason or "(no reason given)"))
            if "venv" in mark and not args.venv:
                why.append("needs the Python venv (--venv DIR)")
            if "sundials" in mark and not sundials:
                why.append("needs a build with SUNDIALS (RCB_WITH_SUNDIALS is off here)")
            if "fft" in mark and not fft:
                why.append("needs an FFT backend (RCB_WITH_FFTW and RCB_WITH_KISSFFT are off here)")
            if "matplotlib" in mark and not mpl:
                why.append("needs python3 with matplotlib on the PATH (--venv DIR, or "
                           "Debian's python3-matplotlib)")
            for rel in sorted(m[5:] for m in mark if m.startswith("data:")):
                missing = data_missing(src, rel)
                if missing.startswith("data:"):  # a mark naming no file of a known set
                    failed.append(where)
                    print(f"FAIL {where}: {missing}")
                if missing:
                    why.append(missing)
            if "slow" in mark and not args.slow:
                why.append("slow (--slow)" + (": " + reason if reason else ""))
            why = "; ".join(why)
            if why:
                skipped.append((where, why))
            else:
                todo.append((where, text))
        if not todo:
            continue
        if args.list:
            for where, text in todo:
                print(f"run  {where}")
            continue
        d = scratch_clone(src, args.build, args.venv)
        script = ["set -e", "cd " + sq(d)]
        if page != "README.md":
            script.append(path_line)
        if args.venv:
            script.append("export PATH=" + sq(os.path.join(os.path.abspath(args.venv), "bin"))
                          + ':"$PATH"')
        for where, text in todo:
            script += [f"echo '@@ {where}' >&2", text]
        env = dict(os.environ, OPENBLAS_NUM_THREADS="1")
        env.pop("RCB_PLOTS", None)
        t0 = time.monotonic()
        try:
            r = subprocess.run(["bash", "-c", "\n".join(script)], env=env, cwd=d,
                               capture_output=True, text=True, timeout=args.timeout)
            rc, err, out = r.returncode, r.stderr, r.stdout
        except subprocess.TimeoutExpired as e:
            rc, err, out = -1, (e.stderr or b"").decode() if isinstance(e.stderr, bytes) else (e.stderr or ""), ""
            err += f"\n(timed out after {args.timeout:g} s)"
        marks = re.findall(r"^@@ (\S+)$", err, re.M)
        if rc == 0:
            ran += len(todo)
            print(f"ok   {page}: {len(todo)} block(s), {time.monotonic() - t0:.1f} s")
        else:
            bad = marks[-1] if marks else page
            ran += len(marks) - 1 if marks else 0
            failed.append(bad)
            print(f"FAIL {bad} (exit {rc}, {time.monotonic() - t0:.1f} s); the tail of its output:")
            tail = (out[-1500:] + "\n--- stderr:\n" + err.split(f"@@ {bad}")[-1][-2500:])
            print("    " + tail.replace("\n", "\n    "))
        shutil.rmtree(d, ignore_errors=True)
    if args.list:
        for where, why in skipped:
            print(f"skip {where}: {why}")
        return 0
    print(f"\n{ran} block(s) ran, {len(failed)} failed, {len(skipped)} skipped:")
    for where, why in skipped:
        print(f"  skipped {where}: {why}")
    return 1 if failed else 0


def sq(s):
    return "'" + s.replace("'", "'\\''") + "'"


if __name__ == "__main__":
    sys.exit(main())
