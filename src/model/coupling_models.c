/*
 * The five coupling models of Tapia & Cavalca (paper section 3) in one
 * table: the name used in INI files and messages, which of kt, kr, ct, cr
 * each one uses, and how many DOFs of its two stations it ties. The INI
 * loader and writer, the parameter list, the coupling element, the DOF
 * numbering of finalize and the diagnosis catalogue all read it here.
 */
#include <string.h>

#include "core/rcb_internal.h"

typedef struct coupling_kind {
  const char *name;
  unsigned uses; /* RCB_CPL_KT | RCB_CPL_KR | RCB_CPL_CT | RCB_CPL_CR */
  int tied;      /* DOFs of station a tied to station b: x, y (2) or all four */
} coupling_kind;

static const coupling_kind kinds[RCB_COUPLING_MODEL_COUNT] = {
    {"kramer_1", 0u, 2},
    {"kramer_2", RCB_CPL_KR | RCB_CPL_CR, 2},
    {"nelson_crandall_1", RCB_CPL_KT | RCB_CPL_KR, 0},
    {"nelson_crandall_2", RCB_CPL_KT | RCB_CPL_KR | RCB_CPL_CT | RCB_CPL_CR, 0},
    {"rigid", 0u, 4}};

static const char *const coef_keys[4] = {"kt", "kr", "ct", "cr"};

static int valid(rcb_coupling_model t) { return (int)t >= 0 && (int)t < RCB_COUPLING_MODEL_COUNT; }

const char *rcb_coupling_model_name(rcb_coupling_model t) {
  return valid(t) ? kinds[t].name : NULL;
}

rcb_status rcb_coupling_model_parse(const char *name, rcb_coupling_model *t) {
  int i;
  if (!name || !t) return RCB_ERR_ARG;
  for (i = 0; i < RCB_COUPLING_MODEL_COUNT; i++)
    if (strcmp(name, kinds[i].name) == 0) {
      *t = (rcb_coupling_model)i;
      return RCB_OK;
    }
  return RCB_ERR_NOT_FOUND;
}

unsigned rcb_coupling_uses(rcb_coupling_model t) { return valid(t) ? kinds[t].uses : 0u; }

int rcb_coupling_tied(rcb_coupling_model t) { return valid(t) ? kinds[t].tied : 0; }

const char *rcb_coupling_coef_key(int k) { return k >= 0 && k < 4 ? coef_keys[k] : NULL; }

double *rcb_coupling_coef(rcb_coupling_params *p, int k) {
  double *v[4];
  v[0] = &p->kt;
  v[1] = &p->kr;
  v[2] = &p->ct;
  v[3] = &p->cr;
  return v[k >= 0 && k < 4 ? k : 3];
}
