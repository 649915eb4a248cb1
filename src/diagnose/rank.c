/*
 * Which candidates are refitted, and their order: the best scored (and the
 * other coupling models, and the fixed chain edits that lower F), with a
 * run-off baseline the best pre-fits at the nominal model too (prefit.c);
 * each refit's steps run as jobs across the candidates (refit.c, on
 * d->nthreads threads, parallel.c); then the ranking by claim and BIC.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "diagnose/diag_internal.h"
#include "diagnose/tuning.h"
#include "identify/identify.h"

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

void rcb_diag_sort_order(rcb_diag *d) {
  size_t i, j;
  for (i = 0; i < d->ncand; i++) d->order[i] = i;
  for (i = 1; i < d->ncand; i++)
    for (j = i; j > 0 && better(&d->cand[d->order[j]], &d->cand[d->order[j - 1]]); j--) {
      size_t t = d->order[j];
      d->order[j] = d->order[j - 1];
      d->order[j - 1] = t;
    }
}

static rcb_status refit_job(rcb_diag *d, size_t i, void *ctx) {
  diag_jobs *j = ctx;
  return rcb_diag_refit_screen(d, &d->cand[j->k[i]], j->w);
}

static rcb_status restart_job(rcb_diag *d, size_t i, void *ctx) {
  diag_jobs *j = ctx;
  return rcb_diag_refit_restart(d, &d->cand[j->k[i]], j->w);
}

/* Whether a refit's screen ended at the noise floor (d->screen_floor, read by
 * refit_restart). */
static void any_screen_at_floor(rcb_diag *d) {
  size_t k;
  d->screen_floor = 0;
  for (k = 0; k < d->ncand; k++) d->screen_floor |= d->cand[k].screened && d->cand[k].screen_floor;
}

static rcb_status evaluate_job(rcb_diag *d, size_t i, void *ctx) {
  diag_jobs *j = ctx;
  return rcb_diag_refit_evaluate(d, &d->cand[j->k[i]]);
}

static rcb_status polish_job(rcb_diag *d, size_t i, void *ctx) {
  diag_jobs *j = ctx;
  return rcb_diag_refit_polish(d, &d->cand[j->k[i]]);
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
  diag_jobs *j = ctx;
  if (d->cand[j->k[i]].refit_only) return RCB_OK;
  if (d->progress_done < d->ncand) d->progress_done = d->ncand; /* refit-only ones */
  if (d->progress && d->progress(d->progress_user, ++d->progress_done, d->ncand + j->todo))
    return rcb_diag_fail(d, RCB_ERR_STATE, "stopped by the caller");
  return RCB_OK;
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
static rcb_status nominal_starts(rcb_diag *d, diag_jobs *j) {
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
  if ((st = rcb_diag_prefit_selected(d, j))) return st;
  if ((st = rcb_diag_place_search(d, j->w))) return st;
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

rcb_status rcb_diag_refit_best(rcb_diag *d) {
  /* a run-off fit is a poor start (every damping candidate refitted there
   * on the 0.15 kg hub case stayed at F0): its best RCB_DIAG_NOM_REFITS only */
  size_t nfit = d->far && d->nrefit > RCB_DIAG_NOM_REFITS ? RCB_DIAG_NOM_REFITS : d->nrefit, k;
  diag_jobs j;
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
  rcb_diag_sort_order(d); /* by predicted reduction (nothing refitted yet) */
  for (k = 0; k < d->ncand; k++) {
    diag_cand *c = &d->cand[d->order[k]];
    c->from_fit = (c->refit_only && !(rcb_diag_fixed_chain(c) && !(c->predicted > 0))) ||
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
  if (!st && d->lead < d->ncand) st = rcb_diag_refit_polish(d, &d->cand[d->lead]);
  if (!st) st = rcb_diag_for_each(d, j.n, polish_job, &j, NULL);
  if (!st) rcb_diag_sort_order(d);
  rcb_free(&d->alloc, j.w);
  rcb_free(&d->alloc, j.k);
  return st;
}

/* Refit the candidates k[0 .. n) (not refitted yet) after the ranking, stage
 * by stage as refit_best does (screen on the frequency subset when there is
 * one, random starts when no screen reached the floor, evaluation on all
 * points, polish when near the best: refit.c), each from the fitted base
 * (c->from_fit) and the nominal model (c->from_nom) as the caller marked
 * it; then rank again. The polished leader (d->lead) stays what a polish
 * must beat (cannot_lead). */
rcb_status rcb_diag_refit_more(rcb_diag *d, size_t *k, size_t n) {
  diag_jobs j;
  rcb_status st;
  if (!n) return RCB_OK;
  memset(&j, 0, sizeof j);
  j.k = k, j.n = n;
  if (d->ncand && d->cand[d->order[0]].refitted && d->cand[d->order[0]].polished)
    d->lead = d->order[0]; /* the placed refits may have made another */
  if ((st = rcb_diag_subset_weights(d, &j.w))) return st;
  st = rcb_diag_for_each(d, j.n, refit_job, &j, NULL);
  if (!st) any_screen_at_floor(d);
  if (!st) st = rcb_diag_for_each(d, j.n, restart_job, &j, NULL);
  if (!st) st = rcb_diag_for_each(d, j.n, evaluate_job, &j, NULL);
  if (!st) lowest_refit(d);
  if (!st) st = rcb_diag_for_each(d, j.n, polish_job, &j, NULL);
  if (!st) rcb_diag_sort_order(d);
  rcb_free(&d->alloc, j.w);
  return st;
}
