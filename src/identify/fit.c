/*
 * Fit set-up and the public fit API: channels resolved against the model,
 * parameters by name, the residual layout (band, weights, noise model),
 * running the chosen optimiser, and the results.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "identify/fit_internal.h"
#include "io/io.h"

/* Channels -> FRF outputs and inputs (the resolver shared with the
 * comparison), and the kind of each channel's values. */
static rcb_status resolve_channels(rcb_fit *f, rcb_dof *outs, rcb_dof *ins) {
  rcb_meas_dofs d;
  size_t c;
  rcb_status st;
  d.ch_out = f->ch_out, d.ch_in = f->ch_in, d.outs = outs, d.ins = ins;
  if ((st = rcb_meas_resolve_dofs(f->meas, f->m, &d, f->errmsg))) return st;
  f->nout = d.nout, f->nin = d.nin;
  for (c = 0; c < f->nch; c++) {
    rcb_meas_channel_info ci;
    if (rcb_meas_channel(f->meas, c, &ci)) return rcb_fit_fail(f, RCB_ERR_ARG, "channel %zu", c);
    f->ch_kind[c] = ci.kind;
  }
  return RCB_OK;
}

/* The FRF object of f with solver s (fit_setup: RCB_SOLVER_AUTO). */
static rcb_status make_frf(rcb_fit *f, rcb_dof *outs, rcb_dof *ins, rcb_solver_kind s) {
  rcb_status st = rcb_frf_create(&f->frf, f->m, f->nout, outs, f->nin, ins, s, &f->alloc);
  if (st) return rcb_fit_fail(f, st, "FRF workspace: %s", rcb_status_str(st));
  /* the iterations run without the condition check; the final
   * evaluation has it (rcb_fit_run) */
  rcb_frf_set_condition_check(f->frf, RCB_COND_OFF, RCB_RCOND_WARN);
  return RCB_OK;
}

rcb_solver_kind rcb_fit_get_solver(const rcb_fit *f) {
  return f && f->frf ? rcb_frf_solver(f->frf) : RCB_SOLVER_AUTO;
}

rcb_status rcb_fit_set_solver(rcb_fit *f, rcb_solver_kind s) {
  rcb_dof *outs, *ins;
  rcb_status st;
  if (!f || !f->frf) return RCB_ERR_ARG;
  outs = rcb_alloc(&f->alloc, f->nch * sizeof *outs);
  ins = rcb_alloc(&f->alloc, f->nch * sizeof *ins);
  if (!outs || !ins) st = rcb_fit_fail(f, RCB_ERR_NOMEM, "out of memory");
  else if (!(st = resolve_channels(f, outs, ins))) {
    rcb_fit_chain_reroute(f); /* the resolver wrote every channel's own output */
    rcb_frf_destroy(f->frf);
    f->frf = NULL;
    st = make_frf(f, outs, ins, s);
  }
  rcb_free(&f->alloc, outs);
  rcb_free(&f->alloc, ins);
  return st;
}

static rcb_status fit_setup(rcb_fit *f) {
  size_t nch = f->nch;
  rcb_dof *outs = rcb_alloc(&f->alloc, nch * sizeof *outs);
  rcb_dof *ins = rcb_alloc(&f->alloc, nch * sizeof *ins);
  rcb_status st;
  f->ch_out = rcb_alloc(&f->alloc, nch * sizeof *f->ch_out);
  f->ch_in = rcb_alloc(&f->alloc, nch * sizeof *f->ch_in);
  f->ch_kind = rcb_alloc(&f->alloc, nch * sizeof *f->ch_kind);
  f->Hmod = rcb_alloc(&f->alloc, nch * f->npts * sizeof *f->Hmod);
  f->Hraw = rcb_alloc(&f->alloc, nch * f->npts * sizeof *f->Hraw);
  if (!outs || !ins || !f->ch_out || !f->ch_in || !f->ch_kind || !f->Hmod || !f->Hraw)
    st = rcb_fit_fail(f, RCB_ERR_NOMEM, "out of memory setting up the fit");
  else if (!(st = resolve_channels(f, outs, ins))) {
    st = make_frf(f, outs, ins, RCB_SOLVER_AUTO);
    f->Hwork = rcb_alloc(&f->alloc, f->nout * (f->nin ? f->nin : 1) * sizeof *f->Hwork);
    if (!st && !f->Hwork) st = rcb_fit_fail(f, RCB_ERR_NOMEM, "out of memory");
    if (!st) st = rcb_fit_chain_init(f);
  }
  rcb_free(&f->alloc, outs);
  rcb_free(&f->alloc, ins);
  return st;
}

rcb_status rcb_fit_create(rcb_fit **out, rcb_model *m, const rcb_meas *meas,
                          const rcb_allocator *alloc) {
  rcb_allocator a;
  rcb_fit *f;
  rcb_status st;
  if (!out) return RCB_ERR_ARG;
  *out = NULL;
  if (!m || !meas) return RCB_ERR_ARG;
  if (rcb_model_dof_count(m) == 0) return RCB_ERR_STATE;
  rcb_allocator_init(&a, alloc);
  f = rcb_alloc(&a, sizeof *f);
  if (!f) return RCB_ERR_NOMEM;
  f->alloc = a;
  f->m = m;
  f->meas = meas;
  f->nch = rcb_meas_channel_count(meas);
  f->npts = rcb_meas_point_count(meas);
  f->grid = rcb_meas_grid(meas);
  f->unbalance = rcb_meas_get_type(meas) == RCB_MEAS_UNBALANCE;
  f->speed = rcb_meas_speed(meas);
  f->scale = RCB_SCALE_LINEAR;
  f->band_lo = 0.0;
  f->band_hi = HUGE_VAL;
  f->method = RCB_FIT_PAPER;
  f->analytic = 1;
  f->max_iter = 100;
  f->ftol_rel = 1e-10;
  f->xtol_rel = 1e-8;
  *out = f;
  if (f->nch == 0 || f->npts == 0)
    return rcb_fit_fail(f, RCB_ERR_ARG, "the measurement has no channel or no point");
  st = fit_setup(f);
  return st;
}

void rcb_fit_free_layout(rcb_fit *f) {
  rcb_free(&f->alloc, f->res_ch);
  rcb_free(&f->alloc, f->res_pt);
  rcb_free(&f->alloc, f->res_part);
  rcb_free(&f->alloc, f->res_sqrtw);
  rcb_free(&f->alloc, f->res_meas);
  rcb_free(&f->alloc, f->pt_used);
  rcb_free(&f->alloc, f->J);
  rcb_free(&f->alloc, f->r);
  rcb_free(&f->alloc, f->dmat);
  rcb_free(&f->alloc, f->rhs);
  rcb_free(&f->alloc, f->dF);
  rcb_free(&f->alloc, f->cov);
  rcb_free(&f->alloc, f->corr);
  rcb_free(&f->alloc, f->pt_first);
  rcb_free(&f->alloc, f->pt_res);
  f->pt_first = f->pt_res = NULL;
  f->res_ch = f->res_pt = NULL;
  f->res_part = f->pt_used = NULL;
  f->res_sqrtw = f->res_meas = f->J = f->r = f->dmat = f->cov = f->corr = NULL;
  f->rhs = f->dF = NULL;
  f->nres = 0;
  f->prepared = 0;
}

void rcb_fit_destroy(rcb_fit *f) {
  rcb_allocator a;
  if (!f) return;
  a = f->alloc;
  rcb_fit_free_layout(f);
  rcb_frf_destroy(f->frf);
  rcb_free(&a, f->ch_out);
  rcb_free(&a, f->ch_in);
  rcb_free(&a, f->ch_kind);
  rcb_free(&a, f->Hmod);
  rcb_free(&a, f->Hraw);
  rcb_free(&a, f->sens);
  rcb_free(&a, f->ch_sens);
  rcb_free(&a, f->ch_fac);
  rcb_free(&a, f->Hwork);
  rcb_free(&a, f->wuser);
  rcb_free(&a, f->sd);
  rcb_free(&a, f->nref);
  rcb_free(&a, f->par);
  rcb_free(&a, f);
}

const char *rcb_fit_errmsg(const rcb_fit *f) { return f ? f->errmsg : "no fit object"; }

/* ---- settings ---- */

rcb_status rcb_fit_add_param(rcb_fit *f, const char *name, double lo, double hi,
                             int log_param) {
  rcb_fit_par *p;
  double v;
  size_t k;
  rcb_status st;
  if (!f || !name) return RCB_ERR_ARG;
  if (strlen(name) >= RCB_PARAM_NAME_MAX)
    return rcb_fit_fail(f, RCB_ERR_ARG, "parameter name '%s' too long", name);
  if (rcb_fit_param_is_chain(name)) { /* a sensor's: RCB_ERR_ARG when not measured */
    if ((st = rcb_fit_name_value(f, name, &v))) return st;
  } else if (rcb_model_get_param(f->m, name, &v)) {
    return rcb_fit_fail(f, RCB_ERR_NOT_FOUND, "parameter: %s", rcb_model_errmsg(f->m));
  }
  for (k = 0; k < f->np; k++)
    if (strcmp(f->par[k].name, name) == 0)
      return rcb_fit_fail(f, RCB_ERR_ARG, "parameter '%s' is given twice", name);
  if (!isfinite(lo) || !isfinite(hi) || !(lo < hi))
    return rcb_fit_fail(f, RCB_ERR_ARG, "parameter '%s': bounds [%g, %g], expected lo < hi",
                        name, lo, hi);
  if (log_param && !(lo > 0))
    return rcb_fit_fail(f, RCB_ERR_ARG,
                        "parameter '%s': log parametrisation needs a lower bound > 0, got %g",
                        name, lo);
  if (v < lo || v > hi)
    return rcb_fit_fail(f, RCB_ERR_ARG,
                        "parameter '%s': start value %g is outside the bounds [%g, %g]", name,
                        v, lo, hi);
  if (rcb_grow(&f->alloc, (void **)&f->par, &f->cap_par, f->np + 1, sizeof *f->par))
    return rcb_fit_fail(f, RCB_ERR_NOMEM, "out of memory");
  rcb_fit_free_layout(f); /* sized by the parameter count */
  p = &f->par[f->np++];
  memset(p, 0, sizeof *p);
  snprintf(p->name, sizeof p->name, "%s", name);
  p->lo = lo;
  p->hi = hi;
  p->log_param = log_param;
  p->start = p->value = v;
  p->scale = v != 0.0 ? fabs(v) : (fabs(lo) > fabs(hi) ? fabs(lo) : fabs(hi));
  p->identifiable = 1;
  if (rcb_fit_param_is_chain(name)) rcb_fit_chain_param(f, p); /* found above */
  f->prepared = 0;
  return RCB_OK;
}

/* The complex scale needs the phase: a measurement channel of magnitudes
 * only (rcb_meas_add_channel_mag) is refused on it, naming the channel and
 * the scales that take it (issue #35 item 4). */
static rcb_status phase_check(rcb_fit *f, rcb_fit_scale scale) {
  size_t c;
  rcb_meas_channel_info ci;
  if (scale != RCB_SCALE_COMPLEX || rcb_meas_magnitude_only_count(f->meas) == 0) return RCB_OK;
  for (c = 0; rcb_meas_channel(f->meas, c, &ci) == RCB_OK && !ci.magnitude_only; c++) continue;
  return rcb_fit_fail(f, RCB_ERR_ARG, "the complex scale fits Re and Im and so needs the "
                      "phase, but measurement channel %zu (%s%s%s) holds magnitudes only (%zu "
                      "of %zu channels); fit on the log10, linear or dB scale", c + 1,
                      ci.response, ci.reference ? "/" : "", ci.reference ? ci.reference : "",
                      rcb_meas_magnitude_only_count(f->meas), rcb_meas_channel_count(f->meas));
}

rcb_status rcb_fit_set_scale(rcb_fit *f, rcb_fit_scale scale) {
  rcb_status st;
  if (!f || (int)scale < 0 || (int)scale > 3) return RCB_ERR_ARG;
  if ((st = phase_check(f, scale))) return st;
  f->scale = scale;
  f->prepared = 0;
  return RCB_OK;
}

rcb_status rcb_fit_set_band(rcb_fit *f, double lo, double hi) {
  if (!f) return RCB_ERR_ARG;
  if (!(lo >= 0) || !(hi > lo))
    return rcb_fit_fail(f, RCB_ERR_ARG, "band [%g, %g] rad/s: expected 0 <= lo < hi", lo, hi);
  f->band_lo = lo;
  f->band_hi = hi;
  f->prepared = 0;
  return RCB_OK;
}

rcb_status rcb_fit_set_weights(rcb_fit *f, const double *w) {
  size_t i, n;
  if (!f) return RCB_ERR_ARG;
  n = f->nch * f->npts;
  if (!w) {
    rcb_free(&f->alloc, f->wuser);
    f->wuser = NULL;
    f->prepared = 0;
    return RCB_OK;
  }
  for (i = 0; i < n; i++)
    if (!isfinite(w[i]) || w[i] < 0)
      return rcb_fit_fail(f, RCB_ERR_ARG, "weight %zu = %g: expected a finite value >= 0", i,
                          w[i]);
  if (!f->wuser && !(f->wuser = rcb_alloc(&f->alloc, n * sizeof *f->wuser)))
    return rcb_fit_fail(f, RCB_ERR_NOMEM, "out of memory");
  memcpy(f->wuser, w, n * sizeof *w);
  f->prepared = 0;
  return RCB_OK;
}

rcb_status rcb_fit_set_sd(rcb_fit *f, const double *sd) {
  size_t i, n;
  if (!f) return RCB_ERR_ARG;
  n = f->nch * f->npts;
  if (!sd) {
    rcb_free(&f->alloc, f->sd);
    f->sd = NULL;
    f->prepared = 0;
    return RCB_OK;
  }
  if (f->beta_a > 0 || f->beta_s > 0)
    return rcb_fit_fail(f, RCB_ERR_ARG, "standard deviations and the noise model: give one "
                        "or the other (both set the weights)");
  for (i = 0; i < n; i++)
    if (sd[i] < 0)
      return rcb_fit_fail(f, RCB_ERR_ARG, "standard deviation %zu (channel %zu, point %zu) = "
                          "%g: expected >= 0 (0 or NaN drops the point)", i, i / f->npts,
                          i % f->npts, sd[i]);
  if (!f->sd && !(f->sd = rcb_alloc(&f->alloc, n * sizeof *f->sd)))
    return rcb_fit_fail(f, RCB_ERR_NOMEM, "out of memory");
  memcpy(f->sd, sd, n * sizeof *sd);
  f->prepared = 0;
  return RCB_OK;
}

rcb_status rcb_fit_set_noise_model(rcb_fit *f, double beta_a, double beta_s) {
  if (!f) return RCB_ERR_ARG;
  if (f->sd && (beta_a > 0 || beta_s > 0))
    return rcb_fit_fail(f, RCB_ERR_ARG, "the noise model and standard deviations: give one "
                        "or the other (both set the weights)");
  if (!(beta_a >= 0) || !(beta_s >= 0) || !isfinite(beta_a) || !isfinite(beta_s))
    return rcb_fit_fail(f, RCB_ERR_ARG, "noise factors %g %%, %g %%: expected >= 0", beta_a,
                        beta_s);
  f->beta_a = beta_a;
  f->beta_s = beta_s;
  f->prepared = 0;
  return RCB_OK;
}

rcb_status rcb_fit_set_noise_phase(rcb_fit *f, double phase_rad) {
  if (!f) return RCB_ERR_ARG;
  if (!(phase_rad >= 0) || !isfinite(phase_rad) || phase_rad > RCB_PI)
    return rcb_fit_fail(f, RCB_ERR_ARG, "phase noise %g rad (%g deg): expected 0 to pi rad",
                        phase_rad, phase_rad * 180.0 / RCB_PI);
  f->phase = phase_rad;
  f->prepared = 0;
  return RCB_OK;
}

double rcb_fit_get_noise_phase(const rcb_fit *f) { return f ? f->phase : (double)NAN; }

rcb_status rcb_fit_set_noise_reference(rcb_fit *f, const rcb_complex *h) {
  size_t n;
  if (!f) return RCB_ERR_ARG;
  n = f->nch * f->npts;
  if (!h) {
    rcb_free(&f->alloc, f->nref);
    f->nref = NULL;
    f->prepared = 0;
    return RCB_OK;
  }
  if (!f->nref && !(f->nref = rcb_alloc(&f->alloc, (n ? n : 1) * sizeof *f->nref)))
    return rcb_fit_fail(f, RCB_ERR_NOMEM, "out of memory");
  memcpy(f->nref, h, n * sizeof *h);
  f->prepared = 0;
  return RCB_OK;
}

rcb_status rcb_fit_predictions(rcb_fit *f, rcb_complex *h) {
  size_t c, i;
  rcb_status st;
  if (!f || !h) return RCB_ERR_ARG;
  if ((st = rcb_fit_prepare(f)) || (st = rcb_fit_eval(f, f->r))) return st;
  for (c = 0; c < f->nch; c++)
    for (i = 0; i < f->npts; i++)
      h[c * f->npts + i] = f->pt_used[i] ? f->Hmod[c * f->npts + i] : CMPLX(NAN, NAN);
  return RCB_OK;
}

rcb_status rcb_fit_set_method(rcb_fit *f, rcb_fit_method method, const char *algorithm) {
  if (!f || ((int)method != 0 && (int)method != 1)) return RCB_ERR_ARG;
  f->method = method;
  snprintf(f->algorithm, sizeof f->algorithm, "%s", algorithm ? algorithm : "");
  return RCB_OK;
}

rcb_status rcb_fit_set_analytic(rcb_fit *f, int analytic) {
  if (!f) return RCB_ERR_ARG;
  f->analytic = analytic != 0;
  return RCB_OK;
}

rcb_status rcb_fit_set_limits(rcb_fit *f, size_t max_iter, double ftol_rel, double xtol_rel) {
  if (!f || max_iter == 0 || !(ftol_rel >= 0) || !(xtol_rel >= 0)) return RCB_ERR_ARG;
  f->max_iter = max_iter;
  f->ftol_rel = ftol_rel;
  f->xtol_rel = xtol_rel;
  return RCB_OK;
}

rcb_status rcb_fit_set_progress(rcb_fit *f,
                                int (*cb)(void *user, size_t iter, size_t evals,
                                          double objective),
                                void *user) {
  if (!f) return RCB_ERR_ARG;
  f->progress = cb;
  f->progress_user = user;
  return RCB_OK;
}

rcb_status rcb_fit_set_uncertainty(rcb_fit *f, int compute) {
  if (!f) return RCB_ERR_ARG;
  f->no_uncertainty = !compute;
  return RCB_OK;
}

/* ---- getters (NLopt's set/get pairing) ---- */

rcb_status rcb_fit_get_param_bounds(const rcb_fit *f, size_t k, double *lo, double *hi,
                                    int *log_param) {
  if (!f || k >= f->np) return RCB_ERR_ARG;
  if (lo) *lo = f->par[k].lo;
  if (hi) *hi = f->par[k].hi;
  if (log_param) *log_param = f->par[k].log_param;
  return RCB_OK;
}

rcb_fit_scale rcb_fit_get_scale(const rcb_fit *f) { return f ? f->scale : RCB_SCALE_LINEAR; }

rcb_status rcb_fit_get_band(const rcb_fit *f, double *lo, double *hi) {
  if (!f || !lo || !hi) return RCB_ERR_ARG;
  *lo = f->band_lo, *hi = f->band_hi;
  return RCB_OK;
}

int rcb_fit_get_weights(const rcb_fit *f, double *w) {
  size_t i, n;
  if (!f || !w) return RCB_ERR_ARG;
  n = f->nch * f->npts;
  if (f->wuser) {
    memcpy(w, f->wuser, n * sizeof *w);
    return 1;
  }
  for (i = 0; i < n; i++) w[i] = 1.0;
  return 0;
}

int rcb_fit_get_sd(const rcb_fit *f, double *sd) {
  if (!f || !sd) return RCB_ERR_ARG;
  if (!f->sd) return 0;
  memcpy(sd, f->sd, f->nch * f->npts * sizeof *sd);
  return 1;
}

rcb_status rcb_fit_get_noise_model(const rcb_fit *f, double *beta_a, double *beta_s) {
  if (!f || !beta_a || !beta_s) return RCB_ERR_ARG;
  *beta_a = f->beta_a, *beta_s = f->beta_s;
  return RCB_OK;
}

rcb_fit_method rcb_fit_get_method(const rcb_fit *f, const char **algorithm) {
  if (algorithm) *algorithm = f ? f->algorithm : "";
  return f ? f->method : RCB_FIT_PAPER;
}

int rcb_fit_get_analytic(const rcb_fit *f) { return f ? f->analytic : 1; }

rcb_status rcb_fit_get_limits(const rcb_fit *f, size_t *max_iter, double *ftol_rel,
                              double *xtol_rel) {
  if (!f) return RCB_ERR_ARG;
  if (max_iter) *max_iter = f->max_iter;
  if (ftol_rel) *ftol_rel = f->ftol_rel;
  if (xtol_rel) *xtol_rel = f->xtol_rel;
  return RCB_OK;
}

rcb_status rcb_fit_get_progress(const rcb_fit *f,
                                int (**cb)(void *user, size_t iter, size_t evals,
                                           double objective),
                                void **user) {
  if (!f || !cb || !user) return RCB_ERR_ARG;
  *cb = f->progress, *user = f->progress_user;
  return RCB_OK;
}

rcb_status rcb_fit_get_starts(const rcb_fit *f, size_t *n, uint64_t *seed) {
  if (!f || !n || !seed) return RCB_ERR_ARG;
  *n = f->nstarts ? f->nstarts : 1, *seed = f->seed;
  return RCB_OK;
}

size_t rcb_fit_get_first_start(const rcb_fit *f) { return f ? f->first_start : 0; }

int rcb_fit_get_uncertainty(const rcb_fit *f) { return f ? !f->no_uncertainty : 1; }

/* ---- run and results ---- */

rcb_status rcb_fit_set_starts(rcb_fit *f, size_t n, uint64_t seed) {
  if (!f || n == 0) return RCB_ERR_ARG;
  f->nstarts = n;
  f->seed = seed;
  f->rng = seed * 0x9E3779B97F4A7C15ull + 1ull;
  return RCB_OK;
}

rcb_status rcb_fit_set_first_start(rcb_fit *f, size_t first) {
  if (!f) return RCB_ERR_ARG;
  f->first_start = first;
  return RCB_OK;
}

/* Uniform in [0, 1) from a splitmix64 step. */
static double uniform(rcb_fit *f) {
  unsigned long long z = (f->rng += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  z ^= z >> 31;
  return (double)(z >> 11) * (1.0 / 9007199254740992.0);
}

/* A random start within the bounds, in internal coordinates. */
static void random_start(rcb_fit *f, double *x) {
  size_t k;
  for (k = 0; k < f->np; k++) {
    const rcb_fit_par *p = &f->par[k];
    double u = uniform(f);
    x[k] = p->log_param ? log(p->lo) + u * (log(p->hi) - log(p->lo))
                        : (p->lo + u * (p->hi - p->lo)) / p->scale;
  }
}

static int is_unsure(const rcb_fit *f, double err) {
  double floor_pct = rcb_fit_floor_pct(f);
  return !f->converged || (isfinite(floor_pct) && err > 1.5 * floor_pct);
}

/* Run the optimiser from the model's start (unless the caller asked for the
 * random starts only), then from further random starts while the result is
 * unsure; keep the best point in x_best. */
static rcb_status multistart(rcb_fit *f, double *x, double *x_best) {
  size_t s, it = 0, ev = 0, n = f->nstarts ? f->nstarts : 1;
  double best = HUGE_VAL;
  int conv = 0, stall = 0;
  rcb_status st = RCB_OK, first = RCB_OK;
  for (s = f->first_start; s < n; s++) {
    double F;
    if (s > 0) {
      random_start(f, x);
      if ((st = rcb_fit_set_x(f, x))) break;
    }
    f->evaluations = 0;
    f->stalled = 0;
    st = f->method == RCB_FIT_NLOPT ? rcb_fit_run_nlopt(f) : rcb_fit_run_paper(f);
    it += f->iterations, ev += f->evaluations;
    f->starts_used = s + 1 - f->first_start;
    if (st == RCB_ERR_NOMEM) break; /* not a start that failed: the run cannot go on */
    if (st) {
      if (s == f->first_start) first = st;
      continue;
    }
    if ((st = rcb_fit_eval(f, f->r))) break;
    ev++;
    F = rcb_fit_sumsq(f->r, f->nres);
    if (F < best) {
      best = F;
      conv = f->converged;
      stall = f->stalled;
      rcb_fit_get_x(f, x_best);
    }
    if (!is_unsure(f, rcb_fit_error_pct(f))) break;
  }
  f->iterations = it, f->evaluations = ev, f->converged = conv, f->stalled = stall;
  if (st == RCB_ERR_NOMEM) return st; /* even after a start that ended well */
  if (best == HUGE_VAL) return st ? st : first;
  return rcb_fit_set_x(f, x_best);
}

/* A complex-valued objective has local minima where the model's phase is a
 * period away from the measured one; a first stage on log magnitudes brings
 * the parameters into the right basin (continuation). */
static rcb_status log_magnitude_stage(rcb_fit *f, double *x, size_t *it, size_t *ev) {
  rcb_status st;
  double ftol = f->ftol_rel;
  f->scale = RCB_SCALE_LOG10;
  f->prepared = 0;
  f->ftol_rel = ftol > 1e-4 ? ftol : 1e-4; /* the basin is enough here */
  st = rcb_fit_prepare(f);
  if (!st) st = multistart(f, x, x + f->np);
  f->ftol_rel = ftol;
  *it = f->iterations, *ev = f->evaluations;
  f->scale = RCB_SCALE_COMPLEX;
  f->prepared = 0;
  if (!st) st = rcb_fit_prepare(f);
  return st;
}

/* Weights at the model (issue #24). The eq. 19 noise is proportional to the
 * true value, and its variance on the linear and complex scales is
 * (beta_a/100)^2 x^2 / 3 with x the true value's part there. A weight
 * computed from the measured value correlates with that point's own noise
 * (a value pulled towards zero by its noise gets a larger weight), which
 * biases the estimate: on the monitoring rig (8 inertances x 400 lines,
 * 10 %/1 %) by -0.45, +0.56 and -0.43 of the standard errors of kt, kr and
 * ct (2000 linearised replicas), so that the 95 % intervals held the truth
 * in 92-93 % of them. The fix: once fitted, the weights are recomputed at
 * the model's predicted values, and the fit is refined from there, until a
 * pass moves the parameters by less than RCB_REWEIGHT_TOL of their standard
 * errors (each pass moves them about ten times less than the one before: 2,
 * 0.15, 0 at 30 % noise, where the optimiser's own resolution is 0.1), at
 * most RCB_REWEIGHT_MAX passes. On the log scales the proportional part's
 * variance does not depend on the value: the measured weights are kept. */
#define RCB_REWEIGHT_MAX 4
#define RCB_REWEIGHT_TOL 0.25

static int reweights(const rcb_fit *f) {
  return !f->no_uncertainty && f->beta_a > 0 && !f->sd && !f->nref &&
         (f->scale == RCB_SCALE_LINEAR || f->scale == RCB_SCALE_COMPLEX);
}

/* res_sqrtw at the predictions Hmod of the last evaluation (the residuals'
 * set and their user weights unchanged). */
static void weights_at_model(rcb_fit *f) {
  size_t j, c = (size_t)-1;
  double a = 0.0;
  for (j = 0; j < f->nres; j++) {
    size_t pt = f->res_pt[j];
    double wu = f->wuser ? f->wuser[f->res_ch[j] * f->npts + pt] : 1.0;
    double complex h = f->Hmod[f->res_ch[j] * f->npts + pt];
    double v;
    if (f->res_ch[j] != c) a = rcb_fit_noise_level(f, c = f->res_ch[j]); /* as the layout's */
    v = rcb_fit_noise_var(f, h, a, f->res_part[j]);
    if (v > 0 && isfinite(v)) f->res_sqrtw[j] = sqrt(wu / v); /* else the measured one's */
  }
}

/* Refits with the weights at the model until the parameters settle. A
 * pass's move is measured per parameter as |dx_k| sqrt((J^T J)_kk) at the
 * new point: in standard errors when the weights are inverse variances, and
 * never less than the move in standard errors (1 / sqrt((J^T J)_kk) is at
 * most sqrt((J^T J)^-1_kk)), so the test is on the safe side. The weights of
 * the last pass are those at its start (within RCB_REWEIGHT_TOL). */
static rcb_status refit_at_model(rcb_fit *f) {
  size_t pass, k, it = f->iterations, ev = f->evaluations;
  double *x0 = rcb_alloc(&f->alloc, 2 * f->np * sizeof *x0), *x1;
  rcb_status st = RCB_OK;
  if (!x0) return rcb_fit_fail(f, RCB_ERR_NOMEM, "out of memory");
  x1 = x0 + f->np;
  for (pass = 0; pass < RCB_REWEIGHT_MAX && !st; pass++) {
    double move = 0.0;
    rcb_fit_get_x(f, x0);
    if ((st = rcb_fit_eval(f, f->r))) break;
    weights_at_model(f);
    f->wmodel = 1;
    f->evaluations = 0;
    f->stalled = 0;
    f->converged = 0;
    /* a local refinement from the fitted point, whatever the method (a global
     * NLopt method would search its whole box again) */
    st = rcb_fit_run_paper(f);
    it += f->iterations, ev += f->evaluations + 1;
    if (st) break;
    rcb_fit_get_x(f, x1);
    if ((st = rcb_fit_eval_jac(f, f->r, f->J))) break;
    ev++;
    for (k = 0; k < f->np; k++) {
      double jj = 0.0;
      size_t i;
      for (i = 0; i < f->nres; i++) jj += f->J[i + f->nres * k] * f->J[i + f->nres * k];
      if (jj > 0) move = fmax(move, fabs(x1[k] - x0[k]) * sqrt(jj));
    }
    if (move < RCB_REWEIGHT_TOL) break;
  }
  f->iterations = it, f->evaluations = ev;
  rcb_free(&f->alloc, x0);
  return st;
}

/* F at the start on the final weights, so that the report's F0 -> F compares
 * like with like (x: 2 np of workspace; the model is left at the fit). */
static rcb_status objective_at_start(rcb_fit *f, double *x) {
  double *xs = x + f->np;
  size_t k;
  rcb_status st;
  rcb_fit_get_x(f, x);
  for (k = 0; k < f->np; k++) xs[k] = rcb_fit_x_of(f, k, f->par[k].start);
  if ((st = rcb_fit_set_x(f, xs)) || (st = rcb_fit_eval(f, f->r))) return st;
  f->obj0 = rcb_fit_sumsq(f->r, f->nres);
  f->evaluations++;
  return rcb_fit_set_x(f, x);
}

rcb_status rcb_fit_run(rcb_fit *f) {
  rcb_status st;
  size_t k, it0 = 0, ev0 = 0;
  double *x;
  if (!f) return RCB_ERR_ARG;
  if (f->np == 0)
    return rcb_fit_fail(f, RCB_ERR_ARG, "no parameter to fit (add one with --params)");
  if (f->first_start >= (f->nstarts ? f->nstarts : 1))
    return rcb_fit_fail(f, RCB_ERR_ARG, "first start %zu of %zu starting points: nothing to try",
                        f->first_start, f->nstarts ? f->nstarts : 1);
  if ((st = phase_check(f, f->scale))) return st;
  for (k = 0; k < f->np; k++) f->par[k].value = f->par[k].start = rcb_fit_par_get(f, k);
  if (f->wmodel) f->prepared = 0; /* a run starts from the measured weights */
  if ((st = rcb_fit_prepare(f))) return st;
  rcb_frf_refresh(f->frf); /* the caller may have changed the model */
  f->iterations = f->evaluations = 0;
  f->converged = 0;
  f->stop = RCB_FIT_STOP_NONE;
  if ((st = rcb_fit_eval(f, f->r))) return st;
  f->obj0 = rcb_fit_sumsq(f->r, f->nres);
  if ((st = rcb_fit_check_finite(f, f->obj0, "at the start"))) return st;
  f->err0 = rcb_fit_error_pct(f);
  if (!(x = rcb_alloc(&f->alloc, 2 * f->np * sizeof *x)))
    return rcb_fit_fail(f, RCB_ERR_NOMEM, "out of memory");
  st = f->scale == RCB_SCALE_COMPLEX ? log_magnitude_stage(f, x, &it0, &ev0) : RCB_OK;
  if (!st) st = multistart(f, x, x + f->np);
  if (!st && reweights(f)) st = refit_at_model(f);
  if (!st && f->wmodel) st = objective_at_start(f, x);
  f->iterations += it0, f->evaluations += ev0 + 1;
  rcb_free(&f->alloc, x);
  if (st) return st;
  for (k = 0; k < f->np; k++) f->par[k].value = rcb_fit_par_get(f, k);
  /* the final evaluation, with the condition of every solve checked */
  rcb_frf_set_condition_check(f->frf, RCB_COND_SCREEN, RCB_RCOND_WARN);
  st = rcb_fit_eval(f, f->r);
  rcb_frf_get_condition(f->frf, &f->cond);
  rcb_frf_set_condition_check(f->frf, RCB_COND_OFF, RCB_RCOND_WARN);
  if (st) return st;
  f->obj = rcb_fit_sumsq(f->r, f->nres);
  if ((st = rcb_fit_check_finite(f, f->obj, "at the fitted point"))) return st;
  f->err = rcb_fit_error_pct(f);
  st = f->no_uncertainty ? RCB_OK : rcb_fit_uncertainty(f);
  rcb_fit_classify_stop(f);
  return st;
}

rcb_status rcb_fit_get_report(const rcb_fit *f, rcb_fit_report *out) {
  if (!f || !out) return RCB_ERR_ARG;
  out->iterations = f->iterations;
  out->evaluations = f->evaluations;
  out->residuals = f->nres;
  out->objective0 = f->obj0;
  out->objective = f->obj;
  out->error0_pct = f->err0;
  out->error_pct = f->err;
  out->sigma = f->nres > f->np ? sqrt(f->obj / (double)(f->nres - f->np)) : (double)NAN;
  out->converged = f->converged;
  out->floor_pct = rcb_fit_floor_pct(f);
  out->unsure = is_unsure(f, f->err) || f->stop == RCB_FIT_STOP_AT_BOUND;
  out->starts = f->starts_used;
  return RCB_OK;
}

size_t rcb_fit_param_count(const rcb_fit *f) { return f ? f->np : 0; }

size_t rcb_fit_sweeps(const rcb_fit *f) { return f ? f->sweeps : 0; }

rcb_status rcb_fit_get_param(const rcb_fit *f, size_t k, rcb_fit_param *out) {
  const rcb_fit_par *p;
  if (!f || !out || k >= f->np) return RCB_ERR_ARG;
  p = &f->par[k];
  out->name = p->name;
  out->start = p->start;
  out->value = p->value;
  out->stderr_ = p->se;
  out->ci_lo = p->ci_lo;
  out->ci_hi = p->ci_hi;
  out->identifiable = p->identifiable;
  return RCB_OK;
}

rcb_status rcb_fit_correlation(const rcb_fit *f, double *C) {
  if (!f || !C) return RCB_ERR_ARG;
  if (!f->corr) return rcb_fit_fail((rcb_fit *)f, RCB_ERR_STATE, "run the fit first");
  memcpy(C, f->corr, f->np * f->np * sizeof *C);
  return RCB_OK;
}

size_t rcb_fit_residual_count(const rcb_fit *f) {
  if (!f) return 0;
  if (rcb_fit_prepare((rcb_fit *)f)) return 0;
  return f->nres;
}

rcb_status rcb_fit_residuals(rcb_fit *f, double *r) {
  rcb_status st;
  if (!f || !r) return RCB_ERR_ARG;
  if ((st = rcb_fit_prepare(f))) return st;
  rcb_frf_refresh(f->frf);
  return rcb_fit_eval(f, r);
}

rcb_status rcb_fit_error(rcb_fit *f, double *error_pct) {
  rcb_status st;
  if (!f || !error_pct) return RCB_ERR_ARG;
  if ((st = rcb_fit_prepare(f))) return st;
  rcb_frf_refresh(f->frf);
  if ((st = rcb_fit_eval(f, f->r))) return st;
  *error_pct = rcb_fit_error_pct(f);
  return RCB_OK;
}

rcb_status rcb_fit_channel_sensitivity(rcb_fit *f, double *S) {
  size_t *cnt, j, k, c, n;
  double *J;
  rcb_status st;
  if (!f || !S) return RCB_ERR_ARG;
  if ((st = rcb_fit_prepare(f))) return st;
  n = f->nres;
  J = rcb_alloc(&f->alloc, n * (f->np ? f->np : 1) * sizeof *J);
  cnt = rcb_alloc(&f->alloc, f->nch * sizeof *cnt);
  if (!J || !cnt) {
    st = rcb_fit_fail(f, RCB_ERR_NOMEM, "out of memory");
    goto done;
  }
  if ((st = rcb_fit_jacobian(f, f->analytic, J))) goto done;
  memset(S, 0, f->nch * f->np * sizeof *S);
  for (j = 0; j < n; j++) cnt[f->res_ch[j]]++;
  for (k = 0; k < f->np; k++) {
    /* a sensor's phase is neutral at 0, where a relative change says
     * nothing: its figure is per rad */
    double p = f->par[k].chain == RCB_CHAIN_PHASE ? 1.0 : rcb_fit_par_get(f, k);
    for (j = 0; j < n; j++) {
      double v = J[j + n * k] * p / f->res_sqrtw[j]; /* unweighted, relative change */
      if (f->res_sqrtw[j] > 0) S[f->res_ch[j] + f->nch * k] += v * v;
    }
  }
  for (k = 0; k < f->np; k++)
    for (c = 0; c < f->nch; c++)
      S[c + f->nch * k] = cnt[c] ? sqrt(S[c + f->nch * k] / (double)cnt[c]) : 0.0;
done:
  rcb_free(&f->alloc, J);
  rcb_free(&f->alloc, cnt);
  return st;
}

rcb_status rcb_fit_jacobian(rcb_fit *f, int analytic, double *J) {
  rcb_status st;
  int keep;
  size_t k, i;
  if (!f || !J) return RCB_ERR_ARG;
  if ((st = rcb_fit_prepare(f))) return st;
  rcb_frf_refresh(f->frf);
  keep = f->analytic;
  f->analytic = analytic != 0;
  st = rcb_fit_eval_jac(f, f->r, J);
  f->analytic = keep;
  if (st) return st;
  /* d/dx -> d/dp */
  for (k = 0; k < f->np; k++) {
    double dpdx = f->par[k].log_param ? rcb_fit_par_get(f, k) : f->par[k].scale;
    for (i = 0; i < f->nres; i++) J[i + f->nres * k] /= dpdx;
  }
  return RCB_OK;
}
