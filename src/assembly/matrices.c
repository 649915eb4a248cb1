/* Public access to the assembled matrices and the unbalance force vector. */
#include <math.h>
#include <string.h>

#include "assembly/assembly.h"

rcb_status rcb_model_matrices(const rcb_model *m, double speed, double *M, double *C, double *G,
                              double *K) {
  rcb_layout L;
  rcb_entry e[RCB_BEARING_ENTRIES_MAX];
  size_t b, k, ne;
  if (!m || !isfinite(speed)) return RCB_ERR_ARG;
  if (!m->finalized) return RCB_ERR_STATE;
  rcb_layout_dense(&L, m->ndof);
  rcb_assemble_structure(m, &L, M, C, G, K);
  for (b = 0; b < m->n_bearings; b++) {
    ne = rcb_bearing_entries(m, b, speed, e);
    for (k = 0; k < ne; k++) {
      if (K) K[rcb_layout_at(&L, e[k].row, e[k].col)] += e[k].k;
      if (C) C[rcb_layout_at(&L, e[k].row, e[k].col)] += e[k].c;
    }
  }
  return RCB_OK;
}

rcb_status rcb_model_unbalance_force(const rcb_model *m, double speed, rcb_complex *F) {
  size_t i;
  if (!m || !F || !isfinite(speed)) return RCB_ERR_ARG;
  if (!m->finalized) return RCB_ERR_STATE;
  memset(F, 0, m->ndof * sizeof *F);
  for (i = 0; i < m->n_unbalances; i++) {
    const rcb_unbalance_t *u = &m->unbalances[i];
    const rcb_node_t *nd = &m->nodes[u->at.node];
    /* f_x = me W^2 cos(W t + phase), f_y = me W^2 sin(W t + phase) */
    double complex fx = u->amount * speed * speed * cexp(RCB_J * u->phase);
    F[nd->dof[0]] += fx;
    F[nd->dof[1]] += -RCB_J * fx;
  }
  return RCB_OK;
}
