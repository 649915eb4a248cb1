/*
 * Direct stiffness assembly (paper eq. 2): shaft elements with proportional
 * damping C = qz_m M + qz_k K, rigid disks, coupling springs/dampers and hub
 * inertia (paper eq. 1), bearings, each block from src/elements/: this file
 * only scatters. Tied DOFs (Kramer, rigid couplings) share
 * a matrix row, so adding into the shared row is the constraint elimination
 * q_full = T q with T a 0/1 selection: M_r = T^T M T.
 */
#include <string.h>

#include "assembly/assembly.h"

void rcb_layout_dense(rcb_layout *L, size_t n) {
  memset(L, 0, sizeof *L);
  L->banded = 0;
  L->n = n;
  L->kl = L->ku = n ? n - 1 : 0;
  L->ld = n;
}

void rcb_layout_banded(rcb_layout *L, size_t n, size_t bandwidth) {
  memset(L, 0, sizeof *L);
  L->banded = 1;
  L->n = n;
  L->kl = L->ku = bandwidth;
  L->ld = 2 * bandwidth + bandwidth + 1;
}

size_t rcb_layout_size(const rcb_layout *L) { return L->sparse ? L->nnz : L->ld * L->n; }

/* Add an nd x nd column-major block, scaled by f, on the given matrix rows. */
static void scatter(const rcb_layout *L, double *A, const long *rows, int nd, const double *blk,
                    double f) {
  int a, b;
  if (!A || f == 0.0) return;
  for (b = 0; b < nd; b++)
    for (a = 0; a < nd; a++) {
      double v = blk[a + nd * b];
      if (v != 0.0) A[rcb_layout_at(L, (size_t)rows[a], (size_t)rows[b])] += f * v;
    }
}

static void add_shafts(const rcb_model *m, const rcb_layout *L, double *M, double *C, double *G,
                       double *K) {
  double Me[64], Ge[64], Ke[64];
  long rows[8];
  size_t e;
  int k;
  for (e = 0; e < m->n_elements; e++) {
    const rcb_element_t *el = &m->elements[e];
    const rcb_shaft_t *sh = &m->shafts[el->shaft];
    const rcb_material_t *mat = &m->materials[sh->material];
    rcb_beam_props p;
    p.L = el->L;
    p.od = el->od;
    p.id = el->id;
    /* the element's factors (issue #23) and the shaft's (issue #33): E and G
     * together, so phi and the shape of Ke stay; rho scales M and G alike */
    p.rho = mat->rho * sh->sf[1] * (el->k < sh->nef ? sh->ef[2 * el->k + 1] : 1.0);
    p.E = mat->E * sh->sf[0] * (el->k < sh->nef ? sh->ef[2 * el->k] : 1.0);
    p.nu = mat->nu;
    p.kappa = sh->kappa;
    rcb_shaft_element(&p, Me, Ge, Ke);
    for (k = 0; k < 4; k++) {
      rows[k] = m->nodes[el->node0].dof[k];
      rows[4 + k] = m->nodes[el->node0 + 1].dof[k];
    }
    scatter(L, M, rows, 8, Me, 1.0);
    scatter(L, G, rows, 8, Ge, m->speed_factor);
    scatter(L, K, rows, 8, Ke, 1.0);
    scatter(L, C, rows, 8, Me, sh->qz_m);
    scatter(L, C, rows, 8, Ke, sh->qz_k);
  }
}

static void add_disk(const rcb_model *m, const rcb_layout *L, size_t node, double mass,
                     double Id, double Ip, double *M, double *G) {
  double Md[16], Gd[16];
  rcb_disk_element(mass, Id, Ip, Md, Gd);
  scatter(L, M, m->nodes[node].dof, 4, Md, 1.0);
  scatter(L, G, m->nodes[node].dof, 4, Gd, m->speed_factor);
}

/* Pedestals: mass on x and y, springs and dampers to ground. */
static void add_pedestals(const rcb_model *m, const rcb_layout *L, double *M, double *C,
                          double *K) {
  double Mp[4], Cp[4], Kp[4];
  size_t b;
  for (b = 0; b < m->n_bearings; b++) {
    const rcb_bearing_t *br = &m->bearings[b];
    if (!br->has_ped) continue;
    rcb_pedestal_element(br->ped_m, br->ped_k, br->ped_c, Mp, Cp, Kp);
    scatter(L, M, br->ped_dof, 2, Mp, 1.0);
    scatter(L, C, br->ped_dof, 2, Cp, 1.0);
    scatter(L, K, br->ped_dof, 2, Kp, 1.0);
  }
}

static void add_couplings(const rcb_model *m, const rcb_layout *L, double *M, double *C,
                          double *G, double *K) {
  double Ke[64], Ce[64];
  long rows[8];
  size_t i;
  int k;
  for (i = 0; i < m->n_couplings; i++) {
    const rcb_coupling_t *c = &m->couplings[i];
    const rcb_coupling_params *p = &c->p;
    for (k = 0; k < 4; k++) {
      rows[k] = m->nodes[c->at[0].node].dof[k];
      rows[4 + k] = m->nodes[c->at[1].node].dof[k];
    }
    rcb_coupling_element(c->type, p, Ke, Ce);
    scatter(L, K, rows, 8, Ke, 1.0);
    scatter(L, C, rows, 8, Ce, 1.0);
    for (k = 0; k < 2; k++)
      add_disk(m, L, c->at[k].node, p->mass[k], p->Id[k], p->Ip[k], M, G);
  }
}

void rcb_assemble_structure(const rcb_model *m, const rcb_layout *L, double *M, double *C,
                            double *G, double *K) {
  size_t sz = rcb_layout_size(L), i;
  if (M) memset(M, 0, sz * sizeof *M);
  if (C) memset(C, 0, sz * sizeof *C);
  if (G) memset(G, 0, sz * sizeof *G);
  if (K) memset(K, 0, sz * sizeof *K);
  add_shafts(m, L, M, C, G, K);
  for (i = 0; i < m->n_disks; i++)
    add_disk(m, L, m->disks[i].at.node, m->disks[i].m, m->disks[i].Id, m->disks[i].Ip, M, G);
  add_couplings(m, L, M, C, G, K);
  add_pedestals(m, L, M, C, K);
}

/* The bearing block (elements/bearing.c) on the shaft node's x, y rows and,
 * with a pedestal, the pedestal's. */
size_t rcb_bearing_entries(const rcb_model *m, size_t b, double speed,
                           rcb_entry out[RCB_BEARING_ENTRIES_MAX]) {
  const rcb_bearing_t *br = &m->bearings[b];
  const long *dof[2];
  rcb_bearing_coefs c;
  double Kb[16], Cb[16];
  size_t n = 0;
  int r, s, bi, bj, nd;
  dof[0] = m->nodes[br->at.node].dof;
  dof[1] = br->ped_dof;
  rcb_bearing_eval(br, speed * m->speed_factor, &c);
  nd = rcb_bearing_element(&c, br->has_ped, Kb, Cb);
  for (bj = 0; bj < nd / 2; bj++)
    for (bi = 0; bi < nd / 2; bi++)
      for (r = 0; r < 2; r++)
        for (s = 0; s < 2; s++) {
          rcb_entry *e = &out[n++];
          int at = (2 * bi + r) + nd * (2 * bj + s);
          e->row = (size_t)dof[bi][r];
          e->col = (size_t)dof[bj][s];
          e->k = Kb[at];
          e->c = Cb[at];
        }
  return n;
}
