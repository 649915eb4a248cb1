/**
 * @file rcb_measure.h
 * @brief Measured (or simulated) responses: FRFs at a fixed rotor speed, or
 * unbalance responses over a speed range, on one common abscissa; read and
 * written as UFF dataset 58 (ASCII and binary 58b) and CSV.
 *
 * Values are kept in SI as the kind they were given in (receptance m/N,
 * mobility m/(N s), inertance m/(N s^2); unbalance responses in m or rad);
 * rcb_meas_convert changes the kind. Channels are named by model stations:
 * response "DA.x" and, for FRFs, reference (force) "C.B.y".
 */
#ifndef RCB_MEASURE_H
#define RCB_MEASURE_H

#include <stdint.h>

#include "rcb/rcb_analysis.h"
#include "rcb/rcb_core.h"

#ifdef __cplusplus
extern "C" {
#endif

/** @brief What the abscissa and the values are. */
typedef enum rcb_meas_type {
  RCB_MEAS_FRF = 0,      /**< abscissa: excitation frequency, rad/s */
  RCB_MEAS_UNBALANCE = 1 /**< abscissa: rotor speed, rad/s; response to the unbalances */
} rcb_meas_type;

typedef struct rcb_meas rcb_meas;

RCB_API rcb_status rcb_meas_create(rcb_meas **out, const rcb_allocator *alloc);
RCB_API void rcb_meas_destroy(rcb_meas *ms);
/** @brief Last error, with file name and line (or record number) where it applies. */
RCB_API const char *rcb_meas_errmsg(const rcb_meas *ms);

/**
 * @brief Set the common abscissa (before adding channels; clears channels).
 * @param x n values, rad/s, finite, strictly increasing, >= 0
 * @param speed for RCB_MEAS_FRF the rotor speed (rad/s) during the test, or a
 * negative value for a synchronous FRF (rotor speed = excitation frequency);
 * ignored for RCB_MEAS_UNBALANCE
 */
RCB_API rcb_status rcb_meas_set_grid(rcb_meas *ms, rcb_meas_type type, size_t n,
                                     const double *x, double speed);
/**
 * @brief Add a channel of n = rcb_meas_point_count values (copied).
 * @param response station channel "STATION.DIR" @param reference force channel
 * for FRFs, NULL for unbalance responses @param kind receptance, mobility or
 * inertance (RCB_RECEPTANCE for unbalance responses: displacement)
 */
RCB_API rcb_status rcb_meas_add_channel(rcb_meas *ms, const char *response,
                                        const char *reference, rcb_frf_kind kind,
                                        const rcb_complex *data);

/**
 * @brief Add a channel of magnitudes only, the phase unknown (issue #35 item
 * 4: many exports and published data sets give |H| alone): n =
 * rcb_meas_point_count values |H| >= 0 (SI, of @p kind), held as |H| + 0i with
 * the channel marked (rcb_meas_channel_info.magnitude_only). What uses only
 * magnitudes takes it: fits on RCB_SCALE_LINEAR, LOG10 and DB, the
 * comparison's error, log error, residual map and peaks, rcb_meas_convert
 * (times w^k). What needs the phase refuses it with a message (the fit's
 * RCB_SCALE_COMPLEX, sensor phases, the monitor, UFF output) or leaves it out
 * and says so (the comparison's FRAC, phase error, CSAC/CSF are NaN; the
 * diagnosis skips its placement).
 * @return RCB_ERR_ARG for a negative or non-finite magnitude (the message
 * names the point)
 */
RCB_API rcb_status rcb_meas_add_channel_mag(rcb_meas *ms, const char *response,
                                            const char *reference, rcb_frf_kind kind,
                                            const double *mag);
/** @brief Number of channels given as magnitudes only (0: every channel has its phase). */
RCB_API size_t rcb_meas_magnitude_only_count(const rcb_meas *ms);

RCB_API rcb_meas_type rcb_meas_get_type(const rcb_meas *ms);
RCB_API size_t rcb_meas_point_count(const rcb_meas *ms);
RCB_API size_t rcb_meas_channel_count(const rcb_meas *ms);
/** @brief The abscissa, rad/s (rcb_meas_point_count values). */
RCB_API const double *rcb_meas_grid(const rcb_meas *ms);
/** @brief Rotor speed of an FRF test, rad/s (negative: synchronous). */
RCB_API double rcb_meas_speed(const rcb_meas *ms);
/**
 * @brief 1 when the rotor speed was stated (UFF z axis of type 19, CSV "# rpm",
 * rcb_meas_set_grid or rcb_meas_set_speed), 0 when a file left it out and it
 * reads as 0 (a UFF whose speed is only in the text header, z axis type 0).
 */
RCB_API int rcb_meas_speed_given(const rcb_meas *ms);
/**
 * @brief State the rotor speed of an FRF test after reading (rad/s, negative:
 * synchronous), e.g. when the file leaves it out; the read's warning that the
 * speed was not stated is dropped. @return RCB_ERR_STATE for
 * an unbalance response or an empty object, RCB_ERR_ARG if not finite
 */
RCB_API rcb_status rcb_meas_set_speed(rcb_meas *ms, double speed);
/** @brief How a CSV file presents the phase (issue #25). The values held are
 * always the model's (Q e^{i Omega t}: the phase is a lead); LAG presents
 * their conjugate (the phase as vibration monitors show it: the response's
 * peak that many degrees after the reference mark). */
typedef enum rcb_phase_convention {
  RCB_PHASE_UNSTATED = 0, /**< no "# phase" line (read as a lead) */
  RCB_PHASE_LEAD = 1,     /**< "# phase = lead ...": values as held */
  RCB_PHASE_LAG = 2       /**< "# phase = lag ...": conjugates written and read */
} rcb_phase_convention;
/**
 * @brief State the phase convention of the CSV written (rcb_meas_write_csv
 * writes "# phase = lead|lag (@p reference)" and, for LAG, conjugate values;
 * rcb_meas_read_csv reads the line back to the model's values). @p reference
 * (NULL: none) says what the phase is measured from, e.g. "keyphasor rising
 * edge" (at most 80 characters). UFF files hold the model's values as they are.
 */
RCB_API rcb_status rcb_meas_set_phase(rcb_meas *ms, rcb_phase_convention conv,
                                      const char *reference);
/** @brief The convention a CSV read stated (or rcb_meas_set_phase set). */
RCB_API rcb_phase_convention rcb_meas_phase(const rcb_meas *ms);
/**
 * @brief Warnings of the last read: input that is valid but likely misread
 * (a UFF node with no entry in the node map, a UFF FRF that does not state
 * the rotor speed). A warning never fails the read; show the list.
 */
RCB_API size_t rcb_meas_warning_count(const rcb_meas *ms);
/** @brief Warning @p i (0-based) of the last read, NULL past the end. */
RCB_API const char *rcb_meas_warning(const rcb_meas *ms, size_t i);

typedef struct rcb_meas_channel_info {
  const char *response;     /**< "DA.x" */
  const char *reference;    /**< "C.B.y", NULL for unbalance responses */
  rcb_frf_kind kind;        /**< what the values are */
  const rcb_complex *data;  /**< rcb_meas_point_count values, owned by ms (magnitude
                                 only: |H| + 0i) */
  int magnitude_only;       /**< 1: magnitudes without phase (rcb_meas_add_channel_mag) */
} rcb_meas_channel_info;
RCB_API rcb_status rcb_meas_channel(const rcb_meas *ms, size_t i, rcb_meas_channel_info *out);

/** @brief Convert every FRF channel to @p kind (multiplying by (i w)^k). */
RCB_API rcb_status rcb_meas_convert(rcb_meas *ms, rcb_frf_kind kind);

/**
 * @brief The noise model of the paper's eq. 19, applied to every channel:
 * f_e = f_s (1 + beta_a/100 r1) + (sqrt(sum_j |f_sj|^2)/n) (beta_s/100) r2 e^{i phi},
 * r1, r2 uniform in [-1, 1], phi uniform in [0, 2 pi), from a PRNG seeded by
 * @p seed (same seed, same noise on every platform).
 * @param beta_a random (proportional) factor, % @param beta_s systematic factor, %
 */
RCB_API rcb_status rcb_meas_add_noise(rcb_meas *ms, double beta_a, double beta_s,
                                      uint64_t seed);
/**
 * @brief rcb_meas_add_noise with a phase term: each noisy value then turned
 * by e^{i phase_rad r3}, r3 uniform in [-1, 1] (a phase noise uniform in
 * +-phase_rad, drawn after eq. 19's three numbers: phase_rad = 0 gives
 * rcb_meas_add_noise's values). @param phase_rad rad, 0 to pi
 */
RCB_API rcb_status rcb_meas_add_noise_phase(rcb_meas *ms, double beta_a, double beta_s,
                                            double phase_rad, uint64_t seed);

/**
 * @brief UFF node number <-> model station, for dataset 58 files (and CSV
 * channels written as node numbers). An entry with @p dir NULL maps a whole
 * node: its x, y, rx, ry channels read as the station's ("10=DA": 10.x is
 * DA.x). An entry with @p dir maps one channel of the node, in any direction,
 * to a model channel ("1.z=DA.x", "3.s=DB.y" for a scalar channel): an
 * accelerometer's own axis (z, direction 3) or a scalar record (direction 0),
 * as acquisition systems export them, read as the model channel it stands
 * for. A direction entry wins over its node's entry; a negative file
 * direction still flips the sign. Zero-initialised @p dir and @p model_dir
 * (as in {10, "DA"}) make a node entry.
 */
typedef struct rcb_uff_node {
  long node;             /**< UFF node number */
  const char *station;   /**< model station name, e.g. "DA" */
  const char *dir;       /**< NULL: the whole node; else the file direction this entry
                              maps: "x", "y", "z", "rx", "ry", "rz" (UFF 1 to 6) or "s"
                              (scalar, UFF 0) */
  const char *model_dir; /**< with @p dir: the model direction it reads as, "x", "y",
                              "rx" or "ry"; NULL with a node entry */
} rcb_uff_node;

/**
 * @brief Read UFF dataset 58 records (ASCII 58 or binary 58b, any mix; other
 * datasets are skipped). Node numbers map through @p map; a node without an
 * entry maps to model node "#N", with a warning (rcb_meas_warning) naming it.
 * The rotor speed of an FRF is the z value of a z axis of type 19 (rpm); any
 * other z axis reads as 0 rpm with a warning (rcb_meas_set_speed states it). Directions: UFF 1, 2, 4, 5 (+/-) are x, y,
 * rx, ry (a negative direction flips the sign). All records must share one
 * abscissa (Hz in the file). Ordinate units/type decide the kind (function
 * type 4 FRF: displacement, velocity or acceleration over force; type 1 with
 * reference node 0: unbalance response).
 */
RCB_API rcb_status rcb_meas_read_uff(rcb_meas *ms, const char *path, size_t nmap,
                                     const rcb_uff_node *map);
/** @brief Write dataset 58 records (binary 58b if @p binary), atomically. */
RCB_API rcb_status rcb_meas_write_uff(const rcb_meas *ms, const char *path, int binary,
                                      size_t nmap, const rcb_uff_node *map);
/**
 * @brief Read CSV as written by rcbtool frf/unbalance: first column freq_hz
 * (FRF) or rpm (unbalance), then per channel "RESP/REF re","RESP/REF im" or
 * "RESP/REF mag","RESP/REF phase_deg" (unbalance: "RESP re"/"RESP im" or
 * "RESP amp"/"RESP phase_deg"); optional "# key = value" lines before the
 * header: kind = receptance|mobility|inertance, rpm = rotor speed of an FRF test.
 * Other spellings are read too (case, spaces, '_' and a unit in brackets do not
 * matter: "Frequency (Hz)", "speed_rpm", "DA.x/C.y Real", "... Phase (deg)");
 * a header that leaves the unit open is refused with the name to use. The
 * part may follow '_' instead of a space, as lab scripts write it
 * ("DA.x/C.y_re", "DA.x/C.y_im", "_mag"/"_amp", "_phase_deg"); the two columns
 * of a channel are paired by name, adjacent or not, and a channel given both
 * as re/im and as mag/phase is refused as ambiguous. A "mag" or "dB" (20
 * log10 |H|) column without a phase column is read as a channel of magnitudes
 * only (rcb_meas_add_channel_mag). A station written as a
 * number ("3.x", a node number) is refused with the name to use; see
 * rcb_meas_read_csv_map.
 */
RCB_API rcb_status rcb_meas_read_csv(rcb_meas *ms, const char *path);
/**
 * @brief rcb_meas_read_csv with stations written as node numbers ("2.x/11.x_re")
 * read through @p map (@p nmap entries, as rcb_meas_read_uff takes it): node 2
 * mapped to "DA" reads "DA.x". A numeric station without an entry is refused
 * with file:line and the entry to give (unlike a UFF read, which takes it as
 * model node "#N": a CSV names stations, so a number is a lab's node).
 */
RCB_API rcb_status rcb_meas_read_csv_map(rcb_meas *ms, const char *path, size_t nmap,
                                         const rcb_uff_node *map);
/** @brief Write CSV (re/im columns) that rcb_meas_read_csv reads back, atomically. */
RCB_API rcb_status rcb_meas_write_csv(const rcb_meas *ms, const char *path);

#ifdef __cplusplus
}
#endif

#endif /* RCB_MEASURE_H */
