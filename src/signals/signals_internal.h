/*
 * Internals of the measurement front end (src/signals/): the estimator and
 * the signal container, shared by its files. Not installed.
 */
#ifndef RCB_SIGNALS_INTERNAL_H
#define RCB_SIGNALS_INTERNAL_H

#include "core/rcb_internal.h"
#include "rcb/rcb_signal.h"

struct rcb_fft_ops;

struct rcb_spectral {
  char errmsg[RCB_ERRMSG_MAX];
  rcb_spectral_opts o;
  const struct rcb_fft_ops *fft;
  size_t nb, nd;         /* lines, segments averaged */
  double wss;            /* sum of the output window squared */
  double ovl;            /* variance factor of overlapped segments, 1 + 2 sum_j rho_j^2 */
  double *win_in, *win_out; /* nseg each (the same array unless FORCE_EXP) */
  double *buf;           /* nseg: FFT input */
  rcb_complex *spec;     /* (p + 1) * nb: input spectra, then the output's */
  rcb_complex *gxx;      /* nb * p * p, column-major per line */
  rcb_complex *gxy;      /* nb * p * q: line k, input i, output o at (k q + o) p + i */
  double *gyy;           /* nb * q */
  rcb_complex *a, *b;    /* p * p, p: solve scratch */
  const double **seg;    /* p + q segment starts (add_record) */
  void *fft_state;
};

/* Density scale of line k for the averaged sums (spectral.c). */
double rcb_spectral_line_scale(const rcb_spectral *e, size_t k);

#define RCB_SIGNAL_NAME_MAX 64

/* Largest sample magnitude a reader takes, in the file's unit or SI: the
 * estimator sums squares of segment sums (nseg samples), which overflow
 * near 1e154; no sensor reads 1e100 of any unit. A value beyond it (a
 * corrupt field, 1e308) is refused with its place in the file instead of
 * surfacing as a NaN spectrum (issue #26 saw "value -nan-nani"). */
#define RCB_SIGNAL_MAX 1e100

typedef struct rcb_signal_ch {
  char name[RCB_SIGNAL_NAME_MAX];
  rcb_quantity q;
  double *v; /* n samples, SI */
} rcb_signal_ch;

/* A unit given by the caller for a channel whose file label is missing or
 * not known (rcb_signals_set_unit; UFF readers). */
typedef struct rcb_signal_unit {
  char name[RCB_SIGNAL_NAME_MAX];
  char unit[32];
} rcb_signal_unit;

struct rcb_signals {
  rcb_allocator alloc;
  char errmsg[RCB_ERRMSG_MAX];
  double rate; /* samples/s */
  size_t n;    /* samples per channel */
  rcb_signal_ch *ch;
  size_t nch, capch;
  size_t nrec;             /* records per channel joined end to end (0: one) */
  int allow_truncated;     /* rcb_signals_set_allow_truncated */
  int join_records;        /* rcb_signals_set_join_records */
  rcb_warning_t *warnings; /* of the last read */
  size_t nwarn, capwarn;
  rcb_signal_unit *units;  /* rcb_signals_set_unit */
  size_t nunits, capunits;
};

/* The error message of rcb_signals (core/rcb_internal.h; s may be NULL: no
 * message, st returned). */
#define rcb_signals_fail(s, st, ...) rcb_set_error((s) ? (s)->errmsg : NULL, (st), __VA_ARGS__)

/* Add a channel whose values are already allocated through s->alloc (taken over). */
rcb_status rcb_signals_take(rcb_signals *s, const char *name, rcb_quantity q, double *values);
/* Drop every channel (before reading, and after a failed read). */
void rcb_signals_empty(rcb_signals *s);
/* Start a read: no channels, no warnings. */
void rcb_signals_begin_read(rcb_signals *s);
/* Record a warning of the current read (RCB_ERR_NOMEM if it cannot be kept). */
rcb_status rcb_signals_warn(rcb_signals *s, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;
/* The caller's unit for channel @p name (rcb_signals_set_unit), or NULL. */
const char *rcb_signals_unit_override(const rcb_signals *s, const char *name);
/* Whole file into memory through the set's allocator. */
rcb_status rcb_signals_slurp(rcb_signals *s, const char *path, char **buf, size_t *len);

#endif /* RCB_SIGNALS_INTERNAL_H */
