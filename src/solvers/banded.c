/* Banded backend: LAPACK zgbsv. Nodes numbered along the train keep the
 * half-bandwidth small (7 for a chain of 4-DOF nodes), so one factorisation
 * costs O(n bw^2) instead of O(n^3). */
#include <lapacke.h>
#include <math.h>
#include <string.h>

#include "solvers/zsolver.h"

static rcb_status banded_solve(const rcb_layout *L, rcb_complex *Z, int *ipiv, rcb_complex *B,
                               size_t nrhs) {
  lapack_int n = (lapack_int)L->n, info;
  info = LAPACKE_zgbsv_work(LAPACK_COL_MAJOR, n, (lapack_int)L->kl, (lapack_int)L->ku,
                            (lapack_int)nrhs, (lapack_complex_double *)Z, (lapack_int)L->ld,
                            (lapack_int *)ipiv, (lapack_complex_double *)B, n);
  if (info > 0) return RCB_ERR_SINGULAR;
  if (info < 0) return RCB_ERR_LAPACK;
  return RCB_OK;
}

static rcb_status banded_resolve(const rcb_layout *L, const rcb_complex *Z, const int *ipiv,
                                 rcb_complex *B, size_t nrhs, char trans) {
  lapack_int n = (lapack_int)L->n;
  lapack_int info = LAPACKE_zgbtrs_work(LAPACK_COL_MAJOR, trans, n, (lapack_int)L->kl,
                                        (lapack_int)L->ku, (lapack_int)nrhs,
                                        (const lapack_complex_double *)Z, (lapack_int)L->ld,
                                        (const lapack_int *)ipiv,
                                        (lapack_complex_double *)B, n);
  return info ? RCB_ERR_LAPACK : RCB_OK;
}

/* zgbcon: the same estimate from the band LU factors, O(n bw). */
static rcb_status banded_rcond(const rcb_layout *L, const rcb_complex *Z, const int *ipiv,
                               double anorm, rcb_complex *work, double *rwork, double *rcond) {
  lapack_int info = LAPACKE_zgbcon_work(LAPACK_COL_MAJOR, '1', (lapack_int)L->n,
                                        (lapack_int)L->kl, (lapack_int)L->ku,
                                        (const lapack_complex_double *)Z, (lapack_int)L->ld,
                                        (const lapack_int *)ipiv, anorm, rcond,
                                        (lapack_complex_double *)work, rwork);
  return info ? RCB_ERR_LAPACK : RCB_OK;
}

static const rcb_zsolver_ops banded_ops = {
    "banded", rcb_layout_banded, banded_solve, banded_resolve, NULL, NULL, NULL, banded_rcond};

const rcb_zsolver_ops *rcb_zsolver_banded(void) { return &banded_ops; }

/* ---- The same factorisation written out (rcb_zsolver_banded_inline) ----
 * zgbtf2's algorithm, pivots and storage (so zgbcon and either resolve
 * read its factors), without a BLAS call per column: on the paper system
 * (n = 88, kl = ku = 7) OpenBLAS's zgeru, zaxpy and ztbsv on vectors of 7
 * spent most of a sweep in call overhead (bench_band_lu: 19.0 us per
 * factorisation and two solves against 10.8 us written out). Complex
 * products in real arithmetic (the inputs are finite: no C99 Annex G
 * recovery), divisions by Smith's scaling. A(i, j) is ab[kv + i - j + ld j]. */

/* 1 / (ar + i ai). */
static void recip(double ar, double ai, double *rr, double *ri) {
  if (fabs(ar) >= fabs(ai)) {
    double t = ai / ar, d = ar + ai * t;
    *rr = 1.0 / d, *ri = -t / d;
  } else {
    double t = ar / ai, d = ai + ar * t;
    *rr = t / d, *ri = -1.0 / d;
  }
}

/* x /= a, complex (two doubles each). */
static void cdiv(double *x, const double *a) {
  double rr, ri, xr = x[0], xi = x[1];
  recip(a[0], a[1], &rr, &ri);
  x[0] = xr * rr - xi * ri, x[1] = xr * ri + xi * rr;
}

static rcb_status inline_lu(const rcb_layout *L, double *ab, int *ipiv) {
  size_t n = L->n, kl = L->kl, ku = L->ku, kv = kl + ku, ld = L->ld, j, i, c, ju = 0;
  for (j = ku + 1; j < kv && j < n; j++) /* fill-in of the first columns */
    for (i = kv - j; i < kl; i++) ab[2 * (i + ld * j)] = ab[2 * (i + ld * j) + 1] = 0.0;
  for (j = 0; j < n; j++) {
    size_t km = kl < n - 1 - j ? kl : n - 1 - j, jp = 0;
    double best = -1.0, *d = ab + 2 * (kv + ld * j), rr, ri;
    if (j + kv < n) memset(ab + 2 * ld * (j + kv), 0, 2 * kl * sizeof *ab);
    for (i = 0; i <= km; i++) {
      double a = fabs(d[2 * i]) + fabs(d[2 * i + 1]);
      if (a > best) best = a, jp = i;
    }
    ipiv[j] = (int)(j + jp + 1);
    if (!(best > 0.0)) return RCB_ERR_SINGULAR;
    if (j + ku + jp > ju) ju = j + ku + jp < n - 1 ? j + ku + jp : n - 1;
    for (c = j; jp && c <= ju; c++) {
      double *p = ab + 2 * (kv + j - c + ld * c), *q = p + 2 * jp, t0 = p[0], t1 = p[1];
      p[0] = q[0], p[1] = q[1], q[0] = t0, q[1] = t1;
    }
    if (!km) continue;
    recip(d[0], d[1], &rr, &ri);
    for (i = 1; i <= km; i++) {
      double xr = d[2 * i], xi = d[2 * i + 1];
      d[2 * i] = xr * rr - xi * ri, d[2 * i + 1] = xr * ri + xi * rr;
    }
    for (c = j + 1; c <= ju; c++) {
      double *col = ab + 2 * (kv + j - c + ld * c), ur = col[0], ui = col[1];
      if (ur == 0.0 && ui == 0.0) continue;
      for (i = 1; i <= km; i++) {
        double lr = d[2 * i], li = d[2 * i + 1];
        col[2 * i] -= lr * ur - li * ui;
        col[2 * i + 1] -= lr * ui + li * ur;
      }
    }
  }
  return RCB_OK;
}

/* op(A) x = b with the factors of inline_lu (zgbtrs's order), one column. */
static void inline_solve(const rcb_layout *L, const double *ab, const int *ipiv, double *b,
                         char trans) {
  size_t n = L->n, kl = L->kl, kv = kl + L->ku, ld = L->ld, j, i;
  if (trans == 'N') {
    for (j = 0; j + 1 < n; j++) {
      size_t lm = kl < n - 1 - j ? kl : n - 1 - j, l = (size_t)ipiv[j] - 1;
      const double *m = ab + 2 * (kv + ld * j);
      double tr, ti;
      if (l != j) tr = b[2 * l], ti = b[2 * l + 1], b[2 * l] = b[2 * j],
                  b[2 * l + 1] = b[2 * j + 1], b[2 * j] = tr, b[2 * j + 1] = ti;
      tr = b[2 * j], ti = b[2 * j + 1];
      for (i = 1; i <= lm; i++) {
        b[2 * (j + i)] -= m[2 * i] * tr - m[2 * i + 1] * ti;
        b[2 * (j + i) + 1] -= m[2 * i] * ti + m[2 * i + 1] * tr;
      }
    }
    for (j = n; j-- > 0;) {
      const double *u = ab + 2 * (kv - j + ld * j); /* u[2 i]: A(i, j) */
      double tr, ti;
      cdiv(b + 2 * j, u + 2 * j);
      tr = b[2 * j], ti = b[2 * j + 1];
      for (i = j > kv ? j - kv : 0; i < j; i++) {
        b[2 * i] -= u[2 * i] * tr - u[2 * i + 1] * ti;
        b[2 * i + 1] -= u[2 * i] * ti + u[2 * i + 1] * tr;
      }
    }
    return;
  }
  for (j = 0; j < n; j++) {
    const double *u = ab + 2 * (kv - j + ld * j);
    double tr = b[2 * j], ti = b[2 * j + 1];
    for (i = j > kv ? j - kv : 0; i < j; i++) {
      tr -= u[2 * i] * b[2 * i] - u[2 * i + 1] * b[2 * i + 1];
      ti -= u[2 * i] * b[2 * i + 1] + u[2 * i + 1] * b[2 * i];
    }
    b[2 * j] = tr, b[2 * j + 1] = ti;
    cdiv(b + 2 * j, u + 2 * j);
  }
  for (j = n - 1; j-- > 0;) {
    size_t lm = kl < n - 1 - j ? kl : n - 1 - j, l = (size_t)ipiv[j] - 1;
    const double *m = ab + 2 * (kv + ld * j);
    double tr = b[2 * j], ti = b[2 * j + 1];
    for (i = 1; i <= lm; i++) {
      tr -= m[2 * i] * b[2 * (j + i)] - m[2 * i + 1] * b[2 * (j + i) + 1];
      ti -= m[2 * i] * b[2 * (j + i) + 1] + m[2 * i + 1] * b[2 * (j + i)];
    }
    b[2 * j] = tr, b[2 * j + 1] = ti;
    if (l != j) tr = b[2 * l], ti = b[2 * l + 1], b[2 * l] = b[2 * j],
                b[2 * l + 1] = b[2 * j + 1], b[2 * j] = tr, b[2 * j + 1] = ti;
  }
}

static rcb_status inline_resolve(const rcb_layout *L, const rcb_complex *Z, const int *ipiv,
                                 rcb_complex *B, size_t nrhs, char trans) {
  size_t r;
  if (trans != 'N' && trans != 'T') return RCB_ERR_ARG;
  for (r = 0; r < nrhs; r++)
    inline_solve(L, (const double *)Z, ipiv, (double *)(B + L->n * r), trans);
  return RCB_OK;
}

static rcb_status inline_factor_solve(const rcb_layout *L, rcb_complex *Z, int *ipiv,
                                      rcb_complex *B, size_t nrhs) {
  rcb_status st = inline_lu(L, (double *)Z, ipiv);
  return st ? st : inline_resolve(L, Z, ipiv, B, nrhs, 'N');
}

static const rcb_zsolver_ops banded_inline_ops = {"banded (inline)", rcb_layout_banded,
                                                  inline_factor_solve, inline_resolve,
                                                  NULL, NULL, NULL, banded_rcond};

const rcb_zsolver_ops *rcb_zsolver_banded_inline(void) { return &banded_inline_ops; }
