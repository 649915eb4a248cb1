/*
 * FRF sweep benchmark on the paper's system (issue #2, "Speed and memory"):
 * 2000 frequencies, 4 outputs (C.A.x, C.A.y, C.B.x, C.B.y) x 2 inputs
 * (DA.x, DA.y), rotor at a fixed 10000 rpm, receptance, with the dense
 * (zgesv) and the banded (zgbsv) solver. Prints the best time of several
 * sweeps, the memory held by each FRF object, and how far the two solvers
 * disagree. Uses only the public API; the sweep itself allocates nothing.
 *
 * usage: bench_frf MODEL.ini [repeats]   (run with OPENBLAS_NUM_THREADS=1)
 */
#define _POSIX_C_SOURCE 200809L
#include <complex.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/resource.h>
#include <time.h>

#include <rcb/rcb.h>

#define NFREQ 2000
#define NOUT 4
#define NIN 2
#define PI 3.14159265358979323846

static const char *const out_names[NOUT] = {"C.A.x", "C.A.y", "C.B.x", "C.B.y"};
static const char *const in_names[NIN] = {"DA.x", "DA.y"};
static const double fmin_hz = 0.0, fmax_hz = 500.0; /* Hz */
static const double speed_rpm = 10000.0;            /* rpm */

static double now_s(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* One sweep: H holds NOUT x NIN per frequency, NFREQ of them. */
static rcb_status sweep(rcb_frf *f, double speed, rcb_complex *H) {
  size_t i;
  for (i = 0; i < NFREQ; i++) {
    double w = 2.0 * PI * (fmin_hz + (fmax_hz - fmin_hz) * (double)i / (NFREQ - 1));
    rcb_status st = rcb_frf_eval(f, w, speed, RCB_RECEPTANCE, H + (size_t)NOUT * NIN * i);
    if (st != RCB_OK) return st;
  }
  return RCB_OK;
}

/* Best wall time of @p repeats sweeps, s. */
static int time_solver(const rcb_model *m, const rcb_dof *out, const rcb_dof *in,
                       rcb_solver_kind kind, int repeats, rcb_complex *H, double *best,
                       size_t *bytes) {
  rcb_frf *f = NULL;
  double speed = speed_rpm * 2.0 * PI / 60.0; /* rad/s */
  rcb_status st = rcb_frf_create(&f, m, NOUT, out, NIN, in, kind, NULL);
  int r;
  if (st != RCB_OK) {
    fprintf(stderr, "bench_frf: rcb_frf_create: %s\n", rcb_status_str(st));
    return 1;
  }
  *bytes = rcb_frf_memory(f);
  *best = INFINITY;
  for (r = 0; r < repeats; r++) {
    double t0 = now_s(), dt;
    st = sweep(f, speed, H);
    dt = now_s() - t0;
    if (st != RCB_OK) {
      fprintf(stderr, "bench_frf: rcb_frf_eval: %s: %s\n", rcb_status_str(st),
              rcb_frf_errmsg(f));
      rcb_frf_destroy(f);
      return 1;
    }
    if (dt < *best) *best = dt;
  }
  rcb_frf_destroy(f);
  return 0;
}

static int find_dofs(const rcb_model *m, rcb_dof *out, rcb_dof *in) {
  size_t k;
  for (k = 0; k < NOUT + NIN; k++) {
    const char *name = k < NOUT ? out_names[k] : in_names[k - NOUT];
    rcb_dof *d = k < NOUT ? &out[k] : &in[k - NOUT];
    if (rcb_model_find_dof(m, name, d) != RCB_OK) {
      fprintf(stderr, "bench_frf: %s\n", rcb_model_errmsg(m));
      return 1;
    }
  }
  return 0;
}

static void compare(const rcb_complex *Hd, const rcb_complex *Hb) {
  size_t k, n = (size_t)NFREQ * NOUT * NIN;
  double peak = 0.0, worst = 0.0, worst_abs = 0.0;
  for (k = 0; k < n; k++) peak = fmax(peak, cabs(Hd[k]));
  for (k = 0; k < n; k++) {
    double d = cabs(Hd[k] - Hb[k]);
    worst_abs = fmax(worst_abs, d / peak);
    if (cabs(Hd[k]) > 0.0) worst = fmax(worst, d / cabs(Hd[k]));
  }
  printf("dense vs banded: max |Hd - Hb| / |Hd| = %.2e (entry-wise), "
         "max |Hd - Hb| / max|Hd| = %.2e\n",
         worst, worst_abs);
}

int main(int argc, char **argv) {
  rcb_model *m = NULL;
  rcb_dof out[NOUT], in[NIN];
  rcb_complex *Hd, *Hb;
  double t_dense, t_banded;
  size_t b_dense, b_banded;
  struct rusage ru;
  int repeats = argc > 2 ? atoi(argv[2]) : 10, rc = 1;
  if (argc < 2 || repeats < 1) {
    fprintf(stderr, "usage: bench_frf MODEL.ini [repeats]\n");
    return 2;
  }
  Hd = malloc(sizeof *Hd * NFREQ * NOUT * NIN);
  Hb = malloc(sizeof *Hb * NFREQ * NOUT * NIN);
  if (!Hd || !Hb || rcb_model_create(&m, NULL) != RCB_OK) goto done;
  if (rcb_model_load_file(m, argv[1]) != RCB_OK) {
    fprintf(stderr, "bench_frf: %s\n", rcb_model_errmsg(m));
    goto done;
  }
  if (find_dofs(m, out, in)) goto done;
  printf("model %s: %zu nodes, %zu DOFs; %d frequencies %.0f-%.0f Hz, %d outputs x %d "
         "inputs, %.0f rpm, best of %d sweeps\n",
         argv[1], rcb_model_node_count(m), rcb_model_dof_count(m), NFREQ, fmin_hz, fmax_hz,
         NOUT, NIN, speed_rpm, repeats);
  if (time_solver(m, out, in, RCB_SOLVER_DENSE, repeats, Hd, &t_dense, &b_dense) ||
      time_solver(m, out, in, RCB_SOLVER_BANDED, repeats, Hb, &t_banded, &b_banded))
    goto done;
  printf("%-8s %10s %14s %14s\n", "solver", "ms/sweep", "us/frequency", "bytes held");
  printf("%-8s %10.2f %14.2f %14zu\n", "dense", 1e3 * t_dense, 1e6 * t_dense / NFREQ,
         b_dense);
  printf("%-8s %10.2f %14.2f %14zu\n", "banded", 1e3 * t_banded, 1e6 * t_banded / NFREQ,
         b_banded);
  compare(Hd, Hb);
  if (getrusage(RUSAGE_SELF, &ru) == 0)
    printf("peak resident memory of this process: %.1f MB\n", (double)ru.ru_maxrss / 1024.0);
  rc = 0;
done:
  free(Hd);
  free(Hb);
  rcb_model_destroy(m);
  return rc;
}
