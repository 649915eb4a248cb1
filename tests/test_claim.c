/*
 * The one rule of what may be said (issue #33, src/diagnose/claim.c) and the
 * noise model beneath it (src/identify): each expectation here comes from a
 * closed form (chi-square quantiles, the mean of ln(1 + b r) for r uniform)
 * or from an identity (a reference equal to the measured values weighs as
 * the measured values do), not from the code's own output.
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

#include "identify/fit_internal.h"
#include "rcb/rcb.h"
#include "rcb_test_util.h"

/* A known noise: F a chi-square; N residuals, k parameters, drop F0 - F. */
static rcb_evidence known(double drop, double k, double N, double phi, double tried) {
  rcb_evidence e;
  memset(&e, 0, sizeof e);
  e.delta_bic = -drop + k * log(N);
  e.error_before_pct = 6.0, e.error_after_pct = 6.0; /* the error need not fall */
  e.chi2 = N, e.chi2_limit = N + 2.326 * sqrt(2.0 * N);
  e.params = k, e.residuals = N, e.dispersion = phi, e.tried = tried;
  return e;
}

/* The dispersion divides the drop of F; the BIC price k ln N stays. */
static void test_dispersion(void **state) {
  rcb_evidence e = known(30.0, 1.0, 35000.0, 1.0, 1.0);
  double pen = log(35000.0); /* 10.463 */
  (void)state;
  assert_true(fabs(rcb_evidence_dbic(&e) - (-30.0 + pen)) < 1e-12);
  assert_true(rcb_evidence_significant(&e)); /* -19.5 */
  e.dispersion = 1.44;                         /* a noise 20 % above the declared */
  assert_true(fabs(rcb_evidence_dbic(&e) - (-30.0 / 1.44 + pen)) < 1e-12);
  assert_true(rcb_evidence_significant(&e)); /* -10.37 */
  e.dispersion = 2.0;
  assert_false(rcb_evidence_significant(&e)); /* -4.5 */
  e.dispersion = 0.5;                          /* never below the declared */
  assert_true(rcb_evidence_phi(&e) == 1.0);
  assert_true(fabs(rcb_evidence_dbic(&e) - (-30.0 + pen)) < 1e-12);
}

/* Bonferroni over the candidates tried: the drop must pass the chi-square
 * quantile of k degrees of freedom at 1 % / tried. k = 1: z^2 with
 * P(|Z| > z) = p; k = 2: -2 ln p (exact). */
static void test_multiplicity(void **state) {
  double N = 100.0; /* a small set: the BIC price ln 100 = 4.6 alone would pass 16 */
  rcb_evidence e = known(16.0, 1.0, N, 1.0, 1.0);
  (void)state;
  assert_true(rcb_evidence_significant(&e)); /* chi2_1(0.01) = 6.63 */
  e.tried = 1000.0;                           /* chi2_1(1e-5) = 4.4172^2 = 19.51 */
  assert_false(rcb_evidence_significant(&e));
  e = known(19.6, 1.0, N, 1.0, 1000.0);
  assert_true(rcb_evidence_significant(&e));
  e = known(19.4, 1.0, N, 1.0, 1000.0);
  assert_false(rcb_evidence_significant(&e));
  /* k = 2 at p = 1e-4: -2 ln 1e-4 = 18.42; the BIC asks 10 + 2 ln 100 = 19.21 */
  e = known(19.3, 2.0, N, 1.0, 100.0);
  assert_true(rcb_evidence_significant(&e));
  e = known(400.0, 2.0, 1e9, 1.0, 100.0); /* BIC: 10 + 2 ln 1e9 = 51.4 */
  assert_true(rcb_evidence_significant(&e));
  e = known(51.0, 2.0, 1e9, 1.0, 100.0);
  assert_false(rcb_evidence_significant(&e));
}

/* Adequate: within the limit, or beyond it with a white residual at most
 * 2 x the declared level; beyond what the part can be: never "explains". */
static void test_adequate_white_beyond(void **state) {
  rcb_evidence e = known(500.0, 1.0, 35000.0, 1.0, 139.0);
  (void)state;
  assert_int_equal(rcb_evidence_claim(&e), RCB_CLAIM_EXPLAINS);
  e.chi2 = e.chi2_limit + 1.0;
  assert_int_equal(rcb_evidence_adequate(&e), 0);
  assert_int_equal(rcb_evidence_claim(&e), RCB_CLAIM_IMPROVES);
  e.white = 1;
  assert_int_equal(rcb_evidence_adequate(&e), 1);
  assert_int_equal(rcb_evidence_claim(&e), RCB_CLAIM_EXPLAINS);
  /* white, but how far above the declared noise: sqrt(phi) x its level,
   * noise of another level up to RCB_WHITE_LEVEL_MAX = 2 x (phi 4) */
  e.dispersion = 3.99, e.chi2 = 3.99 * 35000.0;
  assert_true(fabs(rcb_evidence_level(&e) - sqrt(3.99)) < 1e-12);
  assert_int_equal(rcb_evidence_claim(&e), RCB_CLAIM_EXPLAINS);
  e.dispersion = 4.01, e.chi2 = 4.01 * 35000.0;
  assert_int_equal(rcb_evidence_white_noise(&e), 0);
  assert_int_equal(rcb_evidence_adequate(&e), 0);
  assert_int_equal(rcb_evidence_claim(&e), RCB_CLAIM_IMPROVES);
  e.dispersion = 96721.0; /* the case study: 311 x the declared (its drop of 500 over
                             phi is no longer significant either) */
  assert_int_equal(rcb_evidence_adequate(&e), 0);
  assert_int_not_equal(rcb_evidence_claim(&e), RCB_CLAIM_EXPLAINS);
  e.dispersion = 0.0; /* none given: chi2 over the limit, 4.01 N / (N + 2.33 sqrt(2 N)) */
  assert_true(fabs(rcb_evidence_level(&e) - sqrt(e.chi2 / e.chi2_limit)) < 1e-12);
  assert_int_equal(rcb_evidence_claim(&e), RCB_CLAIM_EXPLAINS);
  e.dispersion = 1.0, e.chi2 = e.chi2_limit + 1.0;
  e.beyond = 1;
  assert_int_equal(rcb_evidence_claim(&e), RCB_CLAIM_IMPROVES);
  e.chi2_limit = (double)NAN; /* the noise unknown: adequacy unknown */
  assert_int_equal(rcb_evidence_adequate(&e), -1);
}

/* All the fields of issue #33 at 0: the rule of issue #23. */
static void test_issue23_rule(void **state) {
  rcb_evidence e;
  (void)state;
  memset(&e, 0, sizeof e);
  e.delta_bic = -10.5, e.error_before_pct = 6.0, e.error_after_pct = 5.0;
  e.chi2 = 100.0, e.chi2_limit = 120.0;
  assert_true(rcb_evidence_dbic(&e) == -10.5);
  assert_int_equal(rcb_evidence_claim(&e), RCB_CLAIM_EXPLAINS);
  e.delta_bic = -9.5;
  assert_int_equal(rcb_evidence_claim(&e), RCB_CLAIM_NONE);
  e.delta_bic = -50.0, e.chi2_limit = (double)NAN, e.error_after_pct = 5.9; /* < 2 % fall */
  assert_int_equal(rcb_evidence_claim(&e), RCB_CLAIM_NONE);
}

/* The log scales' bias of the declared noise: E log10(1 + b r), r uniform in
 * [-1, 1], by a midpoint rule of 2e5 points. */
static void test_log_bias(void **state) {
  rcb_model *m = rcb_test_model_from_example("paper_system.ini");
  const char *outs[] = {"C.A.x"}, *ins[] = {"DA.x"};
  rcb_meas *ms = rcb_test_frf_meas(m, outs, 1, ins, 1, 200, 400, 11, 10000, RCB_INERTANCE);
  rcb_fit *f = NULL;
  const double b = 0.3;
  double sum = 0.0;
  int i, n = 200000;
  (void)state;
  for (i = 0; i < n; i++) sum += log10(1.0 + b * (-1.0 + 2.0 * (i + 0.5) / n));
  assert_int_equal(rcb_fit_create(&f, m, ms, NULL), RCB_OK);
  assert_int_equal(rcb_fit_set_noise_model(f, 100.0 * b, 1.0), RCB_OK);
  assert_true(rcb_fit_log_bias(f) == 0.0); /* the linear scale: none */
  assert_int_equal(rcb_fit_set_scale(f, RCB_SCALE_LOG10), RCB_OK);
  assert_true(fabs(rcb_fit_log_bias(f) - sum / n) < 1e-9);
  assert_int_equal(rcb_fit_set_scale(f, RCB_SCALE_DB), RCB_OK);
  assert_true(fabs(rcb_fit_log_bias(f) - 20.0 * sum / n) < 2e-8);
  rcb_fit_destroy(f);
  rcb_meas_destroy(ms);
  rcb_model_destroy(m);
}

/* A noise reference equal to the measured values weighs, gates and levels
 * every point as the measured values do: the same residuals, bit for bit;
 * and the predictions are the model's values (linear scale, no noise
 * model: residual = model - measured). */
static void test_reference_identity(void **state) {
  rcb_model *m = rcb_test_model_from_example("paper_system.ini");
  const char *outs[] = {"C.A.x", "C.B.y", "DB.x"}, *ins[] = {"DA.x"};
  rcb_meas *ms = rcb_test_frf_meas(m, outs, 3, ins, 1, 100, 500, 201, 10000, RCB_INERTANCE);
  rcb_fit *f = NULL;
  rcb_complex *h = calloc(3 * 201, sizeof *h), *e = calloc(3 * 201, sizeof *e);
  double *r0, *r1;
  size_t c, i, n0, j;
  int sc;
  (void)state;
  assert_int_equal(rcb_meas_add_noise(ms, 10.0, 1.0, 3u), RCB_OK);
  for (c = 0; c < 3; c++) {
    rcb_meas_channel_info ci;
    rcb_meas_channel(ms, c, &ci);
    memcpy(e + c * 201, ci.data, 201 * sizeof *e);
  }
  assert_int_equal(rcb_fit_create(&f, m, ms, NULL), RCB_OK);
  assert_int_equal(rcb_fit_add_param(f, "coupling.C.kt", 1e3, 1e6, 1), RCB_OK);
  /* predictions = measured + residual on the linear scale, unit weights */
  assert_int_equal(rcb_fit_set_scale(f, RCB_SCALE_COMPLEX), RCB_OK);
  n0 = rcb_fit_residual_count(f);
  r0 = calloc(n0, sizeof *r0);
  assert_int_equal(rcb_fit_residuals(f, r0), RCB_OK);
  assert_int_equal(rcb_fit_predictions(f, h), RCB_OK);
  for (j = 0; j < n0; j += 2) {
    size_t p = j / 2; /* every point used, channel-major */
    assert_true(fabs(creal(h[p]) - creal(e[p]) - r0[j]) <= 1e-12 * cabs(h[p]));
    assert_true(fabs(cimag(h[p]) - cimag(e[p]) - r0[j + 1]) <= 1e-12 * cabs(h[p]));
  }
  free(r0);
  for (sc = 0; sc < 2; sc++) {
    assert_int_equal(rcb_fit_set_scale(f, sc ? RCB_SCALE_LOG10 : RCB_SCALE_COMPLEX), RCB_OK);
    assert_int_equal(rcb_fit_set_noise_model(f, 10.0, 1.0), RCB_OK);
    assert_int_equal(rcb_fit_set_noise_reference(f, NULL), RCB_OK);
    n0 = rcb_fit_residual_count(f);
    r0 = calloc(n0, sizeof *r0), r1 = calloc(n0, sizeof *r1);
    assert_int_equal(rcb_fit_residuals(f, r0), RCB_OK);
    assert_int_equal(rcb_fit_set_noise_reference(f, e), RCB_OK);
    assert_int_equal(rcb_fit_residual_count(f), n0);
    assert_int_equal(rcb_fit_residuals(f, r1), RCB_OK);
    for (i = 0; i < n0; i++) assert_true(r0[i] == r1[i]);
    free(r0), free(r1);
  }
  /* within a band: a reference with no value out of it (the predictions' NaN
   * there) levels each channel as the measured values do (the eq. 19 level
   * takes the measured values where the reference has none): the same
   * residuals again (issue #33: a NaN level made F NaN with --band) */
  assert_int_equal(rcb_fit_set_scale(f, RCB_SCALE_LOG10), RCB_OK);
  assert_int_equal(rcb_fit_set_band(f, 2 * RCB_PI * 200.0, 2 * RCB_PI * 400.0), RCB_OK);
  assert_int_equal(rcb_fit_set_noise_reference(f, NULL), RCB_OK);
  n0 = rcb_fit_residual_count(f);
  r0 = calloc(n0, sizeof *r0), r1 = calloc(n0, sizeof *r1);
  assert_int_equal(rcb_fit_residuals(f, r0), RCB_OK);
  {
    rcb_complex *hb = calloc(3 * 201, sizeof *hb);
    const double *grid = rcb_meas_grid(ms);
    for (c = 0; c < 3; c++)
      for (i = 0; i < 201; i++) {
        double w = grid[i];
        hb[c * 201 + i] = w < 2 * RCB_PI * 199.0 || w > 2 * RCB_PI * 401.0 ? CMPLX(NAN, NAN)
                                                                         : e[c * 201 + i];
      }
    assert_int_equal(rcb_fit_set_noise_reference(f, hb), RCB_OK);
    free(hb);
  }
  assert_int_equal(rcb_fit_residual_count(f), n0);
  assert_int_equal(rcb_fit_residuals(f, r1), RCB_OK);
  for (i = 0; i < n0; i++) assert_true(r0[i] == r1[i]);
  free(r0), free(r1);
  assert_int_equal(rcb_fit_set_band(f, 0.0, HUGE_VAL), RCB_OK);
  assert_int_equal(rcb_fit_set_scale(f, RCB_SCALE_COMPLEX), RCB_OK);
  assert_int_equal(rcb_fit_set_noise_reference(f, e), RCB_OK);
  n0 = rcb_fit_residual_count(f);
  /* a reference with a hole drops that point */
  e[5] = CMPLX(NAN, 0.0);
  assert_int_equal(rcb_fit_set_noise_reference(f, e), RCB_OK);
  assert_int_equal(rcb_fit_residual_count(f), n0 - 2); /* Re and Im */
  assert_int_equal(rcb_fit_set_noise_phase(f, -1.0), RCB_ERR_ARG);
  free(h), free(e);
  rcb_fit_destroy(f);
  rcb_meas_destroy(ms);
  rcb_model_destroy(m);
}

/* The adequacy test at the true model on the complex scale, data with a
 * phase noise of +-5 deg (rcb_meas_add_noise_phase): declared with its
 * phase term F is within its limit and the residual white; declared
 * without it F is far above (68 x its expectation: where one part of a
 * strong value is near 0 its declared variance is tiny, and the turn moves
 * it by |H| theta); a wrong kt (a smooth misfit) is not white. */
static void test_phase_term_white(void **state) {
  rcb_model *m = rcb_test_model_from_example("paper_system.ini");
  const char *outs[] = {"DA.x", "DA.y", "C.A.x", "C.A.y", "C.B.x", "C.B.y", "DB.x", "DB.y"};
  const char *ins[] = {"DA.x"};
  rcb_meas *ms = rcb_test_frf_meas(m, outs, 8, ins, 1, 100, 400, 301, 10000, RCB_INERTANCE);
  rcb_fit *f = NULL;
  rcb_fit_adequacy a0, a1, a2;
  double kt;
  (void)state;
  assert_int_equal(rcb_meas_add_noise_phase(ms, 10.0, 1.0, 5.0 * RCB_PI / 180.0, 11u), RCB_OK);
  assert_int_equal(rcb_fit_create(&f, m, ms, NULL), RCB_OK);
  assert_int_equal(rcb_fit_set_scale(f, RCB_SCALE_COMPLEX), RCB_OK);
  assert_int_equal(rcb_fit_set_noise_model(f, 10.0, 1.0), RCB_OK);
  assert_int_equal(rcb_fit_get_adequacy(f, &a0, NULL, NULL, NULL), RCB_OK);
  assert_int_equal(rcb_fit_set_noise_phase(f, 5.0 * RCB_PI / 180.0), RCB_OK);
  assert_int_equal(rcb_fit_get_adequacy(f, &a1, NULL, NULL, NULL), RCB_OK);
  print_message("phase noise +-5 deg: F/E %.4f undeclared (z %.1f, white %.2f), %.4f "
                "declared (z %.1f, white %.2f)\n", a0.dispersion,
                (a0.chi2 - a0.expected) / a0.sd, a0.white_z, a1.dispersion,
                (a1.chi2 - a1.expected) / a1.sd, a1.white_z);
  assert_false(a0.adequate);
  assert_true(a1.adequate);
  assert_true(a1.white);
  assert_int_equal(rcb_model_get_param(m, "coupling.C.kt", &kt), RCB_OK);
  assert_int_equal(rcb_model_set_param(m, "coupling.C.kt", 0.8 * kt), RCB_OK);
  assert_int_equal(rcb_fit_get_adequacy(f, &a2, NULL, NULL, NULL), RCB_OK);
  print_message("kt 0.8 x: F/E %.3f, white %.1f\n", a2.dispersion, a2.white_z);
  assert_false(a2.adequate);
  assert_false(a2.white);
  rcb_fit_destroy(f);
  rcb_meas_destroy(ms);
  rcb_model_destroy(m);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_dispersion),          cmocka_unit_test(test_multiplicity),
      cmocka_unit_test(test_adequate_white_beyond), cmocka_unit_test(test_issue23_rule),
      cmocka_unit_test(test_log_bias),            cmocka_unit_test(test_reference_identity),
      cmocka_unit_test(test_phase_term_white),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
