/*
 * Identification: sensitivities and the paper's algorithm.
 *  - analytic sensitivities (eq. 9, -H dZ/dp H) agree with extrapolated
 *    central differences of the residuals to 1e-6, and with the paper's forward
 *    differences (eq. 11) to their truncation error, for FRFs (every scale,
 *    every kind) and unbalance responses (including an unbalance phase), and
 *    for the per-element factors shaft.S.e<k>.stiffness | mass on every path
 *    (adjoint, direct re-solve, the diagnosis' batched dZ columns);
 *  - on noise-free synthetic data the paper's algorithm recovers the four
 *    coupling parameters of the paper system from 1/10 of the true values;
 *  - with eq. 19 noise over 20 seeds it reaches the noise floor every time,
 *    with honest standard errors, and flags cR as not identifiable;
 *  - a fit that stays above the noise floor (a missing effect, or a local
 *    minimum of a local NLopt method) is reported as unsure, and restarts
 *    from random starts within the bounds reach the floor; the random
 *    starts run alone (rcb_fit_set_first_start) are those of a whole run;
 *  - bad settings give clear errors.
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
#include "identify/identify.h" /* the batched dZ columns (the internal interface) */
#include "rcb/rcb_config.h"
#include "rcb_test_util.h"

#define RPM (RCB_PI / 30.0)
#define TWO_PI (2.0 * RCB_PI)

/* Central difference of the residuals along parameter name, step h. */
static void central(rcb_model *m, rcb_fit *f, const char *name, double p, double h, size_t n,
                    double *d, double *rp, double *rm) {
  size_t j;
  assert_int_equal(rcb_model_set_param(m, name, p + h), RCB_OK);
  assert_int_equal(rcb_fit_residuals(f, rp), RCB_OK);
  assert_int_equal(rcb_model_set_param(m, name, p - h), RCB_OK);
  assert_int_equal(rcb_fit_residuals(f, rm), RCB_OK);
  assert_int_equal(rcb_model_set_param(m, name, p), RCB_OK);
  for (j = 0; j < n; j++) d[j] = (rp[j] - rm[j]) / (2 * h);
}

/* Compare the analytic Jacobian with Richardson-extrapolated central
 * differences of the residuals (steps 1e-3 and 5e-4 relative: truncation
 * O(h^4)) and with the paper's forward differences (eq. 11). */
static void check_jacobian(rcb_model *m, rcb_fit *f, const char *const *names, size_t np) {
  size_t n = rcb_fit_residual_count(f), k, j;
  double *Ja = calloc(n * np, sizeof *Ja), *Jf = calloc(n * np, sizeof *Jf);
  double *rp = calloc(n, sizeof *rp), *rm = calloc(n, sizeof *rm);
  double *d1 = calloc(n, sizeof *d1), *d2 = calloc(n, sizeof *d2);
  assert_true(n > 0);
  assert_int_equal(rcb_fit_jacobian(f, 1, Ja), RCB_OK);
  assert_int_equal(rcb_fit_jacobian(f, 0, Jf), RCB_OK);
  for (k = 0; k < np; k++) {
    double p, h, na = 0, dc = 0, df = 0;
    assert_int_equal(rcb_model_get_param(m, names[k], &p), RCB_OK);
    /* cR changes H by ~1e-4 of itself over its whole value: a small step
     * drowns in the solver's round-off, and H is linear in it to that level */
    h = p != 0.0 ? (strstr(names[k], ".cr") ? 0.1 : 1e-3) * fabs(p) : 1e-6;
    central(m, f, names[k], p, h, n, d1, rp, rm);
    central(m, f, names[k], p, h / 2, n, d2, rp, rm);
    for (j = 0; j < n; j++) {
      double c = (4 * d2[j] - d1[j]) / 3, a = Ja[j + n * k];
      na += a * a;
      dc += (a - c) * (a - c);
      df += (a - Jf[j + n * k]) * (a - Jf[j + n * k]);
    }
    if (!(na > 0) || sqrt(dc / na) > 1e-6 || sqrt(df / na) > 2e-2)
      fail_msg("%s: |J| = %g, central-difference mismatch %g, eq. 11 mismatch %g", names[k],
               sqrt(na), sqrt(dc / na), sqrt(df / na));
  }
  free(Ja);
  free(Jf);
  free(rp);
  free(rm);
  free(d1);
  free(d2);
}

static void test_sensitivities_frf(void **state) {
  rcb_model *m = rcb_test_model_from_example("paper_system.ini");
  const char *outs[] = {"C.A.x", "C.B.y", "DB.x"}, *ins[] = {"DA.x", "C.B.x"};
  const char *names[] = {"coupling.C.kt", "coupling.C.kr", "coupling.C.ct", "coupling.C.cr",
                         "bearing.B2.kxx", "disk.DA.mass", "shaft.B.damping_stiffness"};
  rcb_meas *ms = rcb_test_frf_meas(m, outs, 3, ins, 2, 120, 400, 15, 10000, RCB_INERTANCE);
  rcb_fit *f = NULL;
  size_t k;
  int sc;
  (void)state;
  for (sc = 0; sc < 4; sc++) {
    assert_int_equal(rcb_fit_create(&f, m, ms, NULL), RCB_OK);
    for (k = 0; k < 7; k++) {
      double p;
      assert_int_equal(rcb_model_get_param(m, names[k], &p), RCB_OK);
      assert_int_equal(rcb_fit_add_param(f, names[k], 0.0, 10 * p + 1, 0), RCB_OK);
    }
    assert_int_equal(rcb_fit_set_scale(f, (rcb_fit_scale)sc), RCB_OK);
    check_jacobian(m, f, names, 7);
    rcb_fit_destroy(f);
  }
  rcb_meas_destroy(ms);
  rcb_model_destroy(m);
}

static void test_sensitivities_unbalance(void **state) {
  rcb_model *m = rcb_test_model_from_example("paper_system.ini");
  const char *outs[] = {"C.A.x", "C.A.y", "C.B.x", "C.B.y"};
  const char *names[] = {"coupling.C.kt", "coupling.C.kr", "coupling.C.ct",
                         "unbalance.UB.phase", "unbalance.UA.amount"};
  rcb_meas *ms = rcb_test_unbalance_meas(m, outs, 4, 300, 18300, 25);
  rcb_fit *f = NULL;
  size_t k;
  (void)state;
  assert_int_equal(rcb_fit_create(&f, m, ms, NULL), RCB_OK);
  for (k = 0; k < 5; k++) {
    double p;
    assert_int_equal(rcb_model_get_param(m, names[k], &p), RCB_OK);
    assert_int_equal(rcb_fit_add_param(f, names[k], -10.0, 10 * p + 1, 0), RCB_OK);
  }
  assert_int_equal(rcb_fit_set_scale(f, RCB_SCALE_COMPLEX), RCB_OK);
  check_jacobian(m, f, names, 5);
  rcb_fit_destroy(f);
  rcb_meas_destroy(ms);
  rcb_model_destroy(m);
}

/* The per-element factors (issue #23) on every path of the sensitivities:
 * the analytic Jacobian (by the adjoint with several parameters, by the
 * direct re-solve with one) and the batched columns of the diagnosis'
 * score test (rcb_fit_dz_get, rcb_fit_jacobian_dz), each against
 * extrapolated central differences of the residuals to 1e-6. */
static void factor_sensitivities(const char *const names[4], int one_element) {
  rcb_model *m = rcb_test_model_from_example("paper_system.ini");
  const char *outs[] = {"C.A.x", "C.B.y", "DB.x"}, *ins[] = {"DA.x", "C.B.x"};
  rcb_meas *ms = rcb_test_frf_meas(m, outs, 3, ins, 2, 120, 400, 15, 10000, RCB_INERTANCE);
  rcb_fit *f = NULL, *fc = NULL;
  rcb_fit_dz dz[2];
  rcb_allocator a;
  size_t n, k, j;
  double *J, *rp, *rm, *d1, *d2;
  int sc;
  for (sc = 0; sc < 4; sc++) { /* all four: the adjoint; one: the direct re-solve */
    size_t np = sc == 3 ? 1 : 4;
    assert_int_equal(rcb_fit_create(&f, m, ms, NULL), RCB_OK);
    for (k = 0; k < np; k++)
      assert_int_equal(rcb_fit_add_param(f, names[k], 0.01, 1e9, 0), RCB_OK);
    assert_int_equal(rcb_fit_set_scale(f, (rcb_fit_scale)sc), RCB_OK);
    check_jacobian(m, f, names, np);
    rcb_fit_destroy(f);
  }
  /* batched: the base fit has coupling.C.kt, the candidate's columns come
   * from the dZ of a fit of the element's (the shaft's) two factors */
  rcb_allocator_init(&a, NULL);
  assert_int_equal(rcb_fit_create(&f, m, ms, NULL), RCB_OK);
  assert_int_equal(rcb_fit_add_param(f, names[3], 0.0, 1e9, 0), RCB_OK);
  assert_int_equal(rcb_fit_set_scale(f, RCB_SCALE_LOG10), RCB_OK);
  assert_int_equal(rcb_fit_create(&fc, m, ms, NULL), RCB_OK);
  for (k = 0; k < 2; k++) assert_int_equal(rcb_fit_add_param(fc, names[k], 0.01, 10, 0), RCB_OK);
  assert_int_equal(rcb_fit_dz_get(fc, &a, dz), RCB_OK);
  assert_int_equal(rcb_fit_prepare(f), RCB_OK);
  n = rcb_fit_residual_count(f);
  J = calloc(2 * n, sizeof *J);
  rp = calloc(n, sizeof *rp), rm = calloc(n, sizeof *rm);
  d1 = calloc(n, sizeof *d1), d2 = calloc(n, sizeof *d2);
  assert_true(J && rp && rm && d1 && d2 && n > 0);
  /* one element's 8 x 8 block, or every element of the shaft */
  assert_true(dz[0].ne > 0 && (dz[0].ne <= 64) == one_element && !dz[0].dF);
  assert_int_equal(rcb_fit_jacobian_dz(f, dz, 2, J), RCB_OK);
  for (k = 0; k < 2; k++) {
    double na = 0, dc = 0;
    central(m, f, names[k], 1.0, 1e-3, n, d1, rp, rm);
    central(m, f, names[k], 1.0, 5e-4, n, d2, rp, rm);
    for (j = 0; j < n; j++) {
      double c = (4 * d2[j] - d1[j]) / 3, v = J[j + n * k];
      na += v * v;
      dc += (v - c) * (v - c);
    }
    print_message("  %-22s batched dZ vs central differences %.2e\n", names[k], sqrt(dc / na));
    if (!(na > 0) || sqrt(dc / na) > 1e-6)
      fail_msg("%s batched: |J| = %g, mismatch %g", names[k], sqrt(na), sqrt(dc / na));
  }
  /* the prepared sweep of the monitor's joint step (rcb_fit_adj): by the
   * direct re-solve with one parameter (1 x 2 inputs < 3 outputs), by the
   * adjoint with both; the same columns as the batched adjoint's above */
  for (k = 1; k <= 2; k++) {
    rcb_fit_adj *adj = NULL;
    double *Ja = calloc(k * n, sizeof *Ja), na = 0, dd = 0;
    assert_non_null(Ja);
    assert_int_equal(rcb_fit_adj_create(f, dz, k, &adj), RCB_OK);
    assert_int_equal(rcb_fit_adj_run(f, adj, Ja), RCB_OK);
    for (j = 0; j < k * n; j++) na += J[j] * J[j], dd += (Ja[j] - J[j]) * (Ja[j] - J[j]);
    print_message("  rcb_fit_adj, %zu parameter(s) vs the batched adjoint %.2e\n", k, sqrt(dd / na));
    if (!(na > 0) || sqrt(dd / na) > 1e-10) fail_msg("rcb_fit_adj (%zu): mismatch %g", k, sqrt(dd / na));
    rcb_fit_adj_destroy(f, adj);
    free(Ja);
  }
  rcb_fit_dz_free(&a, dz, 2);
  free(J), free(rp), free(rm), free(d1), free(d2);
  rcb_fit_destroy(fc);
  rcb_fit_destroy(f);
  rcb_meas_destroy(ms);
  rcb_model_destroy(m);
}

static void test_sensitivities_element(void **state) {
  static const char *const names[4] = {"shaft.B.e3.stiffness", "shaft.B.e3.mass",
                                       "shaft.A.e7.stiffness", "coupling.C.kt"};
  (void)state;
  factor_sensitivities(names, 1);
}

/* The shaft-wide factors (issue #33): the same paths. */
static void test_sensitivities_shaft_factors(void **state) {
  static const char *const names[4] = {"shaft.B.stiffness", "shaft.B.mass", "shaft.A.stiffness",
                                       "coupling.C.kt"};
  (void)state;
  factor_sensitivities(names, 0);
}

/* Noise-free FRF data of the paper system (inertances at the coupling, force
 * at disk A, 200-400 Hz at 10000 rpm): from 1/10 of kt, kr, ct, cr the
 * paper's algorithm returns all four (without noise even cR is determined). */
static void test_paper_fit_noise_free(void **state) {
  rcb_model *truth = rcb_test_model_from_example("paper_system.ini");
  rcb_model *m = rcb_test_model_from_example("paper_system.ini");
  const char *outs[] = {"C.A.x", "C.A.y", "C.B.x", "C.B.y"}, *ins[] = {"DA.x"};
  const char *names[] = {"coupling.C.kt", "coupling.C.kr", "coupling.C.ct", "coupling.C.cr"};
  rcb_meas *ms = rcb_test_frf_meas(truth, outs, 4, ins, 1, 200, 400, 201, 10000, RCB_INERTANCE);
  rcb_fit *f = NULL;
  rcb_fit_report rep;
  double tv[4];
  size_t k;
  (void)state;
  assert_int_equal(rcb_fit_create(&f, m, ms, NULL), RCB_OK);
  for (k = 0; k < 4; k++) {
    assert_int_equal(rcb_model_get_param(truth, names[k], &tv[k]), RCB_OK);
    assert_int_equal(rcb_model_set_param(m, names[k], tv[k] / 10), RCB_OK);
    assert_int_equal(rcb_fit_add_param(f, names[k], tv[k] / 1000, tv[k] * 100, 1), RCB_OK);
  }
  assert_int_equal(rcb_fit_set_scale(f, RCB_SCALE_LOG10), RCB_OK);
  if (rcb_fit_run(f)) fail_msg("%s", rcb_fit_errmsg(f));
  assert_int_equal(rcb_fit_get_report(f, &rep), RCB_OK);
  print_message("paper method: %zu iterations, %zu evaluations, error %.3g %% -> %.3g %%\n",
                rep.iterations, rep.evaluations, rep.error0_pct, rep.error_pct);
  for (k = 0; k < 4; k++) {
    rcb_fit_param p;
    assert_int_equal(rcb_fit_get_param(f, k, &p), RCB_OK);
    print_message("  %-16s %.6g (true %.6g) se %.3g identifiable %d\n", p.name, p.value, tv[k],
                  p.stderr_, p.identifiable);
    assert_true(rcb_test_close(p.value, tv[k], k < 3 ? 1e-6 : 1e-4, 0));
  }
  assert_true(rep.error_pct < 1e-4);
  assert_true(rep.error0_pct > 10);
  rcb_fit_destroy(f);
  rcb_meas_destroy(ms);
  rcb_model_destroy(m);
  rcb_model_destroy(truth);
}

/* Eq. 19 noise (10 %, 1 %), 20 seeds, start at 1/10 (Table 3 set-up with
 * 101 points): every seed reaches the noise floor (an objective no worse than
 * the true model's on the same noisy data, and an error % within 5 % of the
 * truth's), every fitted kt, kr, ct lies within 4.5 of its
 * standard errors of the truth (the uncertainty is honest to within what the
 * log scale's weights at the measured values allow: over these 20 seeds the
 * error over the standard error has mean +0.16 / +0.02 / +0.22 and sd
 * 1.00 / 0.89 / 1.25 for kt / kr / ct, measured with the log scale's bias
 * taken off (issue #33; +0.35 mean for ct without), so ct's largest of 20,
 * 4.03 at seed 10, is its 1-in-20 tail, not a bias), and cR is flagged as
 * not identifiable. */
static void test_paper_fit_noisy_seeds(void **state) {
  rcb_model *truth = rcb_test_model_from_example("paper_system.ini");
  const char *outs[] = {"C.A.x", "C.A.y", "C.B.x", "C.B.y"}, *ins[] = {"DA.x"};
  const char *names[] = {"coupling.C.kt", "coupling.C.kr", "coupling.C.ct", "coupling.C.cr"};
  double tv[4];
  unsigned seed;
  size_t k, evals = 0;
  (void)state;
  for (k = 0; k < 4; k++) assert_int_equal(rcb_model_get_param(truth, names[k], &tv[k]), 0);
  for (seed = 0; seed < 20; seed++) {
    rcb_meas *ms = rcb_test_frf_meas(truth, outs, 4, ins, 1, 200, 400, 101, 10000, RCB_INERTANCE);
    rcb_model *m = rcb_test_model_from_example("paper_system.ini");
    rcb_fit *f = NULL, *ft = NULL;
    rcb_fit_report rep;
    double floor_pct, Ftrue = 0.0, *r;
    size_t j, nr;
    assert_int_equal(rcb_meas_add_noise(ms, 10.0, 1.0, 77u + seed), RCB_OK);
    assert_int_equal(rcb_fit_create(&ft, truth, ms, NULL), RCB_OK);
    assert_int_equal(rcb_fit_create(&f, m, ms, NULL), RCB_OK);
    for (k = 0; k < 4; k++) {
      assert_int_equal(rcb_model_set_param(m, names[k], tv[k] / 10), RCB_OK);
      assert_int_equal(rcb_fit_add_param(f, names[k], tv[k] / 1000, tv[k] * 1000, 1), RCB_OK);
    }
    assert_int_equal(rcb_fit_set_scale(f, RCB_SCALE_LOG10), RCB_OK);
    assert_int_equal(rcb_fit_set_noise_model(f, 10.0, 1.0), RCB_OK);
    assert_int_equal(rcb_fit_set_scale(ft, RCB_SCALE_LOG10), RCB_OK);
    assert_int_equal(rcb_fit_set_noise_model(ft, 10.0, 1.0), RCB_OK);
    assert_int_equal(rcb_fit_error(ft, &floor_pct), RCB_OK);
    nr = rcb_fit_residual_count(ft);
    r = calloc(nr, sizeof *r);
    assert_int_equal(rcb_fit_residuals(ft, r), RCB_OK);
    for (j = 0; j < nr; j++) Ftrue += r[j] * r[j];
    free(r);
    if (rcb_fit_run(f)) fail_msg("seed %u: %s", seed, rcb_fit_errmsg(f));
    assert_int_equal(rcb_fit_get_report(f, &rep), RCB_OK);
    evals += rep.evaluations;
    /* the truth is a feasible point: a global minimum is at least as good */
    if (rep.objective > Ftrue * (1 + 1e-9) || rep.error_pct > 1.05 * floor_pct)
      fail_msg("seed %u: objective %g vs %g at the truth; error %g %% vs floor %g %%", seed,
               rep.objective, Ftrue, rep.error_pct, floor_pct);
    for (k = 0; k < 4; k++) {
      rcb_fit_param p;
      assert_int_equal(rcb_fit_get_param(f, k, &p), RCB_OK);
      if (k == 3) {
        assert_false(p.identifiable);
        continue;
      }
      assert_true(p.identifiable);
      if (fabs(p.value - tv[k]) > 4.5 * p.stderr_)
        fail_msg("seed %u %s: %g, true %g, se %g", seed, p.name, p.value, tv[k], p.stderr_);
    }
    rcb_fit_destroy(f);
    rcb_fit_destroy(ft);
    rcb_meas_destroy(ms);
    rcb_model_destroy(m);
  }
  print_message("20 noisy seeds: %.1f model evaluations per fit on average\n",
                (double)evals / 20.0);
  rcb_model_destroy(truth);
}

/* One noisy Table 3 data set and a start model at 1/10 of kt, kr, ct, cr
 * (coupling model 'model': the truth is nelson_crandall_2). */
static rcb_fit *noisy_setup(rcb_model **mp, rcb_meas **msp, const char *model) {
  rcb_model *truth = rcb_test_model_from_example("paper_system.ini"), *m;
  const char *outs[] = {"C.A.x", "C.A.y", "C.B.x", "C.B.y"}, *ins[] = {"DA.x"};
  const char *names[] = {"coupling.C.kt", "coupling.C.kr", "coupling.C.ct", "coupling.C.cr"};
  rcb_fit *f = NULL;
  size_t k, np = strcmp(model, "nelson_crandall_1") == 0 ? 2 : 4;
  char ini[4096];
  *msp = rcb_test_frf_meas(truth, outs, 4, ins, 1, 200, 400, 101, 10000, RCB_INERTANCE);
  assert_int_equal(rcb_meas_add_noise(*msp, 10.0, 1.0, 5u), RCB_OK);
  snprintf(ini, sizeof ini,
           "[material steel]\ndensity = 7759.255\nyoung = 1.936e11\npoisson = 0.3\n"
           "[shaft A]\nmaterial = steel\nshear_factor = 0.9\ndamping_mass = 15.691\n"
           "damping_stiffness = 22.989e-6\nsegment = 0.5 0.017 0 10\n"
           "[shaft B]\nmaterial = steel\nstart = 0.52\nshear_factor = 0.9\n"
           "damping_mass = 15.691\ndamping_stiffness = 22.989e-6\nsegment = 0.5 0.017 0 10\n"
           "[bearing B1]\nat = A 0.05\nkxx = 5e7\nkyy = 7e7\ncxx = 500\ncyy = 700\n"
           "[bearing B2]\nat = A 0.35\nkxx = 7e7\nkyy = 9e7\ncxx = 300\ncyy = 500\n"
           "[bearing B3]\nat = B 0.67\nkxx = 5e7\nkyy = 7e7\ncxx = 500\ncyy = 700\n"
           "[bearing B4]\nat = B 0.97\nkxx = 7e7\nkyy = 9e7\ncxx = 300\ncyy = 500\n"
           "[disk DA]\nat = A 0.2\ndensity = 6303.235\nouter_diameter = 0.09\n"
           "inner_diameter = 0.017\nwidth = 0.025\n"
           "[disk DB]\nat = B 0.82\ndensity = 6303.235\nouter_diameter = 0.09\n"
           "inner_diameter = 0.017\nwidth = 0.025\n"
           "[coupling C]\nmodel = %s\nbetween = A end, B start\nkt = 4609.5\nkr = 22.076\n"
           "%shub_density = 2758.219\nhub_inner_radius = 0.006\nhub_outer_radius = 0.017\n"
           "hub_thickness = 0.043115\n",
           model, np == 4 ? "ct = 1.0949\ncr = 1.0949e-6\n" : "");
  m = rcb_test_model_from_string(ini);
  assert_int_equal(rcb_fit_create(&f, m, *msp, NULL), RCB_OK);
  for (k = 0; k < np; k++) {
    double v;
    assert_int_equal(rcb_model_get_param(truth, names[k], &v), RCB_OK);
    assert_int_equal(rcb_fit_add_param(f, names[k], v / 1000, v * 1000, 1), RCB_OK);
  }
  assert_int_equal(rcb_fit_set_scale(f, RCB_SCALE_LOG10), RCB_OK);
  assert_int_equal(rcb_fit_set_noise_model(f, 10.0, 1.0), RCB_OK);
  rcb_model_destroy(truth);
  *mp = m;
  return f;
}

/* A model without the coupling damping cannot reach the noise floor of data
 * that has it: the fit says it is unsure instead of reporting success. */
static void test_unsure_missing_effect(void **state) {
  rcb_model *m;
  rcb_meas *ms;
  rcb_fit *f = noisy_setup(&m, &ms, "nelson_crandall_1");
  rcb_fit_report rep;
  (void)state;
  if (rcb_fit_run(f)) fail_msg("%s", rcb_fit_errmsg(f));
  assert_int_equal(rcb_fit_get_report(f, &rep), RCB_OK);
  /* eq. 19 with beta_a = 10 %: uniform noise, floor 10/sqrt(3) = 5.8 % */
  assert_true(rep.floor_pct > 5.0 && rep.floor_pct < 6.5);
  assert_true(rep.error_pct > 2 * rep.floor_pct);
  assert_int_equal(rep.unsure, 1);
  rcb_fit_destroy(f);
  rcb_meas_destroy(ms);
  rcb_model_destroy(m);
}

/* The complex objective from 1/10 (continuation through log magnitudes):
 * at the noise floor, and the phase sharpens the estimates (smaller standard
 * errors than on magnitudes), each within 4 of them of the truth. */
static void test_complex_continuation(void **state) {
  const double tv[3] = {46095, 220.76, 10.949};
  rcb_fit_report rep[2];
  double se[2][3];
  int sc;
  size_t k;
  (void)state;
  for (sc = 0; sc < 2; sc++) {
    rcb_model *m;
    rcb_meas *ms;
    rcb_fit *f = noisy_setup(&m, &ms, "nelson_crandall_2");
    assert_int_equal(rcb_fit_set_scale(f, sc ? RCB_SCALE_COMPLEX : RCB_SCALE_LOG10), RCB_OK);
    if (rcb_fit_run(f)) fail_msg("%s", rcb_fit_errmsg(f));
    assert_int_equal(rcb_fit_get_report(f, &rep[sc]), RCB_OK);
    for (k = 0; k < 3; k++) {
      rcb_fit_param p;
      assert_int_equal(rcb_fit_get_param(f, k, &p), RCB_OK);
      se[sc][k] = p.stderr_;
      if (fabs(p.value - tv[k]) > 4 * p.stderr_)
        fail_msg("scale %d %s: %g, true %g, se %g", sc, p.name, p.value, tv[k], p.stderr_);
    }
    rcb_fit_destroy(f);
    rcb_meas_destroy(ms);
    rcb_model_destroy(m);
  }
  assert_true(rep[1].error_pct < 1.05 * rep[1].floor_pct);
  assert_int_equal(rep[1].unsure, 0);
  for (k = 0; k < 3; k++) assert_true(se[1][k] < se[0][k]);
}

#if RCB_WITH_NLOPT
/* BOBYQA from 1/10 stops in a local minimum and says so; with restarts it
 * reaches the noise floor. */
static void test_multistart_local_minimum(void **state) {
  rcb_fit_report one, many;
  size_t n;
  (void)state;
  for (n = 1; n <= 8; n += 7) {
    rcb_model *m;
    rcb_meas *ms;
    rcb_fit *f = noisy_setup(&m, &ms, "nelson_crandall_2");
    assert_int_equal(rcb_fit_set_method(f, RCB_FIT_NLOPT, "bobyqa"), RCB_OK);
    assert_int_equal(rcb_fit_set_starts(f, n, 3), RCB_OK);
    if (rcb_fit_run(f)) fail_msg("%s", rcb_fit_errmsg(f));
    assert_int_equal(rcb_fit_get_report(f, n == 1 ? &one : &many), RCB_OK);
    rcb_fit_destroy(f);
    rcb_meas_destroy(ms);
    rcb_model_destroy(m);
  }
  print_message("bobyqa: 1 start error %.3g %% (unsure %d); %zu starts error %.3g %% "
                "(floor %.3g %%)\n",
                one.error_pct, one.unsure, many.starts, many.error_pct, many.floor_pct);
  assert_int_equal(one.unsure, 1);
  assert_true(one.error_pct > 2 * one.floor_pct);
  assert_int_equal(many.unsure, 0);
  assert_true(many.starts > 1);
  assert_true(many.error_pct < 1.05 * many.floor_pct);
}

/* rcb_fit_set_first_start(f, 1) tries the random starts alone, the same
 * points a run from the model's start tries after it: the best of a run
 * from the model's start alone and of one from the random starts alone is
 * the run of them all, to the bit, with the starts counted in two parts. */
static void test_random_starts_alone(void **state) {
  rcb_fit_report rep[3]; /* all 8 starts, the model's alone, the random ones alone */
  const size_t n[3] = {8, 1, 8}, first[3] = {0, 0, 1};
  double x[3][3];
  size_t r, k, alone;
  (void)state;
  for (r = 0; r < 3; r++) {
    rcb_model *m;
    rcb_meas *ms;
    rcb_fit *f = noisy_setup(&m, &ms, "nelson_crandall_2");
    assert_int_equal(rcb_fit_set_method(f, RCB_FIT_NLOPT, "bobyqa"), RCB_OK);
    assert_int_equal(rcb_fit_set_starts(f, n[r], 3), RCB_OK);
    assert_int_equal(rcb_fit_set_first_start(f, first[r]), RCB_OK);
    assert_int_equal(rcb_fit_get_first_start(f), first[r]);
    if (rcb_fit_run(f)) fail_msg("%s", rcb_fit_errmsg(f));
    assert_int_equal(rcb_fit_get_report(f, &rep[r]), RCB_OK);
    for (k = 0; k < 3; k++) {
      rcb_fit_param p;
      assert_int_equal(rcb_fit_get_param(f, k, &p), RCB_OK);
      x[r][k] = p.value;
    }
    rcb_fit_destroy(f);
    rcb_meas_destroy(ms);
    rcb_model_destroy(m);
  }
  print_message("all starts: F %.9g in %zu starts; model's alone %.9g; random alone %.9g in "
                "%zu\n",
                rep[0].objective, rep[0].starts, rep[1].objective, rep[2].objective,
                rep[2].starts);
  assert_int_equal(rep[1].unsure, 1); /* so the run of all goes on to the random ones */
  assert_int_equal(rep[0].starts, 1 + rep[2].starts);
  alone = rep[2].objective < rep[1].objective ? 2 : 1;
  assert_true(rep[0].objective == rep[alone].objective);
  assert_memory_equal(x[0], x[alone], sizeof x[0]);
}
#endif

/* The standard errors against replicas (issue #24): the paper system's
 * inertances at the coupling (4 x 101 lines, 200-400 Hz, 10000 rpm), eq. 19
 * noise of 30 % and 1 % (rcb_meas_add_noise, 40 seeds), kt, kr, ct fitted on
 * the complex scale with the noise model, from the truth. For each parameter:
 * its 95 % interval holds the truth in at least 34 of 40 replicas (the
 * binomial 1 % quantile of 95 %: P(X < 34) = 0.0034), and the mean of
 * (value - truth) / se is within 3 / sqrt(40) = 0.47 of zero (its sd is
 * 1 / sqrt(40)). With the weights at the measured values (before the
 * reweighting at the model, fit.c) the means were -1.15, +0.72 and -0.74 and
 * kt's interval held the truth in 22 of 30 (numpy draws of the same noise);
 * the bias grows with beta_a, hence 30 % here, so that 40 replicas see it.
 * (The ideal weighted least squares, weights at the true values, covers
 * 94.2, 95.1, 94.8 % here: 4000 linearised replicas.) */
static void test_interval_coverage_complex(void **state) {
  rcb_model *m = rcb_test_model_from_example("paper_system.ini");
  const char *outs[] = {"C.A.x", "C.A.y", "C.B.x", "C.B.y"}, *ins[] = {"DA.x"};
  const char *names[] = {"coupling.C.kt", "coupling.C.kr", "coupling.C.ct"};
  /* RCB_TEST_FAST=1 (the sanitizer build, tests/CMakeLists.txt): 4 replicas
   * for memory errors on the path, the coverage asserted in the builds without
   * sanitizers (40 took 15 s of the sanitizer stage) */
  const char *fast = getenv("RCB_TEST_FAST");
  const unsigned R = fast && fast[0] == '1' ? 4 : 40;
  double tv[3], zsum[3] = {0, 0, 0};
  unsigned cover[3] = {0, 0, 0}, seed;
  size_t k;
  (void)state;
  for (k = 0; k < 3; k++) assert_int_equal(rcb_model_get_param(m, names[k], &tv[k]), RCB_OK);
  for (seed = 0; seed < R; seed++) {
    rcb_meas *ms = rcb_test_frf_meas(m, outs, 4, ins, 1, 200, 400, 101, 10000, RCB_INERTANCE);
    rcb_fit *f = NULL;
    assert_int_equal(rcb_meas_add_noise(ms, 30.0, 1.0, 2400u + seed), RCB_OK);
    assert_int_equal(rcb_fit_create(&f, m, ms, NULL), RCB_OK);
    for (k = 0; k < 3; k++)
      assert_int_equal(rcb_fit_add_param(f, names[k], tv[k] / 100, tv[k] * 100, 1), RCB_OK);
    assert_int_equal(rcb_fit_set_scale(f, RCB_SCALE_COMPLEX), RCB_OK);
    assert_int_equal(rcb_fit_set_noise_model(f, 30.0, 1.0), RCB_OK);
    if (rcb_fit_run(f)) fail_msg("seed %u: %s", seed, rcb_fit_errmsg(f));
    for (k = 0; k < 3; k++) {
      rcb_fit_param p;
      assert_int_equal(rcb_fit_get_param(f, k, &p), RCB_OK);
      zsum[k] += (p.value - tv[k]) / p.stderr_;
      cover[k] += p.ci_lo <= tv[k] && tv[k] <= p.ci_hi;
      assert_int_equal(rcb_model_set_param(m, names[k], tv[k]), RCB_OK); /* the next start */
    }
    rcb_fit_destroy(f);
    rcb_meas_destroy(ms);
  }
  for (k = 0; k < 3; k++) {
    print_message("%s: 95 %% interval holds the truth in %u of %u, mean z %+.3f\n", names[k],
                  cover[k], R, zsum[k] / R);
    if (R < 40) continue; /* fast: no rate */
    assert_true(cover[k] >= 34);
    assert_true(fabs(zsum[k] / R) <= 3.0 / sqrt((double)R));
  }
  rcb_model_destroy(m);
}

/* The adequacy test's null distribution (issue #23) against the noise it
 * stands for: data = the model's FRFs with eq. 19 noise (rcb_meas_add_noise,
 * 60 seeds), the model itself evaluated (no parameter fitted): F's mean
 * within 4 standard errors of the predicted mean, its spread within 35 % of
 * the predicted sd (the sd of a sample sd of 60 is 9 %), and the 1 % test
 * rejecting at most 4 of 60 (binomial p = 0.01: P(X >= 5) = 3e-3). On the
 * log10 and the complex scales, whose squares are far from chi-square (uniform
 * r1: the variance of a square is 0.8, not 2). */
static void adequacy_null(rcb_fit_scale scale) {
  rcb_model *m = rcb_test_model_from_example("paper_system.ini");
  const char *outs[] = {"DA.x", "C.A.y", "C.B.x", "DB.y"}, *ins[] = {"DA.x"};
  double sum = 0.0, sum2 = 0.0, expected = 0.0, sd = 0.0;
  size_t seed, rejected = 0, nseed = 60;
  for (seed = 1; seed <= nseed; seed++) {
    rcb_meas *ms = rcb_test_frf_meas(m, outs, 4, ins, 1, 100, 400, 151, 10000, RCB_INERTANCE);
    rcb_fit *f = NULL;
    rcb_fit_adequacy a;
    assert_int_equal(rcb_meas_add_noise(ms, 10.0, 1.0, 1000u + seed), RCB_OK);
    assert_int_equal(rcb_fit_create(&f, m, ms, NULL), RCB_OK);
    assert_int_equal(rcb_fit_set_scale(f, scale), RCB_OK);
    assert_int_equal(rcb_fit_set_noise_model(f, 10.0, 1.0), RCB_OK);
    assert_int_equal(rcb_fit_get_adequacy(f, &a, NULL, NULL, NULL), RCB_OK);
    assert_int_equal(a.known, 1);
    sum += a.chi2, sum2 += a.chi2 * a.chi2;
    expected = a.expected, sd = a.sd; /* the same model: the same figures each seed */
    rejected += !a.adequate;
    rcb_fit_destroy(f);
    rcb_meas_destroy(ms);
  }
  {
    double mean = sum / (double)nseed;
    double s = sqrt((sum2 - (double)nseed * mean * mean) / (double)(nseed - 1));
    print_message("adequacy null (scale %d): F mean %.2f (predicted %.2f), sd %.2f (predicted "
                  "%.2f), %zu of %zu rejected\n", (int)scale, mean, expected, s, sd, rejected,
                  nseed);
    assert_true(fabs(mean - expected) < 4.0 * sd / sqrt((double)nseed));
    assert_true(s > 0.65 * sd && s < 1.35 * sd);
    assert_true(rejected <= 4);
  }
  rcb_model_destroy(m);
}

static void test_adequacy_null_log10(void **state) {
  (void)state;
  adequacy_null(RCB_SCALE_LOG10);
}

static void test_adequacy_null_complex(void **state) {
  (void)state;
  adequacy_null(RCB_SCALE_COMPLEX);
}

/* Known standard deviations: each weighted residual N(0, 1), so F is a
 * chi-square of N - np degrees of freedom (mean N - np, sd sqrt(2 (N - np)))
 * exactly as stated; Gaussian noise of that sd added here (Box-Muller on a
 * fixed LCG), and a model that lacks the coupling damping fails the test
 * while the truth passes it. */
static void test_adequacy_known_sd(void **state) {
  rcb_model *m = rcb_test_model_from_example("paper_system.ini");
  rcb_model *lacking = rcb_test_model_from_example("paper_system.ini");
  const char *outs[] = {"C.A.x", "C.B.y"}, *ins[] = {"DA.x"};
  rcb_meas *clean = rcb_test_frf_meas(m, outs, 2, ins, 1, 100, 400, 151, 10000, RCB_INERTANCE);
  rcb_meas *ms = NULL;
  size_t n = 2 * 151, i, c;
  double *sd = malloc(n * sizeof *sd);
  rcb_complex y[151];
  unsigned long long x = 12345u;
  rcb_fit *f = NULL;
  rcb_fit_adequacy a;
  (void)state;
  assert_non_null(sd);
  assert_int_equal(rcb_meas_create(&ms, NULL), RCB_OK);
  assert_int_equal(rcb_meas_set_grid(ms, RCB_MEAS_FRF, 151, rcb_meas_grid(clean),
                                     rcb_meas_speed(clean)),
                   RCB_OK);
  for (c = 0; c < 2; c++) {
    rcb_meas_channel_info ci;
    rcb_meas_channel(clean, c, &ci);
    for (i = 0; i < 151; i++) {
      double u1, u2, r;
      x = x * 6364136223846793005ull + 1442695040888963407ull;
      u1 = ((double)(x >> 11) + 0.5) * 0x1.0p-53;
      x = x * 6364136223846793005ull + 1442695040888963407ull;
      u2 = (double)(x >> 11) * 0x1.0p-53;
      r = sqrt(-2 * log(u1));
      sd[c * 151 + i] = 0.03 * cabs(ci.data[i]);
      y[i] = ci.data[i] + sd[c * 151 + i] * r * CMPLX(cos(2 * RCB_PI * u2), sin(2 * RCB_PI * u2));
    }
    assert_int_equal(rcb_meas_add_channel(ms, ci.response, ci.reference, ci.kind, y), RCB_OK);
  }
  assert_int_equal(rcb_fit_create(&f, m, ms, NULL), RCB_OK);
  assert_int_equal(rcb_fit_set_scale(f, RCB_SCALE_COMPLEX), RCB_OK);
  assert_int_equal(rcb_fit_set_sd(f, sd), RCB_OK);
  assert_int_equal(rcb_fit_get_adequacy(f, &a, NULL, NULL, NULL), RCB_OK);
  assert_true(a.known);
  assert_true(fabs(a.expected - 2.0 * (double)n) < 1e-9);
  assert_true(fabs(a.sd - sqrt(4.0 * (double)n)) < 1e-9);
  print_message("known sd: F %.1f, limit %.1f\n", a.chi2, a.limit);
  assert_true(a.adequate); /* the truth: F a chi-square of 604, the 1 % limit */
  rcb_fit_destroy(f);
  assert_int_equal(rcb_model_set_param(lacking, "coupling.C.ct", 0.0), RCB_OK);
  assert_int_equal(rcb_fit_create(&f, lacking, ms, NULL), RCB_OK);
  assert_int_equal(rcb_fit_set_scale(f, RCB_SCALE_COMPLEX), RCB_OK);
  assert_int_equal(rcb_fit_set_sd(f, sd), RCB_OK);
  assert_int_equal(rcb_fit_get_adequacy(f, &a, NULL, NULL, NULL), RCB_OK);
  print_message("known sd, no coupling damping: F %.1f, limit %.1f\n", a.chi2, a.limit);
  assert_false(a.adequate);
  rcb_fit_destroy(f);
  rcb_model_destroy(lacking);
  rcb_meas_destroy(ms);
  rcb_meas_destroy(clean);
  rcb_model_destroy(m);
  free(sd);
}

static void test_bad_settings(void **state) {
  rcb_model *m = rcb_test_model_from_example("paper_system.ini");
  const char *outs[] = {"C.A.x"}, *ins[] = {"DA.x"};
  rcb_meas *ms = rcb_test_frf_meas(m, outs, 1, ins, 1, 200, 400, 11, 10000, RCB_RECEPTANCE);
  rcb_fit *f = NULL;
  (void)state;
  assert_int_equal(rcb_fit_create(&f, m, ms, NULL), RCB_OK);
  assert_int_equal(rcb_fit_run(f), RCB_ERR_ARG);
  assert_non_null(strstr(rcb_fit_errmsg(f), "no parameter"));
  assert_int_equal(rcb_fit_add_param(f, "coupling.C.kt", 1e5, 1e6, 0), RCB_ERR_ARG);
  assert_non_null(strstr(rcb_fit_errmsg(f), "outside the bounds"));
  assert_int_equal(rcb_fit_add_param(f, "coupling.C.kt", -1, 1e6, 1), RCB_ERR_ARG);
  assert_int_equal(rcb_fit_add_param(f, "coupling.C.zz", 0, 1, 0), RCB_ERR_NOT_FOUND);
  assert_int_equal(rcb_fit_add_param(f, "coupling.C.kt", 1e3, 1e6, 0), RCB_OK);
  assert_int_equal(rcb_fit_add_param(f, "coupling.C.kt", 1e3, 1e6, 0), RCB_ERR_ARG);
  assert_int_equal(rcb_fit_set_first_start(f, 1), RCB_OK); /* of 1 start: nothing to try */
  assert_int_equal(rcb_fit_run(f), RCB_ERR_ARG);
  assert_non_null(strstr(rcb_fit_errmsg(f), "nothing to try"));
  assert_int_equal(rcb_fit_set_first_start(f, 0), RCB_OK);
  assert_int_equal(rcb_fit_set_band(f, 10, 5), RCB_ERR_ARG);
  assert_int_equal(rcb_fit_set_band(f, 0, 1), RCB_OK);
  assert_int_equal(rcb_fit_run(f), RCB_ERR_ARG); /* no point in the band */
  assert_non_null(strstr(rcb_fit_errmsg(f), "no measured point"));
  rcb_fit_destroy(f);
  rcb_meas_destroy(ms);
  rcb_model_destroy(m);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_sensitivities_frf),
      cmocka_unit_test(test_sensitivities_unbalance),
      cmocka_unit_test(test_sensitivities_element),
      cmocka_unit_test(test_sensitivities_shaft_factors),
      cmocka_unit_test(test_paper_fit_noise_free),
      cmocka_unit_test(test_paper_fit_noisy_seeds),
      cmocka_unit_test(test_unsure_missing_effect),
      cmocka_unit_test(test_complex_continuation),
#if RCB_WITH_NLOPT
      cmocka_unit_test(test_multistart_local_minimum),
      cmocka_unit_test(test_random_starts_alone),
#endif
      cmocka_unit_test(test_interval_coverage_complex),
      cmocka_unit_test(test_adequacy_null_log10),
      cmocka_unit_test(test_adequacy_null_complex),
      cmocka_unit_test(test_adequacy_known_sd),
      cmocka_unit_test(test_bad_settings),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
