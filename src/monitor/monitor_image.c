/*
 * The commissioning image (rcb_monitor.h, issue #34 item 5): what create
 * computes by sweeps and QRs, saved so that a create again from the same
 * baseline model, set-up and options takes it instead. A process per
 * measurement (rcbtool monitor --state) spent about 0.5 s of its 0.55 s in
 * create; with the image create does only what is cheap (the set-up, the
 * noise, the baseline's sweep, the catalogue and the small rank-space
 * matrices) and its results are those of a full create, bit for bit: every
 * value the image holds is one a full create computes from the same inputs.
 *
 * Layout (little-endian): "RCBI", the u32 version, the u64 fingerprint of
 * the inputs, ten u64 dimensions (n, ncol, k, nt, ncand, nch, npts, the
 * low-rank path 0/1, its |P| and inputs), Q (n x k row-major), G (k x ncol
 * column-major), the low-rank blocks (H0_oP, H0_PP, H0_Pi as Re, Im), one
 * byte per candidate (1: its joint step without a sweep), zero padding to 8
 * bytes, then a u64 checksum of everything before it. Every dimension must
 * be the one this create computes, every value finite, Q's columns of unit
 * length, every flag 0 or 1. Beyond that the values are not checked against
 * what a create computes (that would be the create): an image whose
 * checksum was made again over other finite values gives wrong statistics,
 * never a read outside the monitor's blocks (fuzz/fuzz_monitor_image.c).
 */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "diagnose/diagnose.h"
#include "monitor/monitor_internal.h"

#define IM_MAGIC "RCBI"
#define IM_HEAD 96u

/* ---- fingerprint of the inputs: FNV-1a 64 over values in a fixed order ---- */

static uint64_t fnv_f64s(uint64_t h, const double *x, size_t n) {
  size_t i;
  for (i = 0; i < n; i++) {
    unsigned char b[8];
    rcb_mon_put_f64(b, x[i]);
    h = rcb_mon_fnv_bytes(h, b, 8);
  }
  return h;
}

uint64_t rcb_mon_image_fingerprint(const rcb_monitor *mon, const rcb_diag *d,
                                   const struct col_plan *pl, unsigned effects) {
  uint64_t h = rcb_mon_fnv_u64(RCB_MON_FNV_OFFSET, RCB_MONITOR_IMAGE_VERSION);
  const double *x = rcb_meas_grid(mon->setup);
  size_t a, c;
  /* the library that computes the image, the set-up exactly, the noise
   * (every residual's weight and frame), the baseline model's values on the
   * set-up, the options that shape the columns and the low-rank path */
  h = rcb_mon_fnv_u64(h, (uint64_t)rcb_version_number());
  h = rcb_mon_fnv_u64(rcb_mon_fnv_u64(h, (uint64_t)rcb_meas_get_type(mon->setup)), mon->npts);
  h = fnv_f64s(fnv_f64s(h, x, mon->npts), (const double[1]){rcb_meas_speed(mon->setup)}, 1);
  for (c = 0; c < mon->nch; c++) {
    rcb_meas_channel_info ci;
    rcb_meas_channel(mon->setup, c, &ci);
    h = rcb_mon_fnv_u64(rcb_mon_fnv_str(rcb_mon_fnv_str(h, ci.response), ci.reference), (uint64_t)ci.kind);
  }
  h = fnv_f64s(h, (const double *)(const void *)mon->e0, 2 * mon->npt);
  h = fnv_f64s(h, (const double *)(const void *)mon->u, 2 * mon->npt);
  h = fnv_f64s(h, mon->winv, mon->n);
  h = fnv_f64s(h, mon->rbase, mon->n);
  h = rcb_mon_fnv_u64(rcb_mon_fnv_u64(rcb_mon_fnv_u64(h, mon->relin), (uint64_t)effects), mon->nt);
  for (a = 0; a < mon->nt; a++) {
    h = rcb_mon_fnv_str(h, mon->tname[a]);
    h = fnv_f64s(fnv_f64s(fnv_f64s(h, &mon->t0[a], 1), &mon->tlo[a], 1), &mon->thi[a], 1);
  }
  h = rcb_mon_fnv_u64(rcb_mon_fnv_u64(h, pl->ncand), pl->ncol);
  for (c = 0; c < pl->ncand; c++) {
    rcb_diag_cand_desc cd;
    rcb_mon_cand_desc(d, pl->cand[c], &cd);
    h = rcb_mon_fnv_u64(rcb_mon_fnv_u64(h, (uint64_t)cd.effect), pl->col[c]);
    h = rcb_mon_fnv_str(rcb_mon_fnv_str(rcb_mon_fnv_str(h, cd.place), cd.desc), cd.params);
    for (a = 0; a < cd.np; a++) h = fnv_f64s(rcb_mon_fnv_str(h, cd.pname[a]), cd.hi + a, 1);
  }
  return fnv_f64s(h, pl->neutral, pl->ncol);
}

/* ---- sizes and the checksum ---- */

/* Doubles of each section for these dimensions. */
static size_t lr_doubles(size_t npt, size_t npts, size_t lnp, size_t lnin) {
  return 2 * (npt * lnp + npts * lnp * lnp + npts * lnin * lnp);
}

static size_t image_bytes(size_t n, size_t ncol, size_t k, size_t ncand, size_t npt, size_t npts,
                          size_t lnp, size_t lnin) {
  size_t nd = n * k + k * ncol + lr_doubles(npt, npts, lnp, lnin);
  return IM_HEAD + 8 * nd + ((ncand + 7) & ~(size_t)7) + 8;
}

/* A checksum of n bytes, a 64-bit word at a time (FNV-1a's step on words,
 * then a final mix): it finds damage, as the state's CRC-32 does, at
 * several GB/s on the image's megabytes. */
static uint64_t checksum(const unsigned char *p, size_t n) {
  uint64_t h = RCB_MON_FNV_OFFSET;
  size_t i;
  for (i = 0; i + 8 <= n; i += 8) h = (h ^ rcb_mon_get_u64(p + i)) * RCB_MON_FNV_PRIME;
  for (; i < n; i++) h = (h ^ p[i]) * RCB_MON_FNV_PRIME;
  h ^= h >> 33;
  h *= 0xff51afd7ed558ccdull;
  return h ^ (h >> 33);
}

/* ---- save ---- */

size_t rcb_monitor_image_size(const rcb_monitor *mon) {
  const mon_lowrank *lr;
  if (!mon || !mon->k || !mon->y) return 0;
  lr = mon->lr;
  return image_bytes(mon->n, mon->ncol, mon->k, mon->ncand, mon->npt, mon->npts,
                     lr ? lr->np : 0, lr ? lr->nin : 0);
}

static unsigned char *put_cplx(unsigned char *p, const rcb_complex *z, size_t n) {
  size_t i;
  for (i = 0; i < n; i++, p += 16) rcb_mon_put_f64(p, creal(z[i])), rcb_mon_put_f64(p + 8, cimag(z[i]));
  return p;
}

rcb_status rcb_monitor_image_save(const rcb_monitor *mon, void *buf, size_t size,
                                  size_t *written) {
  size_t need = rcb_monitor_image_size(mon), i, dims[10];
  const mon_lowrank *lr;
  unsigned char *p = buf, *q;
  if (written) *written = 0;
  if (!need) return RCB_ERR_STATE;
  if (!buf || size < need) return RCB_ERR_WORKSPACE;
  lr = mon->lr;
  memset(p, 0, need);
  for (i = 0; i < 4; i++) p[i] = (unsigned char)IM_MAGIC[i]; /* 4 bytes, no terminator */
  for (i = 0; i < 4; i++) p[4 + i] = (unsigned char)(RCB_MONITOR_IMAGE_VERSION >> (8 * i));
  rcb_mon_put_u64(p + 8, mon->img_fp);
  dims[0] = mon->n, dims[1] = mon->ncol, dims[2] = mon->k, dims[3] = mon->nt;
  dims[4] = mon->ncand, dims[5] = mon->nch, dims[6] = mon->npts, dims[7] = lr != NULL;
  dims[8] = lr ? lr->np : 0, dims[9] = lr ? lr->nin : 0;
  for (i = 0; i < 10; i++) rcb_mon_put_u64(p + 16 + 8 * i, dims[i]);
  q = p + IM_HEAD;
  for (i = 0; i < mon->n * mon->k; i++, q += 8) rcb_mon_put_f64(q, mon->Q[i]);
  for (i = 0; i < mon->k * mon->ncol; i++, q += 8) rcb_mon_put_f64(q, mon->G[i]);
  if (lr) {
    q = put_cplx(q, lr->a, mon->npt * lr->np);
    q = put_cplx(q, lr->hpp, mon->npts * lr->np * lr->np);
    q = put_cplx(q, lr->b, mon->npts * lr->nin * lr->np);
  }
  for (i = 0; i < mon->ncand; i++) q[i] = mon->cand[i].ep != NULL;
  rcb_mon_put_u64(p + need - 8, checksum(p, need - 8));
  if (written) *written = need;
  return RCB_OK;
}

/* ---- load: checked at create, taken piece by piece ---- */

rcb_status rcb_mon_image_open(rcb_monitor *mon, const void *buf, size_t size, uint64_t fp,
                              size_t ncol, size_t ncand, mon_image *im) {
  const unsigned char *p = buf;
  size_t dims[10], i, nd, need;
  memset(im, 0, sizeof *im);
  if (!p || size < IM_HEAD + 8 || memcmp(p, IM_MAGIC, 4) != 0)
    return rcb_mon_fail(mon, RCB_ERR_CORRUPT, "commissioning image: not an image the monitor "
                        "writes (rcb_monitor_image_save)");
  if ((rcb_mon_get_u64(p) >> 32) != RCB_MONITOR_IMAGE_VERSION)
    return rcb_mon_fail(mon, RCB_ERR_VERSION, "commissioning image: format version %lu, this "
                        "library reads %u", (unsigned long)(rcb_mon_get_u64(p) >> 32),
                        RCB_MONITOR_IMAGE_VERSION);
  for (i = 0; i < 10; i++) {
    uint64_t v = rcb_mon_get_u64(p + 16 + 8 * i);
    if (v > (uint64_t)(size / 8)) /* no dimension can pass the image's own size */
      return rcb_mon_fail(mon, RCB_ERR_CORRUPT, "commissioning image: dimension %zu is %llu: "
                          "damaged", i + 1, (unsigned long long)v);
    dims[i] = (size_t)v;
  }
  if (dims[0] != mon->n || dims[1] != ncol || dims[3] != mon->nt || dims[4] != ncand ||
      dims[5] != mon->nch || dims[6] != mon->npts || rcb_mon_get_u64(p + 8) != fp)
    return rcb_mon_fail(mon, RCB_ERR_OTHER_SETUP, "commissioning image of another baseline "
                        "model, set-up or options (its fingerprint or dimensions differ)");
  if (!dims[2] || dims[2] > ncol || dims[2] > mon->n || dims[7] > 1 ||
      (dims[7] ? !dims[8] || dims[8] > MON_LOWRANK_MAXP || !dims[9] || dims[9] > mon->nch
               : dims[8] || dims[9]))
    return rcb_mon_fail(mon, RCB_ERR_CORRUPT, "commissioning image: rank %zu of %zu columns, "
                        "low-rank path %zu with %zu DOFs and %zu inputs: damaged", dims[2], ncol,
                        dims[7], dims[8], dims[9]);
  need = image_bytes(mon->n, ncol, dims[2], ncand, mon->npt, mon->npts, dims[8], dims[9]);
  if (size != need)
    return rcb_mon_fail(mon, RCB_ERR_CORRUPT, "commissioning image: %zu bytes, its dimensions "
                        "make %zu", size, need);
  if (rcb_mon_get_u64(p + need - 8) != checksum(p, need - 8))
    return rcb_mon_fail(mon, RCB_ERR_CORRUPT, "commissioning image: its checksum does not "
                        "match (damaged)");
  nd = mon->n * dims[2] + dims[2] * ncol + lr_doubles(mon->npt, mon->npts, dims[8], dims[9]);
  for (i = 0; i < nd; i++)
    if (!isfinite(rcb_mon_get_f64(p + IM_HEAD + 8 * i)))
      return rcb_mon_fail(mon, RCB_ERR_CORRUPT, "commissioning image: value %zu is not "
                          "finite: damaged", i + 1);
  { /* Q's columns are orthonormal: each of unit length (a cheap check that
     * catches a basis a create never makes, its checksum made again) */
    size_t a, kk = dims[2];
    for (a = 0; a < kk; a++) {
      double s = 0;
      for (i = 0; i < mon->n; i++) {
        double q = rcb_mon_get_f64(p + IM_HEAD + 8 * (kk * i + a));
        s += q * q;
      }
      if (!(fabs(s - 1.0) <= 1e-6))
        return rcb_mon_fail(mon, RCB_ERR_CORRUPT, "commissioning image: column %zu of Q has "
                            "length %g, not 1: damaged", a + 1, sqrt(s));
    }
  }
  for (i = 0; i < ((ncand + 7) & ~(size_t)7); i++)
    if (p[IM_HEAD + 8 * nd + i] > (i < ncand))
      return rcb_mon_fail(mon, RCB_ERR_CORRUPT, "commissioning image: candidate %zu's flag "
                          "%u: damaged", i + 1, (unsigned)p[IM_HEAD + 8 * nd + i]);
  im->p = p;
  im->k = dims[2], im->lr = dims[7] != 0, im->lnp = dims[8], im->lnin = dims[9];
  im->g = IM_HEAD + 8 * mon->n * im->k;
  im->a = im->g + 8 * im->k * ncol;
  im->ep = IM_HEAD + 8 * nd;
  return RCB_OK;
}

void rcb_mon_image_doubles(const mon_image *im, size_t at, double *x, size_t n) {
  size_t i;
  for (i = 0; i < n; i++) x[i] = rcb_mon_get_f64(im->p + at + 8 * i);
}

rcb_status rcb_mon_image_lowrank(rcb_monitor *mon, const mon_image *im, mon_lowrank *lr) {
  size_t i, j, at = im->a, na = mon->npt * lr->np, nh = mon->npts * lr->np * lr->np,
               nb = mon->npts * lr->nin * lr->np;
  rcb_complex *dst[3];
  size_t cnt[3];
  if (!im->lr || im->lnp != lr->np || im->lnin != lr->nin)
    return rcb_mon_fail(mon, RCB_ERR_OTHER_SETUP, "commissioning image: its low-rank path "
                        "(%zu DOFs, %zu inputs) is not this monitor's (%zu, %zu)", im->lnp,
                        im->lnin, lr->np, lr->nin);
  for (j = 0; j < mon->ncand; j++)
    if (im->p[im->ep + j] && !mon->cand[j].ep)
      return rcb_mon_fail(mon, RCB_ERR_OTHER_SETUP, "commissioning image: candidate %zu on "
                          "the low-rank path, not in this monitor's", j + 1);
  dst[0] = lr->a, dst[1] = lr->hpp, dst[2] = lr->b;
  cnt[0] = na, cnt[1] = nh, cnt[2] = nb;
  for (j = 0; j < 3; j++)
    for (i = 0; i < cnt[j]; i++, at += 16)
      dst[j][i] = CMPLX(rcb_mon_get_f64(im->p + at), rcb_mon_get_f64(im->p + at + 8));
  /* the create's check against a sweep, as it came out */
  for (j = 0; j < mon->ncand; j++)
    if (!im->p[im->ep + j]) mon->cand[j].ep = NULL;
  return RCB_OK;
}
