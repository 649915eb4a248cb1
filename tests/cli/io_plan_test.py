#!/usr/bin/env python3
"""Every output of every rcbtool verb tried onto every input (issue #26).

The verbs and their options are read from `rcbtool help` and `rcbtool VERB
--help`, so a verb or an option added later is tried too. For each verb:

* each output (-o, every option whose value is a file: FILE, PATH, FILE.png,
  and convert's OUT) is pointed at each input (the positional files of the
  usage line, and --sd) spelled five ways: plain, ./, absolute, a symbolic
  link, a hard link;
* each pair of outputs is given one new path (the same spelling and ./);

and every run must exit 5 with "refusing" on stderr, leave every input's bytes
unchanged and leave no file behind (no temporary, no output). The plan is
checked when the command line is parsed, so no run does any work: the whole
test takes a few seconds.

usage: io_plan_test.py RCBTOOL EXAMPLES_DIR   (exit 0 pass, 1 fail)
"""
import os
import re
import shutil
import subprocess
import sys
import tempfile

# Options whose FILE/PATH value is read, not written: pointed at an input they
# are not refused. A new input option must be added here (the test fails
# until it is, since it would be expected to exit 5).
INPUT_OPTIONS = {"--sd"}
# Options naming a prefix of several files (compare --plot PREFIX): the files
# are PREFIX_*.json/png, covered by the case guard_output_is_input of cli_test.sh.
PREFIX_METAVARS = {"PREFIX"}
FILE_METAVAR = re.compile(r"^(FILE|PATH|[A-Z]+\.(png|csv|json|ini))$")


def run(exe, args, cwd):
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1")
    r = subprocess.run([exe, *args], cwd=cwd, capture_output=True, text=True, env=env,
                       timeout=60)
    return r.returncode, r.stderr


def verbs(exe):
    rc, _ = run(exe, ["help"], ".")
    out = subprocess.run([exe, "help"], capture_output=True, text=True).stdout
    names = re.findall(r"^  ([a-z]+) ", out, re.M)
    assert rc == 0 and len(names) >= 19, (rc, out)
    return names


def describe(exe, verb):
    """(positional inputs, positional outputs, output options, input options)."""
    text = subprocess.run([exe, verb, "--help"], capture_output=True, text=True).stdout
    usage = re.search(r"usage: rcbtool %s (.*)" % verb, text).group(1).split()
    pos_in, pos_out = [], []
    for word in usage:
        if word.startswith("[") or word.startswith("--"):
            break
        (pos_out if word == "OUT" else pos_in).append(word)
    outs, ins = ["-o"], []
    for name, metavar in re.findall(r"^\s+(--[a-z0-9-]+)[ =]([A-Za-z.|]+)", text, re.M):
        if metavar in PREFIX_METAVARS:
            continue
        if FILE_METAVAR.match(metavar) or metavar == "STATS.csv|DIR":
            (ins if name in INPUT_OPTIONS else outs).append(name)
    return pos_in, pos_out, sorted(set(outs)), sorted(set(ins))


def main():
    exe, examples = os.path.abspath(sys.argv[1]), sys.argv[2]
    failures, runs = [], 0
    work = tempfile.mkdtemp(prefix="rcbtool_ioplan.")
    try:
        for verb in verbs(exe):
            pos_in, pos_out, outs, ins = describe(exe, verb)
            d = os.path.join(work, verb)
            os.mkdir(d)
            inputs = []
            for k, word in enumerate(pos_in):
                name = "in%d.%s" % (k, "ini" if word.endswith(".ini") else "csv")
                shutil.copy(os.path.join(examples, "paper_system.ini"), os.path.join(d, name))
                inputs.append((name, None))
            for opt in ins:
                name = "sd%s.csv" % opt.strip("-")
                with open(os.path.join(d, name), "w") as f:
                    f.write("freq_hz,DA.x/DA.x sd\n1,1\n")
                inputs.append((name, opt))
            base = [p for p, o in inputs if o is None]
            inopts = [a for p, o in inputs if o is not None for a in (o, p)]
            original = {p: open(os.path.join(d, p), "rb").read() for p, _ in inputs}
            for p, _ in inputs:
                os.symlink(p, os.path.join(d, "sym_" + p))
                os.link(os.path.join(d, p), os.path.join(d, "hard_" + p))
            listing = sorted(os.listdir(d))

            def check(args, why):
                nonlocal runs
                runs += 1
                rc, err = run(exe, [verb, *args], d)
                bad = []
                if rc != 5 or "refusing" not in err:
                    bad.append("exit %d, stderr: %s" % (rc, err.strip()[:300]))
                for p, data in original.items():
                    if open(os.path.join(d, p), "rb").read() != data:
                        bad.append("input %s changed" % p)
                left = sorted(set(os.listdir(d)) - set(listing))
                if left:
                    bad.append("left behind: %s" % left)
                    for f in left:
                        os.remove(os.path.join(d, f))
                if bad:
                    failures.append("rcbtool %s %s (%s): %s" % (verb, " ".join(args), why,
                                                                "; ".join(bad)))

            slots = ["OUT"] * len(pos_out) + outs
            for p, _ in inputs:
                spellings = [p, "./" + p, os.path.join(d, p), "sym_" + p, "hard_" + p]
                for slot in slots:
                    for s in spellings:
                        if slot == "OUT":
                            args = base + [s] + inopts
                        else:  # convert's OUT is given a fresh name
                            args = base + ["new_out.csv"] * len(pos_out) + inopts + [slot, s]
                        check(args, "%s onto input %s" % (slot, p))
            for i in range(len(slots)):
                for j in range(i + 1, len(slots)):
                    for s1, s2 in (("same.csv", "same.csv"), ("same.csv", "./same.csv")):
                        args = list(base)
                        for slot, s in ((slots[i], s1), (slots[j], s2)):
                            args += [s] if slot == "OUT" else [slot, s]
                        check(args + inopts, "%s and %s on one path" % (slots[i], slots[j]))
    finally:
        shutil.rmtree(work, ignore_errors=True)
    print("%d runs, %d failures" % (runs, len(failures)))
    for f in failures:
        print("FAIL:", f)
    return 1 if failures or runs < 100 else 0


if __name__ == "__main__":
    sys.exit(main())
