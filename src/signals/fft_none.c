/*
 * No FFT backend built (RCB_WITH_FFTW and RCB_WITH_KISSFFT both OFF): the
 * estimator reports RCB_ERR_UNSUPPORTED. librcb does not carry an FFT of its
 * own: the house rule is to link a well-kept library for what one does.
 */
#include "rcb/rcb_config.h"

#if !RCB_WITH_FFTW && !RCB_WITH_KISSFFT
#include "signals/fft.h"

const rcb_fft_ops *rcb_fft_backend(void) { return NULL; }
#else
typedef int rcb_fft_none_not_built; /* ISO C: no empty translation unit */
#endif
