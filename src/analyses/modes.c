/*
 * Damped modes of M q'' + (C + Omega G) q' + K q = 0 at a rotor speed Omega,
 * from the first-order (state-space) form
 *
 *   d/dt [q; q'] = A [q; q'],   A = [ 0, I ; -M^-1 K, -M^-1 (C + Omega G) ],
 *
 * M symmetric positive definite (Cholesky, dpotrf/dpotrs), then the real
 * nonsymmetric eigenproblem of A (dgeev, right eigenvectors). A root
 * lambda = -zeta wn + i wd with eigenvector [Q; lambda Q] is the free motion
 * q(t) = Re(Q e^{lambda t}).
 *
 * Everything is sized in rcb_modes_create (dgeev's workspace query included)
 * and kept in the object; rcb_modes_compute and rcb_campbell allocate
 * nothing, and only the LAPACKE _work variants are used (the plain LAPACKE
 * wrappers allocate their own workspace).
 */
#include <lapacke.h>
#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "analyses/state_space.h"

/* A root is kept as an oscillating mode when Im(lambda) > RCB_MODES_IM_TOL *
 * max |lambda|. The rigid-body roots of a free rotor are exact double zeros
 * (2x2 Jordan blocks of A), which a backward-stable eigensolver returns
 * scattered over a disc of radius ~ sqrt(eps) max |lambda| (measured: 2e-9 to
 * 5e-9 max |lambda| on free shafts of 10 to 100 elements), so the floor sits
 * 20 to 50 times above that noise. max |lambda| is set by the stiffest local
 * frequency of the mesh (shortest element, stiffest bearing), so the floor is
 * typically 1e-3 to 1e-1 rad/s; nothing below it can be told apart from a
 * rigid-body root by this method anyway. */
#define RCB_MODES_IM_TOL 1e-7
/* A node votes on the whirl direction when its translation amplitude is at
 * least this fraction of the largest one in the mode. */
#define RCB_WHIRL_NODE_TOL 1e-3
/* Forward and backward radii equal within this fraction: planar motion at that
 * node, no vote. */
#define RCB_WHIRL_PLANAR_TOL 1e-6

struct rcb_modes {
  rcb_allocator alloc;
  char errmsg[RCB_ERRMSG_MAX];
  const rcb_model *model;
  size_t n, N;      /* DOFs, states (2n) */
  size_t nnodes;
  size_t *xrow;     /* per node: matrix row of x (y is yrow) */
  size_t *yrow;
  double *M;        /* n x n, then its Cholesky factor */
  double *KC;       /* n x 2n: [K | C + Omega G], then M^-1 [K | C + Omega G] */
  double *G;        /* n x n */
  double *A;        /* N x N state matrix (destroyed by dgeev) */
  double *wr, *wi;  /* N eigenvalues */
  double *VR;       /* N x N right eigenvectors */
  double *work;     /* dgeev workspace */
  lapack_int lwork;
  double max_zeta;  /* roots more damped than this are left out (1: none) */
  size_t *order;    /* N: indices of the kept roots, sorted by wd */
  rcb_mode *buf;    /* n modes, for rcb_campbell */
};

const char *rcb_modes_errmsg(const rcb_modes *e) { return e ? e->errmsg : ""; }

void rcb_modes_destroy(rcb_modes *e) {
  rcb_allocator a;
  if (!e) return;
  a = e->alloc;
  rcb_free(&a, e->xrow);
  rcb_free(&a, e->yrow);
  rcb_free(&a, e->M);
  rcb_free(&a, e->KC);
  rcb_free(&a, e->G);
  rcb_free(&a, e->A);
  rcb_free(&a, e->wr);
  rcb_free(&a, e->wi);
  rcb_free(&a, e->VR);
  rcb_free(&a, e->work);
  rcb_free(&a, e->order);
  rcb_free(&a, e->buf);
  rcb_free(&a, e);
}

/* Translation rows of every node (tied nodes share rows, which is fine). */
static rcb_status node_rows(rcb_modes *e) {
  size_t i;
  for (i = 0; i < e->nnodes; i++) {
    rcb_node_info info;
    rcb_status st = rcb_model_node_info(e->model, i, &info);
    if (st != RCB_OK)
      return rcb_set_error(e->errmsg, st, "modes: node %zu: %s", i,
                           rcb_model_errmsg(e->model));
    if (info.dof[0] < 0 || info.dof[1] < 0 || (size_t)info.dof[0] >= e->n ||
        (size_t)info.dof[1] >= e->n)
      return rcb_set_error(e->errmsg, RCB_ERR_MODEL,
                           "modes: node %zu has translation rows %ld, %ld outside 0..%zu", i,
                           info.dof[0], info.dof[1], e->n - 1);
    e->xrow[i] = (size_t)info.dof[0];
    e->yrow[i] = (size_t)info.dof[1];
  }
  return RCB_OK;
}

/* dgeev workspace query, done once. */
static rcb_status size_workspace(rcb_modes *e) {
  double wq = 0.0, dummy = 0.0;
  lapack_int N = (lapack_int)e->N, info;
  info = LAPACKE_dgeev_work(LAPACK_COL_MAJOR, 'N', 'V', N, e->A, N, e->wr, e->wi, &dummy, 1,
                            e->VR, N, &wq, -1);
  if (info != 0 || !(wq >= 1.0) || wq > (double)INT_MAX)
    return rcb_set_error(e->errmsg, RCB_ERR_LAPACK,
                         "modes: dgeev workspace query failed (info %d) for %zu states",
                         (int)info, e->N);
  e->lwork = (lapack_int)wq;
  if (e->lwork < 4 * N) e->lwork = 4 * N; /* dgeev's documented minimum with vectors */
  e->work = rcb_alloc(&e->alloc, (size_t)e->lwork * sizeof *e->work);
  if (!e->work)
    return rcb_set_error(e->errmsg, RCB_ERR_NOMEM,
                         "modes: out of memory for the dgeev workspace (%d doubles)",
                         (int)e->lwork);
  return RCB_OK;
}

static rcb_status alloc_arrays(rcb_modes *e) {
  const size_t n = e->n, N = e->N;
  const rcb_allocator *a = &e->alloc;
  e->xrow = rcb_alloc(a, e->nnodes * sizeof *e->xrow);
  e->yrow = rcb_alloc(a, e->nnodes * sizeof *e->yrow);
  e->M = rcb_alloc(a, n * n * sizeof *e->M);
  e->KC = rcb_alloc(a, 2 * n * n * sizeof *e->KC);
  e->G = rcb_alloc(a, n * n * sizeof *e->G);
  e->A = rcb_alloc(a, N * N * sizeof *e->A);
  e->wr = rcb_alloc(a, N * sizeof *e->wr);
  e->wi = rcb_alloc(a, N * sizeof *e->wi);
  e->VR = rcb_alloc(a, N * N * sizeof *e->VR);
  e->order = rcb_alloc(a, N * sizeof *e->order);
  e->buf = rcb_alloc(a, n * sizeof *e->buf);
  if (!e->xrow || !e->yrow || !e->M || !e->KC || !e->G || !e->A || !e->wr || !e->wi ||
      !e->VR || !e->order || !e->buf)
    return rcb_set_error(e->errmsg, RCB_ERR_NOMEM,
                         "modes: out of memory for %zu DOFs (state matrices %zu x %zu)", n,
                         N, N);
  return RCB_OK;
}

rcb_status rcb_modes_create(rcb_modes **out, const rcb_model *m, const rcb_allocator *alloc) {
  rcb_allocator a;
  rcb_modes *e;
  rcb_status st;
  size_t n;
  if (!out || !m) return RCB_ERR_ARG;
  *out = NULL;
  n = rcb_model_dof_count(m);
  if (n == 0) return RCB_ERR_STATE; /* not finalized, or no DOF */
  rcb_allocator_init(&a, alloc);
  e = rcb_alloc(&a, sizeof *e);
  if (!e) return RCB_ERR_NOMEM;
  e->alloc = a;
  e->model = m;
  e->max_zeta = RCB_MODES_MAX_ZETA_DEFAULT;
  e->n = n;
  e->N = 2 * n;
  e->nnodes = rcb_model_node_count(m);
  if (e->N > (size_t)INT_MAX || e->N > SIZE_MAX / sizeof(double) / e->N) {
    st = rcb_set_error(e->errmsg, RCB_ERR_ARG,
                       "modes: %zu DOFs is too many for a dense state-space eigenproblem", n);
  } else {
    st = alloc_arrays(e);
    if (st == RCB_OK) st = node_rows(e);
    if (st == RCB_OK) st = size_workspace(e);
  }
  if (st != RCB_OK) {
    rcb_modes_destroy(e);
    return st;
  }
  *out = e;
  return RCB_OK;
}

rcb_status rcb_modes_set_max_zeta(rcb_modes *e, double max_zeta) {
  if (!e) return RCB_ERR_ARG;
  if (!(max_zeta > 0.0 && max_zeta <= 1.0))
    return rcb_set_error(e->errmsg, RCB_ERR_ARG,
                         "modes: max_zeta = %g is out of range, expected 0 < max_zeta <= 1",
                         max_zeta);
  e->max_zeta = max_zeta;
  return RCB_OK;
}

double rcb_modes_get_max_zeta(const rcb_modes *e) { return e ? e->max_zeta : (double)NAN; }

/* A = [0, I; -M^-1 K, -M^-1 (C + Omega G)] at rotor speed Omega (rad/s). */
static rcb_status build_state_matrix(rcb_modes *e, double speed) {
  return rcb_state_matrix(e->model, speed, e->M, e->KC, e->G, e->A, e->errmsg, "modes");
}

static rcb_status solve_eigen(rcb_modes *e, double speed) {
  lapack_int N = (lapack_int)e->N, info;
  double dummy = 0.0;
  info = LAPACKE_dgeev_work(LAPACK_COL_MAJOR, 'N', 'V', N, e->A, N, e->wr, e->wi, &dummy, 1,
                            e->VR, N, e->work, e->lwork);
  if (info > 0)
    return rcb_set_error(e->errmsg, RCB_ERR_LAPACK,
                         "modes: dgeev did not converge at %g rad/s (%d eigenvalues failed "
                         "of %zu); check the model for extreme stiffness ratios",
                         speed, (int)info, e->N);
  if (info < 0)
    return rcb_set_error(e->errmsg, RCB_ERR_LAPACK, "modes: dgeev argument %d invalid",
                         (int)-info);
  return RCB_OK;
}

/* Indices of the oscillating roots (Im > tolerance), sorted by increasing Im
 * (insertion sort: no allocation, and the state size is a few hundred). */
static size_t select_roots(rcb_modes *e) {
  size_t i, j, cnt = 0;
  double big = 0.0, tol;
  for (i = 0; i < e->N; i++) {
    double r = hypot(e->wr[i], e->wi[i]);
    if (r > big) big = r;
  }
  tol = RCB_MODES_IM_TOL * big;
  for (i = 0; i < e->N; i++) {
    if (!(e->wi[i] > tol)) continue;
    if (-e->wr[i] > e->max_zeta * hypot(e->wr[i], e->wi[i])) continue;
    for (j = cnt; j > 0 && e->wi[e->order[j - 1]] > e->wi[i]; j--) e->order[j] = e->order[j - 1];
    e->order[j] = i;
    cnt++;
  }
  return cnt;
}

/* Root col (wi > 0): eigenvector VR[:, col] + i VR[:, col + 1], row r. */
static rcb_complex evec(const rcb_modes *e, size_t col, size_t r) {
  return CMPLX(e->VR[r + e->N * col], e->VR[r + e->N * (col + 1)]);
}

static rcb_complex times_i(rcb_complex z) { return CMPLX(-cimag(z), creal(z)); }

/*
 * x + i y = ((X + iY)/2) e^{i wd t} + ((conj X + i conj Y)/2) e^{-i wd t}
 * (times the decay): the first term turns from +x to +y, the rotor's spin
 * direction, so forward radius |X + iY|/2 and backward |X - iY|/2.
 */
static rcb_whirl whirl_of(const rcb_modes *e, size_t col) {
  size_t i, nf = 0, nb = 0;
  double amax = 0.0;
  for (i = 0; i < e->nnodes; i++) {
    double a = hypot(cabs(evec(e, col, e->xrow[i])), cabs(evec(e, col, e->yrow[i])));
    if (a > amax) amax = a;
  }
  for (i = 0; i < e->nnodes; i++) {
    rcb_complex X = evec(e, col, e->xrow[i]), Y = evec(e, col, e->yrow[i]);
    double rf = cabs(X + times_i(Y)), rb = cabs(X - times_i(Y));
    if (hypot(cabs(X), cabs(Y)) < RCB_WHIRL_NODE_TOL * amax) continue;
    if (fabs(rf - rb) <= RCB_WHIRL_PLANAR_TOL * (rf + rb)) continue;
    if (rf > rb)
      nf++;
    else
      nb++;
  }
  if (nf > 0 && nb == 0) return RCB_WHIRL_FORWARD;
  if (nb > 0 && nf == 0) return RCB_WHIRL_BACKWARD;
  return RCB_WHIRL_MIXED;
}

/* Displacement part, divided by its largest translation entry (so that one is 1). */
static void write_shape(const rcb_modes *e, size_t col, rcb_complex *s) {
  size_t i, best = 0;
  double amax = -1.0;
  rcb_complex d;
  for (i = 0; i < e->nnodes; i++) {
    double ax = cabs(evec(e, col, e->xrow[i])), ay = cabs(evec(e, col, e->yrow[i]));
    if (ax > amax) amax = ax, best = e->xrow[i];
    if (ay > amax) amax = ay, best = e->yrow[i];
  }
  if (!(amax > 0.0)) /* no translation at all: scale by the largest entry */
    for (i = 0; i < e->n; i++)
      if (cabs(evec(e, col, i)) > amax) amax = cabs(evec(e, col, i)), best = i;
  d = evec(e, col, best);
  for (i = 0; i < e->n; i++) s[i] = cabs(d) > 0.0 ? evec(e, col, i) / d : evec(e, col, i);
}

static void fill_mode(const rcb_modes *e, size_t col, rcb_mode *md) {
  double re = e->wr[col], im = e->wi[col];
  md->lambda = CMPLX(re, im);
  md->wn = hypot(re, im);
  md->wd = im;
  md->zeta = md->wn > 0.0 ? -re / md->wn : 0.0;
  md->logdec = 2.0 * RCB_PI * md->zeta / sqrt(1.0 - md->zeta * md->zeta);
  md->whirl = whirl_of(e, col);
}

rcb_status rcb_modes_compute(rcb_modes *e, double speed, size_t max_modes, rcb_mode *modes,
                             size_t *nmodes, rcb_complex *shapes) {
  rcb_status st;
  size_t k, cnt;
  if (!e) return RCB_ERR_ARG;
  if (!nmodes || (max_modes > 0 && !modes))
    return rcb_set_error(e->errmsg, RCB_ERR_ARG,
                         "modes: nmodes and (for max_modes > 0) modes must not be NULL");
  *nmodes = 0;
  if (!isfinite(speed))
    return rcb_set_error(e->errmsg, RCB_ERR_ARG, "modes: rotor speed %g rad/s is not finite",
                         speed);
  st = build_state_matrix(e, speed);
  if (st == RCB_OK) st = solve_eigen(e, speed);
  if (st != RCB_OK) return st;
  cnt = select_roots(e);
  if (cnt > max_modes) cnt = max_modes;
  for (k = 0; k < cnt; k++) {
    fill_mode(e, e->order[k], &modes[k]);
    if (shapes) write_shape(e, e->order[k], shapes + e->n * k);
  }
  *nmodes = cnt;
  e->errmsg[0] = '\0';
  return RCB_OK;
}

rcb_status rcb_campbell(rcb_modes *e, size_t nspeeds, const double *speeds, size_t nmodes,
                        double *wd, double *logdec, rcb_whirl *whirl) {
  size_t s, k, got;
  if (!e) return RCB_ERR_ARG;
  if ((nspeeds > 0 && !speeds) || (nspeeds > 0 && nmodes > 0 && !wd))
    return rcb_set_error(e->errmsg, RCB_ERR_ARG, "campbell: speeds and wd must not be NULL");
  for (s = 0; s < nspeeds; s++) {
    rcb_status st = rcb_modes_compute(e, speeds[s], e->n, e->buf, &got, NULL);
    if (st != RCB_OK) return st; /* message names the speed */
    for (k = 0; k < nmodes; k++) {
      size_t o = k + nmodes * s;
      wd[o] = k < got ? e->buf[k].wd : (double)NAN;
      if (logdec) logdec[o] = k < got ? e->buf[k].logdec : (double)NAN;
      if (whirl) whirl[o] = k < got ? e->buf[k].whirl : RCB_WHIRL_MIXED;
    }
  }
  return RCB_OK;
}
