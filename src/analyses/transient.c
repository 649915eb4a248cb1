/*
 * Time integration of M q'' + (C + Omega(t) G) q' + K q = f(t) (issue #5):
 * setup and the first-order equations of motion for CVODE.
 *
 * State y = [q; v], v = q'. With M factored once (Cholesky),
 *   q' = v,
 *   v' = -M^-1 K q - (M^-1 C + Omega M^-1 G) v + M^-1 f(t),
 * where M^-1 f = Re((Omega^2 - i alpha) e^{i phi} M^-1 F1) (unbalance, see
 * rcb_transient.h). Speed-dependent bearings are kept apart: their four
 * K/C entries are evaluated at Omega(t) on every call and enter through
 * M^-1 e_row (precomputed columns), so nothing is re-factored during a
 * run-up. The Jacobian [0 I; -M^-1 K, -M^-1 (C + Omega G)] is analytic.
 */
#include <lapacke.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "analyses/transient_internal.h"

#if RCB_WITH_SUNDIALS
#include <cvode/cvode.h>
#include <cvode/cvode_ls.h>
#include <sunmatrix/sunmatrix_dense.h>
#endif

static void *tr_alloc(rcb_transient *t, size_t size) {
  t->bytes += size;
  return rcb_alloc(&t->alloc, size);
}

void rcb_profile_eval(const rcb_speed_profile *p, double t, double *speed, double *accel,
                      double *angle) {
  double dw = p->speed1 - p->speed0, a = fabs(p->accel), t1, s;
  if (a == 0.0 || dw == 0.0) {
    *speed = p->speed0;
    *accel = 0.0;
    *angle = p->speed0 * t;
    return;
  }
  s = dw > 0.0 ? 1.0 : -1.0;
  t1 = fabs(dw) / a; /* s, when speed1 is reached */
  if (t < t1) {
    *speed = p->speed0 + s * a * t;
    *accel = s * a;
    *angle = p->speed0 * t + 0.5 * s * a * t * t;
  } else {
    *speed = p->speed1;
    *accel = 0.0;
    *angle = p->speed0 * t1 + 0.5 * s * a * t1 * t1 + p->speed1 * (t - t1);
  }
}

/* ---- setup: M^-1 times everything, by one Cholesky factorisation ---- */

static rcb_status solve_all(rcb_transient *t, const double *Lm, double *B, size_t nrhs,
                            const char *what) {
  lapack_int info;
  if (nrhs == 0) return RCB_OK;
  info = LAPACKE_dpotrs_work(LAPACK_COL_MAJOR, 'L', (lapack_int)t->n, (lapack_int)nrhs, Lm,
                             (lapack_int)t->n, B, (lapack_int)t->n);
  if (info != 0)
    return rcb_set_error(t->errmsg, RCB_ERR_LAPACK, "transient: dpotrs failed (info %d) on %s",
                         (int)info, what);
  return RCB_OK;
}

/* Add the constant bearings to K, C (dense n x n); list the tabulated ones. */
static void split_bearings(rcb_transient *t, double *K, double *C) {
  const rcb_model *m = t->m;
  size_t b, k, n = t->n, ne;
  rcb_entry e[RCB_BEARING_ENTRIES_MAX];
  t->ntab = 0;
  for (b = 0; b < m->n_bearings; b++) {
    if (m->bearings[b].n > 1) {
      t->tab[t->ntab++] = b;
      continue;
    }
    ne = rcb_bearing_entries(m, b, 0.0, e);
    for (k = 0; k < ne; k++) {
      K[e[k].row + n * e[k].col] += e[k].k;
      C[e[k].row + n * e[k].col] += e[k].c;
    }
  }
}

/* Unit columns e_x, e_y of every tabulated bearing, and the unbalance phasor
 * at unit speed, as right-hand sides for M^-1. */
static rcb_status fill_rhs(rcb_transient *t) {
  const rcb_model *m = t->m;
  size_t i, n = t->n;
  rcb_complex *F = tr_alloc(t, n * sizeof *F);
  if (!F) return rcb_set_error(t->errmsg, RCB_ERR_NOMEM, "transient: out of memory");
  rcb_model_unbalance_force(m, 1.0, F);
  for (i = 0; i < n; i++) {
    t->Pr[i] = creal(F[i]);
    t->Pi[i] = cimag(F[i]);
  }
  rcb_free(&t->alloc, F);
  for (i = 0; i < t->ntab; i++) {
    const rcb_node_t *nd = &m->nodes[m->bearings[t->tab[i]].at.node];
    t->MiB[(size_t)nd->dof[0] + n * (2 * i)] = 1.0;
    t->MiB[(size_t)nd->dof[1] + n * (2 * i + 1)] = 1.0;
  }
  return RCB_OK;
}

static rcb_status factor_and_solve(rcb_transient *t, double *Mm) {
  size_t n = t->n;
  rcb_status st;
  lapack_int info = LAPACKE_dpotrf_work(LAPACK_COL_MAJOR, 'L', (lapack_int)n, Mm,
                                        (lapack_int)n);
  if (info != 0)
    return rcb_set_error(t->errmsg, RCB_ERR_MODEL,
                         "transient: the mass matrix is not positive definite (dpotrf info "
                         "%d); every DOF needs mass or inertia",
                         (int)info);
  if ((st = fill_rhs(t)) || (st = solve_all(t, Mm, t->MiK, n, "K")) ||
      (st = solve_all(t, Mm, t->MiC, n, "C")) || (st = solve_all(t, Mm, t->MiG, n, "G")) ||
      (st = solve_all(t, Mm, t->MiB, 2 * t->ntab, "bearing rows")) ||
      (st = solve_all(t, Mm, t->Pr, 1, "unbalance")) ||
      (st = solve_all(t, Mm, t->Pi, 1, "unbalance")))
    return st;
  return RCB_OK;
}

static rcb_status setup_matrices(rcb_transient *t) {
  size_t n = t->n;
  rcb_layout L;
  rcb_status st;
  double *Mm = tr_alloc(t, n * n * sizeof *Mm);
  if (!Mm) return rcb_set_error(t->errmsg, RCB_ERR_NOMEM, "transient: out of memory");
  rcb_layout_dense(&L, n);
  rcb_assemble_structure(t->m, &L, Mm, t->MiC, t->MiG, t->MiK);
  split_bearings(t, t->MiK, t->MiC);
  st = factor_and_solve(t, Mm);
  rcb_free(&t->alloc, Mm);
  t->bytes -= n * n * sizeof *Mm;
  return st;
}

static rcb_status alloc_arrays(rcb_transient *t, size_t nout, const rcb_dof *outputs) {
  size_t i, n = t->n, nb = t->m->n_bearings;
  t->MiK = tr_alloc(t, n * n * sizeof(double));
  t->MiC = tr_alloc(t, n * n * sizeof(double));
  t->MiG = tr_alloc(t, n * n * sizeof(double));
  t->tab = tr_alloc(t, (nb ? nb : 1) * sizeof *t->tab);
  t->MiB = tr_alloc(t, n * 2 * (nb ? nb : 1) * sizeof(double));
  t->Pr = tr_alloc(t, n * sizeof(double));
  t->Pi = tr_alloc(t, n * sizeof(double));
  t->q = tr_alloc(t, n * sizeof(double));
  t->v = tr_alloc(t, n * sizeof(double));
  t->out = tr_alloc(t, (nout ? nout : 1) * sizeof(double));
  t->out_row = tr_alloc(t, (nout ? nout : 1) * sizeof *t->out_row);
  t->Qa = tr_alloc(t, (nout ? nout : 1) * sizeof *t->Qa);
  t->Qb = tr_alloc(t, (nout ? nout : 1) * sizeof *t->Qb);
  if (!t->Qa || !t->Qb || !t->MiK || !t->MiC || !t->MiG || !t->tab || !t->MiB || !t->Pr || !t->Pi || !t->q ||
      !t->v || !t->out || !t->out_row)
    return rcb_set_error(t->errmsg, RCB_ERR_NOMEM, "transient: out of memory (n = %zu)", n);
  t->nout = nout;
  for (i = 0; i < nout; i++)
    if (rcb_model_dof_index(t->m, outputs[i], &t->out_row[i]) != RCB_OK)
      return rcb_set_error(t->errmsg, RCB_ERR_ARG,
                           "transient: output %zu (node %zu, direction %d) is not in the model",
                           i, outputs[i].node, (int)outputs[i].dir);
  return RCB_OK;
}

#if RCB_WITH_SUNDIALS

/* ---- the equations of motion ---- */

/* a = M^-1 (f - K q - (C + Omega G) v) at time tt. */
static void accel(const rcb_transient *t, double tt, const double *q, const double *v,
                  double *a) {
  const rcb_model *m = t->m;
  size_t i, j, b, n = t->n;
  double W, al, phi, cr, ci, cs, sn;
  rcb_profile_eval(&t->prof, tt, &W, &al, &phi);
  /* (Omega^2 - i alpha) e^{i phi} = cr + i ci */
  cs = cos(phi);
  sn = sin(phi);
  cr = W * W * cs + al * sn;
  ci = W * W * sn - al * cs;
  for (i = 0; i < n; i++) a[i] = cr * t->Pr[i] - ci * t->Pi[i];
  if (t->fext) {
    double fe = rcb_transient_force_at(t, tt);
    for (i = 0; i < n; i++) a[i] += fe * t->Mif[i];
  }
  for (j = 0; j < n; j++) {
    const double *kc = t->MiK + n * j, *cc = t->MiC + n * j, *gc = t->MiG + n * j;
    double qj = q[j], vj = v[j], wv = W * vj;
    for (i = 0; i < n; i++) a[i] -= kc[i] * qj + cc[i] * vj + gc[i] * wv;
  }
  for (b = 0; b < t->ntab; b++) {
    rcb_entry e[RCB_BEARING_ENTRIES_MAX];
    double r[2] = {0.0, 0.0};
    const double *bx = t->MiB + n * (2 * b), *by = t->MiB + n * (2 * b + 1);
    rcb_bearing_entries(m, t->tab[b], W, e);
    for (i = 0; i < 4; i++) r[i / 2] += e[i].k * q[e[i].col] + e[i].c * v[e[i].col];
    for (i = 0; i < n; i++) a[i] -= bx[i] * r[0] + by[i] * r[1];
  }
}

int rcb_transient_rhs(sunrealtype tt, N_Vector y, N_Vector ydot, void *user) {
  const rcb_transient *t = user;
  const double *yy = N_VGetArrayPointer(y);
  double *yd = N_VGetArrayPointer(ydot);
  memcpy(yd, yy + t->n, t->n * sizeof *yd);
  accel(t, tt, yy, yy + t->n, yd + t->n);
  return 0;
}

/* Tabulated bearings at speed W (rad/s): Kt(:, col) += M^-1 e_row k and
 * Dt(:, col) += M^-1 e_row c for each entry (1/s^2, 1/s). */
static void add_bearings(const rcb_transient *t, double W, double *Kt, double *Dt) {
  size_t b, i, k, n = t->n;
  for (b = 0; b < t->ntab; b++) {
    rcb_entry e[RCB_BEARING_ENTRIES_MAX];
    rcb_bearing_entries(t->m, t->tab[b], W, e);
    for (k = 0; k < 4; k++) {
      const double *bc = t->MiB + n * (2 * b + k / 2);
      double *kq = Kt + n * e[k].col, *dv = Dt + n * e[k].col;
      for (i = 0; i < n; i++) {
        kq[i] += bc[i] * e[k].k;
        dv[i] += bc[i] * e[k].c;
      }
    }
  }
}

/* CVODE's linear system (CVodeSetLinSysFn). The Jacobian of the first-order
 * form is J = [0 I; -Kt, -Dt] with Kt = M^-1 K and Dt = M^-1 (C + Omega G)
 * at the speed of time tt; the Schur solver (transient_linsol.c) needs only
 * Kt and S = I + gamma Dt + gamma^2 Kt. So these are formed here, n x n,
 * and A (2n x 2n) is left untouched: CVODE's own linear system copied a
 * saved J into A and scaled it at every setup, 4n^2 entries twice, 30 % of
 * a run's time at n = 88 (issue #27). Kt and Dt are re-evaluated when CVODE
 * asks for a new Jacobian (jok false), as its saved J was; S at every call. */
int rcb_transient_linsys(sunrealtype tt, N_Vector y, N_Vector fy, SUNMatrix A,
                         sunbooleantype jok, sunbooleantype *jcur, sunrealtype gamma,
                         void *user, N_Vector tmp1, N_Vector tmp2, N_Vector tmp3) {
  rcb_transient *t = user;
  size_t i, nn = t->n * t->n;
  double g2 = gamma * gamma;
  (void)y;
  (void)fy;
  (void)A;
  (void)tmp1;
  (void)tmp2;
  (void)tmp3;
  if (!jok) {
    double W, al, phi;
    rcb_profile_eval(&t->prof, tt, &W, &al, &phi);
    memcpy(t->Kt, t->MiK, nn * sizeof *t->Kt);
    for (i = 0; i < nn; i++) t->Dt[i] = t->MiC[i] + W * t->MiG[i];
    add_bearings(t, W, t->Kt, t->Dt);
  }
  *jcur = !jok;
  for (i = 0; i < nn; i++) t->S[i] = gamma * t->Dt[i] + g2 * t->Kt[i];
  for (i = 0; i < t->n; i++) t->S[i * (t->n + 1)] += 1.0;
  t->gamma = gamma;
  return 0;
}

/* ---- CVODE set-up ---- */

static void on_message(void *user, int code, const char *func, const char *msg) {
  rcb_transient *t = user;
  (void)code;
  snprintf(t->sunmsg, sizeof t->sunmsg, "%s: %s", func ? func : "CVODE", msg ? msg : "");
}

static rcb_status setup_cvode(rcb_transient *t) {
  sunindextype N = (sunindextype)(2 * t->n);
  if (rcb_sun_context_create(&t->ctx))
    return rcb_set_error(t->errmsg, RCB_ERR_NOMEM, "transient: SUNContext_Create failed");
  t->y = N_VNew_Serial(N, t->ctx);
  t->abstol = N_VNew_Serial(N, t->ctx);
  t->J = SUNDenseMatrix(N, N, t->ctx);
  t->S = tr_alloc(t, t->n * t->n * sizeof *t->S);
  t->Kt = tr_alloc(t, t->n * t->n * sizeof *t->Kt);
  t->Dt = tr_alloc(t, t->n * t->n * sizeof *t->Dt);
  t->ipiv = tr_alloc(t, (t->n ? t->n : 1) * sizeof *t->ipiv);
  t->LS = t->S && t->Kt && t->Dt && t->ipiv ? rcb_transient_linsol(t) : NULL;
  t->cvode = CVodeCreate(CV_BDF, t->ctx);
  if (!t->y || !t->abstol || !t->J || !t->LS || !t->cvode)
    return rcb_set_error(t->errmsg, RCB_ERR_NOMEM,
                         "transient: out of memory creating the CVODE integrator (state %ld)",
                         (long)N);
  t->route.fn = on_message;
  t->route.user = t;
  if (rcb_sun_cvode_messages(t->cvode, t->ctx, &t->route))
    return rcb_set_error(t->errmsg, RCB_ERR_NOMEM, "transient: cannot set the CVODE handler");
  return RCB_OK;
}

static void free_cvode(rcb_transient *t) {
  if (t->cvode) CVodeFree(&t->cvode);
  if (t->LS) SUNLinSolFree(t->LS);
  if (t->J) SUNMatDestroy(t->J);
  if (t->y) N_VDestroy(t->y);
  if (t->abstol) N_VDestroy(t->abstol);
  rcb_sun_context_free(&t->ctx);
  rcb_free(&t->alloc, t->S);
  rcb_free(&t->alloc, t->Kt);
  rcb_free(&t->alloc, t->Dt);
  rcb_free(&t->alloc, t->ipiv);
}
#endif /* RCB_WITH_SUNDIALS */

/* Not integrated (yet): a speed factor (the unbalance would drive at the
 * stated speed while G and the bearings run at the factored one), and a
 * speed-dependent bearing on a pedestal (the tabulated-bearing force path
 * acts on the shaft rows only). */
static rcb_status transient_supported(rcb_transient *t) {
  size_t b;
  if (t->m->speed_factor != 1.0)
    return rcb_set_error(t->errmsg, RCB_ERR_UNSUPPORTED,
                         "transient: speed factor %g; the time integration runs at the stated "
                         "speed (set [model] speed_factor = 1)",
                         t->m->speed_factor);
  for (b = 0; b < t->m->n_bearings; b++)
    if (t->m->bearings[b].has_ped && t->m->bearings[b].n > 1)
      return rcb_set_error(t->errmsg, RCB_ERR_UNSUPPORTED,
                           "transient: bearing '%s' is speed-dependent and on a pedestal; not "
                           "supported by the time integration",
                           t->m->bearings[b].name);
  return RCB_OK;
}

rcb_status rcb_transient_create(rcb_transient **out, const rcb_model *m, size_t nout,
                                const rcb_dof *outputs, const rcb_allocator *alloc) {
  rcb_allocator a;
  rcb_transient *t;
  rcb_status st;
  if (!out) return RCB_ERR_ARG;
  *out = NULL;
  if (!m || (nout && !outputs)) return RCB_ERR_ARG;
  if (!m->finalized) return RCB_ERR_STATE;
  rcb_allocator_init(&a, alloc);
  t = rcb_alloc(&a, sizeof *t);
  if (!t) return RCB_ERR_NOMEM;
  t->alloc = a;
  t->m = m;
  t->n = m->ndof;
  t->bytes = sizeof *t;
  t->rtol = 1e-7;
  t->atol_q = 1e-13;
  t->atol_v = 1e-10;
  t->ss_tol = 1e-5;
  t->ss_spp = 32;
  t->ss_max_periods = 20000;
  *out = t;
  if ((st = transient_supported(t))) return st;
#if RCB_WITH_SUNDIALS
  if ((st = alloc_arrays(t, nout, outputs)) || (st = setup_matrices(t)) ||
      (st = setup_cvode(t)))
    return st;
  return RCB_OK;
#else
  (void)st;
  (void)alloc_arrays;
  (void)setup_matrices;
  return rcb_set_error(t->errmsg, RCB_ERR_UNSUPPORTED,
                       "transient: this librcb was built without SUNDIALS "
                       "(RCB_WITH_SUNDIALS=OFF); time integration is not available");
#endif
}

void rcb_transient_destroy(rcb_transient *t) {
  rcb_allocator a;
  if (!t) return;
  a = t->alloc;
#if RCB_WITH_SUNDIALS
  free_cvode(t);
#endif
  rcb_free(&a, t->MiK);
  rcb_free(&a, t->MiC);
  rcb_free(&a, t->MiG);
  rcb_free(&a, t->tab);
  rcb_free(&a, t->MiB);
  rcb_free(&a, t->Pr);
  rcb_free(&a, t->Pi);
  rcb_free(&a, t->Mif);
  rcb_free(&a, t->q);
  rcb_free(&a, t->v);
  rcb_free(&a, t->out);
  rcb_free(&a, t->out_row);
  rcb_free(&a, t->Qa);
  rcb_free(&a, t->Qb);
  rcb_free(&a, t);
}

const char *rcb_transient_errmsg(const rcb_transient *t) { return t ? t->errmsg : ""; }

rcb_status rcb_transient_set_tolerances(rcb_transient *t, double rtol, double atol_q,
                                        double atol_v) {
  if (!t) return RCB_ERR_ARG;
  if (!(rtol > 0.0 && rtol < 1.0) || !(atol_q > 0.0) || !(atol_v > 0.0) || !isfinite(atol_q) ||
      !isfinite(atol_v))
    return rcb_set_error(t->errmsg, RCB_ERR_ARG,
                         "transient: tolerances rtol %g, atol_q %g m, atol_v %g m/s; expected "
                         "0 < rtol < 1 and finite atol > 0",
                         rtol, atol_q, atol_v);
  t->rtol = rtol;
  t->atol_q = atol_q;
  t->atol_v = atol_v;
  return RCB_OK;
}

rcb_status rcb_transient_set_steady(rcb_transient *t, double tol, size_t samples_per_period,
                                    size_t max_periods) {
  if (!t) return RCB_ERR_ARG;
  if (!(tol > 0.0 && tol < 1.0) || samples_per_period < 4 || max_periods < 4)
    return rcb_set_error(t->errmsg, RCB_ERR_ARG,
                         "transient: steady-state settings tol %g, %zu samples per period, "
                         "%zu periods; expected 0 < tol < 1, >= 4 samples, >= 4 periods",
                         tol, samples_per_period, max_periods);
  t->ss_tol = tol;
  t->ss_spp = samples_per_period;
  t->ss_max_periods = max_periods;
  return RCB_OK;
}

double rcb_transient_force_at(const rcb_transient *t, double tt) {
  double x;
  size_t k;
  if (!t->fext || !(tt >= 0.0)) return 0.0;
  x = tt / t->dtf;
  if (x >= (double)(t->nf - 1)) /* the last sample, then nothing */
    return x <= (double)(t->nf - 1) * (1.0 + 1e-12) ? t->fext[t->nf - 1] : 0.0;
  k = (size_t)x;
  x -= (double)k;
  return (1.0 - x) * t->fext[k] + x * t->fext[k + 1];
}

/* M^-1 e_row into t->Mif: M assembled and factored again (creation keeps
 * only M^-1 K, M^-1 C, M^-1 G). */
static rcb_status force_column(rcb_transient *t, size_t row) {
  size_t n = t->n;
  rcb_layout L;
  rcb_status st = RCB_OK;
  double *Mm = rcb_alloc(&t->alloc, n * n * sizeof *Mm);
  lapack_int info;
  if (!Mm) return rcb_set_error(t->errmsg, RCB_ERR_NOMEM, "transient: out of memory");
  rcb_layout_dense(&L, n);
  rcb_assemble_structure(t->m, &L, Mm, NULL, NULL, NULL);
  info = LAPACKE_dpotrf_work(LAPACK_COL_MAJOR, 'L', (lapack_int)n, Mm, (lapack_int)n);
  memset(t->Mif, 0, n * sizeof *t->Mif);
  t->Mif[row] = 1.0;
  if (info != 0)
    st = rcb_set_error(t->errmsg, RCB_ERR_MODEL, "transient: the mass matrix is not positive "
                       "definite (dpotrf info %d)", (int)info);
  else
    st = solve_all(t, Mm, t->Mif, 1, "the force column");
  rcb_free(&t->alloc, Mm);
  return st;
}

rcb_status rcb_transient_set_force(rcb_transient *t, rcb_dof dof, const double *f, size_t nf,
                                   double dt) {
  size_t row, i;
  if (!t) return RCB_ERR_ARG;
  t->fext = NULL;
  if (!f) return RCB_OK;
  if (nf < 2 || !(dt > 0.0) || !isfinite(dt))
    return rcb_set_error(t->errmsg, RCB_ERR_ARG, "transient: force of %zu samples every %g s; "
                         "expected at least 2 samples and dt > 0", nf, dt);
  for (i = 0; i < nf; i++)
    if (!isfinite(f[i]))
      return rcb_set_error(t->errmsg, RCB_ERR_ARG, "transient: force sample %zu is %g; "
                           "expected finite values (N or N m)", i, f[i]);
  if (rcb_model_dof_index(t->m, dof, &row) != RCB_OK)
    return rcb_set_error(t->errmsg, RCB_ERR_ARG, "transient: force DOF (node %zu, direction "
                         "%d) is not in the model", dof.node, (int)dof.dir);
  if (!t->Mif && !(t->Mif = tr_alloc(t, t->n * sizeof *t->Mif)))
    return rcb_set_error(t->errmsg, RCB_ERR_NOMEM, "transient: out of memory");
  {
    rcb_status st = force_column(t, row);
    if (st) return st;
  }
  t->fext = f;
  t->nf = nf;
  t->dtf = dt;
  return RCB_OK;
}

rcb_status rcb_transient_get_stats(const rcb_transient *t, rcb_transient_stats *s) {
  if (!t || !s) return RCB_ERR_ARG;
  *s = t->stats;
  return RCB_OK;
}
