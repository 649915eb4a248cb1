"""Monitor: model-based condition monitoring (an rcb_monitor handle, issue #16).

    mon = rcb.Monitor(model, commissioning_meas, ["coupling.C.kt"], noise=(10, 1))
    for meas in later_measurements:
        r = mon.update(meas)       # a dict: error_pct, floor_pct, T, threshold,
                                   # alarm, cusum_alarm, tracked [...], top [...]

The library does the statistics (docs/monitoring.md); this layer only lays the
values out in the commissioning measurement's channel order and turns the
result into plain data (dicts, lists, floats: picklable, for Dask).
Units: SI; parameter values in their own units (N/m, N s/m, ...).
"""

import ctypes
import math

import numpy as np

from . import _lib
from .model import Handle


def _tracked(model, params):
    """[(name, lo, hi)]: params is a list of names ([v/1000, 1000 v] around the
    model's value, as rcbtool) or a {name: (lo, hi)} mapping."""
    out = []
    items = params.items() if isinstance(params, dict) else ((p, None) for p in params)
    for name, bounds in items:
        if bounds is None:
            v = model.get(name)
            lo, hi = sorted((v / 1000.0, v * 1000.0)) if v != 0 else (-1.0, 1.0)
        else:
            lo, hi = bounds
        out.append((name, float(lo), float(hi)))
    if len(out) > _lib.MONITOR_MAX_TRACKED:
        raise ValueError(f"{len(out)} tracked parameters, at most {_lib.MONITOR_MAX_TRACKED}")
    return out


def _layout_sd(sd, shape):
    """sd as a contiguous float array of the set-up's shape (channels, points)."""
    sd = np.ascontiguousarray(sd, dtype=float)
    if sd.shape != shape:
        raise ValueError(f"sd has shape {sd.shape}, expected {shape}")
    return sd


def _noise_opts(noise, sd, shape):
    """The declared noise into a MonitorOpts (and the sd array it points to)."""
    o, sd0 = _lib.MonitorOpts(), None
    if noise is not None:
        o.beta_a, o.beta_s = float(noise[0]), float(noise[1])
        o.phase_deg = float(noise[2]) if len(noise) > 2 else 0.0
    if sd is not None:
        sd0 = _layout_sd(sd, shape)
        o.sd = sd0.ctypes.data
    return o, sd0


def noise_scale(setup, values, noise=None, sd=None):
    """The noise's level measured on repeated measurements of one state
    (rcb_monitor_noise_scale): values, shape (N, channels, points), complex,
    the set-up's channel order (N >= 2, e.g. the commissioning measurements
    before they are averaged); noise / sd: the declared noise as for Monitor.
    Returns {"scale": sqrt(chi2 / dof), "chi2", "dof"}: pass the scale as
    Monitor(..., noise_scale=...) with their average as the set-up."""
    v = np.ascontiguousarray(values, dtype=np.complex128)
    shape = (len(setup.channels), setup.n_points)
    if v.ndim != 3 or v.shape[1:] != shape:
        raise ValueError(f"values has shape {v.shape}, expected (N, {shape[0]}, {shape[1]})")
    o, _sd0 = _noise_opts(noise, sd, shape)
    out = _lib.MonitorNoise()
    _lib.check(_lib.lib().rcb_monitor_noise_scale(setup.handle, v.ctypes.data, v.shape[0],
                                                  ctypes.byref(o), ctypes.byref(out)),
               call="rcb_monitor_noise_scale")
    return {"scale": out.scale, "chi2": out.chi2, "dof": out.dof}


class Monitor(Handle):
    """A monitor commissioned on a fitted model and one measurement set-up."""

    _destroy = "rcb_monitor_destroy"
    _errmsg = "rcb_monitor_errmsg"

    def __init__(self, model, setup, params, noise=None, sd=None, alpha=None, cusum_h=None,
                 cusum_k=None, setup_averages=1, relinearise=0, reweight=False,
                 baseline_sd=None, noise_scale=None, sensors=True):
        """model: the fitted baseline (a Model); setup: the commissioning
        measurement (a Meas: channels, grid and the reference values); params:
        tracked parameter names or {name: (lo, hi)}; noise: eq. 19 (beta_a,
        beta_s) in % (and a third number: phase noise, uniform in +- that
        many degrees per point), or sd: standard deviations of Re and Im per (channel,
        point), shape (channels, points), SI; alpha, cusum_h, cusum_k: None for
        the library's defaults; setup_averages: measurements averaged into setup;
        reweight: each update's noise from its own values (generalised least
        squares: T stays chi-square after large changes; O(n k^2) per update);
        baseline_sd: standard errors of the baseline's tracked values (the fit that
        made it), which widen the values' intervals (the changes' stay);
        noise_scale: the noise's level against the declared one (every declared
        standard deviation times it; None: 1), e.g. librcb.monitor.noise_scale
        of the measurements averaged into setup; sensors: every measured probe's
        gain among the candidates (as rcbtool monitor by default; False:
        --no-sensors)."""
        super().__init__()
        self._names = [r if ref is None else f"{r}/{ref}" for r, ref, _ in setup.channels]
        self._shape = (len(self._names), setup.n_points)
        tp = _tracked(model, params)
        self._keep = [n.encode() for n, _, _ in tp]
        arr = (_lib.MonitorParam * max(len(tp), 1))()
        for i, ((_, lo, hi), nb) in enumerate(zip(tp, self._keep)):
            arr[i].name, arr[i].lo, arr[i].hi = nb, lo, hi
        o, self._sd0 = _noise_opts(noise, sd, self._shape)
        o.ntracked, o.tracked = len(tp), arr
        o.alpha, o.cusum_h, o.cusum_k = alpha or 0.0, cusum_h or 0.0, cusum_k or 0.0
        o.noise_scale = float(noise_scale or 0.0)
        o.setup_averages = float(setup_averages)
        o.relinearise = int(relinearise)
        o.reweight = int(bool(reweight))
        if sensors:  # the default catalogue and the measurement chain, as rcbtool
            o.effects = _lib.MONITOR_EFFECTS_SENSORS
        if baseline_sd is not None:
            sdb = np.asarray(baseline_sd, dtype=float)
            if sdb.shape != (len(tp),):
                raise ValueError(f"baseline_sd: {sdb.shape}, expected {len(tp)} values")
            self._cov = np.ascontiguousarray(np.diag(sdb ** 2))
            o.baseline_cov = self._cov.ctypes.data
        self._create("rcb_monitor_create", model.handle, setup.handle, ctypes.byref(o), None)
        self.tracked = [self._tracked_info(k) for k in range(len(tp))]

    def _tracked_info(self, k):
        name, base = ctypes.c_char_p(), ctypes.c_double()
        self.check(_lib.lib().rcb_monitor_tracked_info(self.handle, k, ctypes.byref(name),
                                                       ctypes.byref(base)))
        return {"name": _lib.text(name.value), "baseline": base.value}

    def _values(self, meas):
        """The set-up's channel order from meas (any order; names must match)."""
        names = meas.names()
        missing = [n for n in self._names if n not in names]
        if missing or meas.n_points != self._shape[1]:
            raise ValueError(f"the measurement does not match the set-up: channels "
                             f"{missing or 'ok'}, {meas.n_points} points for "
                             f"{self._shape[1]}")
        data = meas.data
        return np.ascontiguousarray([data[names.index(n)] for n in self._names],
                                    dtype=np.complex128)

    @property
    def rank(self):
        """(k, k_t): the rank of all columns and of the tracked ones."""
        k, kt = ctypes.c_size_t(), ctypes.c_size_t()
        self.check(_lib.lib().rcb_monitor_rank(self.handle, ctypes.byref(k), ctypes.byref(kt)))
        return k.value, kt.value

    @property
    def memory(self):
        """Bytes the monitor holds (all from its allocator)."""
        return int(_lib.lib().rcb_monitor_memory(self.handle))

    def candidate_count(self):
        """Candidates laid out at create (indices for candidate(), separate_by())."""
        return int(_lib.lib().rcb_monitor_candidate_count(self.handle))

    def candidate(self, i):
        info = _lib.MonitorCandidateInfo()
        self.check(_lib.lib().rcb_monitor_candidate_info_get(self.handle, i,
                                                             ctypes.byref(info)))
        return {"effect": _lib.text(_lib.lib().rcb_effect_name(info.effect)),
                "place": _lib.text(info.place), "description": _lib.text(info.description),
                "params": _lib.text(info.params), "np": info.np}

    def separate_by(self, tracked, cand, rpms=()):
        """The measurement that would tell tracked parameter `tracked` from
        candidate `cand` (rcb_monitor_separating: the diagnosis' plan on the
        model's stations at the set-up's speed and each of `rpms`, rpm):
        {"response", "reference", "rpm", "chi2_present", "chi2_after",
        "level_db"}, or None when no channel does, the set-up's channels already
        do, or the plan cannot vary the candidate. Asked once per pair and speeds
        (the plan sweeps the model)."""
        cache = self.__dict__.setdefault("_seps", {})
        key = (tracked, cand, tuple(float(r) for r in rpms))
        if key not in cache:
            sep = _lib.MonitorSeparator()
            w = (ctypes.c_double * max(len(key[2]), 1))(*[r * math.pi / 30.0 for r in key[2]])
            st = _lib.lib().rcb_monitor_separating(self.handle, tracked, cand, w, len(key[2]),
                                                    ctypes.byref(sep))
            cache[key] = (None if st or not sep.found else
                                      {"response": _lib.text(sep.response),
                                       "reference": _lib.text(sep.reference),
                                       "rpm": sep.speed * 30.0 / math.pi,
                                       "chi2_present": sep.chi2_present,
                                       "chi2_after": sep.chi2_after,
                                       "level_db": sep.level_db})
        return cache[key]

    def save_state(self):
        """The monitor's accumulated state (CUSUMs, references, update count) as
        bytes: little-endian, versioned, with a CRC-32 (rcb_monitor_save)."""
        n = _lib.lib().rcb_monitor_state_size(self.handle)
        buf = ctypes.create_string_buffer(max(n, 1))
        self.check(_lib.lib().rcb_monitor_save(self.handle, buf, n, None), "rcb_monitor_save")
        return buf.raw[:n]

    def load_state(self, state):
        """Load bytes from save_state into this monitor, created from the same
        model, set-up and options (else RcbError: another model, set-up, version,
        or damaged data)."""
        state = bytes(state)
        self.check(_lib.lib().rcb_monitor_load(self.handle, state, len(state)),
                   "rcb_monitor_load")

    def reset_cusum(self):
        _lib.lib().rcb_monitor_reset_cusum(self.handle)

    def update(self, meas, sd=None):
        """One new measurement (a Meas with the set-up's channels and grid);
        sd: its own standard deviations (channels, points), SI, or None."""
        v = self._values(meas)
        s = _layout_sd(sd, self._shape) if sd is not None else None
        r = _lib.MonitorResult()
        self.check(_lib.lib().rcb_monitor_update(self.handle, v.ctypes.data,
                                                 None if s is None else s.ctypes.data,
                                                 ctypes.byref(r)), "rcb_monitor_update")
        return self._result(r)

    def _result(self, r):
        tracked = []
        for k in range(r.ntracked):
            t = r.tracked[k]
            tracked.append({"name": self.tracked[k]["name"], "value": t.value,
                            "ci_lo": t.ci_lo, "ci_hi": t.ci_hi, "stderr": t.stderr_,
                            "z": t.z, "u": t.u, "cusum_up": t.cusum_up, "cusum_down": t.cusum_down,
                            "cusum_alarm": t.cusum_alarm, "cusum_allow": t.cusum_allow,
                            "out_of_range": bool(t.out_of_range),
                            "abs_stderr": t.abs_stderr, "change": t.change,
                            "change_lo": t.change_lo, "change_hi": t.change_hi,
                            # a CUSUM alarm's attribution (the one rule): 1 this
                            # parameter, 0 it or the rival (not separable), -1 the rival
                            "named": t.named,
                            "rival": (dict(self.candidate(t.rival),
                                           rate=list(t.rival_rate[:t.rival_dof]))
                                      if t.cusum_alarm and t.rival_dof else None),
                            # named -1 but a runner-up not separable from the rival
                            # (the change is not this parameter's; which of the two,
                            # the data do not say)
                            "rival2": (self.candidate(t.rival2)
                                       if t.cusum_alarm and t.named == -1 and t.rival2_dof
                                       else None),
                            # candidates beyond rival and rival2 the rule's test does
                            # not reject either (the list is not complete)
                            "rivals_open": t.rivals_open if t.cusum_alarm else 0,
                            # not separable: the measurement the plan names
                            "separate_by": self.separate_by(k, t.rival)
                            if t.cusum_alarm and t.named == 0 and t.rival_dof else None})
        top = []
        for k in range(r.ntop):
            c = r.top[k]
            d = self.candidate(c.index)
            d.update({"size": list(c.size[:c.np]), "ci_lo": list(c.ci_lo[:c.np]),
                      "ci_hi": list(c.ci_hi[:c.np]), "score": c.score, "dof": c.dof,
                      "p_value": c.p_value, "implausible": bool(c.implausible)})
            top.append(d)
        named = _lib.lib().rcb_monitor_named(self.handle, ctypes.byref(r))
        return {"update": r.update, "error_pct": r.error_pct, "change_pct": r.change_pct,
                "floor_pct": r.floor_pct, "T": r.T, "dof": r.dof, "threshold": r.threshold,
                "p_value": r.p_value, "alarm": bool(r.alarm),
                "cusum_alarm": bool(r.cusum_alarm), "tracked": tracked, "top": top,
                # the one rule (rcb_monitor_named): the first candidate told apart from
                # the second; None with fewer than two ranked
                "separable": None if named < 0 else bool(named),
                # its test half: the largest p over the rivals (None: the BIC half fails)
                "apart_p": None if math.isnan(r.apart_p) else r.apart_p,
                # the drift test: the candidate whose linear drift is best supported
                "drift": (None if not r.drift_dof else
                          dict(self.candidate(r.drift_index), glr=r.drift_glr,
                               dof=r.drift_dof, p_value=r.drift_p,
                               alarm=bool(r.drift_alarm), onset=r.drift_onset,
                               rate=list(r.drift_rate[:self.candidate(r.drift_index)["np"]])))}

    def __repr__(self):
        if not self._h:
            return "<librcb.Monitor closed>"
        return f"<librcb.Monitor {self._shape[0]} channels x {self._shape[1]} points>"
