/**
 * @file rcb_compare.h
 * @brief Where does the model fail? Correlation of a model with a
 * measurement: per-channel error measures, per-frequency cross-signature
 * criteria, a channel x frequency-band residual map, and a peak table pairing
 * the measured resonances with the model's modes.
 *
 * The model is evaluated on the measurement's abscissa (FRFs at the test's
 * rotor speed, or synchronous; unbalance responses at each speed) and
 * converted to each channel's kind, so e = measured and m = model values of
 * the same quantity. Abscissa values (frequencies or speeds) in rad/s.
 */
#ifndef RCB_COMPARE_H
#define RCB_COMPARE_H

#include "rcb/rcb_analysis.h"
#include "rcb/rcb_core.h"
#include "rcb/rcb_measure.h"
#include "rcb/rcb_model.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct rcb_compare rcb_compare;

RCB_API rcb_status rcb_compare_create(rcb_compare **out, const rcb_allocator *alloc);
RCB_API void rcb_compare_destroy(rcb_compare *c);
/** @brief Last error message (names the channel, point or setting at fault). */
RCB_API const char *rcb_compare_errmsg(const rcb_compare *c);

/**
 * @brief Number of frequency bands of the residual map (default 10): the grid
 * points are split into @p nbands contiguous runs of (nearly) equal count.
 * Fewer bands are used when the measurement has fewer points.
 * @return RCB_ERR_ARG unless 1 <= nbands <= 1000
 */
RCB_API rcb_status rcb_compare_set_bands(rcb_compare *c, size_t nbands);

/**
 * @brief Peak detection and pairing settings.
 * @param prominence_db a measured resonance is a local maximum of the
 * channel-summed magnitude standing at least this much above the higher of
 * its two bounding minima, dB (default 2 dB, > 0: 3 dB misses shoulders, 1 dB takes
 * 10 % noise for peaks)
 * @param freq_tol a measured peak and a model mode pair when their
 * frequencies differ by at most freq_tol times the measured frequency
 * (default 0.1, in (0, 1])
 */
RCB_API rcb_status rcb_compare_set_peaks(rcb_compare *c, double prominence_db, double freq_tol);

/**
 * @brief Known standard deviations of the measured values (issue #15: from
 * `rcbtool estimate --stats` / `order --stats`, as rcb_fit_set_sd): @p sd[k *
 * npoints + i] is the standard deviation of Re and of Im of channel k at point
 * i, in the measurement's SI unit (e.g. m/N); 0 or NaN leaves the point out
 * of the chi-square. With them every run also reports the noise floor (the
 * error % the sds alone explain) and the chi-square per degree of freedom of
 * each channel (about 1 when the model and the measurement agree to within
 * the noise). The values are copied; @p n must equal channels x points of the
 * measurement of the next run (checked there). @p sd NULL (n 0) clears them.
 * @return RCB_ERR_ARG for a negative or infinite value, RCB_ERR_NOMEM
 */
RCB_API rcb_status rcb_compare_set_sd(rcb_compare *c, const double *sd, size_t n);

/**
 * @brief Compare model @p m (finalized) with measurement @p ms: evaluates the
 * model at every point (a point where the model matrix is singular, e.g. a
 * free rotor at 0 Hz, is left out as NaN), computes every result below.
 * Errors: RCB_ERR_NOT_FOUND when a channel names no model station (the
 * message names it), RCB_ERR_ARG for an empty measurement, RCB_ERR_NOMEM,
 * RCB_ERR_LAPACK from the eigensolver. Results stay valid until the next run
 * or destroy (they do not point into @p m or @p ms).
 */
RCB_API rcb_status rcb_compare_run(rcb_compare *c, const rcb_model *m, const rcb_meas *ms);

/** @brief Results for one channel (e measured, m model, over the finite points). */
typedef struct rcb_compare_channel {
  const char *response;   /**< "DA.x" */
  const char *reference;  /**< "C.B.y", NULL for unbalance responses */
  rcb_frf_kind kind;      /**< kind of both value arrays */
  double error_pct;       /**< paper's error: 100 ||(|m| - |e|)|| / || |e| ||, % */
  double frac;            /**< FRAC |sum conj(e) m|^2 / (sum|e|^2 sum|m|^2), 0..1 */
  double log_rms;         /**< RMS of log10|m| - log10|e| (decades; 0.1 ~ 26 %) */
  double phase_rms_deg;   /**< RMS of arg(m) - arg(e) wrapped to (-180, 180], deg */
  const rcb_complex *meas;  /**< measured values, rcb_compare_point_count of them */
  const rcb_complex *model; /**< model values, same kind and units (NaN where left out) */
  double floor_pct;       /**< noise floor: 100 sqrt(sum sd^2 / sum |e|^2), % (NaN without
                               rcb_compare_set_sd) */
  double chi2_dof;        /**< sum |m - e|^2 / (2 sd^2) over the points with sd > 0, divided
                               by 2 x their count (Re and Im): ~1 at the noise (NaN without
                               sds); magnitudes only: (|m| - |e|)^2 / sd^2 per point */
  int magnitude_only;     /**< the measured channel has no phase (rcb_meas_add_channel_mag):
                               frac and phase_rms_deg are NaN, and it is left out of CSAC, CSF
                               and the mean FRAC */
} rcb_compare_channel;

/** @brief Totals over every channel and point. */
typedef struct rcb_compare_summary {
  double error_pct;     /**< paper's error % over all channels (as rcb_fit_error) */
  double frac_mean;     /**< mean FRAC over channels */
  double log_rms;       /**< RMS log10 error over all points, decades */
  double phase_rms_deg; /**< RMS phase error over all points, deg */
  double csac_mean;     /**< mean CSAC over frequencies */
  double csf_mean;      /**< mean CSF over frequencies */
  double floor_pct;     /**< noise floor % over all channels (NaN without sds) */
  double chi2_dof;      /**< chi-square per degree of freedom over all channels (NaN
                             without sds) */
} rcb_compare_summary;

RCB_API size_t rcb_compare_channel_count(const rcb_compare *c);
RCB_API rcb_status rcb_compare_get_channel(const rcb_compare *c, size_t i,
                                           rcb_compare_channel *out);
RCB_API rcb_status rcb_compare_get_summary(const rcb_compare *c, rcb_compare_summary *out);
/** @brief What the abscissa is (FRF: frequency; unbalance: rotor speed). */
RCB_API rcb_meas_type rcb_compare_type(const rcb_compare *c);
RCB_API size_t rcb_compare_point_count(const rcb_compare *c);
/** @brief The abscissa, rad/s. */
RCB_API const double *rcb_compare_grid(const rcb_compare *c);
/**
 * @brief Cross-signature assurance criterion at each point, across channels
 * (Allemang/Pascual): CSAC = |e^H m|^2 / ((e^H e)(m^H m)), 0..1 (NaN where
 * no channel is finite).
 */
RCB_API const double *rcb_compare_csac(const rcb_compare *c);
/** @brief Cross-signature scale factor CSF = 2|e^H m| / (e^H e + m^H m), 0..1. */
RCB_API const double *rcb_compare_csf(const rcb_compare *c);

/** @brief Number of bands of the residual map. */
RCB_API size_t rcb_compare_band_count(const rcb_compare *c);
/**
 * @brief One band: grid points first .. first + count - 1, abscissa lo .. hi
 * (rad/s, the band's first and last points).
 */
RCB_API rcb_status rcb_compare_band(const rcb_compare *c, size_t b, double *lo, double *hi,
                                    size_t *first, size_t *count);
/**
 * @brief Residual map: RMS of log10|m| - log10|e| (decades) per channel and
 * band, map[ch + nch * b] (NaN where a cell has no finite point).
 */
RCB_API const double *rcb_compare_residual_map(const rcb_compare *c);

/**
 * @brief The outlier rule of the per-sensor summary (issue #23), in one
 * place: a value is an outlier among @p n others when it exceeds
 *
 *     max(ratio x median(others), median(others) + 6 x 1.4826 x MAD(others))
 *
 * (MAD the median absolute deviation; 1.4826 MAD estimates a standard
 * deviation of normal data robustly). Both terms must be passed: the ratio
 * alone would name the top of a widely spread set, the MAD term alone
 * anything beyond a tight set (MAD near 0). A sensor whose gain is off by g
 * adds about |1 - g| of its own to its error, while a model error moves the
 * sensors that see a mode together: error % takes ratio 2 (the sensor misfits
 * twice as much as the typical one), chi2/dof ratio 4 (= 2^2, as chi-square
 * grows with the square of the misfit).
 * @param others the others' values (NaN ones left out), @p n of them
 * @param ratio the factor over the median (2 for error %, 4 for chi2/dof)
 * @param work scratch of @p n doubles (no allocation)
 * @return the threshold, or NaN when fewer than 3 others are finite (no
 * judgement is possible)
 */
RCB_API double rcb_compare_outlier_threshold(const double *others, size_t n, double ratio,
                                             double *work);

/**
 * @brief Upper limit of chi2/dof for @p dof degrees of freedom at the
 * noise: the 0.999 quantile of chi-square(dof)/dof (Wilson-Hilferty cube
 * approximation, within 1 % for dof >= 10), NaN for dof 0.
 */
RCB_API double rcb_compare_chi2_limit(size_t dof);

/**
 * @brief A sensor (a response name over all its references) or a channel
 * whose misfit stands out from the others' (rcb_compare_outlier_threshold):
 * the sign of a measurement chain fault (gain, phase, mounting) to check
 * before the model. Error %: a sensor's is 100 ||(|m| - |e|)|| / || |e| ||
 * over all its channels' points; a sensor is named when it exceeds the rule
 * against the other sensors (at least 4 sensors) and is at least 1 % (a gain
 * within calibration tolerance is not a fault), unless it has several
 * channels and only one of them stands out among the channels: a gain, phase
 * or mounting fault shows on every channel of the sensor, one channel alone
 * is its cable, connector or reference, and that channel is named instead
 * (against the other channels). With known sds
 * (rcb_compare_set_sd) on every channel, chi2/dof replaces error %: named
 * when it exceeds both the rule (ratio 4) and its own limit
 * rcb_compare_chi2_limit(2 x points).
 */
typedef struct rcb_compare_outlier {
  const char *response;  /**< the sensor, e.g. "DB.y" */
  const char *reference; /**< NULL: the sensor over all references; else the one channel's */
  double error_pct;      /**< its error %, % */
  double others_lo;      /**< lowest error % of the others (sensors or channels), % */
  double others_hi;      /**< highest error % of the others, % */
  int by_chi2;           /**< 1: judged on chi2/dof (sds known), 0: on error % */
  double chi2_dof;       /**< its chi2/dof (NaN without sds) */
  double chi2_lo;        /**< lowest chi2/dof of the others (NaN without sds) */
  double chi2_hi;        /**< highest chi2/dof of the others (NaN without sds) */
  double threshold;      /**< the threshold it exceeded (error % or chi2/dof) */
} rcb_compare_outlier;

RCB_API size_t rcb_compare_outlier_count(const rcb_compare *c);
RCB_API rcb_status rcb_compare_get_outlier(const rcb_compare *c, size_t i,
                                           rcb_compare_outlier *out);

/** @brief How a row of the peak table is paired. */
typedef enum rcb_peak_match {
  RCB_PEAK_MATCHED = 0,       /**< measured peak with a model mode */
  RCB_PEAK_MEASURED_ONLY = 1, /**< measured peak, no model mode within the tolerance */
  RCB_PEAK_MODEL_ONLY = 2     /**< model mode in the measured range, no measured peak */
} rcb_peak_match;

/**
 * @brief One row of the peak table. Measured peaks: local maxima of the sum
 * over channels of |e|/rms(e) (each channel scaled by its own RMS so no
 * channel dominates by its units), frequency and height by parabolic
 * interpolation through the three points at the top; damping ratio from a
 * local modal fit on the complex FRF of the peak's dominant channel (a
 * single-DOF rational fraction with a residual, over the points within 3.5
 * half-power half-widths of the top, 5 to 250 each side), and from the
 * half-power width zeta = (w2 - w1)/(2 w_peak) (one side doubled when the
 * other does not fall to half power). Model modes: for FRFs at a fixed speed,
 * the damped modes (rcb_modes_compute at the test speed, damping ratio
 * < 0.99) with wd in the measured range; for unbalance responses and
 * synchronous FRFs, the 1X critical speeds (Campbell crossings) in the range,
 * with the damping ratio of the crossing mode there. Rows are sorted by
 * frequency.
 */
typedef struct rcb_compare_peak {
  rcb_peak_match match;
  double meas_freq;    /**< measured peak abscissa, rad/s (NaN for MODEL_ONLY) */
  double meas_zeta;    /**< damping ratio of the local modal fit (meas_zeta_hp when the
                            fit fails; NaN when both do) */
  size_t channel;      /**< channel with the largest |e|/rms(e) at the peak */
  double meas_amp;     /**< |e| of that channel at the peak (channel units) */
  double model_amp;    /**< |m| of that channel at meas_freq (channel units) */
  double amp_ratio;    /**< meas_amp / model_amp */
  double model_freq;   /**< mode wd or critical speed, rad/s (NaN for MEASURED_ONLY) */
  double model_zeta;   /**< the mode's damping ratio */
  int model_visible;   /**< the model's own response shows a peak near model_freq */
  double model_peak;   /**< that peak of the model's response (same detection as the
                            measured one), rad/s; NaN when not visible */
  double freq_err_pct; /**< 100 (model_freq - meas_freq) / meas_freq, % */
  double peak_err_pct; /**< 100 (model_peak - meas_freq) / meas_freq, %: like for like,
                            free of the O(zeta^2) offset between a mode's wd and the
                            top of its resonance */
  double zeta_err_pct; /**< 100 (model_zeta - meas_zeta) / meas_zeta, % */
  double meas_zeta_hp; /**< half-power damping ratio (NaN: no half-power point) */
  double meas_wd;      /**< damped natural frequency wn sqrt(1 - zeta^2) of the local modal
                            fit, rad/s (NaN: no fit) */
} rcb_compare_peak;

RCB_API size_t rcb_compare_peak_count(const rcb_compare *c);
RCB_API rcb_status rcb_compare_get_peak(const rcb_compare *c, size_t i, rcb_compare_peak *out);

#ifdef __cplusplus
}
#endif

#endif /* RCB_COMPARE_H */
