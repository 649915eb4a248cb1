/*
 * Time integration (issue #5), checked against things that could prove it
 * wrong:
 *  - the steady 1X response by time integration equals the frequency-domain
 *    unbalance response (rcb_frf_unbalance, a different algorithm: one
 *    complex solve) within 0.5 % and 0.5 deg at >= 20 speeds, including
 *    speeds within 2 % of the first critical speed (from rcb_campbell, not
 *    from the FRF), on the paper system and on a cross-coupled-bearing
 *    system with a speed-dependent bearing;
 *  - tightening the integrator and steady-state tolerances tightens that
 *    agreement;
 *  - a run-up through the first critical speed: the peak falls and moves to
 *    a higher speed as the angular acceleration grows (the known behaviour
 *    of passage through resonance);
 *  - energy 1/2 v'Mv + 1/2 q'Kq of the undamped, unforced, non-rotating
 *    model is conserved to the integrator tolerance.
 * Without SUNDIALS the create call must say RCB_ERR_UNSUPPORTED.
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
#include "rcb/rcb_config.h"
#include "rcb_test_util.h"

#define RPM (RCB_PI / 30.0)

/* The cross-coupled example made stable over its whole range (the file's
 * forward mode loses its damping at 2550 rpm, below its critical speed, so
 * no steady state exists there): smaller cross-coupling, mass-proportional
 * shaft damping. Bearing BR keeps its speed-dependent table. */
static const char cross_ini[] =
    "[material steel]\ndensity = 7850\nyoung = 2.05e11\npoisson = 0.29\n"
    "[shaft S]\nmaterial = steel\nshear_factor = 0.9\ndamping_stiffness = 2e-5\n"
    "damping_mass = 10\nsegment = 1.0 0.04 0.0 10\n"
    "[disk D]\nat = S 0.5\ndensity = 7850\nouter_diameter = 0.20\ninner_diameter = 0.04\n"
    "width = 0.04\n"
    "[bearing BL]\nat = S start\nkxx = 2.0e7\nkxy = 1.0e6\nkyx = -1.0e6\nkyy = 2.5e7\n"
    "cxx = 2000\ncxy = 300\ncyx = -300\ncyy = 2500\n"
    "[bearing BR]\nat = S end\nspeed_rpm = 0 3000 6000\nkxx = 1.5e7 1.8e7 2.1e7\n"
    "kxy = 0.5e6 1.0e6 1.5e6\nkyx = -0.5e6 -1.0e6 -1.5e6\nkyy = 2.0e7\ncxx = 1500\n"
    "cxy = 200 250 300\ncyx = -200 -250 -300\ncyy = 1800\n"
    "[unbalance U]\nat = D\namount = 1e-4\nphase_deg = 30\n";

/* First 1X critical speed (rad/s) from the Campbell diagram. */
static double first_critical(const rcb_model *m, double wmax) {
  enum { NS = 41, NM = 8 };
  rcb_modes *e = NULL;
  double sp[NS], wd[NM * NS], crit[16];
  size_t i, nc = 0;
  for (i = 0; i < NS; i++) sp[i] = wmax * (double)i / (NS - 1);
  assert_int_equal(rcb_modes_create(&e, m, NULL), RCB_OK);
  assert_int_equal(rcb_modes_set_max_zeta(e, 0.99), RCB_OK);
  assert_int_equal(rcb_campbell(e, NS, sp, NM, wd, NULL, NULL), RCB_OK);
  rcb_critical_speeds(NS, sp, NM, wd, 1.0, 16, crit, NULL, &nc);
  rcb_modes_destroy(e);
  assert_true(nc > 0);
  return crit[0];
}

/* Largest amplitude error (relative) and phase error (deg) over outputs. */
static void compare(const rcb_complex *Qt, const rcb_complex *Qf, size_t n, double *ea,
                    double *ep) {
  size_t o;
  *ea = 0.0;
  *ep = 0.0;
  for (o = 0; o < n; o++) {
    *ea = fmax(*ea, fabs(cabs(Qt[o]) / cabs(Qf[o]) - 1.0));
    *ep = fmax(*ep, fabs(carg(Qt[o] / Qf[o])) * 180.0 / RCB_PI);
  }
}

/* Time vs frequency domain at the given speeds, with the 0.5 % / 0.5 deg
 * criterion. */
static void check_speeds(rcb_model *m, const char *const *chs, size_t nch, const double *w,
                         size_t nw, const char *label) {
  rcb_dof d[8];
  rcb_complex Qt[8], Qf[8];
  rcb_frf *f = NULL;
  rcb_transient *t = NULL;
  rcb_transient_stats s;
  size_t i, k;
  double worst_a = 0.0, worst_p = 0.0;
  long steps = 0;
  for (i = 0; i < nch; i++) assert_int_equal(rcb_model_find_dof(m, chs[i], &d[i]), RCB_OK);
  assert_int_equal(rcb_frf_create(&f, m, nch, d, 0, NULL, RCB_SOLVER_DENSE, NULL), RCB_OK);
  assert_int_equal(rcb_transient_create(&t, m, nch, d, NULL), RCB_OK);
  assert_int_equal(rcb_transient_set_tolerances(t, 1e-6, 1e-12, 1e-9), RCB_OK);
  assert_int_equal(rcb_transient_set_steady(t, 1e-3, 16, 20000), RCB_OK);
  for (k = 0; k < nw; k++) {
    double ea, ep;
    rcb_status st = rcb_transient_steady(t, w[k], Qt);
    if (st) fail_msg("%s at %g rpm: %s", label, w[k] / RPM, rcb_transient_errmsg(t));
    assert_int_equal(rcb_frf_unbalance(f, w[k], Qf), RCB_OK);
    compare(Qt, Qf, nch, &ea, &ep);
    rcb_transient_get_stats(t, &s);
    steps += s.steps;
    if (ea > 5e-3 || ep > 0.5)
      fail_msg("%s at %.1f rpm: amplitude error %.3g, phase error %.3g deg", label,
               w[k] / RPM, ea, ep);
    worst_a = fmax(worst_a, ea);
    worst_p = fmax(worst_p, ep);
  }
  print_message("%s: %zu speeds, worst amplitude error %.2e, phase %.2e deg, %ld steps\n",
                label, nw, worst_a, worst_p, steps);
  rcb_transient_destroy(t);
  rcb_frf_destroy(f);
}

/* RCB_TEST_FAST=1: set for the sanitizer build by tests/CMakeLists.txt, which
 * looks for memory errors on the paths, not for the figures (those are the
 * Release build's). */
static int fast_mode(void) {
  const char *fast = getenv("RCB_TEST_FAST");
  return fast && strcmp(fast, "1") == 0;
}

/* 18 speeds evenly over [lo, hi] plus three at and within 2 % of wc; fast
 * mode: 2 even speeds plus the three near wc. */
static size_t speed_list(double lo, double hi, double wc, double *w) {
  size_t i, ne = fast_mode() ? 2 : 18;
  for (i = 0; i < ne; i++) w[i] = lo + (hi - lo) * (double)i / (double)(ne - 1);
  w[ne] = 0.985 * wc;
  w[ne + 1] = wc;
  w[ne + 2] = 1.015 * wc;
  return ne + 3;
}

static void test_steady_paper(void **state) {
  static const char *const chs[] = {"DA.x", "DA.y", "DB.x", "DB.y"};
  rcb_model *m = rcb_test_model_from_example("paper_system.ini");
  double w[21], wc = first_critical(m, 15000 * RPM);
  (void)state;
  assert_true(wc > 8000 * RPM && wc < 10000 * RPM);
  check_speeds(m, chs, 4, w, speed_list(3000 * RPM, 14000 * RPM, wc, w), "paper system");
  rcb_model_destroy(m);
}

static void test_steady_cross_coupled(void **state) {
  static const char *const chs[] = {"D.x", "D.y", "BL.x", "BR.y"};
  rcb_model *m = rcb_test_model_from_string(cross_ini);
  double w[21], wc = first_critical(m, 6000 * RPM);
  (void)state;
  check_speeds(m, chs, 4, w, speed_list(600 * RPM, 6000 * RPM, wc, w), "cross-coupled");
  rcb_model_destroy(m);
}

/* Agreement at 1 % above the first critical speed for a loose and a tight
 * setting of both tolerances. */
static void test_tolerance_follows(void **state) {
  rcb_model *m = rcb_test_model_from_example("paper_system.ini");
  rcb_dof d[2];
  rcb_complex Qt[2], Qf[2];
  rcb_frf *f = NULL;
  rcb_transient *t = NULL;
  double w, ea[2], ep[2];
  int k;
  (void)state;
  if (fast_mode()) { /* two steady states the steady tests' paths already take */
    rcb_model_destroy(m);
    skip();
  }
  w = 1.01 * first_critical(m, 15000 * RPM);
  assert_int_equal(rcb_model_find_dof(m, "DA.x", &d[0]), RCB_OK);
  assert_int_equal(rcb_model_find_dof(m, "DB.y", &d[1]), RCB_OK);
  assert_int_equal(rcb_frf_create(&f, m, 2, d, 0, NULL, RCB_SOLVER_DENSE, NULL), RCB_OK);
  assert_int_equal(rcb_frf_unbalance(f, w, Qf), RCB_OK);
  assert_int_equal(rcb_transient_create(&t, m, 2, d, NULL), RCB_OK);
  for (k = 0; k < 2; k++) {
    double rtol = k ? 1e-7 : 1e-4, sst = k ? 1e-5 : 1e-2;
    assert_int_equal(rcb_transient_set_tolerances(t, rtol, rtol * 1e-6, rtol * 1e-3), RCB_OK);
    assert_int_equal(rcb_transient_set_steady(t, sst, 16, 20000), RCB_OK);
    assert_int_equal(rcb_transient_steady(t, w, Qt), RCB_OK);
    compare(Qt, Qf, 2, &ea[k], &ep[k]);
  }
  print_message("loose: %.2e / %.2e deg, tight: %.2e / %.2e deg\n", ea[0], ep[0], ea[1],
                ep[1]);
  /* measured: 2.8e-2 / 0.3-0.4 deg loose, 1e-4 / 3.5e-3 deg tight */
  assert_true(ea[1] < ea[0] / 20.0 && ep[1] < ep[0] / 20.0);
  assert_true(ea[1] < 1e-3 && ep[1] < 0.05);
  rcb_transient_destroy(t);
  rcb_frf_destroy(f);
  rcb_model_destroy(m);
}

/* ---- run-up ---- */

typedef struct peak_s {
  double amp, speed; /* m, rad/s */
} peak_t;

static int track_peak(void *user, const rcb_transient_sample *s) {
  peak_t *p = user;
  double r = hypot(s->out[0], s->out[1]);
  if (r > p->amp) {
    p->amp = r;
    p->speed = s->speed;
  }
  return 0;
}

static void test_runup_trend(void **state) {
  rcb_model *m = rcb_test_model_from_example("paper_system.ini");
  size_t n = rcb_model_dof_count(m), i, k;
  rcb_dof *all = calloc(n, sizeof *all), d[2];
  rcb_complex *Q = calloc(n, sizeof *Q);
  double *q0 = calloc(n, sizeof *q0), *v0 = calloc(n, sizeof *v0);
  static const double acc[3] = {300.0, 1200.0, 4800.0}; /* rad/s^2 */
  double w0 = 7000 * RPM, w1 = 11000 * RPM, wc = first_critical(m, 15000 * RPM);
  peak_t pk[3];
  rcb_frf *f = NULL;
  rcb_transient *t = NULL;
  (void)state;
  assert_non_null(all);
  assert_non_null(Q);
  assert_non_null(q0);
  assert_non_null(v0);
  /* Start on the steady orbit at w0 (no start-up transient): all DOFs. */
  for (i = 0; i < rcb_model_node_count(m); i++) {
    rcb_node_info ni;
    assert_int_equal(rcb_model_node_info(m, i, &ni), RCB_OK);
    for (k = 0; k < 4; k++)
      if (ni.dof[k] >= 0) all[ni.dof[k]] = (rcb_dof){i, (rcb_dir)k};
  }
  assert_int_equal(rcb_frf_create(&f, m, n, all, 0, NULL, RCB_SOLVER_DENSE, NULL), RCB_OK);
  assert_int_equal(rcb_frf_unbalance(f, w0, Q), RCB_OK);
  for (i = 0; i < n; i++) {
    q0[i] = creal(Q[i]);
    v0[i] = creal(RCB_J * w0 * Q[i]);
  }
  assert_int_equal(rcb_model_find_dof(m, "DA.x", &d[0]), RCB_OK);
  assert_int_equal(rcb_model_find_dof(m, "DA.y", &d[1]), RCB_OK);
  assert_int_equal(rcb_transient_create(&t, m, 2, d, NULL), RCB_OK);
  assert_int_equal(rcb_transient_set_tolerances(t, 1e-6, 1e-12, 1e-9), RCB_OK);
  /* fast mode: the fastest run-up only (the path; the trend needs all three) */
  for (k = fast_mode() ? 2 : 0; k < 3; k++) {
    rcb_speed_profile p = {w0, w1, acc[k]};
    double t_end = (w1 - w0) / acc[k];
    pk[k].amp = 0.0;
    pk[k].speed = 0.0;
    assert_int_equal(rcb_transient_run(t, &p, t_end, 2e-4, q0, v0, track_peak, &pk[k]),
                     RCB_OK);
    print_message("run-up %g rad/s^2: peak %.4e m at %.1f rpm (critical %.1f rpm)\n", acc[k],
                  pk[k].amp, pk[k].speed / RPM, wc / RPM);
  }
  for (k = fast_mode() ? 2 : 0; k < 3; k++)
    assert_true(pk[k].speed > wc); /* after the critical speed */
  if (!fast_mode()) {
    assert_true(pk[0].amp > pk[1].amp && pk[1].amp > pk[2].amp);
    assert_true(pk[0].speed < pk[1].speed && pk[1].speed < pk[2].speed);
  }
  rcb_transient_destroy(t);
  rcb_frf_destroy(f);
  free(all);
  free(Q);
  free(q0);
  free(v0);
  rcb_model_destroy(m);
}

/* ---- energy ---- */

typedef struct energy_s {
  const double *M, *K;
  double e0, drift; /* J, relative */
} energy_t;

static double quad(const double *A, const double *x, size_t n) {
  size_t i, j;
  double s = 0.0;
  for (j = 0; j < n; j++)
    for (i = 0; i < n; i++) s += x[i] * A[i + n * j] * x[j];
  return s;
}

static int track_energy(void *user, const rcb_transient_sample *s) {
  energy_t *e = user;
  double en = 0.5 * quad(e->M, s->v, s->n) + 0.5 * quad(e->K, s->q, s->n);
  if (s->t == 0.0) e->e0 = en;
  e->drift = fmax(e->drift, fabs(en / e->e0 - 1.0));
  return 0;
}

static void test_energy(void **state) {
  rcb_model *m = NULL;
  rcb_bearing_coefs b = {2e7, 0, 0, 3e7, 0, 0, 0, 0};
  rcb_speed_profile still = {0.0, 0.0, 0.0};
  rcb_transient *t = NULL;
  double *M, *K, *q0, drift[2];
  size_t n, i, k;
  energy_t e;
  (void)state;
  assert_int_equal(rcb_model_create(&m, NULL), RCB_OK);
  assert_int_equal(rcb_model_add_material(m, "steel", 7850, 2.05e11, 0.29), RCB_OK);
  assert_int_equal(rcb_model_add_shaft(m, "S", "steel", 0.0, 0.9), RCB_OK);
  assert_int_equal(rcb_model_add_segment(m, "S", 0.6, 0.03, 0.0, 6), RCB_OK);
  assert_int_equal(rcb_model_add_disk(m, "D", "S", 0.3, 5.0, 0.02, 0.04), RCB_OK);
  assert_int_equal(rcb_model_add_bearing(m, "B1", "S", 0.0, &b), RCB_OK);
  assert_int_equal(rcb_model_add_bearing(m, "B2", "S", 0.6, &b), RCB_OK);
  assert_int_equal(rcb_model_finalize(m), RCB_OK);
  n = rcb_model_dof_count(m);
  M = calloc(n * n, sizeof *M);
  K = calloc(n * n, sizeof *K);
  q0 = calloc(n, sizeof *q0);
  assert_non_null(M);
  assert_non_null(K);
  assert_non_null(q0);
  assert_int_equal(rcb_model_matrices(m, 0.0, M, NULL, NULL, K), RCB_OK);
  for (i = 0; i < n; i += 4) q0[i] = 1e-5; /* rigid x shift, m */
  assert_int_equal(rcb_transient_create(&t, m, 0, NULL, NULL), RCB_OK);
  for (k = 0; k < 2; k++) {
    double rtol = k ? 1e-9 : 1e-6, t_end = fast_mode() ? 0.01 : 0.05; /* s */
    assert_int_equal(rcb_transient_set_tolerances(t, rtol, 1e-5 * rtol, 1e-2 * rtol), RCB_OK);
    e.M = M;
    e.K = K;
    e.e0 = 0.0;
    e.drift = 0.0;
    assert_int_equal(rcb_transient_run(t, &still, t_end, 1e-4, q0, NULL, track_energy, &e),
                     RCB_OK);
    drift[k] = e.drift;
  }
  print_message("energy drift over %g s: %.2e (rtol 1e-6), %.2e (rtol 1e-9)\n",
                fast_mode() ? 0.01 : 0.05, drift[0], drift[1]);
  /* BDF is dissipative: the energy drifts by the accumulated local error,
   * so the drift follows the tolerance (measured 3e-3 and 1.4e-5). */
  assert_true(drift[0] < 1e-2);
  assert_true(drift[1] < 1e-4);
  assert_true(drift[1] < drift[0] / 50.0);
  rcb_transient_destroy(t);
  free(M);
  free(K);
  free(q0);
  rcb_model_destroy(m);
}

static void test_bad_input(void **state) {
  rcb_model *m = rcb_test_model_from_example("paper_system.ini");
  rcb_transient *t = NULL;
  rcb_complex Q[1];
  rcb_speed_profile p = {-1.0, 10.0, 1.0};
  (void)state;
  assert_int_equal(rcb_transient_create(&t, m, 0, NULL, NULL), RCB_OK);
  assert_int_equal(rcb_transient_steady(t, 0.0, Q), RCB_ERR_ARG);
  assert_non_null(strstr(rcb_transient_errmsg(t), "expected a finite speed > 0"));
  assert_int_equal(rcb_transient_run(t, &p, 1.0, 0.1, NULL, NULL, NULL, NULL), RCB_ERR_ARG);
  assert_int_equal(rcb_transient_set_tolerances(t, 0.0, 1e-9, 1e-9), RCB_ERR_ARG);
  assert_int_equal(rcb_transient_set_steady(t, 1e-3, 2, 100), RCB_ERR_ARG);
  rcb_transient_destroy(t);
  rcb_model_destroy(m);
}

static void test_unsupported(void **state) {
  rcb_model *m = rcb_test_model_from_example("paper_system.ini");
  rcb_transient *t = NULL;
  (void)state;
  assert_int_equal(rcb_transient_create(&t, m, 0, NULL, NULL), RCB_ERR_UNSUPPORTED);
  assert_non_null(strstr(rcb_transient_errmsg(t), "RCB_WITH_SUNDIALS=OFF"));
  rcb_transient_destroy(t);
  rcb_model_destroy(m);
}

int main(void) {
  const struct CMUnitTest with[] = {
      cmocka_unit_test(test_bad_input),        cmocka_unit_test(test_energy),
      cmocka_unit_test(test_tolerance_follows), cmocka_unit_test(test_runup_trend),
      cmocka_unit_test(test_steady_paper),     cmocka_unit_test(test_steady_cross_coupled),
  };
  const struct CMUnitTest without[] = {cmocka_unit_test(test_unsupported)};
  if (RCB_WITH_SUNDIALS) return cmocka_run_group_tests(with, NULL, NULL);
  return cmocka_run_group_tests(without, NULL, NULL);
}
