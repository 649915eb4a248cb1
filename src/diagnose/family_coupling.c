/*
 * The coupling family (issue #4; its own file since issue #23): at every
 * coupling, the damping and rotational stiffness it may lack (through a
 * coupling model that has them, their neutral value 0), every other coupling
 * model (no neutral value: refitted, not scored), and the hubs' mass and
 * diametral inertia.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "diagnose/diag_internal.h"

/* The coupling model that ties the same DOFs as t and uses what t uses plus
 * the coefficients of bits (the coupling table): t itself when it has them,
 * NELSON_CRANDALL_2 for NELSON_CRANDALL_1 + ct or cr, KRAMER_2 for KRAMER_1
 * + kr or cr; -1 when none does (KRAMER_1 + ct: tied translations have no
 * translational damping; rigid). */
static int model_with(rcb_coupling_model t, unsigned bits) {
  unsigned need = rcb_coupling_uses(t) | bits;
  int k;
  if ((rcb_coupling_uses(t) & bits) == bits) return (int)t;
  for (k = 0; k < RCB_COUPLING_MODEL_COUNT; k++)
    if (rcb_coupling_tied((rcb_coupling_model)k) == rcb_coupling_tied(t) &&
        (rcb_coupling_uses((rcb_coupling_model)k) & need) == need)
      return k;
  return -1;
}

static rcb_status enumerate(rcb_diag *d, const rcb_model *m) {
  size_t i;
  for (i = 0; i < m->n_couplings; i++) {
    const rcb_coupling_t *cp = &m->couplings[i];
    const rcb_coupling_params *p = &cp->p;
    char place[RCB_DIAG_NAME], nm[RCB_DIAG_NAME];
    double kref = p->kt > 0 ? p->kt : 1e6, krr = p->kr > 0 ? p->kr : 1e3;
    int t;
    diag_cand *c;
    snprintf(place, sizeof place, "coupling %s", cp->name);
    /* damping and rotational stiffness: NC2 has them; NC1/K1 need a model
     * change with the new parameters at 0 (the same physics) */
    for (t = 0; t < 3; t++) {
      static const unsigned bit[3] = {RCB_CPL_CT, RCB_CPL_KR, RCB_CPL_CR};
      static const char *const keys[3] = {"ct", "kr", "cr"};
      static const rcb_effect eff[3] = {RCB_EFFECT_COUPLING_TRANSLATIONAL_DAMPING,
                                        RCB_EFFECT_COUPLING_ROTATIONAL_STIFFNESS,
                                        RCB_EFFECT_COUPLING_ROTATIONAL_DAMPING};
      static const char *const what[3] = {"translational damping", "rotational stiffness",
                                          "rotational damping"};
      double v = t == 0 ? p->ct : t == 1 ? p->kr : p->cr, lo, hi;
      double hi0 = t == 0 ? 1e-2 * kref : t == 1 ? 1e3 * (p->kt > 0 ? 1e-2 * p->kt : 1e3)
                                        : 1e-2 * krr;
      int logp, to = model_with(cp->type, bit[t]);
      snprintf(nm, sizeof nm, "coupling.%s.%s", cp->name, keys[t]);
      if (rcb_diag_is_base(d, nm) || to < 0) continue;
      if (!(c = rcb_diag_new_cand(d, &rcb_diag_family_coupling, eff[t], place))) return RCB_ERR_NOMEM;
      snprintf(c->desc, sizeof c->desc, "%s in coupling %s", what[t], cp->name);
      if (to != (int)cp->type) {
        c->new_model = 1;
        snprintf(c->target, sizeof c->target, "%s", cp->name);
        c->new_type = (rcb_coupling_model)to;
        c->kt0 = p->kt, c->kr0 = p->kr, c->ct0 = p->ct, c->cr0 = p->cr;
      }
      rcb_diag_bounds(v, hi0, &lo, &hi, &logp);
      rcb_diag_add_par(c, "%s", nm, lo, hi, logp);
    }
    for (t = 0; t < RCB_COUPLING_MODEL_COUNT; t++) { /* another coupling model: refitted */
      if (t == (int)cp->type || (cp->type == RCB_COUPLING_NELSON_CRANDALL_1 &&
                                 t == RCB_COUPLING_NELSON_CRANDALL_2))
        continue; /* NC1 -> NC2 is covered by the damping candidates above */
      if (!(c = rcb_diag_new_cand(d, &rcb_diag_family_coupling, RCB_EFFECT_COUPLING_MODEL, place))) return RCB_ERR_NOMEM;
      snprintf(c->desc, sizeof c->desc, "coupling %s as %s instead of %s", cp->name,
               rcb_coupling_model_name((rcb_coupling_model)t),
               rcb_coupling_model_name(cp->type));
      c->refit_only = 1;
      c->new_model = 1;
      snprintf(c->target, sizeof c->target, "%s", cp->name);
      c->new_type = (rcb_coupling_model)t;
      c->kt0 = kref, c->kr0 = krr, c->ct0 = p->ct, c->cr0 = p->cr;
      if (rcb_coupling_uses((rcb_coupling_model)t) & RCB_CPL_KT) {
        snprintf(nm, sizeof nm, "coupling.%s.kt", cp->name);
        rcb_diag_add_par(c, "%s", nm, kref / 1000, kref * 1000, 1);
      }
      if (rcb_coupling_uses((rcb_coupling_model)t) & RCB_CPL_KR) {
        snprintf(nm, sizeof nm, "coupling.%s.kr", cp->name);
        rcb_diag_add_par(c, "%s", nm, krr / 1000, krr * 1000, 1);
      }
    }
    {
      double lo, hi;
      int logp;
      if (!(c = rcb_diag_new_cand(d, &rcb_diag_family_coupling, RCB_EFFECT_COUPLING_HUB, place))) return RCB_ERR_NOMEM;
      snprintf(c->desc, sizeof c->desc, "mass of coupling %s's hubs", cp->name);
      rcb_diag_bounds(p->mass[0], 10.0, &lo, &hi, &logp);
      rcb_diag_add_par(c, "coupling.%s.hub_mass", cp->name, lo, hi, logp);
      if (!(c = rcb_diag_new_cand(d, &rcb_diag_family_coupling, RCB_EFFECT_COUPLING_HUB, place))) return RCB_ERR_NOMEM;
      snprintf(c->desc, sizeof c->desc, "diametral inertia of coupling %s's hubs", cp->name);
      rcb_diag_bounds(p->Id[0], 0.1, &lo, &hi, &logp);
      rcb_diag_add_par(c, "coupling.%s.hub_Id", cp->name, lo, hi, logp);
    }
  }
  return RCB_OK;
}

/* A new coupling model's starting values (the parameters it uses). */
static rcb_status start(const diag_cand *c, rcb_model *m) {
  if (!c->new_model) return RCB_OK;
  const double v[4] = {c->kt0, c->kr0, c->ct0, c->cr0};
  unsigned uses = rcb_coupling_uses(c->new_type);
  rcb_status st = RCB_OK;
  int k;
  for (k = 0; k < 4 && !st; k++) {
    char nm[RCB_DIAG_NAME];
    if (!(uses & (1u << k))) continue;
    snprintf(nm, sizeof nm, "coupling.%s.%s", c->target, rcb_coupling_coef_key(k));
    st = rcb_model_set_param(m, nm, v[k]);
  }
  return st;
}


/* Another coupling model (c->new_model), on the unfinalized copy m. */
static rcb_status edit(const diag_cand *c, rcb_model *m) {
  return c->new_model ? rcb_model_set_coupling_model(m, c->target, c->new_type) : RCB_OK;
}

const diag_family rcb_diag_family_coupling = {"coupling", 0, enumerate, edit, start, NULL,
                                              NULL};
