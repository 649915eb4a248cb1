#!/usr/bin/env python3
"""The monitor's rates at the users' size (issue #34 item 2): replicas of whole
series, noise the monitor did not make, and each count against its binomial
bound.

Set-up (diag_cases' issue #14 size): the paper rig's 8 responses per forces at
DA.x, DA.y, DB.x, DB.y (32 channels), 1101 lines 50-600 Hz, 10000 rpm. Truth:
ROSS 2.3's M, C, K, G of the paper system (diag_cases.ross_inertance's
assembly; checked against it, which checks ROSS's own transfer_matrix), the
case's parameter set on the parsed model; K is affine in kt and in B4's kyy
(checked against a third build to 1e-12) so a drifting series needs two builds.
The clean inertances are cached in OUT/monitor_replicas_truth-<key>.npz.

The monitor: librcb.Monitor on the truth's own model (exact baseline), kt, kr,
ct tracked, --noise 10,1 (10,1,2 for the phase forms), --reweight
--relinearise 8 --alpha 0.01 (docs/monitoring.md's recipe), the reference the
average of COMMISSION = 10 files, the noise's level measured on their scatter
(librcb.monitor.noise_scale, rcbtool monitor's default; --scale declared: the
noise as declared, as before that existed). Each replica is a new commissioning and a new
series (numpy PCG64, seed = 100000 * case + 1000 * replica + file).

Noise forms, one per replica in turn (diag_cases.calibration_noise):
  eq19     eq. 19 as declared (10 %, 1 %)
  high     eq. 19 with both factors 20 % above the declared (12 %, 1.2 %)
  literal  eq. 19 read on magnitudes (the systematic term real, in phase) and
           +-2 deg phase noise; declared 10,1,2
  phase    eq. 19 and +-2 deg phase noise per point; declared 10,1,2

Cases (UPDATES = 30 updates after the commissioning; the change from update
ONSET + 1 = 7):
  null    nothing changes
  wear    coupling kt falls 0.1 % per update (tracked)
  drift   B4 kyy falls DRIFT_SD = 0.215 of its per-update sd per update (untracked)
  step    a point mass of 0.05 kg at disk DB from update 7, then quiet

Counted per case: instant (TEST) false alarms (null updates: all of null, the
updates before the onset, and all of wear, where only a tracked parameter
moves) against the binomial 99 % bound at alpha; replicas with a false CUSUM
alarm (null, before the onset, kr/ct in wear) against 2 x 3 x updates / ARL0
(Siegmund's ARL0 19110, k 0.5, h 8, each side); every "told apart" statement
(the instant test's first named alone, JSON "separable": true on an alarm; a
CUSUM alarm named alone, named 1; a candidate told apart from a tracked
parameter, named -1) and whether it is wrong (the truth not among what it
names; the truth the rival), with the rate's binomial bound against 5 %; the
detection delay; and the tracked values' 95 % intervals covering the truth.

    OPENBLAS_NUM_THREADS=1 LIBRCB_PATH=build/src/librcb.so nice -n 10 \\
      .venv/bin/python tools/bench/monitor_replicas.py --replicas 100 \\
      [--cases null,drift,wear,step] [--forms eq19,high,literal,phase]
      [--scale measured|declared] [--sensors] [--out out/monitor_replicas]
"""

import argparse
import hashlib
import json
import math
import os
import sys
import time
import warnings
from pathlib import Path

import numpy as np
from scipy import stats

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "tests" / "python"))
sys.path.insert(0, str(REPO / "tools" / "python"))
warnings.simplefilter("ignore")

import diag_cases as dc  # noqa: E402
import ross_models as rm  # noqa: E402

PARAMS = dc.FIT_PARAMS.split(",")  # coupling.C.kt, kr, ct
COMMISSION = 10
ALPHA = 0.01
UPDATES = 30
ONSET = 6  # quiet updates before the change
FREQ = dc.LARGE_FREQ_HZ
INS = dc.LARGE_INS
WEAR_PER_UPDATE = 0.001  # kt's fall per update, relative
DRIFT_SD = 0.215  # B4 kyy's fall per update, its per-update standard deviations
# B4 kyy's per-update standard deviation on this set-up (N/m): the monitor's
# linear standard error of the candidate jointly with the tracked parameters
# (a noise-free step, --sd-check prints it), fixed here so that the ROSS data do
# not depend on the code under test
SD_KYY = 5511.0
MASS_DB = 0.05  # kg, at disk DB (shaft B, 0.82 m)
FORMS = {"eq19": (10, 1), "high": (10, 1), "literal": (10, 1, 2), "phase": (10, 1, 2)}
ARL0 = 19110.0  # Siegmund's, k 0.5, h 8 (one side)
CASES = ("null", "drift", "wear", "step")


# --------------------------------------------------------------------------
# truth
# --------------------------------------------------------------------------


def _matrices(edit=None):
    model = rm.Model(dc.BASE_INI)
    if edit:
        edit(model)
    speed = dc.RPM * math.pi / 30.0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rmod = rm.RossModel(model, speed=speed)
        rot = rmod.rotor
        mats = (rot.M(frequency=speed), rot.C(frequency=speed), rot.K(frequency=speed), rot.G())
    rows = [rmod.station_dof(o) for o in dc.OUTS]
    cols = [rmod.station_dof(i) for i in INS]
    return mats, rows, cols, speed


def _solve(mats, rows, cols, speed):
    M, C, K, G = mats
    E = np.zeros((M.shape[0], len(cols)))
    for q, j in enumerate(cols):
        E[j, q] = 1.0
    H = np.empty((len(cols) * len(dc.OUTS), len(FREQ)), dtype=complex)
    for i, f in enumerate(FREQ):
        w = 2.0 * math.pi * f
        X = np.linalg.solve(K - w * w * M + 1j * w * (C + speed * G), E)
        H[:, i] = (-w * w * X[rows, :]).T.reshape(-1)
    return H


def _affine(edit_at, v0, v1, v2):
    """A function v -> clean H (32 x 1101) for a parameter that enters K
    linearly, from builds at v0 and v1 (checked at v2)."""
    (a, rows, cols, speed), (b, _, _, _), (c, _, _, _) = (_matrices(edit_at(v)) for v in
                                                       (v0, v1, v2))
    kmat = lambda v: a[2] + (v - v0) / (v1 - v0) * (b[2] - a[2])  # noqa: E731
    for i in (0, 1, 3):
        assert np.array_equal(a[i], b[i]) or np.allclose(a[i], b[i], rtol=1e-13, atol=0)
    err = np.max(np.abs(kmat(v2) - c[2])) / np.max(np.abs(c[2]))
    assert err < 1e-12, f"ROSS K is not affine ({err:.3e})"
    return lambda v: _solve((a[0], a[1], kmat(v), a[3]), rows, cols, speed)


def _key():
    import ross

    h = hashlib.sha256()
    for p in (REPO / "tests/python/diag_cases.py", REPO / "tests/python/ross_models.py"):
        h.update(p.read_bytes())
    h.update(ross.__version__.encode())
    # what the truth depends on in this file
    h.update(repr((UPDATES, ONSET, WEAR_PER_UPDATE, DRIFT_SD, SD_KYY, MASS_DB, list(INS),
                   FREQ.tobytes())).encode())
    return h.hexdigest()[:12]


def kt0():
    return float(rm.Model(dc.BASE_INI).couplings[0][3]["kt"][-1])


def kyy0():
    return float(dc._bearing(rm.Model(dc.BASE_INI), "B4")["kyy"][-1])


def truth(out):
    """Clean inertances per case: {case: (UPDATES + 1, 32, 1101)}, index 0 the
    commissioning's truth and j the update j's."""
    path = Path(out) / f"monitor_replicas_truth-{_key()}.npz"
    if path.is_file():
        z = np.load(path)
        return {c: z[c] for c in z.files}
    t0 = time.time()
    H0 = dc.ross_inertance(dc.BASE_INI, None, freq=FREQ, ins=INS)  # checked against ROSS
    k = kt0()
    kt = _affine(lambda v: dc.coupling_keys(kt=v), k, 0.5 * k, 0.83 * k)
    y = kyy0()
    ky = _affine(lambda v: dc.bearing_keys("B4", kyy=v), y, 0.5 * y, 0.8 * y)
    mine = kt(k)
    assert np.max(np.abs(mine - H0)) <= 1e-9 * np.max(np.abs(H0))
    Hm = dc.ross_inertance(dc.BASE_INI, dc.point_mass_edit("B 0.82", MASS_DB), freq=FREQ,
                           ins=INS)
    ch = lambda j: max(j - ONSET, 0)  # noqa: E731  updates of change at update j
    H = {"null": H0[None],
         "wear": np.array([kt(k * (1 - WEAR_PER_UPDATE * ch(j))) for j in range(UPDATES + 1)]),
         "drift": np.array([ky(y - DRIFT_SD * SD_KYY * ch(j)) for j in range(UPDATES + 1)]),
         "step": np.array([H0, Hm])}
    Path(out).mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(f".{os.getpid()}.npz")
    np.savez(tmp, **H)
    os.replace(tmp, path)
    print(f"# ROSS truth built in {time.time() - t0:.0f} s, cached in {path}", flush=True)
    return H


def clean(H, case, j):
    """The clean inertances of update j (0: the commissioning)."""
    if case == "null":
        return H["null"][0]
    if case == "step":
        return H["step"][1 if j > ONSET else 0]
    return H[case][j]


# --------------------------------------------------------------------------
# what is true, what was said
# --------------------------------------------------------------------------


def is_truth(case, d, j):
    """Whether candidate d (effect, place, params) is the case's untracked truth
    at update j."""
    if d is None or j <= ONSET:
        return False
    if case == "drift":
        return d["place"] == "bearing B4" and d["params"] == "bearing.B4.kyy"
    if case == "step":
        return d["effect"] == dc.MASS and "DB" in d["place"]
    return False


def tracked_truth(case, j):
    """The tracked parameter that moves at update j (its index), or None."""
    return 0 if case == "wear" and j > ONSET else None


def statements(case, j, r):
    """The update's "told apart" statements: (kind, wrong, truth is the rival, text)."""
    out = []
    if r["alarm"] and r["separable"] and r["top"]:
        a = r["top"][0]
        right = is_truth(case, a, j)
        rival = len(r["top"]) > 1 and is_truth(case, r["top"][1], j)
        out.append(("instant", not right, bool(rival and not right),
                    f"{a['effect']} at {a['place']}: {a['params']}"))
    for k, t in enumerate(r["tracked"]):
        if not t["cusum_alarm"]:
            continue
        falling = t["cusum_alarm"] < 0
        if t["named"] == 1:  # the tracked parameter alone
            right = tracked_truth(case, j) == k and falling
            rival = t["rival"] is not None and is_truth(case, t["rival"], j)
            out.append(("cusum alone", not right, bool(rival and not right),
                        f"{t['name']} {'falling' if falling else 'rising'}"))
        elif t["named"] == -1:  # told apart from the tracked parameter
            named = [t["rival"]] + ([t["rival2"]] if t["rival2"] else [])
            # "or N other candidates": the claim is only "not this parameter"
            right = (any(is_truth(case, d, j) for d in named) if not t.get("rivals_open")
                     else tracked_truth(case, j) != k)
            rival = tracked_truth(case, j) == k
            out.append(("told apart from tracked", not right, bool(rival and not right),
                        " or ".join(f"{d['params']}" for d in named)
                        + (f" or {t['rivals_open']} others" if t.get("rivals_open") else "")
                        + f" (not {t['name']})"))
    return out


# --------------------------------------------------------------------------
# one replica
# --------------------------------------------------------------------------


def _meas(rcb, data):
    resp = [o for _ in INS for o in dc.OUTS]
    refs = [i for i in INS for _ in dc.OUTS]
    return rcb.Meas.from_arrays(FREQ, data, resp, refs, kind="inertance", rpm=dc.RPM)


def replica(rcb, model, H, case, rep, ci, scale="measured", sensors=False):
    form = list(FORMS)[rep % len(FORMS)]
    seed0 = 100000 * ci + 1000 * rep
    files = np.array([dc.calibration_noise(form, clean(H, case, 0), seed0 + i)
                      for i in range(COMMISSION)])
    avg = files.mean(axis=0)
    t0 = time.process_time()
    with _meas(rcb, avg) as setup:
        # the noise's level from the commissioning files' scatter, as rcbtool
        # monitor's default (--noise-scale auto); "declared": none
        ns = (rcb.monitor.noise_scale(setup, files, noise=FORMS[form])["scale"]
              if scale == "measured" else 1.0)
        mon = rcb.Monitor(model, setup, PARAMS, noise=FORMS[form], setup_averages=COMMISSION,
                          alpha=ALPHA, reweight=True, relinearise=8, noise_scale=ns,
                          sensors=sensors)
    t_create = time.process_time() - t0
    base = [t["baseline"] for t in mon.tracked]
    rec = {"case": case, "rep": rep, "form": form, "seed0": seed0, "noise_scale": ns,
           "sensors": bool(sensors), "updates": []}
    t_upd = 0.0
    try:
        for j in range(1, UPDATES + 1):
            data = dc.calibration_noise(form, clean(H, case, j), seed0 + COMMISSION + j)
            with _meas(rcb, data) as ms:
                t1 = time.process_time()
                r = mon.update(ms)
                t_upd += time.process_time() - t1
            tv = list(base)
            if case == "wear":
                tv[0] = base[0] * (1 - WEAR_PER_UPDATE * max(j - ONSET, 0))
            rec["updates"].append({
                "j": j, "alarm": r["alarm"], "separable": r["separable"], "T": r["T"],
                "dof": r["dof"],
                "threshold": r["threshold"],
                "top": [{k: c[k] for k in ("effect", "place", "params", "size", "ci_lo",
                                           "ci_hi")} for c in r["top"][:2]],
                # every ranked candidate's score (the one rule's BIC inputs)
                "scores": [[c["params"], c["score"], c["dof"]] for c in r["top"]],
                "cusum": [t["cusum_alarm"] for t in r["tracked"]],
                "named": [t["named"] if t["cusum_alarm"] else None for t in r["tracked"]],
                "cover": [bool(t["ci_lo"] <= v <= t["ci_hi"]) for t, v in zip(r["tracked"], tv)],
                "drift": (None if r["drift"] is None or not r["drift"]["alarm"] else
                          {k: r["drift"][k] for k in ("effect", "place", "params")}),
                "statements": statements(case, j, r)})
    finally:
        mon.close()
    rec["cpu_create"], rec["cpu_updates"] = t_create, t_upd
    return rec


# --------------------------------------------------------------------------
# counting
# --------------------------------------------------------------------------


def binom_upper(n, p):
    """More than this many of n at rate p rejects the rate (binomial, 99 %)."""
    return int(stats.binom.ppf(0.99, n, p))


def binom_lower(n, p):
    """Fewer than this many of n rejects the rate p (binomial 1 % quantile)."""
    return int(stats.binom.ppf(0.01, n, p))


def null_update(case, j):
    return case in ("null", "wear") or j <= ONSET


def first_named(case, rec):
    """The first update (counted from the onset) at which the truth is named:
    wear kt's CUSUM falling and named (alone or not separable); drift/step the
    instant test's first, the drift test, or a CUSUM attribution's rival."""
    for u in rec["updates"]:
        j = u["j"]
        if j <= ONSET:
            continue
        if case == "wear" and u["cusum"][0] < 0 and u["named"][0] in (0, 1):
            return j - ONSET
        if case in ("drift", "step"):
            if u["alarm"] and u["top"] and is_truth(case, u["top"][0], j):
                return j - ONSET
            if u["drift"] and is_truth(case, u["drift"], j):
                return j - ONSET
    return None


def forms_of(recs, rep):
    return next(r["form"] for r in recs if r["rep"] == rep)


def summarise(case, recs):
    n_null = sum(null_update(case, u["j"]) for r in recs for u in r["updates"])
    fa = sum(u["alarm"] for r in recs for u in r["updates"] if null_update(case, u["j"]))
    rep_fa = sum(any(u["alarm"] for u in r["updates"] if null_update(case, u["j"])) for r in recs)
    nq = UPDATES if case in ("null", "wear") else ONSET
    watch = [1, 2] if case == "wear" else [0, 1, 2]  # CUSUMs that should stay quiet
    cus = sum(any(u["cusum"][k] for u in r["updates"] for k in watch
                  if null_update(case, u["j"]) or case == "wear") for r in recs)
    p_cus = min(1.0, 2 * len(watch) * nq / ARL0)
    st = [(r["rep"], r["seed0"], u["j"], s) for r in recs for u in r["updates"]
          for s in u["statements"]]
    wrong = [x for x in st if x[3][1]]
    rival = [x for x in st if x[3][2]]
    kinds = {}
    for x in st:
        form = "eq19" if forms_of(recs, x[0]) == "eq19" else "other forms"
        k = kinds.setdefault(f"{x[3][0]}, {form}", [0, 0, 0])
        k[0] += 1
        k[1] += x[3][1]
        k[2] += x[3][2]
    rep_wrong = sum(any(s[1] for u in r["updates"] for s in u["statements"]) for r in recs)
    # the drift test's alarms: false on null updates; after the onset, naming
    # another effect than the truth (its text names one candidate alone)
    dfa = sum(bool(u["drift"]) for r in recs for u in r["updates"] if null_update(case, u["j"]))
    dch = [u["drift"] for r in recs for u in r["updates"]
           if u["drift"] and not null_update(case, u["j"])]
    dwrong = sum(not is_truth(case, d, ONSET + 1) for d in dch)
    delays = [d for d in (first_named(case, r) for r in recs) if d is not None]
    cov = np.array([u["cover"] for r in recs for u in r["updates"]])
    last = np.array([r["updates"][-1]["cover"] for r in recs])
    # the named effect's size interval holding the truth (step: the mass, kg)
    sized = [u["top"][0]["ci_lo"][0] <= MASS_DB <= u["top"][0]["ci_hi"][0]
             for r in recs for u in r["updates"]
             if case == "step" and u["alarm"] and u["top"] and is_truth(case, u["top"][0], u["j"])]
    forms = {}
    for r in recs:
        f = forms.setdefault(r["form"], [0] * 8 + [[0] * len(PARAMS), 0])
        nu = [u for u in r["updates"] if null_update(case, u["j"])]
        f[0] += 1
        f[1] += len(nu)
        f[2] += sum(u["alarm"] for u in nu)
        f[3] += sum(bool(u["drift"]) for u in nu)
        f[4] += any(u["cusum"][k] for u in r["updates"] for k in watch
                    if null_update(case, u["j"]) or case == "wear")
        f[5] += sum(len(u["statements"]) for u in r["updates"])
        f[6] += sum(s[1] for u in r["updates"] for s in u["statements"])
        f[7] += first_named(case, r) is not None
        f[8] = [a + sum(u["cover"][k] for u in r["updates"]) for k, a in enumerate(f[8])]
        f[9] += len(r["updates"])
    return {"case": case, "replicas": len(recs), "null_updates": n_null, "test_fa": fa,
            "test_bound": binom_upper(n_null, ALPHA), "replicas_test_fa": rep_fa,
            "cusum_fa": cus, "cusum_bound": binom_upper(len(recs), p_cus), "p_cusum": p_cus,
            "told": len(st), "wrong": len(wrong), "rival": len(rival),
            "replicas_wrong": rep_wrong, "replicas_wrong_bound": binom_upper(len(recs), 0.05),
            "drift_fa": dfa, "drift_after": len(dch), "drift_wrong": dwrong,
            "wrong_bound": binom_upper(len(st), 0.05) if st else 0,
            "wrong_examples": wrong[:5], "named": len(delays),
            "delay_median": float(np.median(delays)) if delays else None,
            "delay_max": max(delays) if delays else None,
            "cover": cov.mean(axis=0).tolist() if cov.size else [], "cover_n": int(len(cov)),
            "cover_last": last.sum(axis=0).tolist(),
            "cover_last_bound": binom_lower(len(recs), 0.95),
            "forms": forms, "kinds": kinds, "size_named": len(sized), "size_covers": int(sum(sized)),
            "size_bound": binom_lower(len(sized), 0.95) if sized else 0,
            # the instant test's T on the null updates against its degrees of freedom
            "mean_T": float(np.mean([u["T"] for r in recs for u in r["updates"]
                                     if null_update(case, u["j"])] or [math.nan])),
            "dof": sorted({u.get("dof") for r in recs for u in r["updates"]} - {None}),
            "cpu_create": float(np.mean([r["cpu_create"] for r in recs])),
            "cpu_update": float(np.sum([r["cpu_updates"] for r in recs]) / (len(recs) * UPDATES))}


def saved(out, case):
    """The replicas saved in OUT/CASE.json and OUT/CASE.FIRST.json (runs with
    --first FIRST), one per replica number, in order."""
    recs = {}
    for p in sorted(out.glob(f"{case}.json")) + sorted(out.glob(f"{case}.*.json")):
        for r in json.loads(p.read_text()):
            recs.setdefault(r["rep"], r)
    return [recs[k] for k in sorted(recs)]


def sd_check(rcb, model):
    """B4 kyy's per-update sd: a noise-free step of 10 sd on the commissioning's
    truth, the first candidate's 95 % interval (the monitor linear, eq. 19)."""
    y = kyy0()
    ky = _affine(lambda v: dc.bearing_keys("B4", kyy=v), y, 0.5 * y, 0.8 * y)
    with _meas(rcb, ky(y)) as setup:
        mon = rcb.Monitor(model, setup, PARAMS, noise=(10, 1), alpha=ALPHA, sensors=False,
                          setup_averages=COMMISSION)
    with _meas(rcb, ky(y - 10 * SD_KYY)) as ms:
        r = mon.update(ms)
    c = r["top"][0]
    sd = (c["ci_hi"][0] - c["ci_lo"][0]) / (2 * 1.959963984540054)
    print(f"first candidate {c['params']}, sd {sd:.6g} N/m (SD_KYY {SD_KYY:g})")
    mon.close()


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--replicas", type=int, default=100)
    ap.add_argument("--first", type=int, default=0, help="first replica number")
    ap.add_argument("--cases", default=",".join(CASES))
    ap.add_argument("--out", default=str(REPO / "out" / "monitor_replicas"))
    ap.add_argument("--sd-check", action="store_true", help="print B4 kyy's sd and stop")
    ap.add_argument("--scale", choices=("measured", "declared"), default="measured",
                    help="the noise's level: measured on the commissioning files' scatter "
                    "(rcbtool monitor's default) or as declared")
    ap.add_argument("--sensors", action="store_true",
                    help="the measurement chain among the candidates (rcbtool monitor --sensors)")
    ap.add_argument("--forms", default=",".join(FORMS),
                    help="run only the replicas of these noise forms (they take turns)")
    ap.add_argument("--from-json", action="store_true",
                    help="no runs: count the replicas saved in OUT/CASE.json and "
                    "OUT/CASE.FIRST.json (runs with --first; a partial run too)")
    args = ap.parse_args()
    if args.from_json:
        return table([summarise(c, recs) for c in args.cases.split(",")
                      if (recs := saved(Path(args.out), c))])
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    import librcb as rcb

    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    ini = out / "model.ini"
    ini.write_text(dc.BASE_INI)
    model = rcb.Model.from_ini(ini)
    if args.sd_check:
        sd_check(rcb, model)
        return 0
    H = truth(out)
    rows = []
    for case in args.cases.split(","):
        ci = CASES.index(case) + 1
        t0 = time.time()
        recs = []
        forms = args.forms.split(",")
        for rep in range(args.first, args.first + args.replicas):
            if list(FORMS)[rep % len(FORMS)] not in forms:
                continue
            recs.append(replica(rcb, model, H, case, rep, ci, args.scale, args.sensors))
            name = f"{case}.json" if args.first == 0 else f"{case}.{args.first}.json"
            (out / name).write_text(json.dumps(recs))
        s = summarise(case, recs)
        s["wall"] = time.time() - t0
        rows.append(s)
        (out / f"{case}_summary.json").write_text(json.dumps(s, indent=1))
        print(f"{case}: {json.dumps({k: v for k, v in s.items() if k != 'wrong_examples'})}",
              flush=True)
        for ex in s["wrong_examples"]:
            print(f"  wrong: replica {ex[0]} seed0 {ex[1]} update {ex[2]}: {ex[3][0]}: "
                  f"{ex[3][3]}{' (the truth was the rival)' if ex[3][2] else ''}", flush=True)
    return table(rows)


def table(rows):
    for s in rows:
        for ex in s["wrong_examples"]:
            print(f"  {s['case']} wrong: replica {ex[0]} seed0 {ex[1]} update {ex[2]}: {ex[3][0]}: "
                  f"{ex[3][3]}{' (the truth was the rival)' if ex[3][2] else ''}")
    print(f"\n{len(dc.OUTS) * len(INS)} channels x {len(FREQ)} lines, {UPDATES} updates per "
          f"replica (change from update {ONSET + 1}), alpha {ALPHA}, commissioning {COMMISSION} "
          f"files; forms in turn: {', '.join(FORMS)}\n")
    print("| case | replicas | TEST false alarms (bound) | replicas with a false CUSUM alarm "
          "(bound) | told apart | wrong (truth the rival) | wrong bound (5 %) | truth named "
          "(median, max delay) | value CI covers kt, kr, ct (per update) | at the last update "
          "(bound) | CPU s per update, create |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for s in rows:
        dl = (f"{s['named']}/{s['replicas']} ({s['delay_median']:g}, {s['delay_max']})"
              if s["named"] else f"0/{s['replicas']}")
        if s["case"] == "null":
            dl = "-"
        print(f"| {s['case']} | {s['replicas']} | {s['test_fa']} of {s['null_updates']} "
              f"({s['test_bound']}) | {s['cusum_fa']} ({s['cusum_bound']}) | {s['told']} | "
              f"{s['wrong']} ({s['rival']}) | {s['wrong_bound']} | {dl} | "
              f"{', '.join(f'{100 * c:.1f} %' for c in s['cover'])} | "
              f"{', '.join(str(c) for c in s['cover_last'])} ({s['cover_last_bound']}) | "
              f"{s['cpu_update']:.3f}, {s['cpu_create']:.2f} |")
    for s in rows:
        if "mean_T" in s:
            print(f"\n{s['case']}: the instant test's mean T on the null updates {s['mean_T']:.1f} "
                  f"on {', '.join(str(d) for d in s['dof'])} degrees of freedom")
    print("\nreplicas with any wrong \"told apart\" (bound at 5 %), and the drift test: false "
          "alarms on null updates (bound at alpha), alarms after the onset naming another effect\n")
    print("| case | replicas with a wrong \"told apart\" (bound) | drift false alarms (bound) | "
          "drift alarms after the onset: another effect named |")
    print("|---|---|---|---|")
    for s in rows:
        print(f"| {s['case']} | {s['replicas_wrong']} of {s['replicas']} "
              f"({s['replicas_wrong_bound']}) | {s['drift_fa']} of {s['null_updates']} "
              f"({s['test_bound']}) | {s['drift_wrong']} of {s['drift_after']} |")
    print("\n\"told apart\" by kind: statements, wrong (the truth the rival), the 99 % bound "
          "of a 5 % rate\n")
    print("| case | kind | statements | wrong (truth the rival) | bound |")
    print("|---|---|---|---|---|")
    for s in rows:
        for k, (n, w, rv) in sorted(s["kinds"].items()):
            print(f"| {s['case']} | {k} | {n} | {w} ({rv}) | {binom_upper(n, 0.05)} |")
    print("\nper noise form: replicas; TEST and drift false alarms in the null updates; replicas "
          "with a false CUSUM alarm; wrong \"told apart\" of all\n")
    print("| case | form | replicas | TEST false alarms (bound) | drift false alarms | "
          "false CUSUM replicas | wrong \"told apart\" | truth named | value CI covers kt, kr, "
          "ct |")
    print("|---|---|---|---|---|---|---|---|---|")
    for s in rows:
        for f in FORMS:
            if f in s["forms"]:
                n, nu, fa, dfa, cus, st, wr, nm, cov, ncov = s["forms"][f]
                print(f"| {s['case']} | {f} | {n} | {fa} of {nu} ({binom_upper(nu, ALPHA)}) | "
                      f"{dfa} | {cus} | {wr} of {st} | "
                      f"{'-' if s['case'] == 'null' else f'{nm} of {n}'} | "
                      f"{', '.join(f'{100 * c / ncov:.1f} %' for c in cov)} |")
    for s in rows:
        if s["size_named"]:
            print(f"\n{s['case']}: the named mass's 95 % interval holds {MASS_DB} kg on "
                  f"{s['size_covers']} of {s['size_named']} alarms (binomial 1 % quantile of 95 %:"
                  f" {s['size_bound']})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
