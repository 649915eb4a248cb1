/*
 * Sparse (KLU) solver path, checked against the LAPACK ones it must agree
 * with:
 *  - the structural pattern holds every nonzero of the assembled matrices
 *    (so no value can fall outside it), sorted and duplicate-free;
 *  - dense zgesv and sparse KLU agree to 1e-10 (normwise relative) on the
 *    paper system over a sweep that crosses its resonances (where kept
 *    pivots are most likely to go bad), for FRFs and unbalance responses;
 *  - the same on a generated long train (6 shafts, all five coupling models,
 *    cross-coupled and speed-dependent bearings): dense vs sparse to 1e-10,
 *    banded vs sparse to 1e-9;
 *  - the fit's analytic Jacobian (eq. 9) through KLU against its finite
 *    differences, on a train where AUTO picks KLU;
 *  - the transposed re-solve (sensitivities) matches dense;
 *  - a sweep allocates nothing through the object's allocator;
 *  - without SuiteSparse, RCB_SOLVER_SPARSE fails with RCB_ERR_UNSUPPORTED
 *    and AUTO falls back to LAPACK.
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

#include "analyses/frf_internal.h"
#include "identify/identify.h"
#include "rcb/rcb_config.h"
#include "rcb_test_util.h"

#define RPM (RCB_PI / 30.0)
#define TOL 1e-10

static void find_dofs(const rcb_model *m, const char *const *specs, size_t n, rcb_dof *out) {
  size_t i;
  for (i = 0; i < n; i++)
    if (rcb_model_find_dof(m, specs[i], &out[i])) fail_msg("%s", rcb_model_errmsg(m));
}

/* A long train: nsh shafts of nel elements of 0.05 m (two sections each),
 * a disk mid-span, two bearings per shaft with cross-coupled coefficients
 * (the first one speed-dependent), couplings between consecutive shafts
 * cycling through the five models, an unbalance on every disk. */
static rcb_model *long_train(int nsh, int nel) {
  static const rcb_coupling_model kinds[5] = {
      RCB_COUPLING_NELSON_CRANDALL_2, RCB_COUPLING_KRAMER_2, RCB_COUPLING_NELSON_CRANDALL_1,
      RCB_COUPLING_RIGID, RCB_COUPLING_KRAMER_1};
  const double le = 0.05, gap = 0.02, Ls = nel * le;
  rcb_model *m = NULL;
  int s;
  assert_int_equal(rcb_model_create(&m, NULL), RCB_OK);
  assert_int_equal(rcb_model_add_material(m, "steel", 7810, 2.1e11, 0.3), RCB_OK);
  for (s = 0; s < nsh; s++) {
    char sh[16], name[32], prev[16];
    double z0 = s * (Ls + gap), d = 0.08 + 0.01 * s;
    int n1 = (2 * nel) / 5;
    rcb_bearing_coefs b = {2e8, 3e7, -3e7, 2.5e8, 2e4, 1e3, 1e3, 2.5e4};
    snprintf(sh, sizeof sh, "S%d", s);
    assert_int_equal(rcb_model_add_shaft(m, sh, "steel", z0, 0.9), RCB_OK);
    assert_int_equal(rcb_model_set_shaft_damping(m, sh, 2.0, 2e-6), RCB_OK);
    assert_int_equal(rcb_model_add_segment(m, sh, n1 * le, d, 0.0, n1), RCB_OK);
    assert_int_equal(rcb_model_add_segment(m, sh, (nel - n1) * le, d + 0.03, 0.02, nel - n1),
                     RCB_OK);
    snprintf(name, sizeof name, "D%d", s);
    assert_int_equal(rcb_model_add_disk(m, name, sh, z0 + (nel / 2) * le, 40.0 + s, 0.8, 1.5),
                     RCB_OK);
    snprintf(name, sizeof name, "U%d", s);
    assert_int_equal(
        rcb_model_add_unbalance(m, name, sh, z0 + (nel / 2) * le, 1e-4, 0.7 * s), RCB_OK);
    snprintf(name, sizeof name, "B%da", s);
    if (s == 0) {
      const double speeds[2] = {0.0, 600.0};
      rcb_bearing_coefs t[2] = {b, b};
      t[1].kxx *= 1.5;
      t[1].kxy *= 2.0;
      t[1].cyy *= 0.5;
      assert_int_equal(
          rcb_model_add_bearing_table(m, name, sh, z0 + le, 2, speeds, t), RCB_OK);
    } else {
      assert_int_equal(rcb_model_add_bearing(m, name, sh, z0 + le, &b), RCB_OK);
    }
    snprintf(name, sizeof name, "B%db", s);
    b.kxx *= 0.7;
    b.cyy *= 1.3;
    assert_int_equal(rcb_model_add_bearing(m, name, sh, z0 + (nel - 1) * le, &b), RCB_OK);
    if (s > 0) {
      rcb_coupling_params p = {5e6, 2e4, 50.0, 0.5, {1.0, 1.0}, {2e-3, 2e-3}, {3e-3, 3e-3}};
      snprintf(prev, sizeof prev, "S%d", s - 1);
      snprintf(name, sizeof name, "C%d", s);
      assert_int_equal(rcb_model_add_coupling(m, name, kinds[(s - 1) % 5], prev,
                                              (s - 1) * (Ls + gap) + Ls, sh, z0, &p),
                       RCB_OK);
    }
  }
  if (rcb_model_finalize(m)) fail_msg("%s", rcb_model_errmsg(m));
  return m;
}

static rcb_frf *make_frf(const rcb_model *m, const char *const *outs, size_t nout,
                         const char *const *ins, size_t nin, rcb_solver_kind kind,
                         const rcb_allocator *a) {
  rcb_dof od[8], id[4];
  rcb_frf *f = NULL;
  rcb_status st;
  find_dofs(m, outs, nout, od);
  find_dofs(m, ins, nin, id);
  st = rcb_frf_create(&f, m, nout, od, nin, id, kind, a);
  if (st) fail_msg("rcb_frf_create(%d): %s", (int)kind, rcb_status_str(st));
  return f;
}

#if RCB_WITH_SUITESPARSE

/* max |a - b| / max |a| over n entries */
static double rel_diff(const rcb_complex *a, const rcb_complex *b, size_t n) {
  double num = 0.0, den = 0.0;
  size_t i;
  for (i = 0; i < n; i++) {
    num = fmax(num, cabs(a[i] - b[i]));
    den = fmax(den, cabs(a[i]));
  }
  return den > 0 ? num / den : num;
}

/* Every nonzero of M, C, G, K (bearings included, at two speeds) is in the
 * pattern; columns are sorted, duplicate-free and hold their diagonal. */
static void check_pattern(const rcb_model *m) {
  size_t n = m->ndof, nnz, i, j, s;
  int *colp = NULL, *rowi = NULL;
  double *A = calloc(4 * n * n, sizeof *A);
  rcb_allocator a;
  rcb_allocator_init(&a, NULL);
  assert_non_null(A);
  assert_int_equal(rcb_csc_pattern(m, &a, &colp, &rowi, &nnz), RCB_OK);
  assert_int_equal(colp[0], 0);
  assert_int_equal((size_t)colp[n], nnz);
  for (j = 0; j < n; j++) {
    int p, diag = 0;
    for (p = colp[j]; p < colp[j + 1]; p++) {
      if (p > colp[j]) assert_true(rowi[p] > rowi[p - 1]);
      diag |= (size_t)rowi[p] == j;
    }
    assert_true(diag);
  }
  for (s = 0; s < 2; s++) {
    assert_int_equal(
        rcb_model_matrices(m, s ? 700.0 : 0.0, A, A + n * n, A + 2 * n * n, A + 3 * n * n),
        RCB_OK);
    for (j = 0; j < n; j++)
      for (i = 0; i < n; i++) {
        int k, found = 0, p;
        for (k = 0; k < 4; k++) found |= A[k * n * n + i + n * j] != 0.0;
        if (!found) continue;
        for (p = colp[j]; p < colp[j + 1]; p++) found = found && (size_t)rowi[p] != i;
        if (found) fail_msg("nonzero (%zu, %zu) not in the pattern", i, j);
      }
  }
  rcb_free(&a, colp);
  rcb_free(&a, rowi);
  free(A);
}

static void test_pattern_covers_matrices(void **state) {
  rcb_model *m = rcb_test_model_from_example("paper_system.ini"), *t = long_train(6, 12);
  (void)state;
  check_pattern(m);
  check_pattern(t);
  rcb_model_destroy(m);
  rcb_model_destroy(t);
}

/* Dense vs sparse on the paper system: 400 frequencies 0.5 Hz .. 4 kHz at
 * 0 and 6000 rpm (resonances included), 4 outputs x 2 inputs, and the
 * unbalance response over 0..12000 rpm. Kept-pivot refactorisations must
 * have been used (else the test would not exercise them). */
static void test_paper_dense_vs_sparse(void **state) {
  static const char *const outs[] = {"DA.x", "DB.y", "C.A.rx", "C.B.ry"};
  static const char *const ins[] = {"DA.x", "DB.y"};
  rcb_model *m = rcb_test_model_from_example("paper_system.ini");
  rcb_frf *fd = make_frf(m, outs, 4, ins, 2, RCB_SOLVER_DENSE, NULL);
  rcb_frf *fs = make_frf(m, outs, 4, ins, 2, RCB_SOLVER_SPARSE, NULL);
  rcb_complex Hd[8], Hs[8];
  double worst = 0.0;
  size_t k, factors, refactors;
  int sp;
  (void)state;
  assert_int_equal(rcb_frf_solver(fs), RCB_SOLVER_SPARSE);
  for (sp = 0; sp < 2; sp++)
    for (k = 0; k < 400; k++) {
      double w = 2 * RCB_PI * (0.5 + (double)k * 10.0), W = sp * 6000 * RPM, e;
      assert_int_equal(rcb_frf_eval(fd, w, W, RCB_RECEPTANCE, Hd), RCB_OK);
      if (rcb_frf_eval(fs, w, W, RCB_RECEPTANCE, Hs)) fail_msg("%s", rcb_frf_errmsg(fs));
      e = rel_diff(Hd, Hs, 8);
      worst = fmax(worst, e);
      if (e > TOL) fail_msg("f = %g Hz, %g rpm: dense vs sparse %.3g", w / (2 * RCB_PI),
                            W / RPM, e);
    }
  for (k = 0; k <= 240; k++) {
    double W = (double)k * 50 * RPM;
    assert_int_equal(rcb_frf_unbalance(fd, W, Hd), RCB_OK);
    assert_int_equal(rcb_frf_unbalance(fs, W, Hs), RCB_OK);
    worst = fmax(worst, rel_diff(Hd, Hs, 4));
    if (rel_diff(Hd, Hs, 4) > TOL) fail_msg("unbalance at %g rpm: %.3g", W / RPM,
                                            rel_diff(Hd, Hs, 4));
  }
  rcb_zsolver_sparse_counts(&fs->L, &factors, &refactors);
  print_message("paper system: worst dense/sparse difference %.3g; %zu factorisations, %zu "
                "refactorisations\n", worst, factors, refactors);
  assert_true(refactors > factors);
  rcb_frf_destroy(fd);
  rcb_frf_destroy(fs);
  rcb_model_destroy(m);
}

/* The long train: dense vs sparse (1e-10) at every third point of a sweep
 * at speed and on the unbalance response; banded vs sparse at every point
 * to 1e-9 only: near resonances this Z is conditioned so that the two
 * LAPACK paths themselves differ by ~1.3e-10 (KLU stays within 3e-11 of
 * zgesv there). */
static void test_train_agreement(void **state) {
  static const char *const outs[] = {"D0.x", "D2.y", "C3.S3.rx", "D5.x", "C1.S0.y", "B4a.x"};
  static const char *const ins[] = {"D0.x", "D3.y", "C4.S3.ry"};
  rcb_model *m = long_train(6, 20);
  rcb_frf *fb = make_frf(m, outs, 6, ins, 3, RCB_SOLVER_BANDED, NULL);
  rcb_frf *fs = make_frf(m, outs, 6, ins, 3, RCB_SOLVER_SPARSE, NULL);
  rcb_frf *fd = make_frf(m, outs, 6, ins, 3, RCB_SOLVER_DENSE, NULL);
  rcb_complex Hb[18], Hs[18], Hd[18];
  double worst = 0.0, e;
  size_t k;
  (void)state;
  print_message("train: %zu DOF, half-bandwidth %zu\n", m->ndof, m->bandwidth);
  for (k = 0; k < 300; k++) {
    double w = 2 * RCB_PI * (1.0 + (double)k * 7.0), W = 3600 * RPM;
    assert_int_equal(rcb_frf_eval(fb, w, W, RCB_MOBILITY, Hb), RCB_OK);
    if (rcb_frf_eval(fs, w, W, RCB_MOBILITY, Hs)) fail_msg("%s", rcb_frf_errmsg(fs));
    e = rel_diff(Hb, Hs, 18);
    worst = fmax(worst, e);
    if (e > 1e-9) fail_msg("f = %g Hz: banded vs sparse %.3g", w / (2 * RCB_PI), e);
    if (k % 3 == 0) {
      assert_int_equal(rcb_frf_eval(fd, w, W, RCB_MOBILITY, Hd), RCB_OK);
      e = rel_diff(Hd, Hs, 18);
      worst = fmax(worst, e);
      if (e > TOL) fail_msg("f = %g Hz: dense vs sparse %.3g", w / (2 * RCB_PI), e);
    }
  }
  for (k = 1; k <= 100; k++) {
    double W = (double)k * 100 * RPM;
    assert_int_equal(rcb_frf_unbalance(fd, W, Hd), RCB_OK);
    assert_int_equal(rcb_frf_unbalance(fs, W, Hs), RCB_OK);
    e = rel_diff(Hd, Hs, 6);
    worst = fmax(worst, e);
    if (e > TOL) fail_msg("unbalance at %g rpm: %.3g", W / RPM, e);
  }
  print_message("train: worst difference %.3g\n", worst);
  rcb_frf_destroy(fb);
  rcb_frf_destroy(fs);
  rcb_frf_destroy(fd);
  rcb_model_destroy(m);
}

/* resolve with 'T' solves Z^T X = B (the adjoint used by sensitivities):
 * multiply back with the dense Z^T. */
static void test_transposed_resolve(void **state) {
  static const char *const outs[] = {"DA.x"};
  static const char *const ins[] = {"DB.y"};
  rcb_model *m = rcb_test_model_from_example("paper_system.ini");
  rcb_frf *fd = make_frf(m, outs, 1, ins, 1, RCB_SOLVER_DENSE, NULL);
  rcb_frf *fs = make_frf(m, outs, 1, ins, 1, RCB_SOLVER_SPARSE, NULL);
  size_t n = m->ndof, i, j;
  rcb_complex *Zd = calloc(n * n, sizeof *Zd), *x = calloc(n, sizeof *x),
              *b = calloc(n, sizeof *b);
  double w = 2 * RCB_PI * 300, W = 3000 * RPM, num = 0, den = 0;
  (void)state;
  assert_non_null(Zd);
  /* Dense Z: factor_solve leaves the LU in fd->Z, so form it from a copy. */
  memset(fd->B, 0, n * sizeof *fd->B);
  memset(fs->B, 0, n * sizeof *fs->B);
  assert_int_equal(rcb_frf_factor_solve(fs, w, W, 1), RCB_OK);
  for (j = 0; j < n; j++)
    for (i = 0; i < n; i++) {
      size_t a;
      int p, in = 0;
      for (p = fs->L.colp[j]; p < fs->L.colp[j + 1]; p++) in |= (size_t)fs->L.rowi[p] == i;
      if (!in) continue;
      a = rcb_layout_at(&fs->L, i, j);
      Zd[i + n * j] = fs->Z[a];
    }
  for (i = 0; i < n; i++) x[i] = b[i] = CMPLX(cos(0.3 * (double)i), sin(0.7 * (double)i));
  assert_int_equal(fs->ops->resolve(&fs->L, fs->Z, fs->ipiv, x, 1, 'T'), RCB_OK);
  /* residual Z^T x - b */
  for (j = 0; j < n; j++) {
    double complex r = -b[j];
    for (i = 0; i < n; i++) r += Zd[i + n * j] * x[i];
    num = fmax(num, cabs(r));
    den = fmax(den, cabs(b[j]));
  }
  if (num / den > 1e-9) fail_msg("transposed residual %.3g", num / den);
  free(Zd);
  free(x);
  free(b);
  rcb_frf_destroy(fd);
  rcb_frf_destroy(fs);
  rcb_model_destroy(m);
}

static void test_sweep_allocates_nothing(void **state) {
  static const char *const outs[] = {"DA.x", "DB.y"};
  static const char *const ins[] = {"DA.x"};
  rcb_test_counter c = {0, 0};
  rcb_allocator a = rcb_test_counting_allocator(&c);
  rcb_model *m = rcb_test_model_from_example("paper_system.ini");
  rcb_frf *f = make_frf(m, outs, 2, ins, 1, RCB_SOLVER_SPARSE, &a);
  rcb_complex H[2];
  size_t before = c.allocs, k;
  (void)state;
  for (k = 0; k < 50; k++)
    assert_int_equal(rcb_frf_eval(f, 10.0 + 40.0 * (double)k, 300.0, RCB_RECEPTANCE, H),
                     RCB_OK);
  assert_int_equal(c.allocs, before);
  assert_true(rcb_frf_memory(f) > 0);
  rcb_frf_destroy(f);
  assert_int_equal(c.allocs, c.frees);
  rcb_model_destroy(m);
}

/* AUTO picks KLU from 32 DOF: a train of a few thousand DOF, one of 32;
 * LAPACK below (24 DOF). */
static void test_auto_picks_sparse(void **state) {
  static const char *const outs[] = {"D0.x"};
  static const char *const ins[] = {"D0.x"};
  static const struct {
    int nsh, nel;
    size_t ndof;
    int sparse;
  } cases[] = {{6, 100, 0, 1}, {1, 7, 32, 1}, {1, 5, 24, 0}};
  size_t k;
  (void)state;
  for (k = 0; k < sizeof cases / sizeof cases[0]; k++) {
    rcb_model *m = long_train(cases[k].nsh, cases[k].nel);
    rcb_frf *f = make_frf(m, outs, 1, ins, 1, RCB_SOLVER_AUTO, NULL);
    if (cases[k].ndof)
      assert_int_equal(m->ndof, cases[k].ndof);
    else
      assert_true(m->ndof >= 2000);
    assert_int_equal(rcb_frf_solver(f) == RCB_SOLVER_SPARSE, cases[k].sparse);
    rcb_frf_destroy(f);
    rcb_model_destroy(m);
  }
}

/* KLU calls the free-free paper rotor singular at 0 Hz, as LAPACK does (its
 * scaled pivot ratio is 4.4e-16 there), and solves it at 1e-4 Hz (2.8e-10),
 * matching the dense solution; the failed frequency leaves the object
 * usable. */
static void test_sparse_singular_free_free(void **state) {
  static const char *const outs[] = {"DA.x"};
  static const char *const ins[] = {"DA.x"};
  rcb_model *m = rcb_test_model_from_example("paper_freefree.ini");
  rcb_frf *fs = make_frf(m, outs, 1, ins, 1, RCB_SOLVER_SPARSE, NULL);
  rcb_frf *fd = make_frf(m, outs, 1, ins, 1, RCB_SOLVER_DENSE, NULL);
  rcb_complex hs, hd;
  double w = 2.0 * 3.14159265358979323846 * 1e-4; /* rad/s */
  (void)state;
  assert_int_equal(rcb_frf_eval(fd, 0.0, 0.0, RCB_RECEPTANCE, &hd), RCB_ERR_SINGULAR);
  assert_int_equal(rcb_frf_eval(fs, 0.0, 0.0, RCB_RECEPTANCE, &hs), RCB_ERR_SINGULAR);
  assert_int_equal(rcb_frf_eval(fs, w, 0.0, RCB_RECEPTANCE, &hs), RCB_OK);
  assert_int_equal(rcb_frf_eval(fd, w, 0.0, RCB_RECEPTANCE, &hd), RCB_OK);
  /* rcond 2.1e-12 here (tests/test_frf_condition.c): the two agree to
   * eps / rcond = 1e-4 at best (measured 2.1e-6) */
  if (cabs(hs - hd) > 1e-4 * cabs(hd)) fail_msg("sparse %g vs dense %g", cabs(hs), cabs(hd));
  rcb_frf_destroy(fs);
  rcb_frf_destroy(fd);
  rcb_model_destroy(m);
}

/* The fit's analytic sensitivities (eq. 9: dZ x over the CSC entries, then
 * a re-solve with the kept KLU factors) against its finite differences, on
 * a train large enough for AUTO to pick KLU. */
static void test_fit_jacobian_sparse(void **state) {
  static const char *const outs[] = {"D1.x", "D2.y"};
  static const char *const ins[] = {"D1.x"};
  static const char *const names[] = {"coupling.C1.kt", "bearing.B2a.kxx", "disk.D1.mass"};
  rcb_model *m = long_train(6, 100);
  rcb_frf *fr = make_frf(m, outs, 2, ins, 1, RCB_SOLVER_SPARSE, NULL);
  rcb_meas *ms = NULL;
  rcb_fit *fit = NULL;
  double x[6], *Ja, *Jf, worst = 0.0, scale = 0.0;
  rcb_complex H[12], col[6];
  size_t i, o, n, k;
  (void)state;
  for (i = 0; i < 6; i++) {
    x[i] = 2 * RCB_PI * (20.0 + 37.0 * (double)i);
    assert_int_equal(rcb_frf_eval(fr, x[i], 200.0, RCB_RECEPTANCE, H + 2 * i), RCB_OK);
  }
  assert_int_equal(rcb_meas_create(&ms, NULL), RCB_OK);
  assert_int_equal(rcb_meas_set_grid(ms, RCB_MEAS_FRF, 6, x, 200.0), RCB_OK);
  for (o = 0; o < 2; o++) {
    for (i = 0; i < 6; i++) col[i] = 1.1 * H[2 * i + o];
    assert_int_equal(rcb_meas_add_channel(ms, outs[o], ins[0], RCB_RECEPTANCE, col), RCB_OK);
  }
  if (rcb_fit_create(&fit, m, ms, NULL)) fail_msg("%s", rcb_fit_errmsg(fit));
  assert_int_equal(rcb_fit_get_solver(fit), RCB_SOLVER_SPARSE);
  for (k = 0; k < 3; k++) {
    double p;
    assert_int_equal(rcb_model_get_param(m, names[k], &p), RCB_OK);
    if (rcb_fit_add_param(fit, names[k], 0.1 * p, 10 * p, 1)) fail_msg("%s", rcb_fit_errmsg(fit));
  }
  n = rcb_fit_residual_count(fit);
  Ja = calloc(3 * n, sizeof *Ja);
  Jf = calloc(3 * n, sizeof *Jf);
  assert_int_equal(rcb_fit_jacobian(fit, 1, Ja), RCB_OK);
  assert_int_equal(rcb_fit_jacobian(fit, 0, Jf), RCB_OK);
  for (k = 0; k < 3; k++) {
    double colmax = 0.0, err = 0.0;
    for (i = 0; i < n; i++) {
      colmax = fmax(colmax, fabs(Ja[i + n * k]));
      err = fmax(err, fabs(Ja[i + n * k] - Jf[i + n * k]));
    }
    assert_true(colmax > 0.0);
    worst = fmax(worst, err / colmax);
    scale = fmax(scale, colmax);
  }
  print_message("fit Jacobian on %zu DOF (KLU): analytic vs forward differences %.3g\n",
                m->ndof, worst);
  /* forward differences with a 1e-3 relative step: O(1e-3) truncation */
  assert_true(worst < 1e-2);
  free(Ja);
  free(Jf);
  rcb_fit_destroy(fit);
  rcb_meas_destroy(ms);
  rcb_frf_destroy(fr);
  rcb_model_destroy(m);
}

#else /* !RCB_WITH_SUITESPARSE */

static void test_sparse_unsupported(void **state) {
  static const char *const outs[] = {"DA.x"};
  static const char *const ins[] = {"DA.x"};
  rcb_model *m = rcb_test_model_from_example("paper_system.ini"), *t = long_train(6, 100);
  rcb_dof od, id;
  rcb_frf *f = NULL;
  (void)state;
  find_dofs(m, outs, 1, &od);
  find_dofs(m, ins, 1, &id);
  assert_int_equal(rcb_frf_create(&f, m, 1, &od, 1, &id, RCB_SOLVER_SPARSE, NULL),
                   RCB_ERR_UNSUPPORTED);
  assert_null(f);
  assert_null(rcb_zsolver_sparse());
  f = make_frf(t, outs + 0, 0, ins, 0, RCB_SOLVER_AUTO, NULL);
  assert_int_equal(rcb_frf_solver(f), RCB_SOLVER_BANDED);
  rcb_frf_destroy(f);
  rcb_model_destroy(m);
  rcb_model_destroy(t);
}

#endif

int main(void) {
  const struct CMUnitTest tests[] = {
#if RCB_WITH_SUITESPARSE
      cmocka_unit_test(test_pattern_covers_matrices),
      cmocka_unit_test(test_paper_dense_vs_sparse),
      cmocka_unit_test(test_train_agreement),
      cmocka_unit_test(test_transposed_resolve),
      cmocka_unit_test(test_sweep_allocates_nothing),
      cmocka_unit_test(test_auto_picks_sparse),
      cmocka_unit_test(test_sparse_singular_free_free),
      cmocka_unit_test(test_fit_jacobian_sparse),
#else
      cmocka_unit_test(test_sparse_unsupported),
#endif
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
