/*
 * The flexible-support family (issue #13): a pedestal (mass on a spring and
 * damper) under every bearing that has none. Its models have DOFs the base
 * model lacks (DIAG_FAM_ADDS_DOFS), and its refit starts from the best point
 * of a grid over the pedestal's mass and stiffness.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "diagnose/diag_internal.h"
#include "identify/identify.h"

/* A pedestal under every bearing that has none. Its neutral point (no
 * pedestal) has no DOFs, so the candidate starts as a very stiff, light
 * pedestal (1000 x the bearing's stiffness, 1e-3 of the rotor mass per
 * bearing, no damping): the model is the same to about 1e-3, and the score
 * test sees the first terms of the pedestal's dynamic compliance,
 * 1/(k - w^2 m + i w c) ~ 1/k + w^2 m/k^2 - i w c/k^2: a series compliance,
 * its w^2-weighted and its w-weighted (damping) shapes. The refit then moves
 * the pedestal into the band. */
static rcb_status enumerate(rcb_diag *d, const rcb_model *m) {
  double mref = rcb_diag_rotor_mass(m) / (double)(m->n_bearings ? m->n_bearings : 1);
  size_t i;
  for (i = 0; i < m->n_bearings; i++) {
    const rcb_bearing_t *b = &m->bearings[i];
    double kb = fmax(fabs(b->c[0].kxx), fabs(b->c[0].kyy));
    char place[RCB_DIAG_NAME];
    diag_cand *c;
    if (b->has_ped) continue;
    if (kb == 0) kb = 1e6;
    snprintf(place, sizeof place, "bearing %s", b->name);
    if (!(c = rcb_diag_new_cand(d, &rcb_diag_family_pedestal, RCB_EFFECT_FLEXIBLE_SUPPORT, place))) return RCB_ERR_NOMEM;
    snprintf(c->desc, sizeof c->desc,
             "a flexible support (pedestal mass on a spring and damper) under bearing %s",
             b->name);
    snprintf(c->target, sizeof c->target, "%s", b->name);
    c->ped0[0] = 1e-3 * mref;
    c->ped0[1] = 1e3 * kb;
    c->ped0[2] = 0.0;
    rcb_diag_add_par(c, "bearing.%s.pedestal_mass", b->name, 1e-4 * mref, 20 * mref, 1);
    rcb_diag_add_par(c, "bearing.%s.pedestal_k", b->name, 1e-2 * kb, 1e4 * kb, 1);
    rcb_diag_add_par(c, "bearing.%s.pedestal_c", b->name, 0.0, 1e-2 * kb, 0);
  }
  return RCB_OK;
}

/* Weighted objective of f at the model's current values (NaN on failure). */
static double objective_now(rcb_fit *f, double *r) {
  size_t i, n = rcb_fit_residual_count(f);
  double F = 0;
  if (rcb_fit_residuals(f, r)) return (double)NAN;
  for (i = 0; i < n; i++) F += r[i] * r[i];
  return F;
}

static rcb_status set_pedestal(rcb_model *m, const char *bearing, double mass, double k,
                               double c) {
  char nm[RCB_DIAG_NAME];
  rcb_status st;
  snprintf(nm, sizeof nm, "bearing.%s.pedestal_mass", bearing);
  if ((st = rcb_model_set_param(m, nm, mass))) return st;
  snprintf(nm, sizeof nm, "bearing.%s.pedestal_k", bearing);
  if ((st = rcb_model_set_param(m, nm, k))) return st;
  snprintf(nm, sizeof nm, "bearing.%s.pedestal_c", bearing);
  return rcb_model_set_param(m, nm, c);
}

/* The refit of a pedestal starts from the best point of a grid: masses 0.3,
 * 1, 3 and 10 x the rotor mass per bearing, stiffnesses over the lower four
 * decades of its bounds (4 per decade), 5 % of critical damping; or from the
 * stiff light start when no grid point is better. The score test, taken at
 * that start, only sees the pedestal's compliance, while a pedestal near the
 * band adds a resonance that a local fit from there does not find. The 69
 * evaluations compare starts only: they use the points of grid_weights (a
 * seventh of the 32 x 1101 case's work), the refit then all points. */
static rcb_status refit_start(rcb_diag *d, const diag_cand *c, rcb_model *m, rcb_fit *f) {
  static const double mass_f[4] = {0.3, 1.0, 3.0, 10.0};
  double *r = NULL, *w, best, bm = c->ped0[0], bk = c->ped0[1], bc = c->ped0[2], mref;
  int a, j;
  rcb_status st = RCB_OK;
  if ((w = rcb_diag_grid_weights(d)) && (st = rcb_fit_set_weights(f, w)) == RCB_OK &&
      (st = rcb_fit_prepare(f)) != RCB_OK && st != RCB_ERR_NOMEM) {
    rcb_fit_set_weights(f, NULL); /* no point left there: all points */
    st = RCB_OK;
  }
  if (!w || st || !(r = rcb_alloc(&d->alloc, (rcb_fit_residual_count(f) + 1) * sizeof *r))) {
    rcb_free(&d->alloc, w);
    return rcb_diag_fail(d, st ? st : RCB_ERR_NOMEM, "%s",
                         st ? rcb_fit_errmsg(f) : "out of memory");
  }
  mref = rcb_diag_rotor_mass(m) / (double)(m->n_bearings ? m->n_bearings : 1);
  best = objective_now(f, r);
  for (a = 0; a < 4 && !st; a++)
    for (j = 0; j <= 16 && !st; j++) {
      double mass = mass_f[a] * mref, k = c->lo[1] * pow(10.0, 0.25 * j);
      double damp = fmin(0.1 * sqrt(k * mass), c->hi[2]), F;
      if ((st = set_pedestal(m, c->target, mass, k, damp))) break;
      F = objective_now(f, r);
      if (F < best) best = F, bm = mass, bk = k, bc = damp;
    }
  if (!st) st = set_pedestal(m, c->target, bm, bk, bc);
  rcb_fit_set_weights(f, NULL); /* all points again */
  rcb_free(&d->alloc, r);
  rcb_free(&d->alloc, w);
  if (st) return rcb_diag_fail(d, st, "%s: %s", c->desc, rcb_model_errmsg(m));
  return RCB_OK;
}

/* The pedestal at its stiff, light start, on the unfinalized copy m. */
static rcb_status edit(const diag_cand *c, rcb_model *m) {
  rcb_pedestal p;
  p.mass = c->ped0[0];
  p.kxx = p.kyy = c->ped0[1];
  p.cxx = p.cyy = c->ped0[2];
  return rcb_model_set_pedestal(m, c->target, &p);
}

const diag_family rcb_diag_family_pedestal = {"pedestal", DIAG_FAM_ADDS_DOFS, enumerate, edit,
                                              NULL, refit_start, NULL};
