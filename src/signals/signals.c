/*
 * The signal container: channels sampled together, held in SI with their
 * quantity. Readers (signals_csv.c, signals_wav.c, signals_uff.c) fill it.
 */
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "signals/signals_internal.h"

rcb_status rcb_signals_create(rcb_signals **out, const rcb_allocator *alloc) {
  rcb_allocator a;
  rcb_signals *s;
  if (!out) return RCB_ERR_ARG;
  rcb_allocator_init(&a, alloc);
  s = rcb_alloc(&a, sizeof *s);
  *out = s;
  if (!s) return RCB_ERR_NOMEM;
  s->alloc = a;
  return RCB_OK;
}

void rcb_signals_empty(rcb_signals *s) {
  size_t i;
  for (i = 0; i < s->nch; i++) rcb_free(&s->alloc, s->ch[i].v);
  s->nch = 0;
  s->n = 0;
  s->nrec = 0;
  s->rate = 0.0;
}

void rcb_signals_begin_read(rcb_signals *s) {
  rcb_signals_empty(s);
  s->nwarn = 0;
}

rcb_status rcb_signals_warn(rcb_signals *s, const char *fmt, ...) {
  va_list ap;
  if (rcb_grow(&s->alloc, (void **)&s->warnings, &s->capwarn, s->nwarn + 1, sizeof *s->warnings))
    return rcb_signals_fail(s, RCB_ERR_NOMEM, "out of memory recording a warning");
  va_start(ap, fmt);
  vsnprintf(s->warnings[s->nwarn].text, RCB_WARNING_MAX, fmt, ap);
  va_end(ap);
  s->nwarn++;
  return RCB_OK;
}

size_t rcb_signals_warning_count(const rcb_signals *s) { return s ? s->nwarn : 0; }

const char *rcb_signals_warning(const rcb_signals *s, size_t i) {
  return s && i < s->nwarn ? s->warnings[i].text : "";
}

rcb_status rcb_signals_set_allow_truncated(rcb_signals *s, int allow) {
  if (!s) return RCB_ERR_ARG;
  s->allow_truncated = allow != 0;
  return RCB_OK;
}

rcb_status rcb_signals_set_join_records(rcb_signals *s, int join) {
  if (!s) return RCB_ERR_ARG;
  s->join_records = join != 0;
  return RCB_OK;
}

size_t rcb_signals_record_count(const rcb_signals *s) {
  return s && s->nch ? (s->nrec ? s->nrec : 1) : 0;
}

rcb_status rcb_signals_set_unit(rcb_signals *s, const char *name, const char *unit) {
  size_t i;
  rcb_quantity q;
  double f;
  if (!s) return RCB_ERR_ARG;
  if (!name || !name[0] || strlen(name) >= RCB_SIGNAL_NAME_MAX || !unit ||
      strlen(unit) >= sizeof s->units->unit)
    return rcb_signals_fail(s, RCB_ERR_ARG, "unit override '%.80s=%.40s': expected a channel "
                            "name of 1 to %d characters and a unit", name ? name : "",
                            unit ? unit : "", RCB_SIGNAL_NAME_MAX - 1);
  if (rcb_unit_parse(unit, &q, &f)) {
    char known[RCB_ERRMSG_MAX / 2];
    rcb_unit_list(RCB_QTY_UNKNOWN, known, sizeof known);
    return rcb_signals_fail(s, RCB_ERR_ARG, "unit override %s=%s: '%s' is not a unit librcb "
                            "knows; expected one of %s", name, unit, unit, known);
  }
  for (i = 0; i < s->nunits && strcmp(s->units[i].name, name) != 0; i++) {
  }
  if (i == s->nunits) {
    if (rcb_grow(&s->alloc, (void **)&s->units, &s->capunits, i + 1, sizeof *s->units))
      return rcb_signals_fail(s, RCB_ERR_NOMEM, "out of memory");
    s->nunits++;
  }
  snprintf(s->units[i].name, sizeof s->units[i].name, "%s", name);
  snprintf(s->units[i].unit, sizeof s->units[i].unit, "%s", unit);
  return RCB_OK;
}

const char *rcb_signals_unit_override(const rcb_signals *s, const char *name) {
  size_t i;
  for (i = 0; i < s->nunits; i++)
    if (strcmp(s->units[i].name, name) == 0) return s->units[i].unit;
  return NULL;
}

void rcb_signals_destroy(rcb_signals *s) {
  if (!s) return;
  rcb_signals_empty(s);
  rcb_free(&s->alloc, s->ch);
  rcb_free(&s->alloc, s->warnings);
  rcb_free(&s->alloc, s->units);
  rcb_free(&s->alloc, s);
}

const char *rcb_signals_errmsg(const rcb_signals *s) { return s ? s->errmsg : ""; }

rcb_status rcb_signals_reset(rcb_signals *s, double rate, size_t nsamples) {
  if (!s) return RCB_ERR_ARG;
  rcb_signals_empty(s);
  if (!isfinite(rate) || !(rate > 0.0) || nsamples == 0)
    return rcb_signals_fail(s, RCB_ERR_ARG, "sample rate %g samples/s, %zu samples: expected "
                            "a rate > 0 and at least one sample", rate, nsamples);
  s->rate = rate;
  s->n = nsamples;
  return RCB_OK;
}

rcb_status rcb_signals_take(rcb_signals *s, const char *name, rcb_quantity q, double *values) {
  size_t i;
  rcb_signal_ch *c;
  if (!name || !name[0] || strlen(name) >= RCB_SIGNAL_NAME_MAX) {
    rcb_free(&s->alloc, values);
    return rcb_signals_fail(s, RCB_ERR_ARG, "channel name '%.80s': expected 1 to %d characters",
                            name ? name : "", RCB_SIGNAL_NAME_MAX - 1);
  }
  for (i = 0; i < s->nch; i++)
    if (strcmp(s->ch[i].name, name) == 0) {
      rcb_free(&s->alloc, values);
      return rcb_signals_fail(s, RCB_ERR_ARG, "channel '%s' given twice", name);
    }
  if (rcb_grow(&s->alloc, (void **)&s->ch, &s->capch, s->nch + 1, sizeof *s->ch)) {
    rcb_free(&s->alloc, values);
    return rcb_signals_fail(s, RCB_ERR_NOMEM, "out of memory");
  }
  c = &s->ch[s->nch++];
  snprintf(c->name, sizeof c->name, "%s", name);
  c->q = q;
  c->v = values;
  return RCB_OK;
}

rcb_status rcb_signals_add(rcb_signals *s, const char *name, rcb_quantity q,
                           const double *values) {
  double *v;
  size_t i;
  if (!s || !values) return RCB_ERR_ARG;
  if (s->n == 0)
    return rcb_signals_fail(s, RCB_ERR_STATE, "add a channel after rcb_signals_reset");
  if ((unsigned)q > RCB_QTY_PRESSURE)
    return rcb_signals_fail(s, RCB_ERR_ARG, "channel '%s': unknown quantity %d", name, (int)q);
  for (i = 0; i < s->n; i++)
    if (!isfinite(values[i]) || fabs(values[i]) > RCB_SIGNAL_MAX)
      return rcb_signals_fail(s, RCB_ERR_ARG, "channel '%s': sample %zu is %g; expected a "
                              "finite value within +-%g", name, i + 1, values[i], RCB_SIGNAL_MAX);
  v = rcb_alloc(&s->alloc, s->n * sizeof *v);
  if (!v) return rcb_signals_fail(s, RCB_ERR_NOMEM, "out of memory (%zu samples)", s->n);
  memcpy(v, values, s->n * sizeof *v);
  return rcb_signals_take(s, name, q, v);
}

size_t rcb_signals_channel_count(const rcb_signals *s) { return s ? s->nch : 0; }
size_t rcb_signals_length(const rcb_signals *s) { return s ? s->n : 0; }
double rcb_signals_rate(const rcb_signals *s) { return s ? s->rate : 0.0; }

rcb_status rcb_signals_channel(const rcb_signals *s, size_t i, const char **name,
                               rcb_quantity *q, const double **values) {
  if (!s || i >= s->nch) return RCB_ERR_ARG;
  if (name) *name = s->ch[i].name;
  if (q) *q = s->ch[i].q;
  if (values) *values = s->ch[i].v;
  return RCB_OK;
}

rcb_status rcb_signals_find(const rcb_signals *s, const char *name, size_t *index) {
  size_t i;
  if (!s || !name || !index) return RCB_ERR_ARG;
  for (i = 0; i < s->nch; i++)
    if (strcmp(s->ch[i].name, name) == 0) {
      *index = i;
      return RCB_OK;
    }
  return RCB_ERR_NOT_FOUND;
}

rcb_status rcb_signals_slurp(rcb_signals *s, const char *path, char **buf, size_t *len) {
  FILE *fp;
  long size;
  char *b;
  *buf = NULL;
  *len = 0;
  if (!path || !path[0]) return rcb_signals_fail(s, RCB_ERR_ARG, "no file name given");
  fp = fopen(path, "rb");
  if (!fp) /* out of memory (fopen's buffer) is RCB_ERR_NOMEM, as everywhere */
    return rcb_signals_fail(s, errno == ENOMEM ? RCB_ERR_NOMEM : RCB_ERR_IO, "%s: cannot open: %s", path,
                          strerror(errno));
  if (fseek(fp, 0, SEEK_END) || (size = ftell(fp)) < 0 || fseek(fp, 0, SEEK_SET)) {
    fclose(fp);
    return rcb_signals_fail(s, RCB_ERR_IO, "%s: cannot read: not a regular file", path);
  }
  b = rcb_alloc(&s->alloc, (size_t)size + 1);
  if (!b) {
    fclose(fp);
    return rcb_signals_fail(s, RCB_ERR_NOMEM, "%s: out of memory (%ld bytes)", path, size);
  }
  if (fread(b, 1, (size_t)size, fp) != (size_t)size) {
    fclose(fp);
    rcb_free(&s->alloc, b);
    return rcb_signals_fail(s, RCB_ERR_IO, "%s: read error", path);
  }
  fclose(fp);
  b[size] = '\0';
  *buf = b;
  *len = (size_t)size;
  return RCB_OK;
}
