/*
 * Uncertainty and identifiability at the fitted point (not in the paper):
 * covariance sigma^2 (J^T W J)^-1 from the weighted Jacobian J (parameter
 * units), sigma^2 = F / (N - np); 95 % intervals p +/- 1.96 se (N large);
 * correlation; and an SVD test on the column-scaled Jacobian: a parameter is
 * not identifiable when it loads on a singular value below 1e-6 of the
 * largest (the data cannot tell it apart), when its 95 % interval reaches
 * zero, or when the data cannot tell the
 * fitted value from half or twice of it: F(2p) and F(p/2) both stay within
 * the 95 % chi-square(1) level (3.84 sigma^2) of F(p) (the paper's "infinite"
 * cR error). These evaluations are not counted in the fit's evaluations.
 */
#include <lapacke.h>
#include <math.h>
#include <string.h>

#include "identify/fit_internal.h"

#define RCB_SVD_RTOL 1e-6
#define RCB_Z95 1.959963984540054

static void flag_and_fill(rcb_fit *f, const double *s, const double *Vt, const double *d,
                          double sigma2) {
  size_t np = f->np, i, j, k;
  for (i = 0; i < np; i++)
    for (j = 0; j < np; j++) {
      double c = 0.0;
      for (k = 0; k < np; k++)
        if (s[k] > 0) c += Vt[k + np * i] * Vt[k + np * j] / (s[k] * s[k]);
      f->cov[i + np * j] = sigma2 * c * d[i] * d[j];
    }
  for (i = 0; i < np; i++) {
    rcb_fit_par *p = &f->par[i];
    p->se = sqrt(f->cov[i + np * i]);
    p->ci_lo = p->value - RCB_Z95 * p->se;
    p->ci_hi = p->value + RCB_Z95 * p->se;
    /* a 95 % interval that reaches zero: the data do not determine it */
    p->identifiable = !(RCB_Z95 * p->se >= fabs(p->value)) && isfinite(p->se);
    for (k = 0; k < np; k++)
      if (s[k] < RCB_SVD_RTOL * s[0] && fabs(Vt[k + np * i]) > 0.5) p->identifiable = 0;
  }
  for (i = 0; i < np; i++)
    for (j = 0; j < np; j++)
      f->corr[i + np * j] = f->cov[i + np * j] / (f->par[i].se * f->par[j].se);
}

/* Objective with parameter k set to v (the model is restored afterwards). */
static rcb_status objective_with(rcb_fit *f, size_t k, double v, double *F) {
  double p = rcb_fit_par_get(f, k);
  rcb_status st;
  if ((st = rcb_fit_par_set(f, k, v))) return st;
  rcb_frf_refresh(f->frf);
  st = rcb_fit_eval(f, f->r + f->nres);
  rcb_fit_par_set(f, k, p);
  rcb_frf_refresh(f->frf);
  if (!st) *F = rcb_fit_sumsq(f->r + f->nres, f->nres);
  return st;
}

/* Can the data tell p from 2p and p/2? */
static rcb_status factor_two_test(rcb_fit *f, double sigma2) {
  size_t k, evals = f->evaluations;
  double F0 = rcb_fit_sumsq(f->r, f->nres);
  rcb_status st = RCB_OK;
  for (k = 0; k < f->np && !st; k++) {
    rcb_fit_par *p = &f->par[k];
    double v = p->value, F2, Fh;
    if (v <= 0.0 || !(sigma2 > 0)) continue;
    if ((st = objective_with(f, k, 2.0 * v, &F2)) || (st = objective_with(f, k, 0.5 * v, &Fh)))
      break;
    if (fmin(F2, Fh) - F0 < 3.84 * sigma2) p->identifiable = 0;
  }
  f->evaluations = evals;
  return st ? rcb_fit_fail(f, st, "identifiability test: %s", rcb_model_errmsg(f->m)) : RCB_OK;
}

rcb_status rcb_fit_uncertainty(rcb_fit *f) {
  size_t n = f->nres, np = f->np, i, k;
  double *A = rcb_alloc(&f->alloc, n * np * sizeof *A);
  double *s = rcb_alloc(&f->alloc, np * sizeof *s), *Vt = rcb_alloc(&f->alloc, np * np * sizeof *Vt);
  double *d = rcb_alloc(&f->alloc, np * sizeof *d), wq, *work = NULL, sigma2;
  rcb_status st = RCB_OK;
  lapack_int info;
  if (!A || !s || !Vt || !d) {
    st = rcb_fit_fail(f, RCB_ERR_NOMEM, "out of memory (uncertainty)");
    goto done;
  }
  {
    size_t evals = f->evaluations;
    st = rcb_fit_eval_jac(f, f->r, f->J);
    f->evaluations = evals;
    if (st) goto done;
  }
  sigma2 = n > np ? rcb_fit_sumsq(f->r, n) / (double)(n - np) : (double)NAN;
  /* J in internal units -> columns scaled to relative parameter changes */
  for (k = 0; k < np; k++) {
    double v = rcb_fit_par_get(f, k), dpdx;
    dpdx = f->par[k].log_param ? v : f->par[k].scale;
    d[k] = v != 0.0 ? fabs(v) : f->par[k].scale;
    for (i = 0; i < n; i++) A[i + n * k] = f->J[i + n * k] / dpdx * d[k];
  }
  info = LAPACKE_dgesvd_work(LAPACK_COL_MAJOR, 'N', 'A', (lapack_int)n, (lapack_int)np, A,
                             (lapack_int)n, s, NULL, 1, Vt, (lapack_int)np, &wq, -1);
  if (!info && (work = rcb_alloc(&f->alloc, (size_t)wq * sizeof *work)))
    info = LAPACKE_dgesvd_work(LAPACK_COL_MAJOR, 'N', 'A', (lapack_int)n, (lapack_int)np, A,
                               (lapack_int)n, s, NULL, 1, Vt, (lapack_int)np, work,
                               (lapack_int)wq);
  if (info || !work) {
    st = rcb_fit_fail(f, info ? RCB_ERR_LAPACK : RCB_ERR_NOMEM, "SVD of the Jacobian failed");
    goto done;
  }
  flag_and_fill(f, s, Vt, d, sigma2);
  st = factor_two_test(f, sigma2);
done:
  rcb_free(&f->alloc, A);
  rcb_free(&f->alloc, s);
  rcb_free(&f->alloc, Vt);
  rcb_free(&f->alloc, d);
  rcb_free(&f->alloc, work);
  return st;
}
