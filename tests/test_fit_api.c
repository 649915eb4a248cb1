/*
 * The fit's settings read back (NLopt's set/get pairing): every rcb_fit_set_*
 * has an rcb_fit_get_* that returns the documented default before any set
 * and the value set after it; a refused setting leaves the value as it was.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "rcb/rcb.h"
#include "rcb_test_util.h"

static int progress_cb(void *user, size_t iter, size_t evals, double objective) {
  (void)user, (void)iter, (void)evals, (void)objective;
  return 0;
}

static rcb_fit *make(rcb_model **m, rcb_meas **ms) {
  const char *outs[] = {"C.A.x", "C.B.y"};
  rcb_fit *f = NULL;
  *m = rcb_test_model_from_example("paper_system.ini");
  *ms = rcb_test_unbalance_meas(*m, outs, 2, 300, 18300, 7);
  assert_int_equal(rcb_fit_create(&f, *m, *ms, NULL), RCB_OK);
  return f;
}

static void test_defaults(void **state) {
  rcb_model *m;
  rcb_meas *ms;
  rcb_fit *f = make(&m, &ms);
  double lo, hi, a, b, w[14], ftol, xtol;
  size_t it, n;
  uint64_t seed;
  const char *alg = NULL;
  int (*cb)(void *, size_t, size_t, double) = progress_cb;
  void *user = &lo;
  (void)state;
  assert_int_equal(rcb_fit_get_scale(f), RCB_SCALE_LINEAR);
  assert_int_equal(rcb_fit_get_band(f, &lo, &hi), RCB_OK);
  assert_true(lo == 0.0 && isinf(hi) && hi > 0);
  memset(w, 0, sizeof w);
  assert_int_equal(rcb_fit_get_weights(f, w), 0);
  for (n = 0; n < 14; n++) assert_true(w[n] == 1.0);
  assert_int_equal(rcb_fit_get_noise_model(f, &a, &b), RCB_OK);
  assert_true(a == 0.0 && b == 0.0);
  assert_int_equal(rcb_fit_get_method(f, &alg), RCB_FIT_PAPER);
  assert_string_equal(alg, "");
  assert_int_equal(rcb_fit_get_analytic(f), 1);
  assert_int_equal(rcb_fit_get_limits(f, &it, &ftol, &xtol), RCB_OK);
  assert_true(it == 100 && ftol == 1e-10 && xtol == 1e-8);
  assert_int_equal(rcb_fit_get_progress(f, &cb, &user), RCB_OK);
  assert_true(cb == NULL && user == NULL);
  assert_int_equal(rcb_fit_get_starts(f, &n, &seed), RCB_OK);
  assert_true(n == 1 && seed == 0);
  assert_int_equal(rcb_fit_get_first_start(f), 0);
  assert_int_equal(rcb_fit_get_uncertainty(f), 1);
  assert_int_equal(rcb_fit_get_param_bounds(f, 0, &lo, &hi, NULL), RCB_ERR_ARG);
  rcb_fit_destroy(f);
  rcb_meas_destroy(ms);
  rcb_model_destroy(m);
}

static void test_set_then_get(void **state) {
  rcb_model *m;
  rcb_meas *ms;
  rcb_fit *f = make(&m, &ms);
  double lo, hi, a, b, w[14], wb[14], ftol, xtol;
  size_t it, n, i;
  uint64_t seed;
  int lg, user_data = 0;
  const char *alg = NULL;
  int (*cb)(void *, size_t, size_t, double) = NULL;
  void *user = NULL;
  (void)state;
  assert_int_equal(rcb_fit_add_param(f, "coupling.C.kt", 1e3, 1e6, 1), RCB_OK);
  assert_int_equal(rcb_fit_add_param(f, "coupling.C.ct", 0.0, 100.0, 0), RCB_OK);
  assert_int_equal(rcb_fit_get_param_bounds(f, 0, &lo, &hi, &lg), RCB_OK);
  assert_true(lo == 1e3 && hi == 1e6 && lg == 1);
  assert_int_equal(rcb_fit_get_param_bounds(f, 1, &lo, &hi, &lg), RCB_OK);
  assert_true(lo == 0.0 && hi == 100.0 && lg == 0);
  assert_int_equal(rcb_fit_set_scale(f, RCB_SCALE_COMPLEX), RCB_OK);
  assert_int_equal(rcb_fit_get_scale(f), RCB_SCALE_COMPLEX);
  assert_int_equal(rcb_fit_set_band(f, 400.0, 1500.0), RCB_OK);
  assert_int_equal(rcb_fit_set_band(f, 10.0, 5.0), RCB_ERR_ARG); /* refused: kept */
  assert_int_equal(rcb_fit_get_band(f, &lo, &hi), RCB_OK);
  assert_true(lo == 400.0 && hi == 1500.0);
  for (i = 0; i < 14; i++) w[i] = 0.5 * (double)i;
  assert_int_equal(rcb_fit_set_weights(f, w), RCB_OK);
  assert_int_equal(rcb_fit_get_weights(f, wb), 1);
  assert_memory_equal(w, wb, sizeof w);
  assert_int_equal(rcb_fit_set_weights(f, NULL), RCB_OK);
  assert_int_equal(rcb_fit_get_weights(f, wb), 0);
  assert_int_equal(rcb_fit_set_noise_model(f, 10.0, 1.0), RCB_OK);
  assert_int_equal(rcb_fit_get_noise_model(f, &a, &b), RCB_OK);
  assert_true(a == 10.0 && b == 1.0);
  assert_int_equal(rcb_fit_set_method(f, RCB_FIT_NLOPT, "LN_BOBYQA"), RCB_OK);
  assert_int_equal(rcb_fit_get_method(f, &alg), RCB_FIT_NLOPT);
  assert_string_equal(alg, "LN_BOBYQA");
  assert_int_equal(rcb_fit_set_analytic(f, 0), RCB_OK);
  assert_int_equal(rcb_fit_get_analytic(f), 0);
  assert_int_equal(rcb_fit_set_limits(f, 7, 1e-4, 1e-3), RCB_OK);
  assert_int_equal(rcb_fit_get_limits(f, &it, &ftol, &xtol), RCB_OK);
  assert_true(it == 7 && ftol == 1e-4 && xtol == 1e-3);
  assert_int_equal(rcb_fit_get_limits(f, NULL, &ftol, NULL), RCB_OK);
  assert_int_equal(rcb_fit_set_progress(f, progress_cb, &user_data), RCB_OK);
  assert_int_equal(rcb_fit_get_progress(f, &cb, &user), RCB_OK);
  assert_true(cb == progress_cb && user == &user_data);
  assert_int_equal(rcb_fit_set_starts(f, 5, 2024ul), RCB_OK);
  assert_int_equal(rcb_fit_get_starts(f, &n, &seed), RCB_OK);
  assert_true(n == 5 && seed == 2024ul);
  assert_int_equal(rcb_fit_set_first_start(f, 1), RCB_OK);
  assert_int_equal(rcb_fit_set_starts(f, 6, 7ul), RCB_OK); /* keeps the first start */
  assert_int_equal(rcb_fit_get_first_start(f), 1);
  assert_int_equal(rcb_fit_set_uncertainty(f, 0), RCB_OK);
  assert_int_equal(rcb_fit_get_uncertainty(f), 0);
  rcb_fit_destroy(f);
  rcb_meas_destroy(ms);
  rcb_model_destroy(m);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_defaults),
      cmocka_unit_test(test_set_then_get),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
