/*
 * Commissioning a monitor (rcb_monitor.h): the set-up and the baseline model
 * copied, the noise of every residual, the sensitivity columns of the
 * tracked parameters (identify/, eq. 9) and of the diagnosis catalogue's
 * candidates at their neutral values (diagnose/diagnose.h, fit_score.c's
 * batched adjoint columns), all whitened and factored once by the score
 * test's QR (diagnose/score_qr.c), and the small rank-space matrices the
 * update applies (monitor_rank.c). Everything is allocated here; nothing in
 * the update.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "diagnose/diagnose.h"
#include "identify/identify.h"
#include "monitor/monitor_internal.h"


/* ---- the counting allocator: every byte the monitor's objects hold ---- */

#define MON_HDR 16u /* keeps the caller's 16-byte alignment */

static void *count_alloc(void *user, size_t size) {
  rcb_monitor *mon = user;
  unsigned char *p;
  if (size > (size_t)-1 - MON_HDR) return NULL;
  p = rcb_alloc(&mon->user, size + MON_HDR);
  if (!p) return NULL;
  memcpy(p, &size, sizeof size);
  mon->held += size;
  return p + MON_HDR;
}

static void count_free(void *user, void *ptr) {
  rcb_monitor *mon = user;
  unsigned char *p = (unsigned char *)ptr - MON_HDR;
  size_t size;
  memcpy(&size, p, sizeof size);
  mon->held -= size;
  rcb_free(&mon->user, p);
}

void *rcb_mon_alloc(rcb_monitor *mon, size_t count, size_t size) {
  if (count && size > (size_t)-1 / count) return NULL;
  return rcb_alloc(&mon->alloc, count * size);
}

/* ---- set-up: a copy of the commissioning measurement ---- */

static rcb_status copy_setup(rcb_monitor *mon, const rcb_meas *setup) {
  size_t c, i;
  rcb_status st;
  mon->nch = rcb_meas_channel_count(setup);
  mon->npts = rcb_meas_point_count(setup);
  if (!mon->nch || !mon->npts)
    return rcb_mon_fail(mon, RCB_ERR_ARG, "set-up: no channel or no point (%zu channels x %zu "
                        "points); give the commissioning measurement", mon->nch, mon->npts);
  mon->npt = mon->nch * mon->npts;
  mon->n = 2 * mon->npt;
  if ((st = rcb_meas_create(&mon->setup, &mon->alloc)) ||
      (st = rcb_meas_set_grid(mon->setup, rcb_meas_get_type(setup), mon->npts,
                              rcb_meas_grid(setup), rcb_meas_speed(setup))))
    return rcb_mon_fail(mon, st, "set-up: %s", mon->setup ? rcb_meas_errmsg(mon->setup) : "");
  for (c = 0; c < mon->nch; c++) {
    rcb_meas_channel_info ci;
    rcb_meas_channel(setup, c, &ci);
    for (i = 0; i < mon->npts; i++)
      if (!isfinite(creal(ci.data[i])) || !isfinite(cimag(ci.data[i])))
        return rcb_mon_fail(mon, RCB_ERR_ARG, "set-up: channel %zu (%s) point %zu: the "
                            "commissioning value is not finite", c + 1, ci.response, i + 1);
    if ((st = rcb_meas_add_channel(mon->setup, ci.response, ci.reference, ci.kind, ci.data)))
      return rcb_mon_fail(mon, st, "set-up: %s", rcb_meas_errmsg(mon->setup));
  }
  return RCB_OK;
}

/* ---- noise: the standard deviation of every residual ---- */

double rcb_mon_eq19_amp(double beta_s, const rcb_complex *v, size_t n) {
  double s2 = 0.0;
  size_t i;
  for (i = 0; i < n; i++) s2 += creal(v[i] * conj(v[i]));
  return beta_s / 100.0 * sqrt(s2) / (double)n;
}

/* One measurement's declared variance at a point of modulus ae, radial
 * (along the value) *vr and tangential *vt, the channel's units squared:
 * eq. 19's proportional part along the value (variance (beta_a/100)^2 ae^2
 * / 3, r1 uniform on [-1, 1]), its additive part of amplitude a circular
 * (a^2 / 3 split over two components), a phase turn uniform in +-phase_deg
 * to first order tangential (phase_var ae^2, phase_var = (phase_deg
 * pi/180)^2 / 3). */
static void eq19_var(double beta_a, double a, double phase_var, double ae, double *vr,
                     double *vt) {
  double pa = beta_a / 100.0 * ae;
  *vt = a * a / 6.0;
  *vr = pa * pa / 3.0 + *vt;
  *vt += phase_var * ae * ae;
}

/* The declared noise of opts checked: the message into err (size n). */
static rcb_status noise_opts(const rcb_monitor_opts *o, char *err, size_t n) {
  if (!o->sd && !(o->beta_a > 0 || o->beta_s > 0))
    return snprintf(err, n, "no noise: give beta_a/beta_s (eq. 19, %%) or per-point standard "
                    "deviations (opts.sd)"), RCB_ERR_ARG;
  if (!o->sd && (!(o->beta_a >= 0) || !(o->beta_s >= 0) || !isfinite(o->beta_a + o->beta_s)))
    return snprintf(err, n, "noise: beta_a = %g, beta_s = %g %%: expected finite >= 0",
                    o->beta_a, o->beta_s), RCB_ERR_ARG;
  if (!(o->phase_deg >= 0) || !(o->phase_deg < 90))
    return snprintf(err, n, "noise: phase_deg = %g degrees: expected 0 <= phase_deg < 90",
                    o->phase_deg), RCB_ERR_ARG;
  if (!(o->noise_scale >= 0) || !isfinite(o->noise_scale))
    return snprintf(err, n, "noise: noise_scale = %g: expected finite >= 0 (0: as declared)",
                    o->noise_scale), RCB_ERR_ARG;
  return RCB_OK;
}

/* The modulus eq. 19's proportional and phase terms are taken at for point
 * p: the baseline model's (mon->h0abs), not the commissioning value's ae.
 * Taken at ae, every sd carries that value's own noise: a point whose
 * commissioning value reads low gets a small sd, a large weight, and a
 * residual against that value pushed up. Along a direction that weights all
 * points alike this adds up over the points instead of averaging out, and a
 * sensor's gain is such a direction (its column is the channel's values,
 * whitened by sds proportional to them: about constant). At 32 channels x
 * 1101 lines (eq. 19 10 %, 1 %, commissioning 10 files) the 8 gain
 * directions' x^2 averaged 2.02 with the sds at the commissioning values,
 * 1.09 at the truth (tools/bench/monitor_noise_weights.py --numpy, 200
 * draws). The model's modulus is kept within a factor 2 of ae (a baseline
 * that does not fit there: the value's). */
static double noise_modulus(const rcb_monitor *mon, size_t p, double ae) {
  return fmin(fmax(mon->h0abs[p], 0.5 * ae), 2.0 * ae);
}

/* Radial and tangential sd of one measurement at each point: eq. 19 with the
 * phase turn (eq19_var) or the caller's sd (circular), at the baseline
 * model's modulus (noise_modulus; its additive amplitude and the radial
 * frame at the commissioning values), times opts.noise_scale.
 *
 * On the reweighted path (opts.reweight, eq. 19 noise, with or without the
 * phase term) the frame u is the baseline model's values' too: there the
 * metric is the covariance C made each update (monitor_gls.c, which turns
 * the commissioning's share var0, radial to e_0, into u, on the split path
 * too) and the frame only sets the coordinates. At e_0 each
 * point's frame turns with that point's own commissioning noise d_0 (its
 * phase noise), which every update's change carries (-d_0): with radial and
 * tangential weights unequal, the same kind of bias as noise_modulus's,
 * shared by all updates (issue #34 item 2; tools/bench/monitor_replicas.py
 * at 32 x 1101, eq. 19 and +-2 deg declared 10,1,2, noise-free updates: the
 * operating speed's drift input +0.47 sd on average over 6 commissionings
 * with the frame at e_0, -0.08 at h_0; tests/test_monitor.c,
 * test_commissioning_noise_unbiased). */
static rcb_status noise(rcb_monitor *mon, const rcb_monitor_opts *o) {
  double navg = o->setup_averages > 0 ? o->setup_averages : 1.0;
  double f0 = isinf(navg) ? 1.0 : 1.0 + 1.0 / navg; /* new + commissioning variance */
  double sc = o->noise_scale > 0 ? o->noise_scale : 1.0, ph = o->phase_deg * sc * RCB_MON_DEG;
  char err[160];
  size_t c, i;
  rcb_status st;
  if (navg < 1.0)
    return rcb_mon_fail(mon, RCB_ERR_ARG, "setup_averages = %g: expected >= 1 (measurements "
                        "averaged into the commissioning values)", navg);
  if ((st = noise_opts(o, err, sizeof err))) return rcb_mon_fail(mon, st, "%s", err);
  mon->navg_inv = isinf(navg) ? 0.0 : 1.0 / navg;
  mon->nscale = sc, mon->beta_a = o->beta_a * sc, mon->beta_s = o->beta_s * sc;
  mon->have_sd0 = o->sd != NULL;
  mon->phase_var = ph * ph / 3.0;
  for (c = 0; c < mon->nch; c++) {
    const rcb_complex *e = mon->e0 + c * mon->npts;
    double a = rcb_mon_eq19_amp(mon->beta_s, e, mon->npts); /* eq. 19 additive amplitude */
    for (i = 0; i < mon->npts; i++) {
      size_t p = c * mon->npts + i;
      double ae = cabs(e[i]), vr, vt;
      mon->e0norm2 += creal(e[i] * conj(e[i]));
      mon->u[p] = ae > 0 ? e[i] / ae : 1.0;
      if (o->sd) {
        double s = o->sd[p] * sc;
        if (!(o->sd[p] > 0) || !isfinite(s))
          return rcb_mon_fail(mon, RCB_ERR_ARG, "opts.sd: channel %zu point %zu: sd = %g, "
                              "expected finite > 0", c + 1, i + 1, o->sd[p]);
        vr = vt = s * s;
        mon->sd0[p] = s;
      } else {
        eq19_var(mon->beta_a, a, mon->phase_var, noise_modulus(mon, p, ae), &vr, &vt);
        if (mon->reweight && mon->h0abs[p] > 0) /* the model's frame */
          mon->u[p] = (e[i] + CMPLX(mon->rbase[2 * p], mon->rbase[2 * p + 1])) / mon->h0abs[p];
      }
      if (!(vr > 0) || !(vt > 0))
        return rcb_mon_fail(mon, RCB_ERR_ARG, "noise: channel %zu point %zu has zero standard "
                            "deviation (commissioning value 0 and beta_s = 0); give beta_s > 0 "
                            "or opts.sd", c + 1, i + 1);
      mon->sd_new_rad[p] = sqrt(vr);
      mon->e0abs[p] = ae;
      mon->var0[2 * p] = vr, mon->var0[2 * p + 1] = vt;
      mon->winv[2 * p] = 1.0 / sqrt(vr * f0);
      mon->winv[2 * p + 1] = 1.0 / sqrt(vt * f0);
    }
  }
  for (i = 0; i < mon->npt; i++) mon->floor2 += mon->sd_new_rad[i] * mon->sd_new_rad[i];
  return RCB_OK;
}

rcb_status rcb_monitor_noise_scale(const rcb_meas *setup, const rcb_complex *values, size_t nrep,
                                   const rcb_monitor_opts *o, rcb_monitor_noise *out) {
  size_t nch, npts, c, i, r;
  double chi2 = 0.0, ph;
  char err[160];
  rcb_monitor_opts od;
  if (!setup || !values || !o || !out || nrep < 2) return RCB_ERR_ARG;
  od = *o, od.noise_scale = 0.0; /* the declared noise, whatever scale o carries */
  if (noise_opts(&od, err, sizeof err)) return RCB_ERR_ARG;
  nch = rcb_meas_channel_count(setup), npts = rcb_meas_point_count(setup);
  if (!nch || !npts) return RCB_ERR_ARG;
  ph = o->phase_deg * RCB_MON_DEG;
  for (c = 0; c < nch; c++) {
    double a = 0.0;
    for (i = 0; i < npts && !o->sd; i++) { /* the additive amplitude of the average */
      rcb_complex m = 0.0;
      for (r = 0; r < nrep; r++) m += values[(r * nch + c) * npts + i];
      m /= (double)nrep;
      a += creal(m * conj(m));
    }
    a = o->beta_s / 100.0 * sqrt(a) / (double)npts;
    for (i = 0; i < npts; i++) {
      rcb_complex m = 0.0, u;
      double ae, vr, vt;
      for (r = 0; r < nrep; r++) m += values[(r * nch + c) * npts + i];
      m /= (double)nrep;
      if (!isfinite(creal(m)) || !isfinite(cimag(m))) return RCB_ERR_ARG;
      ae = cabs(m);
      u = ae > 0 ? m / ae : 1.0;
      if (o->sd) {
        if (!(o->sd[c * npts + i] > 0)) return RCB_ERR_ARG;
        vr = vt = o->sd[c * npts + i] * o->sd[c * npts + i];
      } else {
        eq19_var(o->beta_a, a, ph * ph / 3.0, ae, &vr, &vt);
      }
      if (!(vr > 0) || !(vt > 0) || !isfinite(vr + vt)) return RCB_ERR_ARG;
      for (r = 0; r < nrep; r++) { /* the deviation in the average's frame */
        rcb_complex d = (values[(r * nch + c) * npts + i] - m) * conj(u);
        chi2 += creal(d) * creal(d) / vr + cimag(d) * cimag(d) / vt;
      }
    }
  }
  out->chi2 = chi2;
  out->dof = 2.0 * (double)nch * (double)npts * (double)(nrep - 1);
  out->scale = sqrt(chi2 / out->dof);
  return RCB_OK;
}

/* ---- the baseline model, its fit of the tracked parameters ---- */

static rcb_status baseline(rcb_monitor *mon, const rcb_model *base, const rcb_monitor_opts *o) {
  rcb_status st = rcb_model_clone(&mon->model, base, &mon->alloc);
  size_t k, p;
  if (!st) st = rcb_model_finalize(mon->model);
  if (st) return rcb_mon_fail(mon, st, "baseline model: %s",
                              mon->model ? rcb_model_errmsg(mon->model) : rcb_status_str(st));
  if ((st = rcb_fit_create(&mon->fit, mon->model, mon->setup, &mon->alloc)) ||
      (st = rcb_fit_set_solver(mon->fit, RCB_SOLVER_BANDED)) ||
      (st = rcb_fit_set_scale(mon->fit, RCB_SCALE_COMPLEX)) ||
      (st = rcb_fit_set_uncertainty(mon->fit, 0)))
    return rcb_mon_fail(mon, st, "set-up against the baseline: %s",
                        mon->fit ? rcb_fit_errmsg(mon->fit) : rcb_status_str(st));
  for (k = 0; k < mon->nt; k++) {
    const rcb_monitor_param *t = &o->tracked[k];
    if (!t->name || strlen(t->name) >= RCB_MONITOR_NAME)
      return rcb_mon_fail(mon, RCB_ERR_ARG, "tracked parameter %zu: no name or too long", k + 1);
    snprintf(mon->tname[k], sizeof mon->tname[k], "%s", t->name);
    mon->tlo[k] = t->lo, mon->thi[k] = t->hi;
    if ((st = rcb_model_get_param(mon->model, t->name, &mon->t0[k])))
      return rcb_mon_fail(mon, st, "tracked parameter '%s': %s", t->name,
                          rcb_model_errmsg(mon->model));
    if ((st = rcb_fit_add_param(mon->fit, t->name, t->lo, t->hi, 0)))
      return rcb_mon_fail(mon, st, "tracked parameter '%s': %s", t->name,
                          rcb_fit_errmsg(mon->fit));
  }
  if ((st = rcb_fit_residuals(mon->fit, mon->rbase)))
    return rcb_mon_fail(mon, st, "baseline model on the set-up: %s", rcb_fit_errmsg(mon->fit));
  if (rcb_fit_residual_count(mon->fit) != mon->n)
    return rcb_mon_fail(mon, RCB_ERR_STATE, "residual layout: %zu, expected %zu",
                        rcb_fit_residual_count(mon->fit), mon->n);
  for (p = 0; p < mon->npt; p++)
    mon->h0abs[p] = cabs(mon->e0[p] + CMPLX(mon->rbase[2 * p], mon->rbase[2 * p + 1]));
  return RCB_OK;
}

/* ---- columns ---- */


/* The candidates the monitor tracks: effects with parameters; by default
 * the catalogue of issue #4, not the shaft elements of issue #23 (a crack is
 * a diagnosis' finding, and one candidate per element would double the
 * columns of every update). The measurement chain (issue #34: a drifting
 * probe named as the sensor, not read as the machine) when opts.effects
 * asks for it (rcbtool monitor does by default; the noise taken at the
 * model's modulus, noise_modulus, is what lets the gains hold at the users'
 * size): the catalogue is on the complex scale, so each measured sensor's
 * candidate is its gain and phase (RCB_EFFECT_SENSOR_GAIN); a sign flipped
 * is its gain at -1 (the gain's column is exact: the model's values scale
 * linearly with it; cand_space mirrors its range), and a swap of a
 * station's x and y probes (RCB_EFFECT_SENSOR_SWAP) is made linear by
 * rcb_mon_cand_desc. */
static int wanted(const rcb_diag_cand_desc *c, unsigned mask) {
  if (c->refit_only || !c->np) return 0;
  if (mask) return (mask >> (unsigned)c->effect) & 1u;
  return !c->chain && c->effect < RCB_EFFECT_ELEMENT_STIFFNESS;
}

/* The diagnosis has a swap as a fixed edit (no parameter, refitted only).
 * The monitor's update is linear, so here a swap has one parameter, the
 * fraction swapped: each of the two probes reads (1 - s) its own response
 * + s the other's (0: as wired, 1: exchanged; rcb_fit_swap_column, exact).
 * A swap is whole: its plausible range is [0.5, 1.5], so a fraction whose
 * 95 % interval lies under a half (another effect's leakage into the
 * direction) ranks after every plausible candidate. */
void rcb_mon_cand_desc(const rcb_diag *d, size_t i, rcb_diag_cand_desc *c) {
  rcb_diag_catalogue_get(d, i, c);
  if (!c->swap_a) return;
  c->np = 1, c->refit_only = 0;
  c->params = c->pname[0] = "fraction";
  c->lo[0] = 0.5, c->hi[0] = 1.5, c->logp[0] = 0;
}

/* A candidate whose columns are not a batched adjoint sweep of the base
 * model: one with DOFs of its own (a pedestal: a sweep of its model) or of
 * the measurement chain (a sensor: the base model's own values scaled,
 * rcb_fit_chain_jacobian, no sweep). */
static int own_columns(const rcb_diag_cand_desc *c) { return c->adds_dofs || c->chain; }

/* A fit of candidate model cm with its parameters (complex scale, as the base). */
static rcb_status cand_fit(rcb_monitor *mon, rcb_model *cm, const rcb_diag_cand_desc *c,
                           rcb_fit **out) {
  rcb_status st = rcb_fit_create(out, cm, mon->setup, &mon->alloc);
  size_t k;
  if (!st) st = rcb_fit_set_solver(*out, RCB_SOLVER_BANDED); /* no KLU: every byte via the hooks */
  if (!st) st = rcb_fit_set_scale(*out, RCB_SCALE_COMPLEX);
  if (!st) st = rcb_fit_set_uncertainty(*out, 0);
  for (k = 0; !st && k < c->np; k++) st = rcb_fit_add_param(*out, c->pname[k], c->lo[k], c->hi[k], 0);
  if (st)
    return rcb_mon_fail(mon, st, "%s: %s", c->desc, *out ? rcb_fit_errmsg(*out) : "no memory");
  return RCB_OK;
}

/* The candidates' columns into J (n x ncol, after the tracked ones): one
 * batched adjoint sweep of the base model for those with its DOFs, a sweep
 * of their own model for the others (a pedestal). J NULL (a commissioning
 * image): their neutral values and derivative matrices only. */
static rcb_status cand_columns(rcb_monitor *mon, rcb_diag *d, const col_plan *pl, double *J) {
  size_t ndz = 0, j, k, ndof = rcb_model_dof_count(mon->model), batch = 0;
  rcb_fit_dz *dz = rcb_mon_alloc(mon, pl->ncol ? pl->ncol : 1, sizeof *dz);
  rcb_status st = RCB_OK;
  if (!dz) return rcb_mon_fail(mon, RCB_ERR_NOMEM, "out of memory (candidate columns)");
  for (j = 0; !st && j < pl->ncand; j++) {
    rcb_diag_cand_desc c;
    rcb_model *cm = NULL;
    rcb_fit *cf = NULL;
    rcb_mon_cand_desc(d, pl->cand[j], &c);
    if (c.chain) { /* a sensor's gain and phase at neutral (1, 0 rad), a swap at 0 */
      double *Jc = J ? J + mon->n * pl->col[j] : NULL;
      for (k = 0; k < c.np; k++)
        pl->neutral[pl->col[j] + k] = rcb_fit_param_is_chain(c.pname[k]) == RCB_CHAIN_GAIN;
      if (Jc && c.swap_a) st = rcb_fit_swap_column(mon->fit, c.swap_a, c.swap_b, Jc);
      else if (Jc) st = rcb_fit_chain_jacobian(mon->fit, c.pname, c.np, Jc);
      if (st) rcb_mon_fail(mon, st, "%s: %s", c.desc, rcb_fit_errmsg(mon->fit));
      continue;
    }
    if ((st = rcb_diag_catalogue_model(d, pl->cand[j], mon->model, &cm))) {
      rcb_mon_fail(mon, st, "%s", rcb_diag_errmsg(d));
      break;
    }
    st = cand_fit(mon, cm, &c, &cf);
    for (k = 0; !st && k < c.np; k++)
      if ((st = rcb_model_get_param(cm, c.pname[k], pl->neutral + pl->col[j] + k)))
        rcb_mon_fail(mon, st, "%s: %s", c.desc, rcb_model_errmsg(cm));
    if (!st && pl->own[j] == (rcb_model_dof_count(cm) == ndof))
      st = rcb_mon_fail(mon, RCB_ERR_STATE, "%s: its model's DOFs are not as the catalogue "
                        "states", c.desc);
    if (!st && !pl->own[j]) {
      if ((st = rcb_fit_dz_get(cf, &mon->alloc, dz + ndz)))
        rcb_mon_fail(mon, st, "%s: %s", c.desc, rcb_fit_errmsg(cf));
      else
        ndz += c.np, batch++;
    } else if (!st && J) {
      if ((st = rcb_fit_jacobian(cf, 1, J + mon->n * pl->col[j])))
        rcb_mon_fail(mon, st, "%s: %s", c.desc, rcb_fit_errmsg(cf));
      else if (rcb_fit_residual_count(cf) != mon->n)
        st = rcb_mon_fail(mon, RCB_ERR_STATE, "%s: residual layout differs", c.desc);
    }
    rcb_fit_destroy(cf);
    rcb_model_destroy(cm);
  }
  if (!st && ndz && J) {
    /* the batch's columns are contiguous after the tracked ones (plan order) */
    if ((st = rcb_fit_jacobian_dz(mon->fit, dz, ndz, J + mon->n * mon->nt)))
      rcb_mon_fail(mon, st, "candidate columns: %s", rcb_fit_errmsg(mon->fit));
  }
  (void)batch;
  if (!st && mon->relin && ndz) { /* kept for the low-rank joint re-linearisation */
    mon->cdz = dz, mon->ncdz = ndz;
    return RCB_OK;
  }
  rcb_fit_dz_free(&mon->alloc, dz, ndz);
  rcb_free(&mon->alloc, dz);
  return st;
}

/* Which candidates, their columns: the batched (same DOFs) ones first. */
static rcb_status plan(rcb_monitor *mon, rcb_diag *d, unsigned mask, col_plan *pl) {
  size_t nc = rcb_diag_catalogue_count(d), i, pass;
  pl->cand = rcb_mon_alloc(mon, nc ? nc : 1, sizeof *pl->cand);
  pl->col = rcb_mon_alloc(mon, nc ? nc : 1, sizeof *pl->col);
  pl->own = rcb_mon_alloc(mon, nc ? nc : 1, sizeof *pl->own);
  if (!pl->cand || !pl->col || !pl->own)
    return rcb_mon_fail(mon, RCB_ERR_NOMEM, "out of memory (catalogue)");
  pl->ncol = mon->nt;
  for (pass = 0; pass < 2; pass++)
    for (i = 0; i < nc; i++) {
      rcb_diag_cand_desc c;
      rcb_mon_cand_desc(d, i, &c);
      if (!wanted(&c, mask) || own_columns(&c) != (int)pass) continue;
      pl->own[pl->ncand] = own_columns(&c);
      pl->cand[pl->ncand] = i;
      pl->col[pl->ncand++] = pl->ncol;
      pl->ncol += c.np;
    }
  if (!(pl->neutral = rcb_mon_alloc(mon, pl->ncol ? pl->ncol : 1, sizeof *pl->neutral)))
    return rcb_mon_fail(mon, RCB_ERR_NOMEM, "out of memory (catalogue)");
  return RCB_OK;
}

/* Whiten every column of J (the fit's Re/Im layout) into the radial /
 * tangential frame. */
static void whiten_columns(const rcb_monitor *mon, double *J, size_t ncol) {
  size_t j, p;
  for (j = 0; j < ncol; j++) {
    double *c = J + mon->n * j;
    for (p = 0; p < mon->npt; p++) {
      double complex g = conj(mon->u[p]) * CMPLX(c[2 * p], c[2 * p + 1]);
      c[2 * p] = creal(g) * mon->winv[2 * p];
      c[2 * p + 1] = cimag(g) * mon->winv[2 * p + 1];
    }
  }
}

void rcb_mon_whiten(const rcb_monitor *mon, const rcb_complex *dv, double *r) {
  size_t p;
  for (p = 0; p < mon->npt; p++) {
    double complex g = conj(mon->u[p]) * dv[p];
    r[2 * p] = creal(g) * mon->winv[2 * p];
    r[2 * p + 1] = cimag(g) * mon->winv[2 * p + 1];
  }
}

/* ---- create ---- */

static rcb_status buffers(rcb_monitor *mon) {
  size_t npt = mon->npt, n = mon->n;
  mon->e0 = rcb_mon_alloc(mon, 2 * npt, sizeof *mon->e0);
  mon->h0abs = rcb_mon_alloc(mon, 4 * npt + 5 * n, sizeof *mon->h0abs);
  if (!mon->e0 || !mon->h0abs) return rcb_mon_fail(mon, RCB_ERR_NOMEM, "out of memory (set-up)");
  mon->u = mon->e0 + npt;
  mon->sd_new_rad = mon->h0abs + npt;
  mon->winv = mon->sd_new_rad + npt;
  mon->rbase = mon->winv + n;
  mon->r = mon->rbase + n;
  mon->rm = mon->r + n;
  mon->var0 = mon->rm + n;
  mon->sd0 = mon->var0 + n;
  mon->e0abs = mon->sd0 + npt;
  return RCB_OK;
}

static rcb_status settings(rcb_monitor *mon, const rcb_monitor_opts *o) {
  size_t k;
  mon->alpha = o->alpha > 0 ? o->alpha : 1e-3;
  mon->cusum_k = o->cusum_k > 0 ? o->cusum_k : 0.5;
  mon->cusum_h = o->cusum_h > 0 ? o->cusum_h : 8.0;
  mon->top = o->top ? o->top : RCB_MONITOR_TOP;
  mon->relin = o->relinearise;
  mon->reweight = o->reweight != 0;
  mon->nt = o->ntracked;
  if (!(mon->alpha < 1) || !isfinite(mon->cusum_k) || !isfinite(mon->cusum_h) ||
      o->alpha < 0 || o->cusum_k < 0 || o->cusum_h < 0)
    return rcb_mon_fail(mon, RCB_ERR_ARG, "options: alpha = %g (0 < alpha < 1), cusum_k = %g, "
                        "cusum_h = %g (finite >= 0, 0: default)", o->alpha, o->cusum_k,
                        o->cusum_h);
  if (mon->top > RCB_MONITOR_TOP)
    return rcb_mon_fail(mon, RCB_ERR_ARG, "options: top = %zu, at most %d", mon->top,
                        RCB_MONITOR_TOP);
  if (mon->nt > RCB_MONITOR_MAX_TRACKED || (mon->nt && !o->tracked))
    return rcb_mon_fail(mon, RCB_ERR_ARG, "options: %zu tracked parameters (at most %d, and "
                        "opts.tracked must list them)", mon->nt, RCB_MONITOR_MAX_TRACKED);
  for (k = 0; o->baseline_cov && k < mon->nt; k++) {
    size_t j;
    mon->tbv[k] = o->baseline_cov[k * mon->nt + k];
    if (!(mon->tbv[k] >= 0) || !isfinite(mon->tbv[k]))
      return rcb_mon_fail(mon, RCB_ERR_ARG, "options: baseline_cov[%zu][%zu] = %g: a variance "
                          "must be finite >= 0 (parameter units^2)", k, k, mon->tbv[k]);
    for (j = 0; j < mon->nt; j++) {
      double c = o->baseline_cov[k * mon->nt + j];
      if (!isfinite(c))
        return rcb_mon_fail(mon, RCB_ERR_ARG, "options: baseline_cov[%zu][%zu] = %g: a "
                            "covariance must be finite (parameter units^2)", k, j, c);
      mon->bcov[k * mon->nt + j] = c;
    }
  }
  mon->bcurv = o->baseline_cov && mon->nt > 0;
  /* the allowance's quantile: the baseline's share of false CUSUM alarms is
   * at most alpha per tracked parameter over the baselines' distribution */
  mon->bq = sqrt(rcb_chi2_quantile(1.0 - mon->alpha, 1.0));
  return RCB_OK;
}

/* A commissioning image's rank and basis Q (row-major, as the update reads
 * it) in place of the QR of the columns: in a block of the columns' size,
 * as a full create leaves it (rcb_monitor_memory the same). */
static rcb_status image_q(rcb_monitor *mon, const mon_image *im, size_t ncol) {
  mon->k = im->k;
  if (!(mon->Q = rcb_mon_alloc(mon, mon->n * (ncol ? ncol : 1), sizeof *mon->Q)))
    return rcb_mon_fail(mon, RCB_ERR_NOMEM, "out of memory (rank space)");
  rcb_mon_image_doubles(im, im->g - 8 * mon->n * mon->k, mon->Q, mon->n * mon->k);
  return RCB_OK;
}

static rcb_status commission(rcb_monitor *mon, const rcb_model *base, const rcb_meas *setup,
                             const rcb_monitor_opts *o) {
  rcb_diag *d = NULL;
  mon_image im;
  col_plan pl;
  double *J = NULL;
  size_t c, k;
  rcb_status st;
  memset(&pl, 0, sizeof pl);
  if ((st = settings(mon, o)) || (st = copy_setup(mon, setup)) || (st = buffers(mon)))
    return st;
  for (c = 0; c < mon->nch; c++) {
    rcb_meas_channel_info ci;
    rcb_meas_channel(mon->setup, c, &ci);
    memcpy(mon->e0 + c * mon->npts, ci.data, mon->npts * sizeof *mon->e0);
  }
  if ((st = baseline(mon, base, o)) || (st = noise(mon, o))) return st; /* noise: h0abs */
  if ((st = rcb_diag_create(&d, mon->model, mon->setup, &mon->alloc)))
    st = rcb_mon_fail(mon, st, "catalogue: %s", d ? rcb_diag_errmsg(d) : "out of memory");
  if (!st) st = rcb_diag_set_scale(d, RCB_SCALE_COMPLEX); /* the update's: a sensor's phase */
  for (k = 0; !st && k < mon->nt; k++)
    if ((st = rcb_diag_add_fitted_param(d, mon->tname[k], mon->tlo[k], mon->thi[k], 0)))
      rcb_mon_fail(mon, st, "catalogue: %s", rcb_diag_errmsg(d));
  if (!st && (st = rcb_diag_catalogue(d, mon->model)))
    rcb_mon_fail(mon, st, "catalogue: %s", rcb_diag_errmsg(d));
  if (!st) st = plan(mon, d, o->effects, &pl);
  if (!st && !o->image && !(J = rcb_mon_alloc(mon, mon->n * (pl.ncol ? pl.ncol : 1), sizeof *J)))
    st = rcb_mon_fail(mon, RCB_ERR_NOMEM, "out of memory (%zu x %zu sensitivity columns)",
                      mon->n, pl.ncol);
  if (!st && mon->nt && J && (st = rcb_fit_jacobian(mon->fit, 1, J)))
    rcb_mon_fail(mon, st, "tracked parameters' sensitivities: %s", rcb_fit_errmsg(mon->fit));
  if (!st) st = cand_columns(mon, d, &pl, J);
  if (!st) mon->img_fp = rcb_mon_image_fingerprint(mon, d, &pl, o->effects);
  if (!st && o->image) {
    st = rcb_mon_image_open(mon, o->image, o->image_size, mon->img_fp, pl.ncol, pl.ncand, &im);
    if (!st) st = image_q(mon, &im, pl.ncol);
  } else if (!st) {
    whiten_columns(mon, J, pl.ncol);
    memset(mon->r, 0, mon->n * sizeof *mon->r);
    st = rcb_mon_factor(mon, d, J, pl.ncol);
  }
  if (!st && !(st = rcb_mon_rank_space(mon, d, &pl, J, o->image ? &im : NULL)))
    J = NULL; /* now mon->Q */
  if (!st) {
    mon->y = rcb_mon_alloc(mon, 3 * mon->k + 3 * (mon->ncand ? mon->ncand : 1), sizeof *mon->y);
    if (!mon->y) st = rcb_mon_fail(mon, RCB_ERR_NOMEM, "out of memory (update workspace)");
    else {
      mon->ym = mon->y + mon->k;
      mon->y0 = mon->ym + mon->k;
      mon->pscore = mon->y0 + mon->k;
      mon->gatt = mon->pscore + (mon->ncand ? mon->ncand : 1);
      mon->order = (size_t *)(void *)(mon->gatt + (mon->ncand ? mon->ncand : 1));
    }
  }
  if (!st) {
    size_t W = MON_DRIFT_WINDOW, kr = mon->k;
    mon->dy = rcb_mon_alloc(mon, W * kr + W * RCB_MONITOR_MAX_TRACKED +
                            (W + 1) * (mon->ncand ? mon->ncand : 1) * RCB_MONITOR_MAXP + 2 * kr,
                            sizeof *mon->dy);
    if (!mon->dy) st = rcb_mon_fail(mon, RCB_ERR_NOMEM, "out of memory (drift window)");
    else {
      mon->dth = mon->dy + W * kr;
      mon->ds = mon->dth + W * RCB_MONITOR_MAX_TRACKED;
      mon->dysum = mon->ds + W * (mon->ncand ? mon->ncand : 1) * RCB_MONITOR_MAXP;
      mon->dY = mon->dysum + kr;
      mon->dssum = mon->dY + kr;
      memset(mon->dysum, 0, kr * sizeof *mon->dysum);
      memset(mon->dssum, 0, (mon->ncand ? mon->ncand : 1) * RCB_MONITOR_MAXP * sizeof *mon->dssum);
      mon->rho = mon->navg_inv / (1.0 + mon->navg_inv);
    }
  }
  if (!st) st = rcb_mon_pass_init(mon);
  if (!st) st = rcb_mon_lowrank_init(mon, o->image ? &im : NULL);
  if (!st) st = rcb_mon_adj_init(mon, o->image != NULL);
  if (!st && mon->bcurv) st = rcb_mon_curvature(mon);
  if (!st) {
    size_t dof = mon->k > mon->nt ? mon->k - mon->nt : 0;
    mon->threshold = dof ? rcb_chi2_quantile(1.0 - mon->alpha, (double)dof) : (double)INFINITY;
  }
  rcb_free(&mon->alloc, J);
  rcb_free(&mon->alloc, pl.cand);
  rcb_free(&mon->alloc, pl.col);
  rcb_free(&mon->alloc, pl.own);
  rcb_free(&mon->alloc, pl.neutral);
  rcb_diag_destroy(d);
  return st;
}

rcb_status rcb_monitor_create(rcb_monitor **out, const rcb_model *baseline_model,
                              const rcb_meas *setup, const rcb_monitor_opts *opts,
                              const rcb_allocator *alloc) {
  rcb_allocator a;
  rcb_monitor_opts o0;
  rcb_monitor *mon;
  if (!out) return RCB_ERR_ARG;
  *out = NULL;
  rcb_allocator_init(&a, alloc);
  if (!(mon = rcb_alloc(&a, sizeof *mon))) return RCB_ERR_NOMEM;
  mon->user = a;
  mon->alloc.alloc = count_alloc, mon->alloc.free = count_free, mon->alloc.user = mon;
  mon->held = sizeof *mon;
  *out = mon;
  if (!baseline_model || !setup)
    return rcb_mon_fail(mon, RCB_ERR_ARG, "rcb_monitor_create: baseline model and set-up "
                        "measurement are required");
  if (rcb_model_dof_count(baseline_model) == 0)
    return rcb_mon_fail(mon, RCB_ERR_STATE, "baseline model not finalized (rcb_model_finalize)");
  if (!opts) {
    memset(&o0, 0, sizeof o0);
    opts = &o0;
  }
  return commission(mon, baseline_model, setup, opts);
}
