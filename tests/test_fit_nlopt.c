/*
 * NLopt backend of the fitter (src/identify/fit_nlopt.c).
 *
 * The synthetic, noise-free measurement is the FRF of the paper system
 * (examples/paper_system.ini) itself, so the true parameters are a known
 * zero of the objective: each optimiser, started at half of the coupling's
 * kt, kr and ct, must find them again (local methods to 1e-4 relative).
 * Without NLopt, the backend must refuse with RCB_ERR_UNSUPPORTED.
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
#include "rcb/rcb_config.h"
#include "rcb/rcb_identify.h"
#include "rcb/rcb_measure.h"
#include "rcb_test_util.h"

#define NPAR 3
#define NPTS 60
#define NCH 5
#define TEST_PI 3.14159265358979323846

static const char *const par_names[NPAR] = {"coupling.C.kt", "coupling.C.kr", "coupling.C.ct"};
/* examples/paper_system.ini, paper Table 1: N/m, N m/rad, N s/m */
static const double par_true[NPAR] = {46.095e3, 220.76, 10.949};

/* Responses at the coupling and a disk, force at the coupling (side A). */
static const char *const ch_resp[NCH] = {"C.A.x", "C.B.x", "C.A.ry", "C.B.ry", "DA.x"};
static const char *const ch_ref = "C.x";

typedef struct fixture {
  rcb_meas *meas;
  rcb_model *m; /* fresh model per case, started at half the true values */
} fixture;

/* Noise-free receptances of the true model, 10 to 500 Hz at 10000 rpm. */
static rcb_meas *make_measurement(void) {
  rcb_model *m = rcb_test_model_from_example("paper_system.ini");
  rcb_meas *ms = NULL;
  rcb_frf *frf = NULL;
  rcb_dof outs[NCH], in;
  double w[NPTS], speed = 10000.0 * TEST_PI / 30.0; /* rad/s */
  rcb_complex H[NCH], data[NCH][NPTS];
  size_t i, c;
  for (c = 0; c < NCH; c++) assert_int_equal(rcb_model_find_dof(m, ch_resp[c], &outs[c]), RCB_OK);
  assert_int_equal(rcb_model_find_dof(m, ch_ref, &in), RCB_OK);
  assert_int_equal(rcb_frf_create(&frf, m, NCH, outs, 1, &in, RCB_SOLVER_AUTO, NULL), RCB_OK);
  for (i = 0; i < NPTS; i++) {
    w[i] = 2.0 * TEST_PI * (10.0 + 490.0 * (double)i / (NPTS - 1)); /* rad/s */
    assert_int_equal(rcb_frf_eval(frf, w[i], speed, RCB_RECEPTANCE, H), RCB_OK);
    for (c = 0; c < NCH; c++) data[c][i] = H[c];
  }
  assert_int_equal(rcb_meas_create(&ms, NULL), RCB_OK);
  assert_int_equal(rcb_meas_set_grid(ms, RCB_MEAS_FRF, NPTS, w, speed), RCB_OK);
  for (c = 0; c < NCH; c++)
    assert_int_equal(rcb_meas_add_channel(ms, ch_resp[c], ch_ref, RCB_RECEPTANCE, data[c]),
                     RCB_OK);
  rcb_frf_destroy(frf);
  rcb_model_destroy(m);
  return ms;
}

static int setup(void **state) {
  static fixture fx;
  size_t k;
  memset(&fx, 0, sizeof fx);
  fx.meas = make_measurement();
  fx.m = rcb_test_model_from_example("paper_system.ini");
  for (k = 0; k < NPAR; k++)
    assert_int_equal(rcb_model_set_param(fx.m, par_names[k], 0.5 * par_true[k]), RCB_OK);
  *state = &fx;
  return 0;
}

static int teardown(void **state) {
  fixture *fx = (fixture *)*state;
  rcb_model_destroy(fx->m);
  rcb_meas_destroy(fx->meas);
  return 0;
}

/* A fit of kt, kr, ct (log parameters within [lo_f, hi_f] x true) by method. */
static rcb_fit *make_fit(fixture *fx, const char *algorithm, double lo_f, double hi_f) {
  rcb_fit *f = NULL;
  size_t k;
  assert_int_equal(rcb_fit_create(&f, fx->m, fx->meas, NULL), RCB_OK);
  for (k = 0; k < NPAR; k++)
    assert_int_equal(
        rcb_fit_add_param(f, par_names[k], lo_f * par_true[k], hi_f * par_true[k], 1), RCB_OK);
  assert_int_equal(rcb_fit_set_scale(f, RCB_SCALE_LOG10), RCB_OK);
  assert_int_equal(rcb_fit_set_method(f, RCB_FIT_NLOPT, algorithm), RCB_OK);
  return f;
}

#if RCB_WITH_NLOPT

static void reset_start(void **state) {
  fixture *fx = (fixture *)*state;
  size_t k;
  for (k = 0; k < NPAR; k++)
    assert_int_equal(rcb_model_set_param(fx->m, par_names[k], 0.5 * par_true[k]), RCB_OK);
}


/* Largest relative parameter error after the fit. */
static double max_rel_error(const rcb_fit *f) {
  double e = 0;
  size_t k;
  assert_int_equal(rcb_fit_param_count(f), NPAR);
  for (k = 0; k < NPAR; k++) {
    rcb_fit_param p;
    assert_int_equal(rcb_fit_get_param(f, k, &p), RCB_OK);
    assert_string_equal(p.name, par_names[k]);
    assert_true(rcb_test_close(p.start, 0.5 * par_true[k], 1e-12, 0));
    e = fmax(e, fabs(p.value / par_true[k] - 1.0));
  }
  return e;
}

/* Run, check the recovered values and the report; prints evaluations. */
static void run_and_check(rcb_fit *f, const char *label, double tol, int expect_converged) {
  rcb_fit_report rep;
  rcb_status st = rcb_fit_run(f);
  double err;
  if (st != RCB_OK) fail_msg("%s: %s: %s", label, rcb_status_str(st), rcb_fit_errmsg(f));
  assert_int_equal(rcb_fit_get_report(f, &rep), RCB_OK);
  err = max_rel_error(f);
  print_message("%-22s iterations %4zu  evaluations %5zu  F %.3e -> %.3e  max rel err %.2e\n",
                label, rep.iterations, rep.evaluations, rep.objective0, rep.objective, err);
  /* every objective call evaluates the model at least once */
  assert_true(rep.evaluations >= rep.iterations);
  assert_true(rep.objective < 1e-6 * rep.objective0);
  assert_true(err < tol);
  if (expect_converged) assert_int_equal(rep.converged, 1);
}

static void test_bobyqa_recovers_coupling(void **state) {
  rcb_fit *f = make_fit((fixture *)*state, "LN_BOBYQA", 0.05, 20.0);
  run_and_check(f, "LN_BOBYQA", 1e-4, 1);
  rcb_fit_destroy(f);
}

static void test_lbfgs_recovers_coupling(void **state) {
  rcb_fit *f = make_fit((fixture *)*state, "ld_lbfgs", 0.05, 20.0);
  run_and_check(f, "LD_LBFGS", 1e-4, 0);
  rcb_fit_destroy(f);
}

/* DIRECT-L over a box whose (log) centre is not the answer, polished by
 * BOBYQA; the global stage alone with its default budget also gets close. */
static void test_direct_l_recovers_coupling(void **state) {
  fixture *fx = (fixture *)*state;
  rcb_fit *f = make_fit(fx, "NLOPT_GN_DIRECT_L+bobyqa", 0.1, 5.0);
  run_and_check(f, "GN_DIRECT_L+LN_BOBYQA", 1e-4, 1);
  rcb_fit_destroy(f);
  reset_start(state);
  f = make_fit(fx, "direct-l", 0.1, 5.0);
  assert_int_equal(rcb_fit_set_limits(f, 20, 1e-10, 1e-8), RCB_OK); /* 800 evaluations */
  {
    rcb_fit_report rep;
    double err;
    assert_int_equal(rcb_fit_run(f), RCB_OK);
    assert_int_equal(rcb_fit_get_report(f, &rep), RCB_OK);
    err = max_rel_error(f);
    print_message("%-22s iterations %4zu  evaluations %5zu  F %.3e -> %.3e  max rel err %.2e\n",
                  "GN_DIRECT_L (800)", rep.iterations, rep.evaluations, rep.objective0,
                  rep.objective, err);
    assert_true(rep.iterations <= 800);
    assert_true(rep.objective < 1e-2 * rep.objective0);
    assert_true(err < 0.05);
    assert_int_equal(rep.converged, 0); /* ended by the budget */
  }
  rcb_fit_destroy(f);
}

static void test_unknown_algorithm(void **state) {
  fixture *fx = (fixture *)*state;
  const char *bad[] = {"LN_FOO", "", "bobyqa+direct-l", "bobyqa+lbfgs", "AUGLAG"};
  size_t i;
  for (i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    rcb_fit *f = make_fit(fx, bad[i], 0.05, 20.0);
    double kt = 0;
    assert_int_equal(rcb_fit_run(f), RCB_ERR_ARG);
    assert_non_null(strstr(rcb_fit_errmsg(f), "LN_BOBYQA"));
    /* the model is untouched */
    assert_int_equal(rcb_model_get_param(fx->m, "coupling.C.kt", &kt), RCB_OK);
    assert_true(kt == 0.5 * par_true[0]);
    rcb_fit_destroy(f);
  }
}

/* NLopt's names in any case, with or without the prefix, the aliases and
 * GLOBAL+LOCAL pairs are accepted; max_iter = 1 bounds each run's objective
 * calls by the documented budget (np = 3): LD 2, LN 4, global 40, global
 * with polish 8 + 4. NLopt's LBFGS (Luksan's code) tests maxeval only
 * between line searches, so it may finish its line search first: 2 + 2. */
static void test_names_accepted(void **state) {
  static const struct {
    const char *name;
    size_t budget;
  } ok[] = {{"ln_bobyqa", 4},          {"NLOPT_LN_SBPLX", 4},  {"Sbplx", 4},
            {"nlopt_ld_mma", 2},       {"lbfgs", 4},           {"crs2", 40},
            {"G_MLSL_LDS+LD_LBFGS", 40}, {"mlsl", 40},          {"direct_l+bobyqa", 12},
            {"GN_ISRES", 40}};
  fixture *fx = (fixture *)*state;
  size_t i;
  for (i = 0; i < sizeof ok / sizeof ok[0]; i++) {
    rcb_fit *f = make_fit(fx, ok[i].name, 0.05, 20.0);
    rcb_fit_report rep;
    rcb_status st;
    assert_int_equal(rcb_fit_set_limits(f, 1, 1e-10, 1e-8), RCB_OK);
    st = rcb_fit_run(f);
    if (st != RCB_OK) fail_msg("%s: %s: %s", ok[i].name, rcb_status_str(st), rcb_fit_errmsg(f));
    assert_int_equal(rcb_fit_get_report(f, &rep), RCB_OK);
    if (rep.iterations < 1 || rep.iterations > ok[i].budget)
      fail_msg("%s: %zu objective calls, budget %zu", ok[i].name, rep.iterations, ok[i].budget);
    assert_true(rep.objective <= rep.objective0); /* the best point is kept */
    rcb_fit_destroy(f);
    reset_start(state);
  }
}

/* MLSL (low-discrepancy starts) with LBFGS local searches, 400 calls. */
static void test_mlsl_recovers_coupling(void **state) {
  rcb_fit *f = make_fit((fixture *)*state, "mlsl+lbfgs", 0.1, 5.0);
  assert_int_equal(rcb_fit_set_limits(f, 10, 1e-10, 1e-8), RCB_OK);
  run_and_check(f, "G_MLSL_LDS+LD_LBFGS", 1e-4, 0);
  rcb_fit_destroy(f);
}

static int stop_after(void *user, size_t iter, size_t evals, double objective) {
  size_t *calls = (size_t *)user;
  (void)evals;
  assert_true(objective >= 0);
  assert_int_equal(iter, *calls + 1); /* one call per objective evaluation */
  (*calls)++;
  return iter >= 5;
}

/* A nonzero progress return stops the run, also inside MLSL's local
 * searches and before a polish; the best point seen stays in the model. */
static void test_progress_stops(void **state) {
  static const char *const names[] = {"sbplx", "lbfgs", "mlsl+bobyqa", "direct-l+bobyqa"};
  fixture *fx = (fixture *)*state;
  size_t i;
  for (i = 0; i < sizeof names / sizeof names[0]; i++) {
    rcb_fit *f = make_fit(fx, names[i], 0.05, 20.0);
    size_t calls = 0;
    rcb_fit_report rep;
    assert_int_equal(rcb_fit_set_progress(f, stop_after, &calls), RCB_OK);
    assert_int_equal(rcb_fit_run(f), RCB_ERR_STATE);
    assert_non_null(strstr(rcb_fit_errmsg(f), "stopped by the caller"));
    assert_int_equal(calls, 5);
    assert_int_equal(rcb_fit_get_report(f, &rep), RCB_OK);
    assert_int_equal(rep.iterations, 5);
    assert_int_equal(rep.converged, 0);
    { /* the model holds the best of the 5 points: no worse than the start */
      size_t n = rcb_fit_residual_count(f), j;
      double *r = malloc(n * sizeof *r), F = 0;
      assert_non_null(r);
      assert_int_equal(rcb_fit_residuals(f, r), RCB_OK);
      for (j = 0; j < n; j++) F += r[j] * r[j];
      assert_true(F < rep.objective0);
      free(r);
    }
    rcb_fit_destroy(f);
    reset_start(state);
  }
}

static int each(void **state) {
  reset_start(state);
  return 0;
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test_setup(test_unknown_algorithm, each),
      cmocka_unit_test_setup(test_progress_stops, each),
      cmocka_unit_test_setup(test_bobyqa_recovers_coupling, each),
      cmocka_unit_test_setup(test_lbfgs_recovers_coupling, each),
      cmocka_unit_test_setup(test_direct_l_recovers_coupling, each),
      cmocka_unit_test_setup(test_names_accepted, each),
      cmocka_unit_test_setup(test_mlsl_recovers_coupling, each),
  };
  return cmocka_run_group_tests(tests, setup, teardown);
}

#else /* !RCB_WITH_NLOPT */

static void test_nlopt_unsupported(void **state) {
  rcb_fit *f = make_fit((fixture *)*state, "LN_BOBYQA", 0.05, 20.0);
  double kt = 0;
  assert_int_equal(rcb_fit_run(f), RCB_ERR_UNSUPPORTED);
  assert_non_null(strstr(rcb_fit_errmsg(f), "RCB_WITH_NLOPT=OFF"));
  assert_int_equal(rcb_model_get_param(((fixture *)*state)->m, "coupling.C.kt", &kt), RCB_OK);
  assert_true(kt == 0.5 * par_true[0]);
  rcb_fit_destroy(f);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_nlopt_unsupported),
  };
  return cmocka_run_group_tests(tests, setup, teardown);
}

#endif
