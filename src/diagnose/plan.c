/*
 * Which test would tell them apart (issue #23 item 6): two rival effects A
 * and B fit the data about equally when their weighted sensitivity columns
 * on the measured channels are nearly collinear. The plan states how far
 * apart they are on the present channels (the smallest principal angle and
 * the chi-square by which the best B misses A's data) and ranks the channels
 * one could add by how much they raise that chi-square (rcb_diagnose.h).
 *
 * Linear algebra on the columns scaled to unit norm (units drop out):
 * J_A = Q_A R_A, J_B = Q_B R_B (Householder QR); X = (I - Q_B Q_B^T) Q_A,
 * whose smallest singular value is sin(theta) with right singular vector v;
 * A's data y = sqrt(S) Q_A v (dA = sqrt(S) R_A^-1 v), z = Q_B^T y. With
 * gamma = R_B dB, F(gamma) = S sin^2(theta) + ||z - gamma||^2 on the present
 * rows, and a candidate's rows add ||y_c - C gamma||^2, C = J_B,c R_B^-1: its
 * gain is the residual of the small least squares [I; C] gamma = [z; y_c].
 */
#include <lapacke.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/rcb_internal.h"
#include "identify/identify.h"
#include "rcb/rcb_diagnose.h"

#define PLAN_NAME_MAX 128
#define PLAN_RANK_TOL 1e-10 /* |R_kk| of unit columns below this: dependent */

typedef struct plan_par {
  char name[PLAN_NAME_MAX];
  int side;
  double value, change;
} plan_par;

typedef struct plan_cand {
  char resp[PLAN_NAME_MAX], ref[PLAN_NAME_MAX];
  double speed, gain, rms;
} plan_cand;

struct rcb_plan {
  rcb_allocator alloc;
  char errmsg[RCB_ERRMSG_MAX];
  rcb_model *m; /* finalized copy */
  const rcb_meas *meas;
  plan_par *par;
  size_t np, cap_par;
  double beta_a, beta_s, size;
  double rms_ref; /* RMS magnitude of the strongest present channel */
  double floor_a; /* eq. 19 additive amplitude of the strongest present channel */
  int noise;
  double *speeds;
  size_t nspeeds, cap_sp;
  /* results */
  int done;
  rcb_plan_result res;
  plan_cand *cand;
  size_t ncand, cap_cand;
};

#define plan_fail(p, st, ...) rcb_fail((p), (st), __VA_ARGS__)

rcb_status rcb_plan_create(rcb_plan **out, const rcb_model *m, const rcb_meas *meas,
                           const rcb_allocator *alloc) {
  rcb_allocator a;
  rcb_plan *p;
  rcb_status st;
  if (!out) return RCB_ERR_ARG;
  *out = NULL;
  rcb_allocator_init(&a, alloc);
  if (!(p = rcb_alloc(&a, sizeof *p))) return RCB_ERR_NOMEM;
  *out = p;
  p->alloc = a;
  p->size = 25.0;
  if (!m || !meas) return plan_fail(p, RCB_ERR_ARG, "no model or no measurement given");
  if (rcb_model_dof_count(m) == 0)
    return plan_fail(p, RCB_ERR_STATE, "the model is not finalized");
  if (rcb_meas_get_type(meas) != RCB_MEAS_FRF || rcb_meas_speed(meas) < 0)
    return plan_fail(p, RCB_ERR_ARG, "the plan needs FRFs at a fixed rotor speed (not "
                     "unbalance responses or synchronous FRFs)");
  if (!rcb_meas_channel_count(meas) || !rcb_meas_point_count(meas))
    return plan_fail(p, RCB_ERR_ARG, "the measurement is empty");
  if ((st = rcb_model_clone(&p->m, m, &p->alloc)) || (st = rcb_model_finalize(p->m)))
    return plan_fail(p, st, "copy of the model: %s", rcb_model_errmsg(p->m));
  p->meas = meas;
  return RCB_OK;
}

void rcb_plan_destroy(rcb_plan *p) {
  rcb_allocator a;
  if (!p) return;
  a = p->alloc;
  rcb_model_destroy(p->m);
  rcb_free(&a, p->par);
  rcb_free(&a, p->speeds);
  rcb_free(&a, p->cand);
  rcb_free(&a, p);
}

const char *rcb_plan_errmsg(const rcb_plan *p) { return p ? p->errmsg : "no object"; }

rcb_status rcb_plan_add_param(rcb_plan *p, int side, const char *name) {
  double v;
  size_t k;
  if (!p || !name || (side != 0 && side != 1)) return RCB_ERR_ARG;
  if (!p->m) return plan_fail(p, RCB_ERR_STATE, "no model");
  if (strlen(name) >= PLAN_NAME_MAX)
    return plan_fail(p, RCB_ERR_ARG, "parameter name '%s' too long", name);
  if (rcb_model_get_param(p->m, name, &v))
    return plan_fail(p, RCB_ERR_NOT_FOUND, "%s", rcb_model_errmsg(p->m));
  for (k = 0; k < p->np; k++)
    if (strcmp(p->par[k].name, name) == 0)
      return plan_fail(p, RCB_ERR_ARG, "parameter '%s' given twice%s", name,
                       p->par[k].side != side ? " (on both sides: the rivals must differ)"
                                              : "");
  if (rcb_grow(&p->alloc, (void **)&p->par, &p->cap_par, p->np + 1, sizeof *p->par))
    return plan_fail(p, RCB_ERR_NOMEM, "out of memory");
  strcpy(p->par[p->np].name, name);
  p->par[p->np].side = side;
  p->par[p->np].value = v;
  p->par[p->np].change = 0.0;
  p->np++;
  p->done = 0;
  return RCB_OK;
}

rcb_status rcb_plan_set_noise_model(rcb_plan *p, double beta_a, double beta_s) {
  if (!p) return RCB_ERR_ARG;
  if (!(beta_a >= 0 && beta_s >= 0 && beta_a + beta_s > 0 && isfinite(beta_a + beta_s)))
    return plan_fail(p, RCB_ERR_ARG, "noise model %g, %g %%: expected values >= 0, not both 0",
                     beta_a, beta_s);
  p->beta_a = beta_a, p->beta_s = beta_s, p->noise = 1;
  return RCB_OK;
}

rcb_status rcb_plan_set_size(rcb_plan *p, double chi2) {
  if (!p) return RCB_ERR_ARG;
  if (!(chi2 > 0 && isfinite(chi2)))
    return plan_fail(p, RCB_ERR_ARG, "size %g: expected a chi-square > 0 (e.g. 25)", chi2);
  p->size = chi2;
  return RCB_OK;
}

rcb_status rcb_plan_add_speed(rcb_plan *p, double speed) {
  if (!p) return RCB_ERR_ARG;
  if (!(speed >= 0 && isfinite(speed)))
    return plan_fail(p, RCB_ERR_ARG, "speed %g rad/s: expected >= 0", speed);
  if (rcb_grow(&p->alloc, (void **)&p->speeds, &p->cap_sp, p->nspeeds + 1, sizeof *p->speeds))
    return plan_fail(p, RCB_ERR_NOMEM, "out of memory");
  p->speeds[p->nspeeds++] = speed;
  return RCB_OK;
}

/* ---- model-made measurements and their Jacobians ---- */

/* The model's noise-free FRFs at outputs outs[0 .. nout) per inputs ins[k]
 * (one per channel when nin == nout, else the single ins[0]), on the present
 * grid at speed w0 (rad/s), as the kind of the present first channel. */
static rcb_status simulate(rcb_plan *p, const char *const *outs, const char *const *ins,
                           size_t nout, int one_input, double w0, rcb_meas **out) {
  size_t n = rcb_meas_point_count(p->meas), k, i;
  const double *x = rcb_meas_grid(p->meas);
  rcb_meas_channel_info ci;
  rcb_complex *col = rcb_alloc(&p->alloc, n * sizeof *col);
  rcb_meas *ms = NULL;
  rcb_status st;
  rcb_meas_channel(p->meas, 0, &ci);
  *out = NULL;
  if (!col) return plan_fail(p, RCB_ERR_NOMEM, "out of memory");
  if ((st = rcb_meas_create(&ms, &p->alloc)) || (st = rcb_meas_set_grid(ms, RCB_MEAS_FRF, n, x,
                                                                         w0))) {
    plan_fail(p, st, "model-made measurement: %s", rcb_status_str(st));
    goto done;
  }
  for (k = 0; k < nout && !st; k++) {
    rcb_frf *fr = NULL;
    rcb_dof od, id;
    const char *in = ins[one_input ? 0 : k];
    if ((st = rcb_model_find_dof(p->m, outs[k], &od)) ||
        (st = rcb_model_find_dof(p->m, in, &id))) {
      plan_fail(p, st, "%s", rcb_model_errmsg(p->m));
      break;
    }
    if ((st = rcb_frf_create(&fr, p->m, 1, &od, 1, &id, RCB_SOLVER_AUTO, &p->alloc))) {
      plan_fail(p, st, "FRF of %s per %s: %s", outs[k], in, rcb_status_str(st));
      break;
    }
    for (i = 0; i < n && !st; i++) st = rcb_frf_eval(fr, x[i], w0, ci.kind, &col[i]);
    if (st) plan_fail(p, st, "FRF of %s per %s: %s", outs[k], in, rcb_frf_errmsg(fr));
    rcb_frf_destroy(fr);
    if (!st && (st = rcb_meas_add_channel(ms, outs[k], in, ci.kind, col)))
      plan_fail(p, st, "%s", rcb_meas_errmsg(ms));
  }
done:
  rcb_free(&p->alloc, col);
  if (st) {
    rcb_meas_destroy(ms);
    return st;
  }
  *out = ms;
  return RCB_OK;
}

/* Weighted Jacobian of every plan parameter on measurement ms: *J (nres x
 * np, allocated) and, when ch is not NULL, each row's channel (*ch). */
static rcb_status jacobian(rcb_plan *p, const rcb_meas *ms, const double *w, double **J,
                           size_t **ch, size_t *nres) {
  rcb_fit *f = NULL;
  rcb_status st;
  size_t k;
  *J = NULL;
  if (ch) *ch = NULL;
  if ((st = rcb_fit_create(&f, p->m, ms, &p->alloc))) {
    plan_fail(p, st, "fit set-up: %s", f ? rcb_fit_errmsg(f) : rcb_status_str(st));
    rcb_fit_destroy(f);
    return st;
  }
  st = rcb_fit_set_noise_model(f, p->beta_a, p->beta_s);
  if (!st && w) st = rcb_fit_set_weights(f, w);
  for (k = 0; k < p->np && !st; k++) {
    double v = p->par[k].value, half = (fabs(v) + 1.0) * 1e6; /* bounds never reached */
    st = rcb_fit_add_param(f, p->par[k].name, v - half, v + half, 0);
  }
  if (!st) st = rcb_fit_prepare(f);
  if (!st) {
    *nres = rcb_fit_residual_count(f);
    *J = rcb_alloc(&p->alloc, (*nres ? *nres : 1) * p->np * sizeof **J);
    if (ch) *ch = rcb_alloc(&p->alloc, (*nres ? *nres : 1) * sizeof **ch);
    if (!*J || (ch && !*ch))
      st = RCB_ERR_NOMEM;
    else if (!(st = rcb_fit_jacobian(f, 1, *J)) && ch)
      st = rcb_fit_residual_channels(f, *ch);
  }
  if (st) {
    plan_fail(p, st, "sensitivities: %s", st == RCB_ERR_NOMEM ? "out of memory"
                                                              : rcb_fit_errmsg(f));
    rcb_free(&p->alloc, *J);
    *J = NULL;
    if (ch) {
      rcb_free(&p->alloc, *ch);
      *ch = NULL;
    }
  }
  rcb_fit_destroy(f);
  return st;
}

/* ---- the present channels ---- */

/* What the present rows leave for the candidates (unit-column coordinates). */
typedef struct plan_basis {
  size_t pa, pb;  /* A's and B's parameter counts */
  size_t *ia, *ib; /* their indices in p->par */
  double *scale;  /* np column norms on the present rows */
  double *RB;     /* pb x pb upper triangular factor of B's unit columns */
  double *a;      /* pa: A's data, sqrt(S) R_A^-1 v */
  double *z;      /* pb: Q_B^T y */
} plan_basis;

static void basis_free(rcb_plan *p, plan_basis *b) {
  rcb_free(&p->alloc, b->ia);
  rcb_free(&p->alloc, b->ib);
  rcb_free(&p->alloc, b->scale);
  rcb_free(&p->alloc, b->RB);
  rcb_free(&p->alloc, b->a);
  rcb_free(&p->alloc, b->z);
}

/* Q (n x k, in place of the unit columns A) and R (k x k) of A = Q R; a
 * diagonal entry of R below PLAN_RANK_TOL: the columns are dependent. */
static rcb_status qr(rcb_plan *p, double *A, size_t n, size_t k, double *R, const char *side) {
  double *tau = rcb_alloc(&p->alloc, k * sizeof *tau);
  lapack_int info;
  size_t i, j;
  if (!tau) return plan_fail(p, RCB_ERR_NOMEM, "out of memory");
  info = LAPACKE_dgeqrf(LAPACK_COL_MAJOR, (lapack_int)n, (lapack_int)k, A, (lapack_int)n, tau);
  for (j = 0; j < k && !info; j++)
    for (i = 0; i < k; i++) R[i + k * j] = i <= j ? A[i + n * j] : 0.0;
  if (!info)
    info = LAPACKE_dorgqr(LAPACK_COL_MAJOR, (lapack_int)n, (lapack_int)k, (lapack_int)k, A,
                          (lapack_int)n, tau);
  rcb_free(&p->alloc, tau);
  if (info) return plan_fail(p, RCB_ERR_LAPACK, "QR of %s's sensitivities: info %d", side,
                             (int)info);
  for (j = 0; j < k; j++)
    if (!(fabs(R[j + k * j]) > PLAN_RANK_TOL))
      return plan_fail(p, RCB_ERR_ARG, "%s's parameters are not independent on the present "
                       "channels (one is a combination of the others): drop one", side);
  return RCB_OK;
}

/* Solve U x = b (U k x k upper triangular, column-major) in place. */
static void back_solve(const double *U, size_t k, double *b) {
  size_t i = k, j;
  while (i-- > 0) {
    for (j = i + 1; j < k; j++) b[i] -= U[i + k * j] * b[j];
    b[i] /= U[i + k * i];
  }
}

/* Solve U^T x = b (U upper triangular) in place. */
static void forward_solve_t(const double *U, size_t k, double *b) {
  size_t i, j;
  for (i = 0; i < k; i++) {
    for (j = 0; j < i; j++) b[i] -= U[j + k * i] * b[j];
    b[i] /= U[i + k * i];
  }
}

/* Scaled copies of the columns idx[0 .. k) of J (n x np) into out (n x k). */
static void take_columns(const double *J, size_t n, const size_t *idx, size_t k,
                         const double *scale, double *out) {
  size_t i, j;
  for (j = 0; j < k; j++)
    for (i = 0; i < n; i++) out[i + n * j] = J[i + n * idx[j]] / scale[idx[j]];
}

/* Column norms of J (n x np); a parameter without effect is refused. */
static rcb_status column_scales(rcb_plan *p, const double *J, size_t n, double *scale) {
  size_t i, k;
  for (k = 0; k < p->np; k++) {
    double s = 0.0;
    for (i = 0; i < n; i++) s += J[i + n * k] * J[i + n * k];
    scale[k] = sqrt(s);
    if (!(scale[k] > 0) || !isfinite(scale[k]))
      return plan_fail(p, RCB_ERR_ARG, "parameter %s has no effect on the present channels "
                       "(sensitivity 0): nothing to separate there", p->par[k].name);
  }
  return RCB_OK;
}

static rcb_status basis_alloc(rcb_plan *p, plan_basis *b) {
  size_t k;
  for (k = 0; k < p->np; k++) {
    if (p->par[k].side)
      b->pb++;
    else
      b->pa++;
  }
  b->ia = rcb_alloc(&p->alloc, b->pa * sizeof *b->ia);
  b->ib = rcb_alloc(&p->alloc, b->pb * sizeof *b->ib);
  b->scale = rcb_alloc(&p->alloc, p->np * sizeof *b->scale);
  b->RB = rcb_alloc(&p->alloc, b->pb * b->pb * sizeof *b->RB);
  b->a = rcb_alloc(&p->alloc, b->pa * sizeof *b->a);
  b->z = rcb_alloc(&p->alloc, b->pb * sizeof *b->z);
  if (!b->ia || !b->ib || !b->scale || !b->RB || !b->a || !b->z)
    return plan_fail(p, RCB_ERR_NOMEM, "out of memory");
  b->pa = b->pb = 0;
  for (k = 0; k < p->np; k++) {
    if (p->par[k].side)
      b->ib[b->pb++] = k;
    else
      b->ia[b->pa++] = k;
  }
  return RCB_OK;
}

/* The smallest singular value of X (n x pa) and its right singular vector v. */
static rcb_status smallest_sv(rcb_plan *p, double *X, size_t n, size_t pa, double *sigma,
                              double *v) {
  double *s = rcb_alloc(&p->alloc, (pa + 1) * sizeof *s);
  double *vt = rcb_alloc(&p->alloc, pa * pa * sizeof *vt);
  double *sup = rcb_alloc(&p->alloc, (pa + 1) * sizeof *sup);
  lapack_int info = -1;
  size_t j;
  if (s && vt && sup)
    info = LAPACKE_dgesvd(LAPACK_COL_MAJOR, 'N', 'A', (lapack_int)n, (lapack_int)pa, X,
                          (lapack_int)n, s, NULL, 1, vt, (lapack_int)pa, sup);
  if (!info) {
    *sigma = s[pa - 1];
    for (j = 0; j < pa; j++) v[j] = vt[(pa - 1) + pa * j];
  }
  rcb_free(&p->alloc, s);
  rcb_free(&p->alloc, vt);
  rcb_free(&p->alloc, sup);
  if (!s || !vt || !sup) return plan_fail(p, RCB_ERR_NOMEM, "out of memory");
  if (info) return plan_fail(p, RCB_ERR_LAPACK, "SVD of the rivals' angle: info %d", (int)info);
  return RCB_OK;
}

/* The separability on J (n x np present rows): result, A's data, B's fit. */
static rcb_status separate(rcb_plan *p, const double *J, size_t n, plan_basis *b) {
  size_t pa = b->pa, pb = b->pb, i, j, k;
  double *QA = rcb_alloc(&p->alloc, n * pa * sizeof *QA);
  double *QB = rcb_alloc(&p->alloc, n * pb * sizeof *QB);
  double *RA = rcb_alloc(&p->alloc, pa * pa * sizeof *RA);
  double *X = rcb_alloc(&p->alloc, n * pa * sizeof *X);
  double *y = rcb_alloc(&p->alloc, n * sizeof *y), sigma = 0.0, F = 0.0, sq = sqrt(p->size);
  rcb_status st;
  if (!QA || !QB || !RA || !X || !y) {
    st = plan_fail(p, RCB_ERR_NOMEM, "out of memory");
    goto done;
  }
  if (n < pa + pb) {
    st = plan_fail(p, RCB_ERR_ARG, "%zu residuals for %zu parameters: too few", n, pa + pb);
    goto done;
  }
  take_columns(J, n, b->ia, pa, b->scale, QA);
  take_columns(J, n, b->ib, pb, b->scale, QB);
  if ((st = qr(p, QA, n, pa, RA, "A")) || (st = qr(p, QB, n, pb, b->RB, "B"))) goto done;
  /* X = (I - Q_B Q_B^T) Q_A */
  memcpy(X, QA, n * pa * sizeof *X);
  for (j = 0; j < pa; j++)
    for (k = 0; k < pb; k++) {
      double t = 0.0;
      for (i = 0; i < n; i++) t += QB[i + n * k] * QA[i + n * j];
      for (i = 0; i < n; i++) X[i + n * j] -= t * QB[i + n * k];
    }
  if ((st = smallest_sv(p, X, n, pa, &sigma, b->a))) goto done;
  /* y = sqrt(S) Q_A v, z = Q_B^T y, F = ||y - Q_B z||^2 */
  for (i = 0; i < n; i++) {
    y[i] = 0.0;
    for (j = 0; j < pa; j++) y[i] += sq * QA[i + n * j] * b->a[j];
  }
  for (k = 0; k < pb; k++) {
    b->z[k] = 0.0;
    for (i = 0; i < n; i++) b->z[k] += QB[i + n * k] * y[i];
  }
  for (i = 0; i < n; i++) {
    double r = y[i];
    for (k = 0; k < pb; k++) r -= QB[i + n * k] * b->z[k];
    F += r * r;
  }
  back_solve(RA, pa, b->a);
  for (j = 0; j < pa; j++) {
    b->a[j] *= sq;
    p->par[b->ia[j]].change = b->a[j] / b->scale[b->ia[j]];
  }
  memcpy(y, b->z, pb * sizeof *y);
  back_solve(b->RB, pb, y);
  for (k = 0; k < pb; k++) p->par[b->ib[k]].change = y[k] / b->scale[b->ib[k]];
  p->res.angle_deg = asin(fmin(sigma, 1.0)) * 180.0 / RCB_PI;
  p->res.size = p->size;
  p->res.chi2_sep = F;
  p->res.separable = rcb_evidence_separable(F, 0.0); /* the one rule (claim.c) */
  p->res.residuals = n;
done:
  rcb_free(&p->alloc, QA);
  rcb_free(&p->alloc, QB);
  rcb_free(&p->alloc, RA);
  rcb_free(&p->alloc, X);
  rcb_free(&p->alloc, y);
  return st;
}

/* RMS magnitude of channel k of ms. */
static double channel_rms(const rcb_meas *ms, size_t k) {
  rcb_meas_channel_info ci;
  size_t i, n = rcb_meas_point_count(ms);
  double s = 0.0;
  rcb_meas_channel(ms, k, &ci);
  for (i = 0; i < n; i++) s += creal(ci.data[i] * conj(ci.data[i]));
  return n ? sqrt(s / (double)n) : 0.0;
}

static rcb_status present(rcb_plan *p, plan_basis *b) {
  size_t nch = rcb_meas_channel_count(p->meas), k, n = 0;
  const char **outs = rcb_alloc(&p->alloc, 2 * nch * sizeof *outs), **ins;
  rcb_meas *ms = NULL;
  double *J = NULL;
  rcb_status st;
  if (!outs) return plan_fail(p, RCB_ERR_NOMEM, "out of memory");
  ins = outs + nch;
  for (k = 0; k < nch; k++) {
    rcb_meas_channel_info ci;
    rcb_meas_channel(p->meas, k, &ci);
    outs[k] = ci.response;
    ins[k] = ci.reference;
  }
  if (!(st = simulate(p, outs, ins, nch, 0, rcb_meas_speed(p->meas), &ms)))
    for (k = 0, p->rms_ref = 0.0; k < nch; k++) p->rms_ref = fmax(p->rms_ref, channel_rms(ms, k));
  p->floor_a = p->beta_s / 100.0 * p->rms_ref / sqrt((double)rcb_meas_point_count(p->meas));
  if (!st &&
      !(st = jacobian(p, ms, NULL, &J, NULL, &n)) && !(st = column_scales(p, J, n, b->scale)))
    st = separate(p, J, n, b);
  rcb_free(&p->alloc, J);
  rcb_meas_destroy(ms);
  rcb_free(&p->alloc, outs);
  return st;
}

/* ---- candidate channels ---- */

/* The candidate DOFs: x and y of every named station, each DOF once. */
typedef struct plan_dofs {
  char (*name)[PLAN_NAME_MAX];
  const char **ptr;
  size_t *row, n;
} plan_dofs;

static void dofs_free(rcb_plan *p, plan_dofs *d) {
  rcb_free(&p->alloc, d->name);
  rcb_free(&p->alloc, d->ptr);
  rcb_free(&p->alloc, d->row);
}

static rcb_status dofs_list(rcb_plan *p, plan_dofs *d) {
  size_t ns = rcb_model_station_count(p->m), i, j, dir;
  static const char *const dirs[2] = {"x", "y"};
  d->name = rcb_alloc(&p->alloc, (2 * ns + 1) * sizeof *d->name);
  d->ptr = rcb_alloc(&p->alloc, (2 * ns + 1) * sizeof *d->ptr);
  d->row = rcb_alloc(&p->alloc, (2 * ns + 1) * sizeof *d->row);
  if (!d->name || !d->ptr || !d->row) return plan_fail(p, RCB_ERR_NOMEM, "out of memory");
  for (i = 0; i < ns; i++) {
    rcb_station_info si;
    if (rcb_model_station_info(p->m, i, &si)) continue;
    for (dir = 0; dir < 2; dir++) {
      rcb_dof dof;
      size_t row;
      snprintf(d->name[d->n], PLAN_NAME_MAX, "%s.%s", si.name, dirs[dir]);
      if (rcb_model_find_dof(p->m, d->name[d->n], &dof) || rcb_model_dof_index(p->m, dof, &row))
        continue;
      for (j = 0; j < d->n && d->row[j] != row; j++) {
      }
      if (j < d->n) continue;
      d->row[d->n] = row;
      d->ptr[d->n] = d->name[d->n];
      d->n++;
    }
  }
  if (!d->n) return plan_fail(p, RCB_ERR_ARG, "the model has no station to measure at");
  return RCB_OK;
}

/* DOF row of channel spec @p name, or (size_t)-1. */
static size_t dof_row(const rcb_plan *p, const char *name) {
  rcb_dof dof;
  size_t row;
  if (rcb_model_find_dof(p->m, name, &dof) || rcb_model_dof_index(p->m, dof, &row))
    return (size_t)-1;
  return row;
}

/* Whether response row r per excitation row e is a present channel. */
static int is_present(const rcb_plan *p, size_t r, size_t e) {
  size_t k;
  for (k = 0; k < rcb_meas_channel_count(p->meas); k++) {
    rcb_meas_channel_info ci;
    rcb_meas_channel(p->meas, k, &ci);
    if (dof_row(p, ci.response) == r && dof_row(p, ci.reference) == e) return 1;
  }
  return 0;
}

/* Scratch of one candidate's least squares. */
typedef struct plan_ls {
  double *M, *rhs, *row; /* (pb + nmax) x pb, pb + nmax, np */
  size_t nmax;
} plan_ls;

/* Whether row i of J (nres x np) is finite: a channel the model gives as
 * exactly 0 (x per y at rest) has no finite log10 sensitivity, and no
 * information. */
static int row_finite(const double *J, size_t nres, size_t i, const plan_basis *b) {
  size_t k;
  for (k = 0; k < b->pa + b->pb; k++)
    if (!isfinite(J[i + nres * k])) return 0;
  return 1;
}

/* Gain of the channel whose rows are J's rows with ch[i] == c (J nres x np). */
static rcb_status gain_of(rcb_plan *p, const plan_basis *b, const double *J, const size_t *ch,
                          size_t nres, size_t c, plan_ls *ls, double *gain) {
  size_t pb = b->pb, i, j, nr = 0, m;
  lapack_int info;
  for (i = 0; i < nres; i++) nr += ch[i] == c && row_finite(J, nres, i, b);
  m = pb + nr;
  memset(ls->M, 0, m * pb * sizeof *ls->M);
  for (j = 0; j < pb; j++) {
    ls->M[j + m * j] = 1.0;
    ls->rhs[j] = b->z[j];
  }
  for (i = 0, nr = 0; i < nres; i++) {
    double yc = 0.0;
    if (ch[i] != c || !row_finite(J, nres, i, b)) continue;
    for (j = 0; j < b->pa; j++) yc += J[i + nres * b->ia[j]] / b->scale[b->ia[j]] * b->a[j];
    for (j = 0; j < pb; j++) ls->row[j] = J[i + nres * b->ib[j]] / b->scale[b->ib[j]];
    forward_solve_t(b->RB, pb, ls->row); /* a row of C = J_B,c R_B^-1 */
    for (j = 0; j < pb; j++) ls->M[pb + nr + m * j] = ls->row[j];
    ls->rhs[pb + nr] = yc;
    nr++;
  }
  *gain = 0.0;
  if (!nr) return RCB_OK;
  info = LAPACKE_dgels(LAPACK_COL_MAJOR, 'N', (lapack_int)m, (lapack_int)pb, 1, ls->M,
                       (lapack_int)m, ls->rhs, (lapack_int)m);
  if (info) return plan_fail(p, RCB_ERR_LAPACK, "candidate least squares: info %d", (int)info);
  for (i = pb; i < m; i++) *gain += ls->rhs[i] * ls->rhs[i];
  return RCB_OK;
}

static rcb_status add_cand(rcb_plan *p, const char *resp, const char *ref, double speed,
                           double gain, double rms) {
  plan_cand *c;
  if (rcb_grow(&p->alloc, (void **)&p->cand, &p->cap_cand, p->ncand + 1, sizeof *p->cand))
    return plan_fail(p, RCB_ERR_NOMEM, "out of memory");
  c = &p->cand[p->ncand++];
  snprintf(c->resp, sizeof c->resp, "%s", resp);
  snprintf(c->ref, sizeof c->ref, "%s", ref);
  c->speed = speed;
  c->gain = gain;
  c->rms = rms;
  return RCB_OK;
}

/* Weights that turn the fit's eq. 19 variances (each channel's additive
 * amplitude a_c = beta_s/100 sqrt(sum |e|^2)/n from its own values) into
 * ones with the strongest present channel's amplitude A for every candidate:
 * var = (beta_a/100)^2 |e|^2/3 + a^2/6 on |e| (the log10 factor cancels in the
 * ratio), and points under 2 A are at the test's floor (weight 0). Without
 * this a weak channel (x per y, -80 dB) would be ranked as if measured as
 * cleanly, relative to its size, as the strongest one. Returns the points
 * kept. */
static size_t floor_weights(const rcb_plan *p, const rcb_meas *ms, double *w) {
  size_t n = rcb_meas_point_count(ms), k, i, kept = 0;
  double ba = p->beta_a / 100.0, A = p->floor_a;
  for (k = 0; k < rcb_meas_channel_count(ms); k++) {
    rcb_meas_channel_info ci;
    double ac = p->beta_s / 100.0 * channel_rms(ms, k) / sqrt((double)n);
    rcb_meas_channel(ms, k, &ci);
    for (i = 0; i < n; i++) {
      double m2 = creal(ci.data[i] * conj(ci.data[i]));
      double vc = ba * ba * m2 / 3.0 + ac * ac / 6.0, v = ba * ba * m2 / 3.0 + A * A / 6.0;
      w[k * n + i] = sqrt(m2) >= 2.0 * A && v > 0 ? vc / v : 0.0;
      kept += w[k * n + i] > 0;
    }
  }
  return kept;
}

/* Every response DOF per excitation e at speed w0. */
static rcb_status candidates_at(rcb_plan *p, const plan_basis *b, const plan_dofs *d, size_t e,
                                double w0, int test_speed) {
  rcb_meas *ms = NULL;
  double *J = NULL, g;
  size_t *ch = NULL, nres = 0, r;
  double *w = NULL;
  plan_ls ls;
  rcb_status st;
  memset(&ls, 0, sizeof ls);
  if ((st = simulate(p, d->ptr, d->ptr + e, d->n, 1, w0, &ms))) goto done;
  if (!(w = rcb_alloc(&p->alloc, d->n * rcb_meas_point_count(ms) * sizeof *w))) {
    st = plan_fail(p, RCB_ERR_NOMEM, "out of memory");
    goto done;
  }
  if (!floor_weights(p, ms, w)) goto done; /* all under the test's floor: nothing to add */
  if ((st = jacobian(p, ms, w, &J, &ch, &nres))) goto done;
  ls.M = rcb_alloc(&p->alloc, (b->pb + nres) * b->pb * sizeof *ls.M);
  ls.rhs = rcb_alloc(&p->alloc, (b->pb + nres) * sizeof *ls.rhs);
  ls.row = rcb_alloc(&p->alloc, (b->pb + 1) * sizeof *ls.row);
  if (!ls.M || !ls.rhs || !ls.row) {
    st = plan_fail(p, RCB_ERR_NOMEM, "out of memory");
    goto done;
  }
  for (r = 0; r < d->n && !st; r++) {
    if (test_speed && is_present(p, d->row[r], d->row[e])) continue;
    if (!(st = gain_of(p, b, J, ch, nres, r, &ls, &g)))
      st = add_cand(p, d->ptr[r], d->ptr[e], w0, g, channel_rms(ms, r));
  }
done:
  rcb_free(&p->alloc, w);
  rcb_free(&p->alloc, ls.M);
  rcb_free(&p->alloc, ls.rhs);
  rcb_free(&p->alloc, ls.row);
  rcb_free(&p->alloc, J);
  rcb_free(&p->alloc, ch);
  rcb_meas_destroy(ms);
  return st;
}

static int cmp_cand(const void *x, const void *y) {
  const plan_cand *a = x, *b = y;
  return (a->gain < b->gain) - (a->gain > b->gain);
}

rcb_status rcb_plan_run(rcb_plan *p) {
  plan_basis b;
  plan_dofs d;
  size_t k, e;
  rcb_status st;
  if (!p) return RCB_ERR_ARG;
  if (!p->m) return plan_fail(p, RCB_ERR_STATE, "no model");
  p->done = 0;
  p->ncand = 0;
  memset(&p->res, 0, sizeof p->res);
  memset(&b, 0, sizeof b);
  memset(&d, 0, sizeof d);
  for (k = 0; k < p->np; k++) {
    if (p->par[k].side)
      b.pb++;
    else
      b.pa++;
  }
  if (!b.pa || !b.pb)
    return plan_fail(p, RCB_ERR_ARG, "rival %s has no parameter (rcb_plan_add_param)",
                     b.pa ? "B" : "A");
  if (!p->noise)
    return plan_fail(p, RCB_ERR_ARG, "no noise model (rcb_plan_set_noise_model): the "
                     "separating chi-square needs one");
  b.pa = b.pb = 0;
  if (!(st = basis_alloc(p, &b)) && !(st = present(p, &b)) && !(st = dofs_list(p, &d))) {
    for (k = 0; k <= p->nspeeds && !st; k++) {
      double w0 = k ? p->speeds[k - 1] : rcb_meas_speed(p->meas);
      for (e = 0; e < d.n && !st; e++) st = candidates_at(p, &b, &d, e, w0, k == 0);
    }
  }
  basis_free(p, &b);
  dofs_free(p, &d);
  if (st) return st;
  qsort(p->cand, p->ncand, sizeof *p->cand, cmp_cand);
  p->res.candidates = p->ncand;
  p->done = 1;
  return RCB_OK;
}

/* ---- results ---- */

rcb_status rcb_plan_get_result(const rcb_plan *p, rcb_plan_result *out) {
  if (!p || !out || !p->done) return RCB_ERR_ARG;
  *out = p->res;
  return RCB_OK;
}

size_t rcb_plan_param_count(const rcb_plan *p) { return p ? p->np : 0; }

rcb_status rcb_plan_get_param(const rcb_plan *p, size_t k, rcb_plan_param *out) {
  if (!p || !out || k >= p->np) return RCB_ERR_ARG;
  out->name = p->par[k].name;
  out->side = p->par[k].side;
  out->value = p->par[k].value;
  out->change = p->done ? p->par[k].change : (double)NAN;
  return RCB_OK;
}

rcb_status rcb_plan_get_candidate(const rcb_plan *p, size_t rank, rcb_plan_candidate *out) {
  if (!p || !out || !p->done || rank >= p->ncand) return RCB_ERR_ARG;
  out->response = p->cand[rank].resp;
  out->reference = p->cand[rank].ref;
  out->speed = p->cand[rank].speed;
  out->gain = p->cand[rank].gain;
  out->chi2_after = p->res.chi2_sep + p->cand[rank].gain;
  out->level_db = p->rms_ref > 0 && p->cand[rank].rms > 0
                      ? 20.0 * log10(p->cand[rank].rms / p->rms_ref)
                      : -HUGE_VAL;
  return RCB_OK;
}
