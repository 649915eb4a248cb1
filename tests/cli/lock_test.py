#!/usr/bin/env python3
"""One writer at a time for every file a run reads and replaces (issue #34 item 6).

1. Which files are locked is found, not listed: every file option of every verb
   (read from `rcbtool help` and `VERB --help` as io_plan_test.py does) is given
   an existing file whose lock this test holds, with RCB_LOCK_WAIT=0. A run
   that exits 6 (the lock's exit code) locks that option: the plan declared it
   read-then-rewritten (CLI_IO_INOUT). Every such verb/option must have a race
   recipe below, so a verb added later with such a file fails this test until
   it is raced too. The locked file must be unchanged and the message name it.
2. Each recipe is raced: N runs started together on one file,
   - with a long RCB_LOCK_WAIT: all exit 0 and the file holds all N updates;
   - with RCB_LOCK_WAIT=0: each exits 0 or 6, and the file holds exactly the
     updates of the runs that exited 0 (no run says ok while its update is
     lost);
   each round leaves no lock file and no temporary behind.
3. A held lock released after a while: the waiting run goes on (exit 0) and
   took at least that long.
4. Five runs starting one new monitor series on one new --state: one exits 0,
   the others are told the state exists (exit 2); the state holds one series.

usage: lock_test.py RCBTOOL EXAMPLES_DIR   (exit 0 pass, 1 fail)
"""
import fcntl
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import io_plan_test  # noqa: E402  (the verbs and file options from --help)

EXIT_LOCKED = 6
N = 5  # runs started together
MONITOR_SET = ["--params", "coupling.C.kt,coupling.C.ct", "--noise", "10,1",
               "--relinearise", "2"]


def env(wait):
    return dict(os.environ, OPENBLAS_NUM_THREADS="1", RCB_LOCK_WAIT=str(wait))


def run(exe, args, cwd, wait=10):
    r = subprocess.run([exe, *args], cwd=cwd, capture_output=True, text=True, env=env(wait),
                       timeout=300)
    return r.returncode, r.stdout, r.stderr


def together(exe, arglists, cwd, wait):
    """Start every run at once, then wait for all: [(rc, stderr)]."""
    procs = [subprocess.Popen([exe, *args], cwd=cwd, stdout=subprocess.DEVNULL,
                              stderr=subprocess.PIPE, text=True, env=env(wait))
             for args in arglists]
    return [(p.wait(timeout=600), p.stderr.read()) for p in procs]


class Hold:
    """This test holding the lock of FILE (an fcntl write lock on FILE.lock)."""

    def __init__(self, path):
        self.f = open(path + ".lock", "a")
        fcntl.lockf(self.f, fcntl.LOCK_EX | fcntl.LOCK_NB)

    def release(self):
        fcntl.lockf(self.f, fcntl.LOCK_UN)
        self.f.close()


# ---- the recipes: how to run each locked verb/option so that it adds one update ----

class Recipe:
    """prepare(d) sets the work directory up; args(d, k) is run k's command line
    (its update: one step or one file); count(d) the updates the file holds;
    target the file locked."""


class HistoryRecipe(Recipe):
    def __init__(self, exe, examples, verb):
        self.exe, self.examples, self.verb, self.target = exe, examples, verb, "h.jsonl"

    def prepare(self, d):
        shutil.copy(os.path.join(self.examples, "paper_system.ini"), os.path.join(d, "m.ini"))
        rc, _, err = run(self.exe, ["simulate", "m.ini", "--frf", "--out", "C.A.x", "--in",
                                    "DA.x", "--fmin", "200", "--fmax", "400", "--points", "21",
                                    "--rpm", "10000", "--noise", "10,1", "--seed", "3", "-o",
                                    "meas.csv"], d)
        assert rc == 0, err

    def args(self, d, k):
        return [self.verb, "m.ini", "meas.csv", "--params", "coupling.C.kt", "--history",
                self.target]

    def count(self, d):
        path = os.path.join(d, self.target)
        if not os.path.exists(path):
            return 0
        rc, out, err = run(self.exe, ["history", self.target, "--json"], d)
        assert rc == 0, err
        steps = json.loads(out)
        assert all(s["command"] == self.verb for s in steps), steps
        return len(steps)


class StateRecipe(Recipe):
    """monitor --state S NEW: a series of 3 commissioning/first files, then one
    new file per run (each run its own file: a file is taken once)."""

    def __init__(self, exe, examples):
        self.exe, self.examples, self.target = exe, examples, "s.rcbmon"
        self.round = 0

    def prepare(self, d):
        shutil.copy(os.path.join(self.examples, "paper_system.ini"), os.path.join(d, "m.ini"))
        for k in range(3 + 4 * N):  # the first 3, then 4 rounds of N
            rc, _, err = run(self.exe, ["simulate", "m.ini", "--frf", "--out",
                                        "C.A.x,C.A.y,C.B.x,C.B.y", "--in", "DA.x", "--fmin",
                                        "100", "--fmax", "400", "--points", "61", "--rpm",
                                        "10000", "--kind", "inertance", "--noise", "10,1",
                                        "--seed", str(k + 1), "-o", "f%d.csv" % k], d)
            assert rc == 0, err
        rc, _, err = run(self.exe, ["monitor", "m.ini", "f0.csv", "f1.csv", "f2.csv",
                                    *MONITOR_SET, "--state", self.target], d)
        assert rc == 0, err
        self.used = 3

    def args(self, d, k):
        if k == 0:
            self.base = self.used
            self.used += N
        return ["monitor", "m.ini", "--state", self.target, "f%d.csv" % (self.base + k)]

    def count(self, d):
        rc, out, err = run(self.exe, ["monitor", "m.ini", "--state", self.target, "--json"], d)
        assert rc == 0, err
        files = [u["file"] for u in json.loads(out)["updates"]]
        assert len(files) == len(set(files)), files  # no file twice
        return len(files)


def recipes(exe, examples):
    return {("fit", "--history"): HistoryRecipe(exe, examples, "fit"),
            ("diagnose", "--history"): HistoryRecipe(exe, examples, "diagnose"),
            ("monitor", "--state"): StateRecipe(exe, examples)}


# ---- 1. which verb/option the plan locks ----

def locked_options(exe, examples, work, failures):
    found = []
    for verb in io_plan_test.verbs(exe):
        pos_in, pos_out, outs, ins = io_plan_test.describe(exe, verb)
        d = os.path.join(work, "probe_" + verb)
        os.mkdir(d)
        base = []
        for k, word in enumerate(pos_in):
            name = "in%d.%s" % (k, "ini" if word.endswith(".ini") else "csv")
            shutil.copy(os.path.join(examples, "paper_system.ini"), os.path.join(d, name))
            base.append(name)
        base += ["new_out.csv"] * len(pos_out)
        for opt in outs + ins:
            target = os.path.join(d, "t.dat")
            with open(target, "w") as f:
                f.write("the bytes of a file another run is updating\n")
            hold = Hold(target)
            try:
                rc, _, err = run(exe, [verb, *base, opt, "t.dat"], d, wait=0)
            finally:
                hold.release()
            os.remove(target + ".lock")
            if rc == EXIT_LOCKED:
                with open(target) as f:
                    if f.read() != "the bytes of a file another run is updating\n":
                        failures.append("%s %s: the locked file was changed" % (verb, opt))
                if "t.dat" not in err or "another run" not in err:
                    failures.append("%s %s: exit 6 without naming the file: %s" % (verb, opt,
                                                                                 err.strip()))
                found.append((verb, opt))
            left = sorted(set(os.listdir(d)) - set(base) - {"t.dat"})
            if left:
                failures.append("%s %s: left behind %s" % (verb, opt, left))
                for f in left:
                    os.remove(os.path.join(d, f))
    return found


# ---- 2.-4. ----

def race(exe, rc_name, recipe, work, failures):
    verb, opt = rc_name
    d = os.path.join(work, "race_%s_%s" % (verb, opt.strip("-")))
    os.mkdir(d)
    recipe.prepare(d)
    listing = set(os.listdir(d)) | {recipe.target}
    expected = recipe.count(d)
    for wait, rounds in ((120, 2), (0, 2)):
        for r in range(rounds):
            results = together(exe, [recipe.args(d, k) for k in range(N)], d, wait)
            codes = [rc for rc, _ in results]
            ok = codes.count(0)
            have = recipe.count(d)
            what = "%s %s, %d runs together, RCB_LOCK_WAIT=%d: exits %s, updates %d -> %d" % (
                verb, opt, N, wait, codes, expected, have)
            print(what)
            bad = [rc for rc in codes if rc not in (0, EXIT_LOCKED)]
            if bad or (wait > 0 and ok != N):
                failures.append(what + ": every run should exit 0" +
                                "".join("\n  " + e.strip() for rc, e in results if rc))
            if have != expected + ok:
                failures.append(what + ": the file should hold %d updates" % (expected + ok))
            for rc, err in results:
                if rc == EXIT_LOCKED and recipe.target not in err:
                    failures.append(what + ": exit 6 without naming the file: " + err.strip())
            left = sorted(set(os.listdir(d)) - listing)
            if left:
                failures.append(what + ": left behind %s" % left)
            expected = have


def held_then_released(exe, recipe, work, failures):
    d = os.path.join(work, "held")
    os.mkdir(d)
    recipe.prepare(d)
    before = recipe.count(d)
    hold = Hold(os.path.join(d, recipe.target))
    p = subprocess.Popen([exe, *recipe.args(d, 0)], cwd=d, stdout=subprocess.DEVNULL,
                         stderr=subprocess.PIPE, text=True, env=env(30))
    t0 = time.monotonic()
    time.sleep(1.0)
    still = p.poll() is None
    hold.release()
    rc = p.wait(timeout=60)
    took = time.monotonic() - t0
    print("a run on a held file, released after 1 s: exit %d after %.2f s, updates %d -> %d" %
          (rc, took, before, recipe.count(d)))
    if not still or rc != 0 or took < 1.0 or recipe.count(d) != before + 1:
        failures.append("a run waiting for a held lock: should wait, then exit 0 with its "
                        "update (exit %d, %.2f s): %s" % (rc, took, p.stderr.read().strip()))


def new_state_race(exe, recipe, work, failures):
    d = os.path.join(work, "new_state")
    os.mkdir(d)
    recipe.prepare(d)
    os.remove(os.path.join(d, recipe.target))
    args = ["monitor", "m.ini", "f0.csv", "f1.csv", "f2.csv", *MONITOR_SET, "--state",
            recipe.target]
    results = together(exe, [args] * N, d, 120)
    codes = sorted(rc for rc, _ in results)
    n = recipe.count(d)
    print("%d runs starting one new --state together: exits %s, updates %d" % (N, codes, n))
    if codes != [0] + [2] * (N - 1) or n != 2:
        failures.append("one new --state, %d runs: expected one exit 0 and the others 2 "
                        "(the state exists), 2 updates; got %s, %d" % (N, codes, n))
    for rc, err in results:
        if rc == 2 and "exists" not in err:
            failures.append("new --state: exit 2 without saying the state exists: " + err)


def main():
    exe, examples = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    failures = []
    work = tempfile.mkdtemp(prefix="rcbtool_lock.")
    try:
        known = recipes(exe, examples)
        found = locked_options(exe, examples, work, failures)
        print("locked by the plan: %s" % ", ".join("%s %s" % f for f in found))
        for f in found:
            if f not in known:
                failures.append("%s %s is locked (read and rewritten) but has no race recipe "
                                "in lock_test.py: add one" % f)
        for f in known:
            if f not in found:
                failures.append("%s %s has a race recipe but the plan does not lock it" % f)
        for f in found:
            if f in known:
                race(exe, f, known[f], work, failures)
        held_then_released(exe, HistoryRecipe(exe, examples, "fit"), work, failures)
        new_state_race(exe, StateRecipe(exe, examples), work, failures)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    for f in failures:
        print("FAIL:", f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
