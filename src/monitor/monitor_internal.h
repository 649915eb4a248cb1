/*
 * The monitor object (rcb_monitor.h), private to monitor/: commissioning in
 * monitor_create.c, the allocation-free update in monitor.c, the chi-square
 * distribution in chi2.c. monitor/ comes after diagnose/ in the data flow
 * and uses the public API and the documented internal interfaces only
 * (identify/identify.h, diagnose/diagnose.h, core).
 *
 * Residual layout: point p = c * npts + i of the set-up gives the two real
 * residuals 2 p (radial: along the commissioning value e_0) and 2 p + 1
 * (tangential), each divided by its standard deviation ("whitened").
 */
#ifndef RCB_MONITOR_INTERNAL_H
#define RCB_MONITOR_INTERNAL_H

#include "core/rcb_internal.h"
#include "rcb/rcb_monitor.h"

#define RCB_MONITOR_NAME 128

/* A candidate in the rank space (dimension k): its estimate rows and the
 * orthonormal directions it adds beyond the tracked parameters. */
typedef struct mon_cand {
  rcb_effect effect;
  char place[RCB_MONITOR_NAME];
  char desc[2 * RCB_MONITOR_NAME];
  char params[RCB_MONITOR_MAXP * RCB_MONITOR_NAME];
  size_t np;       /* its parameters */
  size_t dof;      /* directions beyond the tracked ones; 0: not scored */
  double *est;     /* np x k row-major: its parameters' step = est y */
  double *dir;     /* dof x k row-major: orthonormal, score = ||dir y||^2 */
  double se[RCB_MONITOR_MAXP]; /* standard errors, parameter units */
  double score_now;  /* this update's score */
} mon_cand;

struct rcb_monitor {
  rcb_allocator user;  /* the caller's hooks */
  rcb_allocator alloc; /* the same, counting live bytes into held */
  size_t held;
  char errmsg[RCB_ERRMSG_MAX];

  /* set-up */
  size_t nch, npts, npt, n; /* channels, points per channel, npt = nch * npts, n = 2 npt */
  rcb_complex *e0;     /* commissioning values, npt */
  double *h0abs;       /* |baseline model|, npt */
  rcb_complex *u;      /* unit direction of e_0 per point (radial frame) */
  double *winv;        /* 2 per point: 1 / sd of the radial, tangential residual */
  double *sd_new_rad;  /* radial sd of one new measurement per point (floor %) */
  double e0norm2;      /* sum |e_0|^2 */

  /* settings */
  double alpha, cusum_k, cusum_h, threshold;
  size_t top, relin;

  /* tracked parameters */
  size_t nt;
  char tname[RCB_MONITOR_MAX_TRACKED][RCB_MONITOR_NAME];
  double tlo[RCB_MONITOR_MAX_TRACKED], thi[RCB_MONITOR_MAX_TRACKED];
  double t0[RCB_MONITOR_MAX_TRACKED];   /* baseline values */
  double tse[RCB_MONITOR_MAX_TRACKED];  /* standard errors */
  double *test;        /* nt x k row-major: tracked step = test y */
  double *tdir;        /* nt x k row-major: orthonormal basis of the tracked columns */
  double cus_up[RCB_MONITOR_MAX_TRACKED], cus_dn[RCB_MONITOR_MAX_TRACKED];

  /* rank space */
  size_t k;            /* rank of all columns */
  double *Q;           /* n x k column-major, orthonormal */
  mon_cand *cand;
  size_t ncand;

  /* re-linearisation: the baseline model (owned copy) and a fit of the
   * tracked parameters on the commissioning values, its residuals at the
   * baseline (model minus e_0, the fit's Re/Im layout) */
  rcb_model *model;
  rcb_meas *setup;
  rcb_fit *fit;
  double *rbase;       /* n */

  /* update workspace */
  double *r, *rm;      /* n each */
  double *y, *ym;      /* k each */
  double *pscore;      /* ncand */
  size_t *order;       /* ncand */
  size_t updates;
};

#define rcb_mon_fail(mon, st, ...) rcb_fail((mon), (st), __VA_ARGS__)

/* monitor_create.c's pieces used by monitor.c */
void rcb_mon_whiten(const rcb_monitor *mon, const rcb_complex *d, double *r);

#endif
