/*
 * Complex linear solvers for the dynamic stiffness Z(w) X = B, behind a small
 * table of function pointers (one file per backend): dense LAPACK zgesv,
 * banded LAPACK zgbsv, sparse KLU (klu_z_*). Each overwrites B with X; the
 * LAPACK ones factor Z in place, KLU keeps its factors in the layout's
 * solver state.
 */
#ifndef RCB_ZSOLVER_H
#define RCB_ZSOLVER_H

#include "assembly/assembly.h"

typedef struct rcb_zsolver_ops_s {
  const char *name;
  /* Layout this backend factors, for a model of order n and half-bandwidth bw;
   * NULL for the sparse backend (the caller sets a CSC layout on the model's
   * pattern, rcb_csc_pattern, then calls prepare). */
  void (*layout)(rcb_layout *L, size_t n, size_t bw);
  /* Solve in place; ipiv has n entries. RCB_ERR_SINGULAR when a pivot is 0. */
  rcb_status (*solve)(const rcb_layout *L, rcb_complex *Z, int *ipiv, rcb_complex *B,
                      size_t nrhs);
  /* Solve again with the factors left by solve: op(Z) X = B, trans 'N' or 'T'. */
  rcb_status (*resolve)(const rcb_layout *L, const rcb_complex *Z, const int *ipiv,
                        rcb_complex *B, size_t nrhs, char trans);
  /* Optional (NULL for LAPACK): analyse the pattern once (KLU symbolic
   * ordering) and keep the state in L->solver; release frees it. The state
   * struct comes from a; KLU's own factors come from SuiteSparse's malloc. */
  rcb_status (*prepare)(rcb_layout *L, const rcb_allocator *a);
  void (*release)(rcb_layout *L, const rcb_allocator *a);
  /* Optional: bytes held by the backend state (KLU's peak usage), 0 if none. */
  size_t (*memory)(const rcb_layout *L);
  /* Reciprocal condition number (1-norm) of the matrix the last solve
   * factored: LAPACK zgecon / zgbcon on the factors in Z (anorm: the 1-norm
   * of Z before the factorisation, rcb_layout_norm1), KLU klu_z_condest on
   * its own factors and the values still in Z (anorm unused). O(n^2) dense,
   * O(n bw) banded, a few sparse solves; work 2n, rwork 2n entries. */
  rcb_status (*rcond)(const rcb_layout *L, const rcb_complex *Z, const int *ipiv, double anorm,
                      rcb_complex *work, double *rwork, double *rcond);
} rcb_zsolver_ops;

const rcb_zsolver_ops *rcb_zsolver_dense(void);
const rcb_zsolver_ops *rcb_zsolver_banded(void);
/* NULL when librcb was built without RCB_WITH_SUITESPARSE. */
const rcb_zsolver_ops *rcb_zsolver_sparse(void);
/* Full factorisations and kept-pivot refactorisations done so far by the
 * sparse backend on layout L (0, 0 for the other backends). */
/* 1-norm (largest column sum of |Z_ij|) of a matrix in any layout; NaN if
 * an entry is NaN (solvers/condition.c). */
double rcb_layout_norm1(const rcb_layout *L, const rcb_complex *Z);
/* min|U_ii| / max|U_ii| of the factors left by the last solve (-): read off
 * the LAPACK factors in Z, or KLU's, on the row-scaled pivots (as
 * klu_z_rcond; see solvers/klu.c); NaN if unknown. */
double rcb_layout_pivot_ratio(const rcb_layout *L, const rcb_complex *Z);
double rcb_zsolver_sparse_pivot_ratio(const rcb_layout *L);
void rcb_zsolver_sparse_counts(const rcb_layout *L, size_t *factors, size_t *refactors);

#endif
