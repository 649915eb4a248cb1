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
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "diagnose/diag_internal.h"

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
    rcb_diag_add_par(c, "sensor.%s.gain", r, 0.1, 10.0, 1);
    if (cplx) rcb_diag_add_par(c, "sensor.%s.phase", r, -RCB_PI / 2, RCB_PI / 2, 0);
  }
  if (!cplx) return RCB_OK;
  if (!(c = rcb_diag_new_cand(d, &rcb_diag_family_chain, RCB_EFFECT_SENSOR_SIGN, place)))
    return RCB_ERR_NOMEM;
  snprintf(c->desc, sizeof c->desc, "the sensor at %s with its sign flipped (wired the wrong "
           "way)", r);
  snprintf(c->target, sizeof c->target, "%s", r);
  c->refit_only = 1;
  return RCB_OK;
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
  snprintf(place, sizeof place, "sensors %s, %s", r, y);
  if (!(c = rcb_diag_new_cand(d, &rcb_diag_family_chain, RCB_EFFECT_SENSOR_SWAP, place)))
    return RCB_ERR_NOMEM;
  snprintf(c->desc, sizeof c->desc, "the probes at %s and %s swapped", r, y);
  snprintf(c->target, sizeof c->target, "%s", r);
  snprintf(c->target2, sizeof c->target2, "%s", y);
  c->refit_only = 1;
  return RCB_OK;
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

/* The fixed edits of the chain, on every fit of the candidate. */
static rcb_status fit_setup(const diag_cand *c, rcb_fit *f) {
  if (c->effect == RCB_EFFECT_SENSOR_SIGN) return rcb_fit_set_sensor(f, c->target, -1.0, 0.0);
  if (c->effect == RCB_EFFECT_SENSOR_SWAP) return rcb_fit_swap_sensors(f, c->target, c->target2);
  return RCB_OK;
}

const diag_family rcb_diag_family_chain = {"chain", DIAG_FAM_CHAIN | DIAG_FAM_SCORE_ALONE,
                                           enumerate, NULL, NULL, NULL, fit_setup};
