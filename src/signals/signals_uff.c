/*
 * Time signals from UFF dataset 58 time records (function type 1, abscissa
 * type 17), read by io's uff58 reader in time mode (io/meas_internal.h): one
 * channel per record, all with one sample interval and length; with
 * rcb_signals_set_join_records, a channel's further records (one per hit of
 * an impact test) appended end to end.
 */
#include <math.h>
#include <string.h>

#include "io/meas_internal.h"
#include "signals/signals_internal.h"

typedef struct uff_ctx {
  rcb_signals *s;
  const char *path;
  double dt;
  size_t n, first, nskip;
  int failed; /* the message is in s, not in the scratch measurement */
  size_t *rec, *idx; /* per channel: records joined, dataset ordinal of its first */
  size_t caprec, capidx;
} uff_ctx;

/* Every direction is read (issue #35): a signal verb (estimate, order) needs
 * no model direction, so an axial (z), torsional (rz) or scalar record keeps
 * its file name ("#1.z", "DA.z", "#5") until --outputs NAME=STATION.DIR or a
 * map entry "1.z=DA.x" names the model channel it stands for. Unless the
 * caller joins records (an impact test's hits, rcb_signals_set_join_records),
 * a record whose channel an earlier record already gave (a second sensor on
 * one node and direction) is skipped with a warning naming both. 1 when
 * skipped. */
static int repeated(uff_ctx *c, const rcb_uff_time_rec *r, rcb_quantity q, rcb_status *st) {
  size_t i;
  if (rcb_signals_find(c->s, r->name, &i) != RCB_OK) return 0;
  c->nskip++;
  *st = rcb_signals_warn(c->s, "%s:%zu: dataset 58 record %zu ('%s', %s): skipped: an earlier "
                         "record gave channel '%s' (node %ld, direction %ld); each channel is "
                         "read once", c->path, r->line + 6, r->index, r->name,
                         rcb_quantity_name(q), r->name, r->node, r->dir);
  return 1;
}

/* Quantity and factor of a record whose label librcb does not know: the
 * caller's rcb_signals_set_unit, else refused with the known units. A level
 * in dB is logarithmic: no factor makes it a signal. */
static rcb_status unknown_label(uff_ctx *c, const rcb_uff_time_rec *r, rcb_quantity *q,
                                double *f) {
  const char *u = rcb_signals_unit_override(c->s, r->name);
  char known[300];
  if (u && rcb_unit_parse(u, q, f) == 0) {
    if (r->q != RCB_QTY_UNKNOWN && *q != r->q)
      return rcb_signals_fail(c->s, RCB_ERR_PARSE, "%s:%zu: dataset 58 record %zu: the unit "
                              "given for '%s' (%s) is %s, its data type %ld says %s", c->path,
                              r->line + 9, r->index, r->name, u, rcb_quantity_name(*q), r->spec,
                              rcb_quantity_name(r->q));
    return RCB_OK;
  }
  if (strncmp(r->label, "dB", 2) == 0)
    return rcb_signals_fail(c->s, RCB_ERR_PARSE, "%s:%zu: dataset 58 record %zu ('%s'): units "
                            "label '%s' is a level in decibels, a logarithm of the amplitude: "
                            "a time record needs a linear unit (export it in Pa, m/s^2, ...)",
                            c->path, r->line + 9, r->index, r->name, r->label);
  rcb_unit_list(r->q, known, sizeof known);
  return rcb_signals_fail(c->s, RCB_ERR_PARSE, "%s:%zu: dataset 58 record %zu: units label "
                          "'%s' of channel '%s' is not one librcb knows (%s%s%s); give it: "
                          "--units '%s=UNIT' (rcb_signals_set_unit)", c->path, r->line + 9,
                          r->index, r->label, r->name,
                          r->q != RCB_QTY_UNKNOWN ? rcb_quantity_name(r->q) : "",
                          r->q != RCB_QTY_UNKNOWN ? ", as its data type says: " : "", known,
                          r->name);
}

/* The record's samples in SI, in a new buffer through the set's allocator. */
static rcb_status values(uff_ctx *c, const rcb_uff_time_rec *r, double f, double **out) {
  rcb_signals *s = c->s;
  double *v = rcb_alloc(&s->alloc, r->n * sizeof *v);
  size_t i;
  *out = NULL;
  if (!v) return rcb_signals_fail(s, RCB_ERR_NOMEM, "%s: out of memory", c->path);
  for (i = 0; i < r->n; i++) {
    v[i] = creal(r->y[i]) * f;
    if (fabs(v[i]) > RCB_SIGNAL_MAX) {
      double x = v[i];
      rcb_free(&s->alloc, v);
      return rcb_signals_fail(s, RCB_ERR_PARSE, "%s:%zu: dataset 58 record %zu, value %zu is "
                              "%g (SI): beyond %g, the largest sample librcb takes (its power "
                              "would overflow); a corrupt value?", c->path, r->line + 12,
                              r->index, i + 1, x, RCB_SIGNAL_MAX);
    }
  }
  *out = v;
  return RCB_OK;
}

/* A channel seen before (channel @p i): its next record appended when the
 * caller joins records (an impact test's hits), refused otherwise. */
static rcb_status join(uff_ctx *c, const rcb_uff_time_rec *r, rcb_quantity q, size_t i,
                       double *v) {
  rcb_signals *s = c->s;
  rcb_signal_ch *ch = &s->ch[i];
  size_t k = c->rec[i];
  double *all;
  if (!s->join_records || q != ch->q) {
    rcb_free(&s->alloc, v);
    if (!s->join_records)
      return rcb_signals_fail(s, RCB_ERR_PARSE, "%s:%zu: dataset 58 record %zu: channel '%s' "
                              "again (first in record %zu); several records of a channel are "
                              "read as the hits of an impact test (rcbtool estimate; "
                              "rcb_signals_set_join_records)", c->path, r->line, r->index,
                              r->name, c->idx[i]);
    return rcb_signals_fail(s, RCB_ERR_PARSE, "%s:%zu: dataset 58 record %zu: channel '%s' is "
                            "%s here, %s in record %zu", c->path, r->line, r->index, r->name,
                            rcb_quantity_name(q), rcb_quantity_name(ch->q), c->idx[i]);
  }
  all = rcb_alloc(&s->alloc, (k + 1) * c->n * sizeof *all);
  if (!all) {
    rcb_free(&s->alloc, v);
    return rcb_signals_fail(s, RCB_ERR_NOMEM, "%s: out of memory", c->path);
  }
  memcpy(all, ch->v, k * c->n * sizeof *all);
  memcpy(all + k * c->n, v, c->n * sizeof *all);
  rcb_free(&s->alloc, ch->v);
  rcb_free(&s->alloc, v);
  ch->v = all;
  c->rec[i] = k + 1;
  c->failed = 0;
  return RCB_OK;
}

static rcb_status take_record(void *user, const rcb_uff_time_rec *r) {
  uff_ctx *c = user;
  rcb_signals *s = c->s;
  rcb_quantity q = r->q;
  double *v, f = 1.0;
  size_t i;
  rcb_status st = RCB_OK;
  c->failed = 1;
  if (r->label_unknown && (st = unknown_label(c, r, &q, &f))) return st;
  if (q == RCB_QTY_UNKNOWN && rcb_signals_unit_override(s, r->name))
    rcb_unit_parse(rcb_signals_unit_override(s, r->name), &q, &f);
  if (r->claimed && !s->allow_truncated)
    return rcb_signals_fail(s, RCB_ERR_PARSE, "%s:%zu: dataset 58 record %zu ('%s'): record 7 "
                            "claims %zu samples, but the record holds %zu before its %s: the "
                            "file was cut (an excerpt of a longer recording?); to read the %zu "
                            "samples present, allow truncated files (rcbtool --allow-truncated, "
                            "rcb_signals_set_allow_truncated)", c->path, r->line + 7, r->index,
                            r->name, r->claimed, r->n, "closing '-1'", r->n);
  if (r->claimed && (st = rcb_signals_warn(s, "%s:%zu: dataset 58 record %zu ('%s'): record 7 "
                                           "claims %zu samples, the record holds %zu: read "
                                           "cut short, as allowed", c->path, r->line + 7,
                                           r->index, r->name, r->claimed, r->n)))
    return st;
  if (!s->join_records && repeated(c, r, q, &st)) {
    c->failed = st != RCB_OK;
    return st;
  }
  if (!(r->dt > 0.0))
    return rcb_signals_fail(s, RCB_ERR_PARSE, "%s:%zu: dataset 58 record %zu: time step %g s; "
                            "expected > 0", c->path, r->line + 7, r->index, r->dt);
  if (c->n == 0) {
    if ((st = rcb_signals_reset(s, 1.0 / r->dt, r->n))) return st;
    c->dt = r->dt;
    c->n = r->n;
    c->first = r->index;
  } else if (r->n != c->n || fabs(r->dt - c->dt) > 1e-9 * c->dt) {
    return rcb_signals_fail(s, RCB_ERR_PARSE, "%s:%zu: dataset 58 record %zu: %zu samples "
                            "every %.9g s, record %zu has %zu every %.9g s; all channels must "
                            "be sampled together", c->path, r->line + 7, r->index, r->n, r->dt,
                            c->first, c->n, c->dt);
  }
  if ((st = values(c, r, f, &v))) return st;
  if (rcb_signals_find(s, r->name, &i) == RCB_OK) return join(c, r, q, i, v);
  if (rcb_grow(&s->alloc, (void **)&c->rec, &c->caprec, s->nch + 1, sizeof *c->rec) ||
      rcb_grow(&s->alloc, (void **)&c->idx, &c->capidx, s->nch + 1, sizeof *c->idx)) {
    rcb_free(&s->alloc, v);
    return rcb_signals_fail(s, RCB_ERR_NOMEM, "%s: out of memory", c->path);
  }
  c->rec[s->nch] = 1;
  c->idx[s->nch] = r->index;
  if ((st = rcb_signals_take(s, r->name, q, v))) return st;
  c->failed = 0;
  return RCB_OK;
}

/* With joined records: every channel has as many (one per hit); the set is
 * that many records end to end. When the counts differ the records are not
 * hits (a vendor file's second sensor on one node and direction): each
 * channel keeps its first record (its first c->n values), the others are
 * skipped with a warning, as without joining. */
static rcb_status joined(uff_ctx *c) {
  rcb_signals *s = c->s;
  size_t i;
  rcb_status st;
  for (i = 1; i < s->nch; i++)
    if (c->rec[i] != c->rec[0]) break;
  if (i < s->nch) {
    size_t a = c->rec[0] != c->rec[i] && c->rec[0] > c->rec[i] ? 0 : i;
    if ((st = rcb_signals_warn(s, "%s: channel '%s' has %zu records, '%s' has %zu: not read "
                               "as the hits of an impact test (each channel needs one per "
                               "hit); each channel's first record kept, %zu skipped",
                               c->path, s->ch[a].name, c->rec[a], s->ch[a ? 0 : i].name,
                               c->rec[a ? 0 : i], c->rec[a] - 1)))
      return st;
    for (i = 0; i < s->nch; i++) c->rec[i] = 1;
  }
  s->nrec = s->nch ? c->rec[0] : 0;
  s->n = s->nrec * c->n;
  return RCB_OK;
}

rcb_status rcb_signals_read_uff(rcb_signals *s, const char *path, size_t nmap,
                                const rcb_uff_node *map) {
  rcb_meas *ms = NULL;
  uff_ctx c;
  rcb_status st;
  if (!s) return RCB_ERR_ARG;
  rcb_signals_begin_read(s);
  if (rcb_meas_create(&ms, &s->alloc))
    return rcb_signals_fail(s, RCB_ERR_NOMEM, "out of memory");
  memset(&c, 0, sizeof c);
  c.s = s;
  c.path = path;
  st = rcb_uff58_read_time(ms, path, nmap, map, take_record, &c);
  if (st && !c.failed) rcb_signals_fail(s, st, "%s", rcb_meas_errmsg(ms));
  if (!st) st = joined(&c);
  if (!st && s->nch == 0)
    st = rcb_signals_fail(s, RCB_ERR_PARSE, "%s: no usable time record: all %zu were skipped "
                          "(the warnings say why)", path, c.nskip);
  if (st) rcb_signals_empty(s);
  rcb_free(&s->alloc, c.rec);
  rcb_free(&s->alloc, c.idx);
  rcb_meas_destroy(ms);
  return st;
}
