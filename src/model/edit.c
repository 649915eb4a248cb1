/*
 * Editing a model: a deep copy (rcb_model_clone) and the structural edits a
 * copy takes before it is finalized, so that a variant of a model (a
 * candidate effect of the diagnosis, a what-if study) is built from the
 * model itself: clone, edit, finalize, set parameters. No text is written or
 * parsed on the way.
 *
 * A clone holds the items of the model (what the builder calls add), not
 * the mesh, the station table or the warnings that finalize derives from
 * them: it is always unfinalized, whatever the source's state, and
 * rcb_model_finalize rebuilds all of it.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/rcb_internal.h"
#include "model/model_util.h"

/* A copy of n items of size bytes from the allocator a (NULL when n == 0);
 * *fail set on failure. */
static void *dup_items(const rcb_allocator *a, const void *src, size_t n, size_t size,
                       int *fail) {
  void *p;
  if (n == 0 || !src) return NULL;
  if (!(p = rcb_alloc(a, n * size))) {
    *fail = 1;
    return NULL;
  }
  memcpy(p, src, n * size);
  return p;
}

#define DUP_ARRAY(arr)                                                                \
  do {                                                                                \
    c->arr = dup_items(&c->alloc, src->arr, src->n_##arr, sizeof *src->arr, &fail);   \
    c->n_##arr = c->cap_##arr = c->arr ? src->n_##arr : 0;                           \
  } while (0)

/* The shafts' segments and element factors and the bearings' tables: owned per item. The item
 * arrays were copied bytewise, so their pointers are the source's until
 * replaced here; the ones not reached on a failure are cleared, so that
 * destroying the clone frees only what it owns. */
static int dup_owned(rcb_model *c, const rcb_model *src) {
  size_t i;
  int fail = 0;
  for (i = 0; i < c->n_shafts; i++) {
    rcb_shaft_t *sh = &c->shafts[i];
    sh->seg = fail ? NULL : dup_items(&c->alloc, src->shafts[i].seg, sh->nseg, sizeof *sh->seg,
                                      &fail);
    sh->capseg = sh->seg ? sh->nseg : 0;
    if (!sh->seg) sh->nseg = 0;
    sh->ef = fail ? NULL : dup_items(&c->alloc, src->shafts[i].ef, 2 * sh->nef, sizeof *sh->ef,
                                     &fail);
    sh->capef = sh->ef ? 2 * sh->nef : 0;
    if (!sh->ef) sh->nef = 0;
  }
  for (i = 0; i < c->n_bearings; i++) {
    rcb_bearing_t *b = &c->bearings[i];
    const rcb_bearing_t *sb = &src->bearings[i];
    b->speeds = fail ? NULL : dup_items(&c->alloc, sb->speeds, sb->n, sizeof *b->speeds, &fail);
    b->c = fail ? NULL : dup_items(&c->alloc, sb->c, sb->n, sizeof *b->c, &fail);
  }
  return fail;
}

rcb_status rcb_model_clone(rcb_model **out, const rcb_model *src, const rcb_allocator *alloc) {
  rcb_model *c = NULL;
  int fail = 0;
  rcb_status st;
  if (!out) return RCB_ERR_ARG;
  *out = NULL;
  if (!src) return RCB_ERR_ARG;
  if ((st = rcb_model_create(&c, alloc))) return st;
  DUP_ARRAY(materials);
  DUP_ARRAY(shafts);
  DUP_ARRAY(disks);
  DUP_ARRAY(bearings);
  DUP_ARRAY(couplings);
  DUP_ARRAY(unbalances);
  DUP_ARRAY(probes);
  DUP_ARRAY(uffmap);
  fail |= dup_owned(c, src);
  if (fail) {
    rcb_model_destroy(c);
    return RCB_ERR_NOMEM;
  }
  c->speed_factor = src->speed_factor;
  c->has_test_speed = src->has_test_speed; /* [test] rpm */
  c->test_speed = src->test_speed;
  *out = c;
  return RCB_OK;
}

#undef DUP_ARRAY

static rcb_coupling_t *find_coupling(rcb_model *m, const char *name) {
  size_t i;
  for (i = 0; name && i < m->n_couplings; i++)
    if (strcmp(m->couplings[i].name, name) == 0) return &m->couplings[i];
  return NULL;
}

static rcb_bearing_t *find_bearing(rcb_model *m, const char *name) {
  size_t i;
  for (i = 0; name && i < m->n_bearings; i++)
    if (strcmp(m->bearings[i].name, name) == 0) return &m->bearings[i];
  return NULL;
}

rcb_status rcb_model_set_coupling_model(rcb_model *m, const char *coupling,
                                        rcb_coupling_model type) {
  rcb_coupling_t *c;
  unsigned uses;
  int k;
  rcb_status st = rcb_model_check_editable(m, "coupling model");
  if (st) return st;
  if (!(c = find_coupling(m, coupling)))
    return rcb_model_fail(m, RCB_ERR_NOT_FOUND, "coupling model: no coupling named '%s'",
                          coupling ? coupling : "(null)");
  if (!rcb_coupling_model_name(type))
    return rcb_model_fail(m, RCB_ERR_ARG, "coupling '%s': unknown model %d", c->name,
                          (int)type);
  c->type = type;
  uses = rcb_coupling_uses(type);
  for (k = 0; k < 4; k++) /* as the INI format holds it: no value the model ignores */
    if (!(uses & (1u << k))) *rcb_coupling_coef(&c->p, k) = 0.0;
  return RCB_OK;
}

rcb_status rcb_model_set_bearing_coefs(rcb_model *m, const char *bearing, size_t n,
                                       const double *speeds, const rcb_bearing_coefs *c) {
  rcb_bearing_t *b;
  rcb_status st = rcb_model_check_editable(m, "bearing coefficients");
  if (st) return st;
  if (!(b = find_bearing(m, bearing)))
    return rcb_model_fail(m, RCB_ERR_NOT_FOUND, "bearing coefficients: no bearing named '%s'",
                          bearing ? bearing : "(null)");
  return rcb_model_bearing_rows(m, b, b->name, n, speeds, c);
}

/* Node N of the mesh finalize will build (0-based, along the shafts in
 * definition order): its shaft and z (m), exactly as finalize computes it. */
static int node_place(const rcb_model *m, size_t node, size_t *shaft, double *z) {
  size_t s, g, e, k = 0;
  for (s = 0; s < m->n_shafts; s++) {
    const rcb_shaft_t *sh = &m->shafts[s];
    double zz = sh->z0;
    if (k++ == node) {
      *shaft = s, *z = zz;
      return 0;
    }
    for (g = 0; g < sh->nseg; g++) {
      const rcb_segment_t *sg = &sh->seg[g];
      for (e = 0; e < (size_t)sg->nel; e++)
        if (k++ == node) {
          *shaft = s, *z = rcb_segment_node_z(zz, sg->L, e, sg->nel);
          return 0;
        }
      zz += sg->L;
    }
  }
  return -1;
}

/* The place of a station name (disk, bearing, coupling "C", "C.SHAFT",
 * unbalance, probe) or "#N"; 0 if found. */
static int station_place(const rcb_model *m, const char *spec, size_t *shaft, double *z) {
  const rcb_place_t *at = NULL;
  size_t i, k;
  if (spec[0] == '#') {
    char *end;
    long n = strtol(spec + 1, &end, 10);
    if (end == spec + 1 || *end || n < 0) return -1;
    return node_place(m, (size_t)n, shaft, z);
  }
#define RCB_FIND_(arr)                                                  \
  for (i = 0; !at && i < m->n_##arr; i++)                               \
    if (strcmp(m->arr[i].name, spec) == 0) at = &m->arr[i].at;
  RCB_FIND_(disks)
  RCB_FIND_(bearings)
  RCB_FIND_(unbalances)
  RCB_FIND_(probes)
#undef RCB_FIND_
  for (i = 0; !at && i < m->n_couplings; i++) {
    const rcb_coupling_t *c = &m->couplings[i];
    size_t ln = strlen(c->name);
    if (strcmp(c->name, spec) == 0) at = &c->at[0];
    for (k = 0; !at && k < 2; k++)
      if (strncmp(spec, c->name, ln) == 0 && spec[ln] == '.' &&
          strcmp(spec + ln + 1, m->shafts[c->at[k].shaft].name) == 0)
        at = &c->at[k];
  }
  if (!at) return -1;
  *shaft = at->shaft, *z = at->z;
  return 0;
}

rcb_status rcb_model_add_disk_at(rcb_model *m, const char *name, const char *station,
                                 double mass, double Id, double Ip) {
  size_t shaft;
  double z;
  rcb_status st = rcb_model_check_editable(m, "disk");
  if (st) return st;
  if (!station || station_place(m, station, &shaft, &z))
    return rcb_model_fail(m, RCB_ERR_NOT_FOUND,
                          "disk '%s': no station or node '%s' (a disk, bearing, coupling, "
                          "unbalance or station name, or #N for node N)",
                          name ? name : "(null)", station ? station : "(null)");
  return rcb_model_add_disk(m, name, m->shafts[shaft].name, z, mass, Id, Ip);
}
