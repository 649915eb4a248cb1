/* Measurement front end (src/signals): the Welch estimator against closed
 * forms (white noise, a digital SDOF resonator, known coherence and the known
 * biases of H1, H2 and Hv), and the signal readers with their units. The
 * agreement with SciPy to 1e-10 is in tests/python/test_signals_scipy.py. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>
#include <complex.h>
#include <math.h>

#include "rcb/rcb.h"
#include "rcb/rcb_config.h"
#include "rcb_test_util.h"

#define PI 3.14159265358979323846

/* Gaussian samples (xorshift64* + Box-Muller): independent of libc. */
typedef struct rng {
  uint64_t s;
} rng;
static double uni(rng *r) {
  r->s ^= r->s >> 12;
  r->s ^= r->s << 25;
  r->s ^= r->s >> 27;
  return ((double)((r->s * 2685821657736338717ULL) >> 11) + 0.5) / 9007199254740992.0;
}
static double gauss(rng *r) { return sqrt(-2.0 * log(uni(r))) * cos(2.0 * PI * uni(r)); }
static void white(rng *r, double *x, size_t n, double sd) {
  size_t i;
  for (i = 0; i < n; i++) x[i] = sd * gauss(r);
}

/* An estimator in a malloc'ed workspace (the test's; the library allocates nothing). */
typedef struct est {
  rcb_spectral *e;
  void *work;
} est;
static int make(est *t, size_t p, size_t q, size_t nseg, rcb_window w, double rate) {
  rcb_spectral_opts o;
  size_t bytes = 0;
  rcb_status st;
  memset(&o, 0, sizeof o);
  o.ninputs = p;
  o.noutputs = q;
  o.nseg = nseg;
  o.noverlap = nseg / 2;
  o.rate = rate;
  o.window = w;
  st = rcb_spectral_workspace_size(&o, &bytes);
  if (st == RCB_ERR_UNSUPPORTED) return -1;
  assert_int_equal(st, RCB_OK);
  t->work = malloc(bytes);
  assert_non_null(t->work);
  assert_int_equal(rcb_spectral_init(&t->e, &o, t->work, bytes), RCB_OK);
  return 0;
}
static void done(est *t) {
  rcb_spectral_release(t->e);
  free(t->work);
}
#define NEED_FFT(t, ...)     \
  if (make(t, __VA_ARGS__)) { \
    skip();                  \
    return;                  \
  }

/* Signal buffers of the estimator tests (static: nothing to free on a skip). */
static double buf_a[512 * 1000], buf_b[512 * 1000], buf_c[512 * 1000];

/* Unit-variance white noise: one-sided density 2 / rate on every line. */
static void test_white_noise_level(void **state) {
  enum { N = 256 * 400 };
  double *x = buf_a, mean = 0.0;
  rcb_complex g[129];
  const double *ch[1];
  rng r = {12345};
  est t;
  size_t k;
  (void)state;
  NEED_FFT(&t, 0, 1, 256, RCB_WINDOW_HANN, 1000.0);
  white(&r, x, N, 1.0);
  ch[0] = x;
  assert_int_equal(rcb_spectral_add_record(t.e, N, ch), RCB_OK);
  assert_int_equal(rcb_spectral_averages(t.e), 799);
  assert_int_equal(rcb_spectral_cross(t.e, 0, 0, g), RCB_OK);
  for (k = 1; k < 128; k++) mean += creal(g[k]);
  mean /= 127.0;
  /* 799 averages x 127 lines: the mean's scatter is ~0.2 % */
  assert_true(fabs(mean / (2.0 / 1000.0) - 1.0) < 0.01);
  done(&t);
}

/* Digital SDOF resonator y_n = a1 y_{n-1} + a2 y_{n-2} + b x_{n-1}: H1 is its
 * exact transfer function b z^-1 / (1 - a1 z^-1 - a2 z^-2), z = e^{i w T}. */
static void test_sdof_resonator(void **state) {
  enum { N = 1024 * 200, NB = 513 };
  const double fs = 1000.0, fn = 100.0, zeta = 0.05, T = 1.0 / fs;
  double wn = 2 * PI * fn, rr = exp(-zeta * wn * T), th = wn * sqrt(1 - zeta * zeta) * T;
  double a1 = 2 * rr * cos(th), a2 = -rr * rr, b = 1.0, worst = 0.0, rms = 0.0, w[NB], coh[NB];
  double *x = buf_a, *y = buf_b;
  rcb_complex h[NB];
  const double *ch[2];
  rng r = {777};
  est t;
  size_t k, n;
  (void)state;
  NEED_FFT(&t, 1, 1, 1024, RCB_WINDOW_HANN, fs);
  white(&r, x, N, 1.0);
  y[0] = 0.0;
  y[1] = b * x[0] + a1 * y[0];
  for (n = 2; n < N; n++) y[n] = a1 * y[n - 1] + a2 * y[n - 2] + b * x[n - 1];
  ch[0] = x;
  ch[1] = y;
  assert_int_equal(rcb_spectral_add_record(t.e, N, ch), RCB_OK);
  assert_int_equal(rcb_spectral_frf(t.e, RCB_EST_H1, 0, 0, h, coh, NULL), RCB_OK);
  rcb_spectral_frequencies(t.e, w);
  assert_true(fabs(w[1] - 2 * PI * fs / 1024) < 1e-12);
  for (k = 1; k < NB; k++) {
    rcb_complex z1 = cexp(-CMPLX(0.0, w[k] * T));
    rcb_complex hz = b * z1 / (1.0 - a1 * z1 - a2 * z1 * z1);
    double e = cabs(h[k] - hz) / cabs(hz);
    if (e > worst) worst = e;
    rms += e * e;
    assert_true(coh[k] > 0.98);
  }
  rms = sqrt(rms / (NB - 1));
  printf("SDOF resonator: H1 vs closed form: worst %.3g, RMS %.3g\n", worst, rms);
  /* Hann leakage and random error at the 10-line half-power band: ~1 % */
  assert_true(worst < 0.03 && rms < 0.005);
  done(&t);
}

/* y = x + n, var n = var x: coherence 1/2; H1 = 1 unbiased with its 95 %
 * band holding ~95 % of lines; H2 = Gyy/Gyx = 2 and Hv = (1 + sqrt 5)/2. */
static void test_known_coherence_and_biases(void **state) {
  enum { N = 512 * 1000, NB = 257 };
  double *x = buf_a, *y = buf_b, coh[NB], sd[NB];
  double mc = 0.0, m2 = 0.0, mv = 0.0, inside = 0.0;
  rcb_complex h1[NB], h2[NB], hv[NB];
  const double *ch[2];
  rng r = {4242};
  est t;
  size_t k, n;
  (void)state;
  NEED_FFT(&t, 1, 1, 512, RCB_WINDOW_HANN, 2048.0);
  white(&r, x, N, 1.0);
  for (n = 0; n < N; n++) y[n] = x[n] + gauss(&r);
  ch[0] = x;
  ch[1] = y;
  assert_int_equal(rcb_spectral_add_record(t.e, N, ch), RCB_OK);
  assert_int_equal(rcb_spectral_frf(t.e, RCB_EST_H1, 0, 0, h1, coh, sd), RCB_OK);
  assert_int_equal(rcb_spectral_frf(t.e, RCB_EST_H2, 0, 0, h2, NULL, NULL), RCB_OK);
  assert_int_equal(rcb_spectral_frf(t.e, RCB_EST_HV, 0, 0, hv, NULL, NULL), RCB_OK);
  for (k = 1; k < NB - 1; k++) {
    mc += coh[k];
    m2 += creal(h2[k]);
    mv += creal(hv[k]);
    /* circular Gaussian error, sd per component: 95 % radius sqrt(-2 ln 0.05) sd */
    inside += cabs(h1[k] - 1.0) <= 2.4477 * sd[k];
  }
  mc /= NB - 2;
  m2 /= NB - 2;
  mv /= NB - 2;
  inside /= NB - 2;
  assert_true(fabs(mc - 0.5) < 0.01);
  assert_true(fabs(m2 - 2.0) < 0.02);
  assert_true(fabs(mv - 0.5 * (1.0 + sqrt(5.0))) < 0.02);
  printf("known coherence: mean %.4f, H1 inside its 95 %% band at %.1f %% of lines\n", mc,
         100.0 * inside);
  assert_true(inside > 0.90 && inside < 0.99);
  /* and sd itself: |H1| sqrt((1 - coh) / (2 (nd - 1) coh)), nd = 1999 segments
   * over Hann's 50 % overlap factor 1 + 2 rho^2, rho = 1/6 (periodic Hann at N/2) */
  assert_true(fabs(sd[10] - cabs(h1[10]) * sqrt((1 - coh[10]) /
                                                (2 * (1999.0 / (1.0 + 2.0 / 36.0) - 1.0) *
                                                 coh[10]))) < 1e-12);
  done(&t);
}

/* Noise on the input only: H2 unbiased, H1 = 1/(1 + 1) biased low. */
static void test_input_noise(void **state) {
  enum { N = 256 * 1000, NB = 129 };
  double *x = buf_a, *xm = buf_b, m1 = 0.0, m2 = 0.0;
  rcb_complex h1[NB], h2[NB];
  const double *ch[2];
  rng r = {99};
  est t;
  size_t k, n;
  (void)state;
  NEED_FFT(&t, 1, 1, 256, RCB_WINDOW_FLATTOP, 1000.0);
  white(&r, x, N, 1.0);
  for (n = 0; n < N; n++) xm[n] = x[n] + gauss(&r);
  ch[0] = xm;
  ch[1] = x;
  assert_int_equal(rcb_spectral_add_record(t.e, N, ch), RCB_OK);
  assert_int_equal(rcb_spectral_frf(t.e, RCB_EST_H1, 0, 0, h1, NULL, NULL), RCB_OK);
  assert_int_equal(rcb_spectral_frf(t.e, RCB_EST_H2, 0, 0, h2, NULL, NULL), RCB_OK);
  for (k = 1; k < NB - 1; k++) {
    m1 += creal(h1[k]);
    m2 += creal(h2[k]);
  }
  assert_true(fabs(m1 / (NB - 2) - 0.5) < 0.02);
  assert_true(fabs(m2 / (NB - 2) - 1.0) < 0.03);
  done(&t);
}

/* Two independent inputs, y = 2 x1 - 3 x2 + n: H1 = (2, -3), multiple
 * coherence 13/14; the same input twice is refused as singular. */
static void test_two_inputs(void **state) {
  enum { N = 256 * 400, NB = 129 };
  double *x1 = buf_a, *x2 = buf_b, *y = buf_c;
  double coh[NB], sd[NB], mc = 0.0;
  rcb_complex ha[NB], hb[NB];
  const double *ch[3];
  rng r = {31337};
  est t;
  size_t k, n, in_a = 0;
  (void)state;
  NEED_FFT(&t, 2, 1, 256, RCB_WINDOW_HANN, 1000.0);
  white(&r, x1, N, 1.0);
  white(&r, x2, N, 1.0);
  for (n = 0; n < N; n++) y[n] = 2 * x1[n] - 3 * x2[n] + gauss(&r);
  ch[0] = x1;
  ch[1] = x2;
  ch[2] = y;
  assert_int_equal(rcb_spectral_add_record(t.e, N, ch), RCB_OK);
  assert_int_equal(rcb_spectral_frf(t.e, RCB_EST_H1, 0, 0, ha, coh, sd), RCB_OK);
  assert_int_equal(rcb_spectral_frf(t.e, RCB_EST_H1, 0, 1, hb, NULL, NULL), RCB_OK);
  assert_int_equal(rcb_spectral_frf(t.e, RCB_EST_H2, 0, 0, hb, NULL, NULL), RCB_ERR_ARG);
  for (k = 1; k < NB - 1; k++) {
    mc += coh[k];
    in_a += cabs(ha[k] - 2.0) <= 2.4477 * sd[k];
    assert_true(cabs(ha[k] - 2.0) < 0.2 && cabs(hb[k] + 3.0) < 0.2);
  }
  assert_true(fabs(mc / (NB - 2) - 13.0 / 14.0) < 0.005);
  assert_true(in_a > 0.85 * (NB - 2));
  done(&t);
  NEED_FFT(&t, 2, 1, 256, RCB_WINDOW_HANN, 1000.0);
  ch[1] = x1;
  assert_int_equal(rcb_spectral_add_record(t.e, N, ch), RCB_OK);
  assert_int_equal(rcb_spectral_frf(t.e, RCB_EST_H1, 0, 0, ha, NULL, NULL), RCB_ERR_SINGULAR);
  assert_non_null(strstr(rcb_spectral_errmsg(t.e), "fully coherent"));
  done(&t);
}

/* Sizing: too small a workspace is refused, the object sits in the caller's
 * buffer (any alignment), and bad settings are refused. */
static void test_workspace(void **state) {
  rcb_spectral_opts o;
  rcb_spectral *e = NULL;
  size_t bytes = 0;
  unsigned char *work;
  (void)state;
  memset(&o, 0, sizeof o);
  o.ninputs = 1;
  o.noutputs = 3;
  o.nseg = 4096;
  o.noverlap = 2048;
  o.rate = 1000.0;
  if (rcb_spectral_workspace_size(&o, &bytes) == RCB_ERR_UNSUPPORTED) skip();
  assert_true(bytes > (size_t)4 * 2049 * 16 && bytes < 600000);
  work = malloc(bytes + 1);
  assert_int_equal(rcb_spectral_init(&e, &o, work + 1, bytes - 1), RCB_ERR_WORKSPACE);
  assert_int_equal(rcb_spectral_init(&e, &o, work + 1, bytes), RCB_OK);
  assert_true((unsigned char *)e >= work + 1 && (unsigned char *)e < work + 1 + bytes);
  rcb_spectral_release(e);
  o.noverlap = 4096;
  assert_int_equal(rcb_spectral_workspace_size(&o, &bytes), RCB_ERR_ARG);
  o.noverlap = 0;
  o.rate = -1.0;
  assert_int_equal(rcb_spectral_workspace_size(&o, &bytes), RCB_ERR_ARG);
  free(work);
}

/* ---- readers ---- */

static void write_text(const char *path, const char *text) {
  FILE *fp = fopen(path, "w");
  assert_non_null(fp);
  fputs(text, fp);
  fclose(fp);
}

static void test_csv_units(void **state) {
  const char *p = rcb_test_tmp_path("sig.csv");
  rcb_signals *s;
  const char *name;
  const double *v;
  rcb_quantity q;
  (void)state;
  write_text(p, "# a test signal\n# units = N,m,mm\ntime_s,C.B.y,DA.x [g],DB.x\n"
                "0,1,1,1\n0.001,2,0.5,-2\n0.002,3,0,3\n");
  assert_int_equal(rcb_signals_create(&s, NULL), RCB_OK);
  if (rcb_signals_read_csv(s, p)) fail_msg("%s", rcb_signals_errmsg(s));
  assert_int_equal(rcb_signals_channel_count(s), 3);
  assert_int_equal(rcb_signals_length(s), 3);
  assert_true(fabs(rcb_signals_rate(s) - 1000.0) < 1e-9);
  assert_int_equal(rcb_signals_channel(s, 1, &name, &q, &v), RCB_OK);
  assert_string_equal(name, "DA.x");
  assert_int_equal(q, RCB_QTY_ACCELERATION);
  assert_true(v[0] == 9.80665 && v[1] == 0.5 * 9.80665); /* g: CGPM standard gravity */
  assert_int_equal(rcb_signals_channel(s, 2, &name, &q, &v), RCB_OK);
  assert_int_equal(q, RCB_QTY_DISPLACEMENT);
  assert_true(fabs(v[1] + 2e-3) < 1e-18);
  assert_int_equal(rcb_signals_channel(s, 0, &name, &q, &v), RCB_OK);
  assert_int_equal(q, RCB_QTY_FORCE);
  /* refusals: unknown unit, uneven time, ragged row */
  write_text(p, "time_s,DA.x [furlong]\n0,1\n0.001,2\n");
  assert_int_equal(rcb_signals_read_csv(s, p), RCB_ERR_PARSE);
  assert_non_null(strstr(rcb_signals_errmsg(s), "unit 'furlong'"));
  assert_int_equal(rcb_signals_channel_count(s), 0);
  write_text(p, "time_s,DA.x [m]\n0,1\n0.001,2\n0.003,2\n0.004,2\n");
  assert_int_equal(rcb_signals_read_csv(s, p), RCB_ERR_PARSE);
  assert_non_null(strstr(rcb_signals_errmsg(s), "evenly spaced"));
  write_text(p, "time_s,DA.x [m],DB.x [m]\n0,1,1\n0.001,2\n");
  assert_int_equal(rcb_signals_read_csv(s, p), RCB_ERR_PARSE);
  assert_non_null(strstr(rcb_signals_errmsg(s), ":3:"));
  /* 1e308 is finite but its power overflows: refused at its line (issue #26
   * saw a NaN spectrum, "value -nan-nani", with no place in the file) */
  write_text(p, "time_s,DA.x [m]\n0,1\n0.001,1e308\n0.002,2\n");
  assert_int_equal(rcb_signals_read_csv(s, p), RCB_ERR_PARSE);
  assert_non_null(strstr(rcb_signals_errmsg(s), ":3: field 2 is 1e+308"));
  /* an unknown unit given by the caller (--units): read */
  write_text(p, "time_s,DA.x [furlong]\n0,1\n0.001,2\n");
  assert_int_equal(rcb_signals_set_unit(s, "DA.x", "furlong"), RCB_ERR_ARG);
  assert_non_null(strstr(rcb_signals_errmsg(s), "m/s^2"));
  assert_int_equal(rcb_signals_set_unit(s, "DA.x", "mm"), RCB_OK);
  assert_int_equal(rcb_signals_read_csv(s, p), RCB_OK);
  rcb_signals_channel(s, 0, NULL, &q, &v);
  assert_true(q == RCB_QTY_DISPLACEMENT && v[1] == 2e-3);
  rcb_signals_destroy(s);
}

static void put_tag(unsigned char *p, const char *tag) {
  int i;
  for (i = 0; i < 4; i++) p[i] = (unsigned char)tag[i];
}

static void put_le(unsigned char *p, unsigned long v, int n) {
  int i;
  for (i = 0; i < n; i++) p[i] = (unsigned char)(v >> (8 * i));
}

/* A WAV file: 2 channels, nsamp frames, PCM of @p bits or float (fmt 3). */
static void write_wav(const char *path, unsigned fmt, unsigned bits, const long *pcm,
                      const float *flt, size_t nsamp) {
  unsigned char h[44];
  size_t nb = bits / 8, data = nsamp * 2 * nb, i;
  FILE *fp = fopen(path, "wb");
  assert_non_null(fp);
  put_tag(h, "RIFF");
  put_le(h + 4, (unsigned long)(36 + data), 4);
  put_tag(h + 8, "WAVE");
  put_tag(h + 12, "fmt ");
  put_le(h + 16, 16, 4);
  put_le(h + 20, fmt, 2);
  put_le(h + 22, 2, 2);
  put_le(h + 24, 8000, 4);
  put_le(h + 28, 8000UL * 2 * nb, 4);
  put_le(h + 32, (unsigned long)(2 * nb), 2);
  put_le(h + 34, bits, 2);
  put_tag(h + 36, "data");
  put_le(h + 40, (unsigned long)data, 4);
  fwrite(h, 1, 44, fp);
  for (i = 0; i < 2 * nsamp; i++) {
    unsigned char b[4];
    if (flt) {
      uint32_t u;
      memcpy(&u, &flt[i], 4);
      put_le(b, u, 4);
    } else {
      put_le(b, (unsigned long)pcm[i], (int)nb);
    }
    fwrite(b, 1, nb, fp);
  }
  fclose(fp);
}

static void test_wav(void **state) {
  const char *p = rcb_test_tmp_path("sig.wav");
  const char *names[2] = {"C.B.y", "DA.x"}, *units[2] = {"N", "g"};
  const double scale[2] = {500.0, 50.0}; /* full scale: 500 N, 50 g */
  long pcm16[4] = {16384, -32768, -16384, 32767};
  long pcm24[4] = {4194304, -8388608, 1, -1};
  float flt[4] = {0.25f, -1.0f, 0.5f, 2.0f};
  rcb_signals *s;
  const double *v;
  rcb_quantity q;
  (void)state;
  assert_int_equal(rcb_signals_create(&s, NULL), RCB_OK);
  write_wav(p, 1, 16, pcm16, NULL, 2);
  assert_int_equal(rcb_signals_read_wav(s, p, 2, names, units, scale), RCB_OK);
  assert_true(rcb_signals_rate(s) == 8000.0 && rcb_signals_length(s) == 2);
  rcb_signals_channel(s, 0, NULL, &q, &v);
  assert_int_equal(q, RCB_QTY_FORCE);
  assert_true(v[0] == 250.0 && v[1] == -250.0);
  rcb_signals_channel(s, 1, NULL, &q, &v);
  assert_int_equal(q, RCB_QTY_ACCELERATION);
  assert_true(v[0] == -50.0 * 9.80665 && fabs(v[1] - 50.0 * 9.80665 * 32767.0 / 32768.0) < 1e-12);
  write_wav(p, 1, 24, pcm24, NULL, 2);
  assert_int_equal(rcb_signals_read_wav(s, p, 0, NULL, NULL, NULL), RCB_OK);
  rcb_signals_channel(s, 1, NULL, &q, &v);
  assert_int_equal(q, RCB_QTY_VOLTAGE);
  assert_true(v[0] == -1.0 && v[1] == -1.0 / 8388608.0);
  write_wav(p, 3, 32, NULL, flt, 2);
  assert_int_equal(rcb_signals_read_wav(s, p, 0, NULL, NULL, NULL), RCB_OK);
  rcb_signals_channel(s, 1, NULL, &q, &v);
  assert_true(v[0] == -1.0 && v[1] == 2.0);
  write_wav(p, 1, 8, pcm16, NULL, 2);
  assert_int_equal(rcb_signals_read_wav(s, p, 0, NULL, NULL, NULL), RCB_ERR_PARSE);
  assert_non_null(strstr(rcb_signals_errmsg(s), "8 bits"));
  rcb_signals_destroy(s);
}

/* Keep the first @p keep bytes of @p path; with @p data_claim nonzero, also
 * set the data chunk's size field (byte 40 of write_wav's header) to it. */
static void cut_file(const char *path, size_t keep, unsigned long data_claim) {
  unsigned char b[256];
  size_t n;
  FILE *fp = fopen(path, "rb");
  assert_non_null(fp);
  n = fread(b, 1, sizeof b, fp);
  fclose(fp);
  assert_true(keep <= n);
  if (data_claim) put_le(b + 40, data_claim, 4);
  fp = fopen(path, "wb");
  assert_non_null(fp);
  assert_int_equal(fwrite(b, 1, keep, fp), keep);
  fclose(fp);
}

/* Issue #25 item 3: a WAV file cut short, cut mid-frame, or whose data chunk
 * claims more than the file holds is refused with the byte counts (it was
 * read silently from what was there); allowed, its whole frames are read
 * with a warning that gives the counts. 16-bit stereo: 4-byte frames. */
static void test_wav_truncated(void **state) {
  const char *p = rcb_test_tmp_path("cut.wav");
  long pcm[8] = {100, -100, 200, -200, 300, -300, 400, -400};
  rcb_signals *s;
  const double *v;
  (void)state;
  assert_int_equal(rcb_signals_create(&s, NULL), RCB_OK);
  /* 4 frames (16 bytes) claimed, 1 frame and 2 bytes present */
  write_wav(p, 1, 16, pcm, NULL, 4);
  cut_file(p, 44 + 6, 0);
  assert_int_equal(rcb_signals_read_wav(s, p, 0, NULL, NULL, NULL), RCB_ERR_PARSE);
  assert_non_null(strstr(rcb_signals_errmsg(s), "claims 16 bytes, the file holds 6"));
  assert_non_null(strstr(rcb_signals_errmsg(s), "1 whole frames"));
  assert_int_equal(rcb_signals_channel_count(s), 0);
  assert_int_equal(rcb_signals_set_allow_truncated(s, 1), RCB_OK);
  assert_int_equal(rcb_signals_read_wav(s, p, 0, NULL, NULL, NULL), RCB_OK);
  assert_int_equal(rcb_signals_length(s), 1);
  rcb_signals_channel(s, 1, NULL, NULL, &v);
  assert_true(v[0] == -100.0 / 32768.0);
  assert_int_equal(rcb_signals_warning_count(s), 1);
  assert_non_null(strstr(rcb_signals_warning(s, 0), "claims 16 bytes, the file holds 6"));
  /* the header says 6 bytes and 6 are there: cut mid-frame */
  assert_int_equal(rcb_signals_set_allow_truncated(s, 0), RCB_OK);
  write_wav(p, 1, 16, pcm, NULL, 4);
  cut_file(p, 44 + 6, 6);
  assert_int_equal(rcb_signals_read_wav(s, p, 0, NULL, NULL, NULL), RCB_ERR_PARSE);
  assert_non_null(strstr(rcb_signals_errmsg(s), "6 bytes ends 2 bytes into a frame of 4"));
  /* a streaming writer's placeholder: 0xFFFFFFFF bytes claimed, all 4 frames there */
  write_wav(p, 1, 16, pcm, NULL, 4);
  cut_file(p, 44 + 16, 0xFFFFFFFFUL);
  assert_int_equal(rcb_signals_read_wav(s, p, 0, NULL, NULL, NULL), RCB_ERR_PARSE);
  assert_non_null(strstr(rcb_signals_errmsg(s), "claims 4294967295 bytes, the file holds 16"));
  /* the whole file reads with no warning */
  write_wav(p, 1, 16, pcm, NULL, 4);
  assert_int_equal(rcb_signals_read_wav(s, p, 0, NULL, NULL, NULL), RCB_OK);
  assert_int_equal(rcb_signals_length(s), 4);
  assert_int_equal(rcb_signals_warning_count(s), 0);
  rcb_signals_destroy(s);
}

static void test_units_table(void **state) {
  rcb_quantity q;
  double f;
  (void)state;
  assert_int_equal(rcb_unit_parse(" um ", &q, &f), 0);
  assert_true(q == RCB_QTY_DISPLACEMENT && f == 1e-6);
  assert_int_equal(rcb_unit_parse("mil", &q, &f), 0);
  assert_true(fabs(f - 25.4e-6) < 1e-20);
  assert_int_equal(rcb_unit_parse("m/s^2", &q, &f), 0);
  assert_int_equal(q, RCB_QTY_ACCELERATION);
  assert_int_equal(rcb_unit_parse("Mm", &q, &f), -1);
  assert_string_equal(rcb_quantity_name(RCB_QTY_VELOCITY), "velocity");
  /* vendor labels (issue #25): m/s² in UTF-8 and in Latin-1, Pa, in, in/s, lbf */
  assert_int_equal(rcb_unit_parse("m/s\xc2\xb2", &q, &f), 0);
  assert_true(q == RCB_QTY_ACCELERATION && f == 1.0);
  assert_int_equal(rcb_unit_parse("m/s\xb2", &q, &f), 0);
  assert_true(q == RCB_QTY_ACCELERATION && f == 1.0);
  assert_int_equal(rcb_unit_parse("Pa", &q, &f), 0);
  assert_true(q == RCB_QTY_PRESSURE && f == 1.0);
  assert_int_equal(rcb_unit_parse("in", &q, &f), 0);
  assert_true(q == RCB_QTY_DISPLACEMENT && f == 0.0254);
  assert_int_equal(rcb_unit_parse("in/s", &q, &f), 0);
  assert_true(q == RCB_QTY_VELOCITY && f == 0.0254);
  assert_int_equal(rcb_unit_parse("lbf", &q, &f), 0);
  assert_true(q == RCB_QTY_FORCE && fabs(f - 0.45359237 * 9.80665) < 1e-15);
  {
    char list[512];
    size_t n = rcb_unit_list(RCB_QTY_UNKNOWN, list, sizeof list);
    assert_true(n < sizeof list && strlen(list) == n);
    assert_non_null(strstr(list, "m/s^2"));
    assert_non_null(strstr(list, ", Pa"));
    assert_null(strstr(list, "m/s2")); /* aliases are not listed */
    assert_int_equal(rcb_unit_list(RCB_QTY_UNKNOWN, list, 4), n);
    assert_int_equal(strlen(list), 3);
    rcb_unit_list(RCB_QTY_FORCE, list, sizeof list); /* one quantity's labels only */
    assert_string_equal(list, "N, kN, lbf, N m");
  }
}

/* ---- units of FRF files (UFF 164, record-9/10 labels) ---- */

/* An FRF file: optional dataset 164 (length, force factors), one record of
 * data type 8/11/12 over 13 with the given units labels, 1 + 2i at 10 Hz. */
static const char *frf_uff(const char *u164, int s9, const char *lab9, const char *lab10) {
  const char *p = rcb_test_tmp_path("units.uff");
  FILE *fp = fopen(p, "w");
  assert_non_null(fp);
  if (u164) fputs(u164, fp);
  fprintf(fp, "%6d\n%6d%74s\n", -1, 58, "");
  fprintf(fp, "%-80s\n%-80s\n%-80s\n%-80s\n%-80s\n", "id1", "NONE", "NONE", "NONE", "NONE");
  fprintf(fp, "%5d%10d%5d%10d %10s%10ld%4d %10s%10ld%4d\n", 4, 0, 0, 0, "NONE", 1L, 1, "NONE",
          2L, 1);
  fprintf(fp, "%10d%10ld%10d%13.5e%13.5e%13.5e\n", 6, 1L, 1, 10.0, 1.0, 0.0);
  fprintf(fp, "%10d%5d%5d%5d %-20s %-20s\n", 18, 0, 0, 0, "Frequency", "Hz");
  fprintf(fp, "%10d%5d%5d%5d %-20s %-20s\n", s9, 0, 0, 0, "Response", lab9);
  fprintf(fp, "%10d%5d%5d%5d %-20s %-20s\n", 13, 0, 0, 0, "Force", lab10);
  fprintf(fp, "%10d%5d%5d%5d %-20s %-20s\n", 0, 0, 0, 0, "NONE", "NONE");
  fputs("   1.00000000000e+00   2.00000000000e+00\n", fp);
  fprintf(fp, "%6d\n", -1);
  fclose(fp);
  return p;
}

static const char U164_MM[] =
    "    -1\n   164\n         5mm (milli newton)         2\n"
    "  1.00000000000000000D+03  1.00000000000000000D+00  1.00000000000000000D+00\n"
    "  2.73150000000000000D+02\n    -1\n";

static void read_frf_value(const char *p, rcb_frf_kind kind, double factor) {
  rcb_meas *ms;
  rcb_meas_channel_info c;
  assert_int_equal(rcb_meas_create(&ms, NULL), RCB_OK);
  if (rcb_meas_read_uff(ms, p, 0, NULL)) fail_msg("%s", rcb_meas_errmsg(ms));
  assert_int_equal(rcb_meas_channel(ms, 0, &c), RCB_OK);
  assert_int_equal(c.kind, kind);
  assert_true(fabs(creal(c.data[0]) - factor) < 1e-15 * factor &&
              fabs(cimag(c.data[0]) - 2.0 * factor) < 2e-15 * factor);
  rcb_meas_destroy(ms);
}

static void refused(const char *p, const char *frag) {
  rcb_meas *ms;
  assert_int_equal(rcb_meas_create(&ms, NULL), RCB_OK);
  assert_int_equal(rcb_meas_read_uff(ms, p, 0, NULL), RCB_ERR_PARSE);
  if (!strstr(rcb_meas_errmsg(ms), frag))
    fail_msg("message '%s' lacks '%s'", rcb_meas_errmsg(ms), frag);
  assert_int_equal(rcb_meas_channel_count(ms), 0);
  rcb_meas_destroy(ms);
}

static void test_frf_units(void **state) {
  (void)state;
  /* mm/N through dataset 164 (length factor 1000, force 1): 1e-3 m/N */
  read_frf_value(frf_uff(U164_MM, 8, "NONE", "NONE"), RCB_RECEPTANCE, 1e-3);
  read_frf_value(frf_uff(U164_MM, 8, "mm", "N"), RCB_RECEPTANCE, 1e-3);
  /* g/N by the labels: 9.80665 (m/s^2)/N */
  read_frf_value(frf_uff(NULL, 12, "g", "N"), RCB_INERTANCE, 9.80665);
  read_frf_value(frf_uff(NULL, 11, "mm/s", "kN"), RCB_MOBILITY, 1e-6);
  /* SI labels as librcb writes them */
  read_frf_value(frf_uff(NULL, 8, "m", "N"), RCB_RECEPTANCE, 1.0);
  /* refusals: wrong quantity, 164 disagreeing, unknown label */
  refused(frf_uff(NULL, 12, "mm", "N"), "is a displacement, but its data type 12 says "
                                        "acceleration");
  refused(frf_uff(NULL, 8, "m", "g"), "is an acceleration, but its data type 13 says force");
  refused(frf_uff(U164_MM, 8, "m", "N"), "disagrees with dataset 164");
  refused(frf_uff(NULL, 8, "furlong", "N"), "'furlong' is not a unit");
  /* the labels listed are the expected quantity's (issue #26: displacement
   * units were listed after "expected force") */
  refused(frf_uff(NULL, 8, "m", "pound"), "expected force (N, kN, lbf, N m) or NONE");
  refused(frf_uff("    -1\n   164\n        42\n    -1\n", 8, "m", "N"), "dataset 164");
}

/* ---- order tracking ---- */

/* Keyphasor with a linear rising edge of +-7.2 deg about each mark (5 V). */
static double keyphasor(double phi) {
  double w = fmod(phi, 2 * PI), d = 2 * PI * 0.02;
  if (w > PI) w -= 2 * PI;
  if (w >= -d && w <= d) return 2.5 + 2.5 * w / d;
  return w > d && w < PI / 4 ? 5.0 : 0.0;
}

/* A run-up 1000 -> 3000 rpm in 4 s with y = 2 cos(phi + 0.3) + 0.5 cos(2 phi - 1)
 * (+ noise): every bin's 1X and 2X equal 2 e^{0.3i} and 0.5 e^{-i} (to the
 * within-revolution speed change), and with noise the sd predicts the error. */
static void test_order_runup(void **state) {
  enum { N = 4 * 20000 };
  const double fs = 20000.0, w0 = 1000 * PI / 30, al = 500 * PI / 30;
  double *kp = malloc(N * sizeof *kp), *y = malloc(N * sizeof *y), *yn = malloc(N * sizeof *yn);
  const double *ch[2];
  rcb_order_opts o;
  rcb_order *e;
  size_t bytes, b, reported = 0, within = 0, n;
  void *work;
  rng r = {5};
  (void)state;
  for (n = 0; n < N; n++) {
    double t = (double)n / fs, phi = w0 * t + 0.5 * al * t * t;
    kp[n] = keyphasor(phi);
    y[n] = 2 * cos(phi + 0.3) + 0.5 * cos(2 * phi - 1.0);
    yn[n] = y[n] + 0.2 * gauss(&r);
  }
  memset(&o, 0, sizeof o);
  o.norders = 2;
  o.trigger = NAN;
  o.bin_width = 100 * PI / 30;
  o.speed_max = 4000 * PI / 30;
  assert_int_equal(rcb_order_workspace_size(&o, 2, &bytes), RCB_OK);
  work = malloc(bytes);
  assert_int_equal(rcb_order_init(&e, &o, 2, work, bytes - 1), RCB_ERR_WORKSPACE);
  assert_int_equal(rcb_order_init(&e, &o, 2, work, bytes), RCB_OK);
  ch[0] = y;
  ch[1] = yn;
  assert_int_equal(rcb_order_add(e, fs, N, kp, ch), RCB_OK);
  /* phi(4 s) / 2 pi = (1000/60) 4 + (500/60) 8 = 133.3: 133 pulses (the mark
   * at t = 0 is no crossing), 132 revolutions, the first without a pulse
   * before it */
  assert_int_equal(rcb_order_revolutions(e), 131);
  for (b = 0; b < rcb_order_bin_count(e); b++) {
    double speed, sd, sd2;
    rcb_complex q1, q2, qn;
    size_t nr;
    assert_int_equal(rcb_order_result(e, b, 0, 1, &speed, &q1, NULL, &nr), RCB_OK);
    if (nr < 2) continue;
    reported++;
    assert_true(speed >= (double)b * o.bin_width && speed < (double)(b + 1) * o.bin_width);
    rcb_order_result(e, b, 0, 2, NULL, &q2, &sd2, NULL);
    if (cabs(q1 - 2 * cexp(CMPLX(0, 0.3))) > 1e-4 * 2 || cabs(q2 - 0.5 * cexp(CMPLX(0, -1.0))) > 1e-4 * 0.5)
      fail_msg("bin %zu: 1X error %g, 2X error %g", b, cabs(q1 - 2 * cexp(CMPLX(0, 0.3))) / 2, cabs(q2 - 0.5 * cexp(CMPLX(0, -1.0))) / 0.5);
    rcb_order_result(e, b, 1, 1, NULL, &qn, &sd, NULL);
    within += cabs(qn - 2 * cexp(CMPLX(0, 0.3))) <= 2.4477 * sd;
  }
  assert_int_equal(reported, 20); /* 1000 .. 2999 rpm in 100 rpm bins */
  printf("order tracking, noise 0.2: 1X inside its 95 %% band in %zu of %zu bins\n", within,
         reported);
  assert_true(within >= 16);
  /* no keyphasor pulse: refused */
  memset(kp, 0, N * sizeof *kp);
  assert_int_equal(rcb_order_add(e, fs, N, kp, ch), RCB_ERR_ARG);
  assert_non_null(strstr(rcb_order_errmsg(e), "keyphasor"));
  free(work);
  free(kp);
  free(y);
  free(yn);
}

/* A notch keyphasor (issue #25): 5 V, falling linearly through 2.5 V at the
 * shaft's angle 0 (over +-7.2 deg), 0 V in the notch, stepping back to 5 V
 * at 45 deg. */
static double notch(double phi) {
  double w = fmod(phi, 2 * PI), d = 2 * PI * 0.02;
  if (w > PI) w -= 2 * PI;
  if (w >= -d && w <= d) return 2.5 - 2.5 * w / d;
  return w > d && w < PI / 4 ? 0.0 : 5.0;
}

/* --kp-edge falling: a notch keyphasor's falling edge marks angle 0, so 1X is
 * 2 e^{0.3i} to 1e-4 as with a projection's rising edge; its rising edge (the
 * default, before the option) is the notch's far end, 45 deg later, and
 * turns the phase by those 45 deg. */
static void test_order_kp_edge(void **state) {
  enum { N = 4 * 20000 };
  const double fs = 20000.0, w0 = 1000 * PI / 30, al = 500 * PI / 30;
  double *kp = malloc(N * sizeof *kp), *y = malloc(N * sizeof *y);
  const double *ch[1];
  rcb_order_opts o;
  rcb_order *e;
  size_t bytes, b, n, reported = 0;
  void *work;
  int edge;
  (void)state;
  for (n = 0; n < N; n++) {
    double t = (double)n / fs, phi = w0 * t + 0.5 * al * t * t;
    kp[n] = notch(phi);
    y[n] = 2 * cos(phi + 0.3);
  }
  ch[0] = y;
  memset(&o, 0, sizeof o);
  o.norders = 1;
  o.trigger = NAN;
  o.bin_width = 100 * PI / 30;
  o.speed_max = 4000 * PI / 30;
  assert_int_equal(rcb_order_workspace_size(&o, 1, &bytes), RCB_OK);
  work = malloc(bytes);
  for (edge = 1; edge >= 0; edge--) {
    o.kp_falling = edge;
    assert_int_equal(rcb_order_init(&e, &o, 1, work, bytes), RCB_OK);
    assert_int_equal(rcb_order_add(e, fs, N, kp, ch), RCB_OK);
    for (b = 0; b < rcb_order_bin_count(e); b++) {
      rcb_complex q;
      size_t nr;
      rcb_order_result(e, b, 0, 1, NULL, &q, NULL, &nr);
      if (nr < 2) continue;
      reported += edge;
      if (edge && cabs(q - 2 * cexp(CMPLX(0, 0.3))) > 1e-4 * 2)
        fail_msg("falling edge, bin %zu: 1X %g at %g deg", b, cabs(q), carg(q) * 180 / PI);
      /* the rising edge is a step between samples: within 1 sample (<= 0.9 deg) */
      if (!edge && fabs(carg(q * cexp(CMPLX(0, -0.3 - PI / 4)))) > 0.9 * PI / 180)
        fail_msg("rising edge of the notch, bin %zu: phase %g deg, expected %g", b,
                 carg(q) * 180 / PI, (0.3 + PI / 4) * 180 / PI);
    }
  }
  assert_int_equal(reported, 20);
  free(work);
  free(kp);
  free(y);
}

/* The joint fit at a low sample rate (issue #25): 6000 -> 9000 rpm in 3 s
 * at 2000 S/s (13 to 20 samples per revolution), 8 orders asked for. Orders
 * above 0.45 x the sample rate alias onto the lower ones; they are left out
 * of a bin's fit (sd NaN) and 1X and 2X stay exact: 2 e^{0.3i} and 0.5 e^{-i}
 * to 1e-5. The keyphasor is a ramp in the shaft angle (0 at the mark, 2 pi
 * just before the next), so that its crossing of pi, interpolated between
 * samples, is nearly exact (3e-6 rad: the angle is quadratic in time); the
 * mark is angle pi. */
static void test_order_fit_nyquist(void **state) {
  enum { N = 3 * 2000 };
  const double fs = 2000.0, w0 = 6000 * PI / 30, al = 1000 * PI / 30;
  double *kp = malloc(N * sizeof *kp), *y = malloc(N * sizeof *y);
  const double *ch[1];
  rcb_order_opts o;
  rcb_order *e;
  size_t bytes, b, n, reported = 0, nr;
  void *work;
  (void)state;
  for (n = 0; n < N; n++) {
    double t = (double)n / fs, phi = w0 * t + 0.5 * al * t * t;
    kp[n] = fmod(phi, 2 * PI);
    y[n] = 2 * cos(phi + 0.3) + 0.5 * cos(2 * phi - 1.0);
  }
  ch[0] = y;
  memset(&o, 0, sizeof o);
  o.norders = 8;
  o.trigger = PI;
  o.kp_angle = PI;
  o.bin_width = 300 * PI / 30;
  o.speed_max = 10000 * PI / 30;
  assert_int_equal(rcb_order_workspace_size(&o, 1, &bytes), RCB_OK);
  work = malloc(bytes);
  assert_int_equal(rcb_order_init(&e, &o, 1, work, bytes), RCB_OK);
  assert_int_equal(rcb_order_add(e, fs, N, kp, ch), RCB_OK);
  for (b = 0; b < rcb_order_bin_count(e); b++) {
    rcb_complex q1, q2, q;
    double sd, speed;
    size_t m, fitted = 0;
    rcb_order_result(e, b, 0, 1, &speed, &q1, NULL, &nr);
    if (nr < 3) continue;
    reported++;
    rcb_order_result(e, b, 0, 2, NULL, &q2, NULL, NULL);
    if (cabs(q1 - 2 * cexp(CMPLX(0, 0.3))) > 1e-5 * 2 ||
        cabs(q2 - 0.5 * cexp(CMPLX(0, -1.0))) > 1e-5 * 0.5)
      fail_msg("bin %zu: 1X error %g, 2X error %g", b, cabs(q1 - 2 * cexp(CMPLX(0, 0.3))) / 2,
               cabs(q2 - 0.5 * cexp(CMPLX(0, -1.0))) / 0.5);
    for (m = 1; m <= 8; m++) {
      rcb_order_result(e, b, 0, m, NULL, &q, &sd, NULL);
      fitted += !isnan(sd);
    }
    /* the bin's top speed (plus half a bin: whole revolutions) sets the orders */
    assert_int_equal(fitted, (size_t)fmin(8.0, floor(0.45 * fs * 60 / (((double)b + 1.5) * 300))));
    if (b == 29) assert_int_equal(fitted, 5); /* 8700-9000 rpm */
  }
  assert_int_equal(reported, 10);
  /* steady at 8000 rpm, 15 samples per revolution exactly: 8X and 7X are the
   * same samples, so 8 orders would make the normal matrix singular; 6 are
   * fitted, and with no speed spread the phasors are constants */
  for (n = 0; n < N / 2; n++) {
    double phi = 2 * PI * (double)n / 15.0;
    kp[n] = fmod(phi, 2 * PI);
    y[n] = 2 * cos(phi + 0.3) + 0.5 * cos(2 * phi - 1.0);
  }
  assert_int_equal(rcb_order_init(&e, &o, 1, work, bytes), RCB_OK);
  assert_int_equal(rcb_order_add(e, fs, N / 2, kp, ch), RCB_OK);
  {
    rcb_complex q1, q2;
    double sd6, sd7;
    rcb_order_result(e, 26, 0, 1, NULL, &q1, NULL, &nr);
    rcb_order_result(e, 26, 0, 2, NULL, &q2, NULL, NULL);
    rcb_order_result(e, 26, 0, 6, NULL, NULL, &sd6, NULL);
    rcb_order_result(e, 26, 0, 7, NULL, NULL, &sd7, NULL);
    assert_int_equal(nr, 198);
    assert_true(cabs(q1 - 2 * cexp(CMPLX(0, 0.3))) < 1e-9 &&
                cabs(q2 - 0.5 * cexp(CMPLX(0, -1.0))) < 1e-9);
    assert_true(!isnan(sd6) && isnan(sd7));
  }
  free(work);
  free(kp);
  free(y);
}

/* A slow run-up through a 1X resonance: 2700 -> 3300 rpm at 30 rpm/s, y =
 * Re(Q(w) e^{i theta}) + noise, Q(w) = 1 / (1 - r^2 + 2 i zeta r), r = w /
 * (3000 rpm), zeta 0.05 (half-power band 300 rpm), 20 rpm bins (33
 * revolutions each), 10 kS/s. Fills kp, y (n samples) and returns n. */
static size_t resonance_runup(double *kp, double *y, double noise, uint64_t seed) {
  const double fs = 1e4, w0 = 2700 * PI / 30, al = 30 * PI / 30, wn = 3000 * PI / 30;
  size_t n, N = 20 * 10000;
  rng r = {seed};
  for (n = 0; n < N; n++) {
    double t = (double)n / fs, phi = w0 * t + 0.5 * al * t * t, rr = (w0 + al * t) / wn;
    rcb_complex q = 1.0 / CMPLX(1 - rr * rr, 2 * 0.05 * rr);
    kp[n] = keyphasor(phi);
    y[n] = creal(q * cexp(CMPLX(0, phi))) + (noise > 0 ? noise * gauss(&r) : 0.0);
  }
  return N;
}

/* Issue #25 item 4: the sd of a bin measures the noise, not the response's
 * change across the bin's speeds (a local linear fit in speed). Noise-free,
 * the sd near the resonance was up to 0.48 % of |1X|; now 0.017 %. With noise
 * of 0.5 per sample (5 % of the peak |1X|), over 10 seeds, the noise-free
 * bins lie inside the noisy bins' 95 % band (2.448 sd) in 90-99 % of the 150
 * bins of the half-power band (before: 150 of 150, mean |e|^2 / (2 sd^2)
 * 0.13: the sds 2.8x too large; now 139 and 1.16). */
static void test_order_sd_near_resonance(void **state) {
  enum { N = 20 * 10000 };
  double *kp = malloc(N * sizeof *kp), *y = malloc(N * sizeof *y);
  rcb_complex clean[64];
  const double *ch[1];
  rcb_order_opts o;
  rcb_order *e;
  size_t bytes, b, n, inside = 0, total = 0, nr;
  const double NOISE = 0.5;
  double worst = 0.0, chi = 0.0;
  void *work;
  uint64_t seed;
  (void)state;
  memset(&o, 0, sizeof o);
  o.norders = 1;
  o.trigger = NAN;
  o.bin_width = 20 * PI / 30;
  o.speed_max = 3400 * PI / 30;
  o.min_revs = 10;
  assert_int_equal(rcb_order_workspace_size(&o, 1, &bytes), RCB_OK);
  work = malloc(bytes);
  ch[0] = y;
  n = resonance_runup(kp, y, 0.0, 1);
  assert_int_equal(rcb_order_init(&e, &o, 1, work, bytes), RCB_OK);
  assert_int_equal(rcb_order_add(e, 1e4, n, kp, ch), RCB_OK);
  for (b = 136; b < 164; b++) { /* 2720 .. 3280 rpm: whole bins */
    double sd;
    rcb_order_result(e, b, 0, 1, NULL, &clean[b - 136], &sd, &nr);
    assert_true(nr >= 30);
    worst = fmax(worst, sd / cabs(clean[b - 136]));
  }
  printf("order tracking through a resonance, noise-free: largest sd %.3g %% of |1X|\n",
         100 * worst);
  assert_true(worst < 2e-4);
  for (seed = 11; seed < 21; seed++) {
    resonance_runup(kp, y, NOISE, seed);
    assert_int_equal(rcb_order_init(&e, &o, 1, work, bytes), RCB_OK);
    assert_int_equal(rcb_order_add(e, 1e4, n, kp, ch), RCB_OK);
    for (b = 143; b < 158; b++) { /* 2860 .. 3160 rpm: the half-power band */
      rcb_complex q;
      double sd;
      rcb_order_result(e, b, 0, 1, NULL, &q, &sd, &nr);
      total++;
      inside += cabs(q - clean[b - 136]) <= 2.4477 * sd;
      chi += cabs(q - clean[b - 136]) * cabs(q - clean[b - 136]) / (2 * sd * sd);
    }
  }
  printf("order tracking through a resonance, noise %g: inside the 95 %% band %zu of %zu, "
         "mean |e|^2 / (2 sd^2) %.3f\n", NOISE, inside, total, chi / (double)total);
  assert_true(inside >= 0.90 * (double)total && inside <= 0.99 * (double)total);
  assert_true(chi / (double)total > 0.8 && chi / (double)total < 1.35);
  free(work);
  free(kp);
  free(y);
}

/* ---- UFF58 time records ---- */

/* One real, evenly spaced time record (4E20.12): node, direction, ordinate
 * data type and units label, 4 samples from t = 0 every 1 ms. */
static void time_rec(FILE *fp, long node, int dir, int s9, const char *lab, const double *v) {
  fprintf(fp, "%6d\n%6d%74s\n", -1, 58, "");
  fprintf(fp, "%-80s\n%-80s\n%-80s\n%-80s\n%-80s\n", "time", "NONE", "NONE", "NONE", "NONE");
  fprintf(fp, "%5d%10d%5d%10d %10s%10ld%4d %10s%10ld%4d\n", 1, 0, 0, 0, "NONE", node, dir,
          "NONE", 0L, 0);
  fprintf(fp, "%10d%10ld%10d%13.5e%13.5e%13.5e\n", 4, 4L, 1, 0.0, 1e-3, 0.0);
  fprintf(fp, "%10d%5d%5d%5d %-20s %-20s\n", 17, 0, 0, 0, "Time", "s");
  fprintf(fp, "%10d%5d%5d%5d %-20s %-20s\n", s9, 0, 0, 0, "Signal", lab);
  fprintf(fp, "%10d%5d%5d%5d %-20s %-20s\n", 0, 0, 0, 0, "NONE", "NONE");
  fprintf(fp, "%10d%5d%5d%5d %-20s %-20s\n", 0, 0, 0, 0, "NONE", "NONE");
  fprintf(fp, "%20.11e%20.11e%20.11e%20.11e\n", v[0], v[1], v[2], v[3]);
  fprintf(fp, "%6d\n", -1);
}

static void test_uff_time_records(void **state) {
  const char *p = rcb_test_tmp_path("time.uff");
  const double v[4] = {1.0, -2.0, 0.5, 4.0};
  rcb_uff_node map[] = {{1, "DA", NULL, NULL}, {99, "KP", NULL, NULL}};
  rcb_signals *s;
  const char *name;
  const double *x;
  rcb_quantity q;
  FILE *fp = fopen(p, "w");
  (void)state;
  assert_non_null(fp);
  time_rec(fp, 1, 1, 8, "mm", v);     /* DA.x in mm */
  time_rec(fp, 1, -2, 12, "g", v);    /* DA.y in g, negative direction */
  time_rec(fp, 99, 0, 0, "V", v);     /* keyphasor */
  fclose(fp);
  assert_int_equal(rcb_signals_create(&s, NULL), RCB_OK);
  if (rcb_signals_read_uff(s, p, 2, map)) fail_msg("%s", rcb_signals_errmsg(s));
  assert_int_equal(rcb_signals_channel_count(s), 3);
  assert_true(fabs(rcb_signals_rate(s) - 1000.0) < 1e-6 && rcb_signals_length(s) == 4);
  rcb_signals_channel(s, 0, &name, &q, &x);
  assert_string_equal(name, "DA.x");
  assert_true(q == RCB_QTY_DISPLACEMENT && fabs(x[1] + 2e-3) < 1e-15);
  rcb_signals_channel(s, 1, &name, &q, &x);
  assert_string_equal(name, "DA.y");
  assert_true(q == RCB_QTY_ACCELERATION && fabs(x[3] + 4 * 9.80665) < 1e-12);
  rcb_signals_channel(s, 2, &name, &q, &x);
  assert_string_equal(name, "KP");
  assert_true(q == RCB_QTY_VOLTAGE && x[3] == 4.0);
  /* an FRF file has no time record; a label contradicting its data type */
  assert_int_equal(rcb_signals_read_uff(s, frf_uff(NULL, 8, "m", "N"), 0, NULL), RCB_ERR_PARSE);
  assert_non_null(strstr(rcb_signals_errmsg(s), "no dataset 58 time record"));
  fp = fopen(p, "w");
  time_rec(fp, 1, 1, 8, "g", v);
  fclose(fp);
  assert_int_equal(rcb_signals_read_uff(s, p, 2, map), RCB_ERR_PARSE);
  assert_non_null(strstr(rcb_signals_errmsg(s), "is an acceleration, but its data type 8"));
  assert_int_equal(rcb_signals_channel_count(s), 0);
  rcb_signals_destroy(s);
}

/* Impact hits (issue #35): the pulse of a half-sine of T samples has the width
 * T (1 - 2 asin(0.05) / pi) above 5 % of its peak (closed form); a second
 * pulse of 30 % is a double hit, of 8 % not (default fraction 0.1). */
static void test_hit_pulse(void **state) {
  enum { N = 2000 };
  static double f[N];
  const double rate = 10000.0, T = 0.002, pi = 3.14159265358979323846;
  rcb_hit_pulse h;
  size_t i;
  (void)state;
  for (i = 0; i < N; i++) {
    double t = (double)i / rate - 0.01;
    f[i] = t >= 0.0 && t <= T ? -400.0 * sin(pi * t / T) : 0.0; /* a negative pulse */
  }
  assert_int_equal(rcb_hit_pulse_find(f, N, rate, 0.0, &h), RCB_OK);
  assert_true(fabs(h.peak + 400.0) < 1e-9 && !h.double_hit && h.second < 1e-12);
  assert_true(fabs(h.width / (T * (1.0 - 2.0 * asin(0.05) / pi)) - 1.0) < 2e-3);
  assert_true(fabs(h.start - 0.01 - T * asin(0.05) / pi) < 2e-6);
  for (i = 0; i < N; i++) {
    double t = (double)i / rate - 0.04;
    f[i] += t >= 0.0 && t <= T ? -120.0 * sin(pi * t / T) : 0.0;
  }
  assert_int_equal(rcb_hit_pulse_find(f, N, rate, 0.0, &h), RCB_OK);
  assert_true(h.double_hit && fabs(h.second - 0.3) < 1e-9 && fabs(h.second_time - 0.041) < 1e-9);
  assert_int_equal(rcb_hit_pulse_find(f, N, rate, 0.5, &h), RCB_OK); /* 30 % < 50 % */
  assert_false(h.double_hit);
  for (i = 0; i < N; i++) f[i] = 0.0;
  assert_int_equal(rcb_hit_pulse_find(f, N, rate, 0.0, &h), RCB_OK);
  assert_true(h.peak == 0.0 && !h.double_hit);
  assert_int_equal(rcb_hit_pulse_find(f, N, rate, 1.0, &h), RCB_ERR_ARG);
}

/* A decaying 60 Hz response clipped at 60 % of its peak: the run at the clip
 * level is counted; the unclipped one has none; a declared range is met. */
static void test_hit_overload(void **state) {
  enum { N = 8192 };
  static double y[N];
  const double rate = 8192.0, pi = 3.14159265358979323846;
  rcb_hit_overload o;
  size_t i, top = 0;
  (void)state;
  for (i = 0; i < N; i++) y[i] = exp(-7.5 * (double)i / rate) * sin(2 * pi * 60.0 * (double)i / rate);
  assert_int_equal(rcb_hit_overload_find(y, N, 0, 0.0, &o), RCB_OK);
  assert_false(o.overload);
  assert_true(o.run == 1);
  for (i = 0; i < N; i++) {
    if (y[i] > 0.6) y[i] = 0.6, top++;
    if (y[i] < -0.6) y[i] = -0.6;
  }
  assert_int_equal(rcb_hit_overload_find(y, N, 0, 0.0, &o), RCB_OK);
  assert_true(o.overload && !o.at_range && o.level == 0.6 && o.run >= 5 && o.run < top);
  for (i = 0; i < N; i++) y[i] = exp(-7.5 * (double)i / rate) * sin(2 * pi * 60.0 * (double)i / rate);
  assert_int_equal(rcb_hit_overload_find(y, N, 0, 0.9, &o), RCB_OK);
  assert_true(o.overload && o.at_range && o.level >= 0.9 && o.at > 0);
  assert_int_equal(rcb_hit_overload_find(y, N, 1, 0.0, &o), RCB_ERR_ARG);
}

/* Five pulses in a stream, each with a bounce inside its hold-off: five hits
 * starting pre samples before their crossings; one too near the start. */
static void test_hit_triggers(void **state) {
  enum { N = 10000, LEN = 1500, PRE = 50 };
  static double f[N];
  static const size_t at[6] = {20, 1000, 3000, 4600, 6100, 8400};
  size_t starts[8], count = 0, partial = 0, i, k;
  (void)state;
  for (k = 0; k < 6; k++)
    for (i = 0; i < 10; i++) {
      f[at[k] + i] = 100.0 * sin(3.14159265358979323846 * (double)i / 10.0);
      f[at[k] + 300 + i] = 40.0 * sin(3.14159265358979323846 * (double)i / 10.0); /* bounce */
    }
  assert_int_equal(rcb_hit_triggers(f, N, 20.0, PRE, LEN, NULL, 0, &count, &partial), RCB_OK);
  assert_int_equal(count, 4); /* 20: before the start; 1000 within its hold-off (to 1470) */
  assert_int_equal(partial, 1);
  assert_int_equal(rcb_hit_triggers(f, N, 20.0, PRE, LEN, starts, 8, &count, &partial), RCB_OK);
  assert_int_equal(starts[0], 3001 - PRE);
  assert_int_equal(starts[1], 4601 - PRE);
  assert_int_equal(starts[2], 6101 - PRE);
  assert_int_equal(starts[3], 8401 - PRE);
  assert_int_equal(rcb_hit_triggers(f, N, -20.0, PRE, LEN, NULL, 0, &count, &partial), RCB_OK);
  assert_int_equal(count + partial, 0); /* a falling level: the pulses never go below -20 */
  assert_int_equal(rcb_hit_triggers(f, N, 20.0, LEN, LEN, NULL, 0, &count, &partial), RCB_ERR_ARG);
}

/* A UFF file with two records of each channel (two hits): joined end to end
 * when asked, refused otherwise; a channel short of a record is refused. */
static void test_uff_hit_records(void **state) {
  const char *p = rcb_test_tmp_path("hits.uff");
  const double v1[4] = {1.0, -2.0, 0.5, 4.0}, v2[4] = {3.0, 5.0, -1.0, 2.0};
  rcb_uff_node map[] = {{1, "DA", NULL, NULL}, {2, "H", NULL, NULL}};
  rcb_signals *s;
  const double *x;
  FILE *fp = fopen(p, "w");
  (void)state;
  assert_non_null(fp);
  time_rec(fp, 1, 1, 8, "mm", v1);
  time_rec(fp, 2, 1, 13, "N", v1);
  time_rec(fp, 1, 1, 8, "mm", v2);
  time_rec(fp, 2, 1, 13, "N", v2);
  fclose(fp);
  assert_int_equal(rcb_signals_create(&s, NULL), RCB_OK);
  /* not joined: each channel's first record read, the others skipped with a
   * warning naming them (a vendor file's second sensor on a node) */
  assert_int_equal(rcb_signals_read_uff(s, p, 2, map), RCB_OK);
  assert_int_equal(rcb_signals_length(s), 4);
  assert_int_equal(rcb_signals_warning_count(s), 2);
  assert_non_null(strstr(rcb_signals_warning(s, 0), "skipped: an earlier record gave channel 'DA.x'"));
  rcb_signals_set_join_records(s, 1);
  if (rcb_signals_read_uff(s, p, 2, map)) fail_msg("%s", rcb_signals_errmsg(s));
  assert_int_equal(rcb_signals_record_count(s), 2);
  assert_int_equal(rcb_signals_length(s), 8);
  rcb_signals_channel(s, 1, NULL, NULL, &x);
  assert_true(x[1] == -2.0 && x[4] == 3.0 && x[7] == 2.0);
  fp = fopen(p, "a");
  time_rec(fp, 1, 1, 8, "mm", v2);
  fclose(fp);
  /* unequal counts are no hits: each channel's first record, with a warning */
  assert_int_equal(rcb_signals_read_uff(s, p, 2, map), RCB_OK);
  assert_int_equal(rcb_signals_record_count(s), 1);
  assert_int_equal(rcb_signals_length(s), 4);
  assert_non_null(strstr(rcb_signals_warning(s, rcb_signals_warning_count(s) - 1),
                         "channel 'DA.x' has 3 records, 'H.x' has 2: not read as the hits"));
  rcb_signals_channel(s, 1, NULL, NULL, &x); /* H.x, in N: its first record, v1 */
  assert_true(x[1] == -2.0 && x[3] == 4.0);
  rcb_signals_destroy(s);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_white_noise_level),
      cmocka_unit_test(test_sdof_resonator),
      cmocka_unit_test(test_known_coherence_and_biases),
      cmocka_unit_test(test_input_noise),
      cmocka_unit_test(test_two_inputs),
      cmocka_unit_test(test_workspace),
      cmocka_unit_test(test_csv_units),
      cmocka_unit_test(test_wav),
      cmocka_unit_test(test_wav_truncated),
      cmocka_unit_test(test_units_table),
      cmocka_unit_test(test_frf_units),
      cmocka_unit_test(test_order_runup),
      cmocka_unit_test(test_order_kp_edge),
      cmocka_unit_test(test_order_fit_nyquist),
      cmocka_unit_test(test_order_sd_near_resonance),
      cmocka_unit_test(test_uff_time_records),
      cmocka_unit_test(test_hit_pulse),
      cmocka_unit_test(test_hit_overload),
      cmocka_unit_test(test_hit_triggers),
      cmocka_unit_test(test_uff_hit_records),
  };
  return cmocka_run_group_tests(tests, rcb_test_setup_tmpdir, rcb_test_teardown_tmpdir);
}
