/* Per-point standard deviations (the --stats files of rcbtool estimate and
 * rcbtool order), read for rcb_fit_set_sd / rcb_diag_set_sd (rcbtool fit and
 * diagnose --sd): the weights and the noise floor are the library's. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

typedef struct sd_table {
  char *text;
  char **head; /* ncol column names (point into text) */
  size_t ncol, nrow;
  double *v; /* nrow x ncol */
} sd_table;

static void table_free(sd_table *t) {
  free(t->text);
  free(t->head);
  free(t->v);
}

/* Split a line at commas in place (at most max fields); returns the count. */
static size_t split(char *line, char **f, size_t max) {
  size_t n = 0;
  while (line && n < max) {
    char *c = strchr(line, ',');
    if (c) *c = '\0';
    f[n++] = line;
    line = c ? c + 1 : NULL;
  }
  return n;
}

static int read_table(const char *path, sd_table *t) {
  FILE *fp = fopen(path, "rb");
  long size;
  char *line, *next, *f[1024];
  size_t k, cap = 0, lineno = 0;
  memset(t, 0, sizeof *t);
  if (!fp) return cli_fail(CLI_EXIT_INPUT, "--sd: cannot open '%s'", path);
  if (fseek(fp, 0, SEEK_END) || (size = ftell(fp)) < 0 || fseek(fp, 0, SEEK_SET) ||
      !(t->text = malloc((size_t)size + 1)) || fread(t->text, 1, (size_t)size, fp) != (size_t)size) {
    fclose(fp);
    return cli_fail(CLI_EXIT_INPUT, "--sd: cannot read '%s'", path);
  }
  fclose(fp);
  t->text[size] = '\0';
  for (line = t->text; line && *line; line = next) {
    next = strchr(line, '\n');
    if (next) *next++ = '\0';
    lineno++;
    if (line[0] == '#' || line[0] == '\0') continue;
    if (!t->head) {
      t->ncol = split(line, f, 1024);
      t->head = malloc(t->ncol * sizeof *t->head);
      if (!t->head) return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
      memcpy(t->head, f, t->ncol * sizeof *f);
      continue;
    }
    if (split(line, f, 1024) != t->ncol)
      return cli_fail(CLI_EXIT_INPUT, "%s:%zu: %s fields; the header has %zu", path, lineno,
                      "a different number of", t->ncol);
    if (t->nrow == cap) {
      size_t ncol = t->ncol > 0 ? t->ncol : 1; /* >= 1: the header has a column */
      double *v = realloc(t->v, (cap ? 2 * cap : 256) * ncol * sizeof *v);
      if (!v) return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
      t->v = v;
      cap = cap ? 2 * cap : 256;
    }
    for (k = 0; k < t->ncol; k++) {
      char *end;
      t->v[t->nrow * t->ncol + k] = strtod(f[k], &end);
      if (end == f[k]) return cli_fail(CLI_EXIT_INPUT, "%s:%zu: field %zu is not a number",
                                      path, lineno, k + 1);
    }
    t->nrow++;
  }
  if (!t->head) return cli_fail(CLI_EXIT_INPUT, "%s: no header line", path);
  return 0;
}

static long find_col(const sd_table *t, const char *name) {
  size_t k;
  for (k = 0; k < t->ncol; k++)
    if (strcmp(t->head[k], name) == 0) return (long)k;
  return -1;
}

int cli_sd_read(const char *path, const rcb_meas *ms, double **sd_out) {
  sd_table t;
  size_t n = rcb_meas_point_count(ms), nc = rcb_meas_channel_count(ms), c, i;
  int frf = rcb_meas_get_type(ms) == RCB_MEAS_FRF, rc;
  double unit = frf ? CLI_HZ_TO_RAD_S : CLI_RPM_TO_RAD_S, *v;
  const double *x = rcb_meas_grid(ms);
  *sd_out = NULL;
  cli_plan_input(path, "--sd"); /* never an output of the run */
  if ((rc = read_table(path, &t))) {
    table_free(&t);
    return rc;
  }
  if (t.nrow != n) {
    table_free(&t);
    return cli_fail(CLI_EXIT_INPUT, "--sd %s: %zu rows for a measurement of %zu points; give "
                    "the --stats file written with the measurement", path, t.nrow, n);
  }
  for (i = 0; i < n; i++)
    if (fabs(t.v[i * t.ncol] * unit - x[i]) > 1e-5 * fabs(x[i]) + 1e-12) { /* UFF: 6 digits */
      double at = t.v[i * t.ncol];
      table_free(&t);
      return cli_fail(CLI_EXIT_INPUT, "--sd %s: row %zu is at %.9g %s, the measurement's "
                      "point %zu at %.9g: not the same abscissa", path, i + 1, at,
                      frf ? "Hz" : "rpm", i + 1, x[i] / unit);
    }
  v = calloc((n ? n : 1) * (nc ? nc : 1), sizeof *v);
  if (!v) {
    table_free(&t);
    return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  }
  for (c = 0; c < nc; c++) {
    rcb_meas_channel_info ci;
    char name[256];
    long col;
    rcb_meas_channel(ms, c, &ci);
    if (frf)
      snprintf(name, sizeof name, "%s/%s sd", ci.response, ci.reference);
    else
      snprintf(name, sizeof name, "%s 1X sd", ci.response);
    if ((col = find_col(&t, name)) < 0) {
      table_free(&t);
      free(v);
      return cli_fail(CLI_EXIT_INPUT, "--sd %s: no column '%s' for channel %s", path, name,
                      ci.response);
    }
    for (i = 0; i < n; i++) {
      double sd = t.v[i * t.ncol + (size_t)col];
      /* as rcb_compare_set_sd, for every verb (fit and diagnose took inf silently), and a
       * value whose weight 1/sd^2 overflows is blamed on this file, not the noise model */
      if (sd < 0 || isinf(sd) || (sd > 0 && !(1.0 / (sd * sd) < HUGE_VAL))) {
        table_free(&t);
        free(v);
        return cli_fail(CLI_EXIT_INPUT, "--sd %s: column '%s', row %zu: standard deviation "
                        "%g %s (0 or NaN leaves the point out)", path, name, i + 1, sd,
                        sd < 0 ? "< 0" : isinf(sd) ? "is not finite"
                        : "is too small: its weight 1/sd^2 overflows (expected above 1e-154)");
      }
      v[c * n + i] = sd;
    }
  }
  table_free(&t);
  *sd_out = v;
  return 0;
}
