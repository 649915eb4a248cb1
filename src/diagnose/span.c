/*
 * A change of section or material along part of a shaft (issue #33 item 4):
 * a factor on E and G (or on the density) of a contiguous run of elements,
 * shaft.S.e<a>-<b>.stiffness | mass (model/element_params.c). A shaft of n
 * elements holds n (n + 1) / 2 spans; laid out in the catalogue they would
 * multiply its size (the paper system: 110 spans against 129 candidates).
 * So no span is scored: when the data point to a shaft's stiffness or mass
 * (a significant candidate of one element, or of the whole shaft, among the
 * first ranks) and nothing explains them, the span is searched for: from the
 * run of elements the equivalent loads place the misfit on (locate.c), and
 * from the leading candidate's own (its element, or the whole shaft), each
 * end moved by one element while the objective falls, every span fitted
 * alone (its factor, the base parameters where they are) on the frequency
 * subset. The best span, and those one element from it whose search
 * objective is within RCB_DIAG_POLISH_WITHIN of its own, are then refitted
 * as candidates (rank.c, rcb_diag_refit_more), so the data choose among
 * them, the elements and the whole shaft by the one rule. The spans fitted
 * in the search count among the candidates tried (d->span_tried).
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "diagnose/diag_internal.h"
#include "diagnose/tuning.h"
#include "identify/identify.h"

/* Bounds of a span's factor: a section or material error (as the whole
 * shaft's, family_shaft.c), log scale. */
#define SPAN_FACTOR_LO 0.3
#define SPAN_FACTOR_HI 3.0

/* The search of one shaft and variant: its elements 1 .. ne, the first node
 * node0, the objective of every span tried (F[(a - 1) * ne + b - 1], NAN: not
 * tried) and its fitted factor, on the frequency subset w. */
typedef struct span_search {
  size_t shaft, ne, node0;
  int variant;
  double *F, *v;
  const double *w;
  const rcb_model *from;
  size_t tried;
} span_search;

/* The span's parameter name, its place and description (c: a candidate not
 * in d->cand, or one just made by rcb_diag_new_cand). */
static void span_fill(const rcb_diag *d, const span_search *s, size_t a, size_t b,
                      diag_cand *c) {
  const rcb_model *m = d->base_model;
  const rcb_shaft_t *sh = &m->shafts[s->shaft];
  double z0 = m->nodes[s->node0 + a - 1].z, z1 = m->nodes[s->node0 + b].z;
  char item[RCB_NAME_MAX + 48];
  snprintf(c->place, sizeof c->place, "shaft %s elements %zu-%zu (z = %.3f-%.3f m)", sh->name,
           a, b, z0, z1);
  snprintf(c->desc, sizeof c->desc,
           "a change of section or material along shaft %s between z = %.3f and %.3f m "
           "(elements %zu-%zu; its %s)",
           sh->name, z0, z1, a, b, s->variant ? "mass" : "bending stiffness");
  c->fam = &rcb_diag_family_shaft;
  c->effect = s->variant ? RCB_EFFECT_SHAFT_MASS : RCB_EFFECT_SHAFT_STIFFNESS;
  c->variant = s->variant;
  c->shaft = s->shaft;
  c->refit_only = 1; /* not scored: searched for */
  c->late = 1;
  c->np = 0, c->params[0] = '\0';
  snprintf(item, sizeof item, "%s.e%zu-%zu", sh->name, a, b);
  rcb_diag_add_par(c, s->variant ? "shaft.%s.mass" : "shaft.%s.stiffness", item,
                   SPAN_FACTOR_LO, SPAN_FACTOR_HI, 1);
}

/* The objective on the subset of span a-b fitted alone (the base
 * parameters where s->from has them), from factor v0; cached. */
static rcb_status span_eval(rcb_diag *d, span_search *s, size_t a, size_t b, double v0,
                            double *F) {
  size_t at = (a - 1) * s->ne + b - 1;
  diag_cand c;
  rcb_model *m = NULL;
  rcb_fit *f = NULL;
  rcb_fit_report rep;
  rcb_status st;
  *F = s->F[at];
  if (!isnan(*F)) return RCB_OK;
  memset(&c, 0, sizeof c);
  memset(&rep, 0, sizeof rep);
  span_fill(d, s, a, b, &c);
  s->tried++;
  st = rcb_diag_candidate_model(d, &c, s->from, &m);
  if (!st) st = rcb_model_set_param(m, c.pname[0], v0);
  if (!st) st = rcb_diag_make_fit(d, m, 0, &c, &f);
  if (!st) st = rcb_fit_set_starts(f, 1, 1);
  if (!st) { /* a few iterations, on the subset or (small sets) on all points */
    size_t it;
    double ftol, xtol;
    st = rcb_fit_get_limits(f, &it, &ftol, &xtol);
    if (!st) st = rcb_fit_set_limits(f, RCB_DIAG_SPAN_ITER, ftol, xtol);
  }
  if (!st) st = rcb_diag_screen(f, s->w, RCB_DIAG_SPAN_ITER);
  if (!st) st = rcb_fit_get_report(f, &rep);
  if (!st) {
    s->F[at] = *F = rep.objective;
    rcb_model_get_param(m, c.pname[0], &s->v[at]);
  }
  if (f) rcb_diag_drop_fit(d, f);
  rcb_model_destroy(m);
  if (st == RCB_ERR_NOMEM) return rcb_diag_fail(d, st, "out of memory");
  if (st) s->F[at] = *F = HUGE_VAL; /* a span that cannot be fitted is not chosen */
  return RCB_OK;
}

/* From span *a-*b, move one end by one element while the objective falls
 * (at most RCB_DIAG_SPAN_STEPS moves); *a, *b: where it ended. */
static rcb_status span_walk(rcb_diag *d, span_search *s, size_t *a, size_t *b, double v0) {
  double Fc, Fm;
  size_t step;
  rcb_status st = span_eval(d, s, *a, *b, v0, &Fc);
  for (step = 0; !st && step < RCB_DIAG_SPAN_STEPS; step++) {
    const long mv[4][2] = {{-1, 0}, {1, 0}, {0, -1}, {0, 1}};
    size_t k, ba = *a, bb = *b;
    double best = Fc, vc = s->v[(*a - 1) * s->ne + *b - 1];
    for (k = 0; !st && k < 4; k++) {
      long na = (long)*a + mv[k][0], nb = (long)*b + mv[k][1];
      if (na < 1 || nb > (long)s->ne || na > nb) continue;
      st = span_eval(d, s, (size_t)na, (size_t)nb, vc, &Fm);
      if (!st && Fm < best) best = Fm, ba = (size_t)na, bb = (size_t)nb;
    }
    if (st || (ba == *a && bb == *b)) break;
    *a = ba, *b = bb, Fc = best;
  }
  return st;
}

/* The parameter of span a-b: an element's (a = b), the whole shaft's
 * (1 to ne), else the span's. */
static void span_name(const rcb_diag *d, const span_search *s, size_t a, size_t b, char *buf,
                      size_t size) {
  const char *sh = d->base_model->shafts[s->shaft].name, *key = s->variant ? "mass" : "stiffness";
  if (a == b) snprintf(buf, size, "shaft.%s.e%zu.%s", sh, a, key);
  else if (a == 1 && b == s->ne) snprintf(buf, size, "shaft.%s.%s", sh, key);
  else snprintf(buf, size, "shaft.%s.e%zu-%zu.%s", sh, a, b, key);
}

/* The candidate of span a-b, its index in *k: an element's or the whole
 * shaft's from the catalogue, a span's made before, else a new one. */
static rcb_status span_cand(rcb_diag *d, const span_search *s, size_t a, size_t b, size_t *k) {
  char name[RCB_DIAG_NAME];
  diag_cand *c;
  size_t i;
  span_name(d, s, a, b, name, sizeof name);
  for (i = 0; i < d->ncand; i++)
    if (d->cand[i].np == 1 && strcmp(d->cand[i].pname[0], name) == 0) {
      *k = i;
      return RCB_OK;
    }
  if (!(c = rcb_diag_new_cand(d, &rcb_diag_family_shaft, RCB_EFFECT_SHAFT_STIFFNESS, "")))
    return rcb_diag_fail(d, RCB_ERR_NOMEM, "out of memory");
  span_fill(d, s, a, b, c);
  *k = d->ncand - 1;
  return RCB_OK;
}

/* The leading candidate of a shaft's stiffness or mass: significant, among
 * the first RCB_DIAG_SPAN_RANKS ranks, of one element or of the whole shaft;
 * NULL when none, or when a candidate explains the data. */
static const diag_cand *shaft_lead(const rcb_diag *d) {
  size_t k;
  if (!d->ncand || d->cand[d->order[0]].claim == RCB_CLAIM_EXPLAINS) return NULL;
  for (k = 0; k < d->ncand && k < RCB_DIAG_SPAN_RANKS; k++) {
    const diag_cand *c = &d->cand[d->order[k]];
    if (!c->refitted || c->claim == RCB_CLAIM_NONE) continue;
    if (c->effect == RCB_EFFECT_ELEMENT_STIFFNESS || c->effect == RCB_EFFECT_ELEMENT_MASS ||
        c->effect == RCB_EFFECT_SHAFT_STIFFNESS || c->effect == RCB_EFFECT_SHAFT_MASS)
      return c;
  }
  return NULL;
}

/* The run of elements of shaft s the placement's span covers (the elements
 * between its first and last node there): 1 when found. */
static int placed_run(const rcb_diag *d, const span_search *s, size_t *a, size_t *b) {
  size_t k, lo = (size_t)-1, hi = 0;
  for (k = 0; k < d->nplace; k++) {
    size_t n = d->place[k].node;
    if (!d->place[k].in_span || n < s->node0 || n > s->node0 + s->ne) continue;
    if (n < lo) lo = n;
    if (n > hi) hi = n;
  }
  if (lo == (size_t)-1) return 0;
  if (hi == lo) hi = lo < s->node0 + s->ne ? lo + 1 : lo, lo = hi - 1; /* one node: its element */
  *a = lo - s->node0 + 1, *b = hi - s->node0;
  return 1;
}

rcb_status rcb_diag_span_refits(rcb_diag *d) {
  const diag_cand *L = shaft_lead(d);
  const rcb_model *m = d->base_model;
  span_search s;
  size_t a, b, a2, b2, e, k[5], n = 0, i;
  double F1, F2, v0;
  rcb_status st;
  if (!L) return RCB_OK;
  memset(&s, 0, sizeof s);
  s.variant = L->effect == RCB_EFFECT_ELEMENT_MASS || L->effect == RCB_EFFECT_SHAFT_MASS;
  s.shaft = L->shaft;
  for (e = 0; e < m->n_elements; e++)
    if (m->elements[e].shaft == s.shaft) {
      if (!s.ne++) s.node0 = m->elements[e].node0;
    }
  if (s.ne < 3) return RCB_OK; /* every span is an element or the whole shaft */
  s.from = d->far && d->nom_model ? d->nom_model : d->base_model;
  if (!(s.F = rcb_alloc(&d->alloc, 2 * s.ne * s.ne * sizeof *s.F)))
    return rcb_diag_fail(d, RCB_ERR_NOMEM, "out of memory");
  s.v = s.F + s.ne * s.ne;
  for (i = 0; i < s.ne * s.ne; i++) s.F[i] = (double)NAN;
  st = rcb_diag_subset_weights(d, (double **)&s.w);
  /* from the better of two seeds: the leader's own span (its element, the
   * whole shaft) at its fitted factor, and the placement's run */
  if (L->fam == &rcb_diag_family_element) a = b = L->node - s.node0;
  else a = 1, b = s.ne;
  v0 = 1.0;
  if (L->model) rcb_model_get_param(L->model, L->pname[0], &v0);
  if (!st) st = span_eval(d, &s, a, b, v0, &F1);
  if (!st && placed_run(d, &s, &a2, &b2) && !(st = span_eval(d, &s, a2, b2, v0, &F2)) &&
      F2 < F1)
    a = a2, b = b2;
  if (!st) st = span_walk(d, &s, &a, &b, v0);
  /* the best span, and those one element from it whose search objective is
   * within RCB_DIAG_POLISH_WITHIN of its own, refitted as candidates */
  if (!st) {
    const long mv[5][2] = {{0, 0}, {-1, 0}, {1, 0}, {0, -1}, {0, 1}};
    double Fb = s.F[(a - 1) * s.ne + b - 1];
    for (i = 0; !st && i < 5; i++) {
      long na = (long)a + mv[i][0], nb = (long)b + mv[i][1];
      size_t j, t = 0;
      if (na < 1 || nb > (long)s.ne || na > nb ||
          !(s.F[((size_t)na - 1) * s.ne + (size_t)nb - 1] <= (1.0 + RCB_DIAG_POLISH_WITHIN) * Fb))
        continue;
      if ((st = span_cand(d, &s, (size_t)na, (size_t)nb, &t))) break;
      for (j = 0; j < n && k[j] != t; j++) continue;
      if (j < n || d->cand[t].refitted) continue;
      d->cand[t].from_fit = !d->far || !d->nom_model;
      d->cand[t].from_nom = d->far && d->nom_model;
      d->cand[t].late = 1;
      k[n++] = t;
    }
  }
  d->span_tried += s.tried;
  rcb_free(&d->alloc, (void *)s.w);
  rcb_free(&d->alloc, s.F);
  if (st) return st;
  /* d->order sized for the candidates laid out before: grown to them all */
  if (rcb_grow(&d->alloc, (void **)&d->order, &d->cap_order, d->ncand, sizeof *d->order))
    return rcb_diag_fail(d, RCB_ERR_NOMEM, "out of memory");
  rcb_diag_sort_order(d);
  st = rcb_diag_refit_more(d, k, n);
  return st;
}
