/*
 * Probe: where the banded FRF sweep spends its time, on the real matrices of
 * a model (docs/benchmarks.md). Times, for the same 2000 dynamic stiffness
 * matrices Z(w) = K - w^2 M + i w (C + Omega G) in LAPACK band storage:
 *   1. LAPACKE_zgbsv_work (what src/solvers/banded.c calls);
 *   2. the same partial-pivoting band LU written inline (zgbtf2's algorithm),
 *      complex products in plain real arithmetic (no C99 Annex G NaN recovery,
 *      which the library's finite-input checks make unnecessary).
 * Eight Z(w) spread over 0-500 Hz are prepared and cycled through, so that the
 * figures measure the solver and not memory traffic; the copy of a prepared Z
 * into the work array is timed in both. Prints the time per solve and the
 * largest difference between the two solutions.
 *
 * usage: bench_band_lu MODEL.ini   (OPENBLAS_NUM_THREADS=1)
 */
#define _POSIX_C_SOURCE 200809L
#include <complex.h>
#include <lapacke.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <rcb/rcb.h>

#define NFREQ 2000
#define NPOOL 8 /* distinct Z(w) cycled through: 8 x 31 kB stays in cache */
#define NRHS 2
#define PI 3.14159265358979323846

typedef struct band {
  size_t n, kl, ku, ld; /* ld = 2 kl + ku + 1 (LAPACK, with fill-in rows) */
} band;

static double now_s(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static inline double complex mul(double complex a, double complex b) {
  double ar = creal(a), ai = cimag(a), br = creal(b), bi = cimag(b);
  return CMPLX(ar * br - ai * bi, ar * bi + ai * br);
}

static inline double complex recip(double complex a) {
  double ar = creal(a), ai = cimag(a), d = ar * ar + ai * ai;
  return CMPLX(ar / d, -ai / d);
}

/* A(i, j) of band storage. */
static inline double complex *at(const band *b, double complex *ab, size_t i, size_t j) {
  return &ab[b->kl + b->ku + i - j + b->ld * j];
}

/* LU with partial pivoting in place (LAPACK zgbtf2 layout and algorithm):
 * 0, or 1 + the column of a zero pivot. */
static size_t band_lu(const band *b, double complex *ab, size_t *piv) {
  size_t n = b->n, kl = b->kl, ku = b->ku, j, i, c, ju = 0;
  for (j = 0; j < n; j++) {
    size_t km = kl < n - 1 - j ? kl : n - 1 - j, jp = 0, last;
    double best = -1.0;
    for (i = 0; i <= km; i++) {
      double complex z = *at(b, ab, j + i, j);
      double a = fabs(creal(z)) + fabs(cimag(z));
      if (a > best) best = a, jp = i;
    }
    piv[j] = j + jp;
    if (best == 0.0) return j + 1;
    last = j + ku + jp < n - 1 ? j + ku + jp : n - 1;
    if (last > ju) ju = last;
    if (jp)
      for (c = j; c <= ju; c++) {
        double complex *p = at(b, ab, j, c), *q = at(b, ab, j + jp, c), t = *p;
        *p = *q, *q = t;
      }
    if (km) {
      double complex r = recip(*at(b, ab, j, j)), *l = at(b, ab, j, j);
      for (i = 1; i <= km; i++) l[i] = mul(l[i], r);
      for (c = j + 1; c <= ju; c++) {
        double complex *col = at(b, ab, j, c), u = col[0];
        for (i = 1; i <= km; i++) col[i] -= mul(l[i], u);
      }
    }
  }
  return 0;
}

static void band_solve(const band *b, double complex *ab, const size_t *piv,
                       double complex *x) {
  size_t n = b->n, kl = b->kl, kv = b->kl + b->ku, j, i;
  for (j = 0; j + 1 < n; j++) {
    size_t km = kl < n - 1 - j ? kl : n - 1 - j;
    double complex *l = at(b, ab, j, j);
    if (piv[j] != j) {
      double complex t = x[piv[j]];
      x[piv[j]] = x[j], x[j] = t;
    }
    for (i = 1; i <= km; i++) x[j + i] -= mul(l[i], x[j]);
  }
  for (j = n; j-- > 0;) {
    size_t i0 = j > kv ? j - kv : 0;
    double complex t;
    x[j] = mul(x[j], recip(*at(b, ab, j, j)));
    t = x[j];
    for (i = i0; i < j; i++) x[i] -= mul(*at(b, ab, i, j), t);
  }
}

/* Half-bandwidths of the nonzero pattern of n x n column-major matrices. */
static void bandwidth(size_t n, const double *const *mats, size_t nmats, band *b) {
  size_t i, j, k;
  b->n = n, b->kl = b->ku = 0;
  for (k = 0; k < nmats; k++)
    for (j = 0; j < n; j++)
      for (i = 0; i < n; i++)
        if (mats[k][i + n * j] != 0.0) {
          if (i > j && i - j > b->kl) b->kl = i - j;
          if (j > i && j - i > b->ku) b->ku = j - i;
        }
  b->ld = 2 * b->kl + b->ku + 1;
}

int main(int argc, char **argv) {
  rcb_model *m = NULL;
  double *mem = NULL, *M, *C, *G, *K, speed = 10000.0 * PI / 30.0; /* rad/s */
  double complex *Z = NULL, *work, *x1, *x2;
  size_t n, f, i, j, *piv = NULL;
  band b;
  double t_lapack = INFINITY, t_inline = INFINITY, diff = 0.0, peak = 0.0;
  int r, rc = 1;
  lapack_int *ipiv = NULL;
  if (argc < 2) {
    fprintf(stderr, "usage: bench_band_lu MODEL.ini\n");
    return 2;
  }
  if (rcb_model_create(&m, NULL) != RCB_OK || rcb_model_load_file(m, argv[1]) != RCB_OK) {
    fprintf(stderr, "bench_band_lu: %s\n", m ? rcb_model_errmsg(m) : "out of memory");
    goto done;
  }
  n = rcb_model_dof_count(m);
  mem = malloc(sizeof *mem * 4 * n * n);
  if (!mem) goto done;
  M = mem, C = M + n * n, G = C + n * n, K = G + n * n;
  if (rcb_model_matrices(m, speed, M, C, G, K) != RCB_OK) goto done;
  bandwidth(n, (const double *const[]){M, C, G, K}, 4, &b);
  Z = malloc(sizeof *Z * (b.ld * n * (NPOOL + 1) + 2 * NRHS * n));
  piv = malloc(sizeof *piv * n);
  ipiv = malloc(sizeof *ipiv * n);
  if (!Z || !piv || !ipiv) goto done;
  work = Z + b.ld * n * NPOOL;
  x1 = work + b.ld * n, x2 = x1 + NRHS * n;
  memset(Z, 0, sizeof *Z * b.ld * n * NPOOL);
  for (f = 0; f < NPOOL; f++) { /* Z(w_f), w over 0-500 Hz */
    double w = 2.0 * PI * 500.0 * (double)f / (NPOOL - 1), w2 = w * w;
    for (j = 0; j < n; j++)
      for (i = j > b.ku ? j - b.ku : 0; i < n && i <= j + b.kl; i++)
        Z[b.ld * n * f + b.kl + b.ku + i - j + b.ld * j] =
            CMPLX(K[i + n * j] - w2 * M[i + n * j],
                  w * (C[i + n * j] + speed * G[i + n * j]));
  }
  for (r = 0; r < 10; r++) {
    double t0 = now_s(), t1;
    for (f = 0; f < NFREQ; f++) {
      memcpy(work, Z + b.ld * n * (f % NPOOL), sizeof *Z * b.ld * n);
      memset(x1, 0, sizeof *x1 * NRHS * n);
      x1[n / 4] = 1.0, x1[n + n / 2] = 1.0;
      if (LAPACKE_zgbsv_work(LAPACK_COL_MAJOR, (lapack_int)n, (lapack_int)b.kl,
                             (lapack_int)b.ku, NRHS, (lapack_complex_double *)work,
                             (lapack_int)b.ld, ipiv, (lapack_complex_double *)x1,
                             (lapack_int)n))
        goto done;
    }
    t1 = now_s();
    if (t1 - t0 < t_lapack) t_lapack = t1 - t0;
    for (f = 0; f < NFREQ; f++) {
      memcpy(work, Z + b.ld * n * (f % NPOOL), sizeof *Z * b.ld * n);
      memset(x2, 0, sizeof *x2 * NRHS * n);
      x2[n / 4] = 1.0, x2[n + n / 2] = 1.0;
      if (band_lu(&b, work, piv)) goto done;
      band_solve(&b, work, piv, x2);
      band_solve(&b, work, piv, x2 + n);
    }
    t0 = now_s();
    if (t0 - t1 < t_inline) t_inline = t0 - t1;
  }
  for (i = 0; i < NRHS * n; i++) { /* last frequency's solutions */
    peak = fmax(peak, cabs(x1[i]));
    diff = fmax(diff, cabs(x1[i] - x2[i]));
  }
  printf("%zu DOFs, kl = %zu, ku = %zu; %d solves, %d right-hand sides, best of 10\n", n,
         b.kl, b.ku, NFREQ, NRHS);
  printf("LAPACKE_zgbsv_work: %7.2f ms per sweep, %6.2f us per solve\n", 1e3 * t_lapack,
         1e6 * t_lapack / NFREQ);
  printf("inline band LU:     %7.2f ms per sweep, %6.2f us per solve; max diff %.1e "
         "relative\n",
         1e3 * t_inline, 1e6 * t_inline / NFREQ, diff / peak);
  rc = 0;
done:
  if (rc) fprintf(stderr, "bench_band_lu: failed\n");
  free(ipiv);
  free(piv);
  free(Z);
  free(mem);
  rcb_model_destroy(m);
  return rc;
}
