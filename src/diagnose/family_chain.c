/*
 * The measurement-chain family (issue #23, item 4): faults of the probes, not
 * of the machine. For every measured response (a channel's response name,
 * "DB.y"):
 *  - its sensor's gain, sensor.<r>.gain (-, neutral 1, log in [0.1, 10]), with
 *    its phase sensor.<r>.phase (rad, neutral 0, in [-pi/2, pi/2]) on the
 *    complex scale only: on magnitudes a phase is invisible (its column is 0);
 *  - its sign flipped (a probe wired the wrong way): no parameter, the fit's
 *    chain reads it with gain -1; on the complex scale only, where a sign shows;
 * and for every station whose x and y are both measured with the same
 * references, the two probes swapped (no parameter).
 *
 * The model of every candidate is the base model unchanged (no edit, no
 * start): the fit reads the measurement through the edited chain
 * (rcb_fit_set_sensor, rcb_fit_swap_sensors, the sensor parameters of
 * rcb_identify.h). Sensor parameters have no dZ/dp, so a gain is not scored
 * in a batch (DIAG_FAM_SCORE_ALONE): its columns are the base model's values
 * (rcb_fit_chain_jacobian, no sweep); the sign and the swap have no neutral
 * value: they are scored by F with the edit (from the same values,
 * rcb_fit_residuals_from) and refitted only when it falls.
 *
 * Corrections found in an earlier round are carried into every fit
 * (rcb_diag_set_sensor, rcb_diag_swap_sensors, or a sensor's gain among the
 * base parameters); each candidate names the rcbtool options that would
 * carry its own (rcb_diag_carry_text), so a second round reads the data
 * through it.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "diagnose/diag_internal.h"
#include "identify/identify.h"

/* Whether channel c is the first with its response. */
static int first_of_response(const rcb_meas *ms, size_t c, const char *r) {
  size_t k;
  for (k = 0; k < c; k++) {
    rcb_meas_channel_info ci;
    if (!rcb_meas_channel(ms, k, &ci) && strcmp(ci.response, r) == 0) return 0;
  }
  return 1;
}

static int same_ref(const char *a, const char *b) {
  return (!a && !b) || (a && b && strcmp(a, b) == 0);
}

/* Whether every reference of response a's channels is among b's. */
static int refs_within(const rcb_meas *ms, const char *a, const char *b) {
  size_t n = rcb_meas_channel_count(ms), c, k;
  for (c = 0; c < n; c++) {
    rcb_meas_channel_info ca;
    int found = 0;
    if (rcb_meas_channel(ms, c, &ca) || strcmp(ca.response, a) != 0) continue;
    for (k = 0; k < n && !found; k++) {
      rcb_meas_channel_info cb;
      found = !rcb_meas_channel(ms, k, &cb) && strcmp(cb.response, b) == 0 &&
              same_ref(ca.reference, cb.reference);
    }
    if (!found) return 0;
  }
  return 1;
}

/* Whether response y is measured at all. */
static int measured(const rcb_meas *ms, const char *y) {
  size_t n = rcb_meas_channel_count(ms), c;
  for (c = 0; c < n; c++) {
    rcb_meas_channel_info ci;
    if (!rcb_meas_channel(ms, c, &ci) && strcmp(ci.response, y) == 0) return 1;
  }
  return 0;
}

/* A sensor parameter of candidate c with the fit's default start and bounds. */
static void add_chain_par(diag_cand *c, const char *fmt, const char *r) {
  char nm[RCB_DIAG_NAME];
  double lo = 0.1, hi = 10.0;
  int logp = 1;
  snprintf(nm, sizeof nm, fmt, r);
  rcb_fit_sensor_param_defaults(nm, NULL, &lo, &hi, &logp);
  rcb_diag_add_par(c, fmt, r, lo, hi, logp);
}

static const diag_carry *carried_swap(const rcb_diag *d, const char *r);

/* c->carry: the options that carry c's correction (rcb_diag_carry_text), in
 * an allocation of its own. */
static rcb_status set_carry(rcb_diag *d, diag_cand *c, const char *r, const char *r2) {
  char buf[RCB_DIAG_CARRY];
  size_t n;
  rcb_diag_carry_text(d, c->effect, r, r2, buf, sizeof buf);
  n = strlen(buf) + 1;
  if (!(c->carry = rcb_alloc(&d->alloc, n))) return RCB_ERR_NOMEM;
  memcpy(c->carry, buf, n);
  return RCB_OK;
}

static rcb_status gain_and_sign(rcb_diag *d, const char *r) {
  char place[RCB_DIAG_NAME], nm[RCB_DIAG_NAME];
  int cplx = d->scale == RCB_SCALE_COMPLEX;
  diag_cand *c;
  snprintf(place, sizeof place, "sensor %s", r);
  snprintf(nm, sizeof nm, "sensor.%s.gain", r);
  if (!rcb_diag_is_base(d, nm)) {
    if (!(c = rcb_diag_new_cand(d, &rcb_diag_family_chain, RCB_EFFECT_SENSOR_GAIN, place)))
      return RCB_ERR_NOMEM;
    snprintf(c->desc, sizeof c->desc, "the %s of the sensor at %s (a probe reading off)",
             cplx ? "gain and phase" : "gain", r);
    snprintf(c->target, sizeof c->target, "%s", r);
    add_chain_par(c, "sensor.%s.gain", r);
    if (cplx) add_chain_par(c, "sensor.%s.phase", r);
    if (set_carry(d, c, r, NULL)) return RCB_ERR_NOMEM;
  }
  if (!cplx) return RCB_OK;
  if (!(c = rcb_diag_new_cand(d, &rcb_diag_family_chain, RCB_EFFECT_SENSOR_SIGN, place)))
    return RCB_ERR_NOMEM;
  snprintf(c->desc, sizeof c->desc, "the sensor at %s with its sign flipped (wired the wrong "
           "way)", r);
  snprintf(c->target, sizeof c->target, "%s", r);
  c->refit_only = 1;
  return set_carry(d, c, r, NULL);
}

/* r = "<station>.x" with "<station>.y" measured with the same references:
 * the two probes swapped. */
static rcb_status swap(rcb_diag *d, const char *r) {
  char y[RCB_NAME_MAX], place[RCB_DIAG_NAME];
  size_t n = strlen(r);
  diag_cand *c;
  if (n < 3 || strcmp(r + n - 2, ".x") != 0 || n >= sizeof y) return RCB_OK;
  memcpy(y, r, n + 1);
  y[n - 1] = 'y';
  if (!measured(d->meas, y) || !refs_within(d->meas, r, y) || !refs_within(d->meas, y, r))
    return RCB_OK;
  if (carried_swap(d, r) || carried_swap(d, y)) return RCB_OK; /* known swapped already */
  snprintf(place, sizeof place, "sensors %s, %s", r, y);
  if (!(c = rcb_diag_new_cand(d, &rcb_diag_family_chain, RCB_EFFECT_SENSOR_SWAP, place)))
    return RCB_ERR_NOMEM;
  snprintf(c->desc, sizeof c->desc, "the probes at %s and %s swapped", r, y);
  snprintf(c->target, sizeof c->target, "%s", r);
  snprintf(c->target2, sizeof c->target2, "%s", y);
  c->refit_only = 1;
  return set_carry(d, c, r, y);
}

static rcb_status enumerate(rcb_diag *d, const rcb_model *m) {
  size_t n = rcb_meas_channel_count(d->meas), c;
  rcb_status st = RCB_OK;
  (void)m; /* the chain is the measurement's, whatever the model */
  for (c = 0; !st && c < n; c++) {
    rcb_meas_channel_info ci;
    if (rcb_meas_channel(d->meas, c, &ci) || !ci.response) continue;
    /* a name the candidate cannot hold is left out rather than cut */
    if (strlen(ci.response) >= RCB_NAME_MAX || !first_of_response(d->meas, c, ci.response))
      continue;
    if (!(st = gain_and_sign(d, ci.response))) st = swap(d, ci.response);
  }
  return st;
}

/* The fixed edits of the chain, on every fit of the candidate, on top of
 * those carried (rcb_diag_carry_apply ran before): a sign flips the
 * sensor's gain as it stands. */
static rcb_status fit_setup(const diag_cand *c, rcb_fit *f) {
  double g = 1.0, ph = 0.0;
  rcb_status st;
  if (c->effect == RCB_EFFECT_SENSOR_SIGN) {
    if ((st = rcb_fit_get_sensor(f, c->target, &g, &ph, NULL))) return st;
    return rcb_fit_set_sensor(f, c->target, -g, ph);
  }
  if (c->effect == RCB_EFFECT_SENSOR_SWAP) return rcb_fit_swap_sensors(f, c->target, c->target2);
  return RCB_OK;
}

const diag_family rcb_diag_family_chain = {"chain", DIAG_FAM_CHAIN | DIAG_FAM_SCORE_ALONE,
                                           enumerate, NULL, NULL, NULL, fit_setup};

/* ---- corrections carried from an earlier round ---- */

static const diag_carry *carried_swap(const rcb_diag *d, const char *r) {
  size_t k;
  for (k = 0; k < d->ncarry; k++)
    if (d->carry[k].b[0] && (strcmp(d->carry[k].a, r) == 0 || strcmp(d->carry[k].b, r) == 0))
      return &d->carry[k];
  return NULL;
}

static const diag_carry *carried_gain(const rcb_diag *d, const char *r) {
  size_t k;
  for (k = 0; k < d->ncarry; k++)
    if (!d->carry[k].b[0] && strcmp(d->carry[k].a, r) == 0) return &d->carry[k];
  return NULL;
}

/* RCB_ERR_ARG naming r and the measured responses when r is not one. */
static rcb_status need_measured(rcb_diag *d, const char *what, const char *r) {
  char list[RCB_ERRMSG_MAX / 2];
  size_t n = rcb_meas_channel_count(d->meas), c, used = 0;
  if (r && strlen(r) < RCB_NAME_MAX && measured(d->meas, r)) return RCB_OK;
  list[0] = '\0';
  for (c = 0; c < n && used + 1 < sizeof list; c++) {
    rcb_meas_channel_info ci;
    int w;
    if (rcb_meas_channel(d->meas, c, &ci) || !ci.response ||
        !first_of_response(d->meas, c, ci.response))
      continue;
    if ((w = snprintf(list + used, sizeof list - used, "%s%s", used ? ", " : "",
                      ci.response)) < 0)
      break;
    used += (size_t)w;
  }
  return rcb_diag_fail(d, RCB_ERR_ARG,
                       "%s '%s': no measured channel has that response (measured responses: "
                       "%s)",
                       what, r ? r : "(null)", list);
}

static diag_carry *new_carry(rcb_diag *d) {
  if (rcb_grow(&d->alloc, (void **)&d->carry, &d->cap_carry, d->ncarry + 1, sizeof *d->carry))
    return NULL;
  return memset(&d->carry[d->ncarry++], 0, sizeof *d->carry);
}

rcb_status rcb_diag_set_sensor(rcb_diag *d, const char *response, double gain,
                               double phase_rad) {
  diag_carry *e;
  rcb_status st;
  if (!d) return RCB_ERR_ARG;
  if ((st = need_measured(d, "sensor", response))) return st;
  if (!isfinite(gain) || gain == 0.0 || !isfinite(phase_rad))
    return rcb_diag_fail(d, RCB_ERR_ARG,
                         "sensor '%s': gain %g, phase %g rad: expected a finite, nonzero gain "
                         "and a finite phase",
                         response, gain, phase_rad);
  if (!(e = (diag_carry *)carried_gain(d, response)) && !(e = new_carry(d)))
    return rcb_diag_fail(d, RCB_ERR_NOMEM, "out of memory");
  snprintf(e->a, sizeof e->a, "%s", response);
  e->gain = gain, e->phase = phase_rad;
  return RCB_OK;
}

rcb_status rcb_diag_swap_sensors(rcb_diag *d, const char *a, const char *b) {
  const diag_carry *x;
  diag_carry *e;
  rcb_status st;
  if (!d) return RCB_ERR_ARG;
  if ((st = need_measured(d, "swap: sensor", a)) || (st = need_measured(d, "swap: sensor", b)))
    return st;
  if (strcmp(a, b) == 0)
    return rcb_diag_fail(d, RCB_ERR_ARG, "swap %s with %s: two different sensors expected", a,
                         b);
  if ((x = carried_swap(d, a)) || (x = carried_swap(d, b)))
    return rcb_diag_fail(d, RCB_ERR_ARG, "swap %s with %s: %s and %s are swapped already", a,
                         b, x->a, x->b);
  if (!refs_within(d->meas, a, b) || !refs_within(d->meas, b, a))
    return rcb_diag_fail(d, RCB_ERR_ARG,
                         "swap %s with %s: the two are not measured with the same references",
                         a, b);
  if (!(e = new_carry(d))) return rcb_diag_fail(d, RCB_ERR_NOMEM, "out of memory");
  snprintf(e->a, sizeof e->a, "%s", a);
  snprintf(e->b, sizeof e->b, "%s", b);
  return RCB_OK;
}

rcb_status rcb_diag_carry_check(rcb_diag *d, const char *name) {
  int which = rcb_fit_param_is_chain(name);
  char r[RCB_DIAG_NAME], what[RCB_DIAG_NAME + 16];
  if (!which) return RCB_OK;
  rcb_fit_chain_response(name, r, sizeof r);
  snprintf(what, sizeof what, "parameter %s: sensor", name);
  return need_measured(d, what, r);
}

rcb_status rcb_diag_carry_apply(rcb_diag *d, rcb_fit *f, int with_base) {
  rcb_status st = RCB_OK;
  size_t k;
  for (k = 0; !st && k < d->ncarry; k++)
    st = d->carry[k].b[0] ? rcb_fit_swap_sensors(f, d->carry[k].a, d->carry[k].b)
                          : rcb_fit_set_sensor(f, d->carry[k].a, d->carry[k].gain,
                                               d->carry[k].phase);
  for (k = 0; !st && k < d->nbase; k++) {
    const diag_base_par *p = &d->base[k];
    int which = rcb_fit_param_is_chain(p->name);
    char r[RCB_DIAG_NAME];
    double g, ph;
    if (!which || !p->chain_kept) continue;
    if (with_base) {
      st = rcb_fit_set_chain_value(f, p->name, p->chain_v);
      continue;
    }
    rcb_fit_chain_response(p->name, r, sizeof r);
    if (!(st = rcb_fit_get_sensor(f, r, &g, &ph, NULL)))
      st = which == RCB_CHAIN_GAIN ? rcb_fit_set_sensor(f, r, g * p->chain_v, ph)
                                   : rcb_fit_set_sensor(f, r, g, ph + p->chain_v);
  }
  return st;
}

void rcb_diag_carry_keep(rcb_diag *d, const rcb_fit *f) {
  size_t k, j, np = rcb_fit_param_count(f);
  for (k = 0; k < d->nbase; k++)
    for (j = 0; j < np && rcb_fit_param_is_chain(d->base[k].name); j++) {
      rcb_fit_param p;
      if (rcb_fit_get_param(f, j, &p) || strcmp(p.name, d->base[k].name) != 0) continue;
      d->base[k].chain_v = p.value;
      d->base[k].chain_kept = 1;
    }
}

/* Appends "fmt" to buf at *n; 1 when it did not fit. */
static int put(char *buf, size_t size, size_t *n, const char *fmt, const char *a,
               const char *b) {
  int w = *n < size ? snprintf(buf + *n, size - *n, fmt, a, b) : -1;
  if (w < 0 || (size_t)w >= size - *n) return 1;
  *n += (size_t)w;
  return 0;
}

void rcb_diag_carry_text(const rcb_diag *d, rcb_effect kind, const char *r, const char *r2,
                         char *buf, size_t size) {
  size_t n = 0, k, first;
  int cut = 0, cplx = d->scale == RCB_SCALE_COMPLEX, gain = kind == RCB_EFFECT_SENSOR_GAIN;
  char num[64];
  if (!size) return;
  buf[0] = '\0'; /* nothing to carry: the empty text */
  /* the base parameters, and the sensor's gain to fit (its phase on the complex scale) */
  for (k = 0; k < d->nbase; k++)
    cut |= put(buf, size, &n, k ? ",%s%s" : "--params %s%s", d->base[k].name, "");
  if (gain) {
    cut |= put(buf, size, &n, n ? ",sensor.%s.gain%s" : "--params sensor.%s.gain%s", r, "");
    if (cplx) cut |= put(buf, size, &n, ",sensor.%s.phase%s", r, "");
  }
  /* the gain edits carried, the sign candidate's flipping its sensor's */
  first = n;
  for (k = 0; k < d->ncarry; k++) {
    const diag_carry *e = &d->carry[k];
    int flip = kind == RCB_EFFECT_SENSOR_SIGN && strcmp(e->a, r) == 0;
    if (e->b[0]) continue;
    double g = flip ? -e->gain : e->gain;
    cut |= put(buf, size, &n, n == first ? " --sensor %s%s" : ",%s%s", e->a, "");
    if (g == -1.0 && e->phase == 0.0) snprintf(num, sizeof num, ":sign=-1");
    else snprintf(num, sizeof num, ":gain=%.6g", g);
    cut |= put(buf, size, &n, "%s%s", num, "");
    if (e->phase != 0.0) {
      snprintf(num, sizeof num, ",phase=%.6g", e->phase);
      cut |= put(buf, size, &n, "%s%s", num, "");
    }
  }
  if (kind == RCB_EFFECT_SENSOR_SIGN && !carried_gain(d, r))
    cut |= put(buf, size, &n, n == first ? " --sensor %s:sign=-1%s" : ",%s:sign=-1%s", r, "");
  /* the swaps carried, and the candidate's */
  first = n;
  for (k = 0; k < d->ncarry; k++)
    if (d->carry[k].b[0])
      cut |= put(buf, size, &n, n == first ? " --swap %s,%s" : ",%s,%s", d->carry[k].a,
                 d->carry[k].b);
  if (kind == RCB_EFFECT_SENSOR_SWAP)
    cut |= put(buf, size, &n, n == first ? " --swap %s,%s" : ",%s,%s", r, r2);
  if (cut) buf[0] = '\0';
  else if (buf[0] == ' ') memmove(buf, buf + 1, n); /* from the first option on */
}
