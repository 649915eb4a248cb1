"""Pictures of librcb results with matplotlib (every number comes from the C
library through the analyses of this package).

    campbell_figure(cb)           Campbell diagram, whirl colours, 1X line, critical speeds,
                                  and the log decrement against speed
    mode_shapes_figure(md)        damped mode shapes: the orbit of every node along the
                                  shaft (3D), forward / backward whirl coloured
    frf_figure(f_hz, H, ...)      FRF magnitude (log axis) and phase
    unbalance_figure(rpm, Q, ...) unbalance response amplitude and phase against speed

Each returns a matplotlib Figure (save it with fig.savefig(path)). Colours:
forward whirl blue, backward whirl red, mixed grey, as in most rotordynamics
texts and in ROSS.
"""

import math

import numpy as np

FORWARD, BACKWARD, MIXED = "tab:blue", "tab:red", "0.55"
WHIRL_COLOUR = {1: FORWARD, -1: BACKWARD, 0: MIXED,
                "forward": FORWARD, "backward": BACKWARD, "mixed": MIXED}
_KIND_SUFFIX = {"receptance": "", "mobility": " s", "inertance": " s²"}


def _plt():
    import matplotlib.pyplot as plt
    return plt


def _unit(channel, kind="receptance"):
    """Unit of a channel 'RESP/REF' (FRF) or 'RESP' (unbalance response)."""
    resp, _, ref = channel.partition("/")
    num = "rad" if resp.endswith((".rx", ".ry")) else "m"
    if not ref:
        return num
    den = ("N m" if ref.endswith((".rx", ".ry")) else "N") + _KIND_SUFFIX[kind]
    return f"{num}/({den})" if " " in den else f"{num}/{den}"


def _whirl_legend(ax, extra=()):
    from matplotlib.lines import Line2D
    handles = [Line2D([], [], color=FORWARD, lw=2, label="forward whirl"),
               Line2D([], [], color=BACKWARD, lw=2, ls="--", label="backward whirl"),
               Line2D([], [], color=MIXED, lw=2, label="mixed whirl")]
    ax.legend(handles=handles + list(extra), fontsize=8, loc="upper left", framealpha=0.9)


def _coloured_curves(ax, x, Y, whirl):
    """Each column of Y against x, segment by segment in the colour of its whirl
    (the library does not track modes across speeds, so colour follows whirl);
    backward whirl dashed and drawn last, so a backward curve lying on a forward
    one (weak gyroscopic split) stays visible."""
    from matplotlib.collections import LineCollection
    groups = {1: [], 0: [], -1: []}
    for k in range(Y.shape[1]):
        for i in range(len(x) - 1):
            y0, y1 = Y[i, k], Y[i + 1, k]
            if np.isfinite(y0) and np.isfinite(y1):
                w = int(whirl[i, k]) if whirl[i, k] == whirl[i + 1, k] else 0
                groups[w].append([(x[i], y0), (x[i + 1], y1)])
    for w in (1, 0, -1):
        if groups[w]:
            ax.add_collection(LineCollection(groups[w], colors=WHIRL_COLOUR[w],
                                             linewidths=1.6,
                                             linestyles="--" if w == -1 else "-"))


def _critical_whirl(cb):
    """Whirl of the curve crossing at each critical speed (at the nearest row)."""
    out = []
    for c, k in zip(cb.critical_rpm, cb.critical_mode):
        i = int(np.argmin(np.abs(np.asarray(cb.rpm) - c)))
        out.append(int(cb.whirl[i, k]))
    return out


def forward_critical_rpm(cb):
    """The critical speeds of a Campbell result whose crossing mode whirls
    forward: those an unbalance excites (with isotropic bearings)."""
    return [c for c, w in zip(cb.critical_rpm, _critical_whirl(cb)) if w == 1]


def campbell_figure(cb, title=None, fmax_hz=None):
    """Campbell diagram from librcb.campbell(...): damped natural frequencies
    against rotor speed, coloured by whirl, the excitation line (1X), the
    critical speeds circled on it; log decrement against speed below."""
    plt = _plt()
    fig, (ax, axd) = plt.subplots(2, 1, figsize=(8, 7.5), sharex=True,
                                  gridspec_kw={"height_ratios": [3, 1.2]})
    rpm, fd = np.asarray(cb.rpm), np.asarray(cb.fd_hz)
    _coloured_curves(ax, rpm, fd, cb.whirl)
    top = fmax_hz or 1.15 * np.nanmax(fd)
    xline = np.array([rpm[0], rpm[-1]])
    exc_name = "1X" if cb.ratio == 1 else f"{cb.ratio:g}X"
    ax.plot(xline, cb.ratio * xline / 60.0, color="k", ls=(0, (6, 2, 1, 2)), lw=1.1)
    crit = np.asarray(cb.critical_rpm)
    cw = _critical_whirl(cb)
    crit_handle = None
    for c, w in sorted(zip(crit, cw), key=lambda cw_: -cw_[1]):
        # filled: forward criticals (an unbalance excites them); hollow: backward
        crit_handle = ax.plot([c], [cb.ratio * c / 60.0], "o", ms=9, mew=1.6, mec="k",
                              mfc=WHIRL_COLOUR[w] if w == 1 else "none",
                              label="critical speed (filled: forward)")[0]
        ax.axvline(c, color="k", lw=0.6, ls=":", alpha=0.6)
    if len(crit):
        names = {1: "forward", -1: "backward", 0: "mixed"}
        table = "\n".join(f"{c:7.0f} rpm  {names[w]:8s}" for c, w in zip(crit, cw))
        ax.text(0.985, 0.03, f"critical speeds ({exc_name})\n{table}", transform=ax.transAxes,
                ha="right", va="bottom", fontsize=8, family="monospace",
                bbox=dict(boxstyle="round", fc="white", ec="0.6", alpha=0.9))
    ax.set_xlim(rpm[0], rpm[-1])
    ax.set_ylim(0, top)
    ax.set_ylabel("damped natural frequency (Hz)")
    ax.grid(True, alpha=0.3)
    from matplotlib.lines import Line2D
    extra = [Line2D([], [], color="k", ls=(0, (6, 2, 1, 2)), label=f"{exc_name} excitation")]
    if crit_handle is not None:
        extra.append(crit_handle)
    _whirl_legend(ax, extra)
    ax.set_title(title or f"Campbell diagram: {fd.shape[1]} lowest modes, critical speeds "
                          f"where they cross {exc_name}", fontsize=10)
    ld = np.asarray(cb.logdec)
    for k in range(ld.shape[1]):
        for w in (1, -1, 0):
            sel = cb.whirl[:, k] == w
            if sel.any():
                axd.plot(rpm[sel], ld[sel, k], ".", ms=3, color=WHIRL_COLOUR[w])
    axd.axhline(0.0, color="k", lw=0.8)
    axd.set_ylabel("log decrement (-)")
    axd.set_xlabel("rotor speed (rpm)")
    axd.grid(True, alpha=0.3)
    fig.tight_layout()
    return fig


def _orbits(shape_xy, npts=61):
    """x(t), y(t) over one period for every node: q = Re(Q e^{i theta})."""
    th = np.linspace(0.0, 2 * math.pi, npts)
    e = np.exp(1j * th)
    return np.real(shape_xy[:, 0:1] * e), np.real(shape_xy[:, 1:2] * e)


def node_whirl(shape_xy):
    """Per node: +1 forward, -1 backward (forward radius |X + iY| against the
    backward |X - iY|, the library's rule), 0 for planar motion."""
    fw = np.abs(shape_xy[:, 0] + 1j * shape_xy[:, 1])
    bw = np.abs(shape_xy[:, 0] - 1j * shape_xy[:, 1])
    return np.where(fw > bw * (1 + 1e-6), 1, np.where(bw > fw * (1 + 1e-6), -1, 0))


_STATION_MARK = {"bearing": "^", "disk": "s", "coupling": "D"}


def _draw_mode(ax, md, k, stations):
    xy = md.node_shape(k)
    ox, oy = _orbits(xy)
    z = md.node_z
    w = node_whirl(xy)
    for i in range(len(z)):
        if not np.all(np.isfinite(ox[i])):
            continue
        ax.plot(np.full(ox.shape[1], z[i]), ox[i], oy[i], color=WHIRL_COLOUR[int(w[i])],
                lw=1.0)
        ax.plot([z[i]], [ox[i, 0]], [oy[i, 0]], "o", ms=2.2, color=WHIRL_COLOUR[int(w[i])])
    shafts = list(dict.fromkeys(md.node_shaft))
    for s in shafts:  # the deflected shaft line at theta = 0, one line per shaft
        sel = np.array([sh == s for sh in md.node_shaft])
        ax.plot(z[sel], ox[sel, 0], oy[sel, 0], color="k", lw=1.3)
        ax.plot(z[sel], 0 * z[sel], 0 * z[sel], color="0.6", lw=0.8, ls="-.")
    for st in stations or ():
        mk = _STATION_MARK.get(st.kind)
        if mk:
            ax.plot([st.z], [0], [-1.15], mk, color="0.3", ms=5)
    ax.set_xlabel("z (m)", fontsize=7, labelpad=-2)
    ax.set_ylabel("x (-)", fontsize=7, labelpad=-4)
    ax.set_zlabel("y (-)", fontsize=7, labelpad=-4)
    ax.set_ylim(-1.2, 1.2)
    ax.set_zlim(-1.2, 1.2)
    ax.tick_params(labelsize=6, pad=0)
    ax.set_box_aspect((2.6, 1, 1), zoom=1.35)
    ax.view_init(elev=18, azim=-60)
    wh = md.whirl[k]
    ax.set_title(f"mode {k + 1}: {md.fd_hz[k]:.2f} Hz, ζ = {md.zeta[k]:.4f}\n"
                 f"{wh} whirl", fontsize=9, color=WHIRL_COLOUR[wh])


def mode_shapes_figure(md, modes=None, stations=None, ncols=3, title=None):
    """Damped mode shapes from librcb.modes(...): for each mode, the orbit of
    every node over one period drawn at its axial position (unit largest
    translation), blue where the node whirls forward, red backward; the dot on
    each orbit is its position at t = 0 and the black line the shaft at t = 0.
    stations (model.stations) marks bearings (triangles) and disks (squares)."""
    plt = _plt()
    ks = list(range(len(md))) if modes is None else list(modes)
    n = len(ks)
    ncols = min(ncols, n) if n else 1
    nrows = max(1, math.ceil(n / ncols))
    fig = plt.figure(figsize=(4.8 * ncols, 3.3 * nrows + 0.6))
    for j, k in enumerate(ks):
        ax = fig.add_subplot(nrows, ncols, j + 1, projection="3d")
        _draw_mode(ax, md, k, stations)
    from matplotlib.lines import Line2D
    handles = [Line2D([], [], color=FORWARD, label="forward orbit"),
               Line2D([], [], color=BACKWARD, label="backward orbit"),
               Line2D([], [], color="k", label="shaft at t = 0")]
    if stations:
        handles += [Line2D([], [], ls="none", marker=mk, color="0.3", label=kind)
                    for kind, mk in _STATION_MARK.items()]
    fig.legend(handles=handles, loc="lower center", ncol=len(handles), fontsize=8)
    fig.suptitle(title or f"Damped mode shapes at {md.rpm:g} rpm (orbits along the shaft, "
                          "normalised to unit largest translation)", fontsize=10)
    fig.subplots_adjust(left=0.0, right=0.97, bottom=0.07, top=0.9, wspace=0.02,
                        hspace=0.12)
    return fig


def _phase_axis(ax):
    ax.set_ylim(-185, 185)
    ax.set_yticks([-180, -90, 0, 90, 180])
    ax.set_ylabel("phase (deg)")
    ax.grid(True, alpha=0.3)


def _frf_bode(x, curves, title):
    """Magnitude (log axis) over phase; curves: (label, unit, values)."""
    plt = _plt()
    fig, (am, ap) = plt.subplots(2, 1, figsize=(8, 6.5), sharex=True,
                                 gridspec_kw={"height_ratios": [2.2, 1]})
    for label, _, v in curves:
        line = am.semilogy(x, np.abs(v), lw=1.2, label=label)[0]
        ap.plot(x, np.degrees(np.angle(v)), ".", ms=2, color=line.get_color())
    am.set_ylabel(f"|H| ({', '.join(sorted({u for _, u, _ in curves}))})")
    am.grid(True, which="both", alpha=0.3)
    am.legend(fontsize=8, ncol=2 if len(curves) > 4 else 1)
    _phase_axis(ap)
    ap.set_xlabel("excitation frequency (Hz)")
    ap.set_xlim(x[0], x[-1])
    am.set_title(title, fontsize=10)
    fig.tight_layout()
    return fig


def _speed_text(rpm):
    return "synchronous (rotor speed = excitation)" if rpm is None else f"rotor at {rpm:g} rpm"


def frf_figure(freqs_hz, H, outputs, inputs, kind="receptance", rpm=None, title=None):
    """FRF magnitude (log axis, SI units of the kind) and phase against
    frequency; H as returned by librcb.frf (nfreq, nout, nin)."""
    H = np.asarray(H)
    curves = [(f"{o}/{i}", _unit(f"{o}/{i}", kind), H[:, a, b])
              for a, o in enumerate(outputs) for b, i in enumerate(inputs)]
    return _frf_bode(np.asarray(freqs_hz), curves,
                     title or f"FRF ({kind}), {_speed_text(rpm)}")


def unbalance_figure(rpm, Q, outputs, critical_rpm=(), title=None, log=False):
    """Unbalance response (Bode plot): 0-peak amplitude (µm, or mrad for
    rotations) and phase of each channel against rotor speed; Q as returned by
    librcb.unbalance (nrpm, nout). critical_rpm marks the critical speeds."""
    plt = _plt()
    Q = np.asarray(Q)
    fig, (am, ap) = plt.subplots(2, 1, figsize=(8, 6.5), sharex=True,
                                 gridspec_kw={"height_ratios": [2.2, 1]})
    rot = [o.endswith((".rx", ".ry")) for o in outputs]
    for c, out in enumerate(outputs):
        amp = np.abs(Q[:, c]) * 1e6 if not rot[c] else np.abs(Q[:, c]) * 1e3
        line = (am.semilogy if log else am.plot)(rpm, amp, lw=1.3, label=out)[0]
        ph = np.where(np.abs(Q[:, c]) > 0, np.degrees(np.angle(Q[:, c])), np.nan)
        ap.plot(rpm, ph, ".", ms=2, color=line.get_color())
    for j, cr in enumerate(critical_rpm):
        for ax in (am, ap):
            ax.axvline(cr, color="k", ls=":", lw=0.8,
                       label="critical speed (forward, 1X)" if (j == 0 and ax is am) else None)
    unit = " / ".join(u for u, present in (("µm", not all(rot)), ("mrad", any(rot)))
                      if present)
    am.set_ylabel(f"amplitude, 0-peak ({unit})")
    am.grid(True, which="both", alpha=0.3)
    am.legend(fontsize=8)
    if not log:
        am.set_ylim(bottom=0)
    _phase_axis(ap)
    ap.set_ylabel("phase of Q (deg)")
    ap.set_xlabel("rotor speed (rpm)")
    ap.set_xlim(rpm[0], rpm[-1])
    am.set_title(title or "Unbalance response (steady, synchronous): q(t) = Re(Q e^(iΩt))",
                 fontsize=10)
    fig.tight_layout()
    return fig


def meas_figure(meas, title=None):
    """A measurement (librcb.Meas): FRFs as frf_figure, unbalance responses as
    unbalance_figure."""
    data = meas.data
    if meas.type == "unbalance":
        return unbalance_figure(meas.x, data.T, meas.names(), title=title)
    curves = [(f"{r}/{ref} ({k})", _unit(f"{r}/{ref}", k), row)
              for (r, ref, k), row in zip(meas.channels, data)]
    return _frf_bode(meas.x, curves, title or f"measured FRFs, {_speed_text(meas.rpm)}")
