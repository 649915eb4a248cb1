/*
 * Model parameters addressed by name, "KIND.ITEM.KEY" (identification, issue
 * #3). One table lists the keys of each kind with the builder's unit text and
 * sign rule, so getting, setting, counting and naming all walk the same list
 * in the same order: materials, shafts, disks, bearings, couplings,
 * unbalances; within an item, the keys in table order.
 *
 * Setting a value never touches the mesh: every parameter here enters the
 * element matrices (or the unbalance force) directly, so a finalized model
 * stays valid.
 */
#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "core/rcb_internal.h"
#include "model/model_util.h"

#define SPEED_FACTOR "speed.factor"

typedef enum pkind {
  PK_MATERIAL = 0,
  PK_SHAFT,
  PK_DISK,
  PK_BEARING,
  PK_COUPLING,
  PK_UNBALANCE,
  PK_COUNT
} pkind;

/* One key: INI name, builder message text (with unit), sign rule of
 * rcb_model_check_value (1: > 0, 0: >= 0, -1: any finite). */
typedef struct pkey {
  const char *key;
  const char *what;
  int sign;
} pkey;

static const pkey material_keys[] = {{"density", "density (kg/m^3)", 1},
                                     {"young", "young (Pa)", 1}};
/* stiffness, mass: factors on the whole shaft's E and G, and its density
 * (rcb_shaft_t.sf), on top of the element factors */
static const pkey shaft_keys[] = {{"damping_mass", "damping_mass qz_m (1/s)", 0},
                                  {"damping_stiffness", "damping_stiffness qz_k (s)", 0},
                                  {"stiffness", "stiffness factor (-)", 1},
                                  {"mass", "mass factor (-)", 1}};
static const pkey disk_keys[] = {
    {"mass", "mass (kg)", 0}, {"Id", "Id (kg m^2)", 0}, {"Ip", "Ip (kg m^2)", 0}};
/* Bearing coefficients may be negative (cross-coupled bearings): finite only,
 * as the builder checks them. Same order as rcb_bearing_coefs. */
static const pkey bearing_keys[] = {
    {"kxx", "kxx (N/m)", -1},   {"kxy", "kxy (N/m)", -1},   {"kyx", "kyx (N/m)", -1},
    {"kyy", "kyy (N/m)", -1},   {"cxx", "cxx (N s/m)", -1}, {"cxy", "cxy (N s/m)", -1},
    {"cyx", "cyx (N s/m)", -1}, {"cyy", "cyy (N s/m)", -1},
    /* views for the diagnosis: a skew-symmetric (circulatory) pair, setting
     * kxy = v and kyx = -v; not enumerated (they alias kxy/kyx) */
    {"kcross", "kcross = kxy = -kyx (N/m)", -1}, {"ccross", "ccross = cxy = -cyx (N s/m)", -1},
    /* the pedestal (flexible support) of a bearing that has one */
    {"pedestal_mass", "pedestal_mass (kg)", 0}, {"pedestal_kxx", "pedestal_kxx (N/m)", 0},
    {"pedestal_kyy", "pedestal_kyy (N/m)", 0},  {"pedestal_cxx", "pedestal_cxx (N s/m)", 0},
    {"pedestal_cyy", "pedestal_cyy (N s/m)", 0},
    /* views for the diagnosis: an isotropic pedestal, x and y together */
    {"pedestal_k", "pedestal_k = pedestal_kxx = pedestal_kyy (N/m)", 0},
    {"pedestal_c", "pedestal_c = pedestal_cxx = pedestal_cyy (N s/m)", 0}};

/* The first keys of the bearing table are its own; then the views kcross,
 * ccross; the pedestal's own keys; its views. */
#define BEARING_OWN_KEYS 8
#define BEARING_PED_KEYS 10 /* first pedestal key */
#define BEARING_PED_VIEWS 15 /* pedestal_k, pedestal_c */
/* kt, kr, ct, cr first, in the order of the coupling table's bits
 * (rcb_coupling_coef_key, model/coupling_models.c). */
static const pkey coupling_keys[] = {{"kt", "kt (N/m)", 0},
                                     {"kr", "kr (N m/rad)", 0},
                                     {"ct", "ct (N s/m)", 0},
                                     {"cr", "cr (N m s/rad)", 0},
                                     {"hub_mass", "hub mass (kg)", 0},
                                     {"hub_Id", "hub Id (kg m^2)", 0},
                                     {"hub_Ip", "hub Ip (kg m^2)", 0}};
static const pkey unbalance_keys[] = {{"amount", "amount (kg m)", 0},
                                      {"phase", "phase (rad)", -1}};

typedef struct pkind_info {
  const char *name;
  const pkey *keys;
  size_t nkeys;
} pkind_info;

#define PK(n, a) {(n), (a), sizeof(a) / sizeof((a)[0])}
static const pkind_info kinds[PK_COUNT] = {
    PK("material", material_keys), PK("shaft", shaft_keys),
    PK("disk", disk_keys),         PK("bearing", bearing_keys),
    PK("coupling", coupling_keys), PK("unbalance", unbalance_keys)};
#undef PK

static size_t item_count(const rcb_model *m, pkind k) {
  switch (k) {
    case PK_MATERIAL: return m->n_materials;
    case PK_SHAFT: return m->n_shafts;
    case PK_DISK: return m->n_disks;
    case PK_BEARING: return m->n_bearings;
    case PK_COUPLING: return m->n_couplings;
    case PK_UNBALANCE: return m->n_unbalances;
    default: return 0;
  }
}

static const char *item_name(const rcb_model *m, pkind k, size_t i) {
  switch (k) {
    case PK_MATERIAL: return m->materials[i].name;
    case PK_SHAFT: return m->shafts[i].name;
    case PK_DISK: return m->disks[i].name;
    case PK_BEARING: return m->bearings[i].name;
    case PK_COUPLING: return m->couplings[i].name;
    case PK_UNBALANCE: return m->unbalances[i].name;
    default: return "";
  }
}

/* Is (k, j) listed by rcb_model_param_count/_name (views are not)? */
static int enumerated(pkind k, size_t j) {
  return !(k == PK_BEARING && j >= BEARING_OWN_KEYS &&
           (j < BEARING_PED_KEYS || j >= BEARING_PED_VIEWS));
}

/* Does item i of kind k have key j as a fittable parameter? */
static int key_usable(const rcb_model *m, pkind k, size_t i, size_t j) {
  if (k == PK_BEARING && j >= BEARING_PED_KEYS) return m->bearings[i].has_ped;
  if (k == PK_BEARING) return m->bearings[i].n == 1;
  if (k == PK_COUPLING && j < 4) /* kt, kr, ct, cr: the bits of the coupling table */
    return (rcb_coupling_uses(m->couplings[i].type) & (1u << j)) != 0;
  return 1;
}

/* Storage of parameter (k, i, j): one value, or two for coupling hubs
 * (station a, station b). Returns the number of slots. */
static int slots(rcb_model *m, pkind k, size_t i, size_t j, double *v[2]) {
  v[1] = NULL;
  switch (k) {
    case PK_MATERIAL: v[0] = j == 0 ? &m->materials[i].rho : &m->materials[i].E; return 1;
    case PK_SHAFT: {
      rcb_shaft_t *sh = &m->shafts[i];
      v[0] = j == 0 ? &sh->qz_m : j == 1 ? &sh->qz_k : &sh->sf[j - 2];
      return 1;
    }
    case PK_DISK: {
      rcb_disk_t *d = &m->disks[i];
      v[0] = j == 0 ? &d->m : j == 1 ? &d->Id : &d->Ip;
      return 1;
    }
    case PK_BEARING: {
      rcb_bearing_t *b = &m->bearings[i];
      rcb_bearing_coefs *c = &b->c[0];
      if (j >= BEARING_PED_VIEWS) { /* x and y together */
        v[0] = j == BEARING_PED_VIEWS ? &b->ped_k[0] : &b->ped_c[0];
        v[1] = j == BEARING_PED_VIEWS ? &b->ped_k[1] : &b->ped_c[1];
        return 2;
      }
      if (j >= BEARING_PED_KEYS) {
        double *ped[5];
        ped[0] = &b->ped_m;
        ped[1] = &b->ped_k[0];
        ped[2] = &b->ped_k[1];
        ped[3] = &b->ped_c[0];
        ped[4] = &b->ped_c[1];
        v[0] = ped[j - BEARING_PED_KEYS];
        return 1;
      }
      if (j < BEARING_OWN_KEYS) {
        v[0] = &(&c->kxx)[j];
        return 1;
      }
      v[0] = j == BEARING_OWN_KEYS ? &c->kxy : &c->cxy; /* the pair's second slot */
      v[1] = j == BEARING_OWN_KEYS ? &c->kyx : &c->cyx; /* gets the opposite sign */
      return 2;
    }
    case PK_COUPLING: {
      rcb_coupling_params *p = &m->couplings[i].p;
      if (j < 4) {
        v[0] = rcb_coupling_coef(p, (int)j);
        return 1;
      }
      v[0] = j == 4 ? &p->mass[0] : j == 5 ? &p->Id[0] : &p->Ip[0];
      v[1] = j == 4 ? &p->mass[1] : j == 5 ? &p->Id[1] : &p->Ip[1];
      return 2;
    }
    case PK_UNBALANCE:
      v[0] = j == 0 ? &m->unbalances[i].amount : &m->unbalances[i].phase;
      return 1;
    default: v[0] = NULL; return 0;
  }
}

/* ---- enumeration ---- */

typedef struct pref {
  pkind k;
  size_t i, j;
} pref;

/* Parameter number idx in the stable order; 0 if found. */
static int nth_param(const rcb_model *m, size_t idx, pref *out) {
  size_t n = 0, i, j;
  int k;
  for (k = 0; k < PK_COUNT; k++)
    for (i = 0; i < item_count(m, (pkind)k); i++)
      for (j = 0; j < kinds[k].nkeys; j++) {
        if (!enumerated((pkind)k, j) || !key_usable(m, (pkind)k, i, j)) continue;
        if (n++ == idx) {
          out->k = (pkind)k;
          out->i = i;
          out->j = j;
          return 0;
        }
      }
  return -1;
}

size_t rcb_model_param_count(const rcb_model *m) {
  size_t n = 0, i, j;
  int k;
  if (!m) return 0;
  for (k = 0; k < PK_COUNT; k++)
    for (i = 0; i < item_count(m, (pkind)k); i++)
      for (j = 0; j < kinds[k].nkeys; j++)
        n += (size_t)(enumerated((pkind)k, j) && key_usable(m, (pkind)k, i, j));
  return n;
}

static int format_name(const rcb_model *m, const pref *r, char *buf, size_t size) {
  return snprintf(buf, size, "%s.%s.%s", kinds[r->k].name, item_name(m, r->k, r->i),
                  kinds[r->k].keys[r->j].key);
}

rcb_status rcb_model_param_name(const rcb_model *m, size_t i, char *buf, size_t size) {
  rcb_model *mm = (rcb_model *)m; /* only the error buffer is written */
  pref r;
  int len;
  if (!m) return RCB_ERR_ARG;
  if (!buf || size == 0)
    return rcb_model_fail(mm, RCB_ERR_ARG, "rcb_model_param_name: no output buffer");
  buf[0] = '\0';
  if (nth_param(m, i, &r))
    return rcb_model_fail(mm, RCB_ERR_NOT_FOUND,
                          "parameter %zu does not exist; the model has %zu parameters "
                          "(0 to %zu)",
                          i, rcb_model_param_count(m), rcb_model_param_count(m) - 1);
  len = format_name(m, &r, buf, size);
  if (len < 0 || (size_t)len >= size) {
    buf[0] = '\0';
    return rcb_model_fail(mm, RCB_ERR_WORKSPACE,
                          "parameter %zu: name needs %d bytes, the buffer has %zu", i,
                          len + 1, size);
  }
  return RCB_OK;
}

/* ---- closest valid name, for messages ---- */

#define NAME_CMP_MAX 160


/* "; the closest valid name is 'X'" (or that there is none) into buf. */
static void closest_hint(const rcb_model *m, const char *word, char *buf, size_t size) {
  char cand[NAME_CMP_MAX + 8], best[NAME_CMP_MAX + 8];
  size_t i, j, best_d = (size_t)-1, n = 0;
  int k;
  best[0] = '\0';
  for (k = 0; k < PK_COUNT; k++)
    for (i = 0; i < item_count(m, (pkind)k); i++)
      for (j = 0; j < kinds[k].nkeys; j++) {
        pref r;
        size_t d;
        if (!key_usable(m, (pkind)k, i, j)) continue;
        r.k = (pkind)k;
        r.i = i;
        r.j = j;
        n++;
        format_name(m, &r, cand, sizeof cand);
        d = rcb_edit_distance(word, cand);
        if (d < best_d) {
          best_d = d;
          snprintf(best, sizeof best, "%s", cand);
        }
      }
  if (n == 0)
    snprintf(buf, size, "; the model has no fittable parameters");
  else if (best[0])
    snprintf(buf, size, "; the closest valid name is '%s'", best);
  else
    buf[0] = '\0';
}

/* "a, b, c" of the keys item (k, i) offers. */
static void usable_keys(const rcb_model *m, pkind k, size_t i, char *buf, size_t size) {
  size_t j, used = 0;
  buf[0] = '\0';
  for (j = 0; j < kinds[k].nkeys && used < size; j++) {
    int w;
    if (!key_usable(m, k, i, j)) continue;
    w = snprintf(buf + used, size - used, "%s%s", used ? ", " : "", kinds[k].keys[j].key);
    if (w < 0) break;
    used += (size_t)w;
  }
}

/* ---- name lookup ---- */

/* "speed.factor": the model's speed factor, outside the KIND.ITEM.KEY table
 * (not enumerated). */
static int is_speed_factor(const char *name) { return name && strcmp(name, SPEED_FACTOR) == 0; }

static rcb_status lookup(rcb_model *m, const char *name, pref *out) {
  char item[RCB_NAME_MAX], keys[200], hint[NAME_CMP_MAX + 64];
  const char *d1, *d2, *key;
  size_t i, j, lk, li;
  int k;
  if (!name) return rcb_model_fail(m, RCB_ERR_ARG, "parameter name is NULL");
  d1 = strchr(name, '.');
  d2 = strrchr(name, '.');
  hint[0] = '\0';
  if (!d1 || d1 == d2) {
    closest_hint(m, name, hint, sizeof hint);
    return rcb_model_fail(m, RCB_ERR_NOT_FOUND,
                          "parameter '%s': expected a name KIND.ITEM.KEY, e.g. "
                          "coupling.C.kt%s",
                          name, hint);
  }
  lk = (size_t)(d1 - name);
  li = (size_t)(d2 - d1 - 1);
  key = d2 + 1;
  for (k = 0; k < PK_COUNT; k++)
    if (strlen(kinds[k].name) == lk && strncmp(kinds[k].name, name, lk) == 0) break;
  if (k == PK_COUNT) {
    closest_hint(m, name, hint, sizeof hint);
    return rcb_model_fail(m, RCB_ERR_NOT_FOUND,
                          "parameter '%s': unknown kind '%.*s'; expected material, shaft, "
                          "disk, bearing, coupling or unbalance%s",
                          name, (int)(lk < 32 ? lk : 32), name, hint);
  }
  for (i = 0; i < item_count(m, (pkind)k); i++) {
    const char *nm = item_name(m, (pkind)k, i);
    if (strlen(nm) == li && strncmp(nm, d1 + 1, li) == 0) break;
  }
  if (i == item_count(m, (pkind)k)) {
    closest_hint(m, name, hint, sizeof hint);
    snprintf(item, sizeof item, "%.*s", (int)(li < sizeof item ? li : sizeof item - 1), d1 + 1);
    return rcb_model_fail(m, RCB_ERR_NOT_FOUND, "parameter '%s': the model has no %s '%s'%s",
                          name, kinds[k].name, item, hint);
  }
  for (j = 0; j < kinds[k].nkeys; j++)
    if (strcmp(kinds[k].keys[j].key, key) == 0) break;
  if (j == kinds[k].nkeys) {
    closest_hint(m, name, hint, sizeof hint);
    usable_keys(m, (pkind)k, i, keys, sizeof keys);
    return rcb_model_fail(m, RCB_ERR_NOT_FOUND,
                          "parameter '%s': %s '%s' has no parameter '%s'; its parameters are "
                          "%s%s",
                          name, kinds[k].name, item_name(m, (pkind)k, i), key,
                          keys[0] ? keys : "none", hint);
  }
  if (!key_usable(m, (pkind)k, i, j)) {
    if (k == PK_BEARING && j >= BEARING_PED_KEYS)
      return rcb_model_fail(m, RCB_ERR_NOT_FOUND,
                            "parameter '%s': bearing '%s' has no pedestal; give it one in the "
                            "model (pedestal_mass, pedestal_kxx, pedestal_kyy, ... in its "
                            "[bearing] section) before fitting it",
                            name, m->bearings[i].name);
    if (k == PK_BEARING)
      return rcb_model_fail(m, RCB_ERR_NOT_FOUND,
                            "parameter '%s': bearing '%s' is speed-dependent (a table of %zu "
                            "speeds); its coefficients are not fittable, only those of "
                            "constant bearings",
                            name, m->bearings[i].name, m->bearings[i].n);
    usable_keys(m, (pkind)k, i, keys, sizeof keys);
    return rcb_model_fail(m, RCB_ERR_NOT_FOUND,
                          "parameter '%s': coupling '%s' (%s) has no %s; its parameters are %s",
                          name, m->couplings[i].name,
                          rcb_coupling_model_name(m->couplings[i].type), key, keys);
  }
  out->k = (pkind)k;
  out->i = i;
  out->j = j;
  return RCB_OK;
}

rcb_status rcb_model_get_param(const rcb_model *m, const char *name, double *value) {
  rcb_model *mm = (rcb_model *)m; /* only the error buffer is written */
  double *v[2];
  pref r;
  rcb_status st;
  if (!m) return RCB_ERR_ARG;
  if (!value) return rcb_model_fail(mm, RCB_ERR_ARG, "rcb_model_get_param: value is NULL");
  if (is_speed_factor(name)) {
    *value = m->speed_factor;
    return RCB_OK;
  }
  if (rcb_element_param_shape(name)) { /* a span: its first element's */
    size_t ne;
    if ((st = rcb_element_param_slot(mm, name, v, &ne))) return st;
    *value = *v[0];
    return RCB_OK;
  }
  if ((st = lookup(mm, name, &r))) return st;
  slots(mm, r.k, r.i, r.j, v);
  *value = *v[0]; /* hubs: station a */
  return RCB_OK;
}

/* kcross, ccross: the second slot gets the opposite sign. */
static int cross_pair(pkind k, size_t j) {
  return k == PK_BEARING && j >= BEARING_OWN_KEYS && j < BEARING_PED_KEYS;
}

rcb_status rcb_model_set_param(rcb_model *m, const char *name, double value) {
  double *v[2];
  pref r;
  rcb_status st;
  const pkey *key;
  int n, s;
  if (!m) return RCB_ERR_ARG;
  if (is_speed_factor(name)) {
    if ((st = rcb_model_check_value(m, "model", "speed", "factor (-)", value, 1))) return st;
    m->speed_factor = value;
    return RCB_OK;
  }
  if (rcb_element_param_shape(name)) { /* shaft.S.e<k> | e<a>-<b> .stiffness | mass */
    size_t ne, e;
    if ((st = rcb_element_param_slot(m, name, v, &ne)) ||
        (st = rcb_model_check_value(m, "shaft element", name, "factor (-)", value, 1)))
      return st;
    for (e = 0; e < ne; e++) v[0][2 * e] = value;
    return RCB_OK;
  }
  if ((st = lookup(m, name, &r))) return st;
  key = &kinds[r.k].keys[r.j];
  st = rcb_model_check_value(m, kinds[r.k].name, item_name(m, r.k, r.i), key->what, value,
                             key->sign);
  if (st) return st;
  n = slots(m, r.k, r.i, r.j, v);
  for (s = 0; s < n; s++) *v[s] = (cross_pair(r.k, r.j) && s == 1) ? -value : value;
  return RCB_OK;
}
