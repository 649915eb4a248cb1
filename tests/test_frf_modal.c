/*
 * Modal FRF path (paper eq. 7) and the threaded sweep:
 *  - all modes kept: the modal sum equals the direct (zgesv) solution to
 *    1e-8, normwise relative per frequency (max over the outputs x inputs of
 *    |H_modal - H_direct| / max |H_direct|; an entry 1e-5 below its
 *    neighbours carries that much less relative accuracy in either method),
 *    on the paper system (gyroscopic, C + Omega G non-symmetric) at
 *    10000 rpm and on the cross-coupled, speed-dependent bearing model at two
 *    speeds (the basis is recomputed when the speed changes);
 *  - mobility = i w receptance (identity);
 *  - truncated set: the static residual makes omega = 0 exact, the reported
 *    estimate equals the actual error at its frequency, and keeping more
 *    modes does not make the error at 500 Hz larger;
 *  - the sweep gives the same bytes on 1, 2 and 3 threads for every solver,
 *    and the serial sweep the same bytes as an rcb_frf_eval loop (dense,
 *    banded, modal).
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

#include "rcb/rcb.h"
#include "rcb_test_util.h"

#define RPM (3.14159265358979323846 / 30.0)
#define HZ (2.0 * 3.14159265358979323846)
#define NF 400

static const char *const paper_out[] = {"C.A.x", "C.A.y", "C.B.x", "C.B.y"};
static const char *const paper_in[] = {"DA.x", "DA.y"};
static const char *const cc_out[] = {"D.x", "D.y", "BL.x", "BR.y"};
static const char *const cc_in[] = {"D.x", "D.y"};

static rcb_frf *make(const rcb_model *m, const char *const *o, const char *const *in,
                     rcb_solver_kind kind) {
  rcb_dof od[4], id[2];
  rcb_frf *f = NULL;
  size_t k;
  for (k = 0; k < 4; k++)
    if (rcb_model_find_dof(m, o[k], &od[k])) fail_msg("%s", rcb_model_errmsg(m));
  for (k = 0; k < 2; k++)
    if (rcb_model_find_dof(m, in[k], &id[k])) fail_msg("%s", rcb_model_errmsg(m));
  assert_int_equal(rcb_frf_create(&f, m, 4, od, 2, id, kind, NULL), RCB_OK);
  return f;
}

/* max |A - B| / max |B| over 8 entries */
static double rel(const rcb_complex *A, const rcb_complex *B) {
  double num = 0.0, den = 0.0;
  size_t c;
  for (c = 0; c < 8; c++) {
    num = fmax(num, cabs(A[c] - B[c]));
    den = fmax(den, cabs(B[c]));
  }
  return num / den;
}

/* Worst normwise error of modal vs dense over 0..fmax Hz at one speed. */
static double worst_error(rcb_frf *fm, rcb_frf *fd, double f_hi, double speed) {
  rcb_complex Hm[8], Hd[8];
  double worst = 0.0;
  size_t p;
  for (p = 0; p < NF; p++) {
    double w = HZ * f_hi * (double)p / (NF - 1);
    assert_int_equal(rcb_frf_eval(fd, w, speed, RCB_RECEPTANCE, Hd), RCB_OK);
    assert_int_equal(rcb_frf_eval(fm, w, speed, RCB_RECEPTANCE, Hm), RCB_OK);
    worst = fmax(worst, rel(Hm, Hd));
  }
  return worst;
}

static void test_paper_all_modes(void **state) {
  rcb_model *m = rcb_test_model_from_example("paper_system.ini");
  rcb_frf *fm = make(m, paper_out, paper_in, RCB_SOLVER_MODAL);
  rcb_frf *fd = make(m, paper_out, paper_in, RCB_SOLVER_DENSE);
  rcb_modal_info info;
  rcb_complex Hr[8], Hv[8];
  double speed = 10000.0 * RPM, w = HZ * 123.4, err;
  size_t c;
  (void)state;
  assert_int_equal(rcb_frf_solver(fm), RCB_SOLVER_MODAL);
  assert_true(worst_error(fm, fd, 500.0, speed) < 1e-8);
  assert_int_equal(rcb_frf_modal_info(fm, speed, &info), RCB_OK);
  assert_int_equal(info.nroots, 2 * rcb_model_dof_count(m));
  assert_int_equal(info.nkept, info.nroots);
  assert_int_equal(info.residual_used, 0);
  assert_int_equal(rcb_frf_modal_error(fm, HZ * 500.0, speed, &err), RCB_OK);
  assert_true(err < 1e-8);
  /* mobility = i w receptance */
  assert_int_equal(rcb_frf_eval(fm, w, speed, RCB_RECEPTANCE, Hr), RCB_OK);
  assert_int_equal(rcb_frf_eval(fm, w, speed, RCB_MOBILITY, Hv), RCB_OK);
  for (c = 0; c < 8; c++) assert_true(cabs(Hv[c] - CMPLX(0.0, w) * Hr[c]) <= 1e-14 * cabs(Hv[c]));
  /* not modal: the modal setters refuse */
  assert_int_equal(rcb_frf_set_modal(fd, 3, 0.0), RCB_ERR_STATE);
  rcb_frf_destroy(fm);
  rcb_frf_destroy(fd);
  rcb_model_destroy(m);
}

static void test_cross_coupled_speeds(void **state) {
  rcb_model *m = rcb_test_model_from_example("cross_coupled.ini");
  rcb_frf *fm = make(m, cc_out, cc_in, RCB_SOLVER_MODAL);
  rcb_frf *fd = make(m, cc_out, cc_in, RCB_SOLVER_DENSE);
  rcb_modal_info info;
  (void)state;
  /* speed-dependent bearing BR: the basis must follow the speed */
  assert_true(worst_error(fm, fd, 400.0, 1500.0 * RPM) < 1e-8);
  assert_true(worst_error(fm, fd, 400.0, 4500.0 * RPM) < 1e-8);
  assert_int_equal(rcb_frf_modal_info(fm, 4500.0 * RPM, &info), RCB_OK);
  assert_true(info.speed == 4500.0 * RPM);
  assert_true(worst_error(fm, fd, 400.0, 1500.0 * RPM) < 1e-8);
  rcb_frf_destroy(fm);
  rcb_frf_destroy(fd);
  rcb_model_destroy(m);
}

static void test_truncated(void **state) {
  rcb_model *m = rcb_test_model_from_example("paper_system.ini");
  rcb_frf *fm = make(m, paper_out, paper_in, RCB_SOLVER_MODAL);
  rcb_frf *fd = make(m, paper_out, paper_in, RCB_SOLVER_DENSE);
  rcb_complex Hm[8], Hd[8];
  rcb_modal_info info;
  double speed = 10000.0 * RPM, w = HZ * 500.0, est, prev = INFINITY;
  size_t modes[] = {8, 12, 20, 40}, k;
  (void)state;
  for (k = 0; k < 4; k++) {
    assert_int_equal(rcb_frf_set_modal(fm, modes[k], 0.0), RCB_OK);
    assert_int_equal(rcb_frf_modal_info(fm, speed, &info), RCB_OK);
    assert_int_equal(info.nmodes, modes[k]);
    assert_true(info.nkept < info.nroots);
    assert_int_equal(info.residual_used, 1);
    /* the static residual makes omega = 0 exact */
    assert_int_equal(rcb_frf_eval(fm, 0.0, speed, RCB_RECEPTANCE, Hm), RCB_OK);
    assert_int_equal(rcb_frf_eval(fd, 0.0, speed, RCB_RECEPTANCE, Hd), RCB_OK);
    assert_true(rel(Hm, Hd) < 1e-10);
    /* the estimate is the error at its frequency */
    assert_int_equal(rcb_frf_modal_error(fm, w, speed, &est), RCB_OK);
    assert_int_equal(rcb_frf_eval(fm, w, speed, RCB_RECEPTANCE, Hm), RCB_OK);
    assert_int_equal(rcb_frf_eval(fd, w, speed, RCB_RECEPTANCE, Hd), RCB_OK);
    assert_true(rcb_test_close(est, rel(Hm, Hd), 1e-6, 1e-14));
    assert_true(est <= prev * 1.01);
    prev = est;
  }
  assert_true(prev < 1e-3);
  /* a frequency limit instead of a count: only modes below 2 kHz */
  assert_int_equal(rcb_frf_set_modal(fm, 0, HZ * 2000.0), RCB_OK);
  assert_int_equal(rcb_frf_modal_info(fm, speed, &info), RCB_OK);
  assert_true(info.max_kept_wn <= HZ * 2000.0 && info.nkept < info.nroots);
  assert_int_equal(rcb_frf_set_modal(fm, 0, -1.0), RCB_ERR_ARG);
  rcb_frf_destroy(fm);
  rcb_frf_destroy(fd);
  rcb_model_destroy(m);
}

/* Sweep on 1, 2, 3 threads: the same bytes; serial sweep vs eval loop too. */
static void sweep_identical(rcb_solver_kind kind, int sync, int eval_loop) {
  rcb_model *m = rcb_test_model_from_example("paper_system.ini");
  rcb_frf *f;
  size_t n = 300, p, t, bytes = n * 8 * sizeof(rcb_complex);
  double *w = malloc(2 * n * sizeof *w), *sp = w + n;
  rcb_complex *H1 = malloc(bytes), *H2 = malloc(bytes);
  rcb_status st;
  assert_non_null(w);
  assert_non_null(H1);
  assert_non_null(H2);
  for (p = 0; p < n; p++) {
    w[p] = HZ * 500.0 * (double)p / (double)(n - 1);
    sp[p] = sync ? w[p] : 10000.0 * RPM;
  }
  f = make(m, paper_out, paper_in, kind);
  assert_int_equal(rcb_frf_sweep(f, n, w, sp, RCB_RECEPTANCE, H1, 1), RCB_OK);
  for (t = 2; t <= 3; t++) {
    memset(H2, 0, bytes);
    st = rcb_frf_sweep(f, n, w, sp, RCB_RECEPTANCE, H2, t);
    assert_int_equal(st, RCB_OK);
    assert_memory_equal(H1, H2, bytes);
  }
  if (eval_loop) {
    for (p = 0; p < n; p++)
      assert_int_equal(rcb_frf_eval(f, w[p], sp[p], RCB_RECEPTANCE, H2 + 8 * p), RCB_OK);
    assert_memory_equal(H1, H2, bytes);
  }
  rcb_frf_destroy(f);
  rcb_model_destroy(m);
  free(w);
  free(H1);
  free(H2);
}

/* rcb_frf_pick_solver: modal from RCB_MODAL_PAYS x ndof^2 frequencies at
 * one speed (88 DOF: 1548.8, so 1549); never over several speeds, for no
 * model or for a model not finalized. */
static void test_pick_solver(void **state) {
  rcb_model *m = rcb_test_model_from_example("paper_system.ini"), *e = NULL;
  (void)state;
  assert_int_equal(rcb_model_dof_count(m), 88);
  assert_int_equal(rcb_frf_pick_solver(m, 1549, 1), RCB_SOLVER_MODAL);
  assert_int_equal(rcb_frf_pick_solver(m, 1548, 1), RCB_SOLVER_AUTO);
  assert_int_equal(rcb_frf_pick_solver(m, 100000, 0), RCB_SOLVER_AUTO);
  assert_int_equal(rcb_frf_pick_solver(NULL, 100000, 1), RCB_SOLVER_AUTO);
  assert_int_equal(rcb_model_create(&e, NULL), RCB_OK);
  assert_int_equal(rcb_frf_pick_solver(e, 100000, 1), RCB_SOLVER_AUTO);
  rcb_model_destroy(e);
  rcb_model_destroy(m);
}

static void test_sweep_threads(void **state) {
  rcb_model *m = rcb_test_model_from_example("paper_system.ini");
  rcb_frf *f = NULL;
  rcb_dof d;
  (void)state;
  sweep_identical(RCB_SOLVER_DENSE, 0, 1);
  sweep_identical(RCB_SOLVER_BANDED, 1, 1);
  sweep_identical(RCB_SOLVER_MODAL, 0, 1);
  assert_int_equal(rcb_model_find_dof(m, "DA.x", &d), RCB_OK);
  if (rcb_frf_create(&f, m, 1, &d, 1, &d, RCB_SOLVER_SPARSE, NULL) == RCB_OK)
    sweep_identical(RCB_SOLVER_SPARSE, 0, 0);
  rcb_frf_destroy(f);
  rcb_model_destroy(m);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_paper_all_modes),
      cmocka_unit_test(test_cross_coupled_speeds),
      cmocka_unit_test(test_truncated),
      cmocka_unit_test(test_sweep_threads),
      cmocka_unit_test(test_pick_solver),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
