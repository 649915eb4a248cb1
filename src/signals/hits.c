/*
 * Impact tests, hit by hit: the force pulse and a double hit, a clipped
 * (overloaded) channel, and a long recording cut into hits at a trigger level.
 * Pure functions on the caller's samples: nothing allocated, nothing kept.
 *
 * What the checks are for: a double hit excites the structure twice, so the
 * hit's force spectrum has notches the response does not share in the same
 * way once windowed, and a clipped channel is not the signal at all; impact
 * testing practice (pyFRF, the analysers' "double hit" and "overload"
 * rejection) drops such hits before averaging.
 */
#include <math.h>
#include <string.h>

#include "signals/signals_internal.h"

#define DECAYED_MAX 0.05 /* the pulse has decayed below 5 % of its peak (or double_frac / 2) */

/* Where the signed force s f first falls to @p d on either side of the peak:
 * the pulse's first and last samples above it, and the crossings in samples. */
static void pulse_span(const double *f, size_t n, size_t p, double s, double d, size_t *b,
                       size_t *e, double *tb, double *te) {
  *b = p;
  while (*b > 0 && s * f[*b - 1] > d) (*b)--;
  *e = p;
  while (*e + 1 < n && s * f[*e + 1] > d) (*e)++;
  *tb = (double)*b;
  if (*b > 0) { /* s f[b - 1] <= d < s f[b] */
    double lo = s * f[*b - 1], hi = s * f[*b];
    *tb = (double)(*b - 1) + (d - lo) / (hi - lo);
  }
  *te = (double)*e;
  if (*e + 1 < n) {
    double hi = s * f[*e], lo = s * f[*e + 1];
    *te = (double)*e + (hi - d) / (hi - lo);
  }
}

rcb_status rcb_hit_pulse_find(const double *force, size_t n, double rate, double double_frac,
                              rcb_hit_pulse *out) {
  size_t i, p = 0, b, e, sec = 0;
  double s, peak, d, tb, te, second = 0.0;
  if (!force || !out || n == 0 || !(rate > 0.0) || !isfinite(rate)) return RCB_ERR_ARG;
  if (double_frac == 0.0) double_frac = 0.1;
  if (!(double_frac > 0.0 && double_frac < 1.0)) return RCB_ERR_ARG;
  memset(out, 0, sizeof *out);
  for (i = 1; i < n; i++)
    if (fabs(force[i]) > fabs(force[p])) p = i;
  peak = fabs(force[p]);
  if (!(peak > 0.0)) return RCB_OK;
  s = force[p] > 0.0 ? 1.0 : -1.0;
  d = (double_frac / 2.0 < DECAYED_MAX ? double_frac / 2.0 : DECAYED_MAX) * peak;
  pulse_span(force, n, p, s, d, &b, &e, &tb, &te);
  for (i = 0; i < n; i++) {
    if (i == b) i = e; /* skip the pulse itself */
    else if (s * force[i] > second) second = s * force[i], sec = i;
  }
  out->peak = force[p];
  out->peak_time = (double)p / rate;
  out->start = tb / rate;
  out->end = te / rate;
  out->width = (te - tb) / rate;
  out->second = second / peak;
  out->second_time = second > 0.0 ? (double)sec / rate : 0.0;
  out->double_hit = out->second > double_frac;
  return RCB_OK;
}

/* Longest run of samples equal to @p v (its first index in *at). */
static size_t run_of(const double *x, size_t n, double v, size_t *at) {
  size_t i, best = 0, len = 0;
  for (i = 0; i < n; i++) {
    len = x[i] == v ? len + 1 : 0;
    if (len > best) best = len, *at = i + 1 - len;
  }
  return best;
}

rcb_status rcb_hit_overload_find(const double *x, size_t n, size_t min_run, double range,
                                 rcb_hit_overload *out) {
  size_t i, at = 0;
  double lo, hi, big;
  int side;
  if (!x || !out || n == 0 || min_run == 1 || !(range >= 0.0)) return RCB_ERR_ARG;
  if (min_run == 0) min_run = 5;
  memset(out, 0, sizeof *out);
  lo = hi = x[0];
  for (i = 1; i < n; i++) {
    if (x[i] < lo) lo = x[i];
    if (x[i] > hi) hi = x[i];
  }
  big = fabs(lo) > fabs(hi) ? fabs(lo) : fabs(hi);
  for (side = 0; side < 2; side++) {
    double v = side ? lo : hi;
    size_t r;
    if (v == 0.0 || fabs(v) < 0.5 * big) continue;
    r = run_of(x, n, v, &at);
    if (r > out->run) out->run = r, out->level = v, out->at = at;
  }
  out->overload = out->run >= min_run;
  if (range > 0.0)
    for (i = 0; i < n; i++)
      if (fabs(x[i]) >= range * (1.0 - 1e-9)) {
        out->at_range = 1;
        if (!out->overload) out->level = x[i], out->at = i;
        out->overload = 1;
        break;
      }
  return RCB_OK;
}

rcb_status rcb_hit_triggers(const double *force, size_t n, double level, size_t pre,
                            size_t length, size_t *starts, size_t cap, size_t *count,
                            size_t *partial) {
  size_t i = 1, found = 0, cut = 0;
  double s;
  if (!force || !count || !partial || length == 0 || pre >= length || !isfinite(level) ||
      level == 0.0 || (cap && !starts))
    return RCB_ERR_ARG;
  s = level > 0.0 ? 1.0 : -1.0;
  while (i < n) {
    if (!(s * force[i] >= s * level && s * force[i - 1] < s * level)) {
      i++;
      continue;
    }
    if (i < pre || n - (i - pre) < length) {
      cut++;
    } else {
      if (found < cap) starts[found] = i - pre;
      found++;
    }
    i += length - pre; /* hold-off: from the hit's end on */
  }
  *count = found;
  *partial = cut;
  return RCB_OK;
}
