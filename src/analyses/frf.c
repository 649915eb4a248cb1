/*
 * Frequency response functions (paper eqs. 5-6) and unbalance response
 * (eqs. 3-4, solved as the complex system at omega = Omega):
 *   Z(w, W) = K - w^2 M + i w (C + W G),  H = Z^-1,
 * one factorisation per frequency with all inputs as right-hand sides.
 * Everything is sized in rcb_frf_create; evaluations allocate nothing, but
 * for KLU's own factors (solvers/klu.c).
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "analyses/frf_internal.h"


/* Automatic choice: KLU from this many DOF on (when built with it), banded
 * storage once the band is well below the order, dense otherwise. The
 * threshold comes from tools/bench/bench_scale (docs/benchmarks.md): with
 * its refactorisations unscaled, KLU took half the time of zgbsv per
 * frequency on trains of 36, 64 and 106 DOF and on the paper system. */
#define SPARSE_MIN_DOF 32

static rcb_status choose_solver(rcb_frf *f, rcb_solver_kind kind, size_t n, size_t bw) {
  const rcb_zsolver_ops *sparse = rcb_zsolver_sparse();
  switch (kind) {
    case RCB_SOLVER_DENSE: f->ops = rcb_zsolver_dense(); return RCB_OK;
    case RCB_SOLVER_BANDED: f->ops = rcb_zsolver_banded(); return RCB_OK;
    case RCB_SOLVER_SPARSE:
      if (!sparse)
        return rcb_set_error(f->errmsg, RCB_ERR_UNSUPPORTED,
                             "solver 'sparse' needs librcb built with RCB_WITH_SUITESPARSE=ON "
                             "(use dense, banded or auto)");
      f->ops = sparse;
      return RCB_OK;
    case RCB_SOLVER_AUTO:
    case RCB_SOLVER_MODAL: break; /* modal: the direct solver behind it, as auto */
    default:
      return rcb_set_error(f->errmsg, RCB_ERR_ARG,
                           "solver kind %d: expected auto, dense, banded, sparse or modal",
                           (int)kind);
  }
  if (sparse && n >= SPARSE_MIN_DOF)
    f->ops = sparse;
  else
    f->ops = (n >= 32 && 4 * bw < n) ? rcb_zsolver_banded() : rcb_zsolver_dense();
  return RCB_OK;
}

/* Sparse layout: the model's structural pattern, then KLU's symbolic
 * analysis, once for the life of the object. */
static rcb_status sparse_layout(rcb_frf *f) {
  const rcb_model *m = f->m;
  int *colp, *rowi;
  size_t nnz;
  rcb_status st = rcb_csc_pattern(m, &f->alloc, &colp, &rowi, &nnz);
  if (st == RCB_ERR_NOMEM)
    return rcb_set_error(f->errmsg, st, "out of memory building the sparsity pattern");
  if (st)
    return rcb_set_error(f->errmsg, st, "model of %zu DOF too large for KLU's int indices",
                         m->ndof);
  f->bytes += (m->ndof + 1 + nnz) * sizeof(int);
  rcb_layout_csc(&f->L, m->ndof, m->bandwidth, colp, rowi);
  if ((st = f->ops->prepare(&f->L, &f->alloc)))
    return rcb_set_error(f->errmsg, st, "KLU symbolic analysis of %zu DOF, %zu entries failed",
                         m->ndof, nnz);
  return RCB_OK;
}

rcb_solver_kind rcb_frf_pick_solver(const rcb_model *m, size_t nfreq, int one_speed) {
  double n;
  if (!m || !m->finalized || !one_speed || m->ndof > RCB_MODAL_MAX_DOF) return RCB_SOLVER_AUTO;
  n = (double)m->ndof;
  return (double)nfreq >= RCB_MODAL_PAYS * n * n ? RCB_SOLVER_MODAL : RCB_SOLVER_AUTO;
}

static void *frf_alloc(rcb_frf *f, size_t size) {
  f->bytes += size;
  return rcb_alloc(&f->alloc, size);
}

static rcb_status map_dofs(rcb_frf *f, size_t k, const rcb_dof *dofs, size_t *rows,
                           const char *what) {
  size_t i;
  for (i = 0; i < k; i++)
    if (rcb_model_dof_index(f->m, dofs[i], &rows[i]) != RCB_OK)
      return rcb_set_error(f->errmsg, RCB_ERR_ARG, "%s %zu: node %zu direction %d not in model",
                           what, i, dofs[i].node, (int)dofs[i].dir);
  return RCB_OK;
}

static rcb_status frf_setup(rcb_frf *f, size_t nout, const rcb_dof *outputs, size_t nin,
                            const rcb_dof *inputs, rcb_solver_kind solver) {
  const rcb_model *m = f->m;
  size_t n = m->ndof, sz, ncol = nin ? nin : 1;
  rcb_status st;
  if ((st = choose_solver(f, solver, n, m->bandwidth))) return st;
  if (f->ops->layout)
    f->ops->layout(&f->L, n, m->bandwidth);
  else if ((st = sparse_layout(f)))
    return st;
  sz = rcb_layout_size(&f->L);
  f->M = frf_alloc(f, sz * sizeof *f->M);
  f->C = frf_alloc(f, sz * sizeof *f->C);
  f->G = frf_alloc(f, sz * sizeof *f->G);
  f->K = frf_alloc(f, sz * sizeof *f->K);
  f->Z = frf_alloc(f, sz * sizeof *f->Z);
  f->B = frf_alloc(f, n * ncol * sizeof *f->B);
  f->ipiv = frf_alloc(f, n * sizeof *f->ipiv);
  f->out_row = frf_alloc(f, (nout ? nout : 1) * sizeof *f->out_row);
  f->in_row = frf_alloc(f, ncol * sizeof *f->in_row);
  if (!f->M || !f->C || !f->G || !f->K || !f->Z || !f->B || !f->ipiv || !f->out_row ||
      !f->in_row)
    return rcb_set_error(f->errmsg, RCB_ERR_NOMEM, "out of memory sizing the FRF workspace");
  if ((st = rcb_frf_cond_setup(f))) return st;
  f->nout = nout;
  f->nin = nin;
  if ((st = map_dofs(f, nout, outputs, f->out_row, "output"))) return st;
  if ((st = map_dofs(f, nin, inputs, f->in_row, "input"))) return st;
  rcb_assemble_structure(m, &f->L, f->M, f->C, f->G, f->K);
  return RCB_OK;
}

rcb_status rcb_frf_create(rcb_frf **out, const rcb_model *m, size_t nout,
                          const rcb_dof *outputs, size_t nin, const rcb_dof *inputs,
                          rcb_solver_kind solver, const rcb_allocator *alloc) {
  rcb_allocator a;
  rcb_frf *f;
  rcb_status st;
  if (!out) return RCB_ERR_ARG;
  *out = NULL;
  if (!m || (nout && !outputs) || (nin && !inputs)) return RCB_ERR_ARG;
  if (!m->finalized) return RCB_ERR_STATE;
  rcb_allocator_init(&a, alloc);
  f = rcb_alloc(&a, sizeof *f);
  if (!f) return RCB_ERR_NOMEM;
  f->alloc = a;
  f->m = m;
  f->bytes = sizeof *f;
  st = frf_setup(f, nout, outputs, nin, inputs, solver);
  if (!st && solver == RCB_SOLVER_MODAL) st = rcb_frf_modal_create(f, NULL);
  if (st) {
    rcb_frf_destroy(f);
    return st;
  }
  *out = f;
  return RCB_OK;
}

void rcb_frf_destroy(rcb_frf *f) {
  rcb_allocator a;
  if (!f) return;
  a = f->alloc;
  rcb_frf_modal_destroy(f);
  if (f->ops && f->ops->release) f->ops->release(&f->L, &a);
  if (f->L.sparse) {
    rcb_free(&a, f->L.colp);
    rcb_free(&a, f->L.rowi);
  }
  rcb_free(&a, f->M);
  rcb_free(&a, f->C);
  rcb_free(&a, f->G);
  rcb_free(&a, f->K);
  rcb_free(&a, f->Z);
  rcb_free(&a, f->B);
  rcb_free(&a, f->ipiv);
  rcb_free(&a, f->out_row);
  rcb_free(&a, f->in_row);
  rcb_frf_cond_free(f);
  rcb_free(&a, f);
}

rcb_status rcb_frf_refresh(rcb_frf *f) {
  if (!f) return RCB_ERR_ARG;
  rcb_assemble_structure(f->m, &f->L, f->M, f->C, f->G, f->K);
  rcb_frf_modal_invalidate(f);
  f->factored = 0;
  return RCB_OK;
}

const char *rcb_frf_errmsg(const rcb_frf *f) { return f ? f->errmsg : "no FRF object"; }

rcb_solver_kind rcb_frf_solver(const rcb_frf *f) {
  if (f && f->modal) return RCB_SOLVER_MODAL;
  if (f && f->L.sparse) return RCB_SOLVER_SPARSE;
  return (f && f->L.banded) ? RCB_SOLVER_BANDED : RCB_SOLVER_DENSE;
}

size_t rcb_frf_memory(const rcb_frf *f) {
  if (!f) return 0;
  return f->bytes + (f->ops && f->ops->memory ? f->ops->memory(&f->L) : 0) +
         rcb_frf_modal_memory(f);
}

/* Z = K - w^2 M + i w (C + W G) + bearings at speed W, then factor and solve
 * Z X = B in place. */
rcb_status rcb_frf_factor_solve(rcb_frf *f, double omega, double speed, size_t nrhs) {
  const rcb_model *m = f->m;
  size_t k, sz = rcb_layout_size(&f->L), b;
  double w2 = omega * omega;
  rcb_status st;
  for (k = 0; k < sz; k++)
    f->Z[k] = CMPLX(f->K[k] - w2 * f->M[k], omega * (f->C[k] + speed * f->G[k]));
  for (b = 0; b < m->n_bearings; b++) {
    rcb_entry e[RCB_BEARING_ENTRIES_MAX];
    size_t j, ne = rcb_bearing_entries(m, b, speed, e);
    for (j = 0; j < ne; j++) f->Z[rcb_layout_at(&f->L, e[j].row, e[j].col)] +=
        CMPLX(e[j].k, omega * e[j].c);
  }
  rcb_frf_cond_before(f);
  st = f->ops->solve(&f->L, f->Z, f->ipiv, f->B, nrhs);
  f->factored = st == RCB_OK;
  if (!st) rcb_frf_cond_after(f, omega, speed);
  if (st == RCB_ERR_SINGULAR)
    return rcb_set_error(f->errmsg, st,
                         "dynamic stiffness singular at %g rad/s, speed %g rad/s (a free-free "
                         "model at omega = 0, or an undamped resonance hit exactly)",
                         omega, speed);
  if (st == RCB_ERR_NOMEM)
    return rcb_set_error(f->errmsg, st, "%s solver out of memory at %g rad/s", f->ops->name,
                         omega);
  if (st) return rcb_set_error(f->errmsg, st, "%s solver failed at %g rad/s", f->ops->name,
                               omega);
  return RCB_OK;
}

static int bad_speed(double omega, double speed) {
  return !isfinite(omega) || !isfinite(speed) || omega < 0;
}

rcb_status rcb_frf_eval(rcb_frf *f, double omega, double speed, rcb_frf_kind kind,
                        rcb_complex *H) {
  if (f && f->modal) return rcb_frf_modal_eval(f, omega, speed, kind, H);
  return rcb_frf_eval_direct(f, omega, speed, kind, H);
}

rcb_status rcb_frf_eval_direct(rcb_frf *f, double omega, double speed, rcb_frf_kind kind,
                               rcb_complex *H) {
  size_t n, i, o;
  double complex scale;
  rcb_status st;
  if (!f || !H) return RCB_ERR_ARG;
  if (f->nin == 0)
    return rcb_set_error(f->errmsg, RCB_ERR_ARG, "no input DOF: created for unbalance only");
  if (bad_speed(omega, speed))
    return rcb_set_error(f->errmsg, RCB_ERR_ARG,
                         "frequency %g rad/s and speed %g rad/s: expected finite, omega >= 0",
                         omega, speed);
  n = f->m->ndof;
  memset(f->B, 0, n * f->nin * sizeof *f->B);
  for (i = 0; i < f->nin; i++) f->B[f->in_row[i] + n * i] = 1.0;
  if ((st = rcb_frf_factor_solve(f, omega, speed, f->nin))) return st;
  switch (kind) {
    case RCB_MOBILITY: scale = CMPLX(0.0, omega); break;
    case RCB_INERTANCE: scale = -omega * omega; break;
    default: scale = 1.0; break;
  }
  for (i = 0; i < f->nin; i++)
    for (o = 0; o < f->nout; o++) H[o + f->nout * i] = scale * f->B[f->out_row[o] + n * i];
  return RCB_OK;
}

rcb_status rcb_frf_unbalance(rcb_frf *f, double speed, rcb_complex *Q) {
  size_t o;
  rcb_status st;
  if (!f || !Q) return RCB_ERR_ARG;
  if (bad_speed(speed, speed))
    return rcb_set_error(f->errmsg, RCB_ERR_ARG,
                         "speed %g rad/s: expected a finite value >= 0", speed);
  rcb_model_unbalance_force(f->m, speed, f->B);
  /* the speed factor does not apply: the speed is the measured excitation
   * frequency (G and the bearings carry the factor, so divide it out) */
  if ((st = rcb_frf_factor_solve(f, speed, speed / f->m->speed_factor, 1))) return st;
  for (o = 0; o < f->nout; o++) Q[o] = f->B[f->out_row[o]];
  return RCB_OK;
}
