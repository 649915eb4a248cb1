/*
 * Plausibility of a model's values and layout (issue #17), run by finalize.
 *
 * Refused (RCB_ERR_MODEL): a magnitude beyond RCB_ABSURD in SI (kxx = 1e308,
 * an unbalance of 1e200 kg m, a density of 1e308). Such a value is finite, so
 * the builders accept it, but the products the analyses form (w^2 M, sums of
 * squares in norms and condition estimates) overflow, and the failure then
 * surfaced far away as "singular ... free-free". No unit slip or real machine
 * comes within fifty orders of magnitude of the limit, so it only refuses
 * typing errors (an exponent).
 *
 * Warned (rcb_model_warning; the model still computes, because each layout
 * is legal for some machine): a coupling that does not join two facing shaft
 * ends (a station inside a shaft, a shaft's start to another's end, ends with
 * a third shaft between them), shafts that overlap axially (concentric rotors
 * exist, a mistyped start is likelier), a rotor train without a bearing in a
 * model that has bearings elsewhere (a fully free-free model is a deliberate
 * test set-up and is not warned), every bearing and coupling stiffness zero,
 * and an unbalance above the plausible (g mm typed where kg m is meant).
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "core/rcb_internal.h"
#include "model/model_util.h"

/* |value| in SI beyond which a model value is refused: below it the product
 * of two values (and a frequency squared) stays inside the double range,
 * ~1.8e308. */
#define RCB_ABSURD 1e100
/* kg m: above any balancing grade of any machine (a 100 t rotor at G16 and
 * 1000 rpm carries ~15 kg m); a value in g mm typed as kg m lands far above. */
#define WARN_UNBALANCE_MAX 100.0
/* Shaft ends and overlaps are compared to this fraction of the model length. */
#define PLAUS_ZTOL 1e-9

/* ---- magnitudes (refused) ---- */

static rcb_status absurd(rcb_model *m, const char *kind, const char *name, const char *key,
                         double v, const char *unit) {
  return rcb_model_fail(m, RCB_ERR_MODEL,
                        "%s '%s': %s = %g %s is beyond any machine (|value| > %g in SI): "
                        "refused, because products of such values overflow and the solves "
                        "would fail as 'singular'; check the exponent and the unit",
                        kind, name, key, v, unit, RCB_ABSURD);
}

#define CHECK(kind, name, key, v, unit) \
  do { \
    if (fabs(v) > RCB_ABSURD) return absurd(m, kind, name, key, v, unit); \
  } while (0)

static rcb_status check_bearing_values(rcb_model *m, const rcb_bearing_t *b) {
  size_t r;
  for (r = 0; r < b->n; r++) {
    const rcb_bearing_coefs *c = &b->c[r];
    CHECK("bearing", b->name, "kxx", c->kxx, "N/m");
    CHECK("bearing", b->name, "kxy", c->kxy, "N/m");
    CHECK("bearing", b->name, "kyx", c->kyx, "N/m");
    CHECK("bearing", b->name, "kyy", c->kyy, "N/m");
    CHECK("bearing", b->name, "cxx", c->cxx, "N s/m");
    CHECK("bearing", b->name, "cxy", c->cxy, "N s/m");
    CHECK("bearing", b->name, "cyx", c->cyx, "N s/m");
    CHECK("bearing", b->name, "cyy", c->cyy, "N s/m");
  }
  CHECK("bearing", b->name, "pedestal_mass", b->ped_m, "kg");
  CHECK("bearing", b->name, "pedestal_kxx", b->ped_k[0], "N/m");
  CHECK("bearing", b->name, "pedestal_kyy", b->ped_k[1], "N/m");
  CHECK("bearing", b->name, "pedestal_cxx", b->ped_c[0], "N s/m");
  CHECK("bearing", b->name, "pedestal_cyy", b->ped_c[1], "N s/m");
  return RCB_OK;
}

static rcb_status check_coupling_values(rcb_model *m, const rcb_coupling_t *c) {
  int k;
  CHECK("coupling", c->name, "kt", c->p.kt, "N/m");
  CHECK("coupling", c->name, "kr", c->p.kr, "N m/rad");
  CHECK("coupling", c->name, "ct", c->p.ct, "N s/m");
  CHECK("coupling", c->name, "cr", c->p.cr, "N m s/rad");
  for (k = 0; k < 2; k++) {
    CHECK("coupling", c->name, "hub mass", c->p.mass[k], "kg");
    CHECK("coupling", c->name, "hub Id", c->p.Id[k], "kg m^2");
    CHECK("coupling", c->name, "hub Ip", c->p.Ip[k], "kg m^2");
  }
  return RCB_OK;
}

rcb_status rcb_model_check_magnitudes(rcb_model *m) {
  size_t i, g;
  rcb_status st;
  for (i = 0; i < m->n_materials; i++) {
    CHECK("material", m->materials[i].name, "density", m->materials[i].rho, "kg/m^3");
    CHECK("material", m->materials[i].name, "young", m->materials[i].E, "Pa");
  }
  for (i = 0; i < m->n_shafts; i++) {
    const rcb_shaft_t *sh = &m->shafts[i];
    CHECK("shaft", sh->name, "start", sh->z0, "m");
    CHECK("shaft", sh->name, "damping_mass", sh->qz_m, "1/s");
    CHECK("shaft", sh->name, "damping_stiffness", sh->qz_k, "s");
    for (g = 0; g < sh->nseg; g++) {
      CHECK("shaft", sh->name, "segment length", sh->seg[g].L, "m");
      CHECK("shaft", sh->name, "segment outer diameter", sh->seg[g].od, "m");
    }
  }
  for (i = 0; i < m->n_disks; i++) {
    CHECK("disk", m->disks[i].name, "mass", m->disks[i].m, "kg");
    CHECK("disk", m->disks[i].name, "Id", m->disks[i].Id, "kg m^2");
    CHECK("disk", m->disks[i].name, "Ip", m->disks[i].Ip, "kg m^2");
  }
  for (i = 0; i < m->n_bearings; i++)
    if ((st = check_bearing_values(m, &m->bearings[i]))) return st;
  for (i = 0; i < m->n_couplings; i++)
    if ((st = check_coupling_values(m, &m->couplings[i]))) return st;
  for (i = 0; i < m->n_unbalances; i++)
    CHECK("unbalance", m->unbalances[i].name, "amount", m->unbalances[i].amount, "kg m");
  return RCB_OK;
}
#undef CHECK

/* ---- layout (warned) ---- */

static double shaft_end(const rcb_shaft_t *sh) {
  double z = sh->z0;
  size_t g;
  for (g = 0; g < sh->nseg; g++) z += sh->seg[g].L;
  return z;
}

/* -1 at the shaft's start, +1 at its end, 0 inside. */
static int end_of(const rcb_model *m, const rcb_place_t *p, double tol) {
  const rcb_shaft_t *sh = &m->shafts[p->shaft];
  if (fabs(p->z - sh->z0) <= tol) return -1;
  if (fabs(p->z - shaft_end(sh)) <= tol) return 1;
  return 0;
}

static rcb_status check_coupling_ends(rcb_model *m, const rcb_coupling_t *c, double tol) {
  static const char *const side[3] = {"start", "inside", "end"};
  const rcb_place_t *a = &c->at[0], *b = &c->at[1];
  const rcb_shaft_t *sa = &m->shafts[a->shaft], *sb = &m->shafts[b->shaft];
  int ea = end_of(m, a, tol), eb = end_of(m, b, tol), k;
  double lo = fmin(a->z, b->z), hi = fmax(a->z, b->z);
  size_t s;
  if (a->shaft == b->shaft)
    return rcb_model_add_warning(m, "coupling '%s': joins shaft '%s' to itself (z = %g and %g "
                                 "m); expected two shafts' facing ends", c->name, sa->name,
                                 a->z, b->z);
  for (k = 0; k < 2; k++) {
    const rcb_place_t *p = k ? b : a;
    if ((k ? eb : ea) == 0)
      return rcb_model_add_warning(m, "coupling '%s': station %c (shaft '%s', z = %g m) is "
                                   "not an end of the shaft (%g to %g m); a coupling joins "
                                   "shaft ends", c->name, k ? 'b' : 'a',
                                   m->shafts[p->shaft].name, p->z, m->shafts[p->shaft].z0,
                                   shaft_end(&m->shafts[p->shaft]));
  }
  /* facing ends: the lower station is its shaft's end, the upper one its shaft's start */
  if ((a->z <= b->z ? ea : eb) != 1 || (a->z <= b->z ? eb : ea) != -1)
    return rcb_model_add_warning(m, "coupling '%s': joins the %s of shaft '%s' (z = %g m) to "
                                 "the %s of shaft '%s' (z = %g m), ends that do not face each "
                                 "other; expected the end of the shaft with the lower z and "
                                 "the start of the other, e.g. 'between = %s end, %s start'",
                                 c->name, side[ea + 1], sa->name, a->z, side[eb + 1], sb->name,
                                 b->z, sa->z0 <= sb->z0 ? sa->name : sb->name,
                                 sa->z0 <= sb->z0 ? sb->name : sa->name);
  for (s = 0; s < m->n_shafts; s++) {
    const rcb_shaft_t *o = &m->shafts[s];
    if (s == a->shaft || s == b->shaft) continue;
    if (o->z0 < hi - tol && shaft_end(o) > lo + tol)
      return rcb_model_add_warning(m, "coupling '%s': shaft '%s' (%g to %g m) lies between "
                                   "the ends it joins (z = %g and %g m); expected adjacent "
                                   "shafts", c->name, o->name, o->z0, shaft_end(o), lo, hi);
  }
  return RCB_OK;
}

static rcb_status check_overlaps(rcb_model *m, double tol) {
  size_t i, j;
  rcb_status st = RCB_OK;
  for (i = 0; i < m->n_shafts && !st; i++)
    for (j = i + 1; j < m->n_shafts && !st; j++) {
      const rcb_shaft_t *p = &m->shafts[i], *q = &m->shafts[j];
      double lo = fmax(p->z0, q->z0), hi = fmin(shaft_end(p), shaft_end(q));
      if (hi - lo > tol)
        st = rcb_model_add_warning(m, "shaft '%s': overlaps shaft '%s' from z = %g to %g m; "
                                   "concentric rotors are legal, but check the 'start' keys",
                                   q->name, p->name, lo, hi);
    }
  return st;
}

/* Trains of shafts joined by couplings: label = smallest shaft index. */
static void label_trains(const rcb_model *m, size_t *comp) {
  size_t s, c;
  int changed = 1;
  for (s = 0; s < m->n_shafts; s++) comp[s] = s;
  while (changed) {
    changed = 0;
    for (c = 0; c < m->n_couplings; c++) {
      size_t a = m->couplings[c].at[0].shaft, b = m->couplings[c].at[1].shaft;
      size_t lo = comp[a] < comp[b] ? comp[a] : comp[b];
      if (comp[a] != lo || comp[b] != lo) comp[a] = comp[b] = lo, changed = 1;
    }
  }
}

static rcb_status check_support(rcb_model *m) {
  size_t *comp, s, b;
  rcb_status st = RCB_OK;
  if (m->n_bearings == 0) return RCB_OK; /* free-free on purpose */
  comp = rcb_alloc(&m->alloc, m->n_shafts * sizeof *comp);
  if (!comp) return rcb_model_fail(m, RCB_ERR_NOMEM, "out of memory checking supports");
  label_trains(m, comp);
  for (s = 0; s < m->n_shafts && !st; s++) {
    int held = 0;
    if (comp[s] != s) continue;
    for (b = 0; b < m->n_bearings && !held; b++) held = comp[m->bearings[b].at.shaft] == s;
    if (!held)
      st = rcb_model_add_warning(m, "shaft '%s': the rotor train it belongs to has no bearing "
                                 "while the model has %zu elsewhere: it floats free (rigid-body "
                                 "modes at 0 Hz, FRFs singular at 0 Hz); expected a [bearing] "
                                 "on it or a coupling to a supported shaft",
                                 m->shafts[s].name, m->n_bearings);
  }
  rcb_free(&m->alloc, comp);
  return st;
}

static int bearing_stiff(const rcb_bearing_t *b) {
  size_t r;
  for (r = 0; r < b->n; r++)
    if (b->c[r].kxx != 0.0 || b->c[r].kxy != 0.0 || b->c[r].kyx != 0.0 || b->c[r].kyy != 0.0)
      return 1;
  return 0;
}

static rcb_status check_all_zero(rcb_model *m) {
  size_t i;
  if (m->n_bearings + m->n_couplings == 0) return RCB_OK;
  for (i = 0; i < m->n_bearings; i++)
    if (bearing_stiff(&m->bearings[i])) return RCB_OK;
  for (i = 0; i < m->n_couplings; i++)
    if (m->couplings[i].p.kt != 0.0 || m->couplings[i].p.kr != 0.0) return RCB_OK;
  return rcb_model_add_warning(m, "every bearing and coupling stiffness is zero (%zu bearings, "
                               "%zu couplings): nothing holds the rotor elastically (rigid-body "
                               "modes at 0 Hz, FRFs singular at 0 Hz); expected kxx, kyy "
                               "and kt, kr in N/m and N m/rad",
                               m->n_bearings, m->n_couplings);
}

rcb_status rcb_model_check_plausible(rcb_model *m) {
  size_t i;
  double zmax = 1.0, tol;
  rcb_status st = RCB_OK;
  for (i = 0; i < m->n_shafts; i++) zmax = fmax(zmax, fmax(fabs(m->shafts[i].z0),
                                                          fabs(shaft_end(&m->shafts[i]))));
  tol = PLAUS_ZTOL * zmax;
  for (i = 0; i < m->n_couplings && !st; i++) st = check_coupling_ends(m, &m->couplings[i], tol);
  if (!st) st = check_overlaps(m, tol);
  if (!st) st = check_support(m);
  if (!st) st = check_all_zero(m);
  for (i = 0; i < m->n_unbalances && !st; i++)
    if (fabs(m->unbalances[i].amount) > WARN_UNBALANCE_MAX)
      st = rcb_model_add_warning(m, "unbalance '%s': amount = %g kg m is above the plausible "
                                 "%g kg m; a value in g mm where kg m is meant (1 g mm = 1e-6 "
                                 "kg m)?", m->unbalances[i].name, m->unbalances[i].amount,
                                 WARN_UNBALANCE_MAX);
  return st;
}
