/*
 * The chi-square distribution and the CUSUM run length the monitor states
 * its thresholds with. LAPACK, SUNDIALS and the C library have no
 * incomplete gamma function, so it is written here from its classical
 * series and continued fraction (Abramowitz & Stegun 6.5.29 and 6.5.31;
 * the continued fraction evaluated by the modified Lentz method), and the
 * quantile by Newton's method on it from the Wilson-Hilferty start,
 * bracketed so that a step never leaves [lo, hi].
 */
#include <float.h>
#include <math.h>

#include "monitor/monitor_internal.h"

#define RCB_GAMMA_EPS 1e-15
#define RCB_GAMMA_ITER 1000

/* Lower regularised P(a, x) by its series, x < a + 1. */
static double gamma_p_series(double a, double x) {
  double sum = 1.0 / a, term = sum, ap = a;
  int n;
  for (n = 0; n < RCB_GAMMA_ITER; n++) {
    ap += 1.0;
    term *= x / ap;
    sum += term;
    if (fabs(term) < fabs(sum) * RCB_GAMMA_EPS) break;
  }
  return sum * exp(-x + a * log(x) - lgamma(a));
}

/* log Q(a, x) by the continued fraction, x >= a + 1: finite where Q
 * itself underflows (the ranking of strong effects). */
static double gamma_logq_cf(double a, double x);

/* Upper regularised Q(a, x) by its continued fraction, x >= a + 1. */
static double gamma_q_cf(double a, double x) { return exp(gamma_logq_cf(a, x)); }

static double gamma_logq_cf(double a, double x) {
  double b = x + 1.0 - a, c = 1.0 / DBL_MIN, d = 1.0 / b, h = d;
  int i;
  for (i = 1; i < RCB_GAMMA_ITER; i++) {
    double an = -i * (i - a), del;
    b += 2.0;
    d = an * d + b;
    if (fabs(d) < DBL_MIN) d = DBL_MIN;
    c = b + an / c;
    if (fabs(c) < DBL_MIN) c = DBL_MIN;
    d = 1.0 / d;
    del = d * c;
    h *= del;
    if (fabs(del - 1.0) < RCB_GAMMA_EPS) break;
  }
  return -x + a * log(x) - lgamma(a) + log(h);
}

double rcb_mon_chi2_logsf(double x, double dof) {
  double a = 0.5 * dof, h = 0.5 * x;
  if (!(dof >= 1.0) || !(x >= 0.0)) return (double)NAN;
  if (h < a + 1.0) return log(rcb_chi2_sf(x, dof));
  return gamma_logq_cf(a, h);
}

double rcb_chi2_sf(double x, double dof) {
  double a = 0.5 * dof, h = 0.5 * x;
  if (!(dof >= 1.0) || !(x >= 0.0) || isinf(dof)) return (double)NAN;
  if (isinf(x)) return 0.0;
  if (h == 0.0) return 1.0;
  return h < a + 1.0 ? 1.0 - gamma_p_series(a, h) : gamma_q_cf(a, h);
}

/* Lower tail P(X <= x) without the cancellation of 1 - sf where it is small. */
static double chi2_cdf(double x, double dof) {
  double a = 0.5 * dof, h = 0.5 * x;
  if (h <= 0.0) return 0.0;
  return h < a + 1.0 ? gamma_p_series(a, h) : 1.0 - gamma_q_cf(a, h);
}

/* Density of chi-square(dof) at x > 0. */
static double chi2_pdf(double x, double dof) {
  double a = 0.5 * dof;
  return exp((a - 1.0) * log(x) - 0.5 * x - a * log(2.0) - lgamma(a));
}

/* Wilson-Hilferty start from the normal quantile (Acklam's rational
 * approximation would be more exact; Newton polishes it anyway). */
static double normal_quantile_rough(double p) {
  /* Abramowitz & Stegun 26.2.23, |error| < 4.5e-4 */
  double q = p < 0.5 ? p : 1.0 - p, t = sqrt(-2.0 * log(q));
  double z = t - (2.515517 + 0.802853 * t + 0.010328 * t * t) /
                     (1.0 + 1.432788 * t + 0.189269 * t * t + 0.001308 * t * t * t);
  return p < 0.5 ? -z : z;
}

double rcb_chi2_quantile(double p, double dof) {
  double z, c, x, lo = 0.0, hi, up;
  int it;
  if (!(p > 0.0 && p < 1.0) || !(dof >= 1.0) || isinf(dof)) return (double)NAN;
  z = normal_quantile_rough(p);
  c = 2.0 / (9.0 * dof);
  x = dof * pow(fmax(1.0 - c + z * sqrt(c), 0.05), 3.0);
  /* an upper bracket: double until the cdf passes p */
  hi = fmax(2.0 * x, dof + 10.0);
  while (chi2_cdf(hi, dof) < p && hi < 1e300) hi *= 2.0;
  up = 1.0 - p; /* work on the smaller tail for accuracy */
  for (it = 0; it < 200; it++) {
    double f = p < 0.5 ? chi2_cdf(x, dof) - p : up - rcb_chi2_sf(x, dof);
    double d = chi2_pdf(x, dof), xn;
    if (f < 0) lo = x; else hi = x;
    xn = d > 0 ? x - f / d : 0.5 * (lo + hi);
    if (!(xn > lo && xn < hi)) xn = 0.5 * (lo + hi);
    if (fabs(xn - x) <= 1e-14 * fmax(x, 1e-300)) return xn;
    x = xn;
  }
  return x;
}

double rcb_cusum_arl0(double k, double h) {
  double b = h + 1.166, t = 2.0 * k * b;
  if (!(k > 0) || !(h > 0)) return (double)NAN;
  return (exp(t) - t - 1.0) / (2.0 * k * k);
}
