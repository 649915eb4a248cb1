/*
 * The Newton systems of CVODE, (I - gamma J) x = b with the Jacobian of the
 * second-order structure, J = [0 I; -M^-1 K, -M^-1 D], solved on the
 * n x n Schur complement instead of the 2n x 2n matrix. Writing
 * A = I - gamma J = [I, A12; A21, A22] with A12 = -gamma I,
 *   (A22 - A21 A12) x_v = b_v - A21 b_q,   x_q = b_q - A12 x_v,
 * and A22 - A21 A12 = A22 + gamma A21 = I + gamma M^-1 D + gamma^2 M^-1 K.
 * The blocks are read from the matrix CVODE hands over, so the solver holds
 * for any speed profile. One LAPACK dgetrf of order n per setup: 8 times
 * fewer flops than the 2n LU of SUNLinSol_Dense, in blocked LAPACK code.
 * The solver is a SUNLinearSolver of type DIRECT ("matrix-based"), the
 * same in SUNDIALS 6 and 7.
 */
#include <lapacke.h>
#include <string.h>

#include "analyses/transient_internal.h"

#if RCB_WITH_SUNDIALS
#include <sunmatrix/sunmatrix_dense.h>

static SUNLinearSolver_Type schur_type(SUNLinearSolver S) {
  (void)S;
  return SUNLINEARSOLVER_DIRECT;
}

static int schur_initialize(SUNLinearSolver S) {
  (void)S;
  return 0;
}

/* Columns j < n of A hold [I; A21], columns n + j hold [A12; A22]. */
static int schur_setup(SUNLinearSolver LS, SUNMatrix A) {
  rcb_transient *t = LS->content;
  size_t i, j, n = t->n;
  double gamma = -SUNDenseMatrix_Column(A, (sunindextype)n)[0]; /* A12 = -gamma I */
  lapack_int info;
  for (j = 0; j < n; j++) {
    const double *a21 = SUNDenseMatrix_Column(A, (sunindextype)j) + n;
    const double *a22 = SUNDenseMatrix_Column(A, (sunindextype)(n + j)) + n;
    double *s = t->S + n * j;
    for (i = 0; i < n; i++) s[i] = a22[i] + gamma * a21[i];
  }
  info = LAPACKE_dgetrf_work(LAPACK_COL_MAJOR, (lapack_int)n, (lapack_int)n, t->S,
                             (lapack_int)n, t->ipiv);
  return info == 0 ? 0 : SUNLS_LUFACT_FAIL; /* recoverable: CVODE cuts the step */
}

static int schur_solve(SUNLinearSolver LS, SUNMatrix A, N_Vector x, N_Vector b,
                       sunrealtype tol) {
  rcb_transient *t = LS->content;
  size_t i, j, n = t->n;
  const double *bb = N_VGetArrayPointer(b);
  double *xx = N_VGetArrayPointer(x), gamma = -SUNDenseMatrix_Column(A, (sunindextype)n)[0];
  double *xv = xx + n;
  (void)tol;
  /* x may alias b: keep b_q in the top half, form the reduced rhs below. */
  if (xx != bb) memcpy(xx, bb, 2 * n * sizeof *xx);
  for (j = 0; j < n; j++) {
    const double *a21 = SUNDenseMatrix_Column(A, (sunindextype)j) + n;
    double bq = xx[j];
    for (i = 0; i < n; i++) xv[i] -= a21[i] * bq;
  }
  if (LAPACKE_dgetrs_work(LAPACK_COL_MAJOR, 'N', (lapack_int)n, 1, t->S, (lapack_int)n,
                          t->ipiv, xv, (lapack_int)n) != 0)
    return SUNLS_PACKAGE_FAIL_REC;
  for (i = 0; i < n; i++) xx[i] += gamma * xv[i];
  return 0;
}

static int schur_free(SUNLinearSolver S) {
  SUNLinSolFreeEmpty(S);
  return 0;
}

SUNLinearSolver rcb_transient_linsol(rcb_transient *t) {
  SUNLinearSolver S = SUNLinSolNewEmpty(t->ctx);
  if (!S) return NULL;
  S->ops->gettype = schur_type;
  S->ops->initialize = schur_initialize;
  S->ops->setup = schur_setup;
  S->ops->solve = schur_solve;
  S->ops->free = schur_free;
  S->content = t;
  return S;
}
#endif
