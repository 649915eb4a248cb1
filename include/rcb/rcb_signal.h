/**
 * @file rcb_signal.h
 * @brief The measurement front end: sampled time signals (read from CSV, WAV
 * or UFF dataset 58 time records, with their units) and the Welch estimator
 * that turns them into FRFs with coherence and per-point standard deviations.
 *
 * Memory: the estimator lives in one caller buffer sized by
 * rcb_spectral_workspace_size() (two-call sizing, as the FRF sweep); feeding
 * segments and reading results allocate nothing. The FFT backend is chosen at
 * build time (rcb_config.h): FFTW3 in double precision (RCB_WITH_FFTW) plans
 * its transform at rcb_spectral_init() and allocates the plan itself, with
 * FFTW's malloc, outside the hooks (as KLU does, see rcb_analysis.h); its
 * planner is not thread-safe, so create estimators from one thread at a time
 * (feeding and reading from several threads, one object each, is safe).
 * Without an FFT backend the estimator calls return RCB_ERR_UNSUPPORTED.
 *
 * Units: signals are held in SI (m, m/s, m/s^2, N; V for a keyphasor or an
 * uncalibrated channel); sample rates in samples/s; frequencies in rad/s.
 */
#ifndef RCB_SIGNAL_H
#define RCB_SIGNAL_H

#include "rcb/rcb_core.h"
#include "rcb/rcb_measure.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ------------------------------------------------------------ units -- */

/** @brief The physical quantity of a channel (values held in its SI unit). */
typedef enum rcb_quantity {
  RCB_QTY_UNKNOWN = 0,      /**< no unit given */
  RCB_QTY_DISPLACEMENT = 1, /**< m */
  RCB_QTY_VELOCITY = 2,     /**< m/s */
  RCB_QTY_ACCELERATION = 3, /**< m/s^2 */
  RCB_QTY_FORCE = 4,        /**< N */
  RCB_QTY_VOLTAGE = 5,      /**< V (keyphasor, uncalibrated sensor) */
  RCB_QTY_PRESSURE = 6      /**< Pa (a microphone or pressure transducer: read, not a
                                 response the rotor model predicts) */
} rcb_quantity;

/**
 * @brief Parse a unit label ("m", "mm", "um", "mil", "in", "m/s", "mm/s",
 * "in/s", "m/s^2", "m/s2", "m/s²" (UTF-8 or Latin-1 ²), "g", "N", "kN", "lbf",
 * "V", "mV", "Pa", "kPa"; the full list: rcb_unit_list; case-sensitive where
 * it matters: "mm" vs "Mm" is not guessed).
 * @param to_si factor: SI value = file value * to_si
 * @return 0, or -1 if the label is not a unit librcb knows.
 */
RCB_API int rcb_unit_parse(const char *label, rcb_quantity *q, double *to_si);
/** @brief "displacement", "velocity", ... (never NULL). */
RCB_API const char *rcb_quantity_name(rcb_quantity q);
/**
 * @brief The unit labels rcb_unit_parse knows for quantity @p q (all of them
 * for RCB_QTY_UNKNOWN), comma separated, into @p buf (NUL-terminated, cut to
 * @p size; for messages and --help). Other spellings of a label (m/s2, µm)
 * are parsed but not listed.
 * @return the length of the whole list (as snprintf)
 */
RCB_API size_t rcb_unit_list(rcb_quantity q, char *buf, size_t size);

/* ---------------------------------------------------------- signals -- */

/** @brief A set of channels sampled together (one sample rate, one length). */
typedef struct rcb_signals rcb_signals;

RCB_API rcb_status rcb_signals_create(rcb_signals **out, const rcb_allocator *alloc);
RCB_API void rcb_signals_destroy(rcb_signals *s);
/** @brief Last error, with file name and line (or record) where it applies. */
RCB_API const char *rcb_signals_errmsg(const rcb_signals *s);

/** @brief Start a new set: sample rate (samples/s, > 0) and length (samples). */
RCB_API rcb_status rcb_signals_reset(rcb_signals *s, double rate, size_t nsamples);
/**
 * @brief Add a channel (values copied, in SI of @p q).
 * @param name channel name ("DA.x" for a response, "C.B.y" for a force, "KP"
 * for a keyphasor) @param q what the values are
 */
RCB_API rcb_status rcb_signals_add(rcb_signals *s, const char *name, rcb_quantity q,
                                   const double *values);
RCB_API size_t rcb_signals_channel_count(const rcb_signals *s);
RCB_API size_t rcb_signals_length(const rcb_signals *s);
/** @brief Sample rate, samples/s. */
RCB_API double rcb_signals_rate(const rcb_signals *s);
/** @brief Channel i: its name, quantity and rcb_signals_length() values (SI). */
RCB_API rcb_status rcb_signals_channel(const rcb_signals *s, size_t i, const char **name,
                                       rcb_quantity *q, const double **values);
/** @brief Index of the channel named @p name, or RCB_ERR_NOT_FOUND. */
RCB_API rcb_status rcb_signals_find(const rcb_signals *s, const char *name, size_t *index);

/**
 * @brief Whether the readers accept a truncated file (default 0: refused).
 * A WAV data chunk that claims more bytes than the file holds, or that ends
 * inside a frame, is refused with the byte counts; with @p allow nonzero the
 * whole frames present are read and a warning (rcb_signals_warning) says so.
 */
RCB_API rcb_status rcb_signals_set_allow_truncated(rcb_signals *s, int allow);
/**
 * @brief Give channel @p name the unit @p unit (a label rcb_unit_parse
 * knows), for files whose label is missing or not known (UFF records: the
 * name as the reader forms it, "STATION.DIR" or "#NODE.DIR"). Kept for every
 * later read; RCB_ERR_ARG for an unknown unit.
 */
RCB_API rcb_status rcb_signals_set_unit(rcb_signals *s, const char *name, const char *unit);
/** @brief Warnings of the last read: what was read but may not be what the
 * file means, and what was skipped (a UFF record the model cannot use). */
RCB_API size_t rcb_signals_warning_count(const rcb_signals *s);
/** @brief Warning @p i of the last read ("" out of range). */
RCB_API const char *rcb_signals_warning(const rcb_signals *s, size_t i);

/**
 * @brief Read CSV: optional "# units = U1,U2,..." line (one unit per channel
 * column, e.g. "N,g,mm"), then a header "time_s,NAME1,NAME2,..." (a name may
 * carry its unit in brackets: "DA.x [mm]"), then rows of numbers. The time
 * column must be evenly spaced (each time within 0.1 % of a step of
 * t0 + i dt), with a finite spacing and rate; the rate is taken from it.
 * Limits, each refused with file:line and the limit named, never cut: at
 * most 256 channel columns, names of at most 63 characters. Lines, units
 * lines and units have no length limit.
 */
RCB_API rcb_status rcb_signals_read_csv(rcb_signals *s, const char *path);
/**
 * @brief Read a WAV file (RIFF, PCM 16/24/32-bit integer or 32/64-bit float,
 * any number of channels). Integer samples are scaled to [-1, 1). WAV carries
 * no names nor units: @p names and @p units give them per channel ("DA.x",
 * "mm"; NULL: "ch1", ... and V) and @p scale the full-scale value in that
 * unit (1 for float files; NULL: 1).
 */
RCB_API rcb_status rcb_signals_read_wav(rcb_signals *s, const char *path, size_t nnames,
                                        const char *const *names, const char *const *units,
                                        const double *scale);

/**
 * @brief Read UFF dataset 58 time records (function type 1, abscissa type 17
 * time, real data (types 2, 4), evenly sampled: spacing 1, or the times
 * listed (as pyuff writes) within 0.1 sample of an even grid; ASCII or
 * binary 58b), one
 * channel per record, all with one sample interval and length. Channel names
 * "STATION.DIR" through @p map (as rcb_meas_read_uff; a direction entry
 * "1.z=DA.x" names the model channel of any direction), or the station alone
 * for direction 0 (a keyphasor, a scalar record); every direction is read, a
 * channel no entry names keeping its file name ("#1.z", "DA.z", "#5"). A
 * record repeating an earlier record's channel is skipped with a warning; an
 * ASCII record holding fewer samples than record 7 claims before its "-1" is
 * refused, or read with rcb_signals_set_allow_truncated (a warning). Quantity from the ordinate data type (8
 * displacement, 11 velocity, 12 acceleration, 9/13 force) or else from the
 * record-9 units label (V, ...); units from that label or a dataset 164
 * (a disagreement of the two is refused).
 */
RCB_API rcb_status rcb_signals_read_uff(rcb_signals *s, const char *path, size_t nmap,
                                        const rcb_uff_node *map);

/**
 * @brief Join the records of a channel that a UFF file holds several times
 * (default 0: refused as a channel given twice). With @p join nonzero,
 * rcb_signals_read_uff appends the k-th record of each channel after its
 * (k-1)-th: an impact test written as one record per channel per hit becomes
 * channels of rcb_signals_record_count() records of equal length, end to end.
 * Every channel must then have the same number of records (refused otherwise,
 * naming the file and the channels).
 */
RCB_API rcb_status rcb_signals_set_join_records(rcb_signals *s, int join);
/** @brief Records per channel joined by the last read (1 for CSV, WAV and a UFF
 * file with one record per channel; 0 before a read). Each is
 * rcb_signals_length() / count samples long. */
RCB_API size_t rcb_signals_record_count(const rcb_signals *s);

/* ----------------------------------------------------- impact tests -- */

/**
 * @brief The force pulse of one hit of an impact test.
 * The peak is the sample of largest magnitude (its sign is the pulse's); the
 * pulse extends on both sides to where the force, taken with that sign, first
 * falls to the "decayed" level min(0.05, double_frac / 2) x |peak|; the width
 * is the time between those two crossings (interpolated between samples).
 * Any other sample beyond the pulse (before or after it) whose signed force
 * exceeds double_frac x |peak| is a second pulse: a double hit (the hammer
 * bounced, or the structure struck back). Two pulses that overlap above the
 * decayed level are one pulse to this test (its width shows them).
 */
typedef struct rcb_hit_pulse {
  double peak;          /**< force at the peak, signed (unit of the samples, N) */
  double peak_time;     /**< s from the hit's first sample */
  double width;         /**< s, between the crossings of the decayed level */
  double start, end;    /**< s from the first sample: where the pulse begins and ends */
  double second;        /**< largest other pulse / |peak| (0 if none, 0 <= second) */
  double second_time;   /**< s from the first sample (0 if none) */
  int double_hit;       /**< 1 if second > double_frac */
} rcb_hit_pulse;

/**
 * @brief Find a hit's force pulse and whether it is a double hit.
 * @param force @p n samples at @p rate samples/s
 * @param double_frac fraction of the peak above which a second pulse is a
 * double hit, 0 < double_frac < 1 (0: 0.1)
 * @return RCB_ERR_ARG for bad arguments; a force that is 0 throughout gives
 * peak 0, width 0 and no double hit (the caller decides what a hit without a
 * pulse is).
 */
RCB_API rcb_status rcb_hit_pulse_find(const double *force, size_t n, double rate,
                                      double double_frac, rcb_hit_pulse *out);

/** @brief Overload of one channel in one hit (rcb_hit_overload_find). */
typedef struct rcb_hit_overload {
  int overload;   /**< 1 if clipped or at the declared range */
  int at_range;   /**< 1 if a sample reached the declared range */
  size_t run;     /**< longest run of equal samples at an extreme (see below) */
  double level;   /**< the clipped value (the run's, or the first sample at range) */
  size_t at;      /**< index of the run's (or that sample's) first sample */
} rcb_hit_overload;

/**
 * @brief Whether a channel was clipped (its recorder overloaded) in a hit.
 * Clipping shows as a run of @p min_run or more consecutive samples exactly
 * equal to the channel's largest or smallest value in the hit; an extreme
 * counts if it is not 0 and its magnitude is at least half the channel's
 * largest (a flat top, not a quiet stretch). With @p range > 0 (the recorder's
 * declared full scale, unit of the samples), any |sample| >= range (1 - 1e-9)
 * is an overload as well. A channel recorded at a few per cent of a
 * quantizing recorder's scale can show equal samples at a slow peak: raise
 * @p min_run or declare the range.
 * @param min_run 2 or more (0: 5)
 */
RCB_API rcb_status rcb_hit_overload_find(const double *x, size_t n, size_t min_run,
                                         double range, rcb_hit_overload *out);

/**
 * @brief Cut a long recording into hits at the crossings of a trigger level.
 * A crossing is the first sample at or beyond @p level after a sample short of
 * it (rising for level > 0, falling for level < 0); its hit starts @p pre
 * samples before it and is @p length samples long; the next crossing is looked
 * for from the hit's end on (the hold-off: a hit's own pulse, ringing or
 * bounce does not start another). Two-call: the first @p cap starts go to
 * @p starts (may be NULL with cap 0), *count is the number of whole hits;
 * crossings whose hit would begin before the first sample or end after the
 * last are counted in *partial (not in starts).
 */
RCB_API rcb_status rcb_hit_triggers(const double *force, size_t n, double level, size_t pre,
                                    size_t length, size_t *starts, size_t cap, size_t *count,
                                    size_t *partial);

/* ------------------------------------------------------- estimation -- */

/** @brief Segment window. */
typedef enum rcb_window {
  RCB_WINDOW_HANN = 0,     /**< periodic Hann (SciPy's 'hann') */
  RCB_WINDOW_FLATTOP = 1,  /**< periodic flat-top (SciPy's 'flattop') */
  RCB_WINDOW_RECT = 2,     /**< rectangular (boxcar) */
  RCB_WINDOW_FORCE_EXP = 3 /**< impact test: force window on the inputs (1 over
                                the first force_frac of the segment, 0 after),
                                times an exponential window exp(-t/tau) on every
                                channel, tau such that it ends at exp_end */
} rcb_window;

/** @brief How H is formed from the averaged spectra. */
typedef enum rcb_estimator {
  RCB_EST_H1 = 0, /**< Gxx^-1 Gxy: noise on the outputs (any number of inputs) */
  RCB_EST_H2 = 1, /**< Gyy / Gyx: noise on the input (one input) */
  RCB_EST_HV = 2  /**< total least squares, noise on both (one input) */
} rcb_estimator;

/** @brief Estimator settings (zero-initialise, then set what you need). */
typedef struct rcb_spectral_opts {
  size_t ninputs;    /**< force channels (>= 1 for FRFs; 0: spectra only) */
  size_t noutputs;   /**< response channels */
  size_t nseg;       /**< samples per segment (>= 8; the FFT length) */
  size_t noverlap;   /**< samples shared by consecutive segments (< nseg) */
  double rate;       /**< samples/s */
  rcb_window window;
  int no_detrend;    /**< 0: remove each segment's mean (SciPy's default), 1: keep it */
  double force_frac; /**< RCB_WINDOW_FORCE_EXP: force window length / segment (0: 0.1) */
  double exp_end;    /**< RCB_WINDOW_FORCE_EXP: exponential window's last value (0: 0.01) */
} rcb_spectral_opts;

typedef struct rcb_spectral rcb_spectral;

/** @brief Bytes rcb_spectral_init needs for these settings (and the object's
 * whole memory besides the FFT backend's plan). */
RCB_API rcb_status rcb_spectral_workspace_size(const rcb_spectral_opts *o, size_t *bytes);
/**
 * @brief Build an estimator inside @p work (bytes from
 * rcb_spectral_workspace_size, any alignment; the caller keeps it alive and
 * frees it after rcb_spectral_release). No allocation besides FFTW's plan.
 */
RCB_API rcb_status rcb_spectral_init(rcb_spectral **out, const rcb_spectral_opts *o,
                                     void *work, size_t bytes);
/** @brief Release the FFT plan (the workspace stays the caller's). */
RCB_API void rcb_spectral_release(rcb_spectral *e);
RCB_API const char *rcb_spectral_errmsg(const rcb_spectral *e);
/** @brief Forget the averages (same settings). */
RCB_API void rcb_spectral_clear(rcb_spectral *e);
/**
 * @brief Average one segment: @p chan[0..ninputs) are the inputs, then the
 * outputs, each nseg samples (SI). Allocation-free: the streaming entry.
 */
RCB_API rcb_status rcb_spectral_add_segment(rcb_spectral *e, const double *const *chan);
/**
 * @brief Welch over whole records of @p n samples (segments every
 * nseg - noverlap samples; trailing samples that fill no segment are unused,
 * as in SciPy).
 */
RCB_API rcb_status rcb_spectral_add_record(rcb_spectral *e, size_t n,
                                           const double *const *chan);
/** @brief Segments averaged so far. */
RCB_API size_t rcb_spectral_averages(const rcb_spectral *e);
/** @brief nseg / 2 + 1 one-sided frequency lines. */
RCB_API size_t rcb_spectral_bin_count(const rcb_spectral *e);
/** @brief The frequency lines, rad/s (bin_count values). */
RCB_API void rcb_spectral_frequencies(const rcb_spectral *e, double *w);
/**
 * @brief Averaged one-sided cross spectral density conj(X_a) X_b of channels
 * a and b (indices as in add_segment), unit^2 s (per Hz, as SciPy's csd with
 * scaling='density'); the pairs held are input-input, input-output and
 * output-output on the diagonal (RCB_ERR_ARG for two different outputs).
 */
RCB_API rcb_status rcb_spectral_cross(const rcb_spectral *e, size_t a, size_t b,
                                      rcb_complex *g);
/**
 * @brief FRF from input @p in to output @p out, with coherence and standard
 * deviation per frequency line (any pointer may be NULL).
 * @param h response per unit input (SI units of the channels)
 * @param coh ordinary coherence of the pair (one input) or the multiple
 * coherence of the output on all inputs
 * @param sd standard deviation of each of Re h and Im h (of |h|, and of
 * |h| times the phase in rad): sqrt((1 - coh) Gyy [Gxx^-1]_jj / (2 (nd - p)))
 * (Bendat & Piersol, eq. 9.90 generalised, with the residual power over
 * its nd - p degrees of freedom, so unbiased at a few averages: then
 * |h - H|^2 / (2 sd^2) is F(2, 2 (nd - p)), Goodman 1963; for one input
 * |h| sqrt((1 - coh) / (2 (nd - 1) coh))), the same expression for H2 and
 * Hv; nd = segments / (1 + 2 sum_j rho_j^2), the independent averages the
 * overlapped segments are worth (rho_j: the window's overlap correlation);
 * NaN where nd <= p. Neighbouring lines' errors are correlated (Hann, H1 of
 * random excitation: 0.45; two lines apart 0.03)
 * @return RCB_ERR_SINGULAR (with the line in the message) if Gxx is singular
 */
RCB_API rcb_status rcb_spectral_frf(rcb_spectral *e, rcb_estimator est, size_t out,
                                    size_t in, rcb_complex *h, double *coh, double *sd);

/* --------------------------------------------------- order tracking -- */

/**
 * @brief How a speed bin's order phasors are estimated from its revolutions.
 *
 * Both take the revolutions from the keyphasor pulses (upward crossings of
 * @c trigger, or downward with @c kp_falling, interpolated between samples),
 * the shaft angle in each as the quadratic in time through the pulses before,
 * at and after it (constant angular acceleration; Fyfe & Munck 1997, so the
 * first revolution is not used), theta from the keyphasor mark plus
 * @c kp_angle, and put each revolution into the speed bin of its mean speed.
 * The phasor Q_m of order m is such that y = Re(Q_m e^{i m theta}): arg Q_m
 * is a phase lead (the model's convention; a vibration monitor's phase lag
 * is -arg Q_m, see rcb_meas_set_phase).
 */
typedef enum rcb_order_method {
  /** Joint least squares (issue #25; the default): every sample of the
   * bin's revolutions, at its own angle (no resampling), fitted with
   * sum_{m=0..norders} Re(Q_m(u) e^{i m theta}), each Q_m a quadratic in the
   * sample's speed u across the bin (all orders together, order 0 the
   * offset). An order that changes within a revolution (a 1X near a
   * resonance) is modelled instead of leaking into the others, and the
   * reported phasor, at the bin's mean speed, has no curvature bias. The
   * bin is the window: its speed width and the run-up rate set how many
   * revolutions it spans (at least 3 advised). sd: from the fit's residual,
   * taken as white noise. A bin at one steady speed fits lower degrees. An
   * order present in the signal and not fitted leaks into the fitted ones
   * when a bin spans few revolutions (a 5X of 10 % of a 1X resonance's peak,
   * 4 revolutions per bin: 2X 4 % off with norders 4): fit every order
   * present (norders up to 8). Orders at or above 0.45 x the sample rate at
   * a bin's top speed (bin + 1.5 bin widths: whole revolutions) are left out
   * of its fit (they alias onto lower ones): their Q is 0 and sd NaN. */
  RCB_ORDER_FIT = 0,
  /** Per-revolution DFT (before issue #25): each revolution resampled
   * (linear interpolation) to @c per_rev angles, an exact DFT gives Q_m =
   * (2/N) sum_j y_j e^{-i m theta_j}, the bin reports the mean over its
   * revolutions and the sd from their residual about a line in speed. An
   * order whose amplitude changes within a revolution leaks into the others,
   * about 0.42 x (speed change per revolution / half-power band) of the peak
   * near a resonance (docs/signals.md has the measured table). */
  RCB_ORDER_REV_DFT = 1
} rcb_order_method;

/** @brief Order-tracking settings (zero-initialise: the joint fit). */
typedef struct rcb_order_opts {
  size_t norders;   /**< orders 1..norders (1 to 8) */
  size_t per_rev;   /**< RCB_ORDER_REV_DFT: angle samples per revolution (>= 4 norders; 0: 64) */
  double trigger;   /**< keyphasor threshold in its unit (NaN: halfway between its min and max) */
  double kp_angle;  /**< shaft angle at the keyphasor mark, rad */
  double bin_width; /**< speed bin, rad/s (> 0) */
  double speed_max; /**< highest speed binned, rad/s (faster revolutions are ignored) */
  size_t min_revs;  /**< revolutions a bin needs to be reported (>= 2; 0: 2) */
  int kp_falling;   /**< 0: revolutions marked by the keyphasor's upward crossings of
                         @c trigger (a projection passing the probe); 1: downward (a
                         notch, as most proximity-probe keyphasors) */
  rcb_order_method method; /**< RCB_ORDER_FIT (0, default) or RCB_ORDER_REV_DFT */
} rcb_order_opts;

typedef struct rcb_order rcb_order;

/** @brief Bytes for an order tracker of @p nch channels (two-call sizing). */
RCB_API rcb_status rcb_order_workspace_size(const rcb_order_opts *o, size_t nch,
                                            size_t *bytes);
/** @brief Build an order tracker in @p work (no allocation, ever). */
RCB_API rcb_status rcb_order_init(rcb_order **out, const rcb_order_opts *o, size_t nch,
                                  void *work, size_t bytes);
RCB_API const char *rcb_order_errmsg(const rcb_order *e);
/**
 * @brief Track a record: @p kp the keyphasor, @p chan the nch responses,
 * n samples each at @p rate samples/s. May be called for several records.
 * @return RCB_ERR_ARG with a message if fewer than three pulses are found
 */
RCB_API rcb_status rcb_order_add(rcb_order *e, double rate, size_t n, const double *kp,
                                 const double *const *chan);
/** @brief Revolutions tracked so far. */
RCB_API size_t rcb_order_revolutions(const rcb_order *e);
/** @brief Bins (speed_max / bin_width, rounded up). */
RCB_API size_t rcb_order_bin_count(const rcb_order *e);
/**
 * @brief One bin's result for channel @p ch and order @p m (1-based).
 * @param speed RCB_ORDER_FIT: the mean speed of the bin's samples;
 * RCB_ORDER_REV_DFT: of its revolutions; rad/s
 * @param Q phasor at that speed (channel unit): RCB_ORDER_FIT the fitted
 * quadratic there; RCB_ORDER_REV_DFT the mean over the revolutions
 * @param sd standard deviation of Re Q and of Im Q (the root mean of their
 * two variances). RCB_ORDER_FIT: sigma^2 c' (X'X)^-1 c from the fit, sigma^2
 * the residual sum of squares over (samples - parameters). RCB_ORDER_REV_DFT:
 * sqrt(sum |Q_r - a - b (w_r - w_mean)|^2 / (2 n (n - 2))) from the line
 * a + b (w - w_mean) fitted through the bin's revolutions (n = 2:
 * sqrt(sum |Q_r - Q|^2 / (2 n (n - 1))), the scatter about the mean)
 * @param nrev revolutions in the bin (results valid when >= min_revs)
 */
RCB_API rcb_status rcb_order_result(const rcb_order *e, size_t bin, size_t ch, size_t m,
                                    double *speed, rcb_complex *Q, double *sd, size_t *nrev);

#ifdef __cplusplus
}
#endif

#endif /* RCB_SIGNAL_H */
