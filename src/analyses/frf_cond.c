/*
 * Numerical guard of the FRF solves: after each factorisation, an estimate
 * of the reciprocal condition number of Z(w, W) (LAPACK zgecon / zgbcon,
 * KLU klu_z_condest; by default only where the O(n) pivot-ratio screen
 * finds a small pivot, RCB_COND_SCREEN), and a record of the smallest one over a sweep with
 * the frequency and speed where it occurred. The caller reads the record
 * (rcb_frf_get_condition) and warns: a solve that succeeds on a matrix
 * singular up to round-off (an all-free model at omega = 0) returns
 * numbers, but not the response.
 */
#include <math.h>

#include "analyses/frf_internal.h"

static void cond_clear(rcb_frf_condition *c, double threshold) {
  c->rcond_min = c->rcond_last = (double)NAN;
  c->omega = c->speed = (double)NAN;
  c->checked = c->estimated = c->ill = 0;
  c->threshold = threshold;
}

rcb_status rcb_frf_cond_setup(rcb_frf *f) {
  size_t n = f->m->ndof;
  f->cond_on = RCB_COND_SCREEN;
  cond_clear(&f->cond, RCB_RCOND_WARN);
  f->cond_work = rcb_alloc(&f->alloc, 2 * n * sizeof *f->cond_work);
  f->cond_rwork = rcb_alloc(&f->alloc, 2 * n * sizeof *f->cond_rwork);
  f->bytes += 2 * n * (sizeof *f->cond_work + sizeof *f->cond_rwork);
  if (!f->cond_work || !f->cond_rwork)
    return rcb_set_error(f->errmsg, RCB_ERR_NOMEM, "out of memory sizing the condition estimate");
  return RCB_OK;
}

void rcb_frf_cond_free(rcb_frf *f) {
  rcb_free(&f->alloc, f->cond_work);
  rcb_free(&f->alloc, f->cond_rwork);
}

/* ||Z||_1 before a LAPACK backend overwrites Z with its factors; KLU keeps
 * Z, so when screening its norm waits until a small pivot asks for it (one
 * pass over Z less per frequency: 13 % of a 1e5-DOF train's time). */
void rcb_frf_cond_before(rcb_frf *f) {
  if (!f->cond_on || !f->ops->rcond) return;
  if (f->cond_on == RCB_COND_ALWAYS || !f->L.sparse) f->anorm = rcb_layout_norm1(&f->L, f->Z);
}

void rcb_frf_cond_after(rcb_frf *f, double omega, double speed) {
  rcb_frf_condition *c = &f->cond;
  double rc = (double)NAN;
  if (!f->cond_on || !f->ops->rcond) return;
  c->checked++;
  if (f->cond_on == RCB_COND_SCREEN) {
    double ratio = rcb_layout_pivot_ratio(&f->L, f->Z);
    if (ratio >= RCB_PIVOT_SCREEN) { /* no small pivot: not worth an estimate */
      c->rcond_last = (double)NAN;
      return;
    }
    if (f->L.sparse) f->anorm = rcb_layout_norm1(&f->L, f->Z);
  }
  if (!isfinite(f->anorm) ||
      f->ops->rcond(&f->L, f->Z, f->ipiv, f->anorm, f->cond_work, f->cond_rwork, &rc))
    rc = (double)NAN;
  c->rcond_last = rc;
  c->estimated++;
  if (!(rc >= c->threshold)) c->ill++;
  /* a NaN estimate is the worst: keep it as the minimum */
  if (c->estimated == 1 || (!isnan(c->rcond_min) && (isnan(rc) || rc < c->rcond_min))) {
    c->rcond_min = rc;
    c->omega = omega;
    c->speed = speed;
  }
}

rcb_status rcb_frf_set_condition_check(rcb_frf *f, int mode, double threshold) {
  if (!f) return RCB_ERR_ARG;
  if (mode < RCB_COND_OFF || mode > RCB_COND_ALWAYS)
    return rcb_set_error(f->errmsg, RCB_ERR_ARG,
                         "condition check mode %d: expected RCB_COND_OFF, RCB_COND_SCREEN or "
                         "RCB_COND_ALWAYS", mode);
  if (!(threshold > 0.0 && threshold < 1.0))
    return rcb_set_error(f->errmsg, RCB_ERR_ARG,
                         "condition threshold %g: expected 0 < threshold < 1", threshold);
  f->cond_on = mode;
  cond_clear(&f->cond, threshold);
  return RCB_OK;
}

void rcb_frf_reset_condition(rcb_frf *f) {
  if (f) cond_clear(&f->cond, f->cond.threshold);
}

rcb_status rcb_frf_get_condition(const rcb_frf *f, rcb_frf_condition *out) {
  if (!f || !out) return RCB_ERR_ARG;
  *out = f->cond;
  return RCB_OK;
}

double rcb_frf_rcond(const rcb_frf *f) { return f ? f->cond.rcond_min : (double)NAN; }
