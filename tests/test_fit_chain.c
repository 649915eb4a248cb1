/*
 * The measurement chain in the fit (issue #23, item 4): sensor gains and
 * phases fitted beside the model's parameters, fixed sign flips and swapped
 * probes.
 *  - the analytic Jacobian columns of sensor.<r>.gain and .phase (and of the
 *    model's parameters with the chain edited) equal Richardson-extrapolated
 *    central differences to 1e-6 relative on the LOG10, COMPLEX and LINEAR
 *    scales, by the adjoint and by the direct re-solve; the differences of the
 *    sensor columns go through the fixed edit instead (P = g0 e^{i phi0} g
 *    e^{i phi} H: dP/dg = (g0 / g) dP/dg0, dP/dphi = dP/dphi0), a second path;
 *  - data from the paper system with one probe reading 0.8 e^{-i 3 deg} and
 *    eq. 19 noise: the fit recovers 0.8 and -3 deg within 3 standard errors,
 *    kt and kr stay within 3 of theirs from the truth; unbiased data: the
 *    gain within 3 standard errors of 1;
 *  - a sign flipped or two probes swapped in the data, with the matching
 *    fixed edit: the objective equals that of the unedited data (1e-12);
 *  - the monitor's linear swap (rcb_fit_swap_column): on the complex scale
 *    the residuals are affine in the prediction, so the column equals the
 *    residuals with the probes swapped (rcb_fit_swap_sensors) minus those
 *    without, to 1e-10 of the column, with one probe's factor edited;
 *  - unknown sensors, references that differ, a sensor parameter asked for
 *    its dZ/dp: clear errors.
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
#include "identify/identify.h"
#include "rcb_test_util.h"

#define DEG (RCB_PI / 180.0)

static double objective(rcb_fit *f) {
  size_t n = rcb_fit_residual_count(f), j;
  double *r = calloc(n, sizeof *r), F = 0.0;
  assert_true(n > 0);
  assert_int_equal(rcb_fit_residuals(f, r), RCB_OK);
  for (j = 0; j < n; j++) F += r[j] * r[j];
  free(r);
  return F;
}

/* Residuals with the sensor of response resp at the fixed edit (g0, ph0),
 * or the model parameter name at v (resp NULL). */
static void residuals_at(rcb_model *m, rcb_fit *f, const char *resp, const char *name,
                         double g0, double ph0, double v, double *r) {
  if (resp) assert_int_equal(rcb_fit_set_sensor(f, resp, g0, ph0), RCB_OK);
  else assert_int_equal(rcb_model_set_param(m, name, v), RCB_OK);
  assert_int_equal(rcb_fit_residuals(f, r), RCB_OK);
}

/* Richardson-extrapolated central difference (steps h, h/2) of the
 * residuals along: the fixed gain (which 1), the fixed phase (2) of sensor
 * resp at (g0, ph0), or model parameter name at v (which 0). */
static void central(rcb_model *m, rcb_fit *f, const char *resp, const char *name, int which,
                    double g0, double ph0, double v, double h, size_t n, double *d) {
  double *rp = calloc(n, sizeof *rp), *rm = calloc(n, sizeof *rm), *d1 = calloc(n, sizeof *d1);
  size_t j;
  int s;
  for (s = 0; s < 2; s++) {
    double hs = s ? h / 2 : h;
    residuals_at(m, f, resp, name, g0 + (which == 1 ? hs : 0), ph0 + (which == 2 ? hs : 0),
                 v + (which == 0 ? hs : 0), rp);
    residuals_at(m, f, resp, name, g0 - (which == 1 ? hs : 0), ph0 - (which == 2 ? hs : 0),
                 v - (which == 0 ? hs : 0), rm);
    for (j = 0; j < n; j++) {
      double c = (rp[j] - rm[j]) / (2 * hs);
      if (s) d[j] = (4 * c - d1[j]) / 3;
      else d1[j] = c;
    }
  }
  residuals_at(m, f, resp, name, g0, ph0, v, rp); /* back */
  free(rp);
  free(rm);
  free(d1);
}

static double rel_mismatch(const double *a, const double *b, size_t n) {
  double na = 0.0, nd = 0.0;
  size_t j;
  for (j = 0; j < n; j++) na += a[j] * a[j], nd += (a[j] - b[j]) * (a[j] - b[j]);
  return na > 0 ? sqrt(nd / na) : HUGE_VAL;
}

/* One configuration: the fitted parameters (sensor ones as sensor.<r>.gain
 * or .phase), the fixed edit (g0, ph0) of sensor edited, an optional swap;
 * data = the model's FRF with the sensors at 0.9 e^{i 0.1}, so that a short
 * run moves the sensor parameters off their neutral values first. */
typedef struct jac_case {
  const char *const *outs;
  size_t no;
  const char *const *ins;
  size_t ni;
  const char *const *names;
  size_t np;
  const char *edited;
  double g0, ph0;
  const char *swap_a, *swap_b;
} jac_case;

static void check_case(const jac_case *jc, rcb_fit_scale sc) {
  rcb_model *m = rcb_test_model_from_example("paper_system.ini");
  rcb_meas *ms0 = rcb_test_frf_meas(m, jc->outs, jc->no, jc->ins, jc->ni, 120, 400, 15, 10000,
                                    RCB_INERTANCE);
  double complex fac[16];
  rcb_meas *ms;
  rcb_fit *f = NULL;
  size_t n, k, c, nc = rcb_meas_channel_count(ms0);
  double *Ja, *Jf, *d;
  for (c = 0; c < nc; c++) fac[c] = 0.9 * cexp(CMPLX(0.0, 0.1));
  ms = rcb_test_meas_copy(ms0, fac, NULL);
  assert_int_equal(rcb_fit_create(&f, m, ms, NULL), RCB_OK);
  for (k = 0; k < jc->np; k++) {
    const char *nm = jc->names[k];
    int chain = rcb_fit_param_is_chain(nm);
    double p = 1.0;
    if (!chain) assert_int_equal(rcb_model_get_param(m, nm, &p), RCB_OK);
    if (chain == RCB_CHAIN_PHASE) assert_int_equal(rcb_fit_add_param(f, nm, -1.5, 1.5, 0), 0);
    else if (strstr(nm, "C.B.y")) assert_int_equal(rcb_fit_add_param(f, nm, -3, 3, 0), 0);
    else assert_int_equal(rcb_fit_add_param(f, nm, p / 10, p * 10, 1), RCB_OK);
  }
  if (jc->swap_a) assert_int_equal(rcb_fit_swap_sensors(f, jc->swap_a, jc->swap_b), RCB_OK);
  assert_int_equal(rcb_fit_set_sensor(f, jc->edited, jc->g0, jc->ph0), RCB_OK);
  assert_int_equal(rcb_fit_set_scale(f, sc), RCB_OK);
  assert_int_equal(rcb_fit_set_limits(f, 1, 1e-10, 1e-8), RCB_OK);
  assert_int_equal(rcb_fit_set_uncertainty(f, 0), RCB_OK);
  assert_true(rcb_fit_run(f) >= 0); /* one iteration: off the neutral values */
  n = rcb_fit_residual_count(f);
  Ja = calloc(n * jc->np, sizeof *Ja);
  Jf = calloc(n * jc->np, sizeof *Jf);
  d = calloc(n, sizeof *d);
  assert_int_equal(rcb_fit_jacobian(f, 1, Ja), RCB_OK);
  assert_int_equal(rcb_fit_jacobian(f, 0, Jf), RCB_OK);
  for (k = 0; k < jc->np; k++) {
    rcb_fit_param fp;
    const char *nm = jc->names[k];
    int chain = rcb_fit_param_is_chain(nm);
    double mis, mis_fd;
    assert_int_equal(rcb_fit_get_param(f, k, &fp), RCB_OK);
    if (chain) {
      char resp[64];
      double g0 = 1.0, ph0 = 0.0, g = 1.0;
      size_t len = strlen(nm) - strlen("sensor.") - (chain == RCB_CHAIN_GAIN ? 5 : 6), j;
      memcpy(resp, nm + strlen("sensor."), len);
      resp[len] = '\0';
      assert_int_equal(rcb_fit_get_sensor(f, resp, &g0, &ph0, NULL), RCB_OK);
      if (chain == RCB_CHAIN_GAIN) {
        g = fp.value;
        assert_true(fabs(g - 1.0) > 1e-4); /* the run moved it */
        central(m, f, resp, NULL, 1, g0, ph0, 0, 1e-3 * fabs(g0), n, d);
        for (j = 0; j < n; j++) d[j] *= g0 / g; /* dP/dg = (g0 / g) dP/dg0 */
      } else {
        central(m, f, resp, NULL, 2, g0, ph0, 0, 1e-3, n, d);
      }
    } else {
      central(m, f, NULL, nm, 0, 0, 0, fp.value, 1e-3 * fp.value, n, d);
    }
    if (chain == RCB_CHAIN_PHASE && sc != RCB_SCALE_COMPLEX) {
      /* a phase is invisible on magnitudes: d|P|/dphi = Re(conj(P) i P) / |P| = 0
       * exactly, and the differences vanish to round-off */
      double nd = 0.0, nf = 0.0, nr = 0.0, *r = calloc(n, sizeof *r);
      size_t j;
      assert_int_equal(rcb_fit_residuals(f, r), RCB_OK);
      for (j = 0; j < n; j++) {
        if (Ja[j + n * k] != 0.0) fail_msg("scale %d, %s: d r/d phi %g", (int)sc, nm, Ja[j + n * k]);
        nd += d[j] * d[j], nf += Jf[j + n * k] * Jf[j + n * k], nr += r[j] * r[j];
      }
      free(r);
      if (sqrt(nd) > 1e-9 * sqrt(nr) || sqrt(nf) > 1e-9 * sqrt(nr))
        fail_msg("scale %d, %s: differences %g, %g against |r| %g", (int)sc, nm, sqrt(nd),
                 sqrt(nf), sqrt(nr));
      continue;
    }
    mis = rel_mismatch(Ja + n * k, d, n);
    mis_fd = rel_mismatch(Ja + n * k, Jf + n * k, n);
    if (mis > 1e-6 || mis_fd > 2e-2)
      fail_msg("scale %d, %s = %g: central-difference mismatch %g, eq. 11 mismatch %g",
               (int)sc, nm, fp.value, mis, mis_fd);
  }
  free(Ja);
  free(Jf);
  free(d);
  rcb_fit_destroy(f);
  rcb_meas_destroy(ms);
  rcb_meas_destroy(ms0);
  rcb_model_destroy(m);
}

static void test_chain_jacobian(void **state) {
  /* 3 outputs x 2 inputs, 5 parameters: the adjoint (3 < 5 x 2) */
  const char *outs_a[] = {"C.A.x", "DB.x", "DB.y"}, *ins_a[] = {"DA.x", "C.B.x"};
  const char *names_a[] = {"sensor.DB.x.gain", "sensor.DB.x.phase", "sensor.DB.y.gain",
                           "coupling.C.kt", "coupling.C.ct"};
  /* 4 outputs x 1 input, 3 parameters: the direct re-solve (4 >= 3 x 1) */
  const char *outs_b[] = {"C.A.x", "C.B.y", "DB.x", "DB.y"}, *ins_b[] = {"DA.x"};
  const char *names_b[] = {"sensor.C.B.y.gain", "sensor.DB.x.phase", "coupling.C.kt"};
  jac_case a = {outs_a, 3, ins_a, 2, names_a, 5, "DB.y", -1.1, 0.2, "DB.x", "DB.y"};
  jac_case b = {outs_b, 4, ins_b, 1, names_b, 3, "C.B.y", 1.2, -0.3, "DB.y", "DB.x"};
  rcb_fit_scale sc[] = {RCB_SCALE_LOG10, RCB_SCALE_COMPLEX, RCB_SCALE_LINEAR};
  size_t s;
  (void)state;
  for (s = 0; s < 3; s++) {
    check_case(&a, sc[s]);
    check_case(&b, sc[s]);
  }
}

#define NPTS 201

/* The paper system's FRF (inertances at the coupling and disk B for a force
 * at disk A, 200-400 Hz, NPTS points, 10000 rpm) with eq. 19 noise (10 %,
 * 1 %, seed), DB.y's channel multiplied by fy; sd (5 x NPTS) the noise's
 * standard deviations from the noise-free values: sqrt(beta_a^2 |s|^2 / 3 +
 * a^2 / 6), a the additive amplitude of eq. 19. */
static rcb_meas *paper_meas(const rcb_model *m, double complex fy, unsigned seed, double *sd) {
  const char *outs[] = {"C.A.x", "C.A.y", "C.B.x", "C.B.y", "DB.y"}, *ins[] = {"DA.x"};
  rcb_meas *ms0 = rcb_test_frf_meas(m, outs, 5, ins, 1, 200, 400, NPTS, 10000, RCB_INERTANCE);
  double complex fac[5] = {1, 1, 1, 1, fy};
  rcb_meas *ms = rcb_test_meas_copy(ms0, fac, NULL); /* the sensor's factor before the noise */
  size_t c, i;
  for (c = 0; c < 5; c++) {
    rcb_meas_channel_info ci;
    double s2 = 0.0, a;
    assert_int_equal(rcb_meas_channel(ms, c, &ci), RCB_OK);
    for (i = 0; i < NPTS; i++) s2 += cabs(ci.data[i]) * cabs(ci.data[i]);
    a = 0.01 * sqrt(s2) / NPTS;
    for (i = 0; i < NPTS; i++)
      sd[c * NPTS + i] = sqrt(0.01 * cabs(ci.data[i]) * cabs(ci.data[i]) / 3 + a * a / 6);
  }
  assert_int_equal(rcb_meas_add_noise(ms, 10.0, 1.0, seed), RCB_OK);
  rcb_meas_destroy(ms0);
  return ms;
}

/* Fit kt, kr (from the truth) and DB.y's gain (and phase on the complex
 * scale); check each within 3 standard errors of its true value.
 *
 * Weights: on the complex scale the noise's own standard deviations
 * (rcb_fit_set_sd), not the eq. 19 noise model of rcb_fit_set_noise_model.
 * The latter takes each point's variance from its measured value, so that a
 * point measured low weighs more: a level parameter such as a sensor's gain
 * comes out low by about var(r1) beta_a^2 = 0.33 % per component, measured
 * over 30 seeds at 0.8 e^{-i 3 deg}: (gain - 0.8) / se has mean -2.08 (sd
 * 1.14) with the noise model, -0.36 (sd 1.19) with these sds; kt, kr, the
 * phase are unbiased either way. On log10 magnitudes the noise model's
 * weights do not depend on the level (mean -0.38, sd 0.90) and are used. */
static void fit_sensor(double complex fy, rcb_fit_scale sc, unsigned seed) {
  rcb_model *m = rcb_test_model_from_example("paper_system.ini");
  double *sd = calloc(5 * NPTS, sizeof *sd);
  rcb_meas *ms = paper_meas(m, fy, seed, sd);
  const char *names[] = {"coupling.C.kt", "coupling.C.kr", "sensor.DB.y.gain",
                         "sensor.DB.y.phase"};
  double tv[4];
  size_t k, np = sc == RCB_SCALE_COMPLEX ? 4 : 3;
  rcb_fit *f = NULL;
  rcb_fit_report rep;
  assert_int_equal(rcb_model_get_param(m, names[0], &tv[0]), RCB_OK);
  assert_int_equal(rcb_model_get_param(m, names[1], &tv[1]), RCB_OK);
  tv[2] = cabs(fy);
  tv[3] = carg(fy);
  assert_int_equal(rcb_fit_create(&f, m, ms, NULL), RCB_OK);
  assert_int_equal(rcb_fit_add_param(f, names[0], tv[0] / 100, tv[0] * 100, 1), RCB_OK);
  assert_int_equal(rcb_fit_add_param(f, names[1], tv[1] / 100, tv[1] * 100, 1), RCB_OK);
  assert_int_equal(rcb_fit_add_param(f, names[2], 0.1, 10, 1), RCB_OK);
  if (np == 4)
    assert_int_equal(rcb_fit_add_param(f, names[3], -RCB_PI / 2, RCB_PI / 2, 0), RCB_OK);
  assert_int_equal(rcb_fit_set_scale(f, sc), RCB_OK);
  if (sc == RCB_SCALE_COMPLEX) assert_int_equal(rcb_fit_set_sd(f, sd), RCB_OK);
  else assert_int_equal(rcb_fit_set_noise_model(f, 10.0, 1.0), RCB_OK);
  free(sd);
  assert_int_equal(rcb_fit_run(f), RCB_OK);
  assert_int_equal(rcb_fit_get_report(f, &rep), RCB_OK);
  assert_false(rep.unsure);
  for (k = 0; k < np; k++) {
    rcb_fit_param p;
    assert_int_equal(rcb_fit_get_param(f, k, &p), RCB_OK);
    assert_string_equal(p.name, names[k]);
    print_message("scale %d seed %u: %s = %.6g (true %.6g), se %.3g\n", (int)sc, seed, p.name,
                  p.value, tv[k], p.stderr_);
    assert_true(p.stderr_ > 0 && isfinite(p.stderr_));
    if (fabs(p.value - tv[k]) > 3 * p.stderr_)
      fail_msg("scale %d seed %u %s: %g, true %g, se %g", (int)sc, seed, p.name, p.value,
               tv[k], p.stderr_);
  }
  rcb_fit_destroy(f);
  rcb_meas_destroy(ms);
  rcb_model_destroy(m);
}

static void test_chain_recovers_gain_phase(void **state) {
  (void)state;
  fit_sensor(0.8 * cexp(CMPLX(0.0, -3.0 * DEG)), RCB_SCALE_COMPLEX, 1u);
  fit_sensor(0.8 * cexp(CMPLX(0.0, -3.0 * DEG)), RCB_SCALE_COMPLEX, 2u);
  fit_sensor(0.8, RCB_SCALE_LOG10, 3u); /* the gain alone on magnitudes */
}

static void test_chain_null(void **state) {
  (void)state;
  fit_sensor(1.0, RCB_SCALE_COMPLEX, 4u);
  fit_sensor(1.0, RCB_SCALE_LOG10, 5u);
}

/* The objective of model m (kt 1.3 times the truth: not a zero objective)
 * against ms on scale sc with the eq. 19 weights, with DB.y's sign flipped
 * (flip), DB.x and DB.y swapped (swap) in the fit's chain. */
static double chain_objective(rcb_model *m, const rcb_meas *ms, rcb_fit_scale sc, int flip,
                              int swap) {
  rcb_fit *f = NULL;
  double F;
  assert_int_equal(rcb_fit_create(&f, m, ms, NULL), RCB_OK);
  assert_int_equal(rcb_fit_set_scale(f, sc), RCB_OK);
  assert_int_equal(rcb_fit_set_noise_model(f, 10.0, 1.0), RCB_OK);
  if (flip) assert_int_equal(rcb_fit_set_sensor(f, "DB.y", -1.0, 0.0), RCB_OK);
  if (swap) assert_int_equal(rcb_fit_swap_sensors(f, "DB.x", "DB.y"), RCB_OK);
  /* a new FRF workspace resolves the channels again: the swap must survive it
   * (the banded solver: round-off of 1e-12, not the factor 2 of a swap undone) */
  if (swap > 1) assert_int_equal(rcb_fit_set_solver(f, RCB_SOLVER_BANDED), RCB_OK);
  F = objective(f);
  rcb_fit_destroy(f);
  return F;
}

static void test_chain_sign_swap_identity(void **state) {
  rcb_model *truth = rcb_test_model_from_example("paper_system.ini");
  rcb_model *m = rcb_test_model_from_example("paper_system.ini");
  const char *outs[] = {"C.A.x", "DB.x", "DB.y"}, *ins[] = {"DA.x", "C.B.x"};
  const char *swapped[] = {"C.A.x", "DB.y", "DB.x", "C.A.x", "DB.y", "DB.x"};
  double complex one[6] = {1, 1, 1, 1, 1, 1}, neg[6] = {1, 1, -1, 1, 1, -1};
  rcb_meas *ms0 = rcb_test_frf_meas(truth, outs, 3, ins, 2, 200, 400, 101, 10000, RCB_INERTANCE);
  rcb_meas *ms_neg, *ms_swap;
  rcb_fit_scale sc[] = {RCB_SCALE_COMPLEX, RCB_SCALE_LOG10, RCB_SCALE_LINEAR};
  double kt;
  size_t s;
  (void)state;
  assert_int_equal(rcb_meas_add_noise(ms0, 10.0, 1.0, 3u), RCB_OK);
  ms_neg = rcb_test_meas_copy(ms0, neg, NULL);      /* the DB.y probe wired the wrong way */
  ms_swap = rcb_test_meas_copy(ms0, one, swapped); /* the DB.x and DB.y probes exchanged */
  assert_int_equal(rcb_model_get_param(m, "coupling.C.kt", &kt), RCB_OK);
  assert_int_equal(rcb_model_set_param(m, "coupling.C.kt", 1.3 * kt), RCB_OK);
  for (s = 0; s < 3; s++) {
    double F0 = chain_objective(m, ms0, sc[s], 0, 0);
    double Fn = chain_objective(m, ms_neg, sc[s], 1, 0);
    double Fs = chain_objective(m, ms_swap, sc[s], 0, 1);
    double Fsb = chain_objective(m, ms_swap, sc[s], 0, 2);
    double Fsn = chain_objective(m, ms_swap, sc[s], 0, 0);
    assert_true(F0 > 0);
    if (!rcb_test_close(Fn, F0, 1e-12, 0) || !rcb_test_close(Fs, F0, 1e-12, 0))
      fail_msg("scale %d: F %.17g, sign flipped and edited %.17g, swapped and edited %.17g",
               (int)sc[s], F0, Fn, Fs);
    if (!rcb_test_close(Fsb, F0, 1e-9, 0))
      fail_msg("scale %d: F %.17g, swapped on the banded solver %.17g", (int)sc[s], F0, Fsb);
    assert_true(Fsn > 2 * F0); /* the swap matters: not a vacuous identity */
    if (sc[s] == RCB_SCALE_COMPLEX) /* and so does the sign, where it is visible */
      assert_true(chain_objective(m, ms_neg, sc[s], 0, 0) > 2 * F0);
  }
  rcb_meas_destroy(ms0);
  rcb_meas_destroy(ms_neg);
  rcb_meas_destroy(ms_swap);
  rcb_model_destroy(m);
  rcb_model_destroy(truth);
}

static void test_swap_column_identity(void **state) {
  rcb_model *m = rcb_test_model_from_example("paper_system.ini");
  const char *outs[] = {"C.A.x", "DB.x", "DB.y"}, *ins[] = {"DA.x", "C.B.x"};
  rcb_meas *ms = rcb_test_frf_meas(m, outs, 3, ins, 2, 200, 400, 101, 10000, RCB_INERTANCE);
  rcb_fit *f = NULL;
  size_t n, j;
  double *J, *r0, *r1, dmax = 0.0, jmax = 0.0, kt;
  (void)state;
  assert_int_equal(rcb_meas_add_noise(ms, 10.0, 1.0, 5u), RCB_OK);
  assert_int_equal(rcb_model_get_param(m, "coupling.C.kt", &kt), RCB_OK);
  assert_int_equal(rcb_model_set_param(m, "coupling.C.kt", 1.2 * kt), RCB_OK);
  assert_int_equal(rcb_fit_create(&f, m, ms, NULL), RCB_OK);
  assert_int_equal(rcb_fit_set_scale(f, RCB_SCALE_COMPLEX), RCB_OK);
  assert_int_equal(rcb_fit_set_noise_model(f, 10.0, 1.0), RCB_OK);
  assert_int_equal(rcb_fit_set_sensor(f, "DB.x", 1.3, 0.2), RCB_OK); /* its own factor */
  n = rcb_fit_residual_count(f);
  J = calloc(n, sizeof *J), r0 = calloc(n, sizeof *r0), r1 = calloc(n, sizeof *r1);
  assert_int_equal(rcb_fit_swap_column(f, "DB.x", "DB.y", J), RCB_ERR_STATE); /* no evaluation */
  assert_int_equal(rcb_fit_residuals(f, r0), RCB_OK);
  assert_int_equal(rcb_fit_swap_column(f, "DB.x", "DB.y", J), RCB_OK);
  assert_int_equal(rcb_fit_swap_column(f, "DB.x", "DB.x", J), RCB_ERR_ARG);
  assert_int_equal(rcb_fit_swap_column(f, "DB.x", "DA.y", J), RCB_ERR_ARG);
  assert_int_equal(rcb_fit_swap_sensors(f, "DB.x", "DB.y"), RCB_OK);
  assert_int_equal(rcb_fit_residuals(f, r1), RCB_OK);
  for (j = 0; j < n; j++) {
    dmax = fmax(dmax, fabs(r1[j] - r0[j] - J[j]));
    jmax = fmax(jmax, fabs(J[j]));
  }
  if (!(jmax > 0) || !(dmax <= 1e-10 * jmax))
    fail_msg("swap column against the swapped residuals: max |difference| %g, max |column| %g",
             dmax, jmax);
  assert_int_equal(rcb_fit_swap_column(f, "DB.x", "DB.y", J), RCB_ERR_STATE); /* swapped */
  free(J), free(r0), free(r1);
  rcb_fit_destroy(f);
  rcb_meas_destroy(ms);
  rcb_model_destroy(m);
}

static void test_chain_errors(void **state) {
  rcb_model *m = rcb_test_model_from_example("paper_system.ini");
  const char *outs[] = {"C.A.x", "DB.x", "DB.y"}, *ins[] = {"DA.x", "C.B.x"};
  /* DB.y's channel for the reference C.B.x left out */
  double complex part[6] = {1, 1, 1, 1, 1, 0};
  rcb_meas *ms = rcb_test_frf_meas(m, outs, 3, ins, 2, 200, 400, 11, 10000, RCB_INERTANCE);
  rcb_meas *ms_part = rcb_test_meas_copy(ms, part, NULL);
  rcb_fit *f = NULL;
  rcb_fit_dz dz[2];
  double g, ph;
  const char *with;
  (void)state;
  assert_int_equal(rcb_fit_param_is_chain("sensor.DB.y.gain"), RCB_CHAIN_GAIN);
  assert_int_equal(rcb_fit_param_is_chain("sensor.DB.y.phase"), RCB_CHAIN_PHASE);
  assert_int_equal(rcb_fit_param_is_chain("sensor..gain"), 0);
  assert_int_equal(rcb_fit_param_is_chain("coupling.C.kt"), 0);
  assert_int_equal(rcb_fit_param_is_chain(NULL), 0);

  assert_int_equal(rcb_fit_create(&f, m, ms, NULL), RCB_OK);
  assert_int_equal(rcb_fit_add_param(f, "sensor.B4.y.gain", 0.1, 10, 1), RCB_ERR_ARG);
  assert_non_null(strstr(rcb_fit_errmsg(f), "'B4.y'"));
  assert_non_null(strstr(rcb_fit_errmsg(f), "C.A.x, DB.x, DB.y")); /* what is measured */
  assert_int_equal(rcb_fit_add_param(f, "sensor.DB.y.phase", 0.1, 10, 1), RCB_ERR_ARG);
  assert_non_null(strstr(rcb_fit_errmsg(f), "outside the bounds")); /* 0 rad */
  assert_int_equal(rcb_fit_add_param(f, "sensor.DB.y.gain", 0.1, 10, 1), RCB_OK);
  assert_int_equal(rcb_fit_add_param(f, "sensor.DB.y.gain", 0.1, 10, 1), RCB_ERR_ARG);
  assert_int_equal(rcb_fit_set_sensor(f, "B4.y", -1, 0), RCB_ERR_ARG);
  assert_non_null(strstr(rcb_fit_errmsg(f), "B4.y"));
  assert_int_equal(rcb_fit_get_sensor(f, "DB.y", &g, &ph, &with), RCB_OK); /* defaults */
  assert_true(g == 1.0 && ph == 0.0 && with == NULL);
  assert_int_equal(rcb_fit_set_sensor(f, "DB.y", 0.0, 0), RCB_ERR_ARG);
  assert_int_equal(rcb_fit_set_sensor(f, "DB.y", -1.0, NAN), RCB_ERR_ARG);
  assert_int_equal(rcb_fit_get_sensor(f, "DB.y", &g, &ph, &with), RCB_OK); /* refused: kept */
  assert_true(g == 1.0 && ph == 0.0 && with == NULL);
  assert_int_equal(rcb_fit_set_sensor(f, "DB.y", -1.0, 0.1), RCB_OK);
  assert_int_equal(rcb_fit_get_sensor(f, "DB.y", &g, &ph, &with), RCB_OK);
  assert_true(g == -1.0 && ph == 0.1 && with == NULL);
  assert_int_equal(rcb_fit_get_sensor(f, "B4.y", &g, &ph, &with), RCB_ERR_ARG);
  assert_int_equal(rcb_fit_swap_sensors(f, "DB.x", "B4.y"), RCB_ERR_ARG);
  assert_non_null(strstr(rcb_fit_errmsg(f), "B4.y"));
  assert_int_equal(rcb_fit_swap_sensors(f, "DB.x", "DB.y"), RCB_OK);
  assert_int_equal(rcb_fit_get_sensor(f, "DB.x", NULL, NULL, &with), RCB_OK);
  assert_string_equal(with, "DB.y");
  assert_int_equal(rcb_fit_swap_sensors(f, "DB.y", "DB.x"), RCB_OK); /* the same pair */
  assert_int_equal(rcb_fit_swap_sensors(f, "DB.x", "C.A.x"), RCB_ERR_ARG);
  assert_non_null(strstr(rcb_fit_errmsg(f), "swapped with 'DB.y' already"));
  assert_int_equal(rcb_fit_get_sensor(f, "C.A.x", NULL, NULL, &with), RCB_OK); /* kept */
  assert_null(with);
  assert_int_equal(rcb_fit_swap_sensors(f, "DB.y", NULL), RCB_OK); /* undone */
  assert_int_equal(rcb_fit_get_sensor(f, "DB.x", NULL, NULL, &with), RCB_OK);
  assert_null(with);
  /* a chain parameter has no dZ/dp */
  assert_int_equal(rcb_fit_dz_get(f, NULL, dz), RCB_ERR_ARG);
  assert_non_null(strstr(rcb_fit_errmsg(f), "measurement chain"));
  /* its value moved between fits (rcb_fit_set_chain_value): the fitted gain
   * 0.9 on the fixed -1 reads as the fixed edit -0.9 does */
  assert_int_equal(rcb_fit_set_sensor(f, "DB.y", -1.0, 0.0), RCB_OK);
  assert_int_equal(rcb_fit_set_chain_value(f, "sensor.DB.y.gain", 20.0), RCB_ERR_ARG);
  assert_int_equal(rcb_fit_set_chain_value(f, "sensor.DB.x.gain", 0.9), RCB_ERR_ARG);
  assert_int_equal(rcb_fit_set_chain_value(f, "coupling.C.kt", 0.9), RCB_ERR_ARG);
  assert_int_equal(rcb_fit_set_chain_value(f, "sensor.DB.y.gain", 0.9), RCB_OK);
  {
    rcb_fit_param p;
    double F1 = objective(f), F2;
    assert_int_equal(rcb_fit_get_param(f, 0, &p), RCB_OK);
    assert_true(p.value == 0.9 && p.start == 0.9);
    assert_int_equal(rcb_fit_set_chain_value(f, "sensor.DB.y.gain", 1.0), RCB_OK);
    assert_int_equal(rcb_fit_set_sensor(f, "DB.y", -0.9, 0.0), RCB_OK);
    F2 = objective(f);
    if (!rcb_test_close(F1, F2, 1e-12, 0)) fail_msg("fitted 0.9: F %.17g, fixed: %.17g", F1, F2);
  }
  rcb_fit_destroy(f);

  assert_int_equal(rcb_fit_create(&f, m, ms_part, NULL), RCB_OK);
  assert_int_equal(rcb_fit_swap_sensors(f, "DB.x", "DB.y"), RCB_ERR_ARG);
  assert_non_null(strstr(rcb_fit_errmsg(f), "same references"));
  rcb_fit_destroy(f);
  rcb_meas_destroy(ms);
  rcb_meas_destroy(ms_part);
  rcb_model_destroy(m);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_chain_errors),
      cmocka_unit_test(test_chain_sign_swap_identity),
      cmocka_unit_test(test_swap_column_identity),
      cmocka_unit_test(test_chain_jacobian),
      cmocka_unit_test(test_chain_recovers_gain_phase),
      cmocka_unit_test(test_chain_null),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
