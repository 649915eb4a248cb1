/*
 * Per-element parameters (issue #23): a local loss of bending stiffness (a
 * crack, wear, a loose shrink fit) or a local change of mass in one shaft
 * element, as two dimensionless factors per element:
 *
 *   shaft.S.e<k>.stiffness  multiplies the element's E and G (its whole K,
 *                           bending and shear; phi is unchanged)
 *   shaft.S.e<k>.mass       multiplies its density (translational and rotary
 *                           inertia, and the gyroscopic matrix)
 *
 * k counts shaft S's elements from 1 in z order, over its segments as
 * given; both factors are neutral at 1 and enter M, C (through qz_m M +
 * qz_k K), G and K linearly, as the analytic sensitivities need. They live
 * on the shaft (rcb_shaft_t.ef, grown with its segments), so a clone keeps
 * them and finalize does not reset them. They are not enumerated by
 * rcb_model_param_count (one pair per element would swamp the list);
 * rcb_model_element_info lists each element with its z range and factors.
 * INI: [shaft] element_stiffness | element_mass = k factor [k factor ...]
 * (ini_build.c reads them through rcb_model_set_param, ini_write.c writes
 * those that are not 1).
 *
 * A span of elements (issue #33: a change of section or material along part
 * of a shaft) is a view, as pedestal_k is of a pedestal's x and y:
 *
 *   shaft.S.e<a>-<b>.stiffness | mass  the factor of elements a to b
 *                           (a <= b) together: setting it sets each of
 *                           them, getting it gives element a's
 *
 * so the fit's sensitivity (set, assemble, difference) is that of the whole
 * span; the INI and the writer know elements only.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/rcb_internal.h"
#include "model/model_util.h"

static const char *const element_keys[2] = {"stiffness", "mass"};

int rcb_element_param_shape(const char *name) {
  const char *d;
  int dots = 0;
  if (!name || strncmp(name, "shaft.", 6) != 0) return 0;
  for (d = name; *d; d++) dots += *d == '.';
  return dots == 3;
}

/* The shaft named by the n bytes at s, or -1. */
static long shaft_named(const rcb_model *m, const char *s, size_t n) {
  size_t i;
  for (i = 0; i < m->n_shafts; i++)
    if (strlen(m->shafts[i].name) == n && strncmp(m->shafts[i].name, s, n) == 0) return (long)i;
  return -1;
}

rcb_status rcb_element_param_slot(rcb_model *m, const char *name, double **slot, size_t *n) {
  const char *item = name + 6, *d2 = strchr(item, '.'), *d3 = d2 ? strchr(d2 + 1, '.') : NULL;
  const rcb_shaft_t *sh;
  char *end = NULL;
  long s;
  unsigned long k, k2;
  int key;
  *slot = NULL, *n = 0;
  if (!d2 || !d3) return rcb_model_fail(m, RCB_ERR_NOT_FOUND, "parameter '%s' unknown", name);
  if ((s = shaft_named(m, item, (size_t)(d2 - item))) < 0)
    return rcb_model_fail(m, RCB_ERR_NOT_FOUND,
                          "parameter '%s': the model has no shaft '%.*s' (element parameters "
                          "are shaft.SHAFT.e<k>.stiffness | mass, a span of elements "
                          "shaft.SHAFT.e<a>-<b>.stiffness | mass)",
                          name, (int)(d2 - item < 64 ? d2 - item : 64), item);
  sh = &m->shafts[s];
  for (key = 0; key < 2 && strcmp(d3 + 1, element_keys[key]) != 0; key++) continue;
  if (key == 2)
    return rcb_model_fail(m, RCB_ERR_NOT_FOUND,
                          "parameter '%s': an element of shaft '%s' has the parameters "
                          "stiffness and mass (factors, neutral 1)",
                          name, sh->name);
  k = k2 = 0;
  if (d2[1] == 'e' && d2[2] >= '1' && d2[2] <= '9') k = k2 = strtoul(d2 + 2, &end, 10);
  if (k && end && *end == '-' && end[1] >= '1' && end[1] <= '9') /* a span e<a>-<b> */
    k2 = strtoul(end + 1, &end, 10);
  if (k == 0 || end != d3 || k2 < k || k2 > sh->nef) {
    if (sh->nef == 0)
      return rcb_model_fail(m, RCB_ERR_NOT_FOUND, "parameter '%s': shaft '%s' has no element",
                            name, sh->name);
    return rcb_model_fail(m, RCB_ERR_NOT_FOUND,
                          "parameter '%s': expected an element e1 to e%zu of shaft '%s', or a "
                          "span e<a>-<b> of them with a <= b (counted from 1 in z order; "
                          "'rcbtool check' lists them)",
                          name, sh->nef, sh->name);
  }
  *slot = &m->shafts[s].ef[2 * (k - 1) + (size_t)key];
  *n = k2 - k + 1; /* every second double from *slot (stiffness, mass interleaved) */
  return RCB_OK;
}

rcb_status rcb_model_element_info(const rcb_model *m, size_t e, rcb_element_info *out) {
  const rcb_element_t *el;
  const rcb_shaft_t *sh;
  if (!m || !out) return RCB_ERR_ARG;
  memset(out, 0, sizeof *out);
  if (!m->finalized)
    return rcb_model_fail((rcb_model *)m, RCB_ERR_STATE,
                          "element %zu: the model is not finalized", e);
  if (e >= m->n_elements)
    return rcb_model_fail((rcb_model *)m, RCB_ERR_NOT_FOUND,
                          "element %zu does not exist; the model has %zu elements", e,
                          m->n_elements);
  el = &m->elements[e];
  sh = &m->shafts[el->shaft];
  out->shaft = sh->name;
  out->index = el->k + 1;
  out->node0 = el->node0;
  out->node1 = el->node0 + 1;
  out->z0 = m->nodes[el->node0].z;
  out->z1 = m->nodes[el->node0 + 1].z;
  out->outer_d = el->od;
  out->inner_d = el->id;
  out->stiffness = el->k < sh->nef ? sh->ef[2 * el->k] : 1.0;
  out->mass = el->k < sh->nef ? sh->ef[2 * el->k + 1] : 1.0;
  return RCB_OK;
}
