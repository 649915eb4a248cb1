/*
 * Large effects, named where the misfit is placed (issue #23 item 5): when
 * no candidate explains the data and the equivalent loads (locate.c) place
 * the misfit at a few nodes, every one-parameter candidate acting there is
 * refitted from the best point of a grid across its bounds.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "diagnose/diag_internal.h"
#include "diagnose/tuning.h"
#include "identify/identify.h"

/* The model node a candidate acts at (diag_internal.h). */
long rcb_diag_cand_node(const rcb_diag *d, const diag_cand *c) {
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

/* Whether node (element: node + 1 too) is in the placement's span. */
int rcb_diag_node_placed(const rcb_diag *d, long node, int element) {
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
  if (!st) st = rcb_diag_make_fit(d, m, RCB_DIAG_FIT_BASE, c, &f);
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
      rcb_fit_set_starts(f, 1, 1) || rcb_diag_screen(f, w, RCB_DIAG_SCREEN_ITER))
    goto done;
  if (w) { /* on all points where the screen ended; polished when it leads */
    if (rcb_fit_set_weights(f, NULL) || rcb_diag_objective(d, f, r, &F, &err)) goto done;
    if (F < d->best_F && !rcb_diag_polish(f) && !rcb_fit_get_report(f, &rep))
      F = rep.objective, err = rep.error_pct, polished = 1;
  } else if (!rcb_fit_get_report(f, &rep)) {
    F = rep.objective, err = rep.error_pct;
  }
  if (isfinite(F) && (!c->refitted || F < c->F)) {
    c->from_fit = 1;
    if ((st = rcb_diag_refit_result(d, c, &m, f, F, err, polished)) == RCB_ERR_NOMEM) goto done;
    st = RCB_OK; /* a failed test leaves the candidate as it was */
    if (F < d->best_F) d->best_F = F;
  }
done:
  if (f) rcb_diag_drop_fit(d, f);
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
rcb_status rcb_diag_placed_refits(rcb_diag *d) {
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
        !rcb_diag_node_placed(d, rcb_diag_cand_node(d, c), strncmp(c->pname[0], "shaft.", 6) == 0))
      continue;
    st = placed_refit(d, c, w);
  }
  rcb_free(&d->alloc, w);
  if (!st) rcb_diag_sort_order(d);
  return st;
}
