/*
 * The peak table: measured resonances (prominent local maxima of the
 * channel-summed magnitude, parabolic top, damping from a local modal fit,
 * compare_modal.c, and from the half-power width) paired with
 * the model's modes (damped modes at the test speed for FRFs; 1X critical
 * speeds for unbalance responses and synchronous FRFs) by nearest frequency.
 */
#include <math.h>
#include <string.h>

#include "compare/compare_internal.h"

/* A peak of a channel-summed magnitude curve. */
typedef struct peak {
  size_t idx;   /* grid index of the top */
  double freq;  /* rad/s, parabolic */
  double zeta;  /* half-power, NaN when no side falls to half power */
} peak;

/* A model reference: damped mode or critical speed. */
typedef struct mref {
  double freq, zeta; /* rad/s, - */
  int visible;
  double peak;       /* nearest model-response peak within the tolerance, rad/s */
  size_t pair;       /* measured peak index, (size_t)-1 when unpaired */
} mref;

#define NONE ((size_t)-1)

/* The parabola through three points, evaluated at t (Lagrange form). */
static double lagrange3(const double *x, const double *y, double t) {
  return y[0] * (t - x[1]) * (t - x[2]) / ((x[0] - x[1]) * (x[0] - x[2])) +
         y[1] * (t - x[0]) * (t - x[2]) / ((x[1] - x[0]) * (x[1] - x[2])) +
         y[2] * (t - x[0]) * (t - x[1]) / ((x[2] - x[0]) * (x[2] - x[1]));
}

/* Vertex (abscissa and height) of the parabola through three points. */
static void parabola_top(const double *x, const double *y, double *xv, double *yv) {
  double d1 = x[1] - x[0], d2 = x[1] - x[2];
  double num = d1 * d1 * (y[1] - y[2]) - d2 * d2 * (y[1] - y[0]);
  double den = d1 * (y[1] - y[2]) - d2 * (y[1] - y[0]);
  double t;
  *xv = x[1];
  *yv = y[1];
  if (den == 0.0) return;
  t = x[1] - 0.5 * num / den;
  if (!(t > x[0] && t < x[2])) return;
  *xv = t;
  *yv = lagrange3(x, y, t);
}

/* Sum over channels of |v|/rms(e) at each point (non-finite values count 0). */
static void summed(const rcb_compare *c, const rcb_complex *v, const double *wt, double *s) {
  size_t i, k;
  for (i = 0; i < c->npts; i++) {
    s[i] = 0.0;
    for (k = 0; k < c->nch; k++) {
      double a = cabs(v[k * c->npts + i]);
      if (isfinite(a)) s[i] += wt[k] * a;
    }
  }
}

/* Topographic prominence ratio of the local maximum at i: its height over the
 * higher of the lowest points reached on each side before higher ground. */
static double prominence(const double *s, size_t n, size_t i) {
  double lmin = s[i], rmin = s[i];
  size_t j;
  for (j = i; j-- > 0 && s[j] <= s[i];) lmin = s[j] < lmin ? s[j] : lmin;
  for (j = i + 1; j < n && s[j] <= s[i]; j++) rmin = s[j] < rmin ? s[j] : rmin;
  lmin = lmin > rmin ? lmin : rmin;
  return lmin > 0 ? s[i] / lmin : (double)INFINITY;
}

/* Half-power crossing on one side of the top (dir -1 left, +1 right), by
 * linear interpolation; NaN when the curve rises above the top or ends first. */
static double half_power(const double *x, const double *s, size_t n, size_t i, double top,
                         int dir) {
  double lvl = top / sqrt(2.0);
  size_t j = i, prev;
  for (;;) {
    if ((dir < 0 && j == 0) || (dir > 0 && j + 1 >= n)) return (double)NAN;
    prev = j;
    j = dir < 0 ? j - 1 : j + 1;
    if (s[j] > top) return (double)NAN;
    if (s[j] < lvl) break;
  }
  return x[prev] + (x[j] - x[prev]) * (s[prev] - lvl) / (s[prev] - s[j]);
}

/* Prominent local maxima of s; writes at most n/2 peaks. */
static size_t find_peaks(const double *x, const double *s, size_t n, double ratio, peak *out) {
  size_t i, np = 0;
  for (i = 1; i + 1 < n; i++) {
    double top, w1, w2;
    peak *p;
    if (!(s[i] > s[i - 1] && s[i] >= s[i + 1])) continue;
    if (prominence(s, n, i) < ratio) continue;
    p = &out[np++];
    p->idx = i;
    parabola_top(x + i - 1, s + i - 1, &p->freq, &top);
    w1 = half_power(x, s, n, i, top, -1);
    w2 = half_power(x, s, n, i, top, +1);
    if (isfinite(w1) && isfinite(w2))
      p->zeta = (w2 - w1) / (2.0 * p->freq);
    else if (isfinite(w1))
      p->zeta = (p->freq - w1) / p->freq;
    else if (isfinite(w2))
      p->zeta = (w2 - p->freq) / p->freq;
    else
      p->zeta = (double)NAN;
  }
  return np;
}

/* ---- model references ---- */

/* Damping ratio of the mode whose wd is nearest @p w at rotor speed @p speed;
 * also returns that wd. */
static rcb_status nearest_mode(rcb_compare *c, rcb_modes *me, rcb_mode *modes, size_t cap,
                               double speed, double w, double *wd, double *zeta) {
  size_t nm = 0, j, best = NONE;
  rcb_status st = rcb_modes_compute(me, speed, cap, modes, &nm, NULL);
  if (st) return rcb_cmp_fail(c, st, "modes at %g rad/s: %s", speed, rcb_modes_errmsg(me));
  for (j = 0; j < nm; j++)
    if (best == NONE || fabs(modes[j].wd - w) < fabs(modes[best].wd - w)) best = j;
  *wd = best == NONE ? (double)NAN : modes[best].wd;
  *zeta = best == NONE ? (double)NAN : modes[best].zeta;
  return RCB_OK;
}

/* 1X critical speeds within the measured range, each refined by a few
 * fixed-point steps s <- wd(s) of the crossing mode. */
static rcb_status critical_refs(rcb_compare *c, rcb_modes *me, rcb_mode *modes, size_t cap,
                                mref *refs, size_t *nref) {
  double x0 = c->grid[0], x1 = c->grid[c->npts - 1];
  size_t nsp = c->npts < 60 ? c->npts : 60, nmode = cap < 40 ? cap : 40, i, ncrit = 0, it;
  double *sp = rcb_alloc(&c->alloc, nsp * sizeof *sp);
  double *wd = rcb_alloc(&c->alloc, nsp * nmode * sizeof *wd);
  double *crit = rcb_alloc(&c->alloc, nsp * nmode * sizeof *crit);
  rcb_status st = RCB_OK;
  *nref = 0;
  if (!sp || !wd || !crit) st = rcb_cmp_fail(c, RCB_ERR_NOMEM, "out of memory");
  if (!st && nsp >= 2 && x1 > x0) {
    for (i = 0; i < nsp; i++) sp[i] = x0 + (x1 - x0) * (double)i / (double)(nsp - 1);
    st = rcb_campbell(me, nsp, sp, nmode, wd, NULL, NULL);
    if (st) rcb_cmp_fail(c, st, "Campbell data: %s", rcb_modes_errmsg(me));
    if (!st) {
      st = rcb_critical_speeds(nsp, sp, nmode, wd, 1.0, nsp * nmode, crit, NULL, &ncrit);
      if (st == RCB_ERR_WORKSPACE) st = RCB_OK;
    }
    for (i = 0; !st && i < ncrit; i++) {
      double s = crit[i], w = s, z = (double)NAN;
      for (it = 0; !st && it < 4; it++) {
        st = nearest_mode(c, me, modes, cap, s, s, &w, &z);
        if (isfinite(w)) s = w;
      }
      if (*nref && fabs(s - refs[*nref - 1].freq) <= 1e-6 * s) continue; /* repeated */
      if (!st && s >= x0 && s <= x1 && *nref < cap) {
        refs[*nref].freq = s;
        refs[*nref].zeta = z;
        (*nref)++;
      }
    }
  }
  rcb_free(&c->alloc, sp);
  rcb_free(&c->alloc, wd);
  rcb_free(&c->alloc, crit);
  return st;
}

static rcb_status model_refs(rcb_compare *c, const rcb_model *m, mref *refs, size_t cap,
                             size_t *nref) {
  rcb_modes *me = NULL;
  rcb_mode *modes = rcb_alloc(&c->alloc, cap * sizeof *modes);
  size_t nm = 0, j;
  rcb_status st;
  *nref = 0;
  if (!modes) return rcb_cmp_fail(c, RCB_ERR_NOMEM, "out of memory");
  st = rcb_modes_create(&me, m, &c->alloc);
  if (st) rcb_cmp_fail(c, st, "modes: %s", rcb_status_str(st));
  if (!st && c->type == RCB_MEAS_FRF && c->speed >= 0) {
    st = rcb_modes_compute(me, c->speed, cap, modes, &nm, NULL);
    if (st) rcb_cmp_fail(c, st, "modes at %g rad/s: %s", c->speed, rcb_modes_errmsg(me));
    for (j = 0; !st && j < nm; j++) {
      if (modes[j].wd < c->grid[0] || modes[j].wd > c->grid[c->npts - 1]) continue;
      /* a repeated root (an axisymmetric rotor at rest: x and y) is one resonance */
      if (*nref && fabs(modes[j].wd - refs[*nref - 1].freq) <= 1e-6 * modes[j].wd) continue;
      refs[*nref].freq = modes[j].wd;
      refs[*nref].zeta = modes[j].zeta;
      (*nref)++;
    }
  } else if (!st) {
    st = critical_refs(c, me, modes, cap, refs, nref);
  }
  rcb_modes_destroy(me);
  rcb_free(&c->alloc, modes);
  return st;
}

/* ---- pairing ---- */

/* Each peak of the model's own response is claimed by its nearest mode
 * (within the tolerance): that mode is "visible" in these channels. Of two
 * close modes that the response shows as one peak, only one is visible. */
static void mark_visible(const peak *pm, size_t nmp, mref *refs, size_t nref, double tol) {
  size_t i, j;
  for (j = 0; j < nref; j++) refs[j].visible = 0;
  for (i = 0; i < nmp; i++) {
    size_t best = NONE;
    for (j = 0; j < nref; j++) {
      double d = fabs(pm[i].freq - refs[j].freq);
      if (d > tol * refs[j].freq) continue;
      if (best == NONE || d < fabs(pm[i].freq - refs[best].freq)) best = j;
    }
    if (best == NONE) continue;
    if (refs[best].visible &&
        fabs(refs[best].peak - refs[best].freq) <= fabs(pm[i].freq - refs[best].freq))
      continue;
    refs[best].visible = 1;
    refs[best].peak = pm[i].freq;
  }
}

/* One greedy pass: the closest free pair first. */
static void pair_pass(const peak *pk, size_t np, mref *refs, size_t nref, double tol,
                      size_t *pk_pair, int visible_only) {
  size_t i, j;
  for (;;) {
    double best = (double)INFINITY;
    size_t bi = NONE, bj = NONE;
    for (i = 0; i < np; i++) {
      if (pk_pair[i] != NONE) continue;
      for (j = 0; j < nref; j++) {
        double d = fabs(refs[j].freq - pk[i].freq) / pk[i].freq;
        if (refs[j].pair != NONE || d > tol || d >= best) continue;
        if (visible_only && !refs[j].visible) continue;
        best = d;
        bi = i;
        bj = j;
      }
    }
    if (bi == NONE) break;
    pk_pair[bi] = bj;
    refs[bj].pair = bi;
  }
}

/* Greedy one-to-one pairing, closest first; modes the model's response shows
 * in these channels before the others. */
static void pair_up(const peak *pk, size_t np, mref *refs, size_t nref, double tol,
                    size_t *pk_pair) {
  size_t i, j;
  for (i = 0; i < np; i++) pk_pair[i] = NONE;
  for (j = 0; j < nref; j++) refs[j].pair = NONE;
  pair_pass(pk, np, refs, nref, tol, pk_pair, 1);
  pair_pass(pk, np, refs, nref, tol, pk_pair, 0);
}

static double row_freq(const rcb_compare_peak *r) {
  return r->match == RCB_PEAK_MODEL_ONLY ? r->model_freq : r->meas_freq;
}

static void sort_rows(rcb_compare_peak *r, size_t n) {
  size_t i, j;
  for (i = 1; i < n; i++) {
    rcb_compare_peak t = r[i];
    for (j = i; j > 0 && row_freq(&r[j - 1]) > row_freq(&t); j--) r[j] = r[j - 1];
    r[j] = t;
  }
}

/* Fill the measured side of a row: the dominant channel and its amplitudes. */
static void measured_row(const rcb_compare *c, const peak *p, const double *wt,
                         rcb_compare_peak *r) {
  size_t k, best = 0, i = p->idx;
  double bv = -1.0, y[3];
  for (k = 0; k < c->nch; k++) {
    double a = wt[k] * cabs(c->meas[k * c->npts + i]);
    if (isfinite(a) && a > bv) {
      bv = a;
      best = k;
    }
  }
  for (k = 0; k < 3; k++) y[k] = cabs(c->meas[best * c->npts + i - 1 + k]);
  r->meas_freq = p->freq;
  r->meas_zeta = p->zeta;
  r->channel = best;
  /* the channel's own magnitude at the summed curve's peak frequency */
  r->meas_amp = lagrange3(c->grid + i - 1, y, p->freq);
  for (k = 0; k < 3; k++) y[k] = cabs(c->model[best * c->npts + i - 1 + k]);
  r->model_amp = lagrange3(c->grid + i - 1, y, p->freq);
  r->amp_ratio = r->model_amp > 0 ? r->meas_amp / r->model_amp : (double)NAN;
}

/* The fit window of a peak: the grid points within [w0, w1] (rad/s), at
 * least 5 and at most 250 on each side of its top. */
static void fit_window(const rcb_compare *c, const peak *p, double w0, double w1, size_t *lo,
                       size_t *hi) {
  *lo = *hi = p->idx;
  while (*lo > 0 && p->idx - *lo < 250 && (p->idx - *lo < 5 || c->grid[*lo - 1] >= w0)) (*lo)--;
  while (*hi + 1 < c->npts && *hi - p->idx < 250 && (*hi - p->idx < 5 || c->grid[*hi + 1] <= w1))
    (*hi)++;
}

/* A resonance that may share a fit window: frequency and half-power
 * half-width zeta w, rad/s. */
typedef struct reson {
  double f, hw;
} reson;

/* Resonance i of the data: the measured peaks (i < np; zeta from the
 * half-power width, 0.01 when none), then the model's modes no measured
 * peak claimed (modes the data show merged with a neighbour: the gyroscopic
 * pair of a rotor, one peak on the direct and the cross channels). 0 when i
 * is a claimed mode. */
static int resonance(const peak *pk, size_t np, const mref *refs, size_t i, reson *q) {
  if (i < np) {
    q->f = pk[i].freq;
    q->hw = (isfinite(pk[i].zeta) ? pk[i].zeta : 0.01) * q->f;
    return 1;
  }
  i -= np;
  if (refs[i].pair != NONE || !isfinite(refs[i].zeta)) return 0;
  q->f = refs[i].freq;
  q->hw = refs[i].zeta * q->f;
  return 1;
}

/* The resonances fitted with peak ip, at most 4, and their window [*w0,
 * *w1] (rad/s): 3.5 half-widths either side of each. Grown from the peak
 * alone by the nearest resonance whose half-power band [f - hw, f + hw]
 * meets the window (its tail is not negligible there), until none does.
 * Returns how many. */
static size_t fit_group(const peak *pk, size_t np, const mref *refs, size_t nref, size_t ip,
                        double *w0, double *w1) {
  size_t grp[4] = {ip, 0, 0, 0}, ng = 1, i, j;
  reson q = {0.0, 0.0};
  resonance(pk, np, refs, ip, &q);
  *w0 = q.f - 3.5 * q.hw, *w1 = q.f + 3.5 * q.hw;
  while (ng < 4) {
    size_t best = NONE;
    double dbest = (double)INFINITY;
    for (i = 0; i < np + nref; i++) {
      for (j = 0; j < ng && grp[j] != i; j++) {}
      if (j < ng || !resonance(pk, np, refs, i, &q)) continue;
      if (q.f + q.hw < *w0 || q.f - q.hw > *w1 || fabs(q.f - pk[ip].freq) >= dbest) continue;
      best = i, dbest = fabs(q.f - pk[ip].freq);
    }
    if (best == NONE) break;
    resonance(pk, np, refs, best, &q);
    grp[ng++] = best;
    *w0 = fmin(*w0, q.f - 3.5 * q.hw), *w1 = fmax(*w1, q.f + 3.5 * q.hw);
  }
  return ng;
}

/* The window's points into w (rad/s) and h (channel-major, stride
 * hi - lo + 1): channel k0 alone (its finite points), or when k0 == nch
 * every channel finite on the whole window. Returns the point count,
 * *nused the channels. */
static size_t gather(const rcb_compare *c, size_t lo, size_t hi, size_t k0, double *w,
                     rcb_complex *h, size_t *nused) {
  size_t i, k, n = 0, one = k0 < c->nch, kb = one ? k0 : 0, ke = one ? k0 + 1 : c->nch;
  *nused = 0;
  for (k = kb; k < ke; k++) {
    const rcb_complex *e = c->meas + k * c->npts;
    size_t m = 0;
    for (i = lo; i <= hi; i++) {
      int ok = isfinite(creal(e[i])) && isfinite(cimag(e[i]));
      if (!ok && !one) break; /* several channels share the abscissae */
      if (ok) w[m] = c->grid[i], h[*nused * (hi - lo + 1) + m++] = e[i];
    }
    if (!one && m < hi - lo + 1) continue;
    n = m;
    (*nused)++;
  }
  return n;
}

static double damped(double wn, double zeta) { return wn * sqrt(1.0 - zeta * zeta); }

/* The fitted pole whose damped frequency is nearest the peak's, among those
 * at least one grid step wide (half-power half-width zeta wn >= step, rad/s:
 * a narrower one is fitted to the noise of a single point); NONE if none. */
static size_t nearest_pole(const double *wn, const double *zeta, size_t nf, double w,
                           double step) {
  size_t j, best = NONE;
  for (j = 0; j < nf; j++) {
    if (zeta[j] * wn[j] < step) continue;
    if (best == NONE || fabs(damped(wn[j], zeta[j]) - w) < fabs(damped(wn[best], zeta[best]) - w))
      best = j;
  }
  return best;
}

/* The local modal fit of a measured peak (compare_modal.c) over 3.5
 * half-power half-widths (zeta w) either side of the top: a window of about
 * one half-width leaves the fit's residual terms free to take up the noise,
 * and under eq. 19 noise the damping then comes out 25 % low, as the
 * half-power width's does. Alone (fit_group): one mode on the peak's
 * dominant channel. With neighbours: as many modes sharing their poles on
 * every channel finite on the group's window, the peak taking the pole
 * nearest its frequency. */
static rcb_status modal_row(rcb_compare *c, const peak *pk, size_t np, size_t ip,
                            const mref *refs, size_t nref, rcb_compare_peak *r) {
  const peak *p = &pk[ip];
  double wn[4] = {0}, zeta[4] = {0}, w0, w1;
  size_t lo, hi, n = 0, nm, nch = 0, nf = 0, best = NONE;
  rcb_status st = RCB_OK;
  double *w = rcb_alloc(&c->alloc, c->npts * sizeof *w);
  rcb_complex *h = rcb_alloc(&c->alloc, c->nch * c->npts * sizeof *h);
  r->meas_zeta_hp = p->zeta;
  r->meas_wd = (double)NAN;
  if (!w || !h) st = rcb_cmp_fail(c, RCB_ERR_NOMEM, "out of memory (modal fit)");
  nm = fit_group(pk, np, refs, nref, ip, &w0, &w1);
  fit_window(c, p, w0, w1, &lo, &hi);
  if (!st && nm > 1) n = gather(c, lo, hi, c->nch, w, h, &nch);
  if (!st && nch == 0) /* alone, or no channel finite on the whole window */
    nm = 1, n = gather(c, lo, hi, r->channel, w, h, &nch);
  if (!st) st = rcb_cmp_modal_fit_multi(c, w, h, nch, n, p->freq, nm, wn, zeta, &nf);
  if (!st && n > 1) best = nearest_pole(wn, zeta, nf, p->freq, (w[n - 1] - w[0]) / (double)(n - 1));
  if (best != NONE) r->meas_zeta = zeta[best], r->meas_wd = damped(wn[best], zeta[best]);
  rcb_free(&c->alloc, w);
  rcb_free(&c->alloc, h);
  return st;
}

static void model_side(rcb_compare_peak *r, const mref *q) {
  r->model_freq = q->freq;
  r->model_zeta = q->zeta;
  r->model_visible = q->visible;
  r->model_peak = q->visible ? q->peak : (double)NAN;
}

static rcb_status build_rows(rcb_compare *c, const peak *pk, size_t np, const size_t *pk_pair,
                             const mref *refs, size_t nref, const double *wt) {
  size_t i, j, n = 0, unpaired = 0;
  rcb_status st;
  for (j = 0; j < nref; j++) unpaired += refs[j].pair == NONE;
  c->peaks = rcb_alloc(&c->alloc, (np + unpaired + 1) * sizeof *c->peaks);
  if (!c->peaks) return rcb_cmp_fail(c, RCB_ERR_NOMEM, "out of memory");
  for (i = 0; i < np; i++) {
    rcb_compare_peak *r = &c->peaks[n++];
    r->model_freq = r->model_zeta = r->model_peak = (double)NAN;
    r->freq_err_pct = r->zeta_err_pct = r->peak_err_pct = (double)NAN;
    measured_row(c, &pk[i], wt, r);
    if ((st = modal_row(c, pk, np, i, refs, nref, r))) return st;
    r->match = RCB_PEAK_MEASURED_ONLY;
    if (pk_pair[i] == NONE) continue;
    r->match = RCB_PEAK_MATCHED;
    model_side(r, &refs[pk_pair[i]]);
    r->freq_err_pct = 100.0 * (r->model_freq - r->meas_freq) / r->meas_freq;
    r->zeta_err_pct = 100.0 * (r->model_zeta - r->meas_zeta) / r->meas_zeta;
    r->peak_err_pct = 100.0 * (r->model_peak - r->meas_freq) / r->meas_freq;
  }
  for (j = 0; j < nref; j++) {
    rcb_compare_peak *r;
    if (refs[j].pair != NONE) continue;
    r = &c->peaks[n++];
    r->match = RCB_PEAK_MODEL_ONLY;
    r->meas_freq = r->meas_zeta = r->meas_amp = r->model_amp = r->amp_ratio = (double)NAN;
    r->meas_zeta_hp = r->meas_wd = (double)NAN;
    r->freq_err_pct = r->zeta_err_pct = r->peak_err_pct = (double)NAN;
    r->channel = 0;
    model_side(r, &refs[j]);
  }
  c->npeaks = n;
  sort_rows(c->peaks, n);
  return RCB_OK;
}

static double *channel_weights(const rcb_compare *c, double *wt) {
  size_t k, i;
  for (k = 0; k < c->nch; k++) {
    double s = 0.0;
    size_t n = 0;
    for (i = 0; i < c->npts; i++) {
      double a = cabs(c->meas[k * c->npts + i]);
      if (!isfinite(a)) continue;
      s += a * a;
      n++;
    }
    wt[k] = n && s > 0 ? 1.0 / sqrt(s / (double)n) : 0.0;
  }
  return wt;
}

rcb_status rcb_cmp_peaks(rcb_compare *c, rcb_cmp_eval *ev) {
  size_t n = c->npts, cap = rcb_model_dof_count(ev->m), np, nmp, nref = 0;
  double ratio = pow(10.0, c->prom_db / 20.0);
  double *wt = rcb_alloc(&c->alloc, c->nch * sizeof *wt);
  double *se = rcb_alloc(&c->alloc, n * sizeof *se), *sm = rcb_alloc(&c->alloc, n * sizeof *sm);
  peak *pe = rcb_alloc(&c->alloc, (n / 2 + 1) * sizeof *pe);
  peak *pm = rcb_alloc(&c->alloc, (n / 2 + 1) * sizeof *pm);
  mref *refs = rcb_alloc(&c->alloc, (cap + 1) * sizeof *refs);
  size_t *pk_pair = rcb_alloc(&c->alloc, (n / 2 + 1) * sizeof *pk_pair);
  rcb_status st = RCB_OK;
  if (!wt || !se || !sm || !pe || !pm || !refs || !pk_pair)
    st = rcb_cmp_fail(c, RCB_ERR_NOMEM, "out of memory for the peak table");
  if (!st) {
    channel_weights(c, wt);
    summed(c, c->meas, wt, se);
    summed(c, c->model, wt, sm);
    np = find_peaks(c->grid, se, n, ratio, pe);
    nmp = find_peaks(c->grid, sm, n, ratio, pm);
    st = model_refs(c, ev->m, refs, cap, &nref);
    if (!st) mark_visible(pm, nmp, refs, nref, c->tol);
    if (!st) {
      pair_up(pe, np, refs, nref, c->tol, pk_pair);
      st = build_rows(c, pe, np, pk_pair, refs, nref, wt);
    }
  }
  rcb_free(&c->alloc, wt);
  rcb_free(&c->alloc, se);
  rcb_free(&c->alloc, sm);
  rcb_free(&c->alloc, pe);
  rcb_free(&c->alloc, pm);
  rcb_free(&c->alloc, refs);
  rcb_free(&c->alloc, pk_pair);
  return st;
}
