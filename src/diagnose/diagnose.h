/*
 * The internal interface of diagnose/ that other folders may use (the
 * monitor, issue #16): the catalogue of candidate effects of a model
 * without running a diagnosis, each candidate's model at its neutral value
 * (clone, edit, finalise, set parameters, as the diagnosis builds them),
 * and the score test's LAPACK QR of the columns already explained. The
 * diagnosis object's fields (diag_internal.h) stay private to diagnose/.
 * Not installed.
 */
#ifndef RCB_DIAGNOSE_INTERNAL_API_H
#define RCB_DIAGNOSE_INTERNAL_API_H

#include "core/rcb_internal.h"

#define RCB_DIAG_MAXP 3

/* Lay out every candidate effect of the (fitted, finalized) model m on a
 * diagnosis d that has not run (rcb_diag_create, then
 * rcb_diag_add_fitted_param for the parameters that are not candidates;
 * d's measurement decides the operating-speed candidate). */
rcb_status rcb_diag_catalogue(rcb_diag *d, const rcb_model *m);

/* Candidate i of the catalogue (strings owned by d). */
typedef struct rcb_diag_cand_desc {
  rcb_effect effect;
  const char *place, *desc, *params;
  size_t np;
  const char *pname[RCB_DIAG_MAXP]; /* parameter names */
  double lo[RCB_DIAG_MAXP], hi[RCB_DIAG_MAXP]; /* bounds, parameter units */
  int logp[RCB_DIAG_MAXP];
  int refit_only; /* no neutral value (another coupling model): not scored */
  int adds_dofs;  /* its model has DOFs the base model lacks (a pedestal) */
  int chain;      /* it edits the measurement chain (a sensor), not the model */
  const char *swap_a, *swap_b; /* a swap of two probes (RCB_EFFECT_SENSOR_SWAP): their
                                  measured responses (rcb_fit_swap_sensors); else NULL */
} rcb_diag_cand_desc;
size_t rcb_diag_catalogue_count(const rcb_diag *d);
rcb_status rcb_diag_catalogue_get(const rcb_diag *d, size_t i, rcb_diag_cand_desc *out);
/* Candidate i's model: a finalized copy of from (allocator of d) with the
 * candidate's edit and starting values (caller destroys). */
rcb_status rcb_diag_catalogue_model(rcb_diag *d, size_t i, const rcb_model *from,
                                    rcb_model **out);

/* The score test (score_qr.c): the fitted parameters' columns J0 (n x nb,
 * d r / d p) factored once by LAPACK QR with the weighted residual r
 * projected on it, then per candidate the reduction of F = r^T r its
 * columns J (n x np, np <= RCB_DIAG_MAXP, overwritten) can explain beyond
 * J0: || Q_c^T r ||^2, Q_c orthonormal on the part of span(J) orthogonal to
 * span(J0). Columns within 1e-10 (relative) of the span of those before
 * them are dropped. */
typedef struct diag_basis {
  size_t n, rank;     /* residuals; columns of J0 kept */
  double *qr, *tau;   /* Householder QR of J0's kept unit columns (dgeqrf layout) */
  double *rt;         /* Q0^T r, n */
  double *r2, *tau_c; /* a candidate's: its part of rt, its reflectors' scalars */
  double *work;       /* LAPACK work, lwork (enough for dormqr on nb columns) */
  size_t lwork;
} diag_basis;
rcb_status rcb_diag_basis_init(rcb_diag *d, diag_basis *b, const double *J0, size_t n,
                               size_t nb, const double *r);
rcb_status rcb_diag_explained(rcb_diag *d, diag_basis *b, double *J, size_t np, double *pred);
void rcb_diag_basis_free(rcb_diag *d, diag_basis *b);

#endif /* RCB_DIAGNOSE_INTERNAL_API_H */
