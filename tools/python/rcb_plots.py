#!/usr/bin/env python3
"""Pictures of librcb results, drawn with matplotlib from rcbtool's JSON.

    rcb_plots.py compare COMPARE.json PREFIX
    rcb_plots.py estimate ESTIMATE.json FILE.png
    rcb_plots.py order ORDER.json FILE.png
    rcb_plots.py monitor MONITOR.json OUT [FORMAT]

reads the JSON of `rcbtool compare --json` (rcbtool compare --plot PREFIX runs
this script itself) and writes
  PREFIX_overlay.png       measured vs model magnitude (log axis) and phase per
                           channel, the worst frequency bands shaded, measured
                           peaks without a model mode and model-only resonances
                           marked;
  PREFIX_residual_map.png  RMS log10 magnitude error per channel and band, with
                           CSAC and CSF across channels against frequency.
`rcbtool estimate --plot FILE.png` and `rcbtool order --plot FILE.png` run the
estimate and order kinds on their own JSON (written to a temporary file):
  estimate: magnitude (log axis, with the +-2 sd band of each line) and phase
            of every FRF, its coherence below;
  order:    Bode plot (amplitude, phase against speed) and polar plot of the
            1X vectors of every channel.

The monitor kind reads the JSON of `rcbtool monitor --json` (or its --log .json;
rcbtool monitor --plot OUT runs this script itself) and writes the trend OUT
(FORMAT png, pdf or svg; by default from OUT's extension): each tracked
parameter with its 95 % band against the update (CUSUM alarms as dots), the
instant test statistic over its threshold (log axis) with the alarm line at 1
(TEST alarms as dots), and the moments of change marked as vertical lines: the
first update of every run of two or more alarmed updates, with the effect and
place the TEST named (a lone alarm, as a false alarm looks, is a dot only).
Exit codes: 0 written, 2 usage, 3 matplotlib missing, 4 bad JSON, 5 not written.
"""

import json
import math
import sys

MAX_CHANNELS = 12  # overlay panels; the worst channels (by error %) beyond that


def _units(ch, x_unit):
    """Unit of |H| for a channel (response translation m or rotation rad)."""
    rot = ch["response"].rsplit(".", 1)[-1] in ("rx", "ry")
    disp = "rad" if rot else "m"
    if ch.get("reference") is None:  # unbalance response
        return disp
    force = "N m" if ch["reference"].rsplit(".", 1)[-1] in ("rx", "ry") else "N"
    tail = {"receptance": "", "mobility": " s", "inertance": " s²"}[ch["kind"]]
    return f"{disp}/({force}{tail})" if tail or " " in force else f"{disp}/{force}"


def _mag_phase(re, im):
    mag, ph = [], []
    for a, b in zip(re, im):
        if a is None or b is None:
            mag.append(math.nan)
            ph.append(math.nan)
        else:
            mag.append(math.hypot(a, b))
            ph.append(math.degrees(math.atan2(b, a)))
    return mag, ph


def _xlabel(d):
    return "rotor speed (rpm)" if d["x_unit"] == "rpm" else "frequency (Hz)"


def _title(d):
    what = {"frf": f"FRFs at {d.get('rpm') or 0:g} rpm", "synchronous": "synchronous FRFs",
            "unbalance": "unbalance responses"}[d["type"]]
    s = d["summary"]
    return (f"{d['model']} vs {d['measurement']} ({what}): error {s['error_pct']:.3g} %, "
            f"mean FRAC {s['frac_mean']:.3f}, mean CSAC {s['csac_mean']:.3f}")


def _shade_worst(ax, d, label):
    for k, b in enumerate(d["worst_bands"]):
        band = d["bands"][b]
        ax.axvspan(band["lo"], band["hi"], color="tab:red", alpha=0.12, lw=0,
                   label=label if k == 0 else None)


def _mark_peaks(ax, d):
    first = {"measured_only": True, "model_only": True}
    for p in d["peaks"]:
        if p["match"] == "measured_only":
            ax.axvline(p["meas_x"], color="tab:red", ls="--", lw=0.9,
                       label="measured peak, no model mode" if first[p["match"]] else None)
            first[p["match"]] = False
        elif p["match"] == "model_only" and p["model_visible"]:
            ax.axvline(p["model_x"], color="tab:orange", ls=":", lw=1.2,
                       label="model resonance, not measured" if first[p["match"]] else None)
            first[p["match"]] = False


def overlay(plt, d, path):
    chans = list(enumerate(d["channels"]))
    note = ""
    if len(chans) > MAX_CHANNELS:
        chans.sort(key=lambda kc: -(kc[1]["error_pct"] or 0))
        chans = sorted(chans[:MAX_CHANNELS])
        note = f" — the {MAX_CHANNELS} worst of {len(d['channels'])} channels"
    n = len(chans)
    ncols = 1 if n == 1 else 2 if n <= 4 else 3
    nrows = math.ceil(n / ncols)
    fig, axes = plt.subplots(2 * nrows, ncols, figsize=(5.2 * ncols, 4.6 * nrows),
                             sharex=True, squeeze=False,
                             gridspec_kw={"height_ratios": [2.2, 1] * nrows})
    x = d["x"]
    for slot, (k, ch) in enumerate(chans):
        r, c = divmod(slot, ncols)
        am, ap = axes[2 * r][c], axes[2 * r + 1][c]
        me, pe = _mag_phase(ch["meas_re"], ch["meas_im"])
        mm, pm = _mag_phase(ch["model_re"], ch["model_im"])
        _shade_worst(am, d, "worst bands")
        _shade_worst(ap, d, None)
        am.semilogy(x, me, color="tab:blue", lw=1.0, label="measured")
        am.semilogy(x, mm, color="black", lw=1.2, ls="--", label="model")
        _mark_peaks(am, d)
        ap.plot(x, pe, color="tab:blue", lw=0.8, marker=".", ms=1.5, ls="none")
        ap.plot(x, pm, color="black", lw=0.8, marker=".", ms=1.5, ls="none")
        name = ch["response"] + (f" / {ch['reference']}" if ch.get("reference") else "")
        am.set_title(f"{name}: error {ch['error_pct']:.3g} %, FRAC {ch['frac']:.3f}",
                     fontsize=9)
        am.set_ylabel(f"|{ch['kind'] if ch.get('reference') else 'response'}| "
                      f"({_units(ch, d['x_unit'])})", fontsize=8)
        ap.set_ylabel("phase (deg)", fontsize=8)
        ap.set_ylim(-185, 185)
        ap.set_yticks([-180, -90, 0, 90, 180])
        ap.set_xlabel(_xlabel(d), fontsize=8)
        for ax in (am, ap):
            ax.grid(True, which="both", alpha=0.3)
            ax.tick_params(labelsize=7)
            ax.tick_params(labelbottom=True)
        if slot == 0:
            am.legend(fontsize=7, loc="best")
    for slot in range(n, nrows * ncols):
        r, c = divmod(slot, ncols)
        axes[2 * r][c].set_visible(False)
        axes[2 * r + 1][c].set_visible(False)
    fig.suptitle("Measured vs model" + note + "\n" + _title(d), fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def residual_map(plt, d, path):
    import numpy as np

    chans = d["channels"]
    m = np.array([[math.nan if v is None else v for v in row] for row in d["residual_map"]])
    nb = len(d["bands"])
    fig, (ax, ax2) = plt.subplots(2, 1, figsize=(max(7.0, 0.75 * nb + 3), 2.6 + 0.32 * len(chans)
                                                 + 2.2),
                                  gridspec_kw={"height_ratios": [max(2.0, 0.32 * len(chans)),
                                                                 2.0]})
    im = ax.imshow(m, aspect="auto", cmap="magma_r", vmin=0.0,
                   vmax=max(0.05, float(np.nanmax(m)) if np.isfinite(m).any() else 0.05),
                   interpolation="nearest")
    cb = fig.colorbar(im, ax=ax, pad=0.01)
    cb.set_label("RMS log10 |H| error (decades)", fontsize=8)
    ax.set_yticks(range(len(chans)))
    ax.set_yticklabels([c["response"] + (f"/{c['reference']}" if c.get("reference") else "")
                        for c in chans], fontsize=7)
    ax.set_xticks(range(nb))
    ax.set_xticklabels([f"{b['lo']:.4g}-\n{b['hi']:.4g}" for b in d["bands"]], fontsize=7)
    ax.set_xlabel(f"band ({d['x_unit']})", fontsize=8)
    if m.size <= 400:
        for (i, j), v in np.ndenumerate(m):
            if math.isfinite(v):
                ax.text(j, i, f"{v:.2f}", ha="center", va="center", fontsize=6,
                        color="white" if v > 0.6 * im.get_clim()[1] else "black")
    for b in d["worst_bands"]:
        ax.add_patch(plt.Rectangle((b - 0.5, -0.5), 1, len(chans), fill=False,
                                   ec="tab:blue", lw=2))
    ax.set_title("Residual map: where the model fails (worst bands framed)\n" + _title(d),
                 fontsize=9)
    x = d["x"]
    csac = [math.nan if v is None else v for v in d["csac"]]
    csf = [math.nan if v is None else v for v in d["csf"]]
    _shade_worst(ax2, d, "worst bands")
    ax2.plot(x, csac, lw=1.0, label="CSAC (shape)")
    ax2.plot(x, csf, lw=1.0, ls="--", label="CSF (scale)")
    ax2.set_ylim(-0.02, 1.05)
    ax2.set_xlim(x[0], x[-1])
    ax2.set_xlabel(_xlabel(d), fontsize=8)
    ax2.set_ylabel("across channels (-)", fontsize=8)
    ax2.grid(True, alpha=0.3)
    ax2.legend(fontsize=7, loc="lower left")
    ax2.tick_params(labelsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def estimate_plot(plt, d, path):
    """FRF magnitude and phase with the coherence below (rcbtool estimate --plot)."""
    fig, (am, ap, ac) = plt.subplots(3, 1, sharex=True, figsize=(9, 9),
                                     gridspec_kw={"height_ratios": [3, 2, 1.5]})
    f = d["freq_hz"]
    for ch in d["channels"][:MAX_CHANNELS]:
        mag, ph = _mag_phase(ch["re"], ch["im"])
        sd = [math.nan if v is None else v for v in ch["sd"]]
        ch["coh"] = [math.nan if v is None else v for v in ch["coh"]]
        lo = [max(m - 2 * s, m * 1e-3) for m, s in zip(mag, sd)]
        hi = [m + 2 * s for m, s in zip(mag, sd)]
        (line,) = am.semilogy(f, mag, lw=1, label=ch["name"])
        am.fill_between(f, lo, hi, color=line.get_color(), alpha=0.2, lw=0)
        ap.plot(f, ph, lw=1, color=line.get_color())
        ac.plot(f, ch["coh"], lw=1, color=line.get_color())
    am.set_ylabel(f"|H| ({d['kind']}, SI)")
    am.legend(fontsize="small", ncol=2)
    am.set_title(f"{d['estimator'].upper()} from {d['averages']} averages, +-2 sd shaded")
    ap.set_ylabel("phase (deg)")
    ac.set_ylabel("coherence")
    ac.set_ylim(0, 1.05)
    ac.set_xlabel("frequency (Hz)")
    for ax in (am, ap, ac):
        ax.grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110, format="png")
    plt.close(fig)


def order_plot(plt, d, path):
    """Bode and polar plot of the 1X vectors (rcbtool order --plot)."""
    fig = plt.figure(figsize=(12, 6))
    am = fig.add_subplot(2, 2, 1)
    ap = fig.add_subplot(2, 2, 3, sharex=am)
    pol = fig.add_subplot(1, 2, 2)
    r = d["rpm"]
    for ch in d["channels"][:MAX_CHANNELS]:
        mag, ph = _mag_phase(ch["re"], ch["im"])
        (line,) = am.plot(r, mag, lw=1, label=ch["name"])
        ap.plot(r, ph, lw=1, color=line.get_color())
        re = [math.nan if v is None else v for v in ch["re"]]
        im = [math.nan if v is None else v for v in ch["im"]]
        pol.plot(re, im, lw=1, color=line.get_color(), label=ch["name"])
        pol.plot(re[:1], im[:1], "o", ms=3, color=line.get_color())
    am.set_ylabel(f"{d['order']}X amplitude (m)")
    am.legend(fontsize="small")
    am.set_title(f"Bode plot, {d['order']}X")
    ap.set_ylabel("phase (deg)")
    ap.set_xlabel("speed (rpm)")
    pol.set_aspect("equal", adjustable="datalim")
    pol.axhline(0, color="k", lw=0.5)
    pol.axvline(0, color="k", lw=0.5)
    pol.set_xlabel("Re (m)")
    pol.set_ylabel("Im (m)")
    pol.set_title(f"polar plot, {d['order']}X (dot: lowest speed)")
    for ax in (am, ap, pol):
        ax.grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110, format="png")
    plt.close(fig)


KINDS = {"estimate": ("freq_hz", estimate_plot), "order": ("rpm", order_plot)}


def _changes(ups):
    """The moments of change: the first update of every run of two or more
    consecutive alarmed updates (TEST or CUSUM; a lone alarm is drawn as a dot
    only, as a false alarm at the rate asked for looks), with what it was."""
    out, run = [], []
    for u in ups + [None]:
        if u is not None and (u["alarm"] or u["cusum_alarm"]):
            run.append(u)
            continue
        if len(run) >= 2:
            first = run[0]
            what = "CUSUM" if not first["alarm"] else "TEST"
            t = next((v for v in run if v["alarm"] and v["top"]), None)
            name = f": {t['top'][0]['effect']} at {t['top'][0]['place']}" if t else ""
            out.append((first["update"], what + name))
        run = []
    return out


def trend(plt, d, path, fmt=None):
    ups = d["updates"]
    names = [t["name"] for t in d["tracked"]]
    x = [u["update"] for u in ups]
    fig, axes = plt.subplots(len(names) + 1, 1, figsize=(9, 2.4 * (len(names) + 1) + 0.6),
                             sharex=True, squeeze=False)
    axes = axes[:, 0]
    changes = _changes(ups)
    for k, (ax, name) in enumerate(zip(axes, names)):
        v = [u["tracked"][k]["value"] for u in ups]
        lo = [u["tracked"][k]["ci_lo"] for u in ups]
        hi = [u["tracked"][k]["ci_hi"] for u in ups]
        ax.fill_between(x, lo, hi, color="tab:blue", alpha=0.25, lw=0, label="95 % interval")
        ax.plot(x, v, color="tab:blue", lw=1.0, label="estimate")
        ax.axhline(d["tracked"][k]["baseline"], color="k", ls="--", lw=0.8, label="baseline")
        cu = [(xi, vi) for xi, vi, u in zip(x, v, ups) if u["tracked"][k]["cusum_alarm"]]
        if cu:
            ax.plot(*zip(*cu), ".", color="tab:orange", ms=4, label="CUSUM alarm")
        ax.set_ylabel(name, fontsize=8)
        ax.grid(True, alpha=0.3)
        ax.tick_params(labelsize=7)
    ax = axes[-1]
    ratio = [u["T"] / u["threshold"] if u["T"] is not None and u["threshold"] else math.nan
             for u in ups]
    ax.semilogy(x, [max(r, 1e-3) for r in ratio], ".-", color="tab:gray", lw=0.7, ms=3,
                label="T / threshold")
    al = [(xi, max(r, 1e-3)) for xi, r, u in zip(x, ratio, ups) if u["alarm"]]
    if al:
        ax.semilogy(*zip(*al), "o", color="tab:red", ms=4, label="TEST alarm")
    ax.axhline(1.0, color="tab:red", lw=1.0, label=f"alarm line (alpha {d.get('alpha') or 0:.2g})")
    ax.set_ylabel("T / threshold (-)", fontsize=8)
    ax.set_xlabel("update", fontsize=8)
    ax.grid(True, alpha=0.3, which="both")
    ax.tick_params(labelsize=7)
    for a in axes:
        for k, (at, what) in enumerate(changes):
            a.axvline(at, color="tab:red", ls=":", lw=1.2,
                      label=f"change at update {at} ({what})" if a is axes[-1] else
                      ("change" if k == 0 else None))
        a.legend(fontsize=6, loc="best")
    model = str(d["model"]).rsplit("/", 1)[-1]
    n_alarm = sum(1 for u in ups if u["alarm"])
    axes[0].set_title(f"{model}: {len(ups)} updates, {n_alarm} TEST alarms, "
                      f"{len(changes)} change(s) marked", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110, format=fmt)
    plt.close(fig)


def _matplotlib():
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError as e:
        print(f"rcb_plots.py: matplotlib is not available to {sys.executable}: {e}",
              file=sys.stderr)
        return None
    return plt


def main_monitor(argv):
    plt = _matplotlib()
    if plt is None:
        return 3
    try:
        with open(argv[2]) as f:
            d = json.load(f)
        d["updates"][0]["tracked"]
        d["tracked"]
    except (OSError, ValueError, KeyError, IndexError) as e:
        print(f"rcb_plots.py: cannot read {argv[2]} as rcbtool monitor JSON: {e}",
              file=sys.stderr)
        return 4
    out = argv[3]
    fmt = argv[4] if len(argv) > 4 else None
    try:
        trend(plt, d, out, fmt)
    except OSError as e:
        print(f"rcb_plots.py: cannot write the picture: {e}", file=sys.stderr)
        return 5
    return 0


def main(argv):
    if len(argv) in (4, 5) and argv[1] == "monitor":
        return main_monitor(argv)
    if len(argv) != 4 or argv[1] not in ("compare", *KINDS):
        print("usage: rcb_plots.py compare COMPARE.json PREFIX\n"
              "       rcb_plots.py estimate|order DATA.json FILE.png\n"
              "       rcb_plots.py monitor MONITOR.json OUT [FORMAT]", file=sys.stderr)
        return 2
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError as e:
        print(f"rcb_plots.py: matplotlib is not available to {sys.executable}: {e}",
              file=sys.stderr)
        return 3
    try:
        with open(argv[2]) as f:
            d = json.load(f)
        d["channels"][0]
        if argv[1] in KINDS:
            d[KINDS[argv[1]][0]][0]
    except (OSError, ValueError, KeyError, IndexError) as e:
        print(f"rcb_plots.py: cannot read {argv[2]} as rcbtool {argv[1]} JSON: {e}",
              file=sys.stderr)
        return 4
    if argv[1] in KINDS:
        try:
            KINDS[argv[1]][1](plt, d, argv[3])
        except OSError as e:
            print(f"rcb_plots.py: cannot write the picture: {e}", file=sys.stderr)
            return 5
        return 0
    prefix = argv[3]
    try:
        overlay(plt, d, prefix + "_overlay.png")
        residual_map(plt, d, prefix + "_residual_map.png")
    except OSError as e:
        print(f"rcb_plots.py: cannot write the pictures: {e}", file=sys.stderr)
        return 5
    print(f"rcb_plots.py: wrote {prefix}_overlay.png and {prefix}_residual_map.png",
          file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
