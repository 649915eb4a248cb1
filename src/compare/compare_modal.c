/*
 * Local modal fit of one measured resonance (the peak table's damping):
 * a single-DOF rational fraction with a residual,
 *   H(w) = (b0 + b1 s + b2 s^2) / (s^2 + 2 zeta wn s + wn^2),  s = i w,
 * fitted on the complex FRF over the points around the peak, by linear
 * least squares on H D(s) - N(s) = 0 (Levy) weighted by 1/(|H| |D'|), D' the
 * previous pass's denominator (Sanathanan-Koerner iterations): at
 * convergence this is the relative output error |H - N/D| / |H|, which suits
 * eq. 19's proportional noise. The quadratic numerator
 * holds a single mode in any of the three kinds (receptance A/D, mobility
 * s A/D, inertance s^2 A/D = A - A (2 zeta wn s + wn^2)/D) plus a constant
 * residual of the other modes. Exact on a noise-free single-DOF FRF.
 * Frequencies are scaled by the peak's before the solve.
 */
#include <math.h>
#include <string.h>

#include "compare/compare_internal.h"

#define NU 8 /* unknowns: a0 = wn^2, a1 = 2 zeta wn, Re/Im of b0, b1, b2 */

/* Least squares min ||A x - y|| by Householder QR, A (m x NU) column-major
 * with leading dimension m, destroyed; x = NU values. 0 on success. */
static int qr_solve(double *A, double *y, size_t m, double *x) {
  size_t j, i, k;
  for (j = 0; j < NU; j++) {
    double norm = 0.0, alpha, vnorm2, *a = A + m * j;
    for (i = j; i < m; i++) norm += a[i] * a[i];
    norm = sqrt(norm);
    if (!(norm > 0.0)) return 1;
    alpha = a[j] > 0 ? -norm : norm;
    a[j] -= alpha; /* v = a - alpha e_j, stored in place */
    vnorm2 = 0.0;
    for (i = j; i < m; i++) vnorm2 += a[i] * a[i];
    for (k = j + 1; k < NU + 1; k++) { /* apply H = I - 2 v v^T / v^T v to the rest and y */
      double *b = k < NU ? A + m * k : y, dot = 0.0;
      for (i = j; i < m; i++) dot += a[i] * b[i];
      dot *= 2.0 / vnorm2;
      for (i = j; i < m; i++) b[i] -= dot * a[i];
    }
    a[j] = alpha; /* R's diagonal */
  }
  for (j = NU; j-- > 0;) { /* back substitution with R (upper part of A) */
    double s = y[j];
    for (k = j + 1; k < NU; k++) s -= A[j + m * k] * x[k];
    x[j] = s / A[j + m * j];
    if (!isfinite(x[j])) return 1;
  }
  return 0;
}

/* One weighted Levy pass over the n points: rows 2i (real) and 2i + 1
 * (imaginary) of H (a0 + a1 s) - N(s) = -H s^2. */
static int levy_pass(const double *nu, const rcb_complex *h, const double *wt, size_t n,
                     double *A, double *y, double *x) {
  size_t i, m = 2 * n, u;
  for (i = 0; i < n; i++) {
    double complex s = CMPLX(0.0, nu[i]), g[NU], rhs = -h[i] * s * s;
    g[0] = h[i];
    g[1] = h[i] * s;
    g[2] = -1.0, g[3] = CMPLX(0.0, -1.0);
    g[4] = -s, g[5] = -CMPLX(0.0, 1.0) * s;
    g[6] = -s * s, g[7] = -CMPLX(0.0, 1.0) * s * s;
    for (u = 0; u < NU; u++) {
      A[2 * i + m * u] = wt[i] * creal(g[u]);
      A[2 * i + 1 + m * u] = wt[i] * cimag(g[u]);
    }
    y[2 * i] = wt[i] * creal(rhs);
    y[2 * i + 1] = wt[i] * cimag(rhs);
  }
  return qr_solve(A, y, m, x);
}

rcb_status rcb_cmp_modal_fit(rcb_compare *c, const double *w, const rcb_complex *h, size_t n,
                             double wref, double *wn, double *zeta) {
  size_t m = 2 * n, i, pass;
  double *A = rcb_alloc(&c->alloc, (m * NU + m + 2 * n) * sizeof *A), x[NU];
  double *y, *nu, *wt;
  rcb_status st = RCB_OK;
  *wn = *zeta = (double)NAN;
  if (!A) return rcb_cmp_fail(c, RCB_ERR_NOMEM, "out of memory (modal fit)");
  y = A + m * NU, nu = y + m, wt = nu + n;
  for (i = 0; i < n; i++) nu[i] = w[i] / wref, wt[i] = cabs(h[i]) > 0 ? 1.0 / cabs(h[i]) : 0.0;
  for (pass = 0; pass < 8 && n >= NU / 2 + 1; pass++) {
    if (levy_pass(nu, h, wt, n, A, y, x)) break;
    if (!(x[0] > 0.0 && x[1] > 0.0)) break; /* not a damped resonance */
    *wn = wref * sqrt(x[0]);
    *zeta = x[1] / (2.0 * sqrt(x[0]));
    /* Sanathanan-Koerner: divide by the last pass's |D| (output error) */
    for (i = 0; i < n; i++) {
      double complex s = CMPLX(0.0, nu[i]);
      double d = cabs(x[0] + x[1] * s + s * s), a = cabs(h[i]);
      wt[i] = d > 0 && a > 0 ? 1.0 / (d * a) : 0.0;
    }
  }
  rcb_free(&c->alloc, A);
  return st;
}
