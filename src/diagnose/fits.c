/*
 * The fits every stage of the diagnosis runs: a fit of a model with the
 * diagnosis' settings (scale, noise model or standard deviations, band), the
 * base parameters and a candidate's (diag_internal.h), its objective, and
 * where a candidate's chain parameters ended.
 */
#include <string.h>

#include "diagnose/diag_internal.h"
#include "identify/identify.h"

/* A fit of m with the diagnosis settings, the base parameters (with_base)
 * and the candidate's parameters (c, may be NULL). */
rcb_status rcb_diag_make_fit(rcb_diag *d, rcb_model *m, unsigned with_base, const diag_cand *c,
                             rcb_fit **out) {
  rcb_fit *f = NULL;
  rcb_status st = rcb_fit_create(&f, m, d->meas, &d->alloc);
  size_t k, npc = !c ? 0 : (with_base & RCB_DIAG_FIT_LEAD) && c->nlead ? c->nlead : c->np;
  if (!st) st = rcb_fit_set_uncertainty(f, 0); /* intervals are not part of a diagnosis */
  if (!st) st = rcb_fit_set_scale(f, d->scale);
  if (!st && (d->beta_a > 0 || d->beta_s > 0))
    st = rcb_fit_set_noise_model(f, d->beta_a, d->beta_s);
  if (!st && d->phase > 0) st = rcb_fit_set_noise_phase(f, d->phase);
  if (!st && d->nref) st = rcb_fit_set_noise_reference(f, d->nref);
  /* the fit's subset masks (screening, pedestal scan) multiply these */
  if (!st && d->sd) st = rcb_fit_set_sd(f, d->sd);
  if (!st && d->have_band) st = rcb_fit_set_band(f, d->band_lo, d->band_hi);
  for (k = 0; !st && (with_base & RCB_DIAG_FIT_BASE) && k < d->nbase; k++) {
    double v;
    size_t j;
    int dup = 0;
    for (j = 0; c && j < c->np; j++) dup |= strcmp(c->pname[j], d->base[k].name) == 0;
    /* another coupling model may not have the parameter (kramer_1: no kt);
     * a sensor's is in no model */
    if (dup || (!rcb_fit_param_is_chain(d->base[k].name) &&
                rcb_model_get_param(m, d->base[k].name, &v)))
      continue;
    st = rcb_fit_add_param(f, d->base[k].name, d->base[k].lo, d->base[k].hi, d->base[k].logp);
  }
  for (k = 0; !st && k < npc; k++) {
    /* a bound relative to the part's own value follows the model fitted
     * (the nominal base's 0.1 kg disk, not the fitted base's 2 kg) */
    double lo = c->lo[k], v;
    if (c->lo_own[k] > 0 && !rcb_model_get_param(m, c->pname[k], &v) && v > 0 && v < c->hi[k])
      lo = c->lo_own[k] * v;
    st = rcb_fit_add_param(f, c->pname[k], lo, c->hi[k], c->logp[k]);
  }
  if (!st) st = rcb_diag_carry_apply(d, f, (with_base & RCB_DIAG_FIT_BASE) != 0);
  for (k = 0; !st && c && c->chain_kept && k < c->np; k++)
    if (rcb_fit_param_is_chain(c->pname[k]))
      st = rcb_fit_set_chain_value(f, c->pname[k], c->chain_v[k]);
  if (!st && c && c->fam->fit_setup) st = c->fam->fit_setup(c, f);
  if (st) {
    rcb_diag_fail(d, st, "%s", f ? rcb_fit_errmsg(f) : "out of memory");
    rcb_fit_destroy(f);
    return st;
  }
  *out = f;
  return RCB_OK;
}

/* Where the chain parameters of c (the last c->np of fit f) ended, kept
 * with the model of that fit (make_fit restores them). */
void rcb_diag_keep_chain(diag_cand *c, const rcb_fit *f) {
  size_t k, np = rcb_fit_param_count(f);
  for (k = 0; k < c->np && np >= c->np; k++) {
    rcb_fit_param p;
    if (!rcb_fit_param_is_chain(c->pname[k]) || rcb_fit_get_param(f, np - c->np + k, &p))
      continue;
    c->chain_v[k] = p.value;
    c->chain_kept = 1;
  }
}

void rcb_diag_drop_fit(rcb_diag *d, rcb_fit *f) {
  d->stats.evaluations += rcb_fit_sweeps(f);
  rcb_fit_destroy(f);
}

/* F = r^T r with the fit's weights, and the error % of the same sweep. */
rcb_status rcb_diag_objective(rcb_diag *d, rcb_fit *f, double *r, double *F, double *err) {
  rcb_status st = rcb_fit_residuals(f, r);
  size_t i;
  if (st) return rcb_diag_fail(d, st, "%s", rcb_fit_errmsg(f));
  *F = 0;
  for (i = 0; i < d->nres; i++) *F += r[i] * r[i];
  *err = rcb_fit_error_pct(f);
  return RCB_OK;
}
