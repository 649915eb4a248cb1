/*
 * INI model loader: reading values out of the stored sections (numbers,
 * lists, names) and resolving positions ("A 0.20", "A end", "DA", "C.B") to
 * a shaft and an axial coordinate. Used by the build pass (ini_build.c).
 */
#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "model/ini_load.h"

/* Deepest chain of "at = OTHER_STATION" references followed. */
#define INI_MAX_DEPTH 8

#define TRY(x)              \
  do {                      \
    rcb_status st_ = (x);   \
    if (st_) return st_;    \
  } while (0)

/* ---- looking values up ---- */

const ini_entry *rcb_ini_get(const ini_section *s, const char *key) {
  size_t i;
  for (i = 0; i < s->n_ent; i++)
    if (strcmp(s->ent[i].key, key) == 0) return &s->ent[i];
  return NULL;
}

/* Next whitespace-separated token of [*p, end): its start, or NULL. */
const char *rcb_ini_next_tok(const char **p, const char *end, size_t *len) {
  const char *q = *p, *t;
  while (q < end && isspace((unsigned char)*q)) q++;
  if (q >= end) {
    *p = q;
    return NULL;
  }
  t = q;
  while (q < end && !isspace((unsigned char)*q)) q++;
  *len = (size_t)(q - t);
  *p = q;
  return t;
}

size_t rcb_ini_count_tok(const char *s, const char *end) {
  size_t n = 0, len;
  while (rcb_ini_next_tok(&s, end, &len)) n++;
  return n;
}

/* Copy a token into buf (truncated to size - 1). */
static const char *tok_str(char *buf, size_t size, const char *t, size_t n) {
  if (n >= size) n = size - 1;
  memcpy(buf, t, n);
  buf[n] = '\0';
  return buf;
}

rcb_status rcb_ini_parse_num(ini_ctx *c, const ini_section *s, const ini_entry *e, const char *t,
                            size_t n, const char *expect, double *out) {
  char buf[64], *end;
  double v;
  tok_str(buf, sizeof buf, t, n);
  if (n >= sizeof buf)
    return rcb_ini_error(c, RCB_ERR_PARSE, e->line, s, e->key,
                         "'%.20s...' is not a number; expected %s", buf, expect);
  v = strtod(buf, &end);
  if (end == buf || *end)
    return rcb_ini_error(c, RCB_ERR_PARSE, e->line, s, e->key,
                         "'%s' is not a number; expected %s", buf, expect);
  if (!isfinite(v))
    return rcb_ini_error(c, RCB_ERR_PARSE, e->line, s, e->key,
                         "'%s' is not a finite number (NaN and Inf are not accepted); "
                         "expected %s",
                         buf, expect);
  *out = v;
  return RCB_OK;
}

rcb_status rcb_ini_missing(ini_ctx *c, const ini_section *s, const char *key,
                          const char *expect) {
  return rcb_ini_error(c, RCB_ERR_PARSE, s->line, s, NULL, "missing key '%s'; expected %s = %s",
                       key, key, expect);
}

/* The one token of entry e ("value" or "word" in the messages). */
static rcb_status single_token(ini_ctx *c, const ini_section *s, const ini_entry *e,
                               const char *what, const char *expect, const char **t,
                               size_t *len) {
  const char *p = e->val;
  size_t n = rcb_ini_count_tok(e->val, e->val + e->len);
  if (n == 0)
    return rcb_ini_error(c, RCB_ERR_PARSE, e->line, s, e->key, "no value; expected %s", expect);
  if (n > 1)
    return rcb_ini_error(c, RCB_ERR_PARSE, e->line, s, e->key,
                         "%zu %ss in '%s'; expected one %s: %s", n, what, e->val, what, expect);
  *t = rcb_ini_next_tok(&p, e->val + e->len, len);
  return RCB_OK;
}

/* One number. *given (may be NULL) tells whether the key was present. */
rcb_status rcb_ini_get_num(ini_ctx *c, const ini_section *s, const char *key, const char *expect,
                          int required, double def, double *out) {
  const ini_entry *e = rcb_ini_get(s, key);
  const char *t;
  size_t len = 0;
  rcb_status st;
  if (!e) {
    if (required) return rcb_ini_missing(c, s, key, expect);
    *out = def;
    return RCB_OK;
  }
  if ((st = single_token(c, s, e, "value", expect, &t, &len))) return st;
  return rcb_ini_parse_num(c, s, e, t, len, expect, out);
}

/* A list of numbers, allocated through the model's allocator (caller frees). */
rcb_status rcb_ini_get_list(ini_ctx *c, const ini_section *s, const ini_entry *e,
                           const char *expect, double **out, size_t *n) {
  const char *p = e->val, *t;
  size_t len, i = 0, cnt = rcb_ini_count_tok(e->val, e->val + e->len);
  *out = NULL;
  *n = 0;
  if (cnt == 0)
    return rcb_ini_error(c, RCB_ERR_PARSE, e->line, s, e->key, "no value; expected %s", expect);
  *out = rcb_alloc(&c->m->alloc, cnt * sizeof **out);
  if (!*out) return rcb_ini_error(c, RCB_ERR_NOMEM, e->line, s, e->key, "out of memory");
  while ((t = rcb_ini_next_tok(&p, e->val + e->len, &len)) != NULL)
    if (rcb_ini_parse_num(c, s, e, t, len, expect, &(*out)[i++])) {
      rcb_free(&c->m->alloc, *out);
      *out = NULL;
      return c->st;
    }
  *n = cnt;
  return RCB_OK;
}

/* A single word (a name). */
rcb_status rcb_ini_get_word(ini_ctx *c, const ini_section *s, const char *key, const char *expect,
                           char *buf, size_t size) {
  const ini_entry *e = rcb_ini_get(s, key);
  const char *t;
  size_t len = 0;
  rcb_status st;
  if (!e) return rcb_ini_missing(c, s, key, expect);
  if ((st = single_token(c, s, e, "word", expect, &t, &len))) return st;
  if (len >= size)
    return rcb_ini_error(c, RCB_ERR_PARSE, e->line, s, key, "'%s' is too long; expected %s",
                         e->val, expect);
  tok_str(buf, size, t, len);
  return RCB_OK;
}

const ini_section *rcb_ini_find_sec(const ini_ctx *c, ini_sec_type t, const char *name) {
  size_t i;
  for (i = 0; i < c->n_sec; i++)
    if (c->sec[i].type == t && strcmp(c->sec[i].name, name) == 0) return &c->sec[i];
  return NULL;
}

/* "did you mean X?", "defined: A, B" or "none is defined", among the sections
 * whose type is in mask (bit per ini_sec_type), other than self. */
void rcb_ini_name_hint(const ini_ctx *c, unsigned mask, const ini_section *self,
                      const char *word, char *buf, size_t size) {
  const char *cand[64];
  size_t i, n = 0, used = 0;
  const char *near;
  for (i = 0; i < c->n_sec && n < 64; i++)
    if ((mask & (1u << c->sec[i].type)) && &c->sec[i] != self) cand[n++] = c->sec[i].name;
  if (n == 0) {
    snprintf(buf, size, "none is defined");
    return;
  }
  near = rcb_ini_closest(word, cand, n);
  if (near) {
    snprintf(buf, size, "did you mean %s?", near);
    return;
  }
  used = (size_t)snprintf(buf, size, "defined: ");
  for (i = 0; i < n && used < size; i++) {
    int k = snprintf(buf + used, size - used, "%s%s", i ? ", " : "", cand[i]);
    if (k < 0) break;
    used += (size_t)k;
  }
}

/* ---- positions ---- */

static rcb_status place(ini_ctx *c, const ini_section *s, const ini_entry *e, const char *txt,
                        const char *end, const char **shaft, double *z, int depth);

static const char *const at_expect =
    "'SHAFT z' (z in m, absolute), 'SHAFT start', 'SHAFT end', or the name of a disk, "
    "bearing, coupling or station";

/* A coupling's two stations, from its "between" key. */
rcb_status rcb_ini_between(ini_ctx *c, const ini_section *s, const char *sh[2], double z[2],
                          int depth) {
  const ini_entry *e = rcb_ini_get(s, "between");
  const char *comma;
  if (!e)
    return rcb_ini_missing(c, s, "between",
                   "two stations 'SHAFT z|start|end, SHAFT z|start|end', e.g. A end, B start");
  comma = strchr(e->val, ',');
  if (!comma || strchr(comma + 1, ','))
    return rcb_ini_error(c, RCB_ERR_PARSE, e->line, s, e->key,
                         "'%s' has %s; expected two stations separated by one comma: "
                         "'SHAFT z|start|end, SHAFT z|start|end', e.g. A end, B start",
                         e->val, comma ? "more than two fields" : "only one field");
  TRY(place(c, s, e, e->val, comma, &sh[0], &z[0], depth));
  return place(c, s, e, comma + 1, e->val + e->len, &sh[1], &z[1], depth);
}

/* "NAME" (one word): the position of another station. */
static rcb_status place_ref(ini_ctx *c, const ini_section *s, const ini_entry *e,
                            const char *word, const char **shaft, double *z, int depth) {
  static const ini_sec_type kinds[] = {INI_SEC_DISK, INI_SEC_BEARING, INI_SEC_STATION,
                                       INI_SEC_UNBALANCE};
  char name[2 * RCB_NAME_MAX], hint[200];
  const ini_section *o;
  const char *dot;
  size_t k;
  if (depth >= INI_MAX_DEPTH)
    return rcb_ini_error(c, RCB_ERR_PARSE, e->line, s, e->key,
                         "'%s': too many levels of station references (circular?); expected %s",
                         word, at_expect);
  for (k = 0; k < sizeof kinds / sizeof kinds[0]; k++)
    if ((o = rcb_ini_find_sec(c, kinds[k], word)) != NULL) {
      const ini_entry *oe = rcb_ini_get(o, "at");
      if (!oe) return rcb_ini_missing(c, o, "at", at_expect);
      return place(c, o, oe, oe->val, oe->val + oe->len, shaft, z, depth + 1);
    }
  /* a coupling: "C" is its station a, "C.SHAFT" the station on that shaft */
  snprintf(name, sizeof name, "%s", word);
  dot = strchr(name, '.');
  if (dot) name[dot - name] = '\0';
  if ((o = rcb_ini_find_sec(c, INI_SEC_COUPLING, name)) != NULL) {
    const char *sh[2];
    double zz[2];
    TRY(rcb_ini_between(c, o, sh, zz, depth + 1));
    for (k = 0; k < 2; k++)
      if (!dot || strcmp(dot + 1, sh[k]) == 0) {
        *shaft = sh[k];
        *z = zz[k];
        return RCB_OK;
      }
    return rcb_ini_error(c, RCB_ERR_NOT_FOUND, e->line, s, e->key,
                         "'%s': coupling %s joins shafts %s and %s; expected %s.%s or %s.%s",
                         word, name, sh[0], sh[1], name, sh[0], name, sh[1]);
  }
  if (rcb_ini_find_sec(c, INI_SEC_SHAFT, word))
    return rcb_ini_error(c, RCB_ERR_PARSE, e->line, s, e->key,
                         "'%s' is a shaft, not a position on it; expected '%s z' (m), "
                         "'%s start' or '%s end'",
                         word, word, word, word);
  rcb_ini_name_hint(c, INI_STATION_TYPES, s, word, hint, sizeof hint);
  return rcb_ini_error(c, RCB_ERR_NOT_FOUND, e->line, s, e->key,
                       "'%s' is not a defined disk, bearing, coupling or station (%s); "
                       "expected %s",
                       word, hint, at_expect);
}

static rcb_status place(ini_ctx *c, const ini_section *s, const ini_entry *e, const char *txt,
                        const char *end, const char **shaft, double *z, int depth) {
  char w0[2 * RCB_NAME_MAX], w1[64], hint[200];
  const char *p = txt, *t0, *t1;
  size_t n = rcb_ini_count_tok(txt, end), l0 = 0, l1 = 0;
  const ini_section *sh;
  if (n == 0 || n > 2)
    return rcb_ini_error(c, RCB_ERR_PARSE, e->line, s, e->key,
                         "%zu fields in '%.*s'; expected %s", n, (int)(end - txt), txt,
                         at_expect);
  t0 = rcb_ini_next_tok(&p, end, &l0);
  tok_str(w0, sizeof w0, t0, l0);
  if (n == 1) return place_ref(c, s, e, w0, shaft, z, depth);
  t1 = rcb_ini_next_tok(&p, end, &l1);
  tok_str(w1, sizeof w1, t1, l1);
  sh = rcb_ini_find_sec(c, INI_SEC_SHAFT, w0);
  if (!sh) {
    rcb_ini_name_hint(c, INI_TYPE_BIT(INI_SEC_SHAFT), NULL, w0, hint, sizeof hint);
    return rcb_ini_error(c, RCB_ERR_NOT_FOUND, e->line, s, e->key,
                         "shaft '%s' is not defined (%s); expected the name of a [shaft NAME] "
                         "section",
                         w0, hint);
  }
  *shaft = sh->name;
  if (strcmp(w1, "start") == 0)
    *z = sh->z0;
  else if (strcmp(w1, "end") == 0)
    *z = sh->z1;
  else
    return rcb_ini_parse_num(c, s, e, t1, l1,
                             "an axial position z in m (absolute), or start or end", z);
  return RCB_OK;
}

rcb_status rcb_ini_get_at(ini_ctx *c, const ini_section *s, const char **shaft, double *z) {
  const ini_entry *e = rcb_ini_get(s, "at");
  if (!e) return rcb_ini_missing(c, s, "at", at_expect);
  return place(c, s, e, e->val, e->val + e->len, shaft, z, 0);
}
