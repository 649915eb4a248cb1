/*
 * The paper's non-linear least-squares algorithm (Tapia & Cavalca, eqs.
 * 14-18, after Arruda): at each iteration the sensitivity matrix S (eq. 14),
 * the Gauss-Newton step by pseudo-inverse (eq. 16), a derivative-free line
 * search along it (Davies-Swann-Campey with a quadratic (Coggins) fit, eq. 17)
 * unless the full step already achieves half the reduction its linearisation
 * predicts (then it is taken as is: fewer model evaluations than the paper);
 * if the search fails, the damped system [S; lambda Q] with
 * Q = diag(||S_:,i||) and growing lambda (eq. 18). Bounds by the exterior
 * penalty w (p - bound)^2, written as extra residuals so the same
 * Gauss-Newton machinery handles them.
 */
#include <lapacke.h>
#include <math.h>
#include <string.h>

#include "identify/fit_internal.h"

typedef struct paper_ws {
  size_t n, np, m;  /* residuals, parameters, rows of the damped system */
  double wpen;      /* penalty weight (x units) */
  double pred;      /* reduction of Phi the linear model predicts for the step */
  double pred_full; /* the same for the unclipped Gauss-Newton step */
  int capped;       /* the step was shortened to one unit of x */
  double *R, *JA;   /* augmented residuals (n + np) and Jacobian ((n + np) x np) */
  double *A, *b;    /* least-squares copy: (m x np), (m) */
  double *s, *work; /* singular values, LAPACK work */
  lapack_int lwork;
  double *x, *xt, *dx, *lo, *hi; /* np each */
} paper_ws;

/* Exterior penalty rows: sqrt(w) * distance outside [lo, hi] in x. */
static void penalty(const paper_ws *ws, const double *x, double *rp, double *Jp) {
  size_t k;
  double sw = sqrt(ws->wpen);
  for (k = 0; k < ws->np; k++) {
    double v = 0.0, d = 0.0;
    if (x[k] > ws->hi[k]) v = x[k] - ws->hi[k], d = 1.0;
    if (x[k] < ws->lo[k]) v = x[k] - ws->lo[k], d = 1.0;
    rp[k] = sw * v;
    if (Jp) {
      size_t j;
      for (j = 0; j < ws->np; j++) Jp[(ws->n + k) + (ws->n + ws->np) * j] = 0.0;
      Jp[(ws->n + k) + (ws->n + ws->np) * k] = sw * d;
    }
  }
}

/* Phi(x) = ||r(x)||^2 + penalty. */
static rcb_status phi_at(rcb_fit *f, paper_ws *ws, const double *x, double *phi) {
  rcb_status st = rcb_fit_set_x(f, x);
  if (!st) st = rcb_fit_eval(f, ws->R);
  if (st) return st;
  penalty(ws, x, ws->R + ws->n, NULL);
  *phi = rcb_fit_sumsq(ws->R, ws->n + ws->np);
  return RCB_OK;
}

/* Residuals and Jacobian (augmented) at x. */
static rcb_status linearise(rcb_fit *f, paper_ws *ws, const double *x, double *phi) {
  size_t k, rows = ws->n + ws->np;
  rcb_status st = rcb_fit_set_x(f, x);
  if (!st) st = rcb_fit_eval_jac(f, ws->R, f->J);
  if (st) return st;
  for (k = 0; k < ws->np; k++) memcpy(ws->JA + rows * k, f->J + ws->n * k, ws->n * sizeof(double));
  penalty(ws, x, ws->R + ws->n, ws->JA);
  *phi = rcb_fit_sumsq(ws->R, rows);
  return RCB_OK;
}

/* Phi - ||R + JA d||^2: the reduction the linearised model promises for the
 * step d (x units). */
static double promise(const paper_ws *ws, const double *d) {
  size_t rows = ws->n + ws->np, i, k;
  double gain = 0.0;
  for (i = 0; i < rows; i++) {
    double lin = ws->R[i];
    for (k = 0; k < ws->np; k++) lin += ws->JA[i + rows * k] * d[k];
    gain += ws->R[i] * ws->R[i] - lin * lin;
  }
  return gain;
}

/* Step dx minimising ||[JA; lambda Q] dx + [R; 0]|| by SVD (pseudo-inverse,
 * eq. 16; eq. 18 when lambda > 0). */
static rcb_status gn_step(rcb_fit *f, paper_ws *ws, double lambda) {
  size_t rows = ws->n + ws->np, m = rows + ws->np, i, k;
  lapack_int rank, info;
  memset(ws->A, 0, m * ws->np * sizeof *ws->A);
  for (k = 0; k < ws->np; k++) {
    double q = 0.0;
    for (i = 0; i < rows; i++) {
      ws->A[i + m * k] = ws->JA[i + rows * k];
      q += ws->JA[i + rows * k] * ws->JA[i + rows * k];
    }
    ws->A[rows + k + m * k] = lambda * sqrt(q); /* lambda Q, Q_ii = ||S_:,i|| */
  }
  for (i = 0; i < rows; i++) ws->b[i] = -ws->R[i];
  for (i = rows; i < m; i++) ws->b[i] = 0.0;
  info = LAPACKE_dgelss_work(LAPACK_COL_MAJOR, (lapack_int)m, (lapack_int)ws->np, 1, ws->A,
                             (lapack_int)m, ws->b, (lapack_int)m, ws->s, 1e-12, &rank,
                             ws->work, ws->lwork);
  if (info) return rcb_fit_fail(f, RCB_ERR_LAPACK, "dgelss failed (info %d)", (int)info);
  /* An almost unidentifiable parameter (the coupling's cR) gets a huge
   * pseudo-inverse component; clip each component of the step to one unit of
   * x (a factor e for log parameters, the start value otherwise), so that it
   * cannot dictate the others' steps, and let the line search expand it. */
  {
    ws->capped = 0;
    for (k = 0; k < ws->np; k++) {
      ws->dx[k] = fmax(-1.0, fmin(1.0, ws->b[k]));
      if (ws->dx[k] != ws->b[k]) ws->capped = 1;
    }
  }
  /* what the linearised model promises, for the Gauss-Newton step itself
   * (pred_full: is anything left to gain?) and for the clipped step tried */
  ws->pred_full = promise(ws, ws->b);
  ws->pred = promise(ws, ws->dx);
  if (ws->capped && !(ws->pred > 0)) {
    /* clipping turned the step away from descent: scale it as a whole instead */
    double big = 0.0;
    for (k = 0; k < ws->np; k++) big = fmax(big, fabs(ws->b[k]));
    for (k = 0; k < ws->np; k++) ws->dx[k] = ws->b[k] / big;
    ws->pred = promise(ws, ws->dx);
  }
  return RCB_OK;
}

static void along(const paper_ws *ws, double a, double *xt) {
  size_t k;
  for (k = 0; k < ws->np; k++) xt[k] = ws->x[k] + a * ws->dx[k];
}

/* Vertex of the parabola through three points (Coggins). */
static double parabola_min(double a0, double f0, double a1, double f1, double a2, double f2) {
  double num = (a1 - a0) * (a1 - a0) * (f1 - f2) - (a1 - a2) * (a1 - a2) * (f1 - f0);
  double den = (a1 - a0) * (f1 - f2) - (a1 - a2) * (f1 - f0);
  return den != 0.0 ? a1 - 0.5 * num / den : a1;
}

/* Davies-Swann-Campey search along dx from phi0: expand while improving,
 * contract when the unit step fails, then one quadratic fit. On success x and
 * *phi hold the best point found. */
static rcb_status line_search(rcb_fit *f, paper_ws *ws, double phi0, double *phi, int *ok) {
  double a[3] = {0.0, 1.0, 2.0}, p[3], best_a = 0.0, best = phi0, aq, pq;
  int k;
  rcb_status st;
  *ok = 0;
  p[0] = phi0;
  along(ws, 1.0, ws->xt);
  if ((st = phi_at(f, ws, ws->xt, &p[1]))) return st;
  if (!ws->capped && p[1] < phi0 && phi0 - p[1] >= 0.5 * ws->pred) {
    /* the full Gauss-Newton step did at least half of what the linear model
     * promised: take it without spending evaluations on the search */
    along(ws, 1.0, ws->x);
    *phi = p[1];
    *ok = 1;
    return RCB_OK;
  }
  if (p[1] < phi0) {
    for (k = 0; k < 4; k++) { /* expand: 1, 2, 4, ... */
      along(ws, a[2], ws->xt);
      if ((st = phi_at(f, ws, ws->xt, &p[2]))) return st;
      if (p[2] >= p[1]) break;
      a[0] = a[1], p[0] = p[1], a[1] = a[2], p[1] = p[2], a[2] *= 2.0;
    }
    best_a = a[1], best = p[1];
    if (k == 4) a[2] = a[1], p[2] = p[1]; /* no bracket: keep the last */
  } else {
    for (k = 0; k < 5; k++) { /* contract: 1/2, 1/4, ... */
      a[2] = a[1], p[2] = p[1], a[1] *= 0.5;
      along(ws, a[1], ws->xt);
      if ((st = phi_at(f, ws, ws->xt, &p[1]))) return st;
      if (p[1] < phi0) break;
    }
    if (p[1] >= phi0) return RCB_OK;
    best_a = a[1], best = p[1];
  }
  aq = parabola_min(a[0], p[0], a[1], p[1], a[2], p[2]);
  if (isfinite(aq) && aq > 0 && fabs(aq - best_a) > 1e-3 * best_a) {
    along(ws, aq, ws->xt);
    if ((st = phi_at(f, ws, ws->xt, &pq))) return st;
    if (pq < best) best_a = aq, best = pq;
  }
  along(ws, best_a, ws->x);
  *phi = best;
  *ok = 1;
  return RCB_OK;
}

static rcb_status ws_alloc(rcb_fit *f, paper_ws *ws) {
  size_t rows = ws->n + ws->np, m = rows + ws->np, k;
  double wq;
  lapack_int rank;
  ws->R = rcb_alloc(&f->alloc, rows * sizeof *ws->R);
  ws->JA = rcb_alloc(&f->alloc, rows * ws->np * sizeof *ws->JA);
  ws->A = rcb_alloc(&f->alloc, m * ws->np * sizeof *ws->A);
  ws->b = rcb_alloc(&f->alloc, m * sizeof *ws->b);
  ws->s = rcb_alloc(&f->alloc, ws->np * sizeof *ws->s);
  ws->x = rcb_alloc(&f->alloc, 5 * ws->np * sizeof *ws->x);
  if (!ws->R || !ws->JA || !ws->A || !ws->b || !ws->s || !ws->x)
    return rcb_fit_fail(f, RCB_ERR_NOMEM, "out of memory (paper method)");
  ws->xt = ws->x + ws->np, ws->dx = ws->xt + ws->np;
  ws->lo = ws->dx + ws->np, ws->hi = ws->lo + ws->np;
  for (k = 0; k < ws->np; k++) {
    const rcb_fit_par *p = &f->par[k];
    ws->lo[k] = p->log_param ? log(p->lo) : p->lo / p->scale;
    ws->hi[k] = p->log_param ? log(p->hi) : p->hi / p->scale;
  }
  if (LAPACKE_dgelss_work(LAPACK_COL_MAJOR, (lapack_int)m, (lapack_int)ws->np, 1, ws->A,
                          (lapack_int)m, ws->b, (lapack_int)m, ws->s, 1e-12, &rank, &wq, -1))
    return rcb_fit_fail(f, RCB_ERR_LAPACK, "dgelss workspace query failed");
  ws->lwork = (lapack_int)wq;
  ws->work = rcb_alloc(&f->alloc, (size_t)ws->lwork * sizeof *ws->work);
  return ws->work ? RCB_OK : rcb_fit_fail(f, RCB_ERR_NOMEM, "out of memory (paper method)");
}

static void ws_free(rcb_fit *f, paper_ws *ws) {
  rcb_free(&f->alloc, ws->R);
  rcb_free(&f->alloc, ws->JA);
  rcb_free(&f->alloc, ws->A);
  rcb_free(&f->alloc, ws->b);
  rcb_free(&f->alloc, ws->s);
  rcb_free(&f->alloc, ws->x);
  rcb_free(&f->alloc, ws->work);
}

/* One iteration: Gauss-Newton + line search, then damped steps (eq. 18). */
static rcb_status iterate(rcb_fit *f, paper_ws *ws, double *phi, int *moved) {
  static const double lambdas[] = {1e-3, 1e-2, 1e-1, 1.0, 1e1, 1e2, 1e3};
  double phi0 = *phi, lim;
  size_t k;
  int ok, noisy;
  rcb_status st;
  if ((st = linearise(f, ws, ws->x, &phi0)) || (st = gn_step(f, ws, 0.0))) return st;
  /* Nothing left to gain: at a minimum. With noise-aware weights Phi is a
   * chi-square, and a step promising less than 0.01 of one unit moves every
   * parameter combination by under 0.1 of its standard error: stop without
   * spending evaluations on it. The same when the step that can be tried
   * (clipped) promises that little: what is left is an unidentifiable
   * parameter's drift along a flat valley. */
  noisy = rcb_fit_chi2(f);
  lim = noisy ? fmax(f->ftol_rel * phi0, 1e-2) : f->ftol_rel * phi0;
  if (ws->pred_full <= lim || (noisy && ws->pred <= lim)) {
    *moved = 0;
    *phi = phi0;
    return RCB_OK;
  }
  if ((st = line_search(f, ws, phi0, phi, &ok))) return st;
  /* eq. 18: damped steps, one trial each, lambda growing tenfold from 1e-3
   * to 1e3 (a table, not a floating-point loop counter: cert-flp30-c) */
  for (k = 0; !ok && k < sizeof lambdas / sizeof lambdas[0]; k++) {
    const double lambda = lambdas[k];
    double p1;
    if ((st = gn_step(f, ws, lambda))) return st;
    along(ws, 1.0, ws->xt);
    if ((st = phi_at(f, ws, ws->xt, &p1))) return st;
    if (p1 < phi0) {
      memcpy(ws->x, ws->xt, ws->np * sizeof *ws->x);
      *phi = p1;
      ok = 1;
    }
  }
  *moved = ok;
  if (!ok) {
    /* the linearisation promised more than 0.1 % and no step delivered any
     * of it: a stall (a wrong or noisy gradient, a kink), not a minimum */
    f->stalled = ws->pred_full > 1e-3 * phi0;
    *phi = phi0;
  }
  return RCB_OK;
}

rcb_status rcb_fit_run_paper(rcb_fit *f) {
  paper_ws ws;
  double phi, phi_old;
  rcb_status st;
  memset(&ws, 0, sizeof ws);
  ws.n = f->nres;
  ws.np = f->np;
  if ((st = ws_alloc(f, &ws))) goto done;
  rcb_fit_get_x(f, ws.x);
  ws.wpen = 1e4 * (f->obj0 > 0 ? f->obj0 : 1.0);
  if ((st = phi_at(f, &ws, ws.x, &phi)) || (st = rcb_fit_check_finite(f, phi, "at the start")))
    goto done;
  for (f->iterations = 0; f->iterations < f->max_iter;) {
    double step = 0.0, xn = 0.0;
    int moved;
    size_t k;
    phi_old = phi;
    if ((st = iterate(f, &ws, &phi, &moved))) goto done;
    f->iterations++;
    if (f->progress && f->progress(f->progress_user, f->iterations, f->evaluations, phi)) {
      st = rcb_fit_fail(f, RCB_ERR_STATE, "stopped by the caller");
      goto done;
    }
    if (!moved) { /* no descent left: a (local) minimum to working precision */
      f->converged = !f->stalled;
      break;
    }
    for (k = 0; k < ws.np; k++) step += ws.dx[k] * ws.dx[k], xn += ws.x[k] * ws.x[k];
    /* with noise-aware weights Phi is a chi-square: a gain below a
     * thousandth of one unit is no information (an unidentifiable parameter
     * drifting along a flat valley) */
    if (phi_old - phi <= f->ftol_rel * phi_old ||
        (rcb_fit_chi2(f) && phi_old - phi < 1e-3) ||
        sqrt(step) <= f->xtol_rel * (sqrt(xn) + f->xtol_rel)) {
      f->converged = 1;
      break;
    }
  }
  st = rcb_fit_set_x(f, ws.x);
done:
  ws_free(f, &ws);
  return st;
}
