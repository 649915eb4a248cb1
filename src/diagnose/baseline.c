/*
 * The first stage of the diagnosis: the fit of the model as it is (its own
 * parameters, the --params), screened on the frequency subset and polished
 * on all points unless it ran off from the nominal model (itself a finding,
 * d->far); the noise model's reference (its predictions, d->nref), where
 * every later fit evaluates the noise model; its objective, error and noise
 * floor; its adequacy test (each refit takes its own, refit.c); and the
 * sensors the misfit concentrates on.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "diagnose/diag_internal.h"
#include "diagnose/tuning.h"
#include "identify/identify.h"

/* Note the base parameters the fit f moved by more than RCB_DIAG_FAR. */
static void note_drift(rcb_diag *d, const rcb_fit *f) {
  size_t k, n = 0;
  d->far = 0, d->drift[0] = '\0';
  for (k = 0; k < rcb_fit_param_count(f); k++) {
    rcb_fit_param p;
    double ratio, v0; /* fitted / nominal */
    if (rcb_fit_get_param(f, k, &p) || rcb_model_get_param(d->m, p.name, &v0) || !(v0 != 0) ||
        !(p.value / v0 > 0))
      continue;
    ratio = p.value / v0;
    if (!(ratio > RCB_DIAG_FAR || ratio < 1.0 / RCB_DIAG_FAR)) continue;
    d->far = 1;
    n += (size_t)snprintf(d->drift + n, n < sizeof d->drift ? sizeof d->drift - n : 0,
                          "%s%s %.3g -> %.3g", n ? ", " : "", p.name, v0, p.value);
  }
}

/* The fit of the model as it is on the subset w: at most
 * RCB_DIAG_SCREEN_ITER iterations first (tuning.h says why); a fit that has
 * run off by then (d->far) stops there, as a finding, with no polish on all
 * points; one that has not goes on to its end as before (the cases whose
 * fit does not run off converge in a few iterations and take the same path
 * as before). */
static rcb_status baseline_screen(rcb_diag *d, rcb_fit *f, const double *w) {
  size_t it = 0;
  double ftol = 0.0, xtol = 0.0;
  rcb_fit_report rep;
  rcb_status st = rcb_fit_get_limits(f, &it, &ftol, &xtol);
  if (!st) st = rcb_fit_set_weights(f, w);
  if (!st && it > RCB_DIAG_SCREEN_ITER)
    st = rcb_fit_set_limits(f, RCB_DIAG_SCREEN_ITER, ftol, xtol);
  if (!st) st = rcb_fit_run(f);
  if (!st) st = rcb_fit_set_limits(f, it, ftol, xtol);
  if (!st) note_drift(d, f);
  if (!st && !d->far && it > RCB_DIAG_SCREEN_ITER && !rcb_fit_get_report(f, &rep) &&
      !rep.converged)
    st = rcb_fit_run(f); /* on to its end, from where it is */
  if (!st) st = rcb_fit_set_weights(f, NULL);
  return st;
}

/* The median of the n values v (sorted in place). */
static double median(double *v, size_t n) {
  size_t i, j;
  for (i = 1; i < n; i++)
    for (j = i; j > 0 && v[j] < v[j - 1]; j--) {
      double t = v[j];
      v[j] = v[j - 1];
      v[j - 1] = t;
    }
  return n == 0 ? (double)NAN : n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/* The upper normal quantile of p: z with P(Z > z) = 0.5 erfc(z / sqrt 2) = p
 * (bisection to double precision; p in (0, 0.5]). */
static double z_upper(double p) {
  double lo = 0.0, hi = 40.0;
  int it;
  for (it = 0; it < 200; it++) { /* bisection on 0.5 erfc(z / sqrt 2) = p */
    double mid = 0.5 * (lo + hi);
    if (0.5 * erfc(mid / sqrt(2.0)) > p) lo = mid;
    else hi = mid;
  }
  return 0.5 * (lo + hi);
}

/* Whether responses a and b ("C.A.x", "C.A.y") are two directions of one
 * station (a probe pair that may be swapped). */
static int same_station(const char *a, const char *b) {
  const char *da = strrchr(a, '.'), *db = strrchr(b, '.');
  return da && db && da - a == db - b && strncmp(a, b, (size_t)(da - a)) == 0;
}

/* Which sensors concentrate the misfit (rcb_diag_misfit_get states the
 * rule): the per-channel parts of the adequacy test summed per response. */
static rcb_status misfit_sensors(rcb_diag *d, const double *chi2, const double *mean,
                                 const double *var) {
  size_t nch = rcb_meas_channel_count(d->meas), c, k, i, m;
  double excess = 0.0, *ratio, zlim;
  if (!(d->mis = rcb_alloc(&d->alloc, (nch ? nch : 1) * sizeof *d->mis)) ||
      !(ratio = rcb_alloc(&d->alloc, (nch ? nch : 1) * sizeof *ratio)))
    return rcb_diag_fail(d, RCB_ERR_NOMEM, "out of memory");
  for (c = 0; c < nch; c++) {
    rcb_meas_channel_info ci;
    rcb_meas_channel(d->meas, c, &ci);
    for (k = 0; k < d->nmis && strcmp(d->mis[k].sensor, ci.response) != 0; k++) continue;
    if (k == d->nmis) {
      memset(&d->mis[k], 0, sizeof d->mis[k]);
      d->mis[d->nmis++].sensor = ci.response;
    }
    d->mis[k].chi2 += chi2[c], d->mis[k].expected += mean[c], d->mis[k].sd += var[c];
  }
  for (k = 0; k < d->nmis; k++) {
    d->mis[k].sd = sqrt(d->mis[k].sd);
    excess += fmax(d->mis[k].chi2 - d->mis[k].expected, 0.0);
  }
  for (k = 0; k < d->nmis; k++)
    d->mis[k].excess_pct =
        excess > 0 ? 100.0 * fmax(d->mis[k].chi2 - d->mis[k].expected, 0.0) / excess : 0.0;
  for (k = 1; k < d->nmis; k++) /* the largest excess first (stable) */
    for (i = k; i > 0 && d->mis[i].excess_pct > d->mis[i - 1].excess_pct; i--) {
      rcb_diag_misfit t = d->mis[i];
      d->mis[i] = d->mis[i - 1];
      d->mis[i - 1] = t;
    }
  /* one sensor, or two of one station (a swapped pair), holding RCB_DIAG_MISFIT_SHARE of
   * the excess, each failing its own test beyond the Bonferroni limit and
   * RCB_DIAG_MISFIT_RATIO x the median chi2 / expected of the rest */
  zlim = z_upper(0.01 / (double)(d->nmis ? d->nmis : 1));
  for (k = 0; k < d->nmis; k++) { /* evenness: each sensor against the others' dispersion */
    double c2 = 0.0, ex = 0.0, phi;
    for (i = 0; i < d->nmis; i++)
      if (i != k) c2 += d->mis[i].chi2, ex += d->mis[i].expected;
    phi = ex > 0 ? fmax(c2 / ex, 1e-300) : 1.0;
    d->mis[k].z_even = d->mis[k].sd > 0 ? (d->mis[k].chi2 - phi * d->mis[k].expected) /
                                              (phi * d->mis[k].sd)
                                        : 0.0;
    d->mis[k].uneven = d->nmis > 1 && d->mis[k].z_even > zlim && d->mis[k].expected > 0 &&
                       d->mis[k].chi2 / d->mis[k].expected >= RCB_DIAG_UNEVEN_RATIO * phi;
  }
  for (m = 1; m <= 2 && m < d->nmis; m++) {
    double share = 0.0, med;
    size_t n = 0;
    for (k = 0; k < m; k++) share += d->mis[k].excess_pct;
    if (share < RCB_DIAG_MISFIT_SHARE) continue;
    if (m == 2 && !same_station(d->mis[0].sensor, d->mis[1].sensor)) break;
    for (i = m; i < d->nmis; i++)
      if (d->mis[i].expected > 0) ratio[n++] = d->mis[i].chi2 / d->mis[i].expected;
    med = median(ratio, n);
    for (k = 0; k < m; k++) {
      rcb_diag_misfit *s = &d->mis[k];
      s->concentrated = n > 0 && s->expected > 0 && s->sd > 0 &&
                        (s->chi2 - s->expected) / s->sd > zlim &&
                        s->chi2 / s->expected >= RCB_DIAG_MISFIT_RATIO * med;
    }
    break;
  }
  rcb_free(&d->alloc, ratio);
  return RCB_OK;
}

/* The adequacy test of the fitted model as it is (fit f) and where the
 * misfit concentrates (each refit takes its own test: refit.c). */
static rcb_status baseline_adequacy(rcb_diag *d, rcb_fit *f) {
  size_t nch = rcb_meas_channel_count(d->meas);
  double *w = rcb_alloc(&d->alloc, 3 * (nch ? nch : 1) * sizeof *w);
  rcb_status st;
  size_t c;
  if (!w) return rcb_diag_fail(d, RCB_ERR_NOMEM, "out of memory");
  st = rcb_fit_get_adequacy(f, &d->adeq0, w, w + nch, w + 2 * nch);
  if (st) {
    rcb_free(&d->alloc, w);
    return rcb_diag_fail(d, st, "the adequacy test of the model as it is: %s",
                         rcb_fit_errmsg(f));
  }
  for (c = 0; c < nch; c++) w[2 * nch + c] *= w[2 * nch + c]; /* variances */
  if (d->adeq0.known) st = misfit_sensors(d, w, w + nch, w + 2 * nch);
  rcb_free(&d->alloc, w);
  return st;
}

/* The noise model's reference (issue #33): the fitted model's predictions,
 * free of the measurement's noise, where every later fit evaluates the
 * noise model (its weights, levels and floor gate: rcb_fit_set_noise_
 * reference), so that they share one set of weights; the model as it is is
 * refitted on them from where it is (a local step: the weights move by the
 * noise's second order). Weights at the measured values made a null data
 * set of 32 x 1101 name "an operating speed 0.994 x the stated one" with
 * dBIC about -270 on the complex scale in every seed (issue #33). */
static rcb_status noise_reference(rcb_diag *d, rcb_fit *f) {
  size_t n = rcb_meas_channel_count(d->meas) * rcb_meas_point_count(d->meas);
  rcb_status st;
  if (!(d->beta_a > 0 || d->beta_s > 0)) return RCB_OK;
  if (!(d->nref = rcb_alloc(&d->alloc, (n ? n : 1) * sizeof *d->nref)))
    return rcb_diag_fail(d, RCB_ERR_NOMEM, "out of memory");
  st = rcb_fit_predictions(f, d->nref);
  if (!st) st = rcb_fit_set_noise_reference(f, d->nref);
  if (!st && d->nbase && !d->far) st = rcb_fit_run(f);
  if (st) rcb_diag_fail(d, st, "fitting the model as it is: %s", rcb_fit_errmsg(f));
  return st;
}

/* Fit the model as it is, on a copy: the base model, F0, error, floor,
 * residual count; whether the fit ran off from the nominal model. */
rcb_status rcb_diag_fit_baseline(rcb_diag *d) {
  rcb_model *m = NULL;
  rcb_fit *f = NULL;
  rcb_fit_report rep;
  rcb_status st = rcb_diag_copy_model(d, d->m, &m);
  if (!st) st = rcb_diag_make_fit(d, m, 1, NULL, &f);
  if (!st && d->nbase) {
    double *w = NULL;
    /* screened on the subset, polished on all points from there (not when
     * the screen stopped because it ran off) */
    st = rcb_diag_subset_weights(d, &w);
    if (w) st = baseline_screen(d, f, w);
    rcb_free(&d->alloc, w);
    if (!st && !d->far) st = rcb_fit_run(f);
    if (st) rcb_diag_fail(d, st, "fitting the model as it is: %s", rcb_fit_errmsg(f));
    else note_drift(d, f);
  }
  if (!st) st = noise_reference(d, f);
  if (!st) {
    d->nres = rcb_fit_residual_count(f);
    rcb_fit_get_report(f, &rep);
    d->floor0 = rep.floor_pct;
    if (d->far) st = rcb_diag_copy_model(d, d->m, &d->nom_model);
  }
  if (!st) {
    double *r = rcb_alloc(&d->alloc, d->nres * sizeof *r);
    st = r ? rcb_diag_objective(d, f, r, &d->F0, &d->err0) : RCB_ERR_NOMEM;
    rcb_free(&d->alloc, r);
  }
  if (!st) st = baseline_adequacy(d, f);
  if (!st) rcb_diag_carry_keep(d, f); /* the base sensor parameters, for every later fit */
  rcb_diag_drop_fit(d, f);
  if (!st) d->base_model = m; /* the fitted values stay in it */
  else rcb_model_destroy(m);
  return st;
}
