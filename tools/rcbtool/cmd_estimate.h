/**
 * @file cmd_estimate.h
 * @brief rcbtool estimate internals: the Welch run over one stream
 * (cmd_estimate.c) and the impact test's hits as its averages
 * (cmd_estimate_hits.c: several files, a UFF file's records, --trigger).
 */
#ifndef RCBTOOL_CMD_ESTIMATE_H
#define RCBTOOL_CMD_ESTIMATE_H

#include "cli.h"

#define EST_MAX_IN 64
#define EST_MAX_OUT 256

typedef struct est_job {
  const cli_args *a;
  rcb_signals *sig; /* the first signals file */
  size_t p, q;
  size_t *idx;  /* p + q channel indices into sig */
  char *buf;    /* --input and --outputs text, split */
  char **names; /* p + q: channel names in the file */
  char **model; /* p + q: model channels "STATION.DIR" (NAME=STATION.DIR, else NAME) */
  rcb_spectral_opts o;
  rcb_spectral *e;
  void *work;
  rcb_estimator est;
  int kind;
  int window_given; /* --window given (hits: force-exp otherwise) */
  char hits_note[512]; /* hits: which were averaged, for --stats' first line */
  rcb_frf_kind meas_kind[EST_MAX_IN + EST_MAX_OUT];
} est_job;

/** Whether the run is an impact test's hits: several files, a UFF file with
 * several records per channel, or --trigger. */
int est_hits_mode(const est_job *j);
/** Refuse the options of the other mode (exit 2) and set the hits' defaults. */
int est_hits_options(est_job *j, int hits);
/** The hits: read the other files, cut, check, report, and average the kept
 * ones (one segment each) into j->e. 0 or an exit code. */
int est_hits_average(est_job *j);
/** Size and build the estimator for j->o (after j->o.nseg is known). */
int est_setup(est_job *j);
/** Open a side output (--stats, --spectra, --report) through the run's plan. */
int est_side_open(const est_job *j, const char *path, cli_out *out);

#endif /* RCBTOOL_CMD_ESTIMATE_H */
