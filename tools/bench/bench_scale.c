/*
 * Scale benchmark (issue #6): time and memory per frequency of an FRF sweep
 * on long machine trains (tools/bench/gen_train.py) of 1e2 .. 1e5 DOF, with
 * the banded (zgbsv), sparse (KLU) and, up to 2000 DOF, dense (zgesv)
 * solvers; then the slope of log(time) against log(DOF) above 1e3 DOF.
 *
 * Each (model, solver) runs in a forked child, so the peak resident set
 * (getrusage ru_maxrss) is that run's own. Per frequency: one assembly of
 * Z(w), one factorisation, 2 right-hand sides (inputs), 4 outputs; a sweep
 * of 1 .. 200 Hz at 3000 rpm, repeated until it has run 1 s (at least 5
 * frequencies); mean and median time per frequency (the median resists
 * other processes on a shared machine). Prints a Markdown table for
 * docs/benchmarks.md. Never a test: figures only.
 *
 * usage: bench_scale [--solver banded|sparse|dense] MODEL.ini...
 *        (run with OPENBLAS_NUM_THREADS=1; --solver times that solver only,
 *        e.g. under perf)
 *   for n in 100 1000 10000 100000; do
 *     python3 tools/bench/gen_train.py --dof $n -o /tmp/train_$n.ini; done
 *   OPENBLAS_NUM_THREADS=1 build/tools/bench/bench_scale /tmp/train_{100,1000,10000,100000}.ini
 */
#define _POSIX_C_SOURCE 200809L
#include <complex.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <rcb/rcb.h>

#define PI 3.14159265358979323846
#define NOUT 4
#define NIN 2
#define MAX_MODELS 16
#define DENSE_MAX_DOF 2000 /* zgesv beyond this takes minutes and GBs */

typedef struct result_s {
  int ok;
  size_t ndof, nfreq, bytes;
  double setup_s, per_freq_s, median_s, maxrss_kb;
} result;

#define MAX_TIMED 20000

static int cmp_double(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

static double now_s(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* Nodes at 1/4, 1/2, 3/4 and the end of the train as outputs, the first
 * and middle ones as inputs ("#N.x"). */
static int channels(const rcb_model *m, rcb_dof *out, rcb_dof *in) {
  size_t nn = rcb_model_node_count(m), k;
  char spec[32];
  for (k = 0; k < NOUT; k++) {
    snprintf(spec, sizeof spec, "#%zu.%s", (k + 1) * (nn - 1) / NOUT, k % 2 ? "y" : "x");
    if (rcb_model_find_dof(m, spec, &out[k])) return 1;
  }
  for (k = 0; k < NIN; k++) {
    snprintf(spec, sizeof spec, "#%zu.%s", k * (nn - 1) / 2 + 1, k % 2 ? "y" : "x");
    if (rcb_model_find_dof(m, spec, &in[k])) return 1;
  }
  return 0;
}

static int run_one(const char *path, rcb_solver_kind kind, result *r) {
  rcb_model *m = NULL;
  rcb_frf *f = NULL;
  rcb_dof out[NOUT], in[NIN];
  rcb_complex H[NOUT * NIN];
  double t0, t1, speed = 3000.0 * PI / 30.0; /* rad/s */
  size_t i = 0;
  struct rusage ru;
  static double dt[MAX_TIMED];
  if (rcb_model_create(&m, NULL) || rcb_model_load_file(m, path) || rcb_model_finalize(m)) {
    fprintf(stderr, "bench_scale: %s: %s\n", path, m ? rcb_model_errmsg(m) : "no memory");
    rcb_model_destroy(m);
    return 1;
  }
  r->ndof = rcb_model_dof_count(m);
  if (channels(m, out, in)) return 1;
  t0 = now_s();
  if (rcb_frf_create(&f, m, NOUT, out, NIN, in, kind, NULL)) {
    rcb_model_destroy(m);
    return 2; /* solver not built in */
  }
  t1 = now_s();
  r->setup_s = t1 - t0;
  do {
    double w = 2.0 * PI * (1.0 + 199.0 * (double)(i % 97) / 96.0); /* 1 .. 200 Hz */
    double ta = now_s();
    if (rcb_frf_eval(f, w, speed, RCB_RECEPTANCE, H)) {
      fprintf(stderr, "bench_scale: %s\n", rcb_frf_errmsg(f));
      return 1;
    }
    dt[i++] = now_s() - ta;
  } while (i < MAX_TIMED && (i < 5 || now_s() - t1 < 1.0));
  r->per_freq_s = (now_s() - t1) / (double)i;
  qsort(dt, i, sizeof *dt, cmp_double);
  r->median_s = dt[i / 2];
  r->nfreq = i;
  r->bytes = rcb_frf_memory(f);
  getrusage(RUSAGE_SELF, &ru);
  r->maxrss_kb = (double)ru.ru_maxrss;
  r->ok = 1;
  rcb_frf_destroy(f);
  rcb_model_destroy(m);
  return 0;
}

/* Run in a child so ru_maxrss belongs to this run alone. */
static result run_forked(const char *path, rcb_solver_kind kind) {
  result r;
  int fd[2];
  pid_t pid;
  memset(&r, 0, sizeof r);
  if (pipe(fd)) return r;
  pid = fork();
  if (pid == 0) {
    close(fd[0]);
    if (run_one(path, kind, &r)) r.ok = 0;
    if (write(fd[1], &r, sizeof r) != (ssize_t)sizeof r) _exit(1);
    _exit(0);
  }
  close(fd[1]);
  if (pid > 0) {
    if (read(fd[0], &r, sizeof r) != (ssize_t)sizeof r) memset(&r, 0, sizeof r);
    waitpid(pid, NULL, 0);
  }
  close(fd[0]);
  return r;
}

/* Least-squares slope of log(t) against log(n) over points with n >= 1000. */
static double slope(const result *res, size_t nm) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0, k = 0;
  size_t i;
  for (i = 0; i < nm; i++) {
    double x, y;
    if (!res[i].ok || res[i].ndof < 900) continue;
    x = log((double)res[i].ndof);
    y = log(res[i].median_s);
    sx += x;
    sy += y;
    sxx += x * x;
    sxy += x * y;
    k += 1;
  }
  if (k < 2) return NAN;
  return (k * sxy - sx * sy) / (k * sxx - sx * sx);
}

int main(int argc, char **argv) {
  static const rcb_solver_kind kinds[3] = {RCB_SOLVER_BANDED, RCB_SOLVER_SPARSE,
                                           RCB_SOLVER_DENSE};
  static const char *const names[3] = {"banded (zgbsv)", "sparse (KLU)", "dense (zgesv)"};
  static const char *const keys[3] = {"banded", "sparse", "dense"};
  result res[3][MAX_MODELS];
  size_t nm, i;
  int s, only = -1, first = 1;
  if (argc > 2 && !strcmp(argv[1], "--solver")) {
    for (s = 0; s < 3; s++)
      if (!strcmp(argv[2], keys[s])) only = s;
    if (only < 0) {
      fprintf(stderr, "bench_scale: unknown solver '%s' (banded, sparse or dense)\n", argv[2]);
      return 2;
    }
    first = 3;
  }
  nm = (size_t)(argc - first);
  if (argc <= first || nm > MAX_MODELS) {
    fprintf(stderr, "usage: bench_scale [--solver banded|sparse|dense] MODEL.ini... (at most %d)\n",
            MAX_MODELS);
    return 2;
  }
  memset(res, 0, sizeof res);
  printf("| DOF | solver | setup ms | ms / frequency (median) | (mean) | frequencies timed | "
         "FRF object MB | peak RSS MB |\n|---:|---|---:|---:|---:|---:|---:|---:|\n");
  for (i = 0; i < nm; i++)
    for (s = 0; s < 3; s++) {
      result *r = &res[s][i];
      if (only >= 0 && s != only) continue;
      if (s == 2 && only != 2) { /* dense only where it is feasible */
        result probe = res[0][i];
        if (!probe.ok || probe.ndof > DENSE_MAX_DOF) continue;
      }
      *r = run_forked(argv[first + (int)i], kinds[s]);
      if (!r->ok) {
        printf("| %s | %s | - | - | - | - | - | - |\n", argv[first + (int)i], names[s]);
        continue;
      }
      printf("| %zu | %s | %.3f | %.4f | %.4f | %zu | %.2f | %.1f |\n", r->ndof, names[s],
             1e3 * r->setup_s, 1e3 * r->median_s, 1e3 * r->per_freq_s, r->nfreq,
             (double)r->bytes / 1048576.0, r->maxrss_kb / 1024.0);
      fflush(stdout);
    }
  printf("\nslope of log(median time per frequency) against log(DOF), DOF >= 1e3:");
  for (s = 0; s < 2; s++)
    if (only < 0 || s == only) printf(" %s %.3f;", names[s], slope(res[s], nm));
  printf("\n");
  return 0;
}
