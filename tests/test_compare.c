/*
 * Model-measurement comparison:
 *  - a model compared with its own simulated data: error 0, FRAC 1, CSAC 1,
 *    CSF 1, zero log and phase errors, an empty residual map (FRFs of every
 *    kind, unbalance responses); every measured peak paired;
 *  - with known standard deviations: chi-square per dof ~ 1 (4 with sds
 *    halved) and the noise floor in closed form;
 *  - a pure frequency scaling (every stiffness x a, every damper x sqrt(a),
 *    mass unchanged, at rest: every eigenvalue x sqrt(a)) gives a peak
 *    frequency error of 100 (1/sqrt(a) - 1) % on every paired peak;
 *  - the half-power damping of a simulated resonance matches the eigenvalue's
 *    damping ratio within 5 %;
 *  - a resonance added to the data that the model lacks is listed as a
 *    measured peak without counterpart, at its frequency and damping;
 *  - the outlier rule in closed form; a sensor reading 20 % low named (error %
 *    and chi2/dof), nothing named in the null case; with two references, one
 *    low channel named as a channel, a low sensor as the sensor;
 *  - known values of FRAC / CSF for a scaled measurement, channel errors,
 *    allocator balance.
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

#include "compare/compare_internal.h"
#include "core/rcb_internal.h"
#include "rcb_test_util.h"

#define RPM (RCB_PI / 30.0)
#define TWO_PI (2.0 * RCB_PI)

/* A shaft (0.8 m, d 30 mm) with a 20 kg disk in the middle on two isotropic
 * bearings; %g placeholders: young (Pa), bearing k (N/m), bearing c (N s/m). */
static const char ROTOR_FMT[] =
    "[material steel]\ndensity = 7800\nyoung = %.17g\npoisson = 0.3\n"
    "[shaft A]\nmaterial = steel\nshear_factor = 0.9\nsegment = 0.8 0.03 0.0 8\n"
    "[disk D]\nat = A 0.40\nmass = 20\nId = 0.1\nIp = 0.2\n"
    "[bearing B1]\nat = A 0.0\nkxx = %.17g\nkyy = %.17g\ncxx = %.17g\ncyy = %.17g\n"
    "[bearing B2]\nat = A 0.8\nkxx = %.17g\nkyy = %.17g\ncxx = %.17g\ncyy = %.17g\n"
    "[unbalance U]\nat = D\namount = 1e-4\nphase_deg = 0\n";

static rcb_model *rotor(double young, double k, double c) {
  char ini[2048];
  rcb_model *m;
  snprintf(ini, sizeof ini, ROTOR_FMT, young, k, k, c, c, k, k, c, c);
  m = rcb_test_model_from_string(ini);
  if (rcb_model_dof_count(m) == 0) assert_int_equal(rcb_model_finalize(m), RCB_OK);
  return m;
}

static rcb_model *paper(void) {
  rcb_model *m = rcb_test_model_from_example("paper_system.ini");
  if (rcb_model_dof_count(m) == 0) assert_int_equal(rcb_model_finalize(m), RCB_OK);
  return m;
}

/* Synthetic FRF measurement: channels outs[o]/ins[o] (pairs), n points on
 * [f0, f1] Hz at speed rpm, of the given kind. */
static rcb_meas *frf_meas(const rcb_model *m, const char *const *outs, const char *const *ins,
                          size_t nch, double f0, double f1, size_t n, double rpm,
                          rcb_frf_kind kind) {
  rcb_meas *ms = NULL;
  double *x = calloc(n, sizeof *x);
  rcb_complex *col = calloc(n, sizeof *col);
  size_t i, k;
  for (i = 0; i < n; i++) x[i] = TWO_PI * (f0 + (f1 - f0) * (double)i / (double)(n - 1));
  assert_int_equal(rcb_meas_create(&ms, NULL), RCB_OK);
  assert_int_equal(rcb_meas_set_grid(ms, RCB_MEAS_FRF, n, x, rpm * RPM), RCB_OK);
  for (k = 0; k < nch; k++) {
    rcb_frf *fr = NULL;
    rcb_dof od, id;
    assert_int_equal(rcb_model_find_dof(m, outs[k], &od), RCB_OK);
    assert_int_equal(rcb_model_find_dof(m, ins[k], &id), RCB_OK);
    assert_int_equal(rcb_frf_create(&fr, m, 1, &od, 1, &id, RCB_SOLVER_AUTO, NULL), RCB_OK);
    for (i = 0; i < n; i++)
      assert_int_equal(rcb_frf_eval(fr, x[i], rpm * RPM, kind, &col[i]), RCB_OK);
    assert_int_equal(rcb_meas_add_channel(ms, outs[k], ins[k], kind, col), RCB_OK);
    rcb_frf_destroy(fr);
  }
  free(x);
  free(col);
  return ms;
}


static rcb_compare *run(const rcb_model *m, const rcb_meas *ms) {
  rcb_compare *c = NULL;
  rcb_status st;
  assert_int_equal(rcb_compare_create(&c, NULL), RCB_OK);
  st = rcb_compare_run(c, m, ms);
  if (st) fail_msg("compare: %s", rcb_compare_errmsg(c));
  return c;
}

/* Every measure says "identical". */
static void assert_identical(const rcb_compare *c) {
  rcb_compare_summary s;
  size_t k, i, nch = rcb_compare_channel_count(c), n = rcb_compare_point_count(c);
  const double *csac = rcb_compare_csac(c), *csf = rcb_compare_csf(c);
  const double *map = rcb_compare_residual_map(c);
  assert_true(nch > 0 && n > 0);
  for (k = 0; k < nch; k++) {
    rcb_compare_channel ch;
    assert_int_equal(rcb_compare_get_channel(c, k, &ch), RCB_OK);
    assert_true(ch.error_pct < 1e-9);
    assert_true(fabs(ch.frac - 1.0) < 1e-12);
    assert_true(ch.log_rms < 1e-12);
    assert_true(ch.phase_rms_deg < 1e-9);
  }
  for (i = 0; i < n; i++) {
    assert_true(fabs(csac[i] - 1.0) < 1e-12);
    assert_true(fabs(csf[i] - 1.0) < 1e-12);
  }
  for (k = 0; k < nch * rcb_compare_band_count(c); k++) assert_true(map[k] < 1e-12);
  assert_int_equal(rcb_compare_get_summary(c, &s), RCB_OK);
  assert_true(s.error_pct < 1e-9 && fabs(s.frac_mean - 1) < 1e-12);
  assert_true(fabs(s.csac_mean - 1) < 1e-12 && fabs(s.csf_mean - 1) < 1e-12);
}

static void test_self_frf(void **state) {
  static const char *const outs[] = {"DA.x", "C.A.y", "DB.x", "DA.ry"};
  static const char *const ins[] = {"DA.x", "DA.x", "C.B.y", "DA.x"};
  rcb_frf_kind kinds[] = {RCB_RECEPTANCE, RCB_MOBILITY, RCB_INERTANCE};
  rcb_model *m = paper();
  size_t q, p;
  (void)state;
  for (q = 0; q < 3; q++) {
    rcb_meas *ms = frf_meas(m, outs, ins, 4, 5.0, 500.0, 400, 3000.0, kinds[q]);
    rcb_compare *c = run(m, ms);
    assert_identical(c);
    assert_int_equal(rcb_compare_band_count(c), 10);
    /* measured peaks all pair, with the model's own modes nearby */
    for (p = 0; p < rcb_compare_peak_count(c); p++) {
      rcb_compare_peak r;
      assert_int_equal(rcb_compare_get_peak(c, p, &r), RCB_OK);
      assert_int_not_equal(r.match, RCB_PEAK_MEASURED_ONLY);
      if (r.match == RCB_PEAK_MATCHED) {
        assert_true(fabs(r.freq_err_pct) < 2.0);
        assert_true(fabs(r.amp_ratio - 1.0) < 1e-9);
      }
    }
    rcb_compare_destroy(c);
    rcb_meas_destroy(ms);
  }
  rcb_model_destroy(m);
}

static void test_self_unbalance(void **state) {
  static const char *const outs[] = {"DA.x", "DA.y", "DB.x", "DB.y"};
  rcb_model *m = paper();
  rcb_meas *ms = rcb_test_unbalance_meas(m, outs, 4, 300.0, 18300.0, 301);
  rcb_compare *c = run(m, ms);
  size_t p, matched = 0;
  (void)state;
  assert_identical(c);
  for (p = 0; p < rcb_compare_peak_count(c); p++) {
    rcb_compare_peak r;
    assert_int_equal(rcb_compare_get_peak(c, p, &r), RCB_OK);
    assert_int_not_equal(r.match, RCB_PEAK_MEASURED_ONLY);
    if (r.match != RCB_PEAK_MATCHED) continue;
    matched++;
    /* the 1X resonance of a critical speed lies at it, to the damping's effect */
    assert_true(fabs(r.freq_err_pct) < 3.0);
  }
  assert_true(matched >= 1);
  rcb_compare_destroy(c);
  rcb_meas_destroy(ms);
  rcb_model_destroy(m);
}

/* Stiffness x 1.21, dampers x 1.1, at rest: every eigenvalue x 1.1. */
static void test_frequency_scaling(void **state) {
  static const char *const outs[] = {"D.x", "#2.x"};
  static const char *const ins[] = {"#2.x", "#2.x"}; /* off centre: the rocking mode too */
  rcb_model *truth = rotor(2.1e11 * 1.21, 2e6 * 1.21, 1500.0 * 1.1);
  rcb_model *m = rotor(2.1e11, 2e6, 1500.0);
  rcb_meas *ms = frf_meas(truth, outs, ins, 2, 5.0, 200.0, 4000, 0.0, RCB_RECEPTANCE);
  rcb_compare *c = NULL;
  size_t p, matched = 0;
  double expect = 100.0 * (1.0 / 1.1 - 1.0);
  (void)state;
  assert_int_equal(rcb_compare_create(&c, NULL), RCB_OK);
  assert_int_equal(rcb_compare_set_peaks(c, 3.0, 0.15), RCB_OK);
  assert_int_equal(rcb_compare_run(c, m, ms), RCB_OK);
  for (p = 0; p < rcb_compare_peak_count(c); p++) {
    rcb_compare_peak r;
    assert_int_equal(rcb_compare_get_peak(c, p, &r), RCB_OK);
    assert_int_not_equal(r.match, RCB_PEAK_MEASURED_ONLY);
    if (r.match != RCB_PEAK_MATCHED) continue;
    matched++;
    /* like for like (the model's own peak): the scaling exactly */
    if (fabs(r.peak_err_pct - expect) > 0.02)
      fail_msg("peak at %g Hz: peak frequency error %g %%, expected %g %%",
               r.meas_freq / TWO_PI, r.peak_err_pct, expect);
    /* against the mode's wd: the same, to the O(zeta^2) offset of a peak */
    if (fabs(r.freq_err_pct - expect) > 200.0 * r.model_zeta * r.model_zeta + 0.02)
      fail_msg("peak at %g Hz: frequency error %g %%, expected %g %%", r.meas_freq / TWO_PI,
               r.freq_err_pct, expect);
  }
  assert_true(matched >= 1);
  rcb_compare_destroy(c);
  rcb_meas_destroy(ms);
  rcb_model_destroy(m);
  rcb_model_destroy(truth);
}

/* Half-power damping of the first resonance vs the eigenvalue's zeta. */
static void test_half_power_damping(void **state) {
  static const char *const outs[] = {"D.x"};
  static const char *const ins[] = {"D.x"};
  rcb_model *m = rotor(2.1e11, 2e6, 1500.0);
  rcb_modes *me = NULL;
  rcb_mode modes[8];
  size_t nm = 0, p, found = 0;
  rcb_meas *ms;
  rcb_compare *c;
  (void)state;
  assert_int_equal(rcb_modes_create(&me, m, NULL), RCB_OK);
  assert_int_equal(rcb_modes_compute(me, 0.0, 8, modes, &nm, NULL), RCB_OK);
  assert_true(nm >= 2 && modes[0].zeta > 0.005 && modes[0].zeta < 0.2);
  /* the first bending mode alone in the band */
  ms = frf_meas(m, outs, ins, 1, 0.5 * modes[0].wd / TWO_PI, 1.6 * modes[0].wd / TWO_PI, 3000,
                0.0, RCB_RECEPTANCE);
  c = run(m, ms);
  for (p = 0; p < rcb_compare_peak_count(c); p++) {
    rcb_compare_peak r;
    assert_int_equal(rcb_compare_get_peak(c, p, &r), RCB_OK);
    if (r.match != RCB_PEAK_MATCHED) continue;
    found++;
    if (!rcb_test_close(r.meas_zeta, modes[0].zeta, 0.05, 0.0))
      fail_msg("half-power zeta %g, eigenvalue zeta %g", r.meas_zeta, modes[0].zeta);
    assert_true(rcb_test_close(r.model_zeta, modes[0].zeta, 1e-9, 0.0));
    assert_true(fabs(r.zeta_err_pct) < 5.0);
  }
  assert_int_equal(found, 1);
  rcb_compare_destroy(c);
  rcb_meas_destroy(ms);
  rcb_modes_destroy(me);
  rcb_model_destroy(m);
}

/* A resonance in the data that the model lacks (a single-DOF term added to
 * the simulated receptance): listed as measured only, at its frequency. */
static void test_unmatched_peak(void **state) {
  static const char *const outs[] = {"D.x"};
  static const char *const ins[] = {"D.x"};
  rcb_model *m = rotor(2.1e11, 2e6, 400.0);
  rcb_meas *ms0 = frf_meas(m, outs, ins, 1, 5.0, 400.0, 4000, 0.0, RCB_RECEPTANCE), *ms = NULL;
  rcb_modes *me = NULL;
  rcb_mode modes[16];
  rcb_meas_channel_info ci;
  rcb_complex *v = calloc(4000, sizeof *v);
  const double *x = rcb_meas_grid(ms0);
  double wr = TWO_PI * 60.0, zr = 0.02, a, hmax = 0.0;
  size_t i, nm = 0, p, extra = 0;
  rcb_compare *c;
  (void)state;
  assert_int_equal(rcb_modes_create(&me, m, NULL), RCB_OK);
  assert_int_equal(rcb_modes_compute(me, 0.0, 16, modes, &nm, NULL), RCB_OK);
  for (i = 0; i < nm; i++) assert_true(fabs(modes[i].wd / wr - 1.0) > 0.2);
  assert_int_equal(rcb_meas_channel(ms0, 0, &ci), RCB_OK);
  for (i = 0; i < 4000; i++) hmax = fmax(hmax, cabs(ci.data[i]));
  a = 0.3 * hmax * 2.0 * zr * wr * wr; /* a peak 0.3 times the largest one */
  for (i = 0; i < 4000; i++)
    v[i] = ci.data[i] + a / (wr * wr - x[i] * x[i] + RCB_J * 2.0 * zr * wr * x[i]);
  assert_int_equal(rcb_meas_create(&ms, NULL), RCB_OK);
  assert_int_equal(rcb_meas_set_grid(ms, RCB_MEAS_FRF, 4000, x, 0.0), RCB_OK);
  assert_int_equal(rcb_meas_add_channel(ms, "D.x", "D.x", RCB_RECEPTANCE, v), RCB_OK);
  c = run(m, ms);
  for (p = 0; p < rcb_compare_peak_count(c); p++) {
    rcb_compare_peak r;
    assert_int_equal(rcb_compare_get_peak(c, p, &r), RCB_OK);
    if (r.match != RCB_PEAK_MEASURED_ONLY) continue;
    extra++;
    assert_true(rcb_test_close(r.meas_freq, wr, 5e-3, 0.0));
    assert_true(rcb_test_close(r.meas_zeta, zr, 0.15, 0.0));
    assert_true(isnan(r.model_freq));
    assert_true(r.amp_ratio > 3.0); /* the model has nothing there */
  }
  assert_int_equal(extra, 1);
  rcb_compare_destroy(c);
  rcb_meas_destroy(ms);
  rcb_meas_destroy(ms0);
  rcb_modes_destroy(me);
  rcb_model_destroy(m);
  free(v);
}

/* The measured peak of an analytic single-DOF FRF,
 *   H = s^k A / (wr^2 - w^2 + 2 i zr wr w) + R   (k = 0 receptance, 2 inertance),
 * alone in the data (the rotor's modes are far from wr), on 601 points
 * 50-70 Hz, with eq. 19 noise (beta_a %, beta_s %, seed) when beta_a > 0.
 * Returns that peak's row. */
static rcb_compare_peak sdof_peak(rcb_frf_kind kind, double beta_a, double beta_s,
                                  unsigned seed) {
  static const char *const ch = "D.x";
  const double wr = TWO_PI * 60.0, zr = 0.02, R = 2e-8; /* rad/s, -, m/N */
  rcb_model *m = rotor(2.1e11, 2e6, 400.0);
  rcb_meas *ms = NULL;
  rcb_complex v[601];
  double x[601];
  rcb_compare_peak r, out;
  rcb_compare *c;
  size_t i, p, found = 0;
  for (i = 0; i < 601; i++) {
    double complex s = RCB_J * (x[i] = TWO_PI * (50.0 + 20.0 * (double)i / 600.0));
    v[i] = 1e-3 / (wr * wr + s * s + 2.0 * zr * wr * s);
    if (kind == RCB_INERTANCE) v[i] *= s * s;
    v[i] += kind == RCB_INERTANCE ? -wr * wr * R : R; /* the residual in the data's kind */
  }
  assert_int_equal(rcb_meas_create(&ms, NULL), RCB_OK);
  assert_int_equal(rcb_meas_set_grid(ms, RCB_MEAS_FRF, 601, x, 0.0), RCB_OK);
  assert_int_equal(rcb_meas_add_channel(ms, ch, ch, kind, v), RCB_OK);
  if (beta_a > 0) assert_int_equal(rcb_meas_add_noise(ms, beta_a, beta_s, seed), RCB_OK);
  c = run(m, ms);
  memset(&out, 0, sizeof out);
  for (p = 0; p < rcb_compare_peak_count(c); p++) {
    assert_int_equal(rcb_compare_get_peak(c, p, &r), RCB_OK);
    if (r.match == RCB_PEAK_MODEL_ONLY || fabs(r.meas_freq / wr - 1.0) > 0.01) continue;
    out = r;
    found++;
  }
  assert_int_equal(found, 1);
  rcb_compare_destroy(c);
  rcb_meas_destroy(ms);
  rcb_model_destroy(m);
  return out;
}

/* Without noise the local modal fit returns the single-DOF's zeta and wd
 * exactly (receptance and inertance, with a residual R). */
static void test_modal_fit_exact(void **state) {
  const double wr = TWO_PI * 60.0, zr = 0.02;
  int k;
  (void)state;
  for (k = 0; k < 2; k++) {
    rcb_compare_peak r = sdof_peak(k ? RCB_INERTANCE : RCB_RECEPTANCE, 0.0, 0.0, 0);
    if (!rcb_test_close(r.meas_zeta, zr, 1e-8, 0.0) ||
        !rcb_test_close(r.meas_wd, wr * sqrt(1.0 - zr * zr), 1e-10, 0.0))
      fail_msg("kind %d: modal fit zeta %.12g wd %.12g, expected %.12g %.12g", k, r.meas_zeta,
               r.meas_wd, zr, wr * sqrt(1.0 - zr * zr));
    assert_true(isfinite(r.meas_zeta_hp));
  }
}

/* Under eq. 19 noise (10 %, 1 %) over 20 seeds the modal fit's damping stays
 * within 15 % of the truth on every seed, and its RMS error is well below
 * the half-power width's, which leaves that band on some seeds. */
static void test_modal_fit_noise(void **state) {
  const double zr = 0.02;
  double e_fit = 0.0, e_hp = 0.0, worst_fit = 0.0, worst_hp = 0.0;
  unsigned seed;
  (void)state;
  for (seed = 1; seed <= 20; seed++) {
    rcb_compare_peak r = sdof_peak(RCB_INERTANCE, 10.0, 1.0, seed);
    double ef = r.meas_zeta / zr - 1.0, eh = r.meas_zeta_hp / zr - 1.0;
    e_fit += ef * ef, e_hp += eh * eh;
    worst_fit = fmax(worst_fit, fabs(ef)), worst_hp = fmax(worst_hp, fabs(eh));
  }
  e_fit = sqrt(e_fit / 20.0), e_hp = sqrt(e_hp / 20.0);
  print_message("  zeta error over 20 seeds: modal fit RMS %.1f %% (worst %.1f %%), half-power "
                "RMS %.1f %% (worst %.1f %%)\n",
                100 * e_fit, 100 * worst_fit, 100 * e_hp, 100 * worst_hp);
  assert_true(worst_fit < 0.10);
  assert_true(worst_hp > 0.15);
  assert_true(e_fit < 0.25 * e_hp);
}

/* The paper system at rest, inertances DA.x and DB.x per a force at DA.x,
 * 1-500 Hz on 2000 points, eq. 19 noise (10 %, 1 %): the matched peak (the
 * first bending pair near 150 Hz, two modes 0.1 Hz apart that the data show
 * as one, and the pair near 320 Hz) has a modal-fit damping within 25 % of
 * the model's own modal damping (the truth); each pair is fitted as two
 * modes sharing their poles on both channels (test_modal_fit_gyroscopic). */
static void test_modal_fit_paper(void **state) {
  static const char *const outs[] = {"DA.x", "DB.x"};
  static const char *const ins[] = {"DA.x", "DA.x"};
  rcb_model *m = paper();
  rcb_meas *ms = frf_meas(m, outs, ins, 2, 1.0, 500.0, 2000, 0.0, RCB_INERTANCE);
  rcb_compare *c;
  size_t p, matched = 0;
  (void)state;
  assert_int_equal(rcb_meas_add_noise(ms, 10.0, 1.0, 7), RCB_OK);
  c = run(m, ms);
  for (p = 0; p < rcb_compare_peak_count(c); p++) {
    rcb_compare_peak r;
    double ef, eh;
    assert_int_equal(rcb_compare_get_peak(c, p, &r), RCB_OK);
    if (r.match != RCB_PEAK_MATCHED) continue;
    ef = fabs(r.meas_zeta / r.model_zeta - 1.0), eh = fabs(r.meas_zeta_hp / r.model_zeta - 1.0);
    print_message("  peak %.2f Hz: model zeta %.4f, modal fit %.4f, half-power %.4f\n",
                  r.meas_freq / TWO_PI, r.model_zeta, r.meas_zeta, r.meas_zeta_hp);
    matched++;
    assert_true(ef < 0.25);
    (void)eh; /* reported: on this system the two are comparable (docs/rcbtool.md, Peak damping) */
  }
  assert_true(matched >= 1);
  rcb_compare_destroy(c);
  rcb_meas_destroy(ms);
  rcb_model_destroy(m);
}

/* Two modes 1 % apart in frequency (different zetas, complex residues) plus
 * a constant residual on two channels, noise-free: the shared-pole fit with
 * N = 2 returns both poles to 1e-8 (rcb_cmp_modal_fit_multi directly). */
static void test_modal_fit_two_modes(void **state) {
  const double w1 = TWO_PI * 100.0, w2 = 1.01 * w1, z1 = 0.012, z2 = 0.02; /* rad/s, - */
  const rcb_complex r[2][2] = {{CMPLX(3.0, 1.0), CMPLX(-1.0, 2.0)},
                               {CMPLX(1.0, -2.0), CMPLX(2.5, 0.5)}}; /* [channel][mode] */
  double x[301], wn[4], zeta[4];
  rcb_complex v[2 * 301];
  rcb_compare *c = NULL;
  size_t i, k, nf = 0;
  (void)state;
  for (i = 0; i < 301; i++) {
    double complex s = RCB_J * (x[i] = w1 * (0.94 + 0.13 * (double)i / 300.0));
    for (k = 0; k < 2; k++) {
      double complex p1 = CMPLX(-z1 * w1, w1 * sqrt(1 - z1 * z1));
      double complex p2 = CMPLX(-z2 * w2, w2 * sqrt(1 - z2 * z2));
      v[k * 301 + i] = w1 * (r[k][0] / (s - p1) + conj(r[k][0]) / (s - conj(p1)) +
                             r[k][1] / (s - p2) + conj(r[k][1]) / (s - conj(p2))) +
                       CMPLX(0.3, -0.1 * (double)k);
    }
  }
  assert_int_equal(rcb_compare_create(&c, NULL), RCB_OK);
  assert_int_equal(rcb_cmp_modal_fit_multi(c, x, v, 2, 301, w1, 2, wn, zeta, &nf), RCB_OK);
  assert_int_equal(nf, 2);
  if (!rcb_test_close(wn[0], w1, 1e-8, 0.0) || !rcb_test_close(wn[1], w2, 1e-8, 0.0) ||
      !rcb_test_close(zeta[0], z1, 1e-8, 0.0) || !rcb_test_close(zeta[1], z2, 1e-8, 0.0))
    fail_msg("wn %.12g %.12g zeta %.12g %.12g", wn[0], wn[1], zeta[0], zeta[1]);
  rcb_compare_destroy(c);
}

/* Relative zeta errors of the peaks near 150 Hz (g = 0) and 161 Hz (g = 1)
 * of one compare run, against the damped mode nearest each fitted wd. */
static void gyro_errors(const rcb_compare *c, const rcb_mode *modes, size_t nm, double *e2,
                        double *worst, size_t *n) {
  size_t p, j;
  for (p = 0; p < rcb_compare_peak_count(c); p++) {
    rcb_compare_peak r;
    size_t best = 0, g;
    double e;
    assert_int_equal(rcb_compare_get_peak(c, p, &r), RCB_OK);
    if (r.match == RCB_PEAK_MODEL_ONLY || r.meas_freq < TWO_PI * 145.0 ||
        r.meas_freq > TWO_PI * 170.0)
      continue;
    for (j = 1; j < nm; j++)
      if (fabs(modes[j].wd - r.meas_wd) < fabs(modes[best].wd - r.meas_wd)) best = j;
    g = r.meas_freq > TWO_PI * 155.0;
    e = r.meas_zeta / modes[best].zeta - 1.0;
    e2[g] += e * e, n[g]++, worst[g] = fmax(worst[g], fabs(e));
  }
}

/* The paper system at 10000 rpm, inertances DA.x, DA.y, DB.x, DB.y per a
 * force at DA.x, 1-500 Hz on 2000 points: the gyroscopic pair near 150 Hz
 * (150.11 and 150.56 Hz, zeta 0.0131) shows as one peak, its cross channels
 * as the modes' difference, a narrower peak; the pair near 161 Hz (161.5 and
 * 161.9 Hz, zeta 0.031) is weak in these channels. Noise-free, the peak
 * near 150 Hz is fitted with both pairs (four modes sharing their poles on
 * the four channels): zeta within 0.5 % of the damped mode's. Under eq. 19
 * noise (10 %, 1 %), seeds 1 to 10: the single-mode fit gave 0.0054-0.0062
 * there (error 56 % RMS, worst 59 %); the shared-pole fit is asserted below
 * 30 % RMS and 36 % worst (measured 24.9 % and 30.3 %: low, as the pair's
 * split and damping trade off under this noise). The peak near 161 Hz, a
 * peak of the noisy data only, is reported: docs/rcbtool.md, Peak damping. */
static void test_modal_fit_gyroscopic(void **state) {
  static const char *const outs[] = {"DA.x", "DA.y", "DB.x", "DB.y"};
  static const char *const ins[] = {"DA.x", "DA.x", "DA.x", "DA.x"};
  rcb_model *m = paper();
  rcb_modes *me = NULL;
  rcb_mode modes[64];
  size_t nm = 0, j, n[2] = {0, 0};
  double e2[2] = {0, 0}, worst[2] = {0, 0};
  unsigned seed;
  (void)state;
  assert_int_equal(rcb_modes_create(&me, m, NULL), RCB_OK);
  assert_int_equal(rcb_modes_set_max_zeta(me, 0.99), RCB_OK); /* as the peak table */
  assert_int_equal(rcb_modes_compute(me, 10000 * RPM, 64, modes, &nm, NULL), RCB_OK);
  for (seed = 0; seed <= 10; seed++) { /* seed 0: noise-free */
    rcb_meas *ms = frf_meas(m, outs, ins, 4, 1.0, 500.0, 2000, 10000.0, RCB_INERTANCE);
    rcb_compare *c;
    if (seed) assert_int_equal(rcb_meas_add_noise(ms, 10.0, 1.0, seed), RCB_OK);
    c = run(m, ms);
    gyro_errors(c, modes, nm, e2, worst, n);
    if (!seed) {
      assert_true(n[0] == 1 && worst[0] < 0.005);
      e2[0] = worst[0] = 0.0, n[0] = 0;
    }
    rcb_compare_destroy(c);
    rcb_meas_destroy(ms);
  }
  assert_int_equal(n[0], 10);
  for (j = 0; j < 2; j++)
    if (n[j])
      print_message("  peak near %s Hz: %zu peaks, zeta error RMS %.1f %% (worst %.1f %%)\n",
                    j ? "161" : "150", n[j], 100 * sqrt(e2[j] / (double)n[j]), 100 * worst[j]);
  assert_true(sqrt(e2[0] / 10.0) < 0.30);
  assert_true(worst[0] < 0.36);
  rcb_modes_destroy(me);
  rcb_model_destroy(m);
}

/* A measurement that is the model times a constant s on one channel and
 * exact on the other: error |s - 1| 100 % there, FRAC 1 (shape only), log
 * error |log10 s|; CSF across both channels = 2 s' / (1 + s'^2) in the
 * single-channel limit is checked on a one-channel measurement. */
static void test_known_values(void **state) {
  static const char *const outs[] = {"D.x"};
  static const char *const ins[] = {"D.x"};
  rcb_model *m = rotor(2.1e11, 2e6, 400.0);
  rcb_meas *ms0 = frf_meas(m, outs, ins, 1, 5.0, 100.0, 200, 0.0, RCB_MOBILITY), *ms = NULL;
  rcb_meas_channel_info ci;
  rcb_complex v[200];
  double s = 1.25;
  size_t i;
  rcb_compare *c;
  rcb_compare_channel ch;
  (void)state;
  assert_int_equal(rcb_meas_channel(ms0, 0, &ci), RCB_OK);
  for (i = 0; i < 200; i++) v[i] = s * ci.data[i];
  assert_int_equal(rcb_meas_create(&ms, NULL), RCB_OK);
  assert_int_equal(rcb_meas_set_grid(ms, RCB_MEAS_FRF, 200, rcb_meas_grid(ms0), 0.0), RCB_OK);
  assert_int_equal(rcb_meas_add_channel(ms, "D.x", "D.x", RCB_MOBILITY, v), RCB_OK);
  c = run(m, ms);
  assert_int_equal(rcb_compare_get_channel(c, 0, &ch), RCB_OK);
  /* e = s m: ||(|m| - s|m|)|| / ||s|m||| = (s - 1)/s */
  assert_true(rcb_test_close(ch.error_pct, 100.0 * (s - 1.0) / s, 1e-12, 0.0));
  assert_true(fabs(ch.frac - 1.0) < 1e-12);
  assert_true(rcb_test_close(ch.log_rms, log10(s), 1e-12, 0.0));
  assert_true(ch.phase_rms_deg < 1e-9);
  for (i = 0; i < 200; i++) {
    assert_true(fabs(rcb_compare_csac(c)[i] - 1.0) < 1e-12);
    assert_true(rcb_test_close(rcb_compare_csf(c)[i], 2.0 * s / (1.0 + s * s), 1e-12, 0.0));
  }
  rcb_compare_destroy(c);
  rcb_meas_destroy(ms);
  rcb_meas_destroy(ms0);
  rcb_model_destroy(m);
}

static void test_errors_and_allocator(void **state) {
  static const char *const outs[] = {"D.x"};
  static const char *const ins[] = {"D.x"};
  rcb_test_counter cnt = {0, 0};
  rcb_allocator al = rcb_test_counting_allocator(&cnt);
  rcb_model *m = rotor(2.1e11, 2e6, 400.0);
  rcb_meas *ms = frf_meas(m, outs, ins, 1, 5.0, 100.0, 50, 0.0, RCB_RECEPTANCE), *bad = NULL;
  rcb_complex v[50];
  rcb_compare *c = NULL;
  size_t b, first, count, total = 0;
  (void)state;
  assert_int_equal(rcb_compare_create(&c, &al), RCB_OK);
  assert_int_equal(rcb_compare_set_bands(c, 0), RCB_ERR_ARG);
  assert_non_null(strstr(rcb_compare_errmsg(c), "expected 1 to 1000"));
  assert_int_equal(rcb_compare_set_peaks(c, 3.0, 2.0), RCB_ERR_ARG);
  assert_int_equal(rcb_compare_set_bands(c, 7), RCB_OK);
  assert_int_equal(rcb_compare_run(c, m, ms), RCB_OK);
  assert_int_equal(rcb_compare_band_count(c), 7);
  for (b = 0; b < 7; b++) {
    assert_int_equal(rcb_compare_band(c, b, NULL, NULL, &first, &count), RCB_OK);
    assert_int_equal(first, total);
    total += count;
  }
  assert_int_equal(total, 50);
  /* a channel the model does not know: named in the message */
  memset(v, 0, sizeof v);
  assert_int_equal(rcb_meas_create(&bad, NULL), RCB_OK);
  assert_int_equal(rcb_meas_set_grid(bad, RCB_MEAS_FRF, 50, rcb_meas_grid(ms), 0.0), RCB_OK);
  assert_int_equal(rcb_meas_add_channel(bad, "NOPE.x", "D.x", RCB_RECEPTANCE, v), RCB_OK);
  assert_int_equal(rcb_compare_run(c, m, bad), RCB_ERR_NOT_FOUND);
  assert_non_null(strstr(rcb_compare_errmsg(c), "NOPE"));
  assert_int_equal(rcb_compare_channel_count(c), 0);
  rcb_compare_destroy(c);
  assert_true(cnt.allocs > 0);
  assert_int_equal(cnt.allocs, cnt.frees);
  rcb_meas_destroy(bad);
  rcb_meas_destroy(ms);
  rcb_model_destroy(m);
}

/* Known standard deviations (issue #15, rcb_compare_set_sd): the measurement
 * is the model plus complex Gaussian noise of sd 2 % of |H| on Re and Im
 * (Box-Muller on the test's own LCG); the chi-square per degree of freedom
 * is then chi2(2N)/(2N): mean 1, sd 1/sqrt(N), and 4 when the stated sds are
 * half the true ones. The floor is the closed form 100 sqrt(sum sd^2 / sum
 * |e|^2). A count that does not match the measurement is refused; NULL
 * clears (NaN). */
static double lcg_uniform(unsigned long long *s) {
  *s = *s * 6364136223846793005ULL + 1442695040888963407ULL;
  return ((double)(*s >> 11) + 0.5) / 9007199254740992.0;
}

static void test_known_sd(void **state) {
  static const char *const outs[] = {"DA.x", "DB.x"};
  static const char *const ins[] = {"DA.x", "DA.x"};
  rcb_model *m = paper();
  rcb_meas *clean = frf_meas(m, outs, ins, 2, 20.0, 400.0, 500, 3000.0, RCB_RECEPTANCE), *ms;
  size_t n = 500, k, i;
  double *sd = calloc(2 * n, sizeof *sd), *half = calloc(2 * n, sizeof *half), s2 = 0, e2 = 0;
  rcb_complex *col = calloc(n, sizeof *col);
  unsigned long long seed = 12345;
  rcb_compare *c = NULL;
  rcb_compare_summary s;
  rcb_compare_channel ch;
  (void)state;
  assert_int_equal(rcb_meas_create(&ms, NULL), RCB_OK);
  assert_int_equal(rcb_meas_set_grid(ms, RCB_MEAS_FRF, n, rcb_meas_grid(clean), 3000.0 * RPM),
                   RCB_OK);
  for (k = 0; k < 2; k++) {
    rcb_meas_channel_info ci;
    rcb_meas_channel(clean, k, &ci);
    for (i = 0; i < n; i++) {
      double u1 = lcg_uniform(&seed), u2 = lcg_uniform(&seed), r = sqrt(-2.0 * log(u1));
      double sdev = 0.02 * cabs(ci.data[i]);
      col[i] = ci.data[i] + sdev * r * CMPLX(cos(TWO_PI * u2), sin(TWO_PI * u2));
      sd[k * n + i] = sdev;
      half[k * n + i] = 0.5 * sdev;
      s2 += sdev * sdev;
      e2 += creal(col[i] * conj(col[i]));
    }
    assert_int_equal(rcb_meas_add_channel(ms, ci.response, ci.reference, ci.kind, col), RCB_OK);
  }
  assert_int_equal(rcb_compare_create(&c, NULL), RCB_OK);
  /* without sds: NaN */
  assert_int_equal(rcb_compare_run(c, m, ms), RCB_OK);
  assert_int_equal(rcb_compare_get_summary(c, &s), RCB_OK);
  assert_true(isnan(s.floor_pct) && isnan(s.chi2_dof));
  /* the true sds: chi2/dof within 4 of its sd 1/sqrt(2N) */
  assert_int_equal(rcb_compare_set_sd(c, sd, 2 * n), RCB_OK);
  assert_int_equal(rcb_compare_run(c, m, ms), RCB_OK);
  assert_int_equal(rcb_compare_get_summary(c, &s), RCB_OK);
  assert_true(fabs(s.chi2_dof - 1.0) < 4.0 / sqrt(2.0 * (double)n));
  assert_true(fabs(s.floor_pct - 100.0 * sqrt(s2 / e2)) < 1e-9 * s.floor_pct);
  for (k = 0; k < 2; k++) {
    assert_int_equal(rcb_compare_get_channel(c, k, &ch), RCB_OK);
    assert_true(fabs(ch.chi2_dof - 1.0) < 4.0 / sqrt((double)n));
    assert_true(ch.floor_pct > 1.0 && ch.floor_pct < 3.0); /* 2 % of |e|, |e| noisy */
  }
  /* sds stated too small by 2: chi2/dof about 4 */
  assert_int_equal(rcb_compare_set_sd(c, half, 2 * n), RCB_OK);
  assert_int_equal(rcb_compare_run(c, m, ms), RCB_OK);
  assert_int_equal(rcb_compare_get_summary(c, &s), RCB_OK);
  assert_true(fabs(s.chi2_dof - 4.0) < 16.0 / sqrt(2.0 * (double)n));
  /* refusals: a wrong count at run, a negative value at set; NULL clears */
  assert_int_equal(rcb_compare_set_sd(c, sd, n), RCB_OK);
  assert_int_equal(rcb_compare_run(c, m, ms), RCB_ERR_ARG);
  assert_non_null(strstr(rcb_compare_errmsg(c), "2 channels x 500 points"));
  half[3] = -1.0;
  assert_int_equal(rcb_compare_set_sd(c, half, 2 * n), RCB_ERR_ARG);
  assert_int_equal(rcb_compare_set_sd(c, NULL, 0), RCB_OK);
  assert_int_equal(rcb_compare_run(c, m, ms), RCB_OK);
  assert_int_equal(rcb_compare_get_summary(c, &s), RCB_OK);
  assert_true(isnan(s.chi2_dof));
  rcb_compare_destroy(c);
  rcb_meas_destroy(ms);
  rcb_meas_destroy(clean);
  rcb_model_destroy(m);
  free(sd);
  free(half);
  free(col);
}

/* The outlier rule in closed form: others {1, 2, 3, 4, 100}: median 3, the
 * absolute deviations {2, 1, 0, 1, 97} have median 1, so the threshold is
 * max(2 x 3, 3 + 6 x 1.4826 x 1) = 11.8956; fewer than 3 finite others: NaN.
 * The chi-square limit: the 0.999 quantile of chi2(100) is 149.449 (tables),
 * of chi2(1000) 1143.917. */
static void test_outlier_rule(void **state) {
  const double others[] = {4.0, 100.0, 1.0, NAN, 3.0, 2.0}, two[] = {1.0, NAN, 2.0};
  double work[6];
  (void)state;
  assert_true(fabs(rcb_compare_outlier_threshold(others, 6, 2.0, work) - 11.8956) < 1e-12);
  assert_true(fabs(rcb_compare_outlier_threshold(others, 6, 5.0, work) - 15.0) < 1e-12);
  assert_true(isnan(rcb_compare_outlier_threshold(two, 3, 2.0, work)));
  assert_true(fabs(rcb_compare_chi2_limit(100) - 1.49449) < 2e-3);
  assert_true(fabs(rcb_compare_chi2_limit(1000) - 1.143917) < 1e-3);
  assert_true(isnan(rcb_compare_chi2_limit(0)));
}

/* The channels of @p clean (n points, 3000 rpm) with complex Gaussian noise of
 * sd 2 % of |e| on Re and Im (Box-Muller on the LCG from @p seed), the
 * channels whose bit is set in @p low scaled by @p gain; the sds into @p sd
 * (channel-major) when not NULL. Destroys clean. */
static rcb_meas *noisy_copy(rcb_meas *clean, size_t n, unsigned long long seed,
                            unsigned low, double gain, double *sd) {
  size_t nch = rcb_meas_channel_count(clean), k, i;
  rcb_complex *col = calloc(n, sizeof *col);
  rcb_meas *ms;
  assert_non_null(col);
  assert_int_equal(rcb_meas_create(&ms, NULL), RCB_OK);
  assert_int_equal(rcb_meas_set_grid(ms, RCB_MEAS_FRF, n, rcb_meas_grid(clean), 3000.0 * RPM),
                   RCB_OK);
  for (k = 0; k < nch; k++) {
    rcb_meas_channel_info ci;
    rcb_meas_channel(clean, k, &ci);
    for (i = 0; i < n; i++) {
      double u1 = lcg_uniform(&seed), u2 = lcg_uniform(&seed), r = sqrt(-2.0 * log(u1));
      double sdev = 0.02 * cabs(ci.data[i]);
      col[i] = ci.data[i] + sdev * r * CMPLX(cos(TWO_PI * u2), sin(TWO_PI * u2));
      if (low >> k & 1u) col[i] *= gain;
      if (sd) sd[k * n + i] = sdev;
    }
    assert_int_equal(rcb_meas_add_channel(ms, ci.response, ci.reference, ci.kind, col), RCB_OK);
  }
  rcb_meas_destroy(clean);
  free(col);
  return ms;
}

/* Model-made FRFs of six sensors (paper system, input DA.x), noise as
 * noisy_copy; sensor DB.y's values scaled by @p gain (a probe reading low). */
static rcb_meas *six_sensors(const rcb_model *m, double gain, double **sd_out) {
  static const char *const outs[] = {"C.A.x", "C.A.y", "C.B.x", "C.B.y", "DA.x", "DB.y"};
  static const char *const ins[] = {"DA.x", "DA.x", "DA.x", "DA.x", "DA.x", "DA.x"};
  size_t n = 400;
  double *sd = calloc(6 * n, sizeof *sd);
  assert_non_null(sd);
  *sd_out = sd;
  return noisy_copy(frf_meas(m, outs, ins, 6, 5.0, 400.0, n, 3000.0, RCB_INERTANCE), n, 777,
                    1u << 5, gain, sd);
}

/* A probe reading 20 % low is named (its error % about 20 against about 2
 * on the others; with sds, its chi2/dof about 0.2^2/(2 x 0.02^2) = 50 against
 * about 1); with the gain right nothing is named. */
static void test_outlier_sensor(void **state) {
  rcb_model *m = paper();
  double *sd = NULL;
  rcb_meas *bad = six_sensors(m, 0.8, &sd), *good;
  rcb_compare *c = run(m, bad);
  rcb_compare_outlier o;
  (void)state;
  assert_int_equal(rcb_compare_outlier_count(c), 1);
  assert_int_equal(rcb_compare_get_outlier(c, 0, &o), RCB_OK);
  assert_string_equal(o.response, "DB.y");
  assert_null(o.reference);
  assert_int_equal(o.by_chi2, 0);
  assert_true(o.error_pct > 15.0 && o.error_pct < 25.0);
  assert_true(o.others_lo > 0.5 && o.others_hi < 4.0);
  assert_true(o.error_pct > o.threshold && o.threshold >= 2.0 * o.others_lo);
  assert_int_equal(rcb_compare_get_outlier(c, 1, &o), RCB_ERR_ARG);
  /* with the sds: chi2/dof */
  assert_int_equal(rcb_compare_set_sd(c, sd, 6 * 400), RCB_OK);
  assert_int_equal(rcb_compare_run(c, m, bad), RCB_OK);
  assert_int_equal(rcb_compare_outlier_count(c), 1);
  assert_int_equal(rcb_compare_get_outlier(c, 0, &o), RCB_OK);
  assert_string_equal(o.response, "DB.y");
  assert_int_equal(o.by_chi2, 1);
  assert_true(o.chi2_dof > 30.0 && o.chi2_dof < 70.0);
  assert_true(o.chi2_lo > 0.8 && o.chi2_hi < 1.2);
  rcb_compare_destroy(c);
  free(sd);
  /* the null case, with and without sds */
  good = six_sensors(m, 1.0, &sd);
  c = run(m, good);
  assert_int_equal(rcb_compare_outlier_count(c), 0);
  assert_int_equal(rcb_compare_set_sd(c, sd, 6 * 400), RCB_OK);
  assert_int_equal(rcb_compare_run(c, m, good), RCB_OK);
  assert_int_equal(rcb_compare_outlier_count(c), 0);
  rcb_compare_destroy(c);
  free(sd);
  rcb_meas_destroy(good);
  rcb_meas_destroy(bad);
  rcb_model_destroy(m);
}

/* Twelve channels (six sensors, each per forces at DA.x and DB.y), noise as
 * noisy_copy; channels whose bit is set in @p low read 20 % low. */
static rcb_meas *two_refs(const rcb_model *m, unsigned low) {
  static const char *const outs[] = {"C.A.x", "C.A.x", "C.A.y", "C.A.y", "C.B.x", "C.B.x",
                                     "C.B.y", "C.B.y", "DA.x",  "DA.x",  "DB.y",  "DB.y"};
  static const char *const ins[] = {"DA.x", "DB.y", "DA.x", "DB.y", "DA.x", "DB.y",
                                    "DA.x", "DB.y", "DA.x", "DB.y", "DA.x", "DB.y"};
  size_t n = 300;
  return noisy_copy(frf_meas(m, outs, ins, 12, 5.0, 400.0, n, 3000.0, RCB_INERTANCE), n, 99,
                    low, 0.8, NULL);
}

/* With two references: DB.y low on both channels names the sensor; low on
 * its DA.x channel alone names that channel, not the sensor. */
static void test_outlier_channel(void **state) {
  rcb_model *m = paper();
  rcb_meas *both = two_refs(m, 3u << 10), *one = two_refs(m, 1u << 10);
  rcb_compare *c = run(m, both);
  rcb_compare_outlier o;
  (void)state;
  assert_int_equal(rcb_compare_outlier_count(c), 1);
  assert_int_equal(rcb_compare_get_outlier(c, 0, &o), RCB_OK);
  assert_string_equal(o.response, "DB.y");
  assert_null(o.reference);
  assert_int_equal(rcb_compare_run(c, m, one), RCB_OK);
  assert_int_equal(rcb_compare_outlier_count(c), 1);
  assert_int_equal(rcb_compare_get_outlier(c, 0, &o), RCB_OK);
  assert_string_equal(o.response, "DB.y");
  assert_non_null(o.reference);
  assert_string_equal(o.reference, "DA.x");
  assert_true(o.error_pct > 15.0 && o.others_hi < 4.0);
  rcb_compare_destroy(c);
  rcb_meas_destroy(both);
  rcb_meas_destroy(one);
  rcb_model_destroy(m);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_self_frf),
      cmocka_unit_test(test_self_unbalance),
      cmocka_unit_test(test_frequency_scaling),
      cmocka_unit_test(test_half_power_damping),
      cmocka_unit_test(test_unmatched_peak),
      cmocka_unit_test(test_modal_fit_exact),
      cmocka_unit_test(test_modal_fit_noise),
      cmocka_unit_test(test_modal_fit_paper),
      cmocka_unit_test(test_modal_fit_two_modes),
      cmocka_unit_test(test_modal_fit_gyroscopic),
      cmocka_unit_test(test_known_values),
      cmocka_unit_test(test_errors_and_allocator),
      cmocka_unit_test(test_known_sd),
      cmocka_unit_test(test_outlier_rule),
      cmocka_unit_test(test_outlier_sensor),
      cmocka_unit_test(test_outlier_channel),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
