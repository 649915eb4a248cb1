/*
 * INI model loader, first pass: read the text, hand it to inih line by line,
 * and store the sections with their raw values and line numbers.
 *
 * inih's handler gets no line number in the Debian build
 * (INI_HANDLER_LINENO = 0), so the loader reads through ini_parse_stream with
 * its own reader over an in-memory buffer: the reader counts lines, spots
 * section headers (inih does not report them, and truncates long ones), and
 * flags lines longer than inih's line buffer instead of letting inih split
 * them. The reader mirrors inih's rule for continuation lines (an indented
 * line after a key continues that key's value) so the handler knows whether
 * a call is a new key or a continuation.
 */
#include <ctype.h>
#include <errno.h>
#include <stdio.h>
#include <string.h>

#include <ini.h>

#include "model/ini_load.h"
#include "model/model_util.h"

/* Longest file accepted, bytes: a model is a few kB; this only guards against
 * reading a wrong (binary, huge) file into memory. */
#define INI_MAX_FILE ((size_t)16 * 1024 * 1024)

static const char *const type_names[INI_SEC_COUNT] = {
    "model", "material", "shaft", "disk", "bearing", "coupling", "unbalance", "station", "uff",
    "test"};

/* Keys of each section type, in the order the format documents them. */
static const char *const keys_model[] = {"name", "description", "speed_factor"};
static const char *const keys_material[] = {"density", "young", "poisson"};
static const char *const keys_shaft[] = {"material",          "start",
                                         "shear_factor",      "damping_mass",
                                         "damping_stiffness", "stiffness_factor",
                                         "mass_factor",       "segment",
                                         "element_stiffness", "element_mass"};
static const char *const keys_disk[] = {"at",      "mass",           "Id",
                                        "Ip",      "density",        "outer_diameter",
                                        "inner_diameter", "width"};
static const char *const keys_bearing[] = {"at",  "kxx", "kxy", "kyx",       "kyy", "cxx",
                                           "cxy", "cyx", "cyy", "speed_rpm", "speed",
                                           "pedestal_mass", "pedestal_kxx", "pedestal_kyy",
                                           "pedestal_cxx", "pedestal_cyy"};
static const char *const keys_coupling[] = {
    "model",       "between",      "kt",           "kr",
    "ct",          "cr",           "hub_mass",     "hub_Id",
    "hub_Ip",      "hub_density",  "hub_inner_radius", "hub_outer_radius",
    "hub_thickness"};
static const char *const keys_unbalance[] = {"at", "amount", "phase_deg"};
static const char *const keys_station[] = {"at"};
static const char *const keys_uff[] = {"map"};
static const char *const keys_test[] = {"rpm"};

typedef struct key_table {
  const char *const *keys;
  size_t n;
} key_table;

#define KT(a) {(a), sizeof(a) / sizeof((a)[0])}
static const key_table key_tables[INI_SEC_COUNT] = {
    KT(keys_model),    KT(keys_material), KT(keys_shaft),     KT(keys_disk),
    KT(keys_bearing),  KT(keys_coupling), KT(keys_unbalance), KT(keys_station),
    KT(keys_uff),      KT(keys_test)};
#undef KT

const char *rcb_ini_type_name(ini_sec_type t) {
  return (int)t >= 0 && t < INI_SEC_COUNT ? type_names[t] : "?";
}

/* ---- messages ---- */

rcb_status (rcb_ini_error)(ini_ctx *c, rcb_status st, int line, const ini_section *s,
                           const char *key, const char *fmt, ...) {
  char what[RCB_ERRMSG_MAX], where[2 * RCB_NAME_MAX + 80], pos[24];
  va_list ap;
  if (c->st) return c->st;
  va_start(ap, fmt);
  vsnprintf(what, sizeof what, fmt, ap);
  va_end(ap);
  if (s && !s->name[0]) /* [model], [uff], [test] take no name */
    snprintf(where, sizeof where, " [%s]", type_names[s->type]);
  else if (s)
    snprintf(where, sizeof where, " [%s %s]", type_names[s->type], s->name);
  else
    where[0] = '\0';
  /* "FILE:LINE: [type name] key: what", with the parts that apply */
  if (line > 0)
    snprintf(pos, sizeof pos, ":%d", line);
  else
    pos[0] = '\0';
  if (s || key)
    rcb_model_fail(c->m, st, "%s%s:%s%s%s: %s", c->src, pos, where, key ? " " : "",
                   key ? key : "", what);
  else
    rcb_model_fail(c->m, st, "%s%s: %s", c->src, pos, what);
  c->st = st;
  return st;
}


const char *rcb_ini_closest(const char *word, const char *const *cand, size_t n) {
  size_t i, best_d = (size_t)-1, limit = strlen(word) >= 4 ? 2 : 1;
  const char *best = NULL;
  for (i = 0; i < n; i++) {
    size_t d = rcb_edit_distance(word, cand[i]);
    if (d < best_d) {
      best_d = d;
      best = cand[i];
    }
  }
  return best_d <= limit ? best : NULL;
}

/* "a, b, c" into buf. */
static void join(char *buf, size_t size, const char *const *w, size_t n) {
  size_t i, used = 0;
  buf[0] = '\0';
  for (i = 0; i < n && used < size; i++) {
    int k = snprintf(buf + used, size - used, "%s%s", i ? ", " : "", w[i]);
    if (k < 0) break;
    used += (size_t)k;
  }
}

/* ---- sections and entries ---- */

static ini_entry *add_entry(ini_ctx *c, ini_section *s, const char *key, const char *value) {
  ini_entry *e;
  size_t n = strlen(value);
  if (rcb_grow(&c->m->alloc, (void **)&s->ent, &s->cap_ent, s->n_ent + 1, sizeof *s->ent)) {
    rcb_ini_error(c, RCB_ERR_NOMEM, c->line, s, key, "out of memory");
    return NULL;
  }
  e = &s->ent[s->n_ent];
  memset(e, 0, sizeof *e);
  e->val = rcb_alloc(&c->m->alloc, n + 1);
  if (!e->val) {
    rcb_ini_error(c, RCB_ERR_NOMEM, c->line, s, key, "out of memory");
    return NULL;
  }
  memcpy(e->val, value, n + 1);
  e->key = key;
  e->line = c->line;
  e->len = n;
  e->cap = n + 1;
  c->last = (long)s->n_ent++;
  return e;
}

static rcb_status append_value(ini_ctx *c, ini_section *s, ini_entry *e, const char *more) {
  size_t n = strlen(more);
  if (n == 0) return RCB_OK;
  if (rcb_grow(&c->m->alloc, (void **)&e->val, &e->cap, e->len + n + 2, 1))
    return rcb_ini_error(c, RCB_ERR_NOMEM, c->line, s, e->key, "out of memory");
  if (e->len) e->val[e->len++] = ' ';
  memcpy(e->val + e->len, more, n + 1);
  e->len += n;
  return RCB_OK;
}

static int is_station_type(ini_sec_type t) {
  return t == INI_SEC_DISK || t == INI_SEC_BEARING || t == INI_SEC_COUPLING ||
         t == INI_SEC_UNBALANCE || t == INI_SEC_STATION;
}

/* Check a new section's name against those already read. */
static rcb_status check_duplicate(ini_ctx *c, ini_sec_type t, const char *name) {
  size_t i;
  for (i = 0; i < c->n_sec; i++) {
    const ini_section *o = &c->sec[i];
    if (o->type == t && strcmp(o->name, name) == 0) {
      if (t == INI_SEC_MODEL || t == INI_SEC_UFF)
        return rcb_ini_error(c, RCB_ERR_PARSE, c->line, NULL, NULL,
                             "duplicate section [%s] (first at line %d); expected at most "
                             "one [%s] section",
                             type_names[t], o->line, type_names[t]);
      return rcb_ini_error(c, RCB_ERR_PARSE, c->line, NULL, NULL,
                           "duplicate section [%s %s] (first defined at line %d); expected "
                           "unique names",
                           type_names[t], name, o->line);
    }
    if (is_station_type(t) && is_station_type(o->type) && strcmp(o->name, name) == 0)
      return rcb_ini_error(c, RCB_ERR_PARSE, c->line, NULL, NULL,
                           "duplicate name: [%s %s] uses the name of [%s %s] (line %d); "
                           "expected unique names for disks, bearings, couplings, unbalances "
                           "and stations (channels are addressed by them)",
                           type_names[t], name, type_names[o->type], o->name, o->line);
  }
  return RCB_OK;
}

/* A "[type name]" header (p points at '['). */
static rcb_status open_section(ini_ctx *c, const char *p) {
  char head[256], type[64], name[256], extra[8];
  const char *end = p + 1;
  const unsigned char *q;
  int nf, t;
  ini_section *s;
  /* inih: ']' ends the header unless an inline comment (" ;") comes first */
  while (*end && *end != ']' && !(*end == ';' && isspace((unsigned char)end[-1]))) end++;
  if (*end != ']')
    return rcb_ini_error(c, RCB_ERR_PARSE, c->line, NULL, NULL,
                         "section header without closing ']'; expected [TYPE NAME], e.g. "
                         "[shaft A]");
  if ((size_t)(end - p - 1) >= sizeof head)
    return rcb_ini_error(c, RCB_ERR_PARSE, c->line, NULL, NULL,
                         "section header too long; expected [TYPE NAME] with a name of at "
                         "most %d characters",
                         RCB_NAME_MAX - 1);
  memcpy(head, p + 1, (size_t)(end - p - 1));
  head[end - p - 1] = '\0';
  nf = sscanf(head, "%63s %255s %7s", type, name, extra);
  if (nf < 1)
    return rcb_ini_error(c, RCB_ERR_PARSE, c->line, NULL, NULL,
                         "empty section header []; expected [TYPE NAME], e.g. [shaft A]");
  for (t = 0; t < INI_SEC_COUNT; t++)
    if (strcmp(type, type_names[t]) == 0) break;
  if (t == INI_SEC_COUNT) {
    char all[160];
    const char *near = rcb_ini_closest(type, type_names, INI_SEC_COUNT);
    join(all, sizeof all, type_names, INI_SEC_COUNT);
    if (near)
      return rcb_ini_error(c, RCB_ERR_PARSE, c->line, NULL, NULL,
                           "unknown section type [%s]; did you mean [%s]? (expected one of: %s)",
                           type, near, all);
    return rcb_ini_error(c, RCB_ERR_PARSE, c->line, NULL, NULL,
                         "unknown section type [%s]; expected one of: %s", type, all);
  }
  if ((t == INI_SEC_MODEL || t == INI_SEC_UFF || t == INI_SEC_TEST) && nf > 1)
    return rcb_ini_error(c, RCB_ERR_PARSE, c->line, NULL, NULL,
                         "[%s %s]: the [%s] section takes no name; expected [%s]", type, name,
                         type, type);
  if (t != INI_SEC_MODEL && t != INI_SEC_UFF && t != INI_SEC_TEST && nf < 2)
    return rcb_ini_error(c, RCB_ERR_PARSE, c->line, NULL, NULL,
                         "[%s] needs a name; expected [%s NAME], e.g. [%s %s]", type, type,
                         type, t == INI_SEC_SHAFT ? "A" : "X1");
  if (nf > 2)
    return rcb_ini_error(c, RCB_ERR_PARSE, c->line, NULL, NULL,
                         "[%s]: more than one name in the header; expected [TYPE NAME] with a "
                         "name without spaces",
                         head);
  if (nf < 2) name[0] = '\0';
  if (strlen(name) >= RCB_NAME_MAX)
    return rcb_ini_error(c, RCB_ERR_PARSE, c->line, NULL, NULL,
                         "[%s %s]: name longer than %d characters; expected a shorter name",
                         type, name, RCB_NAME_MAX - 1);
  /* a name the INI writer could not write back ([kind NAME], KEY = NAME,
   * "NAME z, NAME z"); bytes >= 0x80 (UTF-8) pass */
  for (q = (const unsigned char *)name; *q; q++)
    if (*q < 0x20 || *q == 0x7f || strchr("[];,=:", *q))
      return rcb_ini_error(c, RCB_ERR_PARSE, c->line, NULL, NULL,
                           "[%s ...]: byte 0x%02x cannot be used in a name; expected letters, "
                           "digits, '_' or '-' (no control characters or [ ] ; , = :)",
                           type, *q);
  if (check_duplicate(c, (ini_sec_type)t, name)) return c->st;
  if (rcb_grow(&c->m->alloc, (void **)&c->sec, &c->cap_sec, c->n_sec + 1, sizeof *c->sec))
    return rcb_ini_error(c, RCB_ERR_NOMEM, c->line, NULL, NULL, "out of memory");
  s = &c->sec[c->n_sec];
  memset(s, 0, sizeof *s);
  s->type = (ini_sec_type)t;
  memcpy(s->name, name, strlen(name) + 1); /* length checked above */
  s->line = c->line;
  c->cur = (long)c->n_sec++;
  c->last = -1;
  c->prev_key = 0;
  return RCB_OK;
}

/* Classify a line the way inih will, before inih sees it. */
static rcb_status classify(ini_ctx *c, const char *line) {
  const char *p = line, *q;
  while (isspace((unsigned char)*p)) p++;
  c->cont = 0;
  if (*p == '\0' || *p == ';' || *p == '#') return RCB_OK;
  if (c->prev_key && p > line) {
    c->cont = 1;
    return RCB_OK;
  }
  if (*p == '[') return open_section(c, p);
  for (q = p; *q && *q != '=' && *q != ':'; q++)
    if (*q == ';' && q > p && isspace((unsigned char)q[-1])) break;
  if (*q != '=' && *q != ':')
    return rcb_ini_error(c, RCB_ERR_PARSE, c->line, NULL, NULL,
                         "cannot read this line; expected a [TYPE NAME] header, KEY = VALUE, "
                         "or a comment starting with ';'");
  c->prev_key = 1;
  return RCB_OK;
}

/* inih reader: one line of the buffer per call, with the line counted. */
static char *read_line(char *str, int num, void *stream) {
  ini_ctx *c = stream;
  const char *p, *nl;
  size_t n, rest;
  if (c->st || c->pos >= c->len) return NULL;
  p = c->text + c->pos;
  rest = c->len - c->pos;
  nl = memchr(p, '\n', rest);
  n = nl ? (size_t)(nl - p) : rest;
  c->pos += nl ? n + 1 : n;
  c->line++;
  if (n > 0 && p[n - 1] == '\r') n--;
  if (memchr(p, '\0', n)) {
    rcb_ini_error(c, RCB_ERR_PARSE, c->line, NULL, NULL,
                  "the line contains a NUL byte; expected a text file");
    return NULL;
  }
  /* inih needs room for the text, "\r\n" and the NUL: longer lines would be
   * split silently into two "lines" */
  if (num < 4 || n > (size_t)num - 3) {
    rcb_ini_error(c, RCB_ERR_PARSE, c->line, NULL, NULL,
                  "line too long (%zu characters); expected at most %d characters per line "
                  "(inih's limit): continue a long list on indented lines below the key",
                  n, num - 3);
    return NULL;
  }
  memcpy(str, p, n);
  str[n] = '\0';
  if (classify(c, str)) return NULL;
  str[n] = '\n';
  str[n + 1] = '\0';
  return str;
}

static const char *lookup_key(ini_sec_type t, const char *key) {
  size_t i;
  for (i = 0; i < key_tables[t].n; i++)
    if (strcmp(key, key_tables[t].keys[i]) == 0) return key_tables[t].keys[i];
  return NULL;
}

static rcb_status unknown_key(ini_ctx *c, const ini_section *s, const char *key) {
  char all[300];
  const key_table *kt = &key_tables[s->type];
  const char *near;
  if (s->type == INI_SEC_UNBALANCE && strcmp(key, "phase") == 0)
    return rcb_ini_error(c, RCB_ERR_PARSE, c->line, s, key,
                         "unknown key; the phase is given in degrees: expected phase_deg = "
                         "angle in degrees from +x towards +y");
  near = rcb_ini_closest(key, kt->keys, kt->n);
  join(all, sizeof all, kt->keys, kt->n);
  if (near)
    return rcb_ini_error(c, RCB_ERR_PARSE, c->line, s, key,
                         "unknown key; did you mean %s? (expected one of: %s)", near, all);
  return rcb_ini_error(c, RCB_ERR_PARSE, c->line, s, key,
                       "unknown key for a [%s] section; expected one of: %s",
                       type_names[s->type], all);
}

/* An indented line continuing the previous key. */
static rcb_status continuation(ini_ctx *c, ini_section *s, const char *value) {
  char buf[512];
  size_t n;
  const char *q;
  ini_entry *e = &s->ent[c->last];
  /* inih 55 does not strip inline comments from continuation lines */
  for (q = value; *q; q++)
    if (*q == ';' && (q == value || isspace((unsigned char)q[-1]))) break;
  n = (size_t)(q - value);
  while (n > 0 && isspace((unsigned char)value[n - 1])) n--;
  if (n >= sizeof buf) n = sizeof buf - 1; /* cannot happen: lines are shorter */
  memcpy(buf, value, n);
  buf[n] = '\0';
  if (buf[0] == '[')
    return rcb_ini_error(c, RCB_ERR_PARSE, c->line, s, e->key,
                         "indented line '%s' is read as a continuation of %s (line %d); "
                         "expected section headers to start in the first column",
                         buf, e->key, e->line);
  if (n == 0) return RCB_OK;
  if (strcmp(e->key, "segment") == 0) {
    /* each continuation line of segment is one more segment */
    const char *key = e->key;
    return add_entry(c, s, key, buf) ? RCB_OK : c->st;
  }
  return append_value(c, s, e, buf);
}

/* inih handler: every "key = value" and every continuation line. */
static int on_key(void *user, const char *section, const char *key, const char *value) {
  ini_ctx *c = user;
  ini_section *s;
  const char *k;
  size_t i;
  (void)section; /* inih truncates it; the reader keeps the full header */
  if (c->st) return 0;
  if (c->cur < 0) {
    rcb_ini_error(c, RCB_ERR_PARSE, c->line, NULL, key,
                  "key outside any section; expected a section header first, e.g. "
                  "[shaft A]");
    return 0;
  }
  s = &c->sec[c->cur];
  if (c->cont) return continuation(c, s, value) ? 0 : 1;
  k = lookup_key(s->type, key);
  if (!k) {
    unknown_key(c, s, key);
    return 0;
  }
  /* list keys that may be repeated: segment, and the element factors
   * (pairs "k factor", any number of lines) */
  if (strcmp(k, "segment") != 0 && strcmp(k, "element_stiffness") != 0 &&
      strcmp(k, "element_mass") != 0)
    for (i = 0; i < s->n_ent; i++)
      if (s->ent[i].key == k) {
        rcb_ini_error(c, RCB_ERR_PARSE, c->line, s, key,
                      "given twice (first at line %d); expected one %s per section", s->ent[i].line,
                      key);
        return 0;
      }
  return add_entry(c, s, k, value) ? 1 : 0;
}

/* ---- the model is loaded whole or not at all ---- */

static int model_is_empty(const rcb_model *m) {
  return !m->finalized && m->n_materials == 0 && m->n_shafts == 0 && m->n_disks == 0 &&
         m->n_bearings == 0 && m->n_couplings == 0 && m->n_unbalances == 0 &&
         m->n_probes == 0;
}

/* After a failed load: drop what the builder added, keep the message. */
static void model_reset(rcb_model *m) {
  size_t i;
  for (i = 0; i < m->n_shafts; i++) {
    rcb_free(&m->alloc, m->shafts[i].seg);
    rcb_free(&m->alloc, m->shafts[i].ef);
    m->shafts[i].seg = NULL;
    m->shafts[i].ef = NULL;
    m->shafts[i].nseg = m->shafts[i].capseg = 0;
    m->shafts[i].nef = m->shafts[i].capef = 0;
  }
  for (i = 0; i < m->n_bearings; i++) {
    rcb_free(&m->alloc, m->bearings[i].speeds);
    rcb_free(&m->alloc, m->bearings[i].c);
    m->bearings[i].speeds = NULL;
    m->bearings[i].c = NULL;
  }
  m->n_materials = m->n_shafts = m->n_disks = m->n_bearings = 0;
  m->n_couplings = m->n_unbalances = m->n_probes = 0;
  m->n_uffmap = m->n_warnings = 0;
  m->n_stations = m->n_nodes = m->n_elements = 0;
  m->ndof = m->bandwidth = 0;
  m->n_peds = 0;
  m->speed_factor = 1.0;
  m->has_test_speed = 0;
  m->finalized = 0;
}

static void ctx_free(ini_ctx *c) {
  size_t i, j;
  for (i = 0; i < c->n_sec; i++) {
    for (j = 0; j < c->sec[i].n_ent; j++) rcb_free(&c->m->alloc, c->sec[i].ent[j].val);
    rcb_free(&c->m->alloc, c->sec[i].ent);
  }
  rcb_free(&c->m->alloc, c->sec);
}

static rcb_status load_text(rcb_model *m, const char *text, size_t len, const char *src) {
  ini_ctx c;
  int r;
  memset(&c, 0, sizeof c);
  c.m = m;
  c.src = src;
  c.text = text;
  c.len = len;
  c.cur = -1;
  c.last = -1;
  if (len >= 3 && memcmp(text, "\xEF\xBB\xBF", 3) == 0) c.pos = 3; /* UTF-8 BOM */
  r = ini_parse_stream(read_line, &c, on_key, &c);
  if (!c.st && r > 0)
    rcb_ini_error(&c, RCB_ERR_PARSE, r, NULL, NULL,
                  "cannot read this line; expected a [TYPE NAME] header, KEY = VALUE, or a "
                  "comment starting with ';'");
  else if (!c.st && r < 0)
    rcb_ini_error(&c, RCB_ERR_NOMEM, 0, NULL, NULL, "the INI reader ran out of memory");
  if (!c.st) rcb_ini_build(&c);
  ctx_free(&c);
  if (c.st) model_reset(m);
  return c.st;
}

rcb_status rcb_model_load_string(rcb_model *m, const char *text, const char *source_name) {
  if (!m || !text) return RCB_ERR_ARG;
  if (!source_name) source_name = "<string>";
  if (!model_is_empty(m))
    return rcb_model_fail(m, RCB_ERR_STATE,
                          "%s: the model already has items; expected a new model from "
                          "rcb_model_create",
                          source_name);
  return load_text(m, text, strlen(text), source_name);
}

rcb_status rcb_model_load_file(rcb_model *m, const char *path) {
  FILE *f;
  char *buf = NULL;
  size_t len = 0, cap = 0, got;
  rcb_status st;
  if (!m || !path) return RCB_ERR_ARG;
  if (!model_is_empty(m))
    return rcb_model_fail(m, RCB_ERR_STATE,
                          "%s: the model already has items; expected a new model from "
                          "rcb_model_create",
                          path);
  f = fopen(path, "rb");
  if (!f) /* out of memory (fopen's buffer) is RCB_ERR_NOMEM, as everywhere */
    return rcb_model_fail(m, errno == ENOMEM ? RCB_ERR_NOMEM : RCB_ERR_IO,
                          "%s: cannot open the model file (%s)", path, strerror(errno));
  do {
    if (rcb_grow(&m->alloc, (void **)&buf, &cap, len + 4096 + 1, 1)) {
      fclose(f);
      rcb_free(&m->alloc, buf);
      return rcb_model_fail(m, RCB_ERR_NOMEM, "%s: out of memory reading the file", path);
    }
    got = fread(buf + len, 1, cap - len - 1, f);
    len += got;
  } while (got > 0 && len <= INI_MAX_FILE);
  if (ferror(f) || len > INI_MAX_FILE) {
    int toolong = len > INI_MAX_FILE;
    fclose(f);
    rcb_free(&m->alloc, buf);
    if (toolong)
      return rcb_model_fail(m, RCB_ERR_IO,
                            "%s: file larger than %zu bytes; expected an INI model file", path,
                            INI_MAX_FILE);
    return rcb_model_fail(m, RCB_ERR_IO, "%s: read error", path);
  }
  fclose(f);
  buf[len] = '\0';
  st = load_text(m, buf, len, path);
  rcb_free(&m->alloc, buf);
  return st;
}
