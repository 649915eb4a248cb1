/*
 * The one rule of what the data let a tool say of an edit of a model (issues
 * #23 and #33, rcb_diagnose.h: rcb_evidence). Every word that claims
 * something, "significant", "explains", "at the floor", "white", in every
 * verb and in the Python package, is decided here.
 */
#include <math.h>

#include "rcb/rcb_diagnose.h"

/* With a known noise F is a chi-square. */
static int known(const rcb_evidence *e) { return e && isfinite(e->chi2_limit); }

double rcb_evidence_phi(const rcb_evidence *e) {
  return e && e->dispersion > 1.0 && isfinite(e->dispersion) ? e->dispersion : 1.0;
}

/* k ln N, the BIC's price of the edit's parameters (0 when N is not given:
 * delta_bic then holds it already, and the calibration divides the whole). */
static double penalty(const rcb_evidence *e) {
  return e->residuals > 1.0 && e->params > 0 ? e->params * log(e->residuals) : 0.0;
}

double rcb_evidence_dbic(const rcb_evidence *e) {
  double pen;
  if (!e) return (double)NAN;
  if (!known(e)) return e->delta_bic;
  pen = penalty(e);
  return (e->delta_bic - pen) / rcb_evidence_phi(e) + pen;
}

/* The upper quantile of a chi-square of k degrees of freedom at p: exact
 * for k = 1 (a squared normal) and 2 (an exponential), Wilson-Hilferty's
 * cube for more (within 1 % at these tails). */
static double chi2_upper(double k, double p) {
  double lo = 0.0, hi = 40.0, z, h;
  int it;
  if (k <= 0) return 0.0;
  if (k == 2.0) return -2.0 * log(p);
  for (it = 0; it < 200; it++) { /* z with P(Z > z) = p (k = 1: p / 2) */
    double mid = 0.5 * (lo + hi);
    if (0.5 * erfc(mid / sqrt(2.0)) > (k == 1.0 ? 0.5 * p : p)) lo = mid;
    else hi = mid;
  }
  z = 0.5 * (lo + hi);
  if (k == 1.0) return z * z;
  h = 2.0 / (9.0 * k);
  return k * pow(1.0 - h + z * sqrt(h), 3.0);
}

int rcb_evidence_significant(const rcb_evidence *e) {
  double drop;
  if (!e || !(rcb_evidence_dbic(e) < RCB_BIC_SIGNIFICANT)) return 0;
  /* without a known noise, the error itself must fall too */
  if (!known(e)) return e->error_after_pct < RCB_ERROR_FALL * e->error_before_pct;
  if (!(e->params > 0)) return 1; /* nothing fitted: BIC alone (another coupling model) */
  drop = (e->delta_bic - penalty(e)) / -rcb_evidence_phi(e);
  return drop > chi2_upper(e->params, RCB_FALSE_ALARM / (e->tried > 1 ? e->tried : 1.0));
}

double rcb_evidence_level(const rcb_evidence *e) {
  double phi;
  if (!e || !known(e) || !isfinite(e->chi2)) return (double)NAN;
  /* the dispersion when given, else chi2 over the limit (below chi2 /
   * expected, so never a larger level than the data show) */
  phi = e->dispersion > 0 && isfinite(e->dispersion) ? e->dispersion
                                                      : e->chi2 / fmax(e->chi2_limit, 1e-300);
  return sqrt(fmax(phi, 0.0));
}

int rcb_evidence_white_noise(const rcb_evidence *e) {
  if (!e || e->white != 1 || !known(e) || !isfinite(e->chi2)) return 0;
  return rcb_evidence_level(e) <= RCB_WHITE_LEVEL_MAX;
}

int rcb_evidence_adequate(const rcb_evidence *e) {
  if (!e || !known(e) || !isfinite(e->chi2)) return -1;
  return e->chi2 <= e->chi2_limit || rcb_evidence_white_noise(e);
}

rcb_claim rcb_evidence_claim(const rcb_evidence *e) {
  if (!rcb_evidence_significant(e)) return RCB_CLAIM_NONE;
  return rcb_evidence_adequate(e) == 1 && !e->beyond ? RCB_CLAIM_EXPLAINS : RCB_CLAIM_IMPROVES;
}

const char *rcb_claim_str(rcb_claim c) {
  return c == RCB_CLAIM_EXPLAINS ? "explains" : c == RCB_CLAIM_IMPROVES ? "improves" : "none";
}

int rcb_evidence_separable(double dbic_a, double dbic_b) {
  return fabs(dbic_a - dbic_b) > -RCB_BIC_SIGNIFICANT;
}
