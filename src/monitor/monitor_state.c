/*
 * rcb_monitor's state that survives a restart (rcb_monitor.h, issue #24):
 * the accumulated CUSUM and reference sums saved into a caller's buffer in
 * a little-endian, versioned layout with a CRC-32, and loaded into a
 * monitor created again from the same model, set-up and settings, checked
 * by fingerprints. Neither direction allocates.
 */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "monitor/monitor_internal.h"

#define ST_MAGIC "RCBM" /* 4 bytes, no terminator in the state */
#define ST_HEAD 72u   /* bytes before the tracked parameters */
#define ST_PER 40u    /* bytes per tracked parameter */
#define ST_CRC 4u
/* The model's response sums agree to this relative difference (another
 * BLAS may change their last bits, never their 9th digit). */
#define ST_SIG_TOL 1e-9
/* The end of every message about a field no monitor writes. */
#define ST_NOT_WRITTEN "not a state the monitor writes (damaged, or made by something else)"

/* The update count is read into a size_t (rcb_monitor_load): bounded by
 * RCB_MONITOR_MAX_UPDATES first, so no target's size_t may be narrower. */
_Static_assert(SIZE_MAX >= RCB_MONITOR_MAX_UPDATES, "size_t holds every update count");

/* ---- little-endian fields (those of 8 bytes shared: monitor_internal.h) ---- */

static void put_u32(unsigned char *p, uint32_t v) {
  int i;
  for (i = 0; i < 4; i++) p[i] = (unsigned char)(v >> (8 * i));
}
void rcb_mon_put_u64(unsigned char *p, uint64_t v) {
  int i;
  for (i = 0; i < 8; i++) p[i] = (unsigned char)(v >> (8 * i));
}
void rcb_mon_put_f64(unsigned char *p, double x) {
  uint64_t v;
  memcpy(&v, &x, sizeof v);
  rcb_mon_put_u64(p, v);
}
static uint32_t get_u32(const unsigned char *p) {
  uint32_t v = 0;
  int i;
  for (i = 3; i >= 0; i--) v = (v << 8) | p[i];
  return v;
}
uint64_t rcb_mon_get_u64(const unsigned char *p) {
  uint64_t v = 0;
  int i;
  for (i = 7; i >= 0; i--) v = (v << 8) | p[i];
  return v;
}
double rcb_mon_get_f64(const unsigned char *p) {
  uint64_t v = rcb_mon_get_u64(p);
  double x;
  memcpy(&x, &v, sizeof x);
  return x;
}

/* CRC-32, IEEE 802.3 polynomial reflected (0xEDB88320), a byte at a time
 * through a table made on the stack at each call (256 entries, 2 k steps:
 * the state, tens of kB with the drift window, took 0.3 ms bit by bit). */
unsigned long rcb_monitor_crc32(unsigned long crc, const void *data, size_t n) {
  const unsigned char *p = data;
  uint32_t c = ~(uint32_t)crc, t[256];
  size_t i;
  int b;
  for (i = 0; i < 256; i++) {
    uint32_t v = (uint32_t)i;
    for (b = 0; b < 8; b++) v = (v >> 1) ^ (0xEDB88320u & (0u - (v & 1u)));
    t[i] = v;
  }
  for (i = 0; i < n; i++) c = (c >> 8) ^ t[(c ^ p[i]) & 0xFFu];
  c = ~c;
  return (unsigned long)c;
}

/* ---- fingerprints: FNV-1a 64 over values in a fixed byte order ---- */

uint64_t rcb_mon_fnv_bytes(uint64_t h, const void *data, size_t n) {
  const unsigned char *p = data;
  size_t i;
  for (i = 0; i < n; i++) h = (h ^ p[i]) * RCB_MON_FNV_PRIME;
  return h;
}
uint64_t rcb_mon_fnv_u64(uint64_t h, uint64_t v) {
  unsigned char b[8];
  rcb_mon_put_u64(b, v);
  return rcb_mon_fnv_bytes(h, b, 8);
}
uint64_t rcb_mon_fnv_f64(uint64_t h, double x) {
  unsigned char b[8];
  rcb_mon_put_f64(b, x);
  return rcb_mon_fnv_bytes(h, b, 8);
}
uint64_t rcb_mon_fnv_str(uint64_t h, const char *s) {
  return rcb_mon_fnv_bytes(h, s ? s : "", (s ? strlen(s) : 0) + 1);
}

/* The tracked names and baseline values, the candidates (a structural
 * change of the model changes them), and two sums of |baseline model|
 * over the set-up's points (weights 1 and 1 + (p mod 7) / 7), compared with
 * a tolerance. */
static uint64_t model_hash(const rcb_monitor *mon, double sig[2]) {
  uint64_t h = RCB_MON_FNV_OFFSET;
  size_t a, p;
  h = rcb_mon_fnv_u64(h, mon->nt);
  for (a = 0; a < mon->nt; a++) h = rcb_mon_fnv_f64(rcb_mon_fnv_str(h, mon->tname[a]), mon->t0[a]);
  h = rcb_mon_fnv_u64(h, mon->ncand);
  for (a = 0; a < mon->ncand; a++)
    h = rcb_mon_fnv_str(rcb_mon_fnv_u64(h, (uint64_t)mon->cand[a].effect), mon->cand[a].place);
  sig[0] = sig[1] = 0;
  for (p = 0; p < mon->npt; p++) {
    sig[0] += mon->h0abs[p];
    sig[1] += mon->h0abs[p] * (1.0 + (double)(p % 7) / 7.0);
  }
  return h;
}

static uint64_t setup_hash(const rcb_monitor *mon) {
  const double *x = rcb_meas_grid(mon->setup);
  uint64_t h = RCB_MON_FNV_OFFSET;
  size_t c, i;
  h = rcb_mon_fnv_u64(h, (uint64_t)rcb_meas_get_type(mon->setup));
  h = rcb_mon_fnv_f64(rcb_mon_fnv_u64(h, mon->npts), rcb_meas_speed(mon->setup));
  for (i = 0; i < mon->npts; i++) h = rcb_mon_fnv_f64(h, x[i]);
  h = rcb_mon_fnv_u64(h, mon->nch);
  for (c = 0; c < mon->nch; c++) {
    rcb_meas_channel_info ci;
    rcb_meas_channel(mon->setup, c, &ci);
    h = rcb_mon_fnv_u64(rcb_mon_fnv_str(rcb_mon_fnv_str(h, ci.response), ci.reference), (uint64_t)ci.kind);
  }
  for (i = 0; i < mon->npt; i++) h = rcb_mon_fnv_f64(rcb_mon_fnv_f64(h, creal(mon->e0[i])), cimag(mon->e0[i]));
  return h;
}

static uint64_t settings_hash(const rcb_monitor *mon) {
  const double v[] = {mon->alpha, mon->cusum_k, mon->cusum_h, mon->beta_a, mon->beta_s,
                      mon->navg_inv, mon->phase_var};
  uint64_t h = RCB_MON_FNV_OFFSET;
  size_t i;
  for (i = 0; i < sizeof v / sizeof v[0]; i++) h = rcb_mon_fnv_f64(h, v[i]);
  h = rcb_mon_fnv_u64(rcb_mon_fnv_u64(rcb_mon_fnv_u64(h, mon->top), mon->relin), (uint64_t)mon->reweight);
  for (i = 0; i < mon->nt; i++)
    h = rcb_mon_fnv_f64(rcb_mon_fnv_f64(rcb_mon_fnv_f64(h, mon->tlo[i]), mon->thi[i]), mon->tbv[i]);
  for (i = 0; i < mon->nt * mon->nt; i++) h = rcb_mon_fnv_f64(h, mon->bcov[i]); /* version 3 */
  if (mon->nscale != 1.0) h = rcb_mon_fnv_f64(h, mon->nscale); /* as before scales existed */
  h = rcb_mon_fnv_u64(h, (uint64_t)mon->have_sd0);
  for (i = 0; mon->have_sd0 && i < mon->npt; i++) h = rcb_mon_fnv_f64(h, mon->sd0[i]);
  return h;
}

static int ready(const rcb_monitor *mon) { return mon && mon->k > 0 && mon->y; }

/* The drift window after the tracked parameters: its dimensions (k, nt,
 * window; u32 each), the ring's count and newest slot (u32), the updates in
 * the sums (u64), the free-offset flag (u32), the sums of y (k), of the
 * steps (nt) and of each scored candidate's s (its rank), then per slot of
 * the window the same three. */
#define ST_DRIFT_HEAD 32u
static size_t cand_dofs(const rcb_monitor *mon) {
  size_t j, n = 0;
  for (j = 0; j < mon->ncand; j++) n += mon->cand[j].dof;
  return n;
}
static size_t drift_bytes(const rcb_monitor *mon) {
  return ST_DRIFT_HEAD + (size_t)8 * (MON_DRIFT_WINDOW + 1u) * (mon->k + mon->nt + cand_dofs(mon));
}
/* The candidates' s of one slot (or their sums) written at q or read from
 * r; the bytes after. */
static unsigned char *put_s(const rcb_monitor *mon, const double *s, unsigned char *q) {
  size_t j, a;
  for (j = 0; j < mon->ncand; j++)
    for (a = 0; a < mon->cand[j].dof; a++, q += 8) rcb_mon_put_f64(q, s[j * RCB_MONITOR_MAXP + a]);
  return q;
}
static const unsigned char *get_s(const rcb_monitor *mon, double *s, const unsigned char *r) {
  size_t j, a;
  for (j = 0; j < mon->ncand; j++)
    for (a = 0; a < mon->cand[j].dof; a++, r += 8) s[j * RCB_MONITOR_MAXP + a] = rcb_mon_get_f64(r);
  return r;
}

/* Version 3: after the tracked parameters, each one's reference sums of
 * every tracked step (the baseline's share of the allowance, bref), nt x nt
 * binary64. */
static size_t bref_bytes(const rcb_monitor *mon) { return (size_t)8 * mon->nt * mon->nt; }

size_t rcb_monitor_state_size(const rcb_monitor *mon) {
  return ready(mon) ? ST_HEAD + ST_PER * mon->nt + bref_bytes(mon) + drift_bytes(mon) + ST_CRC
                    : 0;
}

static void save_drift(const rcb_monitor *mon, unsigned char *q) {
  size_t i, s, k = mon->k, nt = mon->nt;
  put_u32(q, (uint32_t)k), put_u32(q + 4, (uint32_t)nt), put_u32(q + 8, MON_DRIFT_WINDOW);
  put_u32(q + 12, (uint32_t)mon->dcount), put_u32(q + 16, (uint32_t)mon->dhead);
  rcb_mon_put_u64(q + 20, (uint64_t)mon->dall), put_u32(q + 28, (uint32_t)mon->dfree);
  q += ST_DRIFT_HEAD;
  for (i = 0; i < k; i++, q += 8) rcb_mon_put_f64(q, mon->dysum[i]);
  for (i = 0; i < nt; i++, q += 8) rcb_mon_put_f64(q, mon->dthsum[i]);
  q = put_s(mon, mon->dssum, q);
  for (s = 0; s < MON_DRIFT_WINDOW; s++) {
    for (i = 0; i < k; i++, q += 8) rcb_mon_put_f64(q, mon->dy[s * k + i]);
    for (i = 0; i < nt; i++, q += 8) rcb_mon_put_f64(q, mon->dth[s * RCB_MONITOR_MAX_TRACKED + i]);
    q = put_s(mon, mon->ds + s * mon->ncand * RCB_MONITOR_MAXP, q);
  }
}

/* The drift window, checked before anything is changed against what the
 * update writes (monitor_drift.c, push and reset): its dimensions, at most
 * the monitor's updates in its sums (none before the first update), the
 * ring's count min(updates in the sums, window) and its newest slot the last
 * of them, finite values, and sums of zero while no update is in them. */
static rcb_status check_drift(rcb_monitor *mon, const unsigned char *q, uint64_t updates,
                              int started) {
  const size_t W = MON_DRIFT_WINDOW, nsum = mon->k + mon->nt + cand_dofs(mon);
  const uint64_t dall = rcb_mon_get_u64(q + 20);
  const uint32_t cnt = get_u32(q + 12), head = get_u32(q + 16);
  size_t i, n = (W + 1u) * nsum;
  if (get_u32(q) != mon->k || get_u32(q + 4) != mon->nt || get_u32(q + 8) != W)
    return rcb_mon_fail(mon, RCB_ERR_CORRUPT, "state: the drift window's dimensions (rank %lu, "
                        "%lu tracked, window %lu) are not this monitor's (%zu, %zu, %zu): "
                        ST_NOT_WRITTEN, (unsigned long)get_u32(q), (unsigned long)get_u32(q + 4),
                        (unsigned long)get_u32(q + 8), mon->k, mon->nt, W);
  if (dall > updates || (!started && dall))
    return rcb_mon_fail(mon, RCB_ERR_CORRUPT, "state: the drift window holds %llu updates in "
                        "its sums, the monitor %llu%s: " ST_NOT_WRITTEN,
                        (unsigned long long)dall, (unsigned long long)updates,
                        started ? "" : " before its first update");
  if (cnt != (dall < W ? dall : W) || head != (dall ? (dall - 1u) % W : 0u))
    return rcb_mon_fail(mon, RCB_ERR_CORRUPT, "state: the drift window's ring count %lu and "
                        "newest slot %lu, with %llu updates in its sums (expected %llu and "
                        "%llu): " ST_NOT_WRITTEN, (unsigned long)cnt, (unsigned long)head,
                        (unsigned long long)dall, (unsigned long long)(dall < W ? dall : W),
                        (unsigned long long)(dall ? (dall - 1u) % W : 0u));
  if (get_u32(q + 28) > 1)
    return rcb_mon_fail(mon, RCB_ERR_CORRUPT, "state: the drift window's free-offset flag %lu, "
                        "expected 0 or 1: " ST_NOT_WRITTEN, (unsigned long)get_u32(q + 28));
  for (i = 0, q += ST_DRIFT_HEAD; i < n; i++, q += 8) {
    double v = rcb_mon_get_f64(q);
    if (!isfinite(v) || (i < nsum && !dall && v != 0))
      return rcb_mon_fail(mon, RCB_ERR_CORRUPT, "state: the drift window's %s %zu = %g, "
                          "expected %s: " ST_NOT_WRITTEN, i < nsum ? "sum" : "value",
                          i < nsum ? i + 1 : (i - nsum) % nsum + 1, v,
                          isfinite(v) ? "0 with no update in the sums" : "finite");
  }
  return RCB_OK;
}

static void load_drift(rcb_monitor *mon, const unsigned char *q) {
  size_t i, s, k = mon->k, nt = mon->nt;
  mon->dcount = get_u32(q + 12), mon->dhead = get_u32(q + 16);
  mon->dall = (size_t)rcb_mon_get_u64(q + 20), mon->dfree = get_u32(q + 28) != 0;
  q += ST_DRIFT_HEAD;
  for (i = 0; i < k; i++, q += 8) mon->dysum[i] = rcb_mon_get_f64(q);
  memset(mon->dthsum, 0, sizeof mon->dthsum);
  for (i = 0; i < nt; i++, q += 8) mon->dthsum[i] = rcb_mon_get_f64(q);
  q = get_s(mon, mon->dssum, q);
  for (s = 0; s < MON_DRIFT_WINDOW; s++) {
    for (i = 0; i < k; i++, q += 8) mon->dy[s * k + i] = rcb_mon_get_f64(q);
    for (i = 0; i < nt; i++, q += 8) mon->dth[s * RCB_MONITOR_MAX_TRACKED + i] = rcb_mon_get_f64(q);
    q = get_s(mon, mon->ds + s * mon->ncand * RCB_MONITOR_MAXP, q);
  }
}

rcb_status rcb_monitor_save(const rcb_monitor *mon, void *buf, size_t size, size_t *written) {
  unsigned char *b = buf, *q;
  size_t need = rcb_monitor_state_size(mon), a;
  double sig[2];
  if (written) *written = 0;
  if (!need) return RCB_ERR_STATE;
  if (!buf || size < need) return RCB_ERR_WORKSPACE;
  memset(b, 0, need);
  b[0] = 'R', b[1] = 'C', b[2] = 'B', b[3] = 'M';
  put_u32(b + 4, RCB_MONITOR_STATE_VERSION);
  put_u32(b + 8, (uint32_t)need);
  put_u32(b + 12, (uint32_t)mon->nt);
  rcb_mon_put_u64(b + 16, model_hash(mon, sig));
  rcb_mon_put_f64(b + 24, sig[0]);
  rcb_mon_put_f64(b + 32, sig[1]);
  rcb_mon_put_u64(b + 40, setup_hash(mon));
  rcb_mon_put_u64(b + 48, settings_hash(mon));
  rcb_mon_put_u64(b + 56, (uint64_t)mon->updates);
  put_u32(b + 64, (uint32_t)mon->ref_started);
  for (a = 0, q = b + ST_HEAD; a < mon->nt; a++, q += ST_PER) {
    rcb_mon_put_f64(q, mon->cus_up[a]);
    rcb_mon_put_f64(q + 8, mon->cus_dn[a]);
    rcb_mon_put_f64(q + 16, mon->ref_sum[a]);
    rcb_mon_put_f64(q + 24, mon->ref_w[a]);
    put_u32(q + 32, (uint32_t)mon->ref_frozen[a]);
  }
  for (a = 0; a < mon->nt * mon->nt; a++, q += 8)
    rcb_mon_put_f64(q, mon->bref[(a / mon->nt) * RCB_MONITOR_MAX_TRACKED + a % mon->nt]);
  save_drift(mon, q);
  put_u32(b + need - ST_CRC, (uint32_t)rcb_monitor_crc32(0, b, need - ST_CRC));
  if (written) *written = need;
  return RCB_OK;
}

static int sig_differs(double x, double y) {
  return !(fabs(x - y) <= ST_SIG_TOL * fmax(fabs(x), fabs(y)));
}

/* The header's checks, in the order a reader needs them: what it is, its
 * version (a newer layout may move everything after it), its integrity,
 * whose it is, and then its length (of a state of this monitor: a shorter
 * one with a CRC of its own was cut short, not saved by another model). */
static rcb_status check(rcb_monitor *mon, const unsigned char *b, size_t size) {
  size_t need = rcb_monitor_state_size(mon), len;
  uint32_t ver;
  double sig[2];
  if (size < 16 || memcmp(b, ST_MAGIC, 4) != 0)
    return rcb_mon_fail(mon, RCB_ERR_CORRUPT, "state: %zu bytes that do not begin with '%s': "
                        "not a monitor state (rcb_monitor_save)", size, ST_MAGIC);
  if ((ver = get_u32(b + 4)) != RCB_MONITOR_STATE_VERSION)
    return rcb_mon_fail(mon, RCB_ERR_VERSION, "state: format version %lu, this library reads "
                        "version %u; replay the series to rebuild it", (unsigned long)ver,
                        RCB_MONITOR_STATE_VERSION);
  len = get_u32(b + 8);
  if (len < ST_HEAD + ST_CRC || len > size)
    return rcb_mon_fail(mon, RCB_ERR_CORRUPT, "state: it says %zu bytes, %zu were given "
                        "(truncated)", len, size);
  if (get_u32(b + len - ST_CRC) != (uint32_t)rcb_monitor_crc32(0, b, len - ST_CRC))
    return rcb_mon_fail(mon, RCB_ERR_CORRUPT, "state: CRC-32 does not match (the %zu bytes "
                        "were changed or damaged)", len);
  if (get_u32(b + 12) != mon->nt)
    return rcb_mon_fail(mon, RCB_ERR_OTHER_MODEL, "state: %lu tracked parameters, this "
                        "monitor tracks %zu", (unsigned long)get_u32(b + 12), mon->nt);
  if (rcb_mon_get_u64(b + 16) != model_hash(mon, sig) || sig_differs(rcb_mon_get_f64(b + 24), sig[0]) ||
      sig_differs(rcb_mon_get_f64(b + 32), sig[1]))
    return rcb_mon_fail(mon, RCB_ERR_OTHER_MODEL, "state: saved from another baseline model "
                        "(tracked parameters, their baseline values, the candidate effects "
                        "or the model's response differ); create the monitor from the model "
                        "the state was saved with, or, when a newer library changed the "
                        "candidates, replay the series to rebuild the state");
  if (rcb_mon_get_u64(b + 40) != setup_hash(mon))
    return rcb_mon_fail(mon, RCB_ERR_OTHER_SETUP, "state: saved with another set-up "
                        "(channels, points, speed or commissioning values differ)");
  if (rcb_mon_get_u64(b + 48) != settings_hash(mon))
    return rcb_mon_fail(mon, RCB_ERR_OTHER_SETUP, "state: saved with other settings (alpha, "
                        "CUSUM k or h, noise, averages, re-linearisation, reweighting or "
                        "tracked ranges differ)");
  if (len != need)
    return rcb_mon_fail(mon, RCB_ERR_CORRUPT, "state: %zu bytes, a state of this monitor has "
                        "%zu (truncated or damaged, its CRC-32 made again)", len, need);
  return RCB_OK;
}

/* The update count and the reference-started flag (then the padding after
 * it, written 0). */
static rcb_status check_counts(rcb_monitor *mon, const unsigned char *b) {
  uint64_t updates = rcb_mon_get_u64(b + 56);
  if (updates > RCB_MONITOR_MAX_UPDATES)
    return rcb_mon_fail(mon, RCB_ERR_CORRUPT, "state: update count %llu, more than a monitor "
                        "takes (%llu, RCB_MONITOR_MAX_UPDATES): " ST_NOT_WRITTEN,
                        (unsigned long long)updates,
                        (unsigned long long)RCB_MONITOR_MAX_UPDATES);
  if (get_u32(b + 64) > 1 || get_u32(b + 68) != 0)
    return rcb_mon_fail(mon, RCB_ERR_CORRUPT, "state: reference-started flag %lu (and padding "
                        "%lu), expected 0 or 1 (and 0): " ST_NOT_WRITTEN,
                        (unsigned long)get_u32(b + 64), (unsigned long)get_u32(b + 68));
  return RCB_OK;
}

/* Tracked parameter a's fields against what the update writes
 * (monitor.c, tracked_result and innovation): CUSUMs finite and >= 0, the
 * reference's sum finite and its weight finite and >= 0 (+inf only for a
 * noise-free reference, setup_averages HUGE_VAL), sums of 0 while the
 * weight is 0 (no update in the reference) and everything 0 before the
 * first update; the frozen flag 0 or 1 and the padding after it 0; its row
 * of the reference's sums of every step (bref) finite, and 0 without
 * opts.baseline_cov (then never accumulated). */
static const char *tracked_want(const rcb_monitor *mon, const double *v, int started,
                                size_t *bad) {
  size_t i;
  for (i = 0; i < 4; i++) {
    *bad = i;
    if (i == 2 ? !isfinite(v[i]) : !(v[i] >= 0)) return i == 2 ? "finite" : "finite >= 0";
    if (isinf(v[i]) && !(i == 3 && mon->navg_inv == 0))
      return i == 3 ? "finite >= 0 (+inf only for a noise-free reference)" : "finite >= 0";
    if (v[i] != 0 && !started) return "0 before the first update";
  }
  *bad = 2;
  return v[3] == 0 && v[2] != 0 ? "0 while the reference's weight is 0" : NULL;
}

static rcb_status check_tracked(rcb_monitor *mon, const unsigned char *b, size_t a,
                                int started) {
  static const char *const field[4] = {"CUSUM S+", "CUSUM S-", "reference sum",
                                       "reference weight"};
  const unsigned char *q = b + ST_HEAD + ST_PER * a;
  const unsigned char *r = b + ST_HEAD + ST_PER * mon->nt + 8 * mon->nt * a;
  const char *want;
  double v[4];
  size_t i, j;
  for (i = 0; i < 4; i++) v[i] = rcb_mon_get_f64(q + 8 * i);
  if ((want = tracked_want(mon, v, started, &i)))
    return rcb_mon_fail(mon, RCB_ERR_CORRUPT, "state: tracked parameter %zu (%s): %s = %g, "
                        "expected %s: " ST_NOT_WRITTEN, a + 1, mon->tname[a], field[i], v[i],
                        want);
  if (get_u32(q + 32) > (uint32_t)started || get_u32(q + 36) != 0)
    return rcb_mon_fail(mon, RCB_ERR_CORRUPT, "state: tracked parameter %zu (%s): frozen flag "
                        "%lu (and padding %lu), expected %s (and 0): " ST_NOT_WRITTEN, a + 1,
                        mon->tname[a], (unsigned long)get_u32(q + 32),
                        (unsigned long)get_u32(q + 36), started ? "0 or 1" : "0");
  for (j = 0; j < mon->nt; j++, r += 8) {
    double x = rcb_mon_get_f64(r);
    if (!isfinite(x) || (x != 0 && (!mon->bcurv || v[3] == 0)))
      return rcb_mon_fail(mon, RCB_ERR_CORRUPT, "state: tracked parameter %zu (%s): the "
                          "reference's sum of step %zu = %g, expected %s: " ST_NOT_WRITTEN,
                          a + 1, mon->tname[a], j + 1, x,
                          !isfinite(x) ? "finite"
                          : mon->bcurv ? "0 while the reference's weight is 0"
                                       : "0 without opts.baseline_cov");
  }
  return RCB_OK;
}

/* Every field against what a monitor writes, before anything is changed. */
static rcb_status check_fields(rcb_monitor *mon, const unsigned char *b) {
  int started = get_u32(b + 64) != 0;
  size_t a;
  rcb_status st;
  if ((st = check_counts(mon, b))) return st;
  for (a = 0; a < mon->nt; a++)
    if ((st = check_tracked(mon, b, a, started))) return st;
  return check_drift(mon, b + ST_HEAD + ST_PER * mon->nt + bref_bytes(mon), rcb_mon_get_u64(b + 56),
                     started);
}

rcb_status rcb_monitor_load(rcb_monitor *mon, const void *buf, size_t size) {
  const unsigned char *b = buf, *q;
  size_t a;
  rcb_status st;
  if (!mon) return RCB_ERR_ARG;
  if (!ready(mon))
    return rcb_mon_fail(mon, RCB_ERR_STATE, "rcb_monitor_load: the monitor was not created "
                        "successfully");
  if (!buf) return rcb_mon_fail(mon, RCB_ERR_ARG, "rcb_monitor_load: no buffer");
  if ((st = check(mon, b, size)) || (st = check_fields(mon, b))) return st;
  load_drift(mon, b + ST_HEAD + ST_PER * mon->nt + bref_bytes(mon));
  memset(mon->bref, 0, sizeof mon->bref);
  for (a = 0, q = b + ST_HEAD + ST_PER * mon->nt; a < mon->nt * mon->nt; a++, q += 8)
    mon->bref[(a / mon->nt) * RCB_MONITOR_MAX_TRACKED + a % mon->nt] = rcb_mon_get_f64(q);
  mon->updates = (size_t)rcb_mon_get_u64(b + 56); /* <= RCB_MONITOR_MAX_UPDATES: check_counts */
  mon->ref_started = get_u32(b + 64) != 0;
  for (a = 0, q = b + ST_HEAD; a < mon->nt; a++, q += ST_PER) {
    mon->cus_up[a] = rcb_mon_get_f64(q);
    mon->cus_dn[a] = rcb_mon_get_f64(q + 8);
    mon->ref_sum[a] = rcb_mon_get_f64(q + 16);
    mon->ref_w[a] = rcb_mon_get_f64(q + 24);
    mon->ref_frozen[a] = get_u32(q + 32) != 0;
  }
  return RCB_OK;
}

rcb_status rcb_monitor_thresholds(const rcb_monitor *mon, double *alpha, double *threshold,
                                  double *cusum_k, double *cusum_h) {
  if (!ready(mon)) return RCB_ERR_STATE;
  if (alpha) *alpha = mon->alpha;
  if (threshold) *threshold = mon->threshold;
  if (cusum_k) *cusum_k = mon->cusum_k;
  if (cusum_h) *cusum_h = mon->cusum_h;
  return RCB_OK;
}
