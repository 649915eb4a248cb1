/*
 * Order tracking: keyphasor -> revolutions (constant acceleration in each)
 * -> speed bins, and per bin either the joint least-squares fit of all
 * orders (order_fit.c, the default) or the exact DFT of each revolution
 * resampled to shaft angle with the scatter over revolutions (method and
 * why: rcb_signal.h). Everything in the caller's workspace: [object]
 * [twiddles][per-bin sums], nothing allocated.
 */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "signals/order_internal.h"

static size_t al16(size_t b) { return (b + 15) & ~(size_t)15; }

static int opts_ok(const rcb_order_opts *o, size_t nch) {
  size_t per = o && o->per_rev ? o->per_rev : 64;
  return o && nch >= 1 && nch <= 4096 && o->norders >= 1 && o->norders <= 8 &&
         per >= 4 * o->norders && per <= 65536 && isfinite(o->bin_width) && o->bin_width > 0.0 &&
         isfinite(o->speed_max) && o->speed_max > 0.0 && o->speed_max / o->bin_width < 1e6 &&
         isfinite(o->kp_angle) &&
         (o->method == RCB_ORDER_FIT || o->method == RCB_ORDER_REV_DFT);
}

/* [object][twiddles (DFT)][per-bin doubles][per-bin, channel and order sums] */
static size_t layout(const rcb_order_opts *o, size_t nch, size_t sz[4], size_t *nbins) {
  size_t per = o->per_rev ? o->per_rev : 64, nb = (size_t)ceil(o->speed_max / o->bin_width);
  size_t cells = nb * nch * o->norders;
  sz[0] = sizeof(struct rcb_order);
  if (o->method == RCB_ORDER_FIT) {
    sz[1] = 0;
    sz[3] = rcb_order_fit_bytes(o, nch, nb, &sz[2]);
    sz[2] += 2 * nb * sizeof(double);
  } else {
    sz[1] = o->norders * per * sizeof(rcb_complex);
    sz[2] = 4 * nb * sizeof(double) + cells * sizeof(double);
    sz[3] = 3 * cells * sizeof(rcb_complex);
  }
  *nbins = nb;
  return 16 + al16(sz[0]) + al16(sz[1]) + al16(sz[2]) + al16(sz[3]);
}

rcb_status rcb_order_workspace_size(const rcb_order_opts *o, size_t nch, size_t *bytes) {
  size_t sz[4], nb;
  if (!bytes || !opts_ok(o, nch)) return RCB_ERR_ARG;
  *bytes = layout(o, nch, sz, &nb);
  return RCB_OK;
}

rcb_status rcb_order_init(rcb_order **out, const rcb_order_opts *o, size_t nch, void *work,
                          size_t bytes) {
  size_t sz[4], nb, need, m, j, per;
  unsigned char *p;
  rcb_order *e;
  if (!out || !work) return RCB_ERR_ARG;
  *out = NULL;
  if (!opts_ok(o, nch)) return RCB_ERR_ARG;
  need = layout(o, nch, sz, &nb);
  if (bytes < need) return RCB_ERR_WORKSPACE;
  p = (unsigned char *)(((uintptr_t)work + 15) & ~(uintptr_t)15);
  memset(p, 0, need - 16);
  e = (rcb_order *)(void *)p;
  e->o = *o;
  if (!e->o.per_rev) e->o.per_rev = 64;
  if (e->o.min_revs < 2) e->o.min_revs = 2;
  per = e->o.per_rev;
  e->nch = nch;
  e->nbins = nb;
  p += al16(sz[0]);
  e->tw = (rcb_complex *)(void *)p;
  p += al16(sz[1]);
  e->cnt = (double *)(void *)p;
  e->wsum = e->cnt + nb;
  if (o->method == RCB_ORDER_FIT) {
    e->ng = 2 * o->norders + 1;
    e->ngg = e->ng * (e->ng + 1) / 2;
    e->mom = e->wsum + nb;
    p += al16(sz[2]);
    e->ysum = (double *)(void *)p;
    *out = e;
    return RCB_OK;
  }
  e->w0 = e->wsum + nb;
  e->u2sum = e->w0 + nb;
  e->d2sum = e->u2sum + nb;
  p += al16(sz[2]);
  e->q0 = (rcb_complex *)(void *)p;
  e->dsum = e->q0 + nb * nch * o->norders;
  e->dusum = e->dsum + nb * nch * o->norders;
  for (m = 1; m <= o->norders; m++)
    for (j = 0; j < per; j++) {
      double th = (double)m * (2.0 * RCB_PI * (double)j / (double)per + o->kp_angle);
      e->tw[(m - 1) * per + j] = CMPLX(cos(th), -sin(th));
    }
  *out = e;
  return RCB_OK;
}

const char *rcb_order_errmsg(const rcb_order *e) { return e ? e->errmsg : ""; }

/* Sample time (in samples, from pulse b) of angle th in [0, 2 pi) past pulse
 * b, on the quadratic phi(tau) = p tau + q tau^2 through the pulses a < b < c
 * (phi = -2 pi, 0, 2 pi): constant angular acceleration over two revolutions
 * (Fyfe & Munck 1997). The root is taken in its cancellation-free form. */
static double angle_time(double p, double q, double th) {
  return 2.0 * th / (p + sqrt(fmax(0.0, p * p + 4.0 * q * th)));
}

/* One revolution between pulse times b < c (in samples), a the pulse before. */
static void revolution(rcb_order *e, double rate, double a, double b, double c,
                       const double *const *chan) {
  size_t per = e->o.per_rev, ch, j, m, bin, at;
  int first;
  double u, ta = a - b, tc = c - b, det = ta * tc * (tc - ta), speed = 2.0 * RCB_PI * rate / tc;
  double p = -2.0 * RCB_PI * (tc * tc + ta * ta) / det, q = 2.0 * RCB_PI * (ta + tc) / det;
  if (!(speed < e->o.speed_max) || !(p > 0.0)) return;
  bin = (size_t)floor(speed / e->o.bin_width);
  if (bin >= e->nbins) return;
  if (e->o.method == RCB_ORDER_FIT) {
    e->cnt[bin] += 1.0;
    e->wsum[bin] += speed;
    e->nrevs++;
    rcb_order_fit_revolution(e, rate, b, c, p, q, bin, chan);
    return;
  }
  first = e->cnt[bin] == 0.0;
  if (first) e->w0[bin] = speed;
  u = speed - e->w0[bin];
  e->cnt[bin] += 1.0;
  e->wsum[bin] += speed;
  e->u2sum[bin] += u * u;
  for (ch = 0; ch < e->nch; ch++) {
    rcb_complex z[8] = {0};
    for (j = 0; j < per; j++) {
      double ts = b + angle_time(p, q, 2.0 * RCB_PI * (double)j / (double)per);
      double fl = floor(ts), fr = ts - fl;
      size_t i0 = (size_t)fl;
      double y = chan[ch][i0] + fr * (chan[ch][i0 + 1] - chan[ch][i0]);
      for (m = 0; m < e->o.norders; m++) z[m] += y * e->tw[m * per + j];
    }
    for (m = 0; m < e->o.norders; m++) {
      rcb_complex d, Q = z[m] * (2.0 / (double)per);
      at = (bin * e->nch + ch) * e->o.norders + m;
      if (first) e->q0[at] = Q;
      d = Q - e->q0[at];
      e->dsum[at] += d;
      e->dusum[at] += d * u;
      e->d2sum[at] += creal(d) * creal(d) + cimag(d) * cimag(d);
    }
  }
  e->nrevs++;
}

rcb_status rcb_order_add(rcb_order *e, double rate, size_t n, const double *kp,
                         const double *const *chan) {
  double trig, prev = -1.0, prev2 = -1.0, lo, hi;
  size_t i, c, pulses = 0;
  if (!e || !kp || !chan || n < 2 || !isfinite(rate) || !(rate > 0.0)) return RCB_ERR_ARG;
  for (c = 0; c < e->nch; c++)
    if (!chan[c]) return rcb_set_error(e->errmsg, RCB_ERR_ARG, "order: channel %zu is NULL", c);
  if (!(e->rate > 0.0) || rate < e->rate) e->rate = rate;
  trig = e->o.trigger;
  if (isnan(trig)) {
    for (lo = hi = kp[0], i = 1; i < n; i++) {
      lo = fmin(lo, kp[i]);
      hi = fmax(hi, kp[i]);
    }
    trig = 0.5 * (lo + hi);
  }
  for (i = 1; i < n; i++)
    if (e->o.kp_falling ? (kp[i - 1] > trig && kp[i] <= trig)
                        : (kp[i - 1] < trig && kp[i] >= trig)) {
      double t = (double)(i - 1) + (trig - kp[i - 1]) / (kp[i] - kp[i - 1]);
      if (prev2 >= 0.0) revolution(e, rate, prev2, prev, t, chan);
      prev2 = prev;
      prev = t;
      pulses++;
    }
  if (pulses < 3)
    return rcb_set_error(e->errmsg, RCB_ERR_ARG, "order: %zu keyphasor pulse%s (%s "
                         "crossings of %g) in %zu samples; need three or more: check the "
                         "keyphasor channel, the trigger level and the edge", pulses,
                         pulses == 1 ? "" : "s", e->o.kp_falling ? "downward" : "upward", trig, n);
  return RCB_OK;
}

size_t rcb_order_revolutions(const rcb_order *e) { return e ? e->nrevs : 0; }
size_t rcb_order_bin_count(const rcb_order *e) { return e ? e->nbins : 0; }

/* A bin's phasor is the mean of its revolutions' (the line's value at the
 * mean speed, which the bin reports); its sd comes from the residual of the
 * line Q_r = a + b (w_r - w_mean), sum |res|^2 = S_dd - |S_du|^2 / S_uu (sums
 * about the means), over 2 (n - 2) degrees of freedom (Re and Im), divided by
 * n for the mean. Two revolutions fit any line: then the scatter about the
 * mean (n - 1 degrees of freedom) as before. */
rcb_status rcb_order_result(const rcb_order *e, size_t bin, size_t ch, size_t m,
                            double *speed, rcb_complex *Q, double *sd, size_t *nrev) {
  double n, ubar, suu, sdd, res;
  size_t at;
  rcb_complex dbar, sdu;
  if (!e || bin >= e->nbins || ch >= e->nch || m < 1 || m > e->o.norders) return RCB_ERR_ARG;
  n = e->cnt[bin];
  if (nrev) *nrev = (size_t)n;
  if (e->o.method == RCB_ORDER_FIT) {
    rcb_order_fit_result(e, bin, ch, m, speed, Q, sd);
    return RCB_OK;
  }
  at = (bin * e->nch + ch) * e->o.norders + m - 1;
  dbar = n > 0.0 ? e->dsum[at] / n : 0.0;
  ubar = n > 0.0 ? e->wsum[bin] / n - e->w0[bin] : 0.0;
  suu = e->u2sum[bin] - n * ubar * ubar;
  sdd = e->d2sum[at] - n * (creal(dbar) * creal(dbar) + cimag(dbar) * cimag(dbar));
  sdu = e->dusum[at] - ubar * e->dsum[at];
  res = n > 2.0 && suu > 0.0 ? sdd - (creal(sdu) * creal(sdu) + cimag(sdu) * cimag(sdu)) / suu
                             : sdd;
  if (speed) *speed = n > 0.0 ? e->wsum[bin] / n : (double)NAN;
  if (Q) *Q = n > 0.0 ? e->q0[at] + dbar : 0.0;
  if (sd)
    *sd = n > 2.0 && suu > 0.0 ? sqrt(fmax(0.0, res) / (2.0 * n * (n - 2.0)))
          : n > 1.0           ? sqrt(fmax(0.0, res) / (2.0 * n * (n - 1.0)))
                              : (double)NAN;
  return RCB_OK;
}
