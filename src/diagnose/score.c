/*
 * The score test: every candidate scored by the reduction of the objective
 * its parameters can explain at the fitted base model (or at the nominal
 * one, for a run-off baseline): its sensitivity columns orthogonalised
 * against the fitted parameters' and projected on the weighted residual
 * (score_qr.c), alike candidates swept in batches.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "diagnose/diag_internal.h"
#include "diagnose/tuning.h"
#include "identify/identify.h"

/* The candidate's model and a fit of its own parameters (the base's
 * residual layout); the caller destroys both. */
static rcb_status candidate_fit(rcb_diag *d, const diag_cand *c, rcb_model **m, rcb_fit **f) {
  rcb_status st = rcb_diag_candidate_model(d, c, d->base_model, m);
  *f = NULL;
  if (!st) st = rcb_diag_make_fit(d, *m, 0, c, f);
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
  rcb_diag_drop_fit(d, f);
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
  if (!st) st = rcb_diag_make_fit(d, m, 0, c, &f); /* no residual layout needed */
  *same = !st && rcb_model_dof_count(m) == ndof && !(c->fam->flags & DIAG_FAM_SCORE_ALONE);
  if (*same && (st = rcb_fit_dz_get(f, &d->alloc, dz))) {
    rcb_diag_fail(d, st, "%s: %s", c->desc, rcb_fit_errmsg(f));
    *same = 0;
  }
  rcb_diag_drop_fit(d, f);
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
int rcb_diag_fixed_chain(const diag_cand *c) {
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
    if (!rcb_diag_fixed_chain(c)) continue;
    st = candidate_fit(d, c, &m, &f);
    if (!st && !rcb_fit_residuals_from(f, src, r)) {
      size_t j;
      for (F = 0, j = 0; j < d->nres; j++) F += r[j] * r[j];
    } else if (!st) {
      st = rcb_diag_objective(d, f, r, &F, &err);
    }
    if (st != RCB_ERR_NOMEM) st = RCB_OK; /* an edit that cannot be evaluated: not refitted */
    c->predicted = isfinite(F) ? d->F0 - F : 0.0;
    rcb_diag_drop_fit(d, f);
    rcb_model_destroy(m);
  }
  rcb_free(&d->alloc, r);
  return st;
}

/* Score every candidate at the fitted base model (nominal = 0: predicted)
 * or at the nominal one (predicted_nom; the base text swapped for the
 * nominal one, so the candidates' models are built on it too). */
rcb_status rcb_diag_score_all(rcb_diag *d, int nominal) {
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
  if (!st) st = rcb_diag_make_fit(d, m, 1, NULL, &w.f);
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
  rcb_diag_drop_fit(d, w.f);
  rcb_model_destroy(m);
  rcb_free(&d->alloc, later);
  rcb_free(&d->alloc, w.r);
  rcb_free(&d->alloc, w.J);
  return st;
}
