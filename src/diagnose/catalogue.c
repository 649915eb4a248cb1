/*
 * The catalogue of physical effects (issue #4), laid out at every place each
 * can occur in a given model, each with the parameters it adds, their neutral
 * value (the model as it is) and refit bounds; and the edit of the model
 * (rcb_model.h's edit API) that builds a candidate's model.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "diagnose/diag_internal.h"
#include "identify/identify.h"

static const char *const effect_names[RCB_EFFECT_COUNT] = {
    "coupling translational damping", "coupling rotational stiffness",
    "coupling rotational damping",    "coupling model",
    "coupling hub mass and inertia",  "bearing stiffness (anisotropy)",
    "bearing cross-coupled stiffness", "bearing damping",
    "shaft material damping",         "added mass and inertia",
    "flexible support",               "operating speed",
    "shaft element stiffness",        "shaft element mass",
    "sensor gain and phase",          "sensor sign",
    "swapped sensors"};

const char *rcb_effect_name(rcb_effect e) {
  return (int)e >= 0 && e < RCB_EFFECT_COUNT ? effect_names[e] : "?";
}

static diag_cand *new_cand(rcb_diag *d, rcb_effect e, const char *place) {
  diag_cand *c;
  if (rcb_grow(&d->alloc, (void **)&d->cand, &d->cap_cand, d->ncand + 1, sizeof *d->cand))
    return NULL;
  c = &d->cand[d->ncand++];
  memset(c, 0, sizeof *c);
  c->effect = e;
  snprintf(c->place, sizeof c->place, "%s", place);
  c->F = c->err = c->dbic = (double)NAN;
  return c;
}

static void add_par(diag_cand *c, const char *fmt, const char *item, double lo, double hi,
                    int logp) {
  size_t k = c->np++;
  snprintf(c->pname[k], sizeof c->pname[k], fmt, item);
  c->lo[k] = lo;
  c->hi[k] = hi;
  c->logp[k] = logp;
  snprintf(c->params + strlen(c->params), sizeof c->params - strlen(c->params), "%s%s",
           k ? ", " : "", c->pname[k]);
}

/* Is name among the parameters already fitted? */
static int is_base(const rcb_diag *d, const char *name) {
  size_t i;
  for (i = 0; i < d->nbase; i++)
    if (strcmp(d->base[i].name, name) == 0) return 1;
  return 0;
}

/* Bounds for a parameter starting at v: four decades either way (log) when
 * positive, else linear from 0 to hi0. */
static void bounds(double v, double hi0, double *lo, double *hi, int *logp) {
  *logp = v > 0;
  *lo = v > 0 ? v / 1e4 : 0.0;
  *hi = v > 0 ? v * 1e4 : hi0;
}

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

static rcb_status couplings(rcb_diag *d, const rcb_model *m) {
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
      if (is_base(d, nm) || to < 0) continue;
      if (!(c = new_cand(d, eff[t], place))) return RCB_ERR_NOMEM;
      snprintf(c->desc, sizeof c->desc, "%s in coupling %s", what[t], cp->name);
      if (to != (int)cp->type) {
        c->edit = EDIT_COUPLING_MODEL;
        snprintf(c->target, sizeof c->target, "%s", cp->name);
        c->new_type = (rcb_coupling_model)to;
        c->kt0 = p->kt, c->kr0 = p->kr, c->ct0 = p->ct, c->cr0 = p->cr;
      }
      bounds(v, hi0, &lo, &hi, &logp);
      add_par(c, "%s", nm, lo, hi, logp);
    }
    for (t = 0; t < RCB_COUPLING_MODEL_COUNT; t++) { /* another coupling model: refitted */
      if (t == (int)cp->type || (cp->type == RCB_COUPLING_NELSON_CRANDALL_1 &&
                                 t == RCB_COUPLING_NELSON_CRANDALL_2))
        continue; /* NC1 -> NC2 is covered by the damping candidates above */
      if (!(c = new_cand(d, RCB_EFFECT_COUPLING_MODEL, place))) return RCB_ERR_NOMEM;
      snprintf(c->desc, sizeof c->desc, "coupling %s as %s instead of %s", cp->name,
               rcb_coupling_model_name((rcb_coupling_model)t),
               rcb_coupling_model_name(cp->type));
      c->refit_only = 1;
      c->edit = EDIT_COUPLING_MODEL;
      snprintf(c->target, sizeof c->target, "%s", cp->name);
      c->new_type = (rcb_coupling_model)t;
      c->kt0 = kref, c->kr0 = krr, c->ct0 = p->ct, c->cr0 = p->cr;
      if (rcb_coupling_uses((rcb_coupling_model)t) & RCB_CPL_KT) {
        snprintf(nm, sizeof nm, "coupling.%s.kt", cp->name);
        add_par(c, "%s", nm, kref / 1000, kref * 1000, 1);
      }
      if (rcb_coupling_uses((rcb_coupling_model)t) & RCB_CPL_KR) {
        snprintf(nm, sizeof nm, "coupling.%s.kr", cp->name);
        add_par(c, "%s", nm, krr / 1000, krr * 1000, 1);
      }
    }
    {
      double lo, hi;
      int logp;
      if (!(c = new_cand(d, RCB_EFFECT_COUPLING_HUB, place))) return RCB_ERR_NOMEM;
      snprintf(c->desc, sizeof c->desc, "mass of coupling %s's hubs", cp->name);
      bounds(p->mass[0], 10.0, &lo, &hi, &logp);
      add_par(c, "coupling.%s.hub_mass", cp->name, lo, hi, logp);
      if (!(c = new_cand(d, RCB_EFFECT_COUPLING_HUB, place))) return RCB_ERR_NOMEM;
      snprintf(c->desc, sizeof c->desc, "diametral inertia of coupling %s's hubs", cp->name);
      bounds(p->Id[0], 0.1, &lo, &hi, &logp);
      add_par(c, "coupling.%s.hub_Id", cp->name, lo, hi, logp);
    }
  }
  return RCB_OK;
}

static rcb_status bearings(rcb_diag *d, const rcb_model *m) {
  size_t i;
  int a;
  for (i = 0; i < m->n_bearings; i++) {
    const rcb_bearing_t *b = &m->bearings[i];
    const rcb_bearing_coefs *k = &b->c[0];
    double kb = fmax(fabs(k->kxx), fabs(k->kyy)), lo, hi;
    char place[RCB_DIAG_NAME];
    int logp;
    diag_cand *c;
    if (b->n != 1) continue; /* speed-dependent: not fittable */
    if (kb == 0) kb = 1e6;
    snprintf(place, sizeof place, "bearing %s", b->name);
    for (a = 0; a < 2; a++) {
      double v = a ? k->kyy : k->kxx;
      if (!(c = new_cand(d, RCB_EFFECT_BEARING_STIFFNESS, place))) return RCB_ERR_NOMEM;
      snprintf(c->desc, sizeof c->desc, "stiffness in %s at bearing %s (anisotropy)",
               a ? "y" : "x", b->name);
      bounds(v, 10 * kb, &lo, &hi, &logp);
      add_par(c, a ? "bearing.%s.kyy" : "bearing.%s.kxx", b->name, lo, hi, logp);
    }
    if (!(c = new_cand(d, RCB_EFFECT_BEARING_CROSS_COUPLING, place))) return RCB_ERR_NOMEM;
    snprintf(c->desc, sizeof c->desc, "cross-coupled stiffness kxy = -kyx at bearing %s",
             b->name);
    add_par(c, "bearing.%s.kcross", b->name, -kb, kb, 0);
    if (!(c = new_cand(d, RCB_EFFECT_BEARING_DAMPING, place))) return RCB_ERR_NOMEM;
    snprintf(c->desc, sizeof c->desc, "damping at bearing %s", b->name);
    bounds(k->cxx, 1e-2 * kb, &lo, &hi, &logp);
    add_par(c, "bearing.%s.cxx", b->name, lo, hi, logp);
    bounds(k->cyy, 1e-2 * kb, &lo, &hi, &logp);
    add_par(c, "bearing.%s.cyy", b->name, lo, hi, logp);
  }
  return RCB_OK;
}

static rcb_status shafts(rcb_diag *d, const rcb_model *m) {
  size_t i;
  for (i = 0; i < m->n_shafts; i++) {
    const rcb_shaft_t *s = &m->shafts[i];
    char place[RCB_DIAG_NAME];
    double lo, hi;
    int logp;
    diag_cand *c;
    snprintf(place, sizeof place, "shaft %s", s->name);
    if (!(c = new_cand(d, RCB_EFFECT_SHAFT_DAMPING, place))) return RCB_ERR_NOMEM;
    snprintf(c->desc, sizeof c->desc, "material (stiffness-proportional) damping of shaft %s",
             s->name);
    bounds(s->qz_k, 1e-3, &lo, &hi, &logp);
    add_par(c, "shaft.%s.damping_stiffness", s->name, lo, hi, logp);
  }
  return RCB_OK;
}

/* A mass at every disk, and a new (massless) disk at every other node. */
static rcb_status added_masses(rcb_diag *d, const rcb_model *m) {
  double mtot = 0.0;
  size_t i, k;
  for (i = 0; i < m->n_disks; i++) mtot += m->disks[i].m;
  if (mtot <= 0) mtot = 1.0;
  for (i = 0; i < m->n_nodes; i++) {
    const rcb_node_t *nd = &m->nodes[i];
    const rcb_disk_t *disk = NULL;
    char place[RCB_DIAG_NAME];
    diag_cand *c;
    for (k = 0; k < m->n_disks; k++)
      if (m->disks[k].at.node == i) disk = &m->disks[k];
    if (disk)
      snprintf(place, sizeof place, "disk %s", disk->name);
    else
      snprintf(place, sizeof place, "node #%zu (shaft %s, z = %g m)", i,
               m->shafts[nd->shaft].name, nd->z);
    for (k = 0; k < 2; k++) { /* a mass, or a diametral inertia */
      if (!(c = new_cand(d, RCB_EFFECT_ADDED_MASS, place))) return RCB_ERR_NOMEM;
      snprintf(c->desc, sizeof c->desc, "an added %s at %s", k ? "diametral inertia" : "mass",
               place);
      c->node = i + 1;
      c->inertia = (int)k;
      c->shaft = nd->shaft;
      if (disk) {
        double lo, hi;
        int logp;
        if (k == 0) bounds(disk->m, 10 * mtot, &lo, &hi, &logp);
        else bounds(disk->Id, 0.01 * mtot, &lo, &hi, &logp);
        add_par(c, k ? "disk.%s.Id" : "disk.%s.mass", disk->name, lo, hi, logp);
        continue;
      }
      c->edit = EDIT_ADD_DISK;
      snprintf(c->target, sizeof c->target, "ADDED_%zu", i);
      snprintf(c->at, sizeof c->at, "#%zu", i);
      add_par(c, k ? "disk.%s.Id" : "disk.%s.mass", c->target, 0.0, k ? 0.01 * mtot : mtot,
              0);
    }
  }
  return RCB_OK;
}

/* Mass of the rotor train, kg: shafts, disks, coupling hubs. */
static double rotor_mass(const rcb_model *m) {
  double mt = 0.0;
  size_t i;
  for (i = 0; i < m->n_elements; i++) {
    const rcb_element_t *e = &m->elements[i];
    mt += m->materials[m->shafts[e->shaft].material].rho * RCB_PI / 4 *
          (e->od * e->od - e->id * e->id) * e->L;
  }
  for (i = 0; i < m->n_disks; i++) mt += m->disks[i].m;
  for (i = 0; i < m->n_couplings; i++) mt += m->couplings[i].p.mass[0] + m->couplings[i].p.mass[1];
  return mt > 0 ? mt : 1.0;
}

/* A pedestal under every bearing that has none. Its neutral point (no
 * pedestal) has no DOFs, so the candidate starts as a very stiff, light
 * pedestal (1000 x the bearing's stiffness, 1e-3 of the rotor mass per
 * bearing, no damping): the model is the same to about 1e-3, and the score
 * test sees the first terms of the pedestal's dynamic compliance,
 * 1/(k - w^2 m + i w c) ~ 1/k + w^2 m/k^2 - i w c/k^2: a series compliance,
 * its w^2-weighted and its w-weighted (damping) shapes. The refit then moves
 * the pedestal into the band. */
static rcb_status pedestals(rcb_diag *d, const rcb_model *m) {
  double mref = rotor_mass(m) / (double)(m->n_bearings ? m->n_bearings : 1);
  size_t i;
  for (i = 0; i < m->n_bearings; i++) {
    const rcb_bearing_t *b = &m->bearings[i];
    double kb = fmax(fabs(b->c[0].kxx), fabs(b->c[0].kyy));
    char place[RCB_DIAG_NAME];
    diag_cand *c;
    if (b->has_ped) continue;
    if (kb == 0) kb = 1e6;
    snprintf(place, sizeof place, "bearing %s", b->name);
    if (!(c = new_cand(d, RCB_EFFECT_FLEXIBLE_SUPPORT, place))) return RCB_ERR_NOMEM;
    snprintf(c->desc, sizeof c->desc,
             "a flexible support (pedestal mass on a spring and damper) under bearing %s",
             b->name);
    c->edit = EDIT_ADD_PEDESTAL;
    snprintf(c->target, sizeof c->target, "%s", b->name);
    c->ped0[0] = 1e-3 * mref;
    c->ped0[1] = 1e3 * kb;
    c->ped0[2] = 0.0;
    add_par(c, "bearing.%s.pedestal_mass", b->name, 1e-4 * mref, 20 * mref, 1);
    add_par(c, "bearing.%s.pedestal_k", b->name, 1e-2 * kb, 1e4 * kb, 1);
    add_par(c, "bearing.%s.pedestal_c", b->name, 0.0, 1e-2 * kb, 0);
  }
  return RCB_OK;
}

/* Weighted objective of f at the model's current values (NaN on failure). */
static double objective_now(rcb_fit *f, double *r) {
  size_t i, n = rcb_fit_residual_count(f);
  double F = 0;
  if (rcb_fit_residuals(f, r)) return (double)NAN;
  for (i = 0; i < n; i++) F += r[i] * r[i];
  return F;
}

static rcb_status set_pedestal(rcb_model *m, const char *bearing, double mass, double k,
                               double c) {
  char nm[RCB_DIAG_NAME];
  rcb_status st;
  snprintf(nm, sizeof nm, "bearing.%s.pedestal_mass", bearing);
  if ((st = rcb_model_set_param(m, nm, mass))) return st;
  snprintf(nm, sizeof nm, "bearing.%s.pedestal_k", bearing);
  if ((st = rcb_model_set_param(m, nm, k))) return st;
  snprintf(nm, sizeof nm, "bearing.%s.pedestal_c", bearing);
  return rcb_model_set_param(m, nm, c);
}

/* Points kept with a relative step: each at least 1 + step times the last
 * kept one's frequency (w: 1 kept, 0 not, per point; may be NULL). */
static size_t grid_keep(const double *x, size_t n, double step, double *w) {
  double last = -1.0;
  size_t i, k = 0;
  for (i = 0; i < n; i++) {
    int keep = last < 0 || x[i] >= (1.0 + step) * last;
    if (keep) last = x[i], k++;
    if (w) w[i] = keep ? 1.0 : 0.0;
  }
  return k;
}

/* Unit weights on a subset of the measured points, 0 elsewhere (grid_keep).
 * The grid's pedestals have 5 % of critical damping, a half-power width of
 * 10 % of their frequency: a step of 2.5 % puts 4 points in every width. The
 * step is smaller when that keeps fewer than RCB_DIAG_GRID_MIN points: on 8
 * channels x 151 points over 100-400 Hz, 47 points lost a start that all of
 * them find (the tests' hidden shaft damping: the pedestal under B3 ended
 * 3e4 of BIC worse). 32 x 1101 over 50-600 Hz: 150 points, 150 of 151 over
 * 100-400 Hz. */
#define RCB_DIAG_GRID_STEP 0.025
#define RCB_DIAG_GRID_MIN 150
double *rcb_diag_grid_weights(rcb_diag *d) {
  size_t n = rcb_meas_point_count(d->meas), nch = rcb_meas_channel_count(d->meas), c;
  const double *x = rcb_meas_grid(d->meas);
  double *w = rcb_alloc(&d->alloc, (n * nch > 0 ? n * nch : 1) * sizeof *w);
  double step = RCB_DIAG_GRID_STEP;
  int it;
  if (!w) return NULL;
  if (grid_keep(x, n, step, NULL) < RCB_DIAG_GRID_MIN) {
    /* the largest step that keeps enough points (bisection; 0: all) */
    double lo = 0.0, hi = step;
    for (it = 0; it < 40; it++) {
      double mid = 0.5 * (lo + hi);
      if (grid_keep(x, n, mid, NULL) >= RCB_DIAG_GRID_MIN) lo = mid;
      else hi = mid;
    }
    step = lo;
  }
  grid_keep(x, n, step, w);
  for (c = 1; c < nch; c++) memcpy(w + c * n, w, n * sizeof *w);
  return w;
}

/* The refit of a pedestal starts from the best point of a grid: masses 0.3,
 * 1, 3 and 10 x the rotor mass per bearing, stiffnesses over the lower four
 * decades of its bounds (4 per decade), 5 % of critical damping; or from the
 * stiff light start when no grid point is better. The score test, taken at
 * that start, only sees the pedestal's compliance, while a pedestal near the
 * band adds a resonance that a local fit from there does not find. The 69
 * evaluations compare starts only: they use the points of grid_weights (a
 * seventh of the 32 x 1101 case's work), the refit then all points. */
rcb_status rcb_diag_refit_start(rcb_diag *d, const diag_cand *c, rcb_model *m, rcb_fit *f) {
  static const double mass_f[4] = {0.3, 1.0, 3.0, 10.0};
  double *r = NULL, *w, best, bm = c->ped0[0], bk = c->ped0[1], bc = c->ped0[2], mref;
  int a, j;
  rcb_status st = RCB_OK;
  if (c->edit != EDIT_ADD_PEDESTAL) return RCB_OK;
  if ((w = rcb_diag_grid_weights(d)) && (st = rcb_fit_set_weights(f, w)) == RCB_OK &&
      (st = rcb_fit_prepare(f)) != RCB_OK && st != RCB_ERR_NOMEM) {
    rcb_fit_set_weights(f, NULL); /* no point left there: all points */
    st = RCB_OK;
  }
  if (!w || st || !(r = rcb_alloc(&d->alloc, (rcb_fit_residual_count(f) + 1) * sizeof *r))) {
    rcb_free(&d->alloc, w);
    return rcb_diag_fail(d, st ? st : RCB_ERR_NOMEM, "%s",
                         st ? rcb_fit_errmsg(f) : "out of memory");
  }
  mref = rotor_mass(m) / (double)(m->n_bearings ? m->n_bearings : 1);
  best = objective_now(f, r);
  for (a = 0; a < 4 && !st; a++)
    for (j = 0; j <= 16 && !st; j++) {
      double mass = mass_f[a] * mref, k = c->lo[1] * pow(10.0, 0.25 * j);
      double damp = fmin(0.1 * sqrt(k * mass), c->hi[2]), F;
      if ((st = set_pedestal(m, c->target, mass, k, damp))) break;
      F = objective_now(f, r);
      if (F < best) best = F, bm = mass, bk = k, bc = damp;
    }
  if (!st) st = set_pedestal(m, c->target, bm, bk, bc);
  rcb_fit_set_weights(f, NULL); /* all points again */
  rcb_free(&d->alloc, r);
  rcb_free(&d->alloc, w);
  if (st) return rcb_diag_fail(d, st, "%s: %s", c->desc, rcb_model_errmsg(m));
  return RCB_OK;
}

/* The operating speed (FRF data taken on a spinning rotor only): a speed
 * factor, neutral 1. Unbalance responses are left out: their abscissa is the
 * measured once-per-revolution speed, and the factor does not apply there. */
static rcb_status speed(rcb_diag *d) {
  diag_cand *c;
  if (rcb_meas_get_type(d->meas) != RCB_MEAS_FRF || rcb_meas_speed(d->meas) == 0 ||
      is_base(d, "speed.factor"))
    return RCB_OK;
  if (!(c = new_cand(d, RCB_EFFECT_SPEED, "operating speed"))) return RCB_ERR_NOMEM;
  snprintf(c->desc, sizeof c->desc,
           "an operating speed other than the stated one (gyroscopic split)");
  add_par(c, "%s", "speed.factor", 0.25, 4.0, 1);
  return RCB_OK;
}

rcb_status rcb_diag_catalogue(rcb_diag *d, const rcb_model *m) {
  rcb_status st;
  if ((st = couplings(d, m)) || (st = bearings(d, m)) || (st = pedestals(d, m)) ||
      (st = shafts(d, m)) || (st = added_masses(d, m)) || (st = speed(d)))
    return rcb_diag_fail(d, st, "out of memory laying out the candidates");
  return RCB_OK;
}

/* ---- candidate models: edits of a copy of the fitted base model ---- */

rcb_status rcb_diag_copy_model(rcb_diag *d, const rcb_model *src, rcb_model **out) {
  rcb_model *m = NULL;
  rcb_status st = rcb_model_clone(&m, src, &d->alloc);
  *out = NULL;
  if (st) return rcb_diag_fail(d, st, "copying the model: %s", rcb_status_str(st));
  if ((st = rcb_model_finalize(m))) {
    rcb_diag_fail(d, st, "copying the model: %s", rcb_model_errmsg(m));
    rcb_model_destroy(m);
    return st;
  }
  *out = m;
  return RCB_OK;
}

/* The structural edit of c on the unfinalized copy m. */
static rcb_status edit(const diag_cand *c, rcb_model *m) {
  if (c->edit == EDIT_COUPLING_MODEL)
    return rcb_model_set_coupling_model(m, c->target, c->new_type);
  if (c->edit == EDIT_ADD_PEDESTAL) {
    rcb_pedestal p;
    p.mass = c->ped0[0];
    p.kxx = p.kyy = c->ped0[1];
    p.cxx = p.cyy = c->ped0[2];
    return rcb_model_set_pedestal(m, c->target, &p);
  }
  if (c->edit == EDIT_ADD_DISK) return rcb_model_add_disk_at(m, c->target, c->at, 0, 0, 0);
  return RCB_OK;
}

/* A new coupling model's starting values (the parameters it uses). */
static rcb_status coupling_start(const diag_cand *c, rcb_model *m) {
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

rcb_status rcb_diag_candidate_model(rcb_diag *d, const diag_cand *c, const rcb_model *from,
                                    rcb_model **out) {
  rcb_model *m = NULL;
  rcb_status st = rcb_model_clone(&m, from, &d->alloc);
  *out = NULL;
  if (st) return rcb_diag_fail(d, st, "%s: %s", c->desc, rcb_status_str(st));
  if (!(st = edit(c, m)) && !(st = rcb_model_finalize(m)) && c->edit == EDIT_COUPLING_MODEL)
    st = coupling_start(c, m);
  if (st) {
    rcb_diag_fail(d, st, "%s: %s", c->desc, rcb_model_errmsg(m));
    rcb_model_destroy(m);
    return st;
  }
  *out = m;
  return RCB_OK;
}

/* ---- the catalogue for other folders (diagnose/diagnose.h) ---- */

size_t rcb_diag_catalogue_count(const rcb_diag *d) { return d ? d->ncand : 0; }

rcb_status rcb_diag_catalogue_get(const rcb_diag *d, size_t i, rcb_diag_cand_desc *out) {
  const diag_cand *c;
  size_t k;
  if (!d || !out || i >= d->ncand) return RCB_ERR_ARG;
  c = &d->cand[i];
  memset(out, 0, sizeof *out);
  out->effect = c->effect;
  out->place = c->place, out->desc = c->desc, out->params = c->params;
  out->np = c->np;
  for (k = 0; k < c->np; k++) {
    out->pname[k] = c->pname[k];
    out->lo[k] = c->lo[k], out->hi[k] = c->hi[k], out->logp[k] = c->logp[k];
  }
  out->refit_only = c->refit_only;
  out->adds_dofs = c->edit == EDIT_ADD_PEDESTAL;
  return RCB_OK;
}

rcb_status rcb_diag_catalogue_model(rcb_diag *d, size_t i, const rcb_model *from,
                                    rcb_model **out) {
  if (!d || !out || i >= d->ncand) return RCB_ERR_ARG;
  return rcb_diag_candidate_model(d, &d->cand[i], from, out);
}
