/*
 * Reuse of an FRF object's last factorisation by other folders
 * (analyses/analyses.h): further right-hand sides and the adjoint solve of
 * the outputs, through the object's own solver backend.
 */
#include <string.h>

#include "analyses/analyses.h"
#include "analyses/frf_internal.h"

const rcb_layout *rcb_frf_layout(const rcb_frf *f) { return &f->L; }

size_t rcb_frf_output_row(const rcb_frf *f, size_t o) { return f->out_row[o]; }

const rcb_complex *rcb_frf_solution(const rcb_frf *f, size_t q) {
  return f->factored ? f->B + f->m->ndof * q : NULL;
}

static rcb_status resolve(rcb_frf *f, rcb_complex *B, size_t nrhs, char trans) {
  rcb_status st;
  if (!f->factored)
    return rcb_set_error(f->errmsg, RCB_ERR_STATE,
                         "no factorisation to reuse: solve the model at a point first");
  if (nrhs == 0) return RCB_OK;
  st = f->ops->resolve(&f->L, f->Z, f->ipiv, B, nrhs, trans);
  if (st)
    return rcb_set_error(f->errmsg, st, "%s solver: %s re-solve with the last factors failed",
                         f->ops->name, trans == 'T' ? "transposed" : "a");
  return RCB_OK;
}

rcb_status rcb_frf_solve_again(rcb_frf *f, rcb_complex *B, size_t nrhs) {
  if (!f || (!B && nrhs)) return RCB_ERR_ARG;
  return resolve(f, B, nrhs, 'N');
}

rcb_status rcb_frf_solve_adjoint(rcb_frf *f, rcb_complex *Y) {
  size_t n, o;
  if (!f || !Y) return RCB_ERR_ARG;
  n = f->m->ndof;
  memset(Y, 0, n * f->nout * sizeof *Y);
  for (o = 0; o < f->nout; o++) Y[f->out_row[o] + n * o] = 1.0;
  return resolve(f, Y, f->nout, 'T');
}
