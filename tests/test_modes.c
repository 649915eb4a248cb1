/*
 * Damped modes, Campbell data and critical speeds against closed forms:
 *  - Euler-Bernoulli (and Rayleigh) pinned-pinned slender beam;
 *  - Timoshenko pinned-pinned stocky beam (frequency equation with shear and
 *    rotary inertia), showing the Euler value is off by more than 5 %;
 *  - free-free shaft (beta L = 4.7300), rigid-body roots left out;
 *  - rigid disk on a rigid massless-ish shaft and two isotropic bearings:
 *    translation sqrt(2k/m), conical Id w^2 -/+ Ip Omega w - k_theta = 0 for
 *    forward/backward whirl, with the whirl labels; damping ratios
 *    c/(2 sqrt(k m)) of the translational and conical modes;
 *  - critical speeds on a synthetic table and on the disk rotor (closed form
 *    Omega_c = sqrt(k_theta / (Id - Ip)) for the forward conical mode);
 *  - rcb_modes_compute and rcb_campbell allocate nothing after create.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "core/rcb_internal.h"
#include "rcb_test_util.h"

#define MAXM 400

static rcb_mode g_modes[MAXM];

/* Uniform shaft S from z = 0, nel elements; isotropic bearings of stiffness
 * kb (N/m) and damping cb (N s/m) at both ends when kb > 0. */
static rcb_model *beam(double L, double d, int nel, double kappa, double rho, double E,
                       double nu, double kb, double cb, const rcb_allocator *al) {
  rcb_model *m = NULL;
  assert_int_equal(rcb_model_create(&m, al), RCB_OK);
  assert_int_equal(rcb_model_add_material(m, "mat", rho, E, nu), RCB_OK);
  assert_int_equal(rcb_model_add_shaft(m, "S", "mat", 0.0, kappa), RCB_OK);
  assert_int_equal(rcb_model_add_segment(m, "S", L, d, 0.0, nel), RCB_OK);
  if (kb > 0) {
    rcb_bearing_coefs c;
    memset(&c, 0, sizeof c);
    c.kxx = c.kyy = kb;
    c.cxx = c.cyy = cb;
    assert_int_equal(rcb_model_add_bearing(m, "B1", "S", 0.0, &c), RCB_OK);
    assert_int_equal(rcb_model_add_bearing(m, "B2", "S", L, &c), RCB_OK);
  }
  return m;
}

static void finalize(rcb_model *m) {
  if (rcb_model_finalize(m) != RCB_OK) fail_msg("finalize: %s", rcb_model_errmsg(m));
}

static size_t modes_at(rcb_modes *e, double speed) {
  size_t n = 0;
  rcb_status st = rcb_modes_compute(e, speed, MAXM, g_modes, &n, NULL);
  if (st != RCB_OK) fail_msg("modes: %s", rcb_modes_errmsg(e));
  return n;
}

/* Index of the mode whose wd is closest to w. */
static size_t nearest(size_t n, double w) {
  size_t k, best = 0;
  for (k = 1; k < n; k++)
    if (fabs(g_modes[k].wd - w) < fabs(g_modes[best].wd - w)) best = k;
  return best;
}

/* -------------------------------------------------- beams, closed forms -- */

static void test_euler_pinned_pinned(void **state) {
  const double L = 1.0, d = 0.01, rho = 7800, E = 2.0e11;
  const double A = RCB_PI * d * d / 4, Ie = RCB_PI * d * d * d * d / 64;
  rcb_model *m = beam(L, d, 40, 0.0, rho, E, 0.3, 1e12, 0.0, NULL);
  rcb_modes *e = NULL;
  size_t n, k;
  (void)state;
  finalize(m);
  assert_int_equal(rcb_modes_create(&e, m, NULL), RCB_OK);
  n = modes_at(e, 0.0);
  assert_true(n >= 6);
  for (k = 1; k <= 3; k++) {
    double kn = (double)k * RCB_PI / L;
    double w_euler = kn * kn * sqrt(E * Ie / (rho * A));
    /* Rayleigh beam (rotary inertia, which the element always has) */
    double w_rayl = w_euler / sqrt(1.0 + Ie / A * kn * kn);
    /* isotropic at standstill: each frequency twice (x and y planes) */
    const rcb_mode *a = &g_modes[2 * (k - 1)], *b = &g_modes[2 * k - 1];
    assert_true(rcb_test_close(a->wd, w_euler, 5e-3, 0));
    assert_true(rcb_test_close(b->wd, w_euler, 5e-3, 0));
    assert_true(rcb_test_close(a->wd, w_rayl, 2e-5, 0));
    assert_true(rcb_test_close(b->wd, w_rayl, 2e-5, 0));
    /* undamped: lambda purely imaginary */
    assert_true(fabs(a->zeta) < 1e-6);
    assert_true(rcb_test_close(a->wn, a->wd, 1e-9, 0));
  }
  rcb_modes_destroy(e);
  rcb_model_destroy(m);
}

/* Lowest root w of the simply supported Timoshenko beam, mode number k:
 * (rho A w^2 - kGA q^2)(rho I w^2 - E I q^2 - kGA) - (kGA q)^2 = 0, q = k pi/L. */
static double timoshenko_ss(int k, double L, double d, double rho, double E, double nu,
                            double kappa) {
  const double A = RCB_PI * d * d / 4, Ie = RCB_PI * d * d * d * d / 64;
  const double kGA = kappa * E / (2 * (1 + nu)) * A, q = k * RCB_PI / L;
  const double a = rho * A * rho * Ie;
  const double b = -(rho * A * (E * Ie * q * q + kGA) + kGA * q * q * rho * Ie);
  const double c = kGA * E * Ie * q * q * q * q;
  const double w2 = (-b - sqrt(b * b - 4 * a * c)) / (2 * a);
  return sqrt(w2);
}

static void test_timoshenko_pinned_pinned(void **state) {
  const double L = 0.4, d = 0.1, rho = 7800, E = 2.0e11, nu = 0.3, kappa = 0.9;
  const double A = RCB_PI * d * d / 4, Ie = RCB_PI * d * d * d * d / 64;
  rcb_model *m = beam(L, d, 40, kappa, rho, E, nu, 1e14, 0.0, NULL);
  rcb_modes *e = NULL;
  size_t n;
  int k;
  (void)state;
  finalize(m);
  assert_int_equal(rcb_modes_create(&e, m, NULL), RCB_OK);
  n = modes_at(e, 0.0);
  assert_true(n >= 6);
  for (k = 1; k <= 3; k++) {
    double wt = timoshenko_ss(k, L, d, rho, E, nu, kappa);
    double we = pow(k * RCB_PI / L, 2) * sqrt(E * Ie / (rho * A));
    size_t j = (size_t)(2 * (k - 1));
    assert_true(rcb_test_close(g_modes[j].wd, wt, 5e-3, 0));
    assert_true(rcb_test_close(g_modes[j + 1].wd, wt, 5e-3, 0));
    /* shear and rotary inertia matter here */
    assert_true(fabs(we - g_modes[j].wd) > 0.05 * we);
  }
  rcb_modes_destroy(e);
  rcb_model_destroy(m);
}

static void test_free_free(void **state) {
  const double L = 1.0, d = 0.01, rho = 7800, E = 2.0e11;
  const double A = RCB_PI * d * d / 4, Ie = RCB_PI * d * d * d * d / 64;
  const double bl = 4.730040745;
  const double w1 = bl * bl / (L * L) * sqrt(E * Ie / (rho * A));
  /* rigid free rotor: Ip = 2 rho Ie L, Id = rho A L^3 / 12 + rho Ie L; the
   * gyroscopic nutation is a forward whirl at Ip Omega / Id */
  const double Ip = 2 * rho * Ie * L, Id = rho * A * L * L * L / 12 + rho * Ie * L;
  const double speed = 3000.0;
  rcb_model *m = beam(L, d, 40, 0.0, rho, E, 0.3, 0.0, 0.0, NULL);
  rcb_modes *e = NULL;
  size_t n, k, nlow = 0;
  (void)state;
  finalize(m);
  assert_int_equal(rcb_modes_create(&e, m, NULL), RCB_OK);
  /* standstill: no rigid-body root, the first is the elastic mode (twice) */
  n = modes_at(e, 0.0);
  assert_true(n >= 2);
  for (k = 0; k < n; k++) assert_true(g_modes[k].wd > 1e-3 * w1);
  assert_true(rcb_test_close(g_modes[0].wd, w1, 5e-3, 0));
  assert_true(rcb_test_close(g_modes[1].wd, w1, 5e-3, 0));
  /* at speed, the only root below 1e-2 w1 is the nutation (0.45 rad/s) */
  n = modes_at(e, speed);
  for (k = 0; k < n; k++)
    if (g_modes[k].wd < 1e-2 * w1) {
      nlow++;
      assert_true(rcb_test_close(g_modes[k].wd, Ip / Id * speed, 1e-3, 0));
      assert_int_equal(g_modes[k].whirl, RCB_WHIRL_FORWARD);
    }
  assert_int_equal(nlow, 1);
  rcb_modes_destroy(e);
  rcb_model_destroy(m);
}

/* ------------------------------------------ rigid disk on two bearings -- */

/* Shaft 0..0.4 m, nearly rigid (E = 2e13 Pa) and nearly massless (1 kg/m^3),
 * disk (mass, Id, Ip) at 0.2 m, isotropic bearings k, c at both ends. */
#define DISK_M 10.0
#define DISK_ID 0.1
#define BRG_K 1e5
#define BRG_A 0.2 /* bearing distance from the disk, m */
static rcb_model *disk_rotor(double Ip, double c, const rcb_allocator *al) {
  rcb_model *m = beam(0.4, 0.05, 4, 0.0, 1.0, 2e13, 0.3, BRG_K, c, al);
  assert_int_equal(rcb_model_add_disk(m, "D", "S", 0.2, DISK_M, DISK_ID, Ip), RCB_OK);
  finalize(m);
  return m;
}

/* Conical closed form: Id w^2 - s Ip Omega w - k_theta = 0, s = +1 forward, -1 backward. */
static double conical(double Ip, double speed, int s) {
  const double kth = 2 * BRG_K * BRG_A * BRG_A, r = s * Ip / DISK_ID;
  return 0.5 * (r * speed + sqrt(r * r * speed * speed + 4 * kth / DISK_ID));
}

static void test_gyroscopic_split(void **state) {
  const double Ip = 0.2, wt = sqrt(2 * BRG_K / DISK_M);
  rcb_model *m = disk_rotor(Ip, 0.0, NULL);
  rcb_modes *e = NULL;
  size_t n, k, kf, kb;
  double spd[4] = {0.0, 200.0, 500.0, 1000.0}, fprev = 0, bprev = 1e300;
  int s;
  rcb_complex *shapes;
  size_t ndof = rcb_model_dof_count(m);
  (void)state;
  assert_int_equal(rcb_modes_create(&e, m, NULL), RCB_OK);
  for (s = 0; s < 4; s++) {
    double wf = conical(Ip, spd[s], 1), wb = conical(Ip, spd[s], -1);
    n = modes_at(e, spd[s]);
    assert_true(n >= 4);
    kf = nearest(n, wf);
    kb = nearest(n, wb);
    assert_true(rcb_test_close(g_modes[kf].wd, wf, 5e-4, 0));
    assert_true(rcb_test_close(g_modes[kb].wd, wb, 5e-4, 0));
    /* the translational pair does not see the gyroscopic moment */
    k = nearest(n, wt);
    assert_true(rcb_test_close(g_modes[k].wd, wt, 5e-4, 0));
    if (spd[s] > 0) {
      assert_true(kf != kb);
      assert_int_equal(g_modes[kf].whirl, RCB_WHIRL_FORWARD);
      assert_int_equal(g_modes[kb].whirl, RCB_WHIRL_BACKWARD);
      assert_true(g_modes[kf].wd > fprev * (1 + 1e-3));
      assert_true(g_modes[kb].wd < bprev * (1 - 1e-3));
    }
    fprev = g_modes[kf].wd;
    bprev = g_modes[kb].wd;
  }
  /* shapes: unit largest translation, and the forward conical mode is a pure tilt
   * about the disk (x at the two bearings opposite) */
  shapes = calloc(ndof * MAXM, sizeof *shapes);
  assert_non_null(shapes);
  assert_int_equal(rcb_modes_compute(e, 500.0, MAXM, g_modes, &n, shapes), RCB_OK);
  kf = nearest(n, conical(Ip, 500.0, 1));
  {
    const rcb_complex *v = shapes + ndof * kf;
    rcb_node_info a, b, c;
    double big = 0;
    assert_int_equal(rcb_model_node_info(m, 0, &a), RCB_OK);
    assert_int_equal(rcb_model_node_info(m, 4, &b), RCB_OK);
    assert_int_equal(rcb_model_node_info(m, 2, &c), RCB_OK);
    for (k = 0; k < 5; k++) {
      rcb_node_info ni;
      assert_int_equal(rcb_model_node_info(m, k, &ni), RCB_OK);
      big = fmax(big, fmax(cabs(v[ni.dof[0]]), cabs(v[ni.dof[1]])));
    }
    assert_true(rcb_test_close(big, 1.0, 1e-12, 0));
    assert_true(cabs(v[a.dof[0]] + v[b.dof[0]]) < 1e-6);
    assert_true(cabs(v[c.dof[0]]) < 1e-6);
    /* circular forward orbit at the bearing: Y = -i X (x + iy ~ e^{+i wt}) */
    assert_true(cabs(v[a.dof[1]] + CMPLX(-cimag(v[a.dof[0]]), creal(v[a.dof[0]]))) < 1e-6);
  }
  free(shapes);
  rcb_modes_destroy(e);
  rcb_model_destroy(m);
}

static void test_damping_ratio(void **state) {
  const double c = 100.0, Ip = 0.2;
  const double zt = 2 * c / (2 * sqrt(2 * BRG_K * DISK_M));
  const double kth = 2 * BRG_K * BRG_A * BRG_A, cth = 2 * c * BRG_A * BRG_A;
  const double zc = cth / (2 * sqrt(kth * DISK_ID));
  rcb_model *m = disk_rotor(Ip, c, NULL);
  rcb_modes *e = NULL;
  size_t n, k;
  (void)state;
  assert_int_equal(rcb_modes_create(&e, m, NULL), RCB_OK);
  n = modes_at(e, 0.0);
  assert_true(n >= 4);
  /* translational pair first (141 rad/s), conical pair next (283 rad/s) */
  for (k = 0; k < 2; k++) {
    assert_true(rcb_test_close(g_modes[k].zeta, zt, 5e-4, 0));
    assert_true(rcb_test_close(g_modes[k].wn, sqrt(2 * BRG_K / DISK_M), 5e-4, 0));
    assert_true(rcb_test_close(g_modes[k].wd, g_modes[k].wn * sqrt(1 - zt * zt), 5e-4, 0));
    assert_true(rcb_test_close(g_modes[k].logdec, 2 * RCB_PI * zt / sqrt(1 - zt * zt), 5e-4, 0));
    assert_true(rcb_test_close(g_modes[2 + k].zeta, zc, 5e-4, 0));
    assert_true(rcb_test_close(g_modes[2 + k].wn, sqrt(kth / DISK_ID), 5e-4, 0));
    assert_true(rcb_test_close(creal(g_modes[k].lambda), -g_modes[k].zeta * g_modes[k].wn, 1e-12, 0));
  }
  rcb_modes_destroy(e);
  rcb_model_destroy(m);
}

/* ------------------------------------------------------ critical speeds -- */

static void test_critical_synthetic(void **state) {
  /* 3 curves over speeds 0..100: 50 + 0.2 W crosses W at 62.5 (exact for a
   * straight curve); a constant 300 never does; the third touches the line at
   * the row W = 30 and is NaN from W = 80 on. */
  double sp[11], wd[3 * 11], crit[4];
  size_t mo[4], nc, s;
  (void)state;
  for (s = 0; s < 11; s++) {
    sp[s] = 10.0 * (double)s;
    wd[0 + 3 * s] = 50 + 0.2 * sp[s];
    wd[1 + 3 * s] = 300;
    wd[2 + 3 * s] = s >= 8 ? (double)NAN : 30 + 0.5 * (sp[s] - 30);
  }
  /* third: 30 + 0.5 (W - 30) = W  ->  W = 30 exactly (a row) */
  assert_int_equal(rcb_critical_speeds(11, sp, 3, wd, 1.0, 4, crit, mo, &nc), RCB_OK);
  assert_int_equal(nc, 2);
  assert_true(rcb_test_close(crit[0], 30.0, 1e-14, 0));
  assert_int_equal(mo[0], 2);
  assert_true(rcb_test_close(crit[1], 62.5, 1e-14, 0));
  assert_int_equal(mo[1], 0);
  /* 2X line: 50 + 0.2 W = 2 W at W = 27.777..., 300 = 2 W at 150 (outside),
   * third: 15 + 0.5 W = 2 W at W = 10 (a row) */
  assert_int_equal(rcb_critical_speeds(11, sp, 3, wd, 2.0, 4, crit, mo, &nc), RCB_OK);
  assert_int_equal(nc, 2);
  assert_true(rcb_test_close(crit[0], 10.0, 1e-14, 0));
  assert_true(rcb_test_close(crit[1], 50.0 / 1.8, 1e-12, 0));
  /* room for one: the lowest is kept, and the call says more exist */
  assert_int_equal(rcb_critical_speeds(11, sp, 3, wd, 1.0, 1, crit, NULL, &nc),
                   RCB_ERR_WORKSPACE);
  assert_int_equal(nc, 1);
  assert_true(rcb_test_close(crit[0], 30.0, 1e-14, 0));
  /* speeds must increase */
  sp[3] = sp[2];
  assert_int_equal(rcb_critical_speeds(11, sp, 3, wd, 1.0, 4, crit, mo, &nc), RCB_ERR_ARG);
}

static void test_critical_model(void **state) {
  /* Ip < Id: the forward conical mode crosses 1X at sqrt(k_theta / (Id - Ip)),
   * the backward one at sqrt(k_theta / (Id + Ip)), the translational pair at
   * sqrt(2 k / m). */
  const double Ip = 0.05, kth = 2 * BRG_K * BRG_A * BRG_A;
  const double cf = sqrt(kth / (DISK_ID - Ip)), cb = sqrt(kth / (DISK_ID + Ip));
  const double ct = sqrt(2 * BRG_K / DISK_M);
  enum { NS = 26, NM = 4 };
  double sp[NS], wd[NM * NS], lg[NM * NS], crit[8];
  rcb_whirl wh[NM * NS];
  size_t mo[8], nc, s, n, k, nf = 0;
  rcb_model *m = disk_rotor(Ip, 0.0, NULL);
  rcb_modes *e = NULL;
  (void)state;
  assert_int_equal(rcb_modes_create(&e, m, NULL), RCB_OK);
  for (s = 0; s < NS; s++) sp[s] = 40.0 * (double)s;
  assert_int_equal(rcb_campbell(e, NS, sp, NM, wd, lg, wh), RCB_OK);
  for (s = 0; s < NM * NS; s++) assert_true(fabs(lg[s]) < 1e-6);
  /* the top curve is the forward conical mode at every speed > 0 */
  for (s = 1; s < NS; s++) {
    assert_true(rcb_test_close(wd[3 + NM * s], conical(Ip, sp[s], 1), 5e-4, 0));
    assert_int_equal(wh[3 + NM * s], RCB_WHIRL_FORWARD);
  }
  assert_int_equal(rcb_critical_speeds(NS, sp, NM, wd, 1.0, 8, crit, mo, &nc), RCB_OK);
  assert_int_equal(nc, 4); /* two translational, backward, forward */
  assert_true(rcb_test_close(crit[0], ct, 1e-3, 0));
  assert_true(rcb_test_close(crit[1], ct, 1e-3, 0));
  assert_true(rcb_test_close(crit[2], cb, 2e-3, 0));
  assert_true(rcb_test_close(crit[3], cf, 2e-3, 0));
  assert_int_equal(mo[3], 3);
  /* at the interpolated speed, the forward mode is on the 1X line to within
   * the interpolation error (h^2 |wd''| / 8 ~ 0.04 rad/s here) */
  n = modes_at(e, crit[3]);
  for (k = 0; k < n; k++)
    if (g_modes[k].whirl == RCB_WHIRL_FORWARD && fabs(g_modes[k].wd - crit[3]) < 1.0) nf++;
  assert_int_equal(nf, 1);
  k = nearest(n, crit[3]);
  assert_true(fabs(g_modes[k].wd - crit[3]) < 0.2);
  rcb_modes_destroy(e);
  rcb_model_destroy(m);
}

/* ------------------------------------------- near-critical root filter -- */

static void test_paper_max_zeta(void **state) {
  /* paper system: qz_k = 22.989e-6 s overdamps every mode above 2/qz_k; at
   * speed their roots near -1/qz_k pick up tiny wd and would come first */
  rcb_model *m = rcb_test_model_from_example("paper_system.ini");
  rcb_modes *e = NULL;
  const double w300 = 300.0 * 2 * RCB_PI / 60; /* 300 rpm */
  size_t n, n0, k;
  double w0;
  (void)state;
  assert_int_equal(rcb_modes_create(&e, m, NULL), RCB_OK);
  assert_int_equal(rcb_modes_set_max_zeta(e, 1.0), RCB_OK); /* every root, as ROSS */
  n0 = modes_at(e, 0.0);
  w0 = g_modes[0].wd;
  assert_true(w0 > 100.0 && g_modes[0].zeta < 0.5); /* a physical bending mode */
  n = modes_at(e, w300);
  assert_true(g_modes[0].wd < 0.1 * w0 && g_modes[0].zeta > 0.999);
  assert_int_equal(rcb_modes_set_max_zeta(e, 0.0), RCB_ERR_ARG);
  assert_int_equal(rcb_modes_set_max_zeta(e, 0.99), RCB_OK);
  /* at standstill nothing changes */
  assert_int_equal(modes_at(e, 0.0), n0);
  assert_true(g_modes[0].wd == w0);
  /* at speed, the filtered list starts with the same bending mode, slightly
   * split by the gyroscopic moments, and every root kept is below 0.99 */
  k = modes_at(e, w300);
  assert_true(k < n);
  assert_true(rcb_test_close(g_modes[0].wd, w0, 0.02, 0));
  for (n = 0; n < k; n++) assert_true(g_modes[n].zeta <= 0.99);
  rcb_modes_destroy(e);
  rcb_model_destroy(m);
}

/* A fresh object (what a firmware caller gets without a setter) starts from
 * RCB_MODES_MAX_ZETA_DEFAULT, rcbtool's and Python's value: at 300 rpm the
 * paper system's first mode is the bending mode near 150 Hz, not a root of
 * the overdamped cluster with wd < 0.1 w0 and zeta ~ 1 (issue #17). */
static void test_default_max_zeta(void **state) {
  rcb_model *m = rcb_test_model_from_example("paper_system.ini");
  rcb_modes *e = NULL;
  const double w300 = 300.0 * 2 * RCB_PI / 60;
  size_t n;
  (void)state;
  assert_int_equal(rcb_modes_create(&e, m, NULL), RCB_OK);
  assert_true(rcb_modes_get_max_zeta(e) == RCB_MODES_MAX_ZETA_DEFAULT);
  assert_true(RCB_MODES_MAX_ZETA_DEFAULT < 1.0);
  n = modes_at(e, w300);
  assert_true(n > 0);
  assert_true(g_modes[0].zeta < 0.5);
  assert_true(g_modes[0].wd / (2 * RCB_PI) > 140.0 && g_modes[0].wd / (2 * RCB_PI) < 160.0);
  rcb_modes_destroy(e);
  rcb_model_destroy(m);
}

/* ----------------------------------------------------------- allocation -- */

static void test_no_allocation(void **state) {
  rcb_test_counter cnt = {0, 0};
  rcb_allocator al = rcb_test_counting_allocator(&cnt);
  rcb_model *m = disk_rotor(0.2, 50.0, &al);
  rcb_modes *e = NULL;
  size_t n, ndof = rcb_model_dof_count(m);
  double sp[5] = {0, 100, 200, 300, 400}, wd[3 * 5], lg[3 * 5];
  rcb_whirl wh[3 * 5];
  rcb_complex *shapes = calloc(ndof * MAXM, sizeof *shapes);
  (void)state;
  assert_non_null(shapes);
  assert_int_equal(rcb_modes_create(&e, m, &al), RCB_OK);
  assert_true(cnt.allocs > 0); /* the hooks are really used */
  cnt.allocs = cnt.frees = 0;
  assert_int_equal(rcb_modes_compute(e, 300.0, MAXM, g_modes, &n, shapes), RCB_OK);
  assert_true(n > 0);
  assert_int_equal(rcb_campbell(e, 5, sp, 3, wd, lg, wh), RCB_OK);
  assert_int_equal(cnt.allocs, 0);
  assert_int_equal(cnt.frees, 0);
  rcb_modes_destroy(e);
  rcb_model_destroy(m);
  assert_true(cnt.frees > 0);
  free(shapes);
}

static void test_errors(void **state) {
  rcb_model *m = NULL;
  rcb_modes *e = NULL;
  size_t n;
  (void)state;
  /* not finalized */
  m = beam(1.0, 0.01, 4, 0.0, 7800, 2e11, 0.3, 0.0, 0.0, NULL);
  assert_int_equal(rcb_modes_create(&e, m, NULL), RCB_ERR_STATE);
  assert_null(e);
  finalize(m);
  assert_int_equal(rcb_modes_create(&e, m, NULL), RCB_OK);
  assert_int_equal(rcb_modes_compute(e, NAN, MAXM, g_modes, &n, NULL), RCB_ERR_ARG);
  assert_true(strstr(rcb_modes_errmsg(e), "rad/s") != NULL);
  assert_int_equal(rcb_modes_compute(e, 0.0, 0, NULL, &n, NULL), RCB_OK);
  assert_int_equal(n, 0);
  rcb_modes_destroy(e);
  rcb_model_destroy(m);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_euler_pinned_pinned),
      cmocka_unit_test(test_timoshenko_pinned_pinned),
      cmocka_unit_test(test_free_free),
      cmocka_unit_test(test_gyroscopic_split),
      cmocka_unit_test(test_damping_ratio),
      cmocka_unit_test(test_critical_synthetic),
      cmocka_unit_test(test_critical_model),
      cmocka_unit_test(test_paper_max_zeta),
      cmocka_unit_test(test_default_max_zeta),
      cmocka_unit_test(test_no_allocation),
      cmocka_unit_test(test_errors),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
