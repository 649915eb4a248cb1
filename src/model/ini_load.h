/*
 * INI model loader, internal. Two passes:
 *  1. ini_load.c feeds inih one line at a time from an in-memory buffer (so
 *     every key and section header gets its line number) and stores the
 *     sections and their raw values;
 *  2. ini_build.c turns the stored sections into builder calls
 *     (rcb_model_add_*), in dependency order, so sections may come in any
 *     order in the file.
 * Every error names "FILE:LINE: [section] key: what is wrong; expected ...".
 */
#ifndef RCB_INI_LOAD_H
#define RCB_INI_LOAD_H

#include "core/rcb_internal.h"

typedef enum ini_sec_type {
  INI_SEC_MODEL = 0,
  INI_SEC_MATERIAL,
  INI_SEC_SHAFT,
  INI_SEC_DISK,
  INI_SEC_BEARING,
  INI_SEC_COUPLING,
  INI_SEC_UNBALANCE,
  INI_SEC_STATION,
  INI_SEC_UFF,
  INI_SEC_TEST,
  INI_SEC_COUNT
} ini_sec_type;

/* One key of a section. Repeated list keys (segment) and every continuation
 * line of a segment are separate entries; continuation lines of other keys
 * are appended to the value, separated by a space. */
typedef struct ini_entry {
  const char *key; /* points into the static key table */
  int line;        /* line of the key, 1-based */
  char *val;       /* NUL-terminated, owned */
  size_t len, cap;
} ini_entry;

typedef struct ini_section {
  ini_sec_type type;
  char name[2 * RCB_NAME_MAX];
  int line; /* line of the [header] */
  ini_entry *ent;
  size_t n_ent, cap_ent;
  /* filled by the build pass for shafts: axial extent, m */
  double z0, z1;
  int built;
} ini_section;

typedef struct ini_ctx {
  rcb_model *m;
  const char *src; /* file or source name for messages */
  const char *text;
  size_t len, pos;
  int line;      /* lines handed to inih so far */
  int cont;      /* the current line continues the previous key */
  int prev_key;  /* mirrors inih's prev_name: a key was read in this section */
  long cur;      /* current section, -1 before the first header */
  long last;     /* entry index of the last key in the current section */
  rcb_status st; /* first error (its message is in m->errmsg) */
  ini_section *sec;
  size_t n_sec, cap_sec;
} ini_ctx;

/* Section type name ("material", ...). */
const char *rcb_ini_type_name(ini_sec_type t);

/* Record an error "SRC:LINE: [type name] key: message" (section and key may
 * be NULL) unless one is already recorded; returns the status. */
rcb_status rcb_ini_error(ini_ctx *c, rcb_status st, int line, const ini_section *s,
                         const char *key, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 6, 7)))
#endif
    ;
#ifdef __clang_analyzer__ /* returns st: see rcb_set_error in core/rcb_internal.h */
#define rcb_ini_error(o, st, ...) ((void)(rcb_ini_error)((o), (st), __VA_ARGS__), (st))
#endif

/* Closest of n candidate strings to word (case-insensitive edit distance),
 * NULL if none is close enough to be a plausible typo. */
const char *rcb_ini_closest(const char *word, const char *const *cand, size_t n);

/* ---- ini_values.c: values of the stored sections ---- */

#define INI_TYPE_BIT(t) (1u << (t))
#define INI_STATION_TYPES                                                            \
  (INI_TYPE_BIT(INI_SEC_DISK) | INI_TYPE_BIT(INI_SEC_BEARING) |                      \
   INI_TYPE_BIT(INI_SEC_COUPLING) | INI_TYPE_BIT(INI_SEC_UNBALANCE) |                \
   INI_TYPE_BIT(INI_SEC_STATION))

/* First entry of key in s, or NULL. */
const ini_entry *rcb_ini_get(const ini_section *s, const char *key);
/* Whitespace-separated tokens of [*p, end): next one (NULL at the end), count. */
const char *rcb_ini_next_tok(const char **p, const char *end, size_t *len);
size_t rcb_ini_count_tok(const char *s, const char *end);
/* A finite number from token t (n chars) of entry e; expect says what is expected. */
rcb_status rcb_ini_parse_num(ini_ctx *c, const ini_section *s, const ini_entry *e,
                             const char *t, size_t n, const char *expect, double *out);
/* Report a missing key at the section header. */
rcb_status rcb_ini_missing(ini_ctx *c, const ini_section *s, const char *key,
                           const char *expect);
/* One number; def when absent and not required. */
rcb_status rcb_ini_get_num(ini_ctx *c, const ini_section *s, const char *key,
                           const char *expect, int required, double def, double *out);
/* All numbers of e, allocated through the model's allocator (caller frees). */
rcb_status rcb_ini_get_list(ini_ctx *c, const ini_section *s, const ini_entry *e,
                            const char *expect, double **out, size_t *n);
/* One word (a name), required. */
rcb_status rcb_ini_get_word(ini_ctx *c, const ini_section *s, const char *key,
                            const char *expect, char *buf, size_t size);
const ini_section *rcb_ini_find_sec(const ini_ctx *c, ini_sec_type t, const char *name);
/* "did you mean X?", "defined: A, B" or "none is defined", among the sections
 * whose type bit is in mask, other than self. */
void rcb_ini_name_hint(const ini_ctx *c, unsigned mask, const ini_section *self,
                       const char *word, char *buf, size_t size);
/* The position of s's "at" key / a coupling's two "between" stations: shaft
 * name (points into the section table) and absolute z, m. */
rcb_status rcb_ini_get_at(ini_ctx *c, const ini_section *s, const char **shaft, double *z);
rcb_status rcb_ini_between(ini_ctx *c, const ini_section *s, const char *sh[2], double z[2],
                           int depth);

/* ---- ini_build.c ---- */

/* Second pass: build the model from the stored sections and finalize it. */
rcb_status rcb_ini_build(ini_ctx *c);

#endif
