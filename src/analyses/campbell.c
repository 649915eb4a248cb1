/*
 * Critical speeds from a Campbell table: the rotor speeds where a curve
 * wd_k(Omega) meets the excitation line wd = ratio * Omega (ratio 1 for the
 * synchronous 1X line, 2 for 2X, ...).
 *
 * Pure function of its inputs. Between two adjacent table rows both curves
 * are taken as straight lines, so with f(Omega) = wd_k(Omega) - ratio Omega,
 * a sign change of f between rows s and s+1 gives the crossing
 *
 *   Omega_c = Omega_s + (Omega_{s+1} - Omega_s) f_s / (f_s - f_{s+1}),
 *
 * exact for piecewise-linear curves, with an error of order h^2 |wd''| / 8
 * for a smooth curve sampled with step h. A row where f is exactly 0 is a
 * crossing at that row (counted once even when f stays 0 over several rows,
 * i.e. where the curve lies on the line). Rows holding NaN (fewer modes at
 * that speed) break a curve: no crossing is reported across them.
 *
 * Curves are taken in table order (mode k is the k-th lowest wd at each
 * speed, no mode tracking), as rcb_campbell produces them.
 */
#include <math.h>

#include "core/rcb_internal.h"

/* Keep the max_crit lowest speeds found so far, sorted; count them all. */
static void record(double speed, size_t k, size_t max_crit, double *crit, size_t *mode_of,
                   size_t *total) {
  size_t j, have = *total < max_crit ? *total : max_crit;
  (*total)++;
  if (have == max_crit && (have == 0 || speed >= crit[have - 1])) return;
  j = have < max_crit ? have : max_crit - 1; /* slot freed at the end */
  for (; j > 0 && crit[j - 1] > speed; j--) {
    crit[j] = crit[j - 1];
    if (mode_of) mode_of[j] = mode_of[j - 1];
  }
  crit[j] = speed;
  if (mode_of) mode_of[j] = k;
}

static void scan_curve(size_t nspeeds, const double *speeds, size_t nmodes, const double *wd,
                       double ratio, size_t k, size_t max_crit, double *crit,
                       size_t *mode_of, size_t *total) {
  size_t s;
  for (s = 0; s < nspeeds; s++) {
    double f1 = wd[k + nmodes * s] - ratio * speeds[s], f0;
    if (isnan(f1)) continue;
    f0 = s > 0 ? wd[k + nmodes * (s - 1)] - ratio * speeds[s - 1] : (double)NAN;
    if (f1 == 0.0) {
      if (!(f0 == 0.0)) record(speeds[s], k, max_crit, crit, mode_of, total);
    } else if (!isnan(f0) && f0 != 0.0 && (f0 < 0.0) != (f1 < 0.0)) {
      double h = speeds[s] - speeds[s - 1];
      record(speeds[s - 1] + h * f0 / (f0 - f1), k, max_crit, crit, mode_of, total);
    }
  }
}

rcb_status rcb_critical_speeds(size_t nspeeds, const double *speeds, size_t nmodes,
                               const double *wd, double ratio, size_t max_crit, double *crit,
                               size_t *mode_of, size_t *ncrit) {
  size_t s, k, total = 0;
  if (!ncrit) return RCB_ERR_ARG;
  *ncrit = 0;
  if ((nspeeds > 0 && !speeds) || (nspeeds > 0 && nmodes > 0 && !wd) ||
      (max_crit > 0 && !crit) || !isfinite(ratio))
    return RCB_ERR_ARG;
  for (s = 0; s < nspeeds; s++) {
    if (!isfinite(speeds[s])) return RCB_ERR_ARG;
    if (s > 0 && !(speeds[s] > speeds[s - 1])) return RCB_ERR_ARG; /* strictly increasing */
  }
  for (k = 0; k < nmodes; k++)
    scan_curve(nspeeds, speeds, nmodes, wd, ratio, k, max_crit, crit, mode_of, &total);
  *ncrit = total < max_crit ? total : max_crit;
  return total > max_crit ? RCB_ERR_WORKSPACE : RCB_OK;
}
