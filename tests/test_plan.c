/*
 * Which test would tell them apart (rcb_plan, issue #23 item 6):
 *  - identity: the separating chi-square S sin^2(theta) equals the objective
 *    at which rcb_fit leaves rival B fitted to A's noise-free data (A moved
 *    by the plan's dA), and B's fitted change equals the plan's dB, for one
 *    parameter a side and for two;
 *  - a symmetric rotor measured at its midspan disk only: the two bearings'
 *    y stiffnesses have the same sensitivities there (angle 0, chi-square 0:
 *    "cannot separate"); the plan ranks a y channel at a bearing first, and
 *    every x channel gains nothing (at rest x and y do not couple);
 *  - mirror symmetry: swapping the rivals gives the same angle and
 *    chi-square, and the mirrored candidate the same gain;
 *  - refusals: no noise model, a name on both sides, an unknown name.
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

#include "core/rcb_internal.h"
#include "rcb/rcb.h"
#include "rcb/rcb_config.h"
#include "rcb_test_util.h"

/* A shaft (0.8 m, d 30 mm, 8 elements) with a 20 kg disk D in the middle on
 * two equal bearings: mirror-symmetric about the disk. */
static const char ROTOR[] =
    "[material steel]\ndensity = 7800\nyoung = 2.1e11\npoisson = 0.3\n"
    "[shaft A]\nmaterial = steel\nshear_factor = 0.9\nsegment = 0.8 0.03 0.0 8\n"
    "[disk D]\nat = A 0.40\nmass = 20\nId = 0.1\nIp = 0.2\n"
    "[bearing B1]\nat = A 0.0\nkxx = 2e7\nkyy = 2e7\ncxx = 500\ncyy = 500\n"
    "[bearing B2]\nat = A 0.8\nkxx = 2e7\nkyy = 2e7\ncxx = 500\ncyy = 500\n";

static rcb_model *finalized(rcb_model *m) {
  if (rcb_model_dof_count(m) == 0) assert_int_equal(rcb_model_finalize(m), RCB_OK);
  return m;
}

static rcb_plan *plan_of(const rcb_model *m, const rcb_meas *ms, const char *a, const char *b,
                         double size) {
  rcb_plan *p = NULL;
  rcb_status st;
  assert_int_equal(rcb_plan_create(&p, m, ms, NULL), RCB_OK);
  assert_int_equal(rcb_plan_add_param(p, 0, a), RCB_OK);
  assert_int_equal(rcb_plan_add_param(p, 1, b), RCB_OK);
  assert_int_equal(rcb_plan_set_noise_model(p, 10.0, 1.0), RCB_OK);
  if (size > 0) assert_int_equal(rcb_plan_set_size(p, size), RCB_OK);
  st = rcb_plan_run(p);
  if (st) fail_msg("plan: %s", rcb_plan_errmsg(p));
  return p;
}

/* The plan's chi-square against a brute-force fit of B to A's data: rivals
 * a[0 .. na) and b[0 .. nb) on the paper system. */
static void identity_case(const rcb_model *m, const rcb_meas *layout, const char *const *a,
                          size_t na, const char *const *b, size_t nb) {
  static const char *const outs[] = {"C.A.x", "C.B.x", "DA.x", "DB.y"};
  static const char *const ins[] = {"DA.x"};
  rcb_model *truth = NULL, *start = NULL;
  rcb_meas *data;
  rcb_plan_result r;
  rcb_fit_report rep;
  rcb_fit *f = NULL;
  rcb_plan *p = NULL;
  size_t k;
  assert_int_equal(rcb_plan_create(&p, m, layout, NULL), RCB_OK);
  for (k = 0; k < na; k++) assert_int_equal(rcb_plan_add_param(p, 0, a[k]), RCB_OK);
  for (k = 0; k < nb; k++) assert_int_equal(rcb_plan_add_param(p, 1, b[k]), RCB_OK);
  assert_int_equal(rcb_plan_set_noise_model(p, 10.0, 1.0), RCB_OK);
  /* a small size: the linearisation's own error is O(dA / A) (1.6e-4 at
   * S = 1e-3, 5e-4 at S = 1e-2 for one parameter each: it falls as sqrt(S)) */
  assert_int_equal(rcb_plan_set_size(p, 1e-3), RCB_OK);
  if (rcb_plan_run(p)) fail_msg("plan: %s", rcb_plan_errmsg(p));
  assert_int_equal(rcb_plan_get_result(p, &r), RCB_OK);
  assert_true(r.angle_deg > 1.0 && r.angle_deg < 89.0);
  assert_true(fabs(r.chi2_sep - 1e-3 * pow(sin(r.angle_deg * RCB_PI / 180.0), 2)) <
              1e-9 * r.chi2_sep);
  /* A's data: the model with A's parameters moved by dA, noise-free */
  assert_int_equal(rcb_model_clone(&truth, m, NULL), RCB_OK);
  assert_int_equal(rcb_model_finalize(truth), RCB_OK);
  assert_int_equal(rcb_model_clone(&start, m, NULL), RCB_OK);
  assert_int_equal(rcb_model_finalize(start), RCB_OK);
  for (k = 0; k < na; k++) {
    rcb_plan_param q;
    assert_int_equal(rcb_plan_get_param(p, k, &q), RCB_OK);
    assert_int_equal(rcb_model_set_param(truth, q.name, q.value + q.change), RCB_OK);
  }
  data = rcb_test_frf_meas(truth, outs, 4, ins, 1, 100.0, 400.0, 151, 3000.0, RCB_INERTANCE);
  /* B fitted to them from the model's values */
  assert_int_equal(rcb_fit_create(&f, start, data, NULL), RCB_OK);
  assert_int_equal(rcb_fit_set_noise_model(f, 10.0, 1.0), RCB_OK);
  for (k = 0; k < nb; k++) {
    rcb_plan_param q;
    assert_int_equal(rcb_plan_get_param(p, na + k, &q), RCB_OK);
    assert_int_equal(rcb_fit_add_param(f, q.name, q.value / 10, q.value * 10, 0), RCB_OK);
  }
  assert_int_equal(rcb_fit_set_starts(f, 1, 1), RCB_OK);
  /* NLopt's BOBYQA to the precision asked: the paper's method stops at a gain
   * under 0.01 of a chi-square unit, and F here is 0.001 in all */
  assert_int_equal(rcb_fit_set_method(f, RCB_FIT_NLOPT, "LN_BOBYQA"), RCB_OK);
  assert_int_equal(rcb_fit_set_limits(f, 400, 1e-15, 1e-15), RCB_OK);
  assert_int_equal(rcb_fit_run(f), RCB_OK);
  assert_int_equal(rcb_fit_get_report(f, &rep), RCB_OK);
  print_message("%zu + %zu parameters: angle %.6g deg, chi2_sep %.10g; fit: F0 %.10g, F %.10g\n",
                na, nb, r.angle_deg, r.chi2_sep, rep.objective0, rep.objective);
  assert_true(fabs(rep.objective0 - 1e-3) < 1e-3 * 1e-3); /* ||J_A dA||^2 = S */
  assert_true(fabs(rep.objective - r.chi2_sep) < 1e-3 * r.chi2_sep);
  for (k = 0; k < nb; k++) { /* B's fitted change is the plan's dB */
    rcb_plan_param q;
    double v;
    assert_int_equal(rcb_plan_get_param(p, na + k, &q), RCB_OK);
    assert_int_equal(rcb_model_get_param(start, q.name, &v), RCB_OK);
    print_message("  %s: plan %.8g, fit %.8g\n", q.name, q.change, v - q.value);
    assert_true(fabs((v - q.value) - q.change) < 2e-3 * fabs(q.change));
  }
  rcb_fit_destroy(f);
  rcb_plan_destroy(p);
  rcb_meas_destroy(data);
  rcb_model_destroy(truth);
  rcb_model_destroy(start);
}

static void test_identity(void **state) {
  static const char *const outs[] = {"C.A.x", "C.B.x", "DA.x", "DB.y"};
  static const char *const ins[] = {"DA.x"};
  static const char *const a1[] = {"coupling.C.kt"}, *const b1[] = {"bearing.B2.kxx"};
  static const char *const a2[] = {"coupling.C.kt", "coupling.C.kr"};
  static const char *const b2[] = {"bearing.B2.kxx", "bearing.B3.kxx"};
  rcb_model *m;
  rcb_meas *layout;
  (void)state;
#if !RCB_WITH_NLOPT
  skip(); /* the brute force needs NLopt (identity_case) */
#endif
  m = finalized(rcb_test_model_from_example("paper_system.ini"));
  layout = rcb_test_frf_meas(m, outs, 4, ins, 1, 100.0, 400.0, 151, 3000.0, RCB_INERTANCE);
  identity_case(m, layout, a1, 1, b1, 1);
  identity_case(m, layout, a2, 2, b2, 2);
  rcb_meas_destroy(layout);
  rcb_model_destroy(m);
}

/* The symmetric rotor at rest, measured at D only: D.x and D.y per D.x, D.y. */
static rcb_meas *midspan(const rcb_model *m) {
  static const char *const outs[] = {"D.x", "D.y"};
  rcb_meas *a = rcb_test_frf_meas(m, outs, 1, outs, 1, 10.0, 300.0, 200, 0.0, RCB_RECEPTANCE);
  rcb_meas *b = rcb_test_frf_meas(m, outs + 1, 1, outs + 1, 1, 10.0, 300.0, 200, 0.0,
                                  RCB_RECEPTANCE);
  rcb_meas_channel_info ci;
  rcb_meas_channel(b, 0, &ci);
  assert_int_equal(rcb_meas_add_channel(a, ci.response, ci.reference, ci.kind, ci.data), RCB_OK);
  rcb_meas_destroy(b);
  return a;
}

static int at_bearing(const char *ch) { return ch[0] == 'B'; }

static void test_cannot_separate(void **state) {
  rcb_model *m = finalized(rcb_test_model_from_string(ROTOR));
  rcb_meas *ms = midspan(m);
  rcb_plan *p = plan_of(m, ms, "bearing.B1.kyy", "bearing.B2.kyy", 0);
  rcb_plan_result r;
  rcb_plan_candidate c;
  size_t i;
  (void)state;
  assert_int_equal(rcb_plan_get_result(p, &r), RCB_OK);
  assert_true(r.size == 25.0);
  assert_true(r.angle_deg < 1e-3);
  assert_true(r.chi2_sep < 1e-6);
  assert_int_equal(r.separable, 0);
  assert_true(r.candidates > 0);
  assert_int_equal(rcb_plan_get_candidate(p, 0, &c), RCB_OK);
  print_message("best: %s per %s, gain %g\n", c.response, c.reference, c.gain);
  assert_true(c.response[strlen(c.response) - 1] == 'y');
  assert_true(c.reference[strlen(c.reference) - 1] == 'y');
  assert_true(at_bearing(c.response) || at_bearing(c.reference));
  assert_true(c.gain > RCB_PLAN_SEPARATE_CHI2 && c.chi2_after >= c.gain);
  for (i = 0; i < r.candidates; i++) {
    assert_int_equal(rcb_plan_get_candidate(p, i, &c), RCB_OK);
    assert_true(c.gain >= 0.0);
    if (c.response[strlen(c.response) - 1] == 'x' && c.reference[strlen(c.reference) - 1] == 'x')
      assert_true(c.gain < 1e-9); /* x does not see kyy at rest */
    /* the present channels are not candidates */
    assert_false(strcmp(c.response, "D.y") == 0 && strcmp(c.reference, "D.y") == 0);
  }
  assert_int_equal(rcb_plan_get_candidate(p, r.candidates, &c), RCB_ERR_ARG);
  rcb_plan_destroy(p);
  rcb_meas_destroy(ms);
  rcb_model_destroy(m);
}

/* Gain of candidate resp/ref in p (-1 when absent). */
static double gain_at(const rcb_plan *p, const char *resp, const char *ref) {
  rcb_plan_candidate c;
  size_t i;
  for (i = 0; rcb_plan_get_candidate(p, i, &c) == RCB_OK; i++)
    if (strcmp(c.response, resp) == 0 && strcmp(c.reference, ref) == 0) return c.gain;
  return -1.0;
}

static void test_mirror_symmetry(void **state) {
  rcb_model *m = finalized(rcb_test_model_from_string(ROTOR));
  rcb_meas *ms = midspan(m);
  /* rivals that the midspan can tell apart: a stiffness at B1 vs a damping at B2 */
  rcb_plan *p1 = plan_of(m, ms, "bearing.B1.kyy", "bearing.B2.cyy", 0);
  rcb_plan *p2 = plan_of(m, ms, "bearing.B2.kyy", "bearing.B1.cyy", 0);
  rcb_plan_result r1, r2;
  static const char *const pairs[][2] = {{"B1.y", "D.y"}, {"B1.y", "B1.y"}, {"D.y", "B1.y"},
                                         {"B1.y", "B2.y"}};
  static const char *const mirror[][2] = {{"B2.y", "D.y"}, {"B2.y", "B2.y"}, {"D.y", "B2.y"},
                                          {"B2.y", "B1.y"}};
  size_t i;
  (void)state;
  assert_int_equal(rcb_plan_get_result(p1, &r1), RCB_OK);
  assert_int_equal(rcb_plan_get_result(p2, &r2), RCB_OK);
  print_message("angle %.8g vs %.8g deg, chi2 %.8g vs %.8g\n", r1.angle_deg, r2.angle_deg,
                r1.chi2_sep, r2.chi2_sep);
  assert_true(fabs(r1.angle_deg - r2.angle_deg) < 1e-6 * r1.angle_deg);
  assert_true(fabs(r1.chi2_sep - r2.chi2_sep) < 1e-6 * r1.chi2_sep);
  assert_int_equal(r1.candidates, r2.candidates);
  for (i = 0; i < 4; i++) {
    double g1 = gain_at(p1, pairs[i][0], pairs[i][1]);
    double g2 = gain_at(p2, mirror[i][0], mirror[i][1]);
    print_message("%s/%s %.10g vs %s/%s %.10g\n", pairs[i][0], pairs[i][1], g1, mirror[i][0],
                  mirror[i][1], g2);
    assert_true(g1 > 0 && fabs(g1 - g2) < 1e-6 * g1);
  }
  rcb_plan_destroy(p1);
  rcb_plan_destroy(p2);
  rcb_meas_destroy(ms);
  rcb_model_destroy(m);
}

static void test_refusals(void **state) {
  rcb_model *m = finalized(rcb_test_model_from_string(ROTOR));
  rcb_meas *ms = midspan(m);
  rcb_plan *p = NULL;
  rcb_plan_result r;
  (void)state;
  assert_int_equal(rcb_plan_create(&p, m, ms, NULL), RCB_OK);
  assert_int_equal(rcb_plan_add_param(p, 0, "bearing.B1.kyy"), RCB_OK);
  assert_int_equal(rcb_plan_add_param(p, 1, "bearing.B1.kyy"), RCB_ERR_ARG);
  assert_non_null(strstr(rcb_plan_errmsg(p), "both sides"));
  assert_int_equal(rcb_plan_add_param(p, 1, "bearing.B9.kyy"), RCB_ERR_NOT_FOUND);
  assert_int_equal(rcb_plan_run(p), RCB_ERR_ARG); /* no B */
  assert_int_equal(rcb_plan_add_param(p, 1, "bearing.B2.kyy"), RCB_OK);
  assert_int_equal(rcb_plan_run(p), RCB_ERR_ARG); /* no noise model */
  assert_non_null(strstr(rcb_plan_errmsg(p), "noise model"));
  assert_int_equal(rcb_plan_get_result(p, &r), RCB_ERR_ARG);
  assert_int_equal(rcb_plan_set_size(p, 0.0), RCB_ERR_ARG);
  assert_int_equal(rcb_plan_add_speed(p, -1.0), RCB_ERR_ARG);
  rcb_plan_destroy(p);
  rcb_meas_destroy(ms);
  rcb_model_destroy(m);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_identity),
      cmocka_unit_test(test_cannot_separate),
      cmocka_unit_test(test_mirror_symmetry),
      cmocka_unit_test(test_refusals),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
