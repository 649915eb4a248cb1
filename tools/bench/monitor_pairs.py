#!/usr/bin/env python3
"""The monitor's wrong "told apart" for each truth its catalogue can hold
(issue #34 item 2: for each pair the text can print, replicas where the truth
is the other candidate).

The set-up, the monitor and its options are monitor_replicas.py's (the paper
rig at 32 x 1101, kt, kr, ct tracked, --noise 10,1 or 10,1,2, --reweight
--relinearise 8 --alpha 0.01, --sensors, the reference the average of 10
commissioning files, the noise level measured on them). Each truth is one
effect of the catalogue made by ROSS 2.3 (the model's matrices at two values
of the parameter; the matrices are checked affine in it at a third, to
1e-12) or, for the measurement chain, applied to ROSS's clean inertances (a
probe's gain or phase, two probes swapped):

  bearing kxx, kyy at B1-B4; cross-coupling kxy = -kyx at B1-B4; damping cxx
  and cyy (x 1 + s both) at B1-B4; coupling cr and hub mass; a point mass at
  disks DA and DB; the shafts' stiffness-proportional damping; the operating
  speed (C + speed G: the paper system's bearings do not depend on it); a
  point mass at shaft A z = 0.3 m and shaft B z = 0.72 m (nodes, not disks);
  the hubs' diametral inertia (x 1 + s); probe
  gain at DA.x, DA.y, DB.x, DB.y and phase at C.A.x, DB.y; probes swapped
  DA.x/DA.y and C.B.x/C.B.y; a flexible support under B1 and under B4 (a
  2 kg pedestal, 500 N s/m, its stiffness 1/v: degrees of freedom the model
  lacks, so one ROSS build per size).

Not held here: the other nodes' masses, the disks' and the hubs' inertias
alone, the other probes' gains and phases (kinds held above at other
places). Another coupling model is diagnose's candidate, not the monitor's.

For each truth its per-update standard deviation sd is the monitor's own (a
clean update at a small size of the truth; the first ranked candidate that is
the truth gives its interval). A flexible support's three parameters are
the pedestal's, not v: its sizes are those whose clean update's T (the
noncentrality, the reference clean) is SIZES^2, from one clean update at a
small v and T growing as v^2 (the sd printed is that v's step per unit). Then BLOCKS commissionings, each with UPDATES
updates at each of the sizes SIZES x sd (a full swap: fraction 1 only): a new
commissioning, its noise form in turn (eq19, high, literal, phase: the forms
of monitor_replicas.py, none of them the monitor's own formula but eq19), a
new draw per update. Counted per truth: the instant test's alarms, its "told
apart" statements (JSON separable true on an alarm) and the wrong ones (the
first is not the truth), and the commissionings with a wrong one; the wrong
pairs are listed. The rule's stated rate (rcb_monitor_named): at most
RCB_MONITOR_APART_ALPHA (0.001) per update for every pair with the noise as
declared; the counts are set against the binomial 99 % bound of that rate
over the alarmed updates, and of 5 % over the statements.

    OPENBLAS_NUM_THREADS=1 LIBRCB_PATH=build/src/librcb.so nice -n 5 \\
      .venv/bin/python tools/bench/monitor_pairs.py [--blocks 8] [--updates 5] \\
      [--truths B4.kyy,gain.DA.x,...] [--out out/monitor_pairs] [--list]
"""

import argparse
import functools
import json
import math
import sys
import time
import warnings
from pathlib import Path

import numpy as np
from scipy import stats

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "tests" / "python"))
sys.path.insert(0, str(REPO / "tools" / "python"))
sys.path.insert(0, str(REPO / "tools" / "bench"))
warnings.simplefilter("ignore")

import diag_cases as dc  # noqa: E402
import monitor_replicas as mr  # noqa: E402
import ross_models as rm  # noqa: E402

SIZES = (3.0, 4.0, 5.0, 6.0, 8.0)  # the truth's size, its per-update sd
FORMS = ("eq19", "high", "literal", "phase")
APART_ALPHA = 0.001  # rcb_monitor.h RCB_MONITOR_APART_ALPHA


# --------------------------------------------------------------------------
# truths: name -> (kind, build, is_truth)
# --------------------------------------------------------------------------


def _nominal(section, name, key):
    model = rm.Model(dc.BASE_INI)
    d = dc._bearing(model, name) if section == "bearing" else model.couplings[0][3]
    return float(d[key][-1]) if key in d else 0.0


def _model_truth(edit_at, v0, v1, v2):
    """v -> clean H (32 x 1101) for a parameter the ROSS matrices are affine
    in (M, C, K and G, from builds at v0 and v1, checked at v2)."""
    (a, rows, cols, speed), (b, _, _, _), (c, _, _, _) = (mr._matrices(edit_at(v)) for v in
                                                       (v0, v1, v2))
    mats = lambda v: tuple(x + (v - v0) / (v1 - v0) * (y - x) for x, y in zip(a, b))  # noqa: E731
    for x, y in zip(mats(v2), c):
        err = np.max(np.abs(x - y)) / max(np.max(np.abs(y)), 1e-300)
        assert err < 1e-12, f"ROSS matrices are not affine in the parameter ({err:.3e})"
    return lambda v: mr._solve(mats(v), rows, cols, speed)


def _rows(response):
    return [q * len(dc.OUTS) + dc.OUTS.index(response) for q in range(len(mr.INS))]


def truths():
    """{name: (kind, nominal, make, is_truth, (index, factor))}: make(H0) -> v ->
    clean H, or (H0, the chain's edit after the noise); is_truth(candidate
    dict) -> bool; the truth's sd is the candidate's parameter index's sd over
    factor (the parameter's units per unit of v)."""
    out = {}
    for b in ("B1", "B2", "B3", "B4"):
        for key in ("kxx", "kyy"):
            v0 = _nominal("bearing", b, key)
            out[f"{b}.{key}"] = ("model", v0,
                                 lambda H0, b=b, key=key, v0=v0: _model_truth(
                                     lambda v: dc.bearing_keys(b, **{key: v}), v0, 0.5 * v0,
                                     0.8 * v0),
                                 lambda d, b=b, key=key: d["params"] == f"bearing.{b}.{key}",
                                 (0, 1.0))
        out[f"{b}.kcross"] = ("model", 0.0,
                              lambda H0, b=b: _model_truth(
                                  lambda v: dc.bearing_keys(b, kxy=v, kyx=-v), 0.0, 1e7, 3e6),
                              lambda d, b=b: d["params"] == f"bearing.{b}.kcross", (0, 1.0))
        cx, cy = _nominal("bearing", b, "cxx"), _nominal("bearing", b, "cyy")
        # both coefficients by 1 + s: the parameter is s
        out[f"{b}.damping"] = ("model", 0.0,
                               lambda H0, b=b, cx=cx, cy=cy: _model_truth(
                                   lambda s: dc.bearing_keys(b, cxx=cx * (1 + s),
                                                             cyy=cy * (1 + s)), 0.0, 0.5, 0.2),
                               lambda d, b=b: d["params"] == f"bearing.{b}.cxx, bearing.{b}.cyy",
                               (0, cx))
    cr = _nominal("coupling", "C", "cr")
    out["C.cr"] = ("model", cr, lambda H0: _model_truth(
        lambda v: dc.coupling_keys(cr=v), cr, cr + 1.0, cr + 0.3),
        lambda d: d["params"] == "coupling.C.cr", (0, 1.0))
    out["C.hub"] = ("model", 0.0, lambda H0: _model_truth(
        lambda s: dc.hub_mass_edit(_hub_mass() * (1 + s)), 0.0, 0.5, 0.2),
        lambda d: d["effect"] == dc.HUB, (0, _hub_mass()))
    for disk in ("DA", "DB"):
        out[f"mass.{disk}"] = ("model", 0.0, lambda H0, disk=disk: _model_truth(
            lambda m: _mass_at_disk(disk, m), 0.0, 0.2, 0.05),
            lambda d, disk=disk: d["effect"] == dc.MASS and f"disk {disk}" in d["place"],
            (0, 1.0))
    for spec, node in (("A 0.3", "node #6 "), ("B 0.72", "node #15 ")):
        out[f"mass.{spec.replace(' ', '')}"] = ("model", 0.0, lambda H0, spec=spec: _model_truth(
            lambda m: dc.point_mass_edit(spec, m), 0.0, 0.2, 0.05),
            lambda d, node=node: d["effect"] == dc.MASS and d["place"].startswith(node),
            (0, 1.0))
    out["C.hubId"] = ("model", 0.0, lambda H0: _model_truth(
        lambda s: dc.hub_inertia_edit(1 + s), 0.0, 0.5, 0.2),
        lambda d: d["params"] == "coupling.C.hub_Id", (0, _hub_id()))
    for shaft in ("A", "B"):
        beta = _shaft_beta(shaft)
        out[f"shaft.{shaft}.damping"] = ("model", beta, lambda H0, shaft=shaft, beta=beta:
                                         _model_truth(lambda v: _beta_edit(shaft, v), beta,
                                                      beta + 1e-5, beta + 3e-6),
                                         lambda d, shaft=shaft:
                                         d["params"] == f"shaft.{shaft}.damping_stiffness",
                                         (0, 1.0))
    out["speed"] = ("model", 0.0, lambda H0: _speed_truth(),
                    lambda d: d["params"] == "speed.factor", (0, 1.0))
    for probe in ("DA.x", "DA.y", "DB.x", "DB.y"):
        out[f"gain.{probe}"] = ("chain", 0.0, lambda H0, probe=probe: _chain(
            H0, lambda data, g: _scaled(data, probe, 1 + g)),
            lambda d, probe=probe: d["effect"] == dc.SENSOR and d["place"] == f"sensor {probe}",
            (0, 1.0))
    for probe in ("C.A.x", "DB.y"):
        out[f"phase.{probe}"] = ("chain", 0.0, lambda H0, probe=probe: _chain(
            H0, lambda data, ph: _scaled(data, probe, np.exp(1j * ph))),
            lambda d, probe=probe: d["effect"] == dc.SENSOR and d["place"] == f"sensor {probe}",
            (1, 1.0))
    for b in ("B1", "B4"):
        out[f"pedestal.{b}"] = ("lambda", 0.0, lambda H0, b=b: _pedestal_truth(b),
                                lambda d, b=b: d["effect"] == dc.PEDESTAL and
                                d["place"] == f"bearing {b}", None)
    for a, b in (("DA.x", "DA.y"), ("C.B.x", "C.B.y")):
        out[f"swap.{a}.{b}"] = ("swap", 1.0, lambda H0, a=a, b=b: _chain(
            H0, lambda data, f: dc.swap_edit(a, b)(data)),
            lambda d, a=a, b=b: d["effect"] == dc.SWAP and a in d["place"] and b in d["place"],
            None)
    return out


def _shaft_beta(name):
    return next(sh.beta for sh in rm.Model(dc.BASE_INI).shafts if sh.name == name)


def _beta_edit(name, beta):
    """model_edit: shaft NAME's stiffness-proportional damping beta (s)."""

    def edit(model):
        next(sh for sh in model.shafts if sh.name == name).beta = beta

    return edit


def _pedestal_truth(bearing):
    """v -> clean H with bearing on a pedestal of dc.PEDESTAL_B4's mass and
    damping and stiffness 1/v (N/m; v = 0: none), one ROSS build each."""
    ped = dc.PEDESTAL_B4

    @functools.lru_cache(maxsize=None)
    def at(v):
        if v == 0:
            return mr._solve(*mr._matrices())
        return mr._solve(*mr._matrices(dc.bearing_keys(
            bearing, pedestal_mass=ped["pedestal_mass"], pedestal_kxx=1.0 / v,
            pedestal_kyy=1.0 / v, pedestal_cxx=ped["pedestal_cxx"],
            pedestal_cyy=ped["pedestal_cyy"])))

    return at


def clean_update(rcb, model, H0, H):
    """The result of one clean update H against the clean reference H0 (the
    commissioning exact: setup_averages 1e9)."""
    with mr._meas(rcb, H0) as setup:
        mon = rcb.Monitor(model, setup, mr.PARAMS, noise=mr.FORMS["eq19"],
                          setup_averages=1e9, alpha=mr.ALPHA, reweight=True, relinearise=8,
                          sensors=True)
    try:
        with mr._meas(rcb, H) as ms:
            return mon.update(ms)
    finally:
        mon.close()


def clean_T(rcb, model, H0, H):
    """T of a clean update H against the clean reference H0."""
    return clean_update(rcb, model, H0, H)["T"]


def _speed_truth():
    """s -> clean H at the rotor speed (1 + s) x the test's (the frequencies
    kept): the paper system's bearings do not depend on speed, so only the
    gyroscopic term C + speed G moves."""
    mats, rows, cols, speed = mr._matrices()
    return lambda s: mr._solve(mats, rows, cols, speed * (1.0 + s))


def _hub_mass():
    return dc._hub(rm.Model(dc.BASE_INI))[0]


def _hub_id():
    return dc._hub(rm.Model(dc.BASE_INI))[1]


def _mass_at_disk(name, mass):
    """model_edit: a point mass (kg; no inertia) at disk NAME's station, as
    dc.point_mass_edit places one at a station it is given."""

    def edit(model):
        model.disks.append((f"added_{len(model.disks)}", dc._disk(model, name)[1], mass, 0.0, 0.0))

    return edit


def _scaled(data, probe, factor):
    data = np.array(data, dtype=complex)
    data[_rows(probe)] *= factor
    return data


def _chain(H0, edit):
    """v -> (H0, the chain's edit at v, applied after the noise)."""
    return lambda v: (H0, lambda data: edit(data, v))


# --------------------------------------------------------------------------
# runs
# --------------------------------------------------------------------------


def _monitor(rcb, model, files, form):
    with mr._meas(rcb, files.mean(axis=0)) as setup:
        ns = rcb.monitor.noise_scale(setup, files, noise=mr.FORMS[form])["scale"]
        return rcb.Monitor(model, setup, mr.PARAMS, noise=mr.FORMS[form],
                           setup_averages=mr.COMMISSION, alpha=mr.ALPHA, reweight=True,
                           relinearise=8, noise_scale=ns, sensors=True)


def _data(at, v, form, seed):
    """One noisy measurement of the truth at v."""
    out = at(v)
    H, after = out if isinstance(out, tuple) else (out, None)
    data = dc.calibration_noise(form, H, seed)
    return after(data) if after else data


def per_update_sd(rcb, model, H0, at, v_small, is_truth, conv):
    """The truth's per-update sd (parameter units): the interval of its first
    ranked candidate on a clean update at v_small, the reference clean."""
    out = at(v_small)
    H, after = out if isinstance(out, tuple) else (out, None)
    r = clean_update(rcb, model, H0, after(H) if after else H)
    i, factor = conv
    for c in r["top"]:
        if is_truth(c):
            return (c["ci_hi"][i] - c["ci_lo"][i]) / (2 * 1.959963984540054) / factor
    raise RuntimeError("the truth is not among the ranked candidates of a clean update: "
                       + ", ".join(c["params"] for c in r["top"]))


def run_truth(rcb, model, name, spec, H0, blocks, updates, seed0):
    kind, v0, make, is_truth, conv = spec
    at = make(H0)
    t0 = time.process_time()
    if kind == "swap":
        sd, sizes = None, [1.0]
    elif kind == "lambda":
        v1 = 1e-12  # m/N (a pedestal of 1e12 N/m): T = 2.0 there, 195 at 1e-11
        sd = v1 / math.sqrt(clean_T(rcb, model, H0, at(v1)))
        sizes = [s * sd for s in SIZES]
        # T grows as v^2 there: the largest size's clean T against SIZES[-1]^2
        print(f"# {name}: clean T {clean_T(rcb, model, H0, at(sizes[-1])):.1f} at "
              f"{SIZES[-1]:g} sd (v^2: {SIZES[-1] ** 2:g})", flush=True)
    else:
        # a clean change well above the two models' difference (ROSS's H0 and
        # librcb's baseline): 1 % of the nominal, 1e5 N/m of kcross, 0.01 else
        small = (1e-6 if name.startswith("shaft.") else 0.01 * abs(v0) if v0 else
                 1e5 if name.endswith("kcross") else 0.01)
        sd = per_update_sd(rcb, model, H0, at, v0 + small, is_truth, conv)
        sizes = [v0 - s * sd if name.endswith(("kxx", "kyy")) else v0 + s * sd for s in SIZES]
    rec = {"truth": name, "sd": sd, "sizes": sizes, "blocks": []}
    for blk in range(blocks):
        form = FORMS[blk % len(FORMS)]
        seed = seed0 + 1000 * blk
        files = np.array([dc.calibration_noise(form, H0, seed + i) for i in range(mr.COMMISSION)])
        mon = _monitor(rcb, model, files, form)
        b = {"form": form, "alarms": 0, "apart": 0, "wrong": [], "named_right": 0}
        try:
            j = 0
            for v in sizes:
                for _ in range(updates):
                    j += 1
                    with mr._meas(rcb, _data(at, v, form, seed + mr.COMMISSION + j)) as ms:
                        r = mon.update(ms)
                    if not r["alarm"] or not r["top"]:
                        continue
                    b["alarms"] += 1
                    first = r["top"][0]
                    b["named_right"] += bool(is_truth(first))
                    if r["separable"]:
                        b["apart"] += 1
                        if not is_truth(first):
                            b["wrong"].append([first["params"], v])
        finally:
            mon.close()
        rec["blocks"].append(b)
    rec["cpu"] = time.process_time() - t0
    return rec


def binom_upper(n, p):
    return int(stats.binom.ppf(0.99, n, p)) if n else 0


def summary(recs):
    rows, tot = [], {"alarms": 0, "apart": 0, "wrong": 0, "blocks": 0, "blocks_wrong": 0}
    for rec in recs:
        al = sum(b["alarms"] for b in rec["blocks"])
        ap = sum(b["apart"] for b in rec["blocks"])
        wr = sum(len(b["wrong"]) for b in rec["blocks"])
        bw = sum(bool(b["wrong"]) for b in rec["blocks"])
        right = sum(b["named_right"] for b in rec["blocks"])
        pairs = sorted({w[0] for b in rec["blocks"] for w in b["wrong"]})
        rows.append((rec["truth"], rec["sd"], al, right, ap, wr, binom_upper(al, APART_ALPHA),
                     binom_upper(ap, 0.05), bw, len(rec["blocks"]), pairs, rec["cpu"]))
        tot["alarms"] += al
        tot["apart"] += ap
        tot["wrong"] += wr
        tot["blocks"] += len(rec["blocks"])
        tot["blocks_wrong"] += bw
    return rows, tot


def print_table(rows, tot):
    print("| truth | sd | alarms | first right | told apart | wrong (bound per update, "
          "per statement) | commissionings with a wrong one | wrong pairs (named) |")
    print("|---|---|---|---|---|---|---|---|")
    for t, sd, al, right, ap, wr, bu, bs, bw, nb, pairs, _ in rows:
        print(f"| {t} | {'-' if sd is None else f'{sd:.4g}'} | {al} | {right} | {ap} | "
              f"{wr} ({bu}, {bs}) | {bw} of {nb} | {'; '.join(pairs) or '-'} |")
    print(f"| all | | {tot['alarms']} | | {tot['apart']} | {tot['wrong']} "
          f"({binom_upper(tot['alarms'], APART_ALPHA)}, {binom_upper(tot['apart'], 0.05)}) | "
          f"{tot['blocks_wrong']} of {tot['blocks']} | |")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--blocks", type=int, default=8, help="commissionings per truth")
    ap.add_argument("--updates", type=int, default=5, help="updates per size and commissioning")
    ap.add_argument("--truths", default="", help="comma-separated names (default: all)")
    ap.add_argument("--out", default=str(REPO / "out" / "monitor_pairs"))
    ap.add_argument("--list", action="store_true", help="the truths and the monitor's "
                    "catalogue, and stop")
    ap.add_argument("--from-json", action="store_true", help="no runs: the table of OUT/pairs.json")
    args = ap.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    path = out / "pairs.json"
    if args.from_json:
        print_table(*summary(json.loads(path.read_text())))
        return 0
    import librcb as rcb

    every = truths()
    names = [n for n in args.truths.split(",") if n] or list(every)
    for n in names:
        if n not in every:
            ap.error(f"--truths: no truth '{n}' (one of {', '.join(every)})")
    ini = out / "model.ini"
    ini.write_text(dc.BASE_INI)
    H0 = dc.ross_inertance(dc.BASE_INI, None, freq=mr.FREQ, ins=mr.INS)
    recs = json.loads(path.read_text()) if path.is_file() else []
    done = {r["truth"] for r in recs}
    model = rcb.Model.from_ini(ini)
    if args.list:
        with mr._meas(rcb, H0) as setup:
            mon = rcb.Monitor(model, setup, mr.PARAMS, noise=mr.FORMS["eq19"],
                              setup_averages=1e9, sensors=True)
        for i in range(mon.candidate_count()):
            c = mon.candidate(i)
            print(f"{i:3d} {c['effect']:32s} {c['place']:40s} {c['params']}")
        mon.close()
        print("truths:", ", ".join(every))
        return 0
    for n in names:
        if n in done:
            continue
        rec = run_truth(rcb, model, n, every[n], H0, args.blocks, args.updates,
                        7000000 + 100000 * list(every).index(n))
        recs.append(rec)
        tmp = path.with_suffix(".tmp")
        tmp.write_text(json.dumps(recs))
        tmp.replace(path)
        rows, _ = summary([rec])
        t, sd, al, right, apn, wr = rows[0][:6]
        print(f"# {t}: sd {sd}, alarms {al}, first right {right}, told apart {apn}, "
              f"wrong {wr} ({rec['cpu']:.0f} s CPU)", flush=True)
    print_table(*summary([r for r in recs if r["truth"] in names]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
