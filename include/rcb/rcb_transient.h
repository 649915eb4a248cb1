/**
 * @file rcb_transient.h
 * @brief Time integration of M q'' + (C + Omega(t) G) q' + K q = f(t) with
 * SUNDIALS CVODE: unbalance response at constant speed (steady-state 1X
 * amplitude and phase, a cross-check of rcb_frf_unbalance), run-up and
 * coast-down along a speed ramp, free vibration from initial conditions.
 *
 * The model is integrated as the first-order system y = [q; q'] of size 2n
 * (n = rcb_model_dof_count()) with CVODE's BDF method (variable order 1-3,
 * Newton iteration; the 2n x 2n Newton systems are solved on their n x n
 * Schur complement with LAPACK) and an analytic Jacobian
 * J = [0 I; -M^-1 K, -M^-1 (C + Omega G)], formed at each call from
 * matrices factored once in rcb_transient_create (the system is linear, so
 * the Jacobian does not depend on q; it depends on t only through Omega(t)
 * and speed-dependent bearings).
 *
 * Unbalance forcing (each [unbalance] of the model, amount me kg m, angle
 * phase rad), with the rotor angle phi(t) = integral of Omega dt and the
 * angular acceleration alpha = dOmega/dt:
 *   f_x = me (Omega^2 cos(phi + phase) + alpha sin(phi + phase))
 *   f_y = me (Omega^2 sin(phi + phase) - alpha cos(phi + phase)),
 * i.e. f = Re((Omega^2 - i alpha) F1 e^{i phi}) with F1 the phasor of
 * rcb_model_unbalance_force at unit speed. At constant Omega and phi =
 * Omega t this is f(t) = Re(F e^{i Omega t}), the forcing of
 * rcb_frf_unbalance, so the steady 1X phasors are directly comparable.
 *
 * Memory: the object's own arrays (factored matrices, work vectors) come
 * from the allocator hooks and are sized at creation; SUNDIALS allocates
 * its integrator memory, vectors and the 2n x 2n dense matrix with malloc
 * (it has no allocator hooks) once at creation too. A run allocates
 * nothing further. Only when the library is built with RCB_WITH_SUNDIALS;
 * otherwise rcb_transient_create returns RCB_ERR_UNSUPPORTED.
 */
#ifndef RCB_TRANSIENT_H
#define RCB_TRANSIENT_H

#include "rcb/rcb_core.h"
#include "rcb/rcb_model.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct rcb_transient rcb_transient;

/**
 * @brief Rotor speed profile: Omega starts at @c speed0 and moves towards
 * @c speed1 at constant angular acceleration |@c accel|, then stays at
 * speed1. accel = 0 (or speed0 = speed1) means constant speed0. Rotor angle
 * phi(0) = 0.
 */
typedef struct rcb_speed_profile {
  double speed0; /**< rad/s at t = 0 (>= 0) */
  double speed1; /**< rad/s held once reached (>= 0) */
  double accel;  /**< rad/s^2, magnitude (>= 0): run-up if speed1 > speed0, else coast-down */
} rcb_speed_profile;

/** @brief One output sample passed to the sampling callback. */
typedef struct rcb_transient_sample {
  double t;          /**< time, s */
  double speed;      /**< rotor speed Omega(t), rad/s */
  double angle;      /**< rotor angle phi(t), rad */
  double accel;      /**< angular acceleration, rad/s^2 */
  size_t n;          /**< number of DOFs */
  size_t nout;       /**< number of outputs */
  const double *out; /**< the nout output DOFs' displacements, m (rad) */
  const double *q;   /**< all n displacements, m (rad) */
  const double *v;   /**< all n velocities, m/s (rad/s) */
} rcb_transient_sample;

/** @brief Sampling callback; a nonzero return stops the run (RCB_ERR_STATE). */
typedef int (*rcb_transient_sample_fn)(void *user, const rcb_transient_sample *s);

/** @brief Integrator statistics of the last run (CVODE counters). */
typedef struct rcb_transient_stats {
  long steps;          /**< internal time steps */
  long rhs_evals;      /**< right-hand side evaluations */
  long jac_evals;      /**< Jacobian evaluations */
  long lin_setups;     /**< LU factorisations of I - gamma J */
  long lin_solves;     /**< Newton iterations (one dense triangular solve each) */
  long err_test_fails; /**< rejected steps */
  double t_final;      /**< time reached, s */
  size_t periods;      /**< steady state: revolutions integrated */
  double steady_err;   /**< steady state: estimated relative error of the 1X phasors (-) */
} rcb_transient_stats;

/**
 * @brief Prepare time integration of a finalized model: factors M
 * (Cholesky), forms M^-1 K, M^-1 C, M^-1 G and sets up CVODE.
 * @param nout number of output DOFs @param outputs output DOFs (steady-state
 * phasors and the sample's @c out are in this order)
 * @param alloc allocator hooks, NULL for malloc
 * @return RCB_ERR_MODEL if M is not positive definite, RCB_ERR_UNSUPPORTED
 * without SUNDIALS, RCB_ERR_NOMEM
 */
RCB_API rcb_status rcb_transient_create(rcb_transient **out, const rcb_model *m, size_t nout,
                                        const rcb_dof *outputs, const rcb_allocator *alloc);
RCB_API void rcb_transient_destroy(rcb_transient *t);
RCB_API const char *rcb_transient_errmsg(const rcb_transient *t);

/**
 * @brief Integrator tolerances (CVODE's local error test).
 * @param rtol relative tolerance (-), default 1e-7
 * @param atol_q absolute tolerance on displacements, m (rad), default 1e-13
 * @param atol_v absolute tolerance on velocities, m/s (rad/s), default 1e-10
 */
RCB_API rcb_status rcb_transient_set_tolerances(rcb_transient *t, double rtol, double atol_q,
                                                double atol_v);

/**
 * @brief Steady-state extraction settings of rcb_transient_steady.
 * @param tol stop when the estimated relative error of the 1X phasors is
 * below tol (-), default 1e-5
 * @param samples_per_period DFT samples per revolution (>= 4), default 32
 * @param max_periods give up after this many revolutions, default 20000
 */
RCB_API rcb_status rcb_transient_set_steady(rcb_transient *t, double tol,
                                            size_t samples_per_period, size_t max_periods);

/**
 * @brief An external force on one DOF during the runs, in addition to the
 * unbalances: samples f[k] at t = k dt (k = 0 .. nf - 1), linear between
 * them (first-order hold, as a force-cell record is read), 0 after the last;
 * the integrator stops at every sample so that no step straddles a kink.
 * The samples are the caller's and must outlive the runs (not copied).
 * @param dof the forced DOF (a force, N, on x/y; a moment, N m, on rx/ry)
 * @param f samples, N or N m; NULL removes the force @param nf >= 2
 * @param dt sample interval, s (> 0)
 * @return RCB_ERR_ARG for a DOF not in the model, a non-finite sample, nf < 2
 * or dt <= 0
 */
RCB_API rcb_status rcb_transient_set_force(rcb_transient *t, rcb_dof dof, const double *f,
                                           size_t nf, double dt);

/**
 * @brief Integrate from t = 0 to @p t_end along a speed profile, with the
 * model's unbalances (and the force of rcb_transient_set_force) as forcing, calling @p fn at t = k dt (k = 0, 1, ...,
 * while k dt <= t_end, t = 0 included).
 * @param q0 initial displacements (n), NULL for rest @param v0 initial
 * velocities (n), NULL for rest
 * @param t_end s (> 0) @param dt sampling interval, s (> 0)
 * @param fn callback (may be NULL) @param user passed to fn
 * @return RCB_ERR_SINGULAR when CVODE fails (the message names its return
 * flag and the time reached), RCB_ERR_STATE if fn stopped the run
 */
RCB_API rcb_status rcb_transient_run(rcb_transient *t, const rcb_speed_profile *p,
                                     double t_end, double dt, const double *q0,
                                     const double *v0, rcb_transient_sample_fn fn,
                                     void *user);

/**
 * @brief Steady unbalance response at constant speed by time integration:
 * starts at rest, integrates revolution by revolution, takes the 1X phasor
 * of each output by a DFT over each whole revolution, Q = (2/N) sum_j
 * q(t_j) e^{-i Omega t_j}, and stops when the phasors have settled: from the
 * change d_k between successive revolutions and its ratio r = d_k/d_{k-1}
 * (the decay per revolution of the slowest transient), the remaining error
 * is estimated as d_k/(1 - r); the run stops when that falls below the tol
 * of rcb_transient_set_steady on three revolutions in a row.
 * @param speed rad/s (> 0)
 * @param Q output phasors (nout), q(t) = Re(Q e^{i Omega t}), m (rad)
 * @return RCB_ERR_MODEL if no steady state within max_periods (an unstable
 * or too lightly damped model)
 */
RCB_API rcb_status rcb_transient_steady(rcb_transient *t, double speed, rcb_complex *Q);

/** @brief Statistics of the last run or steady-state computation. */
RCB_API rcb_status rcb_transient_get_stats(const rcb_transient *t, rcb_transient_stats *s);

#ifdef __cplusplus
}
#endif

#endif /* RCB_TRANSIENT_H */
