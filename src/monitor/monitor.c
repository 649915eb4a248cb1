/*
 * rcb_monitor: the update (allocation-free: every buffer was sized by
 * rcb_monitor_create), the getters and destroy. The statistics are stated
 * in rcb_monitor.h; here they are applied in the rank space of the
 * whitened sensitivity columns (y = Q^T r, k values).
 */
#include <cblas.h>
#include <math.h>
#include <string.h>

#include "identify/identify.h"
#include "monitor/monitor_internal.h"

/* A re-linearisation's chord correction below this many standard errors
 * of every tracked parameter ends the iterations (-). */
#define MON_RELIN_TOL 0.05
/* A joint step (joint_gn) of this many standard errors or more for some
 * parameter: the next iteration re-evaluates the columns (Gauss-Newton);
 * under it, on the adjoint path, the next keeps them (a chord step, one
 * plain sweep). */
#define MON_CHORD_SD 1.0
/* A joint step may end without a confirming sweep only where the standard
 * errors, at the rate they moved between the last two evaluations of the
 * columns, would move by less than this share over its last step (-). */
#define MON_SD_TOL 0.01
/* The step, in standard errors (create's) of each of its parameters, of
 * the sweep that prepares a candidate's one-pole model at create
 * (pole_fill): as the low-rank path's check (LR_CAND_STEP), a change well
 * above the sweep's rounding and well below a far-from-linear one. On
 * shaft A's material damping (bench_monitor damping: a change of 2.2e4 of
 * these, 1800 of the update's) the model's prediction from the linear
 * estimate, 640 of the update's standard errors off, landed 16.5 off with
 * the step at 30 to 300, 8 at 1e4. */
#define MON_POLE_STEP 100.0
/* Two-sided 95 % normal quantile. */
#define MON_Z95 1.959963984540054

void rcb_monitor_destroy(rcb_monitor *mon) {
  rcb_allocator a;
  size_t j;
  if (!mon) return;
  a = mon->user;
  rcb_mon_lowrank_free(mon, mon->lr); /* before the candidates: it resets their ep */
  for (j = 0; j < mon->ncand && mon->cand; j++) {
    rcb_fit_adj_destroy(mon->fit, mon->cand[j].adj);
    rcb_free(&mon->alloc, mon->cand[j].pole);
  }
  rcb_free(&mon->alloc, mon->rat);
  if (mon->tdz) rcb_fit_dz_free(&mon->alloc, mon->tdz, mon->nt);
  rcb_free(&mon->alloc, mon->tdz);
  if (mon->cdz) rcb_fit_dz_free(&mon->alloc, mon->cdz, mon->ncdz);
  rcb_free(&mon->alloc, mon->cdz);
  for (j = 0; j < mon->ncand; j++) rcb_free(&mon->alloc, mon->cand[j].est);
  rcb_free(&mon->alloc, mon->cand);
  rcb_free(&mon->alloc, mon->test);
  rcb_free(&mon->alloc, mon->Q);
  rcb_free(&mon->alloc, mon->G);
  rcb_free(&mon->alloc, mon->C);
  rcb_free(&mon->alloc, mon->Cfix);
  rcb_free(&mon->alloc, mon->tres);
  rcb_free(&mon->alloc, mon->rmx);
  rcb_free(&mon->alloc, mon->sw.A);
  rcb_free(&mon->alloc, mon->sw.work);
  rcb_free(&mon->alloc, mon->y);
  rcb_free(&mon->alloc, mon->dy);
  rcb_fit_destroy(mon->fit);
  rcb_model_destroy(mon->model);
  rcb_meas_destroy(mon->setup);
  rcb_free(&mon->alloc, mon->e0);
  rcb_free(&mon->alloc, mon->h0abs);
  rcb_free(&a, mon);
}

const char *rcb_monitor_errmsg(const rcb_monitor *mon) { return mon ? mon->errmsg : "no monitor"; }

static int ready(const rcb_monitor *mon) { return mon && mon->k > 0 && mon->y; }

/* out = Q^T r (k values; Q row-major, read once). */
static void to_rank(const rcb_monitor *mon, const double *r, double *out) {
  size_t a, i, n = mon->n, k = mon->k;
  memset(out, 0, k * sizeof *out);
  for (i = 0; i < n; i++) {
    const double *q = mon->Q + k * i;
    double ri = r[i];
    for (a = 0; a < k; a++) out[a] += q[a] * ri;
  }
}

/* out = Q^T R for the m columns of R (n x m) into out (k x m), both
 * column-major: each column as to_rank, Q read once for all. */
static void to_rank_many(const rcb_monitor *mon, const double *R, size_t m, double *out) {
  size_t a, i, j, n = mon->n, k = mon->k;
  memset(out, 0, k * m * sizeof *out);
  for (i = 0; i < n; i++) {
    const double *q = mon->Q + k * i;
    for (j = 0; j < m; j++) {
      double ri = R[i + n * j], *o = out + k * j;
      for (a = 0; a < k; a++) o[a] += q[a] * ri;
    }
  }
}

/* The same by BLAS (dgemm: Q^T as the k x n column-major matrix it is):
 * the joint step's sweep path, where Q is read once for 1 + nt + np
 * columns (0.5 ms of a 7 ms iteration by the loop above). */
static void to_rank_blas(const rcb_monitor *mon, const double *R, size_t m, double *out) {
  cblas_dgemm(CblasColMajor, CblasNoTrans, CblasNoTrans, (blasint)mon->k, (blasint)m,
              (blasint)mon->n, 1.0, mon->Q, (blasint)mon->k, R, (blasint)mon->n, 0.0, out,
              (blasint)mon->k);
}

static double dot(const double *a, const double *b, size_t n) {
  double s = 0;
  size_t i;
  for (i = 0; i < n; i++) s += a[i] * b[i];
  return s;
}

static rcb_status check_input(rcb_monitor *mon, const rcb_complex *v, const double *sd) {
  size_t p;
  for (p = 0; p < mon->npt; p++) {
    if (!isfinite(creal(v[p])) || !isfinite(cimag(v[p])))
      return rcb_mon_fail(mon, RCB_ERR_ARG, "update %zu: channel %zu point %zu is not finite "
                          "(NaN or infinite value); the update was not taken", mon->updates + 1,
                          p / mon->npts + 1, p % mon->npts + 1);
    if (sd && (!(sd[p] > 0) || !isfinite(sd[p])))
      return rcb_mon_fail(mon, RCB_ERR_ARG, "update %zu: channel %zu point %zu: sd = %g, "
                          "expected finite > 0; the update was not taken", mon->updates + 1,
                          p / mon->npts + 1, p % mon->npts + 1, sd[p]);
  }
  return RCB_OK;
}

/* The tracked parameters back at their baseline values and candidate c's
 * (if any) at their neutral ones. */
void rcb_mon_model_restore(rcb_monitor *mon, const mon_cand *c) {
  size_t k;
  for (k = 0; k < mon->nt; k++) rcb_model_set_param(mon->model, mon->tname[k], mon->t0[k]);
  for (k = 0; c && k < c->np; k++) rcb_model_set_param(mon->model, c->pname[k], c->neutral[k]);
}

/* The model at tracked values t0 + theta and, with c, candidate c's
 * parameters at neutral + s (the caller restores them). */
static rcb_status set_point(rcb_monitor *mon, const double *theta, const mon_cand *c,
                            const double *s) {
  size_t k;
  rcb_status st = RCB_OK;
  for (k = 0; !st && k < mon->nt; k++)
    if ((st = rcb_model_set_param(mon->model, mon->tname[k], mon->t0[k] + theta[k])))
      rcb_mon_fail(mon, st, "re-linearising at %s = %g: %s", mon->tname[k],
                   mon->t0[k] + theta[k], rcb_model_errmsg(mon->model));
  for (k = 0; !st && c && k < c->np; k++)
    if ((st = rcb_model_set_param(mon->model, c->pname[k], c->neutral[k] + s[k])))
      rcb_mon_fail(mon, st, "re-linearising at %s = %g: %s", c->pname[k], c->neutral[k] + s[k],
                   rcb_model_errmsg(mon->model));
  return st;
}

/* out (the fit's Re/Im layout, n values) less base (NULL: a derivative),
 * whitened in place. */
static void whiten_change(const rcb_monitor *mon, double *out, const double *base) {
  size_t p;
  for (p = 0; p < mon->npt; p++) {
    double complex g = conj(mon->u[p]) *
                       CMPLX(out[2 * p] - (base ? base[2 * p] : 0.0),
                             out[2 * p + 1] - (base ? base[2 * p + 1] : 0.0));
    out[2 * p] = creal(g) * mon->winv[2 * p];
    out[2 * p + 1] = cimag(g) * mon->winv[2 * p + 1];
  }
}

/* out = W (m(theta, s) - m(0, 0)) (the whitened change, n values) for
 * tracked values t0 + theta and, with c, candidate c's parameters at
 * neutral + s (c->settable). The parameters stay set: the caller restores
 * them (rcb_mon_model_restore). */
static rcb_status model_resid(rcb_monitor *mon, const double *theta, const mon_cand *c,
                              const double *s, double *out) {
  size_t p;
  rcb_status st = RCB_OK;
  if (mon->lr && (!c || c->ep)) { /* without a sweep */
    rcb_complex *dm = mon->lr->dm;
    if ((st = rcb_mon_lowrank_change(mon, theta, c, s, dm))) return st;
    for (p = 0; p < mon->npt; p++) {
      double complex g = conj(mon->u[p]) * dm[p];
      out[2 * p] = creal(g) * mon->winv[2 * p];
      out[2 * p + 1] = cimag(g) * mon->winv[2 * p + 1];
    }
    return RCB_OK;
  }
  if (!(st = set_point(mon, theta, c, s)) && (st = rcb_fit_residuals(mon->fit, out)))
    rcb_mon_fail(mon, st, "re-linearising at the tracked estimate: %s", rcb_fit_errmsg(mon->fit));
  if (st) {
    rcb_mon_model_restore(mon, c);
    return st;
  }
  whiten_change(mon, out, mon->rbase);
  return RCB_OK;
}

/* ym = Q^T rm: model_resid taken to the rank space. */
static rcb_status model_change(rcb_monitor *mon, const double *theta, const mon_cand *c,
                               const double *s) {
  rcb_status st = model_resid(mon, theta, c, s, mon->rm);
  if (!st) to_rank(mon, mon->rm, mon->ym);
  return st;
}

/* The tracked columns at the re-linearised step th (rank space, into
 * mon->Jx; base = ym(th)): forward differences of one standard error each
 * (nt model evaluations). The reweighted path projects them out of the
 * update's change instead of the baseline's columns (rcb_mon_gls): with
 * the baseline's, the tracked part of the commissioning's noise, shared
 * by every update, leaked beyond the tracked directions in proportion to
 * the tracked change (the columns turn as the parameters move: the ROSS
 * kt_wear series' drift test alarmed at kt -8.5 to -10 %, a ramp the
 * wear made of that shared noise). */
static rcb_status tracked_columns(rcb_monitor *mon, double *th, const double *base) {
  size_t a, i, k = mon->k;
  rcb_status st;
  for (a = 0; a < mon->nt; a++) {
    double keep = th[a], h = mon->tse[a] > 0 ? mon->tse[a] : 1e-6 * fmax(fabs(mon->t0[a]), 1.0);
    double *col = mon->Jx + k * a;
    th[a] += h;
    st = model_change(mon, th, NULL, NULL);
    th[a] = keep;
    if (st) return st;
    for (i = 0; i < k; i++) col[i] = (mon->ym[i] - base[i]) / h;
  }
  mon->jt = 1;
  return RCB_OK;
}

/* The re-linearised tracked step theta (chord iterations re-evaluating the
 * model: theta += E (y - ym(theta)), E the linear estimator; 0 without
 * re-linearisation), at most opts.relinearise of them, stopping once a
 * correction is below MON_RELIN_TOL standard errors for every tracked
 * parameter; on return mon->y holds the change the model at baseline +
 * theta does not explain (y itself without): after a converged correction
 * d, y - ym(theta) - G_t d (the baseline's columns carry so small a step
 * exactly enough), else one more evaluation. On entry theta is the linear
 * estimate and mon->ym its first evaluation (rcb_monitor_update's pass). */
static rcb_status tracked_step(rcb_monitor *mon, double *theta) {
  size_t a, it, i, k = mon->k, nt = mon->nt;
  double d[RCB_MONITOR_MAX_TRACKED];
  rcb_status st;
  int small = 0;
  double *base, th[RCB_MONITOR_MAX_TRACKED];
  mon->jt = 0;
  if (!mon->relin || !nt) return RCB_OK;
  base = mon->rmx + mon->n * (1 + nt + RCB_MONITOR_MAXP); /* rmx: with relinearise */
  for (it = 0; !small && it < mon->relin; it++) {
    if (it && (st = model_change(mon, theta, NULL, NULL))) return st;
    memcpy(base, mon->ym, k * sizeof *base); /* ym at the step before this correction */
    memcpy(th, theta, sizeof th);
    for (i = 0; i < k; i++) mon->ym[i] = mon->y[i] - mon->ym[i];
    small = 1;
    for (a = 0; a < nt; a++) {
      d[a] = dot(mon->test + a * k, mon->ym, k);
      theta[a] += d[a];
      if (!(fabs(d[a]) < MON_RELIN_TOL * mon->tse[a])) small = 0;
    }
  }
  if (small) {
    for (i = 0; i < k; i++) {
      double s = mon->ym[i];
      for (a = 0; a < nt; a++) s -= mon->G[i + k * a] * d[a];
      mon->y[i] = s;
    }
  } else {
    if ((st = model_change(mon, theta, NULL, NULL))) return st;
    for (i = 0; i < k; i++) mon->y[i] -= mon->ym[i];
    memcpy(base, mon->ym, k * sizeof *base);
    memcpy(th, theta, sizeof th);
  }
  if (mon->reweight && (st = tracked_columns(mon, th, base))) return st;
  rcb_mon_model_restore(mon, NULL);
  return RCB_OK;
}

/* The curvature of the tracked steps in the baseline (rcb_monitor.h,
 * sequential detector): a baseline off the truth by d, linearised there,
 * takes a change D of the tracked parameters as the step D - E H[d, D]
 * (E the tracked estimator, H the second derivatives of the model's
 * whitened change in the rank space), so tracked a's step is off by
 * -sum_ij bM[a, i, j] d_i D_j. bM by model re-evaluations at steps h_i
 * (the baseline's standard error, or the change's where that is 0): the
 * mixed differences of E ym, (E ym(h_i e_i + h_j e_j) - E ym(h_i e_i) -
 * E ym(h_j e_j)) / (h_i h_j), ym(0) = 0. */
rcb_status rcb_mon_curvature(rcb_monitor *mon) {
  enum { MT = RCB_MONITOR_MAX_TRACKED };
  double h[MT], p1[MT][MT], th[MT], pij;
  size_t a, i, j, nt = mon->nt, k = mon->k;
  rcb_status st = RCB_OK;
  for (i = 0; i < nt; i++) h[i] = mon->tbv[i] > 0 ? sqrt(mon->tbv[i]) : mon->tse[i];
  memset(th, 0, sizeof th);
  for (i = 0; !st && i < nt; i++) {
    th[i] = h[i];
    if (!(st = model_change(mon, th, NULL, NULL)))
      for (a = 0; a < nt; a++) p1[i][a] = dot(mon->test + a * k, mon->ym, k);
    th[i] = 0;
  }
  for (i = 0; !st && i < nt; i++)
    for (j = i; !st && j < nt; j++) {
      th[i] += h[i], th[j] += h[j];
      if (!(st = model_change(mon, th, NULL, NULL)))
        for (a = 0; a < nt; a++) {
          pij = (dot(mon->test + a * k, mon->ym, k) - p1[i][a] - p1[j][a]) / (h[i] * h[j]);
          mon->bM[(a * MT + i) * MT + j] = mon->bM[(a * MT + j) * MT + i] = pij;
        }
      th[i] = th[j] = 0;
    }
  rcb_mon_model_restore(mon, NULL);
  return st;
}

/* The baseline's share of tracked a's CUSUM allowance: bq standard
 * deviations, over the baselines' distribution (opts.baseline_cov S), of
 * the error the baseline's error makes in a's innovation u: g^T d / sd(u),
 * g_i = sum_j bM[a, i, j] (theta_j - the mean of step j over a's
 * reference), var g^T S g. One baseline error d is shared by every update:
 * while |g^T d| <= bq sqrt(g^T S g) (probability 1 - alpha when the changes
 * keep one direction), u - k - this allowance is below what it is on an
 * exact baseline, and the CUSUM's run length is at least its ARL0. */
static double baseline_allowance(const rcb_monitor *mon, size_t a, const double *theta,
                                 double v) {
  enum { MT = RCB_MONITOR_MAX_TRACKED };
  double g[MT], w = mon->ref_w[a], s2 = 0;
  int fin = isfinite(w);
  size_t i, j, nt = mon->nt;
  if (!mon->bcurv || !(w > 0)) return 0.0;
  for (i = 0; i < nt; i++) {
    g[i] = 0;
    for (j = 0; j < nt; j++)
      g[i] += mon->bM[(a * MT + i) * MT + j] * (theta[j] - (fin ? mon->bref[a * MT + j] / w : 0));
  }
  for (i = 0; i < nt; i++)
    for (j = 0; j < nt; j++) s2 += g[i] * mon->bcov[i * nt + j] * g[j];
  return mon->bq * sqrt(fmax(s2, 0.0) / (fin ? v + 1.0 / w : v));
}

/* The baseline's error in tracked a's change and value (rcb_mon_curvature):
 * a baseline off by d takes the change theta as off by -g^T d, g_i =
 * sum_j bM[a, i, j] theta_j, and the value t0 + theta as off by (e_a -
 * g)^T d; over the baselines' distribution (opts.baseline_cov S) their
 * variances g^T S g (*vc) and (e_a - g)^T S (e_a - g) (*vv), parameter
 * units^2. Without the curvature (no baseline_cov) the value takes S's
 * diagonal alone and the change nothing, as before. On ROSS's kt_wear series
 * from a baseline fitted on log10 magnitudes (sd 60.6 N/m, 13 x the complex
 * fit's), the change interval without this term covered the true change in
 * 68 of 101 updates (issue #34 item 4). */
static void baseline_share(const rcb_monitor *mon, size_t a, const double *theta, double *vc,
                           double *vv) {
  enum { MT = RCB_MONITOR_MAX_TRACKED };
  double g[MT], h[MT];
  size_t i, j, nt = mon->nt;
  *vc = 0.0, *vv = mon->tbv[a];
  if (!mon->bcurv) return;
  for (i = 0; i < nt; i++) {
    g[i] = 0;
    for (j = 0; j < nt; j++) g[i] += mon->bM[(a * MT + i) * MT + j] * theta[j];
    h[i] = (i == a) - g[i];
  }
  *vv = 0.0;
  for (i = 0; i < nt; i++)
    for (j = 0; j < nt; j++) {
      *vc += g[i] * mon->bcov[i * nt + j] * g[j];
      *vv += h[i] * mon->bcov[i * nt + j] * h[j];
    }
  *vc = fmax(*vc, 0.0), *vv = fmax(*vv, 0.0);
}

/* The self-starting CUSUM's input for tracked parameter a with step theta
 * (parameter units) and standard error se (with the commissioning's share):
 * u = (theta - m) / sqrt(v + 1 / W), m and W the reference's weighted mean
 * and weight before this update, v = se^2 / (1 + 1/N) the update's own
 * variance (N: setup_averages). On the first update the commissioning
 * itself is the reference: step 0 with variance se^2 (1/N) / (1 + 1/N)
 * (infinite weight for a noise-free reference, when u = theta / se: the
 * plain CUSUM). 0 when there is no reference yet (the first update after
 * rcb_monitor_reset_cusum). */
static double innovation(rcb_monitor *mon, size_t a, double theta, double se, double *v) {
  double nu = mon->navg_inv, w;
  *v = se * se / (1.0 + nu);
  if (!mon->ref_started) {
    mon->ref_w[a] = nu > 0 ? 1.0 / (*v * nu) : (double)INFINITY;
    mon->ref_sum[a] = 0;
    memset(mon->bref + a * RCB_MONITOR_MAX_TRACKED, 0, sizeof(double) * RCB_MONITOR_MAX_TRACKED);
  }
  w = mon->ref_w[a];
  if (!(w > 0)) return 0.0;
  return (theta - mon->ref_sum[a] / w) / sqrt(*v + 1.0 / w);
}

static void tracked_result(rcb_monitor *mon, const double *theta, const double *sev,
                           rcb_monitor_result *res) {
  size_t a;
  res->ntracked = mon->nt;
  res->cusum_alarm = 0;
  for (a = 0; a < mon->nt; a++) {
    rcb_monitor_tracked *t = &res->tracked[a];
    double se = sev[a], v, u = innovation(mon, a, theta[a], se, &v),
           kb = mon->cusum_k + baseline_allowance(mon, a, theta, v), vc, vv, sc;
    baseline_share(mon, a, theta, &vc, &vv);
    sc = sqrt(se * se + vc);
    t->value = mon->t0[a] + theta[a];
    t->stderr_ = se;
    t->abs_stderr = sqrt(se * se + vv);
    t->ci_lo = t->value - MON_Z95 * t->abs_stderr, t->ci_hi = t->value + MON_Z95 * t->abs_stderr;
    t->change = theta[a];
    t->change_lo = theta[a] - MON_Z95 * sc, t->change_hi = theta[a] + MON_Z95 * sc;
    t->z = theta[a] / se;
    t->u = u;
    mon->cus_up[a] = fmax(0.0, mon->cus_up[a] + u - kb);
    mon->cus_dn[a] = fmax(0.0, mon->cus_dn[a] - u - kb);
    t->cusum_allow = kb;
    t->cusum_up = mon->cus_up[a], t->cusum_down = mon->cus_dn[a];
    t->cusum_alarm = t->cusum_up > mon->cusum_h ? 1 : t->cusum_down > mon->cusum_h ? -1 : 0;
    t->out_of_range = t->value < mon->tlo[a] || t->value > mon->thi[a];
    if (t->cusum_alarm) res->cusum_alarm = 1, mon->ref_frozen[a] = 1;
    /* in control: the step joins the reference (not while the instant test
     * fires: the step is then fitted jointly with a candidate) */
    if (!mon->ref_frozen[a] && !res->alarm) {
      size_t j;
      mon->ref_sum[a] += theta[a] / v, mon->ref_w[a] += 1.0 / v;
      for (j = 0; mon->bcurv && j < mon->nt; j++)
        mon->bref[a * RCB_MONITOR_MAX_TRACKED + j] += theta[j] / v;
    }
  }
  mon->ref_started = 1;
}

/* a ranks before b: smaller p-value, compared as logarithms (the p-values
 * of strong effects underflow to 0 together); then the larger score. */
static int before(const rcb_monitor *mon, size_t a, size_t b) {
  double pa = mon->pscore[a], pb = mon->pscore[b];
  if (mon->cand[a].implausible != mon->cand[b].implausible) return !mon->cand[a].implausible;
  if (pa != pb) return pa < pb;
  return mon->cand[a].score_now > mon->cand[b].score_now;
}

/* Is some parameter's 95 % interval, neutral + size +- 1.96 se, wholly
 * outside the catalogue's plausible range? */
static int implausible(const mon_cand *c) {
  size_t a;
  for (a = 0; a < c->np; a++) {
    double v = c->neutral[a] + c->size_now[a], h = MON_Z95 * c->se_now[a];
    if (v + h < c->lo[a] || v - h > c->hi[a]) return 1;
  }
  return 0;
}

/* The second place to the candidate at place t (mon->order), the others
 * between keeping their order. */
static void to_second(rcb_monitor *mon, size_t t) {
  size_t keep = mon->order[t];
  if (t < 2) return;
  memmove(mon->order + 2, mon->order + 1, (t - 1) * sizeof *mon->order);
  mon->order[1] = keep;
}

/* The second place goes to the first's closest rival: of the other nsc
 * scored candidates (mon->order, the first ranked), the one with the
 * lowest BIC change -score + dof ln n (rcb_mon_bic), the implausible ones
 * only when the first is; the rest keep their order. rcb_monitor_named
 * tells the first apart from it, hence from every candidate. Ranked by p
 * alone, the second was often not the closest: a 2- or 3-dof runner-up
 * pays 1-2 ln n more, so the first was "told apart" from it while a 1-dof
 * candidate behind it, the truth, was within 10 (ROSS drift of B4 kyy,
 * eq. 19: sensor C.A.x's gain 7.89 told apart from B4's damping, 2 dof,
 * 6.47, with B4 kyy third at 3.82), and a 3-dof first was "told apart"
 * from 1-dof runners-up whose BIC was lower than its own. */
static void rival_second(rcb_monitor *mon, size_t nsc) {
  size_t t, best = 0;
  double bb = 0;
  int any = mon->cand[mon->order[0]].implausible;
  for (t = 1; t < nsc; t++) {
    const mon_cand *c = &mon->cand[mon->order[t]];
    double b = rcb_mon_bic(mon, c->score_now, c->dof);
    if ((any || !c->implausible) && (!best || b < bb)) best = t, bb = b;
  }
  to_second(mon, best);
}

/* res->top from mon->order. */
static void fill_top(const rcb_monitor *mon, rcb_monitor_result *res) {
  size_t t, a;
  for (t = 0; t < res->ntop; t++) {
    const mon_cand *c = &mon->cand[mon->order[t]];
    rcb_monitor_candidate *o = &res->top[t];
    o->index = mon->order[t];
    o->effect = c->effect;
    o->np = c->np;
    o->score = c->score_now;
    o->dof = c->dof;
    o->p_value = exp(mon->pscore[mon->order[t]]);
    o->implausible = c->implausible;
    for (a = 0; a < c->np; a++) {
      double se = c->se_now[a];
      o->size[a] = c->size_now[a];
      o->ci_lo[a] = o->size[a] - MON_Z95 * se;
      o->ci_hi[a] = o->size[a] + MON_Z95 * se;
    }
  }
}

/* The test half of the one naming rule (rcb_monitor_named): res->apart_p,
 * the largest p over the first's rivals (rival_second's set) of the test
 * that the first adds to the rival's fit (rcb_mon_adds), only while the
 * BIC half holds. A rival the first outscores by more than the test's
 * quantile is rejected whatever the joint fit (it explains at least the
 * first's score): its p is bounded by the gap's, with no QR. The rival
 * the data do not reject becomes the second, so the text names it. */
static rcb_status apart(rcb_monitor *mon, int gls, size_t nsc, rcb_monitor_result *res) {
  const mon_cand *a = &mon->cand[mon->order[0]];
  double q, worst = 0; /* 0: no rival (every other implausible, the first not) */
  size_t t, wt = 0;
  int any = a->implausible;
  rcb_status st;
  res->apart_p = (double)NAN;
  if (res->ntop < 2 || !rcb_mon_bic_apart(mon, res)) return RCB_OK;
  q = rcb_chi2_quantile(1.0 - RCB_MONITOR_APART_ALPHA, (double)a->dof);
  for (t = 1; t < nsc; t++) {
    const mon_cand *c = &mon->cand[mon->order[t]];
    double gap = a->score_now - c->score_now, p;
    if (!any && c->implausible) continue;
    if (gap > q) p = rcb_chi2_sf(gap, (double)a->dof);
    else if ((st = rcb_mon_adds(mon, gls, a, c, &p))) return st;
    if (p > worst) worst = p, wt = t;
  }
  res->apart_p = worst;
  if (worst >= RCB_MONITOR_APART_ALPHA && wt > 1) {
    to_second(mon, wt);
    fill_top(mon, res);
  }
  return RCB_OK;
}

/* Scores and sizes (on the reweighted path) were left in the candidates
 * by the caller when gls != 0. */
static rcb_status candidates(rcb_monitor *mon, int gls, rcb_monitor_result *res) {
  size_t j, a, k = mon->k, nsc = 0, t;
  for (j = 0; j < mon->ncand; j++) {
    mon_cand *c = &mon->cand[j];
    if (!c->dof) continue;
    for (a = 0; !gls && a < c->dof; a++) {
      double z = dot(c->dir + a * k, mon->y0, k);
      if (!a) c->score_now = 0;
      c->score_now += z * z;
    }
    for (a = 0; !gls && a < c->np; a++)
      c->size_now[a] = dot(c->est + a * k, mon->y0, k), c->se_now[a] = c->se[a];
    c->implausible = implausible(c);
    mon->pscore[j] = rcb_mon_chi2_logsf(c->score_now, (double)c->dof);
    mon->order[nsc++] = j;
  }
  /* partial selection sort: the best mon->top first */
  res->ntop = nsc < mon->top ? nsc : mon->top;
  for (t = 0; t < res->ntop; t++) {
    size_t best = t;
    for (j = t + 1; j < nsc; j++)
      if (before(mon, mon->order[j], mon->order[best])) best = j;
    if (best != t) {
      size_t s = mon->order[t];
      mon->order[t] = mon->order[best], mon->order[best] = s;
    }
  }
  if (res->ntop >= 2) rival_second(mon, nsc);
  fill_top(mon, res);
  return apart(mon, gls, nsc, res);
}

/* Paper's error %, change % and the noise floor % of this measurement. */
static void errors(const rcb_monitor *mon, const rcb_complex *v, rcb_monitor_result *res) {
  double em = 0, ec = 0, ee = 0, fl = mon->floor2;
  size_t p;
  for (p = 0; p < mon->npt; p++) {
    double av = cabs(v[p]), dm = mon->h0abs[p] - av, dc = mon->e0abs[p] - av;
    em += dm * dm, ec += dc * dc, ee += av * av;
  }
  ee = ee > 0 ? sqrt(ee) : 1.0;
  res->error_pct = 100.0 * sqrt(em) / ee;
  res->change_pct = 100.0 * sqrt(ec) / ee;
  res->floor_pct = 100.0 * sqrt(fl) / ee;
}

/* The tracked step beyond the re-linearised one, and its standard errors:
 * alone, or, once the instant test has fired, fitted jointly with the best
 * candidate (a new effect left out would bias the trend). */
static void tracked_rest(const rcb_monitor *mon, int gls, const rcb_monitor_result *res,
                         double *theta, double *dth, double *se) {
  const mon_cand *c = res->alarm && res->ntop ? &mon->cand[res->top[0].index] : NULL;
  size_t a, k = mon->k;
  for (a = 0; a < mon->nt; a++) {
    if (c) theta[a] = 0; /* the joint fit is from the baseline, as the candidates' */
    if (c && gls) dth[a] = c->th_now[a], se[a] = c->set_now[a];
    else if (c) dth[a] = dot(c->test_t + a * k, mon->y0, k), se[a] = c->se_t[a];
    else if (!gls) dth[a] = dot(mon->test + a * k, mon->y, k), se[a] = mon->tse[a];
  }
}

/* A joint Gauss-Newton step from w = mon->z and the columns mon->Jx (k x
 * p, rank space), both taken to this update's metric on the reweighted
 * path (U^-T), by the small QR: x += R^-1 Qa^T w, sd the row norms of
 * R^-1. *ok and *step as joint_gn's. */
static rcb_status gn_step(rcb_monitor *mon, int gls, size_t p, double *x, double *sd, int *ok,
                          double *step) {
  size_t a, k = mon->k;
  double qz[RCB_MONITOR_MAX_TRACKED + RCB_MONITOR_MAXP], dx[RCB_MONITOR_MAX_TRACKED +
                                                            RCB_MONITOR_MAXP];
  double *w = mon->z, *J = mon->Jx;
  rcb_status st;
  *ok = 0, *step = 0.0;
  if (gls && (rcb_mon_gls_solve(mon, w, 1) || rcb_mon_gls_solve(mon, J, p)))
    return rcb_mon_fail(mon, RCB_ERR_LAPACK, "re-linearising the joint step: triangular "
                        "solve failed");
  memcpy(mon->sw.A, J, k * p * sizeof *J);
  if ((st = rcb_mon_small_qr(mon, &mon->sw, k, p, ok)) || !*ok) return st;
  (void)rcb_mon_gls_explained(&mon->sw, w, k, 0, p, qz);
  rcb_mon_gls_step(&mon->sw, qz, p, 0, p, dx, sd);
  for (a = 0; a < p; a++) {
    x[a] += dx[a];
    if (!(fabs(dx[a]) < MON_RELIN_TOL * sd[a]) && *ok != 4) *ok = 2; /* not converged yet */
    if (!(fabs(dx[a]) < MON_CHORD_SD * sd[a])) *ok = 4; /* nor near: fresh columns next */
    *step = fmax(*step, fabs(dx[a]) / sd[a]);
  }
  if (!isfinite(*step)) *ok = 4;
  return RCB_OK;
}

/* The joint Gauss-Newton step at x (nt + np: tracked steps, candidate c's
 * sizes): w = y0 - ym(x) and the columns of ym at x by forward differences
 * (steps of a tenth of each standard error, rank space), both taken to
 * this update's metric on the reweighted path (U^-T), then the small QR:
 * x += R^-1 Qa^T w, sd the row norms of R^-1. 1 + nt + np model sweeps,
 * or with c->adj one adjoint sweep (fresh) or one plain sweep reusing the
 * last columns (a chord step). *ok = 0 when the model refused a value or a
 * column is dependent, 4 when some step was MON_CHORD_SD standard errors
 * or more, 2 when MON_RELIN_TOL or more, else 1; *step the largest step
 * in standard errors. */
static rcb_status joint_gn(rcb_monitor *mon, const mon_cand *c, int gls, int fresh, double *x,
                           double *sd, int *ok, double *step) {
  size_t a, i, k = mon->k, nt = mon->nt, p = nt + c->np;
  double *w = mon->z, *J = mon->Jx, *Rm = mon->rmx, *Ym = Rm + mon->n * (1 + p),
         h[RCB_MONITOR_MAX_TRACKED + RCB_MONITOR_MAXP];
  rcb_status st;
  *ok = 0, *step = 0.0;
  if (c->adj) {
    /* the first iteration: one adjoint sweep, the change and its columns at
     * x; the later ones: the change by a plain sweep, the columns kept
     * (chord steps from a point already near the solution) */
    if (set_point(mon, x, c, x + nt)) return RCB_OK;
    if (fresh) {
      if (rcb_fit_adj_run(mon->fit, c->adj, Rm + mon->n) || rcb_fit_last_residuals(mon->fit, Rm))
        return RCB_OK;
      whiten_change(mon, Rm, mon->rbase);
      for (a = 0; a < p; a++) whiten_change(mon, Rm + mon->n * (1 + a), NULL);
      to_rank_many(mon, Rm, 1 + p, Ym);
    } else {
      if (rcb_fit_residuals(mon->fit, Rm)) return RCB_OK;
      whiten_change(mon, Rm, mon->rbase);
      to_rank(mon, Rm, Ym);
    }
    for (i = 0; i < k; i++) w[i] = mon->y0[i] - Ym[i];
    memcpy(J, Ym + k, k * p * sizeof *J);
  } else {
    /* the 1 + p evaluations first, then Q read once for their projections */
    if (model_resid(mon, x, c, x + nt, Rm)) return RCB_OK;
    for (a = 0; a < p; a++) {
      double keep = x[a];
      h[a] = 0.1 * sd[a];
      x[a] += h[a];
      st = model_resid(mon, x, c, x + nt, Rm + mon->n * (1 + a));
      x[a] = keep;
      if (st) return RCB_OK;
    }
    to_rank_many(mon, Rm, 1 + p, Ym);
    for (i = 0; i < k; i++) w[i] = mon->y0[i] - Ym[i];
    for (a = 0; a < p; a++)
      for (i = 0; i < k; i++) J[i + k * a] = (Ym[i + k * (1 + a)] - mon->y0[i] + w[i]) / h[a];
  }
  return gn_step(mon, gls, p, x, sd, ok, step);
}

/* The baseline's whitened columns of the joint step (the tracked ones,
 * then candidate c's) on the residuals, Q G, into W (n x p). */
static void pole_columns(rcb_monitor *mon, const mon_cand *c, size_t p, double *W) {
  size_t a, k = mon->k, nt = mon->nt;
  for (a = 0; a < p; a++)
    memcpy(mon->Jx + k * a, mon->G + k * (a < nt ? a : c->col + a - nt), k * sizeof *mon->Jx);
  cblas_dgemm(CblasColMajor, CblasTrans, CblasNoTrans, (blasint)mon->n, (blasint)p, (blasint)k,
              1.0, mon->Q, (blasint)k, mon->Jx, (blasint)k, 0.0, W, (blasint)mon->n);
}

/* Point q's value of whitened column a of W (n x p), unwhitened (complex). */
static double complex unw(const rcb_monitor *mon, const double *W, size_t q, size_t a) {
  const double *w = W + 2 * q + mon->n * a;
  return CMPLX(w[0] / mon->winv[2 * q], w[1] / mon->winv[2 * q + 1]);
}

/* The one-pole model's coefficient per point, gam (Re, Im), from the
 * whitened change R at x0 and the baseline columns W (n x p): g = 1 / r -
 * 1 / v, r the change and v = W x0 the linear one (unwhitened, complex);
 * 0 (linear) where a part is left out or the two differ by half or more. */
static void pole_coef(const rcb_monitor *mon, const double *W, const double *R,
                      const double *x0, size_t p, double *gam) {
  size_t a, q;
  for (q = 0; q < mon->npt; q++) {
    double w1 = mon->winv[2 * q], w2 = mon->winv[2 * q + 1];
    double complex v = 0, r, g = 0;
    if (w1 > 0 && w2 > 0) {
      for (a = 0; a < p; a++) v += unw(mon, W, q, a) * x0[a];
      r = CMPLX(R[2 * q] / w1, R[2 * q + 1] / w2);
      g = cabs(v) > 0 && cabs(r) > 0 && cabs(r / v - 1.0) < 0.5 ? 1.0 / r - 1.0 / v : 0.0;
    }
    gam[2 * q] = creal(g), gam[2 * q + 1] = cimag(g);
  }
}

/* The one-pole model of each point's change (pole_solve): its
 * coefficients, the baseline's columns W (n x p, pole_columns) and, when
 * D is not NULL, D (n x p) added as D (x - xr). */
typedef struct pole_model {
  const double *gam, *W, *D, *xr;
} pole_model;

/* x minimising the misfit of the one-pole model of each point's change,
 * v / (1 + g v) (v = W x, g from gam) plus D (x - xr), by up to maxit
 * Gauss-Newton steps on it (no sweep), ending after one under tol standard
 * errors (*step: the last); sd those of the model's columns. Uses
 * mon->rmx. */
static rcb_status pole_solve(rcb_monitor *mon, const mon_cand *c, int gls, const pole_model *pm,
                             double tol, size_t maxit, double *x, double *sd, int *ok,
                             double *step) {
  size_t a, q, it, k = mon->k, p = mon->nt + c->np, n = mon->n, npt = mon->npt;
  double *R = mon->rmx, *J = R + n, *Ym = R + n * (1 + p);
  const double *W = pm->W, *gam = pm->gam, *D = pm->D, *xr = pm->xr;
  rcb_status st = RCB_OK;
  *ok = 0, *step = 0;
  for (it = 0; it < maxit; it++) {
    for (q = 0; q < npt; q++) {
      double w1 = mon->winv[2 * q], w2 = mon->winv[2 * q + 1];
      double complex v = 0, g, d, e;
      if (!(w1 > 0 && w2 > 0)) { /* a part left out: linear */
        for (a = 0, R[2 * q] = R[2 * q + 1] = 0; a < p; a++) {
          R[2 * q] += W[2 * q + n * a] * x[a], R[2 * q + 1] += W[2 * q + 1 + n * a] * x[a];
          J[2 * q + n * a] = W[2 * q + n * a], J[2 * q + 1 + n * a] = W[2 * q + 1 + n * a];
        }
      } else {
        for (a = 0; a < p; a++) v += unw(mon, W, q, a) * x[a];
        g = CMPLX(gam[2 * q], gam[2 * q + 1]);
        d = 1.0 + g * v;
        e = v / d;
        R[2 * q] = creal(e) * w1, R[2 * q + 1] = cimag(e) * w2;
        d = 1.0 / (d * d);
        for (a = 0; a < p; a++) {
          e = unw(mon, W, q, a) * d;
          J[2 * q + n * a] = creal(e) * w1, J[2 * q + 1 + n * a] = cimag(e) * w2;
        }
      }
      for (a = 0; D && a < p; a++) {
        size_t i = 2 * q + n * a;
        R[2 * q] += D[i] * (x[a] - xr[a]), R[2 * q + 1] += D[i + 1] * (x[a] - xr[a]);
        J[i] += D[i], J[i + 1] += D[i + 1];
      }
    }
    to_rank_blas(mon, R, 1 + p, Ym);
    for (q = 0; q < k; q++) mon->z[q] = mon->y0[q] - Ym[q];
    memcpy(mon->Jx, Ym + k, k * p * sizeof *mon->Jx);
    st = gn_step(mon, gls, p, x, sd, ok, step);
    if (st || !*ok || *step < tol) break;
  }
  return st;
}

/* After the first fresh evaluation at x0 of a joint step far from linear
 * (its step MON_CHORD_SD standard errors or more): the next point from a
 * one-pole model of each point's change instead of the columns at x0. Near
 * a resonance a point's change is v / (1 + g v), v = J_0 x the baseline's
 * linear change (complex, per point, unwhitened) and g fixed by the
 * evaluation at x0 (exact for a single mode whose pole moves with x: a
 * shaft's material damping, a stiffness); x minimises the model's misfit
 * (pole_solve). On entry mon->rmx holds the whitened change at x0
 * (joint_gn) and x, sd the columns' step from x0; x and sd are left so
 * when the model fails (a dependent column) or lands farther from that
 * step than the step is long. On shaft A's material damping 2300 standard
 * errors above the baseline (bench_monitor damping), the columns' step
 * landed 60 standard errors short, the model's 3.9. */
static rcb_status pole_step(rcb_monitor *mon, const mon_cand *c, int gls, const double *x0,
                            double *x, double *sd) {
  enum { MX = RCB_MONITOR_MAX_TRACKED + RCB_MONITOR_MAXP };
  size_t a, p = mon->nt + c->np;
  double keep[MX], ksd[MX], step = 0, far;
  int own = c->pole && c->pole_ready > 0; /* the baseline's columns held with the model */
  pole_model pm = {mon->rat, own ? c->pole + mon->n : mon->rat + mon->n, NULL, NULL};
  rcb_status st;
  int ok = 0;
  memcpy(keep, x, p * sizeof *x), memcpy(ksd, sd, p * sizeof *sd);
  if (!own) pole_columns(mon, c, p, mon->rat + mon->n);
  pole_coef(mon, pm.W, mon->rmx, x0, p, mon->rat);
  st = pole_solve(mon, c, gls, &pm, MON_RELIN_TOL, 2 * mon->relin, x, sd, &ok, &step);
  /* kept only when no farther from the columns' step than that step is long */
  for (a = 0, step = 0, far = 0; a < p; a++) {
    step = fmax(step, fabs(x[a] - keep[a]) / ksd[a]);
    far = fmax(far, fabs(keep[a] - x0[a]) / ksd[a]);
  }
  if (st || !ok || !(step <= far)) memcpy(x, keep, p * sizeof *x), memcpy(sd, ksd, p * sizeof *sd);
  return st;
}

/* Before the first evaluation of candidate c's joint step: the point its
 * one-pole model (c->pole, pole_fill) predicts from the
 * linear estimate x, taken (*pred = 1) when the model's first step from x
 * is one that would not end the iterations (joint_relin's rule, with the
 * linear step's length as the contraction's distance): the step is far
 * from linear. Else x and sd are left as they are, and the iterations go
 * on as without the model. */
static rcb_status pole_predict(rcb_monitor *mon, const mon_cand *c, int gls, double *x,
                               double *sd, int *pred) {
  enum { MX = RCB_MONITOR_MAX_TRACKED + RCB_MONITOR_MAXP };
  size_t a, p = mon->nt + c->np;
  double xl[MX], sdl[MX], dist = 0, step = 0, s = 0, nl = 0;
  pole_model pm = {NULL, NULL, NULL, NULL};
  rcb_status st;
  int ok = 0;
  *pred = 0;
  if (!c->pole) return RCB_OK;
  pm.gam = c->pole, pm.W = c->pole + mon->n;
  for (a = 0; a < p; a++) dist = fmax(dist, fabs(x[a]) / sd[a]);
  for (a = 0; a < c->np; a++) s = fmax(s, fabs(x[mon->nt + a]) / c->se[a]);
  /* the step the sweep's part beyond the linear change makes at s
   * standard errors, about c->pole_dx s^2 (its own grows more slowly with
   * s): at under half of what would not end the iterations, no model */
  for (a = 0; a < p; a++) nl = fmax(nl, fabs(c->pole_dx[a]) * s * s / sd[a]);
  if (!(4.0 * nl * nl >= MON_RELIN_TOL * dist)) return RCB_OK;
  memcpy(xl, x, p * sizeof *x), memcpy(sdl, sd, p * sizeof *sd);
  st = pole_solve(mon, c, gls, &pm, MON_CHORD_SD, 1, x, sd, &ok, &step);
  if (!st && ok && step * step >= MON_RELIN_TOL * dist) {
    *pred = 1;
    st = pole_solve(mon, c, gls, &pm, MON_CHORD_SD, 2 * mon->relin, x, sd, &ok, &step);
  }
  if (st || !ok || !*pred) {
    memcpy(x, xl, p * sizeof *x), memcpy(sd, sdl, p * sizeof *sd);
    *pred = 0;
  }
  return st;
}

/* After the fresh evaluation at the predicted point xp (pole_predict) and
 * its Gauss-Newton step to x: that step corrected for the curvature the
 * one-pole model through the evaluation shows. The model, v / (1 + g v)
 * with g from the change at xp (pole_coef), plus D (x - xp), D the
 * evaluated columns at xp less the model's own there, has the evaluation's
 * value and columns at xp; x moves to its solution. *corr: the move, in
 * standard errors. On entry mon->rmx holds the whitened change and columns
 * at xp (joint_gn). x and sd are left so when the model fails. */
static rcb_status pole_correct(rcb_monitor *mon, const mon_cand *c, int gls, const double *xp,
                               double *x, double *sd, double *corr) {
  enum { MX = RCB_MONITOR_MAX_TRACKED + RCB_MONITOR_MAXP };
  size_t a, q, i, j, n = mon->n, p = mon->nt + c->np;
  double x1[MX], sd1[MX], *gam = mon->rat, *D = gam + n, step;
  const double *R = mon->rmx, *Jp = R + n, *W;
  pole_model pm = {NULL, NULL, NULL, NULL};
  rcb_status st;
  int ok = 0;
  *corr = INFINITY;
  if (!c->pole) return RCB_OK;
  W = c->pole + n;
  pm.gam = gam, pm.W = W, pm.D = D, pm.xr = xp;
  memcpy(x1, x, p * sizeof *x), memcpy(sd1, sd, p * sizeof *sd);
  pole_coef(mon, W, R, xp, p, gam);
  for (q = 0; q < mon->npt; q++) { /* D = Jp less the model's columns at xp */
    double w1 = mon->winv[2 * q], w2 = mon->winv[2 * q + 1];
    double complex v = 0, d;
    if (!(w1 > 0 && w2 > 0)) { /* a part left out: linear */
      for (a = 0; a < p; a++)
        for (i = 2 * q + n * a, j = 0; j < 2; j++) D[i + j] = Jp[i + j] - W[i + j];
      continue;
    }
    for (a = 0; a < p; a++) v += unw(mon, W, q, a) * xp[a];
    d = 1.0 + CMPLX(gam[2 * q], gam[2 * q + 1]) * v;
    d = 1.0 / (d * d);
    for (a = 0; a < p; a++) {
      double complex e = unw(mon, W, q, a) * d;
      i = 2 * q + n * a;
      D[i] = Jp[i] - creal(e) * w1, D[i + 1] = Jp[i + 1] - cimag(e) * w2;
    }
  }
  st = pole_solve(mon, c, gls, &pm, MON_RELIN_TOL * MON_RELIN_TOL, 2 * mon->relin, x, sd, &ok,
                  &step);
  for (a = 0, *corr = 0; a < p; a++) *corr = fmax(*corr, fabs(x[a] - x1[a]) / sd1[a]);
  if (st || !ok) memcpy(x, x1, p * sizeof *x), memcpy(sd, sd1, p * sizeof *sd), *corr = INFINITY;
  return st;
}

/* Candidate c's one-pole model (pole_predict) into c->pole (n x (1 + p),
 * held since create): the baseline's columns of its joint step (Q G) after
 * the coefficient per point from one sweep with its parameters
 * MON_POLE_STEP standard errors from their neutral values (the tracked
 * ones at the baseline), and c->pole_dx. c->pole_ready 1, or -1 (no model)
 * when the model refuses that value or the sweep fails. Done by create,
 * or, by a create from an image, by the first update that needs it (the
 * same values: the baseline's alone), so that such a create stays cheap. */
static void pole_fill(rcb_monitor *mon, mon_cand *c) {
  enum { MX = RCB_MONITOR_MAX_TRACKED + RCB_MONITOR_MAXP };
  double x0[MX] = {0}, sd[MX], step, *R = mon->rmx, *W = c->pole + mon->n;
  size_t a, i, nt = mon->nt, p = nt + c->np;
  rcb_status st = RCB_OK;
  int ok = 0;
  for (a = 0; !st && a < c->np; a++) {
    x0[nt + a] = MON_POLE_STEP * c->se[a];
    st = rcb_model_set_param(mon->model, c->pname[a], c->neutral[a] + x0[nt + a]);
  }
  if (!st && !(st = rcb_fit_residuals(mon->fit, R))) {
    whiten_change(mon, R, mon->rbase);
    pole_columns(mon, c, p, W); /* also G's columns into mon->Jx */
    pole_coef(mon, W, R, x0, p, c->pole);
    for (i = 0; i < mon->n; i++) /* the change's part beyond the linear one */
      for (a = nt; a < p; a++) R[i] -= W[i + mon->n * a] * x0[a];
    to_rank(mon, R, mon->z);
    memset(c->pole_dx, 0, sizeof c->pole_dx);
    st = gn_step(mon, 0, p, c->pole_dx, sd, &ok, &step);
    for (a = 0; a < p; a++) c->pole_dx[a] /= MON_POLE_STEP * MON_POLE_STEP;
  }
  rcb_mon_model_restore(mon, c);
  c->pole_ready = !st && ok ? 1 : -1;
}

/* With opts.relinearise and while the instant test fires: the joint step
 * of the tracked parameters and the best candidate, linearised at the
 * baseline, refined by up to as many Gauss-Newton iterations (until a
 * step is below MON_RELIN_TOL standard errors) with the columns
 * re-evaluated at the estimate (joint_gn), when the candidate's
 * parameters are the model's own (c->settable); the standard errors are
 * then those of the last iteration's columns. A large new effect is not
 * linear in its size: linearised at the baseline, B3's 1.5e7 N/m
 * cross-coupling of the ROSS series came out 5 % short, and the tracked
 * parameters 17-68 standard errors off; chord iterations with the
 * baseline's columns converged at a rate of about 0.8. A step the model
 * refuses (a negative stiffness) keeps the linear estimate. On the sweep
 * path a step the candidate's one-pole model finds far from linear starts
 * at that model's prediction (pole_predict), and the step from the first
 * evaluation there is corrected by the model through it (pole_correct):
 * on shaft A's material damping the correction was 0.04-0.05 standard
 * errors and left the estimate 2e-4 of them from the converged one, so one
 * sweep where there were two (bench_monitor damping 22.9 -> 13 ms). */
static rcb_status joint_relin(rcb_monitor *mon, int gls, rcb_monitor_result *res, double *dth,
                              double *se) {
  mon_cand *c = res->alarm && res->ntop ? &mon->cand[res->top[0].index] : NULL;
  double x[RCB_MONITOR_MAX_TRACKED + RCB_MONITOR_MAXP] = {0},
         sd[RCB_MONITOR_MAX_TRACKED + RCB_MONITOR_MAXP] = {0};
  enum { MX = RCB_MONITOR_MAX_TRACKED + RCB_MONITOR_MAXP };
  double xa[MX], xp[MX] = {0}, sdp[MX], prev = 0, step, dist, drift;
  size_t a, it, nt = mon->nt, p;
  rcb_status st = RCB_OK;
  int ok = 1, fresh = 1, pred = 0;
  if (!c || !mon->relin || !c->settable) return RCB_OK;
  p = nt + c->np;
  for (a = 0; a < nt; a++) x[a] = dth[a], sd[a] = se[a];
  for (a = 0; a < c->np; a++) x[nt + a] = c->size_now[a], sd[nt + a] = c->se_now[a];
  memcpy(sdp, sd, sizeof sdp); /* the baseline's columns: the linear estimate's */
  if (c->pole && mon->rat && !c->pole_ready) pole_fill(mon, c);
  if (c->pole_ready > 0 && (st = pole_predict(mon, c, gls, x, sd, &pred))) return st;
  for (it = 0; ok == 1 && !st && it < mon->relin; it++) {
    memcpy(xa, x, sizeof xa);
    st = joint_gn(mon, c, gls, fresh, x, sd, &ok, &step);
    if (!st && ok && fresh) {
      /* a step whose successor, at the contraction from the last fresh
       * columns' point to these (the baseline's the first time), would be
       * under MON_RELIN_TOL standard errors, and over which the standard
       * errors would move by less than MON_SD_TOL at the rate they moved
       * between the two: converged without another sweep */
      for (a = 0, dist = 0, drift = 0; a < p; a++) {
        dist = fmax(dist, fabs(xa[a] - xp[a]) / sd[a]);
        drift = fmax(drift, fabs(sd[a] - sdp[a]) / sd[a]);
      }
      if (ok != 1 && step * step < MON_RELIN_TOL * dist && drift * step < MON_SD_TOL * dist) ok = 1;
      memcpy(xp, xa, sizeof xp), memcpy(sdp, sd, sizeof sdp);
      if (pred && !it && ok != 1) {
        /* the same rule on the correction after the step: its successor at
         * the contraction from the step to it under MON_RELIN_TOL, and the
         * standard errors' move at the rate they moved over it */
        double corr, sdn[MX], dr = 0;
        memcpy(sdn, sd, sizeof sdn);
        st = pole_correct(mon, c, gls, xa, x, sd, &corr);
        for (a = 0; a < p; a++) dr = fmax(dr, fabs(sd[a] - sdn[a]) / sd[a]);
        if (!st && corr * corr < MON_RELIN_TOL * step && dr * corr < MON_SD_TOL * step) ok = 1;
      } else if (ok == 4 && !it && c->adj && mon->rat) st = pole_step(mon, c, gls, xa, x, sd);
    } else if (!st && ok == 2 && step * step < MON_RELIN_TOL * prev) {
      ok = 1; /* the same on kept columns, at the contraction of the last two steps */
    }
    prev = step;
    fresh = ok == 4;
    ok = ok == 2 || ok == 4 ? 1 : ok ? 3 : 0; /* 3: converged */
  }
  rcb_mon_model_restore(mon, c);
  if (st || !ok) return st;
  for (a = 0; a < nt; a++) dth[a] = x[a], se[a] = sd[a];
  for (a = 0; a < c->np; a++) {
    double h = MON_Z95 * sd[nt + a];
    c->size_now[a] = x[nt + a], c->se_now[a] = sd[nt + a];
    res->top[0].size[a] = x[nt + a];
    res->top[0].ci_lo[a] = x[nt + a] - h, res->top[0].ci_hi[a] = x[nt + a] + h;
  }
  return RCB_OK;
}

rcb_status rcb_monitor_update(rcb_monitor *mon, const rcb_complex *values, const double *sd,
                              rcb_monitor_result *res) {
  double theta[RCB_MONITOR_MAX_TRACKED], dth[RCB_MONITOR_MAX_TRACKED] = {0},
      se[RCB_MONITOR_MAX_TRACKED] = {0}, T, threl[RCB_MONITOR_MAX_TRACKED];
  size_t p, a;
  int gls;
  rcb_status st;
  if (!mon) return RCB_ERR_ARG;
  if (!values || !res) return rcb_mon_fail(mon, RCB_ERR_ARG, "rcb_monitor_update: values and "
                                           "result are required");
  if (!ready(mon))
    return rcb_mon_fail(mon, RCB_ERR_STATE, "rcb_monitor_update: the monitor was not created "
                        "successfully");
  if (mon->updates >= RCB_MONITOR_MAX_UPDATES)
    return rcb_mon_fail(mon, RCB_ERR_STATE, "rcb_monitor_update: %zu updates taken, the most "
                        "a monitor takes (RCB_MONITOR_MAX_UPDATES); start a new series",
                        mon->updates);
  if ((st = check_input(mon, values, sd))) return st;
  gls = mon->reweight || sd;
  for (p = 0; p < mon->npt; p++) {
    double complex g = conj(mon->u[p]) * (values[p] - mon->e0[p]);
    mon->r[2 * p] = creal(g) * mon->winv[2 * p];
    mon->r[2 * p + 1] = cimag(g) * mon->winv[2 * p + 1];
  }
  /* the linear tracked step from the residuals (E Q^T r) and its first
   * evaluation, so that one pass over Q gives y, ym and the covariance */
  memset(theta, 0, sizeof theta);
  for (a = 0; mon->relin && a < mon->nt; a++)
    theta[a] = dot(mon->tres + a * mon->n, mon->r, mon->n);
  if (mon->relin && mon->nt && (st = model_resid(mon, theta, NULL, NULL, mon->rm))) {
    rcb_mon_model_restore(mon, NULL);
    return st;
  }
  rcb_mon_pass(mon, values, sd, gls, mon->relin && mon->nt);
  memcpy(mon->y0, mon->y, mon->k * sizeof *mon->y0);
  if ((st = tracked_step(mon, theta))) {
    rcb_mon_model_restore(mon, NULL);
    return st;
  }
  memcpy(threl, theta, sizeof threl);
  if (gls) {
    if ((st = rcb_mon_gls(mon, dth, se, &T))) return st;
  } else {
    /* instant test: the part of y beyond the tracked directions */
    T = dot(mon->y, mon->y, mon->k);
    for (a = 0; a < mon->nt; a++) {
      double z = dot(mon->tdir + a * mon->k, mon->y, mon->k);
      T -= z * z;
    }
  }
  memset(res, 0, sizeof *res);
  mon->updates++;
  res->update = mon->updates;
  errors(mon, values, res);
  res->T = fmax(T, 0.0);
  res->dof = mon->k - mon->nt;
  res->threshold = mon->threshold;
  res->p_value = res->dof ? rcb_chi2_sf(res->T, (double)res->dof) : 1.0;
  res->alarm = res->dof && res->T > mon->threshold;
  if ((st = candidates(mon, gls, res))) return st;
  tracked_rest(mon, gls, res, theta, dth, se);
  if ((st = joint_relin(mon, gls, res, dth, se))) return st;
  for (a = 0; a < mon->nt; a++) theta[a] += dth[a];
  tracked_result(mon, theta, se, res);
  rcb_mon_drift_update(mon, threl, gls, res);
  return RCB_OK;
}

void rcb_monitor_reset_cusum(rcb_monitor *mon) {
  if (!mon) return;
  memset(mon->cus_up, 0, sizeof mon->cus_up);
  memset(mon->cus_dn, 0, sizeof mon->cus_dn);
  memset(mon->ref_sum, 0, sizeof mon->ref_sum);
  memset(mon->ref_w, 0, sizeof mon->ref_w);
  memset(mon->ref_frozen, 0, sizeof mon->ref_frozen);
  memset(mon->bref, 0, sizeof mon->bref);
  mon->ref_started = 1; /* the next update starts the reference afresh */
  rcb_mon_drift_reset(mon); /* and the drift test its window */
}

size_t rcb_monitor_point_count(const rcb_monitor *mon) { return ready(mon) ? mon->npt : 0; }
size_t rcb_monitor_update_count(const rcb_monitor *mon) { return ready(mon) ? mon->updates : 0; }
int rcb_monitor_fast_relinearise(const rcb_monitor *mon) { return ready(mon) && mon->lr; }
size_t rcb_monitor_memory(const rcb_monitor *mon) { return mon ? mon->held : 0; }

rcb_status rcb_monitor_rank(const rcb_monitor *mon, size_t *k, size_t *k_tracked) {
  if (!ready(mon)) return RCB_ERR_STATE;
  if (k) *k = mon->k;
  if (k_tracked) *k_tracked = mon->nt;
  return RCB_OK;
}

size_t rcb_monitor_candidate_count(const rcb_monitor *mon) { return ready(mon) ? mon->ncand : 0; }

rcb_status rcb_monitor_candidate_info_get(const rcb_monitor *mon, size_t i,
                                          rcb_monitor_candidate_info *out) {
  const mon_cand *c;
  if (!ready(mon) || !out || i >= mon->ncand) return RCB_ERR_ARG;
  c = &mon->cand[i];
  out->effect = c->effect;
  out->place = c->place;
  out->description = c->desc;
  out->params = c->params;
  out->np = c->np;
  return RCB_OK;
}

rcb_status rcb_monitor_tracked_info(const rcb_monitor *mon, size_t k, const char **name,
                                    double *baseline) {
  if (!ready(mon) || k >= mon->nt) return RCB_ERR_ARG;
  if (name) *name = mon->tname[k];
  if (baseline) *baseline = mon->t0[k];
  return RCB_OK;
}

/* The candidates whose joint step is re-linearised by sweeps (settable,
 * with derivative matrices, not on the low-rank path: the operating speed,
 * a shaft's material damping) get that step's columns by one adjoint sweep
 * per iteration (rcb_fit_adj, prepared here so that the update allocates
 * nothing) instead of 1 + nt + np forward-difference sweeps; the tracked
 * parameters' derivative matrices are the baseline's (exact where Z is
 * affine in them, as a coupling's; elsewhere the iteration still converges
 * to the same step, more slowly). Each also gets its one-pole model's
 * block, filled here (pole_fill) unless lazy (a create from an image). */
rcb_status rcb_mon_adj_init(rcb_monitor *mon, int lazy) {
  enum { MT = RCB_MONITOR_MAX_TRACKED, MP = RCB_MONITOR_MAXP };
  struct rcb_fit_dz dz[MT + MP];
  size_t j, a, pm, nt = mon->nt;
  rcb_status st;
  if (!mon->relin || !nt || !mon->fit) return RCB_OK;
  for (j = 0; j < mon->ncand; j++)
    if (mon->cand[j].dz && mon->cand[j].settable && !mon->cand[j].ep) break;
  if (j == mon->ncand) return RCB_OK;
  for (j = 0, pm = 0; j < mon->ncand; j++)
    if (mon->cand[j].dz && mon->cand[j].settable && !mon->cand[j].ep && mon->cand[j].np > pm)
      pm = mon->cand[j].np;
  if (!(mon->rat = rcb_mon_alloc(mon, mon->n * (1 + nt + pm), sizeof *mon->rat)))
    return rcb_mon_fail(mon, RCB_ERR_NOMEM, "out of memory (joint step's model)");
  if (!(mon->tdz = rcb_mon_alloc(mon, nt, sizeof *mon->tdz)))
    return rcb_mon_fail(mon, RCB_ERR_NOMEM, "out of memory (tracked derivative matrices)");
  if ((st = rcb_fit_dz_get(mon->fit, &mon->alloc, mon->tdz))) {
    rcb_free(&mon->alloc, mon->tdz);
    mon->tdz = NULL;
    return rcb_mon_fail(mon, st, "tracked derivative matrices: %s", rcb_fit_errmsg(mon->fit));
  }
  for (j = 0; j < mon->ncand; j++) {
    mon_cand *c = &mon->cand[j];
    if (!c->dz || !c->settable || c->ep) continue;
    for (a = 0; a < nt; a++) dz[a] = mon->tdz[a];
    for (a = 0; a < c->np; a++) dz[nt + a] = c->dz[a];
    if ((st = rcb_fit_adj_create(mon->fit, dz, nt + c->np, &c->adj)))
      return rcb_mon_fail(mon, st, "%s: joint step: %s", c->desc, rcb_fit_errmsg(mon->fit));
    if (!(c->pole = rcb_mon_alloc(mon, mon->n * (1 + nt + c->np), sizeof *c->pole)))
      return rcb_mon_fail(mon, RCB_ERR_NOMEM, "out of memory (joint step's model)");
    if (!lazy) pole_fill(mon, c);
  }
  return RCB_OK;
}
