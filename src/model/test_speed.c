/*
 * The rotor speed of the test a model is compared with ([test] rpm): many
 * measurement files (UFF with a z axis other than type 19, CSV without
 * "# rpm") do not state it, and read as 0 rpm. Kept with the model so the
 * fact is written once, next to the machine it belongs to.
 */
#include <math.h>

#include "core/rcb_internal.h"
#include "model/model_util.h"

rcb_status rcb_model_set_test_speed(rcb_model *m, double speed) {
  if (!m) return RCB_ERR_ARG;
  if (!(isfinite(speed) && speed >= 0.0))
    return rcb_model_fail(m, RCB_ERR_ARG,
                          "test speed %g rad/s: expected a finite rotor speed >= 0", speed);
  m->test_speed = speed;
  m->has_test_speed = 1;
  return RCB_OK;
}

rcb_status rcb_model_get_test_speed(const rcb_model *m, double *speed) {
  if (!m || !speed) return RCB_ERR_ARG;
  if (!m->has_test_speed) return RCB_ERR_NOT_FOUND;
  *speed = m->test_speed;
  return RCB_OK;
}
