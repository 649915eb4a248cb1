/*
 * FFT backend on kissfft (RCB_WITH_KISSFFT, used when FFTW is not built):
 * Debian's libkissfft-float, so the transform runs in single precision
 * (~1e-7 relative): good enough for condition monitoring on a small target,
 * not for the 1e-10 agreement with SciPy that the FFTW build gives. Entirely
 * in the caller's memory: kiss_fftr_alloc(n, 0, mem, &len) places its tables
 * in the workspace, with float copies of the input and output.
 */
#include "rcb/rcb_config.h"

#if RCB_WITH_KISSFFT && !RCB_WITH_FFTW
#include <kiss_fftr.h>
#include <stdio.h>

#include "signals/fft.h"

typedef struct kiss_state {
  kiss_fftr_cfg cfg;
  size_t n;
  double *in;
  rcb_complex *out;
  kiss_fft_scalar *fin;
  kiss_fft_cpx *fout;
  size_t cfg_len;
} kiss_state;

static size_t align16(size_t b) { return (b + 15) & ~(size_t)15; }

static size_t cfg_len(size_t n) {
  size_t len = 0;
  kiss_fftr_alloc((int)n, 0, NULL, &len);
  return len;
}

static size_t kiss_state_size(size_t n) {
  return align16(sizeof(kiss_state)) + align16(cfg_len(n)) + align16(n * sizeof(kiss_fft_scalar)) +
         (n / 2 + 1) * sizeof(kiss_fft_cpx) + 16;
}

static int kiss_init(void *state, size_t n, double *in, rcb_complex *out, char *err) {
  kiss_state *st = state;
  unsigned char *p = (unsigned char *)state + align16(sizeof(kiss_state));
  size_t len = cfg_len(n);
  if (n % 2 || n > (size_t)1 << 30) {
    snprintf(err, RCB_ERRMSG_MAX, "kissfft's real FFT needs an even length; got %zu", n);
    return -1;
  }
  st->cfg = kiss_fftr_alloc((int)n, 0, p, &len);
  if (!st->cfg) {
    snprintf(err, RCB_ERRMSG_MAX, "kissfft could not set up a real FFT of length %zu", n);
    return -1;
  }
  p += align16(len);
  st->fin = (kiss_fft_scalar *)(void *)p;
  p += align16(n * sizeof(kiss_fft_scalar));
  st->fout = (kiss_fft_cpx *)(void *)p;
  st->n = n;
  st->in = in;
  st->out = out;
  return 0;
}

static void kiss_exec(void *state) {
  kiss_state *st = state;
  size_t i;
  for (i = 0; i < st->n; i++) st->fin[i] = (kiss_fft_scalar)st->in[i];
  kiss_fftr(st->cfg, st->fin, st->fout);
  for (i = 0; i <= st->n / 2; i++) st->out[i] = CMPLX((double)st->fout[i].r, (double)st->fout[i].i);
}

static void kiss_release(void *state) { (void)state; }

static const rcb_fft_ops kiss_ops = {"kissfft (float)", kiss_state_size, kiss_init, kiss_exec,
                                     kiss_release};

const rcb_fft_ops *rcb_fft_backend(void) { return &kiss_ops; }
#else
typedef int rcb_fft_kiss_not_built; /* ISO C: no empty translation unit */
#endif
