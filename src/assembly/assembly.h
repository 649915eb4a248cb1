/*
 * Global assembly by the direct stiffness method (paper section 4, eq. 2)
 * into a storage layout chosen by the solver: dense column-major, the
 * LAPACK band layout that zgbsv factors in place, or compressed sparse
 * columns (CSC) on the model's structural pattern for KLU.
 */
#ifndef RCB_ASSEMBLY_H
#define RCB_ASSEMBLY_H

#include "core/rcb_internal.h"

typedef struct rcb_layout_s {
  int banded;          /* 0: dense n x n, 1: LAPACK band storage */
  size_t n, kl, ku, ld; /* order, sub/super-diagonals, leading dimension */
  /* CSC (sparse != 0): the rows of column j are rowi[colp[j] .. colp[j+1]-1],
   * ascending, nnz entries in all; kl = ku = the model's half-bandwidth.
   * The arrays belong to the FRF object (rcb_csc_pattern). */
  int sparse;
  int *colp, *rowi;
  size_t nnz;
  void *solver; /* backend state (KLU symbolic/numeric factors), NULL for LAPACK */
} rcb_layout;

void rcb_layout_dense(rcb_layout *L, size_t n);
/* Band layout for zgbsv: ld = 2 kl + ku + 1 (kl extra rows for fill-in). */
void rcb_layout_banded(rcb_layout *L, size_t n, size_t bandwidth);
/* Number of array entries the layout uses. */
size_t rcb_layout_size(const rcb_layout *L);

/* CSC layout on a pattern from rcb_csc_pattern (the arrays are not copied). */
void rcb_layout_csc(rcb_layout *L, size_t n, size_t bandwidth, int *colp, int *rowi);

/* Index of (i, j) in a CSC layout: binary search in column j (a handful of
 * rows); the caller guarantees (i, j) is in the pattern. */
static inline size_t rcb_csc_at(const rcb_layout *L, size_t i, size_t j) {
  size_t lo = (size_t)L->colp[j], hi = (size_t)L->colp[j + 1];
  while (hi - lo > 1) {
    size_t mid = lo + (hi - lo) / 2;
    if ((size_t)L->rowi[mid] <= i)
      lo = mid;
    else
      hi = mid;
  }
  return lo;
}

/* Array index of entry (i, j); the caller guarantees |i - j| is in the band
 * (dense, banded) or (i, j) in the pattern (sparse). */
static inline size_t rcb_layout_at(const rcb_layout *L, size_t i, size_t j) {
  if (L->sparse) return rcb_csc_at(L, i, j);
  return L->banded ? (L->kl + L->ku + i - j) + j * L->ld : i + j * L->ld;
}

/* Structural pattern of the reduced matrices (shaft elements, disks,
 * couplings with their hubs, bearings: every entry any parameter value can
 * make nonzero, so it survives rcb_model_set_param). CSC, rows ascending in
 * each column; colp has n + 1 entries. Arrays from the allocator a, freed by
 * the caller. RCB_ERR_NOMEM, or RCB_ERR_UNSUPPORTED if nnz exceeds INT_MAX
 * (KLU's int indices). */
rcb_status rcb_csc_pattern(const rcb_model *m, const rcb_allocator *a, int **colp, int **rowi,
                           size_t *nnz);

/* Speed-independent parts: M, G, and C, K of shafts (with proportional
 * damping), couplings and bearing pedestals (mass, springs and dampers to
 * ground), bearings left out. G includes the model's speed factor. Arrays of rcb_layout_size()
 * entries are overwritten; any may be NULL. */
void rcb_assemble_structure(const rcb_model *m, const rcb_layout *L, double *M, double *C,
                            double *G, double *K);

/* A bearing's contribution to one matrix entry: K(row, col) += k,
 * C(row, col) += c. */
typedef struct rcb_entry_s {
  size_t row, col;
  double k, c; /* N/m, N s/m */
} rcb_entry;

/* Most entries one bearing contributes: its 2x2 block between the shaft
 * node and ground (4), or between the shaft node and its pedestal (16). */
#define RCB_BEARING_ENTRIES_MAX 16

/* The entries of bearing b at rotor speed (rad/s; times the model's speed
 * factor): the shaft block first (x/y rows and columns of the shaft node),
 * then with a pedestal the shaft-pedestal, pedestal-shaft and pedestal
 * blocks. Returns the count (4 or 16). The pedestal's own mass, springs and
 * dampers are speed-independent and in rcb_assemble_structure. */
size_t rcb_bearing_entries(const rcb_model *m, size_t b, double speed,
                           rcb_entry out[RCB_BEARING_ENTRIES_MAX]);

#endif
