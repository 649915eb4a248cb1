/*
 * Sensitivities of many parameters at one model, for the diagnosis' score
 * test: eq. 9 by the adjoint. With the factorisation of Z at each point, the
 * solutions X = Z^-1 B (kept by the model solve) and Y = Z^-T E_out (one
 * transposed re-solve for the outputs), every parameter's
 *   dH_oq/dp = Y_o^T (dF/dp - dZ/dp X_q)
 * costs a sum over the few non-zero entries of dZ/dp: no solve per
 * parameter, and one factorisation per point for all the candidates.
 */
#include <string.h>

#include "identify/fit_internal.h"

/* The non-zero entries (i, j) of dM, dC, dG, dK (d: four matrices in the
 * layout), column by column over the stored pattern; count only when e is
 * NULL. */
static void collect(const rcb_layout *L, const double *d, rcb_fit_dz_entry *e, size_t *ne) {
  size_t sz = rcb_layout_size(L), n = L->n, i, j, a, k = 0;
  for (j = 0; j < n; j++) {
    size_t i0 = j > L->ku ? j - L->ku : 0, i1 = j + L->kl < n ? j + L->kl : n - 1;
    size_t a0 = L->sparse ? (size_t)L->colp[j] : i0, a1 = L->sparse ? (size_t)L->colp[j + 1] : i1 + 1;
    for (a = a0; a < a1; a++) {
      size_t s;
      i = L->sparse ? (size_t)L->rowi[a] : a;
      s = L->sparse ? a : rcb_layout_at(L, i, j);
      if (d[s] == 0.0 && d[sz + s] == 0.0 && d[2 * sz + s] == 0.0 && d[3 * sz + s] == 0.0)
        continue;
      if (e) {
        e[k].row = i, e[k].col = j;
        e[k].m = d[s], e[k].c = d[sz + s], e[k].g = d[2 * sz + s], e[k].k = d[3 * sz + s];
      }
      k++;
    }
  }
  *ne = k;
}

void rcb_fit_dz_free(const rcb_allocator *a, rcb_fit_dz *dz, size_t n) {
  size_t k;
  for (k = 0; dz && k < n; k++) {
    rcb_free(a, dz[k].e);
    rcb_free(a, dz[k].dF);
    dz[k].e = NULL, dz[k].dF = NULL, dz[k].ne = 0;
  }
}

rcb_status rcb_fit_dz_collect(rcb_fit *f, const rcb_allocator *a, rcb_fit_dz *dz) {
  size_t k, ndof = f->m->ndof, sz = 4 * rcb_layout_size(rcb_frf_layout(f->frf)), d;
  for (k = 0; k < f->np; k++) dz[k].e = NULL, dz[k].dF = NULL, dz[k].ne = 0;
  for (k = 0; k < f->np; k++) {
    const double *dm = f->dmat + k * sz;
    const rcb_complex *F = f->dF + k * ndof;
    size_t ne;
    collect(rcb_frf_layout(f->frf), dm, NULL, &ne);
    dz[k].e = rcb_alloc(a, (ne ? ne : 1) * sizeof *dz[k].e);
    if (!dz[k].e) goto nomem;
    collect(rcb_frf_layout(f->frf), dm, dz[k].e, &dz[k].ne);
    for (d = 0; d < ndof && F[d] == 0.0; d++) continue;
    if (d == ndof) continue; /* the force does not depend on it */
    if (!(dz[k].dF = rcb_alloc(a, ndof * sizeof *dz[k].dF))) goto nomem;
    memcpy(dz[k].dF, F, ndof * sizeof *F);
  }
  return RCB_OK;
nomem:
  rcb_fit_dz_free(a, dz, f->np);
  return rcb_fit_fail(f, RCB_ERR_NOMEM, "out of memory (parameter derivatives)");
}

/* Only the derivative matrices' workspaces: the residual layout (every
 * measured point's weight, the prepare step) is not needed for them, and
 * the diagnosis takes the derivatives of every candidate (70 x 35 000
 * residuals on 32 x 1101). rcb_fit_prepare frees and resizes them. */
static rcb_status dz_workspace(rcb_fit *c) {
  size_t sz = 4 * rcb_layout_size(rcb_frf_layout(c->frf)) * (c->np + 1);
  size_t nf = c->m->ndof * (c->np + 1);
  if (c->prepared) return RCB_OK;
  rcb_free(&c->alloc, c->dmat);
  rcb_free(&c->alloc, c->dF);
  c->dmat = rcb_alloc(&c->alloc, sz * sizeof *c->dmat);
  c->dF = rcb_alloc(&c->alloc, (nf ? nf : 1) * sizeof *c->dF);
  if (c->dmat && c->dF) return RCB_OK;
  return rcb_fit_fail(c, RCB_ERR_NOMEM, "out of memory (parameter derivatives)");
}

rcb_status rcb_fit_dz_get(rcb_fit *c, const rcb_allocator *a, rcb_fit_dz *dz) {
  size_t k;
  rcb_status st;
  for (k = 0; k < c->np; k++) dz[k].e = NULL, dz[k].dF = NULL, dz[k].ne = 0;
  for (k = 0; k < c->np; k++)
    if (c->par[k].chain)
      return rcb_fit_fail(c, RCB_ERR_ARG,
                          "parameter %s belongs to the measurement chain: it has no dZ/dp "
                          "(its column is the fit's own, rcb_fit_jacobian)",
                          c->par[k].name);
  if ((st = dz_workspace(c)) || (st = rcb_fit_derivative_matrices(c))) return st;
  return rcb_fit_dz_collect(c, a, dz);
}

/* dZ/dp = dK - w^2 dM + i w (dC + W dG) of one parameter at a point, over
 * its entries (z: 2 ne values, real and imaginary parts), once for all the
 * channels that use it. */
static void dz_values(const rcb_fit_dz *p, double w, double W, double *z) {
  size_t a;
  for (a = 0; a < p->ne; a++) {
    const rcb_fit_dz_entry *e = &p->e[a];
    z[2 * a] = e->k - w * w * e->m;
    z[2 * a + 1] = w * (e->c + W * e->g);
  }
}

/* The distinct rows of one parameter's entries: rows[0 .. *nr) and each
 * entry's index among them, slot[a]. */
static void entry_rows(const rcb_fit_dz *p, size_t *slot, size_t *rows, size_t *nr) {
  size_t a, r;
  *nr = 0;
  for (a = 0; a < p->ne; a++) {
    for (r = 0; r < *nr && rows[r] != p->e[a].row; r++) continue;
    if (r == *nr) rows[(*nr)++] = p->e[a].row;
    slot[a] = r;
  }
}

/* dH_oq/dp of one parameter, -Y_o^T dZ X_q, for every output o and input
 * q < nq into dh[o * nq + q], grouped by the rows of dZ's entries: first
 * s_q = dZ X_q on those rows (ne nq products), then -Y_o^T s_q (nr nout nq):
 * a shaft element's 64 entries on 8 rows take 512 complex products per
 * point for 8 outputs and 4 inputs, where the entry-wise sum Y_o(row) z
 * X_q(col) took 2560. z from dz_values; s work (2 nr nq). The sums in real
 * arithmetic, without the compiler's NaN-recovery branches of complex
 * products. The unbalance's force term is the caller's. */
static void dh_adjoint(const rcb_fit_dz *p, const size_t *slot, const size_t *rows, size_t nr,
                       const double *z, const rcb_complex *X, const rcb_complex *Y, size_t n,
                       size_t nout, size_t nq, double *sq, rcb_complex *dh) {
  size_t o, q, a, r;
  for (a = 0; a < 2 * nr * nq; a++) sq[a] = 0.0;
  for (a = 0; a < p->ne; a++) {
    double zr = z[2 * a], zi = z[2 * a + 1];
    const rcb_complex *x = X + p->e[a].col;
    double *t = sq + 2 * slot[a] * nq;
    for (q = 0; q < nq; q++) {
      double xr = creal(x[n * q]), xi = cimag(x[n * q]);
      t[2 * q] += zr * xr - zi * xi;
      t[2 * q + 1] += zr * xi + zi * xr;
    }
  }
  for (o = 0; o < nout; o++) {
    const rcb_complex *y = Y + n * o;
    double *acc = (double *)(dh + o * nq); /* re, im of each q */
    for (q = 0; q < 2 * nq; q++) acc[q] = 0.0;
    for (r = 0; r < nr; r++) {
      double yr = creal(y[rows[r]]), yi = cimag(y[rows[r]]);
      const double *t = sq + 2 * r * nq;
      for (q = 0; q < nq; q++) {
        acc[2 * q] -= yr * t[2 * q] - yi * t[2 * q + 1];
        acc[2 * q + 1] -= yr * t[2 * q + 1] + yi * t[2 * q];
      }
    }
  }
}

/* The unbalance's force term of dH_o/dp, Y_o^T w^2 dF, added to s. */
static double complex dh_force(const rcb_fit_dz *p, const rcb_complex *y, double w, size_t n,
                               double complex s) {
  size_t a;
  for (a = 0; a < n; a++) s += y[a] * (w * w) * p->dF[a];
  return s;
}

/* Work of the adjoint sweep: adjoint solutions, one point's dH per channel,
 * one parameter's dZ entries, and the rows of every parameter's entries. */
typedef struct adj_ws {
  rcb_complex *Y, *dH; /* n x nout, nch */
  rcb_complex *g;      /* the point's residuals' coefficients (rcb_fit_res_coef) */
  double *z;           /* 2 x the most entries of any parameter */
  double *sq;          /* 2 x the most rows x the inputs: dZ X_q on the rows (dh_adjoint) */
  rcb_complex *dho;    /* nout x the inputs: one parameter's dH of every pair */
  size_t *slot, *rows; /* per parameter, from off[k]: entry_rows' slot and rows */
  size_t *off, *nr;    /* ndz each: the parameter's first entry in slot, rows; its rows */
} adj_ws;

/* One point: the model solve, the adjoint solutions with its factorisation
 * (rcb_frf_solve_adjoint), then every column. */
static rcb_status score_point(rcb_fit *f, size_t i, const rcb_fit_dz *dz, size_t ndz,
                              const adj_ws *ws, double *J) {
  size_t n = f->m->ndof, k, c, jj, nq = f->unbalance || !f->nin ? 1 : f->nin;
  double w = f->grid[i], W = rcb_fit_point_speed(f, w);
  const rcb_complex *X;
  rcb_status st;
  if ((st = rcb_fit_solve_point(f, i))) return st;
  if ((st = rcb_frf_solve_adjoint(f->frf, ws->Y)))
    return rcb_fit_fail(f, st, "adjoint solve at %g rad/s: %s", w, rcb_frf_errmsg(f->frf));
  X = rcb_frf_solution(f->frf, 0); /* not NULL: the adjoint solve found the factors */
  for (jj = f->pt_first[i]; jj < f->pt_first[i + 1]; jj++)
    ws->g[jj - f->pt_first[i]] = rcb_fit_res_coef(f, f->pt_res[jj]);
  for (k = 0; k < ndz; k++) {
    dz_values(&dz[k], w, W, ws->z);
    dh_adjoint(&dz[k], ws->slot + ws->off[k], ws->rows + ws->off[k], ws->nr[k], ws->z, X,
               ws->Y, n, f->nout, nq, ws->sq, ws->dho);
    for (c = 0; c < f->nch; c++) {
      size_t q = f->unbalance ? 0 : f->ch_in[c];
      ws->dH[c] = ws->dho[f->ch_out[c] * nq + q];
      if (f->unbalance && dz[k].dF)
        ws->dH[c] = dh_force(&dz[k], ws->Y + n * f->ch_out[c], w, n, ws->dH[c]);
    }
    for (jj = f->pt_first[i]; jj < f->pt_first[i + 1]; jj++) {
      size_t j = f->pt_res[jj];
      rcb_complex g = ws->g[jj - f->pt_first[i]], dh = ws->dH[f->res_ch[j]];
      J[j + f->nres * k] = creal(g) * creal(dh) - cimag(g) * cimag(dh); /* Re(g dh) */
    }
  }
  return RCB_OK;
}

/* One point by the direct re-solve instead (rcb_fit_adj with fewer
 * parameters x inputs than outputs): dX_kq = Z^-1 (w^2 dF_k - dZ_k X_q)
 * with the point's factors, ndz nq right-hand sides in ws->Y (n x nout
 * holds them), and dH_oq/dp_k its output's row. */
static rcb_status direct_point(rcb_fit *f, size_t i, const rcb_fit_dz *dz, size_t ndz,
                               const adj_ws *ws, double *J) {
  size_t n = f->m->ndof, k, c, q, a, jj, nq = f->unbalance || !f->nin ? 1 : f->nin;
  double w = f->grid[i], W = rcb_fit_point_speed(f, w);
  const rcb_complex *X;
  rcb_status st;
  if ((st = rcb_fit_solve_point(f, i))) return st;
  if (!(X = rcb_frf_solution(f->frf, 0)))
    return rcb_fit_fail(f, RCB_ERR_STATE, "direct re-solve at %g rad/s: no factors", w);
  memset(ws->Y, 0, n * ndz * nq * sizeof *ws->Y);
  for (k = 0; k < ndz; k++) {
    double *y = (double *)(ws->Y + n * nq * k); /* re, im */
    dz_values(&dz[k], w, W, ws->z);
    for (a = 0; a < dz[k].ne; a++) {
      double zr = ws->z[2 * a], zi = ws->z[2 * a + 1];
      size_t row = dz[k].e[a].row, col = dz[k].e[a].col;
      for (q = 0; q < nq; q++) {
        double xr = creal(X[col + n * q]), xi = cimag(X[col + n * q]);
        y[2 * (row + n * q)] -= zr * xr - zi * xi;
        y[2 * (row + n * q) + 1] -= zr * xi + zi * xr;
      }
    }
    for (a = 0; f->unbalance && dz[k].dF && a < n; a++) ws->Y[n * k + a] += (w * w) * dz[k].dF[a];
  }
  if ((st = rcb_frf_solve_again(f->frf, ws->Y, ndz * nq)))
    return rcb_fit_fail(f, st, "direct re-solve at %g rad/s: %s", w, rcb_frf_errmsg(f->frf));
  for (jj = f->pt_first[i]; jj < f->pt_first[i + 1]; jj++)
    ws->g[jj - f->pt_first[i]] = rcb_fit_res_coef(f, f->pt_res[jj]);
  for (k = 0; k < ndz; k++) {
    for (c = 0; c < f->nch; c++) {
      q = f->unbalance ? 0 : f->ch_in[c];
      ws->dH[c] = ws->Y[rcb_frf_output_row(f->frf, f->ch_out[c]) + n * (q + nq * k)];
    }
    for (jj = f->pt_first[i]; jj < f->pt_first[i + 1]; jj++) {
      size_t j = f->pt_res[jj];
      rcb_complex g = ws->g[jj - f->pt_first[i]], dh = ws->dH[f->res_ch[j]];
      J[j + f->nres * k] = creal(g) * creal(dh) - cimag(g) * cimag(dh); /* Re(g dh) */
    }
  }
  return RCB_OK;
}

static void adj_free(rcb_fit *f, adj_ws *ws) {
  rcb_free(&f->alloc, ws->Y);
  rcb_free(&f->alloc, ws->dH);
  rcb_free(&f->alloc, ws->z);
  rcb_free(&f->alloc, ws->g);
  rcb_free(&f->alloc, ws->sq);
  rcb_free(&f->alloc, ws->dho);
  rcb_free(&f->alloc, ws->slot);
  rcb_free(&f->alloc, ws->rows);
  rcb_free(&f->alloc, ws->off);
  rcb_free(&f->alloc, ws->nr);
}

/* The sweep's work, and the rows of every parameter's entries. */
static rcb_status adj_alloc(rcb_fit *f, const rcb_fit_dz *dz, size_t ndz, adj_ws *ws) {
  size_t n = f->m->ndof, ne = 1, tot = 0, nrmax = 1, k;
  size_t nq = f->unbalance || !f->nin ? 1 : f->nin, nout = f->nout ? f->nout : 1;
  memset(ws, 0, sizeof *ws);
  for (k = 0; k < ndz; k++) ne = dz[k].ne > ne ? dz[k].ne : ne, tot += dz[k].ne;
  ws->slot = rcb_alloc(&f->alloc, (tot ? tot : 1) * sizeof *ws->slot);
  ws->rows = rcb_alloc(&f->alloc, (tot ? tot : 1) * sizeof *ws->rows);
  ws->off = rcb_alloc(&f->alloc, (ndz ? ndz : 1) * sizeof *ws->off);
  ws->nr = rcb_alloc(&f->alloc, (ndz ? ndz : 1) * sizeof *ws->nr);
  if (ws->slot && ws->rows && ws->off && ws->nr)
    for (k = 0, tot = 0; k < ndz; tot += dz[k].ne, k++) {
      ws->off[k] = tot;
      entry_rows(&dz[k], ws->slot + tot, ws->rows + tot, &ws->nr[k]);
      nrmax = ws->nr[k] > nrmax ? ws->nr[k] : nrmax;
    }
  ws->Y = rcb_alloc(&f->alloc, n * nout * sizeof *ws->Y);
  ws->dH = rcb_alloc(&f->alloc, (f->nch ? f->nch : 1) * sizeof *ws->dH);
  ws->z = rcb_alloc(&f->alloc, 2 * ne * sizeof *ws->z);
  ws->sq = rcb_alloc(&f->alloc, 2 * nrmax * nq * sizeof *ws->sq);
  ws->dho = rcb_alloc(&f->alloc, nout * nq * sizeof *ws->dho);
  ws->g = rcb_alloc(&f->alloc, 2 * (f->nch ? f->nch : 1) * sizeof *ws->g); /* 2 parts per channel */
  if (ws->Y && ws->dH && ws->z && ws->sq && ws->dho && ws->g && ws->slot && ws->rows &&
      ws->off && ws->nr)
    return RCB_OK;
  adj_free(f, ws);
  return rcb_fit_fail(f, RCB_ERR_NOMEM, "out of memory (adjoint)");
}

/* Every point with workspace ws: columns d r / d p of dz[0 .. ndz) into J,
 * the model values into Hmod. */
static rcb_status adj_points(rcb_fit *f, const rcb_fit_dz *dz, size_t ndz, const adj_ws *ws,
                             double *J) {
  size_t i;
  rcb_status st = RCB_OK;
  for (i = 0; !st && i < f->npts; i++)
    if (f->pt_used[i]) st = score_point(f, i, dz, ndz, ws, J);
  return st;
}

/* The same with a workspace of its own. */
static rcb_status sweep_adjoint(rcb_fit *f, const rcb_fit_dz *dz, size_t ndz, double *J) {
  adj_ws ws;
  rcb_status st = adj_alloc(f, dz, ndz, &ws);
  if (st) return st;
  st = adj_points(f, dz, ndz, &ws, J);
  adj_free(f, &ws);
  return st;
}

struct rcb_fit_adj {
  rcb_fit_dz *dz; /* ndz copies of the caller's (their entries stay the caller's) */
  size_t ndz;
  int direct;     /* ndz x the inputs < the outputs: direct_point's re-solves
                     are fewer than the adjoint's (rcb_fit_adjoint_cheaper) */
  adj_ws ws;
};

rcb_status rcb_fit_adj_create(rcb_fit *f, const rcb_fit_dz *dz, size_t ndz, rcb_fit_adj **out) {
  rcb_fit_adj *a;
  rcb_status st;
  if (!f || !out || (!dz && ndz)) return RCB_ERR_ARG;
  *out = NULL;
  if (!(a = rcb_alloc(&f->alloc, sizeof *a)))
    return rcb_fit_fail(f, RCB_ERR_NOMEM, "out of memory (adjoint)");
  if (!(a->dz = rcb_alloc(&f->alloc, (ndz ? ndz : 1) * sizeof *a->dz))) {
    rcb_free(&f->alloc, a);
    return rcb_fit_fail(f, RCB_ERR_NOMEM, "out of memory (adjoint)");
  }
  if (ndz) memcpy(a->dz, dz, ndz * sizeof *dz);
  a->ndz = ndz;
  a->direct = ndz * (f->unbalance || !f->nin ? 1 : f->nin) < f->nout;
  if ((st = adj_alloc(f, a->dz, ndz, &a->ws))) {
    rcb_free(&f->alloc, a->dz);
    rcb_free(&f->alloc, a);
    return st;
  }
  *out = a;
  return RCB_OK;
}

rcb_status rcb_fit_adj_run(rcb_fit *f, rcb_fit_adj *a, double *J) {
  rcb_status st;
  if (!f || !a || !J) return RCB_ERR_ARG;
  size_t i;
  if ((st = rcb_fit_prepare(f))) return st;
  rcb_frf_refresh(f->frf);
  if (!a->direct) st = adj_points(f, a->dz, a->ndz, &a->ws, J);
  for (i = 0; a->direct && !st && i < f->npts; i++)
    if (f->pt_used[i]) st = direct_point(f, i, a->dz, a->ndz, &a->ws, J);
  if (!st) f->sweeps++;
  return st;
}

void rcb_fit_adj_destroy(rcb_fit *f, rcb_fit_adj *a) {
  if (!f || !a) return;
  adj_free(f, &a->ws);
  rcb_free(&f->alloc, a->dz);
  rcb_free(&f->alloc, a);
}

rcb_status rcb_fit_jacobian_dz(rcb_fit *f, const rcb_fit_dz *dz, size_t ndz, double *J) {
  rcb_status st;
  if (!f || (!dz && ndz) || !J) return RCB_ERR_ARG;
  if ((st = rcb_fit_prepare(f))) return st;
  rcb_frf_refresh(f->frf);
  if (!(st = sweep_adjoint(f, dz, ndz, J))) f->sweeps++;
  return st;
}

int rcb_fit_adjoint_cheaper(const rcb_fit *f) {
  /* right-hand sides per point: nout transposed vs np per input direct */
  return f->nout < f->np * (f->unbalance || !f->nin ? 1 : f->nin);
}

rcb_status rcb_fit_jac_adjoint(rcb_fit *f, double *Jp) {
  rcb_fit_dz *dz = rcb_alloc(&f->alloc, (f->np ? f->np : 1) * sizeof *dz);
  rcb_status st = dz ? rcb_fit_dz_collect(f, &f->alloc, dz)
                     : rcb_fit_fail(f, RCB_ERR_NOMEM, "out of memory (adjoint)");
  if (!st) st = sweep_adjoint(f, dz, f->np, Jp);
  if (dz) rcb_fit_dz_free(&f->alloc, dz, f->np);
  rcb_free(&f->alloc, dz);
  return st;
}
