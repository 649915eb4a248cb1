/*
 * Welch estimator: averaged one-sided spectra of p inputs and q outputs, and
 * FRFs (H1, H2, Hv) with coherence and per-line standard deviations.
 *
 * Per segment each channel is detrended (mean), windowed and transformed
 * once; the sums conj(X_i) X_j (p x p), conj(X_i) Y_o (p x q) and |Y_o|^2
 * are accumulated per line. Memory grows as (p^2 + p q + q + p + 1) lines,
 * not as the square of all channels: two outputs are never crossed.
 * Scaling is SciPy's 'density': 2 / (rate sum w^2) per segment average
 * (1 at DC and, for even nseg, at Nyquist), so rcb_spectral_cross equals
 * scipy.signal.csd(x, y, window, nperseg, noverlap) to rounding.
 *
 * Everything sits in the caller's workspace: [object][windows][time buffer]
 * [p + 1 spectra][Gxx][Gxy][Gyy][solve scratch][FFT state], each 16-aligned.
 */
#include <lapacke.h>
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "signals/fft.h"
#include "signals/signals_internal.h"

static size_t al16(size_t b) { return (b + 15) & ~(size_t)15; }

static int opts_ok(const rcb_spectral_opts *o) {
  return o && o->nseg >= 8 && o->noverlap < o->nseg && o->ninputs + o->noutputs >= 1 &&
         o->ninputs <= 64 && o->noutputs <= 4096 && isfinite(o->rate) && o->rate > 0.0 &&
         (unsigned)o->window <= RCB_WINDOW_FORCE_EXP && o->nseg <= ((size_t)1 << 28);
}

/* Bytes of each block, in workspace order; returns the total. */
static size_t layout(const rcb_spectral_opts *o, const rcb_fft_ops *fft, size_t sz[9]) {
  size_t p = o->ninputs, q = o->noutputs, n = o->nseg, nb = n / 2 + 1, i, tot = 16;
  sz[0] = sizeof(struct rcb_spectral);
  sz[1] = 2 * n * sizeof(double);
  sz[2] = n * sizeof(double);
  sz[3] = (p + 1) * nb * sizeof(rcb_complex);
  sz[4] = nb * p * p * sizeof(rcb_complex);
  sz[5] = nb * p * q * sizeof(rcb_complex);
  sz[6] = nb * q * sizeof(double);
  sz[7] = (p * p + p + 1) * sizeof(rcb_complex) + (p + q) * sizeof(double *);
  sz[8] = fft ? fft->state_size(n) : 0;
  for (i = 0; i < 9; i++) tot += al16(sz[i]);
  return tot;
}

rcb_status rcb_spectral_workspace_size(const rcb_spectral_opts *o, size_t *bytes) {
  size_t sz[9];
  const rcb_fft_ops *fft = rcb_fft_backend();
  if (!bytes || !opts_ok(o)) return RCB_ERR_ARG;
  if (!fft) return RCB_ERR_UNSUPPORTED;
  *bytes = layout(o, fft, sz);
  return RCB_OK;
}

/* Overlapped segments are not independent: the variance of an average of
 * many is that of independent ones times 1 + 2 sum_j rho_j^2, rho_j the
 * window's correlation at a shift of j steps (Welch 1967; Bendat & Piersol
 * eq. 11.107): 1.056 for Hann at 50 %, 1.5 for rectangular at 50 %. */
static void overlap_factor(rcb_spectral *e) {
  size_t n = e->o.nseg, step = n - e->o.noverlap, lag, t;
  e->ovl = 1.0;
  for (lag = step; lag < n; lag += step) {
    double r = 0.0;
    for (t = 0; t + lag < n; t++) r += e->win_out[t] * e->win_out[t + lag];
    r /= e->wss;
    e->ovl += 2.0 * r * r;
  }
}

/* SciPy's periodic windows (get_window(..., fftbins=True)). */
static void make_windows(rcb_spectral *e) {
  static const double ft[5] = {0.21557895, 0.41663158, 0.277263158, 0.083578947, 0.006947368};
  size_t n = e->o.nseg, t, k;
  double tau = 0.0;
  if (e->o.window == RCB_WINDOW_FORCE_EXP) {
    double end = e->o.exp_end > 0.0 && e->o.exp_end < 1.0 ? e->o.exp_end : 0.01;
    tau = -(double)(n - 1) / log(end);
  }
  for (t = 0; t < n; t++) {
    double x = 2.0 * RCB_PI * (double)t / (double)n, w = 1.0;
    switch (e->o.window) {
      case RCB_WINDOW_HANN: w = 0.5 - 0.5 * cos(x); break;
      case RCB_WINDOW_FLATTOP:
        for (w = 0.0, k = 0; k < 5; k++) w += (k % 2 ? -1.0 : 1.0) * ft[k] * cos((double)k * x);
        break;
      case RCB_WINDOW_RECT: w = 1.0; break;
      case RCB_WINDOW_FORCE_EXP: w = exp(-(double)t / tau); break;
    }
    e->win_out[t] = w;
    e->win_in[t] = w;
  }
  if (e->o.window == RCB_WINDOW_FORCE_EXP) {
    double frac = e->o.force_frac > 0.0 && e->o.force_frac <= 1.0 ? e->o.force_frac : 0.1;
    for (t = (size_t)ceil(frac * (double)n); t < n; t++) e->win_in[t] = 0.0;
  }
  for (e->wss = 0.0, t = 0; t < n; t++) e->wss += e->win_out[t] * e->win_out[t];
  overlap_factor(e);
}

rcb_status rcb_spectral_init(rcb_spectral **out, const rcb_spectral_opts *o, void *work,
                             size_t bytes) {
  size_t sz[9], need;
  const rcb_fft_ops *fft = rcb_fft_backend();
  unsigned char *p;
  void **slot[9];
  rcb_spectral *e;
  char err[RCB_ERRMSG_MAX];
  size_t i;
  if (!out || !work) return RCB_ERR_ARG;
  *out = NULL;
  if (!opts_ok(o)) return RCB_ERR_ARG;
  if (!fft) return RCB_ERR_UNSUPPORTED;
  need = layout(o, fft, sz);
  if (bytes < need) return RCB_ERR_WORKSPACE;
  p = (unsigned char *)(((uintptr_t)work + 15) & ~(uintptr_t)15);
  memset(p, 0, need - 16);
  e = (rcb_spectral *)(void *)p;
  e->o = *o;
  e->fft = fft;
  e->nb = o->nseg / 2 + 1;
  slot[1] = (void **)&e->win_in;
  slot[2] = (void **)&e->buf;
  slot[3] = (void **)&e->spec;
  slot[4] = (void **)&e->gxx;
  slot[5] = (void **)&e->gxy;
  slot[6] = (void **)&e->gyy;
  slot[7] = (void **)&e->a;
  slot[8] = &e->fft_state;
  p += al16(sz[0]);
  for (i = 1; i < 9; i++) {
    *slot[i] = p;
    p += al16(sz[i]);
  }
  e->win_out = e->win_in + o->nseg;
  e->b = e->a + o->ninputs * o->ninputs;
  e->seg = (const double **)(void *)(e->b + o->ninputs + 1);
  make_windows(e);
  if (fft->init(e->fft_state, o->nseg, e->buf, e->spec + o->ninputs * e->nb, err)) {
    rcb_set_error(e->errmsg, RCB_ERR_ARG, "spectral estimator: %s", err);
    return RCB_ERR_ARG;
  }
  *out = e;
  return RCB_OK;
}

void rcb_spectral_release(rcb_spectral *e) {
  if (e && e->fft) e->fft->release(e->fft_state);
  if (e) e->fft = NULL;
}

const char *rcb_spectral_errmsg(const rcb_spectral *e) { return e ? e->errmsg : ""; }

void rcb_spectral_clear(rcb_spectral *e) {
  size_t p = e->o.ninputs, q = e->o.noutputs;
  memset(e->gxx, 0, e->nb * p * p * sizeof *e->gxx);
  memset(e->gxy, 0, e->nb * p * q * sizeof *e->gxy);
  memset(e->gyy, 0, e->nb * q * sizeof *e->gyy);
  e->nd = 0;
}

/* Detrend, window and transform one channel into spectrum slot @p slot. */
static void transform(rcb_spectral *e, const double *x, const double *w, size_t slot) {
  size_t n = e->o.nseg, t;
  double mean = 0.0;
  rcb_complex *fout = e->spec + e->o.ninputs * e->nb;
  if (!e->o.no_detrend) {
    for (t = 0; t < n; t++) mean += x[t];
    mean /= (double)n;
  }
  for (t = 0; t < n; t++) e->buf[t] = (x[t] - mean) * w[t];
  e->fft->exec(e->fft_state);
  if (slot != e->o.ninputs) memcpy(e->spec + slot * e->nb, fout, e->nb * sizeof *fout);
}

rcb_status rcb_spectral_add_segment(rcb_spectral *e, const double *const *chan) {
  size_t p, q, nb, i, j, o, k;
  const rcb_complex *y;
  if (!e || !chan) return RCB_ERR_ARG;
  if (!e->fft)
    return rcb_set_error(e->errmsg, RCB_ERR_STATE, "spectral estimator already released");
  p = e->o.ninputs;
  q = e->o.noutputs;
  nb = e->nb;
  for (i = 0; i < p + q; i++)
    if (!chan[i])
      return rcb_set_error(e->errmsg, RCB_ERR_ARG, "add_segment: channel %zu is NULL", i);
  for (i = 0; i < p; i++) transform(e, chan[i], e->win_in, i);
  for (k = 0; k < nb; k++)
    for (j = 0; j < p; j++)
      for (i = 0; i < p; i++)
        e->gxx[(k * p + j) * p + i] += conj(e->spec[i * nb + k]) * e->spec[j * nb + k];
  y = e->spec + p * nb;
  for (o = 0; o < q; o++) {
    transform(e, chan[p + o], e->win_out, p);
    for (k = 0; k < nb; k++) {
      e->gyy[k * q + o] += creal(y[k]) * creal(y[k]) + cimag(y[k]) * cimag(y[k]);
      for (i = 0; i < p; i++) e->gxy[(k * q + o) * p + i] += conj(e->spec[i * nb + k]) * y[k];
    }
  }
  e->nd++;
  return RCB_OK;
}

rcb_status rcb_spectral_add_record(rcb_spectral *e, size_t n, const double *const *chan) {
  size_t c, nc, start, step;
  rcb_status st;
  if (!e || !chan) return RCB_ERR_ARG;
  nc = e->o.ninputs + e->o.noutputs;
  step = e->o.nseg - e->o.noverlap;
  if (n < e->o.nseg)
    return rcb_set_error(e->errmsg, RCB_ERR_ARG, "record of %zu samples is shorter than one "
                         "segment (%zu samples); use a shorter segment", n, e->o.nseg);
  for (c = 0; c < nc; c++)
    if (!chan[c])
      return rcb_set_error(e->errmsg, RCB_ERR_ARG, "add_record: channel %zu is NULL", c);
  for (start = 0; start + e->o.nseg <= n; start += step) {
    for (c = 0; c < nc; c++) e->seg[c] = chan[c] + start;
    if ((st = rcb_spectral_add_segment(e, e->seg))) return st;
  }
  return RCB_OK;
}

size_t rcb_spectral_averages(const rcb_spectral *e) { return e ? e->nd : 0; }
size_t rcb_spectral_bin_count(const rcb_spectral *e) { return e ? e->nb : 0; }

void rcb_spectral_frequencies(const rcb_spectral *e, double *w) {
  size_t k;
  for (k = 0; k < e->nb; k++) w[k] = 2.0 * RCB_PI * (double)k * e->o.rate / (double)e->o.nseg;
}

/* Density scale of line k for the averaged sums. */
double rcb_spectral_line_scale(const rcb_spectral *e, size_t k) {
  int single = k == 0 || (e->o.nseg % 2 == 0 && k == e->nb - 1);
  return (single ? 1.0 : 2.0) / (e->o.rate * e->wss * (double)e->nd);
}

rcb_status rcb_spectral_cross(const rcb_spectral *e, size_t a, size_t b, rcb_complex *g) {
  size_t p, q, k;
  if (!e || !g) return RCB_ERR_ARG;
  p = e->o.ninputs;
  q = e->o.noutputs;
  if (a >= p + q || b >= p + q || (a >= p && b >= p && a != b))
    return RCB_ERR_ARG;
  if (e->nd == 0) return RCB_ERR_STATE;
  for (k = 0; k < e->nb; k++) {
    rcb_complex v;
    if (a < p && b < p)
      v = e->gxx[(k * p + b) * p + a];
    else if (a < p)
      v = e->gxy[(k * q + (b - p)) * p + a];
    else if (b < p)
      v = conj(e->gxy[(k * q + (a - p)) * p + b]);
    else
      v = e->gyy[k * q + (a - p)];
    g[k] = v * rcb_spectral_line_scale(e, k);
  }
  return RCB_OK;
}
