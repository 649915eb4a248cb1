/*
 * Guards on the outcome of a fit (issue #7): a fit that stalls, runs out of
 * iterations or ends with a parameter pressed against a bound says so
 * (rcb_fit_stop_reason, and the report's unsure flag) instead of handing
 * back a point that merely looks fitted; a non-finite objective is an error
 * (RCB_ERR_NOT_CONVERGED) rather than a "minimum" that no step could improve.
 */
#include <math.h>

#include "identify/fit_internal.h"

/* A parameter closer to a bound than this fraction of its range, in the
 * optimiser's coordinates (log p for log parameters), is "at" the bound. */
#define AT_BOUND_FRACTION 1e-3

/* 0 inside, +1 at (or past) the upper bound, -1 at the lower one. */
static int at_bound(const rcb_fit_par *p) {
  double v = p->log_param ? log(p->value) : p->value;
  double lo = p->log_param ? log(p->lo) : p->lo, hi = p->log_param ? log(p->hi) : p->hi;
  double tol = AT_BOUND_FRACTION * (hi - lo);
  return v >= hi - tol ? 1 : (v <= lo + tol ? -1 : 0);
}

/* Is bound side of parameter k active: would the objective F = r^T r fall
 * by more than 0.1 % if the parameter could move past it? The Gauss-Newton
 * gain of a step in x_k alone is (J_k^T r)^2 / (J_k^T J_k), outward when
 * dF/dx_k = 2 J_k^T r points out of the box. An unidentifiable parameter
 * drifting onto a bound along a flat valley gains nothing and is left
 * alone. f->J and f->r are the workspace at the fitted point. */
static int bound_active(const rcb_fit *f, size_t k, int side) {
  const double *Jk = f->J + f->nres * k;
  double g = 0.0, jj = 0.0;
  size_t j;
  for (j = 0; j < f->nres; j++) g += Jk[j] * f->r[j], jj += Jk[j] * Jk[j];
  if (!(jj > 0.0) || (side > 0 ? g >= 0.0 : g <= 0.0)) return 0;
  return g * g / jj > 1e-3 * rcb_fit_sumsq(f->r, f->nres);
}

void rcb_fit_classify_stop(rcb_fit *f) {
  size_t k, evals = f->evaluations;
  int have_jac = 0;
  f->stop_param = f->np;
  if (!f->converged) {
    f->stop = f->stalled ? RCB_FIT_STOP_STALLED : RCB_FIT_STOP_MAX_ITER;
    return;
  }
  f->stop = RCB_FIT_STOP_CONVERGED;
  for (k = 0; k < f->np; k++) {
    int side = at_bound(&f->par[k]);
    if (!side) continue;
    /* one Jacobian at the fitted point, only when some parameter is at a
     * bound (not counted in the report's evaluations) */
    if (!have_jac && rcb_fit_eval_jac(f, f->r, f->J) != RCB_OK) break;
    have_jac = 1;
    if (bound_active(f, k, side)) {
      f->stop = RCB_FIT_STOP_AT_BOUND;
      f->stop_param = k;
      break;
    }
  }
  f->evaluations = evals;
}

/* Why residual j is not finite, for the message (issue #17: "objective is
 * infinite" alone left a user with a UFF read at 0 rpm nowhere to look). */
static const char *likely_cause(const rcb_fit *f, size_t j) {
  rcb_complex h = f->Hmod[f->res_ch[j] * f->npts + f->res_pt[j]];
  int logs = f->scale == RCB_SCALE_LOG10 || f->scale == RCB_SCALE_DB;
  if (!isfinite(f->res_sqrtw[j]))
    return "its weight is infinite (the noise model with a measured value of 0 there: "
           "leave the point out with --band, or drop --noise)";
  if (!isfinite(creal(h)) || !isfinite(cimag(h)))
    return "the model's response there is not finite (a singular model at this frequency: "
           "no support, or no damping at a resonance)";
  if (logs && cabs(h) == 0.0) {
    if (!f->unbalance && f->speed == 0.0)
      return rcb_meas_speed_given(f->meas)
                 ? "the model's response there is exactly 0 (the log of 0): at 0 rpm nothing "
                   "couples this response to this force (the gyroscopic terms are off); is "
                   "the test speed right?"
                 : "the model's response there is exactly 0 (the log of 0): the measurement "
                   "does not state its rotor speed and was read as 0 rpm, where nothing "
                   "couples this response to this force; give the speed (--rpm R, the "
                   "model's [test] rpm)";
    return "the model's response there is exactly 0 (the log of 0): the model does not "
           "couple this response to this force; use the linear scale or leave the channel "
           "out";
  }
  return "its residual overflows (model and measurement many orders of magnitude apart: "
         "check the units of the measurement and the model)";
}

rcb_status rcb_fit_check_finite(rcb_fit *f, double F, const char *where) {
  size_t j;
  if (isfinite(F)) return RCB_OK;
  for (j = 0; f->r && f->Hmod && j < f->nres; j++) {
    rcb_meas_channel_info ci;
    double x = f->grid[f->res_pt[j]];
    if (isfinite(f->r[j])) continue;
    if (rcb_meas_channel(f->meas, f->res_ch[j], &ci) != RCB_OK) break;
    return rcb_fit_fail(f, RCB_ERR_NOT_CONVERGED,
                        "objective is %s %s: channel %s%s%s at %.6g %s: %s; no result",
                        isnan(F) ? "NaN" : "infinite", where, ci.response,
                        ci.reference ? "/" : "", ci.reference ? ci.reference : "",
                        f->unbalance ? x * 30.0 / RCB_PI : x / (2.0 * RCB_PI),
                        f->unbalance ? "rpm" : "Hz", likely_cause(f, j));
  }
  return rcb_fit_fail(f, RCB_ERR_NOT_CONVERGED,
                      "objective is %s %s (residuals overflow or are not numbers: check the "
                      "weights, the measurement and the model there); no result",
                      isnan(F) ? "NaN" : "infinite", where);
}

rcb_fit_stop rcb_fit_stop_reason(const rcb_fit *f, size_t *param) {
  if (param) *param = f ? f->stop_param : 0;
  return f ? (rcb_fit_stop)f->stop : RCB_FIT_STOP_NONE;
}

const char *rcb_fit_stop_str(rcb_fit_stop s) {
  switch (s) {
    case RCB_FIT_STOP_CONVERGED: return "converged";
    case RCB_FIT_STOP_AT_BOUND: return "a parameter ended at its bound";
    case RCB_FIT_STOP_STALLED: return "stalled: no step reduced the objective";
    case RCB_FIT_STOP_MAX_ITER: return "iteration limit reached before convergence";
    case RCB_FIT_STOP_NONE: break;
  }
  return "not run";
}

rcb_status rcb_fit_get_condition(const rcb_fit *f, rcb_frf_condition *out) {
  if (!f || !out) return RCB_ERR_ARG;
  *out = f->cond;
  return RCB_OK;
}
