/*
 * The sensitivities behind the diagnosis' score test, and the score test's
 * orthogonalisation (LAPACK QR, src/diagnose/score_qr.c):
 *  - eq. 9 by the adjoint (one transposed re-solve of the outputs per point,
 *    rcb_frf_solve_adjoint) and by the direct re-solve (rcb_frf_solve_again)
 *    give the same Jacobian columns to 1e-9, for FRFs and unbalance
 *    responses: two paths through the FRF object's factorisation;
 *  - the predicted reductions of candidates scored in one batched sweep of
 *    the base model equal those from a sweep of each candidate alone;
 *  - the predicted reduction equals RSS(J0) - RSS([J0 Jc]), the drop of the
 *    least-squares residual sum when the candidate's columns join the fitted
 *    ones, both from LAPACK dgels (an independent computation); the residual
 *    projected off J0 is orthogonal to every column of J0;
 *  - a column that is a combination of those before it (any scale) adds
 *    nothing: a candidate inside span(J0) predicts 0, and a duplicated
 *    column in J0 or in the candidate leaves the scores unchanged.
 */
#include <complex.h>
#include <lapacke.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "diagnose/diagnose.h" /* the score test's QR (the internal interface) */
#include "identify/identify.h" /* the adjoint choice (the internal interface) */
#include "rcb_test_util.h"

#define RPM (RCB_PI / 30.0)
#define TWO_PI (2.0 * RCB_PI)

/* A fit of m to ms on log10 magnitudes with parameters names[0 .. np). */
static rcb_fit *fit_of(rcb_model *m, const rcb_meas *ms, const char *const *names, size_t np) {
  rcb_fit *f = NULL;
  size_t k;
  assert_int_equal(rcb_fit_create(&f, m, ms, NULL), RCB_OK);
  assert_int_equal(rcb_fit_set_scale(f, RCB_SCALE_LOG10), RCB_OK);
  for (k = 0; k < np; k++) {
    double p;
    assert_int_equal(rcb_model_get_param(m, names[k], &p), RCB_OK);
    assert_int_equal(rcb_fit_add_param(f, names[k], -1e9, 1e9 + 10 * fabs(p), 0), RCB_OK);
  }
  return f;
}

/* max_j |a_j - b_j| / max_j |b_j| over n values. */
static double rel_diff(const double *a, const double *b, size_t n) {
  double d = 0.0, s = 0.0;
  size_t j;
  for (j = 0; j < n; j++) {
    d = fmax(d, fabs(a[j] - b[j]));
    s = fmax(s, fabs(b[j]));
  }
  return s > 0 ? d / s : d;
}

static double sumsq(const double *r, size_t n) {
  double F = 0.0;
  size_t i;
  for (i = 0; i < n; i++) F += r[i] * r[i];
  return F;
}

/* The Jacobian of all parameters at once (the adjoint path: few outputs,
 * many parameters x inputs) against one fit per parameter (the direct
 * re-solve: one parameter, as many right-hand sides as inputs). */
static void adjoint_vs_direct(rcb_model *m, const rcb_meas *ms, const char *const *names,
                              size_t np) {
  rcb_fit *fa = fit_of(m, ms, names, np);
  size_t n = rcb_fit_residual_count(fa), k;
  double *Ja = calloc(n * np, sizeof *Ja), *Jd = calloc(n, sizeof *Jd);
  assert_true(n > 0);
  assert_true(rcb_fit_adjoint_cheaper(fa));
  assert_int_equal(rcb_fit_jacobian(fa, 1, Ja), RCB_OK);
  for (k = 0; k < np; k++) {
    rcb_fit *fd = fit_of(m, ms, names + k, 1);
    double e;
    assert_false(rcb_fit_adjoint_cheaper(fd));
    assert_int_equal(rcb_fit_residual_count(fd), n);
    assert_int_equal(rcb_fit_jacobian(fd, 1, Jd), RCB_OK);
    e = rel_diff(Ja + n * k, Jd, n);
    print_message("  %-28s adjoint vs direct %.2e\n", names[k], e);
    assert_true(e < 1e-9);
    rcb_fit_destroy(fd);
  }
  free(Ja);
  free(Jd);
  rcb_fit_destroy(fa);
}

static void test_adjoint_equals_direct_frf(void **state) {
  rcb_model *m = rcb_test_model_from_example("paper_system.ini");
  const char *outs[] = {"C.A.x", "C.B.y", "DB.x"}, *ins[] = {"DA.x", "C.B.x"};
  const char *names[] = {"coupling.C.kt", "coupling.C.kr", "coupling.C.ct", "bearing.B2.kxx",
                         "bearing.B2.kcross", "disk.DA.mass", "shaft.B.damping_stiffness"};
  rcb_meas *ms = rcb_test_frf_meas(m, outs, 3, ins, 2, 120, 400, 25, 10000, RCB_INERTANCE);
  (void)state;
  adjoint_vs_direct(m, ms, names, 7);
  rcb_meas_destroy(ms);
  rcb_model_destroy(m);
}

static void test_adjoint_equals_direct_unbalance(void **state) {
  rcb_model *m = rcb_test_model_from_example("paper_system.ini");
  const char *outs[] = {"C.A.x", "C.A.y", "C.B.x", "C.B.y"};
  const char *names[] = {"coupling.C.kt", "coupling.C.kr", "coupling.C.ct",
                         "unbalance.UB.phase", "unbalance.UA.amount"};
  rcb_meas *ms = rcb_test_unbalance_meas(m, outs, 4, 300, 18300, 25);
  (void)state;
  adjoint_vs_direct(m, ms, names, 5);
  rcb_meas_destroy(ms);
  rcb_model_destroy(m);
}

/* ---- the score test ---- */

/* The case: the paper system against inertances of a truth with a
 * cross-coupled B2 and a softer coupling; base parameters kt, kr, ct;
 * candidates B2 kcross, DA mass, B3 kxx and kyy together, shaft A damping. */
#define NBASE 3
#define NCAND 4
static const char *const base_names[NBASE] = {"coupling.C.kt", "coupling.C.kr",
                                              "coupling.C.ct"};
static const char *const cand_names[NCAND][2] = {{"bearing.B2.kcross", NULL},
                                                 {"disk.DA.mass", NULL},
                                                 {"bearing.B3.kxx", "bearing.B3.kyy"},
                                                 {"shaft.A.damping_stiffness", NULL}};
static const size_t cand_np[NCAND] = {1, 1, 2, 1};

typedef struct score_case {
  rcb_model *m;
  rcb_meas *ms;
  rcb_diag *d;
  size_t n;
  double *r, *J0, *Jc[NCAND]; /* residual; base columns; each candidate's (direct sweep) */
} score_case;

static void case_open(score_case *sc) {
  rcb_model *truth = rcb_test_model_edited("paper_system.ini", "[bearing B2]",
                                            "kxy = 2e7\nkyx = -2e7\n");
  const char *outs[] = {"DA.x", "DA.y", "C.A.x", "C.B.y", "DB.x", "DB.y"}, *ins[] = {"DA.x"};
  rcb_fit *f;
  size_t k;
  memset(sc, 0, sizeof *sc);
  assert_int_equal(rcb_model_set_param(truth, "coupling.C.kt", 3e4), RCB_OK);
  sc->ms = rcb_test_frf_meas(truth, outs, 6, ins, 1, 100, 400, 61, 10000, RCB_INERTANCE);
  rcb_model_destroy(truth);
  sc->m = rcb_test_model_from_example("paper_system.ini");
  assert_int_equal(rcb_diag_create(&sc->d, sc->m, sc->ms, NULL), RCB_OK);
  f = fit_of(sc->m, sc->ms, base_names, NBASE);
  sc->n = rcb_fit_residual_count(f);
  sc->r = calloc(sc->n, sizeof *sc->r);
  sc->J0 = calloc(sc->n * NBASE, sizeof *sc->J0);
  assert_int_equal(rcb_fit_residuals(f, sc->r), RCB_OK);
  assert_int_equal(rcb_fit_jacobian(f, 1, sc->J0), RCB_OK);
  rcb_fit_destroy(f);
  for (k = 0; k < NCAND; k++) {
    f = fit_of(sc->m, sc->ms, cand_names[k], cand_np[k]);
    sc->Jc[k] = calloc(sc->n * cand_np[k], sizeof *sc->Jc[k]);
    assert_int_equal(rcb_fit_residual_count(f), sc->n);
    assert_int_equal(rcb_fit_jacobian(f, 1, sc->Jc[k]), RCB_OK);
    rcb_fit_destroy(f);
  }
}

static void case_close(score_case *sc) {
  size_t k;
  for (k = 0; k < NCAND; k++) free(sc->Jc[k]);
  free(sc->r);
  free(sc->J0);
  rcb_diag_destroy(sc->d);
  rcb_meas_destroy(sc->ms);
  rcb_model_destroy(sc->m);
}

/* Predicted reduction of candidate columns J (n x np, copied) against base
 * columns J0 (n x nb). */
static double predicted(score_case *sc, const double *J0, size_t nb, const double *J, size_t np,
                        size_t *rank) {
  diag_basis b;
  double *Jw = malloc(sc->n * np * sizeof *Jw), pred = -1.0;
  memcpy(Jw, J, sc->n * np * sizeof *Jw);
  assert_int_equal(rcb_diag_basis_init(sc->d, &b, J0, sc->n, nb, sc->r), RCB_OK);
  assert_int_equal(rcb_diag_explained(sc->d, &b, Jw, np, &pred), RCB_OK);
  if (rank) *rank = b.rank;
  rcb_diag_basis_free(sc->d, &b);
  free(Jw);
  return pred;
}

/* Residual sum of squares of the least-squares fit of r by the columns of
 * [A B] (n x (na + nb)), by LAPACK dgels. */
static double rss(const score_case *sc, const double *A, size_t na, const double *B, size_t nb) {
  size_t n = sc->n, k = na + nb, i;
  double *M = malloc(n * k * sizeof *M), *y = malloc(n * sizeof *y), s = 0.0;
  memcpy(M, A, n * na * sizeof *M);
  if (nb) memcpy(M + n * na, B, n * nb * sizeof *M);
  memcpy(y, sc->r, n * sizeof *y);
  assert_int_equal(LAPACKE_dgels(LAPACK_COL_MAJOR, 'N', (lapack_int)n, (lapack_int)k, 1, M,
                                 (lapack_int)n, y, (lapack_int)n),
                   0);
  for (i = k; i < n; i++) s += y[i] * y[i];
  free(M);
  free(y);
  return s;
}

/* Batched (one sweep of the base model, the adjoint) and alone (a sweep of
 * each candidate's own fit) give the same scores. */
static void test_batched_scores_equal_alone(void **state) {
  score_case sc;
  rcb_fit *fb, *fc;
  rcb_fit_dz dz[5];
  size_t k, off = 0, ndz = 0;
  double *J;
  rcb_allocator a; /* malloc, as the dz's owner */
  (void)state;
  rcb_allocator_init(&a, NULL);
  case_open(&sc);
  fb = fit_of(sc.m, sc.ms, base_names, NBASE);
  for (k = 0; k < NCAND; k++) {
    fc = fit_of(sc.m, sc.ms, cand_names[k], cand_np[k]);
    assert_int_equal(rcb_fit_dz_get(fc, &a, dz + ndz), RCB_OK);
    ndz += cand_np[k];
    rcb_fit_destroy(fc);
  }
  J = calloc(sc.n * ndz, sizeof *J);
  assert_int_equal(rcb_fit_jacobian_dz(fb, dz, ndz, J), RCB_OK);
  for (k = 0; k < NCAND; k++) {
    double pb = predicted(&sc, sc.J0, NBASE, J + sc.n * off, cand_np[k], NULL);
    double pa = predicted(&sc, sc.J0, NBASE, sc.Jc[k], cand_np[k], NULL);
    print_message("  %-28s batched %.10g alone %.10g (F %.6g)\n", cand_names[k][0], pb, pa,
                  sumsq(sc.r, sc.n));
    assert_true(pa > 0);
    assert_true(rcb_test_close(pb, pa, 1e-8, 0.0));
    off += cand_np[k];
  }
  rcb_fit_dz_free(&a, dz, ndz);
  free(J);
  rcb_fit_destroy(fb);
  case_close(&sc);
}

/* The predicted reduction is the drop of the least-squares residual when
 * the candidate joins the base, and the residual left by the base is
 * orthogonal to its columns. */
static void test_score_identities(void **state) {
  score_case sc;
  diag_basis b;
  size_t k, i, j, rank;
  double rss0, nr = 0.0, *z;
  (void)state;
  case_open(&sc);
  rss0 = rss(&sc, sc.J0, NBASE, NULL, 0);
  for (k = 0; k < NCAND; k++) {
    double p = predicted(&sc, sc.J0, NBASE, sc.Jc[k], cand_np[k], &rank);
    double drop = rss0 - rss(&sc, sc.J0, NBASE, sc.Jc[k], cand_np[k]);
    print_message("  %-28s QR %.12g, RSS drop %.12g (RSS0 %.6g)\n", cand_names[k][0], p, drop,
                  rss0);
    assert_int_equal(rank, NBASE);
    assert_true(p > 1e-6 * rss0);
    assert_true(rcb_test_close(p, drop, 1e-8, 1e-12 * rss0));
  }
  /* r - Q0 Q0^T r from the basis: rt with its first rank rows zeroed, then Q0 */
  assert_int_equal(rcb_diag_basis_init(sc.d, &b, sc.J0, sc.n, NBASE, sc.r), RCB_OK);
  z = calloc(sc.n, sizeof *z);
  memcpy(z, b.rt, sc.n * sizeof *z);
  for (i = 0; i < b.rank; i++) z[i] = 0.0;
  assert_int_equal(LAPACKE_dormqr(LAPACK_COL_MAJOR, 'L', 'N', (lapack_int)sc.n, 1,
                                  (lapack_int)b.rank, b.qr, (lapack_int)sc.n, b.tau, z,
                                  (lapack_int)sc.n),
                   0);
  for (i = 0; i < sc.n; i++) nr += z[i] * z[i];
  assert_true(rcb_test_close(nr, rss0, 1e-10, 0.0)); /* |r - P0 r|^2 = RSS(J0) */
  for (j = 0; j < NBASE; j++) {
    double dot = 0.0, nj = 0.0;
    const double *a = sc.J0 + sc.n * j;
    for (i = 0; i < sc.n; i++) {
      dot += a[i] * z[i];
      nj += a[i] * a[i];
    }
    print_message("  %s . (r - P0 r) = %.2e of |J0_j| |r - P0 r|\n", base_names[j],
                  fabs(dot) / sqrt(nj * nr));
    assert_true(fabs(dot) <= 1e-12 * sqrt(nj * nr));
  }
  rcb_diag_basis_free(sc.d, &b);
  free(z);
  case_close(&sc);
}

/* Dependent columns, at any scale: dropped, scores unchanged. */
static void test_score_rank(void **state) {
  score_case sc;
  size_t n, i, rank;
  double *J0d, *Jin, *Jdup, p, pd;
  (void)state;
  case_open(&sc);
  n = sc.n;
  /* J0 with a fourth column 1e6 x (kt column) - 3e-4 x (ct column) */
  J0d = malloc(n * (NBASE + 1) * sizeof *J0d);
  memcpy(J0d, sc.J0, n * NBASE * sizeof *J0d);
  for (i = 0; i < n; i++) J0d[i + n * NBASE] = 1e6 * sc.J0[i] - 3e-4 * sc.J0[i + 2 * n];
  p = predicted(&sc, sc.J0, NBASE, sc.Jc[0], 1, NULL);
  pd = predicted(&sc, J0d, NBASE + 1, sc.Jc[0], 1, &rank);
  assert_int_equal(rank, NBASE);
  assert_true(rcb_test_close(pd, p, 1e-8, 0.0));
  /* a candidate inside span(J0) explains nothing */
  Jin = malloc(n * sizeof *Jin);
  for (i = 0; i < n; i++) Jin[i] = 2.5e3 * sc.J0[i + n] + 7.0 * sc.J0[i + 2 * n];
  pd = predicted(&sc, sc.J0, NBASE, Jin, 1, NULL);
  print_message("  J0 with a dependent fourth column: %.12g (rank %zu), without: %.12g\n",
                predicted(&sc, J0d, NBASE + 1, sc.Jc[0], 1, NULL), rank, p);
  print_message("  a candidate inside span(J0): %.3g (F %.6g)\n", pd, sumsq(sc.r, n));
  assert_true(pd == 0.0);
  /* a candidate of two columns, the second 1e8 x the first: as the first */
  Jdup = malloc(2 * n * sizeof *Jdup);
  for (i = 0; i < n; i++) Jdup[i] = sc.Jc[1][i], Jdup[i + n] = 1e8 * sc.Jc[1][i];
  p = predicted(&sc, sc.J0, NBASE, sc.Jc[1], 1, NULL);
  pd = predicted(&sc, sc.J0, NBASE, Jdup, 2, NULL);
  print_message("  a candidate column twice (x 1e8): %.12g, once: %.12g\n", pd, p);
  assert_true(rcb_test_close(pd, p, 1e-10, 0.0));
  free(J0d);
  free(Jin);
  free(Jdup);
  case_close(&sc);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_adjoint_equals_direct_frf),
      cmocka_unit_test(test_adjoint_equals_direct_unbalance),
      cmocka_unit_test(test_batched_scores_equal_alone),
      cmocka_unit_test(test_score_identities),
      cmocka_unit_test(test_score_rank),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
