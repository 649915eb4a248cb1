/* Banded backend: LAPACK zgbsv. Nodes numbered along the train keep the
 * half-bandwidth small (7 for a chain of 4-DOF nodes), so one factorisation
 * costs O(n bw^2) instead of O(n^3). */
#include <lapacke.h>

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
