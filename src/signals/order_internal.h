/*
 * Internals of order tracking (src/signals/order*.c): the tracker object,
 * shared by the keyphasor/revolution code (order.c) and the joint
 * least-squares fit (order_fit.c). Not installed.
 */
#ifndef RCB_ORDER_INTERNAL_H
#define RCB_ORDER_INTERNAL_H

#include "signals/signals_internal.h"

/* Envelope degree of the fit: each order's phasor is a quadratic in speed
 * across a bin (so its value at the bin's mean speed carries no curvature
 * bias); its moments need powers of speed up to twice that. */
#define RCB_ORDER_FIT_DEG 2
#define RCB_ORDER_FIT_POW (2 * RCB_ORDER_FIT_DEG + 1)

struct rcb_order {
  char errmsg[RCB_ERRMSG_MAX];
  rcb_order_opts o;
  size_t nch, nbins, nrevs;
  double rate;        /* lowest sample rate given to rcb_order_add, samples/s */
  double *cnt, *wsum; /* nbins: revolutions, sum of their speeds (rad/s) */
  /* RCB_ORDER_REV_DFT: per bin, the sums of a least-squares line
   * Q_r = a + b (w_r - w_mean) over its revolutions r, taken about the bin's
   * first revolution (w0, Q0) so that the residual is not the small
   * difference of two large sums. */
  rcb_complex *tw;    /* norders * per_rev: e^{-i m (2 pi j / N + kp_angle)} */
  double *w0, *u2sum; /* nbins: first speed, sum (w - w0)^2 */
  rcb_complex *q0;    /* (bin * nch + ch) * norders + m - 1: the first Q */
  rcb_complex *dsum;  /* same layout: sum (Q - Q0) */
  rcb_complex *dusum; /* same layout: sum (Q - Q0) (w - w0) */
  double *d2sum;      /* same layout: sum |Q - Q0|^2 */
  /* RCB_ORDER_FIT: g = (1, cos th, sin th, ..., cos M th, sin M th), T = 2M + 1
   * functions of the shaft angle th, and u = (w - bin centre) / bin width
   * per sample. */
  size_t ng, ngg;     /* T, T (T + 1) / 2 */
  double *mom;        /* bin * POW * ngg: sum g_i g_j u^s, s = 0..2 DEG, i <= j packed */
  double *ysum;       /* (bin * nch + ch) * (T (DEG + 1) + 1): sum y g_i u^k, then sum y^2 */
};

/* Bytes of the fit's per-bin sums (order_fit.c). */
size_t rcb_order_fit_bytes(const rcb_order_opts *o, size_t nch, size_t nbins, size_t *mom_bytes);
/* Add the samples of one revolution, from pulse b to pulse c (in samples),
 * its angle phi(tau) = p tau + q tau^2 past b (rad), to bin @p bin. */
void rcb_order_fit_revolution(rcb_order *e, double rate, double b, double c, double p, double q,
                              size_t bin, const double *const *chan);
/* One bin's fitted phasor of order m at the bin's mean speed, and its sd. */
void rcb_order_fit_result(const rcb_order *e, size_t bin, size_t ch, size_t m, double *speed,
                          rcb_complex *Q, double *sd);

#endif /* RCB_ORDER_INTERNAL_H */
