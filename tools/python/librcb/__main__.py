"""Command-line pictures: `python -m librcb plot KIND ...` or `rcbplot KIND ...`.

    rcbplot campbell  MODEL.ini --rpm-max 20000 [--rpm-min 0] [--points 81] [--modes 6] -o campbell.png
    rcbplot modes     MODEL.ini [--rpm 10000] [--modes 6] -o modes.png
    rcbplot frf       MODEL.ini --out C.A.x,C.B.x --in DA.x --fmax 500 [--fmin 0] [--points 1001]
                      [--rpm 10000 | --synchronous] [--kind receptance] -o frf.png
    rcbplot unbalance MODEL.ini --out DA.x,DB.x --rpm-max 20000 [--rpm-min 0] [--points 401]
                      [--log] -o unbalance.png
    rcbplot meas      FILE.uff|FILE.csv [--model MODEL.ini] -o meas.png

Frequencies in Hz, speeds in rpm. Exit codes: 0 written, 1 library error
(message on stderr with FILE:LINE where it applies), 2 usage.
"""

import argparse
import sys

import numpy as np


def _parser():
    p = argparse.ArgumentParser(prog="rcbplot", description="Pictures of librcb results "
                                "(matplotlib). Frequencies in Hz, speeds in rpm.")
    sub = p.add_subparsers(dest="what", required=True)

    def add(name, help_, model=True):
        s = sub.add_parser(name, help=help_)
        if model:
            s.add_argument("model", help="model INI file")
        s.add_argument("-o", "--output", required=True, help="PNG (or PDF, SVG) to write")
        s.add_argument("--title", help="figure title")
        s.add_argument("--dpi", type=int, default=110)
        return s

    s = add("campbell", "Campbell diagram with 1X and the critical speeds")
    s.add_argument("--rpm-min", type=float, default=0.0)
    s.add_argument("--rpm-max", type=float, required=True)
    s.add_argument("--points", type=int, default=81)
    s.add_argument("--modes", type=int, default=6)
    s.add_argument("--max-zeta", type=float, default=None)
    s = add("modes", "damped mode shapes (orbits along the shaft)")
    s.add_argument("--rpm", type=float, default=0.0)
    s.add_argument("--modes", type=int, default=6)
    s.add_argument("--max-zeta", type=float, default=None)
    s = add("frf", "FRF magnitude and phase")
    s.add_argument("--out", required=True, help="output channels, e.g. C.A.x,C.B.x")
    s.add_argument("--in", dest="inp", required=True, help="input (force) channels, e.g. DA.x")
    s.add_argument("--fmin", type=float, default=0.0)
    s.add_argument("--fmax", type=float, required=True)
    s.add_argument("--points", type=int, default=1001)
    g = s.add_mutually_exclusive_group()
    g.add_argument("--rpm", type=float, default=0.0)
    g.add_argument("--synchronous", action="store_true")
    s.add_argument("--kind", dest="frf_kind", default="receptance",
                   choices=("receptance", "mobility", "inertance"))
    s = add("unbalance", "unbalance response amplitude and phase against speed")
    s.add_argument("--out", required=True, help="output channels, e.g. DA.x,DB.x")
    s.add_argument("--rpm-min", type=float, default=0.0)
    s.add_argument("--rpm-max", type=float, required=True)
    s.add_argument("--points", type=int, default=401)
    s.add_argument("--log", action="store_true", help="log amplitude axis")
    s = add("meas", "a measurement file (UFF58 or CSV)", model=False)
    s.add_argument("file", help="FILE.uff or FILE.csv")
    s.add_argument("--model", help="model whose [uff] map names the UFF nodes")
    return p


def _figure(a):
    import librcb as rcb
    from librcb import plots

    if a.what == "meas":
        model = rcb.Model.from_ini(a.model) if a.model else None
        return plots.meas_figure(rcb.Meas.read(a.file, model=model), title=a.title)
    m = rcb.Model.from_ini(a.model)
    if a.what == "campbell":
        cb = rcb.campbell(m, np.linspace(a.rpm_min, a.rpm_max, a.points), n=a.modes,
                          max_zeta=a.max_zeta)
        return plots.campbell_figure(cb, title=a.title)
    if a.what == "modes":
        md = rcb.modes(m, a.rpm, a.modes, max_zeta=a.max_zeta)
        return plots.mode_shapes_figure(md, stations=m.stations, title=a.title)
    if a.what == "frf":
        f = np.linspace(a.fmin, a.fmax, a.points)
        outs, ins = a.out.split(","), a.inp.split(",")
        rpm = None if a.synchronous else a.rpm
        H = rcb.frf(m, outs, ins, f, rpm=rpm, kind=a.frf_kind)
        return plots.frf_figure(f, H, outs, ins, kind=a.frf_kind, rpm=rpm, title=a.title)
    r = np.linspace(a.rpm_min, a.rpm_max, a.points)
    outs = a.out.split(",")
    Q = rcb.unbalance(m, outs, r)
    cb = rcb.campbell(m, r, n=8)
    return plots.unbalance_figure(r, Q, outs, critical_rpm=plots.forward_critical_rpm(cb),
                                  title=a.title,
                                  log=a.log)


def main(argv=None):
    argv = list(sys.argv[1:] if argv is None else argv)
    if argv[:1] == ["plot"]:  # python -m librcb plot KIND ...
        argv = argv[1:]
    a = _parser().parse_args(argv)
    import matplotlib
    matplotlib.use("Agg")
    import librcb as rcb
    try:
        fig = _figure(a)
    except (rcb.RcbError, rcb.LibraryNotFound, ValueError) as e:
        print(f"rcbplot {a.what}: {e}", file=sys.stderr)
        return 1
    fig.savefig(a.output, dpi=a.dpi)
    print(f"rcbplot: wrote {a.output}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
