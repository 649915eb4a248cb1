/*
 * The measurement chain (issue #23, item 4): what a probe does to the
 * response it measures, between the model and the measured values. Each
 * distinct measured response (a channel's response name, "DB.y") has a
 * sensor; every channel with that response is predicted as
 *   H_pred = g0 e^{i phi0} g e^{i phi} H_model(response read),
 * with g0, phi0 a fixed edit (rcb_fit_set_sensor: a sign flip is g0 = -1),
 * g, phi the fitted parameters sensor.<response>.gain and .phase (neutral 1
 * and 0), and the response read the sensor's own unless it is swapped with
 * another measured response (rcb_fit_swap_sensors: the x and y probes of a
 * station exchanged). Phases in rad, positive = the sensor leads.
 *
 * Every path of the fit reads and writes its parameters through
 * rcb_fit_par_get / rcb_fit_par_set, which send the sensor parameters here
 * and the others to the model; the chain reaches the predictions through
 * ch_fac (the factor of each channel) and ch_out (the model output each
 * channel reads), both set by chain_route.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "identify/fit_internal.h"

#define SENSOR_PREFIX "sensor."

/* Channel c's response name. */
static const char *ch_response(const rcb_fit *f, size_t c) {
  rcb_meas_channel_info ci;
  if (rcb_meas_channel(f->meas, c, &ci) || !ci.response) return "";
  return ci.response;
}

static size_t find_sensor(const rcb_fit *f, const char *response) {
  size_t s;
  for (s = 0; s < f->nsens; s++)
    if (strcmp(f->sens[s].response, response) == 0) return s;
  return (size_t)-1;
}

int rcb_fit_param_is_chain(const char *name) {
  size_t n, p = sizeof SENSOR_PREFIX - 1;
  if (!name || strncmp(name, SENSOR_PREFIX, p) != 0) return 0;
  n = strlen(name);
  /* sensor.<response>.gain | .phase with a response of one character at least */
  if (n > p + 5 && strcmp(name + n - 5, ".gain") == 0) return RCB_CHAIN_GAIN;
  if (n > p + 6 && strcmp(name + n - 6, ".phase") == 0) return RCB_CHAIN_PHASE;
  return 0;
}

void rcb_fit_chain_response(const char *name, char *r, size_t size) {
  int which = rcb_fit_param_is_chain(name);
  size_t p = sizeof SENSOR_PREFIX - 1, len;
  if (!size) return;
  r[0] = '\0';
  if (!which) return;
  len = strlen(name) - p - (which == RCB_CHAIN_GAIN ? 5 : 6);
  if (len >= size) len = size - 1;
  memcpy(r, name + p, len);
  r[len] = '\0';
}

int rcb_fit_sensor_param_defaults(const char *name, double *start, double *lo, double *hi,
                                  int *log_param) {
  int which = rcb_fit_param_is_chain(name);
  if (!which) return 0;
  /* a probe off by a factor 10 is a wrong unit or range, not a calibration:
   * the gain's bounds stop there; a phase beyond a quarter period is a
   * sign or a swap (fixed edits), not a lag */
  if (start) *start = which == RCB_CHAIN_GAIN ? 1.0 : 0.0;
  if (lo) *lo = which == RCB_CHAIN_GAIN ? 0.1 : -RCB_PI / 2;
  if (hi) *hi = which == RCB_CHAIN_GAIN ? 10.0 : RCB_PI / 2;
  if (log_param) *log_param = which == RCB_CHAIN_GAIN;
  return which;
}

/* The measured responses, "DA.x, DA.y, ...", into list (cut to size). */
static void list_responses(const rcb_fit *f, char *list, size_t size) {
  size_t s, used = 0;
  list[0] = '\0';
  for (s = 0; s < f->nsens && used + 1 < size; s++) {
    int w = snprintf(list + used, size - used, "%s%s", s ? ", " : "", f->sens[s].response);
    if (w < 0) break;
    used += (size_t)w;
  }
}

/* Every channel's model output (its sensor's, or the swapped partner's) and
 * its factor g0 e^{i phi0} g e^{i phi}. */
static void chain_route(rcb_fit *f) {
  size_t c;
  for (c = 0; c < f->nch; c++) {
    const rcb_fit_sensor *s = &f->sens[f->ch_sens[c]];
    f->ch_out[c] = f->sens[s->swap].out;
    f->ch_fac[c] = s->gain * s->fgain * cexp(CMPLX(0.0, s->phase + s->fphase));
  }
}

rcb_status rcb_fit_chain_init(rcb_fit *f) {
  size_t c, s;
  f->sens = rcb_alloc(&f->alloc, f->nch * sizeof *f->sens);
  f->ch_sens = rcb_alloc(&f->alloc, f->nch * sizeof *f->ch_sens);
  f->ch_fac = rcb_alloc(&f->alloc, f->nch * sizeof *f->ch_fac);
  if (!f->sens || !f->ch_sens || !f->ch_fac)
    return rcb_fit_fail(f, RCB_ERR_NOMEM, "out of memory (measurement chain)");
  f->nsens = 0;
  for (c = 0; c < f->nch; c++) {
    const char *r = ch_response(f, c);
    if ((s = find_sensor(f, r)) == (size_t)-1) {
      rcb_fit_sensor *p = &f->sens[s = f->nsens++];
      p->response = r;
      p->out = f->ch_out[c]; /* the resolver's output, before any swap */
      p->gain = p->fgain = 1.0;
      p->phase = p->fphase = 0.0;
      p->swap = s;
    }
    f->ch_sens[c] = s;
  }
  chain_route(f);
  return RCB_OK;
}

void rcb_fit_chain_reroute(rcb_fit *f) {
  if (f->sens) chain_route(f);
}

/* The sensor a parameter name refers to: RCB_ERR_ARG with a message naming
 * the measured responses when it is none of them. */
static rcb_status chain_lookup(rcb_fit *f, const char *name, int *which, size_t *sensor) {
  char resp[RCB_PARAM_NAME_MAX];
  *which = rcb_fit_param_is_chain(name);
  if (!*which)
    return rcb_fit_fail(f, RCB_ERR_ARG,
                        "parameter '%s': a sensor parameter is sensor.<response>.gain or "
                        "sensor.<response>.phase",
                        name);
  rcb_fit_chain_response(name, resp, sizeof resp);
  if ((*sensor = find_sensor(f, resp)) != (size_t)-1) return RCB_OK;
  {
    char list[RCB_ERRMSG_MAX / 2];
    list_responses(f, list, sizeof list);
    return rcb_fit_fail(f, RCB_ERR_ARG,
                        "parameter '%s': no measured channel has the response '%s' (measured "
                        "responses: %s)",
                        name, resp, list);
  }
}

rcb_status rcb_fit_chain_param(rcb_fit *f, rcb_fit_par *p) {
  int which;
  size_t s;
  rcb_status st = chain_lookup(f, p->name, &which, &s);
  if (st) return st;
  p->chain = which;
  p->sensor = s;
  return RCB_OK;
}

rcb_status rcb_fit_name_value(rcb_fit *f, const char *name, double *v) {
  int which;
  size_t s;
  rcb_status st;
  if (!rcb_fit_param_is_chain(name)) {
    if ((st = rcb_model_get_param(f->m, name, v)))
      return rcb_fit_fail(f, st, "parameter: %s", rcb_model_errmsg(f->m));
    return RCB_OK;
  }
  if ((st = chain_lookup(f, name, &which, &s))) return st;
  *v = which == RCB_CHAIN_GAIN ? f->sens[s].fgain : f->sens[s].fphase;
  return RCB_OK;
}

double rcb_fit_par_get(const rcb_fit *f, size_t k) {
  const rcb_fit_par *p = &f->par[k];
  double v = (double)NAN;
  if (p->chain == RCB_CHAIN_GAIN) return f->sens[p->sensor].fgain;
  if (p->chain == RCB_CHAIN_PHASE) return f->sens[p->sensor].fphase;
  rcb_model_get_param(f->m, p->name, &v); /* checked when the parameter was added */
  return v;
}

rcb_status rcb_fit_par_set(rcb_fit *f, size_t k, double v) {
  const rcb_fit_par *p = &f->par[k];
  rcb_status st;
  if (p->chain) {
    rcb_fit_sensor *s = &f->sens[p->sensor];
    if (!isfinite(v))
      return rcb_fit_fail(f, RCB_ERR_ARG, "setting %s = %g: expected a finite value", p->name,
                          v);
    if (p->chain == RCB_CHAIN_GAIN) s->fgain = v;
    else s->fphase = v;
    chain_route(f);
    return RCB_OK;
  }
  if ((st = rcb_model_set_param(f->m, p->name, v)))
    return rcb_fit_fail(f, st, "setting %s = %g: %s", p->name, v, rcb_model_errmsg(f->m));
  return RCB_OK;
}

/* One sensor parameter's column (which: RCB_CHAIN_GAIN or _PHASE, sensor s)
 * at f's last evaluation, into Jk (nres values, parameter units). */
static void chain_column(const rcb_fit *f, int which, size_t s, double *Jk) {
  const rcb_fit_sensor *p = &f->sens[s];
  double complex u = p->gain * cexp(CMPLX(0.0, p->phase + p->fphase));
  size_t j;
  for (j = 0; j < f->nres; j++) {
    size_t c = f->res_ch[j], idx = c * f->npts + f->res_pt[j];
    double complex dp;
    if (f->ch_sens[c] != s) {
      Jk[j] = 0.0;
      continue;
    }
    dp = which == RCB_CHAIN_GAIN ? u * f->Hraw[idx] : CMPLX(0.0, 1.0) * f->Hmod[idx];
    Jk[j] = rcb_fit_res_deriv_pred(f, j, dp);
  }
}

/* d r_j / d p of the chain parameters (parameter units: per unit of gain,
 * per rad of phase) into their columns of J (nres x np): the prediction
 * P = g0 e^{i(phi0 + phi)} g H, so dP/dg = P / g (taken as g0 e^{i(phi0 +
 * phi)} H, defined at g = 0 too) and dP/dphi = i P. */
void rcb_fit_chain_columns(const rcb_fit *f, double *J) {
  size_t k;
  for (k = 0; k < f->np; k++)
    if (f->par[k].chain) chain_column(f, f->par[k].chain, f->par[k].sensor, J + f->nres * k);
}

rcb_status rcb_fit_chain_jacobian(rcb_fit *f, const char *const *names, size_t n, double *J) {
  size_t k, s;
  int which;
  rcb_status st;
  if (!f || (!names && n) || !J) return RCB_ERR_ARG;
  if (!f->prepared || !f->sweeps)
    return rcb_fit_fail(f, RCB_ERR_STATE, "chain columns: no evaluation of the model yet");
  for (k = 0; k < n; k++) {
    if ((st = chain_lookup(f, names[k], &which, &s))) return st;
    chain_column(f, which, s, J + f->nres * k);
  }
  return RCB_OK;
}

/* The channel of sensor s that reads channel c's reference (and kind):
 * (size_t)-1 when none does (any of s's channels with unbalance responses). */
static size_t partner_channel(const rcb_fit *f, size_t s, size_t c) {
  size_t d;
  for (d = 0; d < f->nch; d++)
    if (f->ch_sens[d] == s && f->ch_kind[d] == f->ch_kind[c] &&
        (f->unbalance || f->ch_in[d] == f->ch_in[c]))
      return d;
  return (size_t)-1;
}

rcb_status rcb_fit_swap_column(rcb_fit *f, const char *a, const char *b, double *J) {
  size_t sa, sb, j, c;
  if (!f || !a || !b || !J) return RCB_ERR_ARG;
  if (!f->prepared || !f->sweeps)
    return rcb_fit_fail(f, RCB_ERR_STATE, "swap column: no evaluation of the model yet");
  sa = find_sensor(f, a), sb = find_sensor(f, b);
  if (sa == (size_t)-1 || sb == (size_t)-1 || sa == sb)
    return rcb_fit_fail(f, RCB_ERR_ARG, "swap column %s, %s: two different measured responses "
                        "expected", a, b);
  if (f->sens[sa].swap != sa || f->sens[sb].swap != sb)
    return rcb_fit_fail(f, RCB_ERR_STATE, "swap column %s, %s: a probe is swapped already", a,
                        b);
  for (c = 0; c < f->nch; c++) /* every channel of the two has its partner */
    if ((f->ch_sens[c] == sa || f->ch_sens[c] == sb) &&
        partner_channel(f, f->ch_sens[c] == sa ? sb : sa, c) == (size_t)-1)
      return rcb_fit_fail(f, RCB_ERR_ARG, "swap column %s, %s: not measured with the same "
                          "references and kinds", a, b);
  for (j = 0; j < f->nres; j++) {
    size_t ch = f->res_ch[j], pt = f->res_pt[j], d;
    size_t s = f->ch_sens[ch];
    if (s != sa && s != sb) {
      J[j] = 0.0;
      continue;
    }
    d = partner_channel(f, s == sa ? sb : sa, ch);
    J[j] = rcb_fit_res_deriv_pred(f, j, f->ch_fac[ch] * (f->Hraw[d * f->npts + pt] -
                                                         f->Hraw[ch * f->npts + pt]));
  }
  return RCB_OK;
}

/* ---- fixed edits (public API) ---- */

rcb_status rcb_fit_set_sensor(rcb_fit *f, const char *response, double gain, double phase_rad) {
  size_t s;
  if (!f || !response) return RCB_ERR_ARG;
  if ((s = find_sensor(f, response)) == (size_t)-1) {
    char list[RCB_ERRMSG_MAX / 2];
    list_responses(f, list, sizeof list);
    return rcb_fit_fail(f, RCB_ERR_ARG,
                        "sensor '%s': no measured channel has that response (measured "
                        "responses: %s)",
                        response, list);
  }
  if (!isfinite(gain) || gain == 0.0 || !isfinite(phase_rad))
    return rcb_fit_fail(f, RCB_ERR_ARG,
                        "sensor '%s': gain %g, phase %g rad: expected a finite, nonzero gain "
                        "and a finite phase",
                        response, gain, phase_rad);
  f->sens[s].gain = gain;
  f->sens[s].phase = phase_rad;
  chain_route(f);
  return RCB_OK;
}

/* 1 when every reference of sensor a's channels is among sensor b's. */
static int refs_within(const rcb_fit *f, size_t a, size_t b) {
  size_t c, d;
  if (f->unbalance) return 1;
  for (c = 0; c < f->nch; c++) {
    int found = 0;
    if (f->ch_sens[c] != a) continue;
    for (d = 0; d < f->nch && !found; d++)
      found = f->ch_sens[d] == b && f->ch_in[d] == f->ch_in[c];
    if (!found) return 0;
  }
  return 1;
}

rcb_status rcb_fit_swap_sensors(rcb_fit *f, const char *a, const char *b) {
  size_t sa, sb;
  if (!f || !a) return RCB_ERR_ARG;
  if ((sa = find_sensor(f, a)) == (size_t)-1 || (b && find_sensor(f, b) == (size_t)-1)) {
    char list[RCB_ERRMSG_MAX / 2];
    list_responses(f, list, sizeof list);
    return rcb_fit_fail(f, RCB_ERR_ARG,
                        "swap %s with %s: no measured channel has the response '%s' (measured "
                        "responses: %s)",
                        a, b ? b : "itself", sa == (size_t)-1 ? a : b, list);
  }
  if (!b || strcmp(a, b) == 0) { /* undo a's swap */
    f->sens[f->sens[sa].swap].swap = f->sens[sa].swap;
    f->sens[sa].swap = sa;
    chain_route(f);
    return RCB_OK;
  }
  sb = find_sensor(f, b); /* found above */
  if (f->sens[sa].swap == sb) return RCB_OK; /* already */
  if (f->sens[sa].swap != sa || f->sens[sb].swap != sb) {
    size_t x = f->sens[sa].swap != sa ? sa : sb;
    return rcb_fit_fail(f, RCB_ERR_ARG,
                        "swap %s with %s: '%s' is swapped with '%s' already (undo with "
                        "rcb_fit_swap_sensors(f, \"%s\", NULL))",
                        a, b, f->sens[x].response, f->sens[f->sens[x].swap].response,
                        f->sens[x].response);
  }
  if (!refs_within(f, sa, sb) || !refs_within(f, sb, sa))
    return rcb_fit_fail(f, RCB_ERR_ARG,
                        "swap %s with %s: the two are not measured with the same references "
                        "(a channel of %s has a reference no channel of %s has)",
                        a, b, refs_within(f, sa, sb) ? b : a, refs_within(f, sa, sb) ? a : b);
  f->sens[sa].swap = sb;
  f->sens[sb].swap = sa;
  chain_route(f);
  return RCB_OK;
}

rcb_status rcb_fit_get_sensor(const rcb_fit *f, const char *response, double *gain,
                              double *phase_rad, const char **swapped_with) {
  size_t s;
  if (!f || !response || (s = find_sensor(f, response)) == (size_t)-1) return RCB_ERR_ARG;
  if (gain) *gain = f->sens[s].gain;
  if (phase_rad) *phase_rad = f->sens[s].phase;
  if (swapped_with) *swapped_with = f->sens[s].swap != s ? f->sens[f->sens[s].swap].response : NULL;
  return RCB_OK;
}

rcb_status rcb_fit_set_chain_value(rcb_fit *f, const char *name, double v) {
  size_t k;
  if (!f || !name) return RCB_ERR_ARG;
  for (k = 0; k < f->np; k++) {
    rcb_fit_par *p = &f->par[k];
    if (!p->chain || strcmp(p->name, name) != 0) continue;
    if (!(v >= p->lo && v <= p->hi))
      return rcb_fit_fail(f, RCB_ERR_ARG, "%s = %g: outside its bounds [%g, %g]", name, v,
                          p->lo, p->hi);
    p->start = p->value = v; /* as rcb_fit_add_param reads a model parameter's */
    return rcb_fit_par_set(f, k, v);
  }
  return rcb_fit_fail(f, RCB_ERR_ARG, "%s: not a sensor parameter of this fit", name);
}

size_t rcb_fit_sensor_count(const rcb_fit *f) { return f ? f->nsens : 0; }

const char *rcb_fit_sensor_response(const rcb_fit *f, size_t k) {
  return f && k < f->nsens ? f->sens[k].response : NULL;
}
