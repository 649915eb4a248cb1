"""Identification (fit), diagnosis and comparison through the C library."""

import ctypes
import math
from dataclasses import dataclass

import numpy as np

from . import _lib
from .model import RPM, Handle, Model

SCALES = ("linear", "log10", "db", "complex")
METHODS = ("paper", "nlopt")


def _param_specs(model, params, log):
    """params: "name", "name:lo:hi", or {name: (lo, hi) or None} -> list of
    (name, lo, hi, log). Default bounds [start/1000, start*1000] (start > 0),
    as rcbtool fit; log None: optimise log(p) whenever lo > 0."""
    if isinstance(params, str):
        params = [p for p in params.split(",") if p]
    items = list(params.items()) if isinstance(params, dict) else [(p, None) for p in params]
    out = []
    for name, bounds in items:
        if bounds is None and ":" in name:
            name, lo, hi = name.split(":")
            bounds = (float(lo), float(hi))
        if bounds is None:
            start = model.get(name)
            if not start > 0:
                raise ValueError(f"parameter {name!r} starts at {start:g}: default bounds "
                                 f"[start/1000, start*1000] need a start > 0; give (lo, hi)")
            bounds = (start / 1000.0, start * 1000.0)
        lo, hi = float(bounds[0]), float(bounds[1])
        out.append((name, lo, hi, (lo > 0) if log is None else bool(log)))
    return out


def _band_si(meas, band):
    """band (lo, hi) in Hz (FRFs) or rpm (unbalance) -> rad/s."""
    s = 2 * math.pi if meas.type == "frf" else RPM
    return float(band[0]) * s, float(band[1]) * s


class _Fit(Handle):
    _destroy = "rcb_fit_destroy"
    _errmsg = "rcb_fit_errmsg"

    def __init__(self, model, meas):
        super().__init__()
        self.model, self.meas = model, meas  # the library points into both
        self._create("rcb_fit_create", model.handle, meas.handle, None)


@dataclass
class FitResult:
    """Outcome of a fit: the fitted model, each parameter with its uncertainty,
    and the run's report (paper's error % before/after, noise floor...)."""

    model: Model
    params: list        # dicts: name, start, value, stderr, ci95, identifiable
    report: dict        # iterations, evaluations, error0_pct, error_pct, floor_pct, ...
    correlation: np.ndarray

    @property
    def values(self):
        return {p["name"]: p["value"] for p in self.params}

    def summary(self):
        """A plain-dict summary (picklable, JSON-friendly) without the model."""
        return {"params": self.params, **self.report}


def fit(model, meas, params, log=None, scale="log10", noise=None, band=None,
        method="paper", algorithm=None, starts=8, seed=1, max_iter=None, ftol_rel=None,
        xtol_rel=None, inplace=False):
    """Fit model parameters to a measurement (paper's eq. 12 objective).

    params: names ("coupling.C.kt"), "name:lo:hi" strings, or {name: (lo, hi)};
    log: optimise log(p) (None: wherever lo > 0); scale: linear|log10|db|complex;
    noise: (beta_a, beta_s) %, noise-aware weights and floor; band: (lo, hi) in Hz
    (FRFs) or rpm (unbalance); method "paper" or "nlopt" with algorithm
    ("LN_BOBYQA"...); starts/seed: up to `starts` starting points, restarts only
    while the fit ends unsure (not converged, or above 1.5 x the noise floor);
    8 by default, as rcbtool fit (issue #17: FRF fits have local minima), 1 for
    a single run.
    The model is copied unless inplace=True; the result holds the fitted model.
    """
    m = model if inplace else model.copy()
    L = _lib.lib()
    with _Fit(m, meas) as f:
        for name, lo, hi, lg in _param_specs(m, params, log):
            f.check(L.rcb_fit_add_param(f.handle, name.encode(), lo, hi, int(lg)),
                    "rcb_fit_add_param")
        f.check(L.rcb_fit_set_scale(f.handle, SCALES.index(scale)), "rcb_fit_set_scale")
        if band is not None:
            f.check(L.rcb_fit_set_band(f.handle, *_band_si(meas, band)), "rcb_fit_set_band")
        if noise is not None:
            f.check(L.rcb_fit_set_noise_model(f.handle, float(noise[0]), float(noise[1])),
                    "rcb_fit_set_noise_model")
        if method != "paper" or algorithm:
            f.check(L.rcb_fit_set_method(f.handle, METHODS.index(method),
                                         algorithm.encode() if algorithm else None),
                    "rcb_fit_set_method")
        if max_iter is not None or ftol_rel is not None or xtol_rel is not None:
            f.check(L.rcb_fit_set_limits(f.handle, int(max_iter or 0), float(ftol_rel or 0),
                                         float(xtol_rel or 0)), "rcb_fit_set_limits")
        if starts != 1:
            f.check(L.rcb_fit_set_starts(f.handle, int(starts), int(seed)),
                    "rcb_fit_set_starts")
        f.check(L.rcb_fit_run(f.handle), "rcb_fit_run")
        rep = _lib.FitReport()
        f.check(L.rcb_fit_get_report(f.handle, ctypes.byref(rep)))
        report = {k: (getattr(rep, k) if isinstance(getattr(rep, k), float)
                      else int(getattr(rep, k))) for k, _ in _lib.FitReport._fields_}
        report["converged"], report["unsure"] = bool(rep.converged), bool(rep.unsure)
        out = []
        p = _lib.FitParam()
        npar = L.rcb_fit_param_count(f.handle)
        for k in range(npar):
            f.check(L.rcb_fit_get_param(f.handle, k, ctypes.byref(p)))
            out.append({"name": _lib.text(p.name), "start": p.start, "value": p.value,
                        "stderr": p.stderr_, "ci95": (p.ci_lo, p.ci_hi),
                        "identifiable": bool(p.identifiable)})
        C = np.zeros((npar, npar), order="F")
        f.check(L.rcb_fit_correlation(f.handle, C.ctypes.data), "rcb_fit_correlation")
    return FitResult(model=m, params=out, report=report, correlation=C)


class Diagnosis(Handle):
    """Which physical effect a model lacks, and where (rcb_diag). Candidates are
    plain dicts in rank order; apply(rank) gives the model with one added."""

    _destroy = "rcb_diag_destroy"
    _errmsg = "rcb_diag_errmsg"

    def __init__(self, model, meas):
        super().__init__()
        self.model, self.meas = model, meas
        self._create("rcb_diag_create", model.handle, meas.handle, None)
        self.candidates, self.baseline, self.explanation = [], {}, ""
        self.adequacy, self.misfit, self.places = {}, [], []

    def _collect(self):
        L = _lib.lib()
        e, obj, fl = ctypes.c_double(), ctypes.c_double(), ctypes.c_double()
        self.check(L.rcb_diag_baseline(self.handle, ctypes.byref(e), ctypes.byref(obj),
                                       ctypes.byref(fl)), "rcb_diag_baseline")
        self.baseline = {"error_pct": e.value, "objective": obj.value, "floor_pct": fl.value}
        c = _lib.DiagCandidate()
        for r in range(L.rcb_diag_candidate_count(self.handle)):
            self.check(L.rcb_diag_candidate_get(self.handle, r, ctypes.byref(c)))
            self.candidates.append({
                "rank": r, "effect": _lib.text(L.rcb_effect_name(c.effect)),
                "place": _lib.text(c.place), "description": _lib.text(c.description),
                "params": _lib.text(c.params), "predicted_pct": c.predicted_pct,
                "refitted": bool(c.refitted), "error_pct": c.error_pct,
                "objective_drop_pct": c.objective_drop_pct, "delta_bic": c.delta_bic,
                "significant": bool(c.significant), "fitted": _lib.text(c.fitted),
                "claim": _lib.text(L.rcb_claim_str(c.claim)),
                "adequate": None if c.adequate < 0 else bool(c.adequate),
                "chi2": c.chi2, "chi2_limit": c.chi2_limit, "chain": bool(c.chain),
                "screened_only": bool(c.screened_only), "dispersion": c.dispersion,
                "white_z": c.white_z, "white": None if c.white < 0 else bool(c.white),
                "beyond": bool(c.beyond), "carry": _lib.text(c.carry)})
        a = _lib.FitAdequacy()
        self.check(L.rcb_diag_adequacy(self.handle, ctypes.byref(a)), "rcb_diag_adequacy")
        self.adequacy = {"known": bool(a.known), "chi2": a.chi2, "dof": a.dof,
                         "expected": a.expected if a.known else float("nan"),
                         "sd": a.sd if a.known else float("nan"), "limit": a.limit,
                         "adequate": bool(a.adequate) if a.known else None,
                         "white_z": a.white_z if a.known else float("nan"),
                         "white": bool(a.white) if a.known else None,
                         "dispersion": a.dispersion}
        m = _lib.DiagMisfit()
        self.misfit = []
        for k in range(L.rcb_diag_misfit_count(self.handle)):
            self.check(L.rcb_diag_misfit_get(self.handle, k, ctypes.byref(m)))
            self.misfit.append({"response": _lib.text(m.sensor), "chi2": m.chi2,
                                "expected": m.expected, "excess_pct": m.excess_pct,
                                "concentrated": bool(m.concentrated),
                                "z_even": m.z_even, "uneven": bool(m.uneven)})
        pl = _lib.DiagPlace()
        self.places = []  # where equivalent loads place the misfit, the largest share first
        for k in range(L.rcb_diag_place_count(self.handle)):
            self.check(L.rcb_diag_place_get(self.handle, k, ctypes.byref(pl)))
            self.places.append({"node": pl.node, "shaft": _lib.text(pl.shaft), "z": pl.z,
                                "share_pct": pl.share_pct, "chi2": pl.chi2, "dof": pl.dof,
                                "adequate": bool(pl.adequate), "in_span": bool(pl.in_span),
                                "at_drive": bool(pl.at_drive)})
        st, self.explanation = _lib.two_call_string(L.rcb_diag_explain, self.handle)
        self.check(st, "rcb_diag_explain")

    @property
    def best(self):
        """The best significant candidate (claim "explains" or "improves", the
        library's one rule), or None."""
        return next((c for c in self.candidates if c["claim"] != "none"), None)

    def apply(self, rank=0):
        """The model with candidate rank added and fitted (a new Model)."""
        L = _lib.lib()
        h = ctypes.c_void_p()
        self.check(L.rcb_diag_apply_model(self.handle, int(rank), None, ctypes.byref(h)),
                   "rcb_diag_apply_model")
        try:  # the fitted model, through its INI text (a Model owns its handle)
            st, ini = _lib.two_call_string(L.rcb_model_write_ini, h)
            _lib.check(st, L.rcb_model_errmsg, h, "rcb_model_write_ini")
        finally:
            L.rcb_model_destroy(h)
        return Model.from_ini(ini, name=f"<diagnosis candidate {rank}>")


def diagnose(model, meas, params, log=None, scale="log10", noise=None, band=None,
             refits=8):
    """Fit params of the model as it is, score every catalogued effect at every
    place, refit the best `refits`; returns a Diagnosis (close it, or use `with`)."""
    d = Diagnosis(model, meas)
    L = _lib.lib()
    try:
        for name, lo, hi, lg in _param_specs(model, params, log):
            d.check(L.rcb_diag_add_fitted_param(d.handle, name.encode(), lo, hi, int(lg)),
                    "rcb_diag_add_fitted_param")
        d.check(L.rcb_diag_set_scale(d.handle, SCALES.index(scale)), "rcb_diag_set_scale")
        if noise is not None:
            d.check(L.rcb_diag_set_noise_model(d.handle, float(noise[0]), float(noise[1])))
        if band is not None:
            d.check(L.rcb_diag_set_band(d.handle, *_band_si(meas, band)))
        d.check(L.rcb_diag_set_refits(d.handle, int(refits)), "rcb_diag_set_refits")
        d.check(L.rcb_diag_run(d.handle), "rcb_diag_run")
        d._collect()
    except Exception:
        d.close()
        raise
    return d


class _Compare(Handle):
    _destroy = "rcb_compare_destroy"
    _errmsg = "rcb_compare_errmsg"

    def __init__(self):
        super().__init__()
        self._create("rcb_compare_create", None)


def compare(model, meas):
    """Model vs measurement: summary (error %, FRAC, CSAC...) and per-channel
    measures with both value arrays, as plain dicts and numpy arrays; "outliers":
    the sensors (and channels) whose error stands out from the others'
    (rcb_compare_outlier: check them before the model)."""
    L = _lib.lib()
    with _Compare() as c:
        c.check(L.rcb_compare_run(c.handle, model.handle, meas.handle), "rcb_compare_run")
        s = _lib.CompareSummary()
        c.check(L.rcb_compare_get_summary(c.handle, ctypes.byref(s)))
        n = L.rcb_compare_point_count(c.handle)
        grid = np.ctypeslib.as_array(L.rcb_compare_grid(c.handle), shape=(n,)).copy()
        chans = []
        ch = _lib.CompareChannel()
        for i in range(L.rcb_compare_channel_count(c.handle)):
            c.check(L.rcb_compare_get_channel(c.handle, i, ctypes.byref(ch)))
            arr = [np.frombuffer((ctypes.c_double * (2 * n)).from_address(a), np.complex128,
                                 n).copy() for a in (ch.meas, ch.model)]
            chans.append({"response": _lib.text(ch.response),
                          "reference": _lib.text(ch.reference), "error_pct": ch.error_pct,
                          "frac": ch.frac, "log_rms": ch.log_rms,
                          "phase_rms_deg": ch.phase_rms_deg, "meas": arr[0], "model": arr[1]})
        outliers = []
        o = _lib.CompareOutlier()
        for i in range(L.rcb_compare_outlier_count(c.handle)):
            c.check(L.rcb_compare_get_outlier(c.handle, i, ctypes.byref(o)))
            outliers.append({k: (_lib.text(getattr(o, k)) if k in ("response", "reference")
                                 else bool(o.by_chi2) if k == "by_chi2" else getattr(o, k))
                             for k, _ in _lib.CompareOutlier._fields_})
    x = grid / (2 * math.pi if meas.type == "frf" else RPM)
    return {"x": x, "summary": {k: getattr(s, k) for k, _ in _lib.CompareSummary._fields_},
            "channels": chans, "outliers": outliers}


def claim(delta_bic, error_before_pct, error_after_pct, chi2=float("nan"),
          chi2_limit=float("nan"), params=0, residuals=0, dispersion=0, tried=0, white=0,
          beyond=0):
    """What the evidence lets one say of an edit of a model: "explains",
    "improves" or "none". The library's one rule (rcb_evidence_claim), called,
    not restated: significant when the calibrated BIC falls by more than 10
    (and, noise unknown, the error by 2 % of itself; noise known, the drop
    over the dispersion passes the 1 % test over the candidates tried);
    "explains" only when also adequate (chi2 <= chi2_limit, or a white
    residual at most RCB_WHITE_LEVEL_MAX = 2 x the declared noise level,
    sqrt(dispersion); give the dispersion, else chi2 / chi2_limit stands in
    for it) and no fitted size is beyond its part (rcb_diagnose.h)."""
    L = _lib.lib()
    e = _lib.Evidence(float(delta_bic), float(error_before_pct), float(error_after_pct),
                      float(chi2), float(chi2_limit), float(params), float(residuals),
                      float(dispersion), float(tried), int(white), int(beyond))
    return _lib.text(L.rcb_claim_str(L.rcb_evidence_claim(ctypes.byref(e))))


class _Plan(Handle):
    _destroy = "rcb_plan_destroy"
    _errmsg = "rcb_plan_errmsg"

    def __init__(self, model, meas):
        super().__init__()
        self.model, self.meas = model, meas  # the library reads meas until run
        self._create("rcb_plan_create", model.handle, meas.handle, None)


def plan(model, meas, between, noise=(10.0, 1.0), size=25.0, rpm=()):
    """Which measurement would tell two rival effects apart (rcb_plan; the
    library call beneath `rcbtool plan`). between = (A, B), each a parameter
    name or a list of them (A's data are made, B is fitted to them); noise:
    eq. 19 (beta_a, beta_s) in %; size: the chi-square A moves F by on its own;
    rpm: other rotor speeds for the candidates (the test speed is always one).
    Returns {"angle_deg", "size", "chi2_sep", "separable" (the one rule,
    rcb_evidence_separable), "residuals", "params": [{"name", "side", "value",
    "change"}], "candidates": [{"response", "reference", "rpm", "gain",
    "chi2_after", "level_db"}] by falling gain}."""
    L = _lib.lib()
    p = _Plan(model, meas)
    for side, names in enumerate(between):
        for name in ([names] if isinstance(names, str) else names):
            p.check(L.rcb_plan_add_param(p.handle, side, name.encode()), "rcb_plan_add_param")
    p.check(L.rcb_plan_set_noise_model(p.handle, float(noise[0]), float(noise[1])),
            "rcb_plan_set_noise_model")
    p.check(L.rcb_plan_set_size(p.handle, float(size)), "rcb_plan_set_size")
    for r in rpm:
        p.check(L.rcb_plan_add_speed(p.handle, float(r) * RPM), "rcb_plan_add_speed")
    p.check(L.rcb_plan_run(p.handle), "rcb_plan_run")
    res = _lib.PlanResult()
    p.check(L.rcb_plan_get_result(p.handle, ctypes.byref(res)), "rcb_plan_get_result")
    out = {"angle_deg": res.angle_deg, "size": res.size, "chi2_sep": res.chi2_sep,
           "separable": bool(res.separable), "residuals": int(res.residuals), "params": [],
           "candidates": []}
    pp = _lib.PlanParam()
    for k in range(L.rcb_plan_param_count(p.handle)):
        p.check(L.rcb_plan_get_param(p.handle, k, ctypes.byref(pp)))
        out["params"].append({"name": _lib.text(pp.name), "side": "AB"[pp.side],
                              "value": pp.value, "change": pp.change})
    c = _lib.PlanCandidate()
    for k in range(int(res.candidates)):
        p.check(L.rcb_plan_get_candidate(p.handle, k, ctypes.byref(c)))
        out["candidates"].append({"response": _lib.text(c.response),
                                  "reference": _lib.text(c.reference), "rpm": c.speed / RPM,
                                  "gain": c.gain, "chi2_after": c.chi2_after,
                                  "level_db": c.level_db})
    return out
