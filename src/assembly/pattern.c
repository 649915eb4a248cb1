/*
 * Structural sparsity pattern of the reduced matrices, in compressed sparse
 * columns, for the sparse (KLU) solver. Every matrix term the assembly can
 * write couples the DOFs of one node or of two nodes (a shaft element's two
 * ends, a coupling's two stations), so the pattern is the union of full
 * node blocks: 8 x 8 for elements and couplings, 4 x 4 for disks and
 * bearings (and a bearing's shaft x, y with its pedestal's x, y), plus the
 * diagonal. Full blocks (not the current nonzeros) keep
 * the pattern valid when rcb_model_set_param turns a zero coefficient on.
 */
#include <limits.h>
#include <string.h>

#include "assembly/assembly.h"

typedef struct pat_s {
  size_t *cnt;  /* per column: entries written so far */
  size_t *base; /* per column: first slot (upper bound layout) */
  int *rows;    /* slots */
} pat;

/* Add the nd DOFs d as a full block. */
static void dof_block(pat *p, const long *d, int nd, int count_only) {
  int r, c;
  for (c = 0; c < nd; c++) {
    size_t col = (size_t)d[c];
    if (count_only) {
      p->cnt[col] += (size_t)nd;
      continue;
    }
    for (r = 0; r < nd; r++) p->rows[p->base[col] + p->cnt[col]++] = (int)d[r];
  }
}

/* Add the DOFs of nodes a and b (b may equal a) as a full block. */
static void node_block(const rcb_model *m, pat *p, size_t a, size_t b, int count_only) {
  long d[8];
  int k;
  for (k = 0; k < 4; k++) {
    d[k] = m->nodes[a].dof[k];
    d[4 + k] = m->nodes[b].dof[k];
  }
  dof_block(p, d, a == b ? 4 : 8, count_only);
}

/* A bearing on a pedestal: shaft x, y and pedestal x, y as one block. */
static void pedestal_block(const rcb_model *m, pat *p, const rcb_bearing_t *b, int count_only) {
  long d[4];
  d[0] = m->nodes[b->at.node].dof[0];
  d[1] = m->nodes[b->at.node].dof[1];
  d[2] = b->ped_dof[0];
  d[3] = b->ped_dof[1];
  dof_block(p, d, 4, count_only);
}

static void all_blocks(const rcb_model *m, pat *p, int count_only) {
  size_t i;
  for (i = 0; i < m->n_elements; i++)
    node_block(m, p, m->elements[i].node0, m->elements[i].node0 + 1, count_only);
  for (i = 0; i < m->n_couplings; i++)
    node_block(m, p, m->couplings[i].at[0].node, m->couplings[i].at[1].node, count_only);
  for (i = 0; i < m->n_disks; i++) node_block(m, p, m->disks[i].at.node, m->disks[i].at.node,
                                               count_only);
  for (i = 0; i < m->n_bearings; i++) {
    node_block(m, p, m->bearings[i].at.node, m->bearings[i].at.node, count_only);
    if (m->bearings[i].has_ped) pedestal_block(m, p, &m->bearings[i], count_only);
  }
}

static void sort_unique(int *v, size_t *len) {
  size_t i, j, k = 0;
  for (i = 1; i < *len; i++) {
    int x = v[i];
    for (j = i; j > 0 && v[j - 1] > x; j--) v[j] = v[j - 1];
    v[j] = x;
  }
  for (i = 0; i < *len; i++)
    if (k == 0 || v[i] != v[k - 1]) v[k++] = v[i];
  *len = k;
}

rcb_status rcb_csc_pattern(const rcb_model *m, const rcb_allocator *a, int **colp, int **rowi,
                           size_t *nnz) {
  size_t n = m->ndof, j, total = 0, out = 0;
  pat p;
  rcb_status st = RCB_OK;
  *colp = NULL;
  *rowi = NULL;
  *nnz = 0;
  if (n >= (size_t)INT_MAX) return RCB_ERR_UNSUPPORTED;
  p.cnt = rcb_alloc(a, n * sizeof *p.cnt);
  p.base = rcb_alloc(a, (n + 1) * sizeof *p.base);
  p.rows = NULL;
  if (!p.cnt || !p.base) goto nomem;
  for (j = 0; j < n; j++) p.cnt[j] = 1; /* the diagonal */
  all_blocks(m, &p, 1);
  for (j = 0; j < n; j++) {
    p.base[j] = total;
    total += p.cnt[j];
  }
  p.base[n] = total;
  p.rows = rcb_alloc(a, (total ? total : 1) * sizeof *p.rows);
  if (!p.rows) goto nomem;
  for (j = 0; j < n; j++) {
    p.rows[p.base[j]] = (int)j;
    p.cnt[j] = 1;
  }
  all_blocks(m, &p, 0);
  /* Sort and compact column by column, in place (out <= base[j]). */
  for (j = 0; j < n; j++) {
    size_t len = p.cnt[j];
    sort_unique(p.rows + p.base[j], &len);
    memmove(p.rows + out, p.rows + p.base[j], len * sizeof *p.rows);
    p.base[j] = out;
    out += len;
  }
  p.base[n] = out;
  if (out > (size_t)INT_MAX) {
    st = RCB_ERR_UNSUPPORTED;
    goto done;
  }
  *colp = rcb_alloc(a, (n + 1) * sizeof **colp);
  *rowi = rcb_alloc(a, (out ? out : 1) * sizeof **rowi);
  if (!*colp || !*rowi) goto nomem;
  for (j = 0; j <= n; j++) (*colp)[j] = (int)p.base[j];
  memcpy(*rowi, p.rows, out * sizeof **rowi);
  *nnz = out;
  goto done;
nomem:
  st = RCB_ERR_NOMEM;
done:
  if (st) {
    rcb_free(a, *colp);
    rcb_free(a, *rowi);
    *colp = NULL;
    *rowi = NULL;
  }
  rcb_free(a, p.cnt);
  rcb_free(a, p.base);
  rcb_free(a, p.rows);
  return st;
}

void rcb_layout_csc(rcb_layout *L, size_t n, size_t bandwidth, int *colp, int *rowi) {
  memset(L, 0, sizeof *L);
  L->sparse = 1;
  L->n = n;
  L->kl = L->ku = bandwidth;
  L->ld = n;
  L->colp = colp;
  L->rowi = rowi;
  L->nnz = n ? (size_t)colp[n] : 0;
}
