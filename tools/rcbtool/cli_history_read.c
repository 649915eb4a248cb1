/* rcbtool: reading a history file (issue #34 item 6).
 *
 * A history is input like a model or a measurement: every line is checked
 * whole before any step is shown or appended to, and the first line that is no
 * record is named with what is wrong with it. Each line is one flat JSON object
 * read by a small tokenizer (strings, numbers, null, true, false: the writer,
 * cli_history_append, writes nothing else). Numbers are read as whole JSON
 * tokens, however long, so the finite check sees the number the file holds
 * (a token cut at 63 characters let "1.000...e999" through as 1 and showed a
 * 71-digit 2e70 as 2e62). Errors and floors are finite and >= 0 (a -1.4e17 %
 * made a bar of 1.67 GB), commands are the three the tool writes. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli_history.h"

static const char *const COMMANDS[] = {"fit", "diagnose", "apply"};

/* The reader's place in one line. */
typedef struct lex {
  const char *p, *end;
  char *why;
  size_t nwhy;
  int nomem;
} lex;

static int fail(lex *x, const char *what) {
  snprintf(x->why, x->nwhy, "%s", what);
  return -1;
}

static void skip_ws(lex *x) {
  while (x->p < x->end && (*x->p == ' ' || *x->p == '\t')) x->p++;
}

/* Append code point @p cp as UTF-8 to @p out (room checked by the caller:
 * 4 bytes). */
static size_t put_utf8(char *out, unsigned long cp) {
  if (cp < 0x80) {
    out[0] = (char)cp;
    return 1;
  }
  if (cp < 0x800) {
    out[0] = (char)(0xc0 | (cp >> 6));
    out[1] = (char)(0x80 | (cp & 0x3f));
    return 2;
  }
  if (cp < 0x10000) {
    out[0] = (char)(0xe0 | (cp >> 12));
    out[1] = (char)(0x80 | ((cp >> 6) & 0x3f));
    out[2] = (char)(0x80 | (cp & 0x3f));
    return 3;
  }
  out[0] = (char)(0xf0 | (cp >> 18));
  out[1] = (char)(0x80 | ((cp >> 12) & 0x3f));
  out[2] = (char)(0x80 | ((cp >> 6) & 0x3f));
  out[3] = (char)(0x80 | (cp & 0x3f));
  return 4;
}

/* Four hex digits at @p s (within @p end) as a number, or -1. */
static long hex4(const char *s, const char *end) {
  long v = 0;
  int i;
  if (end - s < 4) return -1;
  for (i = 0; i < 4; i++) {
    char c = s[i];
    int d = c >= '0' && c <= '9' ? c - '0' : c >= 'a' && c <= 'f' ? c - 'a' + 10
          : c >= 'A' && c <= 'F' ? c - 'A' + 10 : -1;
    if (d < 0) return -1;
    v = 16 * v + d;
  }
  return v;
}

/* One escape after the backslash at x->p: its UTF-8 bytes into @p out; the
 * count, or 0 for a bad escape. \u0000 and a lone surrogate are read as
 * U+FFFD: a NUL would end the text. */
static size_t escape(lex *x, char *out) {
  static const char from[] = "\"\\/bfnrt", to[] = "\"\\/\b\f\n\r\t";
  const char *k;
  long cp;
  if (x->p >= x->end) return 0;
  if (*x->p != 'u') {
    if (!*x->p || !(k = strchr(from, *x->p))) return 0;
    x->p++;
    out[0] = to[k - from];
    return 1;
  }
  if ((cp = hex4(x->p + 1, x->end)) < 0) return 0;
  x->p += 5;
  if (cp >= 0xd800 && cp <= 0xdbff && x->end - x->p >= 6 && x->p[0] == '\\' &&
      x->p[1] == 'u') {
    long lo = hex4(x->p + 2, x->end);
    if (lo >= 0xdc00 && lo <= 0xdfff) {
      x->p += 6;
      return put_utf8(out, 0x10000 + (((unsigned long)cp - 0xd800) << 10) +
                               ((unsigned long)lo - 0xdc00));
    }
  }
  if (cp == 0 || (cp >= 0xd800 && cp <= 0xdfff)) cp = 0xfffd;
  return put_utf8(out, (unsigned long)cp);
}

/* A JSON string at x->p (its opening quote), decoded into a new string
 * (*out, NULL to skip it); 0 or -1. Raw bytes are kept as they are: the
 * printers escape them (cli_text.c). */
static int string(lex *x, char **out) {
  const char *q = ++x->p;
  char *s, *w;
  while (q < x->end && *q != '"') q += *q == '\\' && q + 1 < x->end ? 2 : 1;
  if (q >= x->end) return fail(x, "a string without its closing '\"'");
  /* decoded, a string is never longer than its text (an escape of 2, 6 or 12
   * characters gives 1, at most 3 or 4 bytes): the text's length + 1 is room */
  if (!(s = w = malloc((size_t)(q - x->p) + 1))) {
    x->nomem = 1;
    return -1;
  }
  while (x->p < q) {
    size_t n;
    if (*x->p != '\\') {
      *w++ = *x->p++;
      continue;
    }
    x->p++;
    if (!(n = escape(x, w))) {
      free(s);
      return fail(x, "a bad escape in a string (JSON: \\\" \\\\ \\/ \\b \\f \\n \\r \\t "
                  "\\uXXXX)");
    }
    w += n;
  }
  *w = '\0';
  x->p = q + 1;
  if (out)
    *out = s;
  else
    free(s);
  return 0;
}

/* The length of the JSON number at @p s (within @p end), 0 if none:
 * -?(0|[1-9][0-9]*)(.[0-9]+)?([eE][+-]?[0-9]+)?; *integer says it has no
 * fraction and no exponent. */
static size_t number_len(const char *s, const char *end, int *integer) {
  const char *p = s;
  size_t d;
  *integer = 1;
  if (p < end && *p == '-') p++;
  for (d = 0; p < end && *p >= '0' && *p <= '9'; p++) d++;
  if (d == 0 || (d > 1 && p[-(long)d] == '0')) return 0;
  if (p < end && *p == '.') {
    *integer = 0;
    for (p++, d = 0; p < end && *p >= '0' && *p <= '9'; p++) d++;
    if (d == 0) return 0;
  }
  if (p < end && (*p == 'e' || *p == 'E')) {
    *integer = 0;
    p++;
    if (p < end && (*p == '+' || *p == '-')) p++;
    for (d = 0; p < end && *p >= '0' && *p <= '9'; p++) d++;
    if (d == 0) return 0;
  }
  return (size_t)(p - s);
}

/* Kinds of value. */
enum { V_STRING, V_NUMBER, V_NULL, V_BOOL };

/* One value at x->p: its kind, a string decoded into *str (when @p str), a
 * number into *num (the whole token: strtod on a copy, the line has no NUL
 * after it) and *integer; 0 or -1. */
static int value(lex *x, int *kind, char **str, double *num, int *integer, const char *key) {
  size_t n;
  char *tok;
  if (x->p < x->end && *x->p == '"') {
    *kind = V_STRING;
    return string(x, str);
  }
  if ((size_t)(x->end - x->p) >= 4 && memcmp(x->p, "null", 4) == 0) {
    *kind = V_NULL;
    x->p += 4;
    return 0;
  }
  if ((size_t)(x->end - x->p) >= 4 && memcmp(x->p, "true", 4) == 0) {
    *kind = V_BOOL;
    x->p += 4;
    return 0;
  }
  if ((size_t)(x->end - x->p) >= 5 && memcmp(x->p, "false", 5) == 0) {
    *kind = V_BOOL;
    x->p += 5;
    return 0;
  }
  if (!(n = number_len(x->p, x->end, integer))) {
    char m[120];
    snprintf(m, sizeof m, "%s: expected a string, a number or null (a JSON number: no "
             "nan, inf, hex or leading '+')", key);
    return fail(x, m);
  }
  if (!(tok = malloc(n + 1))) {
    x->nomem = 1;
    return -1;
  }
  memcpy(tok, x->p, n);
  tok[n] = '\0';
  *num = strtod(tok, NULL);
  free(tok);
  *kind = V_NUMBER;
  x->p += n;
  return 0;
}

/* A key's number (error_pct, floor_pct): finite and >= 0, or null (NaN). */
static int percent(lex *x, const char *key, int kind, double v, double *out) {
  char m[160];
  if (kind == V_NULL) {
    *out = (double)NAN;
    return 0;
  }
  if (kind != V_NUMBER) {
    snprintf(m, sizeof m, "%s: expected a number or null", key);
    return fail(x, m);
  }
  if (!isfinite(v) || v < 0) {
    snprintf(m, sizeof m, "%s %.6g %% is %s", key, v, isfinite(v) ? "negative" : "not finite");
    return fail(x, m);
  }
  *out = v;
  return 0;
}

/* The known keys of a record. */
enum { K_COMMAND, K_MODEL, K_ERROR, K_FLOOR, K_PARAMS, K_NOTE, K_COUNT };
static const char *const KEYS[K_COUNT] = {"command", "model", "error_pct",
                                          "floor_pct", "params", "note"};

/* The value of known key @p k (kind @p kind; the string @p s, when the value is
 * one, is taken over) into @p st. */
static int set_field(lex *x, cli_hist_step *st, int k, int kind, char *s, double v,
                     int integer) {
  size_t i;
  if (k != K_COMMAND && k != K_MODEL && k != K_NOTE) free(s); /* a string for a number */
  if (k == K_COMMAND || k == K_MODEL || k == K_NOTE) {
    char **to = k == K_COMMAND ? &st->command : k == K_MODEL ? &st->model : &st->note;
    char m[120];
    if (kind != V_STRING) {
      snprintf(m, sizeof m, "%s: expected a string", KEYS[k]);
      return fail(x, m);
    }
    *to = s;
    if (k != K_COMMAND) return 0;
    for (i = 0; i < sizeof COMMANDS / sizeof COMMANDS[0]; i++)
      if (strcmp(s, COMMANDS[i]) == 0) return 0;
    snprintf(m, sizeof m, "command \"%.40s\" is none of fit, diagnose, apply", s);
    return fail(x, m);
  }
  if (k == K_ERROR) return percent(x, KEYS[k], kind, v, &st->error_pct);
  if (k == K_FLOOR) return percent(x, KEYS[k], kind, v, &st->floor_pct);
  if (kind == V_NULL) return 0; /* params: -1 already */
  if (kind != V_NUMBER || !integer || v < 0 || v > 1e9)
    return fail(x, "params: expected a count of parameters (a whole number from 0 to 1e9) "
                "or null");
  st->params = (long)v;
  return 0;
}

static void step_free(cli_hist_step *st) {
  free(st->command);
  free(st->model);
  free(st->note);
  memset(st, 0, sizeof *st);
}

/* The members of the object after its '{'; 0 or -1. */
static int members(lex *x, cli_hist_step *st, int *seen) {
  for (;;) {
    char *key = NULL, *s = NULL;
    double v = 0;
    int kind, integer = 0, k, rc;
    skip_ws(x);
    if (x->p >= x->end || *x->p != '"') return fail(x, "expected a key in '\"'");
    if (string(x, &key)) return -1;
    skip_ws(x);
    if (x->p >= x->end || *x->p != ':') {
      free(key);
      return fail(x, "expected ':' after a key");
    }
    x->p++;
    skip_ws(x);
    for (k = 0; k < K_COUNT && strcmp(key, KEYS[k]) != 0; k++) {
    }
    rc = value(x, &kind, k < K_COUNT ? &s : NULL, &v, &integer, key);
    if (!rc && k < K_COUNT && seen[k]) {
      char m[80];
      snprintf(m, sizeof m, "%s given twice", KEYS[k]);
      rc = fail(x, m);
    }
    free(key);
    if (rc) {
      free(s);
      return -1;
    }
    if (k < K_COUNT) {
      seen[k] = 1;
      if (set_field(x, st, k, kind, s, v, integer)) return -1;
    }
    skip_ws(x);
    if (x->p < x->end && *x->p == ',') {
      x->p++;
      continue;
    }
    if (x->p < x->end && *x->p == '}') {
      x->p++;
      return 0;
    }
    return fail(x, "expected ',' or '}' after a value (one flat JSON object a line)");
  }
}

/* One line (no newline, no trailing '\r') into @p st; 0 or -1. */
static int record(lex *x, cli_hist_step *st) {
  int seen[K_COUNT] = {0}, k;
  st->error_pct = st->floor_pct = (double)NAN;
  st->params = -1;
  if (memchr(x->p, '\0', (size_t)(x->end - x->p))) return fail(x, "a NUL byte");
  skip_ws(x);
  if (x->p >= x->end || *x->p != '{') return fail(x, "expected a JSON object '{...}'");
  x->p++;
  skip_ws(x);
  if (x->p < x->end && *x->p == '}') return fail(x, "an empty object");
  if (members(x, st, seen)) return -1;
  skip_ws(x);
  if (x->p < x->end) return fail(x, "text after the object's closing '}'");
  for (k = K_COMMAND; k <= K_ERROR; k++)
    if (!seen[k]) {
      char m[80];
      snprintf(m, sizeof m, "no \"%s\"", KEYS[k]);
      return fail(x, m);
    }
  if (!st->note && !(st->note = calloc(1, 1))) {
    x->nomem = 1;
    return -1;
  }
  return 0;
}

static int blank(const char *s, const char *end) {
  while (s < end && (*s == ' ' || *s == '\t')) s++;
  return s == end;
}

int cli_history_parse(const char *text, size_t len, cli_history *h) {
  size_t pos = 0, line = 0;
  memset(h, 0, sizeof *h);
  while (pos < len) {
    const char *nl = memchr(text + pos, '\n', len - pos);
    size_t end = nl ? (size_t)(nl - text) : len;
    lex x;
    cli_hist_step st;
    line++;
    x.p = text + pos;
    x.end = text + end;
    pos = end + 1;
    if (x.end > x.p && x.end[-1] == '\r') x.end--; /* CRLF */
    if (blank(x.p, x.end)) continue;
    x.why = h->why;
    x.nwhy = sizeof h->why;
    x.nomem = 0;
    memset(&st, 0, sizeof st);
    if (record(&x, &st)) {
      step_free(&st);
      cli_history_free(h);
      if (x.nomem) return -1;
      h->bad_line = line;
      return 1;
    }
    st.line = line;
    if (h->n == h->cap) {
      size_t cap = h->cap ? 2 * h->cap : 16;
      cli_hist_step *ns = realloc(h->step, cap * sizeof *ns);
      if (!ns) {
        step_free(&st);
        cli_history_free(h);
        return -1;
      }
      h->step = ns;
      h->cap = cap;
    }
    h->step[h->n++] = st;
  }
  return 0;
}

void cli_history_free(cli_history *h) {
  size_t i;
  for (i = 0; i < h->n; i++) step_free(&h->step[i]);
  free(h->step);
  h->step = NULL;
  h->n = h->cap = 0;
}

int cli_history_bar(double e, double emax, int width) {
  double r;
  if (!(emax > 0) || !(e > 0)) return 0;
  r = e / emax * width; /* e / emax first: 50 * 1e308 would be inf */
  if (!(r < width)) return width;
  return (int)lround(r);
}
