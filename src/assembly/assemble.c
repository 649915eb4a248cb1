/*
 * Direct stiffness assembly (paper eq. 2): shaft elements with proportional
 * damping C = qz_m M + qz_k K, rigid disks, coupling springs/dampers and hub
 * inertia (paper eq. 1), bearings. Tied DOFs (Kramer, rigid couplings) share
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
    p.rho = mat->rho;
    p.E = mat->E;
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

/* Pedestals: mass on x and y, springs and dampers to ground (diagonal). */
static void add_pedestals(const rcb_model *m, const rcb_layout *L, double *M, double *C,
                          double *K) {
  size_t b;
  int k;
  for (b = 0; b < m->n_bearings; b++) {
    const rcb_bearing_t *br = &m->bearings[b];
    if (!br->has_ped) continue;
    for (k = 0; k < 2; k++) {
      size_t at = rcb_layout_at(L, (size_t)br->ped_dof[k], (size_t)br->ped_dof[k]);
      if (M) M[at] += br->ped_m;
      if (C) C[at] += br->ped_c[k];
      if (K) K[at] += br->ped_k[k];
    }
  }
}

/* Translational and rotational spring (or damper) between the two coupling
 * stations: [k -k; -k k] with k = diag(t, t, r, r) on [x, y, rx, ry]. */
static void coupling_block(double t, double r, double blk[64]) {
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

static void add_couplings(const rcb_model *m, const rcb_layout *L, double *M, double *C,
                          double *G, double *K) {
  double blk[64];
  long rows[8];
  size_t i;
  int k;
  for (i = 0; i < m->n_couplings; i++) {
    const rcb_coupling_t *c = &m->couplings[i];
    const rcb_coupling_params *p = &c->p;
    double kt = 0, kr = 0, ct = 0, cr = 0;
    switch (c->type) {
      case RCB_COUPLING_NELSON_CRANDALL_2:
        ct = p->ct;
        cr = p->cr;
        /* fall through */
      case RCB_COUPLING_NELSON_CRANDALL_1:
        kt = p->kt;
        kr = p->kr;
        break;
      case RCB_COUPLING_KRAMER_2:
        kr = p->kr;
        cr = p->cr;
        break;
      case RCB_COUPLING_KRAMER_1:
      case RCB_COUPLING_RIGID:
        break;
    }
    for (k = 0; k < 4; k++) {
      rows[k] = m->nodes[c->at[0].node].dof[k];
      rows[4 + k] = m->nodes[c->at[1].node].dof[k];
    }
    coupling_block(kt, kr, blk);
    scatter(L, K, rows, 8, blk, 1.0);
    coupling_block(ct, cr, blk);
    scatter(L, C, rows, 8, blk, 1.0);
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

/* The bearing force -K (q_shaft - q_ped) acts on the shaft and, reversed,
 * on the pedestal: blocks [+B -B; -B +B] on (shaft, pedestal). */
size_t rcb_bearing_entries(const rcb_model *m, size_t b, double speed,
                           rcb_entry out[RCB_BEARING_ENTRIES_MAX]) {
  const rcb_bearing_t *br = &m->bearings[b];
  const rcb_node_t *nd = &m->nodes[br->at.node];
  const long *dof[2];
  rcb_bearing_coefs c;
  const double *kv = &c.kxx, *cv = &c.cxx;
  size_t n = 0;
  int r, s, bi, bj, nb = br->has_ped ? 2 : 1;
  dof[0] = nd->dof;
  dof[1] = br->ped_dof;
  rcb_bearing_eval(br, speed * m->speed_factor, &c);
  for (bj = 0; bj < nb; bj++)
    for (bi = 0; bi < nb; bi++) {
      double sign = bi == bj ? 1.0 : -1.0;
      for (r = 0; r < 2; r++)
        for (s = 0; s < 2; s++) {
          rcb_entry *e = &out[n++];
          e->row = (size_t)dof[bi][r];
          e->col = (size_t)dof[bj][s];
          e->k = sign * kv[2 * r + s]; /* kxx kxy kyx kyy */
          e->c = sign * cv[2 * r + s];
        }
    }
  return n;
}
