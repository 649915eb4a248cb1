/*
 * Model-measurement comparison ("where does the model fail?"): the model is
 * evaluated on the measurement's abscissa and kinds, then per channel the
 * paper's error % (as rcb_fit_error), FRAC, RMS log-magnitude and phase
 * errors; per point CSAC and CSF across channels (Allemang; Pascual et al.);
 * a channel x band residual map. The peak table is in compare_peaks.c.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "compare/compare_internal.h"
#include "io/io.h"

rcb_status rcb_compare_create(rcb_compare **out, const rcb_allocator *alloc) {
  rcb_allocator a;
  rcb_compare *c;
  if (!out) return RCB_ERR_ARG;
  rcb_allocator_init(&a, alloc);
  *out = c = rcb_alloc(&a, sizeof *c);
  if (!c) return RCB_ERR_NOMEM;
  c->alloc = a;
  c->nbands_req = 10;
  c->prom_db = 2.0;
  c->tol = 0.1;
  return RCB_OK;
}

static void free_results(rcb_compare *c) {
  const rcb_allocator *a = &c->alloc;
  void *ptrs[] = {c->grid, c->meas,  c->model, c->names, (void *)c->resp, (void *)c->ref,
                  c->kind, c->err,   c->frac,  c->lrms,  c->prms,         c->csac,
                  c->csf,  c->map,   c->peaks, c->band_first, c->band_count,
                  c->floor, c->chi2, c->outl, c->magonly};
  size_t k;
  for (k = 0; k < sizeof ptrs / sizeof ptrs[0]; k++) rcb_free(a, ptrs[k]);
  c->grid = NULL;
  c->meas = c->model = NULL;
  c->names = NULL;
  c->resp = c->ref = NULL;
  c->kind = NULL;
  c->magonly = NULL;
  c->err = c->frac = c->lrms = c->prms = c->csac = c->csf = c->map = NULL;
  c->floor = c->chi2 = NULL;
  c->peaks = NULL;
  c->outl = NULL;
  c->noutl = 0;
  c->band_first = c->band_count = NULL;
  c->nch = c->npts = c->nbands = c->npeaks = 0;
  c->done = 0;
}

void rcb_compare_destroy(rcb_compare *c) {
  rcb_allocator a;
  if (!c) return;
  free_results(c);
  a = c->alloc;
  rcb_free(&a, c->sd);
  rcb_free(&a, c);
}

const char *rcb_compare_errmsg(const rcb_compare *c) { return c ? c->errmsg : "no object"; }

rcb_status rcb_compare_set_bands(rcb_compare *c, size_t nbands) {
  if (!c) return RCB_ERR_ARG;
  if (nbands < 1 || nbands > 1000)
    return rcb_cmp_fail(c, RCB_ERR_ARG, "number of bands %zu: expected 1 to 1000", nbands);
  c->nbands_req = nbands;
  return RCB_OK;
}

rcb_status rcb_compare_set_peaks(rcb_compare *c, double prominence_db, double freq_tol) {
  if (!c) return RCB_ERR_ARG;
  if (!(prominence_db > 0 && prominence_db < 200))
    return rcb_cmp_fail(c, RCB_ERR_ARG, "peak prominence %g dB: expected > 0 (e.g. 3)",
                        prominence_db);
  if (!(freq_tol > 0 && freq_tol <= 1))
    return rcb_cmp_fail(c, RCB_ERR_ARG,
                        "frequency tolerance %g: expected a fraction in (0, 1] (e.g. 0.1)",
                        freq_tol);
  c->prom_db = prominence_db;
  c->tol = freq_tol;
  return RCB_OK;
}

rcb_status rcb_compare_set_sd(rcb_compare *c, const double *sd, size_t n) {
  double *copy = NULL;
  size_t i;
  if (!c) return RCB_ERR_ARG;
  if (sd && n) {
    for (i = 0; i < n; i++)
      if (sd[i] < 0 || isinf(sd[i]))
        return rcb_cmp_fail(c, RCB_ERR_ARG, "standard deviation %zu is %g: expected >= 0 "
                            "and finite (0 or NaN leaves the point out)", i, sd[i]);
    if (!(copy = rcb_alloc(&c->alloc, n * sizeof *copy)))
      return rcb_cmp_fail(c, RCB_ERR_NOMEM, "out of memory");
    memcpy(copy, sd, n * sizeof *copy);
  }
  rcb_free(&c->alloc, c->sd);
  c->sd = copy;
  c->nsd = copy ? n : 0;
  return RCB_OK;
}

/* ---- the model side ---- */

/* Channels -> FRF outputs and inputs (the resolver shared with the fit). */
static rcb_status resolve(rcb_compare *c, const rcb_meas *ms, rcb_cmp_eval *ev, rcb_dof *outs,
                          rcb_dof *ins) {
  rcb_meas_dofs d;
  rcb_status st;
  d.ch_out = ev->ch_out, d.ch_in = ev->ch_in, d.outs = outs, d.ins = ins;
  if ((st = rcb_meas_resolve_dofs(ms, ev->m, &d, c->errmsg))) return st;
  ev->nout = d.nout, ev->nin = d.nin;
  return RCB_OK;
}

static rcb_status eval_setup(rcb_compare *c, const rcb_meas *ms, rcb_cmp_eval *ev) {
  rcb_dof *outs = rcb_alloc(&c->alloc, c->nch * sizeof *outs);
  rcb_dof *ins = rcb_alloc(&c->alloc, c->nch * sizeof *ins);
  rcb_status st = RCB_OK;
  ev->ch_out = rcb_alloc(&c->alloc, c->nch * sizeof *ev->ch_out);
  ev->ch_in = rcb_alloc(&c->alloc, c->nch * sizeof *ev->ch_in);
  if (!outs || !ins || !ev->ch_out || !ev->ch_in)
    st = rcb_cmp_fail(c, RCB_ERR_NOMEM, "out of memory setting up the comparison");
  else if (!(st = resolve(c, ms, ev, outs, ins))) {
    st = rcb_frf_create(&ev->frf, ev->m, ev->nout, outs, ev->nin, ins, RCB_SOLVER_AUTO,
                        &c->alloc);
    if (st) rcb_cmp_fail(c, st, "model FRF workspace: %s", rcb_status_str(st));
    ev->H = rcb_alloc(&c->alloc, ev->nout * (ev->nin ? ev->nin : 1) * sizeof *ev->H);
    if (!st && !ev->H) st = rcb_cmp_fail(c, RCB_ERR_NOMEM, "out of memory");
  }
  rcb_free(&c->alloc, outs);
  rcb_free(&c->alloc, ins);
  return st;
}

static void eval_free(rcb_compare *c, rcb_cmp_eval *ev) {
  rcb_frf_destroy(ev->frf);
  rcb_free(&c->alloc, ev->ch_out);
  rcb_free(&c->alloc, ev->ch_in);
  rcb_free(&c->alloc, ev->H);
}

static double complex kind_factor(rcb_frf_kind kind, double w) {
  if (kind == RCB_MOBILITY) return CMPLX(0.0, w);
  if (kind == RCB_INERTANCE) return -w * w;
  return 1.0;
}

rcb_status rcb_cmp_model_at(rcb_compare *c, rcb_cmp_eval *ev, double w, rcb_complex *out) {
  size_t k;
  rcb_status st;
  if (c->type == RCB_MEAS_UNBALANCE)
    st = rcb_frf_unbalance(ev->frf, w, ev->H);
  else
    st = rcb_frf_eval(ev->frf, w, c->speed < 0 ? w : c->speed, RCB_RECEPTANCE, ev->H);
  if (st == RCB_ERR_SINGULAR) {
    for (k = 0; k < c->nch; k++) out[k] = CMPLX(NAN, NAN);
    return RCB_OK;
  }
  if (st) return rcb_cmp_fail(c, st, "model at %g rad/s: %s", w, rcb_frf_errmsg(ev->frf));
  for (k = 0; k < c->nch; k++) {
    double complex h = ev->H[ev->ch_out[k] + ev->nout * (c->type == RCB_MEAS_UNBALANCE
                                                              ? 0 : ev->ch_in[k])];
    out[k] = c->type == RCB_MEAS_UNBALANCE ? h : h * kind_factor(c->kind[k], w);
  }
  return RCB_OK;
}

/* ---- copying the measurement ---- */

static rcb_status alloc_results(rcb_compare *c) {
  size_t n = c->npts, nc = c->nch, nb = c->nbands;
  const rcb_allocator *a = &c->alloc;
  c->grid = rcb_alloc(a, n * sizeof *c->grid);
  c->meas = rcb_alloc(a, nc * n * sizeof *c->meas);
  c->model = rcb_alloc(a, nc * n * sizeof *c->model);
  c->resp = rcb_alloc(a, nc * sizeof *c->resp);
  c->ref = rcb_alloc(a, nc * sizeof *c->ref);
  c->kind = rcb_alloc(a, nc * sizeof *c->kind);
  c->magonly = rcb_alloc(a, nc * sizeof *c->magonly);
  c->err = rcb_alloc(a, nc * sizeof *c->err);
  c->frac = rcb_alloc(a, nc * sizeof *c->frac);
  c->lrms = rcb_alloc(a, nc * sizeof *c->lrms);
  c->prms = rcb_alloc(a, nc * sizeof *c->prms);
  c->floor = rcb_alloc(a, nc * sizeof *c->floor);
  c->chi2 = rcb_alloc(a, nc * sizeof *c->chi2);
  c->csac = rcb_alloc(a, n * sizeof *c->csac);
  c->csf = rcb_alloc(a, n * sizeof *c->csf);
  c->map = rcb_alloc(a, nc * nb * sizeof *c->map);
  c->band_first = rcb_alloc(a, nb * sizeof *c->band_first);
  c->band_count = rcb_alloc(a, nb * sizeof *c->band_count);
  if (!c->grid || !c->meas || !c->model || !c->resp || !c->ref || !c->kind || !c->err ||
      !c->frac || !c->lrms || !c->prms || !c->csac || !c->csf || !c->map || !c->band_first ||
      !c->band_count || !c->floor || !c->chi2 || !c->magonly)
    return rcb_cmp_fail(c, RCB_ERR_NOMEM, "out of memory for the comparison results");
  return RCB_OK;
}

static rcb_status copy_meas(rcb_compare *c, const rcb_meas *ms) {
  size_t k, len = 0, pos = 0;
  rcb_meas_channel_info ci;
  rcb_status st;
  if ((st = alloc_results(c))) return st;
  memcpy(c->grid, rcb_meas_grid(ms), c->npts * sizeof *c->grid);
  for (k = 0; k < c->nch; k++) {
    rcb_meas_channel(ms, k, &ci);
    len += strlen(ci.response) + 1 + (ci.reference ? strlen(ci.reference) + 1 : 0);
  }
  if (!(c->names = rcb_alloc(&c->alloc, len ? len : 1)))
    return rcb_cmp_fail(c, RCB_ERR_NOMEM, "out of memory");
  for (k = 0; k < c->nch; k++) {
    rcb_meas_channel(ms, k, &ci);
    c->kind[k] = ci.kind;
    c->magonly[k] = ci.magnitude_only;
    memcpy(c->meas + k * c->npts, ci.data, c->npts * sizeof *c->meas);
    strcpy(c->names + pos, ci.response);
    c->resp[k] = c->names + pos;
    pos += strlen(ci.response) + 1;
    c->ref[k] = NULL;
    if (ci.reference && c->type != RCB_MEAS_UNBALANCE) {
      strcpy(c->names + pos, ci.reference);
      c->ref[k] = c->names + pos;
      pos += strlen(ci.reference) + 1;
    }
  }
  return RCB_OK;
}

/* ---- metrics ---- */

static int usable(double complex e, double complex m) {
  return isfinite(creal(e)) && isfinite(cimag(e)) && isfinite(creal(m)) && isfinite(cimag(m));
}

/* log10 magnitude error of one point, or NaN when either magnitude is 0. */
static double log_err(double complex e, double complex m) {
  double ae = cabs(e), am = cabs(m);
  if (!(ae > 0) || !(am > 0)) return (double)NAN;
  return log10(am) - log10(ae);
}

static double phase_err_deg(double complex e, double complex m) {
  double d = carg(m) - carg(e);
  while (d > RCB_PI) d -= 2.0 * RCB_PI;
  while (d <= -RCB_PI) d += 2.0 * RCB_PI;
  return d * 180.0 / RCB_PI;
}

/* Running sums of the channel measures. */
typedef struct sums {
  double num, den, ee, mm, l2, p2;
  double complex em;
  size_t nl, np;
} sums;

/* A point of a channel; @p phase 0 for magnitudes only: the measures that
 * need the phase (FRAC, the phase error) leave it out. */
static void add_point(sums *s, double complex e, double complex m, int phase) {
  double ae = cabs(e), am = cabs(m), l;
  s->num += (am - ae) * (am - ae);
  s->den += ae * ae;
  l = log_err(e, m);
  if (isfinite(l)) {
    s->l2 += l * l;
    s->nl++;
  }
  if (!phase) return;
  s->ee += ae * ae;
  s->mm += am * am;
  s->em += conj(e) * m;
  if (ae > 0 && am > 0) {
    double p = phase_err_deg(e, m);
    s->p2 += p * p;
    s->np++;
  }
}

/* Noise floor % and chi-square per degree of freedom of channel k (all
 * channels for k == nch) from the known sds: NaN without them. */
static void sd_metrics(const rcb_compare *c, size_t k, double *floor_pct, double *chi2) {
  double s2 = 0.0, e2 = 0.0, x2 = 0.0;
  size_t n = 0, k0 = k < c->nch ? k : 0, k1 = k < c->nch ? k + 1 : c->nch, i;
  *floor_pct = *chi2 = (double)NAN;
  if (!c->sd) return;
  for (k = k0; k < k1; k++)
    for (i = 0; i < c->npts; i++) {
      rcb_complex e = c->meas[k * c->npts + i], m = c->model[k * c->npts + i], d = m - e;
      double sd = c->sd[k * c->npts + i];
      if (!usable(e, m) || !(sd > 0)) continue;
      s2 += sd * sd;
      e2 += creal(e * conj(e));
      /* magnitudes only: one degree of freedom, (|m| - |e|) of variance sd^2,
       * counted twice against the 2 n of the complex points */
      if (c->magonly[k])
        x2 += 2.0 * (cabs(m) - cabs(e)) * (cabs(m) - cabs(e)) / (sd * sd);
      else
        x2 += creal(d * conj(d)) / (sd * sd);
      n++;
    }
  if (e2 > 0) *floor_pct = 100.0 * sqrt(s2 / e2);
  if (n) *chi2 = x2 / (2.0 * (double)n);
}

static void channel_metrics(rcb_compare *c) {
  sums all;
  size_t k, i, nfrac = 0;
  double fsum = 0.0;
  memset(&all, 0, sizeof all);
  for (k = 0; k < c->nch; k++) {
    const rcb_complex *e = c->meas + k * c->npts, *m = c->model + k * c->npts;
    sums s;
    double cem;
    memset(&s, 0, sizeof s);
    for (i = 0; i < c->npts; i++) {
      if (!usable(e[i], m[i])) continue;
      add_point(&s, e[i], m[i], !c->magonly[k]);
      add_point(&all, e[i], m[i], !c->magonly[k]);
    }
    cem = cabs(s.em);
    c->err[k] = s.den > 0 ? 100.0 * sqrt(s.num / s.den) : (double)NAN;
    c->frac[k] = s.ee > 0 && s.mm > 0 ? cem * cem / (s.ee * s.mm) : (double)NAN;
    c->lrms[k] = s.nl ? sqrt(s.l2 / (double)s.nl) : (double)NAN;
    c->prms[k] = s.np ? sqrt(s.p2 / (double)s.np) : (double)NAN;
    if (!c->magonly[k]) fsum += c->frac[k], nfrac++;
    sd_metrics(c, k, &c->floor[k], &c->chi2[k]);
  }
  sd_metrics(c, c->nch, &c->sum.floor_pct, &c->sum.chi2_dof);
  c->sum.error_pct = all.den > 0 ? 100.0 * sqrt(all.num / all.den) : (double)NAN;
  c->sum.frac_mean = nfrac ? fsum / (double)nfrac : (double)NAN; /* channels with phase */
  c->sum.log_rms = all.nl ? sqrt(all.l2 / (double)all.nl) : (double)NAN;
  c->sum.phase_rms_deg = all.np ? sqrt(all.p2 / (double)all.np) : (double)NAN;
}

/* CSAC and CSF across channels at each point. */
static void point_metrics(rcb_compare *c) {
  size_t i, k, n = 0;
  double s_ac = 0.0, s_sf = 0.0;
  for (i = 0; i < c->npts; i++) {
    double ee = 0.0, mm = 0.0, a;
    double complex em = 0.0;
    size_t used = 0;
    for (k = 0; k < c->nch; k++) {
      double complex e = c->meas[k * c->npts + i], m = c->model[k * c->npts + i];
      if (!usable(e, m) || c->magonly[k]) continue; /* CSAC, CSF need the phase */
      ee += creal(conj(e) * e);
      mm += creal(conj(m) * m);
      em += conj(e) * m;
      used++;
    }
    a = cabs(em);
    c->csac[i] = used && ee > 0 && mm > 0 ? a * a / (ee * mm) : (double)NAN;
    c->csf[i] = used && ee + mm > 0 ? 2.0 * a / (ee + mm) : (double)NAN;
    if (isfinite(c->csac[i]) && isfinite(c->csf[i])) {
      s_ac += c->csac[i];
      s_sf += c->csf[i];
      n++;
    }
  }
  c->sum.csac_mean = n ? s_ac / (double)n : (double)NAN;
  c->sum.csf_mean = n ? s_sf / (double)n : (double)NAN;
}

static void band_map(rcb_compare *c) {
  size_t b, k, i;
  for (b = 0; b < c->nbands; b++) {
    size_t i0 = b * c->npts / c->nbands, i1 = (b + 1) * c->npts / c->nbands;
    c->band_first[b] = i0;
    c->band_count[b] = i1 - i0;
    for (k = 0; k < c->nch; k++) {
      double s = 0.0;
      size_t n = 0;
      for (i = i0; i < i1; i++) {
        double l = log_err(c->meas[k * c->npts + i], c->model[k * c->npts + i]);
        if (!isfinite(l)) continue;
        s += l * l;
        n++;
      }
      c->map[k + c->nch * b] = n ? sqrt(s / (double)n) : (double)NAN;
    }
  }
}

/* ---- run ---- */

static rcb_status model_sweep(rcb_compare *c, rcb_cmp_eval *ev) {
  size_t i, k;
  rcb_status st;
  rcb_complex *col = rcb_alloc(&c->alloc, c->nch * sizeof *col);
  if (!col) return rcb_cmp_fail(c, RCB_ERR_NOMEM, "out of memory");
  for (i = 0; i < c->npts; i++) {
    if ((st = rcb_cmp_model_at(c, ev, c->grid[i], col))) {
      rcb_free(&c->alloc, col);
      return st;
    }
    for (k = 0; k < c->nch; k++) c->model[k * c->npts + i] = col[k];
  }
  rcb_free(&c->alloc, col);
  return RCB_OK;
}

rcb_status rcb_compare_run(rcb_compare *c, const rcb_model *m, const rcb_meas *ms) {
  rcb_cmp_eval ev;
  rcb_status st;
  if (!c) return RCB_ERR_ARG;
  free_results(c);
  c->errmsg[0] = '\0';
  if (!m || !ms) return rcb_cmp_fail(c, RCB_ERR_ARG, "no model or no measurement given");
  if (rcb_model_dof_count(m) == 0)
    return rcb_cmp_fail(c, RCB_ERR_STATE, "the model is not finalized");
  c->type = rcb_meas_get_type(ms);
  c->speed = rcb_meas_speed(ms);
  c->npts = rcb_meas_point_count(ms);
  c->nch = rcb_meas_channel_count(ms);
  if (c->npts == 0 || c->nch == 0) {
    c->npts = c->nch = 0;
    return rcb_cmp_fail(c, RCB_ERR_ARG,
                        "the measurement is empty (%zu points, %zu channels); expected at "
                        "least one channel with one point", rcb_meas_point_count(ms),
                        rcb_meas_channel_count(ms));
  }
  if (c->sd && c->nsd != c->nch * c->npts) {
    size_t nsd = c->nsd, nch = c->nch, npts = c->npts;
    c->npts = c->nch = 0;
    return rcb_cmp_fail(c, RCB_ERR_ARG,
                        "%zu standard deviations set (rcb_compare_set_sd) for a measurement "
                        "of %zu channels x %zu points: expected %zu", nsd, nch, npts,
                        nch * npts);
  }
  c->nbands = c->nbands_req < c->npts ? c->nbands_req : c->npts;
  memset(&ev, 0, sizeof ev);
  ev.m = m;
  if (!(st = copy_meas(c, ms)) && !(st = eval_setup(c, ms, &ev)) && !(st = model_sweep(c, &ev))) {
    channel_metrics(c);
    point_metrics(c);
    band_map(c);
    if (!(st = rcb_cmp_outliers(c))) st = rcb_cmp_peaks(c, &ev);
  }
  eval_free(c, &ev);
  if (st) {
    char keep[RCB_ERRMSG_MAX];
    memcpy(keep, c->errmsg, sizeof keep);
    free_results(c);
    memcpy(c->errmsg, keep, sizeof keep);
    return st;
  }
  c->done = 1;
  return RCB_OK;
}

/* ---- results ---- */

size_t rcb_compare_channel_count(const rcb_compare *c) { return c && c->done ? c->nch : 0; }
size_t rcb_compare_point_count(const rcb_compare *c) { return c && c->done ? c->npts : 0; }
size_t rcb_compare_band_count(const rcb_compare *c) { return c && c->done ? c->nbands : 0; }
size_t rcb_compare_peak_count(const rcb_compare *c) { return c && c->done ? c->npeaks : 0; }
rcb_meas_type rcb_compare_type(const rcb_compare *c) {
  return c ? c->type : RCB_MEAS_FRF;
}
const double *rcb_compare_grid(const rcb_compare *c) { return c && c->done ? c->grid : NULL; }
const double *rcb_compare_csac(const rcb_compare *c) { return c && c->done ? c->csac : NULL; }
const double *rcb_compare_csf(const rcb_compare *c) { return c && c->done ? c->csf : NULL; }
const double *rcb_compare_residual_map(const rcb_compare *c) {
  return c && c->done ? c->map : NULL;
}

rcb_status rcb_compare_get_channel(const rcb_compare *c, size_t i, rcb_compare_channel *out) {
  if (!c || !out || !c->done || i >= c->nch) return RCB_ERR_ARG;
  out->response = c->resp[i];
  out->reference = c->ref[i];
  out->kind = c->kind[i];
  out->error_pct = c->err[i];
  out->frac = c->frac[i];
  out->log_rms = c->lrms[i];
  out->phase_rms_deg = c->prms[i];
  out->floor_pct = c->floor[i];
  out->chi2_dof = c->chi2[i];
  out->magnitude_only = c->magonly[i];
  out->meas = c->meas + i * c->npts;
  out->model = c->model + i * c->npts;
  return RCB_OK;
}

rcb_status rcb_compare_get_summary(const rcb_compare *c, rcb_compare_summary *out) {
  if (!c || !out || !c->done) return RCB_ERR_ARG;
  *out = c->sum;
  return RCB_OK;
}

rcb_status rcb_compare_band(const rcb_compare *c, size_t b, double *lo, double *hi,
                            size_t *first, size_t *count) {
  if (!c || !c->done || b >= c->nbands) return RCB_ERR_ARG;
  if (lo) *lo = c->grid[c->band_first[b]];
  if (hi) *hi = c->grid[c->band_first[b] + c->band_count[b] - 1];
  if (first) *first = c->band_first[b];
  if (count) *count = c->band_count[b];
  return RCB_OK;
}

rcb_status rcb_compare_get_peak(const rcb_compare *c, size_t i, rcb_compare_peak *out) {
  if (!c || !out || !c->done || i >= c->npeaks) return RCB_ERR_ARG;
  *out = c->peaks[i];
  return RCB_OK;
}
