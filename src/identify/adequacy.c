/*
 * The adequacy test of a fitted model (issue #23): does the model leave what
 * the noise alone leaves? rcb_identify.h states the test; here F's null mean
 * and variance, residual by residual.
 *
 * Known standard deviations: the weighted residual is N(0, 1), mean 1 and
 * variance 2 of its square. The eq. 19 noise model: the square's mean and
 * variance are drawn (RCB_ADEQ_DRAWS values of the noise on the model's
 * value at the residual's point, each weighted as the fit weights a measured
 * value, io/noise.c's generator), since on a log scale and with uniform
 * r1, r2 they are not 1 and 2 (uniform r1: the variance of the square is 0.8,
 * not 2) and the weight itself comes from the noisy value (or from the
 * model's value, when the fit moved its weights there: fit.c,
 * refit_at_model).
 */
#include <math.h>
#include <string.h>

#include "identify/fit_internal.h"
#include "io/io.h"

#define RCB_ADEQ_DRAWS 16
#define RCB_ADEQ_SEED UINT64_C(0x23ADE9)

/* Mean of the square of one standardized residual j (and of its Im part
 * j + 1 when the point has two: both drawn from the same noisy value), and
 * the variance of the point's sum of squares (its parts are correlated: the
 * weight of both comes from the one noisy value). a: the channel's additive
 * amplitude. Returns the parts used. */
static size_t draw_point(const rcb_fit *f, size_t j, double a, rcb_rng *rng, double *mean,
                         double *var) {
  size_t parts = (j + 1 < f->nres && f->res_part[j + 1] == 1 && f->res_pt[j + 1] == f->res_pt[j] &&
                  f->res_ch[j + 1] == f->res_ch[j])
                     ? 2
                     : 1;
  double complex h = f->Hmod[f->res_ch[j] * f->npts + f->res_pt[j]];
  double complex ref = f->nref ? rcb_fit_noise_value(f, f->res_ch[j], f->res_pt[j], a) : h;
  double bias = rcb_fit_log_bias(f);
  double wu = f->wuser ? f->wuser[f->res_ch[j] * f->npts + f->res_pt[j]] : 1.0;
  double s1[2] = {0, 0}, t1 = 0.0, t2 = 0.0;
  size_t k, p;
  for (k = 0; k < RCB_ADEQ_DRAWS; k++) {
    double complex e = rcb_noise_draw(rng, h, f->beta_a, a, f->phase);
    double t = 0.0;
    for (p = 0; p < parts; p++) {
      double z = rcb_fit_on_scale(f, e, (int)p) - bias - rcb_fit_on_scale(f, h, (int)p);
      double q = wu * z * z / rcb_fit_noise_var(f, f->nref || f->wmodel ? ref : e, a, (int)p);
      s1[p] += q, t += q;
    }
    t1 += t, t2 += t * t;
  }
  for (p = 0; p < parts; p++) mean[p] = s1[p] / RCB_ADEQ_DRAWS;
  *var = (t2 - t1 * t1 / RCB_ADEQ_DRAWS) / (RCB_ADEQ_DRAWS - 1);
  return parts;
}

/* The lag-1 statistic of the weighted residuals r along frequency (issue
 * #33): sum r_j r_j' over neighbouring used points j, j' of one channel and
 * part, over sqrt(sum (r_j r_j')^2). The products of independent residuals
 * have mean 0 whatever each point's variance, so the statistic is N(0, 1)
 * under any white noise, declared or not (a level 20 % off, another
 * distribution, a phase noise); a misfit that is smooth along frequency (an
 * effect the model lacks, a sensor's gain) correlates neighbours and drives
 * it up: an excess of F that the adequacy test sees at z = 2.3 gives about
 * z = 2.9 here when the misfit is smooth over the line spacing. */
double rcb_fit_white_z(const rcb_fit *f, const double *r) {
  double num = 0.0, den = 0.0;
  size_t j, prev[2] = {(size_t)-1, (size_t)-1}, c = (size_t)-1;
  for (j = 0; j < f->nres; j++) {
    unsigned p = f->res_part[j];
    if (f->res_ch[j] != c) c = f->res_ch[j], prev[0] = prev[1] = (size_t)-1;
    if (prev[p] != (size_t)-1) {
      double q = r[prev[p]] * r[j];
      num += q, den += q * q;
    }
    prev[p] = j;
  }
  return den > 0 ? num / sqrt(den) : 0.0;
}

rcb_status rcb_fit_get_adequacy(rcb_fit *f, rcb_fit_adequacy *out, double *chi2_ch,
                                double *expected_ch, double *sd_ch) {
  double *r, *level = NULL, F = 0.0, mean = 0.0, var = 0.0;
  rcb_rng rng;
  size_t j, c;
  rcb_status st;
  if (!f || !out) return RCB_ERR_ARG;
  memset(out, 0, sizeof *out);
  if ((st = rcb_fit_prepare(f))) return st;
  if (!(r = rcb_alloc(&f->alloc, (f->nres + 1) * sizeof *r)) ||
      !(level = rcb_alloc(&f->alloc, (f->nch + 1) * sizeof *level))) {
    rcb_free(&f->alloc, r);
    return rcb_fit_fail(f, RCB_ERR_NOMEM, "adequacy test: out of memory");
  }
  if ((st = rcb_fit_residuals(f, r))) goto done;
  if (chi2_ch) memset(chi2_ch, 0, f->nch * sizeof *chi2_ch);
  if (expected_ch) memset(expected_ch, 0, f->nch * sizeof *expected_ch);
  if (sd_ch) memset(sd_ch, 0, f->nch * sizeof *sd_ch); /* variances until the end */
  for (c = 0; c < f->nch; c++) level[c] = rcb_fit_noise_level(f, c); /* as the layout's */
  out->known = rcb_fit_chi2(f);
  rcb_rng_seed(&rng, RCB_ADEQ_SEED);
  for (j = 0; j < f->nres;) {
    double m[2] = {1.0, 1.0}, v = 2.0; /* N(0, 1): a square's mean 1, variance 2 */
    size_t parts = 1, p;
    c = f->res_ch[j];
    if (out->known && !f->sd) parts = draw_point(f, j, level[c], &rng, m, &v);
    var += v;
    if (sd_ch) sd_ch[c] += v;
    for (p = 0; p < parts; p++, j++) {
      F += r[j] * r[j];
      mean += m[p];
      if (chi2_ch) chi2_ch[c] += r[j] * r[j];
      if (expected_ch) expected_ch[c] += m[p];
    }
  }
  out->chi2 = F;
  out->dof = (double)f->nres - (double)f->np;
  out->expected = mean - (double)f->np;
  out->sd = sqrt(var);
  out->limit = out->known ? out->expected + RCB_ADEQUACY_Z * out->sd : (double)NAN;
  out->adequate = out->known && F <= out->limit;
  out->white_z = rcb_fit_white_z(f, r);
  out->white = out->known && out->white_z <= RCB_ADEQUACY_Z;
  out->dispersion = out->known && out->expected > 0 ? F / out->expected : (double)NAN;
  for (c = 0; c < f->nch; c++) {
    /* each channel's share of the parameters, by its share of the residuals */
    if (expected_ch && f->nres)
      expected_ch[c] -= (double)f->np * expected_ch[c] / (mean > 0 ? mean : 1.0);
    if (sd_ch) sd_ch[c] = sqrt(sd_ch[c]);
  }
done:
  rcb_free(&f->alloc, r);
  rcb_free(&f->alloc, level);
  return st;
}
