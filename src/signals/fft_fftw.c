/*
 * FFT backend on FFTW3 in double precision (RCB_WITH_FFTW). Why FFTW and not
 * Debian's kissfft: libkissfft-dev ships the float build only (~1e-7
 * relative), which cannot give FRFs that agree with SciPy to 1e-10; FFTW is
 * double, well kept and packaged everywhere. Its plan is allocated by FFTW
 * (outside the allocator hooks) at init, once; fftw_execute on that plan
 * allocates nothing. The planner is not thread-safe (see rcb_signal.h).
 */
#include "rcb/rcb_config.h"

#if RCB_WITH_FFTW
#include <fftw3.h>
#include <stdio.h>

#include "signals/fft.h"

typedef struct fftw_state {
  fftw_plan plan;
} fftw_state;

static size_t fftw_state_size(size_t n) {
  (void)n;
  return sizeof(fftw_state);
}

static int fftw_init(void *state, size_t n, double *in, rcb_complex *out, char *err) {
  fftw_state *st = state;
  if (n > (size_t)1 << 30) {
    snprintf(err, RCB_ERRMSG_MAX, "FFT length %zu too large for FFTW's int", n);
    return -1;
  }
  /* FFTW_ESTIMATE: no trial runs (deterministic, fast to create) */
  st->plan = fftw_plan_dft_r2c_1d((int)n, in, (fftw_complex *)out, FFTW_ESTIMATE);
  if (!st->plan) {
    snprintf(err, RCB_ERRMSG_MAX, "FFTW could not plan a real FFT of length %zu", n);
    return -1;
  }
  return 0;
}

static void fftw_exec(void *state) { fftw_execute(((fftw_state *)state)->plan); }

static void fftw_release(void *state) {
  fftw_state *st = state;
  if (st->plan) fftw_destroy_plan(st->plan);
  st->plan = NULL;
}

static const rcb_fft_ops fftw_ops = {"fftw3 (double)", fftw_state_size, fftw_init, fftw_exec,
                                     fftw_release};

const rcb_fft_ops *rcb_fft_backend(void) { return &fftw_ops; }
#else
typedef int rcb_fft_fftw_not_built; /* ISO C: no empty translation unit */
#endif
