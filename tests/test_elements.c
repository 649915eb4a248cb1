/*
 * Element matrices and assembly against closed forms:
 *  - symmetry of M and K, skew-symmetry of G, M positive definite;
 *  - rigid-body motions of a free shaft: K v = 0, v^T M v = mass and
 *    diametral inertia, v^T G v = polar inertia;
 *  - static deflection of a cantilever with shear (Timoshenko elements are
 *    exact for end loads): P L^3/(3 E I) + P L/(kappa G A);
 *  - disks and bearings land on the right rows;
 *  - coupling blocks of the five models, bearing blocks (to ground, on a
 *    pedestal), pedestal blocks and the bearing-table interpolation.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>
#include <lapacke.h>

#include "core/rcb_internal.h"
#include "rcb_test_util.h"

static const double rho = 7800, E = 2.1e11, nu = 0.3;

static void elem(double L, double od, double id, double kappa, double *Me, double *Ge,
                 double *Ke) {
  rcb_beam_props p = {L, od, id, rho, E, nu, kappa};
  rcb_shaft_element(&p, Me, Ge, Ke);
}

static void test_element_symmetry(void **state) {
  double Me[64], Ge[64], Ke[64], Mc[64];
  int i, j;
  (void)state;
  elem(0.05, 0.04, 0.01, 0.8, Me, Ge, Ke);
  for (i = 0; i < 8; i++)
    for (j = 0; j < 8; j++) {
      assert_true(rcb_test_close(Me[i + 8 * j], Me[j + 8 * i], 1e-14, 1e-300));
      assert_true(rcb_test_close(Ke[i + 8 * j], Ke[j + 8 * i], 1e-14, 1e-300));
      assert_true(rcb_test_close(Ge[i + 8 * j], -Ge[j + 8 * i], 1e-14, 1e-300));
    }
  memcpy(Mc, Me, sizeof Mc);
  assert_int_equal(LAPACKE_dpotrf(LAPACK_COL_MAJOR, 'L', 8, Mc, 8), 0);
}

/* Uniform free shaft of n elements, length L, built through the public API. */
static rcb_model *free_shaft(double L, double od, double id, int n, double kappa) {
  rcb_model *m = NULL;
  assert_int_equal(rcb_model_create(&m, NULL), RCB_OK);
  assert_int_equal(rcb_model_add_material(m, "steel", rho, E, nu), RCB_OK);
  assert_int_equal(rcb_model_add_shaft(m, "S", "steel", 0.0, kappa), RCB_OK);
  assert_int_equal(rcb_model_add_segment(m, "S", L, od, id, n), RCB_OK);
  return m;
}

/* Rigid motions on [x, y, rx, ry] per node at axial position z: translation
 * in x; tilt about +y (x = z theta, ry = theta); tilt about +x (y = -z theta,
 * rx = theta). */
static void rigid(const rcb_model *m, int which, double *v) {
  size_t i, n = rcb_model_node_count(m);
  for (i = 0; i < n; i++) {
    rcb_node_info ni;
    assert_int_equal(rcb_model_node_info(m, i, &ni), RCB_OK);
    v[ni.dof[0]] = which == 0 ? 1.0 : which == 1 ? ni.z : 0.0;
    v[ni.dof[1]] = which == 2 ? -ni.z : 0.0;
    v[ni.dof[2]] = which == 2 ? 1.0 : 0.0;
    v[ni.dof[3]] = which == 1 ? 1.0 : 0.0;
  }
}

static double quad(const double *A, const double *u, const double *v, size_t n) {
  size_t i, j;
  double s = 0;
  for (j = 0; j < n; j++)
    for (i = 0; i < n; i++) s += u[i] * A[i + n * j] * v[j];
  return s;
}

static void test_rigid_body(void **state) {
  const double L = 0.8, od = 0.05, id = 0.02;
  const double A = RCB_PI * (od * od - id * id) / 4, Ia = RCB_PI * (pow(od, 4) - pow(id, 4)) / 64;
  const double mass = rho * A * L;
  /* about z = 0: rho A L^3 / 3 plus the rotary inertia rho I L */
  const double Id0 = rho * A * L * L * L / 3 + rho * Ia * L;
  const double Ip = rho * 2 * Ia * L;
  rcb_model *m = free_shaft(L, od, id, 16, 0.8);
  size_t n, i, k;
  double *M, *G, *K, *v[3], *Kv;
  (void)state;
  assert_int_equal(rcb_model_finalize(m), RCB_OK);
  n = rcb_model_dof_count(m);
  assert_int_equal(n, 68);
  M = calloc(n * n, sizeof *M);
  G = calloc(n * n, sizeof *G);
  K = calloc(n * n, sizeof *K);
  Kv = calloc(n, sizeof *Kv);
  for (k = 0; k < 3; k++) {
    v[k] = calloc(n, sizeof *v[k]);
    rigid(m, (int)k, v[k]);
  }
  assert_int_equal(rcb_model_matrices(m, 0.0, M, NULL, G, K), RCB_OK);
  for (k = 0; k < 3; k++) {
    double kmax = 0;
    for (i = 0; i < n * n; i++) kmax = fmax(kmax, fabs(K[i]));
    for (i = 0; i < n; i++) {
      size_t j;
      Kv[i] = 0;
      for (j = 0; j < n; j++) Kv[i] += K[i + n * j] * v[k][j];
      assert_true(fabs(Kv[i]) < 1e-9 * kmax);
    }
  }
  assert_true(rcb_test_close(quad(M, v[0], v[0], n), mass, 1e-12, 0));
  assert_true(rcb_test_close(quad(M, v[1], v[1], n), Id0, 1e-12, 0));
  assert_true(rcb_test_close(quad(M, v[2], v[2], n), Id0, 1e-12, 0));
  /* gyroscopic coupling of the two tilts: +Ip from rx to ry (as a disk) */
  assert_true(rcb_test_close(quad(G, v[2], v[1], n), Ip, 1e-12, 0));
  assert_true(rcb_test_close(quad(G, v[1], v[2], n), -Ip, 1e-12, 0));
  for (k = 0; k < 3; k++) free(v[k]);
  free(M);
  free(G);
  free(K);
  free(Kv);
  rcb_model_destroy(m);
}

/* Clamp node 0 (drop its rows), load the tip, solve K u = f. */
static double cantilever_tip(double L, double od, double id, int nel, double kappa, double P,
                             int dir) {
  rcb_model *m = free_shaft(L, od, id, nel, kappa);
  size_t n, r, i, j;
  double *K, *Kr, *f, tip;
  rcb_node_info ni;
  assert_int_equal(rcb_model_finalize(m), RCB_OK);
  n = rcb_model_dof_count(m);
  r = n - 4;
  K = calloc(n * n, sizeof *K);
  Kr = calloc(r * r, sizeof *Kr);
  f = calloc(r, sizeof *f);
  assert_int_equal(rcb_model_matrices(m, 0.0, NULL, NULL, NULL, K), RCB_OK);
  for (j = 0; j < r; j++)
    for (i = 0; i < r; i++) Kr[i + r * j] = K[(i + 4) + n * (j + 4)];
  assert_int_equal(rcb_model_node_info(m, (size_t)nel, &ni), RCB_OK);
  f[ni.dof[dir] - 4] = P;
  assert_int_equal(LAPACKE_dposv(LAPACK_COL_MAJOR, 'L', (lapack_int)r, 1, Kr, (lapack_int)r, f,
                                 (lapack_int)r),
                   0);
  tip = f[ni.dof[dir] - 4];
  free(K);
  free(Kr);
  free(f);
  rcb_model_destroy(m);
  return tip;
}

static void test_cantilever_shear(void **state) {
  const double L = 0.3, od = 0.1, id = 0.04, kappa = 0.75, P = 1e4;
  const double A = RCB_PI * (od * od - id * id) / 4, Ia = RCB_PI * (pow(od, 4) - pow(id, 4)) / 64;
  const double Gs = E / (2 * (1 + nu));
  const double bending = P * L * L * L / (3 * E * Ia), shear = P * L / (kappa * Gs * A);
  double ux, uy;
  (void)state;
  /* stocky beam: shear is ~9 % of the deflection, so it is really tested */
  assert_true(shear > 0.05 * bending);
  ux = cantilever_tip(L, od, id, 3, kappa, P, 0);
  uy = cantilever_tip(L, od, id, 7, kappa, P, 1);
  assert_true(rcb_test_close(ux, bending + shear, 1e-9, 0));
  assert_true(rcb_test_close(uy, bending + shear, 1e-9, 0));
  /* without shear: Euler-Bernoulli */
  ux = cantilever_tip(L, od, id, 2, 0.0, P, 0);
  assert_true(rcb_test_close(ux, bending, 1e-9, 0));
}

static void test_disk_and_bearing_rows(void **state) {
  rcb_model *m = free_shaft(1.0, 0.05, 0.0, 4, 0.9);
  rcb_bearing_coefs c = {1e7, 2e5, -3e5, 2e7, 10, 1, 2, 20};
  double Md, Id, Ip, *M, *K, *C, *G, *M0;
  size_t n, r;
  rcb_dof d = {2, RCB_DIR_X};
  (void)state;
  assert_int_equal(rcb_disk_from_geometry(7800, 0.3, 0.05, 0.04, &Md, &Id, &Ip), RCB_OK);
  /* annulus: m = rho pi (D^2 - d^2) w / 4 */
  assert_true(rcb_test_close(Md, 7800 * RCB_PI * (0.09 - 0.0025) * 0.04 / 4, 1e-14, 0));
  assert_int_equal(rcb_model_add_disk(m, "D", "S", 0.5, Md, Id, Ip), RCB_OK);
  assert_int_equal(rcb_model_add_bearing(m, "B", "S", 0.5, &c), RCB_OK);
  assert_int_equal(rcb_model_finalize(m), RCB_OK);
  n = rcb_model_dof_count(m);
  M = calloc(n * n, sizeof *M);
  M0 = calloc(n * n, sizeof *M0);
  K = calloc(n * n, sizeof *K);
  C = calloc(n * n, sizeof *C);
  G = calloc(n * n, sizeof *G);
  assert_int_equal(rcb_model_matrices(m, 0.0, M, C, G, K), RCB_OK);
  assert_int_equal(rcb_model_dof_index(m, d, &r), RCB_OK);
  /* shaft-only reference */
  {
    rcb_model *s = free_shaft(1.0, 0.05, 0.0, 4, 0.9);
    double *Ks = calloc(n * n, sizeof *Ks), *Gs = calloc(n * n, sizeof *Gs);
    assert_int_equal(rcb_model_finalize(s), RCB_OK);
    assert_int_equal(rcb_model_matrices(s, 0.0, M0, NULL, Gs, Ks), RCB_OK);
    assert_true(rcb_test_close(M[r + n * r] - M0[r + n * r], Md, 1e-12, 0));
    assert_true(rcb_test_close(M[(r + 2) + n * (r + 2)] - M0[(r + 2) + n * (r + 2)], Id, 1e-12, 0));
    assert_true(rcb_test_close(G[(r + 2) + n * (r + 3)] - Gs[(r + 2) + n * (r + 3)], Ip, 1e-12, 0));
    assert_true(rcb_test_close(K[r + n * (r + 1)] - Ks[r + n * (r + 1)], 2e5, 1e-12, 0));
    assert_true(rcb_test_close(K[(r + 1) + n * r] - Ks[(r + 1) + n * r], -3e5, 1e-12, 0));
    assert_true(rcb_test_close(C[(r + 1) + n * (r + 1)], 20, 1e-12, 0));
    assert_true(rcb_test_close(C[(r + 1) + n * r], 2, 1e-12, 0));
    free(Ks);
    free(Gs);
    rcb_model_destroy(s);
  }
  free(M);
  free(M0);
  free(K);
  free(C);
  free(G);
  rcb_model_destroy(m);
}

/* Tabulated bearing: linear interpolation between rows, constant outside. */
static void test_bearing_table(void **state) {
  rcb_model *m = free_shaft(1.0, 0.05, 0.0, 2, 0.9);
  const double speeds[3] = {0.0, 100.0, 300.0};
  rcb_bearing_coefs c[3] = {{1e6, 0, 0, 2e6, 10, 0, 0, 20},
                            {3e6, 1e5, -1e5, 4e6, 30, 0, 0, 40},
                            {7e6, 3e5, -3e5, 8e6, 70, 0, 0, 80}};
  double K[144], C[144], K0[144];
  size_t r;
  rcb_dof d = {1, RCB_DIR_X};
  (void)state;
  assert_int_equal(rcb_model_add_bearing_table(m, "B", "S", 0.5, 3, speeds, c), RCB_OK);
  assert_int_equal(rcb_model_finalize(m), RCB_OK);
  assert_int_equal(rcb_model_dof_count(m), 12);
  assert_int_equal(rcb_model_dof_index(m, d, &r), RCB_OK);
  assert_int_equal(rcb_model_matrices(m, -50.0, NULL, C, NULL, K0), RCB_OK);
  K0[r + 12 * r] -= 1e6; /* shaft-only stiffness at that entry */
  assert_int_equal(rcb_model_matrices(m, 200.0, NULL, C, NULL, K), RCB_OK);
  assert_true(rcb_test_close(K[r + 12 * r] - K0[r + 12 * r], 5e6, 1e-12, 0));
  assert_true(rcb_test_close(K[r + 12 * (r + 1)], 2e5, 1e-12, 0));
  assert_true(rcb_test_close(C[(r + 1) + 12 * (r + 1)], 60, 1e-12, 0));
  assert_int_equal(rcb_model_matrices(m, 1e4, NULL, C, NULL, K), RCB_OK);
  assert_true(rcb_test_close(K[r + 12 * r] - K0[r + 12 * r], 7e6, 1e-12, 0));
  rcb_model_destroy(m);
}

/* Coupling block of each model (paper section 3): a relative motion of the
 * stations, unit in one DOF, pulls the two back with the coefficient the
 * model uses (kt for x, y; kr for rx, ry; damping alike) and 0 for those it
 * does not; a common motion of both stations (any vector) loads nothing. */
static void test_coupling_element(void **state) {
  /* kt, kr, ct, cr used by kramer_1, kramer_2, nelson_crandall_1, _2, rigid */
  static const int uses[5][4] = {
      {0, 0, 0, 0}, {0, 1, 0, 1}, {1, 1, 0, 0}, {1, 1, 1, 1}, {0, 0, 0, 0}};
  rcb_coupling_params p = {2e5, 3e3, 40.0, 0.5, {0}, {0}, {0}};
  const double val[4] = {2e5, 3e3, 40.0, 0.5};
  double Ke[64], Ce[64];
  int t, a, b, k;
  (void)state;
  for (t = 0; t < 5; t++) {
    rcb_coupling_element((rcb_coupling_model)t, &p, Ke, Ce);
    for (a = 0; a < 4; a++) {
      double kv = uses[t][a < 2 ? 0 : 1] ? val[a < 2 ? 0 : 1] : 0.0;
      double cv = uses[t][a < 2 ? 2 : 3] ? val[a < 2 ? 2 : 3] : 0.0;
      /* station b moved by 1 in DOF a: force -k on a, +k on b, nothing else */
      for (b = 0; b < 8; b++) {
        double ek = b == a ? -kv : b == a + 4 ? kv : 0.0;
        double ec = b == a ? -cv : b == a + 4 ? cv : 0.0;
        assert_true(Ke[b + 8 * (a + 4)] == ek);
        assert_true(Ce[b + 8 * (a + 4)] == ec);
      }
    }
    for (b = 0; b < 8; b++) { /* common motion v on both stations */
      const double v[4] = {1.0, -2.0, 0.3, 0.7};
      double fk = 0, fc = 0;
      for (k = 0; k < 8; k++) {
        fk += Ke[b + 8 * k] * v[k % 4];
        fc += Ce[b + 8 * k] * v[k % 4];
      }
      assert_true(fabs(fk) <= 1e-12 * 2e5 && fabs(fc) <= 1e-12 * 40.0);
    }
  }
}

/* Bearing table: linear interpolation between rows, held outside. */
static void test_bearing_interp(void **state) {
  const double speeds[3] = {0.0, 100.0, 300.0};
  const rcb_bearing_coefs rows[3] = {{1, 2, 3, 4, 5, 6, 7, 8},
                                     {3, 2, 1, 0, 5, 6, 7, 8},
                                     {7, 0, 0, 0, 9, 6, 7, 0}};
  rcb_bearing_coefs o;
  (void)state;
  rcb_bearing_interp(3, speeds, rows, 50.0, &o); /* halfway through the first interval */
  assert_true(o.kxx == 2.0 && o.kxy == 2.0 && o.kyx == 2.0 && o.kyy == 2.0 && o.cyy == 8.0);
  rcb_bearing_interp(3, speeds, rows, 250.0, &o); /* 3/4 through the second */
  assert_true(rcb_test_close(o.kxx, 6.0, 1e-15, 0) && rcb_test_close(o.kxy, 0.5, 1e-15, 0));
  assert_true(rcb_test_close(o.cxx, 8.0, 1e-15, 0) && rcb_test_close(o.cyy, 2.0, 1e-15, 0));
  rcb_bearing_interp(3, speeds, rows, -10.0, &o);
  assert_true(o.kxx == 1.0 && o.kyy == 4.0);
  rcb_bearing_interp(3, speeds, rows, 1e9, &o);
  assert_true(o.kxx == 7.0 && o.cxx == 9.0);
  rcb_bearing_interp(1, NULL, rows + 1, 1e9, &o); /* constant bearing */
  assert_true(o.kxx == 3.0 && o.kyy == 0.0);
}

/* Bearing block: force -B (q_shaft - q_ped). To ground: B itself. On a
 * pedestal: a unit shaft motion loads the shaft with +B e and the pedestal
 * with -B e; equal motion of shaft and pedestal loads neither. */
static void test_bearing_element(void **state) {
  const rcb_bearing_coefs c = {1e7, 2e5, -3e5, 2e7, 10, 1, 2, 20};
  const double B[2][2] = {{1e7, 2e5}, {-3e5, 2e7}}, D[2][2] = {{10, 1}, {2, 20}};
  double Kb[16], Cb[16];
  int r, s, k;
  (void)state;
  assert_int_equal(rcb_bearing_element(&c, 0, Kb, Cb), 2);
  for (r = 0; r < 2; r++)
    for (s = 0; s < 2; s++) {
      assert_true(Kb[r + 2 * s] == B[r][s]);
      assert_true(Cb[r + 2 * s] == D[r][s]);
    }
  assert_int_equal(rcb_bearing_element(&c, 1, Kb, Cb), 4);
  for (s = 0; s < 2; s++)
    for (r = 0; r < 2; r++) {
      assert_true(Kb[r + 4 * s] == B[r][s] && Kb[(r + 2) + 4 * s] == -B[r][s]);
      assert_true(Cb[r + 4 * s] == D[r][s] && Cb[(r + 2) + 4 * s] == -D[r][s]);
    }
  for (r = 0; r < 4; r++) {
    const double v[2] = {0.4, -1.3};
    double f = 0;
    for (k = 0; k < 4; k++) f += Kb[r + 4 * k] * v[k % 2];
    assert_true(fabs(f) <= 1e-12 * 2e7);
  }
}

/* Pedestal: a mass on springs to ground, x and y uncoupled; its natural
 * frequencies sqrt(k/m) follow from the diagonal blocks. */
static void test_pedestal_element(void **state) {
  const double k[2] = {4e6, 9e6}, c[2] = {30, 50};
  double Mp[4], Cp[4], Kp[4];
  int a;
  (void)state;
  rcb_pedestal_element(25.0, k, c, Mp, Cp, Kp);
  assert_true(Mp[1] == 0 && Mp[2] == 0 && Kp[1] == 0 && Kp[2] == 0 && Cp[1] == 0 && Cp[2] == 0);
  for (a = 0; a < 2; a++) {
    assert_true(rcb_test_close(sqrt(Kp[3 * a] / Mp[3 * a]), a ? 600.0 : 400.0, 1e-15, 0));
    assert_true(Cp[3 * a] == c[a]);
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_element_symmetry),
      cmocka_unit_test(test_rigid_body),
      cmocka_unit_test(test_cantilever_shear),
      cmocka_unit_test(test_disk_and_bearing_rows),
      cmocka_unit_test(test_bearing_table),
      cmocka_unit_test(test_coupling_element),
      cmocka_unit_test(test_bearing_interp),
      cmocka_unit_test(test_bearing_element),
      cmocka_unit_test(test_pedestal_element),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
