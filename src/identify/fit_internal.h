/*
 * The fit object, private to identify/ (other folders use the public
 * rcb_identify.h and the internal interface identify/identify.h), shared by
 * the identification files: fit.c (set-up, residuals, Jacobians, report),
 * fit_paper.c (the paper's algorithm, eqs. 14-18), fit_nlopt.c (NLopt
 * adapter), uncertainty.c.
 *
 * Optimisers work in internal coordinates x: x_k = ln p_k for log
 * parameters, x_k = p_k / s_k otherwise (s_k = |start| or 1), so that all
 * coordinates are of order one.
 */
#ifndef RCB_FIT_INTERNAL_H
#define RCB_FIT_INTERNAL_H

#include "analyses/analyses.h"
#include "core/rcb_internal.h"
#include "identify/identify.h"

#define RCB_PARAM_NAME_MAX ((size_t)3 * RCB_NAME_MAX)

typedef struct rcb_fit_par_s {
  char name[RCB_PARAM_NAME_MAX];
  double lo, hi;    /* bounds, parameter units */
  int log_param;    /* x = ln p */
  double scale;     /* s: x = p / s when not log */
  double start;     /* value at rcb_fit_run start */
  double value;     /* current / fitted value */
  double se, ci_lo, ci_hi;
  int identifiable;
  int chain;        /* 0: a model parameter; RCB_CHAIN_GAIN, RCB_CHAIN_PHASE: a
                       sensor's (fit_chain.c), not in the model */
  size_t sensor;    /* the sensor of a chain parameter (index into sens) */
} rcb_fit_par;

/* One measured response's sensor in the measurement chain (fit_chain.c):
 * every channel with that response is predicted as
 * gain e^{i phase} fgain e^{i fphase} H_model(the response of sensor swap). */
typedef struct rcb_fit_sensor {
  const char *response; /* the channels' response name (owned by the measurement) */
  size_t out;           /* its FRF output (the resolver's, before any swap) */
  double gain, phase;   /* fixed edit (rcb_fit_set_sensor): -, rad; 1, 0 neutral */
  double fgain, fphase; /* current values of sensor.<response>.gain, .phase: -, rad */
  size_t swap;          /* the sensor whose model response it reads (itself: none) */
} rcb_fit_sensor;

struct rcb_fit {
  rcb_allocator alloc;
  char errmsg[RCB_ERRMSG_MAX];
  rcb_model *m;
  const rcb_meas *meas;
  rcb_frf *frf;          /* outputs: distinct response DOFs; inputs: distinct references */
  size_t nch, npts;      /* channels, abscissa points */
  size_t *ch_out, *ch_in; /* per channel: index into the frf outputs / inputs */
  rcb_frf_kind *ch_kind; /* per channel: kind of the measured values */
  /* measurement chain (fit_chain.c): ch_out above is the output each
   * channel's prediction reads, its own unless its sensor is swapped */
  rcb_fit_sensor *sens;  /* nsens distinct measured responses */
  size_t nsens;
  size_t *ch_sens;       /* per channel: its sensor */
  rcb_complex *ch_fac;   /* per channel: the chain's factor (-) */
  const double *grid;    /* rad/s, npts */
  int unbalance;         /* 1: unbalance responses over speed */
  double speed;          /* rotor speed of an FRF test, rad/s (< 0: synchronous) */
  rcb_fit_scale scale;
  double band_lo, band_hi; /* rad/s */
  double *wuser;         /* nch * npts user weights, NULL: 1 */
  double beta_a, beta_s; /* noise model, %, both 0: none */
  double phase;          /* the noise model's phase term: uniform in +-phase, rad (0: none) */
  rcb_complex *nref;     /* nch * npts values the noise model is evaluated at (its
                            variances, each channel's additive level, the floor gate),
                            rcb_fit_set_noise_reference; NULL: the measured values */
  double *sd;            /* nch * npts known standard deviations, NULL: none */
  rcb_fit_method method;
  char algorithm[64];
  int analytic;
  size_t max_iter;
  double ftol_rel, xtol_rel;
  int (*progress)(void *user, size_t iter, size_t evals, double objective);
  void *progress_user;

  /* parameters */
  rcb_fit_par *par;
  size_t np, cap_par;

  /* residual layout, rebuilt by rcb_fit_prepare: residual j comes from
   * (channel res_ch[j], point res_pt[j]); with the complex scale each point
   * gives two residuals (res_part 0: real, 1: imaginary). */
  size_t nres;
  size_t *res_ch, *res_pt;
  unsigned char *res_part;
  double *res_sqrtw;     /* sqrt of the weight */
  double *res_meas;      /* measured value on the scale */
  rcb_complex *Hmod;     /* predicted values, nch * npts (kind of each channel): the
                            chain's factor times Hraw */
  rcb_complex *Hraw;     /* the model's values before the chain's factor */
  rcb_complex *Hwork;    /* frf output buffer, nout * nin */
  size_t nout, nin;
  unsigned char *pt_used; /* npts: 1 when some residual needs the model there */
  size_t *pt_first, *pt_res; /* residuals of point i: pt_res[pt_first[i] .. pt_first[i+1]) */
  double *J, *r;         /* nres x np, nres (workspace for optimisers) */
  double *dmat;          /* np x 4 x layout size: dM, dC, dG, dK per parameter */
  rcb_complex *rhs;      /* n x (np * max(nin, 1)): sensitivity right-hand sides */
  rcb_complex *dF;       /* n x (np + 1): dF/dp at unit speed, then F itself */
  int prepared;          /* residual layout matches the settings */
  int wmodel;            /* res_sqrtw at the model's predictions, not the
                            measured values (fit.c, refit_at_model) */

  /* results */
  size_t iterations, evaluations;
  int no_uncertainty;    /* rcb_fit_run skips the uncertainty step (the diagnosis' refits) */
  size_t sweeps;         /* model sweeps since creation (never reset; the diagnosis counts them) */
  double obj0, obj, err0, err;
  int converged;
  int stalled;           /* the optimiser stopped without meeting a convergence test
                            though its model promised progress (fit_guard.c) */
  int stop;              /* rcb_fit_stop of the last run */
  size_t stop_param;     /* parameter at its bound (RCB_FIT_STOP_AT_BOUND) */
  rcb_frf_condition cond; /* condition of the final evaluation's solves */
  size_t nstarts, starts_used;
  size_t first_start;         /* rcb_fit_set_first_start */
  uint64_t seed;         /* as given to rcb_fit_set_starts */
  unsigned long long rng;
  double *cov, *corr;    /* np x np */
};

/* The error message of rcb_fit (core/rcb_internal.h, rcb_fail). */
#define rcb_fit_fail(f, st, ...) rcb_fail((f), (st), __VA_ARGS__)
double rcb_fit_sumsq(const double *r, size_t n);
void rcb_fit_free_layout(rcb_fit *f);

/* The measurement chain (fit_chain.c). Sensors of the measured responses,
 * after the channels are resolved (ch_out); reroute after a new resolve. */
rcb_status rcb_fit_chain_init(rcb_fit *f);
void rcb_fit_chain_reroute(rcb_fit *f);
/* A new parameter p whose name is a sensor's (rcb_fit_param_is_chain):
 * its sensor, or RCB_ERR_ARG naming the measured responses. */
rcb_status rcb_fit_chain_param(rcb_fit *f, rcb_fit_par *p);
/* The current value of a parameter by name, the chain's or the model's,
 * with a message on failure. */
rcb_status rcb_fit_name_value(rcb_fit *f, const char *name, double *v);
/* Parameter k's current value, and setting it (parameter units): every
 * path of the fit goes through these, never rcb_model_*_param on a name, so
 * that sensor parameters reach the chain. par_set leaves the FRF workspace
 * to the caller (rcb_frf_refresh after model parameters). */
double rcb_fit_par_get(const rcb_fit *f, size_t k);
rcb_status rcb_fit_par_set(rcb_fit *f, size_t k, double v);
/* The columns d r / d p (parameter units) of the chain parameters into J
 * (nres x np), from the predictions of the last evaluation; the other
 * columns untouched. */
void rcb_fit_chain_columns(const rcb_fit *f, double *J);
/* d r_j / d p from the derivative dP of residual j's predicted value
 * (channel's kind, chain included) (fit_eval.c). */
double rcb_fit_res_deriv_pred(const rcb_fit *f, size_t j, double complex dP);

/* Parameters <-> internal coordinates. set_x writes the model and refreshes
 * the FRF workspace. */
/* Parameter k's internal coordinate for its value v (log, or value / scale). */
double rcb_fit_x_of(const rcb_fit *f, size_t k, double v);
void rcb_fit_get_x(const rcb_fit *f, double *x);
rcb_status rcb_fit_set_x(rcb_fit *f, const double *x);
/* Weighted residuals at the current model (counts one evaluation). */
rcb_status rcb_fit_eval(rcb_fit *f, double *r);
/* Residuals and their Jacobian d r / d x (internal coordinates), nres x np
 * column-major, analytic or finite-difference per f->analytic. */
rcb_status rcb_fit_eval_jac(rcb_fit *f, double *r, double *Jx);
/* F = r^T r at x (sets the model), and its gradient d F / d x when grad is
 * not NULL. */
rcb_status rcb_fit_objective(rcb_fit *f, const double *x, double *F, double *grad);
/* Error % the eq. 19 noise model alone explains (NaN without a noise model). */
double rcb_fit_floor_pct(const rcb_fit *f);
/* 1 when the weights are inverse variances (noise model or known sds): the
 * objective is then a chi-square. */
int rcb_fit_chi2(const rcb_fit *f);
/* A value on the fit's scale (part: 0 Re or the magnitude, 1 Im), and the
 * variance of a measured value e under the eq. 19 noise model with additive
 * amplitude a (fit_eval.c; adequacy.c draws its null distribution). */
double rcb_fit_on_scale(const rcb_fit *f, double complex h, int part);
double rcb_fit_noise_var(const rcb_fit *f, double complex e, double a, int part);
/* The eq. 19 additive amplitude of channel c (the measurement's units), from
 * the noise reference when set, else from the measured values. */
double rcb_fit_noise_level(const rcb_fit *f, size_t c);
/* The declared noise's mean on the log scales, E log10(1 + beta_a r1) (x 20
 * on dB; 0 on the others): the bias of a log magnitude the proportional part
 * puts in (-7.2e-4 at 10 %). The additive part of random phase adds none
 * where it is below the value (E ln|1 + u| = 0 for |u| < 1 and a uniform
 * phase), which the floor gate (2 a) keeps. */
double rcb_fit_log_bias(const rcb_fit *f);
/* Where the noise model is evaluated for point i of channel c (additive
 * amplitude a): the measured value; with a noise reference, the reference,
 * unless it lies farther than RCB_NOISE_REF_SD declared standard deviations
 * from the measured value (a misfit: then the measured value; fit_eval.c). */
double complex rcb_fit_noise_value(const rcb_fit *f, size_t c, size_t i, double a);


/* Pieces of the analytic Jacobian (fit_eval.c) for fit_score.c: the model
 * solve at point i (factors and solutions left in the FRF workspace); the
 * rotor speed of the gyroscopic and bearing terms there; dr_j/dp from
 * dH/dp of residual j's channel (receptance for FRF channels); dM, dC, dG,
 * dK and dF per parameter into f->dmat, f->dF. */
rcb_status rcb_fit_solve_point(rcb_fit *f, size_t i);
double rcb_fit_point_speed(const rcb_fit *f, double w);
double rcb_fit_res_deriv(const rcb_fit *f, size_t j, double complex dh);
/* The same as a coefficient g, dr_j/dp = Re(g dh), taken once per residual
 * for all the parameters of a sweep (after the point's solve). */
double complex rcb_fit_res_coef(const rcb_fit *f, size_t j);
rcb_status rcb_fit_derivative_matrices(rcb_fit *f);

/* The same from f->dmat, f->dF (after rcb_fit_derivative_matrices). */
rcb_status rcb_fit_dz_collect(rcb_fit *f, const rcb_allocator *a, rcb_fit_dz *dz);
/* f's own Jacobian d r / d p by the adjoint (models values into Hmod, no
 * residuals); whether that needs fewer solves per point than the direct
 * re-solve of jac_point is rcb_fit_adjoint_cheaper (identify.h). */
rcb_status rcb_fit_jac_adjoint(rcb_fit *f, double *Jp);

/* fit_guard.c: after the run, why it stopped (converged, at a bound,
 * stalled, out of iterations) into f->stop; a non-finite objective as
 * RCB_ERR_NOT_CONVERGED with a message (RCB_OK when finite). */
void rcb_fit_classify_stop(rcb_fit *f);
rcb_status rcb_fit_check_finite(rcb_fit *f, double F, const char *where);

/* Optimisers: each leaves the best point in the model and fills
 * iterations/evaluations/converged (and stalled). */
rcb_status rcb_fit_run_paper(rcb_fit *f);
rcb_status rcb_fit_run_nlopt(rcb_fit *f);
/* Standard errors, confidence intervals, correlation, identifiability at the
 * current (fitted) point. */
rcb_status rcb_fit_uncertainty(rcb_fit *f);

#endif
