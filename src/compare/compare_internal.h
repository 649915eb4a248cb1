/* Model-measurement comparison: the object and the helpers shared by
 * compare.c (metrics, bands) and compare_peaks.c (peak table). Not installed. */
#ifndef RCB_COMPARE_INTERNAL_H
#define RCB_COMPARE_INTERNAL_H

#include "core/rcb_internal.h"
#include "rcb/rcb_compare.h"

struct rcb_compare {
  rcb_allocator alloc;
  char errmsg[RCB_ERRMSG_MAX];
  size_t nbands_req;   /* requested bands */
  double prom_db;      /* peak prominence, dB */
  double tol;          /* relative frequency tolerance of the pairing */
  double *sd;          /* nsd known standard deviations (rcb_compare_set_sd), NULL: none */
  size_t nsd;
  /* results */
  int done;
  rcb_meas_type type;
  double speed;        /* FRF test speed rad/s, < 0 synchronous */
  size_t nch, npts, nbands, npeaks;
  double *grid;                /* npts, rad/s */
  rcb_complex *meas, *model;   /* nch * npts, channel-major */
  char *names;                 /* response and reference strings */
  const char **resp, **ref;    /* nch each, into names (ref NULL for unbalance) */
  rcb_frf_kind *kind;          /* nch */
  int *magonly;                /* nch: magnitudes only (no phase; issue #35 item 4) */
  double *err, *frac, *lrms, *prms; /* nch */
  double *floor, *chi2;        /* nch, NaN without sds */
  double *csac, *csf;          /* npts */
  size_t *band_first, *band_count; /* nbands */
  double *map;                 /* nch * nbands */
  rcb_compare_peak *peaks;     /* npeaks */
  rcb_compare_outlier *outl;   /* noutl (compare_outliers.c) */
  size_t noutl;
  rcb_compare_summary sum;
};

/* The model side during a run: channel -> FRF output/input slots. */
typedef struct rcb_cmp_eval {
  const rcb_model *m;
  rcb_frf *frf;
  size_t nout, nin;
  size_t *ch_out, *ch_in;
  rcb_complex *H; /* nout * max(nin, 1) */
} rcb_cmp_eval;

/* The error message of rcb_compare (core/rcb_internal.h, rcb_fail). */
#define rcb_cmp_fail(c, st, ...) rcb_fail((c), (st), __VA_ARGS__)

/* Model values of every channel at abscissa w (rad/s) into out[nch]. */
rcb_status rcb_cmp_model_at(rcb_compare *c, rcb_cmp_eval *ev, double w, rcb_complex *out);

/* Local modal fit of one resonance on n points (w rad/s, h complex, one
 * channel; wref: the peak's frequency, for scaling): natural frequency wn
 * (rad/s) and damping ratio zeta, both NaN when the fit fails
 * (compare_modal.c). */
rcb_status rcb_cmp_modal_fit(rcb_compare *c, const double *w, const rcb_complex *h, size_t n,
                             double wref, double *wn, double *zeta);

/* Local modal fit of nmodes (1 to 4) resonances sharing their poles over
 * nch channels of n points each (w rad/s; h channel-major, nch * n; wref
 * rad/s, for scaling): the stable underdamped poles found, at most nmodes,
 * as natural frequencies wn (rad/s, ascending) and damping ratios zeta;
 * *nfound = 0 when the fit fails or n < 3 nmodes + 2 (compare_modal.c). */
rcb_status rcb_cmp_modal_fit_multi(rcb_compare *c, const double *w, const rcb_complex *h,
                                   size_t nch, size_t n, double wref, size_t nmodes,
                                   double *wn, double *zeta, size_t *nfound);

/* Name the sensors and channels whose misfit stands out (compare_outliers.c). */
rcb_status rcb_cmp_outliers(rcb_compare *c);

/* Build the peak table (compare_peaks.c). */
rcb_status rcb_cmp_peaks(rcb_compare *c, rcb_cmp_eval *ev);

#endif /* RCB_COMPARE_INTERNAL_H */
