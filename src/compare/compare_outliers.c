/*
 * Which sensor to check before the model (issue #23 item 4): a probe reading
 * 20 % low shows in its channels' error % at about 25 % against 5 % on the
 * others. The rule that names it (rcb_compare_outlier_threshold) is applied
 * per sensor (a response name over all its references) and per channel, on
 * error %, or on chi2/dof when the standard deviations are known.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "compare/compare_internal.h"

#define OUTLIER_MAD_SIGMAS 6.0   /* robust standard deviations above the median */
#define OUTLIER_MAD_NORMAL 1.4826 /* MAD -> standard deviation of normal data */
#define OUTLIER_RATIO_ERR 2.0    /* error %: twice the typical sensor's */
#define OUTLIER_RATIO_CHI2 4.0   /* chi2/dof: 2^2 */
#define OUTLIER_MIN_PCT 1.0      /* a sensor within 1 % is never named */
#define OUTLIER_MIN_OTHERS 3     /* fewer others: no judgement */

static int cmp_double(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

/* Median of the n values of v (sorted in place), n >= 1. */
static double median_sorted(double *v, size_t n) {
  qsort(v, n, sizeof *v, cmp_double);
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

double rcb_compare_outlier_threshold(const double *others, size_t n, double ratio,
                                     double *work) {
  size_t i, m = 0;
  double med, mad;
  if (!others || !work) return (double)NAN;
  for (i = 0; i < n; i++)
    if (isfinite(others[i])) work[m++] = others[i];
  if (m < OUTLIER_MIN_OTHERS) return (double)NAN;
  med = median_sorted(work, m);
  for (i = 0; i < m; i++) work[i] = fabs(work[i] - med);
  mad = median_sorted(work, m);
  return fmax(ratio * med, med + OUTLIER_MAD_SIGMAS * OUTLIER_MAD_NORMAL * mad);
}

double rcb_compare_chi2_limit(size_t dof) {
  /* Wilson-Hilferty: (chi2/nu)^(1/3) ~ normal, mean 1 - 2/(9 nu), variance 2/(9 nu) */
  const double z = 3.090232306167813; /* the 0.999 quantile of the standard normal */
  double nu = (double)dof, a, t;
  if (dof == 0) return (double)NAN;
  a = 2.0 / (9.0 * nu);
  t = 1.0 - a + z * sqrt(a);
  return t * t * t;
}

/* Sums of one unit (a channel or a sensor): error % and chi-square. */
typedef struct unit_sums {
  double num, den, x2;
  size_t nx;
} unit_sums;

static void channel_sums(const rcb_compare *c, size_t k, unit_sums *u) {
  size_t i;
  for (i = 0; i < c->npts; i++) {
    rcb_complex e = c->meas[k * c->npts + i], m = c->model[k * c->npts + i], d = m - e;
    double ae = cabs(e), am = cabs(m), sd;
    if (!isfinite(ae) || !isfinite(am)) continue;
    u->num += (am - ae) * (am - ae);
    u->den += ae * ae;
    if (!c->sd) continue;
    sd = c->sd[k * c->npts + i];
    if (!(sd > 0)) continue;
    /* magnitudes only: |m| - |e|, one degree of freedom counted as two */
    u->x2 += c->magonly[k] ? 2.0 * (am - ae) * (am - ae) / (sd * sd)
                           : creal(d * conj(d)) / (sd * sd);
    u->nx++;
  }
}

/* The figures of n units, and the scratch of a judgement. */
typedef struct unit_set {
  size_t n;
  double *err, *chi; /* n each: error %, chi2/dof (NaN without sds) */
  size_t *nx;        /* n: points with an sd */
  double *oth, *work; /* n each, scratch */
} unit_set;

static void set_figures(unit_set *s, const unit_sums *u) {
  size_t k;
  for (k = 0; k < s->n; k++) {
    s->err[k] = u[k].den > 0 ? 100.0 * sqrt(u[k].num / u[k].den) : (double)NAN;
    s->chi[k] = u[k].nx ? u[k].x2 / (2.0 * (double)u[k].nx) : (double)NAN;
    s->nx[k] = u[k].nx;
  }
}

/* Lowest and highest finite value of v over the units other than u. */
static void others_range(const double *v, size_t n, size_t u, double *lo, double *hi) {
  size_t k;
  *lo = *hi = (double)NAN;
  for (k = 0; k < n; k++) {
    if (k == u || !isfinite(v[k])) continue;
    if (!(v[k] >= *lo)) *lo = v[k];
    if (!(v[k] <= *hi)) *hi = v[k];
  }
}

/* Is unit u an outlier among the set? Fills the figures of *o. */
static int judge(unit_set *s, size_t u, int by_chi2, rcb_compare_outlier *o) {
  const double *v = by_chi2 ? s->chi : s->err;
  size_t k, m = 0;
  double thr;
  for (k = 0; k < s->n; k++)
    if (k != u) s->oth[m++] = v[k];
  thr = rcb_compare_outlier_threshold(s->oth, m, by_chi2 ? OUTLIER_RATIO_CHI2
                                                          : OUTLIER_RATIO_ERR, s->work);
  if (!isfinite(thr) || !(v[u] > thr)) return 0;
  if (by_chi2 && !(v[u] > rcb_compare_chi2_limit(2 * s->nx[u]))) return 0;
  if (!by_chi2 && !(v[u] >= OUTLIER_MIN_PCT)) return 0;
  memset(o, 0, sizeof *o);
  o->error_pct = s->err[u];
  others_range(s->err, s->n, u, &o->others_lo, &o->others_hi);
  o->by_chi2 = by_chi2;
  o->chi2_dof = s->chi[u];
  others_range(s->chi, s->n, u, &o->chi2_lo, &o->chi2_hi);
  o->threshold = thr;
  return 1;
}

typedef struct outl_work {
  size_t *sens;        /* nch: sensor index of each channel */
  size_t *nchan;       /* nsens: channels of each sensor */
  int *named;          /* nsens: the sensor is an outlier */
  int *chan_out;       /* nch: the channel stands out among the channels */
  unit_sums *su, *cu;  /* nsens, nch */
  double *buf;         /* 5 nch: err, chi, oth, work for the sets */
  size_t *nx;          /* nch */
} outl_work;

static void work_free(rcb_compare *c, outl_work *w) {
  rcb_free(&c->alloc, w->sens);
  rcb_free(&c->alloc, w->nchan);
  rcb_free(&c->alloc, w->named);
  rcb_free(&c->alloc, w->chan_out);
  rcb_free(&c->alloc, w->su);
  rcb_free(&c->alloc, w->cu);
  rcb_free(&c->alloc, w->buf);
  rcb_free(&c->alloc, w->nx);
}

static rcb_status work_alloc(rcb_compare *c, outl_work *w) {
  size_t n = c->nch;
  memset(w, 0, sizeof *w);
  w->sens = rcb_alloc(&c->alloc, n * sizeof *w->sens);
  w->nchan = rcb_alloc(&c->alloc, n * sizeof *w->nchan);
  w->named = rcb_alloc(&c->alloc, n * sizeof *w->named);
  w->chan_out = rcb_alloc(&c->alloc, n * sizeof *w->chan_out);
  w->su = rcb_alloc(&c->alloc, n * sizeof *w->su);
  w->cu = rcb_alloc(&c->alloc, n * sizeof *w->cu);
  w->buf = rcb_alloc(&c->alloc, 4 * n * sizeof *w->buf);
  w->nx = rcb_alloc(&c->alloc, n * sizeof *w->nx);
  c->outl = rcb_alloc(&c->alloc, n * sizeof *c->outl);
  if (!w->sens || !w->nchan || !w->named || !w->chan_out || !w->su || !w->cu || !w->buf ||
      !w->nx || !c->outl)
    return rcb_cmp_fail(c, RCB_ERR_NOMEM, "out of memory for the outlier summary");
  return RCB_OK;
}

/* Sensors: the distinct response names, in order of first appearance. */
static size_t group_sensors(const rcb_compare *c, outl_work *w) {
  size_t k, j, ns = 0;
  for (k = 0; k < c->nch; k++) {
    for (j = 0; j < k && strcmp(c->resp[j], c->resp[k]) != 0; j++) {
    }
    w->sens[k] = j < k ? w->sens[j] : ns++;
    w->nchan[w->sens[k]]++;
  }
  return ns;
}

static unit_set make_set(outl_work *w, size_t n) {
  unit_set s;
  s.n = n;
  s.err = w->buf;
  s.chi = w->buf + n;
  s.oth = w->buf + 2 * n;
  s.work = w->buf + 3 * n;
  s.nx = w->nx;
  return s;
}

/* Which channels stand out among all channels (w->chan_out). */
static void flag_channels(const rcb_compare *c, outl_work *w, int by_chi2) {
  unit_set s = make_set(w, c->nch);
  rcb_compare_outlier scratch;
  size_t k;
  set_figures(&s, w->cu);
  for (k = 0; k < c->nch; k++) w->chan_out[k] = judge(&s, k, by_chi2, &scratch);
}

/* Sensors named: the rule against the other sensors, unless the sensor has
 * several channels and only one of them stands out among the channels (a
 * gain, phase or mounting fault shows on every channel of the sensor; one
 * channel alone is its cable, connector or reference: named as a channel). */
static void name_sensors(rcb_compare *c, outl_work *w, size_t ns, int by_chi2) {
  unit_set s = make_set(w, ns);
  size_t k, j, first, nout;
  set_figures(&s, w->su);
  for (k = 0; k < ns; k++) {
    rcb_compare_outlier *o = &c->outl[c->noutl];
    if (!(w->named[k] = judge(&s, k, by_chi2, o))) continue;
    for (j = 0, first = c->nch, nout = 0; j < c->nch; j++) {
      if (w->sens[j] != k) continue;
      if (first == c->nch) first = j;
      nout += w->chan_out[j] != 0;
    }
    if (w->nchan[k] >= 2 && nout == 1) {
      w->named[k] = 0;
      continue;
    }
    o->response = c->resp[first];
    c->noutl++;
  }
}

/* Channels named: standing out among the channels, of a sensor with several
 * channels that is not named itself. */
static void name_channels(rcb_compare *c, outl_work *w, int by_chi2) {
  unit_set s = make_set(w, c->nch);
  size_t k;
  set_figures(&s, w->cu);
  for (k = 0; k < c->nch && c->noutl < c->nch; k++) {
    rcb_compare_outlier *o = &c->outl[c->noutl];
    if (!w->chan_out[k] || w->nchan[w->sens[k]] < 2 || w->named[w->sens[k]]) continue;
    judge(&s, k, by_chi2, o); /* fills o (it stands out: flag_channels) */
    o->response = c->resp[k];
    o->reference = c->ref[k];
    c->noutl++;
  }
}

rcb_status rcb_cmp_outliers(rcb_compare *c) {
  outl_work w;
  size_t k, ns;
  int by_chi2 = c->sd != NULL;
  rcb_status st;
  c->noutl = 0;
  if ((st = work_alloc(c, &w))) {
    work_free(c, &w);
    return st;
  }
  ns = group_sensors(c, &w);
  for (k = 0; k < c->nch; k++) {
    unit_sums *su = &w.su[w.sens[k]];
    channel_sums(c, k, &w.cu[k]);
    su->num += w.cu[k].num, su->den += w.cu[k].den;
    su->x2 += w.cu[k].x2, su->nx += w.cu[k].nx;
    if (!w.cu[k].nx) by_chi2 = 0; /* chi2/dof only when every channel has sds */
  }
  flag_channels(c, &w, by_chi2);
  name_sensors(c, &w, ns, by_chi2);
  name_channels(c, &w, by_chi2);
  work_free(c, &w);
  return RCB_OK;
}

size_t rcb_compare_outlier_count(const rcb_compare *c) { return c && c->done ? c->noutl : 0; }

rcb_status rcb_compare_get_outlier(const rcb_compare *c, size_t i, rcb_compare_outlier *out) {
  if (!c || !out || !c->done || i >= c->noutl) return RCB_ERR_ARG;
  *out = c->outl[i];
  return RCB_OK;
}
