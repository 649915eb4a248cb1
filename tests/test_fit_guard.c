/*
 * Guards on a fit's outcome (issue #7): a fit whose true minimum lies outside
 * the bounds ends AT_BOUND (and unsure), one out of iterations ends MAX_ITER
 * (unsure), a non-finite objective is an error, and a normal fit still
 * converges to the truth without a flag. Data: noise-free unbalance
 * responses of the paper's system (the truth is the model's own
 * coupling.C.kt = 46095 N/m).
 */
#include <float.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "rcb/rcb.h"
#include "rcb_test_util.h"

#define KT "coupling.C.kt"
#define KT_TRUE 46095.0 /* N/m, examples/paper_system.ini */

static const char *const outs[] = {"C.A.x", "C.A.y", "C.B.x", "C.B.y"};

typedef struct guard_case {
  rcb_model *m;
  rcb_meas *ms;
  rcb_fit *f;
} guard_case;

/* A fit of kt alone from @p start (N/m) within [lo, hi], log parameter. */
static void setup_case(guard_case *g, double start, double lo, double hi) {
  double kt;
  g->m = rcb_test_model_from_example("paper_system.ini");
  assert_int_equal(rcb_model_get_param(g->m, KT, &kt), RCB_OK);
  assert_true(kt == KT_TRUE);
  g->ms = rcb_test_unbalance_meas(g->m, outs, 4, 300, 18300, 25);
  assert_int_equal(rcb_model_set_param(g->m, KT, start), RCB_OK);
  assert_int_equal(rcb_fit_create(&g->f, g->m, g->ms, NULL), RCB_OK);
  assert_int_equal(rcb_fit_add_param(g->f, KT, lo, hi, 1), RCB_OK);
  assert_int_equal(rcb_fit_set_scale(g->f, RCB_SCALE_LOG10), RCB_OK);
}

static void teardown_case(guard_case *g) {
  rcb_fit_destroy(g->f);
  rcb_meas_destroy(g->ms);
  rcb_model_destroy(g->m);
}

static void fitted(const guard_case *g, rcb_fit_report *rep, rcb_fit_param *p) {
  assert_int_equal(rcb_fit_get_report(g->f, rep), RCB_OK);
  assert_int_equal(rcb_fit_get_param(g->f, 0, p), RCB_OK);
  print_message("kt %.10g N/m, stop: %s, iterations %zu, E1 %.3g %%\n", p->value,
                rcb_fit_stop_str(rcb_fit_stop_reason(g->f, NULL)), rep->iterations,
                rep->error_pct);
}

/* The control: bounds around the truth, a clean converged fit. */
static void test_converges(void **state) {
  guard_case g;
  rcb_fit_report rep;
  rcb_fit_param p;
  rcb_frf_condition c;
  size_t k;
  (void)state;
  setup_case(&g, 30000.0, 1e3, 1e6);
  assert_int_equal(rcb_fit_stop_reason(g.f, NULL), RCB_FIT_STOP_NONE);
  assert_int_equal(rcb_fit_run(g.f), RCB_OK);
  fitted(&g, &rep, &p);
  assert_true(rcb_test_close(p.value, KT_TRUE, 1e-5, 0));
  assert_int_equal(rcb_fit_stop_reason(g.f, &k), RCB_FIT_STOP_CONVERGED);
  assert_int_equal(k, 1); /* np: no parameter at a bound */
  assert_true(rep.converged && !rep.unsure);
  /* the final evaluation was checked: one solve per measured speed */
  assert_int_equal(rcb_fit_get_condition(g.f, &c), RCB_OK);
  assert_int_equal(c.checked, 25);
  assert_int_equal(c.ill, 0);
  /* screened: no small pivot, so no estimate was needed */
  assert_true(c.estimated == 0 || c.rcond_min > RCB_RCOND_WARN);
  teardown_case(&g);
}

/* The truth (46095 N/m) above the upper bound 2e4 N/m: the fit runs to the
 * bound, where it "converges" (the penalty holds it); a silent answer of
 * 2e4 would be wrong by a factor 2.3. */
static void test_at_bound(void **state) {
  guard_case g;
  rcb_fit_report rep;
  rcb_fit_param p;
  size_t k = 99;
  (void)state;
  setup_case(&g, 120000.0, 7e4, 1e6);
  assert_int_equal(rcb_fit_run(g.f), RCB_OK);
  fitted(&g, &rep, &p);
  assert_true(rcb_test_close(p.value, 7e4, 2e-3, 0)); /* pressed against lo */
  assert_int_equal(rcb_fit_stop_reason(g.f, &k), RCB_FIT_STOP_AT_BOUND);
  assert_int_equal(k, 0);
  assert_true(rep.unsure);
  assert_non_null(strstr(rcb_fit_stop_str(RCB_FIT_STOP_AT_BOUND), "bound"));
  teardown_case(&g);
}

/* A start two decades off and a single iteration: not converged, said so. */
static void test_max_iter(void **state) {
  guard_case g;
  rcb_fit_report rep;
  rcb_fit_param p;
  (void)state;
  setup_case(&g, 460.0, 1e2, 1e6);
  assert_int_equal(rcb_fit_set_limits(g.f, 1, 1e-10, 1e-8), RCB_OK);
  assert_int_equal(rcb_fit_run(g.f), RCB_OK);
  fitted(&g, &rep, &p);
  assert_false(rcb_test_close(p.value, KT_TRUE, 1e-3, 0)); /* not there yet */
  assert_int_equal(rcb_fit_stop_reason(g.f, NULL), RCB_FIT_STOP_MAX_ITER);
  assert_true(!rep.converged && rep.unsure);
  teardown_case(&g);
}

/* Weights so large that the objective overflows: an error naming it, not a
 * "minimum" no step could improve on. */
static void test_nonfinite_objective(void **state) {
  guard_case g;
  double *w;
  size_t k, n = 4 * 25;
  (void)state;
  setup_case(&g, 460.0, 1e2, 1e6);
  w = malloc(n * sizeof *w);
  assert_non_null(w);
  for (k = 0; k < n; k++) w[k] = DBL_MAX;
  assert_int_equal(rcb_fit_set_weights(g.f, w), RCB_OK);
  assert_int_equal(rcb_fit_run(g.f), RCB_ERR_NOT_CONVERGED);
  assert_non_null(strstr(rcb_fit_errmsg(g.f), "objective is "));
  assert_non_null(strstr(rcb_fit_errmsg(g.f), " at the start"));
  assert_int_equal(rcb_fit_stop_reason(g.f, NULL), RCB_FIT_STOP_NONE);
  free(w);
  teardown_case(&g);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_converges),
      cmocka_unit_test(test_at_bound),
      cmocka_unit_test(test_max_iter),
      cmocka_unit_test(test_nonfinite_objective),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
