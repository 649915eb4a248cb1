/* rcbtool: CSV/JSON number and string writers, the output size limit and the
 * progress line on stderr (outputs are opened through the plan, cli_plan.c). */
#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "cli.h"

/* Bytes of one number as text: "-1.2345678901234567e-100" (24) and a separator. */
#define CLI_BYTES_PER_NUMBER 25.0

int cli_check_size(const cli_args *a, double rows, double numbers) {
  double limit = a->max_output_mb > 0 ? a->max_output_mb : CLI_MAX_OUTPUT_MB;
  double mb = rows * numbers * CLI_BYTES_PER_NUMBER / 1e6;
  if (mb <= limit) return 0;
  return cli_usage(a->cmd, "the output would be about %.3g MB (%.3g rows x %.3g numbers, ~%g "
                   "bytes each), above the limit of %g MB; use fewer points or channels, or "
                   "raise the limit with --max-output MB",
                   mb, rows, numbers, CLI_BYTES_PER_NUMBER, limit);
}

int cli_is_rotation(const char *channel) {
  const char *dot = strrchr(channel, '.');
  return dot && (strcmp(dot, ".rx") == 0 || strcmp(dot, ".ry") == 0);
}

const char *cli_channel_unit(const char *resp, const char *ref, int kind, char *buf,
                             size_t size) {
  static const char *const per[3] = {"", " s", " s^2"}; /* receptance, mobility, inertance */
  const char *num = cli_is_rotation(resp) ? "rad" : "m";
  char den[32];
  if (!ref) {
    snprintf(buf, size, "%s", num);
    return buf;
  }
  snprintf(den, sizeof den, "%s%s", cli_is_rotation(ref) ? "N m" : "N",
           per[kind >= 0 && kind < 3 ? kind : 0]);
  snprintf(buf, size, strchr(den, ' ') ? "%s/(%s)" : "%s/%s", num, den);
  return buf;
}

void cli_csv_num(FILE *fp, double x) { fprintf(fp, "%.17g", x); }

void cli_json_num(FILE *fp, double x) {
  if (isfinite(x))
    fprintf(fp, "%.17g", x);
  else
    fputs("null", fp);
}

void cli_json_nums(FILE *fp, const double *x, size_t n, size_t stride) {
  size_t i;
  fputc('[', fp);
  for (i = 0; i < n; i++) {
    if (i) fputs(", ", fp);
    cli_json_num(fp, x[i * stride]);
  }
  fputc(']', fp);
}

const char *cli_whirl_name(rcb_whirl w) {
  switch (w) {
    case RCB_WHIRL_FORWARD:
      return "forward";
    case RCB_WHIRL_BACKWARD:
      return "backward";
    default:
      return "mixed";
  }
}

/* Sweeps shorter than this stay silent on a terminal unless --progress. */
#define CLI_PROGRESS_MIN 50

void cli_progress_start(cli_progress *p, const cli_args *a, const char *label,
                        const char *unit, size_t total) {
  p->tty = isatty(fileno(stderr));
  p->on = a->progress || (p->tty && total >= CLI_PROGRESS_MIN);
  p->label = label;
  p->unit = unit;
  p->total = total;
  p->shown = 0;
}

void cli_progress_step(cli_progress *p, size_t done) {
  /* A terminal gets ~100 updates in place; a log file one line per 10 %. */
  size_t steps = p->tty ? 100 : 10;
  if (!p->on || done <= p->shown) return; /* a count that only rises */
  if (done != p->total && done * steps / p->total == p->shown * steps / p->total) return;
  fprintf(stderr, "%s%s: %zu/%zu %s", p->tty ? "\r" : "", p->label, done, p->total, p->unit);
  if (!p->tty) fputc('\n', stderr);
  fflush(stderr);
  p->shown = done;
}

void cli_progress_end(cli_progress *p) {
  if (p->on && p->tty && p->shown > 0) fputc('\n', stderr);
  p->on = 0;
}
