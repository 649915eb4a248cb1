/*
 * The refit of one candidate with the base parameters, in the steps the
 * flow runs each as a job across the candidates (rank.c): the first
 * start(s) from the fitted and the nominal base, screened on the frequency
 * subset (or fitted on all points on a small set); random starts while no
 * screen reached the noise floor; the evaluation on all points where the
 * screen ended; the polish of those that can lead. judge() gives each its
 * BIC change and claim, from its own adequacy test at its own predictions
 * (cand_adequacy(): limit, dispersion, whiteness).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "diagnose/diag_internal.h"
#include "diagnose/tuning.h"
#include "identify/identify.h"

/* Whether F is a chi-square: the weights are inverse variances (the noise
 * model, or known standard deviations). */
static int chi2(const rcb_diag *d) { return d->beta_a > 0 || d->beta_s > 0 || d->sd; }

/* Starts of a candidate's refit (rcb_fit_set_starts: further random starts
 * while the result is unsure). A pedestal's start is already the best of a
 * grid over its mass and stiffness (rcb_diag_refit_start), and another
 * coupling model starts from the fitted coupling's stiffnesses. A wrong
 * coupling model stays above the noise floor, "unsure", whatever its start;
 * random starts over the whole bounds of every parameter, the fitted ones
 * too, did not lower any of these objectives by 1e-5 of itself on 32 x 1101
 * and took 476 of the 709 refit sweeps. Only the scored candidates, started
 * at their neutral value, get them, and only while the baseline stayed near
 * the nominal model: when it ran off (d->far) each candidate is fitted from
 * the fitted and from the nominal base, two informed starts in place of the
 * random ones (see refit). A candidate refitted after the ranking (c->late:
 * a leading local candidate's neighbour, a span) starts at its neutral value
 * and gets none: on ROSS's element 8 at 0.6 (8 x 151) the four neighbours'
 * random starts took 2743 sweeps, 4.7 s, against 412 for the whole
 * diagnosis. */
static size_t refit_starts(const rcb_diag *d, const diag_cand *c) {
  return c->refit_only || c->late || (c->fam->flags & DIAG_FAM_ADDS_DOFS) || d->far ? 1
                                                                                      : 3;
}

typedef enum refit_stage {
  REFIT_ALL_POINTS, /* the refit on all points (8 x 151) */
  REFIT_SCREEN,     /* a screen on the frequency subset */
  REFIT_POLISH      /* a polish on all points after a screen */
} refit_stage;
/* How far each stage of a refit goes: RCB_DIAG_BIC_RESOLUTION of BIC (all
 * points; not for a scored candidate on 8 x 151) or RCB_DIAG_SCREEN_RESOLUTION
 * (a screen on the subset) as the fit's relative tolerance on F (tuning.h). */
static rcb_status refit_tolerance(const rcb_diag *d, const diag_cand *c, rcb_fit *f,
                                  refit_stage stage) {
  double scale = chi2(d) ? d->F0 : (double)d->nres;
  double tol = (stage == REFIT_SCREEN ? RCB_DIAG_SCREEN_RESOLUTION : RCB_DIAG_BIC_RESOLUTION) /
               scale;
  double ftol, xtol;
  size_t max_iter;
  rcb_fit_get_limits(f, &max_iter, &ftol, &xtol);
  if (c->late && max_iter > RCB_DIAG_SCREEN_ITER) max_iter = RCB_DIAG_SCREEN_ITER;
  if ((stage == REFIT_ALL_POINTS && !c->refit_only && !c->late) || !(scale > 0) ||
      !(tol < 1e-2) || tol <= ftol)
    return rcb_fit_set_limits(f, max_iter, ftol, xtol);
  return rcb_fit_set_limits(f, max_iter, tol, xtol);
}

static void record_fit(diag_cand *c, rcb_fit *f) {
  size_t k, n = 0;
  c->fitted[0] = '\0';
  for (k = rcb_fit_param_count(f) - c->np; k < rcb_fit_param_count(f); k++) {
    rcb_fit_param p;
    rcb_fit_get_param(f, k, &p);
    n += (size_t)snprintf(c->fitted + n, n < sizeof c->fitted ? sizeof c->fitted - n : 0,
                          "%s%s = %.6g", n ? ", " : "", p.name, p.value);
  }
  if (!c->np) snprintf(c->fitted, sizeof c->fitted, "no parameter of its own");
}

/* The candidate's model built on the base model src (the fitted one, or the
 * nominal one) and its fit, ready to run: start moved where the neutral
 * start sees nothing, starts, tolerance. */
static rcb_status refit_setup(rcb_diag *d, const diag_cand *c, const rcb_model *src,
                              int from_pre, refit_stage stage, rcb_model **m, rcb_fit **f) {
  rcb_status st;
  *m = NULL, *f = NULL;
  st = rcb_diag_candidate_model(d, c, src, m);
  if (!st) st = rcb_diag_make_fit(d, *m, RCB_DIAG_FIT_BASE, c, f);
  /* not when the start is where the pre-fit ended (set by the caller) */
  if (!st && !from_pre) st = rcb_diag_refit_start(d, c, *m, *f);
  if (!st) st = rcb_fit_set_starts(*f, refit_starts(d, c), 1);
  if (!st) st = refit_tolerance(d, c, *f, stage);
  return st;
}

/* The screening fit on the frequency subset w (NULL: the fit on all points)
 * stops after cap iterations (RCB_DIAG_SCREEN_ITER): it ranks the starts and
 * brings the polish near its end, and a fit crawling along a bound (a
 * damping at 0) goes on in the polish only if it is the best start. */
rcb_status rcb_diag_screen(rcb_fit *f, const double *w, size_t cap) {
  size_t it = 0;
  double ftol = 0.0, xtol = 0.0;
  rcb_status st = rcb_fit_get_limits(f, &it, &ftol, &xtol);
  if (!st) st = rcb_fit_set_weights(f, w);
  if (!st && w && it > cap) st = rcb_fit_set_limits(f, cap, ftol, xtol);
  if (!st) st = rcb_fit_run(f);
  if (w && it > cap) rcb_fit_set_limits(f, it, ftol, xtol);
  return st;
}

/* The polish of a screened fit on all points, from where the subset left it,
 * with no further starts, and at most RCB_DIAG_POLISH_ITER iterations
 * (tuning.h: a wrong candidate can crawl along a valley). */
rcb_status rcb_diag_polish(rcb_fit *f) {
  size_t it = 0;
  double ftol = 0.0, xtol = 0.0;
  rcb_status st = rcb_fit_get_limits(f, &it, &ftol, &xtol);
  if (!st) st = rcb_fit_set_weights(f, NULL);
  if (!st) st = rcb_fit_set_starts(f, 1, 1);
  if (!st && it > RCB_DIAG_POLISH_ITER)
    st = rcb_fit_set_limits(f, RCB_DIAG_POLISH_ITER, ftol, xtol);
  if (!st) st = rcb_fit_run(f);
  return st;
}

/* BIC change, adequacy limit and claim of a refitted candidate (F, err set;
 * k: its own parameters, refitted with the base's). */
static void judge(const rcb_diag *d, diag_cand *c, double k) {
  double N = (double)d->nres;
  rcb_evidence e;
  memset(&e, 0, sizeof e);
  /* with noise-aware weights or known standard deviations F is a
   * chi-square: BIC = F + k ln N; else the Gaussian likelihood with the
   * variance estimated */
  e.delta_bic = chi2(d) ? (c->F - d->F0) + k * log(N) : N * log(c->F / d->F0) + k * log(N);
  e.error_before_pct = d->err0, e.error_after_pct = c->err;
  e.chi2 = c->adeq_chi2, e.chi2_limit = c->chi2_limit;
  e.params = k, e.residuals = N, e.dispersion = c->dispersion;
  e.tried = (double)(d->ncand + d->span_tried);
  e.white = d->adeq0.known && c->white_z <= RCB_ADEQUACY_Z;
  e.beyond = c->beyond;
  c->ev = e;
  c->dbic = rcb_evidence_dbic(&e);
  c->significant = rcb_evidence_significant(&e);
  c->adequate = rcb_evidence_adequate(&e);
  c->claim = rcb_evidence_claim(&e);
}

/* The adequacy test of the model with candidate c (its fit f, on all
 * points, at its refitted values): its chi-square, limit, dispersion and
 * whiteness (issue #33). Its own test, with the noise model evaluated at
 * its own predictions: the weights every fit shares come from the model as
 * it is, and a large effect (a hub 120 % off) leaves them at values the
 * model with the effect does not have, which no test of it may use. F for
 * the BIC stays on the shared weights (c->F). f is left on the new weights. */
static rcb_status cand_adequacy(rcb_diag *d, diag_cand *c, rcb_fit *f) {
  size_t n = rcb_meas_channel_count(d->meas) * rcb_meas_point_count(d->meas);
  rcb_complex *h;
  rcb_fit_adequacy a;
  rcb_status st;
  c->adeq_chi2 = c->chi2_limit = c->dispersion = (double)NAN, c->white_z = HUGE_VAL;
  if (!d->adeq0.known) return RCB_OK;
  if (!(h = rcb_alloc(&d->alloc, (n ? n : 1) * sizeof *h)))
    return rcb_diag_fail(d, RCB_ERR_NOMEM, "out of memory");
  st = d->nref ? rcb_fit_predictions(f, h) : RCB_OK;
  if (!st && d->nref) st = rcb_fit_set_noise_reference(f, h);
  if (!st) st = rcb_fit_get_adequacy(f, &a, NULL, NULL, NULL);
  rcb_free(&d->alloc, h);
  if (st) return rcb_diag_fail(d, st, "the adequacy test of %s: %s", c->desc, rcb_fit_errmsg(f));
  c->adeq_chi2 = a.chi2, c->chi2_limit = a.limit, c->dispersion = a.dispersion;
  c->white_z = a.white_z;
  return RCB_OK;
}

/* Whether a fitted value of the candidate (the last c->np parameters of f)
 * lies outside what its part can be, [plo, phi] (issue #33: a section error
 * along a whole shaft was named "an added diametral inertia" 5 x the disk's
 * own). */
static void beyond(diag_cand *c, const rcb_fit *f) {
  size_t k, np = rcb_fit_param_count(f);
  c->beyond = 0;
  for (k = 0; k < c->np && np >= c->np; k++) {
    rcb_fit_param p;
    if (rcb_fit_get_param(f, np - c->np + k, &p)) continue;
    if (p.value < c->plo[k] - 1e-3 * fabs(c->plo[k]) ||
        p.value > c->phi[k] + 1e-3 * fabs(c->phi[k])) {
      c->beyond = 1, c->beyond_k = k, c->beyond_v = p.value;
      return;
    }
  }
}

/* A refit with nothing to fit (kramer_1, rigid): the model evaluated. */
static rcb_status evaluate_only(rcb_diag *d, diag_cand *c, rcb_model **m, rcb_fit *f) {
  double *r = rcb_alloc(&d->alloc, d->nres * sizeof *r);
  rcb_status st = r ? rcb_diag_objective(d, f, r, &c->F, &c->err) : RCB_ERR_NOMEM;
  rcb_free(&d->alloc, r);
  if (!st) st = cand_adequacy(d, c, f);
  if (st) return st;
  c->refitted = 1;
  c->polished = 1;
  judge(d, c, 0.0);
  snprintf(c->fitted, sizeof c->fitted, "no parameter");
  c->model = *m, *m = NULL; /* kept: --apply writes it */
  return RCB_OK;
}

/* A refit fitted or evaluated on all points: its figures. */
rcb_status rcb_diag_refit_result(rcb_diag *d, diag_cand *c, rcb_model **m, rcb_fit *f,
                                 double F, double err, int polished) {
  rcb_status st = cand_adequacy(d, c, f);
  if (st) return st;
  c->refitted = 1;
  c->polished = polished;
  c->F = F, c->err = err;
  beyond(c, f);
  judge(d, c, (double)c->np);
  record_fit(c, f);
  rcb_diag_keep_chain(c, f);
  rcb_model_destroy(c->model);
  c->model = *m, *m = NULL;
  return RCB_OK;
}

/* The first step of the refit of candidate c with the base parameters, from
 * the fitted base model (c->from_fit) and from the nominal one (c->from_nom:
 * the baseline fit ran off, and c scores high at the nominal model): a
 * missing effect that pulled the base parameters far leaves the fitted point
 * in a basin a joint fit does not leave. With w (a subset of the
 * frequencies, subset()) each start is screened on the subset and the best
 * is kept in c->model (c->screened) for the steps that follow once every
 * candidate's screen has ended (refit_restart, refit_evaluate,
 * refit_polish); without, the fit on all points is the refit. */
rcb_status rcb_diag_refit_screen(rcb_diag *d, diag_cand *c, const double *w) {
  rcb_model *m[2] = {NULL, NULL};
  rcb_fit *f[2] = {NULL, NULL};
  double F[2] = {HUGE_VAL, HUGE_VAL};
  char why[320] = "";
  size_t s, b = 0;
  int from_pre;
  /* from a run-off fit on the subset, RCB_DIAG_PREFIT_ITER_SUBSET iterations
   * first, and on only when within RCB_DIAG_PRE_RATIO of the best pre-fit
   * (tuning.h) */
  int far_start = w && d->far;
  rcb_fit_report rep;
  rcb_status st = RCB_OK;
  d->stats.refits++;
  for (s = 0; s < 2; s++) {
    if (!(s ? c->from_nom : c->from_fit)) continue;
    from_pre = s && c->prefitted && c->pre_F < HUGE_VAL;
    st = refit_setup(d, c, s ? d->nom_model : d->base_model, from_pre,
                     w ? REFIT_SCREEN : REFIT_ALL_POINTS, &m[s], &f[s]);
    if (!st && w) st = rcb_fit_set_starts(f[s], RCB_DIAG_STARTS_SUBSET, 1); /* see refit_restart */
    if (!st && from_pre) { /* where its pre-fit ended */
      size_t k;
      for (k = 0; !st && k < c->np; k++)
        st = rcb_fit_param_is_chain(c->pname[k])
                 ? rcb_fit_set_chain_value(f[s], c->pname[k], c->pre[k])
                 : rcb_model_set_param(m[s], c->pname[k], c->pre[k]);
    }
    if (st == RCB_ERR_NOMEM) break;
    if (st) { /* a candidate that cannot be built is reported, not fatal */
      if (!why[0]) snprintf(why, sizeof why, "not fitted: %.300s", d->errmsg);
      continue;
    }
    if (rcb_fit_param_count(f[s]) == 0) break; /* nothing to fit: evaluated below */
    st = rcb_diag_screen(f[s], w,
                         !s && far_start ? RCB_DIAG_PREFIT_ITER_SUBSET : RCB_DIAG_SCREEN_ITER);
    if (!st && !s && far_start && !rcb_fit_get_report(f[s], &rep) && !rep.converged &&
        !(rep.objective > RCB_DIAG_PRE_RATIO * d->pre_best))
      st = rcb_diag_screen(f[s], w,
                           RCB_DIAG_SCREEN_ITER - RCB_DIAG_PREFIT_ITER_SUBSET); /* on from there */
    if (st == RCB_ERR_NOMEM) {
      rcb_diag_fail(d, st, "refitting %s: %s", c->desc, rcb_fit_errmsg(f[s]));
      break;
    }
    if (st) { /* a candidate that cannot be fitted is reported, not fatal */
      if (!why[0]) snprintf(why, sizeof why, "refit failed: %.300s", rcb_fit_errmsg(f[s]));
      continue;
    }
    rcb_fit_get_report(f[s], &rep);
    F[s] = rep.objective;
    if (F[s] < F[b]) b = s;
  }
  if (st != RCB_ERR_NOMEM) {
    st = RCB_OK;
    if (f[b] && rcb_fit_param_count(f[b]) == 0) {
      st = evaluate_only(d, c, &m[b], f[b]);
    } else if (!(F[b] < HUGE_VAL)) {
      snprintf(c->fitted, sizeof c->fitted, "%s", why);
    } else if (w) { /* kept for refit_restart and refit_evaluate */
      rcb_fit_get_report(f[b], &rep);
      c->screened = 1;
      c->screen_F = F[b];
      c->screen_unsure = rep.unsure;
      c->screen_floor = rcb_diag_at_floor(rep.error_pct, rep.floor_pct);
      rcb_diag_keep_chain(c, f[b]);
      c->model = m[b], m[b] = NULL;
    } else {
      rcb_fit_get_report(f[b], &rep);
      st = rcb_diag_refit_result(d, c, &m[b], f[b], rep.objective, rep.error_pct, 1);
    }
  }
  for (s = 0; s < 2; s++) {
    rcb_diag_drop_fit(d, f[s]);
    rcb_model_destroy(m[s]);
  }
  return st;
}

/* The second step of a screened refit (c->screened) whose screen ended
 * unsure, when no candidate's screen reached the noise floor (d->screen_floor):
 * the random starts of refit_starts the first step left out, screened on
 * the subset w from the same points a run of them all would have drawn
 * (rcb_fit_set_first_start); the lower of the two ends is kept. */
rcb_status rcb_diag_refit_restart(rcb_diag *d, diag_cand *c, const double *w) {
  rcb_model *m = NULL;
  rcb_fit *f = NULL;
  rcb_fit_report rep = {0};
  size_t n = refit_starts(d, c);
  rcb_status st;
  if (!c->screened || !c->screen_unsure || d->screen_floor || n <= RCB_DIAG_STARTS_SUBSET)
    return RCB_OK;
  d->stats.restarts++;
  st = rcb_diag_copy_model(d, c->model, &m);
  if (!st) st = rcb_diag_make_fit(d, m, 1, c, &f);
  if (!st) st = rcb_fit_set_starts(f, n, 1);
  if (!st) st = rcb_fit_set_first_start(f, RCB_DIAG_STARTS_SUBSET);
  if (!st) st = refit_tolerance(d, c, f, REFIT_SCREEN);
  if (!st) st = rcb_diag_screen(f, w, RCB_DIAG_SCREEN_ITER);
  if (!st) st = rcb_fit_get_report(f, &rep);
  if (!st && rep.objective < c->screen_F) {
    c->screen_F = rep.objective;
    rcb_diag_keep_chain(c, f);
    rcb_model_destroy(c->model);
    c->model = m, m = NULL;
  }
  if (st == RCB_ERR_NOMEM)
    rcb_diag_fail(d, st, "refitting %s: %s", c->desc, f ? rcb_fit_errmsg(f) : "out of memory");
  rcb_diag_drop_fit(d, f);
  rcb_model_destroy(m);
  return st == RCB_ERR_NOMEM ? st : RCB_OK; /* a failed restart leaves the first screen */
}

/* The third step of a screened refit (c->screened), once every screen has
 * ended: evaluated on all points where its screen ended (its model in
 * c->model). */
rcb_status rcb_diag_refit_evaluate(rcb_diag *d, diag_cand *c) {
  rcb_model *m = c->model;
  rcb_fit *f = NULL;
  double *r = NULL, F = 0.0, err = 0.0;
  rcb_status st;
  if (!c->screened) return RCB_OK;
  c->model = NULL;
  st = rcb_diag_make_fit(d, m, 1, c, &f);
  if (!st) st = (r = rcb_alloc(&d->alloc, d->nres * sizeof *r)) ? RCB_OK : RCB_ERR_NOMEM;
  if (!st) st = rcb_diag_objective(d, f, r, &F, &err);
  if (!st) st = rcb_diag_refit_result(d, c, &m, f, F, err, 0);
  if (st && st != RCB_ERR_NOMEM)
    snprintf(c->fitted, sizeof c->fitted, "refit failed: %.300s", d->errmsg);
  rcb_free(&d->alloc, r);
  rcb_diag_drop_fit(d, f);
  rcb_model_destroy(m);
  if (st == RCB_ERR_NOMEM) return rcb_diag_fail(d, st, "refitting %s: out of memory", c->desc);
  return RCB_OK;
}

/* Whether the candidate's own parameters all ended their screen at 0, the
 * neutral value and lower bound of a linear one (an added mass, a damping):
 * its model is then the model as it is, and a polish would refit only the
 * base parameters. On large_null (seed 4) five added masses and inertias
 * ended so, each polish 19-28 sweeps on all points at 10-14 sweeps an
 * iteration along the bound, to lower F by 1 at most. */
static int at_neutral(const diag_cand *c) {
  size_t k;
  for (k = 0; k < c->np; k++) {
    double v = 1.0;
    if (c->logp[k] || c->lo[k] != 0.0 || rcb_model_get_param(c->model, c->pname[k], &v) ||
        v > 0.0)
      return 0;
  }
  return c->np > 0;
}

/* Whether the polish of c (its fit f, at its evaluation c->F) cannot make
 * it lead d->cand[d->lead], nor its rival (within RCB_BIC_SIGNIFICANT of
 * it): one Jacobian on all points. *out stays 0 when
 * that cannot be told (a failed Jacobian: the polish runs). */
static rcb_status cannot_lead(rcb_diag *d, const diag_cand *c, rcb_fit *f, int *out) {
  const diag_cand *L = d->lead < d->ncand ? &d->cand[d->lead] : NULL;
  size_t n, np = rcb_fit_param_count(f), nb, k;
  double *J, *r, pred = 0.0, own = 0.0, Fb, N = (double)d->nres, dbic;
  diag_basis b;
  rcb_status st = rcb_fit_prepare(f); /* the residual layout (it allocates) */
  *out = 0;
  if (st == RCB_ERR_NOMEM) return rcb_diag_fail(d, st, "out of memory");
  if (st) return RCB_OK; /* the polish runs, and says what failed */
  n = rcb_fit_residual_count(f);
  if (!L || L == c || !L->polished || L->claim != RCB_CLAIM_EXPLAINS || np < c->np ||
      n != d->nres || !n)
    return RCB_OK;
  nb = np - c->np;
  if (!(J = rcb_alloc(&d->alloc, (n * np + n) * sizeof *J)))
    return rcb_diag_fail(d, RCB_ERR_NOMEM, "out of memory");
  r = J + n * np;
  if ((st = rcb_fit_residuals(f, r)) || (st = rcb_fit_jacobian(f, 1, J))) {
    rcb_free(&d->alloc, J);
    if (st == RCB_ERR_NOMEM) /* out of memory fails the run; anything else: the polish runs */
      return rcb_diag_fail(d, st, "out of memory");
    return RCB_OK;
  }
  st = rcb_diag_basis_init(d, &b, J, n, nb, r);
  if (!st) {
    for (k = 0; k < b.rank; k++) pred += b.rt[k] * b.rt[k]; /* the base's columns */
    st = rcb_diag_explained(d, &b, J + n * nb, c->np, &own); /* its own, beyond */
    pred += own;
    rcb_diag_basis_free(d, &b);
  }
  rcb_free(&d->alloc, J);
  if (st) return st == RCB_ERR_NOMEM ? st : RCB_OK; /* the polish runs */
  Fb = c->F - RCB_DIAG_GN_SLACK * pred;
  if (!(Fb > 0.0)) return RCB_OK;
  dbic = chi2(d) ? (Fb - d->F0) + (double)c->np * log(N)
                 : N * log(Fb / d->F0) + (double)c->np * log(N);
  /* nor come within RCB_BIC_SIGNIFICANT of it: a rival the data cannot
   * separate from it is named in the words (say_rival) with its own BIC */
  *out = dbic > L->dbic - RCB_BIC_SIGNIFICANT;
  return RCB_OK;
}

/* The fourth step: a screened refit within RCB_DIAG_POLISH_WITHIN of the
 * lowest objective of all refits (d->best_F) polished on all points, on a
 * copy of its model (a failed polish leaves the evaluation); not one that
 * ended at its neutral value (at_neutral), nor one that cannot lead
 * (cannot_lead). */
rcb_status rcb_diag_refit_polish(rcb_diag *d, diag_cand *c) {
  rcb_model *m = NULL;
  rcb_fit *f = NULL;
  rcb_fit_report rep = {0};
  rcb_status st;
  int skip = 0;
  if (!c->screened || !c->refitted || c->polished ||
      !(c->F <= (1.0 + RCB_DIAG_POLISH_WITHIN) * d->best_F) || at_neutral(c))
    return RCB_OK;
  st = rcb_diag_copy_model(d, c->model, &m);
  if (!st) st = rcb_diag_make_fit(d, m, 1, c, &f);
  if (!st) st = cannot_lead(d, c, f, &skip);
  if (!st && skip) {
    rcb_diag_drop_fit(d, f);
    rcb_model_destroy(m);
    return RCB_OK;
  }
  if (!st) st = refit_tolerance(d, c, f, REFIT_POLISH);
  if (!st) st = rcb_diag_polish(f);
  if (!st) st = rcb_fit_get_report(f, &rep);
  if (!st) st = rcb_diag_refit_result(d, c, &m, f, rep.objective, rep.error_pct, 1);
  if (st == RCB_ERR_NOMEM)
    rcb_diag_fail(d, st, "refitting %s: %s", c->desc, f ? rcb_fit_errmsg(f) : "out of memory");
  rcb_diag_drop_fit(d, f);
  rcb_model_destroy(m);
  return st == RCB_ERR_NOMEM ? st : RCB_OK;
}
