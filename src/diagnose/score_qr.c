/*
 * The score test's orthogonalisation by LAPACK Householder QR (dgeqrf,
 * dormqr): the predicted reduction of F = r^T r from a candidate's columns
 * J_c is || Q_c^T r ||^2, Q_c an orthonormal basis of the part of span(J_c)
 * orthogonal to the fitted parameters' columns J0.
 *
 * J0 is factored once, J0 = Q0 R0. For a candidate, Q0^T J_c splits into
 * the rows of span(Q0) and the rows of its orthogonal complement; a second
 * QR of the complement rows gives Q_c there, and with rt = Q0^T r (taken
 * once) the reduction is || (Q_c^T rt_2)_{1..k} ||^2 (orthogonal maps keep
 * inner products).
 *
 * Columns are factored one at a time so that a column nearly in the span of
 * those kept before it (its remaining part below RCB_DIAG_RANK_TOL of its
 * own norm, columns scaled to unit norm first) is dropped, whatever its
 * units: the parameter itself is explained by what is already fitted.
 */
#include <lapacke.h>
#include <math.h>
#include <string.h>

#include "diagnose/diag_internal.h"

/* Relative norm below which a column counts as dependent on those kept. */
#define RCB_DIAG_RANK_TOL 1e-10

/* Scale the k columns of A (m x k, leading dimension lda) to unit norm (a
 * zero column stays zero, and is dropped by qr_keep). */
static void unit_columns(double *A, size_t m, size_t k, size_t lda) {
  size_t j, i;
  for (j = 0; j < k; j++) {
    double *a = A + lda * j, s = 0.0;
    for (i = 0; i < m; i++) s += a[i] * a[i];
    if (!(s > 0)) continue;
    s = 1.0 / sqrt(s);
    for (i = 0; i < m; i++) a[i] *= s;
  }
}

/* Householder QR of the unit columns of A (m x k, leading dimension lda),
 * column by column: each is reflected by those kept before it (dormqr) and
 * kept, with a new reflector (dgeqrf of its remaining rows), when its
 * remaining part exceeds RCB_DIAG_RANK_TOL. Kept columns move to the front;
 * reflectors and tau in dgeqrf's layout. *kept: columns kept; -1 when
 * LAPACK reports an error. */
static int qr_keep(double *A, size_t m, size_t k, size_t lda, double *tau, double *work,
                   size_t lwork, size_t *kept) {
  size_t j, i, q = 0;
  lapack_int ld = (lapack_int)lda, lw = (lapack_int)lwork;
  for (j = 0; j < k && q < m; j++) {
    double *c = A + lda * q, s = 0.0;
    if (j != q) memcpy(c, A + lda * j, m * sizeof *c);
    if (q && LAPACKE_dormqr_work(LAPACK_COL_MAJOR, 'L', 'T', (lapack_int)m, 1, (lapack_int)q, A,
                                 ld, tau, c, ld, work, lw))
      return -1;
    for (i = q; i < m; i++) s += c[i] * c[i];
    if (!(s > RCB_DIAG_RANK_TOL * RCB_DIAG_RANK_TOL)) continue;
    if (LAPACKE_dgeqrf_work(LAPACK_COL_MAJOR, (lapack_int)(m - q), 1, c + q, ld, tau + q, work,
                            lw))
      return -1;
    q++;
  }
  *kept = q;
  return 0;
}

/* Largest workspace of dgeqrf on one column and dormqr on up to ncol
 * columns with up to k reflectors, m rows. */
static size_t work_query(size_t m, size_t k, size_t ncol, double *A, double *tau) {
  double q1 = 0.0, q2 = 0.0;
  lapack_int lm = (lapack_int)m;
  if (LAPACKE_dgeqrf_work(LAPACK_COL_MAJOR, lm, 1, A, lm, tau, &q1, -1) ||
      LAPACKE_dormqr_work(LAPACK_COL_MAJOR, 'L', 'T', lm, (lapack_int)ncol, (lapack_int)k, A, lm,
                          tau, A, lm, &q2, -1))
    return 0;
  return (size_t)fmax(fmax(q1, q2), 1.0);
}

void rcb_diag_basis_free(rcb_diag *d, diag_basis *b) {
  rcb_free(&d->alloc, b->qr);
  rcb_free(&d->alloc, b->work);
  memset(b, 0, sizeof *b);
}

rcb_status rcb_diag_basis_init(rcb_diag *d, diag_basis *b, const double *J0, size_t n,
                               size_t nb, const double *r) {
  size_t ncol = nb > RCB_DIAG_MAXP ? nb : RCB_DIAG_MAXP, lwork, total;
  lapack_int info;
  memset(b, 0, sizeof *b);
  b->n = n;
  /* qr: n x nb; rt, r2: n each; tau: nb + RCB_DIAG_MAXP; then the work */
  total = n * (nb ? nb : 1) + 2 * n + nb + RCB_DIAG_MAXP;
  if (!(b->qr = rcb_alloc(&d->alloc, total * sizeof *b->qr)))
    return rcb_diag_fail(d, RCB_ERR_NOMEM, "out of memory (score test)");
  b->rt = b->qr + n * (nb ? nb : 1), b->r2 = b->rt + n, b->tau = b->r2 + n;
  b->tau_c = b->tau + nb;
  /* at most n reflectors on n rows (DORMQR's argument 5: 1 channel x 21
   * points with 88 columns asked for 88, an illegal argument that LAPACK's
   * xerbla printed) */
  lwork = work_query(n, ncol < n ? ncol : n, ncol, b->qr, b->tau);
  if (!lwork) {
    rcb_diag_basis_free(d, b);
    return rcb_diag_fail(d, RCB_ERR_LAPACK, "score test: LAPACK workspace query failed");
  }
  b->lwork = lwork;
  if (!(b->work = rcb_alloc(&d->alloc, lwork * sizeof *b->work))) {
    rcb_diag_basis_free(d, b);
    return rcb_diag_fail(d, RCB_ERR_NOMEM, "out of memory (score test)");
  }
  if (nb) memcpy(b->qr, J0, n * nb * sizeof *b->qr);
  memcpy(b->rt, r, n * sizeof *b->rt);
  unit_columns(b->qr, n, nb, n);
  info = qr_keep(b->qr, n, nb, n, b->tau, b->work, lwork, &b->rank);
  if (!info && b->rank)
    info = LAPACKE_dormqr_work(LAPACK_COL_MAJOR, 'L', 'T', (lapack_int)n, 1,
                               (lapack_int)b->rank, b->qr, (lapack_int)n, b->tau, b->rt,
                               (lapack_int)n, b->work, (lapack_int)lwork);
  if (info) {
    rcb_diag_basis_free(d, b);
    return rcb_diag_fail(d, RCB_ERR_LAPACK, "score test: QR of the fitted parameters' columns "
                                            "failed (LAPACK info %d)", (int)info);
  }
  return RCB_OK;
}

rcb_status rcb_diag_explained(rcb_diag *d, diag_basis *b, double *J, size_t np, double *pred) {
  size_t n = b->n, q = b->rank, m = n - q, kept = 0, k;
  lapack_int info = 0, lw = (lapack_int)b->lwork;
  *pred = 0.0;
  if (np > RCB_DIAG_MAXP) return rcb_diag_fail(d, RCB_ERR_ARG, "score test: %zu columns", np);
  if (!np || !m) return RCB_OK;
  unit_columns(J, n, np, n);
  if (q)
    info = LAPACKE_dormqr_work(LAPACK_COL_MAJOR, 'L', 'T', (lapack_int)n, (lapack_int)np,
                               (lapack_int)q, b->qr, (lapack_int)n, b->tau, J, (lapack_int)n,
                               b->work, lw);
  /* rows q .. n of Q0^T J_c: the candidate beyond span(J0) */
  if (!info && qr_keep(J + q, m, np, n, b->tau_c, b->work, b->lwork, &kept)) info = -1;
  memcpy(b->r2, b->rt + q, m * sizeof *b->r2);
  if (!info && kept)
    info = LAPACKE_dormqr_work(LAPACK_COL_MAJOR, 'L', 'T', (lapack_int)m, 1, (lapack_int)kept,
                               J + q, (lapack_int)n, b->tau_c, b->r2, (lapack_int)m, b->work, lw);
  if (info)
    return rcb_diag_fail(d, RCB_ERR_LAPACK, "score test: QR of a candidate's columns failed "
                                            "(LAPACK info %d)", (int)info);
  for (k = 0; k < kept; k++) *pred += b->r2[k] * b->r2[k];
  return RCB_OK;
}
