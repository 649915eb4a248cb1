/*
 * FRF sweep benchmark on the paper's system (issue #2, "Speed and memory"):
 * 2000 frequencies, 4 outputs (C.A.x, C.A.y, C.B.x, C.B.y) x 2 inputs
 * (DA.x, DA.y), rotor at a fixed 10000 rpm, receptance, with the dense
 * (zgesv), the banded (zgbsv), when built with SuiteSparse the sparse (KLU),
 * and the modal (eq. 7: all modes, and the 20 lowest + static residual)
 * solvers, serial and on threads (rcb_frf_sweep, as rcbtool frf). Prints the
 * best time of several sweeps, the memory held by each FRF object, and how
 * far each solver disagrees with the dense one. Uses only the public API.
 *
 * usage: bench_frf MODEL.ini [repeats] [threads]   (run with
 * OPENBLAS_NUM_THREADS=1; threads default 2)
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

/* One sweep (rcb_frf_sweep, which the CLI uses): H holds NOUT x NIN per
 * frequency, NFREQ of them. rcb_frf_refresh first, so that the modal
 * solver's basis (eigenvectors at this speed) is part of every timed sweep. */
static rcb_status sweep(rcb_frf *f, double speed, size_t nthreads, rcb_complex *H) {
  static double w[NFREQ], sp[NFREQ];
  size_t i;
  rcb_status st = rcb_frf_refresh(f);
  for (i = 0; i < NFREQ; i++) {
    w[i] = 2.0 * PI * (fmin_hz + (fmax_hz - fmin_hz) * (double)i / (NFREQ - 1));
    sp[i] = speed;
  }
  return st ? st : rcb_frf_sweep(f, NFREQ, w, sp, RCB_RECEPTANCE, H, nthreads);
}

typedef struct run {
  const char *name;
  rcb_solver_kind kind;
  size_t nthreads, modes; /* modes: modal truncation, 0 = all */
  double best;            /* s */
  size_t bytes;
  double err;             /* max |H - H_dense| / max |H_dense| per frequency */
} run;

/* Best wall time of @p repeats sweeps, s. */
static int time_solver(const rcb_model *m, const rcb_dof *out, const rcb_dof *in, run *r,
                       int repeats, rcb_complex *H) {
  rcb_frf *f = NULL;
  double speed = speed_rpm * 2.0 * PI / 60.0; /* rad/s */
  rcb_status st = rcb_frf_create(&f, m, NOUT, out, NIN, in, r->kind, NULL);
  int k;
  if (st == RCB_OK && r->modes) st = rcb_frf_set_modal(f, r->modes, 0.0);
  if (st == RCB_ERR_UNSUPPORTED) return -1; /* sparse without SuiteSparse */
  if (st != RCB_OK) {
    fprintf(stderr, "bench_frf: %s: %s: %s\n", r->name, rcb_status_str(st),
            f ? rcb_frf_errmsg(f) : "");
    rcb_frf_destroy(f);
    return 1;
  }
  r->bytes = rcb_frf_memory(f);
  r->best = INFINITY;
  for (k = 0; k < repeats; k++) {
    double t0 = now_s(), dt;
    st = sweep(f, speed, r->nthreads, H);
    dt = now_s() - t0;
    if (st != RCB_OK) {
      fprintf(stderr, "bench_frf: %s: %s: %s\n", r->name, rcb_status_str(st),
              rcb_frf_errmsg(f));
      rcb_frf_destroy(f);
      return 1;
    }
    if (dt < r->best) r->best = dt;
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

/* Worst over the frequencies of max |H - Hd| / max |Hd| (all NOUT x NIN). */
static double compare(const rcb_complex *Hd, const rcb_complex *H) {
  size_t p, c;
  double worst = 0.0;
  for (p = 0; p < NFREQ; p++) {
    double num = 0.0, den = 0.0;
    for (c = 0; c < NOUT * NIN; c++) {
      num = fmax(num, cabs(H[p * NOUT * NIN + c] - Hd[p * NOUT * NIN + c]));
      den = fmax(den, cabs(Hd[p * NOUT * NIN + c]));
    }
    if (den > 0.0) worst = fmax(worst, num / den);
  }
  return worst;
}

int main(int argc, char **argv) {
  rcb_model *m = NULL;
  rcb_dof out[NOUT], in[NIN];
  rcb_complex *Hd, *H;
  struct rusage ru;
  int repeats = argc > 2 ? atoi(argv[2]) : 10, rc = 1;
  size_t k, nthreads = argc > 3 ? (size_t)atoi(argv[3]) : 2, nruns = 0;
  run runs[10];
  if (argc < 2 || repeats < 1 || nthreads < 1) {
    fprintf(stderr, "usage: bench_frf MODEL.ini [repeats] [threads]\n");
    return 2;
  }
  Hd = malloc(sizeof *Hd * NFREQ * NOUT * NIN);
  H = malloc(sizeof *H * NFREQ * NOUT * NIN);
  if (!Hd || !H || rcb_model_create(&m, NULL) != RCB_OK) goto done;
  if (rcb_model_load_file(m, argv[1]) != RCB_OK) {
    fprintf(stderr, "bench_frf: %s\n", rcb_model_errmsg(m));
    goto done;
  }
  if (find_dofs(m, out, in)) goto done;
  printf("model %s: %zu nodes, %zu DOFs; %d frequencies %.0f-%.0f Hz, %d outputs x %d "
         "inputs, %.0f rpm, best of %d sweeps (modal: basis included in every sweep)\n",
         argv[1], rcb_model_node_count(m), rcb_model_dof_count(m), NFREQ, fmin_hz, fmax_hz,
         NOUT, NIN, speed_rpm, repeats);
  runs[nruns++] = (run){"dense", RCB_SOLVER_DENSE, 1, 0, 0, 0, 0};
  runs[nruns++] = (run){"banded", RCB_SOLVER_BANDED, 1, 0, 0, 0, 0};
  runs[nruns++] = (run){"banded", RCB_SOLVER_BANDED, nthreads, 0, 0, 0, 0};
  runs[nruns++] = (run){"sparse", RCB_SOLVER_SPARSE, 1, 0, 0, 0, 0};
  runs[nruns++] = (run){"sparse", RCB_SOLVER_SPARSE, nthreads, 0, 0, 0, 0};
  runs[nruns++] = (run){"modal", RCB_SOLVER_MODAL, 1, 0, 0, 0, 0};
  runs[nruns++] = (run){"modal", RCB_SOLVER_MODAL, nthreads, 0, 0, 0, 0};
  runs[nruns++] = (run){"modal/20", RCB_SOLVER_MODAL, 1, 20, 0, 0, 0};
  printf("%-9s %7s %10s %14s %12s %14s\n", "solver", "threads", "ms/sweep", "us/frequency",
         "bytes held", "err vs dense");
  for (k = 0; k < nruns; k++) {
    run *r = &runs[k];
    int trc = time_solver(m, out, in, r, repeats, k == 0 ? Hd : H);
    if (trc < 0) {
      printf("%-9s %7zu   (not built: librcb without SuiteSparse)\n", r->name, r->nthreads);
      continue;
    }
    if (trc) goto done;
    r->err = k == 0 ? 0.0 : compare(Hd, H);
    printf("%-9s %7zu %10.2f %14.2f %12zu %14.2e\n", r->name, r->nthreads, 1e3 * r->best,
           1e6 * r->best / NFREQ, r->bytes, r->err);
  }
  printf("err vs dense: worst over frequencies of max|H - H_dense| / max|H_dense| "
         "(all outputs x inputs); modal/20: 20 lowest modes + static residual\n");
  if (getrusage(RUSAGE_SELF, &ru) == 0)
    printf("peak resident memory of this process: %.1f MB\n", (double)ru.ru_maxrss / 1024.0);
  rc = 0;
done:
  free(Hd);
  free(H);
  rcb_model_destroy(m);
  return rc;
}
