/* rcbtool: messages, exit codes and small helpers shared by the subcommands. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>

#include "cli.h"

int (cli_fail)(int code, const char *fmt, ...) {
  va_list ap;
  fputs("rcbtool: ", stderr);
  va_start(ap, fmt);
  vfprintf(stderr, fmt, ap);
  va_end(ap);
  fputc('\n', stderr);
  return code;
}

int (cli_usage)(const char *cmd, const char *fmt, ...) {
  va_list ap;
  fputs("rcbtool: ", stderr);
  if (cmd) fprintf(stderr, "%s: ", cmd);
  va_start(ap, fmt);
  vfprintf(stderr, fmt, ap);
  va_end(ap);
  fputc('\n', stderr);
  if (cmd)
    fprintf(stderr, "Try 'rcbtool %s --help' for the options.\n", cmd);
  else
    fputs("Try 'rcbtool help' for the commands.\n", stderr);
  return CLI_EXIT_USAGE;
}

const char *cli_msg(const char *msg, rcb_status st) {
  return msg && *msg ? msg : rcb_status_str(st);
}

/* Errors from an analysis on a loaded model: anything the model itself gets
 * wrong is bad input (3), the rest is a numerical failure (4). */
int cli_status_exit(rcb_status st) {
  switch (st) {
    case RCB_OK:
      return CLI_EXIT_OK;
    case RCB_ERR_PARSE:
    case RCB_ERR_MODEL:
    case RCB_ERR_NOT_FOUND:
      return CLI_EXIT_INPUT;
    case RCB_ERR_IO:
      return CLI_EXIT_IO;
    default:
      return CLI_EXIT_NUMERIC;
  }
}

int cli_print_help(const char *text) {
  fputs(text, stdout);
  if (fflush(stdout) != 0 || ferror(stdout))
    return cli_fail(CLI_EXIT_IO, "cannot write the help text to standard output");
  return CLI_EXIT_OK;
}

void cli_linspace(double lo, double hi, size_t n, double *x) {
  size_t i;
  if (n == 1) {
    x[0] = lo;
    return;
  }
  for (i = 0; i < n; i++) x[i] = lo + (double)i * (hi - lo) / (double)(n - 1);
  x[n - 1] = hi; /* exact end point, no rounding drift */
}

void cli_warn_condition(const char *cmd, const rcb_frf_condition *c, int by_speed) {
  char where[96];
  if (c->ill == 0) return;
  if (by_speed)
    snprintf(where, sizeof where, "%.6g rpm", c->speed / CLI_RPM_TO_RAD_S);
  else
    snprintf(where, sizeof where, "%.6g Hz (rotor %.6g rpm)", c->omega / CLI_HZ_TO_RAD_S,
             c->speed / CLI_RPM_TO_RAD_S);
  fprintf(stderr,
          "rcbtool: warning: %s: ill-conditioned dynamic stiffness at %s: reciprocal "
          "condition number %.3g < %.3g (%zu of %zu solves): the response there may be off "
          "by up to %.1g (relative; 2.2e-16 / rcond): a free rotor near 0 Hz, or an "
          "undamped resonance\n",
          cmd, where, c->rcond_min, c->threshold, c->ill, c->checked,
          c->rcond_min > 0 ? fmin(1.0, 2.220446049250313e-16 / c->rcond_min) : 1.0);
}
