/*
 * Local modal fit of measured resonances (the peak table's damping): a
 * rational fraction in s = i w with a common denominator of order 2N (N
 * modes, real coefficients) shared by every channel given and one numerator
 * of order 2N per channel (complex coefficients: the modes' residues in any
 * of the three kinds plus a constant residual of the other modes),
 *   H_k(w) = (b_k0 + ... + b_k,2N s^2N) / (a_0 + ... + a_2N-1 s^2N-1 + s^2N),
 * fitted by linear least squares on H_k D(s) - N_k(s) = 0 (Levy) weighted by
 * 1/(|H_k| |D'|), D' the previous pass's denominator (Sanathanan-Koerner
 * iterations): at convergence this is the relative output error
 * |H - N/D| / |H|, which suits eq. 19's proportional noise. N = 1 is the
 * single-DOF fraction with a residual, (b0 + b1 s + b2 s^2) / (s^2 + 2 zeta
 * wn s + wn^2); exact on a noise-free FRF of N modes.
 *
 * Each channel's numerator is eliminated by a QR factorisation of its block
 * [numerator columns | denominator columns | right-hand side] (dgeqrf): the
 * trailing (2N + 1) x (2N + 1) triangle of R is that channel's reduced
 * problem in the denominator alone; the channels' triangles stacked are
 * solved by dgels. The poles are the eigenvalues of D's companion matrix
 * (dhseqr). Frequencies are scaled by a reference frequency first.
 */
#include <lapacke.h>
#include <math.h>
#include <string.h>

#include "compare/compare_internal.h"

/* Work arrays of one fit, all in one allocation. */
typedef struct modal_ws {
  size_t n, nch, order;   /* points, channels, 2N */
  size_t rows, cols, nb;  /* channel block: 2n x (nb + 2N + 1), nb numerator columns */
  double *nu, *wt;        /* n scaled frequencies; nch * n weights */
  double *B, *tau;        /* channel block, its Householder scalars */
  double *S;              /* stacked triangles: nch (2N + 1) x (2N + 1) */
  double *work;
  lapack_int lwork;
} modal_ws;

/* Largest LAPACK workspace of dgeqrf on a channel block and dgels on the stack. */
static lapack_int ws_query(modal_ws *ws) {
  double q1 = 0.0, q2 = 0.0;
  lapack_int m = (lapack_int)ws->rows, ls = (lapack_int)(ws->nch * (ws->order + 1));
  if (LAPACKE_dgeqrf_work(LAPACK_COL_MAJOR, m, (lapack_int)ws->cols, ws->B, m, ws->tau, &q1,
                          -1) ||
      LAPACKE_dgels_work(LAPACK_COL_MAJOR, 'N', ls, (lapack_int)ws->order, 1, ws->S, ls,
                         ws->S, ls, &q2, -1))
    return -1;
  return (lapack_int)fmax(q1, q2);
}

static rcb_status ws_create(rcb_compare *c, modal_ws *ws, size_t n, size_t nch, size_t nmodes) {
  size_t ns, total;
  double probe = 0.0;
  memset(ws, 0, sizeof *ws);
  ws->n = n, ws->nch = nch, ws->order = 2 * nmodes;
  ws->nb = 2 * (ws->order + 1), ws->rows = 2 * n, ws->cols = ws->nb + ws->order + 1;
  ns = nch * (ws->order + 1) * (ws->order + 1);
  total = n + nch * n + ws->rows * ws->cols + ws->cols + ns;
  ws->nu = rcb_alloc(&c->alloc, total * sizeof *ws->nu);
  if (!ws->nu) return rcb_cmp_fail(c, RCB_ERR_NOMEM, "out of memory (modal fit)");
  ws->wt = ws->nu + n, ws->B = ws->wt + nch * n, ws->tau = ws->B + ws->rows * ws->cols;
  ws->S = ws->tau + ws->cols;
  ws->lwork = ws_query(ws);
  if (ws->lwork < 0) return rcb_cmp_fail(c, RCB_ERR_LAPACK, "modal fit: workspace query failed");
  if (ws->lwork < 1) ws->lwork = 1;
  ws->work = rcb_alloc(&c->alloc, (size_t)ws->lwork * sizeof probe);
  return ws->work ? RCB_OK : rcb_cmp_fail(c, RCB_ERR_NOMEM, "out of memory (modal fit)");
}

static void ws_destroy(rcb_compare *c, modal_ws *ws) {
  rcb_free(&c->alloc, ws->nu);
  rcb_free(&c->alloc, ws->work);
}

/* Channel k's weighted Levy rows into ws->B: 2i (real) and 2i + 1 (imaginary)
 * of -N_k(s) + H (a_0 + ... + a_2N-1 s^2N-1) = -H s^2N, columns
 * Re b_0..b_2N, Im b_0..b_2N, a_0..a_2N-1, right-hand side. */
static void levy_block(modal_ws *ws, const rcb_complex *h, const double *wt) {
  size_t i, j, m = ws->rows, q = ws->order + 1;
  for (i = 0; i < ws->n; i++) {
    double complex s = CMPLX(0.0, ws->nu[i]), sj = 1.0, hk = h[i];
    for (j = 0; j <= ws->order; j++, sj *= s) {
      double complex g[3] = {-sj, CMPLX(0.0, -1.0) * sj, hk * sj};
      size_t col[3] = {j, q + j, ws->nb + j}, u;
      if (j == ws->order) g[2] = -g[2]; /* the monic term goes to the right */
      for (u = 0; u < 3; u++) {
        ws->B[2 * i + m * col[u]] = wt[i] * creal(g[u]);
        ws->B[2 * i + 1 + m * col[u]] = wt[i] * cimag(g[u]);
      }
    }
  }
}

/* One weighted Levy pass over every channel: a[0..2N-1]. 0 on success. */
static int levy_pass(modal_ws *ws, const rcb_complex *h, double *a) {
  size_t k, r, col, q = ws->order + 1, ls = ws->nch * q, m = ws->rows;
  for (k = 0; k < ws->nch; k++) {
    levy_block(ws, h + k * ws->n, ws->wt + k * ws->n);
    if (LAPACKE_dgeqrf_work(LAPACK_COL_MAJOR, (lapack_int)m, (lapack_int)ws->cols, ws->B,
                            (lapack_int)m, ws->tau, ws->work, ws->lwork))
      return 1;
    for (col = 0; col < q; col++) /* R's trailing triangle (below it: reflectors) */
      for (r = 0; r < q; r++)
        ws->S[k * q + r + ls * col] = r <= col ? ws->B[ws->nb + r + m * (ws->nb + col)] : 0.0;
  }
  if (LAPACKE_dgels_work(LAPACK_COL_MAJOR, 'N', (lapack_int)ls, (lapack_int)ws->order, 1, ws->S,
                         (lapack_int)ls, ws->S + ls * ws->order, (lapack_int)ls, ws->work,
                         ws->lwork))
    return 1;
  for (k = 0; k < ws->order; k++) {
    a[k] = ws->S[ls * ws->order + k];
    if (!isfinite(a[k])) return 1;
  }
  return 0;
}

/* Roots of the monic s^2N + a_2N-1 s^2N-1 + ... + a_0 (2N <= 8): eigenvalues
 * of its companion matrix, already upper Hessenberg. 0 on success. */
static int poly_roots(const double *a, size_t order, double *re, double *im) {
  double H[64], scale[8], work[64], z = 0.0;
  lapack_int nn = (lapack_int)order, ilo = 1, ihi = nn;
  size_t j;
  memset(H, 0, sizeof H);
  for (j = 0; j < order; j++) H[order * j] = -a[order - 1 - j];
  for (j = 1; j < order; j++) H[j + order * (j - 1)] = 1.0;
  if (LAPACKE_dgebal_work(LAPACK_COL_MAJOR, 'S', nn, H, nn, &ilo, &ihi, scale)) return 1;
  return LAPACKE_dhseqr_work(LAPACK_COL_MAJOR, 'E', 'N', nn, ilo, ihi, H, nn, re, im, &z, 1,
                             work, 64) != 0;
}

/* The stable underdamped roots (Re < 0 < Im) as wn (scaled) and zeta,
 * sorted by wn; returns how many. */
static size_t keep_modes(const double *re, const double *im, size_t order, double *wn,
                         double *zeta) {
  size_t j, np = 0, i;
  for (j = 0; j < order; j++) {
    double r = hypot(re[j], im[j]), z;
    if (!(re[j] < 0.0 && im[j] > 0.0)) continue;
    z = -re[j] / r;
    for (i = np++; i > 0 && wn[i - 1] > r; i--) wn[i] = wn[i - 1], zeta[i] = zeta[i - 1];
    wn[i] = r, zeta[i] = z;
  }
  return np;
}

/* Sanathanan-Koerner weights 1 / (|D(s)| |H|) of this pass's denominator. */
static void sk_weights(modal_ws *ws, const rcb_complex *h, const double *a) {
  size_t i, j, k;
  for (i = 0; i < ws->n; i++) {
    double complex s = CMPLX(0.0, ws->nu[i]), d = 1.0;
    double ad;
    for (j = ws->order; j-- > 0;) d = d * s + a[j];
    ad = cabs(d);
    for (k = 0; k < ws->nch; k++) {
      double ah = cabs(h[k * ws->n + i]);
      ws->wt[k * ws->n + i] = ad > 0 && ah > 0 ? 1.0 / (ad * ah) : 0.0;
    }
  }
}

rcb_status rcb_cmp_modal_fit_multi(rcb_compare *c, const double *w, const rcb_complex *h,
                                   size_t nch, size_t n, double wref, size_t nmodes,
                                   double *wn, double *zeta, size_t *nfound) {
  modal_ws ws;
  double a[8], re[8], im[8], pw[4], pz[4];
  size_t i, pass, np;
  rcb_status st;
  *nfound = 0;
  if (nmodes < 1 || nmodes > 4 || nch < 1 || !(wref > 0))
    return rcb_cmp_fail(c, RCB_ERR_ARG, "modal fit: %zu modes, %zu channels", nmodes, nch);
  if (n < 3 * nmodes + 2) return RCB_OK; /* fewer equations than unknowns */
  if ((st = ws_create(c, &ws, n, nch, nmodes))) {
    ws_destroy(c, &ws);
    return st;
  }
  for (i = 0; i < n; i++) ws.nu[i] = w[i] / wref;
  for (i = 0; i < nch * n; i++) ws.wt[i] = cabs(h[i]) > 0 ? 1.0 / cabs(h[i]) : 0.0;
  for (pass = 0; pass < 8; pass++) {
    if (levy_pass(&ws, h, a) || poly_roots(a, ws.order, re, im)) break;
    np = keep_modes(re, im, ws.order, pw, pz);
    if (!np) break; /* no damped resonance: keep the last pass that had one */
    for (i = 0; i < np; i++) wn[i] = wref * pw[i], zeta[i] = pz[i];
    *nfound = np;
    sk_weights(&ws, h, a);
  }
  ws_destroy(c, &ws);
  return RCB_OK;
}

rcb_status rcb_cmp_modal_fit(rcb_compare *c, const double *w, const rcb_complex *h, size_t n,
                             double wref, double *wn, double *zeta) {
  size_t np = 0;
  rcb_status st = rcb_cmp_modal_fit_multi(c, w, h, 1, n, wref, 1, wn, zeta, &np);
  if (!np) *wn = *zeta = (double)NAN;
  return st;
}
