/*
 * Sparse backend: SuiteSparse KLU, complex (klu_z_*), on the CSC layout of
 * the model's structural pattern (rcb_csc_pattern).
 *  - prepare: symbolic analysis (BTF + AMD ordering) once per pattern;
 *  - solve: the first call factors (klu_z_factor, partial pivoting); later
 *    calls only change values, so they refactor with the same pivot order
 *    (klu_z_refactor, no allocation, no graph search). A frequency sweep can
 *    make a kept pivot poor (K - w^2 M changes sign along the diagonal), so
 *    each refactorisation's pivot ratio min|U_ii| / max|U_ii| (as
 *    klu_z_rcond, O(n)) is compared with the last full factorisation's, and a full
 *    factorisation redone when it drops below REFACTOR_RCOND_RATIO of it.
 *    (The reciprocal pivot growth, klu_z_rgrowth, would be the sharper
 *    test but costs as much as the refactorisation itself: on a 1e5-DOF
 *    train it doubled the time per frequency. tests/test_sparse.c checks the
 *    kept pivots against zgesv across resonances.)
 *  - row scaling: a full factorisation chooses its pivots on the row-scaled
 *    matrix (KLU scale 2: each row by its largest |entry|, which balances
 *    translational rows in N/m against rotational ones in N m/rad). A
 *    refactorisation keeps those pivots and skips KLU's scaling pass, which
 *    reads all of Z again (12 % of the time per frequency): with a fixed
 *    pivot order, row scaling changes the factors only by rounding, and
 *    klu_z_solve then applies no scale factors either. The pivot ratio is
 *    still taken on the scaled diagonal, |U_kk| / Rs_k with the scale
 *    factors Rs of the last full factorisation (pivot order), so that the
 *    refactor test and the condition screen see the same, units-free,
 *    figure as before.
 * KLU allocates through SuiteSparse's global malloc (KLU 1.3 has no
 * per-object hooks): only the state struct comes from the caller's
 * allocator; KLU's bytes are reported by klu_memory (Common.mempeak).
 */
#include <math.h>

#include "rcb/rcb_config.h"
#include "solvers/zsolver.h"

#if RCB_WITH_SUITESPARSE

#include <float.h>
#include <klu.h>
#include <limits.h>
#include <stdint.h>

/* Accept a refactorisation whose pivot ratio is at least this fraction of
 * the last full factorisation's (-). */
#define REFACTOR_RCOND_RATIO 1e-3
/* A factorisation whose scaled pivot ratio is below this is singular (-):
 * its smallest pivot is rounding noise of the largest (a free-free model at
 * 0 Hz gives 4.4e-16, the same model at 1e-4 Hz 2.8e-10). */
#define SINGULAR_PIVOT_RATIO (16 * DBL_EPSILON)
/* KLU row scaling for full factorisations: 2 = by the row's largest |entry| */
#define KLU_SCALE_FULL 2

typedef struct klu_state_s {
  klu_common common;
  klu_symbolic *sym;
  klu_numeric *num;
  double rcond0;             /* pivot ratio of the last full factorisation (-) */
  double rcond;              /* pivot ratio of the last factorisation of either kind (-) */
  double *irs;               /* n reciprocal row scale factors of the last full
                              * factorisation, pivot order (1 / KLU Numeric->Rs) */
  size_t factors, refactors; /* counts of each kind, for tests and benchmarks */
} klu_state;

static rcb_status klu_status(const klu_common *c) {
  switch (c->status) {
    case KLU_OK: return RCB_OK;
    case KLU_SINGULAR: return RCB_ERR_SINGULAR;
    case KLU_OUT_OF_MEMORY: return RCB_ERR_NOMEM;
    case KLU_TOO_LARGE: return RCB_ERR_UNSUPPORTED;
    default: return RCB_ERR_ARG;
  }
}

static rcb_status klu_prepare(rcb_layout *L, const rcb_allocator *a) {
  klu_state *s;
  if (L->n > (size_t)INT_MAX || L->nnz > (size_t)INT_MAX) return RCB_ERR_UNSUPPORTED;
  s = rcb_alloc(a, sizeof *s);
  if (!s) return RCB_ERR_NOMEM;
  s->irs = rcb_alloc(a, L->n * sizeof *s->irs);
  if (!s->irs) {
    rcb_free(a, s);
    return RCB_ERR_NOMEM;
  }
  klu_defaults(&s->common);
  s->common.scale = KLU_SCALE_FULL;
  /* COLAMD rather than AMD: on trains numbered along the shaft line it
   * keeps neighbouring columns together, and the memory-bound
   * refactorisation ran 1.5 to 2 times faster for the same fill
   * (1e5-DOF train: lnz 650001 vs 649969). */
  s->common.ordering = 1;
  /* COLAMD gives KLU no fill estimate, so the first factorisation reserves
   * initmem x nnz(A) entries (default 10: 0.5 GB transient on 1e5 DOF);
   * fill on these patterns is ~1.1 nnz(A), and KLU grows the space itself
   * if needed. */
  s->common.initmem = 1.2;
  s->sym = klu_analyze((int)L->n, L->colp, L->rowi, &s->common);
  if (!s->sym) {
    rcb_status st = klu_status(&s->common);
    rcb_free(a, s->irs);
    rcb_free(a, s);
    return st ? st : RCB_ERR_NOMEM;
  }
  L->solver = s;
  return RCB_OK;
}

static void klu_release(rcb_layout *L, const rcb_allocator *a) {
  klu_state *s = L->solver;
  if (!s) return;
  if (s->num) klu_z_free_numeric(&s->num, &s->common);
  if (s->sym) klu_free_symbolic(&s->sym, &s->common);
  rcb_free(a, s->irs);
  rcb_free(a, s);
  L->solver = NULL;
}

/* Pivot ratio min |U_kk| / max |U_kk| of the row-scaled matrix (-); 0 if a
 * pivot is zero or NaN (as klu_z_rcond, O(n), but on squared moduli: no
 * hypot per pivot). After an unscaled refactorisation (unscaled = 1) U_kk
 * is multiplied by the kept reciprocal scale factor of its pivot row, so
 * the moduli are O(1) and their squares safe from overflow; a full
 * factorisation's U is scaled already. */
static double pivot_ratio(const klu_state *s, int unscaled) {
  const double *u = s->num->Udiag; /* n complex entries, re/im interleaved */
  double umin = (double)INFINITY, umax = 0;
  size_t k, n = (size_t)s->num->n;
  for (k = 0; k < n; k++) {
    double r = unscaled ? s->irs[k] : 1.0, re = r * u[2 * k], im = r * u[2 * k + 1];
    double d = re * re + im * im;
    if (!(d > 0)) return 0.0;
    if (d < umin) umin = d;
    if (d > umax) umax = d;
  }
  return n && umax < (double)INFINITY ? sqrt(umin / umax) : 0.0;
}

/* Refactor with the kept pivots, without row scaling (KLU scale -1: no
 * scaling pass and no pattern check; the pattern is the one analysed).
 * Returns 1 if it succeeded, with its pivot ratio in s->rcond. */
static int refactor_unscaled(const rcb_layout *L, klu_state *s, double *Ax) {
  int ok;
  s->common.scale = -1;
  ok = klu_z_refactor(L->colp, L->rowi, Ax, s->sym, s->num, &s->common);
  s->common.scale = KLU_SCALE_FULL;
  if (ok) s->rcond = pivot_ratio(s, 1);
  return ok;
}

/* Refactor with the kept pivots; 1 if the result is acceptable. */
static int try_refactor(const rcb_layout *L, klu_state *s, double *Ax) {
  return refactor_unscaled(L, s, Ax) && s->rcond >= REFACTOR_RCOND_RATIO * s->rcond0;
}

/* Full factorisation with row scaling; its scale factors are kept for the
 * pivot ratios of the unscaled refactorisations that follow. */
static rcb_status full_factor(const rcb_layout *L, klu_state *s, double *Ax) {
  size_t k;
  if (s->num) klu_z_free_numeric(&s->num, &s->common);
  s->num = klu_z_factor(L->colp, L->rowi, Ax, s->sym, &s->common);
  if (!s->num) return klu_status(&s->common) ? klu_status(&s->common) : RCB_ERR_NOMEM;
  for (k = 0; k < L->n; k++) s->irs[k] = s->num->Rs ? 1.0 / s->num->Rs[k] : 1.0;
  s->rcond0 = s->rcond = pivot_ratio(s, 0);
  s->factors++;
  return RCB_OK;
}

static rcb_status klu_solve_(const rcb_layout *L, rcb_complex *Z, int *ipiv, rcb_complex *B,
                             size_t nrhs) {
  klu_state *s = L->solver;
  double *Ax = (double *)Z;
  rcb_status st;
  (void)ipiv;
  if (!s || nrhs > (size_t)INT_MAX) return RCB_ERR_ARG;
  /* KLU stops only at an exactly zero pivot; a scaled pivot at rounding
   * level of the largest is as singular (LAPACK finds an exactly zero pivot
   * on the same matrix: a free-free model at 0 Hz), once fresh pivoting has
   * been tried. */
  if (s->num && try_refactor(L, s, Ax) && s->rcond >= SINGULAR_PIVOT_RATIO)
    s->refactors++;
  else if ((st = full_factor(L, s, Ax)))
    return st;
  if (s->rcond < SINGULAR_PIVOT_RATIO) return RCB_ERR_SINGULAR;
  if (!klu_z_solve(s->sym, s->num, (int)L->n, (int)nrhs, (double *)B, &s->common))
    return klu_status(&s->common) ? klu_status(&s->common) : RCB_ERR_ARG;
  return RCB_OK;
}

static rcb_status klu_resolve(const rcb_layout *L, const rcb_complex *Z, const int *ipiv,
                              rcb_complex *B, size_t nrhs, char trans) {
  klu_state *s = L->solver;
  int ok;
  (void)Z;
  (void)ipiv;
  if (!s || !s->num || nrhs > (size_t)INT_MAX) return RCB_ERR_STATE;
  if (trans == 'N' || trans == 'n')
    ok = klu_z_solve(s->sym, s->num, (int)L->n, (int)nrhs, (double *)B, &s->common);
  else
    ok = klu_z_tsolve(s->sym, s->num, (int)L->n, (int)nrhs, (double *)B,
                      trans == 'C' || trans == 'c', &s->common);
  return ok ? RCB_OK : RCB_ERR_ARG;
}

static size_t klu_memory(const rcb_layout *L) {
  const klu_state *s = L->solver;
  return s ? s->common.mempeak : 0;
}

/* klu_z_condest: Hager-Higham 1-norm estimate from KLU's factors and the
 * matrix values (still in Z: KLU does not factor in place); a few solves.
 * klu_z_rcond is only the pivot ratio min|U_ii| / max|U_ii|, not a
 * condition number. */
static rcb_status klu_rcond_(const rcb_layout *L, const rcb_complex *Z, const int *ipiv,
                             double anorm, rcb_complex *work, double *rwork, double *rcond) {
  klu_state *s = L->solver;
  (void)ipiv, (void)anorm, (void)work, (void)rwork;
  if (!s || !s->num) return RCB_ERR_STATE;
  /* klu_z_condest takes non-const arrays but only reads them */
  if (!klu_z_condest(L->colp, (double *)(uintptr_t)Z, s->sym, s->num, &s->common))
    return klu_status(&s->common) ? klu_status(&s->common) : RCB_ERR_ARG;
  *rcond = s->common.condest > 0 ? 1.0 / s->common.condest : (double)NAN;
  return RCB_OK;
}

static const rcb_zsolver_ops klu_ops = {"sparse",    NULL,        klu_solve_, klu_resolve,
                                        klu_prepare, klu_release, klu_memory, klu_rcond_};

const rcb_zsolver_ops *rcb_zsolver_sparse(void) { return &klu_ops; }

void rcb_zsolver_sparse_counts(const rcb_layout *L, size_t *factors, size_t *refactors) {
  const klu_state *s = L->solver;
  *factors = s ? s->factors : 0;
  *refactors = s ? s->refactors : 0;
}

/* Pivot ratio of the row-scaled matrix at the last factorisation (full or
 * kept-pivot): both compute it. */
double rcb_zsolver_sparse_pivot_ratio(const rcb_layout *L) {
  const klu_state *s = L->solver;
  return s ? s->rcond : (double)NAN;
}

#else /* !RCB_WITH_SUITESPARSE */

double rcb_zsolver_sparse_pivot_ratio(const rcb_layout *L) {
  (void)L;
  return (double)NAN;
}

const rcb_zsolver_ops *rcb_zsolver_sparse(void) { return NULL; }

void rcb_zsolver_sparse_counts(const rcb_layout *L, size_t *factors, size_t *refactors) {
  (void)L;
  *factors = *refactors = 0;
}

#endif
