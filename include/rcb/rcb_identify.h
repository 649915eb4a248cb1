/**
 * @file rcb_identify.h
 * @brief Fitting model parameters to measured FRFs or unbalance responses by
 * non-linear least squares (paper sections 6-7, eqs. 11-18), or by NLopt,
 * with standard errors and an identifiability check.
 *
 * The objective (eq. 12) is F = r^T W r with residuals r_i = s(m_i) - s(e_i)
 * between model m and measurement e at every (channel, abscissa) point of the
 * selected band, on a scale s: |.|, log10|.|, 20 log10|.|, or the complex value
 * (real and imaginary parts as two residuals). W is diagonal.
 */
#ifndef RCB_IDENTIFY_H
#define RCB_IDENTIFY_H

#include "rcb/rcb_analysis.h"
#include "rcb/rcb_core.h"
#include "rcb/rcb_measure.h"
#include "rcb/rcb_model.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum rcb_fit_scale {
  RCB_SCALE_LINEAR = 0, /**< |H| */
  RCB_SCALE_LOG10 = 1,  /**< log10 |H| */
  RCB_SCALE_DB = 2,     /**< 20 log10 |H| */
  RCB_SCALE_COMPLEX = 3 /**< Re H, Im H; uses the phase. The fit first converges on
                             log10 |H| (continuation: the complex objective has local
                             minima a phase period apart), then on Re, Im */
} rcb_fit_scale;

typedef enum rcb_fit_method {
  RCB_FIT_PAPER = 0, /**< Gauss-Newton by pseudo-inverse, Coggins line search,
                          lambda Q damping, exterior penalty (eqs. 14-18) */
  RCB_FIT_NLOPT = 1  /**< an NLopt algorithm by name (needs RCB_WITH_NLOPT) */
} rcb_fit_method;

typedef struct rcb_fit rcb_fit;

/**
 * @brief Prepare a fit of model @p m (changed in place by rcb_fit_run) to @p meas.
 * Channels are resolved against the model here (unknown station: error).
 * On failure *out may still hold an object carrying the message
 * (rcb_fit_errmsg); destroy it in every case.
 */
RCB_API rcb_status rcb_fit_create(rcb_fit **out, rcb_model *m, const rcb_meas *meas,
                                  const rcb_allocator *alloc);
RCB_API void rcb_fit_destroy(rcb_fit *f);
RCB_API const char *rcb_fit_errmsg(const rcb_fit *f);

/**
 * @brief Add a parameter to fit (see rcb_model_get_param for names).
 *
 * Besides the model's parameters, the measurement chain's: every measured
 * channel whose response is R (the channel's response name, "DB.y") is
 * predicted as g e^{i phi} H_model, with
 * - "sensor.R.gain": g, dimensionless, neutral 1 (a probe reading 20 % low:
 *   0.8), and
 * - "sensor.R.phase": phi, rad, neutral 0, positive when the sensor leads.
 * They start from their current values (1 and 0 until a run moves them) and
 * multiply any fixed edit of rcb_fit_set_sensor. The phase is invisible on
 * magnitude scales (LINEAR, LOG10, DB): fit it on RCB_SCALE_COMPLEX.
 * @param lo lower bound @param hi upper bound (lo < hi; the current value is the
 * start) @param log_param optimise log(p) instead of p (needs lo > 0)
 * @return RCB_ERR_NOT_FOUND for an unknown model parameter, RCB_ERR_ARG for a
 * sensor parameter whose response no measured channel has
 */
RCB_API rcb_status rcb_fit_add_param(rcb_fit *f, const char *name, double lo, double hi,
                                     int log_param);

/**
 * @brief The neutral start and default bounds of a measurement-chain
 * parameter, as rcb_fit_add_param would take them when the caller has none:
 * "sensor.R.gain" starts at 1 (dimensionless) in [0.1, 10], fitted on log(g);
 * "sensor.R.phase" starts at 0 rad in [-pi/2, pi/2] rad, fitted on phi. The
 * diagnosis's sensor candidates use the same. Syntactic only: whether R is
 * measured is checked by rcb_fit_add_param. Any output may be NULL.
 * @param start neutral value (1, or 0 rad) @param lo lower bound @param hi
 * upper bound @param log_param 1 for a gain, 0 for a phase
 * @return 1 for a gain, 2 for a phase, 0 when @p name is not a chain parameter
 * (outputs untouched)
 */
RCB_API int rcb_fit_sensor_param_defaults(const char *name, double *start, double *lo,
                                          double *hi, int *log_param);

/* ---- the measurement chain: fixed edits (not fitted) ---- */

/**
 * @brief A fixed edit of the sensor of measured response @p response ("DB.y"):
 * every channel with that response is predicted as gain e^{i phase_rad} times
 * the model's value (times any fitted sensor.<response>.gain, .phase). A sign
 * flipped is gain -1; (1, 0) undoes the edit.
 * @param gain dimensionless, finite and nonzero @param phase_rad rad, positive
 * when the sensor leads
 * @return RCB_ERR_ARG when no measured channel has that response
 */
RCB_API rcb_status rcb_fit_set_sensor(rcb_fit *f, const char *response, double gain,
                                      double phase_rad);
/**
 * @brief Two probes swapped: channels whose response is @p a are predicted from
 * the model's response at @p b and vice versa (each sensor's gain and phase
 * stay with its own channels). @p b NULL (or equal to @p a) undoes a's swap.
 * Swapping a pair already swapped is a no-op.
 * @return RCB_ERR_ARG when a or b is not a measured response, when the two are
 * not measured with the same references, or when either is swapped with a
 * third already (undo that first)
 */
RCB_API rcb_status rcb_fit_swap_sensors(rcb_fit *f, const char *a, const char *b);
/**
 * @brief The fixed edit of a measured response's sensor, as set (default 1, 0,
 * NULL). @param gain dimensionless @param phase_rad rad @param swapped_with the
 * response it is swapped with (owned by the measurement), NULL when none. Any
 * output may be NULL.
 * @return RCB_ERR_ARG when no measured channel has that response
 */
RCB_API rcb_status rcb_fit_get_sensor(const rcb_fit *f, const char *response, double *gain,
                                      double *phase_rad, const char **swapped_with);
RCB_API rcb_status rcb_fit_set_scale(rcb_fit *f, rcb_fit_scale scale);
/** @brief Keep only abscissa values in [lo, hi], rad/s. */
RCB_API rcb_status rcb_fit_set_band(rcb_fit *f, double lo, double hi);
/**
 * @brief Diagonal weights, one per (channel, point) in channel-major order
 * (w[c * npoints + i]); NULL restores unit weights. 0 drops a point.
 */
RCB_API rcb_status rcb_fit_set_weights(rcb_fit *f, const double *w);
/**
 * @brief Noise-aware weights from the eq. 19 noise model: each point weighted
 * by the inverse variance of its residual on the chosen scale, and points whose
 * measured magnitude lies near the channel's additive noise floor dropped.
 * The variance is taken at the measured value; on the linear and complex
 * scales (where it grows with the value) a run with the uncertainty step
 * (rcb_fit_set_uncertainty) then recomputes it at the model's predicted
 * values and refines the fit from there, which removes the bias the
 * measured values' own noise puts into their weights; rcb_fit_residuals and
 * the adequacy test after such a run use those weights.
 * @param beta_a random factor, % @param beta_s systematic factor, %
 */
RCB_API rcb_status rcb_fit_set_noise_model(rcb_fit *f, double beta_a, double beta_s);
/**
 * @brief The noise model's phase term (issue #33): each measured value also
 * turned by a phase uniform in +-@p phase_rad (a trigger's jitter, a
 * sensor's phase error), which adds phase_rad^2 / 3 times the other part
 * squared to the variance of each part on the complex scale (the modulus,
 * and so the linear and log scales, are unchanged). 0 (default): none.
 * @param phase_rad rad, 0 to pi
 */
RCB_API rcb_status rcb_fit_set_noise_phase(rcb_fit *f, double phase_rad);
/** @brief The noise model's phase term, rad (0: none). */
RCB_API double rcb_fit_get_noise_phase(const rcb_fit *f);
/**
 * @brief Where the noise model is evaluated (issue #33): the variance of
 * each point, each channel's additive level and the noise-floor gate are
 * computed from these values instead of the measured ones. A weight or a
 * gate taken from the measured value correlates with that value's own
 * noise (a value pulled towards zero weighs more; one pushed above the
 * floor is kept), which biases F by far more than chance at 32 x 1101; a
 * reference free of the measurement's noise (the fitted model's
 * predictions, rcb_fit_predictions) removes it, and fits that share one
 * reference share their weights, so their F compare as chi-squares. Where
 * a reference value lies more than 4 declared standard deviations from the
 * measured value (a misfit, not noise: the model far off there), the
 * measured value is used instead.
 * @param h nch * npts values in channel-major order (h[c * npoints + i]),
 * the measurement's units; a non-finite value drops its point; NULL: the
 * measured values again
 */
RCB_API rcb_status rcb_fit_set_noise_reference(rcb_fit *f, const rcb_complex *h);
/**
 * @brief The model's predictions at its current values (one sweep), with the
 * measurement chain applied, in the measurement's kind and units: nch *
 * npts values in channel-major order; NaN at the points the fit leaves out
 * (band, zero weight, the noise floor).
 */
RCB_API rcb_status rcb_fit_predictions(rcb_fit *f, rcb_complex *h);
/**
 * @brief Known standard deviations of the measured values (an estimate's own
 * statistics: rcb_spectral_frf's sd, the order tracker's sd), instead of the
 * eq. 19 noise model: each point weighted by the inverse variance of its
 * residual on the chosen scale (sd^2 on |.| and on each of Re, Im;
 * (sd / (|e| ln 10))^2 on log10; 400 times that on dB), so that F is a
 * chi-square (about N - np when the model is right), and the noise floor of
 * the report is 100 sqrt(sum sd^2 / sum |e|^2) over the points used. These
 * weights multiply the user weights (rcb_fit_set_weights): a 0/1 mask keeps
 * its meaning.
 * @param sd one per (channel, point) in channel-major order (sd[c * npoints
 * + i]), the measurement's units; 0 or NaN drops the point; NULL removes them
 * @return RCB_ERR_ARG for a negative value, or when the noise model is set
 * (one or the other)
 */
RCB_API rcb_status rcb_fit_set_sd(rcb_fit *f, const double *sd);
/** @brief Method and, for RCB_FIT_NLOPT, the algorithm name ("LN_BOBYQA", "LD_LBFGS", "GN_DIRECT_L", ...). */
RCB_API rcb_status rcb_fit_set_method(rcb_fit *f, rcb_fit_method method, const char *algorithm);
/** @brief Analytic sensitivities (eq. 9, default) or finite differences (eq. 11). */
RCB_API rcb_status rcb_fit_set_analytic(rcb_fit *f, int analytic);
/** @brief Stopping rules: iterations, relative objective change, relative step. */
RCB_API rcb_status rcb_fit_set_limits(rcb_fit *f, size_t max_iter, double ftol_rel,
                                      double xtol_rel);
/**
 * @brief Progress callback, called once per iteration; a nonzero return stops
 * the fit (status RCB_ERR_STATE "stopped by the caller").
 */
RCB_API rcb_status rcb_fit_set_progress(rcb_fit *f,
                                        int (*cb)(void *user, size_t iter, size_t evals,
                                                  double objective),
                                        void *user);

/**
 * @brief Guard against local minima: when a fit ends unsure (above the noise
 * floor of the noise model, or not converged), try up to n - 1 further
 * starting points, drawn log-uniformly (uniformly for linear parameters)
 * within the bounds from a PRNG seeded by @p seed (64 bits on every platform,
 * so armhf draws the starts x86_64 draws), and keep the best result.
 * n = 1 (default) tries only the model's own start.
 */
RCB_API rcb_status rcb_fit_set_starts(rcb_fit *f, size_t n, uint64_t seed);
/**
 * @brief The first of the n starting points of rcb_fit_set_starts that
 * rcb_fit_run tries: 0 (default) the model's own start, then the random ones;
 * 1 the random ones only, the same points a run from 0 tries after the
 * model's start (for a caller that ran that start already and decides after
 * it whether the further starts are worth their cost). Must be below n when
 * the fit runs. Setting the starts again keeps it.
 */
RCB_API rcb_status rcb_fit_set_first_start(rcb_fit *f, size_t first);

/**
 * @brief Whether rcb_fit_run ends with the uncertainty step (standard errors,
 * confidence intervals, correlation, identifiability; default 1). With 0
 * rcb_fit_get_param's stderr_, ci_lo, ci_hi, identifiable and
 * rcb_fit_correlation are not updated by the run, and the noise model's
 * weights stay at the measured values (no refinement at the model's values:
 * rcb_fit_set_noise_model), so that a caller that compares objectives only,
 * as the diagnosis' refits, saves both; otherwise the fit and its report are
 * the same.
 */
RCB_API rcb_status rcb_fit_set_uncertainty(rcb_fit *f, int compute);

/* ---- getters: every setting above, as set (or its default) ---- */

/**
 * @brief Bounds and parametrisation of parameter @p k (0-based, in the order
 * added). @param lo, hi bounds, parameter units @param log_param 1 when log(p)
 * is optimised. Any output may be NULL.
 */
RCB_API rcb_status rcb_fit_get_param_bounds(const rcb_fit *f, size_t k, double *lo, double *hi,
                                            int *log_param);
/** @brief The residual scale (default RCB_SCALE_LINEAR). */
RCB_API rcb_fit_scale rcb_fit_get_scale(const rcb_fit *f);
/** @brief The abscissa band kept, rad/s (default [0, HUGE_VAL]: every point). */
RCB_API rcb_status rcb_fit_get_band(const rcb_fit *f, double *lo, double *hi);
/**
 * @brief The user weights, nch * npoints values in channel-major order (as
 * rcb_fit_set_weights; all 1 when none are set). @return 1 when weights are
 * set, 0 when not (w filled with 1), negative on bad arguments.
 */
RCB_API int rcb_fit_get_weights(const rcb_fit *f, double *w);
/**
 * @brief The standard deviations of rcb_fit_set_sd (nch * npoints values).
 * @return 1 when set (sd filled), 0 when not (sd untouched), negative on bad
 * arguments.
 */
RCB_API int rcb_fit_get_sd(const rcb_fit *f, double *sd);
/** @brief The eq. 19 noise factors, % (both 0: no noise model, unit weights). */
RCB_API rcb_status rcb_fit_get_noise_model(const rcb_fit *f, double *beta_a, double *beta_s);
/**
 * @brief The method and, when @p algorithm is not NULL, the NLopt algorithm
 * name ("" when none was given; the string belongs to f).
 */
RCB_API rcb_fit_method rcb_fit_get_method(const rcb_fit *f, const char **algorithm);
/** @brief 1: analytic sensitivities (eq. 9, default), 0: finite differences (eq. 11). */
RCB_API int rcb_fit_get_analytic(const rcb_fit *f);
/**
 * @brief Stopping rules: iterations (default 100), relative objective change
 * (-, default 1e-10), relative step (-, default 1e-8). Any output may be NULL.
 */
RCB_API rcb_status rcb_fit_get_limits(const rcb_fit *f, size_t *max_iter, double *ftol_rel,
                                      double *xtol_rel);
/** @brief The progress callback and its user pointer (NULL, NULL: none). */
RCB_API rcb_status rcb_fit_get_progress(const rcb_fit *f,
                                        int (**cb)(void *user, size_t iter, size_t evals,
                                                   double objective),
                                        void **user);
/** @brief Starting points (default 1) and the PRNG seed of the further ones (default 0). */
RCB_API rcb_status rcb_fit_get_starts(const rcb_fit *f, size_t *n, uint64_t *seed);
/** @brief The first starting point tried (default 0, see rcb_fit_set_first_start). */
RCB_API size_t rcb_fit_get_first_start(const rcb_fit *f);
/** @brief Whether rcb_fit_run computes the uncertainties (default 1). */
RCB_API int rcb_fit_get_uncertainty(const rcb_fit *f);

/** @brief Run the fit; on success the model holds the fitted values. */
RCB_API rcb_status rcb_fit_run(rcb_fit *f);

/** @brief Summary of the last run. */
typedef struct rcb_fit_report {
  size_t iterations;   /**< outer iterations */
  size_t evaluations;  /**< model evaluations (each a full sweep), Jacobians included */
  size_t residuals;    /**< residuals used (after band and weights) */
  double objective0;   /**< F at the start (on the final weights) */
  double objective;    /**< F at the end */
  double error0_pct;   /**< paper's error % at the start (see rcb_fit_error) */
  double error_pct;    /**< the same at the end */
  double sigma;        /**< residual standard deviation sqrt(F / (N - np)) */
  int converged;       /**< 1 when a convergence criterion was met */
  double floor_pct;    /**< error % the noise model alone explains (NaN without one) */
  int unsure;          /**< 1 when the fit did not converge (see rcb_fit_stop_reason),
                            or ends above 1.5 times floor_pct: a local minimum, or an
                            effect the model lacks */
  size_t starts;       /**< starting points tried (see rcb_fit_set_starts) */
} rcb_fit_report;
RCB_API rcb_status rcb_fit_get_report(const rcb_fit *f, rcb_fit_report *out);

/**
 * @brief The adequacy test of a model (issue #23): is what the fit leaves
 * what the noise alone would leave? With known standard deviations
 * (rcb_fit_set_sd) every weighted residual is N(0, 1) and F a chi-square of
 * N - np degrees of freedom; with the eq. 19 noise model F's null
 * distribution is calibrated by drawing that noise (io/noise.c, its own
 * generator and a fixed seed: the same figures every run) on the model's
 * values at every residual, 16 draws each, weighted as the fit weights the
 * data. The residuals are independent, so F's mean and variance are the
 * sums of theirs (a relative error of about 1/sqrt(16 N) on 32 x 1101). The
 * model is adequate when F <= limit = mean - np + 2.326 sd: 1 % of
 * adequate models are rejected (F is a sum of N terms: normal to a good
 * approximation). Without either (known = 0) nothing is tested: the noise is
 * unknown.
 */
typedef struct rcb_fit_adequacy {
  int known;       /**< 1: the noise is known (a noise model or standard deviations) */
  double chi2;     /**< F, the weighted objective at the model's current values (-) */
  double dof;      /**< residuals less fitted parameters (-) */
  double expected; /**< F's mean under the noise alone, less np (-) */
  double sd;       /**< F's standard deviation under the noise alone (-) */
  double limit;    /**< expected + RCB_ADEQUACY_Z sd (-); NaN when not known */
  int adequate;    /**< known and chi2 <= limit */
  /* issue #33: is what the fit leaves noise of another level or form, or a
   * misfit? */
  double white_z;    /**< lag-1 statistic of the weighted residuals along frequency
                          (per channel and part; N(0, 1) for any white noise, declared
                          or not; large when the misfit is smooth: a missing effect) (-) */
  int white;         /**< known and white_z <= RCB_ADEQUACY_Z: no structure along
                          frequency at 1 % */
  double dispersion; /**< chi2 / expected: the residual's variance over the declared
                          noise's (-); NaN when not known */
} rcb_fit_adequacy;
/** One-sided normal quantile of the adequacy test: 1 % false rejections. */
#define RCB_ADEQUACY_Z 2.3263478740408408
/**
 * @brief The adequacy test at the model's current values (one sweep).
 * @param chi2_ch, expected_ch, sd_ch: when not NULL, per channel
 * (rcb_meas_channel_count entries): its part of F, of the mean and the sd
 * (channels are independent: where the misfit concentrates).
 */
RCB_API rcb_status rcb_fit_get_adequacy(rcb_fit *f, rcb_fit_adequacy *out, double *chi2_ch,
                                        double *expected_ch, double *sd_ch);

/**
 * @brief Why the last run stopped. Anything but RCB_FIT_STOP_CONVERGED makes
 * the report unsure. (A non-finite objective is not a stop reason: rcb_fit_run
 * fails with RCB_ERR_NOT_CONVERGED, naming where it appeared.)
 */
typedef enum rcb_fit_stop {
  RCB_FIT_STOP_NONE = 0,      /**< not run yet */
  RCB_FIT_STOP_CONVERGED = 1, /**< a convergence test was met */
  RCB_FIT_STOP_AT_BOUND = 2,  /**< converged with a parameter at (or past) a bound that
                                   the objective pushes against (moving past it would
                                   lower F by more than 0.1 %): the minimum lies outside
                                   the bounds */
  RCB_FIT_STOP_STALLED = 3,   /**< no step reduced the objective although the local
                                   model promised a reduction (or NLopt ended
                                   round-off limited): a wrong or noisy gradient, or a
                                   kink */
  RCB_FIT_STOP_MAX_ITER = 4   /**< the iteration or evaluation budget ran out first */
} rcb_fit_stop;
/**
 * @brief Stop reason of the last run. @param param if not NULL, receives the
 * index of the parameter at its bound (RCB_FIT_STOP_AT_BOUND), else np.
 */
RCB_API rcb_fit_stop rcb_fit_stop_reason(const rcb_fit *f, size_t *param);
/** @brief Short English text for a stop reason (never NULL). */
RCB_API const char *rcb_fit_stop_str(rcb_fit_stop s);
/**
 * @brief Condition of the linear solves in the final evaluation of the last run
 * (see rcb_frf_condition; only that sweep is checked, the iterations run
 * without the estimate). ill > 0 means the fitted model is near-singular at
 * some point of the band (omega there): its residuals are not to be trusted.
 */
RCB_API rcb_status rcb_fit_get_condition(const rcb_fit *f, rcb_frf_condition *out);

/** @brief One fitted parameter with its uncertainty. */
typedef struct rcb_fit_param {
  const char *name;
  double start, value; /**< parameter units */
  double stderr_;      /**< standard error from (J^T W J)^-1 sigma^2 */
  double ci_lo, ci_hi; /**< 95 % confidence interval */
  int identifiable;    /**< 0 when the data cannot determine it (SVD test) */
} rcb_fit_param;
RCB_API size_t rcb_fit_param_count(const rcb_fit *f);
RCB_API rcb_status rcb_fit_get_param(const rcb_fit *f, size_t k, rcb_fit_param *out);
/** @brief Parameter correlation matrix, np x np column-major. */
RCB_API rcb_status rcb_fit_correlation(const rcb_fit *f, double *C);

/* ---- building blocks, exposed for checks and for other optimisers ---- */

/**
 * @brief The paper's error % of the model as it is now, over the fit's points:
 * 100 ||(|m| - |e|)|| / || |e| || on linear magnitudes (before any fit: E0).
 */
RCB_API rcb_status rcb_fit_error(rcb_fit *f, double *error_pct);
/**
 * @brief Sensitivity of each measurement channel to each parameter (paper
 * Figs. 7 and 11): S[c + nch * k] = RMS over the channel's points of
 * p_k d s(H)/d p_k (the change on the fit's scale for a 100 % change of p_k,
 * weights not applied; for a sensor's phase, neutral at 0, d s(H)/d phi per
 * rad). Use a noise-free simulated measurement with many
 * candidate channels to pick the most sensitive ones.
 * @param S output, nch x np column-major (nch = rcb_meas_channel_count)
 */
RCB_API rcb_status rcb_fit_channel_sensitivity(rcb_fit *f, double *S);
/** @brief Number of residuals (after band and zero weights). */
RCB_API size_t rcb_fit_residual_count(const rcb_fit *f);
/** @brief Weighted residuals sqrt(W) r at the model's current parameters. */
RCB_API rcb_status rcb_fit_residuals(rcb_fit *f, double *r);
/**
 * @brief Jacobian of the weighted residuals with respect to the parameters
 * (d/dp, not d/dlog p), residual_count x np column-major: analytic (eq. 9,
 * reusing each frequency's factorisation) or finite differences (eq. 11).
 */
RCB_API rcb_status rcb_fit_jacobian(rcb_fit *f, int analytic, double *J);

#ifdef __cplusplus
}
#endif

#endif /* RCB_IDENTIFY_H */
