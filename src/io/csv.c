/*
 * CSV measurements, as rcbtool frf / unbalance write them:
 *   # kind = receptance          (optional; FRFs only; default receptance)
 *   # rpm = 3000                 (optional; FRF test speed, or "synchronous")
 *   # phase = lag (keyphasor falling edge)   (optional; lag: the values are the
 *                                 conjugates of the model's, read back to them)
 *   freq_hz,D1.x/C.x re,D1.x/C.x im,...     (FRF, abscissa Hz)
 *   rpm,DA.x amp,DA.x phase_deg,...         (unbalance, abscissa rpm)
 * Per channel two columns: "re","im", or "mag"/"amp","phase_deg" (degrees),
 * the part after a space or, as lab scripts write them, after '_'
 * ("2.x/11.x_re", "DA.x_phase_deg"; issue #35 item 3). The two columns of a
 * channel are paired by name, adjacent or not; a channel given both ways
 * (re/im and mag/phase) is refused as ambiguous. A "mag" (or "dB", 20 log10)
 * column without phase is a channel of magnitudes only (issue #35 item 4:
 * rcb_meas_add_channel_mag), written back as one "mag" column. Other "#" lines are
 * comments. Errors name the file, line and column. Other tools' spellings are
 * read too (case, spaces, '_' and a unit in brackets do not matter:
 * "Frequency (Hz)", "frequency_hz", "Speed [rpm]", "DA.x/C.y Real",
 * "DA.x/C.y Phase (deg)", "DA.x/C.y re (m/N)"); a spelling that leaves the
 * unit open (frequency, phase) is refused with the name to use. A station
 * given as a number ("3.x", a test system's node) is read through the node
 * map of rcb_meas_read_csv_map (rcbtool --map, the model's [uff] map), and
 * refused with what to write when the map has no entry for it.
 *
 * No fixed-size buffer cuts a header (issue #35 item 6): a name, part word or
 * unit too long for its buffer is refused, or is not a word the reader knows,
 * which is refused with the text as written.
 */
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "io/meas_internal.h"

#define CSV_WHERE 512

typedef enum col_part { COL_RE, COL_IM, COL_MAG, COL_PHASE, COL_DB } col_part;

typedef struct csv_col {
  char name[RCB_MEAS_CH_MAX * 2 + 2]; /* "RESP/REF" or "RESP" */
  col_part part;
  size_t mate; /* RE/MAG/DB: the column of its IM/PHASE (check_pairs); MAG or DB
                  alone: itself (a magnitude-only channel, issue #35 item 4) */
} csv_col;

#define CSV_REF_MAX 80 /* characters of a "# phase = lag (reference)" */

typedef struct csv_state {
  rcb_meas *ms;
  const char *path;
  size_t line;
  int have_header, have_kind, have_rpm;
  rcb_meas_type type;
  rcb_frf_kind kind;
  double speed; /* rad/s, < 0 synchronous */
  rcb_phase_convention phase; /* "# phase = lead|lag (reference)" */
  char phase_ref[CSV_REF_MAX + 4];
  size_t nmap; /* node map for stations written as numbers */
  const rcb_uff_node *map;
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
    if (strlen(ref) > CSV_REF_MAX)
      return rcb_meas_fail(S->ms, RCB_ERR_PARSE, "%s:%zu: phase reference '%.40s...' has %zu "
                           "characters; at most %d are kept", S->path, S->line, ref, strlen(ref),
                           CSV_REF_MAX);
    snprintf(S->phase_ref, sizeof S->phase_ref, "%s", ref);
  }
  return RCB_OK;
}

/* Header token (n bytes of s) folded for comparison: lower case, without
 * ' ', '_', '-' and brackets, so "Frequency (Hz)", "frequency_hz" and
 * "FREQ-HZ" all read "frequencyhz". A token too long for out folds to ""
 * (-1): no word the reader knows is that long, so it is refused as written,
 * never matched by a cut prefix. */
static int fold_n(const char *s, size_t n, char *out, size_t size) {
  size_t k = 0, i;
  for (i = 0; i < n && s[i]; i++)
    if (!strchr(" _-()[]\t", s[i])) {
      if (k + 1 >= size) {
        out[0] = '\0';
        return -1;
      }
      out[k++] = (char)tolower((unsigned char)s[i]);
    }
  out[k] = '\0';
  return 0;
}

static int fold(const char *s, char *out, size_t size) { return fold_n(s, strlen(s), out, size); }

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
  double num;
  if (!f[0])
    return rcb_meas_fail(S->ms, RCB_ERR_PARSE, "%s:%zu: the first column has no name; expected "
                         "freq_hz (FRF) or rpm (unbalance response) (pandas writes its row "
                         "index so: DataFrame.to_csv(..., index=False) leaves it out)", S->path,
                         S->line);
  if (!parse_num(f, &num))
    return rcb_meas_fail(S->ms, RCB_ERR_PARSE, "%s:%zu: the line starts with a number: no header "
                         "line (freq_hz,... or rpm,...) before the data (numpy.savetxt writes "
                         "its header as a '# ' comment unless given comments='')", S->path,
                         S->line);
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
 * (folded) into unit ("" without one; a unit too long for it folds to "",
 * which is not degrees). */
static void cut_unit(const char *f, size_t *end, char *unit, size_t size) {
  size_t n = *end;
  char close;
  unit[0] = '\0';
  while (n > 0 && f[n - 1] == ' ') n--;
  if (n == 0 || (f[n - 1] != ')' && f[n - 1] != ']')) return;
  close = f[n - 1];
  while (n > 0 && f[n - 1] != (close == ')' ? '(' : '[')) n--;
  if (n == 0) return;
  fold_n(f + n, *end - n, unit, size);
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
  char g[32];
  if (fold_n(word, n, g, sizeof g)) return -1;
  if (in_list(g, re)) return COL_RE;
  if (in_list(g, im)) return COL_IM;
  if (in_list(g, mag)) return COL_MAG;
  if (strcmp(g, "db") == 0) return COL_DB;
  if (strcmp(g, "phasedeg") == 0) return COL_PHASE;
  if (strcmp(g, "phase") == 0 || strcmp(g, "ph") == 0)
    return strcmp(unit, "deg") == 0 || strcmp(unit, "degrees") == 0 || strcmp(unit, "\u00b0") == 0
               ? COL_PHASE
               : -2;
  return -1;
}

/* The map entry of node @p node for direction [dir, dir + dlen): its direction
 * entry ("2.z=DA.x") first, else its node entry ("2=DA"); NULL when neither. */
static const rcb_uff_node *csv_map_find(const csv_state *S, long node, const char *dir,
                                        size_t dlen) {
  const rcb_uff_node *whole = NULL;
  size_t i;
  for (i = 0; i < S->nmap; i++) {
    const rcb_uff_node *e = &S->map[i];
    if (e->node != node) continue;
    if (!e->dir)
      whole = whole ? whole : e;
    else if (strlen(e->dir) == dlen && strncmp(e->dir, dir, dlen) == 0)
      return e;
  }
  return whole;
}

/* Stations written as numbers ("3.x/10.y", a test system's node numbers)
 * through the node map (issue #35 item 3: lab scripts write them); a
 * direction entry maps a channel of any direction ("3.z=DA.x"); one the map
 * does not name is refused with what to give or write instead. */
static rcb_status map_stations(csv_state *S, csv_col *c, size_t k) {
  char out[sizeof c->name];
  const char *p = c->name;
  size_t at = 0;
  for (;;) {
    const char *slash = strchr(p, '/'), *end = slash ? slash : p + strlen(p), *dot = end, *q;
    const char *st = "", *tail = p, *tail_end = end; /* written: st, then [tail, tail_end) */
    char dirbuf[8];
    size_t stlen = 0, rest;
    while (dot > p && dot[-1] != '.') dot--;
    if (dot > p + 1) {
      for (q = p; q < dot - 1 && isdigit((unsigned char)*q); q++) continue;
      if (q == dot - 1) {
        long node = 0;
        int n = (int)(dot - 1 - p);
        const rcb_uff_node *e;
        for (q = p; q < dot - 1 && node < 100000000L; q++) node = node * 10 + (*q - '0');
        e = q < dot - 1 ? NULL : csv_map_find(S, node, dot, (size_t)(end - dot));
        if (!e)
          return rcb_meas_fail(S->ms, RCB_ERR_PARSE, "%s:%zu: column %zu ('%s'): station '%.*s' "
                               "is a number, not a model station, and the node map has no entry "
                               "for it: give it (rcbtool --map %.*s=STATION, or %.*s.%.*s="
                               "STATION.DIR for this channel alone; the model's [uff] map; "
                               "rcb_meas_read_csv_map), or rename it to the station it stands "
                               "for (e.g. DA; 'rcbtool check' lists them) or to '#%.*s' for "
                               "model node %.*s", S->path, S->line, k + 1, c->name, n, p, n, p,
                               n, p, (int)(end - dot), dot, n, p, n, p);
        st = e->station;
        stlen = strlen(st);
        tail = dot - 1; /* ".DIR" */
        if (e->dir) { /* ".MODEL_DIR" */
          snprintf(dirbuf, sizeof dirbuf, ".%s", e->model_dir);
          tail = dirbuf;
          tail_end = dirbuf + strlen(dirbuf);
        }
      }
    }
    rest = (size_t)(tail_end - tail);
    if (at + stlen + rest + 1 >= sizeof out)
      return rcb_meas_fail(S->ms, RCB_ERR_PARSE, "%s:%zu: column %zu ('%s'): the channel, its "
                           "stations mapped, has more than %zu characters", S->path, S->line,
                           k + 1, c->name, sizeof out - 1);
    memcpy(out + at, st, stlen);
    memcpy(out + at + stlen, tail, rest);
    at += stlen + rest;
    if (!slash) break;
    out[at++] = '/';
    p = slash + 1;
  }
  out[at] = '\0';
  memcpy(c->name, out, at + 1);
  return RCB_OK;
}

/* Where the part word of header field f (its first end bytes) starts: after
 * the last space ("DA.x/C.y re"), else after the last '_' or the one before
 * it whose remainder is a part word ("2.x/11.x_re", "DA.x_phase_deg");
 * *part as part_of, *name_len the channel's length. 0: no part word found. */
static int find_part(const char *f, size_t end, const char *unit, size_t *name_len, int *part) {
  const char *sp = f + end, *u;
  int tries;
  while (sp > f && sp[-1] != ' ') sp--;
  if (sp > f + 1) {
    *name_len = (size_t)(sp - 1 - f);
    *part = part_of(sp, (size_t)(f + end - sp), unit);
    return 1;
  }
  for (u = f + end, tries = 0; tries < 2; tries++) {
    while (u > f && u[-1] != '_') u--;
    if (u <= f + 1) return 0;
    *part = part_of(u, (size_t)(f + end - u), unit);
    *name_len = (size_t)(u - 1 - f);
    if (*part != -1) return 1;
    u--;
  }
  return 0;
}

/* One header field "NAME part" or "NAME_part" -> column. */
static rcb_status header_col(csv_state *S, const char *f, size_t k) {
  csv_col *c;
  char unit[32];
  size_t len = 0, end = strlen(f);
  int part = -1;
  cut_unit(f, &end, unit, sizeof unit);
  if (!find_part(f, end, unit, &len, &part))
    return rcb_meas_fail(S->ms, RCB_ERR_PARSE, "%s:%zu: column %zu '%s': expected \"CHANNEL "
                         "re\", \"CHANNEL im\", \"CHANNEL mag\"/\"amp\" or \"CHANNEL "
                         "phase_deg\" (or CHANNEL_re, CHANNEL_im, CHANNEL_mag, "
                         "CHANNEL_phase_deg); a magnitude alone, \"CHANNEL mag\" or \"CHANNEL "
                         "dB\", is read without phase", S->path, S->line, k + 1, f);
  if (rcb_grow(&S->ms->alloc, (void **)&S->cols, &S->capcols, S->ncols + 1, sizeof *S->cols))
    return rcb_meas_fail(S->ms, RCB_ERR_NOMEM, "%s: out of memory", S->path);
  c = &S->cols[S->ncols];
  while (len > 0 && f[len - 1] == ' ') len--;
  if (len >= sizeof c->name)
    return rcb_meas_fail(S->ms, RCB_ERR_PARSE, "%s:%zu: column %zu: channel name '%.40s...' has "
                         "%zu characters; at most %zu are read", S->path, S->line, k + 1, f, len,
                         sizeof c->name - 1);
  memcpy(c->name, f, len);
  c->name[len] = '\0';
  if (part == -2)
    return rcb_meas_fail(S->ms, RCB_ERR_PARSE, "%s:%zu: column %zu '%s': a phase without "
                         "the unit degrees; give it in degrees and name the column \"%s "
                         "phase_deg\" (or %s_phase_deg)", S->path, S->line, k + 1, f, c->name,
                         c->name);
  if (part < 0)
    return rcb_meas_fail(S->ms, RCB_ERR_PARSE, "%s:%zu: column %zu '%s': unknown part '%.*s'; "
                         "expected re, im, mag, amp, dB or phase_deg", S->path, S->line, k + 1, f,
                         (int)(end - len - 1), f + len + 1);
  c->part = (col_part)part;
  S->ncols++;
  return map_stations(S, c, k);
}

static const char *const part_word[] = {"re", "im", "mag", "phase_deg", "dB"};

typedef struct name_col {
  const char *name;
  size_t col;
} name_col;

static int by_name(const void *a, const void *b) {
  const name_col *x = a, *y = b;
  int d = strcmp(x->name, y->name);
  return d ? d : (x->col > y->col) - (x->col < y->col);
}

/* The columns of one channel (sorted[g0..g1), one name): re+im or
 * mag+phase_deg, each once; cols[RE or MAG].mate set. */
static rcb_status pair_channel(csv_state *S, const name_col *sorted, size_t g0, size_t g1) {
  size_t at[5] = {0, 0, 0, 0, 0}, g; /* 1 + column of each part, 0: none */
  const char *name = sorted[g0].name;
  for (g = g0; g < g1; g++) {
    size_t c = sorted[g].col;
    col_part p = S->cols[c].part;
    if (at[p])
      return rcb_meas_fail(S->ms, RCB_ERR_PARSE, "%s:%zu: duplicate channel %s: column %zu "
                           "repeats its %s (column %zu); give each channel once", S->path,
                           S->line, name, c + 2, part_word[p], at[p] + 1);
    at[p] = c + 1;
  }
  if ((at[COL_RE] || at[COL_IM]) && (at[COL_MAG] || at[COL_PHASE] || at[COL_DB]))
    return rcb_meas_fail(S->ms, RCB_ERR_PARSE, "%s:%zu: channel %s is given both as re/im and "
                         "as mag/phase (columns %zu and %zu): ambiguous; keep one pair",
                         S->path, S->line, name, (at[COL_RE] ? at[COL_RE] : at[COL_IM]) + 1,
                         (at[COL_MAG] ? at[COL_MAG] : at[COL_PHASE] ? at[COL_PHASE] : at[COL_DB]) + 1);
  if (at[COL_MAG] && at[COL_DB])
    return rcb_meas_fail(S->ms, RCB_ERR_PARSE, "%s:%zu: channel %s is given both as mag and as "
                         "dB (columns %zu and %zu): ambiguous; keep one", S->path, S->line, name,
                         at[COL_MAG] + 1, at[COL_DB] + 1);
  if (at[COL_DB]) { /* dB stands for the magnitude: paired with a phase as mag is */
    at[COL_MAG] = at[COL_DB];
    at[COL_DB] = 0;
  }
  if (at[COL_MAG] && !at[COL_PHASE]) { /* magnitudes only (issue #35 item 4) */
    S->cols[at[COL_MAG] - 1].mate = at[COL_MAG] - 1;
    return RCB_OK;
  }
  for (g = 0; g < 4; g += 2)
    if (at[g] || at[g + 1]) {
      size_t have = at[g] ? g : g + 1, miss = at[g] ? g + 1 : g;
      if (!at[miss])
        return rcb_meas_fail(S->ms, RCB_ERR_PARSE, "%s:%zu: column %zu ('%s'): its %s has no "
                             "pair; expected the two columns \"%s %s\",\"%s %s\"", S->path,
                             S->line, at[have] + 1, name, part_word[have], name, part_word[g],
                             name, part_word[g + 1]);
      S->cols[at[g] - 1].mate = at[g + 1] - 1;
    }
  return RCB_OK;
}

/* Columns come in pairs re+im or mag+phase_deg of one channel, found by
 * name (sorted, so a header of many columns costs n log n). */
static rcb_status check_pairs(csv_state *S) {
  name_col *sorted;
  size_t c, g0;
  rcb_status st = RCB_OK;
  if (S->ncols == 0)
    return rcb_meas_fail(S->ms, RCB_ERR_PARSE, "%s:%zu: no channel columns after the "
                         "abscissa", S->path, S->line);
  for (c = 0; c < S->ncols; c++) {
    const char *name = S->cols[c].name;
    if ((S->type == RCB_MEAS_FRF) != (strchr(name, '/') != NULL))
      return rcb_meas_fail(S->ms, RCB_ERR_PARSE, "%s:%zu: column %zu ('%s'): %s", S->path,
                           S->line, c + 2, name,
                           S->type == RCB_MEAS_FRF
                               ? "an FRF channel is RESPONSE/REFERENCE, e.g. DA.x/C.y"
                               : "an unbalance response channel has no /REFERENCE");
  }
  sorted = rcb_alloc(&S->ms->alloc, S->ncols * sizeof *sorted);
  if (!sorted) return rcb_meas_fail(S->ms, RCB_ERR_NOMEM, "%s: out of memory", S->path);
  for (c = 0; c < S->ncols; c++) {
    sorted[c].name = S->cols[c].name;
    sorted[c].col = c;
  }
  qsort(sorted, S->ncols, sizeof *sorted, by_name);
  for (g0 = 0, c = 1; c <= S->ncols && !st; c++)
    if (c == S->ncols || strcmp(sorted[c].name, sorted[g0].name) != 0) {
      st = pair_channel(S, sorted, g0, c);
      g0 = c;
    }
  rcb_free(&S->ms->alloc, sorted);
  return st;
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
  for (c = 0; c < S->ncols && !st; c++) {
    char *slash = strchr(S->cols[c].name, '/');
    size_t m = S->cols[c].mate;
    col_part part = S->cols[c].part;
    int mag_only = m == c; /* a mag or dB column without phase (issue #35 item 4) */
    if (part != COL_RE && part != COL_MAG && part != COL_DB) continue;
    for (r = 0; r < S->nrows; r++) {
      double a = S->v[r * S->ncols + c], b = S->v[r * S->ncols + m];
      if (part == COL_DB) a = pow(10.0, a / 20.0); /* 20 log10 |H| */
      d[r] = part == COL_RE ? CMPLX(a, b)
             : mag_only     ? CMPLX(a, 0.0)
                            : a * CMPLX(cos(b * RCB_PI / 180.0), sin(b * RCB_PI / 180.0));
      if (S->phase == RCB_PHASE_LAG) d[r] = conj(d[r]); /* to the model's lead */
    }
    if (mag_only)
      snprintf(where, sizeof where, "%s: column %zu", S->path, c + 2);
    else
      snprintf(where, sizeof where, m == c + 1 ? "%s: columns %zu-%zu" : "%s: columns %zu and %zu",
               S->path, c + 2, m + 2);
    if (slash) *slash = '\0';
    st = (mag_only ? rcb_meas_add_mag_at : rcb_meas_add_channel_at)(
        ms, S->cols[c].name, slash ? slash + 1 : NULL,
        S->type == RCB_MEAS_FRF ? S->kind : RCB_RECEPTANCE, d, where, RCB_ERR_PARSE);
  }
  rcb_free(&ms->alloc, d);
  return st;
}

rcb_status rcb_meas_read_csv(rcb_meas *ms, const char *path) {
  return rcb_meas_read_csv_map(ms, path, 0, NULL);
}

rcb_status rcb_meas_read_csv_map(rcb_meas *ms, const char *path, size_t nmap,
                                 const rcb_uff_node *map) {
  csv_state S;
  char *buf = NULL;
  size_t len;
  rcb_status st;
  if (!ms) return RCB_ERR_ARG;
  if ((st = rcb_meas_check_map(ms, "read_csv", nmap, map))) return st;
  memset(&S, 0, sizeof S);
  S.ms = ms;
  S.path = path;
  S.nmap = nmap;
  S.map = map;
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
    if (h->mag_only) /* magnitudes only: one column (issue #35 item 4) */
      fprintf(fp, frf ? ",%s/%s mag" : ",%s mag", h->resp, h->ref);
    else if (frf)
      fprintf(fp, ",%s/%s re,%s/%s im", h->resp, h->ref, h->resp, h->ref);
    else
      fprintf(fp, ",%s re,%s im", h->resp, h->resp);
  }
  fputc('\n', fp);
  for (i = 0; i < ms->n; i++) {
    fprintf(fp, "%.17g", ms->x[i] * (frf ? 1.0 / (2.0 * RCB_PI) : 30.0 / RCB_PI));
    for (c = 0; c < ms->nch; c++) /* LAG: the conjugate, so arg is the lag */
      if (ms->ch[c].mag_only)
        fprintf(fp, ",%.17g", creal(ms->ch[c].data[i]));
      else
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
