/*
 * Time integration benchmark (issue #5): wall time and CVODE statistics of
 *  - one steady-state cross-check point (rcb_transient_steady at 1 % above
 *    the first critical speed, started from rest), next to the
 *    frequency-domain rcb_frf_unbalance at the same speed;
 *  - one run-up through the first critical speed (7000 -> 11000 rpm at
 *    1200 rad/s^2, sampled every 0.2 ms).
 * Usage: OPENBLAS_NUM_THREADS=1 build/tools/bench/bench_transient examples/paper_system.ini
 * Prints figures only; never fails on a time.
 */
#define _POSIX_C_SOURCE 200809L
#include <complex.h>
#include <math.h>
#include <stdio.h>
#include <time.h>

#include <rcb/rcb.h>

#define RPM (3.14159265358979323846 / 30.0)

static double now(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static void print_stats(const char *what, double secs, const rcb_transient *t) {
  rcb_transient_stats s;
  rcb_transient_get_stats(t, &s);
  printf("%-28s %8.3f s  t_end %.3f s  steps %ld  rhs %ld  jac %ld  LU %ld  solves %ld"
         "  rejected %ld  (%.1f us/step)\n",
         what, secs, s.t_final, s.steps, s.rhs_evals, s.jac_evals, s.lin_setups,
         s.lin_solves, s.err_test_fails, 1e6 * secs / (double)(s.steps ? s.steps : 1));
  if (s.periods)
    printf("%-28s revolutions %zu, estimated 1X error %.2e\n", "", s.periods, s.steady_err);
}

int main(int argc, char **argv) {
  rcb_model *m = NULL;
  rcb_frf *f = NULL;
  rcb_transient *t = NULL;
  rcb_dof d[2];
  rcb_complex Qt[2], Qf[2];
  rcb_speed_profile ramp = {7000 * RPM, 11000 * RPM, 1200.0};
  double w = 1.01 * 9008.13 * RPM, t0;
  rcb_status st;
  int k;
  if (argc < 2) {
    fprintf(stderr, "usage: bench_transient MODEL.ini (examples/paper_system.ini)\n");
    return 2;
  }
  if (rcb_model_create(&m, NULL) || rcb_model_load_file(m, argv[1]) ||
      rcb_model_find_dof(m, "DA.x", &d[0]) || rcb_model_find_dof(m, "DA.y", &d[1])) {
    fprintf(stderr, "bench_transient: %s\n", rcb_model_errmsg(m));
    return 3;
  }
  st = rcb_transient_create(&t, m, 2, d, NULL);
  if (st) {
    fprintf(stderr, "bench_transient: %s\n", rcb_transient_errmsg(t));
    return 4;
  }
  rcb_frf_create(&f, m, 2, d, 0, NULL, RCB_SOLVER_AUTO, NULL);
  printf("model %s: %zu DOFs, state %zu\n", argv[1], rcb_model_dof_count(m),
         2 * rcb_model_dof_count(m));
  t0 = now();
  for (k = 0; k < 100; k++) rcb_frf_unbalance(f, w, Qf);
  printf("%-28s %8.3f ms\n", "frequency domain, 1 speed", 1e3 * (now() - t0) / 100.0);
  for (k = 0; k < 2; k++) {
    double rtol = k ? 1e-7 : 1e-6, sst = k ? 1e-5 : 1e-3;
    char what[64];
    rcb_transient_set_tolerances(t, rtol, 1e-13, 1e-10);
    rcb_transient_set_steady(t, sst, 32, 20000);
    t0 = now();
    if (rcb_transient_steady(t, w, Qt)) fprintf(stderr, "%s\n", rcb_transient_errmsg(t));
    snprintf(what, sizeof what, "steady point rtol %.0e/%.0e", rtol, sst);
    print_stats(what, now() - t0, t);
    printf("%-28s |Q| error %.2e, phase error %.2e deg\n", "",
           cabs(Qt[0]) / cabs(Qf[0]) - 1.0, carg(Qt[0] / Qf[0]) * 180.0 / 3.14159265358979);
  }
  rcb_transient_set_tolerances(t, 1e-6, 1e-13, 1e-10);
  t0 = now();
  if (rcb_transient_run(t, &ramp, (ramp.speed1 - ramp.speed0) / ramp.accel, 2e-4, NULL, NULL,
                        NULL, NULL))
    fprintf(stderr, "%s\n", rcb_transient_errmsg(t));
  print_stats("run-up 7000-11000 rpm", now() - t0, t);
  rcb_transient_destroy(t);
  rcb_frf_destroy(f);
  rcb_model_destroy(m);
  return 0;
}
