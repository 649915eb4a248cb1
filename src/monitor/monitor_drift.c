/*
 * The monitor's drift test and the attribution of its CUSUM alarms
 * (rcb_monitor.h, "Drift test" and "Attribution"; issue #24 item 3). Both
 * read the last MON_DRIFT_WINDOW updates, kept in a ring by the update
 * (allocation-free: the ring was sized by rcb_monitor_create) and saved
 * with the state (monitor_state.c).
 *
 * Every update's whitened change y carries the commissioning's noise,
 * shared by all updates (share rho of an update's variance): under "no
 * change" the updates of one direction have covariance (1 - rho) I +
 * rho 1 1^T over the n updates since commissioning. The statistics below
 * are generalised least squares in that covariance (its inverse is
 * (I - kappa 1 1^T) / (1 - rho), kappa = rho / (1 - rho + n rho)), so they
 * need only the sums of y since commissioning besides the ring; after
 * rcb_monitor_reset_cusum the offset is free (kappa = 1 / n), as the
 * CUSUM's reference starts afresh.
 */
#include <math.h>
#include <string.h>

#include "monitor/monitor_internal.h"

static double dot(const double *a, const double *b, size_t n) {
  double s = 0;
  size_t i;
  for (i = 0; i < n; i++) s += a[i] * b[i];
  return s;
}

/* The onsets tried (updates ago): a geometric grid (ratio ~1.4) over the
 * window, so that the Bonferroni factor is MON_DRIFT_NONSET, not the
 * window's length; neighbouring ramps correlate at 0.96 or more (10 and 14:
 * 605 / sqrt(385 x 1015) = 0.968), so a drift whose onset falls between
 * two loses at most ~6 % of its GLR. */
static const size_t onsets[MON_DRIFT_NONSET] = {1, 2, 3, 5, 7, 10, 14, 19, 25, 32};

static int tried(size_t m) {
  size_t i;
  for (i = 0; i < MON_DRIFT_NONSET; i++)
    if (onsets[i] == m) return 1;
  return 0;
}

static double kappa_of(double rho, size_t nall, int free_off) {
  if (!nall) return 0.0;
  return free_off ? 1.0 / (double)nall : rho / (1.0 - rho + (double)nall * rho);
}

double rcb_mon_drift_glr(const double *ring, size_t ld, size_t w, size_t head, size_t count,
                         size_t dof, const double *sall, size_t nall, double rho, int free_off,
                         size_t *mbest, double *rate) {
  double A[RCB_MONITOR_MAXP] = {0}, C[RCB_MONITOR_MAXP] = {0}, best = 0.0;
  double kappa = kappa_of(rho, nall, free_off);
  size_t j, i;
  *mbest = 0;
  for (i = 0; i < dof; i++) rate[i] = 0.0;
  for (j = 0; j < count && j < w; j++) {
    const double *s = ring + ((head + w - j) % w) * ld;
    double m = (double)(j + 1), sw = m * (m + 1) / 2, q = sw * (2 * m + 1) / 3, den, g = 0;
    double num[RCB_MONITOR_MAXP];
    for (i = 0; i < dof; i++) A[i] += s[i], C[i] += (double)j * s[i];
    /* weights m - j' for the m newest (j' = 0 .. m - 1): sum w s = m A - C */
    den = q - kappa * sw * sw;
    if (!tried(j + 1) || !(den > 0)) continue;
    for (i = 0; i < dof; i++) {
      num[i] = m * A[i] - C[i] - kappa * sw * sall[i];
      g += num[i] * num[i];
    }
    g /= (1.0 - rho) * den;
    if (g > best || !*mbest) {
      best = g, *mbest = j + 1;
      for (i = 0; i < dof; i++) rate[i] = num[i] / den;
    }
  }
  return best;
}

/* v = (sum_j w_j x_j - kappa (sum w) xsum) over the m newest slots of a
 * ring of n-vectors (x_j = ring slot + off), and the denominator. */
static double accumulate(const rcb_monitor *mon, size_t m, double *v) {
  size_t j, i, k = mon->k, W = MON_DRIFT_WINDOW;
  double mm = (double)m, sw = mm * (mm + 1) / 2, q = sw * (2 * mm + 1) / 3;
  double kappa = kappa_of(mon->rho, mon->dall, mon->dfree);
  for (i = 0; i < k; i++) v[i] = -kappa * sw * mon->dysum[i];
  for (j = 0; j < m; j++) {
    const double *y = mon->dy + ((mon->dhead + W - j) % W) * k;
    double wj = mm - (double)j;
    for (i = 0; i < k; i++) v[i] += wj * y[i];
  }
  return q - kappa * sw * sw;
}

static void push(rcb_monitor *mon, const double *theta, int gls) {
  size_t k = mon->k, nt = mon->nt, j, a, W = MON_DRIFT_WINDOW, ld = mon->ncand * RCB_MONITOR_MAXP;
  size_t slot = mon->dcount ? (mon->dhead + 1) % W : 0;
  double *s = mon->ds + slot * ld;
  memcpy(mon->dy + slot * k, mon->y, k * sizeof *mon->dy);
  memcpy(mon->dth + slot * RCB_MONITOR_MAX_TRACKED, theta, nt * sizeof *mon->dth);
  for (j = 0; j < mon->ncand; j++) {
    const mon_cand *c = &mon->cand[j];
    for (a = 0; a < c->dof; a++) {
      double v = gls ? c->xd[a] : dot(c->dir + a * k, mon->y, k);
      s[j * RCB_MONITOR_MAXP + a] = v;
      mon->dssum[j * RCB_MONITOR_MAXP + a] += v;
    }
  }
  for (a = 0; a < k; a++) mon->dysum[a] += mon->y[a];
  for (a = 0; a < nt; a++) mon->dthsum[a] += theta[a];
  mon->dhead = slot;
  if (mon->dcount < W) mon->dcount++;
  mon->dall++;
}

void rcb_mon_drift_reset(rcb_monitor *mon) {
  mon->dcount = mon->dhead = mon->dall = 0;
  mon->dfree = 1;
  if (mon->dysum) memset(mon->dysum, 0, mon->k * sizeof *mon->dysum);
  if (mon->dssum) memset(mon->dssum, 0, mon->ncand * RCB_MONITOR_MAXP * sizeof *mon->dssum);
  memset(mon->dthsum, 0, sizeof mon->dthsum);
}

/* The drift test: each scored candidate's window GLR on its s, the best
 * supported (smallest p) into res, Bonferroni over candidates and onsets. */
static void drift_test(rcb_monitor *mon, rcb_monitor_result *res) {
  size_t j, a, ld = mon->ncand * RCB_MONITOR_MAXP, nsc = 0, best = 0, mb = 0;
  double sall[RCB_MONITOR_MAXP], rate[RCB_MONITOR_MAXP], rbest[RCB_MONITOR_MAXP] = {0};
  double lbest = 0, gbest = 0;
  for (j = 0; j < mon->ncand; j++) {
    const mon_cand *c = &mon->cand[j];
    size_t m;
    double g, lp;
    if (!c->dof) continue;
    for (a = 0; a < c->dof; a++) sall[a] = mon->dssum[j * RCB_MONITOR_MAXP + a];
    g = rcb_mon_drift_glr(mon->ds + j * RCB_MONITOR_MAXP, ld, MON_DRIFT_WINDOW, mon->dhead,
                          mon->dcount, c->dof, sall, mon->dall, mon->rho, mon->dfree, &m, rate);
    lp = rcb_mon_chi2_logsf(g, (double)c->dof);
    if (!nsc++ || lp < lbest || (lp == lbest && g > gbest)) {
      lbest = lp, gbest = g, best = j, mb = m;
      memcpy(rbest, rate, sizeof rbest);
    }
  }
  if (!nsc) return;
  {
    const mon_cand *c = &mon->cand[best];
    double lq = lbest + log((double)nsc * MON_DRIFT_NONSET);
    size_t b;
    res->drift_glr = gbest;
    res->drift_dof = c->dof;
    res->drift_p = lq < 0 ? exp(lq) : 1.0;
    /* while the instant test fires it names the change (re-linearised):
     * a step is no drift, and its best linear drift may be another effect */
    res->drift_alarm = !res->alarm && lq < log(mon->alpha);
    res->drift_index = best;
    res->drift_onset = mb;
    /* the parameters' rate: r0^-1 times the rate of s (back substitution) */
    for (a = c->np; a-- > 0;) {
      double v = rbest[a];
      for (b = a + 1; b < c->np; b++) v -= c->r0[a * RCB_MONITOR_MAXP + b] * res->drift_rate[b];
      res->drift_rate[a] = v / c->r0[a * RCB_MONITOR_MAXP + a];
    }
  }
}

/* The explained part of the accumulated change Y beyond the nuisance
 * columns N (the tracked ones but a) of [N, cols] (q columns of G from
 * col); its parameters' estimates x. -1 when the columns are dependent. */
static double explained(rcb_monitor *mon, size_t a, size_t col, size_t q, double *x) {
  size_t k = mon->k, nt = mon->nt, b, p = 0;
  double qz[RCB_MONITOR_MAX_TRACKED + RCB_MONITOR_MAXP], se[RCB_MONITOR_MAXP], g;
  int ok = 0;
  for (b = 0; b < nt; b++)
    if (b != a) memcpy(mon->sw.A + k * p++, mon->G + k * b, k * sizeof *mon->sw.A);
  memcpy(mon->sw.A + k * p, mon->G + k * col, k * q * sizeof *mon->sw.A);
  p += q;
  if (rcb_mon_small_qr(mon, &mon->sw, k, p, &ok) || !ok) return -1.0;
  g = rcb_mon_gls_explained(&mon->sw, mon->dY, k, nt - 1, p, qz);
  rcb_mon_gls_step(&mon->sw, qz, p, nt - 1, q, x, se);
  return g;
}

/* The test half of the one naming rule on the accumulated change: the
 * part of Y that q2 columns from col2 explain beyond the nuisance (the
 * tracked ones but a) and q1 columns from col1, chi-square(q2) when the
 * truth lies in the span of those; its upper-tail probability (1 when the
 * q2 columns lie in that span: nothing can reject it). */
static double adds(rcb_monitor *mon, size_t a, size_t col1, size_t q1, size_t col2, size_t q2) {
  size_t k = mon->k, nt = mon->nt, b, p = 0;
  double qz[RCB_MONITOR_MAX_TRACKED + 2 * RCB_MONITOR_MAXP];
  int ok = 0;
  for (b = 0; b < nt; b++)
    if (b != a) memcpy(mon->sw.A + k * p++, mon->G + k * b, k * sizeof *mon->sw.A);
  memcpy(mon->sw.A + k * p, mon->G + k * col1, k * q1 * sizeof *mon->sw.A);
  memcpy(mon->sw.A + k * (p + q1), mon->G + k * col2, k * q2 * sizeof *mon->sw.A);
  if (rcb_mon_small_qr(mon, &mon->sw, k, p + q1 + q2, &ok) || !ok) return 1.0;
  return rcb_chi2_sf(rcb_mon_gls_explained(&mon->sw, mon->dY, k, p + q1, p + q1 + q2, qz),
                     (double)q2);
}

/* The largest p over the candidates but skip, skip2 (and a's own column) of the
 * test that q columns from col add to each (adds): a candidate they
 * outscore (g, explained beyond the nuisance; each candidate's in
 * mon->gatt, from attribute) by more than the test's quantile is rejected
 * whatever the joint fit, its p bounded by the gap.
 * *at: the candidate of the largest (ncand: none); *open: how many are not
 * rejected (p at or above RCB_MONITOR_APART_ALPHA). */
static double worst_rival(rcb_monitor *mon, size_t a, size_t col, size_t q, double g,
                          size_t skip, size_t skip2, size_t *at, size_t *open) {
  double worst = 0, lim = rcb_chi2_quantile(1.0 - RCB_MONITOR_APART_ALPHA, (double)q);
  size_t j;
  *at = mon->ncand, *open = 0;
  for (j = 0; j < mon->ncand; j++) {
    const mon_cand *c = &mon->cand[j];
    double gc, p;
    if (!c->dof || j == skip || j == skip2 || c->col == col || (gc = mon->gatt[j]) < 0)
      continue;
    p = g - gc > lim ? rcb_chi2_sf(g - gc, (double)q) : adds(mon, a, c->col, c->np, col, q);
    *open += p >= RCB_MONITOR_APART_ALPHA;
    if (p > worst) worst = p, *at = j;
  }
  return worst;
}

/* A CUSUM alarm of tracked parameter a: is the accumulated change (the
 * drift-weighted sum of the whole window, GLS in the shared noise) better
 * explained by a candidate than by a, the other tracked parameters free? */
static void attribute(rcb_monitor *mon, size_t a, size_t pointed, rcb_monitor_tracked *t) {
  size_t k = mon->k, nt = mon->nt, i, b, j, m = mon->dcount;
  double den, x[RCB_MONITOR_MAXP] = {0}, ga, ba, bbest = 0, b2 = 0, scale;
  size_t r2 = 0;
  int have = 0, have2 = 0;
  if (!m) return;
  den = accumulate(mon, m, mon->dY);
  if (!(den > 0)) return;
  {
    /* y0 = y + G_t theta, linearly: the tracked steps back in */
    double kappa = kappa_of(mon->rho, mon->dall, mon->dfree), mm = (double)m, sw = mm * (mm + 1) / 2;
    double th[RCB_MONITOR_MAX_TRACKED];
    for (b = 0; b < nt; b++) th[b] = -kappa * sw * mon->dthsum[b];
    for (j = 0; j < m; j++) {
      const double *tj = mon->dth + ((mon->dhead + MON_DRIFT_WINDOW - j) % MON_DRIFT_WINDOW) *
                                        RCB_MONITOR_MAX_TRACKED;
      for (b = 0; b < nt; b++) th[b] += (mm - (double)j) * tj[b];
    }
    scale = 1.0 / sqrt((1.0 - mon->rho) * den);
    for (i = 0; i < k; i++) {
      double v = mon->dY[i];
      for (b = 0; b < nt; b++) v += mon->G[i + k * b] * th[b];
      mon->dY[i] = v * scale;
    }
  }
  if ((ga = explained(mon, a, a, 1, x)) < 0) return;
  ba = rcb_mon_bic(mon, ga, 1);
  for (j = 0; j < mon->ncand; j++) {
    const mon_cand *c = &mon->cand[j];
    double g, bj;
    mon->gatt[j] = -1.0;
    if (!c->dof || (g = mon->gatt[j] = explained(mon, a, c->col, c->np, x)) < 0) continue;
    bj = rcb_mon_bic(mon, g, c->dof);
    if (!have || bj < bbest) {
      if (have) have2 = 1, b2 = bbest, r2 = t->rival;
      have = 1, bbest = bj, t->rival = j, t->rival_dof = c->np;
      for (b = 0; b < c->np; b++) t->rival_rate[b] = x[b] / (den * scale);
    } else if (!have2 || bj < b2) {
      have2 = 1, b2 = bj, r2 = j;
    }
  }
  if (!have) return;
  /* a candidate the instant or drift test points at this update (a step
   * named, a drift under way) is the rival whenever the accumulated change
   * does not tell the best candidate from it (issue #34 item 2: after a
   * step, the tracked CUSUMs alarm on its leakage, which the step's own
   * columns explain about as well as any other's) */
  if (pointed < mon->ncand && pointed != t->rival && mon->cand[pointed].dof) {
    const mon_cand *c = &mon->cand[pointed];
    double g = explained(mon, a, c->col, c->np, x), bp;
    if (g >= 0 && (!rcb_evidence_separable(bp = rcb_mon_bic(mon, g, c->dof), bbest) ||
                   bp < bbest)) {
      have2 = 1, b2 = bbest, r2 = t->rival;
      bbest = bp, t->rival = pointed, t->rival_dof = c->np;
      for (b = 0; b < c->np; b++) t->rival_rate[b] = x[b] / (den * scale);
    }
  }
  if (rcb_evidence_separable(ba, bbest)) t->named = ba <= bbest ? 1 : -1;
  else t->named = 0;
  /* the test half of the one rule (rcb_monitor_named): a alone only when
   * every candidate's hypothesis is rejected by what a adds to it, else "a
   * or the candidate not rejected: not separable"; the rival told apart
   * from a only when a's hypothesis is rejected by what the rival adds */
  if (t->named == 1) {
    size_t at, open;
    if (worst_rival(mon, a, a, 1, ga, mon->ncand, mon->ncand, &at, &open) >=
            RCB_MONITOR_APART_ALPHA &&
        explained(mon, a, mon->cand[at].col, mon->cand[at].np, x) >= 0) {
      t->named = 0, t->rival = at, t->rival_dof = mon->cand[at].np, t->rivals_open = open - 1;
      for (b = 0; b < mon->cand[at].np; b++) t->rival_rate[b] = x[b] / (den * scale);
    }
  } else if (t->named == -1 &&
             adds(mon, a, a, 1, mon->cand[t->rival].col, mon->cand[t->rival].np) >=
                 RCB_MONITOR_APART_ALPHA) {
    t->named = 0;
  }
  /* untracked before tracked (issue #34 item 3): while this update's instant
   * or drift test points at an untracked candidate, the CUSUM alarm is not
   * the tracked parameter alone: "a, or that candidate: not separable" */
  if (t->named == 1 && pointed < mon->ncand && mon->cand[pointed].dof &&
      explained(mon, a, mon->cand[pointed].col, mon->cand[pointed].np, x) >= 0) {
    const mon_cand *c = &mon->cand[pointed];
    t->named = 0, t->rival = pointed, t->rival_dof = c->np;
    for (b = 0; b < c->np; b++) t->rival_rate[b] = x[b] / (den * scale);
    return;
  }
  /* the rival named alone only when the runner-up is told apart from it too:
   * on few channels two candidates can fit the change equally well */
  if (t->named == -1 && have2 && !rcb_evidence_separable(bbest, b2))
    t->rival2 = r2, t->rival2_dof = mon->cand[r2].np;
  /* and only when every other candidate's hypothesis is rejected by what
   * the rival adds to it (the test half): else, without the BIC's
   * runner-up, the one rejected least is it, and the others not rejected
   * are counted (the list is not complete) */
  if (t->named == -1) {
    const mon_cand *c = &mon->cand[t->rival];
    double g = (double)c->dof * log((double)mon->n) - bbest; /* rcb_mon_bic inverted */
    size_t at, open, skip2 = t->rival2_dof ? t->rival2 : mon->ncand;
    if (worst_rival(mon, a, c->col, c->np, g, t->rival, skip2, &at, &open) >=
        RCB_MONITOR_APART_ALPHA) {
      if (!t->rival2_dof) t->rival2 = at, t->rival2_dof = mon->cand[at].np, open--;
      t->rivals_open = open;
    }
  }
}

void rcb_mon_drift_update(rcb_monitor *mon, const double *theta, int gls,
                          rcb_monitor_result *res) {
  size_t a;
  size_t pointed;
  push(mon, theta, gls);
  drift_test(mon, res);
  /* the untracked candidate this update's tests point at, if any */
  pointed = res->alarm && res->ntop ? res->top[0].index
            : res->drift_alarm         ? res->drift_index
                                       : (size_t)-1;
  for (a = 0; a < mon->nt; a++) {
    res->tracked[a].named = 1;
    if (res->tracked[a].cusum_alarm) attribute(mon, a, pointed, &res->tracked[a]);
  }
}
