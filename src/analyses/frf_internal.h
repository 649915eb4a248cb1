/* The FRF workspace, shared with the identification stage, which reuses its
 * factorisation for the analytic sensitivities (paper eq. 9). */
#ifndef RCB_FRF_INTERNAL_H
#define RCB_FRF_INTERNAL_H

#include "assembly/assembly.h"
#include "solvers/zsolver.h"

struct rcb_frf {
  rcb_allocator alloc;
  char errmsg[RCB_ERRMSG_MAX];
  const rcb_model *m;
  const rcb_zsolver_ops *ops;
  rcb_layout L;
  double *M, *C, *G, *K; /* structure without bearings, in layout L */
  rcb_complex *Z;        /* dynamic stiffness, factored in place */
  rcb_complex *B;        /* n x max(nin, 1) right-hand sides / solutions */
  int *ipiv;
  size_t nout, nin, *out_row, *in_row;
  size_t bytes;
};

/* Form Z(omega, speed) (rad/s), factor it in place and solve Z X = B for the
 * first nrhs columns of f->B. The factors stay in f->Z / f->ipiv. */
rcb_status rcb_frf_factor_solve(rcb_frf *f, double omega, double speed, size_t nrhs);

#endif
