"""Monitoring series with hidden changes (issue #16), generated with ROSS.

A series is a directory of measurement files, one per update, named so that
sorting by name is the time order (m0000.uff, m0001.uff, ...), and a
truth.json beside them that only the tests read (the monitor is never told
when or what changed). Every file holds the 8 inertances of diag_cases.py
(DA, C.A, C.B, DB in x and y per a force at DA in x) at 400 frequencies,
100-399.25 Hz in 0.75 Hz steps (exact in UFF's E13.5), at 10000 rpm: the
budget case of issue #16 (8 channels x 400 frequencies). Noise: the paper's
eq. 19 (10 % random, 1 % systematic, drawn as src/io/noise.c draws it), each
update its own seed; the null_phase series adds issue #14's phase noise (each
point turned by its own angle, uniform in +-2 degrees), which rcb_monitor's
noise model does not hold yet (eq. 19 puts the random part along the value
only: docs/monitoring.md).

The series (SERIES):

* null:     200 updates of the paper system as it is;
* null_phase: the same with the 2 degrees of phase noise on top;
* kt_wear:  the coupling's kt stays at its nominal value for the first
            COMMISSION files (the commissioning period), then falls linearly by
            0.1 % per update to -10 % at file COMMISSION + 100 (111 files);
* cross_B3: a cross-coupled stiffness kxy = -kyx = 1.5e7 N/m appears at
            bearing B3 at update 37 of 60 and stays;
* cross_B3_r1 .. cross_B3_r5: cross_B3 again with other noise seeds (its
            interval's coverage is a rate: one series' 23 alarmed updates
            share one commissioning and prove little);
* probe_DA_x: the machine as it is, read by a DA.x probe whose gain stays 1
            for the COMMISSION files, then falls linearly to 0.85 over 70
            updates (issue #34: a drifting probe, not a drifting machine);
* mass_DB:  a point mass of 0.05 kg appears at disk DB at update 37 of 60 and
            stays (issue #34: a step named, then quiet);
* phase_DA_y: the machine as it is, read by a DA.y probe whose phase stays 0
            for the COMMISSION files, then lags linearly to -PHASE_LAG_DEG
            over 50 updates (issue #34: a probe's phase drifting, e.g. its
            driver's filter);
* swap_DA:  the machine as it is; from update 37 of 60 the DA.x and DA.y
            probes' cables are exchanged (issue #34: a swap, a step of the
            measurement chain).

Truth: ROSS 2.3 (an implementation that is not ours). Its rotor is built from
the INI by the independent parser of the ROSS bridge (ross_models.py), the
effect is set on the parsed model (diag_cases.bearing_keys, coupling_keys),
and H = [K - w^2 M + i w (C + Omega G)]^-1 is solved from ROSS's matrices
(checked against ROSS's own transfer_matrix at one frequency per build).
ROSS builds a rotor in seconds, so the 101 kt values are not 101 builds:
ROSS's matrices are affine in kt (the coupling stiffness enters K linearly),
so two builds give K(kt) = K0 + (kt - kt0)/(kt1 - kt0) (K1 - K0), and a third
build at another kt checks that to 1e-12 (relative) before any file is
written.

Generation (about a minute: five ROSS builds, ~1900 sweeps of 400
frequencies, the eq. 19 draws in Python) is cached: series(name) writes into
a cache directory keyed by a hash of this file, diag_cases.py, the model and
the ROSS version ($RCB_MONITOR_CACHE, default <tmp>/rcb_monitor_cases-<key>),
made in a temporary directory and renamed into place, so a half-written cache
is never read.

    python tests/python/monitor_cases.py OUTDIR [SERIES...]

writes the series into OUTDIR/<name>/ (all of them by default) and the
user's model (the paper system with the test's [uff] node table) as
OUTDIR/model.ini.

SI units (m, kg, N/m, N s/m, rad/s); Hz and rpm only in the files.
"""

import hashlib
import json
import math
import os
import shutil
import sys
import tempfile
import warnings
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import diag_cases as dc  # noqa: E402
import ross_models as rm  # noqa: E402

FREQ_HZ = 100.0 + 0.75 * np.arange(400)  # Hz; exact in E13.5
OUTS = dc.OUTS
IN = dc.IN
NOISE = dc.NOISE  # eq. 19 (10 % random, 1 % systematic)
PHASE_DEG = 2.0  # null_phase: uniform in +-2 degrees per point
KT0 = float(rm.Model(dc.BASE_INI).couplings[0][3]["kt"][-1])  # N/m, the model's kt
CROSS_B3 = 1.5e7  # N/m, kxy = -kyx at B3 (diag_cases' ross_cross_B3)
CROSS_REPLICAS = 5  # cross_B3_r1 .. r5: the same change under other noise seeds
FIT_PARAMS = "coupling.C.kt,coupling.C.kr,coupling.C.ct"  # what the monitor tracks


class Series:
    """A series: n updates; kt(u) the coupling's kt (N/m) at update u;
    cross_from the first update with the cross-coupling at B3 (None: never)."""

    def __init__(self, name, n, seed0, what, kt=None, cross_from=None, phase_deg=0.0,
                 probe=None, step=None, lag=None, swap=None):
        self.name = name
        # (edit key of STEPS, first update): an untracked step; cross_from is
        # the cross-coupling's
        self.step = step or (("cross_B3", cross_from) if cross_from is not None else None)
        # (response, gain(u)): a probe's gain, applied last (the sensor reads
        # the machine's motion and the noise alike)
        self.probe = probe
        # (response, phase(u) in rad, positive = the sensor leads): a probe's
        # phase, applied last as the gain
        self.lag = lag
        # (response a, response b, first update): the two probes exchanged
        self.swap = swap
        self.phase_deg = phase_deg  # uniform phase noise, +- degrees
        self.n = n
        self.seed0 = seed0  # update u has noise seed seed0 + u
        self.what = what
        self._kt = kt or (lambda u: KT0)
        self.cross_from = cross_from

    def kt(self, u):
        return float(self._kt(u))

    def cross(self, u):
        return self.cross_from is not None and u >= self.cross_from

    def edit(self, u):
        """The STEPS key of the untracked step in force at update u (None: none)."""
        return self.step[0] if self.step and u >= self.step[1] else None

    def truth(self):
        return {
            "name": self.name, "what": self.what, "updates": self.n,
            "kt": [self.kt(u) for u in range(self.n)], "kt0": KT0,
            "change_update": self.step[1] if self.step else None,
            "effect": STEPS[self.step[0]][1] if self.step else None,
            "place": STEPS[self.step[0]][2] if self.step else None,
            "step_size": STEPS[self.step[0]][3] if self.step else None,
            "cross_kxy": CROSS_B3 if self.cross_from is not None else 0.0,
            "seeds": [self.seed0 + u for u in range(self.n)],
            "freq_hz": [float(f) for f in FREQ_HZ], "rpm": dc.RPM,
            "noise": list(NOISE), "phase_deg": self.phase_deg,
            "files": [file_name(u) for u in range(self.n)],
            "probe": self.probe[0] if self.probe else None,
            "probe_gain": [float(self.probe[1](u)) for u in range(self.n)] if self.probe
            else None,
            "lag_probe": self.lag[0] if self.lag else None,
            "lag_rad": [float(self.lag[1](u)) for u in range(self.n)] if self.lag else None,
            "swap": list(self.swap) if self.swap else None,
        }

    def chain(self, m, u):
        """What the probes do to update u's measured values m (rows OUTS)."""
        if self.probe:
            m[OUTS.index(self.probe[0])] *= self.probe[1](u)
        if self.lag:
            m[OUTS.index(self.lag[0])] *= np.exp(1j * self.lag[1](u))
        if self.swap and u >= self.swap[2]:
            a, b = OUTS.index(self.swap[0]), OUTS.index(self.swap[1])
            m[[a, b]] = m[[b, a]]
        return m


COMMISSION = 10  # files averaged into the reference (rcbtool monitor --commission)
WEAR_UPDATES = 100  # kt falls 10 % over these updates after the commissioning period


def _wear(u):
    k = min(max(u - COMMISSION, 0), WEAR_UPDATES)
    return KT0 * (1.0 - 0.10 * k / WEAR_UPDATES)


MASS_DB = 0.05  # kg, a point mass added at disk DB (mass_DB's step)
# untracked steps: key -> (ROSS model edit, effect, place, size in the candidate's units)
STEPS = {
    "cross_B3": (dc.bearing_keys("B3", kxy=CROSS_B3, kyx=-CROSS_B3), dc.CROSS, "bearing B3",
                 CROSS_B3),
    "mass_DB": (dc.point_mass_edit("B 0.82", MASS_DB), dc.MASS, "disk DB", MASS_DB),
}
PROBE_UPDATES = 70  # probe_DA_x: DA.x's gain falls to PROBE_GAIN over these updates
PROBE_GAIN = 0.85


def _probe(u):
    k = min(max(u - COMMISSION, 0), PROBE_UPDATES)
    return 1.0 - (1.0 - PROBE_GAIN) * k / PROBE_UPDATES


LAG_UPDATES = 50  # phase_DA_y: DA.y's phase lags to -PHASE_LAG_DEG over these updates
PHASE_LAG_DEG = 3.0


def _lag(u):
    k = min(max(u - COMMISSION, 0), LAG_UPDATES)
    return -math.radians(PHASE_LAG_DEG) * k / LAG_UPDATES


SERIES = {
    "null": Series("null", 200, 160000, "nothing changes"),
    "null_phase": Series("null_phase", 200, 163000, "nothing changes; 2 degrees of phase noise",
                         phase_deg=PHASE_DEG),
    "kt_wear": Series("kt_wear", COMMISSION + WEAR_UPDATES + 1, 161000,
                      f"coupling kt steady for {COMMISSION} files, then falling 0.1 % per "
                      f"update to -10 % at file {COMMISSION + WEAR_UPDATES}", kt=_wear),
    "cross_B3": Series("cross_B3", 60, 162000,
                       "kxy = -kyx = 1.5e7 N/m appears at bearing B3 at update 37",
                       cross_from=37),
    **{f"cross_B3_r{r}": Series(f"cross_B3_r{r}", 60, 170000 + 1000 * r,
                                 "cross_B3 with other noise seeds", cross_from=37)
       for r in range(1, CROSS_REPLICAS + 1)},
    "mass_DB": Series("mass_DB", 60, 165000,
                      f"a point mass of {MASS_DB} kg appears at disk DB at update 37 (issue #34: "
                      f"a step, then quiet)", step=("mass_DB", 37)),
    "probe_DA_x": Series("probe_DA_x", COMMISSION + PROBE_UPDATES + 1, 164000,
                         f"the machine unchanged; the DA.x probe's gain steady for "
                         f"{COMMISSION} files, then falling linearly to {PROBE_GAIN} at file "
                         f"{COMMISSION + PROBE_UPDATES}", probe=("DA.x", _probe)),
    "phase_DA_y": Series("phase_DA_y", COMMISSION + LAG_UPDATES + 1, 166000,
                         f"the machine unchanged; the DA.y probe's phase 0 for {COMMISSION} "
                         f"files, then lagging linearly to -{PHASE_LAG_DEG} degrees at file "
                         f"{COMMISSION + LAG_UPDATES}", lag=("DA.y", _lag)),
    "swap_DA": Series("swap_DA", 60, 167000, "the machine unchanged; the DA.x and DA.y probes "
                      "exchanged from update 37", swap=("DA.x", "DA.y", 37)),
}


def file_name(u):
    return f"m{u:04d}.uff"


# --------------------------------------------------------------------------
# ROSS matrices, affine in kt
# --------------------------------------------------------------------------


class RossSystem:
    """ROSS's M, C, K, G at the test speed for one edit of the model, with the
    rows and input column of the test's channels."""

    def __init__(self, edit=None):
        model = rm.Model(dc.BASE_INI)
        if edit:
            edit(model)
        self.speed = dc.RPM * math.pi / 30.0  # rad/s
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            rmod = rm.RossModel(model, speed=self.speed)
            rot = rmod.rotor
            s = self.speed
            self.M, self.C = rot.M(frequency=s), rot.C(frequency=s)
            self.K, self.G = rot.K(frequency=s), rot.G()
            self.rows = [rmod.station_dof(o) for o in OUTS]
            self.jin = rmod.station_dof(IN)
            # the solve below is ROSS's own transfer matrix (one frequency)
            w = 2.0 * math.pi * FREQ_HZ[len(FREQ_HZ) // 2]
            T = rot.transfer_matrix(speed=s, frequency=w)
        ref = -w * w * T[self.rows, self.jin]
        got = inertance(self.M, self.C, self.K, self.G, self.speed, [w / (2 * math.pi)],
                        self.rows, self.jin)[:, 0]
        assert np.max(np.abs(got - ref)) <= 1e-9 * np.max(np.abs(ref)), (got, ref)


def inertance(M, C, K, G, speed, freq, rows, jin):
    """Inertances (len(rows) x len(freq), m/s^2/N) for a unit force on DOF jin."""
    e = np.zeros(M.shape[0])
    e[jin] = 1.0
    H = np.empty((len(rows), len(freq)), dtype=complex)
    for i, f in enumerate(freq):
        w = 2.0 * math.pi * f
        x = np.linalg.solve(K - w * w * M + 1j * w * (C + speed * G), e)
        H[:, i] = -w * w * x[rows]
    return H


class Truth:
    """Clean inertances for any (kt, untracked step of STEPS or none)."""

    def __init__(self):
        self.sys = {}
        kt1 = 0.5 * KT0
        for key in (None, *STEPS):
            edits = [STEPS[key][0]] if key else []
            a = RossSystem(dc.both(*edits) if edits else None)
            b = RossSystem(dc.both(*edits, dc.coupling_keys(kt=kt1)))
            self.sys[key] = (a, b, kt1)
        # affine in kt: a third build at another kt is the interpolation
        kt2 = 0.83 * KT0
        c = RossSystem(dc.coupling_keys(kt=kt2))
        for name in ("M", "C", "K", "G"):
            want = getattr(c, name)
            got = self._matrix(None, name, kt2)
            err = np.max(np.abs(got - want)) / max(np.max(np.abs(want)), 1e-300)
            assert err < 1e-12, f"ROSS {name} is not affine in kt ({err:.3e})"

    def _matrix(self, key, name, kt):
        a, b, kt1 = self.sys[key]
        ma, mb = getattr(a, name), getattr(b, name)
        return ma + (kt - KT0) / (kt1 - KT0) * (mb - ma)

    def inertance(self, kt, key):
        a = self.sys[key][0]
        M, C, K, G = (self._matrix(key, n, kt) for n in ("M", "C", "K", "G"))
        return inertance(M, C, K, G, a.speed, FREQ_HZ, a.rows, a.jin)


def measurement(H, seed, phase_deg=0.0):
    """eq. 19 noise, then any phase noise (its own generator, same seed)."""
    out = dc.add_noise(H, *NOISE, seed)
    return dc.add_phase_noise(out, phase_deg, seed) if phase_deg else out


# --------------------------------------------------------------------------
# Writing and caching
# --------------------------------------------------------------------------


def model_ini():
    """The user's model: the paper system with the test's UFF node table."""
    return dc.model_ini()


def write_series(outdir, names=None, truth=None):
    """Write the series (all by default) into outdir/<name>/ and outdir/model.ini."""
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    truth = truth or Truth()
    (outdir / "model.ini").write_text(model_ini())
    for name in names or SERIES:
        s = SERIES[name]
        d = outdir / name
        d.mkdir(exist_ok=True)
        clean = {}
        for u in range(s.n):
            key = (round(s.kt(u), 9), s.edit(u))
            if key not in clean:
                clean[key] = truth.inertance(s.kt(u), s.edit(u))
            m = s.chain(measurement(clean[key], s.seed0 + u, s.phase_deg), u)
            dc.write_uff(d / file_name(u), m, FREQ_HZ)
        (d / "truth.json").write_text(json.dumps(s.truth(), indent=1) + "\n")
    return outdir


def _cache_key():
    import ross

    h = hashlib.sha256()
    for p in (Path(__file__), HERE / "diag_cases.py"):
        h.update(p.read_bytes())
    h.update(dc.BASE_INI.encode())
    h.update(ross.__version__.encode())
    return h.hexdigest()[:12]


def cache_dir():
    """The cache directory of every series (made on first use, whole)."""
    root = os.environ.get("RCB_MONITOR_CACHE")
    base = Path(root) if root else Path(tempfile.gettempdir())
    final = base / f"rcb_monitor_cases-{_cache_key()}"
    if (final / "done").is_file():
        return final
    base.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=final.name + ".", dir=base))
    try:
        write_series(tmp)
        (tmp / "done").write_text("complete\n")
        try:
            tmp.rename(final)
        except OSError:  # another process made it first
            if not (final / "done").is_file():
                raise
    finally:
        if tmp.exists():
            shutil.rmtree(tmp, ignore_errors=True)
    return final


def series(name):
    """(directory of the series' files, its truth dict, the model.ini path)."""
    root = cache_dir()
    d = root / name
    return d, json.loads((d / "truth.json").read_text()), root / "model.ini"


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(f"usage: {sys.argv[0]} OUTDIR [{' '.join(SERIES)}]")
    bad = [n for n in sys.argv[2:] if n not in SERIES]
    if bad:
        sys.exit(f"unknown series {bad}; expected some of {list(SERIES)}")
    out = write_series(sys.argv[1], sys.argv[2:] or None)
    print(f"wrote {', '.join(sys.argv[2:] or SERIES)} and model.ini into {out}")
