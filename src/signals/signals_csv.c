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

#define CSV_MAXCH 256 /* channel columns; one more is refused with the limit named */
#define CSV_CHUNK (1u << 20) /* bytes per read */
#define CSV_SHOW 60          /* characters of a long name or unit shown in a message */

/* Names and units point into copies of the header and units lines, so a
 * line of any length is read whole (issue #35 item 6: a units line cut at
 * 1024 bytes read "mm/s^2" as "m" without a word). The only limit left is
 * the name the container keeps (RCB_SIGNAL_NAME_MAX - 1 characters), and a
 * longer name is refused with file:line, never cut. */
typedef struct csv_col {
  const char *name;
  const char *unit; /* "" without one */
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
  char *head;  /* the header line (allocated copy) */
  char *units; /* the text after "# units =" (allocated copy), NULL: none */
  size_t units_at;
  size_t row_line[2]; /* lines of the first and the last sample row */
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

/* A copy of line @p l in *out (the previous one freed). */
static rcb_status keep_line(csv_state *C, const char *l, char **out) {
  size_t n = strlen(l);
  char *c = rcb_alloc(&C->s->alloc, n + 1);
  if (!c) return rcb_signals_fail(C->s, RCB_ERR_NOMEM, "%s:%zu: out of memory", C->path, C->line);
  memcpy(c, l, n + 1);
  rcb_free(&C->s->alloc, *out);
  *out = c;
  return RCB_OK;
}

/* Blanks cut off both ends, in place. */
static char *trim(char *a) {
  size_t n;
  while (*a == ' ' || *a == '\t') a++;
  n = strlen(a);
  while (n > 0 && (a[n - 1] == ' ' || a[n - 1] == '\t')) n--;
  a[n] = '\0';
  return a;
}

/* "NAME [unit]" (in place) -> column k. */
static rcb_status split_name(csv_state *C, char *f, size_t k) {
  csv_col *c = &C->col[k];
  char *lb = strchr(f, '['), *rb = lb ? strchr(lb, ']') : NULL;
  c->unit = "";
  if (lb && !rb)
    return rcb_signals_fail(C->s, RCB_ERR_PARSE, "%s:%zu: column %zu ('%.*s'): '[' without "
                            "']'; write the unit as NAME [unit]", C->path, C->line, k + 2,
                            CSV_SHOW, f);
  if (rb) {
    const char *after = trim(rb + 1);
    if (*after)
      return rcb_signals_fail(C->s, RCB_ERR_PARSE, "%s:%zu: column %zu: '%.*s' after the "
                              "unit's ']'; write NAME [unit]", C->path, C->line, k + 2,
                              CSV_SHOW, after);
    *lb = *rb = '\0';
    c->unit = trim(lb + 1);
  }
  c->name = trim(f);
  c->unit_line = C->line;
  if (!c->name[0])
    return rcb_signals_fail(C->s, RCB_ERR_PARSE, "%s:%zu: column %zu has no name", C->path,
                            C->line, k + 2);
  if (strlen(c->name) >= RCB_SIGNAL_NAME_MAX)
    return rcb_signals_fail(C->s, RCB_ERR_PARSE, "%s:%zu: column %zu: name '%.*s...' has %zu "
                            "characters; at most %d are kept (a shorter name, please)",
                            C->path, C->line, k + 2, CSV_SHOW, c->name, strlen(c->name),
                            RCB_SIGNAL_NAME_MAX - 1);
  return RCB_OK;
}

static rcb_status parse_header(csv_state *C, char *l) {
  char *f = l, *comma, *first;
  size_t k = 0;
  rcb_status st;
  comma = strchr(f, ',');
  if (comma) *comma = '\0';
  first = trim(f);
  if (strncmp(first, "time", 4) != 0 && strcmp(first, "t") != 0)
    return rcb_signals_fail(C->s, RCB_ERR_PARSE, "%s:%zu: first column '%.*s': expected the "
                            "time column 'time_s' (seconds), then one column per channel",
                            C->path, C->line, CSV_SHOW, first);
  while (comma) {
    f = comma + 1;
    comma = strchr(f, ',');
    if (comma) *comma = '\0';
    if (k == CSV_MAXCH)
      return rcb_signals_fail(C->s, RCB_ERR_PARSE, "%s:%zu: more than %d channel columns, "
                              "the most librcb reads from one file; split the file",
                              C->path, C->line, CSV_MAXCH);
    if ((st = split_name(C, f, k))) return st;
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
  char *f = C->units, *comma;
  size_t k = 0;
  if (!C->units) return RCB_OK;
  do {
    comma = strchr(f, ',');
    if (comma) *comma = '\0';
    if (k == C->ncol)
      return rcb_signals_fail(C->s, RCB_ERR_PARSE, "%s:%zu: more units than the %zu channel "
                              "columns of the header", C->path, C->units_at, C->ncol);
    if (!C->col[k].unit[0]) {
      C->col[k].unit = trim(f);
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
    C->row_line[r == 0 ? 0 : 1] = C->line;
    r++;
  }
  *nrows = r;
  return RCB_OK;
}

/* The rate from the time column. Times of -1e308 and 1e308 made the
 * spacing overflow to infinity, which passed the spacing test below (every
 * difference compared with inf) and surfaced as "sample rate 0" with no
 * file nor line (issue #35 item 6): a spacing or a rate that is not a
 * finite positive number is refused here, with the lines of the first and
 * the last row. */
static rcb_status check_time(csv_state *C, const double *t, size_t n, size_t first_line,
                             double *rate) {
  double dt;
  size_t i;
  if (n < 2)
    return rcb_signals_fail(C->s, RCB_ERR_PARSE, "%s: %zu sample rows; expected at least 2",
                            C->path, n);
  dt = (t[n - 1] - t[0]) / (double)(n - 1);
  if (!isfinite(dt))
    return rcb_signals_fail(C->s, RCB_ERR_PARSE, "%s:%zu: time %g s, and %g s at line %zu: the "
                            "spacing of the time column, (last - first) / %zu, is not a finite "
                            "number; expected times in seconds", C->path, C->row_line[0], t[0],
                            t[n - 1], C->row_line[1], n - 1);
  if (!(dt > 0.0))
    return rcb_signals_fail(C->s, RCB_ERR_PARSE, "%s:%zu: time %.9g s, and %.9g s at line %zu: "
                            "the time column is not increasing", C->path, C->row_line[0], t[0],
                            t[n - 1], C->row_line[1]);
  if (!isfinite(1.0 / dt))
    return rcb_signals_fail(C->s, RCB_ERR_PARSE, "%s:%zu: time %g s, and %g s at line %zu: a "
                            "spacing of %g s, whose sample rate is not a finite number; "
                            "expected times in seconds", C->path, C->row_line[0], t[0],
                            t[n - 1], C->row_line[1], dt);
  for (i = 0; i < n; i++)
    if (!(fabs(t[i] - (t[0] + (double)i * dt)) <= 1e-3 * dt))
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
    const char *given = rcb_signals_unit_override(C->s, C->col[k].name), *u = C->col[k].unit;
    if (given && (!C->col[k].unit[0] || rcb_unit_parse(C->col[k].unit, &q, &f))) {
      rcb_unit_parse(given, &q, &f); /* checked by rcb_signals_set_unit */
    } else if (C->col[k].unit[0] && rcb_unit_parse(C->col[k].unit, &q, &f)) {
      char known[300];
      rcb_unit_list(RCB_QTY_UNKNOWN, known, sizeof known);
      return rcb_signals_fail(C->s, RCB_ERR_PARSE, "%s:%zu: channel '%s': unit '%.*s%s' is not "
                              "one librcb knows (%s); give it: --units '%s=UNIT' "
                              "(rcb_signals_set_unit)", C->path, C->col[k].unit_line,
                              C->col[k].name, CSV_SHOW, u, strlen(u) > CSV_SHOW ? "..." : "",
                              known, C->col[k].name);
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
      if ((st = keep_line(C, strchr(l, '=') + 1, &C->units))) return st;
      C->units_at = C->line;
    }
  }
  if (!l) return rcb_signals_fail(C->s, RCB_ERR_PARSE, "%s: no header line", C->path);
  if ((st = keep_line(C, l, &C->head)) || (st = parse_header(C, C->head)) ||
      (st = apply_units(C)))
    return st;
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
  if (C) memset(C, 0, sizeof *C);
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
  rcb_free(&s->alloc, C->head);
  rcb_free(&s->alloc, C->units);
  rcb_free(&s->alloc, C->buf);
  rcb_free(&s->alloc, C);
  return st;
}
