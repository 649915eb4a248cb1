/*
 * The internal interface of analyses/ that other folders may use (identify/
 * for the analytic sensitivities of paper eq. 9). Everything else about the
 * FRF object (its matrices, its factors, the solver table) stays private to
 * analyses/ (frf_internal.h). Not installed.
 *
 * A direct solve at one point, rcb_frf_eval (not with RCB_SOLVER_MODAL) or
 * rcb_frf_unbalance, leaves that point's factorisation of
 * Z = K - w^2 M + i w (C + W G) in the object with its solutions X; the
 * calls below reuse both, so that the sensitivities of every parameter at
 * that point cost re-solves, never another factorisation. They fail with
 * RCB_ERR_STATE when no direct solve has succeeded since the object was
 * created or refreshed (rcb_frf_refresh).
 */
#ifndef RCB_ANALYSES_H
#define RCB_ANALYSES_H

#include "assembly/assembly.h"

/* The storage layout of the object's matrices (dense, band or CSC): the
 * layout derivative matrices dM, dC, dG, dK are assembled in to meet its
 * solutions. */
const rcb_layout *rcb_frf_layout(const rcb_frf *f);
/* Matrix row (reduced DOF index) of output o. */
size_t rcb_frf_output_row(const rcb_frf *f, size_t o);
/* Solution of input q of the last direct solve, X_q = Z^-1 e_q (n values;
 * rcb_frf_unbalance: q = 0, the unbalance response); NULL without one. The
 * inputs' solutions are contiguous: X_q = rcb_frf_solution(f, 0) + n q. */
const rcb_complex *rcb_frf_solution(const rcb_frf *f, size_t q);
/* Solve again with the last factorisation: Z X = B for nrhs right-hand
 * sides (B: n x nrhs column-major, the caller's, overwritten by X). */
rcb_status rcb_frf_solve_again(rcb_frf *f, rcb_complex *B, size_t nrhs);
/* The adjoint solutions of the outputs with the last factorisation:
 * Z^T Y = E_out, column o of Y (n x nout column-major, the caller's) being
 * the row of Z^-1 that output o reads, so that dH_oq/dp = -Y_o^T (dZ/dp) X_q. */
rcb_status rcb_frf_solve_adjoint(rcb_frf *f, rcb_complex *Y);

#endif /* RCB_ANALYSES_H */
