#!/usr/bin/env python3
"""Generate a long multi-rotor machine train as a librcb INI model (issue #6).

The train is a motor, a gearbox's two shafts, a compressor, a turbine and a
generator (6 shafts by default), joined by flexible couplings of several
models, each shaft on two fluid-film bearings (a dozen in all, cross-coupled,
half of them speed-dependent), with impellers/wheels as disks and an
unbalance on every disk. The mesh is refined until the model reaches the
requested number of degrees of freedom (within a few DOF), so one machine
can be studied at 1e2 to 1e5 DOF.

usage:  gen_train.py --dof N [--shafts S] [-o FILE]
        (writes to stdout without -o; units SI throughout)

Only the Python standard library is used.
"""
import argparse
import sys

# One row per shaft kind, cycled: name, length m, body outer diameter m,
# journal diameter m, disks (count, mass kg, Id kg m^2, Ip kg m^2).
KINDS = [
    ("motor", 2.4, 0.22, 0.12, (1, 900.0, 60.0, 110.0)),
    ("pinion", 0.9, 0.14, 0.10, (1, 60.0, 0.8, 1.4)),
    ("wheel", 1.1, 0.20, 0.14, (1, 250.0, 9.0, 17.0)),
    ("compressor", 2.0, 0.18, 0.12, (5, 80.0, 1.5, 2.8)),
    ("turbine", 1.8, 0.20, 0.13, (4, 120.0, 2.5, 4.6)),
    ("generator", 3.0, 0.26, 0.16, (1, 1500.0, 140.0, 260.0)),
]
# Coupling models between consecutive shafts, cycled (kramer ties DOFs).
COUPLINGS = ["nelson_crandall_2", "nelson_crandall_1", "kramer_2", "nelson_crandall_2",
             "nelson_crandall_2"]
GAP = 0.15  # m, axial length of each coupling


def split(total, weights):
    """Integer parts of total proportional to weights, each >= 1."""
    s = float(sum(weights))
    parts = [max(1, int(round(total * w / s))) for w in weights]
    while sum(parts) > total and max(parts) > 1:
        parts[parts.index(max(parts))] -= 1
    while sum(parts) < total:
        parts[parts.index(min(parts))] += 1
    return parts


def tied_dofs(nshafts):
    n = 0
    for s in range(nshafts - 1):
        model = COUPLINGS[s % len(COUPLINGS)]
        n += {"rigid": 4, "kramer_1": 2, "kramer_2": 2}.get(model, 0)
    return n


def shafts_layout(dof, nshafts):
    """Elements per shaft so that 4 (elements + shafts) - tied ~= dof."""
    kinds = [KINDS[s % len(KINDS)] for s in range(nshafts)]
    nodes = (dof + tied_dofs(nshafts)) // 4
    elements = max(3 * nshafts, nodes - nshafts)
    return kinds, split(elements, [k[1] for k in kinds])


def fmt(x):
    return "%.17g" % x


def write_shaft(out, s, kind, nel, z0):
    """Three segments (journal, body, journal); returns body node positions
    and the journal (bearing) positions."""
    name, length, d_body, d_jour, _ = kind
    lj = 0.12 * length
    nj = max(1, nel // 8)
    nb = max(1, nel - 2 * nj)
    out.append("[shaft S%d]" % s)
    out.append("; %s, %d elements" % (name, nj + nb + nj))
    out.append("material = steel")
    out.append("start = %s                ; m" % fmt(z0))
    out.append("shear_factor = 0.9            ; -")
    out.append("damping_mass = 0.5            ; 1/s")
    out.append("damping_stiffness = 2e-6      ; s")
    body = length - 2 * lj
    out.append("segment = %s %s 0.0 %d   ; m, m, m, -" % (fmt(lj), fmt(d_jour), nj))
    out.append("segment = %s %s 0.0 %d   ; m, m, m, -" % (fmt(body), fmt(d_body), nb))
    out.append("segment = %s %s 0.0 %d   ; m, m, m, -" % (fmt(lj), fmt(d_jour), nj))
    out.append("")
    # z of the body nodes: the loader meshes each segment uniformly
    zb = [z0 + lj + body * k / nb for k in range(nb + 1)]
    return zb, (z0 + lj, z0 + length - lj), length


def write_bearings(out, s, zs):
    for j, z in enumerate(zs):
        out.append("[bearing B%d%s]" % (s, "ab"[j]))
        out.append("at = S%d %s" % (s, fmt(z)))
        if (s + j) % 2 == 0:
            # tilting-pad-like: speed-dependent, mildly cross-coupled
            out.append("speed_rpm = 0 3000 6000 9000")
            out.append("kxx = 4e8 5e8 6e8 7e8        ; N/m")
            out.append("kxy = 0 2e7 4e7 6e7          ; N/m")
            out.append("kyx = 0 -2e7 -4e7 -6e7       ; N/m")
            out.append("kyy = 5e8 6e8 7e8 8e8        ; N/m")
            out.append("cxx = 2e5 3e5 4e5 5e5        ; N s/m")
            out.append("cyy = 2.5e5 3.5e5 4.5e5 5.5e5 ; N s/m")
        else:
            # plain cylindrical: constant, cross-coupled
            out.append("kxx = 6e8                    ; N/m")
            out.append("kxy = 1.5e8                  ; N/m")
            out.append("kyx = -1.5e8                 ; N/m")
            out.append("kyy = 7e8                    ; N/m")
            out.append("cxx = 4e5                    ; N s/m")
            out.append("cxy = 2e4                    ; N s/m")
            out.append("cyx = 2e4                    ; N s/m")
            out.append("cyy = 4.5e5                  ; N s/m")
        out.append("")


def write_disks(out, s, kind, zb):
    count, mass, Id, Ip = kind[4]
    n = len(zb) - 1
    picks = sorted({max(1, min(n - 1, round(n * (k + 1) / (count + 1)))) if n > 1 else 0
                    for k in range(count)})
    for k, i in enumerate(picks):
        out.append("[disk D%d_%d]" % (s, k))
        out.append("at = S%d %s" % (s, fmt(zb[i])))
        out.append("mass = %s                ; kg" % fmt(mass))
        out.append("Id = %s                  ; kg m^2" % fmt(Id))
        out.append("Ip = %s                  ; kg m^2" % fmt(Ip))
        out.append("")
        out.append("[unbalance U%d_%d]" % (s, k))
        out.append("at = D%d_%d" % (s, k))
        out.append("amount = %s            ; kg m" % fmt(1e-4 * mass / 100.0))
        out.append("phase_deg = %d                ; degrees" % ((37 * (s + k)) % 360))
        out.append("")


def write_coupling(out, s):
    model = COUPLINGS[(s - 1) % len(COUPLINGS)]
    out.append("[coupling C%d]" % s)
    out.append("model = %s" % model)
    out.append("between = S%d end, S%d start" % (s - 1, s))
    if model != "kramer_1" and model != "rigid":
        if model != "kramer_2":
            out.append("kt = 2e8                      ; N/m")
        out.append("kr = 3e5                      ; N m/rad")
    if model in ("nelson_crandall_2", "kramer_2"):
        if model == "nelson_crandall_2":
            out.append("ct = 2e3                      ; N s/m")
        out.append("cr = 5.0                      ; N m s/rad")
    out.append("hub_mass = 25                 ; kg (each station)")
    out.append("hub_Id = 0.2                  ; kg m^2")
    out.append("hub_Ip = 0.35                 ; kg m^2")
    out.append("")


def generate(dof, nshafts):
    kinds, nels = shafts_layout(dof, nshafts)
    out = ["; Long machine train generated by tools/bench/gen_train.py",
           "; --dof %d --shafts %d (SI units)" % (dof, nshafts), "",
           "[model]", "name = machine train, %d shafts, target %d DOF" % (nshafts, dof), "",
           "[material steel]", "density = 7850                ; kg/m^3",
           "young = 2.1e11                ; Pa", "poisson = 0.3                 ; -", ""]
    z0 = 0.0
    for s in range(nshafts):
        zb, zj, length = write_shaft(out, s, kinds[s], nels[s], z0)
        write_bearings(out, s, zj)
        write_disks(out, s, kinds[s], zb)
        if s > 0:
            write_coupling(out, s)
        z0 += length + GAP
    return "\n".join(out) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--dof", type=int, required=True, help="target degrees of freedom")
    ap.add_argument("--shafts", type=int, default=6, help="number of shafts (default 6)")
    ap.add_argument("-o", dest="out", help="output INI file (default stdout)")
    a = ap.parse_args()
    if a.shafts < 1 or a.dof < 4 * 4 * a.shafts:
        ap.error("need --shafts >= 1 and --dof >= 16 per shaft")
    text = generate(a.dof, a.shafts)
    if a.out:
        with open(a.out, "w") as f:
            f.write(text)
    else:
        sys.stdout.write(text)


if __name__ == "__main__":
    main()
