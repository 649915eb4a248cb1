/*
 * INI model loader, second pass: turn the stored sections into builder calls.
 * Items are built in dependency order (materials, shafts, then everything
 * placed on shafts), whatever their order in the file, and every builder or
 * finalize message is prefixed with the file and the line of the section
 * header of the item concerned.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "model/ini_load.h"
#include "model/model_util.h"

#define TRY(x)              \
  do {                      \
    rcb_status st_ = (x);   \
    if (st_) return st_;    \
  } while (0)

/* Re-raise the builder's message with the file and the section's line. */
static rcb_status builder_fail(ini_ctx *c, const ini_section *s, int line, rcb_status st) {
  char msg[RCB_ERRMSG_MAX];
  snprintf(msg, sizeof msg, "%s", rcb_model_errmsg(c->m));
  return rcb_ini_error(c, st, line, s, NULL, "%s", msg);
}

/* ---- one builder per section type ---- */

static rcb_status build_material(ini_ctx *c, const ini_section *s) {
  double rho, E, nu;
  rcb_status st;
  TRY(rcb_ini_get_num(c, s, "density", "density in kg/m^3, e.g. 7850", 1, 0, &rho));
  TRY(rcb_ini_get_num(c, s, "young", "Young's modulus in Pa, e.g. 2.1e11", 1, 0, &E));
  TRY(rcb_ini_get_num(c, s, "poisson", "Poisson's ratio (-), 0 <= nu < 0.5, e.g. 0.3", 1, 0, &nu));
  st = rcb_model_add_material(c->m, s->name, rho, E, nu);
  return st ? builder_fail(c, s, s->line, st) : RCB_OK;
}

static rcb_status segment(ini_ctx *c, ini_section *s, const ini_entry *e) {
  static const char *const what[3] = {"segment length in m", "outer diameter in m",
                                      "inner diameter in m (0 = solid)"};
  double v[4];
  const char *p = e->val, *t;
  size_t n = rcb_ini_count_tok(e->val, e->val + e->len), len;
  int k;
  rcb_status st;
  if (n != 4)
    return rcb_ini_error(c, RCB_ERR_PARSE, e->line, s, e->key,
                         "%zu fields in '%s'; expected 4: length (m), outer diameter (m), "
                         "inner diameter (m), number of elements",
                         n, e->val);
  for (k = 0; k < 4; k++) {
    t = rcb_ini_next_tok(&p, e->val + e->len, &len);
    TRY(rcb_ini_parse_num(c, s, e, t, len, k < 3 ? what[k] : "a whole number of elements >= 1",
                          &v[k]));
  }
  if (v[3] != floor(v[3]) || v[3] < 1 || v[3] > 100000)
    return rcb_ini_error(c, RCB_ERR_PARSE, e->line, s, e->key,
                         "%g elements; expected a whole number of elements from 1 to 100000",
                         v[3]);
  st = rcb_model_add_segment(c->m, s->name, v[0], v[1], v[2], (int)v[3]);
  if (st) return builder_fail(c, s, e->line, st);
  s->z1 += v[0];
  return RCB_OK;
}

/* element_stiffness | element_mass = k factor [k factor ...]: factors of
 * single elements (k from 1 in z order over the shaft's segments; the
 * parameters shaft.S.e<k>.stiffness | mass, model/element_params.c). */
static rcb_status element_factors(ini_ctx *c, ini_section *s, const ini_entry *e) {
  const char *p = e->val, *t, *key = strcmp(e->key, "element_mass") == 0 ? "mass" : "stiffness";
  char name[256];
  size_t n = rcb_ini_count_tok(e->val, e->val + e->len), len, i;
  double k, f;
  rcb_status st;
  if (n == 0 || n % 2)
    return rcb_ini_error(c, RCB_ERR_PARSE, e->line, s, e->key,
                         "%zu fields in '%s'; expected pairs: element number (from 1 along "
                         "the shaft) and factor, e.g. %s = 7 0.6",
                         n, e->val, e->key);
  for (i = 0; i < n; i += 2) {
    t = rcb_ini_next_tok(&p, e->val + e->len, &len);
    TRY(rcb_ini_parse_num(c, s, e, t, len, "an element number from 1 along the shaft", &k));
    t = rcb_ini_next_tok(&p, e->val + e->len, &len);
    TRY(rcb_ini_parse_num(c, s, e, t, len, "a factor > 0 (1: as the material states)", &f));
    if (k != floor(k) || k < 1 || k > 1e9)
      return rcb_ini_error(c, RCB_ERR_PARSE, e->line, s, e->key,
                           "element %g; expected a whole element number from 1 along the "
                           "shaft ('rcbtool check' lists them)",
                           k);
    snprintf(name, sizeof name, "shaft.%s.e%.0f.%s", s->name, k, key);
    if ((st = rcb_model_set_param(c->m, name, f))) return builder_fail(c, s, e->line, st);
  }
  return RCB_OK;
}

static rcb_status build_shaft(ini_ctx *c, ini_section *s) {
  char mat[RCB_NAME_MAX], hint[200];
  double z0, kappa, qm, qk, sf[2];
  static const char *const sf_keys[2] = {"stiffness_factor", "mass_factor"};
  static const char *const sf_params[2] = {"stiffness", "mass"};
  char pname[256];
  size_t i, nseg = 0;
  rcb_status st;
  TRY(rcb_ini_get_word(c, s, "material", "the name of a [material NAME] section", mat, sizeof mat));
  if (!rcb_ini_find_sec(c, INI_SEC_MATERIAL, mat)) {
    rcb_ini_name_hint(c, INI_TYPE_BIT(INI_SEC_MATERIAL), NULL, mat, hint, sizeof hint);
    return rcb_ini_error(c, RCB_ERR_NOT_FOUND, rcb_ini_get(s, "material")->line, s, "material",
                         "material '%s' is not defined (%s); expected the name of a "
                         "[material NAME] section",
                         mat, hint);
  }
  TRY(rcb_ini_get_num(c, s, "start", "axial position of the first node in m", 0, 0.0, &z0));
  TRY(rcb_ini_get_num(c, s, "shear_factor",
              "Timoshenko shear factor (-), e.g. 0.9 for a solid circular section, 0 for no "
              "shear",
              1, 0, &kappa));
  TRY(rcb_ini_get_num(c, s, "damping_mass", "mass-proportional damping qz_m in 1/s", 0, 0.0, &qm));
  TRY(rcb_ini_get_num(c, s, "damping_stiffness", "stiffness-proportional damping qz_k in s", 0, 0.0,
              &qk));
  TRY(rcb_ini_get_num(c, s, "stiffness_factor",
              "a factor > 0 on E and G of the whole shaft (1: as the material states)", 0, 1.0,
              &sf[0]));
  TRY(rcb_ini_get_num(c, s, "mass_factor",
              "a factor > 0 on the density of the whole shaft (1: as the material states)", 0,
              1.0, &sf[1]));
  for (i = 0; i < s->n_ent; i++) nseg += strcmp(s->ent[i].key, "segment") == 0;
  if (nseg == 0)
    return rcb_ini_missing(c, s, "segment",
                   "length (m) outer_diameter (m) inner_diameter (m) elements, e.g. "
                   "segment = 0.50 0.017 0 10");
  if ((st = rcb_model_add_shaft(c->m, s->name, mat, z0, kappa)) ||
      (st = rcb_model_set_shaft_damping(c->m, s->name, qm, qk)))
    return builder_fail(c, s, s->line, st);
  for (i = 0; i < 2; i++) { /* shaft.S.stiffness | mass: checked > 0 by the parameter table */
    const ini_entry *e = rcb_ini_get(s, sf_keys[i]);
    snprintf(pname, sizeof pname, "shaft.%s.%s", s->name, sf_params[i]);
    if ((st = rcb_model_set_param(c->m, pname, sf[i])))
      return builder_fail(c, s, e ? e->line : s->line, st);
  }
  s->z0 = s->z1 = z0;
  for (i = 0; i < s->n_ent; i++)
    if (strcmp(s->ent[i].key, "segment") == 0) TRY(segment(c, s, &s->ent[i]));
  for (i = 0; i < s->n_ent; i++) /* after every segment: they number the elements */
    if (strcmp(s->ent[i].key, "element_stiffness") == 0 ||
        strcmp(s->ent[i].key, "element_mass") == 0)
      TRY(element_factors(c, s, &s->ent[i]));
  s->built = 1;
  return RCB_OK;
}

/* First key of the list present in s, or NULL. */
static const ini_entry *first_of(const ini_section *s, const char *const *keys, size_t n) {
  size_t i;
  const ini_entry *best = NULL;
  for (i = 0; i < n; i++) {
    const ini_entry *e = rcb_ini_get(s, keys[i]);
    if (e && (!best || e->line < best->line)) best = e;
  }
  return best;
}

/* Explicit inertia (3 keys) or geometry (4 keys), never both. */
static rcb_status inertia_kind(ini_ctx *c, const ini_section *s, const char *const *mk,
                               const char *const *gk, const char *what, int *geometry) {
  const ini_entry *em = first_of(s, mk, 3), *eg = first_of(s, gk, 4);
  if (em && eg) {
    const ini_entry *later = em->line > eg->line ? em : eg;
    return rcb_ini_error(c, RCB_ERR_PARSE, later->line, s, later->key,
                         "both explicit inertia (%s, %s, %s) and geometry (%s, %s, %s, %s) "
                         "are given; expected one or the other",
                         mk[0], mk[1], mk[2], gk[0], gk[1], gk[2], gk[3]);
  }
  if (!em && !eg)
    return rcb_ini_error(c, RCB_ERR_PARSE, s->line, s, NULL,
                         "missing %s inertia; expected either %s, %s, %s (kg, kg m^2, kg m^2) "
                         "or %s (kg/m^3), %s, %s, %s (m)",
                         what, mk[0], mk[1], mk[2], gk[0], gk[1], gk[2], gk[3]);
  *geometry = eg != NULL;
  return RCB_OK;
}

static rcb_status build_disk(ini_ctx *c, const ini_section *s) {
  static const char *const mk[3] = {"mass", "Id", "Ip"};
  static const char *const gk[4] = {"density", "outer_diameter", "inner_diameter", "width"};
  const char *shaft;
  double z, m, Id, Ip;
  int geo;
  rcb_status st;
  TRY(rcb_ini_get_at(c, s, &shaft, &z));
  TRY(inertia_kind(c, s, mk, gk, "the disk's", &geo));
  if (geo) {
    double rho, od, id, w;
    TRY(rcb_ini_get_num(c, s, "density", "density in kg/m^3", 1, 0, &rho));
    TRY(rcb_ini_get_num(c, s, "outer_diameter", "outer diameter in m", 1, 0, &od));
    TRY(rcb_ini_get_num(c, s, "inner_diameter", "bore diameter in m (0 = solid)", 0, 0.0, &id));
    TRY(rcb_ini_get_num(c, s, "width", "axial width in m", 1, 0, &w));
    if (rcb_disk_from_geometry(rho, od, id, w, &m, &Id, &Ip))
      return rcb_ini_error(c, RCB_ERR_PARSE, s->line, s, NULL,
                           "invalid geometry (density %g, outer_diameter %g, inner_diameter "
                           "%g, width %g); expected density > 0, outer_diameter > "
                           "inner_diameter >= 0, width > 0",
                           rho, od, id, w);
  } else {
    TRY(rcb_ini_get_num(c, s, "mass", "mass in kg", 1, 0, &m));
    TRY(rcb_ini_get_num(c, s, "Id", "diametral moment of inertia in kg m^2", 1, 0, &Id));
    TRY(rcb_ini_get_num(c, s, "Ip", "polar moment of inertia in kg m^2", 1, 0, &Ip));
  }
  st = rcb_model_add_disk(c->m, s->name, shaft, z, m, Id, Ip);
  return st ? builder_fail(c, s, s->line, st) : RCB_OK;
}

static const char *const coef_keys[8] = {"kxx", "kxy", "kyx", "kyy",
                                         "cxx", "cxy", "cyx", "cyy"};

/* Fill column k of the coefficient table rows (one value = constant). */
static rcb_status bearing_coef(ini_ctx *c, const ini_section *s, int k, const char *speed_key,
                               size_t nspeed, rcb_bearing_coefs *rows, size_t nrows) {
  const ini_entry *e = rcb_ini_get(s, coef_keys[k]);
  double *v;
  size_t n, i;
  if (!e) return RCB_OK; /* rows are zeroed */
  TRY(rcb_ini_get_list(c, s, e, k < 4 ? "stiffness in N/m" : "damping in N s/m", &v, &n));
  if (n > 1 && nspeed == 0) {
    rcb_free(&c->m->alloc, v);
    return rcb_ini_error(c, RCB_ERR_PARSE, e->line, s, e->key,
                         "%zu values but the bearing has no speed table; expected one value, "
                         "or speed_rpm = ... (or speed = ... in rad/s) with one speed per value",
                         n);
  }
  if (n != 1 && n != nspeed) {
    rcb_free(&c->m->alloc, v);
    return rcb_ini_error(c, RCB_ERR_PARSE, e->line, s, e->key,
                         "%zu values but %s lists %zu speeds; expected 1 value (constant) or "
                         "%zu (one per speed)",
                         n, speed_key, nspeed, nspeed);
  }
  for (i = 0; i < nrows; i++) (&rows[i].kxx)[k] = v[n == 1 ? 0 : i];
  rcb_free(&c->m->alloc, v);
  return RCB_OK;
}

/* The bearing's pedestal keys (all absent or 0: no pedestal). */
static rcb_status build_pedestal(ini_ctx *c, const ini_section *s) {
  rcb_pedestal p;
  rcb_status st;
  TRY(rcb_ini_get_num(c, s, "pedestal_mass", "pedestal mass in kg", 0, 0.0, &p.mass));
  TRY(rcb_ini_get_num(c, s, "pedestal_kxx", "pedestal stiffness in N/m", 0, 0.0, &p.kxx));
  TRY(rcb_ini_get_num(c, s, "pedestal_kyy", "pedestal stiffness in N/m", 0, 0.0, &p.kyy));
  TRY(rcb_ini_get_num(c, s, "pedestal_cxx", "pedestal damping in N s/m", 0, 0.0, &p.cxx));
  TRY(rcb_ini_get_num(c, s, "pedestal_cyy", "pedestal damping in N s/m", 0, 0.0, &p.cyy));
  st = rcb_model_set_pedestal(c->m, s->name, &p);
  /* out of memory stays what it is: the caller must not read it as bad input */
  if (st) return builder_fail(c, s, s->line, st == RCB_ERR_NOMEM ? st : RCB_ERR_ARG);
  return RCB_OK;
}

/* [model] speed_factor: real rotor speed / stated speed (default 1). */
static rcb_status build_model_section(ini_ctx *c, const ini_section *s) {
  double f;
  TRY(rcb_ini_get_num(c, s, "speed_factor", "a speed factor > 0 (real / stated speed)", 0, 1.0,
                      &f));
  if (rcb_model_set_param(c->m, "speed.factor", f))
    return builder_fail(c, s, s->line, RCB_ERR_ARG);
  return RCB_OK;
}

static rcb_status build_bearing(ini_ctx *c, const ini_section *s) {
  const ini_entry *rpm = rcb_ini_get(s, "speed_rpm"), *rad = rcb_ini_get(s, "speed");
  const char *shaft, *speed_key = rpm ? "speed_rpm" : "speed";
  double z, *speeds = NULL;
  size_t ns = 0, nrows, i;
  int k;
  rcb_bearing_coefs *rows;
  rcb_status st = RCB_OK;
  TRY(rcb_ini_get_at(c, s, &shaft, &z));
  if (rpm && rad) {
    const ini_entry *later = rpm->line > rad->line ? rpm : rad;
    return rcb_ini_error(c, RCB_ERR_PARSE, later->line, s, later->key,
                         "both speed_rpm and speed are given; expected one speed table "
                         "(speed_rpm in rpm or speed in rad/s)");
  }
  if (rpm || rad) {
    TRY(rcb_ini_get_list(c, s, rpm ? rpm : rad,
                 rpm ? "rotor speeds in rpm, increasing" : "rotor speeds in rad/s, increasing",
                 &speeds, &ns));
    if (rpm)
      for (i = 0; i < ns; i++) speeds[i] *= RCB_PI / 30.0; /* rpm -> rad/s */
  }
  nrows = ns ? ns : 1;
  rows = rcb_alloc(&c->m->alloc, nrows * sizeof *rows);
  if (!rows) {
    rcb_free(&c->m->alloc, speeds);
    return rcb_ini_error(c, RCB_ERR_NOMEM, s->line, s, NULL, "out of memory");
  }
  for (k = 0; k < 8 && !st; k++) st = bearing_coef(c, s, k, speed_key, ns, rows, nrows);
  if (!st) {
    st = rcb_model_add_bearing_table(c->m, s->name, shaft, z, nrows, speeds, rows);
    if (st) builder_fail(c, s, s->line, st);
  }
  if (!st) st = build_pedestal(c, s);
  rcb_free(&c->m->alloc, rows);
  rcb_free(&c->m->alloc, speeds);
  return st;
}

/* Which of kt, kr, ct, cr each model uses, and the names: the coupling
 * table (model/coupling_models.c). */
static rcb_status coupling_params(ini_ctx *c, const ini_section *s, rcb_coupling_model type,
                                  rcb_coupling_params *p) {
  static const char *const pe[4] = {
      "translational stiffness in N/m", "rotational stiffness in N m/rad",
      "translational damping in N s/m", "rotational damping in N m s/rad"};
  const char *pk[4];
  char uses[64];
  const char *used[4];
  size_t nu = 0, k;
  unsigned mask = rcb_coupling_uses(type);
  for (k = 0; k < 4; k++) pk[k] = rcb_coupling_coef_key((int)k);
  for (k = 0; k < 4; k++)
    if (mask & (1u << k)) used[nu++] = pk[k];
  uses[0] = '\0';
  for (k = 0; k < nu; k++)
    snprintf(uses + strlen(uses), sizeof uses - strlen(uses), "%s%s", k ? ", " : "", used[k]);
  for (k = 0; k < 4; k++) {
    const ini_entry *e = rcb_ini_get(s, pk[k]);
    if (e && !(mask & (1u << k)))
      return rcb_ini_error(c, RCB_ERR_PARSE, e->line, s, e->key,
                           "not used by model %s; expected %s%s (remove %s or change the "
                           "model)",
                           rcb_coupling_model_name(type),
                           nu ? "only " : "no stiffness or damping keys",
                           uses, pk[k]);
    if (!e && (mask & (1u << k)))
      return rcb_ini_error(c, RCB_ERR_PARSE, s->line, s, NULL,
                           "missing key '%s'; expected %s = %s (model %s needs %s)", pk[k],
                           pk[k], pe[k], rcb_coupling_model_name(type), uses);
    if (e) TRY(rcb_ini_get_num(c, s, pk[k], pe[k], 1, 0, rcb_coupling_coef(p, (int)k)));
  }
  return RCB_OK;
}

static rcb_status coupling_hubs(ini_ctx *c, const ini_section *s, rcb_coupling_params *p) {
  static const char *const mk[3] = {"hub_mass", "hub_Id", "hub_Ip"};
  static const char *const gk[4] = {"hub_density", "hub_inner_radius", "hub_outer_radius",
                                    "hub_thickness"};
  const ini_entry *em = first_of(s, mk, 3), *eg = first_of(s, gk, 4);
  int geo, k;
  if (!em && !eg) return RCB_OK; /* massless coupling */
  TRY(inertia_kind(c, s, mk, gk, "hub", &geo));
  if (geo) {
    double rho, ri, ro, t;
    TRY(rcb_ini_get_num(c, s, "hub_density", "equivalent density in kg/m^3", 1, 0, &rho));
    TRY(rcb_ini_get_num(c, s, "hub_inner_radius", "inner radius in m", 1, 0, &ri));
    TRY(rcb_ini_get_num(c, s, "hub_outer_radius", "outer radius in m", 1, 0, &ro));
    TRY(rcb_ini_get_num(c, s, "hub_thickness", "equivalent thickness of the whole coupling in m",
                        1, 0, &t));
    if (rcb_coupling_hubs_from_geometry(rho, ri, ro, t, p))
      return rcb_ini_error(c, RCB_ERR_PARSE, s->line, s, NULL,
                           "invalid hub geometry (density %g, inner radius %g, outer radius "
                           "%g, thickness %g); expected density > 0, outer radius > inner "
                           "radius >= 0, thickness > 0",
                           rho, ri, ro, t);
    return RCB_OK;
  }
  TRY(rcb_ini_get_num(c, s, "hub_mass", "hub mass at each station in kg", 1, 0, &p->mass[0]));
  TRY(rcb_ini_get_num(c, s, "hub_Id", "hub diametral inertia at each station in kg m^2", 1, 0,
              &p->Id[0]));
  TRY(rcb_ini_get_num(c, s, "hub_Ip", "hub polar inertia at each station in kg m^2", 1, 0,
                      &p->Ip[0]));
  for (k = 1; k < 2; k++) {
    p->mass[k] = p->mass[0];
    p->Id[k] = p->Id[0];
    p->Ip[k] = p->Ip[0];
  }
  return RCB_OK;
}

static rcb_status build_coupling(ini_ctx *c, const ini_section *s) {
  char name[64], all[120];
  const char *sh[2];
  double z[2];
  rcb_coupling_model type;
  rcb_coupling_params p;
  rcb_status st;
  const char *model_names[RCB_COUPLING_MODEL_COUNT];
  int k;
  memset(&p, 0, sizeof p);
  for (k = 0; k < RCB_COUPLING_MODEL_COUNT; k++)
    model_names[k] = rcb_coupling_model_name((rcb_coupling_model)k);
  all[0] = '\0';
  for (k = 0; k < RCB_COUPLING_MODEL_COUNT; k++)
    snprintf(all + strlen(all), sizeof all - strlen(all), "%s%s",
             k == 0 ? "" : k + 1 < RCB_COUPLING_MODEL_COUNT ? ", " : " or ", model_names[k]);
  TRY(rcb_ini_get_word(c, s, "model", all, name, sizeof name));
  if (rcb_coupling_model_parse(name, &type)) {
    const char *near = rcb_ini_closest(name, model_names, RCB_COUPLING_MODEL_COUNT);
    return rcb_ini_error(c, RCB_ERR_PARSE, rcb_ini_get(s, "model")->line, s, "model",
                         "unknown coupling model '%s'%s%s%s; expected %s", name,
                         near ? " (did you mean " : "", near ? near : "", near ? "?)" : "",
                         all);
  }
  TRY(rcb_ini_between(c, s, sh, z, 0));
  TRY(coupling_params(c, s, type, &p));
  TRY(coupling_hubs(c, s, &p));
  st = rcb_model_add_coupling(c->m, s->name, type, sh[0], z[0], sh[1], z[1], &p);
  return st ? builder_fail(c, s, s->line, st) : RCB_OK;
}

static rcb_status build_unbalance(ini_ctx *c, const ini_section *s) {
  const char *shaft;
  double z, amount, deg;
  rcb_status st;
  TRY(rcb_ini_get_at(c, s, &shaft, &z));
  TRY(rcb_ini_get_num(c, s, "amount", "unbalance m e in kg m", 1, 0, &amount));
  TRY(rcb_ini_get_num(c, s, "phase_deg", "angle in degrees from +x towards +y", 0, 0.0, &deg));
  st = rcb_model_add_unbalance(c->m, s->name, shaft, z, amount, deg * RCB_PI / 180.0);
  return st ? builder_fail(c, s, s->line, st) : RCB_OK;
}

static rcb_status build_station(ini_ctx *c, const ini_section *s) {
  const char *shaft;
  double z;
  rcb_status st;
  TRY(rcb_ini_get_at(c, s, &shaft, &z));
  st = rcb_model_add_station(c->m, s->name, shaft, z);
  return st ? builder_fail(c, s, s->line, st) : RCB_OK;
}

/* A finalize message starts "KIND 'NAME'": find that item's section. */
static const ini_section *section_of_message(const ini_ctx *c, const char *msg) {
  char kind[32], name[2 * RCB_NAME_MAX];
  size_t i;
  if (sscanf(msg, "%31s '%95[^']'", kind, name) != 2) return NULL;
  for (i = 0; i < c->n_sec; i++)
    if (strcmp(rcb_ini_type_name(c->sec[i].type), kind) == 0 &&
        strcmp(c->sec[i].name, name) == 0)
      return &c->sec[i];
  return NULL;
}

/* Finalize warnings start "KIND 'NAME'" like its errors: prefix each with the
 * file and the line of that item's section header. */
static void prefix_warnings(ini_ctx *c) {
  size_t i;
  rcb_model *m = c->m;
  for (i = 0; i < m->n_warnings; i++) {
    char buf[RCB_WARNING_MAX];
    const ini_section *s = section_of_message(c, m->warnings[i].text);
    int k = s ? snprintf(buf, sizeof buf, "%s:%d: %s", c->src, s->line, m->warnings[i].text)
              : snprintf(buf, sizeof buf, "%s: %s", c->src, m->warnings[i].text);
    if (k < 0) continue;
    memcpy(m->warnings[i].text, buf, sizeof buf);
  }
}

/* [uff] map = NODE STATION, NODE STATION, ... */
static rcb_status build_uff(ini_ctx *c, const ini_section *s) {
  const ini_entry *e = rcb_ini_get(s, "map");
  const char *p, *q;
  rcb_status st;
  if (!e) return RCB_OK;
  for (p = e->val; p && *p;) {
    char item[2 * RCB_NAME_MAX + 40], station[2 * RCB_NAME_MAX + 2], extra[8];
    long node;
    char *end;
    size_t len;
    q = strchr(p, ',');
    len = q ? (size_t)(q - p) : strlen(p);
    if (len >= sizeof item) len = sizeof item - 1;
    memcpy(item, p, len);
    item[len] = '\0';
    /* strtol, not sscanf's %ld: an out-of-range node is an error (cert-err34-c) */
    errno = 0;
    node = strtol(item, &end, 10);
    if (end == item || errno == ERANGE || sscanf(end, "%97s %7s", station, extra) != 1)
      return rcb_ini_error(c, RCB_ERR_PARSE, e->line, s, "map",
                           "'%s': expected NODE STATION pairs separated by commas, e.g. "
                           "map = 10 DA, 20 C.B",
                           item);
    if ((st = rcb_model_add_uff_node(c->m, node, station)))
      return rcb_ini_error(c, st == RCB_ERR_NOMEM ? st : RCB_ERR_PARSE, e->line, s, "map",
                           "%s", rcb_model_errmsg(c->m));
    p = q ? q + 1 : NULL;
  }
  return RCB_OK;
}

/* [test] rpm = rotor speed of the measurements this model is compared with. */
static rcb_status build_test(ini_ctx *c, const ini_section *s) {
  double rpm;
  if (!rcb_ini_get(s, "rpm")) return RCB_OK;
  TRY(rcb_ini_get_num(c, s, "rpm", "the test's rotor speed >= 0, rpm", 1, 0.0, &rpm));
  if (rcb_model_set_test_speed(c->m, rpm * RCB_PI / 30.0)) {
    const ini_entry *e = rcb_ini_get(s, "rpm");
    return rcb_ini_error(c, RCB_ERR_PARSE, e->line, s, "rpm", "%g: expected a rotor speed >= 0 "
                         "(rpm)", rpm);
  }
  return RCB_OK;
}

rcb_status rcb_ini_build(ini_ctx *c) {
  /* dependency order: what is placed on a shaft comes after the shafts */
  static const ini_sec_type order[] = {INI_SEC_MODEL,     INI_SEC_MATERIAL, INI_SEC_SHAFT,
                                       INI_SEC_DISK,
                                       INI_SEC_BEARING,   INI_SEC_COUPLING, INI_SEC_UNBALANCE,
                                       INI_SEC_STATION,   INI_SEC_UFF,      INI_SEC_TEST};
  size_t k, i;
  rcb_status st = RCB_OK;
  for (k = 0; k < sizeof order / sizeof order[0] && !st; k++)
    for (i = 0; i < c->n_sec && !st; i++) {
      ini_section *s = &c->sec[i];
      if (s->type != order[k]) continue;
      switch (s->type) {
        case INI_SEC_MODEL: st = build_model_section(c, s); break;
        case INI_SEC_MATERIAL: st = build_material(c, s); break;
        case INI_SEC_SHAFT: st = build_shaft(c, s); break;
        case INI_SEC_DISK: st = build_disk(c, s); break;
        case INI_SEC_BEARING: st = build_bearing(c, s); break;
        case INI_SEC_COUPLING: st = build_coupling(c, s); break;
        case INI_SEC_UNBALANCE: st = build_unbalance(c, s); break;
        case INI_SEC_STATION: st = build_station(c, s); break;
        case INI_SEC_UFF: st = build_uff(c, s); break;
        case INI_SEC_TEST: st = build_test(c, s); break;
        default: break;
      }
    }
  if (st) return st;
  st = rcb_model_finalize(c->m);
  if (st) {
    const ini_section *s = section_of_message(c, rcb_model_errmsg(c->m));
    return builder_fail(c, s, s ? s->line : 0, st);
  }
  prefix_warnings(c);
  return RCB_OK;
}
