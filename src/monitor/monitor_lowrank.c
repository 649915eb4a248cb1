/*
 * The re-linearisation's model evaluations without a sweep (FRF set-ups).
 * The tracked parameters are coefficients of the dynamic stiffness:
 * Z(w; t0 + theta) = Z0(w) + sum_j theta_j D_j(w), D_j = dK_j - w^2 dM_j +
 * i w (dC_j + Omega dG_j) (identify.h's rcb_fit_dz: the parameters'
 * derivative matrices, constant when Z is affine in them), all on the few
 * DOFs P they touch (a coupling's kt, kr, ct: the 8 DOFs of its two hubs).
 * With H0 = Z0^-1, the Woodbury identity gives every channel's change
 *   H_oi(theta) - H0_oi = -H0_oP (I + dZ H0_PP)^-1 dZ H0_Pi,  dZ = dZ_PP,
 * one |P| x |P| solve per frequency (about 1 us) instead of the banded
 * factorisation of the whole model (about 20 us). H0_oP (in each channel's
 * kind), H0_PP and H0_Pi (receptances) are kept from create, where one
 * evaluation is checked against a sweep of the model (rcb_mon_lowrank_init):
 * a parameter that does not enter Z affinely (or a unbalance set-up) leaves
 * the sweep in charge. All memory from the monitor's hooks at create.
 */
#include <lapacke.h>
#include <math.h>
#include <string.h>

#include "identify/identify.h"
#include "io/io.h"
#include "monitor/monitor_internal.h"

/* Largest relative difference, over the points, of the low-rank change
 * against the sweep's (of the largest change) that create accepts. */
#define LR_TOL 1e-7
/* The check's step: this fraction of each tracked parameter's baseline. */
#define LR_STEP 0.05
/* A candidate's check step, in its standard errors at create. The sweep's
 * change (rm - rbase, a difference of two sweeps) carries a rounding floor
 * of about 3e-17 on the paper system (receptances up to 1e-6 m/N): at 10
 * standard errors B1's and B2's cross-coupling changed the model by 2-3e-10,
 * so the check read 1.0e-7 and 1.6e-7 (rounding, not a non-affine
 * parameter), failed against LR_TOL, and their joint step ran by sweeps
 * (the alarmed update 39 ms against 4.7 ms, bench_monitor 'changed'). At
 * 100 the smallest change of any candidate is 2e-9 and the worst check
 * 2.6e-8, 4 times under LR_TOL; a parameter that does not enter Z affinely
 * shows more clearly at the larger step, not less. */
#define LR_CAND_STEP 100.0


/* Index of matrix row r in P (appending it if new; np capped by cap). */
static size_t p_index(mon_lowrank *lr, size_t r, size_t cap) {
  size_t q;
  for (q = 0; q < lr->np; q++)
    if (lr->pdof[q] == r) return q;
  if (lr->np < cap) lr->pdof[lr->np++] = r;
  return q;
}

/* The rcb_dof of matrix row r (a node's DOF; pedestal DOFs are not). */
static int dof_of(const rcb_model *m, size_t r, rcb_dof *out) {
  size_t n, d, idx, nn = rcb_model_node_count(m);
  for (n = 0; n < nn; n++)
    for (d = 0; d < 4; d++) {
      rcb_dof x;
      x.node = n, x.dir = (rcb_dir)d;
      if (rcb_model_dof_index(m, x, &idx) == RCB_OK && idx == r) {
        *out = x;
        return 1;
      }
    }
  return 0;
}

/* The kind of channel c of the set-up (rcb_frf_kind), -1 if unreadable. */
static int channel_kind(const rcb_monitor *mon, size_t c) {
  rcb_meas_channel_info ci;
  return rcb_meas_channel(mon->setup, c, &ci) == RCB_OK ? (int)ci.kind : -1;
}

/* The blocks H0_oP, H0_PP, H0_Pi at every frequency of the set-up. */
static rcb_status blocks(rcb_monitor *mon, mon_lowrank *lr, const rcb_meas_dofs *md) {
  size_t np = lr->np, nout = md->nout + np, nin = md->nin + np, i, c, q, r, pass;
  rcb_dof *outs = rcb_mon_alloc(mon, nout, sizeof *outs), *ins = rcb_mon_alloc(mon, nin,
                                                                               sizeof *ins);
  rcb_complex *H = rcb_mon_alloc(mon, nout * nin, sizeof *H);
  rcb_frf *f = NULL;
  rcb_status st = RCB_ERR_NOMEM;
  if (!outs || !ins || !H) goto done;
  memcpy(outs, md->outs, md->nout * sizeof *outs);
  memcpy(ins, md->ins, md->nin * sizeof *ins);
  for (q = 0; q < np; q++) {
    st = RCB_ERR_UNSUPPORTED;
    if (!dof_of(mon->model, lr->pdof[q], &outs[md->nout + q])) goto done;
    ins[md->nin + q] = outs[md->nout + q];
  }
  if ((st = rcb_frf_create(&f, mon->model, nout, outs, nin, ins, RCB_SOLVER_BANDED,
                           &mon->alloc)))
    goto done;
  for (i = 0; i < mon->npts; i++) {
    double w = lr->w[i], W = lr->speed < 0 ? w : lr->speed;
    /* pass 0: receptance (H0_PP, H0_Pi, and the receptance channels); then
     * each other kind's channels */
    for (pass = 0; pass < 3; pass++) {
      int used = pass == 0;
      for (c = 0; !used && c < mon->nch; c++) used = channel_kind(mon, c) == (int)pass;
      if (!used) continue;
      if ((st = rcb_frf_eval(f, w, W, (rcb_frf_kind)pass, H))) goto done;
      for (c = 0; c < mon->nch; c++)
        if (channel_kind(mon, c) == (int)pass)
          for (q = 0; q < np; q++)
            lr->a[(c * mon->npts + i) * np + q] = H[md->ch_out[c] + nout * (md->nin + q)];
      if (pass) continue;
      for (q = 0; q < np; q++) {
        for (r = 0; r < np; r++)
          lr->hpp[i * np * np + q + np * r] = H[md->nout + q + nout * (md->nin + r)];
        for (r = 0; r < md->nin; r++)
          lr->b[(i * md->nin + r) * np + q] = H[md->nout + q + nout * r];
      }
    }
  }
done:
  rcb_frf_destroy(f);
  rcb_free(&mon->alloc, H);
  rcb_free(&mon->alloc, ins);
  rcb_free(&mon->alloc, outs);
  return st;
}

/* The structure of dZ (na x na on the active DOFs, column-major) for this
 * evaluation: for each row q, its columns holding an entry, ascending,
 * cols[q * MON_LOWRANK_MAXP ..], ncol[q] of them. */
static void dz_pattern(const mon_lowrank *lr, size_t nt, const mon_cand *c, size_t na,
                       unsigned char *cols, unsigned char *ncol) {
  unsigned char hit[MON_LOWRANK_MAXP * MON_LOWRANK_MAXP];
  const size_t *loc = lr->loc;
  size_t j, a, e = 0, q;
  memset(hit, 0, na * na);
  for (j = 0; j < nt; j++)
    for (a = 0; a < lr->dz[j].ne; a++, e++)
      hit[loc[lr->ep[2 * e]] + na * loc[lr->ep[2 * e + 1]]] = 1;
  for (j = 0, e = 0; c && j < c->np; j++)
    for (a = 0; a < c->dz[j].ne; a++, e++)
      hit[loc[c->ep[2 * e]] + na * loc[c->ep[2 * e + 1]]] = 1;
  for (q = 0; q < na; q++) {
    ncol[q] = 0;
    for (a = 0; a < na; a++)
      if (hit[q + na * a]) cols[q * MON_LOWRANK_MAXP + ncol[q]++] = (unsigned char)a;
  }
}

/* A hint to fetch the cache line at p ahead of its use (no effect on any
 * value): the next point's entries of H0_PP and H0_oP, scattered over blocks
 * of |P| x |P| and nch x |P| values, are otherwise each a cache miss. */
#if defined(__GNUC__)
#define LR_PREFETCH(p) __builtin_prefetch(p)
#else
#define LR_PREFETCH(p) ((void)(p))
#endif

/* The next point's entries of the blocks (point i + 1) ahead of their use. */
static void prefetch_point(const rcb_monitor *mon, const mon_lowrank *lr, size_t i, size_t na) {
  size_t np = lr->np, q, r, ch;
  const rcb_complex *hpp = lr->hpp + i * np * np;
  if (i >= mon->npts) return;
  for (r = 0; r < na; r++)
    for (q = 0; q < na; q++) LR_PREFETCH(hpp + lr->act[q] + np * lr->act[r]);
  for (ch = 0; ch < mon->nch; ch++)
    for (q = 0; q < na; q++) LR_PREFETCH(lr->a + (ch * mon->npts + i) * np + lr->act[q]);
}

/* v + x y in real arithmetic: the same products and sums as C's complex
 * multiply, without its NaN-recovery branch (the values are finite). */
static rcb_complex cmac(rcb_complex v, rcb_complex x, rcb_complex y) {
  double xr = creal(x), xi = cimag(x), yr = creal(y), yi = cimag(y);
  return CMPLX(creal(v) + (xr * yr - xi * yi), cimag(v) + (xr * yi + xi * yr));
}

rcb_status rcb_mon_lowrank_change(rcb_monitor *mon, const double *theta, const mon_cand *c,
                                  const double *s, rcb_complex *dm) {
  mon_lowrank *lr = mon->lr;
  size_t nin = lr->nin, np = lr->np, na, i, j, a, q, r, ch, e0, t;
  size_t *act = lr->act, *loc = lr->loc;
  unsigned char cols[MON_LOWRANK_MAXP * MON_LOWRANK_MAXP], ncol[MON_LOWRANK_MAXP];
  /* this evaluation's DOFs: the tracked parameters', then c's */
  na = lr->npt;
  for (q = 0; q < np; q++) loc[q] = q < na ? q : (size_t)-1, act[q] = q;
  for (a = 0, e0 = 0; c && a < c->np; e0 += c->dz[a].ne, a++)
    for (q = 0; q < 2 * c->dz[a].ne; q++) {
      size_t pos = c->ep[2 * e0 + q];
      if (loc[pos] == (size_t)-1) loc[pos] = na, act[na++] = pos;
    }
  /* dZ's entries: the products below skip its structural zeros, whose
   * terms (0 x a finite value) would leave every sum as it is */
  dz_pattern(lr, mon->nt, c, na, cols, ncol);
  for (i = 0; i < mon->npts; i++) {
    double w = lr->w[i], W = lr->speed < 0 ? w : lr->speed;
    const rcb_complex *hpp = lr->hpp + i * np * np, *b = lr->b + i * nin * np;
    rcb_complex *dZ = lr->dZ, *M = lr->M, *X = lr->X;
    size_t e = 0;
    prefetch_point(mon, lr, i + 1, na);
    memset(dZ, 0, na * na * sizeof *dZ);
    for (j = 0; j < mon->nt; j++)
      for (a = 0; a < lr->dz[j].ne; a++, e++) {
        const rcb_fit_dz_entry *d = &lr->dz[j].e[a];
        dZ[loc[lr->ep[2 * e]] + na * loc[lr->ep[2 * e + 1]]] +=
            theta[j] * CMPLX(d->k - w * w * d->m, w * (d->c + W * d->g));
      }
    for (j = 0, e = 0; c && j < c->np; j++)
      for (a = 0; a < c->dz[j].ne; a++, e++) {
        const rcb_fit_dz_entry *d = &c->dz[j].e[a];
        dZ[loc[c->ep[2 * e]] + na * loc[c->ep[2 * e + 1]]] +=
            s[j] * CMPLX(d->k - w * w * d->m, w * (d->c + W * d->g));
      }
    for (r = 0; r < na; r++) /* M = I + dZ H0_PP, X = dZ H0_Pi (on the active DOFs) */
      for (q = 0; q < na; q++) {
        rcb_complex v = q == r ? 1.0 : 0.0;
        const unsigned char *cq = cols + q * MON_LOWRANK_MAXP;
        for (t = 0; t < ncol[q]; t++)
          v = cmac(v, dZ[q + na * cq[t]], hpp[act[cq[t]] + np * act[r]]);
        M[q + na * r] = v;
      }
    for (r = 0; r < nin; r++)
      for (q = 0; q < na; q++) {
        rcb_complex v = 0;
        const unsigned char *cq = cols + q * MON_LOWRANK_MAXP;
        for (t = 0; t < ncol[q]; t++) v = cmac(v, dZ[q + na * cq[t]], b[r * np + act[cq[t]]]);
        X[q + na * r] = v;
      }
    if (LAPACKE_zgesv_work(LAPACK_COL_MAJOR, (lapack_int)na, (lapack_int)nin, M, (lapack_int)na,
                           lr->ipiv, X, (lapack_int)na))
      return rcb_mon_fail(mon, RCB_ERR_SINGULAR, "re-linearising at %g rad/s: the changed "
                          "model is singular", w);
    for (ch = 0; ch < mon->nch; ch++) {
      const rcb_complex *ac = lr->a + (ch * mon->npts + i) * np, *x = X + na * lr->ch_in[ch];
      rcb_complex v = 0;
      for (q = 0; q < na; q++) v = cmac(v, ac[act[q]], x[q]);
      dm[ch * mon->npts + i] = -v;
    }
  }
  return RCB_OK;
}

/* Entries of derivative matrices dz[0 .. n). */
static size_t entries(const rcb_fit_dz *dz, size_t n) {
  size_t j, ne = 0;
  for (j = 0; j < n; j++) ne += dz[j].ne;
  return ne;
}

/* Places in P of the entries of dz[0 .. n) into ep (2 per entry), P grown
 * as needed up to cap; 0 when P would pass cap (P and ep then as before). */
static int places(mon_lowrank *lr, const rcb_fit_dz *dz, size_t n, size_t *ep, size_t cap) {
  size_t j, a, e = 0, np0 = lr->np;
  for (j = 0; j < n; j++)
    for (a = 0; a < dz[j].ne; a++, e++) {
      ep[2 * e] = p_index(lr, dz[j].e[a].row, cap);
      ep[2 * e + 1] = p_index(lr, dz[j].e[a].col, cap);
      if (ep[2 * e] >= cap || ep[2 * e + 1] >= cap) {
        lr->np = np0;
        return 0;
      }
    }
  return 1;
}

/* Sizes, the tracked parameters' derivative matrices and P: the tracked
 * parameters' DOFs first, then those of each settable candidate with
 * derivative matrices while P stays within MON_LOWRANK_MAXP and the
 * candidate's own DOFs within MON_LOWRANK_CAND (a distributed effect such
 * as shaft damping stays on the sweep). */
static rcb_status layout(rcb_monitor *mon, mon_lowrank *lr, size_t nin) {
  size_t j, ne, cap = MON_LOWRANK_MAXP, used;
  rcb_status st;
  lr->dz = rcb_mon_alloc(mon, mon->nt, sizeof *lr->dz);
  lr->pdof = rcb_mon_alloc(mon, cap, sizeof *lr->pdof);
  lr->act = rcb_mon_alloc(mon, 2 * cap, sizeof *lr->act);
  if (!lr->dz || !lr->pdof || !lr->act) return RCB_ERR_NOMEM;
  lr->loc = lr->act + cap;
  if ((st = rcb_fit_dz_get(mon->fit, &mon->alloc, lr->dz))) return st;
  ne = entries(lr->dz, mon->nt);
  for (j = 0; j < mon->ncand; j++)
    if (mon->cand[j].dz && mon->cand[j].settable && mon->cand[j].dof)
      ne += entries(mon->cand[j].dz, mon->cand[j].np);
  lr->ep = rcb_mon_alloc(mon, 2 * (ne ? ne : 1), sizeof *lr->ep);
  if (!lr->ep) return RCB_ERR_NOMEM;
  if (!places(lr, lr->dz, mon->nt, lr->ep, cap) || !lr->np) return RCB_ERR_UNSUPPORTED;
  lr->npt = lr->np;
  used = 2 * entries(lr->dz, mon->nt);
  for (j = 0; j < mon->ncand; j++) {
    mon_cand *c = &mon->cand[j];
    size_t np0 = lr->np;
    if (!c->dz || !c->settable || !c->dof) continue;
    if (places(lr, c->dz, c->np, lr->ep + used, cap) && lr->np - np0 <= MON_LOWRANK_CAND) {
      c->ep = lr->ep + used;
      used += 2 * entries(c->dz, c->np);
    } else {
      lr->np = np0;
    }
  }
  lr->nin = nin;
  lr->a = rcb_mon_alloc(mon, mon->npt * lr->np, sizeof *lr->a);
  lr->hpp = rcb_mon_alloc(mon, mon->npts * lr->np * lr->np, sizeof *lr->hpp);
  lr->b = rcb_mon_alloc(mon, mon->npts * nin * lr->np, sizeof *lr->b);
  lr->dZ = rcb_mon_alloc(mon, 2 * lr->np * lr->np + lr->np * nin + mon->npt, sizeof *lr->dZ);
  lr->ipiv = rcb_mon_alloc(mon, lr->np, sizeof *lr->ipiv);
  lr->ch_in = rcb_mon_alloc(mon, mon->nch, sizeof *lr->ch_in);
  if (!lr->a || !lr->hpp || !lr->b || !lr->dZ || !lr->ipiv || !lr->ch_in) return RCB_ERR_NOMEM;
  lr->M = lr->dZ + lr->np * lr->np, lr->X = lr->M + lr->np * lr->np;
  lr->dm = lr->X + lr->np * nin;
  return RCB_OK;
}

/* Largest difference of the low-rank change against the sweep's (rm -
 * rbase), over the largest change, for the model's current values. */
static double mismatch(rcb_monitor *mon, const double *theta, const mon_cand *c,
                       const double *s, rcb_complex *dm, rcb_status *st) {
  double big = 0, diff = 0;
  size_t p;
  if ((*st = rcb_fit_residuals(mon->fit, mon->rm)) ||
      (*st = rcb_mon_lowrank_change(mon, theta, c, s, dm)))
    return HUGE_VAL;
  for (p = 0; p < mon->npt; p++) {
    rcb_complex v = CMPLX(mon->rm[2 * p] - mon->rbase[2 * p],
                          mon->rm[2 * p + 1] - mon->rbase[2 * p + 1]);
    big = fmax(big, cabs(v));
    diff = fmax(diff, cabs(v - dm[p]));
  }
  return big > 0 ? diff / big : HUGE_VAL;
}

/* Does the low-rank change equal the sweep's, at theta = LR_STEP t0 for the
 * tracked parameters (*ok), and at LR_CAND_STEP standard errors of each
 * candidate taken (c->ep, reset for one that does not)? */
static rcb_status check(rcb_monitor *mon, int *ok) {
  double theta[RCB_MONITOR_MAX_TRACKED], zero[RCB_MONITOR_MAX_TRACKED] = {0}, s[RCB_MONITOR_MAXP];
  rcb_complex *dm = rcb_mon_alloc(mon, mon->npt, sizeof *dm);
  size_t j, a;
  rcb_status st = RCB_OK;
  *ok = 0;
  if (!dm) return RCB_ERR_NOMEM;
  for (j = 0; j < mon->nt; j++) theta[j] = LR_STEP * mon->t0[j];
  for (j = 0; !st && j < mon->nt; j++)
    st = rcb_model_set_param(mon->model, mon->tname[j], mon->t0[j] + theta[j]);
  *ok = !st && mismatch(mon, theta, NULL, NULL, dm, &st) <= LR_TOL;
  rcb_mon_model_restore(mon, NULL);
  for (j = 0; *ok && !st && j < mon->ncand; j++) {
    mon_cand *c = &mon->cand[j];
    rcb_status sc = RCB_OK;
    int good;
    if (!c->ep) continue;
    for (a = 0; !sc && a < c->np; a++) {
      s[a] = LR_CAND_STEP * c->se[a];
      sc = rcb_model_set_param(mon->model, c->pname[a], c->neutral[a] + s[a]);
    }
    good = !sc && mismatch(mon, zero, c, s, dm, &sc) <= LR_TOL;
    rcb_mon_model_restore(mon, c);
    if (sc == RCB_ERR_NOMEM) st = sc;
    if (!good) c->ep = NULL; /* not affine after all: by sweeps */
  }
  rcb_free(&mon->alloc, dm);
  return st == RCB_ERR_NOMEM ? st : RCB_OK;
}

void rcb_mon_lowrank_free(rcb_monitor *mon, mon_lowrank *lr) {
  size_t j;
  if (!lr) return;
  for (j = 0; j < mon->ncand; j++) mon->cand[j].ep = NULL;
  if (lr->dz) rcb_fit_dz_free(&mon->alloc, lr->dz, mon->nt);
  rcb_free(&mon->alloc, lr->dz);
  rcb_free(&mon->alloc, lr->ep);
  rcb_free(&mon->alloc, lr->pdof);
  rcb_free(&mon->alloc, lr->act);
  rcb_free(&mon->alloc, lr->a);
  rcb_free(&mon->alloc, lr->hpp);
  rcb_free(&mon->alloc, lr->b);
  rcb_free(&mon->alloc, lr->dZ);
  rcb_free(&mon->alloc, lr->ipiv);
  rcb_free(&mon->alloc, lr->ch_in);
  rcb_free(&mon->alloc, lr);
}

/* The low-rank path when it applies (mon->lr), else none (mon->lr NULL):
 * an error only for memory. */
static rcb_status lowrank_try(rcb_monitor *mon, mon_lowrank *lr, rcb_meas_dofs *md,
                              const mon_image *im) {
  size_t c;
  rcb_status st;
  int ok;
  if (rcb_meas_resolve_dofs(mon->setup, mon->model, md, NULL) != RCB_OK) return RCB_OK;
  for (c = 0; c < mon->nch; c++)
    if (channel_kind(mon, c) < 0) return RCB_OK;
  lr->w = rcb_meas_grid(mon->setup);
  lr->speed = rcb_meas_speed(mon->setup);
  if ((st = layout(mon, lr, md->nin))) return st == RCB_ERR_NOMEM ? st : RCB_OK;
  for (c = 0; c < mon->nch; c++) lr->ch_in[c] = md->ch_in[c];
  if (im) { /* the blocks and the check's outcome as a full create made them */
    if (!im->lr) return RCB_OK;
    if ((st = rcb_mon_image_lowrank(mon, im, lr))) return st;
    mon->lr = lr;
    return RCB_OK;
  }
  if ((st = blocks(mon, lr, md))) return st == RCB_ERR_NOMEM ? st : RCB_OK;
  mon->lr = lr;
  if ((st = check(mon, &ok)) || !ok) mon->lr = NULL;
  return st;
}

rcb_status rcb_mon_lowrank_init(rcb_monitor *mon, const mon_image *im) {
  mon_lowrank *lr;
  rcb_meas_dofs md;
  size_t nch = mon->nch;
  rcb_status st;
  if (!mon->nt || !mon->relin || rcb_meas_get_type(mon->setup) != RCB_MEAS_FRF)
    return im && im->lr ? rcb_mon_fail(mon, RCB_ERR_OTHER_SETUP, "commissioning image: a "
                                       "low-rank path this monitor has not") : RCB_OK;
  memset(&md, 0, sizeof md);
  lr = rcb_mon_alloc(mon, 1, sizeof *lr);
  md.ch_out = rcb_mon_alloc(mon, 2 * nch, sizeof *md.ch_out);
  md.outs = rcb_mon_alloc(mon, 2 * nch, sizeof *md.outs);
  st = lr && md.ch_out && md.outs ? RCB_OK : RCB_ERR_NOMEM;
  if (!st) {
    md.ch_in = md.ch_out + nch, md.ins = md.outs + nch;
    st = lowrank_try(mon, lr, &md, im);
  }
  rcb_free(&mon->alloc, md.outs);
  rcb_free(&mon->alloc, md.ch_out);
  if (!mon->lr) rcb_mon_lowrank_free(mon, lr); /* not applicable: the sweep re-evaluates */
  if (st == RCB_ERR_NOMEM) return rcb_mon_fail(mon, st, "out of memory (re-linearisation blocks)");
  if (!st && im && im->lr && !mon->lr)
    st = rcb_mon_fail(mon, RCB_ERR_OTHER_SETUP, "commissioning image: a low-rank path this "
                      "monitor has not");
  return st; /* an image's refusal keeps its message */
}
