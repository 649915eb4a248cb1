/*
 * Transient runs (speed profiles, initial conditions) and the steady-state
 * 1X extraction at constant speed (issue #5). CVODE is created once in
 * rcb_transient_create; each run re-initialises it (CVodeReInit), which
 * also resets its counters, so the statistics are those of the last run.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "analyses/transient_internal.h"

#if RCB_WITH_SUNDIALS
#include <cvode/cvode.h>
#include <cvode/cvode_ls.h>

/* BDF order cap. Shaft finite-element models have modes at 1e3-1e4 rad/s
 * with a few per cent of damping (eigenvalues close to the imaginary axis):
 * BDF4-5 are only A(73 deg)/A(51 deg)-stable and CVODE's steps then stay at
 * the stability limit of those modes; BDF3 (A(86 deg)) takes 1.5 times fewer
 * steps than order 5 and 3 times fewer than the A-stable BDF2 on the paper
 * system at 1e-6 (measured, docs/benchmarks.md). */
#define RCB_TRANSIENT_MAX_ORDER 3

/* CVODE's out-of-memory flag is RCB_ERR_NOMEM (SUNDIALS allocates with its
 * own malloc; issue #17), every other failure a numerical one. */
static rcb_status cv_status(int flag) { return flag == CV_MEM_FAIL ? RCB_ERR_NOMEM : RCB_ERR_SINGULAR; }

static rcb_status cv_check(rcb_transient *t, int flag, const char *call) {
  if (flag >= 0) return RCB_OK;
  return rcb_set_error(t->errmsg, cv_status(flag), "transient: %s failed (flag %d): %s", call,
                       flag, t->sunmsg[0] ? t->sunmsg : "no message");
}

/* y(0) = [q0; v0] (NULL = 0), tolerances, (re)initialise CVODE at t = 0. */
static rcb_status cv_start(rcb_transient *t, const double *q0, const double *v0) {
  size_t i, n = t->n;
  double *y = N_VGetArrayPointer(t->y), *at = N_VGetArrayPointer(t->abstol);
  rcb_status st;
  for (i = 0; i < n; i++) {
    y[i] = q0 ? q0[i] : 0.0;
    y[n + i] = v0 ? v0[i] : 0.0;
    at[i] = t->atol_q;
    at[n + i] = t->atol_v;
  }
  t->sunmsg[0] = '\0';
  memset(&t->stats, 0, sizeof t->stats);
  if (!t->started) {
    if ((st = cv_check(t, CVodeInit(t->cvode, rcb_transient_rhs, 0.0, t->y), "CVodeInit")) ||
        (st = cv_check(t, CVodeSetUserData(t->cvode, t), "CVodeSetUserData")) ||
        (st = cv_check(t, CVodeSetLinearSolver(t->cvode, t->LS, t->J),
                       "CVodeSetLinearSolver")) ||
        (st = cv_check(t, CVodeSetLinSysFn(t->cvode, rcb_transient_linsys),
                       "CVodeSetLinSysFn")) ||
        (st = cv_check(t, CVodeSetMaxNumSteps(t->cvode, 1000000), "CVodeSetMaxNumSteps")) ||
        (st = cv_check(t, CVodeSetMaxOrd(t->cvode, RCB_TRANSIENT_MAX_ORDER), "CVodeSetMaxOrd")))
      return st;
    t->started = 1;
  } else if ((st = cv_check(t, CVodeReInit(t->cvode, 0.0, t->y), "CVodeReInit"))) {
    return st;
  }
  /* no stop time left from a run with an external force */
  if ((st = cv_check(t, CVodeSetStopTime(t->cvode, 1e300), "CVodeSetStopTime"))) return st;
  return cv_check(t, CVodeSVtolerances(t->cvode, t->rtol, t->abstol), "CVodeSVtolerances");
}

static void cv_stats(rcb_transient *t, double tret) {
  long v = 0;
  CVodeGetNumSteps(t->cvode, &t->stats.steps);
  CVodeGetNumRhsEvals(t->cvode, &t->stats.rhs_evals);
  CVodeGetNumJacEvals(t->cvode, &t->stats.jac_evals);
  CVodeGetNumLinSolvSetups(t->cvode, &t->stats.lin_setups);
  CVodeGetNumNonlinSolvIters(t->cvode, &t->stats.lin_solves);
  CVodeGetNumErrTestFails(t->cvode, &t->stats.err_test_fails);
  CVodeGetNumLinRhsEvals(t->cvode, &v); /* 0 with the analytic Jacobian */
  t->stats.rhs_evals += v;
  t->stats.t_final = tret;
}

/* Advance to tout and copy the state into t->q, t->v, t->out. */
static rcb_status cv_advance(rcb_transient *t, double tout) {
  size_t i, n = t->n;
  const double *y;
  double tret = 0.0;
  if (tout > 0.0) CVodeGetCurrentTime(t->cvode, &tret);
  /* without an external force one call returns at tout (interpolated); an
   * external force is linear between its samples: the integrator stops at
   * each of them (tret is then the last stop), so no step straddles a kink */
  while (tout > 0.0 && (!t->fext || tret < tout)) {
    double tstop = tout;
    int flag;
    if (t->fext) {
      double k = floor(tret / t->dtf * (1.0 + 1e-12)) + 1.0;
      if (k * t->dtf < tout * (1.0 - 1e-12)) tstop = k * t->dtf;
      CVodeSetStopTime(t->cvode, tstop);
    }
    flag = CVode(t->cvode, tstop, t->y, &tret, CV_NORMAL);
    if (flag < 0) {
      cv_stats(t, tret);
      return rcb_set_error(t->errmsg, cv_status(flag),
                           "transient: CVode failed at t = %.9g s (flag %d): %s", tret, flag,
                           t->sunmsg[0] ? t->sunmsg : "no message");
    }
    if (!t->fext) break;
  }
  y = N_VGetArrayPointer(t->y);
  memcpy(t->q, y, n * sizeof *t->q);
  memcpy(t->v, y + n, n * sizeof *t->v);
  for (i = 0; i < t->nout; i++) t->out[i] = t->q[t->out_row[i]];
  return RCB_OK;
}

static rcb_status check_profile(rcb_transient *t, const rcb_speed_profile *p) {
  if (!p || !isfinite(p->speed0) || !isfinite(p->speed1) || !isfinite(p->accel) ||
      p->speed0 < 0.0 || p->speed1 < 0.0 || p->accel < 0.0)
    return rcb_set_error(t->errmsg, RCB_ERR_ARG,
                         "transient: speed profile (%g rad/s -> %g rad/s at %g rad/s^2); "
                         "expected finite speeds >= 0 and accel >= 0",
                         p ? p->speed0 : (double)NAN, p ? p->speed1 : (double)NAN,
                         p ? p->accel : (double)NAN);
  return RCB_OK;
}

static int call_sample(rcb_transient *t, double tt, rcb_transient_sample_fn fn, void *user) {
  rcb_transient_sample s;
  if (!fn) return 0;
  rcb_profile_eval(&t->prof, tt, &s.speed, &s.accel, &s.angle);
  s.t = tt;
  s.n = t->n;
  s.nout = t->nout;
  s.out = t->out;
  s.q = t->q;
  s.v = t->v;
  return fn(user, &s);
}

rcb_status rcb_transient_run(rcb_transient *t, const rcb_speed_profile *p, double t_end,
                             double dt, const double *q0, const double *v0,
                             rcb_transient_sample_fn fn, void *user) {
  rcb_status st;
  size_t k, nsamp;
  if (!t) return RCB_ERR_ARG;
  if ((st = check_profile(t, p))) return st;
  if (!(t_end > 0.0) || !(dt > 0.0) || !isfinite(t_end) || !(t_end / dt < 1e12))
    return rcb_set_error(t->errmsg, RCB_ERR_ARG,
                         "transient: t_end %g s, dt %g s; expected t_end > 0, dt > 0 and "
                         "fewer than 1e12 samples",
                         t_end, dt);
  t->prof = *p;
  if ((st = cv_start(t, q0, v0))) return st;
  nsamp = (size_t)floor(t_end / dt * (1.0 + 1e-12)) + 1;
  for (k = 0; k < nsamp; k++) {
    double tt = (double)k * dt;
    if ((st = cv_advance(t, tt))) return st;
    if (call_sample(t, tt, fn, user)) {
      cv_stats(t, tt);
      return rcb_set_error(t->errmsg, RCB_ERR_STATE,
                           "transient: the sampling callback stopped the run at t = %g s", tt);
    }
  }
  cv_stats(t, (double)(nsamp - 1) * dt);
  return RCB_OK;
}

/* ---- steady state ---- */

/* One revolution number p (t in (p T, (p+1) T]): the 1X phasors by a DFT of
 * spp samples into Q. */
static rcb_status one_period(rcb_transient *t, size_t p, double W, rcb_complex *Q) {
  size_t j, o, spp = t->ss_spp;
  double T = 2.0 * RCB_PI / W;
  rcb_status st;
  for (o = 0; o < t->nout; o++) Q[o] = 0.0;
  for (j = 1; j <= spp; j++) {
    double th = 2.0 * RCB_PI * (double)j / (double)spp; /* Omega t mod 2 pi */
    rcb_complex e = CMPLX(cos(th), -sin(th));
    if ((st = cv_advance(t, ((double)p + (double)j / (double)spp) * T))) return st;
    for (o = 0; o < t->nout; o++) Q[o] += t->out[o] * e;
  }
  for (o = 0; o < t->nout; o++) Q[o] *= 2.0 / (double)spp;
  return RCB_OK;
}

/* Largest change between two revolutions, relative to the largest phasor. */
static double rel_change(const rcb_transient *t, const rcb_complex *a, const rcb_complex *b) {
  size_t o;
  double d = 0.0, s = 0.0;
  for (o = 0; o < t->nout; o++) {
    d = fmax(d, cabs(a[o] - b[o]));
    s = fmax(s, cabs(a[o]));
  }
  if (s == 0.0) return d == 0.0 ? 0.0 : (double)INFINITY;
  return d / s;
}

/* Remaining error of a geometric sequence of changes: d/(1 - r), with the
 * larger of the last two ratios r (r >= 1 means "not settling"). Once the
 * change is at the level of the integration error itself (d below
 * @p floor, 10 rtol) the ratios are noise: d is the estimate. */
static double error_estimate(double d, double r1, double r2, double floor) {
  double r = fmax(r1, r2);
  if (d <= floor) return d;
  if (!(r < 0.999)) return (double)INFINITY;
  return d / (1.0 - r);
}

rcb_status rcb_transient_steady(rcb_transient *t, double speed, rcb_complex *Q) {
  rcb_speed_profile prof = {speed, speed, 0.0};
  rcb_complex *cur, *prev;
  double d_prev = (double)INFINITY, r_prev = 1.0, est = (double)INFINITY;
  size_t p, good = 0;
  rcb_status st;
  if (!t || !Q) return RCB_ERR_ARG;
  if (!(speed > 0.0) || !isfinite(speed))
    return rcb_set_error(t->errmsg, RCB_ERR_ARG,
                         "transient: steady state at speed %g rad/s; expected a finite speed > 0",
                         speed);
  t->prof = prof;
  if ((st = cv_start(t, NULL, NULL))) return st;
  cur = t->Qa;
  prev = t->Qb;
  for (p = 0; p < t->ss_max_periods; p++) {
    rcb_complex *sw;
    double d, r;
    if ((st = one_period(t, p, speed, cur))) return st;
    if (p > 0) {
      d = rel_change(t, cur, prev);
      r = (d_prev > 0.0 && isfinite(d_prev)) ? d / d_prev : 1.0;
      est = error_estimate(d, r, r_prev, 10.0 * t->rtol);
      good = (p >= 4 && est < t->ss_tol) ? good + 1 : 0;
      d_prev = d;
      r_prev = r;
    }
    sw = cur;
    cur = prev;
    prev = sw;
    if (good >= 3) break;
  }
  p = p < t->ss_max_periods ? p + 1 : p; /* revolutions integrated */
  cv_stats(t, (double)p * 2.0 * RCB_PI / speed);
  t->stats.periods = p;
  t->stats.steady_err = est;
  memcpy(Q, prev, t->nout * sizeof *Q);
  if (good < 3)
    return rcb_set_error(t->errmsg, RCB_ERR_MODEL,
                         "transient: no steady state at %g rad/s after %zu revolutions "
                         "(estimated error %g, tol %g): the model is unstable or too lightly "
                         "damped; raise max_periods or tol with rcb_transient_set_steady",
                         speed, t->ss_max_periods, est, t->ss_tol);
  return RCB_OK;
}

#else /* !RCB_WITH_SUNDIALS: create fails, so these are never reached with a valid object */

static rcb_status unsupported(rcb_transient *t) {
  if (!t) return RCB_ERR_ARG;
  return rcb_set_error(t->errmsg, RCB_ERR_UNSUPPORTED,
                       "transient: this librcb was built without SUNDIALS "
                       "(RCB_WITH_SUNDIALS=OFF)");
}

rcb_status rcb_transient_run(rcb_transient *t, const rcb_speed_profile *p, double t_end,
                             double dt, const double *q0, const double *v0,
                             rcb_transient_sample_fn fn, void *user) {
  (void)p;
  (void)t_end;
  (void)dt;
  (void)q0;
  (void)v0;
  (void)fn;
  (void)user;
  return unsupported(t);
}

rcb_status rcb_transient_steady(rcb_transient *t, double speed, rcb_complex *Q) {
  (void)speed;
  (void)Q;
  return unsupported(t);
}
#endif
