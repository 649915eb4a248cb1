/*
 * Neighbouring places told apart (issue #33 item 4): a candidate that sits
 * at a node or an element (an element's stiffness or mass, an added mass or
 * inertia: DIAG_FAM_PLACE_WALK) scores much as its neighbours do, and of the
 * elements only the best scored is refitted (DIAG_FAM_ONE_REFIT), so the
 * refitted one can be the neighbour of the right one at a far larger size
 * (ROSS, shaft B element 8 at 0.6 on 8 x 151: element 7 at 0.787 "explains",
 * 5.95 % against the floor 5.77 %). When the leading candidate is
 * significant and the equivalent loads (locate.c) place the misfit at it or
 * next to it, the candidates of its kind at the neighbouring places and in
 * the placement's span are refitted too, and the data choose among them by
 * the one rule (rcb_evidence_*): the best leads, and one within
 * RCB_BIC_SIGNIFICANT of it is named as a rival the data cannot separate
 * (words.c, say_rival).
 */
#include <stdlib.h>
#include <string.h>

#include "diagnose/diag_internal.h"
#include "diagnose/tuning.h"
#include "identify/identify.h"

/* Whether e is of L's kind: its family and variant, on its shaft. */
static int same_kind(const diag_cand *L, const diag_cand *e) {
  return e->fam == L->fam && e->variant == L->variant && e->shaft == L->shaft && e->node;
}

/* Whether c sits at an element (its places are nodes node - 1 and node). */
static int at_element(const diag_cand *c) { return strncmp(c->pname[0], "shaft.", 6) == 0; }

/* Whether the placement's span holds L's place or a node next to it. */
static int placed_near(const rcb_diag *d, const diag_cand *L) {
  long n0 = (long)L->node - 1, k;
  for (k = n0 - 1; k <= n0 + 1 + at_element(L); k++)
    if (rcb_diag_node_placed(d, k, 0)) return 1;
  return 0;
}

/* The distance of e from L in places (nodes or elements along the shaft). */
static size_t places_apart(const diag_cand *L, const diag_cand *e) {
  return e->node > L->node ? e->node - L->node : L->node - e->node;
}

/* The candidates of L's kind not refitted yet at the places next to L (one
 * place either way) and, in the first round, in the placement's span,
 * nearest first, at most RCB_DIAG_NEIGHBOURS; marked to refit as L was. */
static size_t pick(rcb_diag *d, const diag_cand *L, int first, size_t *k) {
  size_t i, n = 0, dist;
  for (dist = 1; dist <= d->ncand && n < RCB_DIAG_NEIGHBOURS; dist++) {
    int any = 0;
    for (i = 0; i < d->ncand && n < RCB_DIAG_NEIGHBOURS; i++) {
      diag_cand *e = &d->cand[i];
      if (e == L || !same_kind(L, e) || places_apart(L, e) != dist) continue;
      any = 1;
      if (e->refitted || e->refit_only ||
          !(dist == 1 ||
            (first && rcb_diag_node_placed(d, (long)e->node - 1, at_element(e)))))
        continue;
      e->late = 1;
      e->from_fit = L->from_fit || !L->from_nom;
      e->from_nom = L->from_nom && d->nom_model;
      k[n++] = i;
    }
    if (!any) break; /* the shaft's end either way */
  }
  return n;
}

rcb_status rcb_diag_neighbour_refits(rcb_diag *d) {
  size_t *k, round, lead;
  rcb_status st = RCB_OK;
  const diag_cand *L;
  if (!d->ncand || !d->nplace) return RCB_OK;
  lead = d->order[0];
  L = &d->cand[lead];
  if (!L->refitted || L->claim == RCB_CLAIM_NONE || !(L->fam->flags & DIAG_FAM_PLACE_WALK) ||
      !L->node || !placed_near(d, L))
    return RCB_OK;
  if (!(k = rcb_alloc(&d->alloc, RCB_DIAG_NEIGHBOURS * sizeof *k)))
    return rcb_diag_fail(d, RCB_ERR_NOMEM, "out of memory");
  /* walk on while the lead moves to a newly refitted neighbour */
  for (round = 0; !st && round < RCB_DIAG_NEIGHBOUR_WALK; round++) {
    size_t n = pick(d, &d->cand[lead], round == 0, k), i;
    int moved = 0;
    if (!n) break;
    if ((st = rcb_diag_refit_more(d, k, n))) break;
    for (i = 0; i < n; i++) moved |= d->order[0] == k[i];
    if (!moved) break;
    lead = d->order[0];
  }
  rcb_free(&d->alloc, k);
  return st;
}
