/* The FRF workspace, shared with the identification stage, which reuses its
 * factorisation for the analytic sensitivities (paper eq. 9). */
#ifndef RCB_FRF_INTERNAL_H
#define RCB_FRF_INTERNAL_H

#include "assembly/assembly.h"
#include "solvers/zsolver.h"

/* A new array owned by the object must also be given its own copy in
 * sweep.c (worker_create / worker_destroy: thread workspaces are shallow
 * copies of this struct). */
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
  int factored;          /* Z / ipiv (or KLU's factors) and B hold the last
                            successful direct solve (frf_reuse.c) */
  size_t nout, nin, *out_row, *in_row;
  size_t bytes;
  struct rcb_frf_modal *modal; /* frf_modal.c: NULL unless RCB_SOLVER_MODAL */
  /* condition monitoring (frf_cond.c) */
  int cond_on;             /* RCB_COND_OFF, _SCREEN (default) or _ALWAYS */
  double anorm;            /* 1-norm of Z before the factorisation */
  rcb_complex *cond_work;  /* 2n, estimator work */
  double *cond_rwork;      /* 2n */
  rcb_frf_condition cond;  /* smallest rcond since the last reset, and where */
};

/* frf_cond.c, called by frf.c: size the estimator's work (at creation),
 * free it, note ||Z||_1 before the factorisation, and estimate the
 * condition after a successful one (never fails: a failed estimate is
 * recorded as NaN, which counts as ill-conditioned). */
rcb_status rcb_frf_cond_setup(rcb_frf *f);
void rcb_frf_cond_free(rcb_frf *f);
void rcb_frf_cond_before(rcb_frf *f);
void rcb_frf_cond_after(rcb_frf *f, double omega, double speed);

/* Form Z(omega, speed) (rad/s), factor it in place and solve Z X = B for the
 * first nrhs columns of f->B. The factors stay in f->Z / f->ipiv. */
rcb_status rcb_frf_factor_solve(rcb_frf *f, double omega, double speed, size_t nrhs);

/* H(omega) by the direct solver, whatever f's solver kind (rcb_frf_eval
 * without the modal dispatch). */
rcb_status rcb_frf_eval_direct(rcb_frf *f, double omega, double speed, rcb_frf_kind kind,
                               rcb_complex *H);

/* frf_modal.c, called by frf.c and sweep.c: the modal solution path (paper
 * eq. 7). create sizes f->modal (copying the truncation settings of like,
 * if not NULL); invalidate forgets the basis (after rcb_frf_refresh); basis
 * computes it at a speed unless it is current; sum evaluates the modal sum
 * of a current basis without touching it (threads share it). */
struct rcb_frf_modal;
rcb_status rcb_frf_modal_create(rcb_frf *f, const struct rcb_frf_modal *like);
void rcb_frf_modal_destroy(rcb_frf *f);
void rcb_frf_modal_invalidate(rcb_frf *f);
size_t rcb_frf_modal_memory(const rcb_frf *f);
rcb_status rcb_frf_modal_basis(rcb_frf *f, double speed);
rcb_status rcb_frf_modal_eval(rcb_frf *f, double omega, double speed, rcb_frf_kind kind,
                              rcb_complex *H);
/* sweep.c: drop the sparse solver's factors and pivot history (a fresh
 * symbolic analysis; nothing for the LAPACK solvers), so that the next
 * solve does not depend on earlier ones. */
rcb_status rcb_frf_solver_reset(rcb_frf *f);
void rcb_frf_modal_sum(const struct rcb_frf_modal *md, double omega, rcb_frf_kind kind,
                       rcb_complex *H);

#endif
