/* The state-space matrix of M q'' + (C + Omega G) q' + K q = f (see state_space.h). */
#include <lapacke.h>
#include <string.h>

#include "analyses/state_space.h"

rcb_status rcb_state_matrix(const rcb_model *m, double speed, double *M, double *KD, double *G,
                            double *A, char *errmsg, const char *who) {
  const size_t n = m->ndof, N = 2 * n, nn = n * n;
  double *K = KD, *D = KD + nn;
  lapack_int ni = (lapack_int)n, info;
  size_t i, j;
  rcb_status st = rcb_model_matrices(m, speed, M, D, G, K);
  if (st)
    return rcb_set_error(errmsg, st, "%s: assembling the matrices at %g rad/s: %s", who, speed,
                         rcb_status_str(st));
  for (i = 0; i < nn; i++) D[i] += speed * G[i];
  info = LAPACKE_dpotrf_work(LAPACK_COL_MAJOR, 'L', ni, M, ni);
  if (info > 0)
    return rcb_set_error(errmsg, RCB_ERR_MODEL,
                         "%s: the mass matrix is not positive definite (leading minor %d of "
                         "%zu); every DOF needs mass or inertia (shaft elements give both)",
                         who, (int)info, n);
  if (!info) info = LAPACKE_dpotrs_work(LAPACK_COL_MAJOR, 'L', ni, 2 * ni, M, ni, KD, ni);
  if (info)
    return rcb_set_error(errmsg, RCB_ERR_LAPACK, "%s: Cholesky of M failed (LAPACK info %d)",
                         who, (int)info);
  memset(A, 0, N * N * sizeof *A);
  for (i = 0; i < n; i++) A[i + N * (n + i)] = 1.0;
  for (j = 0; j < 2 * n; j++)
    for (i = 0; i < n; i++) A[n + i + N * j] = -KD[i + n * j];
  return RCB_OK;
}
