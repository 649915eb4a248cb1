/*
 * FRFs from the averaged spectra (Bendat & Piersol, Random Data, 4th ed.,
 * ch. 9): H1 = Gxx^-1 Gxy (least squares, noise on the outputs), H2 =
 * Gyy / Gyx and Hv (total least squares, the eigenvector of the 2x2
 * spectral matrix [Gxx Gxy; Gyx Gyy]) for one input; ordinary (one input)
 * or multiple coherence; per-line standard deviation of Re h and Im h,
 * sigma^2 = (1 - coh) Gyy [Gxx^-1]_jj / (2 (nd - p)): the residual power
 * (1 - coh) Gyy of the least squares over nd averages with p inputs has
 * the expectation sigma_n^2 (nd - p) / nd, so this is unbiased, and
 * |h - H|^2 / (2 sigma^2) is then F(2, 2 (nd - p)) distributed (Goodman
 * 1963); B&P's large-sample eps[|H|] = sqrt(1 - coh) / (sqrt(coh) sqrt(2 nd))
 * divides by nd and under-states the scatter at a few averages (by 1.27 in
 * variance at nd = 4.7). nd is the number of segments divided by the
 * overlap factor (spectral.c), the equivalent number of independent
 * averages; NaN for nd <= p (no scatter to estimate from).
 * Several inputs: Gxx is Hermitian positive definite unless two inputs are
 * fully coherent, so it is factored by LAPACK zpotrf (zpotrs, zpotri).
 */
#include <lapacke.h>
#include <math.h>
#include <string.h>

#include "signals/signals_internal.h"

/* One input, line k: h, coherence, sd from the raw sums. */
static void frf_siso(rcb_estimator est, double gxx, rcb_complex gxy, double gyy, double nd,
                     rcb_complex *h, double *coh, double *sd) {
  double g2 = creal(gxy) * creal(gxy) + cimag(gxy) * cimag(gxy);
  double c = g2 / (gxx * gyy);
  if (!(gxx > 0.0) || !(gyy > 0.0)) {
    *h = CMPLX((double)NAN, (double)NAN);
    *coh = (double)NAN;
    *sd = (double)NAN;
    return;
  }
  if (est == RCB_EST_H1) {
    *h = gxy / gxx;
  } else if (est == RCB_EST_H2) {
    *h = gyy / conj(gxy);
  } else {
    /* The eigenvector's closed form (d + r) / (2 conj(Gxy)), r = sqrt(d^2 +
     * 4 |Gxy|^2), d = Gyy - Gxx, cancels when Gxx >> Gyy (force in N, response
     * in m: d + r ~ 2 |Gxy|^2 / |d| is the difference of two numbers 1e12 times
     * larger; issue #25 saw Hv 2.5 off and exactly 0 at some lines). Its
     * conjugate form 2 Gxy / (r - d) adds two positive terms there; each form is
     * used where it adds. hypot keeps r finite for any scale of the channels. */
    double d = gyy - gxx, r = hypot(d, 2.0 * sqrt(g2));
    *h = d >= 0.0 ? (d + r) / (2.0 * conj(gxy)) : 2.0 * gxy / (r - d);
  }
  if (c > 1.0) c = 1.0; /* rounding when the pair is exactly linear */
  *coh = c;
  *sd = nd > 1.0 ? sqrt((1.0 - c) * gyy / (gxx * 2.0 * (nd - 1.0))) : (double)NAN;
}

/* Several inputs, line k: solve Gxx h = gxy (Cholesky); -1 if Gxx is singular. */
static int frf_miso(rcb_spectral *e, size_t k, size_t out, size_t in, rcb_complex *h,
                    double *coh, double *sd) {
  size_t p = e->o.ninputs, q = e->o.noutputs, j;
  lapack_int n = (lapack_int)p, info;
  double gyy = e->gyy[k * q + out], num = 0.0, nd;
  const rcb_complex *g = e->gxy + (k * q + out) * p;
  memcpy(e->a, e->gxx + k * p * p, p * p * sizeof *e->a);
  memcpy(e->b, g, p * sizeof *e->b);
  info = LAPACKE_zpotrf_work(LAPACK_COL_MAJOR, 'L', n, (lapack_complex_double *)e->a, n);
  if (info) return -1;
  info = LAPACKE_zpotrs_work(LAPACK_COL_MAJOR, 'L', n, 1, (const lapack_complex_double *)e->a,
                             n, (lapack_complex_double *)e->b, n);
  if (info) return -1;
  *h = e->b[in];
  for (j = 0; j < p; j++) num += creal(conj(g[j]) * e->b[j]);
  *coh = gyy > 0.0 ? fmin(1.0, num / gyy) : (double)NAN;
  info = LAPACKE_zpotri_work(LAPACK_COL_MAJOR, 'L', n, (lapack_complex_double *)e->a, n);
  if (info) return -1;
  nd = (double)e->nd / e->ovl - (double)p;
  *sd = nd > 0.0 ? sqrt(fmax(0.0, 1.0 - *coh) * gyy * creal(e->a[in * p + in]) / (2.0 * nd))
                 : (double)NAN;
  return 0;
}

rcb_status rcb_spectral_frf(rcb_spectral *e, rcb_estimator est, size_t out, size_t in,
                            rcb_complex *h, double *coh, double *sd) {
  size_t p, q, k, first_bad = 0, nbad = 0;
  if (!e) return RCB_ERR_ARG;
  p = e->o.ninputs;
  q = e->o.noutputs;
  if (in >= p || out >= q || (unsigned)est > RCB_EST_HV)
    return rcb_set_error(e->errmsg, RCB_ERR_ARG, "frf: input %zu of %zu, output %zu of %zu, "
                         "estimator %d: out of range", in, p, out, q, (int)est);
  if (est != RCB_EST_H1 && p != 1)
    return rcb_set_error(e->errmsg, RCB_ERR_ARG, "frf: H2 and Hv take one input (%zu given); "
                         "use H1 with several inputs", p);
  if (e->nd == 0)
    return rcb_set_error(e->errmsg, RCB_ERR_STATE, "frf: no segment averaged yet");
  for (k = 0; k < e->nb; k++) {
    rcb_complex hk;
    double ck, sk;
    if (p == 1) {
      frf_siso(est, creal(e->gxx[k]), e->gxy[k * q + out], e->gyy[k * q + out],
               (double)e->nd / e->ovl, &hk, &ck, &sk);
    } else if (frf_miso(e, k, out, in, &hk, &ck, &sk)) {
      hk = CMPLX((double)NAN, (double)NAN);
      ck = sk = (double)NAN;
      if (k > 0 && nbad++ == 0) first_bad = k;
    }
    if (h) h[k] = hk;
    if (coh) coh[k] = ck;
    if (sd) sd[k] = sk;
  }
  if (nbad)
    return rcb_set_error(e->errmsg, RCB_ERR_SINGULAR, "frf: the input spectral matrix is "
                         "singular at %zu lines, first %.6g Hz: two inputs are fully coherent "
                         "there (excite them independently)", nbad,
                         (double)first_bad * e->o.rate / (double)e->o.nseg);
  return RCB_OK;
}
