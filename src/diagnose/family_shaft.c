/*
 * The shaft family (issue #4): each shaft's material (stiffness-proportional)
 * damping; and (issue #33) a change of section or material along the whole
 * shaft, as the shaft-wide factors on its E and G (shaft.S.stiffness) and on
 * its density (shaft.S.mass). Coefficients of the model: no structural edit.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "diagnose/diag_internal.h"

/* Bounds of the shaft-wide factors: a section or material error along a
 * shaft, not a crack (an element's factor reaches far lower). Log scale. */
#define SHAFT_FACTOR_LO 0.3
#define SHAFT_FACTOR_HI 3.0

/* The shaft-wide factor `variant` (0: stiffness, 1: mass) of shaft s, unless
 * the base fit already holds it. */
static rcb_status add_factor(rcb_diag *d, const rcb_model *m, size_t i, int variant) {
  const rcb_shaft_t *s = &m->shafts[i];
  static const char *const key[2] = {"stiffness", "mass"};
  char name[RCB_DIAG_NAME], place[RCB_DIAG_NAME];
  double v = s->sf[variant];
  diag_cand *c;
  snprintf(name, sizeof name, "shaft.%s.%s", s->name, key[variant]);
  if (rcb_diag_is_base(d, name)) return RCB_OK;
  snprintf(place, sizeof place, "shaft %s", s->name);
  c = rcb_diag_new_cand(d, &rcb_diag_family_shaft,
                        variant ? RCB_EFFECT_SHAFT_MASS : RCB_EFFECT_SHAFT_STIFFNESS, place);
  if (!c) return RCB_ERR_NOMEM;
  snprintf(c->desc, sizeof c->desc,
           variant ? "a change of section or material along shaft %s (its mass)"
                   : "a change of section or material along shaft %s (its bending stiffness)",
           s->name);
  c->variant = variant;
  c->shaft = i;
  /* a model that already holds a factor (an applied candidate): its value inside */
  rcb_diag_add_par(c, variant ? "shaft.%s.mass" : "shaft.%s.stiffness", s->name,
                   fmin(SHAFT_FACTOR_LO, 0.5 * v), fmax(SHAFT_FACTOR_HI, 2.0 * v), 1);
  return RCB_OK;
}

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
  for (i = 0; i < m->n_shafts; i++) {
    rcb_status st;
    if ((st = add_factor(d, m, i, 0)) || (st = add_factor(d, m, i, 1)))
      return st;
  }
  return RCB_OK;
}


const diag_family rcb_diag_family_shaft = {"shaft", 0, enumerate, NULL, NULL, NULL, NULL};
