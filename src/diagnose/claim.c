/*
 * The one rule of what the data let a tool say of an edit of a model (issue
 * #23, rcb_diagnose.h: rcb_evidence). Every word that claims something,
 * "significant", "explains", "at the floor", in every verb and in the Python
 * package, is decided here.
 */
#include <math.h>

#include "rcb/rcb_diagnose.h"

int rcb_evidence_significant(const rcb_evidence *e) {
  /* with a known noise F is a chi-square and the BIC test stands alone;
   * without one, the error itself must fall too */
  return e && e->delta_bic < RCB_BIC_SIGNIFICANT &&
         (isfinite(e->chi2_limit) || e->error_after_pct < RCB_ERROR_FALL * e->error_before_pct);
}

int rcb_evidence_adequate(const rcb_evidence *e) {
  if (!e || !isfinite(e->chi2_limit) || !isfinite(e->chi2)) return -1;
  return e->chi2 <= e->chi2_limit;
}

rcb_claim rcb_evidence_claim(const rcb_evidence *e) {
  if (!rcb_evidence_significant(e)) return RCB_CLAIM_NONE;
  return rcb_evidence_adequate(e) == 1 ? RCB_CLAIM_EXPLAINS : RCB_CLAIM_IMPROVES;
}

const char *rcb_claim_str(rcb_claim c) {
  return c == RCB_CLAIM_EXPLAINS ? "explains" : c == RCB_CLAIM_IMPROVES ? "improves" : "none";
}

int rcb_evidence_separable(double dbic_a, double dbic_b) {
  return fabs(dbic_a - dbic_b) > -RCB_BIC_SIGNIFICANT;
}
