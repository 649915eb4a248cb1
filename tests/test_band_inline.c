/*
 * The banded backend written out (rcb_zsolver_banded_inline, the monitor's
 * update-time sweeps) against LAPACK's (rcb_zsolver_banded) and against
 * the matrix itself:
 *  - on random complex band matrices whose diagonal does not dominate (so
 *    that rows pivot), square and unequal bands, one wider than the
 *    on-stack multiplier copy (kl > 32): the residual of Z X = B and of
 *    Z^T X = B by its own solves below 1e-13 relative, and LAPACK's zgbtrs
 *    and zgbcon reading its factors give its solutions and LAPACK's own
 *    condition estimate (the storage and pivots are zgbtf2's);
 *  - a zero column is RCB_ERR_SINGULAR;
 *  - an FRF object switched to it (rcb_frf_use_inline_band) gives the paper
 *    system's FRFs of the LAPACK backend to 1e-10 over a sweep through its
 *    resonances.
 */
#include <complex.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "analyses/analyses.h"
#include "rcb/rcb.h"
#include "rcb_test_util.h"
#include "solvers/zsolver.h"

#define NRHS 2

static double uniform(uint64_t *s) {
  *s = *s * 6364136223846793005ULL + 1442695040888963407ULL;
  return (double)(*s >> 11) / 9007199254740992.0 * 2.0 - 1.0;
}

/* A random band matrix: dense copy D (n x n) and band storage Z. */
static void random_band(const rcb_layout *L, uint64_t *seed, rcb_complex *D, rcb_complex *Z) {
  size_t n = L->n, i, j;
  memset(D, 0, n * n * sizeof *D);
  memset(Z, 0, rcb_layout_size(L) * sizeof *Z);
  for (j = 0; j < n; j++)
    for (i = j > L->ku ? j - L->ku : 0; i < n && i <= j + L->kl; i++) {
      rcb_complex v = CMPLX(uniform(seed), uniform(seed));
      D[i + n * j] = v;
      Z[rcb_layout_at(L, i, j)] = v;
    }
}

/* max |op(D) x - b| / (max |D| max |x|) over the columns. */
static double residual(const rcb_complex *D, size_t n, const rcb_complex *X,
                       const rcb_complex *B, size_t nrhs, char trans) {
  double worst = 0, dmax = 0, xmax = 0;
  size_t i, j, r;
  for (i = 0; i < n * n; i++) dmax = fmax(dmax, cabs(D[i]));
  for (i = 0; i < n * nrhs; i++) xmax = fmax(xmax, cabs(X[i]));
  for (r = 0; r < nrhs; r++)
    for (i = 0; i < n; i++) {
      rcb_complex s = -B[i + n * r];
      for (j = 0; j < n; j++) s += (trans == 'N' ? D[i + n * j] : D[j + n * i]) * X[j + n * r];
      worst = fmax(worst, cabs(s));
    }
  return worst / (dmax * xmax);
}

static void one_band(size_t n, size_t kl, size_t ku, uint64_t seed) {
  const rcb_zsolver_ops *in = rcb_zsolver_banded_inline(), *la = rcb_zsolver_banded();
  rcb_layout L;
  size_t sz, i, t;
  rcb_complex *D, *Z, *Z2, *B, *X, *X2;
  int *piv = malloc(n * sizeof *piv), *piv2 = malloc(n * sizeof *piv2);
  double rc_in, rc_la, rw[2 * 400], anorm;
  rcb_complex work[2 * 400];
  L.n = n, L.kl = kl, L.ku = ku, L.ld = 2 * kl + ku + 1, L.banded = 1, L.sparse = 0;
  L.colp = L.rowi = NULL, L.nnz = 0, L.solver = NULL;
  assert_true(n <= 400);
  sz = rcb_layout_size(&L);
  D = malloc(n * n * sizeof *D), Z = malloc(sz * sizeof *Z), Z2 = malloc(sz * sizeof *Z2);
  B = malloc(n * NRHS * sizeof *B), X = malloc(n * NRHS * sizeof *X);
  X2 = malloc(n * NRHS * sizeof *X2);
  assert_true(D && Z && Z2 && B && X && X2 && piv && piv2);
  random_band(&L, &seed, D, Z);
  memcpy(Z2, Z, sz * sizeof *Z);
  anorm = rcb_layout_norm1(&L, Z);
  for (i = 0; i < n * NRHS; i++) B[i] = CMPLX(uniform(&seed), uniform(&seed));
  for (t = 0; t < 2; t++) {
    char tr = t ? 'T' : 'N';
    double r;
    memcpy(X, B, n * NRHS * sizeof *X);
    if (!t) assert_int_equal(in->solve(&L, Z, piv, X, NRHS), RCB_OK);
    else assert_int_equal(in->resolve(&L, Z, piv, X, NRHS, 'T'), RCB_OK);
    r = residual(D, n, X, B, NRHS, tr);
    print_message("n %zu kl %zu ku %zu %c: residual %.2e\n", n, kl, ku, tr, r);
    if (r > 1e-13) fail_msg("inline band %c residual %g", tr, r);
    /* LAPACK's zgbtrs on the same factors */
    memcpy(X2, B, n * NRHS * sizeof *X2);
    assert_int_equal(la->resolve(&L, Z, piv, X2, NRHS, tr), RCB_OK);
    for (i = 0; i < n * NRHS; i++)
      if (cabs(X2[i] - X[i]) > 1e-10 * (1.0 + cabs(X[i])))
        fail_msg("zgbtrs on the inline factors differs at %zu (%c)", i, tr);
  }
  /* zgbcon on them: LAPACK's estimate from its own factors */
  memcpy(X2, B, n * NRHS * sizeof *X2);
  assert_int_equal(la->solve(&L, Z2, piv2, X2, NRHS), RCB_OK);
  assert_int_equal(in->rcond(&L, Z, piv, anorm, work, rw, &rc_in), RCB_OK);
  assert_int_equal(la->rcond(&L, Z2, piv2, anorm, work, rw, &rc_la), RCB_OK);
  assert_true(fabs(rc_in - rc_la) <= 1e-6 * rc_la);
  /* a zero column */
  random_band(&L, &seed, D, Z);
  for (i = 0; i < n; i++)
    if (i + ku >= n / 2 && i <= n / 2 + kl) Z[rcb_layout_at(&L, i, n / 2)] = 0.0;
  memcpy(X, B, n * NRHS * sizeof *X);
  assert_int_equal(in->solve(&L, Z, piv, X, NRHS), RCB_ERR_SINGULAR);
  free(D), free(Z), free(Z2), free(B), free(X), free(X2), free(piv), free(piv2);
}

static void test_random_bands(void **state) {
  (void)state;
  one_band(88, 7, 7, 1);
  one_band(60, 3, 9, 2);
  one_band(50, 11, 2, 3);
  one_band(120, 40, 35, 4); /* kl > the on-stack copy */
  one_band(1, 0, 0, 5);
}

/* The paper system's FRFs through an object switched to the inline band. */
static void test_frf_switched(void **state) {
  rcb_model *m = rcb_test_model_from_example("paper_system.ini");
  rcb_dof od[2], id;
  rcb_frf *fl = NULL, *fi = NULL;
  size_t i, c;
  double worst = 0, peak = 0;
  (void)state;
  assert_int_equal(rcb_model_find_dof(m, "DA.x", &od[0]), RCB_OK);
  assert_int_equal(rcb_model_find_dof(m, "C.B.y", &od[1]), RCB_OK);
  assert_int_equal(rcb_model_find_dof(m, "DA.x", &id), RCB_OK);
  assert_int_equal(rcb_frf_create(&fl, m, 2, od, 1, &id, RCB_SOLVER_BANDED, NULL), RCB_OK);
  assert_int_equal(rcb_frf_create(&fi, m, 2, od, 1, &id, RCB_SOLVER_BANDED, NULL), RCB_OK);
  assert_int_equal(rcb_frf_use_inline_band(fi), RCB_OK);
  for (i = 0; i < 400; i++) {
    double w = 2 * RCB_PI * (20.0 + 380.0 * (double)i / 399.0), W = 10000.0 * RCB_PI / 30.0;
    rcb_complex hl[2], hi[2];
    assert_int_equal(rcb_frf_eval(fl, w, W, RCB_RECEPTANCE, hl), RCB_OK);
    assert_int_equal(rcb_frf_eval(fi, w, W, RCB_RECEPTANCE, hi), RCB_OK);
    for (c = 0; c < 2; c++) {
      worst = fmax(worst, cabs(hl[c] - hi[c]));
      peak = fmax(peak, cabs(hl[c]));
    }
  }
  print_message("paper system, inline band vs zgbsv: %.2e of the peak\n", worst / peak);
  assert_true(worst <= 1e-10 * peak); /* banded vs dense 3e-12 (docs/benchmarks.md) */
  rcb_frf_destroy(fl);
  rcb_frf_destroy(fi);
  rcb_model_destroy(m);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_random_bands),
      cmocka_unit_test(test_frf_switched),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
