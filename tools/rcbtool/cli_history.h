/* rcbtool: reading a history file (cli_history_read.c), the steps that
 * 'fit --history' and 'diagnose --history' append as JSON lines. Kept apart
 * from cli.h and the plan so that the libFuzzer harness fuzz/fuzz_history.c
 * builds it on its own. */
#ifndef RCBTOOL_CLI_HISTORY_H
#define RCBTOOL_CLI_HISTORY_H

#include <stddef.h>

/** One step: the record of one line. */
typedef struct cli_hist_step {
  char *command;    /**< "fit", "diagnose" or "apply" */
  char *model;      /**< the model's path, decoded UTF-8 (\u0000 read as U+FFFD) */
  char *note;       /**< "" when absent */
  double error_pct; /**< the error, % (finite, >= 0), NaN for null */
  double floor_pct; /**< the noise floor, % (finite, >= 0), NaN for null or absent */
  long params;      /**< the parameters fitted so far (>= 0), -1 for null or absent */
  size_t line;      /**< the file's line (from 1) */
} cli_hist_step;

/** A history read whole. */
typedef struct cli_history {
  cli_hist_step *step;
  size_t n, cap;
  size_t bad_line; /**< the first line that is no record (from 1); 0 when none */
  char why[200];   /**< what is wrong with it */
} cli_history;

/** Read @p len bytes of @p text (need not end in NUL) as history lines: one JSON
 * object a line with "command" (fit, diagnose, apply), "model", "error_pct"
 * and optionally "floor_pct", "params", "note" (other keys with a plain value
 * are passed over), numbers finite and >= 0 or null; blank lines (also "\r\n")
 * are skipped. A number is read whole, however long. 0 with @p h holding the
 * steps; 1 when a line is no record (h->bad_line, h->why; no step kept); -1 out
 * of memory. Free @p h with cli_history_free in every case. */
int cli_history_parse(const char *text, size_t len, cli_history *h);
void cli_history_free(cli_history *h);

/** The width, in characters, of the bar of @p e in a chart whose longest bar
 * (@p emax) is @p width: 0 ... width for any @p e and @p emax. */
int cli_history_bar(double e, double emax, int width);

#endif /* RCBTOOL_CLI_HISTORY_H */
