/*
 * Model building, element by element. Every call checks its arguments at
 * once and leaves a message naming the item, the value and what is expected.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "core/rcb_internal.h"
#include "model/model_util.h"

rcb_status rcb_model_create(rcb_model **out, const rcb_allocator *alloc) {
  rcb_allocator a;
  rcb_model *m;
  if (!out) return RCB_ERR_ARG;
  *out = NULL;
  rcb_allocator_init(&a, alloc);
  m = rcb_alloc(&a, sizeof *m);
  if (!m) return RCB_ERR_NOMEM;
  m->alloc = a;
  m->speed_factor = 1.0;
  *out = m;
  return RCB_OK;
}

void rcb_model_destroy(rcb_model *m) {
  size_t i;
  rcb_allocator a;
  if (!m) return;
  a = m->alloc;
  for (i = 0; i < m->n_shafts; i++) {
    rcb_free(&a, m->shafts[i].seg);
    rcb_free(&a, m->shafts[i].ef);
  }
  for (i = 0; i < m->n_bearings; i++) {
    rcb_free(&a, m->bearings[i].speeds);
    rcb_free(&a, m->bearings[i].c);
  }
  rcb_free(&a, m->materials);
  rcb_free(&a, m->shafts);
  rcb_free(&a, m->disks);
  rcb_free(&a, m->bearings);
  rcb_free(&a, m->couplings);
  rcb_free(&a, m->unbalances);
  rcb_free(&a, m->probes);
  rcb_free(&a, m->uffmap);
  rcb_free(&a, m->stations);
  rcb_free(&a, m->nodes);
  rcb_free(&a, m->elements);
  rcb_free(&a, m->warnings);
  rcb_free(&a, m);
}

const char *rcb_model_errmsg(const rcb_model *m) { return m ? m->errmsg : "no model"; }

/* ---- small helpers shared by the builder ---- */

rcb_status rcb_model_check_editable(rcb_model *m, const char *what) {
  if (!m) return RCB_ERR_ARG;
  if (m->finalized)
    return rcb_model_fail(m, RCB_ERR_STATE,
                          "%s: the model is already finalized; add items before "
                          "rcb_model_finalize",
                          what);
  return RCB_OK;
}

static rcb_status check_name(rcb_model *m, const char *kind, const char *name) {
  if (!name || !name[0])
    return rcb_model_fail(m, RCB_ERR_ARG, "%s: a name is required", kind);
  if (strlen(name) >= RCB_NAME_MAX)
    return rcb_model_fail(m, RCB_ERR_ARG, "%s '%s': name longer than %d characters", kind,
                          name, RCB_NAME_MAX - 1);
  if (strchr(name, '.') || strchr(name, '#') || strchr(name, ' '))
    return rcb_model_fail(m, RCB_ERR_ARG,
                          "%s '%s': names may not contain '.', '#' or spaces", kind, name);
  return RCB_OK;
}

/* A station name must be unique among disks, bearings, couplings,
 * unbalances and probes, since channels are addressed by it. */
static rcb_status check_station_name(rcb_model *m, const char *kind, const char *name) {
  size_t i;
  rcb_status st = check_name(m, kind, name);
  if (st) return st;
#define RCB_DUP_CHECK_(arr, what)                                                     \
  for (i = 0; i < m->n_##arr; i++)                                                      \
    if (strcmp(m->arr[i].name, name) == 0)                                              \
      return rcb_model_fail(m, RCB_ERR_MODEL, "%s '%s': the name is already used by " \
                                              what "; station names must be unique",   \
                            kind, name);
  RCB_DUP_CHECK_(disks, "a disk")
  RCB_DUP_CHECK_(bearings, "a bearing")
  RCB_DUP_CHECK_(couplings, "a coupling")
  RCB_DUP_CHECK_(unbalances, "an unbalance")
  RCB_DUP_CHECK_(probes, "a station")
#undef RCB_DUP_CHECK_
  return RCB_OK;
}

rcb_status rcb_model_check_value(rcb_model *m, const char *kind, const char *name,
                                 const char *what, double v, int sign) {
  if (!isfinite(v))
    return rcb_model_fail(m, RCB_ERR_ARG, "%s '%s': %s is not a finite number", kind, name,
                          what);
  if (sign > 0 && !(v > 0))
    return rcb_model_fail(m, RCB_ERR_ARG, "%s '%s': %s = %g, expected a positive value",
                          kind, name, what, v);
  if (sign == 0 && v < 0)
    return rcb_model_fail(m, RCB_ERR_ARG,
                          "%s '%s': %s = %g, expected a value >= 0", kind, name, what, v);
  return RCB_OK;
}
#define CHECK_VALUE(kind, name, what, v, sign)                            \
  do {                                                                    \
    rcb_status st_ = rcb_model_check_value(m, kind, name, what, v, sign); \
    if (st_) return st_;                                                  \
  } while (0)

static long find_shaft(const rcb_model *m, const char *name) {
  size_t i;
  if (!name) return -1;
  for (i = 0; i < m->n_shafts; i++)
    if (strcmp(m->shafts[i].name, name) == 0) return (long)i;
  return -1;
}

static rcb_status place_on(rcb_model *m, const char *kind, const char *name,
                           const char *shaft, double z, rcb_place_t *at) {
  long s = find_shaft(m, shaft);
  if (s < 0)
    return rcb_model_fail(m, RCB_ERR_NOT_FOUND,
                          "%s '%s': shaft '%s' is not defined (define the shaft first)", kind,
                          name, shaft ? shaft : "(null)");
  if (!isfinite(z))
    return rcb_model_fail(m, RCB_ERR_ARG, "%s '%s': position z is not a finite number", kind,
                          name);
  at->shaft = (size_t)s;
  at->z = z;
  at->node = 0;
  return RCB_OK;
}

#define GROW(arr)                                                                       \
  do {                                                                                  \
    if (rcb_grow(&m->alloc, (void **)&m->arr, &m->cap_##arr, m->n_##arr + 1,           \
                 sizeof *m->arr))                                                       \
      return rcb_model_fail(m, RCB_ERR_NOMEM, "out of memory adding to " #arr);         \
    memset(&m->arr[m->n_##arr], 0, sizeof *m->arr);                                     \
  } while (0)

/* ---- public builder ---- */

rcb_status rcb_model_add_material(rcb_model *m, const char *name, double density, double young,
                                  double poisson) {
  size_t i;
  rcb_material_t *mat;
  rcb_status st = rcb_model_check_editable(m, "material");
  if (st || (st = check_name(m, "material", name))) return st;
  for (i = 0; i < m->n_materials; i++)
    if (strcmp(m->materials[i].name, name) == 0)
      return rcb_model_fail(m, RCB_ERR_MODEL, "material '%s' is defined twice", name);
  CHECK_VALUE("material", name, "density (kg/m^3)", density, 1);
  CHECK_VALUE("material", name, "young (Pa)", young, 1);
  CHECK_VALUE("material", name, "poisson", poisson, 0);
  if (poisson >= 0.5)
    return rcb_model_fail(m, RCB_ERR_ARG,
                          "material '%s': poisson = %g, expected 0 <= poisson < 0.5", name,
                          poisson);
  GROW(materials);
  mat = &m->materials[m->n_materials++];
  snprintf(mat->name, sizeof mat->name, "%s", name);
  mat->rho = density;
  mat->E = young;
  mat->nu = poisson;
  return RCB_OK;
}

rcb_status rcb_model_add_shaft(rcb_model *m, const char *name, const char *material,
                               double z_start, double shear_factor) {
  size_t i;
  long mat = -1;
  rcb_shaft_t *s;
  rcb_status st = rcb_model_check_editable(m, "shaft");
  if (st || (st = check_name(m, "shaft", name))) return st;
  if (find_shaft(m, name) >= 0)
    return rcb_model_fail(m, RCB_ERR_MODEL, "shaft '%s' is defined twice", name);
  for (i = 0; material && i < m->n_materials; i++)
    if (strcmp(m->materials[i].name, material) == 0) mat = (long)i;
  if (mat < 0)
    return rcb_model_fail(m, RCB_ERR_NOT_FOUND,
                          "shaft '%s': material '%s' is not defined (define it first)", name,
                          material ? material : "(null)");
  CHECK_VALUE("shaft", name, "start (m)", z_start, -1);
  CHECK_VALUE("shaft", name, "shear_factor", shear_factor, 0);
  if (shear_factor > 1.5)
    return rcb_model_fail(m, RCB_ERR_ARG,
                          "shaft '%s': shear_factor = %g, expected 0 (no shear) to about 1",
                          name, shear_factor);
  GROW(shafts);
  s = &m->shafts[m->n_shafts++];
  snprintf(s->name, sizeof s->name, "%s", name);
  s->material = (size_t)mat;
  s->z0 = z_start;
  s->kappa = shear_factor;
  s->sf[0] = s->sf[1] = 1.0; /* the shaft-wide factors' neutral value */
  return RCB_OK;
}

rcb_status rcb_model_set_shaft_damping(rcb_model *m, const char *shaft, double qz_m,
                                       double qz_k) {
  long s;
  rcb_status st = rcb_model_check_editable(m, "shaft damping");
  if (st) return st;
  s = find_shaft(m, shaft);
  if (s < 0)
    return rcb_model_fail(m, RCB_ERR_NOT_FOUND, "shaft '%s' is not defined",
                          shaft ? shaft : "(null)");
  CHECK_VALUE("shaft", shaft, "damping_mass qz_m (1/s)", qz_m, 0);
  CHECK_VALUE("shaft", shaft, "damping_stiffness qz_k (s)", qz_k, 0);
  m->shafts[s].qz_m = qz_m;
  m->shafts[s].qz_k = qz_k;
  return RCB_OK;
}

rcb_status rcb_model_add_segment(rcb_model *m, const char *shaft, double length,
                                 double outer_d, double inner_d, int n_elements) {
  long s;
  size_t e;
  rcb_shaft_t *sh;
  rcb_status st = rcb_model_check_editable(m, "segment");
  if (st) return st;
  s = find_shaft(m, shaft);
  if (s < 0)
    return rcb_model_fail(m, RCB_ERR_NOT_FOUND, "segment: shaft '%s' is not defined",
                          shaft ? shaft : "(null)");
  CHECK_VALUE("shaft", shaft, "segment length (m)", length, 1);
  CHECK_VALUE("shaft", shaft, "segment outer diameter (m)", outer_d, 1);
  CHECK_VALUE("shaft", shaft, "segment inner diameter (m)", inner_d, 0);
  if (inner_d >= outer_d)
    return rcb_model_fail(m, RCB_ERR_ARG,
                          "shaft '%s': segment inner diameter %g m >= outer diameter %g m",
                          shaft, inner_d, outer_d);
  if (n_elements < 1 || n_elements > 100000)
    return rcb_model_fail(m, RCB_ERR_ARG,
                          "shaft '%s': segment with %d elements, expected 1 to 100000", shaft,
                          n_elements);
  sh = &m->shafts[s];
  if (rcb_grow(&m->alloc, (void **)&sh->seg, &sh->capseg, sh->nseg + 1, sizeof *sh->seg) ||
      rcb_grow(&m->alloc, (void **)&sh->ef, &sh->capef, 2 * (sh->nef + (size_t)n_elements),
               sizeof *sh->ef))
    return rcb_model_fail(m, RCB_ERR_NOMEM, "out of memory adding a segment");
  for (e = 2 * sh->nef; e < 2 * (sh->nef + (size_t)n_elements); e++)
    sh->ef[e] = 1.0; /* the element factors' neutral value */
  sh->nef += (size_t)n_elements;
  sh->seg[sh->nseg].L = length;
  sh->seg[sh->nseg].od = outer_d;
  sh->seg[sh->nseg].id = inner_d;
  sh->seg[sh->nseg].nel = n_elements;
  sh->nseg++;
  return RCB_OK;
}

rcb_status rcb_disk_from_geometry(double density, double outer_d, double inner_d, double width,
                                  double *mass, double *Id, double *Ip) {
  double mm;
  if (!mass || !Id || !Ip || !isfinite(density) || !isfinite(outer_d) || !isfinite(inner_d) ||
      !isfinite(width) || density <= 0 || outer_d <= 0 || inner_d < 0 || inner_d >= outer_d ||
      width <= 0)
    return RCB_ERR_ARG;
  /* Uniform annulus: m = rho pi/4 (D^2 - d^2) w, Ip = m (D^2 + d^2)/8,
   * Id = Ip/2 + m w^2/12 (about a diameter through the centre of mass). */
  mm = density * RCB_PI / 4.0 * (outer_d * outer_d - inner_d * inner_d) * width;
  *mass = mm;
  *Ip = mm * (outer_d * outer_d + inner_d * inner_d) / 8.0;
  *Id = *Ip / 2.0 + mm * width * width / 12.0;
  return RCB_OK;
}

rcb_status rcb_model_add_disk(rcb_model *m, const char *name, const char *shaft, double z,
                              double mass, double Id, double Ip) {
  rcb_disk_t *d;
  rcb_place_t at;
  rcb_status st = rcb_model_check_editable(m, "disk");
  if (st || (st = check_station_name(m, "disk", name))) return st;
  if ((st = place_on(m, "disk", name, shaft, z, &at))) return st;
  CHECK_VALUE("disk", name, "mass (kg)", mass, 0);
  CHECK_VALUE("disk", name, "Id (kg m^2)", Id, 0);
  CHECK_VALUE("disk", name, "Ip (kg m^2)", Ip, 0);
  GROW(disks);
  d = &m->disks[m->n_disks++];
  snprintf(d->name, sizeof d->name, "%s", name);
  d->at = at;
  d->m = mass;
  d->Id = Id;
  d->Ip = Ip;
  return RCB_OK;
}

static rcb_status check_coefs(rcb_model *m, const char *name, const rcb_bearing_coefs *c) {
  const double *v = &c->kxx;
  int i;
  for (i = 0; i < 8; i++)
    if (!isfinite(v[i]))
      return rcb_model_fail(m, RCB_ERR_ARG, "bearing '%s': coefficient is not finite", name);
  return RCB_OK;
}

rcb_status rcb_model_bearing_rows(rcb_model *m, rcb_bearing_t *b, const char *name, size_t n,
                                  const double *speeds, const rcb_bearing_coefs *c) {
  double *sp;
  rcb_bearing_coefs *cc;
  size_t i;
  rcb_status st;
  if (n < 1 || !c || (n > 1 && !speeds))
    return rcb_model_fail(m, RCB_ERR_ARG, "bearing '%s': no coefficients given", name);
  for (i = 0; i < n; i++) {
    if ((st = check_coefs(m, name, &c[i]))) return st;
    if (speeds && !isfinite(speeds[i]))
      return rcb_model_fail(m, RCB_ERR_ARG, "bearing '%s': speed %zu is not finite", name, i);
    if (speeds && i > 0 && !(speeds[i] > speeds[i - 1]))
      return rcb_model_fail(m, RCB_ERR_ARG,
                            "bearing '%s': speeds must increase strictly (row %zu: %g after "
                            "%g rad/s)",
                            name, i + 1, speeds[i], speeds[i - 1]);
  }
  if (!b) return RCB_OK; /* checked only */
  sp = rcb_alloc(&m->alloc, n * sizeof *sp);
  cc = rcb_alloc(&m->alloc, n * sizeof *cc);
  if (!sp || !cc) {
    rcb_free(&m->alloc, sp);
    rcb_free(&m->alloc, cc);
    return rcb_model_fail(m, RCB_ERR_NOMEM, "out of memory adding bearing '%s'", name);
  }
  for (i = 0; i < n; i++) {
    sp[i] = speeds ? speeds[i] : 0.0;
    cc[i] = c[i];
  }
  rcb_free(&m->alloc, b->speeds);
  rcb_free(&m->alloc, b->c);
  b->speeds = sp;
  b->c = cc;
  b->n = n;
  return RCB_OK;
}

rcb_status rcb_model_add_bearing_table(rcb_model *m, const char *name, const char *shaft,
                                       double z, size_t n, const double *speeds,
                                       const rcb_bearing_coefs *c) {
  rcb_bearing_t *b;
  rcb_place_t at;
  rcb_status st = rcb_model_check_editable(m, "bearing");
  if (st || (st = check_station_name(m, "bearing", name))) return st;
  if ((st = place_on(m, "bearing", name, shaft, z, &at))) return st;
  if ((st = rcb_model_bearing_rows(m, NULL, name, n, speeds, c))) return st;
  GROW(bearings);
  b = &m->bearings[m->n_bearings];
  if ((st = rcb_model_bearing_rows(m, b, name, n, speeds, c))) return st;
  snprintf(b->name, sizeof b->name, "%s", name);
  b->at = at;
  b->has_ped = 0;
  b->ped_m = b->ped_k[0] = b->ped_k[1] = b->ped_c[0] = b->ped_c[1] = 0.0;
  m->n_bearings++;
  return RCB_OK;
}

rcb_status rcb_model_set_pedestal(rcb_model *m, const char *bearing, const rcb_pedestal *p) {
  static const rcb_pedestal none = {0, 0, 0, 0, 0};
  rcb_bearing_t *b = NULL;
  size_t i;
  rcb_status st = rcb_model_check_editable(m, "pedestal");
  if (st) return st;
  for (i = 0; bearing && i < m->n_bearings; i++)
    if (strcmp(m->bearings[i].name, bearing) == 0) b = &m->bearings[i];
  if (!b)
    return rcb_model_fail(m, RCB_ERR_NOT_FOUND, "pedestal: no bearing named '%s'",
                          bearing ? bearing : "(null)");
  if (!p) p = &none;
  CHECK_VALUE("bearing", b->name, "pedestal_mass (kg)", p->mass, 0);
  CHECK_VALUE("bearing", b->name, "pedestal_kxx (N/m)", p->kxx, 0);
  CHECK_VALUE("bearing", b->name, "pedestal_kyy (N/m)", p->kyy, 0);
  CHECK_VALUE("bearing", b->name, "pedestal_cxx (N s/m)", p->cxx, 0);
  CHECK_VALUE("bearing", b->name, "pedestal_cyy (N s/m)", p->cyy, 0);
  b->has_ped = p->mass != 0 || p->kxx != 0 || p->kyy != 0 || p->cxx != 0 || p->cyy != 0;
  b->ped_m = p->mass;
  b->ped_k[0] = p->kxx;
  b->ped_k[1] = p->kyy;
  b->ped_c[0] = p->cxx;
  b->ped_c[1] = p->cyy;
  return RCB_OK;
}

rcb_status rcb_model_add_bearing(rcb_model *m, const char *name, const char *shaft, double z,
                                 const rcb_bearing_coefs *c) {
  return rcb_model_add_bearing_table(m, name, shaft, z, 1, NULL, c);
}

rcb_status rcb_coupling_hubs_from_geometry(double density, double r_inner, double r_outer,
                                           double thickness, rcb_coupling_params *p) {
  double mm, id, ip;
  rcb_status st;
  int k;
  if (!p) return RCB_ERR_ARG;
  /* Each station carries half the coupling body: an annulus of half the
   * equivalent thickness. */
  st = rcb_disk_from_geometry(density, 2.0 * r_outer, 2.0 * r_inner, 0.5 * thickness, &mm, &id,
                              &ip);
  if (st) return st;
  for (k = 0; k < 2; k++) {
    p->mass[k] = mm;
    p->Id[k] = id;
    p->Ip[k] = ip;
  }
  return RCB_OK;
}

rcb_status rcb_model_add_coupling(rcb_model *m, const char *name, rcb_coupling_model type,
                                  const char *shaft_a, double z_a, const char *shaft_b,
                                  double z_b, const rcb_coupling_params *p) {
  rcb_coupling_t *c;
  rcb_place_t at[2];
  rcb_coupling_params zero = {0};
  const rcb_coupling_params *q = p ? p : &zero;
  int k;
  rcb_status st = rcb_model_check_editable(m, "coupling");
  if (st || (st = check_station_name(m, "coupling", name))) return st;
  if (!rcb_coupling_model_name(type))
    return rcb_model_fail(m, RCB_ERR_ARG, "coupling '%s': unknown model %d", name, (int)type);
  if ((st = place_on(m, "coupling", name, shaft_a, z_a, &at[0]))) return st;
  if ((st = place_on(m, "coupling", name, shaft_b, z_b, &at[1]))) return st;
  if (at[0].shaft == at[1].shaft)
    return rcb_model_fail(m, RCB_ERR_MODEL,
                          "coupling '%s': both stations are on shaft '%s'; a coupling joins "
                          "two different shafts",
                          name, shaft_a);
  CHECK_VALUE("coupling", name, "kt (N/m)", q->kt, 0);
  CHECK_VALUE("coupling", name, "kr (N m/rad)", q->kr, 0);
  CHECK_VALUE("coupling", name, "ct (N s/m)", q->ct, 0);
  CHECK_VALUE("coupling", name, "cr (N m s/rad)", q->cr, 0);
  for (k = 0; k < 2; k++) {
    CHECK_VALUE("coupling", name, "hub mass (kg)", q->mass[k], 0);
    CHECK_VALUE("coupling", name, "hub Id (kg m^2)", q->Id[k], 0);
    CHECK_VALUE("coupling", name, "hub Ip (kg m^2)", q->Ip[k], 0);
  }
  GROW(couplings);
  c = &m->couplings[m->n_couplings++];
  snprintf(c->name, sizeof c->name, "%s", name);
  c->type = type;
  c->at[0] = at[0];
  c->at[1] = at[1];
  c->p = *q;
  return RCB_OK;
}

rcb_status rcb_model_add_unbalance(rcb_model *m, const char *name, const char *shaft, double z,
                                   double amount, double phase) {
  rcb_unbalance_t *u;
  rcb_place_t at;
  rcb_status st = rcb_model_check_editable(m, "unbalance");
  if (st || (st = check_station_name(m, "unbalance", name))) return st;
  if ((st = place_on(m, "unbalance", name, shaft, z, &at))) return st;
  CHECK_VALUE("unbalance", name, "amount (kg m)", amount, 0);
  CHECK_VALUE("unbalance", name, "phase (rad)", phase, -1);
  GROW(unbalances);
  u = &m->unbalances[m->n_unbalances++];
  snprintf(u->name, sizeof u->name, "%s", name);
  u->at = at;
  u->amount = amount;
  u->phase = phase;
  return RCB_OK;
}

rcb_status rcb_model_add_station(rcb_model *m, const char *name, const char *shaft, double z) {
  rcb_probe_t *p;
  rcb_place_t at;
  rcb_status st = rcb_model_check_editable(m, "station");
  if (st || (st = check_station_name(m, "station", name))) return st;
  if ((st = place_on(m, "station", name, shaft, z, &at))) return st;
  GROW(probes);
  p = &m->probes[m->n_probes++];
  snprintf(p->name, sizeof p->name, "%s", name);
  p->at = at;
  return RCB_OK;
}

rcb_status rcb_model_add_uff_node(rcb_model *m, long node, const char *station) {
  rcb_uffmap_t *u;
  size_t i;
  rcb_status st = rcb_model_check_editable(m, "uff map");
  if (st) return st;
  if (!station || !station[0] || strlen(station) >= sizeof u->station)
    return rcb_model_fail(m, RCB_ERR_ARG, "uff map: node %ld: a station name is required",
                          node);
  if (node <= 0)
    return rcb_model_fail(m, RCB_ERR_ARG, "uff map: node %ld, expected a positive UFF node "
                          "number", node);
  for (i = 0; i < m->n_uffmap; i++)
    if (m->uffmap[i].node == node)
      return rcb_model_fail(m, RCB_ERR_MODEL, "uff map: node %ld is mapped twice (%s, %s)",
                            node, m->uffmap[i].station, station);
  GROW(uffmap);
  u = &m->uffmap[m->n_uffmap++];
  u->node = node;
  snprintf(u->station, sizeof u->station, "%s", station);
  return RCB_OK;
}

size_t rcb_model_uff_node_count(const rcb_model *m) { return m ? m->n_uffmap : 0; }

rcb_status rcb_model_uff_node(const rcb_model *m, size_t i, long *node, const char **station) {
  if (!m || i >= m->n_uffmap || !node || !station) return RCB_ERR_ARG;
  *node = m->uffmap[i].node;
  *station = m->uffmap[i].station;
  return RCB_OK;
}
