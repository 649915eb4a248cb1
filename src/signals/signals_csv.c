/*
 * Time signals from CSV: "# units = U1,U2,..." (optional, one per channel),
 * header "time_s,NAME1,NAME2 [unit],...", rows of numbers. The rate comes
 * from the time column, which must be evenly spaced (each time within 0.1 %
 * of a step of t0 + i dt): a file with dropped samples is refused rather than
 * read with a wrong frequency axis.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "signals/signals_internal.h"

#define CSV_MAXCH 256

typedef struct csv_col {
  char name[RCB_SIGNAL_NAME_MAX];
  char unit[32];
  size_t unit_line; /* line the unit came from */
} csv_col;

typedef struct csv_state {
  rcb_signals *s;
  const char *path;
  char *p, *end; /* cursor */
  size_t line;
  csv_col col[CSV_MAXCH];
  size_t ncol; /* channel columns (time excluded) */
  char units_line[1024];
  size_t units_at;
} csv_state;

/* Next line (NUL-terminated in place), or NULL. */
static char *next_line(csv_state *C) {
  char *l = C->p, *e;
  if (C->p >= C->end) return NULL;
  e = memchr(C->p, '\n', (size_t)(C->end - C->p));
  if (!e) e = C->end;
  C->p = e < C->end ? e + 1 : e;
  *e = '\0';
  if (e > l && e[-1] == '\r') e[-1] = '\0';
  C->line++;
  return l;
}

static void trim(char *a, char *out, size_t size) {
  size_t n;
  while (*a == ' ' || *a == '\t') a++;
  n = strlen(a);
  while (n > 0 && (a[n - 1] == ' ' || a[n - 1] == '\t')) n--;
  if (n >= size) n = size - 1;
  memcpy(out, a, n);
  out[n] = '\0';
}

/* "NAME [unit]" -> name, unit. */
static void split_name(const char *f, csv_col *c) {
  const char *lb = strchr(f, '['), *rb = lb ? strchr(lb, ']') : NULL;
  char tmp[RCB_SIGNAL_NAME_MAX + 40];
  size_t n = lb && rb ? (size_t)(lb - f) : strlen(f);
  if (n >= sizeof tmp) n = sizeof tmp - 1;
  memcpy(tmp, f, n);
  tmp[n] = '\0';
  trim(tmp, c->name, sizeof c->name);
  if (lb && rb && (size_t)(rb - lb - 1) < sizeof tmp) {
    memcpy(tmp, lb + 1, (size_t)(rb - lb - 1));
    tmp[rb - lb - 1] = '\0';
    trim(tmp, c->unit, sizeof c->unit);
  }
}

static rcb_status parse_header(csv_state *C, char *l) {
  char *f = l, *comma;
  char first[64];
  size_t k = 0;
  comma = strchr(f, ',');
  if (comma) *comma = '\0';
  trim(f, first, sizeof first);
  if (strncmp(first, "time", 4) != 0 && strcmp(first, "t") != 0)
    return rcb_signals_fail(C->s, RCB_ERR_PARSE, "%s:%zu: first column '%s': expected the time "
                            "column 'time_s' (seconds), then one column per channel", C->path,
                            C->line, first);
  while (comma) {
    f = comma + 1;
    comma = strchr(f, ',');
    if (comma) *comma = '\0';
    if (k == CSV_MAXCH)
      return rcb_signals_fail(C->s, RCB_ERR_PARSE, "%s:%zu: more than %d channels", C->path,
                              C->line, CSV_MAXCH);
    split_name(f, &C->col[k]);
    C->col[k].unit_line = C->line;
    if (!C->col[k].name[0])
      return rcb_signals_fail(C->s, RCB_ERR_PARSE, "%s:%zu: column %zu has no name", C->path,
                              C->line, k + 2);
    k++;
  }
  if (k == 0)
    return rcb_signals_fail(C->s, RCB_ERR_PARSE, "%s:%zu: no channel column after the time "
                            "column", C->path, C->line);
  C->ncol = k;
  return RCB_OK;
}

/* "# units = N,mm": fills columns without a bracketed unit. */
static rcb_status apply_units(csv_state *C) {
  char *f = C->units_line, *comma;
  size_t k = 0;
  if (!C->units_at) return RCB_OK;
  do {
    comma = strchr(f, ',');
    if (comma) *comma = '\0';
    if (k == C->ncol)
      return rcb_signals_fail(C->s, RCB_ERR_PARSE, "%s:%zu: more units than the %zu channel "
                              "columns of the header", C->path, C->units_at, C->ncol);
    if (!C->col[k].unit[0]) {
      trim(f, C->col[k].unit, sizeof C->col[k].unit);
      C->col[k].unit_line = C->units_at;
    }
    k++;
    f = comma ? comma + 1 : f;
  } while (comma);
  if (k != C->ncol)
    return rcb_signals_fail(C->s, RCB_ERR_PARSE, "%s:%zu: %zu units for %zu channel columns; "
                            "give one unit per channel", C->path, C->units_at, k, C->ncol);
  return RCB_OK;
}

static rcb_status parse_rows(csv_state *C, size_t nrows, double *t, double **v) {
  size_t r = 0, k;
  char *l;
  while (r < nrows && (l = next_line(C)) != NULL) {
    char *q = l, *endp;
    if (l[0] == '\0' || l[0] == '#') continue;
    for (k = 0; k <= C->ncol; k++) {
      double x;
      errno = 0;
      x = strtod(q, &endp);
      if (endp == q || errno == ERANGE || !isfinite(x))
        return rcb_signals_fail(C->s, RCB_ERR_PARSE, "%s:%zu: field %zu is not a finite "
                                "number", C->path, C->line, k + 1);
      if (k > 0 && fabs(x) > RCB_SIGNAL_MAX)
        return rcb_signals_fail(C->s, RCB_ERR_PARSE, "%s:%zu: field %zu is %g: beyond %g, "
                                "the largest sample librcb takes (its power would overflow); "
                                "a corrupt field?", C->path, C->line, k + 1, x, RCB_SIGNAL_MAX);
      while (*endp == ' ' || *endp == '\t') endp++;
      if (k < C->ncol && *endp != ',')
        return rcb_signals_fail(C->s, RCB_ERR_PARSE, "%s:%zu: %zu fields; expected %zu (time "
                                "and %zu channels)", C->path, C->line, k + 1, C->ncol + 1,
                                C->ncol);
      if (k == C->ncol && *endp != '\0')
        return rcb_signals_fail(C->s, RCB_ERR_PARSE, "%s:%zu: more than %zu fields", C->path,
                                C->line, C->ncol + 1);
      if (k == 0)
        t[r] = x;
      else
        v[k - 1][r] = x;
      q = endp + 1;
    }
    r++;
  }
  return RCB_OK;
}

static rcb_status check_time(csv_state *C, const double *t, size_t n, size_t first_line,
                             double *rate) {
  double dt;
  size_t i;
  if (n < 2)
    return rcb_signals_fail(C->s, RCB_ERR_PARSE, "%s: %zu sample rows; expected at least 2",
                            C->path, n);
  dt = (t[n - 1] - t[0]) / (double)(n - 1);
  if (!(dt > 0.0))
    return rcb_signals_fail(C->s, RCB_ERR_PARSE, "%s: time column not increasing", C->path);
  for (i = 0; i < n; i++)
    if (fabs(t[i] - (t[0] + (double)i * dt)) > 1e-3 * dt)
      return rcb_signals_fail(C->s, RCB_ERR_PARSE, "%s: sample row %zu (near line %zu): time "
                              "%.9g s, expected %.9g s: the time column must be evenly spaced "
                              "(a dropped or repeated sample?)", C->path, i + 1,
                              first_line + i, t[i], t[0] + (double)i * dt);
  *rate = 1.0 / dt;
  return RCB_OK;
}

static rcb_status take_columns(csv_state *C, double **v) {
  size_t k, i;
  rcb_status st;
  for (k = 0; k < C->ncol; k++) {
    rcb_quantity q = RCB_QTY_UNKNOWN;
    double f = 1.0;
    const char *given = rcb_signals_unit_override(C->s, C->col[k].name);
    if (given && (!C->col[k].unit[0] || rcb_unit_parse(C->col[k].unit, &q, &f))) {
      rcb_unit_parse(given, &q, &f); /* checked by rcb_signals_set_unit */
    } else if (C->col[k].unit[0] && rcb_unit_parse(C->col[k].unit, &q, &f)) {
      char known[300];
      rcb_unit_list(RCB_QTY_UNKNOWN, known, sizeof known);
      return rcb_signals_fail(C->s, RCB_ERR_PARSE, "%s:%zu: channel '%s': unit '%s' is not "
                              "one librcb knows (%s); give it: --units '%s=UNIT' "
                              "(rcb_signals_set_unit)", C->path, C->col[k].unit_line,
                              C->col[k].name, C->col[k].unit, known, C->col[k].name);
    }
    for (i = 0; i < C->s->n; i++) v[k][i] *= f;
    st = rcb_signals_take(C->s, C->col[k].name, q, v[k]);
    v[k] = NULL;
    if (st) return st;
  }
  return RCB_OK;
}

static rcb_status read_body(csv_state *C) {
  char *l, *save;
  size_t nrows = 0, saved_line, k;
  double *t = NULL, *v[CSV_MAXCH] = {NULL};
  rcb_status st = RCB_OK;
  double rate = 0.0;
  while ((l = next_line(C)) != NULL) {
    if (l[0] != '#') break;
    if (strncmp(l, "# units", 7) == 0 && strchr(l, '=')) {
      snprintf(C->units_line, sizeof C->units_line, "%s", strchr(l, '=') + 1);
      C->units_at = C->line;
    }
  }
  if (!l) return rcb_signals_fail(C->s, RCB_ERR_PARSE, "%s: no header line", C->path);
  if ((st = parse_header(C, l)) || (st = apply_units(C))) return st;
  save = C->p;
  saved_line = C->line;
  while ((l = next_line(C)) != NULL)
    if (l[0] != '\0' && l[0] != '#') nrows++;
  /* lines were cut in place: restore the NULs to newlines for the second pass */
  for (l = save; l < C->end; l++)
    if (*l == '\0') *l = '\n';
  C->p = save;
  C->line = saved_line;
  t = rcb_alloc(&C->s->alloc, (nrows ? nrows : 1) * sizeof *t);
  for (k = 0; k < C->ncol; k++) v[k] = rcb_alloc(&C->s->alloc, (nrows ? nrows : 1) * sizeof **v);
  for (k = 0; k < C->ncol; k++)
    if (!v[k]) st = RCB_ERR_NOMEM;
  if (!t || st) st = rcb_signals_fail(C->s, RCB_ERR_NOMEM, "%s: out of memory", C->path);
  if (!st) st = parse_rows(C, nrows, t, v);
  if (!st) st = check_time(C, t, nrows, saved_line + 1, &rate);
  if (!st) st = rcb_signals_reset(C->s, rate, nrows);
  if (!st) st = take_columns(C, v);
  for (k = 0; k < C->ncol; k++) rcb_free(&C->s->alloc, v[k]);
  rcb_free(&C->s->alloc, t);
  return st;
}

rcb_status rcb_signals_read_csv(rcb_signals *s, const char *path) {
  csv_state *C;
  char *buf = NULL;
  size_t len;
  rcb_status st;
  if (!s) return RCB_ERR_ARG;
  rcb_signals_begin_read(s);
  if ((st = rcb_signals_slurp(s, path, &buf, &len))) return st;
  C = rcb_alloc(&s->alloc, sizeof *C);
  if (!C) {
    rcb_free(&s->alloc, buf);
    return rcb_signals_fail(s, RCB_ERR_NOMEM, "out of memory");
  }
  C->s = s;
  C->path = path;
  C->p = buf;
  C->end = buf + len;
  st = read_body(C);
  if (st) rcb_signals_empty(s);
  rcb_free(&s->alloc, C);
  rcb_free(&s->alloc, buf);
  return st;
}
