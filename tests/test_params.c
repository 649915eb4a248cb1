/*
 * Parameters by name and the INI writer.
 *  - get returns the values written in examples/paper_system.ini (and the
 *    hand formulas of the geometry-given disks and hubs);
 *  - set changes exactly the matrix entries the parameter enters, by exactly
 *    the change (coupling kt: +dk on the diagonal x/y entries of both
 *    stations, -dk between them; disk mass on the disk's x/y diagonal;
 *    bearing kxy at K(x, y) of its node);
 *  - set checks values as the builder does and names errors precisely;
 *  - every enumerated name is accepted by get;
 *  - write -> reload gives bit-identical M, C, G, K and unbalance forces, for
 *    the four examples and a kramer_2 model with a tabulated bearing; the
 *    two-call sizing idiom works and the writer does not allocate;
 *  - per-element factors shaft.S.e<k>.stiffness | mass: on every element of
 *    a uniform shaft, f times K (or M and G), bit for bit at f = 1/4; one
 *    element changes only its own rows, linearly; free-free frequencies
 *    scale by sqrt(f) (1/sqrt(f) for mass), and a pinned-pinned Timoshenko
 *    beam matches the closed form with E -> f E.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "core/rcb_internal.h"
#include "rcb_test_util.h"

#define PI 3.14159265358979323846

/* Kramer 2 coupling, a speed-dependent bearing of 6 rows (the writer
 * continues lists longer than 4 values on indented lines), a geometry disk
 * and an unbalance phase that is not a round number of radians. */
static const char KRAMER_TABLE[] =
    "[material steel]\n"
    "density = 7850\n"
    "young = 2.05e11\n"
    "poisson = 0.29\n"
    "[shaft A]\n"
    "material = steel\n"
    "shear_factor = 0.9\n"
    "damping_stiffness = 1.7e-5\n"
    "segment = 0.3 0.03 0 3\n"
    "segment = 0.2 0.025 0.005 2\n"
    "[shaft B]\n"
    "material = steel\n"
    "start = 0.5\n"
    "shear_factor = 0.85\n"
    "damping_mass = 3.3\n"
    "segment = 0.5 0.03 0 5\n"
    "[bearing BA]\n"
    "at = A start\n"
    "kxx = 1e6\n"
    "kyy = 1.2e6\n"
    "cxx = 100\n"
    "cyy = 120\n"
    "[bearing BT]\n"
    "at = B end\n"
    "speed_rpm = 0 1000 2000 3000 4000 5000\n"
    "kxx = 1e6 1.1e6 1.2e6 1.3e6 1.4e6 1.5e6\n"
    "kxy = 1e5 2e5 3e5 4e5 5e5 6e5\n"
    "kyx = -1e5 -2e5 -3e5 -4e5 -5e5 -6e5\n"
    "kyy = 2e6\n"
    "cxx = 100 90 80 70 60 50\n"
    "cyy = 150\n"
    "[coupling K]\n"
    "model = kramer_2\n"
    "between = A end, B start\n"
    "kr = 123.4\n"
    "cr = 0.01\n"
    "hub_mass = 0.3\n"
    "hub_Id = 1e-4\n"
    "hub_Ip = 2e-4\n"
    "[disk D]\n"
    "at = A 0.2\n"
    "density = 7850\n"
    "outer_diameter = 0.15\n"
    "inner_diameter = 0.03\n"
    "width = 0.03\n"
    "[unbalance U]\n"
    "at = D\n"
    "amount = 1e-4\n"
    "phase_deg = 33.3\n"
    "[station P]\n"
    "at = B 0.7\n";

static double get(const rcb_model *m, const char *name) {
  double v = NAN;
  rcb_status st = rcb_model_get_param(m, name, &v);
  if (st != RCB_OK) fail_msg("get %s: %s", name, rcb_model_errmsg(m));
  return v;
}

static void set(rcb_model *m, const char *name, double v) {
  rcb_status st = rcb_model_set_param(m, name, v);
  if (st != RCB_OK) fail_msg("set %s: %s", name, rcb_model_errmsg(m));
}

static size_t row(const rcb_model *m, const char *spec) {
  rcb_dof d;
  size_t i = 0;
  assert_int_equal(rcb_model_find_dof(m, spec, &d), RCB_OK);
  assert_int_equal(rcb_model_dof_index(m, d, &i), RCB_OK);
  return i;
}

/* The four matrices at one speed, one allocation (M, C, G, K of n x n). */
static double *matrices(const rcb_model *m, double speed) {
  size_t n = rcb_model_dof_count(m), nn = n * n;
  double *A = calloc(4 * nn, sizeof *A);
  assert_non_null(A);
  if (rcb_model_matrices(m, speed, A, A + nn, A + 2 * nn, A + 3 * nn) != RCB_OK)
    fail_msg("matrices: %s", rcb_model_errmsg(m));
  return A;
}

/* Status want and every phrase in the message. */
static void expect_set_error(rcb_model *m, const char *name, double v, rcb_status want,
                             const char *p1, const char *p2) {
  rcb_status st = rcb_model_set_param(m, name, v);
  const char *msg = rcb_model_errmsg(m);
  if (st != want || (p1 && !strstr(msg, p1)) || (p2 && !strstr(msg, p2)))
    fail_msg("set %s = %g: status %d (want %d), message: %s\nexpected '%s' and '%s'", name, v,
             (int)st, (int)want, msg, p1 ? p1 : "", p2 ? p2 : "");
}

/* ---- get ---- */

static void test_get_paper_values(void **state) {
  rcb_model *m = rcb_test_model_from_example("paper_system.ini");
  /* disk: annulus D 90 mm, d 17 mm, w 25 mm; hub: half of the Table 1 annulus */
  double md = 6303.235 * PI / 4.0 * (0.090 * 0.090 - 0.017 * 0.017) * 0.025;
  double ipd = md * (0.090 * 0.090 + 0.017 * 0.017) / 8.0;
  double mh = 2758.219 * PI * (0.017 * 0.017 - 0.006 * 0.006) * 0.043115 / 2.0;
  (void)state;
  assert_true(get(m, "coupling.C.kt") == 46.095e3);
  assert_true(get(m, "coupling.C.kr") == 220.76);
  assert_true(get(m, "coupling.C.ct") == 10.949);
  assert_true(get(m, "coupling.C.cr") == 10.949e-6);
  assert_true(get(m, "bearing.B1.kxx") == 5e7);
  assert_true(get(m, "bearing.B1.kyy") == 7e7);
  assert_true(get(m, "bearing.B1.cxx") == 500);
  assert_true(get(m, "bearing.B1.cyy") == 700);
  assert_true(get(m, "bearing.B1.kxy") == 0);
  assert_true(get(m, "bearing.B2.kxx") == 7e7);
  assert_true(get(m, "bearing.B4.cyy") == 500);
  assert_true(get(m, "material.steel.density") == 7759.255);
  assert_true(get(m, "material.steel.young") == 1.936e11);
  assert_true(get(m, "shaft.A.damping_mass") == 15.691);
  assert_true(get(m, "shaft.B.damping_stiffness") == 22.989e-6);
  assert_true(rcb_test_close(get(m, "disk.DA.mass"), md, 1e-13, 0));
  assert_true(rcb_test_close(get(m, "disk.DB.Ip"), ipd, 1e-13, 0));
  assert_true(rcb_test_close(get(m, "coupling.C.hub_mass"), mh, 1e-13, 0));
  assert_true(get(m, "unbalance.UA.amount") == 15e-5);
  assert_true(get(m, "unbalance.UA.phase") == 0);
  assert_true(rcb_test_close(get(m, "unbalance.UB.phase"), PI / 2, 1e-15, 0));
  rcb_model_destroy(m);
}

/* ---- set changes the right matrix entries by the right amount ---- */

/* After a change, entry (i, j) of matrix A1 vs A0: +d where listed, -d
 * where listed negated, bit-identical elsewhere. */
typedef struct delta {
  size_t i, j;
  double d;
} delta;

static void expect_deltas(const double *A0, const double *A1, size_t n, const delta *dl,
                          size_t nd, const char *what) {
  size_t i, j, k;
  for (j = 0; j < n; j++)
    for (i = 0; i < n; i++) {
      double want = 0, got = A1[i + n * j] - A0[i + n * j];
      int listed = 0;
      for (k = 0; k < nd; k++)
        if (dl[k].i == i && dl[k].j == j) {
          want += dl[k].d;
          listed = 1;
        }
      if (!listed) {
        if (A1[i + n * j] != A0[i + n * j])
          fail_msg("%s(%zu,%zu) changed by %g, expected no change", what, i, j, got);
      } else if (!rcb_test_close(got, want, 1e-9, 0)) {
        fail_msg("%s(%zu,%zu) changed by %.17g, expected %.17g", what, i, j, got, want);
      }
    }
}

static void test_set_coupling_kt(void **state) {
  rcb_model *m = rcb_test_model_from_example("paper_system.ini");
  size_t n = rcb_model_dof_count(m), nn = n * n;
  size_t ax = row(m, "C.A.x"), ay = row(m, "C.A.y"), bx = row(m, "C.B.x"), by = row(m, "C.B.y");
  double dk = 1024.0, *A0, *A1;
  delta dl[8];
  (void)state;
  A0 = matrices(m, 1000.0);
  set(m, "coupling.C.kt", 46.095e3 + dk);
  assert_true(get(m, "coupling.C.kt") == 46.095e3 + dk);
  A1 = matrices(m, 1000.0);
  /* [k -k; -k k] on x and on y (paper eq. 1), nothing on the rotations */
  dl[0] = (delta){ax, ax, dk};
  dl[1] = (delta){bx, bx, dk};
  dl[2] = (delta){ax, bx, -dk};
  dl[3] = (delta){bx, ax, -dk};
  dl[4] = (delta){ay, ay, dk};
  dl[5] = (delta){by, by, dk};
  dl[6] = (delta){ay, by, -dk};
  dl[7] = (delta){by, ay, -dk};
  expect_deltas(A0 + 3 * nn, A1 + 3 * nn, n, dl, 8, "K");
  expect_deltas(A0, A1, n, NULL, 0, "M");
  expect_deltas(A0 + nn, A1 + nn, n, NULL, 0, "C");
  expect_deltas(A0 + 2 * nn, A1 + 2 * nn, n, NULL, 0, "G");
  free(A0);
  free(A1);
  rcb_model_destroy(m);
}

static void test_set_disk_mass_and_hub(void **state) {
  rcb_model *m = rcb_test_model_from_example("paper_system.ini");
  size_t n = rcb_model_dof_count(m), nn = n * n;
  size_t dx = row(m, "DA.x"), dy = row(m, "DA.y");
  size_t ax = row(m, "C.A.x"), ay = row(m, "C.A.y"), bx = row(m, "C.B.x"), by = row(m, "C.B.y");
  double dm = 0.125, m0 = get(m, "disk.DA.mass"), h0 = get(m, "coupling.C.hub_mass");
  double *A0, *A1;
  delta dl[4];
  (void)state;
  A0 = matrices(m, 500.0);
  set(m, "disk.DA.mass", m0 + dm);
  A1 = matrices(m, 500.0);
  dl[0] = (delta){dx, dx, dm};
  dl[1] = (delta){dy, dy, dm};
  expect_deltas(A0, A1, n, dl, 2, "M");
  expect_deltas(A0 + nn, A1 + nn, n, NULL, 0, "C"); /* shaft damping only: not the disk */
  expect_deltas(A0 + 3 * nn, A1 + 3 * nn, n, NULL, 0, "K");
  free(A1);
  /* the hub mass is set at both coupling stations */
  free(A0);
  A0 = matrices(m, 500.0);
  set(m, "coupling.C.hub_mass", h0 + dm);
  assert_true(m->couplings[0].p.mass[0] == h0 + dm);
  assert_true(m->couplings[0].p.mass[1] == h0 + dm);
  A1 = matrices(m, 500.0);
  dl[0] = (delta){ax, ax, dm};
  dl[1] = (delta){ay, ay, dm};
  dl[2] = (delta){bx, bx, dm};
  dl[3] = (delta){by, by, dm};
  expect_deltas(A0, A1, n, dl, 4, "M");
  free(A0);
  free(A1);
  rcb_model_destroy(m);
}

static void test_set_bearing_cross(void **state) {
  rcb_model *m = rcb_test_model_from_example("paper_system.ini");
  size_t n = rcb_model_dof_count(m), nn = n * n, x = row(m, "B2.x"), y = row(m, "B2.y");
  double *A0, *A1;
  delta dl[2];
  (void)state;
  A0 = matrices(m, 0.0);
  /* force = -K q: kxy couples the y displacement into the x force, K(x, y);
   * negative values are legal (cross-coupled bearings) */
  set(m, "bearing.B2.kxy", 2.5e6);
  set(m, "bearing.B2.cyx", -40.0);
  A1 = matrices(m, 0.0);
  dl[0] = (delta){x, y, 2.5e6};
  expect_deltas(A0 + 3 * nn, A1 + 3 * nn, n, dl, 1, "K");
  dl[1] = (delta){y, x, -40.0};
  expect_deltas(A0 + nn, A1 + nn, n, dl + 1, 1, "C");
  free(A0);
  free(A1);
  rcb_model_destroy(m);
}

static void test_set_unbalance(void **state) {
  rcb_model *m = rcb_test_model_from_example("paper_system.ini");
  size_t n = rcb_model_dof_count(m), x = row(m, "DA.x"), y = row(m, "DA.y");
  double w = 300.0, me = 2e-4, ph = 0.7;
  rcb_complex *F = calloc(n, sizeof *F);
  double complex fx, fy;
  (void)state;
  assert_non_null(F);
  set(m, "unbalance.UA.amount", me);
  set(m, "unbalance.UA.phase", ph);
  assert_int_equal(rcb_model_unbalance_force(m, w, F), RCB_OK);
  memcpy(&fx, &F[x], sizeof fx);
  memcpy(&fy, &F[y], sizeof fy);
  /* F_x = me w^2 e^{i phase}, F_y = -i F_x */
  assert_true(rcb_test_close(creal(fx), me * w * w * cos(ph), 1e-14, 0));
  assert_true(rcb_test_close(cimag(fx), me * w * w * sin(ph), 1e-14, 0));
  assert_true(rcb_test_close(creal(fy), me * w * w * sin(ph), 1e-14, 0));
  assert_true(rcb_test_close(cimag(fy), -me * w * w * cos(ph), 1e-14, 0));
  free(F);
  rcb_model_destroy(m);
}

/* ---- set rejects what the builder rejects ---- */

static void test_set_errors(void **state) {
  rcb_model *m = rcb_test_model_from_example("paper_system.ini"), *k2, *cc;
  (void)state;
  expect_set_error(m, "coupling.C.kt", NAN, RCB_ERR_ARG, "coupling 'C'", "not a finite");
  expect_set_error(m, "coupling.C.kt", INFINITY, RCB_ERR_ARG, "kt", "not a finite");
  expect_set_error(m, "coupling.C.kt", -1.0, RCB_ERR_ARG, "kt (N/m) = -1", ">= 0");
  expect_set_error(m, "disk.DA.Id", -1e-3, RCB_ERR_ARG, "disk 'DA'", ">= 0");
  expect_set_error(m, "material.steel.young", 0.0, RCB_ERR_ARG, "material 'steel'",
                   "positive");
  expect_set_error(m, "shaft.A.damping_mass", -1.0, RCB_ERR_ARG, "shaft 'A'", ">= 0");
  expect_set_error(m, "bearing.B1.kxx", NAN, RCB_ERR_ARG, "bearing 'B1'", "not a finite");
  /* a failed set leaves the value alone */
  assert_true(get(m, "coupling.C.kt") == 46.095e3);
  /* unknown names: what is wrong and the closest valid name */
  expect_set_error(m, "coupling.C.kx", 1.0, RCB_ERR_NOT_FOUND, "has no parameter 'kx'",
                   "'coupling.C.kt'");
  expect_set_error(m, "coupling.X.kt", 1.0, RCB_ERR_NOT_FOUND, "no coupling 'X'",
                   "'coupling.C.kt'");
  expect_set_error(m, "disk.DA.mas", 1.0, RCB_ERR_NOT_FOUND, "'disk.DA.mass'", NULL);
  expect_set_error(m, "coupling.C.poisson", 1.0, RCB_ERR_NOT_FOUND,
                   "its parameters are kt, kr, ct, cr, hub_mass", NULL);
  expect_set_error(m, "bearings.B1.kxx", 1.0, RCB_ERR_NOT_FOUND, "unknown kind 'bearings'",
                   "'bearing.B1.kxx'");
  expect_set_error(m, "kt", 1.0, RCB_ERR_NOT_FOUND, "KIND.ITEM.KEY", NULL);
  expect_set_error(m, "material.steel.poisson", 0.3, RCB_ERR_NOT_FOUND,
                   "its parameters are density, young", NULL);
  expect_set_error(m, "unbalance.UA.phase_deg", 0.3, RCB_ERR_NOT_FOUND,
                   "'unbalance.UA.phase'", NULL);
  assert_int_equal(rcb_model_set_param(m, NULL, 1.0), RCB_ERR_ARG);
  assert_int_equal(rcb_model_get_param(m, "coupling.C.kt", NULL), RCB_ERR_ARG);
  rcb_model_destroy(m);

  /* keys its coupling model does not use */
  k2 = rcb_test_model_from_string(KRAMER_TABLE);
  expect_set_error(k2, "coupling.K.kt", 1.0, RCB_ERR_NOT_FOUND,
                   "coupling 'K' (kramer_2) has no kt; its parameters are kr, cr", NULL);
  {
    double v = 0;
    assert_int_equal(rcb_model_get_param(k2, "coupling.K.ct", &v), RCB_ERR_NOT_FOUND);
    assert_non_null(strstr(rcb_model_errmsg(k2), "has no ct"));
  }
  /* speed-dependent bearings are not fittable; constant ones are */
  expect_set_error(k2, "bearing.BT.kxx", 1.0, RCB_ERR_NOT_FOUND, "bearing 'BT'",
                   "not fittable");
  set(k2, "bearing.BA.kxx", 2e6);
  rcb_model_destroy(k2);
  cc = rcb_test_model_from_example("cross_coupled.ini");
  expect_set_error(cc, "bearing.BR.kxy", 1.0, RCB_ERR_NOT_FOUND, "speed-dependent",
                   "not fittable");
  rcb_model_destroy(cc);
}

/* ---- enumeration ---- */

static void check_enumeration(const rcb_model *m, size_t want, const char *first,
                              const char *last) {
  size_t n = rcb_model_param_count(m), i, j;
  char(*names)[128];
  double v;
  assert_int_equal(n, want);
  names = calloc(n, sizeof *names);
  assert_non_null(names);
  for (i = 0; i < n; i++) {
    assert_int_equal(rcb_model_param_name(m, i, names[i], sizeof names[i]), RCB_OK);
    if (rcb_model_get_param(m, names[i], &v) != RCB_OK)
      fail_msg("enumerated name %s rejected: %s", names[i], rcb_model_errmsg(m));
    for (j = 0; j < i; j++) assert_string_not_equal(names[i], names[j]);
  }
  assert_string_equal(names[0], first);
  assert_string_equal(names[n - 1], last);
  free(names);
}

static void test_enumerate(void **state) {
  rcb_model *m = rcb_test_model_from_example("paper_system.ini");
  char small[8];
  (void)state;
  /* 1 material x 2 + 2 shafts x 4 (2 damping, 2 factors) + 2 disks x 3 + 4 bearings x 8
   * + nelson_crandall_2 (kt kr ct cr + 3 hub) + 2 unbalances x 2 = 59 */
  check_enumeration(m, 59, "material.steel.density", "unbalance.UB.phase");
  {
    char b[64];
    assert_int_equal(rcb_model_param_name(m, 2, b, sizeof b), RCB_OK);
    assert_string_equal(b, "shaft.A.damping_mass");
    assert_int_equal(rcb_model_param_name(m, 4, b, sizeof b), RCB_OK);
    assert_string_equal(b, "shaft.A.stiffness");
    assert_int_equal(rcb_model_param_name(m, 5, b, sizeof b), RCB_OK);
    assert_string_equal(b, "shaft.A.mass");
    assert_int_equal(rcb_model_param_name(m, 48, b, sizeof b), RCB_OK);
    assert_string_equal(b, "coupling.C.kt");
  }
  assert_int_equal(rcb_model_param_name(m, 59, small, sizeof small), RCB_ERR_NOT_FOUND);
  assert_int_equal(rcb_model_param_name(m, 0, small, sizeof small), RCB_ERR_WORKSPACE);
  assert_int_equal(small[0], '\0');
  rcb_model_destroy(m);
  /* tabulated BR and the unused kt, ct of kramer_2 are left out:
   * 2 + 2 shafts x 4 + BA 8 + kramer_2 (kr cr + 3 hub) + disk 3 + unbalance 2 = 28 */
  m = rcb_test_model_from_string(KRAMER_TABLE);
  check_enumeration(m, 28, "material.steel.density", "unbalance.U.phase");
  rcb_model_destroy(m);
  /* cross_coupled: 2 + 4 + disk 3 + BL 8 (BR tabulated) + 2 = 19 */
  m = rcb_test_model_from_example("cross_coupled.ini");
  check_enumeration(m, 19, "material.steel.density", "unbalance.U.phase");
  rcb_model_destroy(m);
}

/* Parameters can be set before finalize (builder) and the result holds. */
static void test_set_before_finalize(void **state) {
  rcb_model *m = NULL;
  rcb_coupling_params p;
  (void)state;
  memset(&p, 0, sizeof p);
  p.kt = 1e4;
  p.kr = 100;
  assert_int_equal(rcb_model_create(&m, NULL), RCB_OK);
  assert_int_equal(rcb_model_add_material(m, "st", 7800, 2e11, 0.3), RCB_OK);
  assert_int_equal(rcb_model_add_shaft(m, "A", "st", 0, 0.9), RCB_OK);
  assert_int_equal(rcb_model_add_segment(m, "A", 1, 0.05, 0, 4), RCB_OK);
  assert_int_equal(rcb_model_add_shaft(m, "B", "st", 1, 0.9), RCB_OK);
  assert_int_equal(rcb_model_add_segment(m, "B", 1, 0.05, 0, 4), RCB_OK);
  assert_int_equal(rcb_model_add_coupling(m, "C", RCB_COUPLING_NELSON_CRANDALL_1, "A", 1, "B",
                                          1, &p),
                   RCB_OK);
  set(m, "coupling.C.kt", 2e4);
  expect_set_error(m, "coupling.C.ct", 1.0, RCB_ERR_NOT_FOUND,
                   "(nelson_crandall_1) has no ct; its parameters are kt, kr", NULL);
  assert_int_equal(rcb_model_finalize(m), RCB_OK);
  assert_true(get(m, "coupling.C.kt") == 2e4);
  set(m, "coupling.C.kr", 50);
  assert_true(get(m, "coupling.C.kr") == 50);
  rcb_model_destroy(m);
}

/* ---- INI writer ---- */

/* Written text of m (allocated), via the two-call idiom. */
static char *write_text(const rcb_model *m) {
  size_t need = 0, need2 = 0;
  char *buf;
  assert_int_equal(rcb_model_write_ini(m, NULL, 0, &need), RCB_ERR_WORKSPACE);
  assert_true(need > 1);
  buf = malloc(need);
  assert_non_null(buf);
  if (rcb_model_write_ini(m, buf, need, &need2) != RCB_OK)
    fail_msg("write_ini: %s", rcb_model_errmsg(m));
  assert_int_equal(need2, need);
  assert_int_equal(strlen(buf) + 1, need);
  return buf;
}

/* Same entries, bit for bit: the writer prints every input so that it reads
 * back to the same double, and the assembly is deterministic. */
static void expect_same(const double *a, const double *b, size_t n, const char *what) {
  size_t i;
  for (i = 0; i < n; i++)
    if (a[i] != b[i])
      fail_msg("%s[%zu]: %.17g after the round trip, %.17g before", what, i, b[i], a[i]);
}

static void expect_round_trip(const rcb_model *m, const char *label) {
  char *text = write_text(m), *text2;
  rcb_model *r = NULL;
  size_t n = rcb_model_dof_count(m), s, i;
  const double speeds[2] = {0.0, 250.0};
  assert_int_equal(rcb_model_create(&r, NULL), RCB_OK);
  if (rcb_model_load_string(r, text, "<written>") != RCB_OK)
    fail_msg("%s: written INI does not load: %s\n%s", label, rcb_model_errmsg(r), text);
  assert_int_equal(rcb_model_dof_count(r), n);
  assert_int_equal(rcb_model_node_count(r), rcb_model_node_count(m));
  assert_int_equal(rcb_model_station_count(r), rcb_model_station_count(m));
  for (i = 0; i < rcb_model_station_count(m); i++) {
    rcb_station_info a, b;
    assert_int_equal(rcb_model_station_info(m, i, &a), RCB_OK);
    assert_int_equal(rcb_model_station_info(r, i, &b), RCB_OK);
    assert_string_equal(a.name, b.name);
    assert_int_equal(a.node, b.node);
    assert_int_equal(a.kind, b.kind);
  }
  for (s = 0; s < 2; s++) {
    double *A = matrices(m, speeds[s]), *B = matrices(r, speeds[s]);
    rcb_complex *F = calloc(n, sizeof *F), *G = calloc(n, sizeof *G);
    assert_non_null(F);
    assert_non_null(G);
    expect_same(A, B, 4 * n * n, label);
    assert_int_equal(rcb_model_unbalance_force(m, speeds[s] + 10.0, F), RCB_OK);
    assert_int_equal(rcb_model_unbalance_force(r, speeds[s] + 10.0, G), RCB_OK);
    expect_same((const double *)F, (const double *)G, 2 * n, "F");
    free(A);
    free(B);
    free(F);
    free(G);
  }
  /* writing the reloaded model gives the same text */
  text2 = write_text(r);
  assert_string_equal(text, text2);
  free(text);
  free(text2);
  rcb_model_destroy(r);
}

static void test_write_round_trip_examples(void **state) {
  static const char *const ex[4] = {"paper_system.ini", "paper_freefree.ini",
                                    "two_disk_aniso.ini", "cross_coupled.ini"};
  size_t k;
  (void)state;
  for (k = 0; k < 4; k++) {
    rcb_model *m = rcb_test_model_from_example(ex[k]);
    expect_round_trip(m, ex[k]);
    rcb_model_destroy(m);
  }
}

static void test_write_round_trip_kramer_table(void **state) {
  rcb_model *m = rcb_test_model_from_string(KRAMER_TABLE);
  char *text;
  (void)state;
  expect_round_trip(m, "kramer_2 + table");
  /* the table goes out in rad/s, the long lists on continuation lines */
  text = write_text(m);
  assert_non_null(strstr(text, "model = kramer_2"));
  assert_non_null(strstr(text, "speed = 0 104.71975511965977 209.43951023931953 "));
  assert_non_null(strstr(text, "\n    418.87902047863906 523.5987755982989\n"));
  assert_null(strstr(text, "kt ="));
  free(text);
  rcb_model_destroy(m);
}

/* Values set by a fit (full 17-digit doubles) survive the round trip. */
static void test_write_round_trip_after_set(void **state) {
  rcb_model *m = rcb_test_model_from_example("paper_system.ini");
  size_t i, n = rcb_model_param_count(m);
  char name[128];
  (void)state;
  for (i = 0; i < n; i++) {
    double v;
    assert_int_equal(rcb_model_param_name(m, i, name, sizeof name), RCB_OK);
    v = get(m, name);
    /* an awkward value of the same sign, e.g. 0.1 -> 0.1 * (1 + 1/3) */
    set(m, name, v == 0 ? 1.0 / 3.0 : v * (4.0 / 3.0));
  }
  set(m, "unbalance.UA.phase", 2.0);
  set(m, "unbalance.UB.phase", -1.2345678901234567);
  expect_round_trip(m, "paper system, all parameters changed");
  rcb_model_destroy(m);
}

/* Element factors (element_stiffness, element_mass: pairs "k factor", the
 * key repeated every four pairs) survive the round trip bit for bit, and
 * the reloaded model holds them as parameters. */
static void test_write_round_trip_element_factors(void **state) {
  rcb_model *m = rcb_test_model_from_example("paper_system.ini"), *r = NULL;
  char name[64], *text;
  size_t k;
  (void)state;
  for (k = 1; k <= 9; k++) {
    snprintf(name, sizeof name, "shaft.B.e%zu.stiffness", k);
    set(m, name, 1.0 - 1.0 / (3.0 + (double)k));
  }
  set(m, "shaft.A.e10.mass", 1.0 / 3.0);
  set(m, "shaft.A.e1.stiffness", 2.5);
  expect_round_trip(m, "paper system, element factors");
  text = write_text(m);
  assert_non_null(strstr(text, "element_stiffness = 1 2.5 ; "));
  assert_non_null(strstr(text, "element_mass = 10 0.3333333333333333 ; "));
  assert_non_null(strstr(text, "\nelement_stiffness = 5 0.875 6 "));
  assert_int_equal(rcb_model_create(&r, NULL), RCB_OK);
  assert_int_equal(rcb_model_load_string(r, text, "<written>"), RCB_OK);
  assert_true(get(r, "shaft.B.e4.stiffness") == 1.0 - 1.0 / 7.0);
  assert_true(get(r, "shaft.B.e10.stiffness") == 1.0);
  assert_true(get(r, "shaft.A.e10.mass") == 1.0 / 3.0);
  free(text);
  rcb_model_destroy(r);
  rcb_model_destroy(m);
}

static void test_write_sizing(void **state) {
  rcb_test_counter cnt = {0, 0};
  rcb_allocator a = rcb_test_counting_allocator(&cnt);
  rcb_model *m = NULL;
  char path[1024], *buf;
  size_t need = 0, need2 = 0, allocs;
  (void)state;
  snprintf(path, sizeof path, "%s/%s", RCB_EXAMPLES_DIR, "paper_system.ini");
  assert_int_equal(rcb_model_create(&m, &a), RCB_OK);
  assert_int_equal(rcb_model_load_file(m, path), RCB_OK);
  allocs = cnt.allocs;
  assert_int_equal(rcb_model_write_ini(m, NULL, 0, &need), RCB_ERR_WORKSPACE);
  assert_true(need > 100);
  buf = malloc(need);
  assert_non_null(buf);
  memset(buf, 'x', need);
  /* one byte short: error, buffer left as an empty string, size reported */
  assert_int_equal(rcb_model_write_ini(m, buf, need - 1, &need2), RCB_ERR_WORKSPACE);
  assert_int_equal(need2, need);
  assert_int_equal(buf[0], '\0');
  assert_non_null(strstr(rcb_model_errmsg(m), "needs"));
  assert_int_equal(rcb_model_write_ini(m, buf, need, &need2), RCB_OK);
  assert_int_equal(strlen(buf) + 1, need);
  assert_int_equal(rcb_model_write_ini(m, buf, need, NULL), RCB_OK);
  assert_int_equal(cnt.allocs, allocs); /* the writer never allocates */
  /* the documented format: sections, unit comments, the coupling stations */
  assert_non_null(strstr(buf, "[coupling C]\nmodel = nelson_crandall_2\n"));
  assert_non_null(strstr(buf, "between = A 0.5, B 0.52"));
  assert_non_null(strstr(buf, "kt = 46095 "));
  assert_non_null(strstr(buf, "; N m s/rad\n"));
  assert_non_null(strstr(buf, "[unbalance UB]\nat = B 0.82"));
  assert_non_null(strstr(buf, "phase_deg = 90 "));
  assert_non_null(strstr(buf, "[station P1]\nat = A 0.3"));
  free(buf);
  rcb_model_destroy(m);
  assert_int_equal(cnt.allocs, cnt.frees);
}

/* Hubs that differ between the stations cannot be expressed in the INI
 * format: the text says so and carries station a's hub. */
static void test_write_unequal_hubs(void **state) {
  rcb_model *m = NULL, *r = NULL;
  rcb_coupling_params p;
  char *text;
  (void)state;
  memset(&p, 0, sizeof p);
  p.kt = 1e4;
  p.kr = 100;
  p.mass[0] = 0.5;
  p.mass[1] = 0.25;
  assert_int_equal(rcb_model_create(&m, NULL), RCB_OK);
  assert_int_equal(rcb_model_add_material(m, "st", 7800, 2e11, 0.3), RCB_OK);
  assert_int_equal(rcb_model_add_shaft(m, "A", "st", 0, 0.9), RCB_OK);
  assert_int_equal(rcb_model_add_segment(m, "A", 1, 0.05, 0, 4), RCB_OK);
  assert_int_equal(rcb_model_add_shaft(m, "B", "st", 1, 0.9), RCB_OK);
  assert_int_equal(rcb_model_add_segment(m, "B", 1, 0.05, 0, 4), RCB_OK);
  assert_int_equal(rcb_model_add_coupling(m, "C", RCB_COUPLING_NELSON_CRANDALL_1, "A", 1, "B",
                                          1, &p),
                   RCB_OK);
  assert_int_equal(rcb_model_add_unbalance(m, "U", "A", 0.5, 1e-4, 1.0), RCB_OK);
  assert_int_equal(rcb_model_finalize(m), RCB_OK);
  text = write_text(m);
  assert_non_null(strstr(text, "hub at station b differs (mass 0.25 kg"));
  assert_non_null(strstr(text, "hub_mass = 0.5 "));
  assert_int_equal(rcb_model_create(&r, NULL), RCB_OK);
  assert_int_equal(rcb_model_load_string(r, text, "<written>"), RCB_OK);
  assert_true(get(r, "coupling.C.hub_mass") == 0.5);
  assert_true(get(r, "unbalance.U.phase") == 1.0);
  free(text);
  rcb_model_destroy(r);
  rcb_model_destroy(m);
}

/* The longest names and 17-digit positions stay inside inih's line limit. */
static void test_write_long_names(void **state) {
  const char *a = "shaft_a_with_a_name_of_47_characters_0123456789";
  const char *b = "shaft_b_with_a_name_of_47_characters_0123456789";
  const char *mat = "material_with_a_name_of_47_characters_012345678";
  double z0 = -1.2345678901234567e-05, len = 0.10000000000000001 + 1.0 / 3.0;
  rcb_coupling_params p;
  rcb_model *m = NULL;
  (void)state;
  assert_int_equal(strlen(a), RCB_NAME_MAX - 1);
  memset(&p, 0, sizeof p);
  p.kt = 1.0 / 3.0;
  p.kr = 2.0 / 3.0;
  p.ct = 1e-7 / 3.0;
  p.cr = 1e-9 / 7.0;
  assert_int_equal(rcb_model_create(&m, NULL), RCB_OK);
  assert_int_equal(rcb_model_add_material(m, mat, 7800.0 / 3.0, 2e11 / 3.0, 0.3), RCB_OK);
  assert_int_equal(rcb_model_add_shaft(m, a, mat, z0, 0.9), RCB_OK);
  assert_int_equal(rcb_model_add_segment(m, a, len, 0.05 / 3.0, 0.01 / 7.0, 3), RCB_OK);
  assert_int_equal(rcb_model_add_shaft(m, b, mat, z0 + len, 0.9), RCB_OK);
  assert_int_equal(rcb_model_add_segment(m, b, len, 0.05 / 3.0, 0, 3), RCB_OK);
  assert_int_equal(rcb_model_add_coupling(m, "coupling_with_a_name_of_47_characters_012345678",
                                          RCB_COUPLING_NELSON_CRANDALL_2, a, z0 + len, b,
                                          z0 + len, &p),
                   RCB_OK);
  assert_int_equal(rcb_model_finalize(m), RCB_OK);
  expect_round_trip(m, "long names");
  rcb_model_destroy(m);
}

/* Names the builder accepts but INI cannot hold are refused with a message. */
static void test_write_bad_name(void **state) {
  rcb_model *m = NULL;
  size_t need = 0;
  (void)state;
  assert_int_equal(rcb_model_create(&m, NULL), RCB_OK);
  assert_int_equal(rcb_model_add_material(m, "st", 7800, 2e11, 0.3), RCB_OK);
  assert_int_equal(rcb_model_add_shaft(m, "A", "st", 0, 0.9), RCB_OK);
  assert_int_equal(rcb_model_add_segment(m, "A", 1, 0.05, 0, 4), RCB_OK);
  assert_int_equal(rcb_model_add_disk(m, "D]1", "A", 0.5, 1, 0.1, 0.2), RCB_OK);
  assert_int_equal(rcb_model_finalize(m), RCB_OK);
  assert_int_equal(rcb_model_write_ini(m, NULL, 0, &need), RCB_ERR_MODEL);
  assert_non_null(strstr(rcb_model_errmsg(m), "disk 'D]1': the name cannot be written"));
  rcb_model_destroy(m);
}

/* ---- per-element factors (issue #23): shaft.S.e<k>.stiffness | mass ---- */

/* Uniform shaft S from z = 0 (L m, diameter d m, nel elements, shear
 * factor kappa), no support: a free-free beam. */
static rcb_model *uniform_beam(double L, double d, int nel, double kappa) {
  rcb_model *m = NULL;
  assert_int_equal(rcb_model_create(&m, NULL), RCB_OK);
  assert_int_equal(rcb_model_add_material(m, "st", 7800, 2e11, 0.3), RCB_OK);
  assert_int_equal(rcb_model_add_shaft(m, "S", "st", 0.0, kappa), RCB_OK);
  assert_int_equal(rcb_model_add_segment(m, "S", L, d, 0.0, nel), RCB_OK);
  return m;
}

/* Every element of shaft S of m at factor f (key "stiffness" or "mass"). */
static void set_all_elements(rcb_model *m, const char *key, double f) {
  char name[64];
  size_t k, ne = rcb_model_element_count(m);
  for (k = 1; k <= ne; k++) {
    snprintf(name, sizeof name, "shaft.S.e%zu.%s", k, key);
    set(m, name, f);
  }
}

/* B == f A entry by entry: bit for bit (tol 0), or to tol of the largest. */
static void expect_scaled(const double *A, const double *B, size_t nn, double f, double tol,
                          const char *what) {
  double amax = 0.0;
  size_t i;
  for (i = 0; i < nn; i++) amax = fmax(amax, fabs(A[i]));
  assert_true(amax > 0.0);
  for (i = 0; i < nn; i++)
    if (tol == 0.0 ? B[i] != f * A[i] : fabs(B[i] - f * A[i]) > tol * amax)
      fail_msg("%s[%zu] = %.17g, expected %g x %.17g", what, i, B[i], f, A[i]);
}

/* The identity: a factor f on every element of a uniform shaft is f times
 * its K (stiffness: E and G together, so phi and the shape of Ke stay) or
 * its M and G (mass); C = qz_m M + qz_k K follows. A power of two scales
 * every rounded operation exactly, so the check is bit for bit; 0.6 to
 * round-off. */
static void test_element_factor_identity(void **state) {
  rcb_model *m = uniform_beam(1.0, 0.05, 12, 0.9);
  size_t n, nn;
  double *A0, *A1, *A2;
  (void)state;
  assert_int_equal(rcb_model_set_shaft_damping(m, "S", 0.0, 2e-5), RCB_OK);
  assert_int_equal(rcb_model_finalize(m), RCB_OK);
  n = rcb_model_dof_count(m), nn = n * n;
  A0 = matrices(m, 500.0);
  set_all_elements(m, "stiffness", 0.25);
  A1 = matrices(m, 500.0);
  expect_scaled(A0 + 3 * nn, A1 + 3 * nn, nn, 0.25, 0.0, "K");
  expect_scaled(A0 + nn, A1 + nn, nn, 0.25, 0.0, "C (qz_k K)");
  expect_scaled(A0, A1, nn, 1.0, 0.0, "M");
  expect_scaled(A0 + 2 * nn, A1 + 2 * nn, nn, 1.0, 0.0, "G");
  free(A1);
  set_all_elements(m, "stiffness", 0.6);
  A1 = matrices(m, 500.0);
  expect_scaled(A0 + 3 * nn, A1 + 3 * nn, nn, 0.6, 1e-15, "K");
  free(A1);
  set_all_elements(m, "stiffness", 1.0);
  A1 = matrices(m, 500.0);
  expect_scaled(A0, A1, 4 * nn, 1.0, 0.0, "M, C, G, K back at 1");
  free(A1);
  /* mass, with mass-proportional damping instead */
  set(m, "shaft.S.damping_stiffness", 0.0);
  set(m, "shaft.S.damping_mass", 3.0);
  free(A0);
  A0 = matrices(m, 500.0);
  set_all_elements(m, "mass", 0.25);
  A1 = matrices(m, 500.0);
  expect_scaled(A0, A1, nn, 0.25, 0.0, "M");
  expect_scaled(A0 + nn, A1 + nn, nn, 0.25, 0.0, "C (qz_m M)");
  expect_scaled(A0 + 2 * nn, A1 + 2 * nn, nn, 0.25, 0.0, "G");
  expect_scaled(A0 + 3 * nn, A1 + 3 * nn, nn, 1.0, 0.0, "K");
  set_all_elements(m, "mass", 1.7);
  A2 = matrices(m, 500.0);
  expect_scaled(A0, A2, nn, 1.7, 1e-15, "M");
  expect_scaled(A0 + 2 * nn, A2 + 2 * nn, nn, 1.7, 1e-15, "G");
  free(A0);
  free(A1);
  free(A2);
  rcb_model_destroy(m);
}

/* Every element of shaft `shaft` (only) with factor `key` = f. */
static void set_shaft_elements(rcb_model *m, const char *shaft, const char *key, double f) {
  char name[64];
  size_t e, ne = rcb_model_element_count(m);
  for (e = 0; e < ne; e++) {
    rcb_element_info ei;
    assert_int_equal(rcb_model_element_info(m, e, &ei), RCB_OK);
    if (strcmp(ei.shaft, shaft) != 0) continue;
    snprintf(name, sizeof name, "shaft.%s.e%zu.%s", shaft, ei.index, key);
    set(m, name, f);
  }
}

/* The shaft-wide factors (issue #33), three ways to the same matrices, bit
 * for bit: shaft.S.stiffness = f is the material's young x f when S is the
 * only shaft of that material, and every element factor of S at f; the same
 * for mass and density. M and G stay under a stiffness factor (to rounding:
 * phi holds E/G), K under a mass factor (bit for bit). On the paper system (A and B share steel) only shaft A's rows
 * change: the same as A's element factors. */
static void test_shaft_factors(void **state) {
  static const char *const key[2] = {"stiffness", "mass"};
  static const char *const mat[2] = {"material.steel.young", "material.steel.density"};
  const double f[2] = {0.85, 1.1};
  rcb_model *m0 = rcb_test_model_from_example("cross_coupled.ini"), *m1, *m2, *m3;
  size_t n = rcb_model_dof_count(m0), nn = n * n;
  double *A0, *A1, *A2, *A3;
  char name[64];
  int v;
  (void)state;
  set(m0, "shaft.S.damping_stiffness", 2e-5); /* C = qz_m M + qz_k K follows both */
  set(m0, "shaft.S.damping_mass", 3.0);
  A0 = matrices(m0, 500.0);
  for (v = 0; v < 2; v++) {
    assert_int_equal(rcb_model_clone(&m1, m0, NULL), RCB_OK);
    assert_int_equal(rcb_model_clone(&m2, m0, NULL), RCB_OK);
    assert_int_equal(rcb_model_clone(&m3, m0, NULL), RCB_OK);
    assert_int_equal(rcb_model_finalize(m1), RCB_OK);
    assert_int_equal(rcb_model_finalize(m2), RCB_OK);
    assert_int_equal(rcb_model_finalize(m3), RCB_OK);
    assert_true(get(m1, v ? "shaft.S.mass" : "shaft.S.stiffness") == 1.0);
    snprintf(name, sizeof name, "shaft.S.%s", key[v]);
    set(m1, name, f[v]);
    assert_true(get(m1, name) == f[v]);
    set(m2, mat[v], get(m2, mat[v]) * f[v]);
    set_shaft_elements(m3, "S", key[v], f[v]);
    A1 = matrices(m1, 500.0);
    A2 = matrices(m2, 500.0);
    A3 = matrices(m3, 500.0);
    expect_same(A2, A1, 4 * nn, v ? "M C G K: shaft.S.mass vs density" : "M C G K: shaft.S.stiffness vs young");
    expect_same(A3, A1, 4 * nn, v ? "M C G K: shaft.S.mass vs elements" : "M C G K: shaft.S.stiffness vs elements");
    if (v == 0) {
      /* phi holds E/G: the same, to the rounding of E x f and G x f */
      expect_scaled(A0, A1, nn, 1.0, 1e-15, "M under a stiffness factor");
      expect_scaled(A0 + 2 * nn, A1 + 2 * nn, nn, 1.0, 1e-15, "G under a stiffness factor");
    } else {
      expect_same(A0 + 3 * nn, A1 + 3 * nn, nn, "K under a mass factor");
    }
    assert_true(memcmp(A0, A1, 4 * nn * sizeof *A0) != 0); /* it did change */
    free(A1);
    free(A2);
    free(A3);
    /* a clone keeps the factor through its own finalize */
    rcb_model_destroy(m2);
    assert_int_equal(rcb_model_clone(&m2, m1, NULL), RCB_OK);
    assert_int_equal(rcb_model_finalize(m2), RCB_OK);
    assert_true(get(m2, name) == f[v]);
    rcb_model_destroy(m1);
    rcb_model_destroy(m2);
    rcb_model_destroy(m3);
  }
  expect_set_error(m0, "shaft.S.stiffness", 0.0, RCB_ERR_ARG, "shaft 'S'", "stiffness factor");
  expect_set_error(m0, "shaft.S.mass", -1.0, RCB_ERR_ARG, "shaft 'S'", "mass factor");
  free(A0);
  rcb_model_destroy(m0);
  /* two shafts of one material: shaft A's factor is A's element factors */
  m0 = rcb_test_model_from_example("paper_system.ini");
  nn = rcb_model_dof_count(m0) * rcb_model_dof_count(m0);
  for (v = 0; v < 2; v++) {
    assert_int_equal(rcb_model_clone(&m1, m0, NULL), RCB_OK);
    assert_int_equal(rcb_model_clone(&m3, m0, NULL), RCB_OK);
    assert_int_equal(rcb_model_finalize(m1), RCB_OK);
    assert_int_equal(rcb_model_finalize(m3), RCB_OK);
    snprintf(name, sizeof name, "shaft.A.%s", key[v]);
    set(m1, name, f[v]);
    assert_true(get(m1, v ? "shaft.B.mass" : "shaft.B.stiffness") == 1.0);
    set_shaft_elements(m3, "A", key[v], f[v]);
    A1 = matrices(m1, 500.0);
    A3 = matrices(m3, 500.0);
    expect_same(A3, A1, 4 * nn, "paper system: shaft A's factor vs its elements'");
    free(A1);
    free(A3);
    rcb_model_destroy(m1);
    rcb_model_destroy(m3);
  }
  rcb_model_destroy(m0);
}

/* INI: [shaft] stiffness_factor, mass_factor read and written (only when not
 * 1), the same values and matrices after the round trip; 0 refused at its
 * line. */
static void test_shaft_factors_ini(void **state) {
  rcb_model *m = rcb_test_model_from_example("paper_system.ini"), *r = NULL;
  char *text;
  (void)state;
  text = write_text(m);
  assert_null(strstr(text, "stiffness_factor"));
  assert_null(strstr(text, "mass_factor"));
  free(text);
  set(m, "shaft.B.stiffness", 0.9);
  set(m, "shaft.A.mass", 1.1);
  text = write_text(m);
  assert_non_null(strstr(text, "stiffness_factor = 0.9"));
  assert_non_null(strstr(text, "mass_factor = 1.1"));
  assert_int_equal(rcb_model_create(&r, NULL), RCB_OK);
  if (rcb_model_load_string(r, text, "<written>") != RCB_OK)
    fail_msg("written INI does not load: %s\n%s", rcb_model_errmsg(r), text);
  assert_true(get(r, "shaft.B.stiffness") == 0.9);
  assert_true(get(r, "shaft.A.mass") == 1.1);
  assert_true(get(r, "shaft.A.stiffness") == 1.0);
  assert_true(get(r, "shaft.B.mass") == 1.0);
  expect_round_trip(m, "shaft factors");
  rcb_model_destroy(r);
  r = NULL;
  {
    const char *at = strstr(text, "stiffness_factor = 0.9");
    char *bad = malloc(strlen(text) + 1);
    assert_non_null(bad);
    strcpy(bad, text);
    bad[at - text + strlen("stiffness_factor = ")] = '0';
    bad[at - text + strlen("stiffness_factor = ") + 1] = ' ';
    bad[at - text + strlen("stiffness_factor = ") + 2] = ' ';
    assert_int_equal(rcb_model_create(&r, NULL), RCB_OK);
    assert_int_not_equal(rcb_model_load_string(r, bad, "<bad>"), RCB_OK);
    if (!strstr(rcb_model_errmsg(r), "stiffness factor"))
      fail_msg("message: %s", rcb_model_errmsg(r));
    free(bad);
    rcb_model_destroy(r);
  }
  free(text);
  rcb_model_destroy(m);
}

/* One element of the paper system: only the rows of its two end nodes
 * change, linearly in the factor (K(f) = K_rest + f Ke), and the factors
 * are read back, kept by a clone and set before finalize. */
static void test_element_factor_local(void **state) {
  rcb_model *m = rcb_test_model_from_example("paper_system.ini"), *c = NULL;
  rcb_element_info ei;
  size_t n = rcb_model_dof_count(m), nn = n * n, i, j, e, d;
  int own[400] = {0};
  double *A0, *A1, *A2, amax = 0.0;
  (void)state;
  assert_true(n <= 400);
  /* shaft.B.e3: the third element of shaft B, z = 0.62-0.67 m (B starts at 0.52) */
  for (e = 0; e < rcb_model_element_count(m); e++) {
    assert_int_equal(rcb_model_element_info(m, e, &ei), RCB_OK);
    if (strcmp(ei.shaft, "B") == 0 && ei.index == 3) break;
  }
  assert_true(e < rcb_model_element_count(m));
  assert_true(rcb_test_close(ei.z0, 0.62, 1e-12, 0) && rcb_test_close(ei.z1, 0.67, 1e-12, 0));
  assert_int_equal(ei.node1, ei.node0 + 1);
  for (d = 0; d < 4; d++) {
    rcb_node_info ni;
    assert_int_equal(rcb_model_node_info(m, ei.node0, &ni), RCB_OK);
    own[ni.dof[d]] = 1;
    assert_int_equal(rcb_model_node_info(m, ei.node1, &ni), RCB_OK);
    own[ni.dof[d]] = 1;
  }
  assert_true(get(m, "shaft.B.e3.stiffness") == 1.0 && get(m, "shaft.B.e3.mass") == 1.0);
  A0 = matrices(m, 1000.0);
  set(m, "shaft.B.e3.stiffness", 0.5);
  set(m, "shaft.B.e3.mass", 0.5);
  A1 = matrices(m, 1000.0);
  set(m, "shaft.B.e3.stiffness", 0.25);
  set(m, "shaft.B.e3.mass", 0.25);
  A2 = matrices(m, 1000.0);
  for (i = 0; i < 4 * nn; i++) amax = fmax(amax, fabs(A0[i]));
  for (j = 0; j < n; j++)
    for (i = 0; i < n; i++)
      for (d = 0; d < 4; d++) { /* M, C, G, K */
        size_t a = d * nn + i + n * j;
        if (!(own[i] && own[j])) {
          if (A1[a] != A0[a] || A2[a] != A0[a]) fail_msg("matrix %zu (%zu,%zu) changed", d, i, j);
        } else if (fabs((A2[a] - A0[a]) - 1.5 * (A1[a] - A0[a])) > 1e-13 * amax) {
          fail_msg("matrix %zu (%zu,%zu): not linear in the factor", d, i, j);
        }
      }
  /* a clone keeps the factors through its own finalize */
  assert_int_equal(rcb_model_clone(&c, m, NULL), RCB_OK);
  assert_true(get(c, "shaft.B.e3.stiffness") == 0.25);
  assert_int_equal(rcb_model_finalize(c), RCB_OK);
  free(A1);
  A1 = matrices(c, 1000.0);
  assert_int_equal(memcmp(A1, A2, 4 * nn * sizeof *A1), 0);
  assert_int_equal(rcb_model_element_info(c, e, &ei), RCB_OK);
  assert_true(ei.stiffness == 0.25 && ei.mass == 0.25);
  /* not enumerated: the list of 59 stays */
  assert_int_equal(rcb_model_param_count(m), 59);
  free(A0);
  free(A1);
  free(A2);
  rcb_model_destroy(c);
  rcb_model_destroy(m);
}

static void test_element_factor_errors(void **state) {
  rcb_model *m = rcb_test_model_from_example("paper_system.ini"), *u;
  rcb_element_info ei;
  double v;
  (void)state;
  expect_set_error(m, "shaft.B.e0.stiffness", 0.5, RCB_ERR_NOT_FOUND, "e1 to e10 of shaft 'B'",
                   "rcbtool check");
  expect_set_error(m, "shaft.B.e11.stiffness", 0.5, RCB_ERR_NOT_FOUND, "e1 to e10", NULL);
  expect_set_error(m, "shaft.B.e03.mass", 0.5, RCB_ERR_NOT_FOUND, "e1 to e10", NULL);
  expect_set_error(m, "shaft.B.x3.mass", 0.5, RCB_ERR_NOT_FOUND, "e1 to e10", NULL);
  expect_set_error(m, "shaft.B.e3.young", 0.5, RCB_ERR_NOT_FOUND, "stiffness and mass", NULL);
  expect_set_error(m, "shaft.Q.e3.mass", 0.5, RCB_ERR_NOT_FOUND, "no shaft 'Q'", NULL);
  expect_set_error(m, "shaft.B.e3.stiffness", 0.0, RCB_ERR_ARG, "expected a positive value",
                   NULL);
  expect_set_error(m, "shaft.B.e3.mass", NAN, RCB_ERR_ARG, "not a finite number", NULL);
  assert_int_equal(rcb_model_get_param(m, "shaft.B.e10.mass", &v), RCB_OK);
  assert_int_equal(rcb_model_get_param(m, "shaft.A.e11.mass", &v), RCB_ERR_NOT_FOUND);
  assert_int_equal(rcb_model_element_info(m, 20, &ei), RCB_ERR_NOT_FOUND);
  rcb_model_destroy(m);
  /* before finalize: numbered over the segments given so far */
  u = uniform_beam(1.0, 0.05, 4, 0.9);
  set(u, "shaft.S.e4.stiffness", 0.3);
  expect_set_error(u, "shaft.S.e5.stiffness", 0.5, RCB_ERR_NOT_FOUND, "e1 to e4", NULL);
  assert_int_equal(rcb_model_element_info(u, 0, &ei), RCB_ERR_STATE);
  assert_int_equal(rcb_model_add_segment(u, "S", 0.5, 0.04, 0.0, 2), RCB_OK);
  set(u, "shaft.S.e6.mass", 2.0);
  assert_int_equal(rcb_model_finalize(u), RCB_OK);
  assert_int_equal(rcb_model_element_info(u, 3, &ei), RCB_OK);
  assert_true(ei.stiffness == 0.3 && ei.mass == 1.0 && ei.index == 4);
  assert_true(rcb_test_close(ei.z0, 0.75, 1e-12, 0) && rcb_test_close(ei.z1, 1.0, 1e-12, 0));
  assert_int_equal(rcb_model_element_info(u, 5, &ei), RCB_OK);
  assert_true(ei.mass == 2.0 && ei.stiffness == 1.0 && ei.index == 6 && ei.outer_d == 0.04);
  rcb_model_destroy(u);
}

/* A span of elements (issue #33), shaft.S.e<a>-<b>.stiffness | mass: a
 * view that sets the factor of elements a to b and no other, reads element
 * a's, and refuses what is not a span of the shaft. */
static void test_element_span_param(void **state) {
  rcb_model *m = rcb_test_model_from_example("paper_system.ini");
  rcb_element_info ei;
  size_t e;
  double v;
  (void)state;
  set(m, "shaft.B.e3-7.stiffness", 0.85);
  set(m, "shaft.B.e5-5.mass", 1.5); /* a span of one: element 5 */
  for (e = 0; e < rcb_model_element_count(m); e++) {
    int onB, in;
    assert_int_equal(rcb_model_element_info(m, e, &ei), RCB_OK);
    onB = strcmp(ei.shaft, "B") == 0;
    in = onB && ei.index >= 3 && ei.index <= 7;
    assert_true(ei.stiffness == (in ? 0.85 : 1.0));
    assert_true(ei.mass == (onB && ei.index == 5 ? 1.5 : 1.0));
  }
  assert_int_equal(rcb_model_get_param(m, "shaft.B.e3-7.stiffness", &v), RCB_OK);
  assert_true(v == 0.85);
  set(m, "shaft.B.e7.stiffness", 0.5); /* the elements stay separate parameters */
  assert_int_equal(rcb_model_get_param(m, "shaft.B.e6-7.stiffness", &v), RCB_OK);
  assert_true(v == 0.85); /* element a's */
  assert_int_equal(rcb_model_get_param(m, "shaft.B.e1-10.mass", &v), RCB_OK);
  expect_set_error(m, "shaft.B.e7-3.stiffness", 0.5, RCB_ERR_NOT_FOUND, "a <= b", NULL);
  expect_set_error(m, "shaft.B.e3-11.stiffness", 0.5, RCB_ERR_NOT_FOUND, "e1 to e10", NULL);
  expect_set_error(m, "shaft.B.e3-.stiffness", 0.5, RCB_ERR_NOT_FOUND, "e1 to e10", NULL);
  expect_set_error(m, "shaft.B.e3-07.mass", 0.5, RCB_ERR_NOT_FOUND, "e1 to e10", NULL);
  expect_set_error(m, "shaft.B.e3-7x.mass", 0.5, RCB_ERR_NOT_FOUND, "e1 to e10", NULL);
  expect_set_error(m, "shaft.B.e3-7.stiffness", 0.0, RCB_ERR_ARG, "expected a positive value",
                   NULL);
  assert_int_equal(rcb_model_get_param(m, "shaft.B.e7.stiffness", &v), RCB_OK);
  assert_true(v == 0.5); /* a refused span leaves every element as it was */
  rcb_model_destroy(m);
}

#define NMODE 8

/* The lowest NMODE damped frequencies of m at standstill, rad/s. */
static void frequencies(const rcb_model *m, double *wd) {
  rcb_modes *e = NULL;
  rcb_mode md[64];
  size_t n = 0, k;
  assert_int_equal(rcb_modes_create(&e, m, NULL), RCB_OK);
  if (rcb_modes_compute(e, 0.0, 64, md, &n, NULL) != RCB_OK)
    fail_msg("modes: %s", rcb_modes_errmsg(e));
  assert_true(n >= NMODE);
  for (k = 0; k < NMODE; k++) wd[k] = md[k].wd;
  rcb_modes_destroy(e);
}

/* Lowest root w of the simply supported Timoshenko beam, mode k:
 * (rho A w^2 - kGA q^2)(rho I w^2 - E I q^2 - kGA) - (kGA q)^2 = 0, q = k pi/L. */
static double timoshenko_ss(int k, double L, double d, double rho, double E, double nu,
                            double kappa) {
  const double A = PI * d * d / 4, Ie = PI * d * d * d * d / 64;
  const double kGA = kappa * E / (2 * (1 + nu)) * A, q = k * PI / L;
  const double a = rho * A * rho * Ie;
  const double b = -(rho * A * (E * Ie * q * q + kGA) + kGA * q * q * rho * Ie);
  const double c = kGA * E * Ie * q * q * q * q;
  return sqrt((-b - sqrt(b * b - 4 * a * c)) / (2 * a));
}

/* Natural frequencies: with every element's stiffness factor f the free-free
 * beam's frequencies are sqrt(f) times its own (K -> f K, M unchanged), and
 * with a mass factor g 1/sqrt(g) times; a stocky pinned-pinned Timoshenko
 * beam at factor f matches the closed form with E -> f E (G follows) as the
 * unmodified beam matches it with E. */
static void test_element_factor_frequencies(void **state) {
  const double f = 0.6, g = 1.7;
  double w0[NMODE], w1[NMODE];
  rcb_model *m = uniform_beam(1.0, 0.05, 24, 0.9);
  rcb_bearing_coefs bc;
  size_t k;
  (void)state;
  assert_int_equal(rcb_model_finalize(m), RCB_OK);
  frequencies(m, w0);
  set_all_elements(m, "stiffness", f);
  frequencies(m, w1);
  for (k = 0; k < NMODE; k++)
    if (!rcb_test_close(w1[k], sqrt(f) * w0[k], 1e-9, 0))
      fail_msg("stiffness %g, mode %zu: %.12g rad/s, expected sqrt(f) x %.12g", f, k, w1[k],
               w0[k]);
  set_all_elements(m, "stiffness", 1.0);
  set_all_elements(m, "mass", g);
  frequencies(m, w1);
  for (k = 0; k < NMODE; k++)
    if (!rcb_test_close(w1[k], w0[k] / sqrt(g), 1e-9, 0))
      fail_msg("mass %g, mode %zu: %.12g rad/s, expected %.12g / sqrt(g)", g, k, w1[k], w0[k]);
  rcb_model_destroy(m);
  /* pinned-pinned stocky beam (L/d = 4: shear matters), as test_modes */
  m = uniform_beam(0.4, 0.1, 40, 0.9);
  memset(&bc, 0, sizeof bc);
  bc.kxx = bc.kyy = 1e14;
  assert_int_equal(rcb_model_add_bearing(m, "B1", "S", 0.0, &bc), RCB_OK);
  assert_int_equal(rcb_model_add_bearing(m, "B2", "S", 0.4, &bc), RCB_OK);
  assert_int_equal(rcb_model_finalize(m), RCB_OK);
  set_all_elements(m, "stiffness", f);
  frequencies(m, w1);
  for (k = 1; k <= 3; k++) {
    double wt = timoshenko_ss((int)k, 0.4, 0.1, 7800, f * 2e11, 0.3, 0.9);
    assert_true(rcb_test_close(w1[2 * (k - 1)], wt, 5e-3, 0));
    assert_true(rcb_test_close(w1[2 * k - 1], wt, 5e-3, 0));
  }
  rcb_model_destroy(m);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_get_paper_values),
      cmocka_unit_test(test_set_coupling_kt),
      cmocka_unit_test(test_set_disk_mass_and_hub),
      cmocka_unit_test(test_set_bearing_cross),
      cmocka_unit_test(test_set_unbalance),
      cmocka_unit_test(test_set_errors),
      cmocka_unit_test(test_enumerate),
      cmocka_unit_test(test_set_before_finalize),
      cmocka_unit_test(test_write_round_trip_examples),
      cmocka_unit_test(test_write_round_trip_kramer_table),
      cmocka_unit_test(test_write_round_trip_after_set),
      cmocka_unit_test(test_write_round_trip_element_factors),
      cmocka_unit_test(test_write_sizing),
      cmocka_unit_test(test_write_unequal_hubs),
      cmocka_unit_test(test_write_long_names),
      cmocka_unit_test(test_write_bad_name),
      cmocka_unit_test(test_element_factor_identity),
      cmocka_unit_test(test_element_factor_local),
      cmocka_unit_test(test_element_factor_errors),
      cmocka_unit_test(test_element_span_param),
      cmocka_unit_test(test_element_factor_frequencies),
      cmocka_unit_test(test_shaft_factors),
      cmocka_unit_test(test_shaft_factors_ini),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
