/*
 * Measurement front end benchmark (issue #15): prints
 *  - the Welch estimator's throughput (samples per second, all channels) for
 *    1 force + 3 responses, 4096-point Hann segments at 50 % overlap, H1 +
 *    coherence + sd of the three FRFs included;
 *  - the workspace the embedded build needs for that 4-channel 4096-point
 *    estimate (besides FFTW's plan, which FFTW allocates itself);
 *  - order tracking (1X and 2X) of a 60 s, 50 kS/s run-up of 2 responses;
 *  - the limits of both order methods (issue #25): a 1X through a resonance
 *    (3000 rpm, zeta 0.05, half-power band 300 rpm) with a 2X 100 times
 *    smaller, at several run-up rates and bin widths, their largest errors
 *    against the truth at the bin's speed, 2600-3400 rpm.
 * Usage: build/tools/bench/bench_signals [seconds_of_signal]   (default 60)
 * tools/bench/bench_signals.py runs it next to SciPy. Never fails on a time.
 */
#define _POSIX_C_SOURCE 200809L
#include <complex.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include <rcb/rcb.h>

#define PI 3.14159265358979323846

static double now(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static unsigned long long rs = 88172645463325252ULL;
static double noise(void) {
  rs ^= rs << 13;
  rs ^= rs >> 7;
  rs ^= rs << 17;
  return (double)(rs >> 11) / 9007199254740992.0 - 0.5;
}

static int bench_welch(double secs) {
  const double fs = 51200.0;
  size_t n = (size_t)(secs * fs), c, k, bytes = 0, nb;
  double *x[4], t0, t1, *coh, *sd;
  rcb_complex *h;
  rcb_spectral_opts o = {0};
  rcb_spectral *e = NULL;
  void *work;
  for (c = 0; c < 4; c++) {
    x[c] = malloc(n * sizeof *x[c]);
    if (!x[c]) exit(1); /* a benchmark: no recovery */
    for (k = 0; k < n; k++) x[c][k] = noise() + (c ? 0.5 * x[0][k] : 0.0);
  }
  o.ninputs = 1;
  o.noutputs = 3;
  o.nseg = 4096;
  o.noverlap = 2048;
  o.rate = fs;
  o.window = RCB_WINDOW_HANN;
  if (rcb_spectral_workspace_size(&o, &bytes)) {
    printf("estimator: not built (no FFT backend)\n");
    return 0;
  }
  work = malloc(bytes);
  nb = o.nseg / 2 + 1;
  h = malloc(nb * sizeof *h);
  coh = malloc(nb * sizeof *coh);
  sd = malloc(nb * sizeof *sd);
  if (!work || !h || !coh || !sd) exit(1);
  t0 = now();
  if (rcb_spectral_init(&e, &o, work, bytes) ||
      rcb_spectral_add_record(e, n, (const double *const *)x))
    exit(1);
  for (c = 0; c < 3; c++) rcb_spectral_frf(e, RCB_EST_H1, c, 0, h, coh, sd);
  t1 = now();
  printf("estimator: 1 force + 3 responses, %zu samples each (%.0f s at %.0f S/s), nseg 4096, "
         "Hann, 50 %% overlap, %zu averages\n", n, secs, fs, rcb_spectral_averages(e));
  printf("estimator: %.3f s, %.3g samples/s (all 4 channels), %.3g samples/s per channel\n",
         t1 - t0, 4.0 * (double)n / (t1 - t0), (double)n / (t1 - t0));
  printf("embedded memory, 4 channels x 4096 points: %zu bytes workspace (%.1f kB), plus "
         "FFTW's plan\n", bytes, (double)bytes / 1024.0);
  rcb_spectral_release(e);
  free(work);
  free(h);
  free(coh);
  free(sd);
  for (c = 0; c < 4; c++) free(x[c]);
  return 0;
}

static int bench_order(void) {
  const double fs = 50000.0, T = 60.0, w1 = 15000 * PI / 30, al = w1 / T;
  size_t n = (size_t)(T * fs), k, bytes = 0, cfg;
  double *kp = malloc(n * sizeof *kp), *y[2], t0, t1;
  rcb_order_opts o = {0};
  rcb_order *e = NULL;
  void *work;
  y[0] = malloc(n * sizeof *y[0]);
  y[1] = malloc(n * sizeof *y[1]);
  if (!kp || !y[0] || !y[1]) exit(1);
  for (k = 0; k < n; k++) {
    double t = (double)k / fs, phi = 0.5 * al * t * t, w = fmod(phi, 2 * PI);
    if (w > PI) w -= 2 * PI;
    kp[k] = fabs(w) < 0.1 ? 2.5 + 25.0 * w : (w > 0 && w < 0.8 ? 5.0 : 0.0);
    y[0][k] = 1e-5 * cos(phi + 0.2) + 1e-6 * noise();
    y[1][k] = 2e-5 * sin(phi) + 3e-6 * cos(2 * phi) + 1e-6 * noise();
  }
  o.trigger = NAN;
  o.bin_width = 50 * PI / 30;
  o.speed_max = 16000 * PI / 30;
  for (cfg = 0; cfg < 3; cfg++) { /* fit of 8 orders (rcbtool's default), of 2; rev-dft */
    o.norders = cfg ? 2 : 8;
    o.method = cfg == 2 ? RCB_ORDER_REV_DFT : RCB_ORDER_FIT;
    rcb_order_workspace_size(&o, 2, &bytes);
    work = malloc(bytes);
    if (!work) exit(1);
    t0 = now();
    if (rcb_order_init(&e, &o, 2, work, bytes) ||
        rcb_order_add(e, fs, n, kp, (const double *const *)y))
      exit(1);
    t1 = now();
    printf("order tracking (%s, %zu orders): 0 -> 15000 rpm in 60 s at 50 kS/s, keyphasor + "
           "2 responses (%zu samples each): %.3f s, %zu revolutions, %.3g samples/s per "
           "channel; workspace %zu bytes\n", cfg == 2 ? "rev-dft" : "fit", o.norders, n, t1 - t0,
           rcb_order_revolutions(e), (double)n / (t1 - t0), bytes);
    free(work);
  }
  free(kp);
  free(y[0]);
  free(y[1]);
  return 0;
}

static double kp_pulse(double phi) {
  double w = fmod(phi, 2 * PI), d = 2 * PI * 0.02;
  if (w > PI) w -= 2 * PI;
  if (w >= -d && w <= d) return 2.5 + 2.5 * w / d;
  return w > d && w < PI / 4 ? 5.0 : 0.0;
}

/* Issue #25: a 1X resonance (3000 rpm, zeta 0.05, half-power band 300 rpm,
 * peak 10) and a 2X 100 times smaller, 1 H(2 w / 9000 rpm) e^{0.7 i} /
 * |H(6000 / 9000)|, run up 2400 -> 3600 rpm (as
 * tests/python/test_signals_order_separation.py): the largest errors of 1X and
 * 2X against their truth at the bin's speed, over the bins of 2600-3400 rpm
 * with 3 revolutions or more, for each method, run-up rate and bin width. */
static rcb_complex resonance(double w, double wn) {
  double r = w / wn;
  return 1.0 / (1 - r * r + 2 * 0.05 * r * (rcb_complex)_Complex_I);
}

static int order_limits(void) {
  static const double rates[] = {30, 100, 250, 500, 1000}, bins[] = {10, 20, 50}; /* rpm/s, rpm */
  const double w0 = 2400 * PI / 30, wn = 3000 * PI / 30, w2 = 9000 * PI / 30, fs = 1e4;
  const rcb_complex c2 = cexp(0.7 * (rcb_complex)_Complex_I) / cabs(resonance(2 * wn, w2));
  size_t k, n, b, ib, meth;
  for (meth = 0; meth < 2; meth++)
    for (k = 0; k < sizeof rates / sizeof rates[0]; k++) {
      double al = rates[k] * PI / 30, T = 1200.0 / rates[k];
      size_t N = (size_t)(T * fs);
      double *kp = malloc(N * sizeof *kp), *y = malloc(N * sizeof *y);
      const double *ch[1];
      if (!kp || !y) exit(1);
      for (n = 0; n < N; n++) {
        double t = (double)n / fs, phi = w0 * t + 0.5 * al * t * t, w = w0 + al * t;
        rcb_complex e1 = cexp((rcb_complex)_Complex_I * phi);
        kp[n] = kp_pulse(phi);
        y[n] = creal(10.0 * resonance(w, wn) * e1) + creal(c2 * resonance(2 * w, w2) * e1 * e1);
      }
      ch[0] = y;
      for (ib = 0; ib < sizeof bins / sizeof bins[0]; ib++) {
        double e1 = 0, p1 = 0, e2 = 0, p2 = 0;
        size_t bytes = 0, used = 0;
        rcb_order_opts o = {0};
        rcb_order *e = NULL;
        void *work;
        o.norders = meth ? 2 : 8; /* as rcbtool order's defaults */
        o.trigger = NAN;
        o.bin_width = bins[ib] * PI / 30;
        o.speed_max = 3800 * PI / 30;
        o.method = meth ? RCB_ORDER_REV_DFT : RCB_ORDER_FIT;
        if (rcb_order_workspace_size(&o, 1, &bytes) || !(work = malloc(bytes)) ||
            rcb_order_init(&e, &o, 1, work, bytes) || rcb_order_add(e, fs, N, kp, ch))
          exit(1);
        for (b = 0; b < rcb_order_bin_count(e); b++) {
          double sp;
          rcb_complex q1, q2, h1, h2;
          size_t nr;
          rcb_order_result(e, b, 0, 1, &sp, &q1, NULL, &nr);
          if (nr < 3 || sp < 2600 * PI / 30 || sp > 3400 * PI / 30) continue;
          rcb_order_result(e, b, 0, 2, NULL, &q2, NULL, NULL);
          h1 = 10.0 * resonance(sp, wn);
          h2 = c2 * resonance(2 * sp, w2);
          used++;
          e1 = fmax(e1, fabs(cabs(q1 / h1) - 1));
          p1 = fmax(p1, fabs(carg(q1 / h1)) * 180 / PI);
          e2 = fmax(e2, fabs(cabs(q2 / h2) - 1));
          p2 = fmax(p2, fabs(carg(q2 / h2)) * 180 / PI);
        }
        printf("order limits: %s, %g rpm/s (%.2g rpm per revolution at 3000 rpm), %g rpm bins "
               "(%zu in 2600-3400 rpm): 1X within %.3g %% and %.3g deg, 2X (1 %% of the peak "
               "1X) within %.3g %% and %.3g deg\n", meth ? "rev-dft" : "fit", rates[k],
               rates[k] / 50.0, bins[ib], used, 100 * e1, p1, 100 * e2, p2);
        free(work);
      }
      free(kp);
      free(y);
    }
  return 0;
}

int main(int argc, char **argv) {
  double secs = argc > 1 ? strtod(argv[1], NULL) : 60.0;
  if (!(secs > 0.1)) secs = 60.0;
  if (bench_welch(secs) || bench_order() || order_limits()) {
    fprintf(stderr, "bench_signals: failed\n");
    return 1;
  }
  return 0;
}
