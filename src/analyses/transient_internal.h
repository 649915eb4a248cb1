/* The transient-analysis object, shared by transient.c (setup, equations of
 * motion) and transient_run.c (runs, steady-state extraction). */
#ifndef RCB_TRANSIENT_INTERNAL_H
#define RCB_TRANSIENT_INTERNAL_H

#include <lapacke.h>

#include "assembly/assembly.h"
#include "solvers/sundials_adapter.h"

#if RCB_WITH_SUNDIALS
#include <nvector/nvector_serial.h>
#include <sundials/sundials_linearsolver.h>
#include <sundials/sundials_matrix.h>
#endif

struct rcb_transient {
  rcb_allocator alloc;
  char errmsg[RCB_ERRMSG_MAX];
  const rcb_model *m;
  size_t n, nout, *out_row;
  /* M^-1 times the speed-independent matrices (structure and constant
   * bearings), n x n column-major: 1/s^2, 1/s, 1/s. */
  double *MiK, *MiC, *MiG;
  /* Tabulated (speed-dependent) bearings: their indices, and M^-1 e_r for
   * the x and y rows r of each (n x 2 ntab), 1/kg. */
  size_t ntab, *tab;
  double *MiB;
  double *Pr, *Pi; /* M^-1 F1 (unbalance phasor at unit speed), m/s^2 per (rad/s)^2 */
  double *q, *v, *out; /* sample buffers: n, n, nout */
  /* External force (rcb_transient_set_force): M^-1 e_dof (n, 1/kg or
   * 1/(kg m^2)) and the caller's samples (nf, N or N m, every dtf s from
   * t = 0, linear between samples, 0 after the last); fext NULL: none. */
  double *Mif;
  const double *fext;
  size_t nf;
  double dtf;
  rcb_complex *Qa, *Qb; /* steady state: 1X phasors of two revolutions (nout) */
  double rtol, atol_q, atol_v;
  double ss_tol;
  size_t ss_spp, ss_max_periods;
  rcb_speed_profile prof; /* of the run in progress */
  rcb_transient_stats stats;
  size_t bytes;
#if RCB_WITH_SUNDIALS
  SUNContext ctx;
  void *cvode;
  N_Vector y, abstol;
  SUNMatrix J; /* 2n x 2n: CVODE requires one for a direct solver; never filled
                  (rcb_transient_linsys forms the n x n blocks instead) */
  SUNLinearSolver LS;
  rcb_sun_route route;
  double *Kt, *Dt; /* M^-1 K and M^-1 (C + Omega G) at the last Jacobian's speed,
                      n x n: 1/s^2, 1/s (rcb_transient_linsys) */
  double gamma;     /* CVODE's gamma of S (s) */
  double *S;      /* Schur complement of I - gamma J, n x n, LU-factored */
  lapack_int *ipiv; /* its pivots */
  char sunmsg[256]; /* last SUNDIALS message */
  int started;      /* CVodeInit done */
#endif
};

/* The external force at time t (s), N or N m (0 without one). */
double rcb_transient_force_at(const rcb_transient *t, double tt);

/* Omega (rad/s), alpha (rad/s^2) and phi (rad) of the profile at time t (s). */
void rcb_profile_eval(const rcb_speed_profile *p, double t, double *speed, double *accel,
                      double *angle);

#if RCB_WITH_SUNDIALS
/* CVODE callbacks (transient.c). */
int rcb_transient_rhs(sunrealtype t, N_Vector y, N_Vector ydot, void *user);
/* The Schur-complement linear solver for CVODE (transient_linsol.c). */
SUNLinearSolver rcb_transient_linsol(rcb_transient *t);
/* CVODE's linear system function (transient.c): Kt, Dt and S, A untouched. */
int rcb_transient_linsys(sunrealtype t, N_Vector y, N_Vector fy, SUNMatrix A,
                         sunbooleantype jok, sunbooleantype *jcur, sunrealtype gamma,
                         void *user, N_Vector tmp1, N_Vector tmp2, N_Vector tmp3);
#endif

#endif
