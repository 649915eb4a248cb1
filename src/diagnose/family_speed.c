/*
 * The operating-speed family (issue #4): a speed factor, neutral 1.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "diagnose/diag_internal.h"

/* The operating speed (FRF data taken on a spinning rotor only): a speed
 * factor, neutral 1. Unbalance responses are left out: their abscissa is the
 * measured once-per-revolution speed, and the factor does not apply there. */
static rcb_status enumerate(rcb_diag *d, const rcb_model *m) {
  (void)m;
  diag_cand *c;
  if (rcb_meas_get_type(d->meas) != RCB_MEAS_FRF || rcb_meas_speed(d->meas) == 0 ||
      rcb_diag_is_base(d, "speed.factor"))
    return RCB_OK;
  if (!(c = rcb_diag_new_cand(d, &rcb_diag_family_speed, RCB_EFFECT_SPEED, "operating speed"))) return RCB_ERR_NOMEM;
  snprintf(c->desc, sizeof c->desc,
           "an operating speed other than the stated one (gyroscopic split)");
  rcb_diag_add_par(c, "%s", "speed.factor", 0.25, 4.0, 1);
  return RCB_OK;
}


const diag_family rcb_diag_family_speed = {"speed", 0, enumerate, NULL, NULL, NULL, NULL};
