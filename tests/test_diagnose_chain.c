/*
 * Sensor corrections carried from one round of the diagnosis to the next
 * (issue #33, item 5): the paper system exactly as modelled, eq. 19 noise
 * 10/1 %, one probe at fault (DB.y reading 0.8 x, or wired the wrong way,
 * or DB.x and DB.y swapped), 4 responses x 2 references x 31 lines.
 *  - round 1 names the sensor first, claiming it explains the data, and its
 *    candidate names the rcbtool options that carry it (carry); the
 *    explanation and rcb_diag_apply_model's refusal repeat them;
 *  - round 2 with that correction (a gain fitted among the base parameters,
 *    rcb_diag_set_sensor, rcb_diag_swap_sensors) passes the adequacy test
 *    and claims no sensor again;
 *  - corrections carried on top of each other compose (a sign candidate on
 *    a carried gain names the flipped gain);
 *  - unknown sensors, a swap with itself or twice: RCB_ERR_ARG naming them.
 */
#include <complex.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "rcb/rcb.h"
#include "rcb_test_util.h"

static const char *const OUTS[] = {"DA.x", "DA.y", "DB.x", "DB.y"};
static const char *const INS[] = {"DA.x", "DB.y"};
#define NCH 8

/* The model's inertances with noise, channel c (references-major: DA.x..DB.y
 * for DA.x, then for DB.y) read through
 * fac[c] and renamed to rename[c] (NULL: as measured). */
static rcb_meas *faulty(const rcb_model *m, const double complex *fac,
                        const char *const *rename) {
  rcb_meas *ms0 = rcb_test_frf_meas(m, OUTS, 4, INS, 2, 100, 400, 31, 10000, RCB_INERTANCE);
  rcb_meas *ms;
  assert_int_equal(rcb_meas_add_noise(ms0, 10.0, 1.0, 1u), RCB_OK);
  ms = rcb_test_meas_copy(ms0, fac, rename);
  rcb_meas_destroy(ms0);
  return ms;
}

/* What a diagnosis of the model, kt fitted (and base sensor parameters),
 * on scale sc, reports: its first candidate, and its explanation. */
typedef struct diag_round {
  rcb_diag *d;
  rcb_diag_candidate c0;
  char text[4096];
} diag_round;

static void run_round(diag_round *r, const rcb_model *m, const rcb_meas *ms, rcb_fit_scale sc,
                      const char *base_sensor, const char *fixed, double gain,
                      const char *swap_a, const char *swap_b) {
  double lo, hi;
  int logp;
  memset(r, 0, sizeof *r);
  assert_int_equal(rcb_diag_create(&r->d, m, ms, NULL), RCB_OK);
  assert_int_equal(rcb_diag_set_scale(r->d, sc), RCB_OK);
  assert_int_equal(rcb_diag_set_noise_model(r->d, 10.0, 1.0), RCB_OK);
  assert_int_equal(rcb_diag_set_refits(r->d, 3), RCB_OK);
  assert_int_equal(rcb_diag_add_fitted_param(r->d, "coupling.C.kt", 4.6e3, 4.6e5, 1), RCB_OK);
  if (base_sensor) {
    assert_int_equal(rcb_fit_sensor_param_defaults(base_sensor, NULL, &lo, &hi, &logp), 1);
    assert_int_equal(rcb_diag_add_fitted_param(r->d, base_sensor, lo, hi, logp), RCB_OK);
  }
  if (fixed) assert_int_equal(rcb_diag_set_sensor(r->d, fixed, gain, 0.0), RCB_OK);
  if (swap_a) assert_int_equal(rcb_diag_swap_sensors(r->d, swap_a, swap_b), RCB_OK);
  if (rcb_diag_run(r->d)) fail_msg("%s", rcb_diag_errmsg(r->d));
  assert_int_equal(rcb_diag_candidate_get(r->d, 0, &r->c0), RCB_OK);
  assert_int_equal(rcb_diag_explain(r->d, r->text, sizeof r->text, NULL), RCB_OK);
  print_message("%s [%s]: %s\n  %s\n", r->c0.description, rcb_claim_str(r->c0.claim),
                r->c0.carry, r->text);
}

/* Round 1 names effect at place first, explaining, with carry; --apply refuses it naming
 * the same options. */
static void expect_finding(diag_round *r, rcb_effect effect, const char *place, const char *carry) {
  rcb_model *m2 = NULL;
  assert_int_equal(r->c0.effect, effect);
  assert_string_equal(r->c0.place, place);
  assert_int_equal(r->c0.claim, RCB_CLAIM_EXPLAINS);
  assert_true(r->c0.chain);
  assert_string_equal(r->c0.carry, carry);
  assert_non_null(strstr(r->text, carry));
  assert_int_equal(rcb_diag_apply_model(r->d, 0, NULL, &m2), RCB_ERR_STATE);
  assert_null(m2);
  assert_non_null(strstr(rcb_diag_errmsg(r->d), carry));
}

/* Round 2: no chain candidate at sensor claimed again; strict (log10
 * magnitudes): the model as it is adequate and nothing claimed at all. On
 * the complex scale the eq. 19 weights taken at the measured values bias a
 * level (issue #33, item 1): another probe's gain can come out significant
 * there (DA.y, dBIC -17.5 on this seed), so only the sensor carried is
 * checked. */
static void expect_clean(diag_round *r, const char *sensor, int strict) {
  rcb_fit_adequacy a;
  size_t k;
  assert_int_equal(rcb_diag_adequacy(r->d, &a), RCB_OK);
  assert_true(a.known && (a.adequate || !strict));
  for (k = 0; k < rcb_diag_candidate_count(r->d); k++) {
    rcb_diag_candidate c;
    assert_int_equal(rcb_diag_candidate_get(r->d, k, &c), RCB_OK);
    if (c.chain && c.claim != RCB_CLAIM_NONE && (strict || strstr(c.place, sensor)))
      fail_msg("round 2 claims %s", c.description);
  }
  if (!strict) return;
  assert_non_null(strstr(r->text, "none is needed"));
  assert_null(strstr(r->text, sensor));
}

static void test_gain_carried(void **state) {
  rcb_model *m = rcb_test_model_from_example("paper_system.ini");
  double complex fac[NCH] = {1, 1, 1, 0.8, 1, 1, 1, 0.8};
  rcb_meas *ms = faulty(m, fac, NULL);
  diag_round r1, r2, r3;
  (void)state;
  run_round(&r1, m, ms, RCB_SCALE_LOG10, NULL, NULL, 1, NULL, NULL);
  expect_finding(&r1, RCB_EFFECT_SENSOR_GAIN, "sensor DB.y",
                 "--params coupling.C.kt,sensor.DB.y.gain");
  /* the gain fitted with kt: it is no candidate any more */
  run_round(&r2, m, ms, RCB_SCALE_LOG10, "sensor.DB.y.gain", NULL, 1, NULL, NULL);
  expect_clean(&r2, "DB.y", 1);
  /* the gain known */
  run_round(&r3, m, ms, RCB_SCALE_LOG10, NULL, "DB.y", 0.8, NULL, NULL);
  expect_clean(&r3, "DB.y", 1);
  rcb_diag_destroy(r1.d), rcb_diag_destroy(r2.d), rcb_diag_destroy(r3.d);
  rcb_meas_destroy(ms);
  rcb_model_destroy(m);
}

static void test_sign_and_swap_carried(void **state) {
  rcb_model *m = rcb_test_model_from_example("paper_system.ini");
  double complex neg[NCH] = {1, 1, 1, -1, 1, 1, 1, -1}, one[NCH] = {1, 1, 1, 1, 1, 1, 1, 1};
  const char *swapped[NCH] = {"DA.x", "DA.y", "DB.y", "DB.x", "DA.x", "DA.y", "DB.y", "DB.x"};
  rcb_meas *ms_neg = faulty(m, neg, NULL), *ms_swap = faulty(m, one, swapped);
  diag_round r;
  (void)state;
  run_round(&r, m, ms_neg, RCB_SCALE_COMPLEX, NULL, NULL, 1, NULL, NULL);
  expect_finding(&r, RCB_EFFECT_SENSOR_SIGN, "sensor DB.y",
                 "--params coupling.C.kt --sensor DB.y:sign=-1");
  rcb_diag_destroy(r.d);
  run_round(&r, m, ms_neg, RCB_SCALE_COMPLEX, NULL, "DB.y", -1, NULL, NULL);
  expect_clean(&r, "DB.y", 0);
  rcb_diag_destroy(r.d);
  /* the sign found on top of a gain carried: the gain flipped is named */
  run_round(&r, m, ms_neg, RCB_SCALE_COMPLEX, NULL, "DB.y", 1.25, NULL, NULL);
  assert_int_equal(r.c0.effect, RCB_EFFECT_SENSOR_SIGN);
  assert_string_equal(r.c0.carry, "--params coupling.C.kt --sensor DB.y:gain=-1.25");
  rcb_diag_destroy(r.d);
  run_round(&r, m, ms_swap, RCB_SCALE_COMPLEX, NULL, NULL, 1, NULL, NULL);
  expect_finding(&r, RCB_EFFECT_SENSOR_SWAP, "sensors DB.x, DB.y",
                 "--params coupling.C.kt --swap DB.x,DB.y");
  rcb_diag_destroy(r.d);
  run_round(&r, m, ms_swap, RCB_SCALE_COMPLEX, NULL, NULL, 1, "DB.y", "DB.x");
  expect_clean(&r, "DB.", 0);
  rcb_diag_destroy(r.d);
  rcb_meas_destroy(ms_neg);
  rcb_meas_destroy(ms_swap);
  rcb_model_destroy(m);
}

static void test_carry_errors(void **state) {
  rcb_model *m = rcb_test_model_from_example("paper_system.ini");
  double complex one[NCH] = {1, 1, 1, 1, 1, 1, 1, 1};
  rcb_meas *ms = faulty(m, one, NULL);
  rcb_diag *d = NULL;
  double s, lo, hi;
  int logp;
  (void)state;
  assert_int_equal(rcb_fit_sensor_param_defaults("sensor.DB.y.gain", &s, &lo, &hi, &logp), 1);
  assert_true(s == 1.0 && lo == 0.1 && hi == 10.0 && logp == 1);
  assert_int_equal(rcb_fit_sensor_param_defaults("sensor.DB.y.phase", &s, &lo, &hi, &logp), 2);
  assert_true(s == 0.0 && rcb_test_close(hi, 1.5707963267948966, 1e-15, 0) && lo == -hi &&
              logp == 0);
  assert_int_equal(rcb_fit_sensor_param_defaults("coupling.C.kt", &s, &lo, &hi, &logp), 0);
  assert_int_equal(rcb_diag_create(&d, m, ms, NULL), RCB_OK);
  assert_int_equal(rcb_diag_set_sensor(d, "DB.z", -1, 0), RCB_ERR_ARG);
  assert_non_null(strstr(rcb_diag_errmsg(d), "'DB.z'"));
  assert_non_null(strstr(rcb_diag_errmsg(d), "measured responses: DA.x, DA.y, DB.x, DB.y"));
  assert_int_equal(rcb_diag_set_sensor(d, "DB.y", 0.0, 0), RCB_ERR_ARG);
  assert_int_equal(rcb_diag_set_sensor(d, "DB.y", 1.0, NAN), RCB_ERR_ARG);
  assert_int_equal(rcb_diag_add_fitted_param(d, "sensor.B4.y.gain", 0.1, 10, 1), RCB_ERR_ARG);
  assert_non_null(strstr(rcb_diag_errmsg(d), "'B4.y'"));
  assert_int_equal(rcb_diag_swap_sensors(d, "DB.x", "Q.y"), RCB_ERR_ARG);
  assert_non_null(strstr(rcb_diag_errmsg(d), "'Q.y'"));
  assert_int_equal(rcb_diag_swap_sensors(d, "DB.x", "DB.x"), RCB_ERR_ARG);
  assert_int_equal(rcb_diag_swap_sensors(d, "DB.x", "DB.y"), RCB_OK);
  assert_int_equal(rcb_diag_swap_sensors(d, "DA.x", "DB.y"), RCB_ERR_ARG);
  assert_non_null(strstr(rcb_diag_errmsg(d), "swapped already"));
  rcb_diag_destroy(d);
  rcb_meas_destroy(ms);
  rcb_model_destroy(m);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_carry_errors),
      cmocka_unit_test(test_gain_carried),
      cmocka_unit_test(test_sign_and_swap_carried),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
