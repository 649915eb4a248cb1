/*
 * The reweighted update (opts.reweight, or an sd passed to the update):
 * the covariance of the whitened change r is rebuilt from this update's
 * noise, D (2 x 2 per point: the proportional eq. 19 noise lies along the
 * new value, not along e_0), and taken to the rank space, C = Q^T D Q
 * (k x k, accumulated point by point: O(n k^2)). With C = U^T U
 * (Cholesky), every statistic is the least-squares one in the metric
 * C^-1: z = U^-T y, the tracked columns A_t = U^-T G_t, a candidate's
 * A_c = U^-T G_c; T = ||z||^2 - ||P_{A_t} z||^2, the score
 * ||P_{[A_t A_c]} z||^2 - ||P_{A_t} z||^2, the estimates and their
 * standard errors from the QR of [A_t A_c]. All memory was sized by
 * rcb_monitor_create (mon->C, mon->sw).
 */
#include <cblas.h>
#include <lapacke.h>
#include <math.h>
#include <string.h>

#include "monitor/monitor_internal.h"

/* The turn from point p's frame u to its commissioning value e_0 (cos, sin
 * of arg(conj(u) e_0)): on the reweighted path the frame u is the baseline
 * model's values' (monitor_create.c, noise), while var0 is radial and
 * tangential to e_0; elsewhere (or e_0 = 0) no turn. */
static void share_turn(const rcb_monitor *mon, size_t p, double *c, double *s) {
  double ae = mon->e0abs[p];
  *c = 1.0, *s = 0.0;
  if (mon->reweight && !mon->have_sd0 && ae > 0) {
    double complex w = conj(mon->u[p]) * mon->e0[p] / ae;
    *c = creal(w), *s = cimag(w);
  }
}

/* The commissioning values' share of point p's covariance, added to s11,
 * s12, s22 (unwhitened, in the frame u): R diag(var0 / N) R^T, R the turn
 * from e_0's radial frame into u (share_turn). */
static void share(const rcb_monitor *mon, size_t p, double *s11, double *s12, double *s22) {
  double r = mon->var0[2 * p] * mon->navg_inv, t = mon->var0[2 * p + 1] * mon->navg_inv, c, s;
  share_turn(mon, p, &c, &s);
  *s11 += r * c * c + t * s * s, *s12 += (r - t) * c * s, *s22 += r * s * s + t * c * c;
}

/* The modulus eq. 19's proportional and phase terms are taken at for point
 * p of values v (a: its channel's additive amplitude): the fitted value's,
 * e_0 + the update's change projected onto the rank space (yq1 = q1 . y,
 * yq2 = q2 . y: whitened, in the frame u), unless that misses |v| by more
 * than MON_FIT_MISS of v's declared sds (a change the rank space does not
 * hold: then |v|). Taken at |v|, every sd carries the point's own noise: a
 * value pulled towards zero by it weighs more and pulls the estimates with
 * it. On the ROSS cross-coupling series (12 noise draws, eq. 19,
 * tools/bench/monitor_step_bias.py) the step's size read -0.27 of its
 * standard error low at |v|, -0.10 at the fitted moduli (-0.09 with no
 * miss test, -0.18 at 3 sds: the projection misses a fifth of the points
 * after that step); its second-order part alone, by antithetic draws
 * (test_monitor_replicas.py), -0.217 and +0.007. The projection carries
 * the noise of k of the n residuals; e_0's own (1 / N of a measurement's
 * variance) is left. The same rule as rcb_fit's weights at the model
 * (issue #24) and noise_modulus at the commissioning (monitor_create.c). */
#define MON_FIT_MISS 6.0
static double fitted_abs(const rcb_monitor *mon, const rcb_complex *v, size_t p, double a,
                         double yq1, double yq2) {
  double av = cabs(v[p]), pa = mon->beta_a / 100.0 * av;
  double complex d = mon->u[p] * CMPLX(yq1 / mon->winv[2 * p], yq2 / mon->winv[2 * p + 1]);
  double m = cabs(mon->e0[p] + d);
  double lim = MON_FIT_MISS * sqrt(pa * pa / 3.0 + a * a / 6.0 + mon->phase_var * av * av);
  return fabs(m - av) <= lim ? m : av;
}

/* The 2 x 2 covariance of point p's (radial, tangential) residual, whitened:
 * this update's noise (eq. 19's proportional and phase terms at modulus m,
 * along and across v[p]; or the sd) plus the commissioning values' share. */
static void point_cov(const rcb_monitor *mon, const rcb_complex *v, const double *sd, size_t p,
                      double a, double m, double *d11, double *d12, double *d22) {
  double s11, s12 = 0, s22, w1 = mon->winv[2 * p], w2 = mon->winv[2 * p + 1];
  if (sd || mon->have_sd0) {
    double s = sd ? sd[p] * mon->nscale : mon->sd0[p]; /* sd0: scaled at create */
    s11 = s22 = s * s;
  } else {
    double av = cabs(v[p]), sp = mon->beta_a / 100.0 * m;
    double complex w = av > 0 ? conj(mon->u[p]) * v[p] / av : 1.0;
    double c = creal(w), s = cimag(w), vp = sp * sp / 3.0, va = a * a / 6.0;
    double vph = mon->phase_var * m * m; /* phase turn: across the new value */
    s11 = vp * c * c + vph * s * s + va, s12 = (vp - vph) * c * s;
    s22 = vp * s * s + vph * c * c + va;
  }
  share(mon, p, &s11, &s12, &s22);
  *d11 = s11 * w1 * w1, *d12 = s12 * w1 * w2, *d22 = s22 * w2 * w2;
}

/* C += B B^T over the first m columns of B (k x m, column-major; upper). */
static void syrk(const rcb_monitor *mon, const double *B, size_t m, double *C) {
  cblas_dsyrk(CblasColMajor, CblasUpper, CblasNoTrans, (blasint)mon->k, (blasint)m, 1.0, B,
              (blasint)mon->k, 1.0, C, (blasint)mon->k);
}

/* Eq. 19 additive amplitude of channel c in values v. */
static double amplitude(const rcb_monitor *mon, const rcb_complex *v, size_t c) {
  return rcb_mon_eq19_amp(mon->beta_s, v + c * mon->npts, mon->npts);
}

/* Points p0 .. p1 into C (k x k, upper, added to): with share, the
 * commissioning's share W R diag(var0 / N) R^T W (share), as two columns
 * per point, W (q1 c + q2 s) sqrt(var0_r / N) and W (q2 c - q1 s)
 * sqrt(var0_t / N) (c, s: share_turn); else W W (the channel's additive
 * term per unit). */
static void fixed_part(rcb_monitor *mon, size_t p0, size_t p1, int share, double *C) {
  size_t k = mon->k, p, a, nb = 0;
  for (p = p0; p < p1; p++) {
    const double *q1 = mon->Q + k * (2 * p), *q2 = q1 + k;
    double *b1 = mon->b1 + k * (2 * nb), *b2 = b1 + k;
    double w1 = mon->winv[2 * p], w2 = mon->winv[2 * p + 1], c = 1.0, s = 0.0, fr = 1.0, ft = 1.0;
    if (share) {
      share_turn(mon, p, &c, &s);
      fr = sqrt(mon->var0[2 * p] * mon->navg_inv), ft = sqrt(mon->var0[2 * p + 1] * mon->navg_inv);
    }
    for (a = 0; a < k; a++) {
      b1[a] = fr * (w1 * c * q1[a] + w2 * s * q2[a]);
      b2[a] = ft * (w2 * c * q2[a] - w1 * s * q1[a]);
    }
    if (++nb == MON_SYRK_POINTS || p + 1 == p1) syrk(mon, mon->b1, 2 * nb, C), nb = 0;
  }
}

/* Create: the joint step's workspace and the tracked estimator on the
 * residuals (mon->rmx, mon->tres, with re-linearisation) and, on eq. 19
 * noise without a phase term, the parts of the reweighted covariance that
 * depend on the set-up only (mon->Cfix). There a point's whitened
 * covariance is W (var0 / N + a_c^2 / 6 I + s^2 g g^T) W, g = conj(u) v
 * |v|_fit / |v| in the radial frame (fitted_abs), s = beta_a / (100 sqrt
 * 3), a_c its channel's additive amplitude (point_cov): C = C_0 + sum_c
 * a_c^2 / 6 C_c + the update's rank-one terms, one column per point
 * instead of two. */
rcb_status rcb_mon_pass_init(rcb_monitor *mon) {
  size_t k = mon->k, nt = mon->nt, n = mon->n, a, i, c;
  if (mon->relin &&
      !(mon->rmx = rcb_mon_alloc(mon, (1 + nt + RCB_MONITOR_MAXP) * (n + k), sizeof *mon->rmx)))
    return rcb_mon_fail(mon, RCB_ERR_NOMEM, "out of memory (joint re-linearisation)");
  if (mon->relin && nt) {
    if (!(mon->tres = rcb_mon_alloc(mon, nt * n, sizeof *mon->tres)))
      return rcb_mon_fail(mon, RCB_ERR_NOMEM, "out of memory (tracked estimator)");
    for (a = 0; a < nt; a++)
      for (i = 0; i < n; i++) {
        const double *q = mon->Q + k * i, *e = mon->test + a * k;
        double s = 0;
        size_t j;
        for (j = 0; j < k; j++) s += q[j] * e[j];
        mon->tres[a * n + i] = s;
      }
  }
  if (!mon->reweight || mon->have_sd0 || mon->phase_var > 0) return RCB_OK;
  if (!(mon->Cfix = rcb_mon_alloc(mon, (1 + mon->nch) * k * k, sizeof *mon->Cfix)))
    return rcb_mon_fail(mon, RCB_ERR_NOMEM, "out of memory (reweighted covariance)");
  memset(mon->Cfix, 0, (1 + mon->nch) * k * k * sizeof *mon->Cfix);
  if (mon->navg_inv > 0) fixed_part(mon, 0, mon->npt, 1, mon->Cfix);
  for (c = 0; c < mon->nch; c++)
    fixed_part(mon, c * mon->npts, (c + 1) * mon->npts, 0, mon->Cfix + (1 + c) * k * k);
  return RCB_OK;
}

/* C (upper) = the set-up's parts (mon->Cfix) for this update's channel
 * amplitudes. */
static void fixed_c(rcb_monitor *mon) {
  size_t k = mon->k, c, i, j;
  memcpy(mon->C, mon->Cfix, k * k * sizeof *mon->C);
  for (c = 0; c < mon->nch; c++) {
    const double *Cc = mon->Cfix + (1 + c) * k * k;
    double f = mon->achan[c] * mon->achan[c] / 6.0;
    for (j = 0; j < k; j++)
      for (i = 0; i <= j; i++) mon->C[i + k * j] += f * Cc[i + k * j];
  }
}

/* The update's passes over Q (row-major): y = Q^T r, with proj ym = Q^T
 * rm; then with gls C = Q^T D Q (upper triangle), D the update's whitened
 * noise covariance (2 x 2 per point) at the fitted moduli (fitted_abs, from
 * y: hence a second pass): the rows of B^T = L^T Q (D = L L^T), or with
 * mon->Cfix only the rank-one columns s W g (rcb_mon_pass_init), 2
 * MON_SYRK_POINTS columns of B at a time, then C += B B^T (BLAS dsyrk). */
void rcb_mon_pass(rcb_monitor *mon, const rcb_complex *v, const double *sd, int gls, int proj) {
  size_t k = mon->k, p, a, c = 0, nb = 0;
  int split = gls && !sd && mon->Cfix, per = split ? 1 : 2, eq19 = gls && !sd && !mon->have_sd0;
  double *restrict B = mon->b1, *restrict y = mon->y, *restrict ym = mon->ym;
  double s = mon->beta_a / 100.0 / sqrt(3.0);
  const double *r = mon->r, *rm = mon->rm;
  memset(y, 0, k * sizeof *y);
  if (proj) memset(ym, 0, k * sizeof *ym);
  for (p = 0; p < mon->npt; p++) {
    const double *restrict q1 = mon->Q + k * (2 * p), *restrict q2 = q1 + k;
    double r1 = r[2 * p], r2 = r[2 * p + 1];
    /* the same products and order as a pass residual by residual */
    if (proj) {
      double m1 = rm[2 * p], m2 = rm[2 * p + 1];
      for (a = 0; a < k; a++) {
        y[a] = y[a] + q1[a] * r1 + q2[a] * r2;
        ym[a] = ym[a] + q1[a] * m1 + q2[a] * m2;
      }
    } else {
      for (a = 0; a < k; a++) y[a] = y[a] + q1[a] * r1 + q2[a] * r2;
    }
  }
  if (!gls) return;
  if (eq19)
    for (c = 0; c < mon->nch; c++) mon->achan[c] = amplitude(mon, v, c);
  if (split) fixed_c(mon);
  else memset(mon->C, 0, k * k * sizeof *mon->C);
  c = 0;
  for (p = 0; p < mon->npt; p++) {
    const double *restrict q1 = mon->Q + k * (2 * p), *restrict q2 = q1 + k;
    double *restrict b1 = B + k * nb, m = 0, yq1 = 0, yq2 = 0;
    if (p && p == (c + 1) * mon->npts) c++; /* the channel of point p */
    if (eq19) {
      for (a = 0; a < k; a++) yq1 += q1[a] * y[a], yq2 += q2[a] * y[a];
      m = fitted_abs(mon, v, p, mon->achan[c], yq1, yq2);
    }
    if (split) {
      double av = cabs(v[p]);
      double complex g = av > 0 ? conj(mon->u[p]) * v[p] * (m / av) : 0.0;
      double f1 = s * creal(g) * mon->winv[2 * p], f2 = s * cimag(g) * mon->winv[2 * p + 1];
      for (a = 0; a < k; a++) b1[a] = f1 * q1[a] + f2 * q2[a];
    } else {
      double d11, d12, d22, l11, l21, l22, *b2 = b1 + k;
      point_cov(mon, v, sd, p, mon->achan[c], m, &d11, &d12, &d22);
      l11 = sqrt(d11), l21 = d12 / l11, l22 = sqrt(fmax(d22 - l21 * l21, 0.0));
      for (a = 0; a < k; a++) b1[a] = l11 * q1[a] + l21 * q2[a], b2[a] = l22 * q2[a];
    }
    nb += (size_t)per;
    if (nb == (size_t)2 * MON_SYRK_POINTS || p + 1 == mon->npt) syrk(mon, B, nb, mon->C), nb = 0;
  }
}

/* X (k x m) <- U^-T X. */
int rcb_mon_gls_solve(const rcb_monitor *mon, double *X, size_t m) {
  return (int)LAPACKE_dtrtrs_work(LAPACK_COL_MAJOR, 'U', 'T', 'N', (lapack_int)mon->k,
                                  (lapack_int)m, mon->C, (lapack_int)mon->k, X,
                                  (lapack_int)mon->k);
}

/* With w->A = Qa (k x p) and w->Ri from rcb_mon_small_qr: qz = Qa^T z, and
 * the explained part of rows first .. p. */
double rcb_mon_gls_explained(const mon_small *w, const double *z, size_t k, size_t first, size_t p,
                        double *qz) {
  size_t j, i;
  double s = 0;
  for (j = 0; j < p; j++) {
    double v = 0;
    for (i = 0; i < k; i++) v += w->A[i + k * j] * z[i];
    qz[j] = v;
    if (j >= first) s += v * v;
  }
  return s;
}

/* Rows first .. first + q of Ri qz, and their standard errors. */
void rcb_mon_gls_step(const mon_small *w, const double *qz, size_t p, size_t first, size_t q,
                 double *x, double *se) {
  size_t a, b;
  for (a = 0; a < q; a++) {
    size_t row = first + a;
    double v = 0, s = 0;
    for (b = row; b < p; b++) {
      v += w->Ri[row + p * b] * qz[b];
      s += w->Ri[row + p * b] * w->Ri[row + p * b];
    }
    x[a] = v, se[a] = sqrt(s);
  }
}

static rcb_status candidates_gls(rcb_monitor *mon) {
  size_t k = mon->k, nt = mon->nt, j;
  double qz[RCB_MONITOR_MAX_TRACKED + RCB_MONITOR_MAXP];
  rcb_status st;
  for (j = 0; j < mon->ncand; j++) {
    mon_cand *c = &mon->cand[j];
    int ok;
    if (!c->dof) continue;
    memcpy(mon->sw.A, mon->Atw, k * nt * sizeof *mon->sw.A);
    memcpy(mon->sw.A + k * nt, mon->Atw + k * c->col, k * c->np * sizeof *mon->sw.A);
    if ((st = rcb_mon_small_qr(mon, &mon->sw, k, nt + c->np, &ok))) return st;
    if (!ok) { /* dependent in this metric: no evidence */
      c->score_now = 0;
      memset(c->size_now, 0, sizeof c->size_now);
      memcpy(c->se_now, c->se, sizeof c->se_now);
      memset(c->th_now, 0, sizeof c->th_now);
      memcpy(c->set_now, c->se_t, sizeof c->set_now);
      memset(c->xd, 0, sizeof c->xd);
      continue;
    }
    /* the drift test's input: the candidate's orthonormal components beyond
     * the tracked columns in this update's noise, on y (what the
     * re-linearised tracked step leaves; mon->z = U^-T y) */
    (void)rcb_mon_gls_explained(&mon->sw, mon->z, k, nt, nt + c->np, qz);
    memcpy(c->xd, qz + nt, c->np * sizeof *c->xd);
    c->score_now = rcb_mon_gls_explained(&mon->sw, mon->z0, k, nt, nt + c->np, qz);
    rcb_mon_gls_step(&mon->sw, qz, nt + c->np, nt, c->np, c->size_now, c->se_now);
    rcb_mon_gls_step(&mon->sw, qz, nt + c->np, 0, nt, c->th_now, c->set_now);
  }
  return RCB_OK;
}

/* With the tracked columns at the update's step (mon->jt) and the
 * baseline's covariance S (opts.baseline_cov): C += A S A^T, A = J_t(step)
 * - J_t(0) (rank space). A baseline off the truth by d leaves the change
 * -A d beyond what the tracked step takes (the columns at the truth's step
 * less those at the baseline's, to first order in d): an error every
 * update of a wear shares, growing with the wear, which the instant test
 * would otherwise read as a new effect (the ROSS kt_wear series from a
 * log10-fitted baseline, with --sensors: 7 TEST alarms in 101 updates,
 * bound 4; 0 with this part). */
static void baseline_part(rcb_monitor *mon) {
  enum { MT = RCB_MONITOR_MAX_TRACKED };
  size_t k = mon->k, nt = mon->nt, i, j, a, b;
  double m[MT];
  if (!mon->jt || !mon->bcurv) return;
  for (i = 0; i < k; i++) {
    for (a = 0; a < nt; a++) { /* row i of A S */
      m[a] = 0;
      for (b = 0; b < nt; b++)
        m[a] += (mon->Jx[i + k * b] - mon->G[i + k * b]) * mon->bcov[b * nt + a];
    }
    for (j = i; j < k; j++) {
      double v = 0;
      for (a = 0; a < nt; a++) v += m[a] * (mon->Jx[j + k * a] - mon->G[j + k * a]);
      mon->C[i + k * j] += v;
    }
  }
}

rcb_status rcb_mon_gls(rcb_monitor *mon, double *dtheta, double *se, double *T) {
  size_t k = mon->k, nt = mon->nt, a;
  double qz[RCB_MONITOR_MAX_TRACKED];
  lapack_int info;
  int ok = 1;
  rcb_status st;
  baseline_part(mon);
  info = LAPACKE_dpotrf_work(LAPACK_COL_MAJOR, 'U', (lapack_int)k, mon->C, (lapack_int)k);
  if (info)
    return rcb_mon_fail(mon, RCB_ERR_SINGULAR, "reweighted update %zu: the noise covariance in "
                        "the rank space is not positive definite (LAPACK info %d)",
                        mon->updates + 1, (int)info);
  memcpy(mon->z, mon->y, k * sizeof *mon->z);
  memcpy(mon->z0, mon->y0, k * sizeof *mon->z0);
  /* every column at once (one blocked solve, not one per candidate) */
  memcpy(mon->Atw, mon->G, k * mon->ncol * sizeof *mon->Atw);
  if (rcb_mon_gls_solve(mon, mon->z, 1) || rcb_mon_gls_solve(mon, mon->z0, 1) ||
      (mon->ncol && rcb_mon_gls_solve(mon, mon->Atw, mon->ncol)))
    return rcb_mon_fail(mon, RCB_ERR_LAPACK, "reweighted update: triangular solve failed");
  *T = 0;
  for (a = 0; a < k; a++) *T += mon->z[a] * mon->z[a];
  if (nt && mon->jt) {
    /* the tracked columns at the re-linearised step (monitor.c,
     * tracked_columns): T, the rest of the step and the candidates' drift
     * input on the change beyond them */
    memcpy(mon->sw.A, mon->Jx, k * nt * sizeof *mon->sw.A);
    if (rcb_mon_gls_solve(mon, mon->sw.A, nt))
      return rcb_mon_fail(mon, RCB_ERR_LAPACK, "reweighted update: triangular solve failed");
  } else if (nt) {
    memcpy(mon->sw.A, mon->Atw, k * nt * sizeof *mon->sw.A);
  }
  if (nt) {
    if ((st = rcb_mon_small_qr(mon, &mon->sw, k, nt, &ok))) return st;
    if (!ok)
      return rcb_mon_fail(mon, RCB_ERR_SINGULAR, "reweighted update %zu: the tracked parameters "
                          "are not told apart in this update's noise", mon->updates + 1);
    *T -= rcb_mon_gls_explained(&mon->sw, mon->z, k, 0, nt, qz);
    rcb_mon_gls_step(&mon->sw, qz, nt, 0, nt, dtheta, se);
    for (a = 0; mon->jt && a < nt; a++) /* z beyond the step's tracked columns */
      cblas_daxpy((blasint)k, -qz[a], mon->sw.A + k * a, 1, mon->z, 1);
  }
  return candidates_gls(mon);
}
