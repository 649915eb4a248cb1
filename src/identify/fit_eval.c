/*
 * Residuals of eq. 12 and their sensitivities: analytic (eq. 9,
 * dH/dp = -Z^-1 dZ/dp Z^-1, with the factorisation of each frequency reused
 * for all parameters at once) or by finite differences with the paper's step
 * rule (eq. 11).
 */
#include <float.h>
#include <math.h>
#include <string.h>

#include "identify/fit_internal.h"
#include "io/io.h"

double rcb_fit_sumsq(const double *r, size_t n) {
  double s = 0.0;
  size_t i;
  for (i = 0; i < n; i++) s += r[i] * r[i];
  return s;
}

/* |h|^2, when |h| is within hypot-free range (1e-154 .. 1e154), else -1:
 * the residuals' moduli then come from |h|^2 with one sqrt or log, not a
 * hypot each (cabs: 5 % of a diagnosis of 32 x 1101, issue #23). */
static double mod2(double complex h) {
  double re = creal(h), im = cimag(h), a2 = re * re + im * im;
  return a2 >= DBL_MIN && a2 <= DBL_MAX ? a2 : -1.0;
}

/* |h| (cabs outside mod2's range). */
static double modulus(double complex h) {
  double a2 = mod2(h);
  return a2 >= 0 ? sqrt(a2) : cabs(h);
}

/* Value of H on the fit's scale (part 1: imaginary, complex scale only). */
static double on_scale(rcb_fit_scale s, double complex h, int part) {
  double a2 = s == RCB_SCALE_COMPLEX ? 0.0 : mod2(h);
  switch (s) {
    case RCB_SCALE_LOG10: return a2 >= 0 ? 0.5 * log10(a2) : log10(cabs(h));
    case RCB_SCALE_DB: return a2 >= 0 ? 10.0 * log10(a2) : 20.0 * log10(cabs(h));
    case RCB_SCALE_COMPLEX: return part ? cimag(h) : creal(h);
    default: return a2 >= 0 ? sqrt(a2) : cabs(h);
  }
}

/* Derivative of on_scale(H) along dH: d|H| = Re(conj(H) dH) / |H|, so that
 * the log scales' d log|H| = Re(conj(H) dH) / |H|^2 need no modulus. */
static double on_scale_d(rcb_fit_scale s, double complex h, double complex dh, int part) {
  double a2, a, g, p;
  if (s == RCB_SCALE_COMPLEX) return part ? cimag(dh) : creal(dh);
  p = creal(h) * creal(dh) + cimag(h) * cimag(dh); /* Re(conj(H) dH) */
  a2 = mod2(h);
  if (a2 >= 0) {
    switch (s) {
      case RCB_SCALE_LOG10: return p / (a2 * log(10.0));
      case RCB_SCALE_DB: return 20.0 * p / (a2 * log(10.0));
      default: return p / sqrt(a2);
    }
  }
  a = cabs(h), g = a > 0 ? p / a : 0.0; /* d|H| */
  switch (s) {
    case RCB_SCALE_LOG10: return a > 0 ? g / (a * log(10.0)) : 0.0;
    case RCB_SCALE_DB: return a > 0 ? 20.0 * g / (a * log(10.0)) : 0.0;
    default: return g;
  }
}

/* Variance of a measured value on the scale under the eq. 19 noise model:
 * proportional part (beta_a |e| r1, r1 uniform: variance 1/3) and additive
 * part of amplitude a (random phase: 1/6 per component); with a phase term
 * (e turned by theta uniform in +-phase rad: i e theta to first order) the
 * complex scale's parts gain phase^2 / 3 times the other part squared
 * (the modulus, and so the other scales, are unchanged). */
static double noise_var(const rcb_fit *f, double complex e, double a, int part) {
  double ba = f->beta_a / 100.0, mag = modulus(e), v;
  if (f->scale == RCB_SCALE_COMPLEX) {
    double c = part ? cimag(e) : creal(e), o = part ? creal(e) : cimag(e);
    return ba * ba * c * c / 3.0 + a * a / 6.0 + f->phase * f->phase * o * o / 3.0;
  }
  v = ba * ba * mag * mag / 3.0 + a * a / 6.0;
  if (f->scale == RCB_SCALE_LINEAR) return v;
  v /= mag * mag * log(10.0) * log(10.0);
  return f->scale == RCB_SCALE_DB ? 400.0 * v : v;
}

double rcb_fit_noise_level(const rcb_fit *f, size_t c) {
  rcb_meas_channel_info ci;
  double s2 = 0.0;
  size_t i;
  rcb_meas_channel(f->meas, c, &ci);
  if (!f->nref) return rcb_noise_level(ci.data, f->npts, f->beta_s);
  /* eq. 19's ||f||_2 / n over the channel: the reference where it has a
   * value, the measured value where it has none (out of the band) */
  for (i = 0; i < f->npts; i++) {
    double complex h = f->nref[c * f->npts + i];
    if (!isfinite(creal(h)) || !isfinite(cimag(h))) h = ci.data[i];
    s2 += creal(h * conj(h));
  }
  return f->npts ? sqrt(s2) / (double)f->npts * (f->beta_s / 100.0) : 0.0;
}

double rcb_fit_log_bias(const rcb_fit *f) {
  double b = f->beta_a / 100.0, m;
  if (!(f->scale == RCB_SCALE_LOG10 || f->scale == RCB_SCALE_DB) || !(b > 0)) return 0.0;
  /* E ln(1 + b r1), r1 uniform in [-1, 1] (b < 1); -b^2/6 to second order */
  m = b < 1e-4 ? -b * b / 6.0
               : ((1.0 + b) * log1p(b) - (1.0 - b) * log1p(-b)) / (2.0 * b) - 1.0;
  return (f->scale == RCB_SCALE_DB ? 20.0 : 1.0) * m / log(10.0);
}

/* Variance on the scale of a measured value e whose Re and Im (and so |e|)
 * have the known standard deviation sd (rcb_fit_set_sd), to first order. */
static double sd_var(rcb_fit_scale s, double complex e, double sd) {
  double v = sd * sd, mag = modulus(e);
  if (s == RCB_SCALE_LINEAR || s == RCB_SCALE_COMPLEX) return v;
  v /= mag * mag * log(10.0) * log(10.0);
  return s == RCB_SCALE_DB ? 400.0 * v : v;
}

/* Weight of point (c, i) before the noise model, 0 when left out. */
static double base_weight(const rcb_fit *f, size_t c, size_t i, double complex e) {
  double w = f->wuser ? f->wuser[c * f->npts + i] : 1.0;
  if (f->grid[i] < f->band_lo || f->grid[i] > f->band_hi) return 0.0;
  if (!isfinite(creal(e)) || !isfinite(cimag(e))) return 0.0;
  if ((f->scale == RCB_SCALE_LOG10 || f->scale == RCB_SCALE_DB) && cabs(e) == 0.0) return 0.0;
  /* a known sd of 0 or NaN would be an infinite or undefined weight: dropped */
  if (f->sd && !(f->sd[c * f->npts + i] > 0 && isfinite(f->sd[c * f->npts + i]))) return 0.0;
  return w;
}

/* A reference farther from the measured value than this many of the
 * declared noise's standard deviations (of the modulus of the difference)
 * is a misfit, not noise: the measured value is then the better estimate of
 * the true one, and the noise model is evaluated there (issue #33). Eq. 19
 * moves a value by at most 1.7 of them (r1, r2 bounded), so the choice never
 * follows the noise; with a model far off (a seal at 88 % error) the
 * reference alone gave weights for values the data do not have. */
#define RCB_NOISE_REF_SD 4.0

double complex rcb_fit_noise_value(const rcb_fit *f, size_t c, size_t i, double a) {
  rcb_meas_channel_info ci;
  double complex e, h;
  double ba = f->beta_a / 100.0, v;
  rcb_meas_channel(f->meas, c, &ci);
  e = ci.data[i];
  if (!f->nref || !(f->beta_a > 0 || f->beta_s > 0)) return e;
  h = f->nref[c * f->npts + i];
  if (!isfinite(creal(h)) || !isfinite(cimag(h))) return h;
  v = (ba * ba + f->phase * f->phase) * creal(h * conj(h)) / 3.0 + a * a / 3.0;
  return creal((e - h) * conj(e - h)) > RCB_NOISE_REF_SD * RCB_NOISE_REF_SD * v ? e : h;
}

/* Walk every residual; fill the layout when fill != 0. Returns the count.
 * The noise model's variances, the channel's additive level a and the floor
 * gate are evaluated at the reference (rcb_fit_set_noise_reference) when one
 * is set: a weight or a gate computed from the measured value correlates
 * with that value's own noise (a value pulled towards zero weighs more, one
 * pushed above the gate is kept), which biases F and every comparison made
 * on it (issue #33). On the log scales the measured value is moved by the
 * declared noise's mean on that scale (rcb_fit_log_bias). */
static size_t layout(rcb_fit *f, int fill) {
  size_t c, i, n = 0;
  int part, nparts = f->scale == RCB_SCALE_COMPLEX ? 2 : 1;
  int noisy = f->beta_a > 0 || f->beta_s > 0;
  double bias = noisy ? rcb_fit_log_bias(f) : 0.0;
  for (c = 0; c < f->nch; c++) {
    rcb_meas_channel_info ci;
    double a = rcb_fit_noise_level(f, c); /* eq. 19 additive amplitude */
    rcb_meas_channel(f->meas, c, &ci);
    for (i = 0; i < f->npts; i++) {
      double complex e = ci.data[i], v = rcb_fit_noise_value(f, c, i, a);
      double w = base_weight(f, c, i, e);
      if (w == 0.0) continue;
      if (!isfinite(creal(v)) || !isfinite(cimag(v))) continue; /* no reference there */
      /* points at the additive noise floor carry no information on the model */
      if (noisy && modulus(v) < 2.0 * a) continue;
      for (part = 0; part < nparts; part++, n++) {
        double wp = noisy     ? w / noise_var(f, v, a, part)
                    : f->sd ? w / sd_var(f->scale, e, f->sd[c * f->npts + i])
                            : w;
        if (!fill) continue;
        f->res_ch[n] = c;
        f->res_pt[n] = i;
        f->res_part[n] = (unsigned char)part;
        f->res_sqrtw[n] = sqrt(wp);
        f->res_meas[n] = on_scale(f->scale, e, part) - bias;
        f->pt_used[i] = 1;
      }
    }
  }
  return n;
}

/* The residuals of each point (counting sort of res_pt), so that a
 * per-point pass touches only its own residuals. */
static void index_points(rcb_fit *f) {
  size_t i, j;
  memset(f->pt_first, 0, (f->npts + 1) * sizeof *f->pt_first);
  for (j = 0; j < f->nres; j++) f->pt_first[f->res_pt[j] + 1]++;
  for (i = 0; i < f->npts; i++) f->pt_first[i + 1] += f->pt_first[i];
  for (j = f->nres; j-- > 0;) f->pt_res[--f->pt_first[f->res_pt[j] + 1]] = j;
  /* pt_first[i + 1] now holds the start of point i: shift back */
  for (i = 0; i < f->npts; i++) f->pt_first[i] = f->pt_first[i + 1];
  f->pt_first[f->npts] = f->nres;
}

rcb_status rcb_fit_prepare(rcb_fit *f) {
  size_t n, sz, ncol;
  if (f->prepared) return RCB_OK;
  n = layout(f, 0);
  if (n == 0)
    return rcb_fit_fail(f, RCB_ERR_ARG,
                        "no measured point left to fit (check the band, the weights and the "
                        "noise floor)");
  rcb_fit_free_layout(f);
  sz = rcb_layout_size(rcb_frf_layout(f->frf));
  ncol = f->np * (f->nin ? f->nin : 1);
  f->res_ch = rcb_alloc(&f->alloc, n * sizeof *f->res_ch);
  f->res_pt = rcb_alloc(&f->alloc, n * sizeof *f->res_pt);
  f->res_part = rcb_alloc(&f->alloc, n);
  f->res_sqrtw = rcb_alloc(&f->alloc, n * sizeof *f->res_sqrtw);
  f->res_meas = rcb_alloc(&f->alloc, n * sizeof *f->res_meas);
  f->pt_used = rcb_alloc(&f->alloc, f->npts);
  f->r = rcb_alloc(&f->alloc, 2 * n * sizeof *f->r);
  f->J = rcb_alloc(&f->alloc, n * (f->np ? f->np : 1) * sizeof *f->J);
  f->dmat = rcb_alloc(&f->alloc, 4 * sz * (f->np + 1) * sizeof *f->dmat);
  f->dF = rcb_alloc(&f->alloc, f->m->ndof * (f->np + 1) * sizeof *f->dF);
  f->rhs = rcb_alloc(&f->alloc, f->m->ndof * (ncol ? ncol : 1) * sizeof *f->rhs);
  f->cov = rcb_alloc(&f->alloc, (f->np ? f->np * f->np : 1) * sizeof *f->cov);
  f->corr = rcb_alloc(&f->alloc, (f->np ? f->np * f->np : 1) * sizeof *f->corr);
  f->pt_first = rcb_alloc(&f->alloc, (f->npts + 1) * sizeof *f->pt_first);
  f->pt_res = rcb_alloc(&f->alloc, n * sizeof *f->pt_res);
  if (!f->res_ch || !f->res_pt || !f->res_part || !f->res_sqrtw || !f->res_meas ||
      !f->pt_used || !f->r || !f->J || !f->dmat || !f->dF || !f->rhs || !f->cov || !f->corr ||
      !f->pt_first || !f->pt_res) {
    rcb_fit_free_layout(f);
    return rcb_fit_fail(f, RCB_ERR_NOMEM, "out of memory sizing the fit");
  }
  f->nres = layout(f, 1);
  index_points(f);
  f->wmodel = 0; /* the weights at the measured values (fit.c may move them to the model) */
  f->prepared = 1;
  return RCB_OK;
}

/* ---- parameters <-> internal coordinates ---- */

double rcb_fit_x_of(const rcb_fit *f, size_t k, double v) {
  return f->par[k].log_param ? log(v) : v / f->par[k].scale;
}

void rcb_fit_get_x(const rcb_fit *f, double *x) {
  size_t k;
  for (k = 0; k < f->np; k++) x[k] = rcb_fit_x_of(f, k, rcb_fit_par_get(f, k));
}

/* The model is evaluated at x projected onto the bounds (the optimisers'
 * penalty or NLopt keep x itself honest). */
rcb_status rcb_fit_set_x(rcb_fit *f, const double *x) {
  size_t k;
  rcb_status st;
  for (k = 0; k < f->np; k++) {
    const rcb_fit_par *p = &f->par[k];
    double v = p->log_param ? exp(x[k]) : x[k] * p->scale;
    if (!(v >= p->lo)) v = p->lo;
    if (v > p->hi) v = p->hi;
    if ((st = rcb_fit_par_set(f, k, v))) return st;
  }
  return rcb_frf_refresh(f->frf);
}

/* ---- model values ---- */

static double complex kind_factor(rcb_frf_kind kind, double w) {
  if (kind == RCB_MOBILITY) return CMPLX(0.0, w);
  if (kind == RCB_INERTANCE) return -w * w;
  return 1.0;
}

/* Solve the model at point i: leaves the factors in the FRF workspace and
 * the solution vectors in its B; fills Hmod for every channel. */
rcb_status rcb_fit_solve_point(rcb_fit *f, size_t i) {
  double w = f->grid[i];
  size_t c;
  rcb_status st;
  if (f->unbalance) {
    st = rcb_frf_unbalance(f->frf, w, f->Hwork);
  } else {
    st = rcb_frf_eval(f->frf, w, f->speed < 0 ? w : f->speed, RCB_RECEPTANCE, f->Hwork);
  }
  if (st) return rcb_fit_fail(f, st, "model at %g rad/s: %s", w, rcb_frf_errmsg(f->frf));
  for (c = 0; c < f->nch; c++) {
    size_t o = f->ch_out[c], in = f->unbalance ? 0 : f->ch_in[c]; /* o: after any swap */
    f->Hraw[c * f->npts + i] =
        f->Hwork[o + f->nout * in] * (f->unbalance ? 1.0 : kind_factor(f->ch_kind[c], w));
    f->Hmod[c * f->npts + i] = f->ch_fac[c] * f->Hraw[c * f->npts + i];
  }
  return RCB_OK;
}

static void residuals_from_model(const rcb_fit *f, double *r) {
  size_t j;
  for (j = 0; j < f->nres; j++) {
    double complex h = f->Hmod[f->res_ch[j] * f->npts + f->res_pt[j]];
    r[j] = f->res_sqrtw[j] * (on_scale(f->scale, h, f->res_part[j]) - f->res_meas[j]);
  }
}

rcb_status rcb_fit_eval(rcb_fit *f, double *r) {
  size_t i;
  rcb_status st;
  for (i = 0; i < f->npts; i++)
    if (f->pt_used[i] && (st = rcb_fit_solve_point(f, i))) return st;
  residuals_from_model(f, r);
  f->evaluations++;
  f->sweeps++;
  return RCB_OK;
}

rcb_status rcb_fit_last_residuals(rcb_fit *f, double *r) {
  if (!f || !r) return RCB_ERR_ARG;
  if (!f->prepared || !f->sweeps)
    return rcb_fit_fail(f, RCB_ERR_STATE, "residuals: no evaluation of the model yet");
  residuals_from_model(f, r);
  return RCB_OK;
}

/* The channel of src that reads output o with input q and kind k (src
 * unswapped: its channels read their own outputs); nch when none. */
static size_t same_channel(const rcb_fit *src, size_t o, size_t q, rcb_frf_kind k) {
  size_t c;
  for (c = 0; c < src->nch; c++)
    if (src->ch_out[c] == o && (src->unbalance || src->ch_in[c] == q) && src->ch_kind[c] == k)
      return c;
  return src->nch;
}

rcb_status rcb_fit_residuals_from(rcb_fit *f, const rcb_fit *src, double *r) {
  size_t c, i, *from;
  rcb_status st;
  if (!f || !src || !r) return RCB_ERR_ARG;
  if (!src->prepared || !src->sweeps || src->meas != f->meas || src->npts != f->npts ||
      src->nout != f->nout || src->nin != f->nin || src->unbalance != f->unbalance)
    return RCB_ERR_STATE;
  for (c = 0; c < src->nch; c++)
    if (src->ch_out[c] != src->sens[src->ch_sens[c]].out) return RCB_ERR_STATE; /* swapped */
  if ((st = rcb_fit_prepare(f))) return st;
  for (i = 0; i < f->npts; i++)
    if (f->pt_used[i] && !src->pt_used[i]) return RCB_ERR_STATE;
  if (!(from = rcb_alloc(&f->alloc, (f->nch ? f->nch : 1) * sizeof *from))) return RCB_ERR_NOMEM;
  for (c = 0; c < f->nch; c++) {
    from[c] = same_channel(src, f->ch_out[c], f->ch_in[c], f->ch_kind[c]);
    if (from[c] == src->nch) {
      rcb_free(&f->alloc, from);
      return RCB_ERR_STATE;
    }
  }
  for (c = 0; c < f->nch; c++)
    for (i = 0; i < f->npts; i++) {
      if (!f->pt_used[i]) continue;
      f->Hraw[c * f->npts + i] = src->Hraw[from[c] * f->npts + i];
      f->Hmod[c * f->npts + i] = f->ch_fac[c] * f->Hraw[c * f->npts + i];
    }
  rcb_free(&f->alloc, from);
  residuals_from_model(f, r);
  f->evaluations++;
  return RCB_OK;
}

rcb_status rcb_fit_residual_channels(const rcb_fit *f, size_t *ch) {
  return ch ? rcb_fit_residual_layout(f, ch, NULL, NULL, NULL) : RCB_ERR_ARG;
}

rcb_status rcb_fit_residual_layout(const rcb_fit *f, size_t *ch, size_t *pt, unsigned char *part,
                                   double *sqrtw) {
  if (!f) return RCB_ERR_ARG;
  if (!f->res_ch && f->nres) return RCB_ERR_STATE;
  if (!f->nres) return RCB_OK;
  if (ch) memcpy(ch, f->res_ch, f->nres * sizeof *ch);
  if (pt) memcpy(pt, f->res_pt, f->nres * sizeof *pt);
  if (part) memcpy(part, f->res_part, f->nres);
  if (sqrtw) memcpy(sqrtw, f->res_sqrtw, f->nres * sizeof *sqrtw);
  return RCB_OK;
}

double rcb_fit_error_pct(const rcb_fit *f) {
  double num = 0.0, den = 0.0;
  size_t j;
  for (j = 0; j < f->nres; j++) {
    rcb_meas_channel_info ci;
    double em, mm;
    if (f->res_part[j]) continue;
    rcb_meas_channel(f->meas, f->res_ch[j], &ci);
    em = modulus(ci.data[f->res_pt[j]]);
    mm = modulus(f->Hmod[f->res_ch[j] * f->npts + f->res_pt[j]]);
    num += (mm - em) * (mm - em);
    den += em * em;
  }
  return den > 0 ? 100.0 * sqrt(num / den) : (double)NAN;
}

int rcb_fit_chi2(const rcb_fit *f) { return f->beta_a > 0 || f->beta_s > 0 || f->sd; }

double rcb_fit_floor_pct(const rcb_fit *f) {
  double num = 0.0, den = 0.0, ba = f->beta_a / 100.0;
  size_t j, c, i;
  if (f->sd) { /* the known deviations: sd^2 is the variance of |e| too */
    for (j = 0; j < f->nres; j++) {
      rcb_meas_channel_info ci;
      double sd;
      if (f->res_part[j]) continue;
      rcb_meas_channel(f->meas, f->res_ch[j], &ci);
      sd = f->sd[f->res_ch[j] * f->npts + f->res_pt[j]];
      num += sd * sd;
      den += creal(ci.data[f->res_pt[j]] * conj(ci.data[f->res_pt[j]]));
    }
    return den > 0 ? 100.0 * sqrt(num / den) : (double)NAN;
  }
  if (!(f->beta_a > 0 || f->beta_s > 0)) return (double)NAN;
  for (c = 0; c < f->nch; c++) {
    rcb_meas_channel_info ci;
    double s2 = 0.0, a;
    rcb_meas_channel(f->meas, c, &ci);
    for (i = 0; i < f->npts; i++) s2 += creal(ci.data[i] * conj(ci.data[i]));
    a = f->beta_s / 100.0 * sqrt(s2) / (double)f->npts;
    for (j = 0; j < f->nres; j++) {
      double em;
      if (f->res_part[j] || f->res_ch[j] != c) continue;
      em = modulus(ci.data[f->res_pt[j]]);
      /* magnitude variance: proportional part uniform (1/3), additive part
       * of random phase (1/6) */
      num += ba * ba * em * em / 3.0 + a * a / 6.0;
      den += em * em;
    }
  }
  return den > 0 ? 100.0 * sqrt(num / den) : (double)NAN;
}

/* ---- sensitivities ---- */

static double dpdx(const rcb_fit *f, size_t k) {
  return f->par[k].log_param ? rcb_fit_par_get(f, k) : f->par[k].scale;
}

/* Forward differences with the paper's step rule, eq. 11. */
static rcb_status jac_fd(rcb_fit *f, double *r, double *Jx) {
  double *r2 = f->r + f->nres;
  size_t k, j;
  rcb_status st;
  if ((st = rcb_fit_eval(f, r))) return st;
  for (k = 0; k < f->np; k++) {
    double p = rcb_fit_par_get(f, k), dp, g = dpdx(f, k);
    dp = fabs(p) < 1e-6 ? 1e-9 : 1e-3 * fabs(p);
    /* a sensor's phase at its neutral 0 would get the 1e-9 of a vanishing
     * model parameter: too small a step for a quantity of order 1 rad */
    if (f->par[k].chain == RCB_CHAIN_PHASE && fabs(p) < 1e-3) dp = 1e-6;
    if ((st = rcb_fit_par_set(f, k, p + dp))) return st;
    rcb_frf_refresh(f->frf);
    st = rcb_fit_eval(f, r2);
    rcb_fit_par_set(f, k, p);
    rcb_frf_refresh(f->frf);
    if (st) return st;
    for (j = 0; j < f->nres; j++) Jx[j + f->nres * k] = (r2[j] - r[j]) / dp * g;
  }
  return rcb_fit_eval(f, r); /* Hmod back to the unperturbed model */
}

/* Matrices and unbalance force (at unit speed) of the whole model in the FRF
 * layout, bearings included. */
static void full_system(rcb_fit *f, double *A, rcb_complex *F1) {
  const rcb_layout *L = rcb_frf_layout(f->frf);
  size_t sz = rcb_layout_size(L), b;
  int e;
  rcb_assemble_structure(f->m, L, A, A + sz, A + 2 * sz, A + 3 * sz);
  for (b = 0; b < f->m->n_bearings; b++) {
    rcb_entry en[RCB_BEARING_ENTRIES_MAX];
    int ne = (int)rcb_bearing_entries(f->m, b, 0.0, en);
    for (e = 0; e < ne; e++) {
      A[sz + rcb_layout_at(L, en[e].row, en[e].col)] += en[e].c;
      A[3 * sz + rcb_layout_at(L, en[e].row, en[e].col)] += en[e].k;
    }
  }
  rcb_model_unbalance_force(f->m, 1.0, F1);
}

/* dM, dC, dG, dK and dF/dp per parameter: every fittable parameter enters the
 * matrices affinely, so a forward difference of any size is exact there; the
 * unbalance phase enters F through e^{i phase}, hence a small central step. */
rcb_status rcb_fit_derivative_matrices(rcb_fit *f) {
  size_t sz = 4 * rcb_layout_size(rcb_frf_layout(f->frf)), n = f->m->ndof, k, i;
  double *base = f->dmat + f->np * sz;
  rcb_complex *F0 = f->dF + f->np * n, *Fk;
  rcb_status st;
  full_system(f, base, F0);
  for (k = 0; k < f->np; k++) {
    const char *name = f->par[k].name;
    double *dk = f->dmat + k * sz, p, h;
    Fk = f->dF + k * n;
    if (f->par[k].chain) { /* not in the model: its column is rcb_fit_chain_columns' */
      memset(dk, 0, sz * sizeof *dk);
      for (i = 0; i < n; i++) Fk[i] = 0.0;
      continue;
    }
    rcb_model_get_param(f->m, name, &p);
    h = strncmp(name, "unbalance.", 10) == 0 ? 1e-6 * (fabs(p) > 1e-3 ? fabs(p) : 1e-3)
                                             : (p != 0.0 ? 1e-3 * fabs(p) : 1e-3);
    if ((st = rcb_model_set_param(f->m, name, p + h))) goto fail;
    full_system(f, dk, Fk);
    if (strncmp(name, "unbalance.", 10) == 0) {
      if ((st = rcb_model_set_param(f->m, name, p - h))) goto fail;
      full_system(f, dk, F0); /* F0 reused as scratch, rebuilt below */
      for (i = 0; i < n; i++) Fk[i] = (Fk[i] - F0[i]) / (2 * h);
      memset(dk, 0, sz * sizeof *dk);
      rcb_model_set_param(f->m, name, p);
      full_system(f, base, F0);
      continue;
    }
    rcb_model_set_param(f->m, name, p);
    for (i = 0; i < sz; i++) dk[i] = (dk[i] - base[i]) / h;
    for (i = 0; i < n; i++) Fk[i] = 0.0;
  }
  return RCB_OK;
fail:
  return rcb_fit_fail(f, st, "sensitivity of %s: %s", f->par[k].name, rcb_model_errmsg(f->m));
}

/* y = dZ x with dZ = dK - w^2 dM + i w (dC + W dG), over the layout's band. */
static void dz_times(const rcb_layout *L, const double *d, double w, double W,
                     const rcb_complex *x, rcb_complex *y) {
  size_t sz = rcb_layout_size(L), i, j, n = L->n;
  memset(y, 0, n * sizeof *y);
  if (L->sparse) { /* CSC: entry a of column j is on row rowi[a] */
    for (j = 0; j < n; j++) {
      size_t a;
      if (x[j] == 0.0) continue;
      for (a = (size_t)L->colp[j]; a < (size_t)L->colp[j + 1]; a++) {
        double complex z =
            CMPLX(d[3 * sz + a] - w * w * d[a], w * (d[sz + a] + W * d[2 * sz + a]));
        y[L->rowi[a]] += z * x[j];
      }
    }
    return;
  }
  for (j = 0; j < n; j++) {
    size_t i0 = j > L->ku ? j - L->ku : 0, i1 = j + L->kl < n ? j + L->kl : n - 1;
    if (x[j] == 0.0) continue;
    for (i = i0; i <= i1; i++) {
      size_t a = rcb_layout_at(L, i, j);
      double complex z = CMPLX(d[3 * sz + a] - w * w * d[a], w * (d[sz + a] + W * d[2 * sz + a]));
      y[i] += z * x[j];
    }
  }
}

double rcb_fit_point_speed(const rcb_fit *f, double w) {
  /* unbalance: the speed factor is divided out as in rcb_frf_unbalance */
  return f->unbalance ? w / f->m->speed_factor : (f->speed < 0 ? w : f->speed);
}

double rcb_fit_res_deriv_pred(const rcb_fit *f, size_t j, double complex dP) {
  size_t c = f->res_ch[j], i = f->res_pt[j];
  return f->res_sqrtw[j] * on_scale_d(f->scale, f->Hmod[c * f->npts + i], dP, f->res_part[j]);
}

double rcb_fit_res_deriv(const rcb_fit *f, size_t j, double complex dh) {
  size_t c = f->res_ch[j], i = f->res_pt[j];
  if (!f->unbalance) dh *= kind_factor(f->ch_kind[c], f->grid[i]);
  return rcb_fit_res_deriv_pred(f, j, f->ch_fac[c] * dh); /* the chain's factor */
}

double complex rcb_fit_res_coef(const rcb_fit *f, size_t j) {
  size_t c = f->res_ch[j], i = f->res_pt[j];
  double complex h = f->Hmod[c * f->npts + i], g = f->ch_fac[c] * f->res_sqrtw[j];
  double a2, a;
  if (!f->unbalance) g *= kind_factor(f->ch_kind[c], f->grid[i]);
  if (f->scale == RCB_SCALE_COMPLEX) return f->res_part[j] ? CMPLX(cimag(g), -creal(g)) : g;
  /* d|H| = Re(conj(H) dH) / |H|: g conj(H) over |H|, or |H|^2 ln 10 (log10) */
  g *= conj(h);
  a2 = mod2(h);
  a = a2 >= 0 ? sqrt(a2) : cabs(h);
  if (!(a > 0)) return 0.0;
  if (a2 < 0) a2 = a * a;
  switch (f->scale) {
    case RCB_SCALE_LOG10: return g / (a2 * log(10.0));
    case RCB_SCALE_DB: return g * (20.0 / (a2 * log(10.0)));
    default: return g / a;
  }
}

/* Analytic Jacobian, eq. 9, one point: X = Z^-1 B (kept by the solve), then
 * dX/dp_k = Z^-1 (dF_k - dZ_k X), all parameters and inputs in one re-solve
 * with the point's factorisation (rcb_frf_solve_again). */
static rcb_status jac_point(rcb_fit *f, size_t i, double *Jx) {
  const rcb_layout *L = rcb_frf_layout(f->frf);
  size_t n = f->m->ndof, nin = f->nin ? f->nin : 1, k, q, jj, sz = 4 * rcb_layout_size(L);
  double w = f->grid[i], W = rcb_fit_point_speed(f, w);
  rcb_status st;
  for (k = 0; k < f->np; k++)
    for (q = 0; q < nin; q++) {
      rcb_complex *y = f->rhs + n * (k * nin + q);
      const rcb_complex *x = rcb_frf_solution(f->frf, q);
      size_t d;
      if (!x) return rcb_fit_fail(f, RCB_ERR_STATE, "no model solution at %g rad/s", w);
      if (f->par[k].chain) { /* no dZ: rcb_fit_chain_columns fills its column */
        memset(y, 0, n * sizeof *y);
        continue;
      }
      dz_times(L, f->dmat + k * sz, w, W, x, y);
      for (d = 0; d < n; d++) y[d] = -y[d] + (f->unbalance ? w * w * f->dF[k * n + d] : 0.0);
    }
  st = rcb_frf_solve_again(f->frf, f->rhs, f->np * nin);
  if (st)
    return rcb_fit_fail(f, st, "sensitivity solve at %g rad/s: %s", w, rcb_frf_errmsg(f->frf));
  for (jj = f->pt_first[i]; jj < f->pt_first[i + 1]; jj++) {
    size_t j = f->pt_res[jj], c = f->res_ch[j], row = rcb_frf_output_row(f->frf, f->ch_out[c]);
    for (k = 0; k < f->np; k++) {
      size_t col = k * nin + (f->unbalance ? 0 : f->ch_in[c]);
      Jx[j + f->nres * k] = rcb_fit_res_deriv(f, j, f->rhs[n * col + row]);
    }
  }
  return RCB_OK;
}

static rcb_status jac_analytic(rcb_fit *f, double *r, double *Jx) {
  size_t i, k, j;
  rcb_status st;
  if ((st = rcb_fit_derivative_matrices(f))) return st;
  if (rcb_fit_adjoint_cheaper(f)) { /* many inputs: eq. 9 by the adjoint (fit_score.c) */
    if ((st = rcb_fit_jac_adjoint(f, Jx))) return st;
  } else {
    for (i = 0; i < f->npts; i++) {
      if (!f->pt_used[i]) continue;
      if ((st = rcb_fit_solve_point(f, i)) || (st = jac_point(f, i, Jx))) return st;
    }
  }
  residuals_from_model(f, r);
  rcb_fit_chain_columns(f, Jx);
  f->evaluations++;
  f->sweeps++;
  for (k = 0; k < f->np; k++) {
    double g = dpdx(f, k);
    for (j = 0; j < f->nres; j++) Jx[j + f->nres * k] *= g;
  }
  return RCB_OK;
}

rcb_status rcb_fit_eval_jac(rcb_fit *f, double *r, double *Jx) {
  return f->analytic ? jac_analytic(f, r, Jx) : jac_fd(f, r, Jx);
}

rcb_status rcb_fit_objective(rcb_fit *f, const double *x, double *F, double *grad) {
  rcb_status st;
  size_t k, j;
  if ((st = rcb_fit_set_x(f, x))) return st;
  if (!grad) {
    if ((st = rcb_fit_eval(f, f->r))) return st;
  } else {
    if ((st = rcb_fit_eval_jac(f, f->r, f->J))) return st;
    for (k = 0; k < f->np; k++) {
      double g = 0.0;
      for (j = 0; j < f->nres; j++) g += f->J[j + f->nres * k] * f->r[j];
      grad[k] = 2.0 * g;
    }
  }
  *F = rcb_fit_sumsq(f->r, f->nres);
  return RCB_OK;
}

/* For the adequacy test (adequacy.c): a value on the fit's scale, and the
 * variance of a measured value under the eq. 19 noise model (additive
 * amplitude a, the measurement's units). */
double rcb_fit_on_scale(const rcb_fit *f, double complex h, int part) {
  return on_scale(f->scale, h, part);
}
double rcb_fit_noise_var(const rcb_fit *f, double complex e, double a, int part) {
  return noise_var(f, e, a, part);
}
