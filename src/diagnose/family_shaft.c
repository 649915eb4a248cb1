/*
 * The shaft family (issue #4): each shaft's material (stiffness-proportional)
 * damping. A coefficient of the model: no structural edit.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "diagnose/diag_internal.h"

static rcb_status enumerate(rcb_diag *d, const rcb_model *m) {
  size_t i;
  for (i = 0; i < m->n_shafts; i++) {
    const rcb_shaft_t *s = &m->shafts[i];
    char place[RCB_DIAG_NAME];
    double lo, hi;
    int logp;
    diag_cand *c;
    snprintf(place, sizeof place, "shaft %s", s->name);
    if (!(c = rcb_diag_new_cand(d, &rcb_diag_family_shaft, RCB_EFFECT_SHAFT_DAMPING, place))) return RCB_ERR_NOMEM;
    snprintf(c->desc, sizeof c->desc, "material (stiffness-proportional) damping of shaft %s",
             s->name);
    rcb_diag_bounds(s->qz_k, 1e-3, &lo, &hi, &logp);
    rcb_diag_add_par(c, "shaft.%s.damping_stiffness", s->name, lo, hi, logp);
  }
  return RCB_OK;
}


const diag_family rcb_diag_family_shaft = {"shaft", 0, enumerate, NULL, NULL, NULL, NULL};
