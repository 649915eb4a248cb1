/*
 * The added-mass family (issue #4): a mass and a diametral inertia at every
 * node, on its disk where it has one (the disk's own values), else on a new
 * massless disk there (neutral value 0); at a disk also both together (a
 * ring or a balancing collar added to it, with its polar inertia, issue
 * #33: named as mass alone before). Its candidates sit at the nodes of a shaft (node, shaft, variant
 * 0: mass, 1: inertia, 2: both), where the run-off path walks along the
 * shaft (DIAG_FAM_PLACE_WALK).
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "diagnose/diag_internal.h"

/* What an added part can be (issue #33), against the model's own disks: at
 * a disk, at most RCB_MASS_AT_DISK times its own mass, Id and Ip (a ring or
 * collar of up to 3 x the disk's own; the 0.5 kg ring of the tests takes
 * its Id to 2.1 x and Ip to 2.2 x); at a bare node, at most RCB_MASS_AT_NODE
 * times the largest disk's (a part heavier than any disk on the shaft is a
 * stand-in for another effect: a section error along a shaft was named "an
 * added diametral inertia" 5 x the disk's own). Fitted values beyond are
 * said so, and the candidate never "explains" (rcb_evidence.beyond). */
#define RCB_MASS_AT_DISK 4.0
#define RCB_MASS_AT_NODE 2.0
/* A ring's refit bounds below and what it can be (issue #33): with the
 * three free from 1e-4 of the disk's own, a ring at DB took the place of a
 * cross-coupled B2 beside 0.35 kg there (Id 1e-4 x the disk's, Ip 1.8 x: the
 * gyroscopic split standing in for kxy), and ended near the floor. */
#define RCB_RING_LO 0.5
#define RCB_RING_PLAUSIBLE 0.9

/* A mass at every disk, and a new (massless) disk at every other node. */
static rcb_status enumerate(rcb_diag *d, const rcb_model *m) {
  double mtot = 0.0, mmax = 0.0, idmax = 0.0;
  size_t i, k;
  for (i = 0; i < m->n_disks; i++) {
    mtot += m->disks[i].m;
    mmax = fmax(mmax, m->disks[i].m), idmax = fmax(idmax, m->disks[i].Id);
  }
  if (mtot <= 0) mtot = 1.0;
  for (i = 0; i < m->n_nodes; i++) {
    const rcb_node_t *nd = &m->nodes[i];
    const rcb_disk_t *disk = NULL;
    char place[RCB_DIAG_NAME];
    diag_cand *c;
    for (k = 0; k < m->n_disks; k++)
      if (m->disks[k].at.node == i) disk = &m->disks[k];
    if (disk)
      snprintf(place, sizeof place, "disk %s", disk->name);
    else
      snprintf(place, sizeof place, "node #%zu (shaft %s, z = %g m)", i,
               m->shafts[nd->shaft].name, nd->z);
    for (k = 0; k < (disk ? 3u : 2u); k++) { /* a mass, a diametral inertia, both */
      if (!(c = rcb_diag_new_cand(d, &rcb_diag_family_mass, RCB_EFFECT_ADDED_MASS, place))) return RCB_ERR_NOMEM;
      snprintf(c->desc, sizeof c->desc, "an added %s at %s",
               k == 2 ? "mass with its diametral and polar inertia (a ring)"
                      : k ? "diametral inertia" : "mass",
               place);
      c->node = i + 1;
      c->variant = (int)k;
      c->shaft = nd->shaft;
      if (disk) {
        double lo, hi;
        int logp;
        if (k != 1) {
          rcb_diag_bounds(disk->m, 10 * mtot, &lo, &hi, &logp);
          rcb_diag_add_par(c, "disk.%s.mass", disk->name, lo, hi, logp);
          if (disk->m > 0) c->phi[c->np - 1] = fmin(hi, RCB_MASS_AT_DISK * disk->m);
        }
        if (k != 0) {
          rcb_diag_bounds(disk->Id, 0.01 * mtot, &lo, &hi, &logp);
          rcb_diag_add_par(c, "disk.%s.Id", disk->name, lo, hi, logp);
          if (disk->Id > 0) c->phi[c->np - 1] = fmin(hi, RCB_MASS_AT_DISK * disk->Id);
        }
        if (k == 2) { /* a ring turns with the disk: its polar inertia too */
          size_t j;
          const double own[3] = {disk->m, disk->Id, disk->Ip};
          rcb_diag_bounds(disk->Ip, 0.02 * mtot, &lo, &hi, &logp);
          rcb_diag_add_par(c, "disk.%s.Ip", disk->name, lo, hi, logp);
          if (disk->Ip > 0) c->phi[c->np - 1] = fmin(hi, RCB_MASS_AT_DISK * disk->Ip);
          /* a ring adds to the disk: none of the three below the disk's own
           * (RCB_RING_LO of it to fit, RCB_RING_PLAUSIBLE of it to explain) */
          for (j = 0; j < 3; j++)
            if (own[j] > 0) {
              c->lo[j] = RCB_RING_LO * own[j], c->plo[j] = RCB_RING_PLAUSIBLE * own[j];
              c->lo_own[j] = RCB_RING_LO; /* of the own value where each fit starts */
            }
        }
        continue;
      }
      c->new_disk = 1;
      snprintf(c->target, sizeof c->target, "ADDED_%zu", i);
      snprintf(c->at, sizeof c->at, "#%zu", i);
      rcb_diag_add_par(c, k ? "disk.%s.Id" : "disk.%s.mass", c->target, 0.0, k ? 0.01 * mtot : mtot,
              0);
      if ((k ? idmax : mmax) > 0)
        c->phi[0] = fmin(c->phi[0], RCB_MASS_AT_NODE * (k ? idmax : mmax));
    }
  }
  return RCB_OK;
}


/* A new (massless) disk at the candidate's node, on the unfinalized copy m. */
static rcb_status edit(const diag_cand *c, rcb_model *m) {
  return c->new_disk ? rcb_model_add_disk_at(m, c->target, c->at, 0, 0, 0) : RCB_OK;
}

const diag_family rcb_diag_family_mass = {"mass", DIAG_FAM_PLACE_WALK, enumerate, edit, NULL,
                                          NULL, NULL};
