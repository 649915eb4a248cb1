/*
 * Time signals from UFF dataset 58 time records (function type 1, abscissa
 * type 17), read by io's uff58 reader in time mode (io/meas_internal.h): one
 * channel per record, all with one sample interval and length.
 */
#include <math.h>
#include <string.h>

#include "io/meas_internal.h"
#include "signals/signals_internal.h"

typedef struct uff_ctx {
  rcb_signals *s;
  const char *path;
  double dt;
  size_t n, first;
  int failed; /* the message is in s, not in the scratch measurement */
} uff_ctx;

static rcb_status take_record(void *user, const rcb_uff_time_rec *r) {
  uff_ctx *c = user;
  rcb_signals *s = c->s;
  double *v;
  size_t i;
  rcb_status st;
  c->failed = 1;
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
  v = rcb_alloc(&s->alloc, r->n * sizeof *v);
  if (!v) return rcb_signals_fail(s, RCB_ERR_NOMEM, "%s: out of memory", c->path);
  for (i = 0; i < r->n; i++) v[i] = creal(r->y[i]);
  if ((st = rcb_signals_take(s, r->name, r->q, v))) return st;
  c->failed = 0;
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
  if (st) rcb_signals_empty(s);
  rcb_meas_destroy(ms);
  return st;
}
