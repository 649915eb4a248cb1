/*
 * Finalize warnings: values that pass the builder's checks (finite, positive)
 * but are implausible for a machine described in SI units, most often a unit
 * slip (a diameter in mm where m is meant, a modulus in GPa), and shafts that
 * no chain of couplings joins. A warning never fails the load; the caller
 * shows the list (rcb_model_warning_count / rcb_model_warning).
 */
#include <stdio.h>
#include <string.h>

#include "core/rcb_internal.h"
#include "model/model_util.h"

/* Plausible ranges, SI. Wide on purpose: a warning should mean "check the unit". */
#define WARN_OD_MIN 1e-3      /* m: shaft outer diameter */
#define WARN_OD_MAX 5.0       /* m */
#define WARN_LEN_MIN 1e-3     /* m: shaft length */
#define WARN_LEN_MAX 100.0    /* m */
#define WARN_RHO_MIN 100.0    /* kg/m^3 */
#define WARN_RHO_MAX 30000.0  /* kg/m^3 */
#define WARN_E_MIN 1e8        /* Pa */
#define WARN_E_MAX 1e13       /* Pa */
#define WARN_DISK_MASS 1e6    /* kg */

/* One warning more (model/warnings.c; also used by model/plausibility.c). */
rcb_status rcb_model_add_warning(rcb_model *m, const char *fmt, ...) {
  va_list ap;
  if (rcb_grow(&m->alloc, (void **)&m->warnings, &m->cap_warnings, m->n_warnings + 1,
               sizeof *m->warnings))
    return rcb_model_fail(m, RCB_ERR_NOMEM, "out of memory recording a model warning");
  va_start(ap, fmt);
  vsnprintf(m->warnings[m->n_warnings].text, RCB_WARNING_MAX, fmt, ap);
  va_end(ap);
  m->n_warnings++;
  return RCB_OK;
}

static rcb_status check_materials(rcb_model *m) {
  size_t i;
  rcb_status st = RCB_OK;
  for (i = 0; i < m->n_materials && !st; i++) {
    const rcb_material_t *mt = &m->materials[i];
    if (mt->rho < WARN_RHO_MIN || mt->rho > WARN_RHO_MAX)
      st = rcb_model_add_warning(m,
                "material '%s': density = %g kg/m^3 is outside the plausible %g to %g "
                "kg/m^3; a value in g/cm^3 or t/m^3 where kg/m^3 is meant?",
                mt->name, mt->rho, WARN_RHO_MIN, WARN_RHO_MAX);
    if (!st && (mt->E < WARN_E_MIN || mt->E > WARN_E_MAX))
      st = rcb_model_add_warning(m,
                "material '%s': young = %g Pa is outside the plausible %g to %g Pa; a value "
                "in MPa or GPa where Pa is meant?",
                mt->name, mt->E, WARN_E_MIN, WARN_E_MAX);
  }
  return st;
}

static rcb_status check_shafts(rcb_model *m) {
  size_t s, g;
  rcb_status st = RCB_OK;
  for (s = 0; s < m->n_shafts && !st; s++) {
    const rcb_shaft_t *sh = &m->shafts[s];
    double len = 0.0;
    for (g = 0; g < sh->nseg && !st; g++) {
      len += sh->seg[g].L;
      if (sh->seg[g].od < WARN_OD_MIN || sh->seg[g].od > WARN_OD_MAX)
        st = rcb_model_add_warning(m,
                  "shaft '%s': segment %zu outer diameter = %g m is outside the plausible "
                  "%g to %g m; a value in mm where m is meant?",
                  sh->name, g + 1, sh->seg[g].od, WARN_OD_MIN, WARN_OD_MAX);
    }
    if (!st && (len < WARN_LEN_MIN || len > WARN_LEN_MAX))
      st = rcb_model_add_warning(m,
                "shaft '%s': length = %g m is outside the plausible %g to %g m; a value in "
                "mm where m is meant?",
                sh->name, len, WARN_LEN_MIN, WARN_LEN_MAX);
  }
  return st;
}

static rcb_status check_disks(rcb_model *m) {
  size_t i;
  rcb_status st = RCB_OK;
  for (i = 0; i < m->n_disks && !st; i++)
    if (m->disks[i].m > WARN_DISK_MASS)
      st = rcb_model_add_warning(m,
                "disk '%s': mass = %g kg is above the plausible %g kg; a geometry in mm "
                "where m is meant?",
                m->disks[i].name, m->disks[i].m, WARN_DISK_MASS);
  return st;
}

/* Shafts joined by couplings form one rotor train; more than one train is
 * legal (two machines in one file) but usually a coupling placed wrong. The
 * component label of each shaft is the smallest shaft index reachable. */
static rcb_status check_connected(rcb_model *m) {
  size_t *comp, s, c, ntrains = 0;
  int changed = 1;
  rcb_status st = RCB_OK;
  if (m->n_shafts < 2) return RCB_OK;
  comp = rcb_alloc(&m->alloc, m->n_shafts * sizeof *comp);
  if (!comp) return rcb_model_fail(m, RCB_ERR_NOMEM, "out of memory checking shaft links");
  for (s = 0; s < m->n_shafts; s++) comp[s] = s;
  while (changed) { /* relax labels along couplings until stable (few shafts) */
    changed = 0;
    for (c = 0; c < m->n_couplings; c++) {
      size_t a = m->couplings[c].at[0].shaft, b = m->couplings[c].at[1].shaft;
      size_t lo = comp[a] < comp[b] ? comp[a] : comp[b];
      if (comp[a] != lo || comp[b] != lo) {
        comp[a] = comp[b] = lo;
        changed = 1;
      }
    }
  }
  for (s = 0; s < m->n_shafts; s++)
    if (comp[s] == s) ntrains++;
  if (ntrains > 1)
    for (s = 1; s < m->n_shafts && !st; s++)
      if (comp[s] == s)
        st = rcb_model_add_warning(m,
                  "shaft '%s': not joined to shaft '%s' by any chain of couplings; the model "
                  "holds %zu separate rotors (expected a [coupling] between them, or check "
                  "its 'between' stations)",
                  m->shafts[s].name, m->shafts[0].name, ntrains);
  rcb_free(&m->alloc, comp);
  return st;
}

rcb_status rcb_model_collect_warnings(rcb_model *m) {
  rcb_status st;
  m->n_warnings = 0;
  if ((st = check_materials(m)) || (st = check_shafts(m)) || (st = check_disks(m)) ||
      (st = check_connected(m)) || (st = rcb_model_check_plausible(m)))
    return st;
  return RCB_OK;
}

size_t rcb_model_warning_count(const rcb_model *m) {
  return m && m->finalized ? m->n_warnings : 0;
}

const char *rcb_model_warning(const rcb_model *m, size_t i) {
  if (!m || !m->finalized || i >= m->n_warnings) return NULL;
  return m->warnings[i].text;
}
