/*
 * The rank space of a monitor (rcb_monitor.h): the whitened columns of the
 * tracked parameters and the candidates factored by the score test's QR
 * (diagnose/score_qr.c), Q made explicit (and stored row-major for the
 * update), G = Q^T J, and for the tracked parameters and each candidate the
 * small QR that gives its estimator rows, standard errors and the
 * orthonormal directions of its score. Part of rcb_monitor_create.
 */
#include <lapacke.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "diagnose/diagnose.h"
#include "identify/identify.h"
#include "monitor/monitor_internal.h"

/* Relative size of a triangular factor's diagonal below which a column
 * counts as explained by those before it (as score_qr.c's RCB_DIAG_RANK_TOL). */
#define MON_RANK_TOL 1e-10

/* Thin QR of w->A (k x p, column-major, overwritten by Qa) with R (p x p,
 * column-major) and its inverse Ri; *ok = 0 when a diagonal of R falls
 * below MON_RANK_TOL of its column's norm (a dependent column). */
rcb_status rcb_mon_small_qr(rcb_monitor *mon, mon_small *w, size_t k, size_t p, int *ok) {
  size_t i, j;
  double norm[RCB_MONITOR_MAX_TRACKED + 2 * RCB_MONITOR_MAXP];
  double *A = w->A, *R = w->R, *Ri = w->Ri;
  lapack_int info;
  *ok = p <= k;
  if (!*ok || !p) return RCB_OK;
  for (j = 0; j < p; j++) {
    double s = 0;
    for (i = 0; i < k; i++) s += A[i + k * j] * A[i + k * j];
    norm[j] = sqrt(s);
  }
  info = LAPACKE_dgeqrf_work(LAPACK_COL_MAJOR, (lapack_int)k, (lapack_int)p, A, (lapack_int)k,
                             w->tau, w->work, (lapack_int)w->lwork);
  for (j = 0; !info && j < p; j++)
    for (i = 0; i < p; i++) R[i + p * j] = i <= j ? A[i + k * j] : 0.0;
  for (j = 0; j < p; j++)
    if (!(fabs(R[j + p * j]) > MON_RANK_TOL * norm[j])) *ok = 0;
  if (!info)
    info = LAPACKE_dorgqr_work(LAPACK_COL_MAJOR, (lapack_int)k, (lapack_int)p, (lapack_int)p, A,
                               (lapack_int)k, w->tau, w->work, (lapack_int)w->lwork);
  if (!info && *ok) {
    memcpy(Ri, R, p * p * sizeof *Ri);
    info = LAPACKE_dtrtri_work(LAPACK_COL_MAJOR, 'U', 'N', (lapack_int)p, Ri, (lapack_int)p);
  }
  if (info < 0 || (info > 0 && *ok))
    return rcb_mon_fail(mon, RCB_ERR_LAPACK, "rank-space QR failed (LAPACK info %d)", (int)info);
  return RCB_OK;
}

/* est (q x k, row-major) = rows first .. first + q of Ri Qa^T, and the
 * standard errors of those parameters (row norms of Ri). */
static void estimator(const double *Qa, const double *Ri, size_t k, size_t p, size_t first,
                      size_t q, double *est, double *se) {
  size_t a, b, i;
  for (a = 0; a < q; a++) {
    size_t row = first + a;
    double s = 0;
    for (b = row; b < p; b++) s += Ri[row + p * b] * Ri[row + p * b];
    se[a] = sqrt(s);
    for (i = 0; i < k; i++) {
      double v = 0;
      for (b = row; b < p; b++) v += Ri[row + p * b] * Qa[i + k * b];
      est[a * k + i] = v;
    }
  }
}

static rcb_status tracked_space(rcb_monitor *mon, const double *G, mon_small *w) {
  size_t k = mon->k, nt = mon->nt, i, a;
  int ok;
  rcb_status st;
  if (!nt) return RCB_OK;
  memcpy(w->A, G, k * nt * sizeof *w->A);
  if ((st = rcb_mon_small_qr(mon, w, k, nt, &ok))) return st;
  if (!ok)
    return rcb_mon_fail(mon, RCB_ERR_ARG, "the tracked parameters cannot all be told apart on "
                        "this set-up (their sensitivity columns are dependent): track fewer, or "
                        "add channels");
  estimator(w->A, w->Ri, k, nt, 0, nt, mon->test, mon->tse);
  for (a = 0; a < nt; a++)
    for (i = 0; i < k; i++) mon->tdir[a * k + i] = w->A[i + k * a];
  return RCB_OK;
}

static rcb_status cand_space(rcb_monitor *mon, rcb_diag *d, const col_plan *pl,
                             const double *G, mon_small *w) {
  size_t k = mon->k, nt = mon->nt, j, a, i, idz = 0;
  rcb_status st;
  for (j = 0; j < pl->ncand; j++) {
    mon_cand *mc = &mon->cand[j];
    rcb_diag_cand_desc c;
    size_t p;
    int ok;
    rcb_mon_cand_desc(d, pl->cand[j], &c);
    mc->effect = c.effect;
    snprintf(mc->place, sizeof mc->place, "%s", c.place);
    snprintf(mc->desc, sizeof mc->desc, "%s", c.desc);
    snprintf(mc->params, sizeof mc->params, "%s", c.params);
    mc->np = c.np;
    mc->col = pl->col[j];
    for (a = 0; a < c.np; a++)
      mc->neutral[a] = pl->neutral[pl->col[j] + a], mc->lo[a] = c.lo[a], mc->hi[a] = c.hi[a];
    /* a sensor's gain: a sign flipped (a probe wired the wrong way) is its
     * gain at -1, as plausible as the gain's own range mirrored */
    if (c.chain && c.effect == RCB_EFFECT_SENSOR_GAIN) mc->lo[0] = -mc->hi[0];
    if (!pl->own[j]) { /* the batched candidates' derivative matrices, in plan order */
      if (mon->cdz && idz + c.np <= mon->ncdz) mc->dz = mon->cdz + idz;
      idz += c.np;
    }
    mc->settable = !pl->own[j];
    for (a = 0; mc->settable && a < c.np; a++) {
      double v;
      mc->settable = snprintf(mc->pname[a], sizeof mc->pname[a], "%s", c.pname[a]) <
                         (int)sizeof mc->pname[a] &&
                     rcb_model_get_param(mon->model, c.pname[a], &v) == RCB_OK &&
                     v == mc->neutral[a];
    }
    p = nt + c.np;
    memcpy(w->A, G, k * nt * sizeof *w->A);
    memcpy(w->A + k * nt, G + k * pl->col[j], k * c.np * sizeof *w->A);
    if ((st = rcb_mon_small_qr(mon, w, k, p, &ok))) return st;
    if (!ok) continue; /* explained by the tracked parameters or itself dependent: not scored */
    mc->est = rcb_mon_alloc(mon, (2 * c.np + nt) * k, sizeof *mc->est);
    if (!mc->est) return rcb_mon_fail(mon, RCB_ERR_NOMEM, "out of memory (candidates)");
    mc->dir = mc->est + c.np * k;
    mc->test_t = mc->dir + c.np * k;
    mc->dof = c.np;
    estimator(w->A, w->Ri, k, p, nt, c.np, mc->est, mc->se);
    for (a = 0; a < c.np; a++)
      for (i = a; i < c.np; i++) mc->r0[a * RCB_MONITOR_MAXP + i] = w->R[(nt + a) + p * (nt + i)];
    estimator(w->A, w->Ri, k, p, 0, nt, mc->test_t, mc->se_t);
    for (a = 0; a < c.np; a++)
      for (i = 0; i < k; i++) mc->dir[a * k + i] = w->A[i + k * (nt + a)];
  }
  return RCB_OK;
}

/* G = Q^T J (k x ncol, column-major). */
static void project(const rcb_monitor *mon, const double *J, size_t ncol, double *G) {
  size_t j, a, i, n = mon->n, k = mon->k;
  for (j = 0; j < ncol; j++)
    for (a = 0; a < k; a++) {
      const double *q = mon->Q + n * a, *c = J + n * j;
      double s = 0;
      for (i = 0; i < n; i++) s += q[i] * c[i];
      G[a + k * j] = s;
    }
}

/* QR of all whitened columns (score_qr.c), Q made explicit. */
rcb_status rcb_mon_factor(rcb_monitor *mon, rcb_diag *d, const double *J, size_t ncol) {
  diag_basis b;
  double q = 0;
  lapack_int info;
  rcb_status st;
  /* score_qr.c's workspace query asks dormqr for ncol reflectors on n rows,
   * an illegal argument (LAPACK's xerbla prints it) when ncol > n: refused
   * here with the fix, until that query asks for min(ncol, n) */
  if (ncol > mon->n)
    return rcb_mon_fail(mon, RCB_ERR_ARG, "the set-up has %zu real residuals (2 x %zu channels "
                        "x %zu points), fewer than the %zu sensitivity columns of the tracked "
                        "parameters and the candidates: add channels or points, or choose fewer "
                        "effects (opts.effects)", mon->n, mon->nch, mon->npts, ncol);
  st = rcb_diag_basis_init(d, &b, J, mon->n, ncol, mon->r);
  if (st) return rcb_mon_fail(mon, st, "%s", rcb_diag_errmsg(d));
  mon->k = b.rank;
  mon->Q = b.qr; /* the block is the monitor's allocator's (d was made with it) */
  if (!mon->k) {
    rcb_free(&mon->alloc, b.work);
    return rcb_mon_fail(mon, RCB_ERR_ARG, "no sensitivity at all: the tracked parameters and "
                        "the candidates leave the set-up's values unchanged");
  }
  info = LAPACKE_dorgqr_work(LAPACK_COL_MAJOR, (lapack_int)mon->n, (lapack_int)mon->k,
                             (lapack_int)mon->k, b.qr, (lapack_int)mon->n, b.tau, &q, -1);
  if (!info && (size_t)q > b.lwork) {
    double *w = rcb_mon_alloc(mon, (size_t)q, sizeof *w);
    if (!w) {
      rcb_free(&mon->alloc, b.work);
      return rcb_mon_fail(mon, RCB_ERR_NOMEM, "out of memory (QR)");
    }
    rcb_free(&mon->alloc, b.work);
    b.work = w, b.lwork = (size_t)q;
  }
  if (!info)
    info = LAPACKE_dorgqr_work(LAPACK_COL_MAJOR, (lapack_int)mon->n, (lapack_int)mon->k,
                               (lapack_int)mon->k, b.qr, (lapack_int)mon->n, b.tau, b.work,
                               (lapack_int)b.lwork);
  rcb_free(&mon->alloc, b.work);
  if (info) return rcb_mon_fail(mon, RCB_ERR_LAPACK, "forming Q failed (LAPACK info %d)", (int)info);
  return RCB_OK;
}

/* Q (column-major from the QR) to row-major: the update reads it residual
 * by residual. */
static void transpose_q(rcb_monitor *mon, double *Qr) {
  size_t n = mon->n, k = mon->k, i, a;
  for (a = 0; a < k; a++)
    for (i = 0; i < n; i++) Qr[k * i + a] = mon->Q[i + n * a];
  rcb_free(&mon->alloc, mon->Q);
  mon->Q = Qr;
}

/* J (n x ncol >= n x k) is used up: Q moves into its block. With a
 * commissioning image G is its, and Q (row-major) was taken from it. */
rcb_status rcb_mon_rank_space(rcb_monitor *mon, rcb_diag *d, const col_plan *pl, double *J,
                              const mon_image *im) {
  size_t k = mon->k, nt = mon->nt, pmax = nt + 2 * (size_t)RCB_MONITOR_MAXP, lw, pq;
  double q1 = 0, q2 = 0;
  mon_small *w = &mon->sw;
  rcb_status st;
  mon->G = rcb_mon_alloc(mon, k * (pl->ncol ? pl->ncol : 1), sizeof *mon->G);
  w->A = rcb_mon_alloc(mon, k * pmax + 3 * pmax * pmax + pmax, sizeof *w->A);
  mon->test = rcb_mon_alloc(mon, 2 * (nt ? nt : 1) * k, sizeof *mon->test);
  mon->cand = rcb_mon_alloc(mon, pl->ncand ? pl->ncand : 1, sizeof *mon->cand);
  /* the reweighted path: C, z, z0, U^-T G, two rows, the channels' amplitudes */
  mon->C = rcb_mon_alloc(mon, k * k + 2 * k + k * (pl->ncol ? pl->ncol : 1) +
                         2 * k * MON_SYRK_POINTS + mon->nch + k * pmax, sizeof *mon->C);
  if (!mon->G || !w->A || !mon->test || !mon->cand || !mon->C)
    return rcb_mon_fail(mon, RCB_ERR_NOMEM, "out of memory (rank space)");
  mon->z = mon->C + k * k, mon->z0 = mon->z + k, mon->Atw = mon->z0 + k;
  mon->b1 = mon->Atw + k * (pl->ncol ? pl->ncol : 1);
  mon->achan = mon->b1 + 2 * k * MON_SYRK_POINTS;
  mon->Jx = mon->achan + mon->nch;
  mon->ncol = pl->ncol;
  mon->ncand = pl->ncand;
  mon->tdir = mon->test + (nt ? nt : 1) * k;
  w->R = w->A + k * pmax, w->Ri = w->R + pmax * pmax, w->tau = w->Ri + pmax * pmax;
  /* the small QRs have p <= k columns (rcb_mon_small_qr): dorgqr needs N <= M */
  pq = pmax < k ? pmax : k;
  LAPACKE_dgeqrf_work(LAPACK_COL_MAJOR, (lapack_int)k, (lapack_int)pq, w->A, (lapack_int)k,
                      w->tau, &q1, -1);
  LAPACKE_dorgqr_work(LAPACK_COL_MAJOR, (lapack_int)k, (lapack_int)pq, (lapack_int)pq, w->A,
                      (lapack_int)k, w->tau, &q2, -1);
  lw = (size_t)fmax(fmax(q1, q2), (double)pmax);
  if (!(w->work = rcb_mon_alloc(mon, lw, sizeof *w->work)))
    return rcb_mon_fail(mon, RCB_ERR_NOMEM, "out of memory (rank space)");
  w->lwork = lw;
  if (im)
    rcb_mon_image_doubles(im, im->g, mon->G, k * pl->ncol);
  else
    project(mon, J, pl->ncol, mon->G);
  if ((st = tracked_space(mon, mon->G, w)) || (st = cand_space(mon, d, pl, mon->G, w)))
    return st;
  if (!im) transpose_q(mon, J);
  return RCB_OK;
}

/* The one naming rule's BIC change: -score + dof ln n (n real residuals). */
double rcb_mon_bic(const rcb_monitor *mon, double score, size_t dof) {
  return -score + (double)dof * log((double)mon->n);
}

/* The BIC half of the one naming rule: the first's BIC change lower than
 * its closest rival's, the second (monitor.c, rival_second), by more than
 * rcb_evidence_separable's 10. A second better supported by more than 10
 * is no licence to name the first alone (as the absolute difference was). */
int rcb_mon_bic_apart(const rcb_monitor *mon, const rcb_monitor_result *r) {
  double b0 = rcb_mon_bic(mon, r->top[0].score, r->top[0].dof);
  double b1 = rcb_mon_bic(mon, r->top[1].score, r->top[1].dof);
  return rcb_evidence_separable(b0, b1) && b0 < b1;
}

/* The one naming rule: the BIC half, and every rival's hypothesis rejected
 * by the test that the first adds to its fit (rcb_mon_adds; apart_p, the
 * largest p over the rivals, below RCB_MONITOR_APART_ALPHA). */
int rcb_monitor_named(const rcb_monitor *mon, const rcb_monitor_result *r) {
  if (!mon || !r || r->ntop < 2) return -1;
  return rcb_mon_bic_apart(mon, r) && r->apart_p < RCB_MONITOR_APART_ALPHA;
}

/* Does candidate a add to candidate c's fit? The change explained by the
 * tracked columns, c's and a's beyond the tracked and c's (the small QR
 * of [G_t G_c G_a], in this update's metric on the reweighted path:
 * mon->Atw and z0 = U^-T y0; else G and y0), chi-square(np_a) whatever the
 * size of c when the truth is c, linearly and with the noise as declared:
 * so P(c rejected at level alpha | c) = alpha for every pair. *p: its
 * upper-tail probability; 1 when a's columns lie in the span of the others
 * (nothing in the data can reject c). */
rcb_status rcb_mon_adds(rcb_monitor *mon, int gls, const mon_cand *a, const mon_cand *c,
                        double *p) {
  size_t k = mon->k, nt = mon->nt, q = nt + c->np, m = q + a->np;
  const double *B = gls ? mon->Atw : mon->G, *z = gls ? mon->z0 : mon->y0;
  double qz[RCB_MONITOR_MAX_TRACKED + 2 * RCB_MONITOR_MAXP], x;
  mon_small *w = &mon->sw;
  int ok;
  rcb_status st;
  memcpy(w->A, B, k * nt * sizeof *w->A);
  memcpy(w->A + k * nt, B + k * c->col, k * c->np * sizeof *w->A);
  memcpy(w->A + k * q, B + k * a->col, k * a->np * sizeof *w->A);
  *p = 1.0;
  if ((st = rcb_mon_small_qr(mon, w, k, m, &ok)) || !ok) return st;
  x = rcb_mon_gls_explained(w, z, k, q, m, qz);
  *p = rcb_chi2_sf(x, (double)a->np);
  return RCB_OK;
}
