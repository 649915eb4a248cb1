/*
 * CSV measurements, as rcbtool frf / unbalance write them:
 *   # kind = receptance          (optional; FRFs only; default receptance)
 *   # rpm = 3000                 (optional; FRF test speed, or "synchronous")
 *   # phase = lag (keyphasor falling edge)   (optional; lag: the values are the
 *                                 conjugates of the model's, read back to them)
 *   freq_hz,D1.x/C.x re,D1.x/C.x im,...     (FRF, abscissa Hz)
 *   rpm,DA.x amp,DA.x phase_deg,...         (unbalance, abscissa rpm)
 * Per channel two adjacent columns: "re","im", or "mag"/"amp","phase_deg"
 * (degrees). Other "#" lines are comments. Errors name the file, line and
 * column. Other tools' spellings are read too (case, spaces, '_' and a unit
 * in brackets do not matter: "Frequency (Hz)", "frequency_hz", "Speed [rpm]",
 * "DA.x/C.y Real", "DA.x/C.y Phase (deg)", "DA.x/C.y re (m/N)"); a spelling
 * that leaves the unit open (frequency, phase) or a station given as a
 * number is refused with the name to use.
 */
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "io/meas_internal.h"

#define CSV_WHERE 512

typedef enum col_part { COL_RE, COL_IM, COL_MAG, COL_PHASE } col_part;

typedef struct csv_col {
  char name[RCB_MEAS_CH_MAX * 2 + 2]; /* "RESP/REF" or "RESP" */
  col_part part;
} csv_col;

typedef struct csv_state {
  rcb_meas *ms;
  const char *path;
  size_t line;
  int have_header, have_kind, have_rpm;
  rcb_meas_type type;
  rcb_frf_kind kind;
  double speed; /* rad/s, < 0 synchronous */
  rcb_phase_convention phase; /* "# phase = lead|lag (reference)" */
  char phase_ref[84];
  csv_col *cols; /* ncols value columns (after the abscissa) */
  size_t ncols, capcols;
  double *x, *v; /* rows: x[r], v[r * ncols + c] */
  size_t nrows, caprows, capv;
} csv_state;

static char *trim(char *s) {
  char *e;
  while (*s == ' ' || *s == '\t') s++;
  e = s + strlen(s);
  while (e > s && (e[-1] == ' ' || e[-1] == '\t' || e[-1] == '\r')) *--e = '\0';
  if (e - s >= 2 && s[0] == '"' && e[-1] == '"') {
    e[-1] = '\0';
    s++;
  }
  return s;
}

/* Next comma-separated field of *p (modified in place); NULL at the end. */
static char *next_field(char **p) {
  char *s = *p, *c;
  if (!s) return NULL;
  c = strchr(s, ',');
  if (c) {
    *c = '\0';
    *p = c + 1;
  } else {
    *p = NULL;
  }
  return trim(s);
}

static int parse_num(const char *s, double *v) {
  char *end;
  if (!*s) return -1;
  errno = 0;
  *v = rcb_strtod(s, &end); /* strtod, bit for bit (core/numparse.c) */
  return (*end != '\0' || errno == ERANGE) ? -1 : 0;
}

/* "# key = value" before the header. */
static rcb_status comment(csv_state *S, char *text) {
  char *eq = strchr(text, '='), *key, *val;
  if (!eq) return RCB_OK;
  *eq = '\0';
  key = trim(text + 1);
  val = trim(eq + 1);
  if (strcmp(key, "kind") == 0) {
    if (rcb_meas_kind_parse(val, &S->kind))
      return rcb_meas_fail(S->ms, RCB_ERR_PARSE, "%s:%zu: kind '%s': expected receptance, "
                           "mobility or inertance", S->path, S->line, val);
    S->have_kind = 1;
  } else if (strcmp(key, "rpm") == 0) {
    double r;
    if (strcmp(val, "synchronous") == 0) {
      S->speed = -1.0;
    } else if (parse_num(val, &r) || !isfinite(r) || r < 0.0) {
      return rcb_meas_fail(S->ms, RCB_ERR_PARSE, "%s:%zu: rpm '%s': expected a rotor speed "
                           ">= 0 (rpm) or 'synchronous'", S->path, S->line, val);
    } else {
      S->speed = r * RCB_PI / 30.0;
    }
    S->have_rpm = 1;
  } else if (strcmp(key, "phase") == 0) { /* "lead|lag [(reference)]" */
    size_t w = strcspn(val, " \t(");
    char *ref = val + w;
    if ((w != 4 || strncmp(val, "lead", 4) != 0) && (w != 3 || strncmp(val, "lag", 3) != 0))
      return rcb_meas_fail(S->ms, RCB_ERR_PARSE, "%s:%zu: phase '%s': expected lead or lag "
                           "(then the reference in brackets)", S->path, S->line, val);
    S->phase = w == 3 ? RCB_PHASE_LAG : RCB_PHASE_LEAD;
    ref = trim(ref);
    if (*ref == '(' && ref[strlen(ref) - 1] == ')') {
      ref[strlen(ref) - 1] = '\0';
      ref++;
    }
    snprintf(S->phase_ref, sizeof S->phase_ref, "%.80s", ref);
  }
  return RCB_OK;
}

/* Header token folded for comparison: lower case, without ' ', '_', '-' and
 * brackets, so "Frequency (Hz)", "frequency_hz" and "FREQ-HZ" all read
 * "frequencyhz". */
static void fold(const char *s, char *out, size_t size) {
  size_t k = 0;
  for (; *s && k + 1 < size; s++)
    if (!strchr(" _-()[]\t", *s)) out[k++] = (char)tolower((unsigned char)*s);
  out[k] = '\0';
}

static int in_list(const char *s, const char *const *list) {
  for (; *list; list++)
    if (strcmp(s, *list) == 0) return 1;
  return 0;
}

/* First header field: Hz or rpm, under the usual names. */
static rcb_status abscissa(csv_state *S, const char *f) {
  static const char *const hz[] = {"freqhz", "frequencyhz", "fhz", "hz", "frequencyinhz",
                                   NULL};
  static const char *const rpm[] = {"rpm", "speedrpm", "rotorspeedrpm", "nrpm",
                                    "rotationalspeedrpm", "speedinrpm", NULL};
  char g[64];
  fold(f, g, sizeof g);
  if (in_list(g, hz)) {
    S->type = RCB_MEAS_FRF;
    return RCB_OK;
  }
  if (in_list(g, rpm)) {
    S->type = RCB_MEAS_UNBALANCE;
    return RCB_OK;
  }
  if (strstr(g, "rad") || strstr(g, "omega"))
    return rcb_meas_fail(S->ms, RCB_ERR_PARSE, "%s:%zu: first column '%s': an abscissa in "
                         "rad/s is not read; convert it to Hz and name the column freq_hz "
                         "(FRF), or to rpm and name it rpm (unbalance response)", S->path,
                         S->line, f);
  if (strncmp(g, "freq", 4) == 0 || strcmp(g, "f") == 0)
    return rcb_meas_fail(S->ms, RCB_ERR_PARSE, "%s:%zu: first column '%s' gives no unit; "
                         "rename it freq_hz if the values are in Hz", S->path, S->line, f);
  if (strncmp(g, "speed", 5) == 0 || strncmp(g, "rotorspeed", 10) == 0)
    return rcb_meas_fail(S->ms, RCB_ERR_PARSE, "%s:%zu: first column '%s' gives no unit; "
                         "rename it rpm if the values are rotor speeds in rpm", S->path,
                         S->line, f);
  return rcb_meas_fail(S->ms, RCB_ERR_PARSE, "%s:%zu: first column '%s': expected freq_hz "
                       "(FRF, Hz; also read: frequency_hz, \"Frequency (Hz)\", f_hz) or rpm "
                       "(unbalance response; also read: speed_rpm, \"Speed (rpm)\")",
                       S->path, S->line, f);
}

/* A trailing unit in brackets, "(m/N)" or "[deg]": cut off *end, the unit
 * (folded) into unit ("" without one). */
static void cut_unit(const char *f, size_t *end, char *unit, size_t size) {
  size_t n = *end;
  char close;
  unit[0] = '\0';
  while (n > 0 && f[n - 1] == ' ') n--;
  if (n == 0 || (f[n - 1] != ')' && f[n - 1] != ']')) return;
  close = f[n - 1];
  while (n > 0 && f[n - 1] != (close == ')' ? '(' : '[')) n--;
  if (n == 0) return;
  {
    char u[64];
    size_t len = *end - n;
    if (len >= sizeof u) len = sizeof u - 1;
    memcpy(u, f + n, len);
    u[len] = '\0';
    fold(u, unit, size);
  }
  n--;
  while (n > 0 && f[n - 1] == ' ') n--;
  *end = n;
}

/* The part word of a column ("re", "Real", "Phase" + its unit) -> col_part;
 * -1 unknown, -2 a phase whose unit is not degrees. */
static int part_of(const char *word, size_t n, const char *unit) {
  static const char *const re[] = {"re", "real", NULL};
  static const char *const im[] = {"im", "imag", "imaginary", NULL};
  static const char *const mag[] = {"mag", "amp", "abs", "magnitude", "amplitude", NULL};
  char w[32], g[32];
  if (n >= sizeof w) return -1;
  memcpy(w, word, n);
  w[n] = '\0';
  fold(w, g, sizeof g);
  if (in_list(g, re)) return COL_RE;
  if (in_list(g, im)) return COL_IM;
  if (in_list(g, mag)) return COL_MAG;
  if (strcmp(g, "phasedeg") == 0) return COL_PHASE;
  if (strcmp(g, "phase") == 0 || strcmp(g, "ph") == 0)
    return strcmp(unit, "deg") == 0 || strcmp(unit, "degrees") == 0 || strcmp(unit, "\u00b0") == 0
               ? COL_PHASE
               : -2;
  return -1;
}

/* A station written as a number ("3.x/10.y"): a test system's node number,
 * which is not a model station; say what to write instead. */
static rcb_status numeric_station(csv_state *S, const char *name, size_t k) {
  const char *p = name;
  while (p) {
    const char *slash = strchr(p, '/'), *end = slash ? slash : p + strlen(p), *dot = end, *q;
    while (dot > p && dot[-1] != '.') dot--;
    if (dot > p + 1) {
      for (q = p; q < dot - 1 && isdigit((unsigned char)*q); q++) continue;
      if (q == dot - 1)
        return rcb_meas_fail(S->ms, RCB_ERR_PARSE, "%s:%zu: column %zu ('%s'): station '%.*s' "
                             "is a number, not a model station; rename it to the station it "
                             "stands for (e.g. DA; 'rcbtool check' lists them) or to '#%.*s' "
                             "for model node %.*s", S->path, S->line, k + 1, name,
                             (int)(dot - 1 - p), p, (int)(dot - 1 - p), p, (int)(dot - 1 - p),
                             p);
    }
    p = slash ? slash + 1 : NULL;
  }
  return RCB_OK;
}

/* One header field "NAME part" -> column. */
static rcb_status header_col(csv_state *S, const char *f, size_t k) {
  csv_col *c;
  const char *sp;
  char unit[32];
  size_t len, end = strlen(f);
  int part;
  cut_unit(f, &end, unit, sizeof unit);
  for (sp = f + end; sp > f && sp[-1] != ' '; sp--) continue;
  sp = sp > f ? sp - 1 : NULL;
  if (!sp || sp == f)
    return rcb_meas_fail(S->ms, RCB_ERR_PARSE, "%s:%zu: column %zu '%s': expected \"CHANNEL "
                         "re\", \"CHANNEL im\", \"CHANNEL mag\"/\"amp\" or \"CHANNEL "
                         "phase_deg\"", S->path, S->line, k + 1, f);
  if (rcb_grow(&S->ms->alloc, (void **)&S->cols, &S->capcols, S->ncols + 1, sizeof *S->cols))
    return rcb_meas_fail(S->ms, RCB_ERR_NOMEM, "%s: out of memory", S->path);
  c = &S->cols[S->ncols];
  len = (size_t)(sp - f);
  while (len > 0 && f[len - 1] == ' ') len--;
  if (len >= sizeof c->name)
    return rcb_meas_fail(S->ms, RCB_ERR_PARSE, "%s:%zu: column %zu: channel name too long",
                         S->path, S->line, k + 1);
  memcpy(c->name, f, len);
  c->name[len] = '\0';
  part = part_of(sp + 1, (size_t)(f + end - sp - 1), unit);
  if (part == -2)
    return rcb_meas_fail(S->ms, RCB_ERR_PARSE, "%s:%zu: column %zu '%s': a phase without "
                         "the unit degrees; give it in degrees and name the column \"%s "
                         "phase_deg\"", S->path, S->line, k + 1, f, c->name);
  if (part < 0)
    return rcb_meas_fail(S->ms, RCB_ERR_PARSE, "%s:%zu: column %zu '%s': unknown part '%.*s'; "
                         "expected re, im, mag, amp or phase_deg", S->path, S->line, k + 1, f,
                         (int)(f + end - sp - 1), sp + 1);
  c->part = (col_part)part;
  S->ncols++;
  return numeric_station(S, c->name, k);
}

/* Columns come in pairs re+im or mag+phase_deg of one channel. */
static rcb_status check_pairs(csv_state *S) {
  size_t c;
  if (S->ncols == 0)
    return rcb_meas_fail(S->ms, RCB_ERR_PARSE, "%s:%zu: no channel columns after the "
                         "abscissa", S->path, S->line);
  for (c = 0; c < S->ncols; c += 2) {
    csv_col *a = &S->cols[c], *b = c + 1 < S->ncols ? &S->cols[c + 1] : NULL;
    int ok = b && strcmp(a->name, b->name) == 0 &&
             ((a->part == COL_RE && b->part == COL_IM) ||
              (a->part == COL_MAG && b->part == COL_PHASE));
    if (!ok)
      return rcb_meas_fail(S->ms, RCB_ERR_PARSE, "%s:%zu: column %zu ('%s'): expected a pair "
                           "of adjacent columns \"%s re\",\"%s im\" or \"%s mag\",\"%s "
                           "phase_deg\"", S->path, S->line, c + 2, a->name, a->name, a->name,
                           a->name, a->name);
    if ((S->type == RCB_MEAS_FRF) != (strchr(a->name, '/') != NULL))
      return rcb_meas_fail(S->ms, RCB_ERR_PARSE, "%s:%zu: column %zu ('%s'): %s", S->path,
                           S->line, c + 2, a->name,
                           S->type == RCB_MEAS_FRF
                               ? "an FRF channel is RESPONSE/REFERENCE, e.g. DA.x/C.y"
                               : "an unbalance response channel has no /REFERENCE");
  }
  return RCB_OK;
}

static rcb_status header(csv_state *S, char *text) {
  char *p = text, *f = next_field(&p);
  size_t k = 0;
  rcb_status st;
  if ((st = abscissa(S, f))) return st;
  while ((f = next_field(&p)) != NULL)
    if ((st = header_col(S, f, ++k))) return st;
  S->have_header = 1;
  return check_pairs(S);
}

static rcb_status row(csv_state *S, char *text) {
  char *p = text, *f;
  size_t k = 0;
  double val;
  if (rcb_grow(&S->ms->alloc, (void **)&S->x, &S->caprows, S->nrows + 1, sizeof *S->x) ||
      rcb_grow(&S->ms->alloc, (void **)&S->v, &S->capv, (S->nrows + 1) * S->ncols,
               sizeof *S->v))
    return rcb_meas_fail(S->ms, RCB_ERR_NOMEM, "%s: out of memory", S->path);
  while ((f = next_field(&p)) != NULL) {
    const char *what = k == 0 ? (S->type == RCB_MEAS_FRF ? "freq_hz" : "rpm")
                              : S->cols[k <= S->ncols ? k - 1 : 0].name;
    if (k > S->ncols) {
      k++;
      continue;
    }
    if (parse_num(f, &val))
      return rcb_meas_fail(S->ms, RCB_ERR_PARSE, "%s:%zu: column %zu (%s): '%s' is not a "
                           "number", S->path, S->line, k + 1, what, f);
    if (!isfinite(val))
      return rcb_meas_fail(S->ms, RCB_ERR_PARSE, "%s:%zu: column %zu (%s): value '%s' is not "
                           "finite; expected finite numbers", S->path, S->line, k + 1, what, f);
    if (k == 0)
      S->x[S->nrows] = val * (S->type == RCB_MEAS_FRF ? 2.0 * RCB_PI : RCB_PI / 30.0);
    else
      S->v[S->nrows * S->ncols + k - 1] = val;
    k++;
  }
  if (k != S->ncols + 1)
    return rcb_meas_fail(S->ms, RCB_ERR_PARSE, "%s:%zu: %zu fields, the header has %zu; "
                         "every row needs the abscissa and all channel columns", S->path,
                         S->line, k, S->ncols + 1);
  if (S->x[S->nrows] < 0.0 || (S->nrows > 0 && !(S->x[S->nrows] > S->x[S->nrows - 1])))
    return rcb_meas_fail(S->ms, RCB_ERR_PARSE, "%s:%zu: abscissa %s: expected values >= 0, "
                         "strictly increasing from row to row", S->path, S->line,
                         S->x[S->nrows] < 0.0 ? "negative" : "not increasing");
  S->nrows++;
  return RCB_OK;
}

static rcb_status parse_lines(csv_state *S, char *buf) {
  char *line = buf;
  rcb_status st = RCB_OK;
  while (line && !st) {
    char *nl = strchr(line, '\n'), *t;
    if (nl) *nl = '\0';
    S->line++;
    t = trim(line);
    if (t[0] == '#') {
      if (!S->have_header) st = comment(S, t);
    } else if (t[0]) {
      st = S->have_header ? row(S, t) : header(S, t);
    }
    line = nl ? nl + 1 : NULL;
  }
  if (!st && !S->have_header)
    st = rcb_meas_fail(S->ms, RCB_ERR_PARSE, "%s: no header line (freq_hz,... or rpm,...)",
                       S->path);
  if (!st && S->nrows == 0)
    st = rcb_meas_fail(S->ms, RCB_ERR_PARSE, "%s: no data rows after the header", S->path);
  return st;
}

/* Columns -> channels of the container. */
static rcb_status build(csv_state *S) {
  rcb_meas *ms = S->ms;
  rcb_complex *d = rcb_alloc(&ms->alloc, S->nrows * sizeof *d);
  char where[CSV_WHERE];
  size_t c, r;
  rcb_status st;
  if (!d) return rcb_meas_fail(ms, RCB_ERR_NOMEM, "%s: out of memory", S->path);
  if (S->type == RCB_MEAS_UNBALANCE && S->have_kind && S->kind != RCB_RECEPTANCE) {
    rcb_free(&ms->alloc, d);
    return rcb_meas_fail(ms, RCB_ERR_PARSE, "%s: kind = %s, but unbalance responses are "
                         "displacements (receptance)", S->path, rcb_meas_kind_name(S->kind));
  }
  snprintf(where, sizeof where, "%s", S->path);
  st = rcb_meas_set_grid_at(ms, S->type, S->nrows, S->x, S->speed, where, RCB_ERR_PARSE);
  for (c = 0; c < S->ncols && !st; c += 2) {
    char *slash = strchr(S->cols[c].name, '/');
    for (r = 0; r < S->nrows; r++) {
      double a = S->v[r * S->ncols + c], b = S->v[r * S->ncols + c + 1];
      d[r] = S->cols[c].part == COL_RE ? CMPLX(a, b)
                                       : a * CMPLX(cos(b * RCB_PI / 180.0), sin(b * RCB_PI / 180.0));
      if (S->phase == RCB_PHASE_LAG) d[r] = conj(d[r]); /* to the model's lead */
    }
    snprintf(where, sizeof where, "%s: columns %zu-%zu", S->path, c + 2, c + 3);
    if (slash) *slash = '\0';
    st = rcb_meas_add_channel_at(ms, S->cols[c].name, slash ? slash + 1 : NULL,
                                 S->type == RCB_MEAS_FRF ? S->kind : RCB_RECEPTANCE, d, where,
                                 RCB_ERR_PARSE);
  }
  rcb_free(&ms->alloc, d);
  return st;
}

rcb_status rcb_meas_read_csv(rcb_meas *ms, const char *path) {
  csv_state S;
  char *buf = NULL;
  size_t len;
  rcb_status st;
  if (!ms) return RCB_ERR_ARG;
  memset(&S, 0, sizeof S);
  S.ms = ms;
  S.path = path;
  S.kind = RCB_RECEPTANCE;
  rcb_meas_clear(ms);
  rcb_meas_clear_warnings(ms);
  if ((st = rcb_meas_slurp(ms, path, &buf, &len))) return st;
  if (strlen(buf) != len)
    st = rcb_meas_fail(ms, RCB_ERR_PARSE, "%s: contains NUL bytes; expected a text CSV file",
                       path);
  if (!st) st = parse_lines(&S, buf);
  if (!st) st = build(&S);
  if (!st) ms->speed_given = S.type == RCB_MEAS_FRF && S.have_rpm;
  if (!st) rcb_meas_set_phase(ms, S.phase, S.phase_ref);
  if (!st && S.type == RCB_MEAS_FRF && !S.have_rpm) {
    st = rcb_meas_warn(ms, "%s: no '# rpm = R' line before the header: the file does not "
                       "state the test speed, so it reads as 0 rpm; state it (the line, "
                       "rcbtool --rpm R, the model's [test] rpm, rcb_meas_set_speed)", path);
    ms->speed_warning = ms->n_warnings;
  }
  if (st) rcb_meas_clear(ms);
  rcb_free(&ms->alloc, buf);
  rcb_free(&ms->alloc, S.cols);
  rcb_free(&ms->alloc, S.x);
  rcb_free(&ms->alloc, S.v);
  return st;
}

/* ---- writer ---- */

static rcb_status common_kind(rcb_meas *ms, const char *path, rcb_frf_kind *kind) {
  size_t c;
  *kind = ms->nch ? ms->ch[0].kind : RCB_RECEPTANCE;
  for (c = 1; c < ms->nch; c++)
    if (ms->ch[c].kind != *kind)
      return rcb_meas_fail(ms, RCB_ERR_ARG, "%s: channels %s/%s (%s) and %s/%s (%s) differ in "
                           "kind; CSV has one kind line: convert first (rcb_meas_convert)",
                           path, ms->ch[0].resp, ms->ch[0].ref, rcb_meas_kind_name(*kind),
                           ms->ch[c].resp, ms->ch[c].ref, rcb_meas_kind_name(ms->ch[c].kind));
  return RCB_OK;
}

static void write_body(const rcb_meas *ms, FILE *fp, rcb_frf_kind kind) {
  size_t c, i;
  int frf = ms->type == RCB_MEAS_FRF;
  if (frf) {
    fprintf(fp, "# kind = %s\n", rcb_meas_kind_name(kind));
    if (ms->speed < 0.0)
      fputs("# rpm = synchronous\n", fp);
    else
      fprintf(fp, "# rpm = %.17g\n", ms->speed * 30.0 / RCB_PI);
  }
  if (ms->phase != RCB_PHASE_UNSTATED)
    fprintf(fp, "# phase = %s%s%s%s\n", ms->phase == RCB_PHASE_LAG ? "lag" : "lead",
            ms->phase_ref[0] ? " (" : "", ms->phase_ref, ms->phase_ref[0] ? ")" : "");
  fputs(frf ? "freq_hz" : "rpm", fp);
  for (c = 0; c < ms->nch; c++) {
    const rcb_meas_ch *h = &ms->ch[c];
    if (frf)
      fprintf(fp, ",%s/%s re,%s/%s im", h->resp, h->ref, h->resp, h->ref);
    else
      fprintf(fp, ",%s re,%s im", h->resp, h->resp);
  }
  fputc('\n', fp);
  for (i = 0; i < ms->n; i++) {
    fprintf(fp, "%.17g", ms->x[i] * (frf ? 1.0 / (2.0 * RCB_PI) : 30.0 / RCB_PI));
    for (c = 0; c < ms->nch; c++) /* LAG: the conjugate, so arg is the lag */
      fprintf(fp, ",%.17g,%.17g", creal(ms->ch[c].data[i]),
              ms->phase == RCB_PHASE_LAG ? -cimag(ms->ch[c].data[i]) : cimag(ms->ch[c].data[i]));
    fputc('\n', fp);
  }
}

rcb_status rcb_meas_write_csv(const rcb_meas *cms, const char *path) {
  /* The error message is the object's only mutable state on a write. */
  rcb_meas *ms = (rcb_meas *)(uintptr_t)cms;
  rcb_atomic_file af;
  rcb_frf_kind kind;
  rcb_status st;
  if (!ms) return RCB_ERR_ARG;
  if (ms->n == 0 || ms->nch == 0)
    return rcb_meas_fail(ms, RCB_ERR_STATE, "%s: nothing to write (no abscissa or no "
                         "channels)", path ? path : "");
  if ((st = common_kind(ms, path, &kind))) return st;
  if ((st = rcb_atomic_open(ms, &af, path, 0))) return st;
  write_body(ms, af.fp, kind);
  return rcb_atomic_commit(ms, &af, path);
}
