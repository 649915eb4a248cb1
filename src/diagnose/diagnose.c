/*
 * Diagnosis (issue #4): fit the model as it is, score every candidate effect
 * of the catalogue by the error reduction it can explain (score test: the
 * candidate's sensitivity columns orthogonalised against the parameters
 * already fitted, projected on the weighted residual of the fit's own
 * objective), refit the best and the alternative coupling models, and rank by
 * the change of BIC, requiring the error itself to fall.
 *
 * This file holds the object (create, destroy, settings, results) and the
 * flow, rcb_diag_run: each stage in its own file, called in order with what
 * the one before left in the rcb_diag (diag_internal.h lists them):
 * baseline.c, catalogue.c, score.c, rank.c (with prefit.c and refit.c),
 * locate.c, placed.c; the words are words.c's. Their tuning constants are in
 * tuning.h.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "diagnose/diag_internal.h"

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
  for (i = 0; i < d->ncand; i++) {
    rcb_model_destroy(d->cand[i].model);
    rcb_free(&d->alloc, d->cand[i].carry);
  }
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
  d->cap_order = 0, d->span_tried = 0;
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
  rcb_free(&a, d->carry);
  rcb_free(&a, d->sd);
  rcb_free(&a, d);
}

/* ---- the flow ---- */

/* The stages in order, each handing the next what it left in d:
 * rcb_diag_fit_baseline (baseline.c): the fitted base model, F0, the
 *   adequacy test, the sensors the misfit concentrates on, d->far;
 * rcb_diag_catalogue (catalogue.c): the candidates, at the base model;
 * rcb_diag_score_all (score.c): each candidate's predicted reduction, at
 *   the fitted base and, when the baseline ran off, at the nominal model;
 * rcb_diag_refit_best (rank.c, prefit.c, refit.c): the refits, ranked;
 * rcb_diag_locate (locate.c): where the misfit of the model as it is sits;
 * rcb_diag_placed_refits (placed.c): the candidates acting there, refitted
 *   from a grid, ranked again;
 * rcb_diag_neighbour_refits (neighbours.c): a leading local candidate's
 *   neighbours of its kind, refitted where the placement points, ranked
 *   again;
 * rcb_diag_span_refits (span.c): a shaft's stiffness or mass leading, the
 *   span of its elements searched for, refitted, ranked again.
 * rcb_diag_explain (words.c) puts the result in words. */
static rcb_status run_steps(rcb_diag *d) {
  rcb_status st;
  if ((st = rcb_diag_fit_baseline(d))) return st;
  if ((st = rcb_diag_catalogue(d, d->base_model)))
    rcb_diag_fail(d, st, "laying out the catalogue of effects: %s", rcb_status_str(st));
  if (!st && !(d->order = rcb_alloc(&d->alloc, (d->ncand ? d->ncand : 1) * sizeof *d->order)))
    st = rcb_diag_fail(d, RCB_ERR_NOMEM, "out of memory");
  if (!st) d->cap_order = d->ncand ? d->ncand : 1;
  if (!st) st = rcb_diag_score_all(d, 0);
  if (!st && d->far) { /* the candidates scored at the nominal model too */
    rcb_model *fitted = d->base_model;
    d->base_model = d->nom_model;
    st = rcb_diag_score_all(d, 1);
    d->base_model = fitted;
  }
  if (!st) st = rcb_diag_refit_best(d);
  if (!st) st = rcb_diag_locate(d);
  if (!st) st = rcb_diag_placed_refits(d);
  if (!st) st = rcb_diag_neighbour_refits(d);
  if (!st) st = rcb_diag_span_refits(d);
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

/* ---- settings ---- */

const char *rcb_diag_errmsg(const rcb_diag *d) { return d ? d->errmsg : "no diagnosis"; }

rcb_status rcb_diag_add_fitted_param(rcb_diag *d, const char *name, double lo, double hi,
                                     int log_param) {
  diag_base_par *p;
  rcb_status st;
  if (!d || !name || strlen(name) >= RCB_DIAG_NAME) return RCB_ERR_ARG;
  if ((st = rcb_diag_carry_check(d, name))) return st; /* a sensor's: measured? */
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

/* ---- results ---- */

size_t rcb_diag_candidate_count(const rcb_diag *d) { return d && d->ran ? d->ncand : 0; }

int rcb_diag_get_noise_reference(const rcb_diag *d, rcb_complex *h, size_t n) {
  if (!d || !h) return RCB_ERR_ARG;
  if (n != rcb_meas_channel_count(d->meas) * rcb_meas_point_count(d->meas)) return RCB_ERR_ARG;
  if (!d->ran || !d->nref) return 0;
  memcpy(h, d->nref, n * sizeof *h);
  return 1;
}

rcb_status rcb_diag_candidate_evidence(const rcb_diag *d, size_t rank, rcb_evidence *out) {
  const diag_cand *c;
  if (!d || !out || !d->ran || rank >= d->ncand) return RCB_ERR_ARG;
  c = &d->cand[d->order[rank]];
  if (!c->refitted) return RCB_ERR_ARG;
  *out = c->ev;
  return RCB_OK;
}

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
  out->chi2 = c->refitted ? c->adeq_chi2 : (double)NAN; /* its adequacy test's */
  out->chi2_limit = c->refitted ? c->chi2_limit : (double)NAN;
  out->chain = (c->fam->flags & DIAG_FAM_CHAIN) != 0;
  out->carry = c->carry ? c->carry : "";
  out->fitted = c->fitted;
  out->screened_only = c->refitted && !c->polished;
  out->dispersion = c->refitted ? c->dispersion : (double)NAN;
  out->white_z = c->refitted ? c->white_z : (double)NAN;
  out->white = c->refitted && d->adeq0.known ? c->white_z <= RCB_ADEQUACY_Z : -1;
  out->beyond = c->refitted && c->beyond;
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
                         "model: nothing to apply; check or recalibrate the sensor, or read the "
                         "data through the correction in the next round (rcbtool fit or "
                         "diagnose with %s)", rank + 1, c->desc, c->carry ? c->carry : "");
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
