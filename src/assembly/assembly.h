/*
 * Global assembly by the direct stiffness method (paper section 4, eq. 2)
 * into a storage layout chosen by the solver: dense column-major, or the
 * LAPACK band layout that zgbsv factors in place.
 */
#ifndef RCB_ASSEMBLY_H
#define RCB_ASSEMBLY_H

#include "core/rcb_internal.h"

typedef struct rcb_layout_s {
  int banded;          /* 0: dense n x n, 1: LAPACK band storage */
  size_t n, kl, ku, ld; /* order, sub/super-diagonals, leading dimension */
} rcb_layout;

void rcb_layout_dense(rcb_layout *L, size_t n);
/* Band layout for zgbsv: ld = 2 kl + ku + 1 (kl extra rows for fill-in). */
void rcb_layout_banded(rcb_layout *L, size_t n, size_t bandwidth);
/* Number of array entries the layout uses. */
size_t rcb_layout_size(const rcb_layout *L);

/* Array index of entry (i, j); the caller guarantees |i - j| is in the band. */
static inline size_t rcb_layout_at(const rcb_layout *L, size_t i, size_t j) {
  return L->banded ? (L->kl + L->ku + i - j) + j * L->ld : i + j * L->ld;
}

/* Speed-independent parts: M, G, and C, K of shafts (with proportional
 * damping) and couplings, bearings left out. Arrays of rcb_layout_size()
 * entries are overwritten; any may be NULL. */
void rcb_assemble_structure(const rcb_model *m, const rcb_layout *L, double *M, double *C,
                            double *G, double *K);

/* A bearing's contribution to one matrix entry: K(row, col) += k,
 * C(row, col) += c. */
typedef struct rcb_entry_s {
  size_t row, col;
  double k, c; /* N/m, N s/m */
} rcb_entry;

/* The 4 entries (x/y rows and columns) of bearing b at rotor speed (rad/s). */
void rcb_bearing_entries(const rcb_model *m, size_t b, double speed, rcb_entry out[4]);

#endif
