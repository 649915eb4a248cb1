/**
 * @file cmd_monitor.h
 * @brief rcbtool monitor internals: the series of files (cmd_monitor.c), the
 * run (cmd_monitor_run.c) and the log and plot (cmd_monitor_log.c).
 */
#ifndef RCBTOOL_CMD_MONITOR_H
#define RCBTOOL_CMD_MONITOR_H

#include <stdint.h>

#include "cli.h"

/** The measurement files in time order (owned copies of the paths). */
typedef struct mon_series {
  char **files;
  size_t n, cap;
} mon_series;

/** One update as the log keeps it. */
typedef struct mon_record {
  size_t file;   /**< index into the series */
  uint64_t hash; /**< FNV-1a 64 of the file's bytes (with --state) */
  rcb_monitor_result r;
} mon_record;

/** A --state file read back (cmd_monitor_state.c), or one to write. */
typedef struct mon_saved {
  char **opts;     /**< the settings' options as first given (argv strings) */
  size_t nopts;
  char **comm;     /**< the commissioning files' names */
  size_t ncomm;
  rcb_meas *setup; /**< the set-up the monitor was created from (owned when read) */
  unsigned char *blob; /**< rcb_monitor_save's bytes */
  size_t nblob;
  mon_record *rec; /**< the updates so far (file: index into recfile) */
  char **recfile;
  size_t nrec;
} mon_saved;

/** The command line of one run. */
typedef struct mon_job {
  cli_params params; /**< --params: the tracked parameters */
  int have_params;
  size_t commission;  /**< files averaged into the reference (>= 1) */
  size_t relinearise; /**< chord iterations per update */
  int reweight;       /**< --reweight: each update's noise from its own values */
  int sensors;        /**< the probes' gains among the candidates (0: --no-sensors) */
  double alpha, cusum_h, cusum_k; /**< 0: the library's defaults */
  double beta_a, beta_s;          /**< --noise, % */
  double phase_deg;               /**< --noise's third number, degrees */
  double noise_scale;             /**< --noise-scale S (-); 0: auto (the
                                       commissioning files' scatter) */
  double scatter[2];              /**< --noise-scale scatter:CHI2:DOF (as a
                                       state keeps the measured scale; dof 0:
                                       not given) */
  double baseline_sd[RCB_MONITOR_MAX_TRACKED]; /**< --baseline-sd, parameter units */
  int have_baseline_sd;
  const char *sd_path;            /**< --sd FILE or DIR, NULL */
  const char *log, *plot;         /**< --log, --plot, NULL */
  mon_series series;
  const char *state;   /**< --state FILE, NULL */
  mon_saved *saved;    /**< what it held (NULL: a new state) */
  char **setopts;      /**< the settings' options of this command line (to store) */
  size_t nsetopts;
  size_t resume;       /**< first file of the series to update (0: after commissioning) */
  char *image;         /**< --state: FILE.image, the commissioning image (owned) */
} mon_job;

/** The measurement that would separate tracked parameter @c tracked from
 * candidate @c cand (rcb_monitor_separating, asked once per pair: the plan
 * sweeps the model). */
typedef struct mon_sep {
  size_t tracked, cand;
  int ok; /**< 0: the plan could not be made (a candidate not the model's) */
  rcb_monitor_separator sep;
} mon_sep;

/** A finished (or interrupted) run: what the outputs are written from. */
typedef struct mon_state {
  const cli_args *a;
  const mon_job *j;
  const rcb_monitor *mon;
  mon_record *rec;
  size_t nrec, cap;
  size_t memory;   /**< bytes the monitor holds */
  size_t rank, rank_tracked, candidates;
  double rpm;      /**< test speed of the series, rpm (NaN: unbalance data) */
  const char *kind; /**< "frf" or "unbalance" */
  size_t channels, points;
  mon_sep *seps;   /**< the pairs asked so far */
  size_t nseps;
  double noise_scale; /**< the scale the monitor applies to the declared noise (-) */
  rcb_monitor_noise scatter; /**< the commissioning files' scatter (dof 0: not measured) */
  int scale_from;  /**< MON_SCALE_*: where noise_scale came from */
} mon_state;

/** Where the noise's scale came from (mon_state.scale_from). */
enum {
  MON_SCALE_ONE_FILE, /**< 1: one commissioning file, no scatter to measure */
  MON_SCALE_MEASURED, /**< the commissioning files' scatter */
  MON_SCALE_TOO_LOW,  /**< 1: the scatter under MON_SCALE_MIN (repeated files) */
  MON_SCALE_GIVEN,    /**< --noise-scale S, or kept in the state */
  MON_SCALE_SD_DIR    /**< 1: --sd DIR gives each file its own noise */
};
/** A measured scale under this is not used (-): repeated or noise-free
 * files, whose scatter says nothing of the updates' noise. */
#define MON_SCALE_MIN 0.1

/** The header's line on the noise's scale (where it came from, the scatter). */
void mon_print_scale(FILE *fp, const mon_state *s);
/** Add a file, or every measurement file of a directory sorted by name
 * (none: exit 3 naming it); exit code 0, 3 or 4. */
int mon_series_add(const char *cmd, mon_series *s, const char *path);
void mon_series_free(mon_series *s);
/** Case-insensitive "does @p path end with @p ext" (".json"). */
int mon_has_ext(const char *path, const char *ext);
/** --log FILE is CSV (by its extension)? */
int mon_log_is_csv(const char *path);
/** matplotlib's format for --plot FILE ("png", "pdf", "svg"), NULL otherwise. */
const char *mon_plot_format(const char *path);

/** Read a --state file (all of it checked: magic, version, CRC, layout, and
 * every record against what rcbtool writes); 0 or exit 3 naming the file and
 * what is wrong. */
int mon_saved_read(const char *cmd, const char *path, mon_saved *sv);
/** The same on the @p n bytes of a state file at @p p (@p path names it in
 * messages): mon_saved_read's parser, which the fuzz harness calls. */
int mon_saved_parse(const char *cmd, const char *path, const unsigned char *p, size_t n,
                    mon_saved *sv);
/** After rcb_monitor_load: the records against the monitor (one per update
 * of its state, its tracked count, its candidates' indices, effects and
 * parameter counts); 0 or exit 3 naming the file and the update. */
int mon_saved_check(const char *cmd, const char *path, const mon_saved *sv,
                    const rcb_monitor *mon);
void mon_saved_free(mon_saved *sv);
/** Write @p sv to a temporary for @p path (written and fsync'ed; the caller
 * renames it with cli_tmpfile_close); 0 or an exit code. */
int mon_saved_write(const char *cmd, const char *path, mon_saved *sv, cli_tmpfile *t);
/** --state FILE: the commissioning image's path, FILE.image (malloc'ed;
 * NULL when out of memory) (cmd_monitor_image.c). */
char *mon_image_path(const char *state);
/** Its bytes into *buf (malloc'ed), 1; 0 when there is none to read. */
int mon_image_read(const char *path, void **buf, size_t *n);
/** Write @p mon's commissioning image to a temporary for @p path (renamed by
 * the caller with the other outputs); 0 or an exit code. */
int mon_image_write(const char *cmd, const char *path, const rcb_monitor *mon, cli_tmpfile *t);
/** FNV-1a 64 of the bytes of @p path; *ok 0 when it cannot be read. */
uint64_t mon_file_hash(const char *path, int *ok);

/** Commission, update over the series, print; then the log and the plot. */
int mon_run(const cli_args *a, const mon_job *j);

/** The measurement that would separate tracked parameter @p k of update
 * @p r from its rival, when the attribution says "not separable" and the
 * plan names one (found); NULL otherwise. */
const rcb_monitor_separator *mon_separator(const mon_state *s, const rcb_monitor_result *r,
                                           size_t k);
/** The alarm flags of an update: "-", "TEST", "CUSUM-", "TEST,CUSUM+", ... */
void mon_flags(const rcb_monitor_result *r, char *buf, size_t size);
/** The log as JSON (also --json on standard output). */
void mon_print_json(FILE *fp, const mon_state *s);
/** --log and --plot, written to temporaries and renamed together; 0 or an exit code. */
int mon_write_outputs(const mon_state *s);

#endif /* RCBTOOL_CMD_MONITOR_H */
