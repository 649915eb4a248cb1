/*
 * UFF dataset 58 (function at nodal DOF) reader, ASCII and binary 58b.
 *
 * Layout (SDRC/UC-SDRL; pyuff 2.5 writes and reads the same): "    -1", the
 * id line "    58" (58b: "    58b" + byte order, float format, 11 ASCII
 * lines, n bytes), five ID lines, record 6 (2(I5,I10),2(1X,10A1,I10,I4):
 * function type, ids, response entity/node/direction, reference
 * entity/node/direction), record 7 (3I10,3E13.5: ordinate data type, points,
 * spacing, abscissa min, increment, z value), records 8-11 (I10,3I5,...:
 * specific data type of abscissa, ordinate numerator, denominator, z axis),
 * then the values and "    -1".
 *
 * What we use: function type 4 (FRF) or 1 (general, with reference node 0:
 * unbalance response); complex ordinates (data types 5, 6); abscissa in Hz
 * (abscissa type 18 or 0), or rpm (type 19); ordinate type 8/11/12
 * (displacement/velocity/acceleration) over 13 (excitation force) for
 * receptance/mobility/inertance; z axis of type 19 carries the rotor speed
 * of an FRF test in rpm (negative: synchronous). Units: the record-9/10
 * unit labels (m, mm, um, m/s, m/s^2, g, N, ... : io/units.c) and a dataset
 * 164 before the records (units code and factors) scale the values to SI;
 * a label of the wrong quantity for the data type, an unknown label, or a
 * label that disagrees with dataset 164 is refused; neither given: SI.
 *
 * Binary 58b data (IEEE, either byte order): double complex as pairs of
 * doubles; an uneven abscissa as doubles interleaved (as pyuff writes), or
 * as 4-byte floats when n_bytes says so. Some writers (pyuff 2.5) put half
 * the true byte count of complex data in n_bytes, so the count is taken from
 * record 7 and only checked against the file.
 */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "io/meas_internal.h"

#define UFF_WHERE 600

/* ------------------------------------------------------------ reading -- */

typedef struct cursor {
  const char *buf;
  size_t len, pos, line; /* line: number of the line last returned */
} cursor;

/* Next line [*s, *s + *n) without its end-of-line; 0 at the end of the buffer. */
static int get_line(cursor *c, const char **s, size_t *n) {
  size_t p = c->pos;
  if (p >= c->len) return 0;
  *s = c->buf + p;
  while (p < c->len && c->buf[p] != '\n') p++;
  *n = (size_t)(c->buf + p - *s);
  if (*n > 0 && (*s)[*n - 1] == '\r') (*n)--;
  c->pos = p < c->len ? p + 1 : p;
  c->line++;
  return 1;
}

/* Columns [from, from + width) of a line, trimmed, into out (size >= 64); text
 * as written (units labels such as "rad/s" keep their letters). */
static void field(const char *s, size_t n, size_t from, size_t width, char *out, size_t size) {
  size_t a = from, b = from + width, k = 0;
  if (a > n) a = n;
  if (b > n) b = n;
  while (a < b && (s[a] == ' ' || s[a] == '\t')) a++;
  while (b > a && (s[b - 1] == ' ' || s[b - 1] == '\t')) b--;
  for (; a < b && k + 1 < size; a++) out[k++] = s[a];
  out[k] = '\0';
}

static int field_long(const char *s, size_t n, size_t from, size_t width, long *v) {
  char f[64], *end;
  field(s, n, from, width, f, sizeof f);
  if (!f[0]) return -1;
  errno = 0;
  *v = strtol(f, &end, 10);
  return (*end || errno) ? -1 : 0;
}

static int field_double(const char *s, size_t n, size_t from, size_t width, double *v) {
  char f[64], *end;
  field(s, n, from, width, f, sizeof f);
  for (char *p = f; *p; p++) /* Fortran exponents: 1.0D+02 */
    if (*p == 'D' || *p == 'd') *p = 'E';
  if (!f[0]) return -1;
  errno = 0;
  *v = rcb_strtod(f, &end); /* strtod, bit for bit (core/numparse.c) */
  return (*end || errno == ERANGE) ? -1 : 0;
}

static int is_delim(const char *s, size_t n) {
  char f[16];
  field(s, n, 0, n < 80 ? n : 80, f, sizeof f);
  return strcmp(f, "-1") == 0;
}

static void skip_dataset(cursor *c);

/* One dataset-58 record as read. */
typedef struct uff_rec {
  size_t index, line; /* dataset ordinal in the file, line of its id line */
  int binary, byte_order, fp_format;
  long n_bytes;
  long func_type, rsp_node, rsp_dir, ref_node, ref_dir;
  long ord_type, npts, spacing;
  long claimed;            /* time mode: record 7's count when the record holds fewer
                              values (read up to its '-1'), else 0 */
  double xmin, dx, zval;   /* Hz, Hz, z value */
  long spec[4];            /* records 8..11 specific data types */
  int real;                /* real ordinates (types 2, 4): time records only */
  char lab[4][24];         /* records 8..11 axis units labels */
  double *x;               /* Hz (or rpm), npts */
  rcb_complex *y;          /* npts */
} uff_rec;

typedef struct uff_reader {
  rcb_meas *ms;
  const char *path;
  cursor c;
  size_t nmap;
  const rcb_uff_node *map;
  int has164;          /* a dataset 164 was read (-1: malformed, see err164) */
  rcb_uff_time_fn on_time; /* time mode (rcb_uff58_read_time): records go here */
  void *user;
  size_t ntime;
  size_t nskip, skip_index; /* records of a function this read does not take; the first */
  long skip_type, skip_abscissa;
  char err164[RCB_ERRMSG_MAX];
  double lf, ff;       /* its length and force factors (file units per SI unit) */
  size_t line164;
} uff_reader;

static rcb_status rfail(uff_reader *R, const uff_rec *r, size_t line, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;
static rcb_status rfail(uff_reader *R, const uff_rec *r, size_t line, const char *fmt, ...) {
  char msg[RCB_ERRMSG_MAX];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(msg, sizeof msg, fmt, ap);
  va_end(ap);
  return rcb_meas_fail(R->ms, RCB_ERR_PARSE, "%s:%zu: dataset 58 record %zu: %s", R->path,
                       line, r->index, msg);
}

static rcb_status read_headers(uff_reader *R, uff_rec *r) {
  const char *s;
  size_t n;
  int k;
  for (k = 0; k < 5; k++)
    if (!get_line(&R->c, &s, &n))
      return rfail(R, r, R->c.line, "truncated: the file ends inside the ID lines");
  if (!get_line(&R->c, &s, &n) || is_delim(s, n))
    return rfail(R, r, R->c.line, "truncated: record 6 (DOF identification) missing");
  if (field_long(s, n, 0, 5, &r->func_type) || field_long(s, n, 41, 10, &r->rsp_node) ||
      field_long(s, n, 51, 4, &r->rsp_dir) || field_long(s, n, 66, 10, &r->ref_node) ||
      field_long(s, n, 76, 4, &r->ref_dir))
    return rfail(R, r, R->c.line, "record 6 is malformed; expected "
                 "2(I5,I10),2(1X,10A1,I10,I4): function type, response node and direction, "
                 "reference node and direction");
  if (!get_line(&R->c, &s, &n) || is_delim(s, n))
    return rfail(R, r, R->c.line, "truncated: record 7 (data form) missing");
  if (field_long(s, n, 0, 10, &r->ord_type) || field_long(s, n, 10, 10, &r->npts) ||
      field_long(s, n, 20, 10, &r->spacing) || field_double(s, n, 30, 13, &r->xmin) ||
      field_double(s, n, 43, 13, &r->dx))
    return rfail(R, r, R->c.line, "record 7 is malformed; expected 3I10,3E13.5: data type, "
                 "points, spacing, abscissa minimum, increment, z value");
  if (field_double(s, n, 56, 13, &r->zval)) r->zval = 0.0;
  for (k = 0; k < 4; k++) {
    if (!get_line(&R->c, &s, &n) || is_delim(s, n))
      return rfail(R, r, R->c.line, "truncated: record %d (data characteristics) missing",
                   8 + k);
    field(s, n, 47, 20, r->lab[k], sizeof r->lab[k]);
    if (field_long(s, n, 0, 10, &r->spec[k]))
      return rfail(R, r, R->c.line, "record %d is malformed; expected I10,3I5,2(1X,20A1) "
                   "starting with the specific data type", 8 + k);
  }
  return RCB_OK;
}

/* The data form: complex, a sane count and spacing. */
static rcb_status check_form(uff_reader *R, uff_rec *r) {
  size_t line = r->line + 7;
  r->real = r->ord_type == 2 || r->ord_type == 4;
  if (R->on_time && !r->real)
    return rfail(R, r, line, "time record with ordinate data type %ld; expected real data (2 "
                 "single or 4 double precision)", r->ord_type);
  if (r->real && !R->on_time)
    return rfail(R, r, line, "ordinate data type %ld is real; expected complex (5 single or 6 "
                 "double precision)", r->ord_type);
  if (!r->real && r->ord_type != 5 && r->ord_type != 6)
    return rfail(R, r, line, "unknown ordinate data type %ld; expected 5 or 6 (complex)",
                 r->ord_type);
  if (r->npts < 1)
    return rfail(R, r, line, "number of points %ld; expected at least 1", r->npts);
  { /* before allocating: can the bytes left hold that many values? (a value
     * takes at least 2 bytes in ASCII, 4 in binary) */
    size_t per = r->real ? (r->spacing ? 1u : 2u) : (r->spacing ? 2u : 3u);
    size_t least = r->binary ? 4u : 2u, left = R->c.len - R->c.pos;
    size_t cap = left / (per * least);
    r->claimed = r->npts;
    if (R->on_time && !r->binary && cap > 0 && (r->npts > 100000000L || (size_t)r->npts > cap))
      r->npts = (long)(cap < 100000000u ? cap : 100000000u); /* read to its '-1' (read_ascii) */
    else if (r->npts > 100000000L || (size_t)r->npts > cap)
      return rfail(R, r, line, "record 7 claims %ld points (%zu values), but the %zu bytes "
                   "left in the file hold at most %zu: truncated, or a wrong count", r->npts,
                   (size_t)r->npts * per, left, left / least);
  }
  if (r->spacing != 0 && r->spacing != 1)
    return rfail(R, r, line, "abscissa spacing %ld; expected 0 (uneven) or 1 (even)",
                 r->spacing);
  if (r->spacing == 1 && (!isfinite(r->xmin) || !isfinite(r->dx)))
    return rfail(R, r, line, "abscissa minimum/increment not finite");
  if (r->spacing == 1 && r->npts > 1 && !(r->dx > 0.0))
    return rfail(R, r, line, "abscissa increment %g; expected > 0 (increasing frequencies)",
                 r->dx);
  return RCB_OK;
}

/* Store value k of the record's value stream (ASCII or binary). */
static void put_value(uff_rec *r, size_t k, double v) {
  if (r->real && r->spacing == 1) {
    r->y[k] = CMPLX(v, 0.0);
  } else if (r->real) { /* uneven: abscissa and value pairs */
    if (k % 2 == 0)
      r->x[k / 2] = v;
    else
      r->y[k / 2] = CMPLX(v, 0.0);
  } else if (r->spacing == 1) {
    if (k % 2 == 0)
      r->y[k / 2] = CMPLX(v, cimag(r->y[k / 2]));
    else
      r->y[k / 2] = CMPLX(creal(r->y[k / 2]), v);
  } else if (k % 3 == 0) {
    r->x[k / 3] = v;
  } else if (k % 3 == 1) {
    r->y[k / 3] = CMPLX(v, cimag(r->y[k / 3]));
  } else {
    r->y[k / 3] = CMPLX(creal(r->y[k / 3]), v);
  }
}

/* ASCII values: fixed-width fields per the case of the data form. */
static rcb_status read_ascii(uff_reader *R, uff_rec *r) {
  static const size_t w_single[] = {13, 13, 13, 13, 13, 13};
  static const size_t w_even[] = {20, 20, 20, 20};
  static const size_t w_uneven[] = {13, 20, 20};
  static const size_t w_uneven_real[] = {13, 20, 13, 20}; /* 2(E13.5,E20.12) */
  int single = r->ord_type == 5 || r->ord_type == 2;
  const size_t *w = single                      ? w_single
                    : r->spacing                ? w_even
                    : r->real                   ? w_uneven_real
                                                : w_uneven;
  size_t nw = single ? 6 : r->spacing || r->real ? 4 : 3;
  size_t need = (size_t)r->npts * (r->real ? (r->spacing ? 1 : 2) : r->spacing ? 2 : 3), k = 0;
  const char *s;
  size_t n;
  while (k < need) {
    size_t j, at = 0;
    if (!get_line(&R->c, &s, &n) || is_delim(s, n)) {
      size_t per = need / (size_t)r->npts;
      /* a time record cut short (an excerpt of a long recording, as pyuff's
       * dataset_milestone_in_header.uff): its whole samples, the count that
       * record 7 claims kept for the caller to refuse or allow (issue #35) */
      if (R->on_time && k > 0 && k % per == 0) {
        r->npts = (long)(k / per);
        return RCB_OK;
      }
      return rfail(R, r, R->c.line, "truncated: %zu of %zu values (%ld points) before %s",
                   k, need, r->claimed, R->c.pos >= R->c.len ? "the end of the file" : "'-1'");
    }
    for (j = 0; j < nw && at < n && k < need; at += w[j], j++) {
      double v;
      char f[64];
      field(s, n, at, w[j], f, sizeof f);
      if (!f[0]) break;
      if (field_double(s, n, at, w[j], &v))
        return rfail(R, r, R->c.line, "value '%s' (columns %zu-%zu) is not a number", f,
                     at + 1, at + w[j]);
      if (!isfinite(v))
        return rfail(R, r, R->c.line, "value %zu of %zu is '%s': not finite; expected finite "
                     "numbers",
                     k + 1, need, f);
      put_value(r, k++, v);
    }
  }
  if (!get_line(&R->c, &s, &n) || !is_delim(s, n))
    return rfail(R, r, R->c.line, "more values than the %ld points of record 7, or no "
                 "closing '-1'", r->npts);
  return RCB_OK;
}

static double get_real(const unsigned char *p, size_t size, int big) {
  uint64_t u = 0;
  size_t i;
  for (i = 0; i < size; i++) u |= (uint64_t)p[big ? size - 1 - i : i] << (8 * i);
  if (size == 8) {
    double d;
    memcpy(&d, &u, 8);
    return d;
  } else {
    uint32_t u32 = (uint32_t)u;
    float f;
    memcpy(&f, &u32, 4);
    return (double)f;
  }
}

static rcb_status read_binary(uff_reader *R, uff_rec *r) {
  size_t vs = r->ord_type == 6 || r->ord_type == 4 ? 8 : 4, n = (size_t)r->npts, xs = vs, k;
  size_t need, off, count;
  const unsigned char *p = (const unsigned char *)R->c.buf + R->c.pos;
  const char *s;
  size_t ln;
  if (r->byte_order != 1 && r->byte_order != 2)
    return rfail(R, r, r->line, "58b byte ordering %d; expected 1 (little) or 2 (big endian)",
                 r->byte_order);
  if (r->fp_format != 2 && r->fp_format != 0)
    return rfail(R, r, r->line, "58b floating-point format %d; only 2 (IEEE 754) is "
                 "supported", r->fp_format);
  if (r->spacing == 0 && r->n_bytes == (long)(n * (4 + 2 * vs))) xs = 4;
  if (r->real && r->spacing == 0) xs = r->n_bytes == (long)(n * (4 + vs)) ? 4 : vs;
  need = r->real ? (r->spacing ? n * vs : n * (xs + vs))
                 : r->spacing ? 2 * n * vs : n * (xs + 2 * vs);
  count = r->real ? (r->spacing ? n : 2 * n) : r->spacing ? 2 * n : 3 * n;
  if (R->c.len - R->c.pos < need)
    return rfail(R, r, R->c.line, "truncated binary data: %zu bytes in the file, %zu needed "
                 "for %zu points", R->c.len - R->c.pos, need, n);
  for (k = 0, off = 0; k < count; k++) {
    size_t sz = r->spacing == 0 && k % (r->real ? 2 : 3) == 0 ? xs : vs;
    double v = get_real(p + off, sz, r->byte_order == 2);
    off += sz;
    if (!isfinite(v))
      return rfail(R, r, R->c.line, "binary value %zu of %zu is not finite; expected finite "
                   "numbers", k + 1, count);
    put_value(r, k, v);
  }
  /* the data may contain '\n' bytes: count lines past it for later messages */
  for (k = 0; k < need; k++)
    if (p[k] == '\n') R->c.line++;
  R->c.pos += need;
  /* "    -1" follows at once (or after an end of line) */
  while (R->c.pos < R->c.len && (R->c.buf[R->c.pos] == '\r' || R->c.buf[R->c.pos] == '\n')) {
    if (R->c.buf[R->c.pos] == '\n') R->c.line++;
    R->c.pos++;
  }
  if (!get_line(&R->c, &s, &ln) || !is_delim(s, ln))
    return rfail(R, r, R->c.line, "binary data (%zu bytes for %zu points) not followed by "
                 "'-1': the byte count does not match record 7", need, n);
  return RCB_OK;
}

/* Abscissa of an evenly spaced record; then check all of it. */
static rcb_status check_abscissa(uff_reader *R, uff_rec *r) {
  size_t i, n = (size_t)r->npts;
  if (r->spacing == 1)
    for (i = 0; i < n; i++) r->x[i] = r->xmin + (double)i * r->dx;
  for (i = 0; i < n; i++) {
    if (!isfinite(r->x[i]) || r->x[i] < 0.0)
      return rfail(R, r, r->line + 12, "abscissa point %zu is %g; expected frequencies >= 0",
                   i + 1, r->x[i]);
    if (i > 0 && !(r->x[i] > r->x[i - 1]))
      return rfail(R, r, r->line + 12, "abscissa not increasing: point %zu (%.9g) after "
                   "point %zu (%.9g); expected strictly increasing frequencies", i + 1,
                   r->x[i], i, r->x[i - 1]);
  }
  return RCB_OK;
}

/* The 58/58b id line: binary fields (I6,1A1,I6,I6,I12,I12,...). */
static void parse_id(const char *s, size_t n, uff_rec *r) {
  long v;
  r->binary = n > 6 && (s[6] == 'b' || s[6] == 'B');
  if (!r->binary) return;
  r->byte_order = field_long(s, n, 7, 6, &v) ? 0 : (int)v;
  r->fp_format = field_long(s, n, 13, 6, &v) ? 0 : (int)v;
  r->n_bytes = field_long(s, n, 31, 12, &v) ? -1 : v;
}

/* Skip the values of a record we do not use (e.g. coherence): up to the
 * closing "-1" (in binary data, "    -1" followed by an end of line). */
static void skip_values(uff_reader *R, const uff_rec *r) {
  cursor *c = &R->c;
  if (!r->binary) {
    skip_dataset(c);
    return;
  }
  while (c->pos + 6 <= c->len) {
    if (memcmp(c->buf + c->pos, "    -1", 6) == 0 &&
        (c->pos + 6 == c->len || c->buf[c->pos + 6] == '\n' || c->buf[c->pos + 6] == '\r')) {
      const char *s;
      size_t n;
      get_line(c, &s, &n);
      return;
    }
    if (c->buf[c->pos] == '\n') c->line++;
    c->pos++;
  }
  c->pos = c->len;
}

/* Read one record after its id line (values into r->x, r->y); *used = 0
 * for function types other than FRF (4) and general (1), skipped. */
static rcb_status read_record(uff_reader *R, uff_rec *r, int *used) {
  rcb_status st;
  *used = 0;
  int is_time;
  if ((st = read_headers(R, r))) return st;
  is_time = r->func_type == 1 && r->spec[0] == 17;
  if (R->on_time ? !is_time : (r->func_type != 4 && (r->func_type != 1 || is_time))) {
    if (R->nskip++ == 0) {
      R->skip_index = r->index;
      R->skip_type = r->func_type;
      R->skip_abscissa = r->spec[0];
    }
    skip_values(R, r);
    return RCB_OK;
  }
  *used = 1;
  if ((st = check_form(R, r))) return st;
  r->x = rcb_alloc(&R->ms->alloc, (size_t)r->npts * sizeof *r->x);
  r->y = rcb_alloc(&R->ms->alloc, (size_t)r->npts * sizeof *r->y);
  if (!r->x || !r->y)
    return rcb_meas_fail(R->ms, RCB_ERR_NOMEM, "%s: out of memory (%ld points)", R->path,
                         r->npts);
  st = r->binary ? read_binary(R, r) : read_ascii(R, r);
  return st || R->on_time ? st : check_abscissa(R, r);
}

/* ---- record -> channel ---- */

static rcb_status dir_name(uff_reader *R, const uff_rec *r, long code, const char *what,
                           const char **name) {
  static const char *const names[] = {"x", "y", NULL, "rx", "ry"};
  long a = code < 0 ? -code : code;
  if (a == 1 || a == 2 || a == 4 || a == 5) {
    *name = names[a - 1];
    return RCB_OK;
  }
  return rfail(R, r, r->line + 6, "unknown %s direction code %ld; expected 1, 2, 4, 5 (x, y, "
               "rx, ry translations/rotations) or their negatives", what, code);
}

static void station_of(const uff_reader *R, long node, char *buf, size_t size) {
  size_t i;
  for (i = 0; i < R->nmap; i++) /* a node entry: direction entries name one channel */
    if (R->map[i].node == node && R->map[i].station && !R->map[i].dir) {
      snprintf(buf, size, "%s", R->map[i].station);
      return;
    }
  snprintf(buf, size, "#%ld", node);
}

/* Kind from the ordinate numerator/denominator types (records 9, 10). */
static rcb_status record_kind(uff_reader *R, const uff_rec *r, int frf, rcb_frf_kind *kind) {
  if (!frf) {
    if (r->spec[1] != 8)
      return rfail(R, r, r->line + 9, "unbalance response (function type 1): ordinate data "
                   "type %ld; expected 8 (displacement)", r->spec[1]);
    *kind = RCB_RECEPTANCE;
    return RCB_OK;
  }
  switch (r->spec[1]) {
    case 8: *kind = RCB_RECEPTANCE; break;
    case 11: *kind = RCB_MOBILITY; break;
    case 12: *kind = RCB_INERTANCE; break;
    default:
      return rfail(R, r, r->line + 9, "FRF ordinate data type %ld: wrong units; expected 8 "
                   "(displacement), 11 (velocity) or 12 (acceleration) over force", r->spec[1]);
  }
  if (r->spec[2] != 13)
    return rfail(R, r, r->line + 10, "FRF ordinate denominator data type %ld: wrong units; "
                 "expected 13 (excitation force)", r->spec[2]);
  return RCB_OK;
}

/* Dataset 164 (units): record 1 I10,20A1,I10 (units code, description,
 * temperature mode), record 2 3D25.17 (length, force, temperature factors:
 * file value / factor = SI). Without record 2, the factors of the units code
 * (1 SI, 2 BG, 3 MG, 4 BA, 5 MM, 6 CM, 7 IN, 8 GM). A malformed 164 is
 * remembered and refused only if a record it would scale is read. */
static void bad_164(uff_reader *R, size_t line, const char *what) { /* remember it */
  snprintf(R->err164, sizeof R->err164, "%s:%zu: dataset 164 (units): %s", R->path, line, what);
  R->has164 = -1;
}

static void read_164(uff_reader *R) {
  static const double code_lf[] = {1.0, 3.280839895013123, 1.0, 3.280839895013123, 1000.0,
                                   100.0, 39.37007874015748, 1000.0};
  static const double code_ff[] = {1.0, 0.2248089430997105, 0.10197162129779283,
                                   7.233013851209894, 1000.0, 100.0, 0.2248089430997105,
                                   0.10197162129779283};
  const char *s;
  size_t n;
  long code;
  R->line164 = R->c.line;
  if (!get_line(&R->c, &s, &n) || is_delim(s, n)) {
    bad_164(R, R->c.line, "record 1 missing; expected I10 units code");
    return; /* the dataset's "-1" (or the end) is consumed */
  }
  if (field_long(s, n, 0, 10, &code)) {
    bad_164(R, R->c.line, "record 1 malformed; expected I10 units code");
    skip_dataset(&R->c);
    return;
  }
  if (get_line(&R->c, &s, &n) && !is_delim(s, n)) {
    if (field_double(s, n, 0, 25, &R->lf) || field_double(s, n, 25, 25, &R->ff) ||
        !(R->lf > 0.0) || !(R->ff > 0.0) || !isfinite(R->lf) || !isfinite(R->ff)) {
      bad_164(R, R->c.line, "record 2 malformed; expected 3D25.17 length, force and "
              "temperature factors > 0");
      skip_dataset(&R->c);
      return;
    }
    skip_dataset(&R->c);
  } else if (code >= 1 && code <= 8) {
    R->lf = code_lf[code - 1];
    R->ff = code_ff[code - 1];
  } else {
    bad_164(R, R->line164 + 1, "units code without factors; expected code 1-8 or record 2 "
            "with the factors");
    return;
  }
  R->has164 = 1;
}

static int no_label(const char *lab) { return !lab[0] || strcmp(lab, "NONE") == 0; }

/* Factor to SI of record 9 (k = 1) or 10 (k = 2), whose data type says
 * quantity @p want: from its units label, or dataset 164, or 1 (SI). */
static rcb_status unit_factor(uff_reader *R, const uff_rec *r, int k, rcb_quantity want,
                              double *f) {
  double f164 = 1.0, fl = 1.0;
  rcb_quantity q;
  const char *lab = r->lab[k];
  if (R->has164 < 0) return rcb_meas_fail(R->ms, RCB_ERR_PARSE, "%s", R->err164);
  if (R->has164) f164 = want == RCB_QTY_FORCE ? 1.0 / R->ff : 1.0 / R->lf;
  *f = f164;
  if (no_label(lab)) return RCB_OK;
  if (rcb_unit_parse(lab, &q, &fl)) {
    char known[200];
    rcb_unit_list(want, known, sizeof known);
    return rcb_meas_fail(R->ms, RCB_ERR_PARSE, "%s:%zu: dataset 58 record %zu: record %d "
                         "units label '%s' is not a unit librcb knows; expected %s (%s) or "
                         "NONE", R->path, r->line + 8 + (size_t)k, r->index, 8 + k, lab,
                         rcb_quantity_name(want), known);
  }
  if (q != want)
    return rcb_meas_fail(R->ms, RCB_ERR_PARSE, "%s:%zu: dataset 58 record %zu: record %d "
                         "units label '%s' is %s %s, but its data type %ld says %s; fix the "
                         "label or the data type", R->path, r->line + 8 + (size_t)k, r->index,
                         8 + k, lab, q == RCB_QTY_ACCELERATION ? "an" : "a",
                         rcb_quantity_name(q), r->spec[k], rcb_quantity_name(want));
  if (R->has164 && fabs(fl - f164) > 1e-6 * fl)
    return rcb_meas_fail(R->ms, RCB_ERR_PARSE, "%s:%zu: dataset 58 record %zu: record %d "
                         "units label '%s' (%.9g SI) disagrees with dataset 164 at line %zu "
                         "(%.9g SI per file unit); fix one of them", R->path,
                         r->line + 8 + (size_t)k, r->index, 8 + k, lab, fl, R->line164, f164);
  *f = fl;
  return RCB_OK;
}

/* File value -> SI for the record's ordinate (numerator over denominator). */
static rcb_status unit_scale(uff_reader *R, const uff_rec *r, int frf, rcb_frf_kind kind,
                             double *scale) {
  double fn = 1.0, fd = 1.0;
  rcb_status st;
  if ((st = unit_factor(R, r, 1, (rcb_quantity)(RCB_QTY_DISPLACEMENT + (int)kind), &fn)))
    return st;
  if (frf && (st = unit_factor(R, r, 2, RCB_QTY_FORCE, &fd))) return st;
  *scale = fn / fd;
  return RCB_OK;
}

/* Collected channels of accepted records. */
typedef struct uff_set {
  size_t n, cap;
  struct uff_chan {
    char resp[RCB_MEAS_CH_MAX], ref[RCB_MEAS_CH_MAX];
    rcb_frf_kind kind;
    rcb_complex *y;
    size_t index, line;
  } *ch;
  int type; /* -1 until the first record */
  size_t npts;
  double *x; /* Hz or rpm, owned */
  double scale; /* to rad/s */
  double speed; /* rad/s */
  long ztype;   /* z axis data type of the first record (19: speed in rpm) */
  size_t first_index, first_line;
  size_t ndirskip; /* records skipped for a direction the model has no channel for */
  char dirskip[200]; /* the first of them, for the message when nothing is left */
} uff_set;

/* The channel of a record's response (k = 0) or reference (k = 1) into
 * out: a direction entry of the map ("1.z=DA.x", "3.s=DB.y") names it in any
 * direction; else x, y, rx, ry at the node's station (or "#N"). An axial (3),
 * torsional (6) or scalar (0) direction without a direction entry has no model
 * channel: the record is skipped (*skipped = 1) with a warning that names the
 * entry that would read it, not fatal (issue #25: one axial channel refused a
 * whole 4-channel file; issue #35: vendors export an accelerometer's own z). */
static rcb_status chan_name(uff_reader *R, uff_set *S, const uff_rec *r, int k, char *out,
                            size_t size, int *skipped) {
  static const char *const why[] = {"scalar (direction 0)", NULL, NULL, "axial (direction 3, z)",
                                    NULL, NULL, "torsional (direction 6, rz)"};
  long node = k ? r->ref_node : r->rsp_node, code = k ? r->ref_dir : r->rsp_dir;
  long a = code < 0 ? -code : code;
  const rcb_uff_node *e = rcb_uff_map_find(R->nmap, R->map, node, code);
  const char *dir = NULL, *name = rcb_uff_dir_name(code);
  char st[RCB_MEAS_CH_MAX];
  rcb_status status;
  *skipped = 0;
  if (e && e->dir) {
    snprintf(out, size, "%s.%s", e->station, e->model_dir);
    return RCB_OK;
  }
  if (a <= 6 && why[a]) {
    const char *station = e ? e->station : "STATION";
    *skipped = 1;
    if (S->ndirskip++ == 0)
      snprintf(S->dirskip, sizeof S->dirskip, "%zu: dataset 58 record %zu: its %s is %s",
               r->line + 6, r->index, k ? "reference" : "response", why[a]);
    return rcb_meas_warn(R->ms, "%s:%zu: dataset 58 record %zu: skipped: its %s (node %ld) is "
                         "%s; the model's channels are x, y, rx, ry: the map entry %ld.%s=%s.DIR "
                         "(DIR one of them; rcbtool --map) would read it", R->path, r->line + 6,
                         r->index, k ? "reference" : "response", node, why[a], node, name,
                         station);
  }
  if ((status = dir_name(R, r, code, k ? "reference" : "response", &dir))) return status;
  station_of(R, node, st, sizeof st);
  snprintf(out, size, "%.*s.%s", (int)(size - 4), st, dir);
  return RCB_OK;
}

static rcb_status match_first(uff_reader *R, uff_set *S, const uff_rec *r, int type,
                              double scale, double speed) {
  size_t i, n = (size_t)r->npts;
  double tol;
  if (type != S->type)
    return rfail(R, r, r->line + 6, "function type %ld (%s) in a file whose record %zu is %s; "
                 "expected all FRFs or all unbalance responses", r->func_type,
                 type == RCB_MEAS_FRF ? "FRF" : "unbalance response", S->first_index,
                 S->type == RCB_MEAS_FRF ? "an FRF" : "an unbalance response");
  if (n != S->npts)
    return rfail(R, r, r->line + 7, "%zu points, record %zu has %zu: mismatched lengths; all "
                 "records must share one abscissa", n, S->first_index, S->npts);
  if (scale != S->scale)
    return rfail(R, r, r->line + 8, "abscissa unit differs from record %zu (Hz vs rpm)",
                 S->first_index);
  tol = 1e-9 * fabs(S->x[n - 1]);
  for (i = 0; i < n; i++)
    if (fabs(r->x[i] - S->x[i]) > tol)
      return rfail(R, r, r->line + 7, "abscissa differs from record %zu at point %zu (%.9g "
                   "vs %.9g); all records must share one abscissa", S->first_index, i + 1,
                   r->x[i], S->x[i]);
  if (type == RCB_MEAS_FRF && speed != S->speed)
    return rfail(R, r, r->line + 7, "rotor speed (z value, rpm) %g differs from record %zu",
                 r->zval, S->first_index);
  return RCB_OK;
}

static rcb_status accept(uff_reader *R, uff_set *S, uff_rec *r) {
  int frf = r->func_type == 4;
  int type = frf ? RCB_MEAS_FRF : RCB_MEAS_UNBALANCE;
  char ch_r[RCB_MEAS_CH_MAX], ch_f[RCB_MEAS_CH_MAX] = "";
  double scale, speed = 0.0, uscale = 1.0;
  rcb_frf_kind kind = RCB_RECEPTANCE;
  rcb_status st;
  struct uff_chan *c;
  size_t i;
  int skipped = 0;
  if (!frf && r->ref_node != 0)
    return rfail(R, r, r->line + 6, "function type 1 with reference node %ld: read as an "
                 "unbalance response, which needs reference node 0", r->ref_node);
  if ((st = chan_name(R, S, r, 0, ch_r, sizeof ch_r, &skipped)) || skipped) return st;
  if (frf && ((st = chan_name(R, S, r, 1, ch_f, sizeof ch_f, &skipped)) || skipped)) return st;
  if ((st = record_kind(R, r, frf, &kind))) return st;
  if ((st = unit_scale(R, r, frf, kind, &uscale))) return st;
  if (r->spec[0] == 19) {
    scale = RCB_PI / 30.0;
  } else if (r->spec[0] == 18 || r->spec[0] == 0) {
    scale = 2.0 * RCB_PI;
  } else {
    return rfail(R, r, r->line + 8, "abscissa data type %ld; expected 18 (frequency, Hz) or "
                 "19 (rpm)", r->spec[0]);
  }
  if (frf && r->spec[3] == 19) speed = r->zval < 0.0 ? -1.0 : r->zval * RCB_PI / 30.0;
  if (S->type < 0) {
    S->type = type;
    S->npts = (size_t)r->npts;
    S->x = r->x;
    r->x = NULL;
    S->scale = scale;
    S->speed = speed;
    S->ztype = r->spec[3];
    S->first_index = r->index;
    S->first_line = r->line;
  } else if ((st = match_first(R, S, r, type, scale, speed))) {
    return st;
  }
  if (rcb_grow(&R->ms->alloc, (void **)&S->ch, &S->cap, S->n + 1, sizeof *S->ch))
    return rcb_meas_fail(R->ms, RCB_ERR_NOMEM, "%s: out of memory", R->path);
  c = &S->ch[S->n++];
  memcpy(c->resp, ch_r, sizeof c->resp);
  memcpy(c->ref, ch_f, sizeof c->ref);
  c->kind = kind;
  c->index = r->index;
  c->line = r->line;
  c->y = r->y;
  r->y = NULL;
  if ((r->rsp_dir < 0) != (frf && r->ref_dir < 0)) uscale = -uscale;
  if (uscale != 1.0)
    for (i = 0; i < S->npts; i++) c->y[i] *= uscale;
  return RCB_OK;
}

static rcb_status scan(uff_reader *R, uff_set *S);

/* Direction suffix of a time record's channel: x, y, rx, ry as the model
 * names them, z and rz for the axial and torsional directions (the caller
 * decides what it can use), "" for 0 (scalar). */
static rcb_status time_dir(uff_reader *R, const uff_rec *r, const char **dir) {
  static const char *const names[] = {"", "x", "y", "z", "rx", "ry", "rz"};
  long a = r->rsp_dir < 0 ? -r->rsp_dir : r->rsp_dir;
  if (a > 6)
    return rfail(R, r, r->line + 6, "unknown response direction code %ld; expected 0 "
                 "(scalar) or 1 to 6 (x, y, z, rx, ry, rz) or their negatives", r->rsp_dir);
  *dir = names[a];
  return RCB_OK;
}

/* Quantity and factor to SI of a time record: from the ordinate data type
 * (8, 11, 12 motion; 9, 13 force; 15, 21 pressure) checked against the
 * label, or else from the label. A label librcb does not know is left to the
 * caller (t->label_unknown: values in file units). */
static rcb_status time_units(uff_reader *R, const uff_rec *r, rcb_uff_time_rec *t, double *f) {
  static const long motion[] = {8, 11, 12};
  rcb_quantity want = RCB_QTY_UNKNOWN, q = RCB_QTY_UNKNOWN;
  double fl = 1.0;
  size_t i;
  for (i = 0; i < 3; i++)
    if (r->spec[1] == motion[i]) want = (rcb_quantity)(RCB_QTY_DISPLACEMENT + (int)i);
  if (r->spec[1] == 9 || r->spec[1] == 13) want = RCB_QTY_FORCE;
  if (r->spec[1] == 15 || r->spec[1] == 21) want = RCB_QTY_PRESSURE;
  snprintf(t->label, sizeof t->label, "%s", r->lab[1]);
  t->spec = r->spec[1];
  *f = 1.0;
  if (!no_label(r->lab[1]) && rcb_unit_parse(r->lab[1], &q, &fl)) {
    t->label_unknown = 1;
    t->q = want;
    return RCB_OK;
  }
  if (want != RCB_QTY_UNKNOWN && want != RCB_QTY_PRESSURE) {
    rcb_status st = unit_factor(R, r, 1, want, f);
    if (st) return st;
  } else if (!no_label(r->lab[1])) {
    if (want == RCB_QTY_PRESSURE && q != want)
      return rfail(R, r, r->line + 9, "record 9 units label '%s' is %s, but its data type %ld "
                   "says pressure; fix the label or the data type", r->lab[1],
                   rcb_quantity_name(q), r->spec[1]);
    want = q;
    *f = fl;
  }
  t->q = want;
  return RCB_OK;
}

/* A time record (function type 1, abscissa time): channel "STATION.DIR" (or
 * the station alone for direction 0), quantity and units (time_units),
 * values to SI, then handed to the caller, which decides what it uses. */
static rcb_status accept_time(uff_reader *R, uff_rec *r) {
  rcb_uff_time_rec t;
  const rcb_uff_node *e;
  char st_r[RCB_MEAS_CH_MAX];
  const char *dir = "";
  double f = 1.0;
  size_t i;
  rcb_status st;
  memset(&t, 0, sizeof t);
  if ((st = time_units(R, r, &t, &f)) || (st = time_dir(R, r, &dir))) return st;
  e = rcb_uff_map_find(R->nmap, R->map, r->rsp_node, r->rsp_dir);
  station_of(R, r->rsp_node, st_r, sizeof st_r);
  if (e && e->dir) /* "1.z=DA.x": the model channel it stands for (issue #35) */
    snprintf(t.name, sizeof t.name, "%s.%s", e->station, e->model_dir);
  else if (dir[0])
    snprintf(t.name, sizeof t.name, "%.*s.%s", (int)(sizeof t.name - 4), st_r, dir);
  else
    snprintf(t.name, sizeof t.name, "%s", st_r);
  t.node = r->rsp_node;
  t.dir = r->rsp_dir;
  if (r->rsp_dir < 0) f = -f;
  for (i = 0; i < (size_t)r->npts; i++) r->y[i] *= f;
  t.t0 = r->xmin;
  t.dt = r->dx;
  if (r->spacing == 0 && r->npts > 1) { /* times listed (pyuff): evenly spaced? */
    size_t n = (size_t)r->npts;
    t.t0 = r->x[0];
    t.dt = (r->x[n - 1] - r->x[0]) / (double)(n - 1);
    for (i = 0; i < n; i++)
      if (!(fabs(r->x[i] - (t.t0 + (double)i * t.dt)) <= 0.1 * t.dt))
        return rcb_meas_fail(R->ms, RCB_ERR_PARSE, "%s:%zu: dataset 58 record %zu: time %zu "
                             "is %.9g s, expected %.9g s: the samples must be evenly spaced "
                             "(a dropped sample?)", R->path, r->line + 12, r->index, i + 1,
                             r->x[i], t.t0 + (double)i * t.dt);
  }
  t.n = (size_t)r->npts;
  t.claimed = r->claimed > r->npts ? (size_t)r->claimed : 0;
  t.y = r->y;
  t.index = r->index;
  t.line = r->line;
  R->ntime++;
  return R->on_time(R->user, &t);
}

/* ", and record N is function type T (...)" for a read that found nothing. */
static void skipped_text(const uff_reader *R, char *buf, size_t size) {
  char what[300];
  buf[0] = '\0';
  if (!R->nskip) return;
  rcb_uff_function_text(R->skip_type, R->skip_abscissa, what, sizeof what);
  snprintf(buf, size, "; record %zu is %s%s", R->skip_index, what,
           R->nskip > 1 ? " (the first of the records skipped)" : "");
}

/* A reader over the file's bytes buf[0 .. len) and an empty set of records. */
static void reader_init(uff_reader *R, uff_set *S, rcb_meas *ms, const char *path,
                        const char *buf, size_t len, size_t nmap, const rcb_uff_node *map) {
  memset(R, 0, sizeof *R);
  memset(S, 0, sizeof *S);
  S->type = -1;
  R->ms = ms;
  R->path = path;
  R->c.buf = buf;
  R->c.len = len;
  R->nmap = nmap;
  R->map = map;
}

rcb_status rcb_uff58_read_time(rcb_meas *ms, const char *path, size_t nmap,
                               const rcb_uff_node *map, rcb_uff_time_fn fn, void *user) {
  uff_reader R;
  uff_set S;
  char *buf = NULL;
  size_t len;
  rcb_status st;
  if (!ms || !fn) return RCB_ERR_ARG;
  if ((st = rcb_meas_check_map(ms, "read_uff", nmap, map))) return st;
  if ((st = rcb_meas_slurp(ms, path, &buf, &len))) return st;
  reader_init(&R, &S, ms, path, buf, len, nmap, map);
  R.on_time = fn;
  R.user = user;
  st = scan(&R, &S);
  if (!st && R.ntime == 0) {
    char why[360];
    skipped_text(&R, why, sizeof why);
    st = rcb_meas_fail(ms, RCB_ERR_PARSE, "%s: no dataset 58 time record (function type 1, "
                       "abscissa data type 17)%s", path, why);
  }
  rcb_free(&ms->alloc, buf);
  return st;
}

/* Skip a dataset other than 58 up to its closing "-1". */
static void skip_dataset(cursor *c) {
  const char *s;
  size_t n;
  while (get_line(c, &s, &n))
    if (is_delim(s, n)) return;
}

static rcb_status scan(uff_reader *R, uff_set *S) {
  const char *s;
  size_t n, count = 0;
  rcb_status st = RCB_OK;
  while (!st && get_line(&R->c, &s, &n)) {
    uff_rec r;
    long id;
    int used, got;
    if (n == 0 || !is_delim(s, n)) {
      char f[8];
      field(s, n, 0, n, f, sizeof f);
      if (!f[0]) continue;
      return rcb_meas_fail(R->ms, RCB_ERR_PARSE, "%s:%zu: expected '    -1' starting a "
                           "dataset, got '%.40s'", R->path, R->c.line, s);
    }
    /* an empty dataset "-1", "-1" (pyuff 2.5 writes one before its 58b records,
     * with no "-1" of its own after it): every "-1" in a row opens the next */
    while ((got = get_line(&R->c, &s, &n)) && is_delim(s, n)) {
    }
    if (!got) break;
    count++;
    if (field_long(s, n, 0, 6, &id))
      return rcb_meas_fail(R->ms, RCB_ERR_PARSE, "%s:%zu: dataset id '%.10s' is not a number",
                           R->path, R->c.line, s);
    if (id == 164) {
      read_164(R);
      continue;
    }
    if (id != 58) {
      skip_dataset(&R->c);
      continue;
    }
    memset(&r, 0, sizeof r);
    r.index = count;
    r.line = R->c.line;
    parse_id(s, n, &r);
    st = read_record(R, &r, &used);
    if (!st && used) st = R->on_time ? accept_time(R, &r) : accept(R, S, &r);
    rcb_free(&R->ms->alloc, r.x);
    rcb_free(&R->ms->alloc, r.y);
  }
  if (!st && S->type < 0 && !R->on_time && S->ndirskip)
    st = rcb_meas_fail(R->ms, RCB_ERR_PARSE, "%s:%s; the model's channels are x, y, rx, ry, "
                       "and all %zu records were skipped so: nothing to read (a map entry "
                       "NODE.DIR=STATION.DIR, e.g. rcbtool --map 1.z=DA.x, reads a channel "
                       "of another direction as a model channel; the warnings name them)",
                       R->path, S->dirskip, S->ndirskip);
  if (!st && S->type < 0 && !R->on_time) {
    char why[360];
    skipped_text(R, why, sizeof why);
    st = rcb_meas_fail(R->ms, RCB_ERR_PARSE, "%s: no dataset 58 record with function type 4 "
                       "(FRF) or 1 (unbalance response) in %zu datasets%s", R->path, count, why);
  }
  return st;
}

static rcb_status build(uff_reader *R, uff_set *S) {
  char where[UFF_WHERE];
  size_t i;
  rcb_status st;
  for (i = 0; i < S->npts; i++) S->x[i] *= S->scale;
  snprintf(where, sizeof where, "%s:%zu: dataset 58 record %zu", R->path, S->first_line,
           S->first_index);
  st = rcb_meas_set_grid_at(R->ms, (rcb_meas_type)S->type, S->npts, S->x, S->speed, where,
                            RCB_ERR_PARSE);
  for (i = 0; i < S->n && !st; i++) {
    struct uff_chan *c = &S->ch[i];
    snprintf(where, sizeof where, "%s:%zu: dataset 58 record %zu", R->path, c->line, c->index);
    st = rcb_meas_add_channel_at(R->ms, c->resp, S->type == RCB_MEAS_FRF ? c->ref : NULL,
                                 c->kind, c->y, where, RCB_ERR_PARSE);
  }
  return st;
}

rcb_status rcb_meas_read_uff(rcb_meas *ms, const char *path, size_t nmap,
                             const rcb_uff_node *map) {
  uff_reader R;
  uff_set S;
  char *buf = NULL;
  size_t len, i;
  rcb_status st;
  if (!ms) return RCB_ERR_ARG;
  if ((st = rcb_meas_check_map(ms, "read_uff", nmap, map))) return st;
  rcb_meas_clear(ms);
  rcb_meas_clear_warnings(ms);
  if ((st = rcb_meas_slurp(ms, path, &buf, &len))) return st;
  reader_init(&R, &S, ms, path, buf, len, nmap, map);
  st = scan(&R, &S);
  if (!st) st = build(&R, &S);
  if (!st) st = rcb_uff_read_warnings(ms, path, nmap, S.ztype);
  if (st) rcb_meas_clear(ms);
  for (i = 0; i < S.n; i++) rcb_free(&ms->alloc, S.ch[i].y);
  rcb_free(&ms->alloc, S.ch);
  rcb_free(&ms->alloc, S.x);
  rcb_free(&ms->alloc, buf);
  return st;
}
