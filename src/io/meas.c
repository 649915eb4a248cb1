/*
 * The measurement container: one abscissa (rad/s), channels of complex
 * values in SI, every input checked with a message that says where the bad
 * value came from (file and line/record when a reader calls).
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "io/meas_internal.h"

#define TWO_PI (2.0 * RCB_PI)

rcb_status rcb_meas_create(rcb_meas **out, const rcb_allocator *alloc) {
  rcb_allocator a;
  rcb_meas *ms;
  if (!out) return RCB_ERR_ARG;
  *out = NULL;
  rcb_allocator_init(&a, alloc);
  ms = rcb_alloc(&a, sizeof *ms);
  if (!ms) return RCB_ERR_NOMEM;
  ms->alloc = a;
  ms->speed = 0.0;
  *out = ms;
  return RCB_OK;
}

void rcb_meas_clear(rcb_meas *ms) {
  size_t i;
  if (!ms) return;
  for (i = 0; i < ms->nch; i++) rcb_free(&ms->alloc, ms->ch[i].data);
  rcb_free(&ms->alloc, ms->ch);
  rcb_free(&ms->alloc, ms->x);
  ms->ch = NULL;
  ms->nch = ms->capch = 0;
  ms->x = NULL;
  ms->n = 0;
  ms->speed = 0.0;
  ms->speed_given = 0;
  ms->phase = RCB_PHASE_UNSTATED;
  ms->phase_ref[0] = '\0';
  ms->type = RCB_MEAS_FRF;
}

rcb_status rcb_meas_warn(rcb_meas *ms, const char *fmt, ...) {
  va_list ap;
  if (rcb_grow(&ms->alloc, (void **)&ms->warnings, &ms->cap_warnings, ms->n_warnings + 1,
               sizeof *ms->warnings))
    return rcb_meas_fail(ms, RCB_ERR_NOMEM, "out of memory recording a measurement warning");
  va_start(ap, fmt);
  vsnprintf(ms->warnings[ms->n_warnings].text, RCB_WARNING_MAX, fmt, ap);
  va_end(ap);
  ms->n_warnings++;
  return RCB_OK;
}

void rcb_meas_clear_warnings(rcb_meas *ms) {
  rcb_free(&ms->alloc, ms->warnings);
  ms->warnings = NULL;
  ms->n_warnings = ms->cap_warnings = 0;
  ms->speed_warning = 0;
}

size_t rcb_meas_warning_count(const rcb_meas *ms) { return ms ? ms->n_warnings : 0; }

const char *rcb_meas_warning(const rcb_meas *ms, size_t i) {
  return ms && i < ms->n_warnings ? ms->warnings[i].text : NULL;
}

int rcb_meas_speed_given(const rcb_meas *ms) { return ms ? ms->speed_given : 0; }

rcb_status rcb_meas_set_phase(rcb_meas *ms, rcb_phase_convention conv, const char *reference) {
  if (!ms) return RCB_ERR_ARG;
  if ((unsigned)conv > RCB_PHASE_LAG || (reference && strlen(reference) > 80) ||
      (reference && strpbrk(reference, "\r\n")))
    return rcb_meas_fail(ms, RCB_ERR_ARG, "set_phase: convention %d, reference of %zu "
                         "characters: expected 0-2 and one line of at most 80", (int)conv,
                         reference ? strlen(reference) : (size_t)0);
  ms->phase = conv;
  snprintf(ms->phase_ref, sizeof ms->phase_ref, "%s", reference ? reference : "");
  return RCB_OK;
}

rcb_phase_convention rcb_meas_phase(const rcb_meas *ms) {
  return ms ? ms->phase : RCB_PHASE_UNSTATED;
}

rcb_status rcb_meas_set_speed(rcb_meas *ms, double speed) {
  if (!ms) return RCB_ERR_ARG;
  if (ms->n == 0 || ms->type != RCB_MEAS_FRF)
    return rcb_meas_fail(ms, RCB_ERR_STATE, "set_speed: the measurement holds no FRFs (the "
                         "rotor speed of an unbalance response is its abscissa)");
  if (!isfinite(speed))
    return rcb_meas_fail(ms, RCB_ERR_ARG, "set_speed: rotor speed %g: expected a finite "
                         "value (rad/s, negative for synchronous)", speed);
  ms->speed = speed < 0.0 ? -1.0 : speed;
  ms->speed_given = 1;
  if (ms->speed_warning) { /* answered: drop the read's "speed not stated" warning */
    size_t i = ms->speed_warning - 1;
    memmove(&ms->warnings[i], &ms->warnings[i + 1], (ms->n_warnings - i - 1) * sizeof *ms->warnings);
    ms->n_warnings--;
    ms->speed_warning = 0;
  }
  return RCB_OK;
}

void rcb_meas_destroy(rcb_meas *ms) {
  rcb_allocator a;
  if (!ms) return;
  rcb_meas_clear(ms);
  rcb_meas_clear_warnings(ms);
  a = ms->alloc;
  rcb_free(&a, ms);
}

const char *rcb_meas_errmsg(const rcb_meas *ms) { return ms ? ms->errmsg : "no measurement"; }

/* "where: " prefix for messages (empty for API calls). */
static const char *pre(const char *where) { return where ? where : ""; }
static const char *sep(const char *where) { return where ? ": " : ""; }

rcb_status rcb_meas_set_grid_at(rcb_meas *ms, rcb_meas_type type, size_t n, const double *x,
                                double speed, const char *where, rcb_status bad) {
  size_t i;
  if (!ms) return RCB_ERR_ARG;
  if (type != RCB_MEAS_FRF && type != RCB_MEAS_UNBALANCE)
    return rcb_meas_fail(ms, RCB_ERR_ARG, "%s%smeasurement type %d: expected FRF (0) or "
                         "unbalance (1)", pre(where), sep(where), (int)type);
  if (n == 0 || !x)
    return rcb_meas_fail(ms, bad, "%s%sno abscissa points: expected at least one", pre(where),
                         sep(where));
  for (i = 0; i < n; i++) {
    if (!isfinite(x[i]))
      return rcb_meas_fail(ms, bad, "%s%sabscissa point %zu is %g: expected a finite "
                           "frequency", pre(where), sep(where), i + 1, x[i]);
    if (x[i] < 0.0)
      return rcb_meas_fail(ms, bad, "%s%sabscissa point %zu is negative (%.9g Hz): expected "
                           "frequencies >= 0", pre(where), sep(where), i + 1, x[i] / TWO_PI);
    if (i > 0 && !(x[i] > x[i - 1]))
      return rcb_meas_fail(ms, bad, "%s%sabscissa not increasing: point %zu (%.9g Hz) after "
                           "point %zu (%.9g Hz); expected strictly increasing frequencies",
                           pre(where), sep(where), i + 1, x[i] / TWO_PI, i, x[i - 1] / TWO_PI);
  }
  if (type == RCB_MEAS_FRF && !isfinite(speed))
    return rcb_meas_fail(ms, bad, "%s%srotor speed %g: expected a finite value (rad/s, "
                         "negative for synchronous)", pre(where), sep(where), speed);
  rcb_meas_clear(ms);
  ms->x = rcb_alloc(&ms->alloc, n * sizeof *ms->x);
  if (!ms->x) return rcb_meas_fail(ms, RCB_ERR_NOMEM, "out of memory (%zu points)", n);
  memcpy(ms->x, x, n * sizeof *x);
  ms->n = n;
  ms->type = type;
  ms->speed = type == RCB_MEAS_FRF ? speed : 0.0;
  ms->speed_given = 1; /* a reader sets what its file stated */
  ms->errmsg[0] = '\0';
  return RCB_OK;
}

rcb_status rcb_meas_set_grid(rcb_meas *ms, rcb_meas_type type, size_t n, const double *x,
                             double speed) {
  return rcb_meas_set_grid_at(ms, type, n, x, speed, NULL, RCB_ERR_ARG);
}

int rcb_meas_channel_dir(const char *name, size_t *stlen) {
  static const char *const dirs[] = {"x", "y", "rx", "ry"};
  const char *dot = strrchr(name, '.');
  int d;
  if (!dot || dot == name) return -1;
  *stlen = (size_t)(dot - name);
  for (d = 0; d < 4; d++)
    if (strcmp(dot + 1, dirs[d]) == 0) return d;
  return -1;
}

const char *rcb_meas_kind_name(rcb_frf_kind k) {
  switch (k) {
    case RCB_RECEPTANCE: return "receptance";
    case RCB_MOBILITY: return "mobility";
    case RCB_INERTANCE: return "inertance";
    default: return "?";
  }
}

int rcb_meas_kind_parse(const char *s, rcb_frf_kind *k) {
  int i;
  for (i = 0; i < 3; i++)
    if (strcmp(s, rcb_meas_kind_name((rcb_frf_kind)i)) == 0) {
      *k = (rcb_frf_kind)i;
      return 0;
    }
  return -1;
}

static rcb_status check_name(rcb_meas *ms, const char *what, const char *name,
                             const char *where, rcb_status bad) {
  size_t stlen;
  if (!name || !name[0])
    return rcb_meas_fail(ms, bad, "%s%s%s channel: a name STATION.DIR is required",
                         pre(where), sep(where), what);
  if (strlen(name) >= RCB_MEAS_CH_MAX)
    return rcb_meas_fail(ms, bad, "%s%s%s channel '%s': longer than %d characters", pre(where),
                         sep(where), what, name, RCB_MEAS_CH_MAX - 1);
  if (rcb_meas_channel_dir(name, &stlen) < 0)
    return rcb_meas_fail(ms, bad, "%s%s%s channel '%s': unknown direction; expected "
                         "STATION.DIR with DIR x, y, rx or ry", pre(where), sep(where), what,
                         name);
  return RCB_OK;
}

static rcb_status check_channel(rcb_meas *ms, const char *resp, const char *ref,
                                rcb_frf_kind kind, const rcb_complex *data, const char *where,
                                rcb_status bad) {
  rcb_status st;
  size_t i;
  if ((st = check_name(ms, "response", resp, where, bad))) return st;
  if (ms->type == RCB_MEAS_FRF) {
    if ((st = check_name(ms, "reference", ref, where, bad))) return st;
  } else if (ref && ref[0]) {
    return rcb_meas_fail(ms, bad, "%s%s%s: an unbalance response has no reference channel "
                         "(got '%s')", pre(where), sep(where), resp, ref);
  }
  if ((int)kind < 0 || (int)kind > 2)
    return rcb_meas_fail(ms, bad, "%s%s%s: kind %d: expected receptance, mobility or "
                         "inertance", pre(where), sep(where), resp, (int)kind);
  if (ms->type == RCB_MEAS_UNBALANCE && kind != RCB_RECEPTANCE)
    return rcb_meas_fail(ms, bad, "%s%s%s: an unbalance response is a displacement "
                         "(receptance), got %s", pre(where), sep(where), resp,
                         rcb_meas_kind_name(kind));
  for (i = 0; i < ms->nch; i++)
    if (strcmp(ms->ch[i].resp, resp) == 0 && strcmp(ms->ch[i].ref, ref ? ref : "") == 0)
      return rcb_meas_fail(ms, bad, "%s%sduplicate channel %s%s%s: each response/reference "
                           "pair may appear once", pre(where), sep(where), resp,
                           ms->type == RCB_MEAS_FRF ? "/" : "", ms->type == RCB_MEAS_FRF ? ref : "");
  for (i = 0; i < ms->n; i++)
    if (!isfinite(creal(data[i])) || !isfinite(cimag(data[i])))
      return rcb_meas_fail(ms, bad, "%s%schannel %s%s%s, point %zu (%.9g Hz): value %g%+gi is "
                           "not finite; expected finite numbers", pre(where), sep(where), resp,
                           ref && ref[0] ? "/" : "", ref ? ref : "", i + 1, ms->x[i] / TWO_PI,
                           creal(data[i]), cimag(data[i]));
  return RCB_OK;
}

rcb_status rcb_meas_add_channel_at(rcb_meas *ms, const char *response, const char *reference,
                                   rcb_frf_kind kind, const rcb_complex *data,
                                   const char *where, rcb_status bad) {
  rcb_meas_ch *c;
  rcb_status st;
  if (!ms) return RCB_ERR_ARG;
  if (ms->n == 0)
    return rcb_meas_fail(ms, RCB_ERR_STATE, "add channel: set the abscissa first "
                         "(rcb_meas_set_grid)");
  if (!data) return rcb_meas_fail(ms, RCB_ERR_ARG, "add channel: data is NULL");
  if ((st = check_channel(ms, response, reference, kind, data, where, bad))) return st;
  if (rcb_grow(&ms->alloc, (void **)&ms->ch, &ms->capch, ms->nch + 1, sizeof *ms->ch))
    return rcb_meas_fail(ms, RCB_ERR_NOMEM, "out of memory (channel %zu)", ms->nch + 1);
  c = &ms->ch[ms->nch];
  memset(c, 0, sizeof *c);
  c->data = rcb_alloc(&ms->alloc, ms->n * sizeof *c->data);
  if (!c->data) return rcb_meas_fail(ms, RCB_ERR_NOMEM, "out of memory (channel %s)", response);
  memcpy(c->data, data, ms->n * sizeof *data);
  strcpy(c->resp, response);
  if (ms->type == RCB_MEAS_FRF) strcpy(c->ref, reference);
  c->kind = kind;
  ms->nch++;
  return RCB_OK;
}

rcb_status rcb_meas_add_channel(rcb_meas *ms, const char *response, const char *reference,
                                rcb_frf_kind kind, const rcb_complex *data) {
  return rcb_meas_add_channel_at(ms, response, reference, kind, data, NULL, RCB_ERR_ARG);
}

rcb_status rcb_meas_add_mag_at(rcb_meas *ms, const char *response, const char *reference,
                               rcb_frf_kind kind, const rcb_complex *data, const char *where,
                               rcb_status bad) {
  size_t i;
  rcb_status st;
  if (!ms) return RCB_ERR_ARG;
  for (i = 0; data && i < ms->n; i++)
    if (!(creal(data[i]) >= 0.0) || cimag(data[i]) != 0.0)
      return rcb_meas_fail(ms, bad, "%s%schannel %s%s%s, point %zu (%.9g Hz): magnitude %g: "
                           "expected a finite value >= 0", pre(where), sep(where), response,
                           reference ? "/" : "", reference ? reference : "", i + 1,
                           ms->x[i] / TWO_PI, creal(data[i]));
  if ((st = rcb_meas_add_channel_at(ms, response, reference, kind, data, where, bad))) return st;
  ms->ch[ms->nch - 1].mag_only = 1;
  return RCB_OK;
}

rcb_status rcb_meas_add_channel_mag(rcb_meas *ms, const char *response, const char *reference,
                                    rcb_frf_kind kind, const double *mag) {
  rcb_complex *d;
  size_t i;
  rcb_status st;
  if (!ms) return RCB_ERR_ARG;
  if (!mag) return rcb_meas_fail(ms, RCB_ERR_ARG, "add channel: data is NULL");
  if (ms->n == 0)
    return rcb_meas_fail(ms, RCB_ERR_STATE, "add channel: set the abscissa first "
                         "(rcb_meas_set_grid)");
  if (!(d = rcb_alloc(&ms->alloc, ms->n * sizeof *d)))
    return rcb_meas_fail(ms, RCB_ERR_NOMEM, "out of memory (channel %s)", response);
  for (i = 0; i < ms->n; i++) d[i] = CMPLX(mag[i], 0.0);
  st = rcb_meas_add_mag_at(ms, response, reference, kind, d, NULL, RCB_ERR_ARG);
  rcb_free(&ms->alloc, d);
  return st;
}

size_t rcb_meas_magnitude_only_count(const rcb_meas *ms) {
  size_t c, n = 0;
  for (c = 0; ms && c < ms->nch; c++) n += ms->ch[c].mag_only != 0;
  return n;
}

rcb_meas_type rcb_meas_get_type(const rcb_meas *ms) { return ms ? ms->type : RCB_MEAS_FRF; }
size_t rcb_meas_point_count(const rcb_meas *ms) { return ms ? ms->n : 0; }
size_t rcb_meas_channel_count(const rcb_meas *ms) { return ms ? ms->nch : 0; }
const double *rcb_meas_grid(const rcb_meas *ms) { return ms ? ms->x : NULL; }
double rcb_meas_speed(const rcb_meas *ms) { return ms ? ms->speed : 0.0; }

rcb_status rcb_meas_channel(const rcb_meas *ms, size_t i, rcb_meas_channel_info *out) {
  if (!ms || !out) return RCB_ERR_ARG;
  if (i >= ms->nch) return RCB_ERR_NOT_FOUND;
  out->response = ms->ch[i].resp;
  out->reference = ms->type == RCB_MEAS_FRF ? ms->ch[i].ref : NULL;
  out->kind = ms->ch[i].kind;
  out->data = ms->ch[i].data;
  out->magnitude_only = ms->ch[i].mag_only;
  return RCB_OK;
}

rcb_status rcb_meas_convert(rcb_meas *ms, rcb_frf_kind kind) {
  size_t c, i;
  if (!ms) return RCB_ERR_ARG;
  if ((int)kind < 0 || (int)kind > 2)
    return rcb_meas_fail(ms, RCB_ERR_ARG, "convert: kind %d: expected receptance, mobility "
                         "or inertance", (int)kind);
  if (ms->type == RCB_MEAS_UNBALANCE) {
    if (kind == RCB_RECEPTANCE) return RCB_OK;
    return rcb_meas_fail(ms, RCB_ERR_ARG, "convert: unbalance responses are displacements; "
                         "only receptance applies, got %s", rcb_meas_kind_name(kind));
  }
  /* Dividing by (i w)^k needs w > 0: check before touching anything. */
  for (c = 0; c < ms->nch; c++)
    if ((int)kind < (int)ms->ch[c].kind && ms->n > 0 && ms->x[0] == 0.0)
      return rcb_meas_fail(ms, RCB_ERR_ARG, "convert: channel %s/%s from %s to %s divides by "
                           "(i w) at 0 Hz; expected frequencies > 0", ms->ch[c].resp,
                           ms->ch[c].ref, rcb_meas_kind_name(ms->ch[c].kind),
                           rcb_meas_kind_name(kind));
  for (c = 0; c < ms->nch; c++) {
    int k = (int)kind - (int)ms->ch[c].kind;
    for (i = 0; i < ms->n && k != 0; i++) {
      rcb_complex iw = CMPLX(0.0, ms->x[i]);
      rcb_complex f = k == 1 ? iw : k == 2 ? iw * iw : k == -1 ? 1.0 / iw : 1.0 / (iw * iw);
      if (ms->ch[c].mag_only) f = cabs(f); /* |(i w)^k| = w^k: magnitudes stay magnitudes */
      ms->ch[c].data[i] *= f;
    }
    ms->ch[c].kind = kind;
  }
  return RCB_OK;
}

/* ---- files ---- */

rcb_status rcb_meas_slurp(rcb_meas *ms, const char *path, char **buf, size_t *len) {
  FILE *fp;
  char *b = NULL;
  size_t cap = 0, n = 0;
  *buf = NULL;
  *len = 0;
  if (!path || !path[0]) return rcb_meas_fail(ms, RCB_ERR_ARG, "no file name given");
  fp = fopen(path, "rb");
  if (!fp) /* out of memory (fopen's buffer) is RCB_ERR_NOMEM, as everywhere */
    return rcb_meas_fail(ms, errno == ENOMEM ? RCB_ERR_NOMEM : RCB_ERR_IO, "%s: cannot open: %s", path,
                          strerror(errno));
  for (;;) {
    size_t got;
    if (n + 1 >= cap) {
      size_t ncap = cap ? 2 * cap : 65536;
      char *nb = rcb_alloc(&ms->alloc, ncap);
      if (!nb) {
        rcb_free(&ms->alloc, b);
        fclose(fp);
        return rcb_meas_fail(ms, RCB_ERR_NOMEM, "%s: out of memory reading the file", path);
      }
      if (b) memcpy(nb, b, n);
      rcb_free(&ms->alloc, b);
      b = nb;
      cap = ncap;
    }
    got = fread(b + n, 1, cap - 1 - n, fp);
    n += got;
    if (got == 0) break;
  }
  if (ferror(fp)) {
    rcb_free(&ms->alloc, b);
    fclose(fp);
    return rcb_meas_fail(ms, RCB_ERR_IO, "%s: read error", path);
  }
  fclose(fp);
  b[n] = '\0';
  *buf = b;
  *len = n;
  return RCB_OK;
}

rcb_status rcb_atomic_open(rcb_meas *ms, rcb_atomic_file *af, const char *path, int binary) {
  int k;
  af->fp = NULL;
  af->tmp[0] = '\0';
  if (!path || !path[0]) return rcb_meas_fail(ms, RCB_ERR_ARG, "no output file name given");
  if (strlen(path) + 16 >= sizeof af->tmp)
    return rcb_meas_fail(ms, RCB_ERR_ARG, "%s: file name too long", path);
  /* C11 "x": exclusive creation, so two writers never share a temporary. */
  for (k = 0; k < 1000 && !af->fp; k++) {
    snprintf(af->tmp, sizeof af->tmp, "%s.tmp%03d", path, k);
    errno = 0;
    af->fp = fopen(af->tmp, binary ? "wbx" : "wx");
    if (!af->fp && errno != EEXIST) break;
  }
  if (!af->fp) {
    int e = errno;
    af->tmp[0] = '\0';
    return rcb_meas_fail(ms, RCB_ERR_IO, "%s: cannot create a temporary file next to it: %s",
                         path, strerror(e));
  }
  return RCB_OK;
}

void rcb_atomic_abort(rcb_atomic_file *af) {
  if (af->fp) fclose(af->fp);
  af->fp = NULL;
  if (af->tmp[0]) remove(af->tmp);
  af->tmp[0] = '\0';
}

rcb_status rcb_atomic_commit(rcb_meas *ms, rcb_atomic_file *af, const char *path) {
  int bad = ferror(af->fp) != 0;
  errno = 0;
  if (fflush(af->fp) != 0) bad = 1;
  if (fclose(af->fp) != 0) bad = 1;
  af->fp = NULL;
  if (bad) {
    int e = errno ? errno : EIO;
    rcb_atomic_abort(af);
    return rcb_meas_fail(ms, RCB_ERR_IO, "%s: write error: %s", path, strerror(e));
  }
  if (rename(af->tmp, path) != 0) {
    int e = errno;
    rcb_atomic_abort(af);
    return rcb_meas_fail(ms, RCB_ERR_IO, "%s: cannot replace the file: %s", path, strerror(e));
  }
  af->tmp[0] = '\0';
  return RCB_OK;
}

const char *rcb_uff_dir_name(long code) {
  static const char *const names[] = {"s", "x", "y", "z", "rx", "ry", "rz"};
  long a = code < 0 ? -code : code;
  return a <= 6 ? names[a] : NULL;
}

/* The UFF direction code of a map entry's dir name, -1 if it is none. */
static long dir_code(const char *name) {
  long k;
  for (k = 0; k <= 6; k++)
    if (strcmp(name, rcb_uff_dir_name(k)) == 0) return k;
  return -1;
}

const rcb_uff_node *rcb_uff_map_find(size_t nmap, const rcb_uff_node *map, long node,
                                     long code) {
  const char *name = rcb_uff_dir_name(code);
  const rcb_uff_node *whole = NULL;
  size_t i;
  for (i = 0; i < nmap; i++) {
    if (map[i].node != node || !map[i].station) continue;
    if (!map[i].dir)
      whole = whole ? whole : &map[i];
    else if (name && strcmp(map[i].dir, name) == 0)
      return &map[i];
  }
  return whole;
}

/* One entry's direction fields (node entry: both NULL). */
static rcb_status check_entry_dirs(rcb_meas *ms, const char *who, const rcb_uff_node *e) {
  if (!e->dir && !e->model_dir) return RCB_OK;
  if (!e->dir)
    return rcb_meas_fail(ms, RCB_ERR_ARG, "%s: node %ld of the map has a model direction "
                         "'%s' but no file direction; expected both (e.g. %ld.z=%s.x) or "
                         "neither", who, e->node, e->model_dir, e->node, e->station);
  if (dir_code(e->dir) < 0)
    return rcb_meas_fail(ms, RCB_ERR_ARG, "%s: map entry %ld.%.8s: file direction '%.8s' is "
                         "not a UFF direction; expected x, y, z, rx, ry, rz (1 to 6) or s "
                         "(scalar, 0)", who, e->node, e->dir, e->dir);
  if (!e->model_dir || !(strcmp(e->model_dir, "x") == 0 || strcmp(e->model_dir, "y") == 0 ||
                         strcmp(e->model_dir, "rx") == 0 || strcmp(e->model_dir, "ry") == 0))
    return rcb_meas_fail(ms, RCB_ERR_ARG, "%s: map entry %ld.%s=%s.%.8s: the model direction "
                         "must be x, y, rx or ry (the model's channels)", who, e->node, e->dir,
                         e->station, e->model_dir ? e->model_dir : "(none)");
  return RCB_OK;
}

rcb_status rcb_meas_check_map(rcb_meas *ms, const char *who, size_t nmap,
                              const rcb_uff_node *map) {
  size_t i, j;
  rcb_status st;
  if (nmap && !map) return rcb_meas_fail(ms, RCB_ERR_ARG, "%s: node map is NULL", who);
  for (i = 0; i < nmap; i++) {
    const char *st_name = map[i].station;
    if (!st_name || !st_name[0])
      return rcb_meas_fail(ms, RCB_ERR_ARG, "%s: node %ld of the map has no station", who,
                           map[i].node);
    if (strlen(st_name) > RCB_MEAS_STATION_MAX)
      return rcb_meas_fail(ms, RCB_ERR_ARG, "%s: node %ld of the map: station '%.40s...' has "
                           "%zu characters; at most %d", who, map[i].node, st_name,
                           strlen(st_name), RCB_MEAS_STATION_MAX);
    if ((st = check_entry_dirs(ms, who, &map[i]))) return st;
    for (j = 0; j < i; j++)
      if (map[j].node == map[i].node && (map[j].dir == NULL) == (map[i].dir == NULL) &&
          (!map[i].dir || strcmp(map[j].dir, map[i].dir) == 0))
        return rcb_meas_fail(ms, RCB_ERR_ARG, "%s: entries %zu and %zu of the map both give "
                             "node %ld%s%s; give each once", who, j + 1, i + 1, map[i].node,
                             map[i].dir ? "." : "", map[i].dir ? map[i].dir : "");
  }
  return RCB_OK;
}
