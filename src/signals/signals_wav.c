/*
 * Time signals from WAV (RIFF, little-endian): PCM 16/24/32-bit integer
 * (format 1), IEEE float 32/64-bit (format 3), or WAVE_FORMAT_EXTENSIBLE
 * (0xFFFE) with either sub-format. Integers are scaled to [-1, 1) by their
 * full scale (2^(bits-1)), then by the caller's full-scale value in the
 * channel's unit, then to SI. WAV has no channel names or units: the caller
 * gives them (a data recorder's calibration sheet).
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "signals/signals_internal.h"

static unsigned long le(const unsigned char *p, int n) {
  unsigned long v = 0;
  int i;
  for (i = n - 1; i >= 0; i--) v = (v << 8) | p[i];
  return v;
}

typedef struct wav_fmt {
  unsigned format, nch, bits, align;
  unsigned long rate;
  const unsigned char *data;
  size_t data_len;   /* bytes of the data chunk present in the file */
  size_t data_claim; /* bytes its header claims */
  size_t riff_claim; /* bytes the RIFF header claims (8 + its size) */
} wav_fmt;

static rcb_status wav_chunks(rcb_signals *s, const char *path, const unsigned char *b,
                             size_t len, wav_fmt *f) {
  size_t pos = 12;
  int have_fmt = 0;
  if (len < 12 || memcmp(b, "RIFF", 4) != 0 || memcmp(b + 8, "WAVE", 4) != 0)
    return rcb_signals_fail(s, RCB_ERR_PARSE, "%s: not a WAV file (no RIFF/WAVE header)", path);
  f->riff_claim = 8 + (size_t)le(b + 4, 4);
  while (pos + 8 <= len) {
    size_t size = le(b + pos + 4, 4), claim = size;
    const unsigned char *c = b + pos + 8;
    if (size > len - pos - 8) {
      if (memcmp(b + pos, "data", 4) != 0)
        return rcb_signals_fail(s, RCB_ERR_PARSE, "%s: chunk '%.4s' at byte %zu claims %zu "
                                "bytes, the file holds %zu after its header: truncated", path,
                                (const char *)(b + pos), pos, size, len - pos - 8);
      size = len - pos - 8; /* cut short: judged in wav_truncation */
    }
    if (memcmp(b + pos, "fmt ", 4) == 0) {
      if (size < 16)
        return rcb_signals_fail(s, RCB_ERR_PARSE, "%s: 'fmt ' chunk of %zu bytes; expected "
                                "16 or more", path, size);
      f->format = (unsigned)le(c, 2);
      f->nch = (unsigned)le(c + 2, 2);
      f->rate = le(c + 4, 4);
      f->align = (unsigned)le(c + 12, 2);
      f->bits = (unsigned)le(c + 14, 2);
      if (f->format == 0xFFFEu && size >= 26) f->format = (unsigned)le(c + 24, 2);
      have_fmt = 1;
    } else if (memcmp(b + pos, "data", 4) == 0) {
      f->data = c;
      f->data_len = size;
      f->data_claim = claim;
    }
    pos += 8 + size + (size & 1);
  }
  if (!have_fmt || !f->data)
    return rcb_signals_fail(s, RCB_ERR_PARSE, "%s: WAV file without %s chunk", path,
                            have_fmt ? "a 'data'" : "a 'fmt '");
  if (!((f->format == 1 && (f->bits == 16 || f->bits == 24 || f->bits == 32)) ||
        (f->format == 3 && (f->bits == 32 || f->bits == 64))))
    return rcb_signals_fail(s, RCB_ERR_PARSE, "%s: WAV format %u with %u bits per sample; "
                            "expected PCM (1) 16/24/32-bit or IEEE float (3) 32/64-bit", path,
                            f->format, f->bits);
  if (f->nch == 0 || f->rate == 0 || f->align != f->nch * f->bits / 8)
    return rcb_signals_fail(s, RCB_ERR_PARSE, "%s: WAV header: %u channels, %lu samples/s, "
                            "block align %u: inconsistent", path, f->nch, f->rate, f->align);
  return RCB_OK;
}

/* A data chunk that claims more bytes than the file holds (a recording cut
 * short, a streaming writer's placeholder size) or that ends inside a frame
 * is refused with the byte counts: reading what is there would estimate from
 * a record the user did not mean, silently (issue #25). With
 * allow_truncated the whole frames present are read, with a warning. A RIFF
 * header claiming more than the file while the data is whole (a trailing
 * chunk lost) is only a warning. */
static rcb_status wav_truncation(rcb_signals *s, const char *path, const wav_fmt *f,
                                 size_t len) {
  size_t frames = f->data_len / f->align, part = f->data_len % f->align;
  char what[256];
  if (f->data_claim > f->data_len)
    snprintf(what, sizeof what, "the data chunk claims %zu bytes, the file holds %zu of them "
             "(%zu whole frames of %u bytes%s): truncated", f->data_claim, f->data_len,
             frames, f->align, part ? " and part of one" : "");
  else if (part)
    snprintf(what, sizeof what, "the data chunk of %zu bytes ends %zu bytes into a frame of %u "
             "bytes (%u channels x %u bits): cut mid-frame", f->data_len, part, f->align,
             f->nch, f->bits);
  else if (f->riff_claim > len)
    return rcb_signals_warn(s, "%s: the RIFF header claims %zu bytes, the file holds %zu: a "
                            "chunk after the samples is missing (all %zu frames read)", path,
                            f->riff_claim, len, frames);
  else
    return RCB_OK;
  if (!s->allow_truncated)
    return rcb_signals_fail(s, RCB_ERR_PARSE, "%s: %s; refused (to read the %zu whole frames, "
                            "%.6g s, allow truncated files: rcbtool --allow-truncated, "
                            "rcb_signals_set_allow_truncated)", path, what, frames,
                            (double)frames / (double)f->rate);
  return rcb_signals_warn(s, "%s: %s; read the %zu whole frames (%.6g s) as allowed", path,
                          what, frames, (double)frames / (double)f->rate);
}

static double sample(const wav_fmt *f, const unsigned char *p) {
  unsigned long u = le(p, (int)(f->bits / 8));
  if (f->format == 3) {
    if (f->bits == 32) {
      unsigned int u32 = (unsigned int)u;
      float x;
      memcpy(&x, &u32, 4);
      return (double)x;
    } else {
      unsigned long long u64 = (unsigned long long)le(p, 4) | ((unsigned long long)le(p + 4, 4) << 32);
      double x;
      memcpy(&x, &u64, 8);
      return x;
    }
  }
  {
    double full = ldexp(1.0, (int)f->bits - 1);
    double v = (double)u;
    if (v >= full) v -= 2.0 * full; /* two's complement */
    return v / full;
  }
}

static rcb_status wav_channel(rcb_signals *s, const char *path, const wav_fmt *f, size_t c,
                              size_t n, const char *name, const char *unit, double fs) {
  rcb_quantity q = RCB_QTY_VOLTAGE;
  double to_si = 1.0, *v;
  char def[16];
  size_t i;
  if (unit && rcb_unit_parse(unit, &q, &to_si)) {
    char known[300];
    rcb_unit_list(RCB_QTY_UNKNOWN, known, sizeof known);
    return rcb_signals_fail(s, RCB_ERR_ARG, "%s: channel %zu: unit '%s' is not one librcb "
                            "knows; expected one of %s", path, c + 1, unit, known);
  }
  if (!isfinite(fs) || fs == 0.0)
    return rcb_signals_fail(s, RCB_ERR_ARG, "%s: channel %zu: full scale %g; expected a finite "
                            "nonzero value", path, c + 1, fs);
  v = rcb_alloc(&s->alloc, n * sizeof *v);
  if (!v) return rcb_signals_fail(s, RCB_ERR_NOMEM, "%s: out of memory", path);
  for (i = 0; i < n; i++) {
    v[i] = sample(f, f->data + i * f->align + c * (f->bits / 8)) * fs * to_si;
    if (!isfinite(v[i]) || fabs(v[i]) > RCB_SIGNAL_MAX) {
      double x = v[i];
      rcb_free(&s->alloc, v);
      return rcb_signals_fail(s, RCB_ERR_PARSE, "%s: channel %zu, sample %zu is %g: %s", path,
                              c + 1, i + 1, x, isfinite(x) ? "beyond 1e100, the largest sample "
                              "librcb takes (its power would overflow); a corrupt file?"
                              : "not finite");
    }
  }
  if (!name) snprintf(def, sizeof def, "ch%zu", c + 1);
  return rcb_signals_take(s, name ? name : def, q, v);
}

rcb_status rcb_signals_read_wav(rcb_signals *s, const char *path, size_t nnames,
                                const char *const *names, const char *const *units,
                                const double *scale) {
  char *buf = NULL;
  size_t len, n, c;
  wav_fmt f;
  rcb_status st;
  if (!s) return RCB_ERR_ARG;
  rcb_signals_begin_read(s);
  if ((st = rcb_signals_slurp(s, path, &buf, &len))) return st;
  memset(&f, 0, sizeof f);
  st = wav_chunks(s, path, (const unsigned char *)buf, len, &f);
  if (!st) st = wav_truncation(s, path, &f, len);
  if (!st && nnames && nnames != f.nch)
    st = rcb_signals_fail(s, RCB_ERR_ARG, "%s: %zu channel names for a file of %u channels",
                          path, nnames, f.nch);
  n = st ? 0 : f.data_len / f.align;
  if (!st && n == 0) st = rcb_signals_fail(s, RCB_ERR_PARSE, "%s: no samples", path);
  if (!st) st = rcb_signals_reset(s, (double)f.rate, n);
  for (c = 0; !st && c < f.nch; c++)
    st = wav_channel(s, path, &f, c, n, nnames && names ? names[c] : NULL,
                     nnames && units ? units[c] : NULL, nnames && scale ? scale[c] : 1.0);
  if (st) rcb_signals_empty(s);
  rcb_free(&s->alloc, buf);
  return st;
}
