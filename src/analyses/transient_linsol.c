/*
 * The Newton systems of CVODE, (I - gamma J) x = b with the Jacobian of the
 * second-order structure, J = [0 I; -Kt, -Dt] (Kt = M^-1 K, Dt = M^-1 D),
 * solved on the n x n Schur complement instead of the 2n x 2n matrix.
 * Writing A = I - gamma J = [I, A12; A21, A22] with A12 = -gamma I,
 * A21 = gamma Kt, A22 = I + gamma Dt,
 *   (A22 - A21 A12) x_v = b_v - A21 b_q,   x_q = b_q - A12 x_v,
 * and A22 - A21 A12 = S = I + gamma Dt + gamma^2 Kt.
 * rcb_transient_linsys (transient.c, CVODE's linear system function) forms
 * Kt, Dt and S at the speed of the Jacobian's time, so the solver holds for
 * any speed profile, and leaves CVODE's 2n x 2n matrix untouched. One LAPACK
 * dgetrf of order n per setup: 8 times fewer flops than the 2n LU of
 * SUNLinSol_Dense, in blocked LAPACK code. The solver is a SUNLinearSolver of
 * type DIRECT ("matrix-based"), the same in SUNDIALS 6 and 7.
 */
#include <lapacke.h>
#include <string.h>

#include "analyses/transient_internal.h"

#if RCB_WITH_SUNDIALS
static SUNLinearSolver_Type schur_type(SUNLinearSolver S) {
  (void)S;
  return SUNLINEARSOLVER_DIRECT;
}

static int schur_initialize(SUNLinearSolver S) {
  (void)S;
  return 0;
}

/* S was formed by rcb_transient_linsys; A is not read. */
static int schur_setup(SUNLinearSolver LS, SUNMatrix A) {
  rcb_transient *t = LS->content;
  lapack_int info, n = (lapack_int)t->n;
  (void)A;
  info = LAPACKE_dgetrf_work(LAPACK_COL_MAJOR, n, n, t->S, n, t->ipiv);
  return info == 0 ? 0 : SUNLS_LUFACT_FAIL; /* recoverable: CVODE cuts the step */
}

static int schur_solve(SUNLinearSolver LS, SUNMatrix A, N_Vector x, N_Vector b,
                       sunrealtype tol) {
  rcb_transient *t = LS->content;
  size_t i, j, n = t->n;
  const double *bb = N_VGetArrayPointer(b);
  double *xx = N_VGetArrayPointer(x), gamma = t->gamma;
  double *xv = xx + n;
  (void)A;
  (void)tol;
  /* x may alias b: keep b_q in the top half, form the reduced rhs below:
   * x_v = b_v - gamma Kt b_q. */
  if (xx != bb) memcpy(xx, bb, 2 * n * sizeof *xx);
  for (j = 0; j < n; j++) {
    const double *kc = t->Kt + n * j;
    double gq = gamma * xx[j];
    for (i = 0; i < n; i++) xv[i] -= kc[i] * gq;
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
