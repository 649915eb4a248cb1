/**
 * @file rcb_monitor.h
 * @brief Model-based condition monitoring (issue #16): a fitted baseline
 * model and its commissioning measurement, then one new measurement after
 * another, each answered with "unchanged within the noise", the trend of the
 * tracked parameters with confidence intervals, and, when a new effect
 * appears, the effect and place that explain it best, with their size.
 *
 * Method (all sizing and allocation in rcb_monitor_create; rcb_monitor_update
 * allocates nothing):
 *  - Residual space. Every (channel, point) of the set-up gives two real
 *    residuals, the change of the measured value since commissioning,
 *    d = e_new - e_0 (SI units of the channel's kind), taken in the
 *    (radial, tangential) frame of e_0 and divided by its standard deviation:
 *    the eq. 19 noise model (beta_a along e_0 with variance
 *    (beta_a/100)^2 |m|^2 / 3, |m| the baseline model's modulus there, kept
 *    within a factor 2 of |e_0| (not |e_0| itself: its own noise would
 *    correlate with d), beta_s circular with variance a^2 / 6 per
 *    component, a = beta_s/100 sqrt(sum_j |e_0j|^2) / n; with phase noise
 *    +-phase_deg, uniform, (phase_deg pi/180)^2 |m|^2 / 3 more on the
 *    tangential axis) or per-point standard deviations, for the new measurement and for the commissioning
 *    one (divided by the number of measurements averaged into it). The
 *    baseline model's own bias (model minus commissioning measurement) is
 *    therefore never a change.
 *  - Columns. The sensitivities of the tracked parameters (paper eq. 9,
 *    analytic) and of every catalogue candidate's parameters at its neutral
 *    value (the diagnosis catalogue of rcb_diagnose.h, issue #4), all at
 *    the baseline and whitened the same way, are factored once by
 *    Householder QR (columns dependent on earlier ones within 1e-10 dropped):
 *    Q, of rank k.
 *  - Instant test. y = Q^T r (r the whitened change); the tracked
 *    parameters are free to drift (their drift is trended and watched by the
 *    CUSUM below), so the test is on the part of y orthogonal to them:
 *    T = ||y||^2 - ||P_t y||^2, chi-square with k - k_t degrees of freedom
 *    when nothing but the tracked parameters changed; alarm when T exceeds
 *    the chi-square quantile at 1 - alpha (rcb_chi2_quantile, written here:
 *    regularised incomplete gamma by series / continued fraction, inverted
 *    by safeguarded Newton; no LAPACK or SUNDIALS routine offers it).
 *  - Ranking. Each candidate's score statistic: the reduction of ||r||^2
 *    its columns explain beyond the tracked parameters' (the orthogonalised
 *    score test of the diagnosis), chi-square with its rank under "absent";
 *    candidates are ranked by its upper-tail p-value (so one- and
 *    three-parameter effects compare fairly), except that a candidate whose
 *    estimate is physically impossible (for some parameter the 95 %
 *    interval of neutral value + size lies wholly outside the catalogue's
 *    plausible range, e.g. a negative pedestal mass) ranks after every
 *    possible one: a large score at an impossible size means its columns
 *    fit a change of another kind. Size: the linearised
 *    Gauss-Newton step of the tracked parameters and the candidate's
 *    together, with 95 % intervals from (J^T W J)^-1 (the noise is known:
 *    no sigma^2 factor).
 *  - Trend. Tracked parameters: the same step with the tracked parameters
 *    alone (jointly with the best candidate while the instant test fires),
 *    value = baseline + step, 95 % intervals of the value (with the variance
 *    of opts.baseline_cov) and of the change (without). With
 *    opts.relinearise > 0 the step is refined by chord iterations that
 *    re-evaluate the model at the new value (the fit's preallocated FRF
 *    object, no allocation); T is taken on what that step leaves, but the
 *    candidates (scores, sizes) and the joint fit while the test fires are
 *    on the change from the baseline, linearised there: the re-linearised
 *    step of the tracked parameters alone absorbs part of a new effect, and
 *    the model's non-linear response at that wrong step is in no
 *    candidate's columns (with opts.reweight it made a flexible support at
 *    B1 of -1e7 kg explain B3's cross-coupling). While the test fires, the
 *    joint step of the tracked parameters and the best candidate is then
 *    refined by opts.relinearise Gauss-Newton iterations whose columns are
 *    re-evaluated at the estimate (forward differences of the model, 1 +
 *    k_t + its parameters sweeps each), when the candidate's parameters are
 *    the model's own (a bearing's or a disk's coefficients, not a pedestal
 *    or a new mass): its size, the tracked values and all their standard
 *    errors come from there. A large effect is not linear in its size:
 *    linearised at the baseline, 1.5e7 N/m of cross-coupling at B3 came
 *    out 5 % short, its interval missed the truth, and the unchanged
 *    tracked parameters moved 17-68 standard errors.
 *  - Noise after a change. With opts.reweight the covariance of r is
 *    rebuilt at every update from the update's own noise (proportional
 *    noise follows the new response, whose peaks may have moved), C =
 *    Q^T D Q in the rank space, and every statistic above is taken in the
 *    metric C^-1 (generalised least squares): T stays chi-square(k - k_t)
 *    when only tracked parameters changed, however far.
 *  - Sequential detector. A two-sided self-starting CUSUM per tracked
 *    parameter. Its input is not the change since commissioning,
 *    z = (value - baseline) / stderr: every update's z carries the same
 *    commissioning noise (the reference is one measurement, or the average
 *    of N = opts.setup_averages), so successive z are correlated and a
 *    CUSUM on them false-alarms far more often than its ARL0 says (with
 *    N = 10: 15 alarms over 190 updates of a null ROSS series). The input is
 *    the innovation u = (step - m) / sqrt(v + 1 / W): m the inverse-variance
 *    weighted mean of the commissioning (step 0, variance
 *    stderr^2 (1/N) / (1 + 1/N)) and of every earlier in-control update's
 *    step (variance v = stderr^2 / (1 + 1/N), its own noise), W the sum of
 *    those weights. The commissioning noise cancels in step - m, and under
 *    "no change" with Gaussian noise the u of successive updates are
 *    independent N(0, 1) (the innovations of a running mean). Then
 *    S+ = max(0, S+ + u - k), S- = max(0, S- - u - k), alarm when either
 *    exceeds h, and the in-control average run length of one side is
 *    Siegmund's ARL0 = (exp(2 k b) - 2 k b - 1) / (2 k^2), b = h + 1.166
 *    (rcb_cusum_arl0); both sides of n_t parameters alarm about 2 n_t times
 *    as often. An update joins the reference only while neither the instant
 *    test nor that parameter's CUSUM alarms; after a CUSUM alarm its
 *    reference stays frozen until rcb_monitor_reset_cusum, which starts it
 *    afresh from the next update (then the first update after the reset
 *    only seeds it, u = 0). A drift is caught as a run of innovations of one
 *    sign: the running mean trails a linear drift by half its length. With a
 *    noise-free reference (setup_averages HUGE_VAL) m stays 0 and u = z.
 *  - The baseline's error in the CUSUM (opts.baseline_cov S). A baseline off
 *    the truth by d is linearised at the wrong point: a change D of the
 *    tracked parameters comes out as the step D - E H[d, D] (E the tracked
 *    estimator, H the curvature of the whitened response in the rank space,
 *    by nt (nt + 3) / 2 model re-evaluations at create), so a's step is off
 *    by g . d, g_i = sum_j dE_a H_ij D_j; the same d in every update, so the
 *    error grows with the other parameters' change and the CUSUM sums it
 *    (test_monitor's test_baseline_cusum: a baseline 0.2 % off in kt and ct
 *    and kt wearing 0.2 % per update made ct's plain CUSUM alarm in 37 of 40
 *    replicas). With S, a's allowance is raised to k + q sqrt(g^T S g) /
 *    sd(u), D taken as each tracked step minus its mean over a's reference
 *    (what u sees), q the normal quantile at 1 - alpha / 2: while the
 *    baseline's error is within q of its standard deviations along g (1 -
 *    alpha of baselines when the change keeps one direction), u - k - the
 *    allowance is below the exact baseline's u - k, and the ARL0 holds. The
 *    false-alarm rate per tracked parameter over the baselines is then at
 *    most alpha + 2 n / ARL0 over n updates (0 of 40 replicas above). The
 *    cost: a's changes smaller than the allowance go unseen while the others
 *    move (the allowance is reported, rcb_monitor_tracked.cusum_allow; 0
 *    k while nothing changes); a step of ct of 0.9 % (14 of its
 *    standard errors) half-way through that wear was caught within 2
 *    updates (1 on an exact baseline), one of 0.37 % (5.7) within the 20
 *    updates left in 9 of 40 replicas (40, at 1.8 updates, on an exact
 *    baseline).
 *  - Drift test (window GLR, beside the instant test). Per scored candidate,
 *    s_t = D_c y_t, its orthonormal directions beyond the tracked columns
 *    (the tracked parameters free at every update: nuisance), over the last
 *    32 updates (a ring kept with the state). Model: s_t grows linearly,
 *    b (t - tau), from an onset m = t - tau updates ago; the commissioning
 *    noise every update shares is a common offset with the known share
 *    rho = (1/N) / (1 + 1/N) of an update's variance, so the updates of one
 *    direction have covariance (1 - rho) I + rho 1 1^T over the n updates
 *    since commissioning, whose inverse needs only the sums of y over them.
 *    For onset m with weights w_j = m - j on the m newest updates, the GLS
 *    GLR is ||sum w_j s_j - kappa (sum w) S||^2 / ((1 - rho) (sum w^2 -
 *    kappa (sum w)^2)), S the sum of s over the n updates and kappa =
 *    rho / (1 - rho + n rho) (1 / n after rcb_monitor_reset_cusum: the
 *    offset is then free), chi-square(dof) under "no drift" for each m
 *    (exact for Gaussian noise; test_monitor's test_drift_glr). The largest
 *    over the onsets m in {1, 2, 3, 5, 7, 10, 14, 19, 25, 32} (ramps of
 *    neighbours correlate 0.96 or more) is the candidate's; the candidate
 *    with the smallest chi-square p-value is reported, and alarms when that
 *    p-value times the scored candidates times the 10 onsets (Bonferroni:
 *    a false-alarm probability per update of at most alpha, the instant
 *    test's) is below alpha. Its drift rate per update, in parameter units,
 *    is the rate of s taken back through the candidate's triangular factor
 *    at create. With opts.reweight (or an update's sd) s is taken in the
 *    update's own noise: the candidate's orthonormal components beyond the
 *    tracked columns in the instant test's metric (its GLS), on what the
 *    re-linearised tracked step leaves; without, in the commissioning's (on
 *    a 2.6 % wear of kt the commissioning's metric made the drift test alarm
 *    on a pedestal at B3, GLR 700 at one onset, as it makes T alarm; in the
 *    update's own it stayed below 9). The attribution below takes the
 *    commissioning's metric on either path.
 *  - Attribution of CUSUM alarms. While a tracked parameter a's CUSUM
 *    alarms, the accumulated change (the ramp-weighted GLS combination of
 *    the whole window, as above, of y plus the tracked columns times the
 *    re-linearised steps: the change from the baseline, linearly) is
 *    fitted by a's column and, in turn, by each scored candidate's columns,
 *    the other tracked parameters free in both (nuisance); each fit's GLR
 *    (the explained sum of squares beyond the nuisance) gives the BIC
 *    change -GLR + dof ln n of rcb_monitor_named's one rule, and the best
 *    candidate is compared with a by rcb_evidence_separable, then by the
 *    rule's test half on the accumulated change (a alone only when every
 *    candidate's hypothesis is rejected at RCB_MONITOR_APART_ALPHA by what
 *    a's column adds to it, else the one not rejected is the rival; the
 *    candidate told apart from a only when a's is rejected by what the
 *    candidate adds): rcb_monitor_tracked.named says a alone, "a or the
 *    candidate: not separable on these channels", or the candidate told
 *    apart from a; in
 *    the second case rcb_monitor_separating names the channel or speed that
 *    would separate them (the diagnosis' plan). The candidate is told apart
 *    alone only when the runner-up candidate is told apart from it too (by
 *    the BIC, and every other candidate rejected by the test half); else
 *    both are given (rival2: on one channel a B4 kyy drift and B1 kxx fit
 *    the change within 1.5 of BIC, so "not kr" holds but not which bearing).
 *    Untracked before tracked (issue #34): while the same update's instant
 *    test (its first candidate) or drift test (its candidate) points at an
 *    untracked candidate, that candidate is the rival whenever the best one
 *    is not told apart from it, and a CUSUM alarm is never a's alone: "a, or
 *    that candidate: not separable" (named 0) at least.
 */
#ifndef RCB_MONITOR_H
#define RCB_MONITOR_H

#include "rcb/rcb_core.h"
#include "rcb/rcb_diagnose.h"
#include "rcb/rcb_measure.h"
#include "rcb/rcb_model.h"

#ifdef __cplusplus
extern "C" {
#endif

/** @brief Most tracked parameters of one monitor. */
#define RCB_MONITOR_MAX_TRACKED 8
/** @brief Most ranked candidates in one result. */
#define RCB_MONITOR_TOP 8
/** @brief Most parameters of one candidate effect (as the diagnosis). */
#define RCB_MONITOR_MAXP 3
/** @brief Level of the test that tells an alarm's first candidate apart
 * from each rival (rcb_monitor_named, rcb_monitor_result.apart_p): when the
 * truth is a rival, of any size, an update tells the first apart from it
 * at this rate at most, linearly and with the noise as declared, so a
 * series of 50 alarmed updates at 5 % at most (the union bound: the
 * issue's rate, per series, for every pair) (-). */
#define RCB_MONITOR_APART_ALPHA 0.001

/** @brief A parameter to track (rcb_model_get_param names, e.g. "C.kt"). */
typedef struct rcb_monitor_param {
  const char *name; /**< parameter name, copied at create */
  double lo, hi;    /**< plausible range, parameter units (lo < hi); an estimate
                         outside it sets rcb_monitor_tracked.out_of_range */
} rcb_monitor_param;

/** @brief Monitor settings: zero-initialise, then set what you need (0 means
 * the default stated on each field). */
/** The candidates rcbtool monitor asks for by default (issue #34): the
 *  machine's effects of opts.effects = 0 and the measurement chain, each
 *  measured probe's gain and phase (a sign flipped is its gain at -1) and
 *  each station's x and y probes swapped (one parameter: the fraction
 *  swapped, 0 as wired, 1 exchanged). */
#define RCB_MONITOR_EFFECTS_SENSORS                                                        \
  (((1u << RCB_EFFECT_ELEMENT_STIFFNESS) - 1u) | (1u << RCB_EFFECT_SENSOR_GAIN) |          \
   (1u << RCB_EFFECT_SENSOR_SWAP))

typedef struct rcb_monitor_opts {
  size_t ntracked;                  /**< tracked parameters, 0 .. RCB_MONITOR_MAX_TRACKED */
  const rcb_monitor_param *tracked; /**< ntracked entries */
  double alpha;      /**< false-alarm probability of the instant test per update
                          (-), 0 < alpha < 1; 0: 1e-3 */
  double cusum_k;    /**< CUSUM reference value, standard deviations of u (-);
                          0: 0.5 (tuned to a shift of 1 standard deviation) */
  double cusum_h;    /**< CUSUM decision threshold (-); 0: 8 (one side's
                          ARL0 ~ 1.9e4 updates) */
  double beta_a;     /**< eq. 19 random (proportional) noise of one
                          measurement, % (used when sd is NULL) */
  double beta_s;     /**< eq. 19 systematic (additive) noise of one
                          measurement, % (used when sd is NULL) */
  const double *sd;  /**< standard deviation of each of Re and Im of one
                          measurement at each (channel, point), channel-major
                          (sd[c * npoints + i]), SI units of the channel
                          (e.g. from rcb_spectral_frf); NULL: the eq. 19 model */
  double setup_averages; /**< measurements averaged into the set-up values
                              (>= 1); 0: 1; HUGE_VAL: a noise-free reference */
  unsigned effects;  /**< candidate effects: bit (1u << rcb_effect) set for
                          each one catalogued; 0: the effects of the machine
                          before the shaft elements (the coupling model,
                          refitted only by the diagnosis, has no neutral value
                          and is left out); RCB_MONITOR_EFFECTS_SENSORS: those
                          and the measurement chain */
  size_t top;        /**< candidates ranked in each result, 0: RCB_MONITOR_TOP */
  size_t relinearise; /**< chord iterations refining the tracked estimates per
                           update by re-evaluating the model (0: linear only;
                           each costs one sweep of the set-up with the banded
                           LAPACK solver, which allocates nothing, or, where
                           rcb_monitor_fast_relinearise says so, a small
                           solve per frequency on the DOFs the tracked
                           parameters touch) */
  int reweight;      /**< 1: take each update's noise from the update itself
                          (eq. 19 on its own values, or the sd passed to
                          rcb_monitor_update) and apply the statistics in that
                          covariance (generalised least squares in the rank
                          space, O(n k^2) per update); 0 (default): the noise of
                          the commissioning values, exact while the machine is
                          near them (O(n k) per update). Proportional noise
                          grows with the response: after a large change (a
                          resonance moved) only 1 keeps T chi-square */
  double phase_deg;  /**< phase noise of one measurement, degrees: each point
                          turned by an angle uniform in +-phase_deg (issue
                          #14's noise), tangential variance
                          |e|^2 (phase_deg pi/180)^2 / 3 added to the eq. 19
                          model's (used when sd is NULL); 0: none */
  const double *baseline_cov; /**< covariance of the baseline's tracked values,
                          ntracked x ntracked row-major, parameter units^2 (the
                          fit that made the baseline: its standard errors and
                          correlation); its diagonal widens the absolute
                          values' intervals (rcb_monitor_tracked.ci_lo, ci_hi),
                          taken independent of the change's noise. NULL: the
                          baseline is exact (the intervals are the change's) */
  const void *image; /**< a commissioning image (rcb_monitor_image_save) of a
                          monitor created from the same baseline model, set-up
                          and options: create takes the sensitivity columns'
                          QR, the rank-space projection and the low-rank
                          blocks from it instead of computing them (sweeps and
                          QRs: most of create's time), with results identical
                          to a create without it. Checked before use (its
                          checksum, a fingerprint of the inputs, every
                          dimension and value): create fails with
                          RCB_ERR_OTHER_SETUP for an image of other inputs,
                          RCB_ERR_CORRUPT or RCB_ERR_VERSION for a damaged or
                          other-version one; the caller then creates without
                          it. NULL (default): none */
  size_t image_size; /**< bytes at image */
  double noise_scale; /**< the noise's measured level against the declared
                          one (-): every declared standard deviation (beta_a,
                          beta_s, phase_deg, sd) is multiplied by it, in the
                          weights and in every test; e.g. the scale of
                          rcb_monitor_noise_scale on the measurements averaged
                          into the set-up. 0: 1 (the noise as declared) */
} rcb_monitor_opts;

/** @brief The noise's level measured on repeated measurements of one state
 * (rcb_monitor_noise_scale). */
typedef struct rcb_monitor_noise {
  double scale; /**< sqrt(chi2 / dof) (-): the measured level against the
                     declared one (1: as declared) */
  double chi2;  /**< the measurements' scatter about their average, each
                     point's (radial, tangential) deviation whitened by one
                     measurement's declared variance at the average (-) */
  double dof;   /**< its expectation under the declared noise:
                     2 x channels x points x (measurements - 1) */
} rcb_monitor_noise;

/** @brief One ranked candidate effect in a result. */
typedef struct rcb_monitor_candidate {
  size_t index;       /**< candidate index, for rcb_monitor_candidate_info */
  rcb_effect effect;  /**< the kind of effect */
  size_t np;          /**< its parameters (<= RCB_MONITOR_MAXP) */
  double size[RCB_MONITOR_MAXP];  /**< estimated change of each parameter
                                       from its neutral value, parameter units
                                       (e.g. N/m for a cross-coupled stiffness) */
  double ci_lo[RCB_MONITOR_MAXP]; /**< 95 % interval, parameter units */
  double ci_hi[RCB_MONITOR_MAXP];
  double score;       /**< score statistic (-), chi-square(dof) if absent */
  size_t dof;         /**< its degrees of freedom (rank of its columns beyond
                           the tracked ones) */
  double p_value;     /**< upper-tail probability of score (-) */
  int implausible;    /**< 1 when, for some parameter, the 95 % interval of
                           neutral value + size lies wholly outside the
                           catalogue's plausible range (e.g. a negative mass
                           or stiffness); such candidates rank after every
                           plausible one */
} rcb_monitor_candidate;

/** @brief One tracked parameter in a result. While the instant test fires,
 * the estimate is fitted jointly with the best-ranked candidate (a new
 * effect left out of the fit would bias the trend). Two intervals: of the
 * absolute value (the change's noise and the baseline's own uncertainty,
 * opts.baseline_cov) and of the change since the baseline (its noise, and
 * with opts.baseline_cov the error a baseline off the truth makes in a
 * change linearised there: the curvature of the sequential detector; z
 * watches the noise alone). */
typedef struct rcb_monitor_tracked {
  double value;        /**< estimate, parameter units */
  double ci_lo, ci_hi; /**< 95 % interval of the value, parameter units:
                            value -+ 1.96 abs_stderr */
  double stderr_;      /**< standard error of the change, parameter units */
  double z;            /**< (value - baseline) / stderr (-): the change since
                            commissioning */
  double u;            /**< the self-starting CUSUM's input (-): the step's
                            innovation against the reference of the earlier
                            in-control updates (see the method above) */
  double cusum_up;     /**< CUSUM S+ (-) */
  double cusum_down;   /**< CUSUM S- (-) */
  int cusum_alarm;     /**< +1: S+ > h (rising), -1: S- > h (falling), 0 */
  int out_of_range;    /**< 1 when value lies outside [lo, hi] */
  double abs_stderr;   /**< standard error of the value, parameter units:
                            sqrt(stderr_^2 + the baseline's share: its variance,
                            and with opts.baseline_cov (e_a - g)^T S (e_a - g),
                            g the curvature's effect of the change) */
  double change;       /**< value - baseline, parameter units */
  double change_lo, change_hi; /**< its 95 % interval: change -+ 1.96
                            sqrt(stderr_^2 + g^T S g) (S = opts.baseline_cov, g
                            the curvature's effect of the change; 0 without S) */
  int named;           /**< while cusum_alarm: whether the accumulated change is
                            this parameter's (the attribution in the method
                            above, by the one rule of rcb_monitor_named): 1 this
                            parameter alone (also when there is no candidate to
                            compare, rival_dof 0); 0 this parameter or candidate
                            rival, not separable on these channels; -1 candidate
                            rival, told apart from this parameter. 1 without
                            an alarm */
  size_t rival;        /**< the candidate that explains the accumulated change
                            best (index as rcb_monitor_candidate.index) */
  size_t rival_dof;    /**< its parameters (0: no candidate compared) */
  double rival_rate[RCB_MONITOR_MAXP]; /**< its parameters' change per update
                            over the window, parameter units per update (its
                            sign: rising or falling) */
  double cusum_allow;  /**< the CUSUM's allowance this update (-): opts.cusum_k,
                            raised with opts.baseline_cov by the baseline's
                            share (the sequential detector above) */
  size_t rival2;       /**< when named is -1: the runner-up candidate whose
                            explanation of the accumulated change is not
                            separable from the rival's by the one rule (the
                            data say "not this parameter" but not which of
                            the two: "rival, or rival2: not separable on these
                            channels"): the BIC's runner-up within 10, else
                            the candidate the test half rejects least when it
                            does not reject it; index as rival */
  size_t rival2_dof;   /**< its parameters; 0 when the rival is told apart
                            from every other candidate too (or named is not -1) */
  size_t rivals_open;  /**< while cusum_alarm and named is 0 or -1: the other
                            candidates, beyond rival and rival2, whose
                            hypothesis the test half of the one rule does not
                            reject either ("or N other candidates": the list
                            is not complete); 0 else */
} rcb_monitor_tracked;

/** @brief What one update found. Plain value type, owns nothing. */
typedef struct rcb_monitor_result {
  size_t update;      /**< updates so far, this one included */
  double error_pct;   /**< paper's error %, 100 ||(|m| - |e|)|| / || |e| ||, of
                           the baseline model m against this measurement e */
  double change_pct;  /**< the same of the commissioning values against e */
  double floor_pct;   /**< error % the noise alone explains (-, %): the rms of
                           the noise's radial standard deviation over || |e| || */
  double T;           /**< instant test statistic (-) */
  size_t dof;         /**< its degrees of freedom k - k_t */
  double threshold;   /**< chi-square quantile at 1 - alpha (-) */
  double p_value;     /**< upper-tail probability of T (-) */
  int alarm;          /**< 1 when T > threshold */
  int cusum_alarm;    /**< 1 when some tracked parameter's CUSUM is past h */
  size_t ntop;        /**< ranked candidates written */
  rcb_monitor_candidate top[RCB_MONITOR_TOP]; /**< best first (smallest p);
                            second the first's closest rival, the other
                            candidate with the lowest BIC change -score + dof
                            ln n (a plausible one when the first is); then by
                            p */
  size_t ntracked;    /**< tracked parameters */
  rcb_monitor_tracked tracked[RCB_MONITOR_MAX_TRACKED];
  /* the drift test (the method above): the candidate whose drift is best
   * supported, whether or not it alarms */
  double drift_glr;   /**< its window GLR (-), chi-square(drift_dof) for one onset */
  size_t drift_dof;   /**< its degrees of freedom (0: no candidate scored) */
  double drift_p;     /**< its p-value over every candidate and onset (-):
                           Bonferroni, min(1, p x scored candidates x 10 onsets) */
  int drift_alarm;    /**< 1 when drift_p < alpha and the instant test does
                           not fire (then it names the change, re-linearised: on
                           ROSS's step of cross-coupling at B3 the best linear
                           drift was a pedestal at B1) */
  size_t drift_index; /**< the candidate (as rcb_monitor_candidate.index) */
  size_t drift_onset; /**< updates since the drift's onset (one of 1, 2, 3, 5,
                           7, 10, 14, 19, 25, 32) */
  double drift_rate[RCB_MONITOR_MAXP]; /**< its parameters' change per update,
                           parameter units per update */
  double apart_p;     /**< when the BIC half of rcb_monitor_named's rule holds
                           (else NAN): the largest, over the first's rivals
                           (the other scored candidates; the plausible ones
                           when the first is), of the upper-tail probability
                           of the test that the first adds to the rival's fit
                           (the change the first's columns explain beyond the
                           tracked and the rival's, chi-square(first's dof)
                           when the rival is the truth, whatever its size).
                           A rival the first outscores by more than that
                           chi-square's 1 - RCB_MONITOR_APART_ALPHA quantile
                           counts with the bound of its p the score gap gives
                           (below the level, not computed). When it is at or
                           above RCB_MONITOR_APART_ALPHA that rival is the
                           second (top[1]); 0 when there is no rival (every
                           other candidate implausible, the first not) */
} rcb_monitor_result;

typedef struct rcb_monitor rcb_monitor;

/**
 * @brief Commission a monitor: size everything, evaluate the baseline
 * model's sensitivities and lay out the catalogue. All memory comes from
 * @p alloc here (an embedded host passes its arena; rcb_monitor_memory says
 * how much was kept); rcb_monitor_update never allocates. There is no
 * two-call sizing: the size depends on how many candidates the catalogue
 * lays out on this model, known only once it has been built. The model
 * evaluations (here and with opts.relinearise) use the banded LAPACK solver,
 * never KLU, whose factors would bypass the hooks. A bump allocator that
 * never frees needs every temporary of create (tools/bench/bench_monitor
 * prints both that and the bytes kept).
 * @param baseline fitted, finalized model (copied: the caller may destroy it)
 * @param setup channels and abscissa (FRF: frequencies, rad/s, at the test
 * speed; 1X unbalance response: rotor speeds, rad/s) and, as its values, the
 * commissioning measurement (copied)
 * @param opts settings (NULL: every default; noise then must come from
 * somewhere: RCB_ERR_ARG without beta_a, beta_s or sd)
 * @param alloc allocator hooks, NULL for malloc
 * @return RCB_OK; on failure *out may hold an object carrying the message
 * (rcb_monitor_errmsg): destroy it in every case
 */
RCB_API rcb_status rcb_monitor_create(rcb_monitor **out, const rcb_model *baseline,
                                      const rcb_meas *setup, const rcb_monitor_opts *opts,
                                      const rcb_allocator *alloc);
/**
 * @brief The noise's level from @p nrep measurements of one state (the
 * commissioning files, before they are averaged into the set-up): how many
 * times the noise @p opts declares (beta_a, beta_s, phase_deg or sd; its
 * noise_scale is not applied) their scatter about their average is. A noise of
 * the declared form but another level gives scale = that level's ratio, to
 * about sqrt(1 / (2 dof)); pass it as opts.noise_scale to rcb_monitor_create
 * with the average as the set-up. Reads only; allocates nothing.
 * @param setup channels and abscissa (its values are not read)
 * @param values nrep x channels x points, values[(r * nch + c) * npoints + i],
 * the set-up's channel order, the channels' units
 * @param nrep measurements, >= 2
 * @return RCB_OK; RCB_ERR_ARG for nrep < 2, a missing noise model, a value
 * that is not finite or a point of zero declared variance
 */
RCB_API rcb_status rcb_monitor_noise_scale(const rcb_meas *setup, const rcb_complex *values,
                                           size_t nrep, const rcb_monitor_opts *opts,
                                           rcb_monitor_noise *out);
RCB_API void rcb_monitor_destroy(rcb_monitor *mon);
/** @brief Last error, naming the channel and point where it applies. */
RCB_API const char *rcb_monitor_errmsg(const rcb_monitor *mon);

/**
 * @brief One new measurement. Allocates nothing.
 * @param values rcb_monitor_point_count values, the set-up's layout:
 * channel-major (values[c * npoints + i]), each in its channel's kind, SI
 * @param sd standard deviation of each of Re and Im at each point for this
 * measurement (same layout, SI), or NULL for the noise given at create (or,
 * with opts.reweight, eq. 19 on these values). With sd the statistics are
 * taken under that covariance as with opts.reweight, O(n k^2) instead of
 * O(n k)
 * @param res output
 * @return RCB_ERR_ARG for a NaN/infinite value or a negative/NaN sd, naming
 * the channel and point (the monitor's state is left unchanged);
 * RCB_ERR_STATE after RCB_MONITOR_MAX_UPDATES updates
 */
RCB_API rcb_status rcb_monitor_update(rcb_monitor *mon, const rcb_complex *values,
                                      const double *sd, rcb_monitor_result *res);

/** @brief The most updates one monitor takes: 2^32 - 1 (136 years at one a
 * second). Every counter of the monitor and of its saved state then fits a
 * 32-bit size_t and a double exactly, and none can wrap: rcb_monitor_update
 * refuses the next one (RCB_ERR_STATE) and rcb_monitor_load refuses a state
 * that claims more. */
#define RCB_MONITOR_MAX_UPDATES 4294967295u

/** @brief Updates taken so far (result.update of the last one; loaded with
 * a state; rcb_monitor_reset_cusum keeps it); 0 for a monitor not created
 * successfully. */
RCB_API size_t rcb_monitor_update_count(const rcb_monitor *mon);

/** @brief Forget the CUSUM sums and the drift test's window (after
 * maintenance, or once an alarm is acknowledged; the drift test's common
 * offset is then free, as the CUSUM's reference starts afresh); the update
 * count and the baseline stay. */
RCB_API void rcb_monitor_reset_cusum(rcb_monitor *mon);

/** @brief Values one update takes: channels x points of the set-up. */
RCB_API size_t rcb_monitor_point_count(const rcb_monitor *mon);
/** @brief Bytes the monitor holds (all from its allocator). */
RCB_API size_t rcb_monitor_memory(const rcb_monitor *mon);
/** @brief 1 when opts.relinearise re-evaluates the model without a sweep:
 * an FRF set-up whose tracked parameters enter the dynamic stiffness
 * affinely (every stiffness, damping and inertia coefficient does), on the
 * few DOFs they touch; each evaluation is then the Woodbury identity on
 * those DOFs, checked against a sweep at create (relative 1e-7). 0: each
 * re-linearisation sweeps the set-up (a 1X set-up, or no re-linearisation). */
RCB_API int rcb_monitor_fast_relinearise(const rcb_monitor *mon);
/** @brief Rank k of all columns (tracked + candidates) and k_t of the tracked. */
RCB_API rcb_status rcb_monitor_rank(const rcb_monitor *mon, size_t *k, size_t *k_tracked);

/** @brief Static description of candidate @p i (strings owned by the monitor). */
typedef struct rcb_monitor_candidate_info {
  rcb_effect effect;       /**< kind of effect (rcb_effect_name) */
  const char *place;       /**< "bearing B2", "coupling C", "station #7", ... */
  const char *description; /**< an engineer's sentence */
  const char *params;      /**< its parameter names, comma separated */
  size_t np;               /**< parameters */
} rcb_monitor_candidate_info;
/**
 * @brief Whether an alarmed update's first candidate is told apart from its
 * second, its closest rival (rcb_monitor_result.top), and from every other.
 * Two halves. The diagnosis' rule (rcb_evidence_separable): each
 * candidate's BIC change is -score + dof ln n (n: the update's real
 * residuals, 2 x channels x points), and the first's must be lower than the
 * second's by more than 10, hence lower than every other candidate's. And
 * a test with a stated rate: every rival's hypothesis rejected at level
 * RCB_MONITOR_APART_ALPHA by the change the first explains beyond it
 * (rcb_monitor_result.apart_p): whatever the rival and its size, when it is
 * the truth the first is told apart from it at that rate at most (the BIC
 * half alone has no such bound: a 1-dof first beats a 3-dof truth by 2 ln
 * n). 1: the first may be named alone; 0: "A or B: not separable on these
 * channels" (the data cannot choose, prefer B by the BIC, or cannot reject
 * B: then B is the second); -1: fewer than two candidates ranked (nothing
 * to tell apart) or a bad argument.
 */
RCB_API int rcb_monitor_named(const rcb_monitor *mon, const rcb_monitor_result *r);
/** @brief The measurement that would tell a tracked parameter from a
 * candidate effect (rcb_monitor_separating). */
typedef struct rcb_monitor_separator {
  int found;          /**< 1: the channel below separates them; 0: none does
                           (see present_separable) */
  int present_separable; /**< 1: the set-up's own channels already separate
                           them at the plan's size (a larger change will
                           show it; nothing to add) */
  double chi2_present; /**< the plan's separating chi-square on the set-up's
                           channels (-), S sin^2(angle) */
  double angle_deg;   /**< the plan's smallest principal angle there, deg */
  char response[64];  /**< the channel to add: its response DOF, "B4.y" */
  char reference[64]; /**< and its excitation, "DA.x" */
  double speed;       /**< at this rotor speed, rad/s */
  double chi2_after;  /**< the separating chi-square with it added (-); found
                           when rcb_evidence_separable(chi2_after, 0) */
  double level_db;    /**< its RMS level against the strongest present
                           channel's, dB (rcb_plan_candidate.level_db) */
} rcb_monitor_separator;
/**
 * @brief Name the channel or speed that would separate tracked parameter
 * @p tracked from candidate @p cand (as rcb_monitor_tracked.rival, e.g.
 * after "kr falling, or B4 kyy falling: not separable on these channels"),
 * by the diagnosis' plan (rcb_plan, rcbtool plan): the candidate's
 * parameters make the data (side A), every tracked parameter is fitted to
 * them (side B: the others are free in the monitor's attribution too), on
 * the set-up's layout and the eq. 19 noise model of opts.beta_a, beta_s;
 * the plan's candidate channels are x and y of every named station of the
 * baseline model per an excitation at every station, at the set-up's speed
 * and each of @p speeds. The best of them (the largest gain) is reported
 * when it separates them. Not for the update loop: it runs the plan, which
 * allocates (from the monitor's allocator, all freed before return) and
 * sweeps the model once per candidate excitation and speed.
 * @param speeds other rotor speeds to try, rad/s (may be NULL with
 * @p nspeeds 0)
 * @return RCB_ERR_ARG for a bad index, a candidate whose parameters are
 * not the model's own (a pedestal, a new mass: the plan cannot vary them),
 * no eq. 19 noise model (a monitor given sd only) or a set-up the plan
 * does not take (1X responses); the plan's errors otherwise; the message
 * (rcb_monitor_errmsg) says which
 */
RCB_API rcb_status rcb_monitor_separating(rcb_monitor *mon, size_t tracked, size_t cand,
                                          const double *speeds, size_t nspeeds,
                                          rcb_monitor_separator *out);
/** @brief Candidates laid out at create (scored or not). */
RCB_API size_t rcb_monitor_candidate_count(const rcb_monitor *mon);
/** @brief Description of candidate @p i (0-based, as rcb_monitor_candidate.index);
 * no allocation. */
RCB_API rcb_status rcb_monitor_candidate_info_get(const rcb_monitor *mon, size_t i,
                                                  rcb_monitor_candidate_info *out);
/** @brief Name and baseline value (parameter units) of tracked parameter @p k. */
RCB_API rcb_status rcb_monitor_tracked_info(const rcb_monitor *mon, size_t k,
                                            const char **name, double *baseline);

/** @brief The thresholds in use (the defaults resolved): the instant test's
 * false-alarm probability per update @p alpha (-) and its chi-square
 * threshold @p threshold (-), the CUSUM's reference @p cusum_k and decision
 * threshold @p cusum_h (standard deviations of u); any pointer may be NULL. */
RCB_API rcb_status rcb_monitor_thresholds(const rcb_monitor *mon, double *alpha,
                                          double *threshold, double *cusum_k,
                                          double *cusum_h);

/* ---- state that survives a restart (issue #24) ----
 *
 * What the updates accumulate (the update count, each tracked parameter's
 * CUSUM sums S+ and S-, the self-starting reference's weighted sums and
 * whether it is frozen) saved into a caller's buffer and loaded into a
 * monitor created again from the same baseline model, set-up and settings:
 * the updates after the load then give bit for bit what the original
 * monitor would have given (examples/firmware "reboots" mid-year and
 * checks this). Format (version RCB_MONITOR_STATE_VERSION), every field
 * little-endian whatever the host: "RCBM", version u32, size u32, tracked
 * count u32, the model's fingerprint (u64 FNV-1a of the tracked names and
 * baseline values and the candidates' places, and two weighted sums of
 * |baseline model| over the set-up, compared to 1e-9 relative so that
 * another BLAS's last bits do not refuse a state), the set-up's (u64 of its
 * grid, speed, channels and commissioning values), the settings' (u64 of
 * alpha, CUSUM k and h, noise, averages, re-linearisation, reweighting,
 * tracked ranges, opts.baseline_cov), the update count u64, the reference-started flag u32,
 * then per tracked parameter S+, S-, reference sum and weight (IEEE-754
 * binary64) and the frozen flag, then (version 3) per tracked parameter
 * its reference's sums of every tracked step (binary64 x tracked count;
 * the baseline's share of the CUSUM allowance), then the drift window
 * (version 2: the
 * rank k, tracked count and window u32, the ring's count and newest slot
 * u32, the updates in its sums u64, the free-offset flag u32, the sums of
 * the rank-space change y (k), of the re-linearised tracked steps and of
 * each scored candidate's drift input s, and per slot of the window its y,
 * step and s), and last the CRC-32 (IEEE 802.3,
 * reflected 0xEDB88320, as zlib's crc32) of everything before it. Neither
 * call allocates. */

/** @brief Format version of the saved state. */
#define RCB_MONITOR_STATE_VERSION 3u

/** @brief Bytes rcb_monitor_save writes for this monitor (108 + 40 per
 * tracked parameter + 8 per pair of tracked parameters + 264 (k + tracked parameters + the scored candidates'
 * ranks), k its rank (rcb_monitor_rank)); 0 for a monitor not created
 * successfully. */
RCB_API size_t rcb_monitor_state_size(const rcb_monitor *mon);
/**
 * @brief Save the monitor's accumulated state into @p buf.
 * @param size bytes available at @p buf
 * @param written bytes written (rcb_monitor_state_size), may be NULL
 * @return RCB_ERR_WORKSPACE when @p size is too small (nothing written),
 * RCB_ERR_STATE for a monitor not created successfully
 */
RCB_API rcb_status rcb_monitor_save(const rcb_monitor *mon, void *buf, size_t size,
                                    size_t *written);
/**
 * @brief Load a state saved by rcb_monitor_save into @p mon, created from
 * the same baseline model, set-up and settings. All checks come before
 * anything is changed: on any error the monitor is left as it was. Besides
 * its CRC every field is checked against what a monitor writes, so that a
 * state with a CRC made again cannot load values no update gives: CUSUMs
 * and the reference's weights finite and >= 0 (the weight +inf only for a
 * noise-free reference), every sum finite (0 while nothing is in it), the
 * update count at most RCB_MONITOR_MAX_UPDATES, the drift window's updates
 * at most the update count, its ring count and newest slot those that
 * follow from them, flags 0 or 1 and padding 0.
 * @return RCB_ERR_CORRUPT (not a monitor state, truncated, a CRC that
 * does not match, a length other than this monitor's state, or a field no
 * monitor writes: the message names it), RCB_ERR_VERSION (another format version),
 * RCB_ERR_OTHER_MODEL (another baseline model or tracked parameters),
 * RCB_ERR_OTHER_SETUP (another set-up or other settings); the message
 * (rcb_monitor_errmsg) says which field differs
 */
RCB_API rcb_status rcb_monitor_load(rcb_monitor *mon, const void *buf, size_t size);
/** @brief Format version of the commissioning image. */
#define RCB_MONITOR_IMAGE_VERSION 1u
/** @brief Bytes rcb_monitor_image_save writes: 8 per value of the rank-space
 * basis Q (2 x channels x points x k) and projection (k x the columns), 16
 * per value of the low-rank blocks (rcb_monitor_fast_relinearise), one per
 * candidate, and 112 more (megabytes: 9.8 MB for the paper system's 8 x 400
 * set-up with every probe's gain a candidate); 0 for a monitor not created
 * successfully. */
RCB_API size_t rcb_monitor_image_size(const rcb_monitor *mon);
/**
 * @brief Save what commissioning computed by sweeps and QRs (the
 * commissioning image), for rcb_monitor_opts.image: a process that creates
 * the monitor again for every measurement (a gateway) then skips them. It
 * does not change with the updates; little-endian, versioned
 * (RCB_MONITOR_IMAGE_VERSION), with a checksum.
 * @param size bytes available at @p buf (rcb_monitor_image_size)
 * @param written bytes written, may be NULL
 * @return RCB_ERR_WORKSPACE when @p size is too small (nothing written),
 * RCB_ERR_STATE for a monitor not created successfully
 */
RCB_API rcb_status rcb_monitor_image_save(const rcb_monitor *mon, void *buf, size_t size,
                                          size_t *written);
/** @brief CRC-32 (IEEE 802.3, zlib's crc32) of @p n bytes continuing from
 * @p crc (0 to start): the state's checksum, for hosts that store the state
 * inside records of their own. */
RCB_API unsigned long rcb_monitor_crc32(unsigned long crc, const void *data, size_t n);

/* ---- statistics used by the monitor, pure functions ---- */

/** @brief Upper tail P(X > x) of the chi-square distribution with @p dof
 * degrees of freedom (dof >= 1, x >= 0; NaN otherwise). */
RCB_API double rcb_chi2_sf(double x, double dof);
/** @brief Quantile x with P(X <= x) = p of chi-square(@p dof), 0 < p < 1
 * (NaN otherwise); relative accuracy ~1e-12. */
RCB_API double rcb_chi2_quantile(double p, double dof);
/** @brief Siegmund's in-control average run length (updates) of a one-sided
 * CUSUM with reference @p k > 0 and threshold @p h > 0 on N(0,1) data. */
RCB_API double rcb_cusum_arl0(double k, double h);

#ifdef __cplusplus
}
#endif

#endif /* RCB_MONITOR_H */
