/*
 * The shaft-element family (issue #23): a local change of one shaft
 * element, which no other family can stand for: its bending (and shear)
 * stiffness, as a crack, wear or a loose shrink fit lowers it, and its mass.
 * Each is a factor of the model (shaft.S.e<k>.stiffness | mass, neutral 1,
 * model/element_params.c): no structural edit, no start but the model's own
 * value. The candidates sit along a shaft (node: the element's first node
 * + 1, variant 0: stiffness, 1: mass: DIAG_FAM_PLACE_WALK), as added masses
 * do. Neighbouring elements score alike: of each variant only the best
 * scored is refitted, and none is pre-fitted on the run-off path
 * (DIAG_FAM_ONE_REFIT, rank.c one_taken), or they would take most of
 * the refits from the other effects.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "diagnose/diag_internal.h"

/* Refit bounds of the factors (-), fitted as log: a stiffness from 5 % (a
 * deep crack) to twice the material's, a mass from a fifth to five times. */
#define ELEMENT_STIFFNESS_LO 0.05
#define ELEMENT_STIFFNESS_HI 2.0
#define ELEMENT_MASS_LO 0.2
#define ELEMENT_MASS_HI 5.0

/* Candidate (element e of m, variant 0: stiffness, 1: mass); 1 when laid
 * out, 0 when its parameter is fitted with the base, -1 out of memory. */
static int add_element(rcb_diag *d, const rcb_model *m, size_t e, int variant) {
  static const char *const key[2] = {"stiffness", "mass"};
  const rcb_element_t *el = &m->elements[e];
  const rcb_shaft_t *sh = &m->shafts[el->shaft];
  char item[RCB_NAME_MAX + 24], name[RCB_DIAG_NAME], place[RCB_DIAG_NAME];
  double v = el->k < sh->nef ? sh->ef[2 * el->k + (size_t)variant] : 1.0;
  double lo = variant ? ELEMENT_MASS_LO : ELEMENT_STIFFNESS_LO;
  double hi = variant ? ELEMENT_MASS_HI : ELEMENT_STIFFNESS_HI;
  diag_cand *c;
  snprintf(item, sizeof item, "%s.e%zu", sh->name, el->k + 1);
  snprintf(name, sizeof name, "shaft.%s.%s", item, key[variant]);
  if (rcb_diag_is_base(d, name)) return 0;
  snprintf(place, sizeof place, "shaft %s element %zu (z = %.3f-%.3f m)", sh->name, el->k + 1,
           m->nodes[el->node0].z, m->nodes[el->node0 + 1].z);
  c = rcb_diag_new_cand(d, &rcb_diag_family_element,
                        variant ? RCB_EFFECT_ELEMENT_MASS : RCB_EFFECT_ELEMENT_STIFFNESS, place);
  if (!c) return -1;
  snprintf(c->desc, sizeof c->desc,
           variant ? "a local change of mass of %s"
                   : "a local change of bending stiffness (a crack, wear, a loose fit) of %s",
           place);
  c->node = el->node0 + 1;
  c->variant = variant;
  c->shaft = el->shaft;
  /* a model that already holds a factor (an applied candidate): its value inside */
  rcb_diag_add_par(c, variant ? "shaft.%s.mass" : "shaft.%s.stiffness", item,
                   fmin(lo, 0.5 * v), fmax(hi, 2.0 * v), 1);
  return 1;
}

/* A stiffness and a mass factor at every element, shaft by shaft along z. */
static rcb_status enumerate(rcb_diag *d, const rcb_model *m) {
  size_t e;
  int variant;
  for (variant = 0; variant < 2; variant++)
    for (e = 0; e < m->n_elements; e++)
      if (add_element(d, m, e, variant) < 0) return RCB_ERR_NOMEM;
  return RCB_OK;
}

const diag_family rcb_diag_family_element = {"element", DIAG_FAM_PLACE_WALK | DIAG_FAM_ONE_REFIT,
                                             enumerate, NULL, NULL, NULL, NULL};
