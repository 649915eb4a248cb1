/*
 * The bearing family (issue #4): at every bearing with constant coefficients,
 * a stiffness in one direction (anisotropy), in both directions together (a
 * bearing softened or stiffened as a whole: worn, loose, another clearance;
 * issue #33, where no one-direction candidate reached the floor and B3's kxx
 * and kyy fitted together did), a cross-coupled stiffness kxy = -kyx and the
 * damping. Coefficients of the model: no structural edit.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "diagnose/diag_internal.h"

static rcb_status enumerate(rcb_diag *d, const rcb_model *m) {
  size_t i;
  int a;
  for (i = 0; i < m->n_bearings; i++) {
    const rcb_bearing_t *b = &m->bearings[i];
    const rcb_bearing_coefs *k = &b->c[0];
    double kb = fmax(fabs(k->kxx), fabs(k->kyy)), lo, hi;
    char place[RCB_DIAG_NAME];
    int logp;
    diag_cand *c;
    if (b->n != 1) continue; /* speed-dependent: not fittable */
    if (kb == 0) kb = 1e6;
    snprintf(place, sizeof place, "bearing %s", b->name);
    for (a = 0; a < 2; a++) {
      double v = a ? k->kyy : k->kxx;
      if (!(c = rcb_diag_new_cand(d, &rcb_diag_family_bearing, RCB_EFFECT_BEARING_STIFFNESS, place))) return RCB_ERR_NOMEM;
      snprintf(c->desc, sizeof c->desc, "stiffness in %s at bearing %s (anisotropy)",
               a ? "y" : "x", b->name);
      rcb_diag_bounds(v, 10 * kb, &lo, &hi, &logp);
      rcb_diag_add_par(c, a ? "bearing.%s.kyy" : "bearing.%s.kxx", b->name, lo, hi, logp);
    }
    if (!(c = rcb_diag_new_cand(d, &rcb_diag_family_bearing, RCB_EFFECT_BEARING_STIFFNESS_XY, place))) return RCB_ERR_NOMEM;
    snprintf(c->desc, sizeof c->desc, "stiffness in x and y at bearing %s (the bearing as a "
             "whole softer or stiffer)", b->name);
    for (a = 0; a < 2; a++) {
      rcb_diag_bounds(a ? k->kyy : k->kxx, 10 * kb, &lo, &hi, &logp);
      rcb_diag_add_par(c, a ? "bearing.%s.kyy" : "bearing.%s.kxx", b->name, lo, hi, logp);
    }
    if (!(c = rcb_diag_new_cand(d, &rcb_diag_family_bearing, RCB_EFFECT_BEARING_CROSS_COUPLING, place))) return RCB_ERR_NOMEM;
    snprintf(c->desc, sizeof c->desc, "cross-coupled stiffness kxy = -kyx at bearing %s",
             b->name);
    rcb_diag_add_par(c, "bearing.%s.kcross", b->name, -kb, kb, 0);
    if (!(c = rcb_diag_new_cand(d, &rcb_diag_family_bearing, RCB_EFFECT_BEARING_DAMPING, place))) return RCB_ERR_NOMEM;
    snprintf(c->desc, sizeof c->desc, "damping at bearing %s", b->name);
    rcb_diag_bounds(k->cxx, 1e-2 * kb, &lo, &hi, &logp);
    rcb_diag_add_par(c, "bearing.%s.cxx", b->name, lo, hi, logp);
    rcb_diag_bounds(k->cyy, 1e-2 * kb, &lo, &hi, &logp);
    rcb_diag_add_par(c, "bearing.%s.cyy", b->name, lo, hi, logp);
  }
  return RCB_OK;
}


const diag_family rcb_diag_family_bearing = {"bearing", 0, enumerate, NULL, NULL, NULL, NULL};
