/*
 * FFT backends of the spectral estimator: a small table of function pointers,
 * one file per backend (fft_fftw.c: FFTW3 double; fft_kiss.c: kissfft float,
 * the embedded fallback). Not installed.
 *
 * A backend transforms n real samples (n >= 8, even for kissfft) into the
 * n/2 + 1 lines of the one-sided spectrum X_k = sum_t x_t e^{-2 pi i k t / n}
 * (no scaling), from and to the buffers given at init.
 */
#ifndef RCB_SIGNALS_FFT_H
#define RCB_SIGNALS_FFT_H

#include <stddef.h>

#include "core/rcb_internal.h"

typedef struct rcb_fft_ops {
  const char *name;
  /* bytes of backend state for length n (in the estimator's workspace) */
  size_t (*state_size)(size_t n);
  /* plan on these buffers: 0, or -1 (message in err, RCB_ERRMSG_MAX) */
  int (*init)(void *state, size_t n, double *in, rcb_complex *out, char *err);
  void (*exec)(void *state);
  void (*release)(void *state);
} rcb_fft_ops;

/* The backend compiled in (FFTW if built with it, else kissfft), or NULL. */
const rcb_fft_ops *rcb_fft_backend(void);

#endif /* RCB_SIGNALS_FFT_H */
