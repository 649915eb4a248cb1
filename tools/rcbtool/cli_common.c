/* rcbtool: messages, exit codes and small helpers shared by the subcommands. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

/* Format and print escaped (a message of any length). */
static void vput_escaped(const char *fmt, va_list ap) {
  char small[1024], *buf = small;
  va_list aq;
  int n;
  va_copy(aq, ap);
  n = vsnprintf(small, sizeof small, fmt, ap);
  if (n >= (int)sizeof small && (buf = malloc((size_t)n + 1)) != NULL)
    vsnprintf(buf, (size_t)n + 1, fmt, aq);
  else if (n >= (int)sizeof small)
    buf = small; /* out of memory: the first 1023 bytes */
  va_end(aq);
  if (n >= 0) cli_put_text(stderr, buf); /* the one rule: cli_text.c */
  if (buf != small) free(buf);
}

int (cli_fail)(int code, const char *fmt, ...) {
  va_list ap;
  fputs("rcbtool: ", stderr);
  va_start(ap, fmt);
  vput_escaped(fmt, ap);
  va_end(ap);
  fputc('\n', stderr);
  return code;
}

void cli_warn(const char *fmt, ...) {
  va_list ap;
  fputs("rcbtool: warning: ", stderr);
  va_start(ap, fmt);
  vput_escaped(fmt, ap);
  va_end(ap);
  fputc('\n', stderr);
}

int (cli_usage)(const char *cmd, const char *fmt, ...) {
  va_list ap;
  fputs("rcbtool: ", stderr);
  if (cmd) fprintf(stderr, "%s: ", cmd);
  va_start(ap, fmt);
  vput_escaped(fmt, ap);
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

/* One example per command, run from the source tree (the commands in this
 * order make the files the later ones read: meas.csv, session.jsonl). Each
 * runs as written; tests/cli runs them all (case help_examples). */
static const char *const examples[][2] = {
    {"check", "rcbtool check examples/paper_system.ini"},
    {"matrices", "rcbtool matrices examples/paper_system.ini --rpm 3000 --json -o matrices.json"},
    {"frf", "rcbtool frf examples/paper_system.ini --out C.A.x,C.A.y --in DA.x --fmax 500 "
            "--points 501 --rpm 10000 -o frf.csv"},
    {"unbalance", "rcbtool unbalance examples/paper_system.ini --out DA.x,DA.y --rpm-max 20000 "
                  "--points 401 -o unbalance.csv"},
    {"modes", "rcbtool modes examples/paper_system.ini --rpm 10000 --modes 8"},
    {"campbell", "rcbtool campbell examples/paper_system.ini --rpm-max 20000 --points 81 "
                 "-o campbell.csv"},
    {"simulate", "rcbtool simulate examples/paper_system.ini --frf --out C.A.x,C.A.y,C.B.x,C.B.y "
                 "--in DA.x --fmin 200 --fmax 400 --points 201 --rpm 10000 --kind inertance "
                 "--noise 10,1 --seed 1 -o meas.csv"},
    {"convert", "rcbtool convert meas.csv meas.uff"},
    {"fit", "rcbtool fit examples/paper_system.ini meas.csv --params "
            "coupling.C.kt,coupling.C.kr,coupling.C.ct --log --noise 10,1 --history "
            "session.jsonl -o fitted.ini"},
    {"sensitivity", "rcbtool sensitivity examples/paper_system.ini --params "
                    "coupling.C.kt,coupling.C.kr --frf --in DA.x --fmin 200 --fmax 400 "
                    "--rpm 10000"},
    {"compare", "rcbtool compare fitted.ini meas.csv"},
    {"diagnose", "rcbtool diagnose fitted.ini meas.csv --params "
                 "coupling.C.kt,coupling.C.kr,coupling.C.ct --log --noise 10,1 --history "
                 "session.jsonl"},
    {"plan", "rcbtool plan fitted.ini meas.csv --between bearing.B2.kyy coupling.C.kr "
             "--noise 10,1 --rpm-list 6000 --top 5"},
    {"history", "rcbtool history session.jsonl"},
    {"monitor", "rcbtool monitor fitted.ini meas.csv meas.csv --params coupling.C.kt,coupling.C.kr "
                "--noise 10,1 --log monitor.csv"},
    {"transient", "rcbtool transient examples/paper_system.ini --out DA.x,DB.x --rpm 3000 "
                  "--rpm-end 4500 --accel 3000 --dt 1e-4 --signals -o runup.csv"},
    {"order", "rcbtool order runup.csv --kp KP --outputs DA.x,DB.x --bin-rpm 300 "
              "-o runup_1x.csv"},
    {"estimate", "rcbtool estimate examples/signals/random_sdof.csv --input force=DA.x "
                 "--outputs DA.x --nseg 512 --stats sdof_stats.csv -o sdof_h1.csv"},
    {"timecheck", "rcbtool timecheck examples/paper_system.ini --out DA.x --rpm-min 3000 "
                  "--rpm-max 3000 --points 1 --steady-tol 1e-3"},
};

/* The command a help text is for: the word after "usage: rcbtool ". */
static const char *example_for(const char *text) {
  static const char usage[] = "usage: rcbtool ";
  size_t i, n;
  if (strncmp(text, usage, sizeof usage - 1) != 0) return NULL;
  text += sizeof usage - 1;
  n = strcspn(text, " \n");
  for (i = 0; i < sizeof examples / sizeof examples[0]; i++)
    if (strlen(examples[i][0]) == n && strncmp(text, examples[i][0], n) == 0)
      return examples[i][1];
  return NULL;
}

int cli_print_help(const char *text) {
  const char *ex = example_for(text);
  fputs(text, stdout);
  if (ex) printf("\nexample (from the source tree):\n  %s\n", ex);
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

char *cli_read_stdin(size_t *len) {
  size_t cap = 0, n = 0, r;
  char *buf = NULL;
  *len = 0;
  for (;;) {
    if (n + 4096 + 1 > cap) {
      char *nb = realloc(buf, cap = 2 * cap + 65536);
      if (!nb) {
        free(buf);
        cli_fail(CLI_EXIT_NUMERIC, "out of memory reading standard input");
        return NULL;
      }
      buf = nb;
    }
    r = fread(buf + n, 1, cap - n - 1, stdin);
    n += r;
    if (r == 0) break;
  }
  if (ferror(stdin)) {
    free(buf);
    cli_fail(CLI_EXIT_INPUT, "cannot read standard input");
    return NULL;
  }
  buf[n] = '\0';
  *len = n;
  return buf;
}
