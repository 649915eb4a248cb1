/**
 * @file rcb_analysis.h
 * @brief Analyses on a finalized model: FRFs, unbalance response, damped
 * modes, Campbell data and critical speeds.
 *
 * Each analysis object is sized once at creation (all its memory comes from
 * the allocator hooks then); evaluations allocate nothing, so a sweep in a
 * loop is allocation-free. The one exception is the sparse solver (KLU,
 * chosen by RCB_SOLVER_AUTO from 32 DOF when librcb is built with
 * SuiteSparse): KLU allocates its LU factors itself, with SuiteSparse's
 * malloc, at the first factorisation and whenever it pivots anew. A host
 * that needs every byte through its hooks asks for RCB_SOLVER_DENSE or
 * RCB_SOLVER_BANDED, or builds without SuiteSparse (the embedded preset).
 * Objects keep a pointer to the model: the model must outlive them. Two
 * objects on two threads never share state.
 */
#ifndef RCB_ANALYSIS_H
#define RCB_ANALYSIS_H

#include "rcb/rcb_core.h"
#include "rcb/rcb_model.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---------------------------------------------------------------- FRF -- */

/** @brief What an FRF relates to force. */
typedef enum rcb_frf_kind {
  RCB_RECEPTANCE = 0, /**< displacement / force, m/N (rad/(N m) for rotations) */
  RCB_MOBILITY = 1,   /**< velocity / force, m/(N s) */
  RCB_INERTANCE = 2   /**< acceleration / force, m/(N s^2) */
} rcb_frf_kind;

/** @brief Linear solver used for the dynamic stiffness. */
typedef enum rcb_solver_kind {
  RCB_SOLVER_AUTO = 0,   /**< sparse from 32 DOF when built with KLU, else
                              banded when the band is narrow, else dense */
  RCB_SOLVER_DENSE = 1,  /**< LAPACK zgesv */
  RCB_SOLVER_BANDED = 2, /**< LAPACK zgbsv */
  RCB_SOLVER_SPARSE = 3, /**< SuiteSparse KLU (complex); RCB_ERR_UNSUPPORTED
                              when built without RCB_WITH_SUITESPARSE */
  RCB_SOLVER_MODAL = 4   /**< modal superposition (paper eq. 7) on the
                              state-space eigenvectors at one speed, O(modes)
                              per output per frequency; a direct solver (as
                              for auto) serves the unbalance response, the
                              sensitivities and the checks. Dense
                              eigenproblem: up to RCB_MODAL_MAX_DOF DOF */
} rcb_solver_kind;

/** @brief Largest model (DOF) the modal solver accepts (its eigenproblem is
 * dense, 2n x 2n). */
#define RCB_MODAL_MAX_DOF 2000

typedef struct rcb_frf rcb_frf;

/**
 * @brief Prepare FRF evaluation for chosen outputs x inputs.
 * @param nout number of output DOFs @param outputs output DOFs
 * @param nin number of input (force) DOFs, may be 0 for unbalance-only use
 * @param inputs input DOFs
 * @param solver RCB_SOLVER_AUTO, _DENSE, _BANDED or _SPARSE
 * @param alloc allocator hooks, NULL for malloc
 */
RCB_API rcb_status rcb_frf_create(rcb_frf **out, const rcb_model *m, size_t nout,
                                  const rcb_dof *outputs, size_t nin, const rcb_dof *inputs,
                                  rcb_solver_kind solver, const rcb_allocator *alloc);
RCB_API void rcb_frf_destroy(rcb_frf *f);
/**
 * @brief Re-assemble after rcb_model_set_param changed the model (same mesh,
 * no allocation).
 */
RCB_API rcb_status rcb_frf_refresh(rcb_frf *f);
RCB_API const char *rcb_frf_errmsg(const rcb_frf *f);
/** @brief Solver actually chosen (dense, banded or sparse). */
RCB_API rcb_solver_kind rcb_frf_solver(const rcb_frf *f);
/** @brief Bytes held by the object (its whole workspace; with the sparse
 * solver, plus KLU's peak usage, which KLU allocates itself with malloc). */
RCB_API size_t rcb_frf_memory(const rcb_frf *f);

/**
 * @brief H(omega) at rotor speed @p speed: one factorisation, all inputs as
 * right-hand sides.
 * @param omega excitation frequency, rad/s @param speed rotor speed Omega, rad/s
 * (pass speed = omega for a synchronous FRF)
 * @param H output, nout x nin column-major (H[o + nout * i])
 */
RCB_API rcb_status rcb_frf_eval(rcb_frf *f, double omega, double speed, rcb_frf_kind kind,
                                rcb_complex *H);

/**
 * @brief Steady unbalance response at rotor speed @p speed (rad/s), from the
 * model's unbalances (paper eqs. 3-4, solved as the complex system at
 * omega = Omega). q(t) = Re(Q e^{i Omega t}).
 * @param Q output displacement phasors at the nout outputs, m (rad for rotations)
 */
RCB_API rcb_status rcb_frf_unbalance(rcb_frf *f, double speed, rcb_complex *Q);

/**
 * @brief Frequency sweep, optionally on threads: H(omegas[p]) at rotor speed
 * speeds[p] for p = 0..nfreq-1. Each thread works on its own copy of the
 * workspace (sized here, freed on return); the model is only read. The
 * result is bit-identical whatever @p nthreads is: every frequency goes
 * through the same operations (the sparse solver starts a fresh
 * factorisation every RCB_SWEEP_BLOCK frequencies, so its kept-pivot history
 * does not depend on how the sweep is split). With the modal solver and one
 * speed, the threads share the basis computed once.
 * @param omegas excitation frequencies, rad/s (>= 0)
 * @param speeds rotor speed at each frequency, rad/s (pass omegas for a
 * synchronous sweep)
 * @param H output, nout x nin per frequency, column-major, frequency p at
 * H + p * nout * nin
 * @param nthreads threads to use (0 or 1: the calling thread only; at most
 * RCB_SWEEP_MAX_THREADS, and no more than there are blocks). A librcb built
 * with RCB_WITH_THREADS=OFF (no pthreads, e.g. the embedded preset) takes
 * the same values and runs every sweep on the calling thread.
 * @return the first failing part's status (message in rcb_frf_errmsg);
 * RCB_ERR_NOMEM if a thread cannot be started. The condition record
 * (rcb_frf_get_condition) covers the solves of all threads.
 */
RCB_API rcb_status rcb_frf_sweep(rcb_frf *f, size_t nfreq, const double *omegas,
                                 const double *speeds, rcb_frf_kind kind, rcb_complex *H,
                                 size_t nthreads);

/** @brief Frequencies per block of rcb_frf_sweep (see there). */
#define RCB_SWEEP_BLOCK 64
/** @brief Most threads rcb_frf_sweep accepts. */
#define RCB_SWEEP_MAX_THREADS 64

/** @brief State of the modal basis of an FRF object (RCB_SOLVER_MODAL). */
typedef struct rcb_modal_info {
  size_t nroots;      /**< eigenvalues of the state-space form, 2n */
  size_t nkept;       /**< roots kept in the modal sum (a conjugate pair counts 2) */
  size_t nmodes;      /**< kept modes (a conjugate pair counts 1, a real root 1) */
  double speed;       /**< rotor speed of the basis, rad/s */
  double max_kept_wn; /**< largest |lambda| kept, rad/s */
  int residual_used;  /**< 1: static residual-flexibility term added (truncated set) */
  double residual;    /**< max |residual term| / max |H(0)| (-), 0 if all kept */
  double rcond_v;     /**< reciprocal condition number of the eigenvector matrix
                           (-); near 0: nearly defective, modal sum unreliable */
} rcb_modal_info;

/**
 * @brief Truncate the modal sum (RCB_SOLVER_MODAL): keep the roots with
 * |lambda| <= @p max_freq (rad/s, 0: no limit) and at most @p max_modes modes
 * (0: no limit), lowest |lambda| first; conjugate roots stay together. The
 * dropped modes are replaced by a static residual term: the direct solution
 * at omega = 0 minus the kept modes' contribution there (exact at omega = 0;
 * left out, and residual_used = 0, when the dynamic stiffness is singular at
 * 0, as for a free rotor). Default: all modes, no residual. The basis is
 * recomputed at the next evaluation. @return RCB_ERR_STATE if @p f does not
 * use the modal solver, RCB_ERR_ARG for max_freq < 0 or not finite.
 */
RCB_API rcb_status rcb_frf_set_modal(rcb_frf *f, size_t max_modes, double max_freq);

/**
 * @brief The solver that pays for a sweep of @p nfreq frequencies:
 * RCB_SOLVER_MODAL when every frequency has the same rotor speed
 * (@p one_speed = 1), the model has at most RCB_MODAL_MAX_DOF DOF and
 * nfreq >= RCB_MODAL_PAYS * ndof^2; RCB_SOLVER_AUTO (a direct solver) otherwise.
 * The rule weighs the eigenvector basis, about 1.5e-9 s x (2 ndof)^3, against
 * a direct solve per frequency, about 1.2e-7 s x ndof with KLU, with a factor 2
 * of margin for the modal side (docs/benchmarks.md, "Modal path and threads").
 */
RCB_API rcb_solver_kind rcb_frf_pick_solver(const rcb_model *m, size_t nfreq, int one_speed);
/** @brief Frequencies per DOF^2 from which the modal path pays (see
 * rcb_frf_pick_solver): 2 x 1.5e-9 x 8 / 1.2e-7. */
#define RCB_MODAL_PAYS 0.2

/** @brief Modal basis at rotor speed @p speed (rad/s), computed if needed,
 * and its description. @return RCB_ERR_STATE if @p f is not modal. */
RCB_API rcb_status rcb_frf_modal_info(rcb_frf *f, double speed, rcb_modal_info *info);

/**
 * @brief Truncation error estimate: one direct solve at @p omega (rad/s;
 * use the top of the band of interest) compared with the modal sum there.
 * @param err output max |H_modal - H_direct| / max |H_direct| over the
 * outputs x inputs (-); ~1e-12 with all modes kept
 */
RCB_API rcb_status rcb_frf_modal_error(rcb_frf *f, double omega, double speed, double *err);

/* ------------------------------------------- FRF: numerical guard -- */

/** @brief Default threshold below which a solve counts as ill-conditioned:
 * with rcond = 1e-12 about 4 of the 16 significant digits of the response
 * are left (relative error ~ machine eps / rcond). */
#define RCB_RCOND_WARN 1e-12

/** @brief Modes of the condition check (rcb_frf_set_condition_check). */
enum {
  RCB_COND_OFF = 0,    /**< no check */
  RCB_COND_SCREEN = 1, /**< default: the pivot ratio min|U_ii| / max|U_ii| of every
                            factorisation (O(n), read off the factors); the full
                            estimate only where it falls below RCB_PIVOT_SCREEN */
  RCB_COND_ALWAYS = 2  /**< the full estimate after every factorisation */
};

/** @brief Pivot ratio below which RCB_COND_SCREEN computes the full estimate
 * (-). Six decades above RCB_RCOND_WARN: the LU of a matrix with rcond
 * 1e-12 and every pivot within 1e-6 of the largest would need an element
 * growth of 1e6, which partial pivoting does not produce on dynamic
 * stiffness matrices (a heuristic: RCB_COND_ALWAYS removes it). The full
 * estimate costs several triangular solves, and LAPACK's zgbcon, through
 * zlatbs's careful scaled solves, O(n^2) on a long train: screened, a
 * sweep costs what it cost without the check. */
#define RCB_PIVOT_SCREEN 1e-6

/**
 * @brief Condition of the dynamic-stiffness solves since the last reset.
 *
 * rcond is the reciprocal condition number in the 1-norm,
 * 1 / (||Z||_1 ||Z^-1||_1), estimated from the factors (LAPACK zgecon /
 * zgbcon, KLU klu_z_condest: the Hager-Higham estimator, which never
 * overestimates ||Z^-1||_1 and is in practice within a factor 3 of it).
 * A solve is ill-conditioned when rcond < threshold: an all-free model at
 * omega = 0 (rigid-body modes: Z = K is singular up to round-off), or an
 * undamped resonance hit almost exactly. The results are then dominated by
 * round-off and must not be trusted.
 */
typedef struct rcb_frf_condition {
  double rcond_min;  /**< smallest estimate since the reset (-); NaN before any
                          estimated solve or when an estimate failed */
  double omega;      /**< excitation frequency of that solve, rad/s */
  double speed;      /**< rotor speed of that solve, rad/s */
  double rcond_last; /**< estimate of the last solve (-), NaN if screened */
  size_t checked;    /**< solves checked since the reset */
  size_t estimated;  /**< of which had the full estimate (RCB_COND_SCREEN: those
                          whose pivot ratio fell below RCB_PIVOT_SCREEN) */
  size_t ill;        /**< of which ill-conditioned (rcond < threshold or NaN) */
  double threshold;  /**< the threshold in use (-) */
} rcb_frf_condition;

/**
 * @brief Set the condition check of every factorisation and its threshold
 * (default RCB_COND_SCREEN with RCB_RCOND_WARN). Resets the record.
 * @param mode RCB_COND_OFF, RCB_COND_SCREEN or RCB_COND_ALWAYS
 * @param threshold 0 < threshold < 1 (-)
 */
RCB_API rcb_status rcb_frf_set_condition_check(rcb_frf *f, int mode, double threshold);
/** @brief Forget the record (before a new sweep). */
RCB_API void rcb_frf_reset_condition(rcb_frf *f);
/** @brief The record since the last reset (see rcb_frf_condition). */
RCB_API rcb_status rcb_frf_get_condition(const rcb_frf *f, rcb_frf_condition *out);
/** @brief Smallest reciprocal condition estimate since the last reset (-), NaN if
 * none. */
RCB_API double rcb_frf_rcond(const rcb_frf *f);

/* -------------------------------------------------------------- modes -- */

/** @brief Whirl direction of a mode. */
typedef enum rcb_whirl {
  RCB_WHIRL_BACKWARD = -1,
  RCB_WHIRL_MIXED = 0,
  RCB_WHIRL_FORWARD = 1
} rcb_whirl;

/** @brief One damped mode: lambda = -zeta wn + i wd. */
typedef struct rcb_mode {
  rcb_complex lambda; /**< eigenvalue, 1/s */
  double wn;          /**< undamped natural frequency |lambda|, rad/s */
  double wd;          /**< damped natural frequency Im(lambda), rad/s */
  double zeta;        /**< damping ratio -Re(lambda)/|lambda| (-) */
  double logdec;      /**< logarithmic decrement 2 pi zeta / sqrt(1 - zeta^2) (-) */
  rcb_whirl whirl;    /**< forward, backward or mixed whirl */
} rcb_mode;

typedef struct rcb_modes rcb_modes;

RCB_API rcb_status rcb_modes_create(rcb_modes **out, const rcb_model *m,
                                    const rcb_allocator *alloc);
RCB_API void rcb_modes_destroy(rcb_modes *e);
RCB_API const char *rcb_modes_errmsg(const rcb_modes *e);

/**
 * @brief Default of rcb_modes_set_max_zeta (-): the one value the library,
 * rcbtool (--max-zeta) and the Python package start from.
 */
#define RCB_MODES_MAX_ZETA_DEFAULT 0.99

/**
 * @brief Leave out modes whose damping ratio exceeds @p max_zeta (default
 * RCB_MODES_MAX_ZETA_DEFAULT; 1 keeps every oscillating root, as ROSS does).
 * With strong
 * stiffness-proportional damping (qz_k), the overdamped high-frequency modes
 * leave a cluster of roots near -1/qz_k that gyroscopic coupling turns into
 * pairs with tiny wd and zeta ~ 1 - 1e-9; sorted by wd they come first and
 * would fill a Campbell diagram (and cross 1X at a few rad/s); the default
 * 0.99 (logdec ~ 44) removes them. Applies to rcb_modes_compute and
 * rcb_campbell. @return RCB_ERR_ARG unless 0 < max_zeta <= 1
 */
RCB_API rcb_status rcb_modes_set_max_zeta(rcb_modes *e, double max_zeta);
/** @brief The damping-ratio limit in force (-), RCB_MODES_MAX_ZETA_DEFAULT until set. */
RCB_API double rcb_modes_get_max_zeta(const rcb_modes *e);

/**
 * @brief Damped modes at rotor speed @p speed (rad/s) from the state-space
 * pencil, sorted by increasing wd; only oscillating modes (wd > 0) are kept,
 * rigid-body and overdamped roots are left out.
 *
 * A root counts as oscillating when wd > 1e-7 max|lambda| (max over all 2n
 * roots): the rigid-body roots (lambda = 0) of a free rotor come out of the
 * eigensolver scattered at ~ sqrt(machine eps) max|lambda|. The gyroscopic
 * nutation of a free rotor at speed (wd ~ Ip Omega / Id) is a true
 * oscillation and is kept when above that floor. Whirl: from the translations
 * (x, y) of every node moving more than 1e-3 of the largest, forward radius
 * |X + iY|/2 against backward |X - iY|/2; FORWARD if all such nodes whirl
 * forward, BACKWARD if all backward, MIXED otherwise (also for planar motion).
 * Errors: RCB_ERR_MODEL if M is not positive definite, RCB_ERR_LAPACK if the
 * eigensolver fails; the message is in rcb_modes_errmsg(). Allocates nothing.
 * @param max_modes capacity of @p modes (the lowest max_modes are written)
 * @param modes output @param nmodes number written
 * @param shapes optional (NULL): n x max_modes column-major complex right
 * eigenvectors (displacement part), n = rcb_model_dof_count(), each scaled to
 * unit largest translation
 */
RCB_API rcb_status rcb_modes_compute(rcb_modes *e, double speed, size_t max_modes,
                                     rcb_mode *modes, size_t *nmodes, rcb_complex *shapes);

/**
 * @brief Campbell data: the first @p nmodes damped modes at each speed
 * (k-th lowest wd at each speed, no mode tracking: curves that cross swap
 * indices). Allocates nothing.
 * @param speeds rad/s, @p nspeeds of them
 * @param wd output damped frequencies rad/s, nmodes x nspeeds column-major
 * (NaN where fewer modes exist) @param logdec output, same shape, may be NULL
 * @param whirl output, same shape, may be NULL (RCB_WHIRL_MIXED where fewer
 * modes exist)
 */
RCB_API rcb_status rcb_campbell(rcb_modes *e, size_t nspeeds, const double *speeds,
                                size_t nmodes, double *wd, double *logdec, rcb_whirl *whirl);

/**
 * @brief Critical speeds: where a Campbell curve crosses the line
 * wd = ratio * speed (ratio 1 for 1X), by linear interpolation between
 * table rows. Inputs as produced by rcb_campbell. Pure function (no state,
 * no allocation). A row where a curve lies exactly on the line counts once;
 * NaN entries break a curve (no crossing across them). Results are sorted by
 * increasing speed.
 * @param speeds rad/s, strictly increasing (else RCB_ERR_ARG)
 * @param wd nmodes x nspeeds column-major, rad/s
 * @param crit output speeds rad/s, capacity @p max_crit @param mode_of output,
 * index of the curve crossing (may be NULL) @param ncrit number written
 * @return RCB_OK, or RCB_ERR_WORKSPACE when more than max_crit crossings
 * exist (the lowest max_crit are written)
 */
RCB_API rcb_status rcb_critical_speeds(size_t nspeeds, const double *speeds, size_t nmodes,
                                       const double *wd, double ratio, size_t max_crit,
                                       double *crit, size_t *mode_of, size_t *ncrit);

#ifdef __cplusplus
}
#endif

#endif /* RCB_ANALYSIS_H */
