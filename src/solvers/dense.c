/* Dense backend: LAPACK zgesv (LU with partial pivoting), all right-hand
 * sides in one call. The _work variant allocates nothing. */
#include <lapacke.h>

#include "solvers/zsolver.h"

_Static_assert(sizeof(lapack_int) == sizeof(int), "librcb expects 32-bit LAPACK integers");

static void dense_layout(rcb_layout *L, size_t n, size_t bw) {
  (void)bw;
  rcb_layout_dense(L, n);
}

static rcb_status dense_solve(const rcb_layout *L, rcb_complex *Z, int *ipiv, rcb_complex *B,
                              size_t nrhs) {
  lapack_int n = (lapack_int)L->n, info;
  info = LAPACKE_zgesv_work(LAPACK_COL_MAJOR, n, (lapack_int)nrhs, (lapack_complex_double *)Z,
                            (lapack_int)L->ld, (lapack_int *)ipiv, (lapack_complex_double *)B,
                            n);
  if (info > 0) return RCB_ERR_SINGULAR;
  if (info < 0) return RCB_ERR_LAPACK;
  return RCB_OK;
}

static rcb_status dense_resolve(const rcb_layout *L, const rcb_complex *Z, const int *ipiv,
                                rcb_complex *B, size_t nrhs, char trans) {
  lapack_int n = (lapack_int)L->n;
  lapack_int info = LAPACKE_zgetrs_work(LAPACK_COL_MAJOR, trans, n, (lapack_int)nrhs,
                                        (const lapack_complex_double *)Z, (lapack_int)L->ld,
                                        (const lapack_int *)ipiv,
                                        (lapack_complex_double *)B, n);
  return info ? RCB_ERR_LAPACK : RCB_OK;
}

/* zgecon: Hager-Higham estimate of ||Z^-1||_1 from the LU factors, O(n^2). */
static rcb_status dense_rcond(const rcb_layout *L, const rcb_complex *Z, const int *ipiv,
                              double anorm, rcb_complex *work, double *rwork, double *rcond) {
  lapack_int info;
  (void)ipiv;
  info = LAPACKE_zgecon_work(LAPACK_COL_MAJOR, '1', (lapack_int)L->n,
                             (const lapack_complex_double *)Z, (lapack_int)L->ld, anorm, rcond,
                             (lapack_complex_double *)work, rwork);
  return info ? RCB_ERR_LAPACK : RCB_OK;
}

static const rcb_zsolver_ops dense_ops = {"dense", dense_layout, dense_solve, dense_resolve,
                                          NULL,    NULL,         NULL,        dense_rcond};

const rcb_zsolver_ops *rcb_zsolver_dense(void) { return &dense_ops; }
