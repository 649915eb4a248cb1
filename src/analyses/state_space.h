/*
 * The first-order (state-space) form shared by the damped modes (modes.c)
 * and the modal FRF path (frf_modal.c).
 */
#ifndef RCB_STATE_SPACE_H
#define RCB_STATE_SPACE_H

#include "core/rcb_internal.h"

/* A = [0, I; -M^-1 K, -M^-1 (C + speed G)], N = 2n, column-major, at rotor
 * speed (rad/s), with n = m->ndof. Work: M, G (n x n), KD (n x 2n). On
 * return M holds its lower Cholesky factor (for M^-1 of other right-hand
 * sides) and KD = M^-1 [K | C + speed G]. errmsg (the caller's) gets
 * "<who>: ..." on failure: RCB_ERR_MODEL when M is not positive definite,
 * RCB_ERR_LAPACK, or the assembly's status. */
rcb_status rcb_state_matrix(const rcb_model *m, double speed, double *M, double *KD, double *G,
                            double *A, char *errmsg, const char *who);

#endif
