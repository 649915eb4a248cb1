/*
 * Order tracking by a joint least-squares fit (issue #25): the samples of a
 * speed bin's revolutions, at their shaft angles th (from the keyphasor,
 * constant acceleration per revolution), are fitted with
 *   y = sum_{m=0..M} Re(Q_m(u) e^{i m th}),  Q_m(u) = sum_{k=0..DEG} c_mk u^k,
 * u the sample's speed about the bin's centre in bin widths. All orders are
 * fitted together and each may change with speed within the bin, so a 1X
 * that changes within a revolution near a resonance is modelled, not seen at
 * 2X. The normal equations are accumulated per bin as moments of the angle
 * functions (nothing stored per sample) and solved when a result is read.
 */
#include <lapacke.h>
#include <math.h>
#include <string.h>

#include "signals/order_internal.h"

enum { MAXG = 2 * 8 + 1, MAXP = MAXG * (RCB_ORDER_FIT_DEG + 1) };

size_t rcb_order_fit_bytes(const rcb_order_opts *o, size_t nch, size_t nbins,
                           size_t *mom_bytes) {
  size_t ng = 2 * o->norders + 1, ngg = ng * (ng + 1) / 2;
  *mom_bytes = nbins * RCB_ORDER_FIT_POW * ngg * sizeof(double);
  return nbins * nch * (ng * (RCB_ORDER_FIT_DEG + 1) + 1) * sizeof(double);
}

void rcb_order_fit_revolution(rcb_order *e, double rate, double b, double c, double p, double q,
                              size_t bin, const double *const *chan) {
  size_t ng = e->ng, ngg = e->ngg, ny = ng * (RCB_ORDER_FIT_DEG + 1) + 1, i, j, k, s, ch, at;
  double centre = ((double)bin + 0.5) * e->o.bin_width, g[MAXG], gg[MAXG * (MAXG + 1) / 2];
  double *mom = e->mom + bin * RCB_ORDER_FIT_POW * ngg;
  for (i = (size_t)ceil(b); (double)i < c; i++) {
    double tau = (double)i - b, th = p * tau + q * tau * tau + e->o.kp_angle;
    double u = ((p + 2.0 * q * tau) * rate - centre) / e->o.bin_width, up[RCB_ORDER_FIT_POW];
    rcb_complex z1 = CMPLX(cos(th), sin(th)), z = z1;
    g[0] = 1.0;
    for (k = 1; k < ng; k += 2, z *= z1) g[k] = creal(z), g[k + 1] = cimag(z);
    for (up[0] = 1.0, s = 1; s < RCB_ORDER_FIT_POW; s++) up[s] = up[s - 1] * u;
    for (at = 0, j = 0; j < ng; j++)
      for (k = 0; k <= j; k++) gg[at++] = g[j] * g[k];
    for (s = 0; s < RCB_ORDER_FIT_POW; s++)
      for (at = 0; at < ngg; at++) mom[s * ngg + at] += gg[at] * up[s];
    for (ch = 0; ch < e->nch; ch++) {
      double y = chan[ch][i], *ys = e->ysum + (bin * e->nch + ch) * ny;
      for (s = 0; s <= RCB_ORDER_FIT_DEG; s++)
        for (k = 0; k < ng; k++) ys[s * ng + k] += y * g[k] * up[s];
      ys[ny - 1] += y * y;
    }
  }
}

/* The normal matrix of the first nf angle functions (orders 0..(nf - 1) / 2)
 * at envelope degree deg, parameter r = k nf + i for g_i u^k, scaled to a
 * unit diagonal, and its Cholesky factor in a (column-major, np x np); 0 if
 * it is well conditioned (pivots of the scaled matrix above 1e-10: a bin at
 * one steady speed has no spread in u, and then the lower degrees are fitted). */
static int normal(const double *mom, size_t nf, size_t ngg, size_t deg, double *a, double *d) {
  size_t np = nf * (deg + 1), r, c;
  for (r = 0; r < np; r++)
    for (c = 0; c < np; c++) {
      size_t i = r % nf, j = c % nf, lo = i < j ? i : j, hi = i < j ? j : i;
      a[c * np + r] = mom[(r / nf + c / nf) * ngg + hi * (hi + 1) / 2 + lo];
    }
  for (r = 0; r < np; r++) d[r] = a[r * np + r] > 0.0 ? 1.0 / sqrt(a[r * np + r]) : 0.0;
  for (r = 0; r < np; r++)
    for (c = 0; c < np; c++) a[c * np + r] *= d[r] * d[c];
  if (LAPACKE_dpotrf_work(LAPACK_COL_MAJOR, 'L', (lapack_int)np, a, (lapack_int)np)) return -1;
  for (r = 0; r < np; r++)
    if (!(a[r * np + r] * a[r * np + r] > 1e-10)) return -1;
  return 0;
}

/* x' A^-1 x for A = D^-1 As D^-1, As factored in a (x overwritten). */
static double quad(const double *a, const double *d, size_t np, double *x) {
  double z[MAXP], s = 0.0;
  size_t r;
  for (r = 0; r < np; r++) z[r] = x[r] *= d[r];
  LAPACKE_dpotrs_work(LAPACK_COL_MAJOR, 'L', (lapack_int)np, 1, a, (lapack_int)np, z,
                      (lapack_int)np);
  for (r = 0; r < np; r++) s += x[r] * z[r];
  return s;
}

/* Orders fitted in a bin: those below 0.45 x the sample rate at the bin's
 * top speed (an order above the Nyquist frequency aliases onto a lower one
 * and makes the normal matrix singular). */
static size_t orders_resolved(const rcb_order *e, size_t bin) {
  double top = ((double)bin + 1.5) * e->o.bin_width / (2.0 * RCB_PI); /* rev/s */
  double mmax = 0.45 * e->rate / top;
  return mmax >= (double)e->o.norders ? e->o.norders : (size_t)mmax;
}

void rcb_order_fit_result(const rcb_order *e, size_t bin, size_t ch, size_t m, double *speed,
                          rcb_complex *Q, double *sd) {
  size_t ng = e->ng, ngg = e->ngg, ny = ng * (RCB_ORDER_FIT_DEG + 1) + 1, deg, np = 0, r, k;
  size_t nf = 2 * orders_resolved(e, bin) + 1;
  const double *mom = e->mom + bin * RCB_ORDER_FIT_POW * ngg;
  const double *ys = e->ysum + (bin * e->nch + ch) * ny;
  double a[MAXP * MAXP], d[MAXP], beta[MAXP], x[MAXP], n = mom[0], ubar, rss, var = 0.0;
  int ok = 0;
  ubar = n > 0.0 ? mom[ngg] / n : 0.0;
  if (speed) *speed = n > 0.0 ? ((double)bin + 0.5 + ubar) * e->o.bin_width : (double)NAN;
  for (deg = RCB_ORDER_FIT_DEG + 1; !ok && m < (nf + 1) / 2 && deg-- > 0;) {
    np = nf * (deg + 1);
    ok = n > (double)np && normal(mom, nf, ngg, deg, a, d) == 0;
  }
  if (!ok) {
    if (Q) *Q = 0.0;
    if (sd) *sd = (double)NAN;
    return;
  }
  for (r = 0; r < np; r++) beta[r] = ys[r / nf * ng + r % nf] * d[r];
  LAPACKE_dpotrs_work(LAPACK_COL_MAJOR, 'L', (lapack_int)np, 1, a, (lapack_int)np, beta,
                      (lapack_int)np);
  for (rss = ys[ny - 1], r = 0; r < np; r++) {
    beta[r] *= d[r];
    rss -= beta[r] * ys[r / nf * ng + r % nf];
  }
  if (Q) {
    rcb_complex v = 0.0;
    double uk = 1.0;
    /* y = Re(Q e^{i m th}) = Re Q cos(m th) - Im Q sin(m th) */
    for (k = 0; k * nf < np; k++) {
      v += uk * CMPLX(beta[k * nf + 2 * m - 1], -beta[k * nf + 2 * m]);
      uk *= ubar;
    }
    *Q = v;
  }
  if (sd) {
    size_t part;
    for (part = 0; part < 2; part++) { /* Re Q, then Im Q */
      double uk = 1.0;
      memset(x, 0, np * sizeof *x);
      for (k = 0; k * nf < np; k++) {
        x[k * nf + 2 * m - 1 + part] = uk;
        uk *= ubar;
      }
      var += quad(a, d, np, x);
    }
    *sd = sqrt(fmax(0.0, rss) / (n - (double)np) * var / 2.0);
  }
}
