#!/usr/bin/env python3
"""The figures of docs/reliability.md, "Files of a run" (issue #26): what rcbtool
leaves behind when an allocation fails or a signal arrives in a run with several
outputs. Prints them; fails nothing (a measurement, not a test).

usage: io_walk.py RCBTOOL [--kmax N] [--signals N]
  RCBTOOL   the rcbtool to measure (e.g. build/tools/rcbtool)

Allocation walk: an LD_PRELOAD shim (built here with cc) fails the k-th
malloc/calloc/realloc of the process once (ENOMEM), k = 1..KMAX, for
`estimate ... --stats -o` and `order ... --order2 --stats -o`; tallies the exit
codes and the runs that failed but left a file. Signal walk: N runs of `estimate
--stats --spectra -o` over files holding "old", each sent SIGTERM, SIGINT or SIGHUP
at a random time within its run time; counts runs that ended with some outputs new
and some old, and temporaries left.
"""
import argparse
import collections
import os
import random
import shutil
import signal
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SHIM = r"""
#define _GNU_SOURCE
#include <errno.h>
#include <stdlib.h>
extern void *__libc_malloc(size_t);
extern void *__libc_calloc(size_t, size_t);
extern void *__libc_realloc(void *, size_t);
static long n, k = -2;
static int fail(void) {
  if (k == -2) { const char *e = getenv("FAIL_AT"); k = e ? atol(e) : -1; }
  return ++n == k;
}
void *malloc(size_t s) { if (fail()) { errno = ENOMEM; return NULL; } return __libc_malloc(s); }
void *calloc(size_t a, size_t b) { if (fail()) { errno = ENOMEM; return NULL; } return __libc_calloc(a, b); }
void *realloc(void *p, size_t s) { if (fail()) { errno = ENOMEM; return NULL; } return __libc_realloc(p, s); }
"""
ENV = dict(os.environ, OPENBLAS_NUM_THREADS="1")


def alloc_walk(exe, shim, src, args, kmax):
    d = tempfile.mkdtemp()
    shutil.copy(src, os.path.join(d, "sig.csv"))
    codes, left = collections.Counter(), 0
    for k in range(1, kmax + 1):
        env = dict(ENV, FAIL_AT=str(k), LD_PRELOAD=shim)
        rc = subprocess.run([exe, *args], cwd=d, env=env, capture_output=True).returncode
        extra = [f for f in os.listdir(d) if f != "sig.csv"]
        codes[rc] += 1
        if rc != 0 and extra:
            left += 1
        for f in extra:
            os.remove(os.path.join(d, f))
    shutil.rmtree(d)
    return codes, left


def signal_walk(exe, src, n):
    d = tempfile.mkdtemp()
    shutil.copy(src, os.path.join(d, "sig.csv"))
    outs = ("st.csv", "sp.csv", "o.csv")
    cmd = [exe, "estimate", "sig.csv", "--input", "force=DA.x", "--outputs", "DA.x",
           "--nseg", "512", "--stats", "st.csv", "--spectra", "sp.csv", "-o", "o.csv"]

    def reset():
        for f in outs:
            with open(os.path.join(d, f), "w") as fp:
                fp.write("old\n")

    t0 = time.time()
    subprocess.run(cmd, cwd=d, env=ENV, capture_output=True)
    dur = time.time() - t0
    random.seed(1)
    killed = mixed = temps = 0
    for i in range(n):
        reset()
        p = subprocess.Popen(cmd, cwd=d, env=ENV, stderr=subprocess.DEVNULL)
        time.sleep(random.uniform(0, dur))
        p.send_signal((signal.SIGTERM, signal.SIGINT, signal.SIGHUP)[i % 3])
        killed += p.wait() < 0
        old = [open(os.path.join(d, f)).read() == "old\n" for f in outs]
        mixed += any(old) and not all(old)
        extra = set(os.listdir(d)) - {"sig.csv", *outs}
        temps += bool(extra)
        for f in extra:
            os.remove(os.path.join(d, f))
    shutil.rmtree(d)
    return dur, killed, mixed, temps


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("rcbtool")
    ap.add_argument("--kmax", type=int, default=200)
    ap.add_argument("--signals", type=int, default=150)
    o = ap.parse_args()
    exe = os.path.abspath(o.rcbtool)
    work = tempfile.mkdtemp()
    try:
        with open(os.path.join(work, "shim.c"), "w") as f:
            f.write(SHIM)
        shim = os.path.join(work, "failmalloc.so")
        subprocess.run(["cc", "-O2", "-shared", "-fPIC", "-o", shim,
                        os.path.join(work, "shim.c")], check=True)
        sdof = os.path.join(ROOT, "examples", "signals", "random_sdof.csv")
        runup = os.path.join(work, "runup.csv")
        subprocess.run([exe, "transient", os.path.join(ROOT, "examples", "paper_system.ini"),
                        "--out", "DA.x,DB.x", "--rpm", "3000", "--rpm-end", "4500", "--accel",
                        "3000", "--dt", "1e-4", "--signals", "-o", runup], env=ENV, check=True)
        walks = [("estimate --stats -o", sdof,
                  ["estimate", "sig.csv", "--input", "force=DA.x", "--outputs", "DA.x", "--nseg",
                   "512", "--stats", "st.csv", "-o", "o.csv"]),
                 ("order --order2 --stats -o", runup,
                  ["order", "sig.csv", "--kp", "KP", "--outputs", "DA.x,DB.x", "--bin-rpm", "300",
                   "--order2", "o2.csv", "--stats", "st.csv", "-o", "o.csv"])]
        for name, src, args in walks:
            codes, left = alloc_walk(exe, shim, src, args, o.kmax)
            print(f"allocation walk k=1..{o.kmax}, {name}: exit codes "
                  f"{dict(sorted(codes.items()))}, failed runs that left a file: {left}")
        dur, killed, mixed, temps = signal_walk(exe, sdof, o.signals)
        print(f"signal walk: {o.signals} runs ({dur * 1000:.0f} ms each), {killed} killed by the "
              f"signal, {mixed} with some outputs new and some old, {temps} left a temporary")
    finally:
        shutil.rmtree(work, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
