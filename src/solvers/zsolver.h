/*
 * Complex linear solvers for the dynamic stiffness Z(w) X = B, behind a small
 * table of function pointers (one file per backend): dense LAPACK zgesv,
 * banded LAPACK zgbsv. Each factors Z in place and overwrites B with X.
 */
#ifndef RCB_ZSOLVER_H
#define RCB_ZSOLVER_H

#include "assembly/assembly.h"

typedef struct rcb_zsolver_ops_s {
  const char *name;
  /* Layout this backend factors, for a model of order n and half-bandwidth bw. */
  void (*layout)(rcb_layout *L, size_t n, size_t bw);
  /* Solve in place; ipiv has n entries. RCB_ERR_SINGULAR when a pivot is 0. */
  rcb_status (*solve)(const rcb_layout *L, rcb_complex *Z, int *ipiv, rcb_complex *B,
                      size_t nrhs);
  /* Solve again with the factors left by solve: op(Z) X = B, trans 'N' or 'T'. */
  rcb_status (*resolve)(const rcb_layout *L, const rcb_complex *Z, const int *ipiv,
                        rcb_complex *B, size_t nrhs, char trans);
} rcb_zsolver_ops;

const rcb_zsolver_ops *rcb_zsolver_dense(void);
const rcb_zsolver_ops *rcb_zsolver_banded(void);

#endif
