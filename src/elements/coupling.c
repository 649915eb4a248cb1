/*
 * Flexible coupling between two shaft stations (Tapia & Cavalca, paper
 * section 3, eq. 1): a translational and a rotational spring, and the same
 * pair of dampers, joining station a to station b. Which coefficients a
 * model uses comes from the coupling table (model/coupling_models.c); the
 * Kramer and rigid models also tie DOFs, which finalize does by sharing
 * matrix rows (DOF elimination), so the block only carries the springs.
 */
#include <string.h>

#include "core/rcb_internal.h"

/* [k -k; -k k] with k = diag(t, t, r, r), 8x8 column-major. */
static void spring_pair(double t, double r, double blk[64]) {
  int a;
  memset(blk, 0, 64 * sizeof *blk);
  for (a = 0; a < 4; a++) {
    double v = a < 2 ? t : r;
    blk[a + 8 * a] = v;
    blk[(a + 4) + 8 * (a + 4)] = v;
    blk[a + 8 * (a + 4)] = -v;
    blk[(a + 4) + 8 * a] = -v;
  }
}

void rcb_coupling_element(rcb_coupling_model t, const rcb_coupling_params *p, double Ke[64],
                          double Ce[64]) {
  unsigned u = rcb_coupling_uses(t);
  spring_pair(u & RCB_CPL_KT ? p->kt : 0.0, u & RCB_CPL_KR ? p->kr : 0.0, Ke);
  spring_pair(u & RCB_CPL_CT ? p->ct : 0.0, u & RCB_CPL_CR ? p->cr : 0.0, Ce);
}
