/*
 * Numerical guard of the FRF solves (issue #7): the condition estimate of
 * each factorisation (zgecon / zgbcon / klu_z_condest) and the record of
 * the worst one over a sweep.
 *  - a well-posed sweep of the paper's system: no solve below the threshold;
 *  - a free rotor (no bearing) near omega = 0, Z = K - w^2 M singular up to
 *    the rigid-body term: flagged, at the frequency where it happens;
 *  - the estimate against the exact 1-norm condition (explicit inverse) and
 *    the 2-norm one (singular values, zgesvd) of Z formed here from
 *    rcb_model_matrices: the Hager-Higham estimator never overestimates
 *    ||Z^-1||_1 (rcond_est >= rcond_1) and stays within a small factor of
 *    it; kappa_1 and kappa_2 are within a factor n of each other.
 */
#include <complex.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>
#include <lapacke.h>

#include "rcb/rcb.h"
#include "rcb_test_util.h"

#define TWO_PI 6.283185307179586
#define RPM (TWO_PI / 60.0) /* rad/s per rpm */

/* The paper's system, 0-500 Hz at 10000 rpm: a normal sweep, no warning. */
static void test_normal_sweep(void **state) {
  rcb_model *m = rcb_test_model_from_example("paper_system.ini");
  rcb_solver_kind kinds[] = {RCB_SOLVER_DENSE, RCB_SOLVER_BANDED, RCB_SOLVER_SPARSE};
  size_t s, p, np = 201;
  (void)state;
  for (s = 0; s < 3; s++) {
    rcb_frf *f = NULL;
    rcb_dof d;
    rcb_frf_condition c;
    rcb_complex H[1];
    assert_int_equal(rcb_model_find_dof(m, "DA.x", &d), RCB_OK);
    if (rcb_frf_create(&f, m, 1, &d, 1, &d, kinds[s], NULL) == RCB_ERR_UNSUPPORTED) {
      rcb_frf_destroy(f); /* built without KLU */
      continue;
    }
    assert_true(isnan(rcb_frf_rcond(f))); /* nothing checked yet */
    /* the default screen finds no small pivot on a damped rotor: no estimate */
    for (p = 0; p < np; p++)
      assert_int_equal(rcb_frf_eval(f, TWO_PI * 500.0 * (double)p / (double)(np - 1),
                                    10000.0 * RPM, RCB_RECEPTANCE, H),
                       RCB_OK);
    assert_int_equal(rcb_frf_get_condition(f, &c), RCB_OK);
    assert_true(c.checked == np && c.estimated == 0 && c.ill == 0);
    assert_true(isnan(c.rcond_min));
    /* every solve estimated */
    assert_int_equal(rcb_frf_set_condition_check(f, RCB_COND_ALWAYS, RCB_RCOND_WARN), RCB_OK);
    for (p = 0; p < np; p++)
      assert_int_equal(rcb_frf_eval(f, TWO_PI * 500.0 * (double)p / (double)(np - 1),
                                    10000.0 * RPM, RCB_RECEPTANCE, H),
                       RCB_OK);
    assert_int_equal(rcb_frf_get_condition(f, &c), RCB_OK);
    assert_int_equal(c.checked, np);
    assert_int_equal(c.estimated, np);
    assert_int_equal(c.ill, 0);
    assert_true(c.rcond_min > RCB_RCOND_WARN && c.rcond_min <= 1.0);
    assert_true(c.rcond_min <= c.rcond_last);
    assert_true(rcb_frf_rcond(f) == c.rcond_min);
    rcb_frf_reset_condition(f);
    assert_true(isnan(rcb_frf_rcond(f)));
    rcb_frf_destroy(f);
  }
  rcb_model_destroy(m);
}

/* A free rotor just above omega = 0: the rigid-body modes leave Z singular
 * but for the -w^2 M term (relative size ~ w^2 m / k ~ 1e-13 at 1e-4 Hz),
 * so the factorisation succeeds and returns numbers that lost most digits. */
static void test_free_rotor_near_zero(void **state) {
  rcb_model *m = rcb_test_model_from_example("paper_freefree.ini");
  double w_bad = TWO_PI * 1e-4, w[3];
  int s;
  (void)state;
  w[0] = TWO_PI * 50.0, w[1] = w_bad, w[2] = TWO_PI * 100.0;
  for (s = RCB_SOLVER_DENSE; s <= RCB_SOLVER_SPARSE; s++) {
    rcb_frf *f = NULL;
    rcb_dof dof;
    assert_int_equal(rcb_model_find_dof(m, "DA.x", &dof), RCB_OK);
    if (rcb_frf_create(&f, m, 1, &dof, 1, &dof, (rcb_solver_kind)s, NULL) ==
        RCB_ERR_UNSUPPORTED) {
      rcb_frf_destroy(f); /* built without KLU */
      continue;
    }
    rcb_frf_condition c;
    rcb_complex H[1];
    size_t p;
    for (p = 0; p < 3; p++)
      assert_int_equal(rcb_frf_eval(f, w[p], 0.0, RCB_RECEPTANCE, H), RCB_OK);
    assert_int_equal(rcb_frf_get_condition(f, &c), RCB_OK);
    assert_int_equal(c.checked, 3);
    assert_int_equal(c.estimated, 1); /* the screen passes 50 and 100 Hz */
    assert_int_equal(c.ill, 1);
    assert_true(c.rcond_min < RCB_RCOND_WARN);
    assert_true(c.omega == w_bad && c.speed == 0.0);
    /* a looser threshold flags nothing; off: nothing is checked */
    assert_int_equal(rcb_frf_set_condition_check(f, 1, 1e-16), RCB_OK);
    assert_int_equal(rcb_frf_eval(f, w_bad, 0.0, RCB_RECEPTANCE, H), RCB_OK);
    assert_int_equal(rcb_frf_get_condition(f, &c), RCB_OK);
    assert_true(c.checked == 1 && c.ill == 0);
    assert_int_equal(rcb_frf_set_condition_check(f, 0, 1e-12), RCB_OK);
    assert_int_equal(rcb_frf_eval(f, w_bad, 0.0, RCB_RECEPTANCE, H), RCB_OK);
    assert_int_equal(rcb_frf_get_condition(f, &c), RCB_OK);
    assert_true(c.checked == 0 && isnan(c.rcond_min));
    assert_int_equal(rcb_frf_set_condition_check(f, 1, 0.0), RCB_ERR_ARG);
    assert_int_equal(rcb_frf_set_condition_check(f, 3, 1e-12), RCB_ERR_ARG);
    assert_int_equal(rcb_frf_set_condition_check(f, 1, (double)NAN), RCB_ERR_ARG);
    rcb_frf_destroy(f);
  }
  rcb_model_destroy(m);
}

/* Z(w, W) = K - w^2 M + i w (C + W G), dense, from the public matrices. */
static rcb_complex *dense_z(const rcb_model *m, double w, double W, size_t *n_out) {
  size_t n = rcb_model_dof_count(m), k;
  double *A = malloc(4 * n * n * sizeof *A);
  rcb_complex *Z = malloc(n * n * sizeof *Z);
  assert_non_null(A);
  assert_non_null(Z);
  assert_int_equal(rcb_model_matrices(m, W, A, A + n * n, A + 2 * n * n, A + 3 * n * n),
                   RCB_OK);
  for (k = 0; k < n * n; k++)
    Z[k] = CMPLX(A[3 * n * n + k] - w * w * A[k], w * (A[n * n + k] + W * A[2 * n * n + k]));
  free(A);
  *n_out = n;
  return Z;
}

static double norm1(const rcb_complex *Z, size_t n) {
  size_t i, j;
  double best = 0.0;
  for (j = 0; j < n; j++) {
    double s = 0.0;
    for (i = 0; i < n; i++) s += cabs(Z[i + n * j]);
    best = fmax(best, s);
  }
  return best;
}

/* 1 / (||Z||_1 ||Z^-1||_1) with the explicit inverse (zgetrf + zgetri). */
static double rcond1_exact(const rcb_complex *Z0, size_t n) {
  rcb_complex *Z = malloc(n * n * sizeof *Z);
  lapack_int *ipiv = malloc(n * sizeof *ipiv);
  double a, r;
  assert_true(Z && ipiv);
  memcpy(Z, Z0, n * n * sizeof *Z);
  a = norm1(Z, n);
  assert_int_equal(LAPACKE_zgetrf(LAPACK_COL_MAJOR, (lapack_int)n, (lapack_int)n,
                                  (lapack_complex_double *)Z, (lapack_int)n, ipiv),
                   0);
  assert_int_equal(LAPACKE_zgetri(LAPACK_COL_MAJOR, (lapack_int)n, (lapack_complex_double *)Z,
                                  (lapack_int)n, ipiv),
                   0);
  r = 1.0 / (a * norm1(Z, n));
  free(Z);
  free(ipiv);
  return r;
}

/* sigma_min / sigma_max by zgesvd. */
static double rcond2_svd(const rcb_complex *Z0, size_t n) {
  rcb_complex *Z = malloc(n * n * sizeof *Z);
  double *sv = malloc(n * sizeof *sv), *sup = malloc(n * sizeof *sup), r;
  assert_true(Z && sv && sup);
  memcpy(Z, Z0, n * n * sizeof *Z);
  assert_int_equal(LAPACKE_zgesvd(LAPACK_COL_MAJOR, 'N', 'N', (lapack_int)n, (lapack_int)n,
                                  (lapack_complex_double *)Z, (lapack_int)n, sv, NULL, 1, NULL,
                                  1, sup),
                   0);
  r = sv[n - 1] / sv[0];
  free(Z);
  free(sv);
  free(sup);
  return r;
}

static void check_against_svd(const char *example, double w, double W) {
  rcb_model *m = rcb_test_model_from_example(example);
  size_t n;
  rcb_complex *Z = dense_z(m, w, W, &n);
  double r1 = rcond1_exact(Z, n), r2 = rcond2_svd(Z, n);
  int s;
  for (s = RCB_SOLVER_DENSE; s <= RCB_SOLVER_SPARSE; s++) {
    rcb_frf *f = NULL;
    rcb_dof d;
    rcb_complex H[1];
    double est;
    assert_int_equal(rcb_model_find_dof(m, "DA.x", &d), RCB_OK);
    if (rcb_frf_create(&f, m, 1, &d, 1, &d, (rcb_solver_kind)s, NULL) == RCB_ERR_UNSUPPORTED) {
      rcb_frf_destroy(f);
      continue;
    }
    assert_int_equal(rcb_frf_set_condition_check(f, RCB_COND_ALWAYS, RCB_RCOND_WARN), RCB_OK);
    assert_int_equal(rcb_frf_eval(f, w, W, RCB_RECEPTANCE, H), RCB_OK);
    est = rcb_frf_rcond(f);
    print_message("%s w %g rad/s, W %g rad/s, solver %d: rcond est %.4g, exact 1-norm %.4g, "
                  "2-norm %.4g (n %zu)\n",
                  example, w, W, s, est, r1, r2, n);
    /* never above the exact value (to round-off), at most a factor 10 below */
    assert_true(est >= r1 * (1.0 - 1e-6) && est <= 10.0 * r1);
    /* the norms: kappa_2 / n <= kappa_1 <= n kappa_2 */
    assert_true(est >= r2 / (double)n * (1.0 - 1e-6) && est <= 10.0 * (double)n * r2);
    rcb_frf_destroy(f);
  }
  free(Z);
  rcb_model_destroy(m);
}

static void test_estimate_vs_svd(void **state) {
  (void)state;
  check_against_svd("paper_system.ini", TWO_PI * 120.0, 10000.0 * RPM);
  check_against_svd("paper_system.ini", 0.0, 0.0);
  check_against_svd("paper_freefree.ini", TWO_PI * 1e-3, 0.0);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_normal_sweep),
      cmocka_unit_test(test_free_rotor_near_zero),
      cmocka_unit_test(test_estimate_vs_svd),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
