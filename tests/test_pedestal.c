/*
 * Flexible supports (a pedestal mass on springs and dampers between a bearing
 * and ground) and the speed factor: closed-form 2-DOF FRF of a rigid rotor on
 * a pedestal, the stiff massless pedestal limit equal to the grounded bearing,
 * dense = banded = sparse, INI round trip, parameters by name; the speed
 * factor equal to evaluating at the factored speed, and ignored by the
 * unbalance response.
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

/* examples/paper_system.ini with `extra` lines put into [bearing B2]. */
static rcb_model *paper_with(const char *extra) {
  return rcb_test_model_edited("paper_system.ini", "[bearing B2]", extra);
}

/* H(outs / in) at omega (rad/s), speed (rad/s) with a given solver. */
static void frf_at(const rcb_model *m, const char *const *outs, size_t no, const char *in,
                   double omega, double speed, rcb_solver_kind kind, rcb_complex *H) {
  rcb_dof od[8], id;
  rcb_frf *f = NULL;
  size_t o;
  for (o = 0; o < no; o++) assert_int_equal(rcb_model_find_dof(m, outs[o], &od[o]), RCB_OK);
  assert_int_equal(rcb_model_find_dof(m, in, &id), RCB_OK);
  assert_int_equal(rcb_frf_create(&f, m, no, od, 1, &id, kind, NULL), RCB_OK);
  if (rcb_frf_eval(f, omega, speed, RCB_RECEPTANCE, H)) fail_msg("%s", rcb_frf_errmsg(f));
  rcb_frf_destroy(f);
}

static double rel(double complex a, double complex b) {
  return cabs(a - b) / fmax(cabs(a), cabs(b));
}

/* A rigid rotor (a disk on a massless shaft end) on one bearing on a pedestal:
 * the series 2-DOF system, in x and y (different pedestal stiffnesses). */
static void test_rigid_rotor_closed_form(void **state) {
  static const char *ini =
      "[material s]\ndensity = 1e-9\nyoung = 2.1e11\npoisson = 0.3\n"
      "[shaft R]\nmaterial = s\nstart = 0\nshear_factor = 0.9\nsegment = 0.1 0.05 0 1\n"
      "[disk D]\nat = R 0\nmass = 12.5\nId = 0.02\nIp = 0.03\n"
      "[bearing B]\nat = R 0\nkxx = 3e6\nkyy = 3e6\ncxx = 150\ncyy = 150\n"
      "pedestal_mass = 4.2\npedestal_kxx = 8e6\npedestal_kyy = 2e6\n"
      "pedestal_cxx = 90\npedestal_cyy = 40\n";
  static const char *const outs[2] = {"D.x", "B.ped.x"};
  static const char *const outsy[2] = {"D.y", "B.ped.y"};
  const double m = 12.5, mp = 4.2, kb = 3e6, cb = 150, kp[2] = {8e6, 2e6}, cp[2] = {90, 40};
  rcb_model *md = rcb_test_model_from_string(ini);
  double w;
  int dir;
  (void)state;
  assert_int_equal(rcb_model_dof_count(md), 8u + 2u);
  for (dir = 0; dir < 2; dir++)
    for (w = 50.0; w < 5000.0; w *= 1.37) {
      rcb_complex H[2];
      double complex zb = CMPLX(kb, w * cb), zp = CMPLX(kp[dir], w * cp[dir]);
      double complex z11 = zb - w * w * m, z22 = zb + zp - w * w * mp, det = z11 * z22 - zb * zb;
      frf_at(md, dir ? outsy : outs, 2, dir ? "D.y" : "D.x", w, 0.0, RCB_SOLVER_DENSE, H);
      assert_true(rel(H[0], z22 / det) < 1e-8);
      assert_true(rel(H[1], zb / det) < 1e-8);
    }
  rcb_model_destroy(md);
}

/* A huge pedestal stiffness with no mass is the bearing to ground. */
static void test_stiff_massless_limit(void **state) {
  static const char *const outs[4] = {"DA.x", "DB.y", "C.A.x", "P1.y"};
  rcb_model *g = rcb_test_model_from_example("paper_system.ini");
  rcb_model *p = paper_with("pedestal_kxx = 1e19\npedestal_kyy = 1e19\n");
  double w, worst = 0;
  (void)state;
  assert_int_equal(rcb_model_dof_count(p), rcb_model_dof_count(g) + 2);
  for (w = 2 * RCB_PI * 20; w < 2 * RCB_PI * 2000; w *= 1.21) {
    rcb_complex Hg[4], Hp[4];
    int o;
    frf_at(g, outs, 4, "DA.x", w, 10000 * RPM, RCB_SOLVER_DENSE, Hg);
    frf_at(p, outs, 4, "DA.x", w, 10000 * RPM, RCB_SOLVER_DENSE, Hp);
    for (o = 0; o < 4; o++) worst = fmax(worst, rel(Hg[o], Hp[o]));
  }
  print_message("  stiff massless pedestal vs ground: worst relative difference %.2e\n", worst);
  assert_true(worst < 1e-8);
  rcb_model_destroy(g);
  rcb_model_destroy(p);
}

/* Dense, banded and sparse agree; the band stays narrow. */
static void test_solvers_agree(void **state) {
  static const char *const outs[4] = {"DA.x", "B2.ped.x", "B2.ped.y", "DB.y"};
  rcb_model *g = rcb_test_model_from_example("paper_system.ini");
  rcb_model *p = paper_with("pedestal_mass = 8\npedestal_kxx = 2e7\npedestal_kyy = 3e7\n"
                            "pedestal_cxx = 400\npedestal_cyy = 300\n");
  double w;
  (void)state;
  assert_true(p->bandwidth <= g->bandwidth + 2);
  for (w = 2 * RCB_PI * 30; w < 2 * RCB_PI * 1500; w *= 1.7) {
    rcb_complex Hd[4], Hb[4];
    int o;
    frf_at(p, outs, 4, "B2.ped.x", w, 8000 * RPM, RCB_SOLVER_DENSE, Hd);
    frf_at(p, outs, 4, "B2.ped.x", w, 8000 * RPM, RCB_SOLVER_BANDED, Hb);
    for (o = 0; o < 4; o++) assert_true(rel(Hd[o], Hb[o]) < 1e-10);
#if RCB_WITH_SUITESPARSE
    {
      rcb_complex Hs[4];
      frf_at(p, outs, 4, "B2.ped.x", w, 8000 * RPM, RCB_SOLVER_SPARSE, Hs);
      for (o = 0; o < 4; o++) assert_true(rel(Hd[o], Hs[o]) < 1e-10);
    }
#endif
  }
  rcb_model_destroy(g);
  rcb_model_destroy(p);
}

/* The pedestal is written back and its parameters are addressable. */
static void test_ini_and_params(void **state) {
  rcb_model *p = paper_with("pedestal_mass = 8\npedestal_kxx = 2e7\npedestal_kyy = 3e7\n"
                            "pedestal_cxx = 400\n");
  rcb_model *q, *g = rcb_test_model_from_example("paper_system.ini");
  rcb_dof d;
  size_t need = 0, n = rcb_model_dof_count(p), i;
  char *txt;
  double v, *A, *B;
  (void)state;
  assert_int_equal(rcb_model_get_param(p, "bearing.B2.pedestal_kyy", &v), RCB_OK);
  assert_true(v == 3e7);
  assert_int_equal(rcb_model_set_param(p, "bearing.B2.pedestal_k", 5e7), RCB_OK);
  assert_int_equal(rcb_model_get_param(p, "bearing.B2.pedestal_kxx", &v), RCB_OK);
  assert_true(v == 5e7);
  assert_int_equal(rcb_model_set_param(p, "bearing.B2.pedestal_mass", 9), RCB_OK);
  assert_int_equal(rcb_model_set_param(p, "bearing.B2.pedestal_mass", -1), RCB_ERR_ARG);
  assert_int_equal(rcb_model_get_param(p, "bearing.B1.pedestal_mass", &v), RCB_ERR_NOT_FOUND);
  assert_non_null(strstr(rcb_model_errmsg(p), "no pedestal"));
  assert_int_equal(rcb_model_param_count(p), rcb_model_param_count(g) + 5);
  assert_int_equal(rcb_model_set_param(p, "speed.factor", 1.25), RCB_OK);
  assert_int_equal(rcb_model_find_dof(p, "B2.ped.y", &d), RCB_OK);
  assert_true(d.node >= rcb_model_node_count(p));
  assert_int_equal(rcb_model_find_dof(p, "B2.ped.rx", &d), RCB_ERR_ARG);
  rcb_model_write_ini(p, NULL, 0, &need);
  txt = malloc(need);
  assert_int_equal(rcb_model_write_ini(p, txt, need, &need), RCB_OK);
  assert_non_null(strstr(txt, "pedestal_mass = 9"));
  assert_non_null(strstr(txt, "speed_factor = 1.25"));
  q = rcb_test_model_from_string(txt);
  assert_int_equal(rcb_model_dof_count(q), n);
  A = calloc(4 * n * n, sizeof *A);
  B = calloc(4 * n * n, sizeof *B);
  assert_int_equal(rcb_model_matrices(p, 900.0, A, A + n * n, A + 2 * n * n, A + 3 * n * n), 0);
  assert_int_equal(rcb_model_matrices(q, 900.0, B, B + n * n, B + 2 * n * n, B + 3 * n * n), 0);
  for (i = 0; i < 4 * n * n; i++) assert_true(A[i] == B[i]);
  free(A);
  free(B);
  free(txt);
  rcb_model_destroy(p);
  rcb_model_destroy(q);
  rcb_model_destroy(g);
}

/* Speed factor f at speed W equals speed f W in the FRF; the unbalance
 * response ignores it. */
static void test_speed_factor(void **state) {
  static const char *const outs[3] = {"DA.x", "DB.y", "P1.x"};
  rcb_model *a = rcb_test_model_from_example("paper_system.ini");
  rcb_model *b = rcb_test_model_from_example("paper_system.ini");
  rcb_dof od[3];
  rcb_frf *fa = NULL, *fb = NULL;
  rcb_complex Ha[3], Hb[3], Qa[3], Qb[3];
  const double f = 1.37, W = 6000 * RPM;
  int o;
  (void)state;
  assert_int_equal(rcb_model_set_param(b, "speed.factor", f), RCB_OK);
  frf_at(a, outs, 3, "DA.x", 900.0, f * W, RCB_SOLVER_DENSE, Ha);
  frf_at(b, outs, 3, "DA.x", 900.0, W, RCB_SOLVER_DENSE, Hb);
  for (o = 0; o < 3; o++) assert_true(rel(Ha[o], Hb[o]) < 1e-12);
  frf_at(a, outs, 3, "DA.x", 900.0, W, RCB_SOLVER_DENSE, Ha);
  assert_true(rel(Ha[0], Hb[0]) > 1e-6); /* the factor does change the FRF */
  for (o = 0; o < 3; o++) assert_int_equal(rcb_model_find_dof(a, outs[o], &od[o]), RCB_OK);
  assert_int_equal(rcb_frf_create(&fa, a, 3, od, 0, NULL, RCB_SOLVER_DENSE, NULL), RCB_OK);
  assert_int_equal(rcb_frf_create(&fb, b, 3, od, 0, NULL, RCB_SOLVER_DENSE, NULL), RCB_OK);
  assert_int_equal(rcb_frf_unbalance(fa, W, Qa), RCB_OK);
  assert_int_equal(rcb_frf_unbalance(fb, W, Qb), RCB_OK);
  for (o = 0; o < 3; o++) assert_true(rel(Qa[o], Qb[o]) < 1e-12);
  assert_int_equal(rcb_model_set_param(b, "speed.factor", 0.0), RCB_ERR_ARG);
  rcb_frf_destroy(fa);
  rcb_frf_destroy(fb);
  rcb_model_destroy(a);
  rcb_model_destroy(b);
}

/* The time integration takes constant bearings on pedestals, and refuses a
 * speed factor (it would drive the unbalance at the stated speed). */
static void test_transient_scope(void **state) {
  rcb_model *p = paper_with("pedestal_mass = 8\npedestal_kxx = 2e7\npedestal_kyy = 3e7\n");
  rcb_transient *t = NULL;
  rcb_dof d;
  (void)state;
  assert_int_equal(rcb_model_find_dof(p, "B2.ped.x", &d), RCB_OK);
#if RCB_WITH_SUNDIALS
  assert_int_equal(rcb_transient_create(&t, p, 1, &d, NULL), RCB_OK);
  rcb_transient_destroy(t);
  t = NULL;
#endif
  assert_int_equal(rcb_model_set_param(p, "speed.factor", 1.1), RCB_OK);
  assert_int_equal(rcb_transient_create(&t, p, 1, &d, NULL), RCB_ERR_UNSUPPORTED);
  assert_non_null(strstr(rcb_transient_errmsg(t), "speed factor"));
  rcb_transient_destroy(t);
  rcb_model_destroy(p);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_rigid_rotor_closed_form),
      cmocka_unit_test(test_stiff_massless_limit),
      cmocka_unit_test(test_solvers_agree),
      cmocka_unit_test(test_ini_and_params),
      cmocka_unit_test(test_speed_factor),
      cmocka_unit_test(test_transient_scope),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
