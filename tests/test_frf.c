/*
 * FRF and unbalance response, checked against things that could prove them
 * wrong:
 *  - a rigid rotor on springs: H = 1/(k - w^2 m + i w c) in closed form;
 *  - the paper's real 2n-form of the unbalance response (eq. 4), solved
 *    independently with dgesv from the force written as cos/sin terms;
 *  - reciprocity: H symmetric at standstill, H(W)^T = H(-W) when spinning;
 *  - coupling limits: Nelson-Crandall with large kt, kr -> rigid; a rigid
 *    coupling at zero gap = one continuous shaft; kramer_1 = Nelson-Crandall
 *    with large kt and kr = 0; kramer_2 likewise with kr, cr;
 *  - dense zgesv and banded zgbsv agree; a sweep allocates nothing; two
 *    threads give bit-identical results to one.
 */
#include <complex.h>
#include <math.h>
#include <pthread.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>
#include <lapacke.h>

#include "core/rcb_internal.h"
#include "rcb_test_util.h"

#define RPM (RCB_PI / 30.0)

static int cclose(double complex a, double complex b, double rtol) {
  return cabs(a - b) <= rtol * fmax(cabs(a), cabs(b));
}

/* The paper's two-shaft system (issue #2 reconstruction) through the
 * builder API, with a chosen coupling model and parameters, and an optional
 * gap (m) between the coupling stations. */
static rcb_model *two_shafts(rcb_coupling_model type, double kt, double kr, double ct,
                             double cr, double gap, int with_bearings) {
  rcb_model *m = NULL;
  rcb_bearing_coefs b13 = {5e7, 0, 0, 7e7, 500, 0, 0, 700};
  rcb_bearing_coefs b24 = {7e7, 0, 0, 9e7, 300, 0, 0, 500};
  rcb_coupling_params p = {kt, kr, ct, cr, {0, 0}, {0, 0}, {0, 0}};
  double dm, dId, dIp, zb = 0.5 + gap;
  assert_int_equal(rcb_model_create(&m, NULL), RCB_OK);
  assert_int_equal(rcb_model_add_material(m, "steel", 7759.255, 1.936e11, 0.3), RCB_OK);
  assert_int_equal(rcb_model_add_shaft(m, "A", "steel", 0.0, 0.9), RCB_OK);
  assert_int_equal(rcb_model_add_segment(m, "A", 0.5, 0.017, 0.0, 10), RCB_OK);
  if (with_bearings)
    assert_int_equal(rcb_model_set_shaft_damping(m, "A", 15.691, 22.989e-6), RCB_OK);
  assert_int_equal(rcb_model_add_shaft(m, "B", "steel", zb, 0.9), RCB_OK);
  assert_int_equal(rcb_model_add_segment(m, "B", 0.5, 0.017, 0.0, 10), RCB_OK);
  if (with_bearings)
    assert_int_equal(rcb_model_set_shaft_damping(m, "B", 15.691, 22.989e-6), RCB_OK);
  assert_int_equal(rcb_disk_from_geometry(6303.235, 0.09, 0.017, 0.025, &dm, &dId, &dIp), 0);
  assert_int_equal(rcb_model_add_disk(m, "DA", "A", 0.20, dm, dId, dIp), RCB_OK);
  assert_int_equal(rcb_model_add_disk(m, "DB", "B", zb + 0.30, dm, dId, dIp), RCB_OK);
  if (with_bearings) {
    assert_int_equal(rcb_model_add_bearing(m, "B1", "A", 0.05, &b13), RCB_OK);
    assert_int_equal(rcb_model_add_bearing(m, "B2", "A", 0.35, &b24), RCB_OK);
    assert_int_equal(rcb_model_add_bearing(m, "B3", "B", zb + 0.15, &b13), RCB_OK);
    assert_int_equal(rcb_model_add_bearing(m, "B4", "B", zb + 0.45, &b24), RCB_OK);
  }
  assert_int_equal(rcb_coupling_hubs_from_geometry(2758.219, 0.006, 0.017, 0.043115, &p), 0);
  assert_int_equal(rcb_model_add_coupling(m, "C", type, "A", 0.5, "B", zb, &p), RCB_OK);
  assert_int_equal(rcb_model_add_unbalance(m, "UA", "A", 0.20, 15e-5, 0.0), RCB_OK);
  assert_int_equal(rcb_model_add_unbalance(m, "UB", "B", zb + 0.30, 15e-5, RCB_PI / 2), RCB_OK);
  assert_int_equal(rcb_model_finalize(m), RCB_OK);
  return m;
}

static void dofs(const rcb_model *m, const char *const *specs, size_t n, rcb_dof *out) {
  size_t i;
  for (i = 0; i < n; i++)
    if (rcb_model_find_dof(m, specs[i], &out[i])) fail_msg("%s", rcb_model_errmsg(m));
}

/* H (nout x nin) at omega, speed, for channel specs. */
static void frf_at(const rcb_model *m, const char *const *outs, size_t nout,
                   const char *const *ins, size_t nin, double omega, double speed,
                   rcb_solver_kind solver, rcb_complex *H) {
  rcb_dof od[8], id[8];
  rcb_frf *f = NULL;
  dofs(m, outs, nout, od);
  dofs(m, ins, nin, id);
  assert_int_equal(rcb_frf_create(&f, m, nout, od, nin, id, solver, NULL), RCB_OK);
  if (rcb_frf_eval(f, omega, speed, RCB_RECEPTANCE, H)) fail_msg("%s", rcb_frf_errmsg(f));
  rcb_frf_destroy(f);
}

static void test_rigid_rotor_closed_form(void **state) {
  /* A short, very stiff shaft with a heavy central disk on two equal
   * isotropic bearings at its ends: a force at the disk excites only the
   * rigid translation, H = 1/(2k - w^2 m_total + i w 2c), up to the shaft's
   * flexibility: an artificially stiff material (E = 2.1e14 Pa) puts
   * k / k_shaft near 3e-8, so even at resonance (Q ~ 23) the error is < 1e-5. */
  const double k = 1e6, c = 300, L = 0.2, d = 0.2, rho = 7800;
  rcb_model *m = NULL;
  rcb_bearing_coefs b = {k, 0, 0, k, c, 0, 0, c};
  const char *out[] = {"D.x"}, *in[] = {"D.x"};
  double mt = rho * RCB_PI * d * d / 4 * L + 50.0, w;
  rcb_complex H;
  (void)state;
  assert_int_equal(rcb_model_create(&m, NULL), RCB_OK);
  assert_int_equal(rcb_model_add_material(m, "steel", rho, 2.1e14, 0.3), RCB_OK);
  assert_int_equal(rcb_model_add_shaft(m, "S", "steel", 0.0, 0.9), RCB_OK);
  assert_int_equal(rcb_model_add_segment(m, "S", L, d, 0.0, 4), RCB_OK);
  assert_int_equal(rcb_model_add_disk(m, "D", "S", 0.1, 50.0, 1.0, 1.5), RCB_OK);
  assert_int_equal(rcb_model_add_bearing(m, "L", "S", 0.0, &b), RCB_OK);
  assert_int_equal(rcb_model_add_bearing(m, "R", "S", 0.2, &b), RCB_OK);
  assert_int_equal(rcb_model_finalize(m), RCB_OK);
  for (w = 10; w < 400; w *= 1.7) {
    double complex ref = 1.0 / (2 * k - w * w * mt + RCB_J * w * 2 * c);
    frf_at(m, out, 1, in, 1, w, 0.0, RCB_SOLVER_DENSE, &H);
    if (!cclose(H, ref, 1e-4))
      fail_msg("w = %g: H = %g%+gi, closed form %g%+gi", w, creal(H), cimag(H), creal(ref),
               cimag(ref));
  }
  rcb_model_destroy(m);
}

/* Paper eq. 4: [K - W^2 M, W D; -W D, K - W^2 M] [qc; qs] = [Fc; Fs], D = C + W G,
 * with the unbalance forces written from f_x = me W^2 cos(W t + phase),
 * f_y = me W^2 sin(W t + phase). Then Q = qc - i qs. */
static void test_unbalance_paper_eq4(void **state) {
  rcb_model *m = two_shafts(RCB_COUPLING_NELSON_CRANDALL_2, 46.095e3, 220.76, 10.949,
                            10.949e-6, 0.02, 1);
  const char *outs[] = {"DA.x", "DA.y", "C.A.x", "C.B.y", "DB.x", "DB.ry"};
  size_t n = rcb_model_dof_count(m), nn = 2 * n, i, j, o;
  double *M = calloc(n * n, sizeof *M), *C = calloc(n * n, sizeof *C);
  double *G = calloc(n * n, sizeof *G), *K = calloc(n * n, sizeof *K);
  double *A = calloc(nn * nn, sizeof *A), *F = calloc(nn, sizeof *F);
  int *piv = calloc(nn, sizeof *piv);
  rcb_dof od[6];
  rcb_frf *f = NULL;
  rcb_complex Q[6];
  const double W = 6000 * RPM;
  const char *where[2] = {"DA.x", "DB.x"};
  const double phase[2] = {0.0, RCB_PI / 2};
  (void)state;
  assert_int_equal(rcb_model_matrices(m, W, M, C, G, K), RCB_OK);
  for (j = 0; j < n; j++)
    for (i = 0; i < n; i++) {
      double kd = K[i + n * j] - W * W * M[i + n * j], dd = W * (C[i + n * j] + W * G[i + n * j]);
      A[i + nn * j] = kd;
      A[(i + n) + nn * (j + n)] = kd;
      A[i + nn * (j + n)] = dd;
      A[(i + n) + nn * j] = -dd;
    }
  for (i = 0; i < 2; i++) {
    rcb_dof d;
    size_t r;
    double f0 = 15e-5 * W * W;
    assert_int_equal(rcb_model_find_dof(m, where[i], &d), RCB_OK);
    assert_int_equal(rcb_model_dof_index(m, d, &r), RCB_OK);
    F[r] += f0 * cos(phase[i]);          /* x, cos */
    F[r + n] += -f0 * sin(phase[i]);     /* x, sin */
    F[r + 1] += f0 * sin(phase[i]);      /* y, cos */
    F[r + 1 + n] += f0 * cos(phase[i]);  /* y, sin */
  }
  assert_int_equal(LAPACKE_dgesv(LAPACK_COL_MAJOR, (lapack_int)nn, 1, A, (lapack_int)nn, piv, F,
                                 (lapack_int)nn),
                   0);
  dofs(m, outs, 6, od);
  assert_int_equal(rcb_frf_create(&f, m, 6, od, 0, NULL, RCB_SOLVER_AUTO, NULL), RCB_OK);
  assert_int_equal(rcb_frf_unbalance(f, W, Q), RCB_OK);
  for (o = 0; o < 6; o++) {
    size_t r;
    assert_int_equal(rcb_model_dof_index(m, od[o], &r), RCB_OK);
    assert_true(cclose(Q[o], F[r] - RCB_J * F[r + n], 1e-9));
  }
  rcb_frf_destroy(f);
  free(M);
  free(C);
  free(G);
  free(K);
  free(A);
  free(F);
  free(piv);
  rcb_model_destroy(m);
}

static void test_reciprocity(void **state) {
  rcb_model *m = two_shafts(RCB_COUPLING_NELSON_CRANDALL_2, 46.095e3, 220.76, 10.949,
                            10.949e-6, 0.02, 1);
  const char *ch[] = {"DA.x", "DB.y", "C.B.rx", "B2.y"};
  rcb_complex H0[16], Hp[16], Hm[16];
  size_t i, j;
  (void)state;
  frf_at(m, ch, 4, ch, 4, 2 * RCB_PI * 250, 0.0, RCB_SOLVER_DENSE, H0);
  frf_at(m, ch, 4, ch, 4, 2 * RCB_PI * 250, 10000 * RPM, RCB_SOLVER_DENSE, Hp);
  frf_at(m, ch, 4, ch, 4, 2 * RCB_PI * 250, -10000 * RPM, RCB_SOLVER_DENSE, Hm);
  for (i = 0; i < 4; i++)
    for (j = 0; j < 4; j++) {
      assert_true(cclose(H0[i + 4 * j], H0[j + 4 * i], 1e-10));
      assert_true(cclose(Hp[i + 4 * j], Hm[j + 4 * i], 1e-10));
    }
  /* and the gyroscopic effect is really there: spinning breaks symmetry */
  assert_false(cclose(Hp[0 + 4 * 1], Hp[1 + 4 * 0], 1e-3));
  rcb_model_destroy(m);
}

/* Compare the same channels of two models at several frequencies. */
static void same_frf(const rcb_model *a, const rcb_model *b, const char *const *outs,
                     size_t nout, double speed, double rtol) {
  const char *in[] = {"DA.x", "DB.y"};
  rcb_complex Ha[16], Hb[16];
  double f;
  size_t k;
  for (f = 20; f < 1000; f *= 1.9) {
    frf_at(a, outs, nout, in, 2, 2 * RCB_PI * f, speed, RCB_SOLVER_DENSE, Ha);
    frf_at(b, outs, nout, in, 2, 2 * RCB_PI * f, speed, RCB_SOLVER_DENSE, Hb);
    for (k = 0; k < 2 * nout; k++)
      if (!cclose(Ha[k], Hb[k], rtol))
        fail_msg("f = %g Hz, entry %zu: %g%+gi vs %g%+gi", f, k, creal(Ha[k]), cimag(Ha[k]),
                 creal(Hb[k]), cimag(Hb[k]));
  }
}

static void test_coupling_limits(void **state) {
  const char *outs[] = {"DA.x", "DB.y", "C.A.x", "C.B.y", "C.A.ry", "C.B.rx"};
  const char *tr[] = {"DA.x", "DB.y", "C.A.x", "C.B.y"}; /* kramer leaves rotations apart */
  const double W = 8000 * RPM, big = 1e13;
  rcb_model *rigid = two_shafts(RCB_COUPLING_RIGID, 0, 0, 0, 0, 0.02, 1);
  rcb_model *nc1 = two_shafts(RCB_COUPLING_NELSON_CRANDALL_1, big, big, 0, 0, 0.02, 1);
  rcb_model *k1 = two_shafts(RCB_COUPLING_KRAMER_1, 0, 0, 0, 0, 0.02, 1);
  rcb_model *nc1t = two_shafts(RCB_COUPLING_NELSON_CRANDALL_1, big, 0, 0, 0, 0.02, 1);
  rcb_model *k2 = two_shafts(RCB_COUPLING_KRAMER_2, 0, 220.76, 0, 10.949e-3, 0.02, 1);
  rcb_model *nc2 = two_shafts(RCB_COUPLING_NELSON_CRANDALL_2, big, 220.76, 0, 10.949e-3, 0.02, 1);
  (void)state;
  assert_int_equal(rcb_model_dof_count(rigid), 84);
  assert_int_equal(rcb_model_dof_count(k1), 86);
  assert_int_equal(rcb_model_dof_count(nc1), 88);
  same_frf(nc1, rigid, outs, 6, W, 1e-5);
  same_frf(nc1t, k1, tr, 4, W, 1e-5);
  same_frf(nc2, k2, tr, 4, W, 1e-5);
  rcb_model_destroy(rigid);
  rcb_model_destroy(nc1);
  rcb_model_destroy(k1);
  rcb_model_destroy(nc1t);
  rcb_model_destroy(k2);
  rcb_model_destroy(nc2);
}

static void test_rigid_equals_continuous(void **state) {
  /* zero gap: shafts A [0, 0.5] and B [0.5, 1.0] joined rigidly, without hub
   * inertia, against one shaft of 20 elements carrying the same items */
  rcb_model *two = NULL, *one = NULL;
  rcb_coupling_params none = {0};
  rcb_bearing_coefs b = {5e7, 1e6, -1e6, 7e7, 500, 10, 10, 700};
  const char *outs[] = {"DA.x", "DB.y", "J.x", "J.ry", "B2.y"};
  int k;
  (void)state;
  for (k = 0; k < 2; k++) {
    rcb_model *m = NULL;
    const char *sb = k ? "B" : "A";
    assert_int_equal(rcb_model_create(&m, NULL), RCB_OK);
    assert_int_equal(rcb_model_add_material(m, "steel", 7759.255, 1.936e11, 0.3), RCB_OK);
    assert_int_equal(rcb_model_add_shaft(m, "A", "steel", 0.0, 0.9), RCB_OK);
    assert_int_equal(rcb_model_add_segment(m, "A", k ? 0.5 : 1.0, 0.017, 0.0, k ? 10 : 20), 0);
    if (k) {
      assert_int_equal(rcb_model_add_shaft(m, "B", "steel", 0.5, 0.9), RCB_OK);
      assert_int_equal(rcb_model_add_segment(m, "B", 0.5, 0.017, 0.0, 10), RCB_OK);
      assert_int_equal(rcb_model_add_coupling(m, "J", RCB_COUPLING_RIGID, "A", 0.5, "B", 0.5,
                                              &none), RCB_OK);
    } else {
      assert_int_equal(rcb_model_add_station(m, "J", "A", 0.5), RCB_OK);
    }
    assert_int_equal(rcb_model_add_disk(m, "DA", "A", 0.2, 1.2, 6e-4, 1.1e-3), RCB_OK);
    assert_int_equal(rcb_model_add_disk(m, "DB", sb, 0.8, 1.2, 6e-4, 1.1e-3), RCB_OK);
    assert_int_equal(rcb_model_add_bearing(m, "B1", "A", 0.05, &b), RCB_OK);
    assert_int_equal(rcb_model_add_bearing(m, "B2", sb, 0.95, &b), RCB_OK);
    assert_int_equal(rcb_model_finalize(m), RCB_OK);
    if (k)
      two = m;
    else
      one = m;
  }
  assert_int_equal(rcb_model_dof_count(two), rcb_model_dof_count(one));
  same_frf(two, one, outs, 5, 9000 * RPM, 1e-10);
  rcb_model_destroy(two);
  rcb_model_destroy(one);
}

static void test_dense_banded_kinds(void **state) {
  rcb_model *m = two_shafts(RCB_COUPLING_NELSON_CRANDALL_2, 46.095e3, 220.76, 10.949,
                            10.949e-6, 0.02, 1);
  const char *outs[] = {"C.A.x", "C.A.y", "C.B.x", "C.B.y"}, *ins[] = {"DA.x", "DA.y"};
  rcb_dof od[4], id[2];
  rcb_frf *fd = NULL, *fb = NULL;
  rcb_complex Hd[8], Hb[8], Hm[8], Ha[8];
  double f;
  size_t k;
  (void)state;
  dofs(m, outs, 4, od);
  dofs(m, ins, 2, id);
  assert_int_equal(rcb_frf_create(&fd, m, 4, od, 2, id, RCB_SOLVER_DENSE, NULL), RCB_OK);
  assert_int_equal(rcb_frf_create(&fb, m, 4, od, 2, id, RCB_SOLVER_BANDED, NULL), RCB_OK);
  assert_int_equal(rcb_frf_solver(fb), RCB_SOLVER_BANDED);
  assert_true(rcb_frf_memory(fb) < rcb_frf_memory(fd));
  for (f = 5; f < 2000; f *= 1.3) {
    double w = 2 * RCB_PI * f;
    assert_int_equal(rcb_frf_eval(fd, w, 10000 * RPM, RCB_RECEPTANCE, Hd), RCB_OK);
    assert_int_equal(rcb_frf_eval(fb, w, 10000 * RPM, RCB_RECEPTANCE, Hb), RCB_OK);
    assert_int_equal(rcb_frf_eval(fb, w, 10000 * RPM, RCB_MOBILITY, Hm), RCB_OK);
    assert_int_equal(rcb_frf_eval(fb, w, 10000 * RPM, RCB_INERTANCE, Ha), RCB_OK);
    for (k = 0; k < 8; k++) {
      assert_true(cclose(Hd[k], Hb[k], 1e-10));
      assert_true(cclose(Hm[k], RCB_J * w * Hb[k], 1e-14));
      assert_true(cclose(Ha[k], -w * w * Hb[k], 1e-14));
    }
  }
  rcb_frf_destroy(fd);
  rcb_frf_destroy(fb);
  rcb_model_destroy(m);
}

static void test_sweep_allocates_nothing(void **state) {
  rcb_test_counter cnt = {0, 0};
  rcb_allocator a = rcb_test_counting_allocator(&cnt);
  rcb_model *m = two_shafts(RCB_COUPLING_NELSON_CRANDALL_2, 46.095e3, 220.76, 10.949,
                            10.949e-6, 0.02, 1);
  rcb_dof d[2];
  const char *ch[] = {"DA.x", "DB.y"};
  rcb_frf *f = NULL;
  rcb_complex H[4];
  size_t before, i;
  (void)state;
  dofs(m, ch, 2, d);
  assert_int_equal(rcb_frf_create(&f, m, 2, d, 2, d, RCB_SOLVER_AUTO, &a), RCB_OK);
  before = cnt.allocs;
  assert_true(before > 0);
  for (i = 1; i <= 200; i++) {
    assert_int_equal(rcb_frf_eval(f, 10.0 * (double)i, 5000 * RPM, RCB_INERTANCE, H), RCB_OK);
    assert_int_equal(rcb_frf_unbalance(f, 5.0 * (double)i, H), RCB_OK);
  }
  assert_int_equal(cnt.allocs, before);
  rcb_frf_destroy(f);
  assert_int_equal(cnt.frees, cnt.allocs);
  rcb_model_destroy(m);
}

/* Two threads sweeping two models give bit-identical results to one. */
typedef struct {
  rcb_model *m;
  rcb_complex H[400];
} sweep_job;

static void *sweep(void *arg) {
  sweep_job *j = arg;
  const char *ch[] = {"C.A.x", "DB.y"};
  rcb_dof d[2];
  rcb_frf *f = NULL;
  size_t i;
  dofs(j->m, ch, 2, d);
  if (rcb_frf_create(&f, j->m, 2, d, 2, d, RCB_SOLVER_AUTO, NULL)) return NULL;
  for (i = 0; i < 100; i++)
    rcb_frf_eval(f, 2 * RCB_PI * (10.0 + 5.0 * (double)i), 7000 * RPM, RCB_RECEPTANCE,
                 &j->H[4 * i]);
  rcb_frf_destroy(f);
  return NULL;
}

static void test_threads_bit_identical(void **state) {
  sweep_job *ser = calloc(2, sizeof *ser), *par = calloc(2, sizeof *par);
  pthread_t t[2];
  int k;
  (void)state;
  for (k = 0; k < 2; k++) {
    ser[k].m = two_shafts(k ? RCB_COUPLING_KRAMER_2 : RCB_COUPLING_NELSON_CRANDALL_2, 46.095e3,
                          220.76, k ? 0 : 10.949, 10.949e-6, 0.02, 1);
    par[k].m = ser[k].m;
    sweep(&ser[k]);
  }
  for (k = 0; k < 2; k++) assert_int_equal(pthread_create(&t[k], NULL, sweep, &par[k]), 0);
  for (k = 0; k < 2; k++) assert_int_equal(pthread_join(t[k], NULL), 0);
  for (k = 0; k < 2; k++) {
    assert_memory_equal(ser[k].H, par[k].H, sizeof ser[k].H);
    rcb_model_destroy(ser[k].m);
  }
  free(ser);
  free(par);
}

static void test_free_free(void **state) {
  /* no bearings (and no shaft or coupling damping): the FRF exists for
   * omega > 0; far below the first elastic mode (~36 Hz, the coupling) the
   * free rotor moves as one rigid body, H = -(1/m + d^2/J)/w^2 */
  rcb_model *m = two_shafts(RCB_COUPLING_NELSON_CRANDALL_1, 46.095e3, 220.76, 0, 0, 0.02, 0);
  const char *ch[] = {"DA.x"};
  rcb_complex H1, H2;
  (void)state;
  frf_at(m, ch, 1, ch, 1, 2 * RCB_PI * 0.2, 0.0, RCB_SOLVER_AUTO, &H1);
  frf_at(m, ch, 1, ch, 1, 2 * RCB_PI * 0.4, 0.0, RCB_SOLVER_AUTO, &H2);
  assert_true(creal(H1) < 0 && fabs(cimag(H1)) < 1e-12 * fabs(creal(H1)));
  assert_true(isfinite(creal(H1)) && cabs(H1) > 0);
  /* mass line: halving the frequency quadruples the receptance */
  assert_true(rcb_test_close(cabs(H1) / cabs(H2), 4.0, 1e-3, 0));
  rcb_model_destroy(m);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_rigid_rotor_closed_form),
      cmocka_unit_test(test_unbalance_paper_eq4),
      cmocka_unit_test(test_reciprocity),
      cmocka_unit_test(test_coupling_limits),
      cmocka_unit_test(test_rigid_equals_continuous),
      cmocka_unit_test(test_dense_banded_kinds),
      cmocka_unit_test(test_sweep_allocates_nothing),
      cmocka_unit_test(test_threads_bit_identical),
      cmocka_unit_test(test_free_free),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
