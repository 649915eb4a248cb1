/*
 * Modal solution path for FRFs (paper eq. 7). At one rotor speed Omega the
 * first-order form of M q'' + D q' + K q = f, D = C + Omega G (bearings at
 * Omega included), is
 *
 *   x' = A x + b,  x = [q; q'],  A = [0, I; -M^-1 K, -M^-1 D],  b = [0; M^-1 f].
 *
 * With A = V Lambda V^-1 (dgeev's right eigenvectors V; the rows of V^-1 are
 * the left eigenvectors, biorthonormal to V by construction),
 *
 *   H_jk(w) = sum_r V_jr (V^-1 b_k)_r / (i w - lambda_r),
 *
 * the paper's sum of right x left eigenvector products over (i w b_r + a_r)
 * with the normalisation b_r = 1, a_r = -lambda_r. Only the nin columns
 * V^-1 b_k are needed (one LU of V), and only the nout rows of V, so the
 * residues R_r = phi_r psi_r^T of the requested outputs x inputs are formed
 * once per speed; each frequency then costs O(modes x nout x nin).
 *
 * Truncation keeps the lowest |lambda| and adds the static residual of the
 * dropped modes: H_direct(0) - sum_kept R_r / (-lambda_r), so the truncated
 * sum is exact at omega = 0 and its error grows toward the dropped modes.
 */
#include <lapacke.h>
#include <limits.h>
#include <math.h>
#include <string.h>

#include "analyses/frf_internal.h"
#include "analyses/state_space.h"

typedef struct rcb_frf_modal rcb_frf_modal;

struct rcb_frf_modal {
  size_t n, N, nch, bytes; /* DOF, states 2n, outputs x inputs, bytes held */
  size_t max_modes;        /* truncation: modes kept, 0 = all */
  double max_freq;         /* truncation: largest |lambda| kept, rad/s, 0 = all */
  int valid;               /* the basis below is for rotor speed `speed` */
  double speed;            /* rad/s */
  double *M, *KD, *G;      /* n x n, n x 2n ([K | D], then M^-1 [K | D]), n x n */
  double *A;               /* N x N state matrix; after dgeev the LU of V */
  double *V;               /* N x N right eigenvectors, real pairs (dgeev) */
  double *Y;               /* N x nin: b_k, then V^-1 b_k */
  double *wr, *wi, *work;  /* eigenvalues; dgeev work (also dgecon's 4N) */
  lapack_int lwork, *piv;  /* piv: N, also dgecon's integer work */
  size_t *order;           /* N: roots by increasing |lambda| */
  size_t nkept, nterms;    /* kept roots; terms of the sum (a conjugate pair is one) */
  rcb_complex *lam;        /* per term: its root (Im > 0 for a pair), 1/s */
  unsigned char *pair;     /* per term: 1 if the root's conjugate is in it too */
  rcb_complex *R;          /* residues, nch per term: R[t * nch + o + nout * i] */
  rcb_complex *res0;       /* static residual term, nch */
  rcb_complex *Hd, *Hm;    /* nch scratch: direct and modal H for the checks */
  rcb_modal_info info;
};

static void *md_alloc(rcb_frf *f, size_t count, size_t size) {
  if (size && count > SIZE_MAX / size) return NULL;
  f->modal->bytes += count * size;
  return rcb_alloc(&f->alloc, count * size);
}

void rcb_frf_modal_destroy(rcb_frf *f) {
  rcb_frf_modal *md;
  void *arrays[18];
  size_t k;
  if (!f || !f->modal) return;
  md = f->modal;
  arrays[0] = md->M, arrays[1] = md->KD, arrays[2] = md->G, arrays[3] = md->A;
  arrays[4] = md->V, arrays[5] = md->Y, arrays[6] = md->wr, arrays[7] = md->wi;
  arrays[8] = md->work, arrays[9] = md->piv, arrays[10] = md->order, arrays[11] = md->lam;
  arrays[12] = md->R, arrays[13] = md->res0, arrays[14] = md->Hd, arrays[15] = md->Hm;
  arrays[16] = md->pair, arrays[17] = md;
  for (k = 0; k < 18; k++) rcb_free(&f->alloc, arrays[k]);
  f->modal = NULL;
}

/* dgeev's workspace, queried once (at least 4N, dgecon's need). */
static rcb_status size_eigen_work(rcb_frf *f) {
  rcb_frf_modal *md = f->modal;
  lapack_int N = (lapack_int)md->N, info;
  double wq = 0.0, dummy = 0.0;
  info = LAPACKE_dgeev_work(LAPACK_COL_MAJOR, 'N', 'V', N, md->A, N, md->wr, md->wi, &dummy,
                            1, md->V, N, &wq, -1);
  if (info != 0 || !(wq >= 1.0) || wq > (double)INT_MAX)
    return rcb_set_error(f->errmsg, RCB_ERR_LAPACK,
                         "modal: dgeev workspace query failed (info %d) for %zu states",
                         (int)info, md->N);
  md->lwork = (lapack_int)wq < 4 * N ? 4 * N : (lapack_int)wq;
  md->work = md_alloc(f, (size_t)md->lwork, sizeof *md->work);
  return md->work ? RCB_OK
                  : rcb_set_error(f->errmsg, RCB_ERR_NOMEM, "modal: out of memory (dgeev work)");
}

rcb_status rcb_frf_modal_create(rcb_frf *f, const rcb_frf_modal *like) {
  rcb_frf_modal *md;
  size_t n = f->m->ndof, N = 2 * n, nin = f->nin ? f->nin : 1;
  if (n > RCB_MODAL_MAX_DOF)
    return rcb_set_error(f->errmsg, RCB_ERR_ARG,
                         "modal solver: %zu DOF is above its limit of %d (the state-space "
                         "eigenproblem is dense, 2n x 2n); use sparse or banded",
                         n, RCB_MODAL_MAX_DOF);
  md = f->modal = rcb_alloc(&f->alloc, sizeof *md);
  if (!md) return rcb_set_error(f->errmsg, RCB_ERR_NOMEM, "modal: out of memory");
  md->bytes = sizeof *md;
  md->n = n, md->N = N, md->nch = f->nout * f->nin;
  if (like) md->max_modes = like->max_modes, md->max_freq = like->max_freq;
  md->M = md_alloc(f, n * n, sizeof(double));
  md->KD = md_alloc(f, 2 * n * n, sizeof(double));
  md->G = md_alloc(f, n * n, sizeof(double));
  md->A = md_alloc(f, N * N, sizeof(double));
  md->V = md_alloc(f, N * N, sizeof(double));
  md->Y = md_alloc(f, N * nin, sizeof(double));
  md->wr = md_alloc(f, N, sizeof(double));
  md->wi = md_alloc(f, N, sizeof(double));
  md->piv = md_alloc(f, N, sizeof *md->piv);
  md->order = md_alloc(f, N, sizeof *md->order);
  md->lam = md_alloc(f, N, sizeof *md->lam);
  md->pair = md_alloc(f, N, sizeof *md->pair);
  md->R = md_alloc(f, N * (md->nch ? md->nch : 1), sizeof *md->R);
  md->res0 = md_alloc(f, md->nch + 1, sizeof *md->res0);
  md->Hd = md_alloc(f, md->nch + 1, sizeof *md->Hd);
  md->Hm = md_alloc(f, md->nch + 1, sizeof *md->Hm);
  if (!md->M || !md->KD || !md->G || !md->A || !md->V || !md->Y || !md->wr || !md->wi ||
      !md->piv || !md->order || !md->lam || !md->pair || !md->R || !md->res0 || !md->Hd || !md->Hm)
    return rcb_set_error(f->errmsg, RCB_ERR_NOMEM,
                         "modal: out of memory for %zu states (%zu x %zu matrices)", N, N, N);
  return size_eigen_work(f);
}

void rcb_frf_modal_invalidate(rcb_frf *f) {
  if (f && f->modal) f->modal->valid = 0;
}

size_t rcb_frf_modal_memory(const rcb_frf *f) {
  return f && f->modal ? f->modal->bytes : 0;
}

/* A = [0, I; -M^-1 K, -M^-1 D] and Y = [0; M^-1 e_k] at rotor speed (rad/s). */
static rcb_status state_form(rcb_frf *f, double speed) {
  rcb_frf_modal *md = f->modal;
  const size_t n = md->n, N = md->N;
  lapack_int info = 0;
  size_t j;
  rcb_status st = rcb_state_matrix(f->m, speed, md->M, md->KD, md->G, md->A, f->errmsg, "modal");
  if (st) return st;
  memset(md->Y, 0, N * f->nin * sizeof *md->Y);
  for (j = 0; j < f->nin; j++) md->Y[n + f->in_row[j] + N * j] = 1.0;
  if (f->nin)
    info = LAPACKE_dpotrs_work(LAPACK_COL_MAJOR, 'L', (lapack_int)n, (lapack_int)f->nin, md->M,
                               (lapack_int)n, md->Y + n, (lapack_int)N);
  if (info) return rcb_set_error(f->errmsg, RCB_ERR_LAPACK, "modal: dpotrs info %d", (int)info);
  return RCB_OK;
}

/* Eigenvectors V of A, then Y <- V^-1 Y through the LU of V (kept in A). */
static rcb_status eigen_basis(rcb_frf *f, double speed) {
  rcb_frf_modal *md = f->modal;
  lapack_int N = (lapack_int)md->N, info;
  double dummy = 0.0, anorm = 0.0;
  size_t i, j;
  info = LAPACKE_dgeev_work(LAPACK_COL_MAJOR, 'N', 'V', N, md->A, N, md->wr, md->wi, &dummy, 1,
                            md->V, N, md->work, md->lwork);
  if (info)
    return rcb_set_error(f->errmsg, RCB_ERR_LAPACK,
                         "modal: dgeev failed at %g rad/s (info %d, %zu states)", speed,
                         (int)info, md->N);
  memcpy(md->A, md->V, md->N * md->N * sizeof *md->A);
  for (j = 0; j < md->N; j++) {
    double s = 0.0;
    for (i = 0; i < md->N; i++) s += fabs(md->V[i + md->N * j]);
    if (s > anorm) anorm = s;
  }
  info = LAPACKE_dgetrf_work(LAPACK_COL_MAJOR, N, N, md->A, N, md->piv);
  if (info > 0)
    return rcb_set_error(f->errmsg, RCB_ERR_SINGULAR,
                         "modal: the state matrix at %g rad/s is defective (dependent "
                         "eigenvectors, e.g. a free rotor's rigid-body modes): use a direct "
                         "solver", speed);
  if (!info && f->nin)
    info = LAPACKE_dgetrs_work(LAPACK_COL_MAJOR, 'N', N, (lapack_int)f->nin, md->A, N,
                               md->piv, md->Y, N);
  if (info) return rcb_set_error(f->errmsg, RCB_ERR_LAPACK, "modal: dgetrf/s info %d", (int)info);
  /* piv's pivots are no longer needed: it becomes dgecon's integer work */
  if (LAPACKE_dgecon_work(LAPACK_COL_MAJOR, '1', N, md->A, N, anorm, &md->info.rcond_v,
                          md->work, md->piv))
    md->info.rcond_v = (double)NAN;
  return RCB_OK;
}

/* Root j as a complex number, and its eigenvector entry at row r and input
 * coefficient (V^-1 b_k)_j: dgeev stores a pair lambda, conj(lambda) in
 * columns j (Im > 0), j + 1 as v = V_j + i V_{j+1}, conj(v); writing
 * b = y_j V_j + y_{j+1} V_{j+1} in that pair gives coefficients
 * (y_j -+ i y_{j+1}) / 2 on v and conj(v). */
static rcb_complex root(const rcb_frf_modal *md, size_t j) {
  return CMPLX(md->wr[j], md->wi[j]);
}

static rcb_complex vec_entry(const rcb_frf_modal *md, size_t j, size_t r) {
  const double *V = md->V;
  size_t N = md->N;
  if (md->wi[j] > 0.0) return CMPLX(V[r + N * j], V[r + N * (j + 1)]);
  if (md->wi[j] < 0.0) return CMPLX(V[r + N * (j - 1)], -V[r + N * j]);
  return V[r + N * j];
}

static rcb_complex in_coef(const rcb_frf_modal *md, size_t j, size_t k) {
  const double *Y = md->Y + md->N * k;
  if (md->wi[j] > 0.0) return CMPLX(0.5 * Y[j], -0.5 * Y[j + 1]);
  if (md->wi[j] < 0.0) return CMPLX(0.5 * Y[j - 1], 0.5 * Y[j]);
  return Y[j];
}

/* One term of the sum: root j, with its conjugate (residues conj(R), exactly,
 * since V and Y are real) when Im(lambda_j) > 0. */
static void keep_term(const rcb_frf *f, rcb_frf_modal *md, size_t j) {
  size_t o, k;
  rcb_complex *R = md->R + md->nterms * md->nch;
  md->pair[md->nterms] = md->wi[j] > 0.0;
  md->lam[md->nterms++] = root(md, j);
  md->nkept += md->wi[j] > 0.0 ? 2 : 1;
  for (k = 0; k < f->nin; k++) {
    rcb_complex c = in_coef(md, j, k);
    for (o = 0; o < f->nout; o++) R[o + f->nout * k] = vec_entry(md, j, f->out_row[o]) * c;
  }
}

/* Lowest |lambda| first (insertion sort, ties by index), then the kept set:
 * a conjugate pair counts as one mode and stays together. */
static void select_roots(const rcb_frf *f, rcb_frf_modal *md) {
  size_t i, j, modes = 0;
  for (i = 0; i < md->N; i++) {
    double a = cabs(root(md, i));
    for (j = i; j > 0 && cabs(root(md, md->order[j - 1])) > a; j--)
      md->order[j] = md->order[j - 1];
    md->order[j] = i;
  }
  md->nkept = md->nterms = 0;
  md->info.max_kept_wn = 0.0;
  for (i = 0; i < md->N; i++) {
    size_t r = md->order[i];
    double wn = cabs(root(md, r));
    if (md->wi[r] < 0.0) continue; /* kept with its partner */
    if ((md->max_freq > 0.0 && wn > md->max_freq) || (md->max_modes && modes >= md->max_modes))
      break;
    keep_term(f, md, r);
    modes++;
    md->info.max_kept_wn = wn;
  }
  md->info.nmodes = modes;
}

void rcb_frf_modal_sum(const rcb_frf_modal *md, double omega, rcb_frf_kind kind,
                       rcb_complex *H) {
  size_t r, c, nch = md->nch;
  rcb_complex scale;
  for (c = 0; c < nch; c++) H[c] = md->info.residual_used ? md->res0[c] : 0.0;
  for (r = 0; r < md->nterms; r++) {
    /* R d1 + conj(R) d2 with d1 = 1 / (i omega - lambda), d2 = 1 / (i omega -
     * conj(lambda)), written out: Re = a Re(d1 + d2) - b Im(d1 - d2),
     * Im = a Im(d1 + d2) + b Re(d1 - d2) for R = a + i b; a real root has
     * only d1 (and a real R). */
    double lr = creal(md->lam[r]), li = cimag(md->lam[r]);
    double z1 = omega - li, z2 = omega + li, e1 = 1.0 / (lr * lr + z1 * z1);
    double e2 = md->pair[r] ? 1.0 / (lr * lr + z2 * z2) : 0.0;
    double sr = -lr * (e1 + e2), si = -z1 * e1 - z2 * e2; /* d1 + d2 */
    double dr = -lr * (e1 - e2), di = -z1 * e1 + z2 * e2; /* d1 - d2 */
    const rcb_complex *R = md->R + r * nch;
    for (c = 0; c < nch; c++) {
      double a = creal(R[c]), b = cimag(R[c]);
      H[c] += CMPLX(a * sr - b * di, a * si + b * dr);
    }
  }
  switch (kind) {
    case RCB_MOBILITY: scale = CMPLX(0.0, omega); break;
    case RCB_INERTANCE: scale = -omega * omega; break;
    default: return;
  }
  for (c = 0; c < nch; c++) H[c] *= scale;
}

static double max_abs(const rcb_complex *z, size_t n) {
  double m = 0.0;
  size_t k;
  for (k = 0; k < n; k++) m = fmax(m, cabs(z[k]));
  return m;
}

/* Static residual of the dropped modes from one direct solve at omega = 0;
 * none (residual_used = 0) if Z(0) is singular. */
static rcb_status static_residual(rcb_frf *f, double speed) {
  rcb_frf_modal *md = f->modal;
  size_t c;
  rcb_status st;
  md->info.residual_used = 0;
  md->info.residual = 0.0;
  if (md->nkept == md->N || !f->nin) return RCB_OK;
  /* a fresh factorisation: the same residual whatever the sparse solver did before */
  if ((st = rcb_frf_solver_reset(f))) return st;
  st = rcb_frf_eval_direct(f, 0.0, speed, RCB_RECEPTANCE, md->Hd);
  if (st == RCB_ERR_SINGULAR) return RCB_OK;
  if (st) return st;
  rcb_frf_modal_sum(md, 0.0, RCB_RECEPTANCE, md->Hm);
  for (c = 0; c < md->nch; c++) md->res0[c] = md->Hd[c] - md->Hm[c];
  md->info.residual_used = 1;
  md->info.residual = max_abs(md->res0, md->nch) / max_abs(md->Hd, md->nch);
  return RCB_OK;
}

rcb_status rcb_frf_modal_basis(rcb_frf *f, double speed) {
  rcb_frf_modal *md = f->modal;
  rcb_status st;
  if (md->valid && md->speed == speed) return RCB_OK;
  md->valid = 0;
  md->info.residual_used = 0;
  if ((st = state_form(f, speed)) || (st = eigen_basis(f, speed))) return st;
  select_roots(f, md);
  md->info.nroots = md->N;
  md->info.nkept = md->nkept;
  md->info.speed = speed;
  if ((st = static_residual(f, speed))) return st;
  md->speed = speed;
  md->valid = 1;
  return RCB_OK;
}

static rcb_status check_args(rcb_frf *f, double omega, double speed) {
  if (!isfinite(omega) || !isfinite(speed) || omega < 0)
    return rcb_set_error(f->errmsg, RCB_ERR_ARG,
                         "frequency %g rad/s and speed %g rad/s: expected finite, omega >= 0",
                         omega, speed);
  if (f->nin == 0)
    return rcb_set_error(f->errmsg, RCB_ERR_ARG, "no input DOF: created for unbalance only");
  return RCB_OK;
}

rcb_status rcb_frf_modal_eval(rcb_frf *f, double omega, double speed, rcb_frf_kind kind,
                              rcb_complex *H) {
  rcb_status st;
  if (!H) return RCB_ERR_ARG;
  if ((st = check_args(f, omega, speed)) || (st = rcb_frf_modal_basis(f, speed))) return st;
  rcb_frf_modal_sum(f->modal, omega, kind, H);
  return RCB_OK;
}

static rcb_status need_modal(rcb_frf *f) {
  if (!f) return RCB_ERR_ARG;
  if (!f->modal)
    return rcb_set_error(f->errmsg, RCB_ERR_STATE,
                         "not a modal FRF object (create it with RCB_SOLVER_MODAL)");
  return RCB_OK;
}

rcb_status rcb_frf_set_modal(rcb_frf *f, size_t max_modes, double max_freq) {
  rcb_status st = need_modal(f);
  if (st) return st;
  if (!isfinite(max_freq) || max_freq < 0.0)
    return rcb_set_error(f->errmsg, RCB_ERR_ARG,
                         "modal truncation frequency %g rad/s: expected finite, >= 0 (0: all)",
                         max_freq);
  f->modal->max_modes = max_modes;
  f->modal->max_freq = max_freq;
  f->modal->valid = 0;
  return RCB_OK;
}

rcb_status rcb_frf_modal_info(rcb_frf *f, double speed, rcb_modal_info *info) {
  rcb_status st = need_modal(f);
  if (st) return st;
  if (!info) return RCB_ERR_ARG;
  if (!isfinite(speed))
    return rcb_set_error(f->errmsg, RCB_ERR_ARG, "speed %g rad/s: expected finite", speed);
  if ((st = rcb_frf_modal_basis(f, speed))) return st;
  *info = f->modal->info;
  return RCB_OK;
}

rcb_status rcb_frf_modal_error(rcb_frf *f, double omega, double speed, double *err) {
  rcb_frf_modal *md;
  size_t c;
  double num = 0.0;
  rcb_status st = need_modal(f);
  if (st) return st;
  if (!err) return RCB_ERR_ARG;
  md = f->modal;
  if ((st = check_args(f, omega, speed)) || (st = rcb_frf_modal_basis(f, speed)) ||
      (st = rcb_frf_eval_direct(f, omega, speed, RCB_RECEPTANCE, md->Hd)))
    return st;
  rcb_frf_modal_sum(md, omega, RCB_RECEPTANCE, md->Hm);
  for (c = 0; c < md->nch; c++) num = fmax(num, cabs(md->Hm[c] - md->Hd[c]));
  *err = num / max_abs(md->Hd, md->nch);
  return RCB_OK;
}
