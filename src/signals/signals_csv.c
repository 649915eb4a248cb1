/*
 * Time signals from CSV: "# units = U1,U2,..." (optional, one per channel),
 * header "time_s,NAME1,NAME2 [unit],...", rows of numbers. The rate comes
 * from the time column, which must be evenly spaced (each time within 0.1 %
 * of a step of t0 + i dt): a file with dropped samples is refused rather than
 * read with a wrong frequency axis.
 *
 * Read in one pass at the speed of the disk (issue #25): the file streams
 * through one buffer in large reads (CSV_CHUNK bytes, grown only for a
 * longer line), each line is cut in place, its numbers go through
 * rcb_strtod (strtod's value, without its cost) straight into per-channel
 * arrays that double as they fill. No allocation per line or field.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "signals/signals_internal.h"

#define CSV_MAXCH 256
#define CSV_CHUNK (1u << 20) /* bytes per read */

typedef struct csv_col {
  char name[RCB_SIGNAL_NAME_MAX];
  char unit[32];
  size_t unit_line; /* line the unit came from */
} csv_col;

typedef struct csv_state {
  rcb_signals *s;
  const char *path;
  FILE *fp;
  char *buf; /* cap + 1 bytes */
  size_t cap;
  char *p, *lim; /* unread bytes [p, lim); *lim == '\0' */
  int eof;
  size_t line;
  csv_col col[CSV_MAXCH];
  size_t ncol; /* channel columns (time excluded) */
  char units_line[1024];
  size_t units_at;
} csv_state;

/* Keep the unread bytes, then read up to the buffer's end; a buffer that
 * holds only part of one line is doubled first. */
static rcb_status refill(csv_state *C) {
  size_t keep = (size_t)(C->lim - C->p), n;
  if (keep == C->cap) {
    char *b;
    if (C->cap > ((size_t)-1 - 1) / 2 || !(b = rcb_alloc(&C->s->alloc, 2 * C->cap + 1)))
      return rcb_signals_fail(C->s, RCB_ERR_NOMEM, "%s:%zu: out of memory for a line of "
                              "more than %zu bytes", C->path, C->line + 1, C->cap);
    memcpy(b, C->p, keep);
    rcb_free(&C->s->alloc, C->buf);
    C->buf = b;
    C->cap *= 2;
  } else if (keep > 0 && C->p != C->buf) {
    memmove(C->buf, C->p, keep);
  }
  n = fread(C->buf + keep, 1, C->cap - keep, C->fp);
  if (n < C->cap - keep) {
    if (ferror(C->fp))
      return rcb_signals_fail(C->s, RCB_ERR_IO, "%s: read error after line %zu: %s", C->path,
                              C->line, strerror(errno));
    C->eof = 1;
  }
  C->p = C->buf;
  C->lim = C->buf + keep + n;
  *C->lim = '\0';
  return RCB_OK;
}

/* Next line, NUL-terminated in place (a final '\r' dropped), or NULL at
 * the end of the file. */
static rcb_status next_line(csv_state *C, char **line) {
  char *l, *e;
  rcb_status st;
  while ((e = memchr(C->p, '\n', (size_t)(C->lim - C->p))) == NULL && !C->eof)
    if ((st = refill(C))) return st;
  *line = NULL;
  if (!e && C->p == C->lim) return RCB_OK;
  l = C->p;
  if (!e) e = C->lim;
  C->p = e < C->lim ? e + 1 : e;
  *e = '\0';
  if (e > l && e[-1] == '\r') e[-1] = '\0';
  C->line++;
  *line = l;
  return RCB_OK;
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

/* One row of numbers into t[r] and v[k][r], k < nc (the channel columns). */
static rcb_status parse_row(csv_state *C, size_t nc, char *l, size_t r, double *t, double **v) {
  char *q = l, *endp;
  size_t k;
  for (k = 0; k <= nc; k++) {
    double x;
    errno = 0;
    x = rcb_strtod_in(q, C->buf + C->cap + 1, &endp);
    if (endp == q || errno == ERANGE || !isfinite(x))
      return rcb_signals_fail(C->s, RCB_ERR_PARSE, "%s:%zu: field %zu is not a finite "
                              "number", C->path, C->line, k + 1);
    if (k > 0 && fabs(x) > RCB_SIGNAL_MAX)
      return rcb_signals_fail(C->s, RCB_ERR_PARSE, "%s:%zu: field %zu is %g: beyond %g, "
                              "the largest sample librcb takes (its power would overflow); "
                              "a corrupt field?", C->path, C->line, k + 1, x, RCB_SIGNAL_MAX);
    while (*endp == ' ' || *endp == '\t') endp++;
    if (k < nc && *endp != ',')
      return rcb_signals_fail(C->s, RCB_ERR_PARSE, "%s:%zu: %zu fields; expected %zu (time "
                              "and %zu channels)", C->path, C->line, k + 1, nc + 1,
                              nc);
    if (k == nc && *endp != '\0')
      return rcb_signals_fail(C->s, RCB_ERR_PARSE, "%s:%zu: more than %zu fields", C->path,
                              C->line, nc + 1);
    if (k == 0)
      t[r] = x;
    else
      v[k - 1][r] = x;
    q = endp + 1;
  }
  return RCB_OK;
}

/* Every row, the arrays doubled as they fill: *nrows rows. */
static rcb_status parse_rows(csv_state *C, double **t, double **v, size_t *nrows) {
  const size_t nc = C->ncol;
  size_t r = 0, cap = 0, k;
  char *l;
  rcb_status st;
  for (;;) {
    if ((st = next_line(C, &l))) return st;
    if (!l) break;
    if (l[0] == '\0' || l[0] == '#') continue;
    if (r == cap) {
      size_t c = cap;
      if (rcb_grow(&C->s->alloc, (void **)t, &c, r + 1, sizeof **t))
        return rcb_signals_fail(C->s, RCB_ERR_NOMEM, "%s:%zu: out of memory", C->path, C->line);
      for (k = 0; k < nc; k++) {
        size_t ck = cap;
        if (rcb_grow(&C->s->alloc, (void **)&v[k], &ck, r + 1, sizeof **v))
          return rcb_signals_fail(C->s, RCB_ERR_NOMEM, "%s:%zu: out of memory", C->path,
                                  C->line);
      }
      cap = c;
    }
    if ((st = parse_row(C, nc, l, r, *t, v))) return st;
    r++;
  }
  *nrows = r;
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
  char *l;
  size_t nrows = 0, first_line, k;
  double *t = NULL, *v[CSV_MAXCH] = {NULL};
  rcb_status st = RCB_OK;
  double rate = 0.0;
  for (;;) {
    if ((st = next_line(C, &l))) return st;
    if (!l || l[0] != '#') break;
    if (strncmp(l, "# units", 7) == 0 && strchr(l, '=')) {
      snprintf(C->units_line, sizeof C->units_line, "%s", strchr(l, '=') + 1);
      C->units_at = C->line;
    }
  }
  if (!l) return rcb_signals_fail(C->s, RCB_ERR_PARSE, "%s: no header line", C->path);
  if ((st = parse_header(C, l)) || (st = apply_units(C))) return st;
  first_line = C->line + 1;
  st = parse_rows(C, &t, v, &nrows);
  if (!st) st = check_time(C, t, nrows, first_line, &rate);
  if (!st) st = rcb_signals_reset(C->s, rate, nrows);
  if (!st) st = take_columns(C, v);
  for (k = 0; k < C->ncol; k++) rcb_free(&C->s->alloc, v[k]);
  rcb_free(&C->s->alloc, t);
  return st;
}

rcb_status rcb_signals_read_csv(rcb_signals *s, const char *path) {
  csv_state *C;
  rcb_status st;
  if (!s) return RCB_ERR_ARG;
  rcb_signals_begin_read(s);
  if (!path || !path[0]) return rcb_signals_fail(s, RCB_ERR_ARG, "no file name given");
  C = rcb_alloc(&s->alloc, sizeof *C);
  if (C) C->buf = rcb_alloc(&s->alloc, CSV_CHUNK + 1);
  if (!C || !C->buf) {
    if (C) rcb_free(&s->alloc, C);
    return rcb_signals_fail(s, RCB_ERR_NOMEM, "%s: out of memory", path);
  }
  C->s = s;
  C->path = path;
  C->cap = CSV_CHUNK;
  C->p = C->lim = C->buf;
  C->fp = fopen(path, "rb");
  if (!C->fp) {
    st = rcb_signals_fail(s, RCB_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
  } else {
    setvbuf(C->fp, NULL, _IONBF, 0); /* reads go straight into C->buf */
    st = read_body(C);
    fclose(C->fp);
  }
  if (st) rcb_signals_empty(s);
  rcb_free(&s->alloc, C->buf);
  rcb_free(&s->alloc, C);
  return st;
}
