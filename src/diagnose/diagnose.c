/*
 * Diagnosis (issue #4): fit the model as it is, score every candidate effect
 * of the catalogue by the error reduction it can explain (score test: the
 * candidate's sensitivity columns orthogonalised against the parameters
 * already fitted, projected on the weighted residual of the fit's own
 * objective), refit the best and the alternative coupling models, and rank by
 * the change of BIC, requiring the error itself to fall.
 */
#include <math.h>
#include <stdlib.h>
#include <stdio.h>
#include <string.h>

#include "diagnose/diag_internal.h"
#include "diagnose/tuning.h"
#include "identify/identify.h"

rcb_status rcb_diag_create(rcb_diag **out, const rcb_model *m, const rcb_meas *meas,
                           const rcb_allocator *alloc) {
  rcb_allocator a;
  rcb_diag *d;
  if (!out) return RCB_ERR_ARG;
  *out = NULL;
  if (!m || !meas) return RCB_ERR_ARG;
  rcb_allocator_init(&a, alloc);
  if (!(d = rcb_alloc(&a, sizeof *d))) return RCB_ERR_NOMEM;
  d->alloc = a;
  d->m = m;
  d->meas = meas;
  d->scale = RCB_SCALE_LOG10;
  d->nrefit = 8;
  d->nthreads = 1;
  *out = d;
  if (rcb_model_dof_count(m) == 0) return rcb_diag_fail(d, RCB_ERR_STATE, "model not finalized");
  return RCB_OK;
}

static void free_results(rcb_diag *d) {
  size_t i;
  for (i = 0; i < d->ncand; i++) rcb_model_destroy(d->cand[i].model);
  rcb_free(&d->alloc, d->cand);
  rcb_free(&d->alloc, d->order);
  rcb_model_destroy(d->base_model);
  rcb_model_destroy(d->nom_model);
  rcb_free(&d->alloc, d->mis);
  d->mis = NULL, d->nmis = 0;
  rcb_free(&d->alloc, d->place);
  d->place = NULL, d->nplace = 0;
  rcb_free(&d->alloc, d->nref);
  d->nref = NULL;
  memset(&d->adeq0, 0, sizeof d->adeq0);
  d->cand = NULL, d->order = NULL, d->base_model = NULL, d->nom_model = NULL;
  d->far = 0, d->drift[0] = '\0', d->pre_best = HUGE_VAL;
  d->ncand = d->cap_cand = 0;
  d->ran = 0;
  memset(&d->stats, 0, sizeof d->stats);
  d->progress_done = 0;
}

void rcb_diag_destroy(rcb_diag *d) {
  rcb_allocator a;
  if (!d) return;
  a = d->alloc;
  free_results(d);
  rcb_free(&a, d->base);
  rcb_free(&a, d->sd);
  rcb_free(&a, d);
}

const char *rcb_diag_errmsg(const rcb_diag *d) { return d ? d->errmsg : "no diagnosis"; }

rcb_status rcb_diag_add_fitted_param(rcb_diag *d, const char *name, double lo, double hi,
                                     int log_param) {
  diag_base_par *p;
  if (!d || !name || strlen(name) >= RCB_DIAG_NAME) return RCB_ERR_ARG;
  if (rcb_grow(&d->alloc, (void **)&d->base, &d->cap_base, d->nbase + 1, sizeof *d->base))
    return rcb_diag_fail(d, RCB_ERR_NOMEM, "out of memory");
  p = &d->base[d->nbase++];
  snprintf(p->name, sizeof p->name, "%s", name);
  p->lo = lo, p->hi = hi, p->logp = log_param;
  return RCB_OK;
}

rcb_status rcb_diag_set_scale(rcb_diag *d, rcb_fit_scale scale) {
  if (!d) return RCB_ERR_ARG;
  d->scale = scale;
  return RCB_OK;
}

rcb_status rcb_diag_set_noise_model(rcb_diag *d, double beta_a, double beta_s) {
  if (!d || !(beta_a >= 0) || !(beta_s >= 0)) return RCB_ERR_ARG;
  if (d->sd && (beta_a > 0 || beta_s > 0))
    return rcb_diag_fail(d, RCB_ERR_ARG, "the noise model and standard deviations: give one "
                         "or the other (both set the weights)");
  d->beta_a = beta_a, d->beta_s = beta_s;
  return RCB_OK;
}

rcb_status rcb_diag_set_noise_phase(rcb_diag *d, double phase_rad) {
  if (!d) return RCB_ERR_ARG;
  if (!(phase_rad >= 0) || !isfinite(phase_rad) || phase_rad > RCB_PI)
    return rcb_diag_fail(d, RCB_ERR_ARG, "phase noise %g rad: expected 0 to pi rad", phase_rad);
  d->phase = phase_rad;
  return RCB_OK;
}

rcb_status rcb_diag_set_sd(rcb_diag *d, const double *sd, size_t n) {
  size_t i, want;
  if (!d) return RCB_ERR_ARG;
  want = rcb_meas_channel_count(d->meas) * rcb_meas_point_count(d->meas);
  if (!sd) {
    rcb_free(&d->alloc, d->sd);
    d->sd = NULL;
    return RCB_OK;
  }
  if (n != want)
    return rcb_diag_fail(d, RCB_ERR_ARG, "%zu standard deviations for a measurement of %zu "
                         "channels x %zu points (%zu)", n, rcb_meas_channel_count(d->meas),
                         rcb_meas_point_count(d->meas), want);
  if (d->beta_a > 0 || d->beta_s > 0)
    return rcb_diag_fail(d, RCB_ERR_ARG, "standard deviations and the noise model: give one "
                         "or the other (both set the weights)");
  for (i = 0; i < n; i++)
    if (sd[i] < 0)
      return rcb_diag_fail(d, RCB_ERR_ARG, "standard deviation %zu = %g: expected >= 0 (0 or "
                           "NaN drops the point)", i, sd[i]);
  if (!d->sd && !(d->sd = rcb_alloc(&d->alloc, n * sizeof *d->sd)))
    return rcb_diag_fail(d, RCB_ERR_NOMEM, "out of memory");
  memcpy(d->sd, sd, n * sizeof *sd);
  return RCB_OK;
}

int rcb_diag_get_sd(const rcb_diag *d, double *sd, size_t n) {
  if (!d || !sd) return RCB_ERR_ARG;
  if (!d->sd) return 0;
  if (n != rcb_meas_channel_count(d->meas) * rcb_meas_point_count(d->meas)) return RCB_ERR_ARG;
  memcpy(sd, d->sd, n * sizeof *sd);
  return 1;
}

/* Whether F is a chi-square: the weights are inverse variances (the noise
 * model, or known standard deviations). */
static int chi2(const rcb_diag *d) { return d->beta_a > 0 || d->beta_s > 0 || d->sd; }

rcb_status rcb_diag_set_band(rcb_diag *d, double lo, double hi) {
  if (!d || !(lo >= 0) || !(hi > lo)) return RCB_ERR_ARG;
  d->band_lo = lo, d->band_hi = hi, d->have_band = 1;
  return RCB_OK;
}

rcb_status rcb_diag_set_refits(rcb_diag *d, size_t n) {
  if (!d) return RCB_ERR_ARG;
  d->nrefit = n;
  return RCB_OK;
}

rcb_status rcb_diag_set_threads(rcb_diag *d, size_t n) {
  if (!d || n < 1 || n > RCB_DIAG_MAX_THREADS) return RCB_ERR_ARG;
  d->nthreads = n;
  return RCB_OK;
}

rcb_status rcb_diag_set_progress(rcb_diag *d, int (*cb)(void *user, size_t done, size_t total),
                                 void *user) {
  if (!d) return RCB_ERR_ARG;
  d->progress = cb, d->progress_user = user;
  return RCB_OK;
}

/* ---- fits ---- */

/* A fit of m with the diagnosis settings, the base parameters (with_base)
 * and the candidate's parameters (c, may be NULL). */
#define FIT_BASE RCB_DIAG_FIT_BASE
#define FIT_LEAD 2u /* make_fit: the candidate's first nlead parameters only (pre-fit) */
#define make_fit rcb_diag_make_fit
#define drop_fit rcb_diag_drop_fit
rcb_status rcb_diag_make_fit(rcb_diag *d, rcb_model *m, unsigned with_base, const diag_cand *c,
                             rcb_fit **out) {
  rcb_fit *f = NULL;
  rcb_status st = rcb_fit_create(&f, m, d->meas, &d->alloc);
  size_t k, npc = !c ? 0 : (with_base & FIT_LEAD) && c->nlead ? c->nlead : c->np;
  if (!st) st = rcb_fit_set_uncertainty(f, 0); /* intervals are not part of a diagnosis */
  if (!st) st = rcb_fit_set_scale(f, d->scale);
  if (!st && (d->beta_a > 0 || d->beta_s > 0))
    st = rcb_fit_set_noise_model(f, d->beta_a, d->beta_s);
  if (!st && d->phase > 0) st = rcb_fit_set_noise_phase(f, d->phase);
  if (!st && d->nref) st = rcb_fit_set_noise_reference(f, d->nref);
  /* the fit's subset masks (screening, pedestal scan) multiply these */
  if (!st && d->sd) st = rcb_fit_set_sd(f, d->sd);
  if (!st && d->have_band) st = rcb_fit_set_band(f, d->band_lo, d->band_hi);
  for (k = 0; !st && (with_base & FIT_BASE) && k < d->nbase; k++) {
    double v;
    size_t j;
    int dup = 0;
    for (j = 0; c && j < c->np; j++) dup |= strcmp(c->pname[j], d->base[k].name) == 0;
    /* another coupling model may not have the parameter (kramer_1: no kt) */
    if (dup || rcb_model_get_param(m, d->base[k].name, &v)) continue;
    st = rcb_fit_add_param(f, d->base[k].name, d->base[k].lo, d->base[k].hi, d->base[k].logp);
  }
  for (k = 0; !st && k < npc; k++)
    st = rcb_fit_add_param(f, c->pname[k], c->lo[k], c->hi[k], c->logp[k]);
  for (k = 0; !st && c && c->chain_kept && k < c->np; k++)
    if (rcb_fit_param_is_chain(c->pname[k]))
      st = rcb_fit_set_chain_value(f, c->pname[k], c->chain_v[k]);
  if (!st && c && c->fam->fit_setup) st = c->fam->fit_setup(c, f);
  if (st) {
    rcb_diag_fail(d, st, "%s", f ? rcb_fit_errmsg(f) : "out of memory");
    rcb_fit_destroy(f);
    return st;
  }
  *out = f;
  return RCB_OK;
}

/* Where the chain parameters of c (the last c->np of fit f) ended, kept
 * with the model of that fit (make_fit restores them). */
static void keep_chain(diag_cand *c, const rcb_fit *f) {
  size_t k, np = rcb_fit_param_count(f);
  for (k = 0; k < c->np && np >= c->np; k++) {
    rcb_fit_param p;
    if (!rcb_fit_param_is_chain(c->pname[k]) || rcb_fit_get_param(f, np - c->np + k, &p))
      continue;
    c->chain_v[k] = p.value;
    c->chain_kept = 1;
  }
}

void rcb_diag_drop_fit(rcb_diag *d, rcb_fit *f) {
  d->stats.evaluations += rcb_fit_sweeps(f);
  rcb_fit_destroy(f);
}

/* F = r^T r with the fit's weights, and the error % of the same sweep. */
static rcb_status objective(rcb_diag *d, rcb_fit *f, double *r, double *F, double *err) {
  rcb_status st = rcb_fit_residuals(f, r);
  size_t i;
  if (st) return rcb_diag_fail(d, st, "%s", rcb_fit_errmsg(f));
  *F = 0;
  for (i = 0; i < d->nres; i++) *F += r[i] * r[i];
  *err = rcb_fit_error_pct(f);
  return RCB_OK;
}

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

/* Which sensors concentrate the misfit (rcb_diag_misfit_get states the
 * rule): the per-channel parts of the adequacy test summed per response. */
/* Whether responses a and b ("C.A.x", "C.A.y") are two directions of one
 * station (a probe pair that may be swapped). */
static int same_station(const char *a, const char *b) {
  const char *da = strrchr(a, '.'), *db = strrchr(b, '.');
  return da && db && da - a == db - b && strncmp(a, b, (size_t)(da - a)) == 0;
}
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

/* The adequacy test of the fitted model as it is (fit f), the null
 * distribution every refit's limit comes from, and where the misfit
 * concentrates. */
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
  d->nbase_fit = rcb_fit_param_count(f);
  d->adeq_mean = d->adeq0.expected + (double)d->nbase_fit;
  d->adeq_sd = d->adeq0.sd;
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
static rcb_status baseline(rcb_diag *d) {
  rcb_model *m = NULL;
  rcb_fit *f = NULL;
  rcb_fit_report rep;
  rcb_status st = rcb_diag_copy_model(d, d->m, &m);
  if (!st) st = make_fit(d, m, 1, NULL, &f);
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
    st = r ? objective(d, f, r, &d->F0, &d->err0) : RCB_ERR_NOMEM;
    rcb_free(&d->alloc, r);
  }
  if (!st) st = baseline_adequacy(d, f);
  drop_fit(d, f);
  if (!st) d->base_model = m; /* the fitted values stay in it */
  else rcb_model_destroy(m);
  return st;
}

/* ---- the score test ---- */

/* The candidate's model and a fit of its own parameters (the base's
 * residual layout); the caller destroys both. */
static rcb_status candidate_fit(rcb_diag *d, const diag_cand *c, rcb_model **m, rcb_fit **f) {
  rcb_status st = rcb_diag_candidate_model(d, c, d->base_model, m);
  *f = NULL;
  if (!st) st = make_fit(d, *m, 0, c, f);
  if (!st && rcb_fit_residual_count(*f) != d->nres)
    st = rcb_diag_fail(d, RCB_ERR_STATE, "%s: residual layout differs", c->desc);
  return st;
}

/* A candidate whose model has other DOFs than the base: its own sweep. */
static rcb_status score_alone(rcb_diag *d, diag_cand *c, diag_basis *b, double *J,
                              int nominal) {
  rcb_model *m = NULL;
  rcb_fit *f = NULL;
  rcb_status st = candidate_fit(d, c, &m, &f);
  if (!st && (st = rcb_fit_jacobian(f, 1, J)))
    rcb_diag_fail(d, st, "%s: %s", c->desc, rcb_fit_errmsg(f));
  if (!st) st = rcb_diag_explained(d, b, J, c->np, nominal ? &c->predicted_nom : &c->predicted);
  drop_fit(d, f);
  rcb_model_destroy(m);
  return st;
}

/* The derivatives of the candidate's parameters, taken on its own model at
 * the neutral value (the base model itself). *same = 0 when that model has
 * other DOFs than the base (dz left empty). */
static rcb_status candidate_dz(rcb_diag *d, const diag_cand *c, size_t ndof, rcb_fit_dz *dz,
                               int *same) {
  rcb_model *m = NULL;
  rcb_fit *f = NULL;
  rcb_status st = rcb_diag_candidate_model(d, c, d->base_model, &m);
  if (!st) st = make_fit(d, m, 0, c, &f); /* no residual layout needed */
  *same = !st && rcb_model_dof_count(m) == ndof && !(c->fam->flags & DIAG_FAM_SCORE_ALONE);
  if (*same && (st = rcb_fit_dz_get(f, &d->alloc, dz))) {
    rcb_diag_fail(d, st, "%s: %s", c->desc, rcb_fit_errmsg(f));
    *same = 0;
  }
  drop_fit(d, f);
  rcb_model_destroy(m);
  return st;
}

typedef struct score_ws {
  rcb_fit *f;           /* the base model, fitted */
  diag_basis basis;     /* its weighted residual and the fitted parameters' columns */
  double *J;            /* nres x batch */
  size_t batch;         /* parameters per sweep */
  rcb_fit_dz dz[RCB_DIAG_BATCH];
  size_t which[RCB_DIAG_BATCH], ncand, npar; /* candidates of the batch, their parameters */
  size_t nlead;         /* the fitted parameters' columns ahead of the batch's (first sweep) */
  int ready;            /* the basis is made (the first sweep done) */
  double *r;            /* nres: the weighted residual of the base model */
  int nominal;          /* scoring at the nominal model: into predicted_nom */
} score_ws;

/* A sensor's gain (and phase): its columns from the base fit's model values
 * (rcb_fit_chain_jacobian: a sensor parameter scales them, no sweep), the
 * same as its own fit's Jacobian, which took a sweep of the base model per
 * sensor (16 of the 30 score sweeps of the run-off case on 32 x 1101). */
static rcb_status score_chain(rcb_diag *d, diag_cand *c, score_ws *w, double *J) {
  const char *names[RCB_DIAG_MAXP];
  size_t k;
  rcb_status st;
  for (k = 0; k < c->np; k++) names[k] = c->pname[k];
  if ((st = rcb_fit_chain_jacobian(w->f, names, c->np, J)))
    return rcb_diag_fail(d, st, "%s: %s", c->desc, rcb_fit_errmsg(w->f));
  return rcb_diag_explained(d, &w->basis, J, c->np,
                            w->nominal ? &c->predicted_nom : &c->predicted);
}

/* One more candidate scored. Candidates finish out of index order (a batch of
 * alike ones is swept together), so the count reported is the number done,
 * not the index of the one just done. */
static rcb_status progress(rcb_diag *d) {
  if (d->progress && d->progress(d->progress_user, ++d->progress_done, d->ncand + d->nrefit))
    return rcb_diag_fail(d, RCB_ERR_STATE, "stopped by the caller");
  return RCB_OK;
}

/* A batch swept: its columns, and on the first sweep the base model's
 * residual and the basis of the fitted parameters' columns (its first
 * w->nlead), then each candidate's score. */
static rcb_status flush_batch(rcb_diag *d, score_ws *w) {
  size_t b, off = w->nlead;
  rcb_status st = RCB_OK;
  if ((w->npar || !w->ready) && (st = rcb_fit_jacobian_dz(w->f, w->dz, w->npar, w->J)))
    rcb_diag_fail(d, st, "scoring the candidates: %s", rcb_fit_errmsg(w->f));
  if (!st && !w->ready && (st = rcb_fit_last_residuals(w->f, w->r)))
    rcb_diag_fail(d, st, "scoring the candidates: %s", rcb_fit_errmsg(w->f));
  if (!st && !w->ready) st = rcb_diag_basis_init(d, &w->basis, w->J, d->nres, w->nlead, w->r);
  w->ready |= !st;
  for (b = 0; !st && b < w->ncand; b++) {
    diag_cand *c = &d->cand[w->which[b]];
    st = rcb_diag_explained(d, &w->basis, w->J + d->nres * off, c->np,
                            w->nominal ? &c->predicted_nom : &c->predicted);
    off += c->np;
    if (!st) st = progress(d);
  }
  rcb_fit_dz_free(&d->alloc, w->dz, w->npar);
  w->ncand = w->npar = w->nlead = 0;
  return st;
}

/* The fitted parameters' columns go in the first batch sweep, which gives
 * the residual too (rcb_fit_last_residuals): the residual and the Jacobian
 * of the fitted parameters took two sweeps of their own per score step
 * before. Not when one of them is a sensor's (no dZ/dp) or they do not fit
 * in a batch: then the two sweeps, and the basis before any batch. */
static rcb_status score_base(rcb_diag *d, score_ws *w) {
  size_t k, nb = rcb_fit_param_count(w->f), n = d->nres;
  int lead = nb < w->batch;
  rcb_status st;
  double *Q0;
  for (k = 0; lead && k < nb; k++) {
    rcb_fit_param p;
    lead = !rcb_fit_get_param(w->f, k, &p) && !rcb_fit_param_is_chain(p.name);
  }
  if (lead) {
    if ((st = rcb_fit_dz_get(w->f, &d->alloc, w->dz)))
      return rcb_diag_fail(d, st, "scoring the candidates: %s", rcb_fit_errmsg(w->f));
    w->npar = w->nlead = nb;
    return RCB_OK;
  }
  if (!(Q0 = rcb_alloc(&d->alloc, n * (nb ? nb : 1) * sizeof *Q0)))
    return rcb_diag_fail(d, RCB_ERR_NOMEM, "out of memory");
  st = rcb_fit_residuals(w->f, w->r);
  if (!st && nb) st = rcb_fit_jacobian(w->f, 1, Q0);
  if (st) rcb_diag_fail(d, st, "scoring the candidates: %s", rcb_fit_errmsg(w->f));
  if (!st) st = rcb_diag_basis_init(d, &w->basis, Q0, n, nb, w->r);
  w->ready = !st;
  rcb_free(&d->alloc, Q0);
  return st;
}

/* A fixed edit of the measurement chain (a sign, a swap: no parameter, no
 * neutral value) is scored by what it does at the fitted base: its
 * predicted reduction is F0 less F with the edit, F from the model values
 * of the score step's sweep at the fitted base (src, rcb_fit_residuals_from;
 * a sweep of its own when src cannot serve: 4 sweeps on 32 x 1101). Only an edit that
 * lowers F there is refitted (with the base parameters: a swap evaluated at
 * the base alone left 13.4 % of error for 5.8 % after its refit, 8 x 151);
 * the 4 swaps of 32 x 1101 cost 62 sweeps of refits, 0.8 s, for nothing on
 * a machine whose probes are right. */
static int fixed_chain(const diag_cand *c) {
  return (c->fam->flags & DIAG_FAM_CHAIN) && c->np == 0;
}

static rcb_status score_fixed_chain(rcb_diag *d, const rcb_fit *src) {
  size_t k;
  double *r = rcb_alloc(&d->alloc, (d->nres ? d->nres : 1) * sizeof *r);
  rcb_status st = r ? RCB_OK : rcb_diag_fail(d, RCB_ERR_NOMEM, "out of memory");
  for (k = 0; !st && k < d->ncand; k++) {
    diag_cand *c = &d->cand[k];
    rcb_model *m = NULL;
    rcb_fit *f = NULL;
    double F = HUGE_VAL, err;
    if (!fixed_chain(c)) continue;
    st = candidate_fit(d, c, &m, &f);
    if (!st && !rcb_fit_residuals_from(f, src, r)) {
      size_t j;
      for (F = 0, j = 0; j < d->nres; j++) F += r[j] * r[j];
    } else if (!st) {
      st = objective(d, f, r, &F, &err);
    }
    if (st != RCB_ERR_NOMEM) st = RCB_OK; /* an edit that cannot be evaluated: not refitted */
    c->predicted = isfinite(F) ? d->F0 - F : 0.0;
    drop_fit(d, f);
    rcb_model_destroy(m);
  }
  rcb_free(&d->alloc, r);
  return st;
}

/* Score every candidate at the fitted base model (nominal = 0: predicted)
 * or at the nominal one (predicted_nom; the base text swapped for the
 * nominal one, so the candidates' models are built on it too). */
static rcb_status score_all(rcb_diag *d, int nominal) {
  rcb_model *m = NULL;
  score_ws w;
  size_t n = d->nres, k, ndof = rcb_model_dof_count(d->m), nlater = 0;
  /* scored after the batches, which give the basis and the model values:
   * a sensor's gain (from those values) and a model with other DOFs */
  size_t *later = rcb_alloc(&d->alloc, (d->ncand ? d->ncand : 1) * sizeof *later);
  rcb_status st;
  memset(&w, 0, sizeof w);
  w.batch = n ? RCB_DIAG_BATCH_VALUES / n : RCB_DIAG_BATCH;
  w.batch = w.batch < RCB_DIAG_BATCH_MIN ? RCB_DIAG_BATCH_MIN
            : w.batch > RCB_DIAG_BATCH  ? RCB_DIAG_BATCH
                                        : w.batch;
  w.J = rcb_alloc(&d->alloc, n * w.batch * sizeof *w.J);
  w.r = rcb_alloc(&d->alloc, (n ? n : 1) * sizeof *w.r);
  w.nominal = nominal;
  st = (later && w.r && w.J) ? RCB_OK : rcb_diag_fail(d, RCB_ERR_NOMEM, "out of memory");
  if (!st) st = rcb_diag_copy_model(d, d->base_model, &m);
  if (!st) ndof = rcb_model_dof_count(m);
  if (!st) st = make_fit(d, m, 1, NULL, &w.f);
  if (!st) st = score_base(d, &w);
  for (k = 0; !st && k < d->ncand; k++) {
    diag_cand *c = &d->cand[k];
    int same = 0;
    if (c->refit_only) continue;
    d->stats.scored += !nominal;
    if (w.npar + c->np > w.batch && (st = flush_batch(d, &w))) break;
    if (!((c->fam->flags & DIAG_FAM_CHAIN) && c->np) &&
        (st = candidate_dz(d, c, ndof, w.dz + w.npar, &same)))
      break;
    if (same) w.which[w.ncand++] = k, w.npar += c->np;
    else later[nlater++] = k;
  }
  if (!st) st = flush_batch(d, &w);
  for (k = 0; !st && k < nlater; k++) {
    diag_cand *c = &d->cand[later[k]];
    st = (c->fam->flags & DIAG_FAM_CHAIN) ? score_chain(d, c, &w, w.J)
                                          : score_alone(d, c, &w.basis, w.J, nominal);
    if (!st) st = progress(d);
  }
  if (!st && !nominal) st = score_fixed_chain(d, w.f);
  rcb_fit_dz_free(&d->alloc, w.dz, w.npar);
  rcb_diag_basis_free(d, &w.basis);
  drop_fit(d, w.f);
  rcb_model_destroy(m);
  rcb_free(&d->alloc, later);
  rcb_free(&d->alloc, w.r);
  rcb_free(&d->alloc, w.J);
  return st;
}

/* ---- refits ---- */

/* Starts of a candidate's refit (rcb_fit_set_starts: further random starts
 * while the result is unsure). A pedestal's start is already the best of a
 * grid over its mass and stiffness (rcb_diag_refit_start), and another
 * coupling model starts from the fitted coupling's stiffnesses. A wrong
 * coupling model stays above the noise floor, "unsure", whatever its start;
 * random starts over the whole bounds of every parameter, the fitted ones
 * too, did not lower any of these objectives by 1e-5 of itself on 32 x 1101
 * and took 476 of the 709 refit sweeps. Only the scored candidates, started
 * at their neutral value, get them, and only while the baseline stayed near
 * the nominal model: when it ran off (d->far) each candidate is fitted from
 * the fitted and from the nominal base, two informed starts in place of the
 * random ones (see refit). */
static size_t refit_starts(const rcb_diag *d, const diag_cand *c) {
  return c->refit_only || (c->fam->flags & DIAG_FAM_ADDS_DOFS) || d->far ? 1 : 3;
}

typedef enum refit_stage {
  REFIT_ALL_POINTS, /* the refit on all points (8 x 151) */
  REFIT_SCREEN,     /* a screen on the frequency subset */
  REFIT_POLISH      /* a polish on all points after a screen */
} refit_stage;
/* How far each stage of a refit goes: RCB_DIAG_BIC_RESOLUTION of BIC (all
 * points; not for a scored candidate on 8 x 151) or RCB_DIAG_SCREEN_RESOLUTION
 * (a screen on the subset) as the fit's relative tolerance on F (tuning.h). */
static rcb_status refit_tolerance(const rcb_diag *d, const diag_cand *c, rcb_fit *f,
                                  refit_stage stage) {
  double scale = chi2(d) ? d->F0 : (double)d->nres;
  double tol = (stage == REFIT_SCREEN ? RCB_DIAG_SCREEN_RESOLUTION : RCB_DIAG_BIC_RESOLUTION) /
               scale;
  double ftol, xtol;
  size_t max_iter;
  rcb_fit_get_limits(f, &max_iter, &ftol, &xtol);
  if ((stage == REFIT_ALL_POINTS && !c->refit_only) || !(scale > 0) || !(tol < 1e-2) ||
      tol <= ftol)
    return RCB_OK;
  return rcb_fit_set_limits(f, max_iter, tol, xtol);
}

static void record_fit(diag_cand *c, rcb_fit *f) {
  size_t k, n = 0;
  c->fitted[0] = '\0';
  for (k = rcb_fit_param_count(f) - c->np; k < rcb_fit_param_count(f); k++) {
    rcb_fit_param p;
    rcb_fit_get_param(f, k, &p);
    n += (size_t)snprintf(c->fitted + n, n < sizeof c->fitted ? sizeof c->fitted - n : 0,
                          "%s%s = %.6g", n ? ", " : "", p.name, p.value);
  }
  if (!c->np) snprintf(c->fitted, sizeof c->fitted, "no parameter of its own");
}

/* The candidate's model built on the base model src (the fitted one, or the
 * nominal one) and its fit, ready to run: start moved where the neutral
 * start sees nothing, starts, tolerance. */
static rcb_status refit_setup(rcb_diag *d, const diag_cand *c, const rcb_model *src,
                              int from_pre, refit_stage stage, rcb_model **m, rcb_fit **f) {
  rcb_status st;
  *m = NULL, *f = NULL;
  st = rcb_diag_candidate_model(d, c, src, m);
  if (!st) st = make_fit(d, *m, FIT_BASE, c, f);
  /* not when the start is where the pre-fit ended (set by the caller) */
  if (!st && !from_pre) st = rcb_diag_refit_start(d, c, *m, *f);
  if (!st) st = rcb_fit_set_starts(*f, refit_starts(d, c), 1);
  if (!st) st = refit_tolerance(d, c, *f, stage);
  return st;
}

/* The screening fit on the frequency subset w (NULL: the fit on all points)
 * stops after cap iterations (RCB_DIAG_SCREEN_ITER): it ranks the starts and
 * brings the polish near its end, and a fit crawling along a bound (a
 * damping at 0) goes on in the polish only if it is the best start. */
static rcb_status screen(rcb_fit *f, const double *w, size_t cap) {
  size_t it = 0;
  double ftol = 0.0, xtol = 0.0;
  rcb_status st = rcb_fit_get_limits(f, &it, &ftol, &xtol);
  if (!st) st = rcb_fit_set_weights(f, w);
  if (!st && w && it > cap) st = rcb_fit_set_limits(f, cap, ftol, xtol);
  if (!st) st = rcb_fit_run(f);
  if (w && it > cap) rcb_fit_set_limits(f, it, ftol, xtol);
  return st;
}

/* The polish of a screened fit on all points, from where the subset left it,
 * with no further starts, and at most RCB_DIAG_POLISH_ITER iterations
 * (tuning.h: a wrong candidate can crawl along a valley). */
static rcb_status polish(rcb_fit *f) {
  size_t it = 0;
  double ftol = 0.0, xtol = 0.0;
  rcb_status st = rcb_fit_get_limits(f, &it, &ftol, &xtol);
  if (!st) st = rcb_fit_set_weights(f, NULL);
  if (!st) st = rcb_fit_set_starts(f, 1, 1);
  if (!st && it > RCB_DIAG_POLISH_ITER)
    st = rcb_fit_set_limits(f, RCB_DIAG_POLISH_ITER, ftol, xtol);
  if (!st) st = rcb_fit_run(f);
  return st;
}

/* The pre-fit of a candidate when the baseline ran off (d->far): its own
 * parameters alone, the base parameters held at their nominal values, on
 * the subset w, at most RCB_DIAG_PREFIT_ITER iterations, from its neutral
 * value (a pedestal: from the best point of its grid). A missing effect
 * that shifts every resonance is judged there by what it really explains,
 * not by the score test: when every model resonance sits beside its
 * measured peak, the first-order score favours effects that flatten peaks
 * (damping), and a joint fit from the neutral value lets the base
 * parameters run off again before the effect's own parameter reaches its
 * value. With 0.15 kg per hub hidden at coupling C (32 x 1101, seed 1) the
 * hub mass scores 5.7 % of F at the nominal model (14th, behind every
 * damping), and its joint fit from there ends with kt on its bound (error
 * 26.6 %); alone it reaches 0.1500 kg and the floor in 15 sweeps, and the
 * joint fit from that start stays there. The nominal refits
 * (RCB_DIAG_NOM_REFITS) are the pre-fits with the lowest objective, and
 * start where their pre-fit ended. */
/* Whether error err is at the noise floor (the fit's own "unsure" limit,
 * RCB_DIAG_FLOOR_FACTOR: tuning.h). */
static int at_floor(double err, double floor) {
  return isfinite(floor) && err < RCB_DIAG_FLOOR_FACTOR * floor;
}

/* Note where pre-fit f of c ended: its parameters, objective and whether
 * its error is at the noise floor (the floor of the same points). */
static void prefit_note(diag_cand *c, const rcb_model *m, const rcb_fit *f, double F,
                        double err, double floor) {
  size_t k, np = rcb_fit_param_count(f);
  for (k = 0; k < c->np; k++) {
    rcb_fit_param p;
    if (!rcb_fit_param_is_chain(c->pname[k])) rcb_model_get_param(m, c->pname[k], &c->pre[k]);
    else if (np >= c->np && !rcb_fit_get_param(f, np - c->np + k, &p)) c->pre[k] = p.value;
  }
  if (isfinite(F)) c->pre_F = F;
  c->pre_floor = at_floor(err, floor);
}

/* A pedestal's pre-fit on the subset: the best point of its grid
 * (rcb_diag_refit_start, 69 subset sweeps), evaluated once, not iterated
 * from there. On the 0.15 kg hub case the four pedestals' 4 iterations took
 * 12-21 sweeps each and ended at F = 2.0e6 against 4529 for the hub mass;
 * their joint refit from the nominal model, when they are within
 * RCB_DIAG_PRE_RATIO of the best, starts at the grid point. */
static rcb_status prefit_grid(rcb_diag *d, diag_cand *c, const rcb_model *m, rcb_fit *f) {
  size_t n = rcb_fit_residual_count(f), i;
  double *r = rcb_alloc(&d->alloc, (n ? n : 1) * sizeof *r), F = 0.0;
  rcb_fit_report rep;
  rcb_status st = r ? rcb_fit_residuals(f, r) : RCB_ERR_NOMEM;
  for (i = 0; !st && i < n; i++) F += r[i] * r[i];
  if (!st) st = rcb_fit_get_report(f, &rep);
  if (!st) prefit_note(c, m, f, F, rcb_fit_error_pct(f), rep.floor_pct);
  rcb_free(&d->alloc, r);
  return st;
}

/* Any other pre-fit: at most RCB_DIAG_PREFIT_ITER iterations
 * (RCB_DIAG_PREFIT_ITER_SUBSET and RCB_DIAG_PREFIT_FTOL on the subset w,
 * but for an added mass or inertia while no pre-fit has ended at the noise
 * floor: see prefit_selected). */
static rcb_status prefit_run(const rcb_diag *d, diag_cand *c, const rcb_model *m, rcb_fit *f,
                             const double *w) {
  size_t it = 0;
  double ftol = 0.0, xtol = 0.0;
  rcb_fit_report rep;
  int crawl = w && (!c->node || d->node_crawl); /* the subset's limits */
  rcb_status st = rcb_fit_set_starts(f, 1, 1);
  if (!st) st = rcb_fit_get_limits(f, &it, &ftol, &xtol);
  if (!st)
    st = rcb_fit_set_limits(f, crawl ? RCB_DIAG_PREFIT_ITER_SUBSET : RCB_DIAG_PREFIT_ITER,
                            crawl ? fmax(ftol, RCB_DIAG_PREFIT_FTOL) : ftol, xtol);
  if (!st) st = rcb_fit_run(f);
  if (!st) st = rcb_fit_get_report(f, &rep);
  if (!st) prefit_note(c, m, f, rep.objective, rep.error_pct, rep.floor_pct);
  return st;
}

static rcb_status prefit(rcb_diag *d, diag_cand *c, const double *w) {
  rcb_model *m = NULL;
  rcb_fit *f = NULL;
  rcb_status st = rcb_diag_candidate_model(d, c, d->nom_model, &m);
  c->prefitted = 1;
  c->pre_F = HUGE_VAL;
  c->pre_floor = 0;
  if (!st) st = make_fit(d, m, FIT_LEAD, c, &f);
  if (!st) st = rcb_diag_refit_start(d, c, m, f);
  if (!st) st = rcb_fit_set_weights(f, w);
  if (!st)
    st = w && (c->fam->flags & DIAG_FAM_ADDS_DOFS) ? prefit_grid(d, c, m, f)
                                                  : prefit_run(d, c, m, f, w);
  drop_fit(d, f);
  rcb_model_destroy(m);
  if (st == RCB_ERR_NOMEM) return rcb_diag_fail(d, st, "pre-fitting %s: out of memory", c->desc);
  return RCB_OK; /* a candidate that cannot be pre-fitted is not refitted from there */
}

/* BIC change, adequacy limit and claim of a refitted candidate (F, err set;
 * k: its own parameters, refitted with the base's). */
static void judge(const rcb_diag *d, diag_cand *c, double k) {
  double N = (double)d->nres, expected = d->adeq_mean - ((double)d->nbase_fit + k);
  rcb_evidence e;
  memset(&e, 0, sizeof e);
  /* with noise-aware weights or known standard deviations F is a
   * chi-square: BIC = F + k ln N; else the Gaussian likelihood with the
   * variance estimated */
  e.delta_bic = chi2(d) ? (c->F - d->F0) + k * log(N) : N * log(c->F / d->F0) + k * log(N);
  c->chi2_limit = d->adeq0.known ? expected + RCB_ADEQUACY_Z * d->adeq_sd : (double)NAN;
  c->dispersion = d->adeq0.known && expected > 0 ? c->F / expected : (double)NAN;
  e.error_before_pct = d->err0, e.error_after_pct = c->err;
  e.chi2 = c->F, e.chi2_limit = c->chi2_limit;
  e.params = k, e.residuals = N, e.dispersion = c->dispersion;
  e.tried = (double)d->ncand;
  e.white = d->adeq0.known && c->white_z <= RCB_ADEQUACY_Z;
  c->dbic = rcb_evidence_dbic(&e);
  c->significant = rcb_evidence_significant(&e);
  c->adequate = rcb_evidence_adequate(&e);
  c->claim = rcb_evidence_claim(&e);
}

/* The whiteness of the residual of fit f's last evaluation (on all points). */
static void whiteness(diag_cand *c, rcb_fit *f) { c->white_z = rcb_fit_last_white_z(f); }

/* A refit with nothing to fit (kramer_1, rigid): the model evaluated. */
static rcb_status evaluate_only(rcb_diag *d, diag_cand *c, rcb_model **m, rcb_fit *f) {
  double *r = rcb_alloc(&d->alloc, d->nres * sizeof *r);
  rcb_status st = r ? objective(d, f, r, &c->F, &c->err) : RCB_ERR_NOMEM;
  rcb_free(&d->alloc, r);
  if (st) return st;
  c->refitted = 1;
  c->polished = 1;
  whiteness(c, f);
  judge(d, c, 0.0);
  snprintf(c->fitted, sizeof c->fitted, "no parameter");
  c->model = *m, *m = NULL; /* kept: --apply writes it */
  return RCB_OK;
}

/* A refit fitted or evaluated on all points: its figures. */
static void refit_result(rcb_diag *d, diag_cand *c, rcb_model **m, rcb_fit *f, double F,
                         double err, int polished) {
  c->refitted = 1;
  c->polished = polished;
  c->F = F, c->err = err;
  whiteness(c, f);
  judge(d, c, (double)c->np);
  record_fit(c, f);
  keep_chain(c, f);
  rcb_model_destroy(c->model);
  c->model = *m, *m = NULL;
}

/* The first step of the refit of candidate c with the base parameters, from
 * the fitted base model (c->from_fit) and from the nominal one (c->from_nom:
 * the baseline fit ran off, and c scores high at the nominal model): a
 * missing effect that pulled the base parameters far leaves the fitted point
 * in a basin a joint fit does not leave. With w (a subset of the
 * frequencies, subset()) each start is screened on the subset and the best
 * is kept in c->model (c->screened) for the steps that follow once every
 * candidate's screen has ended (refit_restart, refit_evaluate,
 * refit_polish); without, the fit on all points is the refit. */
static rcb_status refit_screen(rcb_diag *d, diag_cand *c, const double *w) {
  rcb_model *m[2] = {NULL, NULL};
  rcb_fit *f[2] = {NULL, NULL};
  double F[2] = {HUGE_VAL, HUGE_VAL};
  char why[320] = "";
  size_t s, b = 0;
  int from_pre;
  /* from a run-off fit on the subset, RCB_DIAG_PREFIT_ITER_SUBSET iterations
   * first, and on only when within RCB_DIAG_PRE_RATIO of the best pre-fit
   * (tuning.h) */
  int far_start = w && d->far;
  rcb_fit_report rep;
  rcb_status st = RCB_OK;
  d->stats.refits++;
  for (s = 0; s < 2; s++) {
    if (!(s ? c->from_nom : c->from_fit)) continue;
    from_pre = s && c->prefitted && c->pre_F < HUGE_VAL;
    st = refit_setup(d, c, s ? d->nom_model : d->base_model, from_pre,
                     w ? REFIT_SCREEN : REFIT_ALL_POINTS, &m[s], &f[s]);
    if (!st && w) st = rcb_fit_set_starts(f[s], RCB_DIAG_STARTS_SUBSET, 1); /* see refit_restart */
    if (!st && from_pre) { /* where its pre-fit ended */
      size_t k;
      for (k = 0; !st && k < c->np; k++)
        st = rcb_fit_param_is_chain(c->pname[k])
                 ? rcb_fit_set_chain_value(f[s], c->pname[k], c->pre[k])
                 : rcb_model_set_param(m[s], c->pname[k], c->pre[k]);
    }
    if (st == RCB_ERR_NOMEM) break;
    if (st) { /* a candidate that cannot be built is reported, not fatal */
      if (!why[0]) snprintf(why, sizeof why, "not fitted: %.300s", d->errmsg);
      continue;
    }
    if (rcb_fit_param_count(f[s]) == 0) break; /* nothing to fit: evaluated below */
    st = screen(f[s], w, !s && far_start ? RCB_DIAG_PREFIT_ITER_SUBSET : RCB_DIAG_SCREEN_ITER);
    if (!st && !s && far_start && !rcb_fit_get_report(f[s], &rep) && !rep.converged &&
        !(rep.objective > RCB_DIAG_PRE_RATIO * d->pre_best))
      st = screen(f[s], w, RCB_DIAG_SCREEN_ITER - RCB_DIAG_PREFIT_ITER_SUBSET); /* on from there */
    if (st == RCB_ERR_NOMEM) {
      rcb_diag_fail(d, st, "refitting %s: %s", c->desc, rcb_fit_errmsg(f[s]));
      break;
    }
    if (st) { /* a candidate that cannot be fitted is reported, not fatal */
      if (!why[0]) snprintf(why, sizeof why, "refit failed: %.300s", rcb_fit_errmsg(f[s]));
      continue;
    }
    rcb_fit_get_report(f[s], &rep);
    F[s] = rep.objective;
    if (F[s] < F[b]) b = s;
  }
  if (st != RCB_ERR_NOMEM) {
    st = RCB_OK;
    if (f[b] && rcb_fit_param_count(f[b]) == 0) {
      st = evaluate_only(d, c, &m[b], f[b]);
    } else if (!(F[b] < HUGE_VAL)) {
      snprintf(c->fitted, sizeof c->fitted, "%s", why);
    } else if (w) { /* kept for refit_restart and refit_evaluate */
      rcb_fit_get_report(f[b], &rep);
      c->screened = 1;
      c->screen_F = F[b];
      c->screen_unsure = rep.unsure;
      c->screen_floor = at_floor(rep.error_pct, rep.floor_pct);
      keep_chain(c, f[b]);
      c->model = m[b], m[b] = NULL;
    } else {
      rcb_fit_get_report(f[b], &rep);
      refit_result(d, c, &m[b], f[b], rep.objective, rep.error_pct, 1);
    }
  }
  for (s = 0; s < 2; s++) {
    drop_fit(d, f[s]);
    rcb_model_destroy(m[s]);
  }
  return st;
}

/* The second step of a screened refit (c->screened) whose screen ended
 * unsure, when no candidate's screen reached the noise floor (d->screen_floor):
 * the random starts of refit_starts the first step left out, screened on
 * the subset w from the same points a run of them all would have drawn
 * (rcb_fit_set_first_start); the lower of the two ends is kept. */
static rcb_status refit_restart(rcb_diag *d, diag_cand *c, const double *w) {
  rcb_model *m = NULL;
  rcb_fit *f = NULL;
  rcb_fit_report rep = {0};
  size_t n = refit_starts(d, c);
  rcb_status st;
  if (!c->screened || !c->screen_unsure || d->screen_floor || n <= RCB_DIAG_STARTS_SUBSET)
    return RCB_OK;
  d->stats.restarts++;
  st = rcb_diag_copy_model(d, c->model, &m);
  if (!st) st = make_fit(d, m, 1, c, &f);
  if (!st) st = rcb_fit_set_starts(f, n, 1);
  if (!st) st = rcb_fit_set_first_start(f, RCB_DIAG_STARTS_SUBSET);
  if (!st) st = refit_tolerance(d, c, f, REFIT_SCREEN);
  if (!st) st = screen(f, w, RCB_DIAG_SCREEN_ITER);
  if (!st) st = rcb_fit_get_report(f, &rep);
  if (!st && rep.objective < c->screen_F) {
    c->screen_F = rep.objective;
    keep_chain(c, f);
    rcb_model_destroy(c->model);
    c->model = m, m = NULL;
  }
  if (st == RCB_ERR_NOMEM)
    rcb_diag_fail(d, st, "refitting %s: %s", c->desc, f ? rcb_fit_errmsg(f) : "out of memory");
  drop_fit(d, f);
  rcb_model_destroy(m);
  return st == RCB_ERR_NOMEM ? st : RCB_OK; /* a failed restart leaves the first screen */
}

/* The third step of a screened refit (c->screened), once every screen has
 * ended: evaluated on all points where its screen ended (its model in
 * c->model). */
static rcb_status refit_evaluate(rcb_diag *d, diag_cand *c) {
  rcb_model *m = c->model;
  rcb_fit *f = NULL;
  double *r = NULL, F = 0.0, err = 0.0;
  rcb_status st;
  if (!c->screened) return RCB_OK;
  c->model = NULL;
  st = make_fit(d, m, 1, c, &f);
  if (!st) st = (r = rcb_alloc(&d->alloc, d->nres * sizeof *r)) ? RCB_OK : RCB_ERR_NOMEM;
  if (!st) st = objective(d, f, r, &F, &err);
  if (!st) refit_result(d, c, &m, f, F, err, 0);
  else if (st != RCB_ERR_NOMEM)
    snprintf(c->fitted, sizeof c->fitted, "refit failed: %.300s", d->errmsg);
  rcb_free(&d->alloc, r);
  drop_fit(d, f);
  rcb_model_destroy(m);
  if (st == RCB_ERR_NOMEM) return rcb_diag_fail(d, st, "refitting %s: out of memory", c->desc);
  return RCB_OK;
}

/* Whether the candidate's own parameters all ended their screen at 0, the
 * neutral value and lower bound of a linear one (an added mass, a damping):
 * its model is then the model as it is, and a polish would refit only the
 * base parameters. On large_null (seed 4) five added masses and inertias
 * ended so, each polish 19-28 sweeps on all points at 10-14 sweeps an
 * iteration along the bound, to lower F by 1 at most. */
static int at_neutral(const diag_cand *c) {
  size_t k;
  for (k = 0; k < c->np; k++) {
    double v = 1.0;
    if (c->logp[k] || c->lo[k] != 0.0 || rcb_model_get_param(c->model, c->pname[k], &v) ||
        v > 0.0)
      return 0;
  }
  return c->np > 0;
}

/* Whether the polish of c (its fit f, at its evaluation c->F) cannot make
 * it lead d->cand[d->lead]: one Jacobian on all points. *out stays 0 when
 * that cannot be told (a failed Jacobian: the polish runs). */
static rcb_status cannot_lead(rcb_diag *d, const diag_cand *c, rcb_fit *f, int *out) {
  const diag_cand *L = d->lead < d->ncand ? &d->cand[d->lead] : NULL;
  size_t n, np = rcb_fit_param_count(f), nb, k;
  double *J, *r, pred = 0.0, own = 0.0, Fb, N = (double)d->nres, dbic;
  diag_basis b;
  rcb_status st = rcb_fit_prepare(f); /* the residual layout (it allocates) */
  *out = 0;
  if (st == RCB_ERR_NOMEM) return rcb_diag_fail(d, st, "out of memory");
  if (st) return RCB_OK; /* the polish runs, and says what failed */
  n = rcb_fit_residual_count(f);
  if (!L || L == c || !L->polished || L->claim != RCB_CLAIM_EXPLAINS || np < c->np ||
      n != d->nres || !n)
    return RCB_OK;
  nb = np - c->np;
  if (!(J = rcb_alloc(&d->alloc, (n * np + n) * sizeof *J)))
    return rcb_diag_fail(d, RCB_ERR_NOMEM, "out of memory");
  r = J + n * np;
  if ((st = rcb_fit_residuals(f, r)) || (st = rcb_fit_jacobian(f, 1, J))) {
    rcb_free(&d->alloc, J);
    if (st == RCB_ERR_NOMEM) /* out of memory fails the run; anything else: the polish runs */
      return rcb_diag_fail(d, st, "out of memory");
    return RCB_OK;
  }
  st = rcb_diag_basis_init(d, &b, J, n, nb, r);
  if (!st) {
    for (k = 0; k < b.rank; k++) pred += b.rt[k] * b.rt[k]; /* the base's columns */
    st = rcb_diag_explained(d, &b, J + n * nb, c->np, &own); /* its own, beyond */
    pred += own;
    rcb_diag_basis_free(d, &b);
  }
  rcb_free(&d->alloc, J);
  if (st) return st == RCB_ERR_NOMEM ? st : RCB_OK; /* the polish runs */
  Fb = c->F - RCB_DIAG_GN_SLACK * pred;
  if (!(Fb > 0.0)) return RCB_OK;
  dbic = chi2(d) ? (Fb - d->F0) + (double)c->np * log(N)
                 : N * log(Fb / d->F0) + (double)c->np * log(N);
  *out = dbic > L->dbic;
  return RCB_OK;
}

/* The fourth step: a screened refit within RCB_DIAG_POLISH_WITHIN of the
 * lowest objective of all refits (d->best_F) polished on all points, on a
 * copy of its model (a failed polish leaves the evaluation); not one that
 * ended at its neutral value (at_neutral), nor one that cannot lead
 * (cannot_lead). */
static rcb_status refit_polish(rcb_diag *d, diag_cand *c) {
  rcb_model *m = NULL;
  rcb_fit *f = NULL;
  rcb_fit_report rep = {0};
  rcb_status st;
  int skip = 0;
  if (!c->screened || !c->refitted || c->polished ||
      !(c->F <= (1.0 + RCB_DIAG_POLISH_WITHIN) * d->best_F) || at_neutral(c))
    return RCB_OK;
  st = rcb_diag_copy_model(d, c->model, &m);
  if (!st) st = make_fit(d, m, 1, c, &f);
  if (!st) st = cannot_lead(d, c, f, &skip);
  if (!st && skip) {
    drop_fit(d, f);
    rcb_model_destroy(m);
    return RCB_OK;
  }
  if (!st) st = refit_tolerance(d, c, f, REFIT_POLISH);
  if (!st) st = polish(f);
  if (!st) st = rcb_fit_get_report(f, &rep);
  if (!st) refit_result(d, c, &m, f, rep.objective, rep.error_pct, 1);
  else if (st == RCB_ERR_NOMEM)
    rcb_diag_fail(d, st, "refitting %s: %s", c->desc, f ? rcb_fit_errmsg(f) : "out of memory");
  drop_fit(d, f);
  rcb_model_destroy(m);
  return st == RCB_ERR_NOMEM ? st : RCB_OK;
}

/* Rank: refitted by BIC change, then the rest by predicted reduction. */
static int better(const diag_cand *a, const diag_cand *b) {
  if (a->refitted != b->refitted) return a->refitted;
  /* what may be said first: a candidate that explains, then one that is
   * significant, then the rest; each by BIC (the text's first candidate is
   * the table's, and --apply 1 applies it) */
  if (a->refitted && a->claim != b->claim) return a->claim > b->claim;
  if (a->refitted) return a->dbic < b->dbic;
  return a->predicted > b->predicted;
}

static void sort_order(rcb_diag *d) {
  size_t i, j;
  for (i = 0; i < d->ncand; i++) d->order[i] = i;
  for (i = 1; i < d->ncand; i++)
    for (j = i; j > 0 && better(&d->cand[d->order[j]], &d->cand[d->order[j - 1]]); j--) {
      size_t t = d->order[j];
      d->order[j] = d->order[j - 1];
      d->order[j - 1] = t;
    }
}

/* The candidates a step fits, in order, for rcb_diag_for_each. */
typedef struct cand_jobs {
  size_t *k;      /* candidate indices */
  size_t n, todo; /* jobs; refits reported to the progress callback */
  double *w;      /* the frequency subset, or NULL */
} cand_jobs;

static rcb_status prefit_job(rcb_diag *d, size_t i, void *ctx) {
  cand_jobs *j = ctx;
  return prefit(d, &d->cand[j->k[i]], j->w);
}

static rcb_status refit_job(rcb_diag *d, size_t i, void *ctx) {
  cand_jobs *j = ctx;
  return refit_screen(d, &d->cand[j->k[i]], j->w);
}

static rcb_status restart_job(rcb_diag *d, size_t i, void *ctx) {
  cand_jobs *j = ctx;
  return refit_restart(d, &d->cand[j->k[i]], j->w);
}

/* Whether a refit's screen ended at the noise floor (d->screen_floor, read by
 * refit_restart). */
static void any_screen_at_floor(rcb_diag *d) {
  size_t k;
  d->screen_floor = 0;
  for (k = 0; k < d->ncand; k++) d->screen_floor |= d->cand[k].screened && d->cand[k].screen_floor;
}

static rcb_status evaluate_job(rcb_diag *d, size_t i, void *ctx) {
  cand_jobs *j = ctx;
  return refit_evaluate(d, &d->cand[j->k[i]]);
}

static rcb_status polish_job(rcb_diag *d, size_t i, void *ctx) {
  cand_jobs *j = ctx;
  return refit_polish(d, &d->cand[j->k[i]]);
}

/* The lowest objective on all points of the refits: what refit_polish
 * measures from. */
static void lowest_refit(rcb_diag *d) {
  size_t k;
  d->best_F = HUGE_VAL;
  for (k = 0; k < d->ncand; k++)
    if (d->cand[k].refitted && d->cand[k].F < d->best_F) d->best_F = d->cand[k].F;
}

/* After a refit: progress (scored candidates only; the count only rises). */
static rcb_status refit_done(rcb_diag *d, size_t i, void *ctx) {
  cand_jobs *j = ctx;
  if (d->cand[j->k[i]].refit_only) return RCB_OK;
  if (d->progress_done < d->ncand) d->progress_done = d->ncand; /* refit-only ones */
  if (d->progress && d->progress(d->progress_user, ++d->progress_done, d->ncand + j->todo))
    return rcb_diag_fail(d, RCB_ERR_STATE, "stopped by the caller");
  return RCB_OK;
}

/* Whether a pre-fit ended at the noise floor. */
static int pre_at_floor(const rcb_diag *d) {
  size_t k;
  for (k = 0; k < d->ncand; k++)
    if (d->cand[k].pre_floor) return 1;
  return 0;
}

/* The same added mass (or inertia) at node i + step of the same shaft, NULL
 * when there is none. */
static diag_cand *next_place(rcb_diag *d, const diag_cand *c, int step) {
  size_t k, want = step < 0 ? c->node - 1 : c->node + 1;
  if (!c->node || want == 0) return NULL;
  for (k = 0; k < d->ncand; k++) {
    diag_cand *e = &d->cand[k];
    if (e->fam == c->fam && e->node == want && e->variant == c->variant && e->shaft == c->shaft)
      return e;
  }
  return NULL;
}

/* A large added mass is poorly placed by the first-order score (the 1.3 kg
 * at DB of the signals case ranks 43rd at the nominal model, its neighbour
 * at node #19 14th), but the pre-fit's objective is smooth along the shaft:
 * from the best pre-fitted mass and inertia, walk to the neighbouring nodes
 * of the same shaft while their pre-fit objective falls (serial: the same
 * result on any number of threads). Not when a pre-fit already ended at the
 * noise floor: nothing is left for the walk to explain (the 0.15 kg hub
 * case: the hub mass there, the walk 187 subset sweeps, 0.85 s, to added
 * masses at F = 1e6 against 4529). */
/* Whether candidate k is the first of its (family, variant) among the
 * candidates that sit at nodes (DIAG_FAM_PLACE_WALK). */
static int first_of_kind(const rcb_diag *d, size_t k) {
  size_t i;
  const diag_cand *c = &d->cand[k];
  if (!(c->fam->flags & DIAG_FAM_PLACE_WALK) || !c->node) return 0;
  for (i = 0; i < k; i++)
    if (d->cand[i].fam == c->fam && d->cand[i].variant == c->variant && d->cand[i].node)
      return 0;
  return 1;
}

static rcb_status place_search(rcb_diag *d, const double *w) {
  size_t k, i;
  rcb_status st;
  if (pre_at_floor(d)) return RCB_OK;
  for (k = 0; k < d->ncand; k++) { /* each kind: the best mass, the best inertia, ... */
    diag_cand *best = NULL;
    int step;
    if (!first_of_kind(d, k)) continue;
    for (i = k; i < d->ncand; i++) {
      diag_cand *e = &d->cand[i];
      if (e->fam == d->cand[k].fam && e->node && e->variant == d->cand[k].variant &&
          e->prefitted && e->pre_F < HUGE_VAL && (!best || e->pre_F < best->pre_F))
        best = e;
    }
    if (!best) continue;
    for (step = -1; step <= 1; step += 2) {
      diag_cand *at = best, *nx;
      while ((nx = next_place(d, at, step)) != NULL) {
        if (!nx->prefitted && (st = prefit(d, nx, w))) return st;
        if (!(nx->pre_F < at->pre_F)) break;
        at = nx;
      }
    }
  }
  return RCB_OK;
}

/* Move the candidates k[0 .. n) of group (0: the others, 1: an added mass
 * or inertia at a node, 2: a pedestal) first when want, else those of the
 * other groups first; the order within each part kept. The count moved. */
static size_t stable_first(const rcb_diag *d, size_t *k, size_t n, unsigned group, unsigned want) {
  size_t i, n1 = 0;
  for (i = 0; i < n; i++) { /* stable partition: those of the group first */
    size_t t = k[i];
    unsigned g = (d->cand[t].fam->flags & DIAG_FAM_ADDS_DOFS) ? 2u : d->cand[t].node ? 1u : 0u;
    if ((g == group) != want) continue;
    memmove(k + n1 + 1, k + n1, (i - n1) * sizeof *k);
    k[n1++] = t;
  }
  return n1;
}

/* Pre-fit the candidates j->k[0 .. j->n): the others first, then the added
 * masses and inertias at nodes, then the pedestals, whose grids (69 subset
 * sweeps each) are left out on the subset once another pre-fit ended at the
 * noise floor: they would only look for a rival there. On the hub cases the
 * pedestals' grids were 280 of the 633 sweeps and ended 52-68 x (0.07 kg)
 * and 435-560 x (0.15 kg) above the hub mass, which was at the floor. Where
 * nothing is at the floor (a pedestal the truth), they run as before. For
 * the same reason the added masses and inertias then take the subset's
 * limits of the other pre-fits (RCB_DIAG_PREFIT_ITER_SUBSET,
 * RCB_DIAG_PREFIT_FTOL) instead of RCB_DIAG_PREFIT_ITER: their objectives
 * serve the place walk (place_search), which does not run then. On the
 * 0.15 kg hub case (bench_diagnose --large --hub-mass 0.15) the added mass
 * at node #7 stopped after 6 subset sweeps instead of 23, at F = 3.2e6
 * against 4529 for the hub mass either way. */
static rcb_status prefit_selected(rcb_diag *d, cand_jobs *j) {
  cand_jobs ped = *j, node = *j;
  size_t n0, n1, i;
  rcb_status st;
  /* the others, then the added masses and inertias, then the pedestals */
  n1 = stable_first(d, j->k, j->n, 2, 0);  /* not pedestals first */
  n0 = stable_first(d, j->k, n1, 0, 1);    /* of those, the others first */
  d->node_crawl = 0;
  if ((st = rcb_diag_for_each(d, n0, prefit_job, j, NULL))) return st;
  d->node_crawl = j->w && pre_at_floor(d);
  node.k = j->k + n0, node.n = n1 - n0;
  st = rcb_diag_for_each(d, node.n, prefit_job, &node, NULL);
  d->node_crawl = 0;
  if (st) return st;
  ped.k = j->k + n1, ped.n = j->n - n1;
  if (j->w && pre_at_floor(d)) {
    for (i = 0; i < ped.n; i++) d->cand[ped.k[i]].prefitted = 0; /* not pre-fitted */
    return RCB_OK;
  }
  return rcb_diag_for_each(d, ped.n, prefit_job, &ped, NULL);
}

/* Whether candidate c's family takes one refit per variant
 * (DIAG_FAM_ONE_REFIT) and another of its variant already has it; such a
 * family takes no pre-fit of the run-off path (prefit). On the ROSS case of
 * a cross-coupling at B3 (8 x 151), the 40 shaft-element candidates took
 * five of the eight refits with scores of 17-39 % (the cross-coupling
 * scores 12.7 %) and it was not refitted at all; on the signals case of
 * 1.3 kg at DB (test_signals_diagnose mass_DB, a run-off baseline) their
 * pre-fits, one per variant and the walk to its neighbours, ended below the
 * added mass at DB (elements 6 and 7 of shaft B, on either side of DB, at
 * 5 x their mass: 3.65 and 4.22 % against 0.546 % for the mass at DB),
 * which then took none of the three nominal refits. */
static int one_taken(const rcb_diag *d, const diag_cand *c, int prefit) {
  size_t k;
  if (!(c->fam->flags & DIAG_FAM_ONE_REFIT)) return 0;
  /* on the run-off path only its first variant (an element's stiffness: a
   * crack pulls the baseline off too, kr 221 -> 18.9 N m/rad) takes one
   * pre-fit, the best scored */
  if (prefit && c->variant != 0) return 1;
  for (k = 0; k < d->ncand; k++) {
    const diag_cand *e = &d->cand[k];
    if (e != c && e->fam == c->fam && e->variant == c->variant &&
        (prefit ? e->prefitted : e->from_fit))
      return 1;
  }
  return 0;
}

/* With the baseline run off: the best RCB_DIAG_NOM_PREFITS at the nominal
 * model pre-fitted alone there, the RCB_DIAG_NOM_REFITS best pre-fits
 * marked for a refit from where they ended. */
static rcb_status nominal_starts(rcb_diag *d, cand_jobs *j) {
  size_t k, n;
  double best = HUGE_VAL;
  d->pre_best = HUGE_VAL;
  rcb_status st;
  for (j->n = 0; j->n < RCB_DIAG_NOM_PREFITS; j->n++) {
    diag_cand *c = NULL;
    for (k = 0; k < d->ncand; k++) {
      diag_cand *e = &d->cand[k];
      if (!e->refit_only && !e->prefitted && e->predicted_nom > 0 && !one_taken(d, e, 1) &&
          (!c || e->predicted_nom > c->predicted_nom))
        c = e;
    }
    if (!c) break;
    c->prefitted = 1;
    j->k[j->n] = (size_t)(c - d->cand);
  }
  if ((st = prefit_selected(d, j))) return st;
  if ((st = place_search(d, j->w))) return st;
  for (n = 0; n < RCB_DIAG_NOM_REFITS; n++) {
    diag_cand *c = NULL;
    for (k = 0; k < d->ncand; k++) {
      diag_cand *e = &d->cand[k];
      if (e->prefitted && !e->from_nom && e->pre_F < HUGE_VAL && (!c || e->pre_F < c->pre_F))
        c = e;
    }
    if (!c) break;
    if (!n) best = d->pre_best = c->pre_F;
    else if (j->w && !(c->pre_F <= RCB_DIAG_PRE_RATIO * best)) break;
    j->todo += !c->from_fit;
    c->from_nom = 1;
  }
  return RCB_OK;
}

static rcb_status refit_best(rcb_diag *d) {
  /* a run-off fit is a poor start (every damping candidate refitted there
   * on the 0.15 kg hub case stayed at F0): its best RCB_DIAG_NOM_REFITS only */
  size_t nfit = d->far && d->nrefit > RCB_DIAG_NOM_REFITS ? RCB_DIAG_NOM_REFITS : d->nrefit, k;
  cand_jobs j;
  rcb_status st;
  memset(&j, 0, sizeof j);
  if ((st = rcb_diag_subset_weights(d, &j.w))) return st;
  /* on the subset (32 x 1101) none: the three refits from the run-off fit
   * of the 0.15 kg hub case took 4.3 s and ended at 72-92 %, and the 0.07 kg
   * hub reaches the same optimum from its pre-fit; the other coupling models
   * are still refitted from there (they have no pre-fit) */
  if (d->far && j.w) nfit = 0;
  if (!(j.k = rcb_alloc(&d->alloc, (d->ncand ? d->ncand : 1) * sizeof *j.k))) {
    rcb_free(&d->alloc, j.w);
    return rcb_diag_fail(d, RCB_ERR_NOMEM, "out of memory");
  }
  sort_order(d); /* by predicted reduction (nothing refitted yet) */
  for (k = 0; k < d->ncand; k++) {
    diag_cand *c = &d->cand[d->order[k]];
    c->from_fit = (c->refit_only && !(fixed_chain(c) && !(c->predicted > 0))) ||
                  (j.todo < nfit && c->predicted > 0 && !one_taken(d, c, 0));
    j.todo += !c->refit_only && c->from_fit;
  }
  if (d->far) st = nominal_starts(d, &j);
  /* the scored candidates in rank order, then those refitted only */
  for (j.n = 0, k = 0; k < d->ncand; k++) {
    diag_cand *c = &d->cand[d->order[k]];
    if (!c->refit_only && (c->from_fit || c->from_nom)) j.k[j.n++] = d->order[k];
  }
  for (k = 0; k < d->ncand; k++)
    if (d->cand[k].refit_only && d->cand[k].from_fit) j.k[j.n++] = k;
  if (!st) st = rcb_diag_for_each(d, j.n, refit_job, &j, refit_done);
  if (!st) any_screen_at_floor(d);
  if (!st) st = rcb_diag_for_each(d, j.n, restart_job, &j, NULL);
  if (!st) st = rcb_diag_for_each(d, j.n, evaluate_job, &j, NULL);
  if (!st) lowest_refit(d);
  /* the lowest first, alone: what the others' polish must beat (cannot_lead) */
  d->lead = d->ncand;
  for (k = 0; !st && k < d->ncand; k++)
    if (d->cand[k].refitted && d->cand[k].F == d->best_F) d->lead = k;
  if (!st && d->lead < d->ncand) st = refit_polish(d, &d->cand[d->lead]);
  if (!st) st = rcb_diag_for_each(d, j.n, polish_job, &j, NULL);
  if (!st) sort_order(d);
  rcb_free(&d->alloc, j.w);
  rcb_free(&d->alloc, j.k);
  return st;
}

/* ---- large effects, named where the misfit is placed (issue #23 item 5) ---- */

/* The model node a candidate acts at, from its node (a place walk) or the
 * station its first parameter names ("bearing.B2.kyy": B2, "disk.DA.mass":
 * DA), or an element's first node ("shaft.A.e5.stiffness"); -1: none (a
 * whole-shaft effect, the speed, a sensor). */
static long cand_node(const rcb_diag *d, const diag_cand *c) {
  const rcb_model *m = d->base_model;
  char name[RCB_DIAG_NAME];
  const char *a = strchr(c->pname[0], '.'), *b = a ? strchr(a + 1, '.') : NULL;
  size_t k, len;
  if (c->node) return (long)c->node - 1;
  if (!a || !b || (len = (size_t)(b - a - 1)) >= sizeof name) return -1;
  memcpy(name, a + 1, len), name[len] = '\0';
  if (strncmp(c->pname[0], "shaft.", 6) == 0 && b[1] == 'e') {
    unsigned long e = strtoul(b + 2, NULL, 10);
    for (k = 0; k < rcb_model_element_count(m); k++) {
      rcb_element_info ei;
      if (!rcb_model_element_info(m, k, &ei) && ei.index == e && strcmp(ei.shaft, name) == 0)
        return (long)ei.node0;
    }
    return -1;
  }
  for (k = 0; k < rcb_model_station_count(m); k++) {
    rcb_station_info si;
    if (!rcb_model_station_info(m, k, &si) && strcmp(si.name, name) == 0 &&
        si.node < rcb_model_node_count(m))
      return (long)si.node;
  }
  return -1;
}

/* Whether node (or, for an element, node + 1) is in the placement's span. */
static int node_placed(const rcb_diag *d, long node, int element) {
  size_t k;
  for (k = 0; node >= 0 && k < d->nplace; k++)
    if (d->place[k].in_span && (d->place[k].node == (size_t)node ||
                                (element && d->place[k].node == (size_t)node + 1)))
      return 1;
  return 0;
}

/* Candidate c, one parameter, acting where the misfit is placed: its
 * objective on a grid across its bounds (one sweep each, the base
 * parameters where the base fit left them), then a fit from the best grid
 * point with the base parameters. On a frequency subset w (32 x 1101) the
 * grid and that fit are screens: the result is evaluated on all points,
 * and polished there (RCB_DIAG_POLISH_ITER) only when it then leads every
 * refit. Kept when it ends below the candidate's own refit. */
static rcb_status placed_refit(rcb_diag *d, diag_cand *c, const double *w) {
  const rcb_model *from = d->far && d->nom_model ? d->nom_model : d->base_model;
  rcb_model *m = NULL;
  rcb_fit *f = NULL;
  double *r = rcb_alloc(&d->alloc, (d->nres ? d->nres : 1) * sizeof *r), bestF = HUGE_VAL;
  double bestv = NAN, F = HUGE_VAL, err = NAN;
  rcb_fit_report rep;
  size_t g, i, n = 0;
  int polished = !w;
  rcb_status st = r ? rcb_diag_candidate_model(d, c, from, &m) : RCB_ERR_NOMEM;
  if (!st) st = make_fit(d, m, FIT_BASE, c, &f);
  if (!st) st = rcb_fit_set_weights(f, w);
  for (g = 0; !st && g < RCB_DIAG_PLACED_GRID; g++) {
    double t = (double)g / (RCB_DIAG_PLACED_GRID - 1), v, Fg = 0.0;
    v = c->logp[0] ? c->lo[0] * pow(c->hi[0] / c->lo[0], t) : c->lo[0] + t * (c->hi[0] - c->lo[0]);
    if (rcb_model_set_param(m, c->pname[0], v) || rcb_fit_residuals(f, r)) continue;
    n = rcb_fit_residual_count(f);
    for (i = 0; i < n; i++) Fg += r[i] * r[i];
    if (Fg < bestF) bestF = Fg, bestv = v;
  }
  d->stats.refits += !st;
  if (st || !isfinite(bestv) || rcb_model_set_param(m, c->pname[0], bestv) ||
      rcb_fit_set_starts(f, 1, 1) || screen(f, w, RCB_DIAG_SCREEN_ITER))
    goto done;
  if (w) { /* on all points where the screen ended; polished when it leads */
    if (rcb_fit_set_weights(f, NULL) || objective(d, f, r, &F, &err)) goto done;
    if (F < d->best_F && !polish(f) && !rcb_fit_get_report(f, &rep))
      F = rep.objective, err = rep.error_pct, polished = 1;
  } else if (!rcb_fit_get_report(f, &rep)) {
    F = rep.objective, err = rep.error_pct;
  }
  if (isfinite(F) && (!c->refitted || F < c->F)) {
    c->from_fit = 1;
    refit_result(d, c, &m, f, F, err, polished);
    if (F < d->best_F) d->best_F = F;
  }
done:
  if (f) drop_fit(d, f);
  rcb_model_destroy(m);
  rcb_free(&d->alloc, r);
  return st == RCB_ERR_NOMEM ? rcb_diag_fail(d, st, "out of memory") : RCB_OK;
}

/* When no candidate explains the data and equivalent loads place the
 * misfit at a node (locate.c; a span of at most RCB_DIAG_PLACED_SPAN
 * nodes), every one-parameter model candidate acting there is fitted from a
 * grid across its bounds (placed_refit), and the candidates ranked again:
 * place first, then name. A wider span places nothing one can name
 * (tuning.h). */
static rcb_status placed_refits(rcb_diag *d) {
  size_t k;
  rcb_status st = RCB_OK;
  if (!d->nplace || d->place[0].share_pct < RCB_DIAG_PLACE_LOCAL) return RCB_OK;
  double *w = NULL;
  size_t nspan = 0;
  for (k = 0; k < d->nplace; k++) nspan += d->place[k].in_span != 0;
  if (nspan > RCB_DIAG_PLACED_SPAN) return RCB_OK;
  for (k = 0; k < d->ncand; k++)
    if (d->cand[k].refitted && d->cand[k].claim == RCB_CLAIM_EXPLAINS) return RCB_OK;
  if ((st = rcb_diag_subset_weights(d, &w))) return st;
  for (k = 0; !st && k < d->ncand; k++) {
    diag_cand *c = &d->cand[k];
    if (c->np != 1 || c->refit_only || (c->fam->flags & (DIAG_FAM_CHAIN | DIAG_FAM_ADDS_DOFS)) ||
        !node_placed(d, cand_node(d, c), strncmp(c->pname[0], "shaft.", 6) == 0))
      continue;
    st = placed_refit(d, c, w);
  }
  rcb_free(&d->alloc, w);
  if (!st) sort_order(d);
  return st;
}

static rcb_status run_steps(rcb_diag *d) {
  rcb_status st;
  if ((st = baseline(d))) return st;
  if ((st = rcb_diag_catalogue(d, d->base_model)))
    rcb_diag_fail(d, st, "laying out the catalogue of effects: %s", rcb_status_str(st));
  if (!st && !(d->order = rcb_alloc(&d->alloc, (d->ncand ? d->ncand : 1) * sizeof *d->order)))
    st = rcb_diag_fail(d, RCB_ERR_NOMEM, "out of memory");
  if (!st) st = score_all(d, 0);
  if (!st && d->far) { /* the candidates scored at the nominal model too */
    rcb_model *fitted = d->base_model;
    d->base_model = d->nom_model;
    st = score_all(d, 1);
    d->base_model = fitted;
  }
  if (!st) st = refit_best(d);
  if (!st) st = rcb_diag_locate(d);
  if (!st) st = placed_refits(d);
  return st;
}

rcb_status rcb_diag_run(rcb_diag *d) {
  rcb_status st;
  if (!d) return RCB_ERR_ARG;
  free_results(d);
  d->errmsg[0] = '\0';
  st = run_steps(d);
  /* every failure carries a message, even one from a step that set none */
  if (st && d->errmsg[0] == '\0')
    rcb_diag_fail(d, st, "diagnosis failed: %s", rcb_status_str(st));
  d->ran = !st;
  return st;
}

/* ---- results ---- */

size_t rcb_diag_candidate_count(const rcb_diag *d) { return d && d->ran ? d->ncand : 0; }

rcb_status rcb_diag_candidate_get(const rcb_diag *d, size_t rank, rcb_diag_candidate *out) {
  const diag_cand *c;
  if (!d || !out || !d->ran || rank >= d->ncand) return RCB_ERR_ARG;
  c = &d->cand[d->order[rank]];
  out->effect = c->effect;
  out->place = c->place;
  out->description = c->desc;
  out->params = c->params;
  out->predicted_pct = d->F0 > 0 ? 100.0 * c->predicted / d->F0 : (double)NAN;
  out->refitted = c->refitted;
  out->error_pct = c->err;
  out->objective_drop_pct = c->refitted ? 100.0 * (d->F0 - c->F) / d->F0 : (double)NAN;
  out->delta_bic = c->dbic;
  out->significant = c->significant;
  out->claim = c->refitted ? c->claim : RCB_CLAIM_NONE;
  out->adequate = c->refitted ? c->adequate : -1;
  out->chi2 = c->refitted ? c->F : (double)NAN;
  out->chi2_limit = c->refitted ? c->chi2_limit : (double)NAN;
  out->chain = (c->fam->flags & DIAG_FAM_CHAIN) != 0;
  out->fitted = c->fitted;
  out->screened_only = c->refitted && !c->polished;
  out->dispersion = c->refitted ? c->dispersion : (double)NAN;
  out->white_z = c->refitted ? c->white_z : (double)NAN;
  out->white = c->refitted && d->adeq0.known ? c->white_z <= RCB_ADEQUACY_Z : -1;
  return RCB_OK;
}

rcb_status rcb_diag_adequacy(const rcb_diag *d, rcb_fit_adequacy *out) {
  if (!d || !out) return RCB_ERR_ARG;
  if (!d->ran) return RCB_ERR_STATE;
  *out = d->adeq0;
  return RCB_OK;
}

size_t rcb_diag_misfit_count(const rcb_diag *d) { return d && d->ran ? d->nmis : 0; }

rcb_status rcb_diag_misfit_get(const rcb_diag *d, size_t k, rcb_diag_misfit *out) {
  if (!d || !out || !d->ran || k >= d->nmis) return RCB_ERR_ARG;
  *out = d->mis[k];
  return RCB_OK;
}

rcb_status rcb_diag_get_stats(const rcb_diag *d, rcb_diag_stats *out) {
  if (!d || !out) return RCB_ERR_ARG;
  *out = d->stats;
  return RCB_OK;
}

rcb_status rcb_diag_baseline(const rcb_diag *d, double *error_pct, double *objective,
                             double *floor_pct) {
  if (!d || !d->ran) return RCB_ERR_STATE;
  if (error_pct) *error_pct = d->err0;
  if (objective) *objective = d->F0;
  if (floor_pct) *floor_pct = d->floor0;
  return RCB_OK;
}

static rcb_status put_text(const char *text, char *buf, size_t size, size_t *needed) {
  size_t n = strlen(text) + 1;
  if (needed) *needed = n;
  if (!buf || size < n) {
    if (buf && size) buf[0] = '\0';
    return RCB_ERR_WORKSPACE;
  }
  memcpy(buf, text, n);
  return RCB_OK;
}

rcb_status rcb_diag_apply_model(const rcb_diag *d, size_t rank, const rcb_allocator *alloc,
                                rcb_model **out) {
  const diag_cand *c;
  rcb_model *m = NULL;
  rcb_status st;
  if (!out) return RCB_ERR_ARG;
  *out = NULL;
  if (!d || !d->ran || rank >= d->ncand) return RCB_ERR_ARG;
  c = &d->cand[d->order[rank]];
  if (c->fam->flags & DIAG_FAM_CHAIN)
    return rcb_diag_fail((rcb_diag *)d, RCB_ERR_STATE,
                         "candidate %zu (%s) is a fault of the measurement chain, not of the "
                         "model: nothing to apply; check or recalibrate the sensor, or fit with "
                         "its gain (%s)", rank + 1, c->desc, c->params);
  if (!c->model)
    return rcb_diag_fail((rcb_diag *)d, RCB_ERR_STATE,
                         "candidate %zu (%s) was not refitted: nothing to apply", rank + 1,
                         c->desc);
  if ((st = rcb_model_clone(&m, c->model, alloc)))
    return rcb_diag_fail((rcb_diag *)d, st, "copying candidate %zu's model: %s", rank + 1,
                         rcb_status_str(st));
  if ((st = rcb_model_finalize(m))) {
    rcb_diag_fail((rcb_diag *)d, st, "candidate %zu's model: %s", rank + 1,
                  rcb_model_errmsg(m));
    rcb_model_destroy(m);
    return st;
  }
  *out = m;
  return RCB_OK;
}

/* Where the misfit of the model as it is concentrates, in words (appended
 * to text at n; nothing without a known noise). */
static size_t say_where(const rcb_diag *d, char *text, size_t size, size_t n) {
  size_t k, shown = 0;
  if (!d->nmis || n >= size) return n;
  if (d->mis[0].concentrated) {
    const rcb_diag_misfit *s = &d->mis[0];
    n += (size_t)snprintf(text + n, size - n,
                          " The misfit concentrates on sensor %s (chi-square %.3g x what the "
                          "noise leaves there, %.0f %% of the excess): check this sensor (gain, "
                          "phase, sign, direction, mounting) before the model.",
                          s->sensor, s->chi2 / s->expected, s->excess_pct);
    return n < size ? n : size - 1;
  }
  n += (size_t)snprintf(text + n, size - n, " The misfit is spread over the sensors; the "
                        "largest excesses over the noise:");
  for (k = 0; k < d->nmis && shown < 3 && n < size; k++, shown++)
    n += (size_t)snprintf(text + n, size - n, "%s %s (%.0f %%)", shown ? "," : "",
                          d->mis[k].sensor, d->mis[k].excess_pct);
  if (n < size) n += (size_t)snprintf(text + n, size - n, ".");
  return n < size ? n : size - 1;
}

/* Where along a shaft the local candidates point (appended to text at n):
 * the significant candidates that sit at nodes (DIAG_FAM_PLACE_WALK) among
 * the first RCB_DIAG_SPAN_RANKS ranks, on the shaft of the best of them, as
 * a span of z. Nothing when none is significant. */
static size_t say_span(const rcb_diag *d, char *text, size_t size, size_t n) {
  const rcb_model *m = d->base_model;
  size_t k, shaft = 0, lo = 0, hi = 0, found = 0;
  for (k = 0; k < d->ncand && k < RCB_DIAG_SPAN_RANKS; k++) {
    const diag_cand *c = &d->cand[d->order[k]];
    if (!(c->fam->flags & DIAG_FAM_PLACE_WALK) || !c->node || !c->refitted ||
        c->claim == RCB_CLAIM_NONE || c->node > m->n_nodes)
      continue;
    if (!found) shaft = c->shaft, lo = hi = c->node - 1;
    if (c->shaft != shaft) continue;
    if (c->node - 1 < lo) lo = c->node - 1;
    if (c->node - 1 > hi) hi = c->node - 1;
    found++;
  }
  if (!found || n >= size) return n;
  if (lo == hi)
    n += (size_t)snprintf(text + n, size - n,
                          " The local candidates point to shaft %s at z = %.3g m (node #%zu): "
                          "an effect there that the catalogue lacks is possible.",
                          m->shafts[shaft].name, m->nodes[lo].z, lo);
  else
    n += (size_t)snprintf(text + n, size - n,
                          " The local candidates point to shaft %s between z = %.3g and %.3g m "
                          "(nodes #%zu-#%zu): an effect there that the catalogue lacks is "
                          "possible.",
                          m->shafts[shaft].name, m->nodes[lo].z, m->nodes[hi].z, lo, hi);
  return n < size ? n : size - 1;
}

/* Where the equivalent loads place the misfit of the model as it is
 * (locate.c), appended to text at n: the best node, its share, whether a
 * load there alone accounts for it, and the runs of neighbouring nodes the
 * data cannot separate from it; or that no one node takes
 * RCB_DIAG_PLACE_LOCAL % of it. */
static const rcb_diag_place *span_at(const rcb_diag *d, size_t node, const char *shaft) {
  size_t j;
  for (j = 0; j < d->nplace; j++)
    if (d->place[j].in_span && d->place[j].node == node &&
        (!shaft || strcmp(d->place[j].shaft, shaft) == 0))
      return &d->place[j];
  return NULL;
}
static size_t say_place(const rcb_diag *d, char *text, size_t size, size_t n) {
  const rcb_diag_place *b = d->place;
  size_t runs = 0, lo, hi;
  if (!d->nplace || n >= size) return n;
  if (b->share_pct < RCB_DIAG_PLACE_LOCAL) {
    n += (size_t)snprintf(text + n, size - n,
                          " No one place takes most of the misfit: a force at one node takes at "
                          "most %.0f %% of its excess over the noise (shaft %s, z = %.3g m, node "
                          "#%zu), so the missing effect is not local to one node, or there are "
                          "several.",
                          b->share_pct, b->shaft, b->z, b->node);
    return n < size ? n : size - 1;
  }
  if (b->adequate)
    n += (size_t)snprintf(text + n, size - n,
                          " Placed by equivalent loads, whatever the effect: a force at shaft %s, "
                          "z = %.3g m (node #%zu) takes %.0f %% of the misfit's excess over the "
                          "noise and leaves the noise alone (chi-square %.6g within its 1 %% "
                          "limit): the missing effect sits there",
                          b->shaft, b->z, b->node, b->share_pct, b->chi2);
  else
    n += (size_t)snprintf(text + n, size - n,
                          " Placed by equivalent loads, whatever the effect: a force at one node "
                          "takes at most %.0f %% of the misfit's excess over the noise (shaft %s, "
                          "z = %.3g m, node #%zu) and leaves more than the noise (chi-square "
                          "%.6g for %.0f degrees of freedom), so the data place it along a span, "
                          "not at one node",
                          b->share_pct, b->shaft, b->z, b->node, b->chi2, b->dof);
  /* the nodes the data cannot separate from it, in node order, as runs of
   * neighbours on one shaft */
  for (lo = 0; lo < d->nplace && n < size && runs < 4; lo++) {
    const rcb_diag_place *pl = span_at(d, lo, NULL), *ph;
    if (!pl) continue;
    for (hi = lo, ph = pl; span_at(d, hi + 1, pl->shaft);) ph = span_at(d, ++hi, NULL);
    if (!runs && lo == hi && lo == b->node) break; /* the best node alone */
    n += (size_t)snprintf(text + n, size - n, "%s",
                          runs ? ","
                          : b->adequate ? "; these data cannot separate it from the nodes of"
                                        : "; the nodes that leave at most twice as much:");
    if (lo == hi)
      n += (size_t)snprintf(text + n, size - n, " shaft %s z = %.3g m (#%zu)", pl->shaft, pl->z,
                            lo);
    else
      n += (size_t)snprintf(text + n, size - n, " shaft %s z = %.3g-%.3g m (#%zu-#%zu)",
                            pl->shaft, pl->z, ph->z, lo, hi);
    runs++, lo = hi;
  }
  if (n < size)
    n += (size_t)snprintf(text + n, size - n, ". The kind of effect there is left open.");
  return n < size ? n : size - 1;
}

/* A parameter list "a, b" as "a,b" (one shell word). */
static void no_spaces(const char *in, char *out) {
  for (; *in; in++)
    if (*in != ' ') *out++ = *in;
  *out = '\0';
}

/* When the second candidate has the first's claim and the data cannot tell
 * them apart (rcb_evidence_separable), say so and name the plan that would
 * (appended to text at n). Sensor candidates are left out: their rival is
 * a check of the sensor, not a test campaign. */
static size_t say_rival(const rcb_diag *d, char *text, size_t size, size_t n) {
  const diag_cand *a, *b;
  if (!d->cand || !d->order || d->ncand < 2 || n >= size) return n;
  a = &d->cand[d->order[0]], b = &d->cand[d->order[1]];
  if (!a->refitted || !b->refitted || a->claim == RCB_CLAIM_NONE || b->claim != a->claim ||
      rcb_evidence_separable(a->dbic, b->dbic) ||
      ((a->fam->flags | b->fam->flags) & DIAG_FAM_CHAIN) ||
      (a->effect == b->effect && strcmp(a->place, b->place) == 0)) /* one effect, two forms */
    return n;
  {
    char pa[sizeof a->params], pb[sizeof b->params];
    no_spaces(a->params, pa), no_spaces(b->params, pb);
    n += (size_t)snprintf(text + n, size - n,
                          " These data cannot separate it from %s (BIC %+.1f, within %g of it): "
                          "rcb_plan (rcbtool plan --between %s %s) names the measurement that "
                          "would.",
                          b->desc, b->dbic, -RCB_BIC_SIGNIFICANT, pa, pb);
  }
  return n < size ? n : size - 1;
}

/* The adequacy test's figures in words: "chi-square F above the limit L". */
int rcb_diag_base_adequate(const rcb_diag *d) {
  rcb_evidence e;
  memset(&e, 0, sizeof e);
  if (!d->adeq0.known) return -1;
  e.chi2 = d->adeq0.chi2, e.chi2_limit = d->adeq0.limit, e.white = d->adeq0.white;
  return rcb_evidence_adequate(&e);
}

/* The adequacy test in words: F against its limit, and when above it
 * with a white residual (rcb_evidence_adequate), what that means. */
static void say_test(char *t, size_t size, double F, double limit, int white, double phi) {
  if (F <= limit || !white)
    snprintf(t, size, "chi-square %.6g %s the adequacy limit %.6g at 1 %%", F,
             F <= limit ? "within" : "above", limit);
  else
    snprintf(t, size, "chi-square %.6g above the adequacy limit %.6g at 1 %%, and what is left is "
             "white along frequency: noise about %.3g x the declared level, not a missing effect",
             F, limit, sqrt(phi));
}

static const char *trend(double before, double after) {
  return after < before ? "falls" : after > before ? "rises" : "stays";
}

rcb_status rcb_diag_explain(const rcb_diag *d, char *buf, size_t size, size_t *needed) {
  char text[3072], test[320], floor_txt[96] = "";
  const diag_cand *c;
  int base_ok;
  size_t n;
  if (!d || !d->ran) return RCB_ERR_STATE;
  base_ok = rcb_diag_base_adequate(d);
  c = d->ncand ? &d->cand[d->order[0]] : NULL;
  if (isfinite(d->floor0))
    snprintf(floor_txt, sizeof floor_txt, " (noise floor %.3g %%)", d->floor0);
  if (c && c->refitted && c->claim == RCB_CLAIM_EXPLAINS) {
    say_test(test, sizeof test, c->F, c->chi2_limit, c->white_z <= RCB_ADEQUACY_Z, c->dispersion);
    if (c->fam->flags & DIAG_FAM_CHAIN)
      snprintf(text, sizeof text,
               "The measurement chain, not the model: %s (%s). Read through it, the data fit "
               "the model as it is: the error %s from %.3g %% to %.3g %%%s, BIC %+.1f, %s. "
               "Check or recalibrate this sensor; the model is not changed.",
               c->desc, c->fitted, trend(d->err0, c->err), d->err0, c->err, floor_txt, c->dbic,
               test);
    else
      snprintf(text, sizeof text,
               "Missing: %s. Adding it (%s) explains the misfit: the error %s from %.3g %% "
               "to %.3g %%%s, BIC %+.1f, and the model with it passes the adequacy test (%s).",
               c->desc, c->fitted, trend(d->err0, c->err), d->err0, c->err, floor_txt, c->dbic,
               test);
  } else if (c && c->refitted && c->claim == RCB_CLAIM_IMPROVES) {
    if (isfinite(c->chi2_limit)) {
      say_test(test, sizeof test, c->F, c->chi2_limit, 0, 1.0);
      snprintf(text, sizeof text,
               "The best candidate, %s (%s), accounts for %.1f %% of the misfit but leaves "
               "%.1f %%: the error %s from %.3g %% to %.3g %%, %.2g x the noise floor of "
               "%.3g %% (%s), and what is left is structured along frequency (lag-1 statistic "
               "%.3g above %.3g), not noise. Another effect is missing, possibly outside the "
               "catalogue.",
               c->desc, c->fitted, 100.0 * (d->F0 - c->F) / d->F0, 100.0 * c->F / d->F0,
               trend(d->err0, c->err), d->err0, c->err, c->err / d->floor0, d->floor0, test,
               c->white_z, RCB_ADEQUACY_Z);
    } else {
      snprintf(text, sizeof text,
               "The best candidate, %s (%s), lowers the misfit by %.1f %%: the error %s "
               "from %.3g %% to %.3g %%, BIC %+.1f. Whether the model then fits the data to their "
               "noise cannot be tested: the noise is unknown (give --noise or --sd).",
               c->desc, c->fitted, 100.0 * (d->F0 - c->F) / d->F0, trend(d->err0, c->err),
               d->err0, c->err, c->dbic);
    }
  } else if (base_ok == 1 && d->adeq0.chi2 <= d->adeq0.limit) {
    say_test(test, sizeof test, d->adeq0.chi2, d->adeq0.limit, 0, 1.0);
    snprintf(text, sizeof text,
             "No candidate is significant, and none is needed: the model as it is passes the "
             "adequacy test (%s; error %.3g %%%s).",
             test, d->err0, floor_txt);
  } else if (base_ok == 1) {
    snprintf(text, sizeof text,
             "No candidate is significant, and none is needed: the model as it is leaves a "
             "chi-square of %.6g, above the adequacy limit %.6g of the declared noise, but what "
             "it leaves is white along frequency (lag-1 statistic %.3g, 1 %% limit %.3g): the "
             "noise is about %.3g x the declared level, and nothing is shown missing (error "
             "%.3g %%%s). Declare the noise as measured to test to its level.",
             d->adeq0.chi2, d->adeq0.limit, d->adeq0.white_z, RCB_ADEQUACY_Z,
             sqrt(d->adeq0.dispersion), d->err0, floor_txt);
  } else if (base_ok == 0) {
    say_test(test, sizeof test, d->adeq0.chi2, d->adeq0.limit, 0, 1.0);
    snprintf(text, sizeof text,
             "No candidate is significant: the model as it is leaves an error of %.3g %%%s "
             "(%s; structured along frequency, lag-1 statistic %.3g), and no effect of the "
             "catalogue is significant (BIC lower by more than %g on the noise's dispersion, "
             "counting the %zu candidates tried): the missing effect may not be in the "
             "catalogue, or a sensor is at fault.",
             d->err0, floor_txt, test, d->adeq0.white_z, -RCB_BIC_SIGNIFICANT, d->ncand);
  } else {
    snprintf(text, sizeof text,
             "No candidate is significant: no effect of the catalogue lowers BIC by more than "
             "%g while lowering the error (%.3g %%). Whether the model as it is fits the data to their "
             "noise cannot be tested: the noise is unknown (give --noise or --sd).",
             -RCB_BIC_SIGNIFICANT, d->err0);
  }
  n = strlen(text);
  n = say_rival(d, text, sizeof text, n);
  if (!(c && c->refitted && c->claim == RCB_CLAIM_EXPLAINS) && base_ok != 1) {
    n = say_where(d, text, sizeof text, n);
    if (d->nplace && !(d->nmis && d->mis[0].concentrated)) n = say_place(d, text, sizeof text, n);
    else if (!d->nplace) n = say_span(d, text, sizeof text, n);
  }
  if (d->far) /* the run-off baseline is a finding of its own */
    snprintf(text + n, sizeof text - n,
             " The fit of the model as it is ran far from the nominal model (%s): a missing "
             "effect pulls it there; the candidates were also scored at the nominal model, the "
             "best there fitted alone and refitted from where that ended.",
             d->drift);
  return put_text(text, buf, size, needed);
}
