/*
 * rcb_monitor_load against states no monitor writes (issue #34 item 7, "a
 * state file that cannot lie"). A monitor on the paper system (4 response
 * channels x 60 frequencies, kt tracked, a small catalogue) runs a noisy
 * series with this test's own generator; its saved state is then patched
 * field by field, the CRC-32 made again (so that only the field checks can
 * refuse it), and loaded into a second monitor:
 *  - an infinite or NaN CUSUM, an infinite reference sum and weight, a
 *    negative weight, an update count or drift counter of 2^64 - 1, an update
 *    count of 0 with updates in the drift ring, a ring count or newest slot
 *    that does not follow from the updates in the sums, flags other than 0
 *    or 1, a cut-short state with its own length and CRC: each refused with
 *    RCB_ERR_CORRUPT, a message naming the field, and the monitor left as
 *    it was;
 *  - the null case: the untouched state loads, and the next update equals
 *    the uninterrupted monitor's bit for bit;
 *  - the states that are written must load: 200 updates (a drift of kt that
 *    alarms and freezes the reference, a CUSUM reset half-way, the ring
 *    wrapping), saved after many of them, each loads into a new monitor and
 *    saves back to the same bytes; on the noise-free reference too (+inf
 *    reference weight, which the monitor writes there), with and without
 *    opts.baseline_cov;
 *  - the update count at RCB_MONITOR_MAX_UPDATES: that state loads, the
 *    next update is refused (RCB_ERR_STATE), one more in the state is refused;
 *  - the commissioning image (rcb_monitor_opts.image): the monitor made from
 *    it updates as the full create's, bit for bit; damaged, cut short, of
 *    another version or of other options, it is refused.
 */
#include <complex.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "monitor/monitor_internal.h" /* white box: the update count near its maximum */
#include "rcb/rcb.h"
#include "rcb_test_util.h"

#define NCH ((size_t)4)
#define NPTS ((size_t)60)
#define NPT (NCH * NPTS)
#define KT_NAME "coupling.C.kt"
#define STMAX 8192 /* bytes: the states here take ~5 kB */

/* rcb_monitor.h's layout (version 3), one tracked parameter */
#define OFF_UPDATES 56
#define OFF_STARTED 64
#define OFF_PAD 68
#define OFF_CUS_UP 72
#define OFF_CUS_DN 80
#define OFF_REF_SUM 88
#define OFF_REF_W 96
#define OFF_FROZEN 104
#define OFF_BREF 112
#define OFF_DRIFT 120 /* 72 + 40 + 8 */
#define OFF_DCOUNT (OFF_DRIFT + 12)
#define OFF_DHEAD (OFF_DRIFT + 16)
#define OFF_DALL (OFF_DRIFT + 20)
#define OFF_DFREE (OFF_DRIFT + 28)
#define OFF_DSUM (OFF_DRIFT + 32)

static const char *const OUTS[NCH] = {"C.A.x", "C.A.y", "C.B.x", "C.B.y"};
static const char *const INS[1] = {"DA.x"};

/* ---- the test's own noise: splitmix64, Box-Muller ---- */

static uint64_t rng_next(uint64_t *s) {
  uint64_t z = (*s += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}
static double rng_normal(uint64_t *s) {
  double u1 = ((double)(rng_next(s) >> 11) + 0.5) * 0x1.0p-53;
  double u2 = (double)(rng_next(s) >> 11) * 0x1.0p-53;
  return sqrt(-2.0 * log(u1)) * cos(2.0 * 3.14159265358979323846 * u2);
}

/* ---- little-endian fields ---- */

static void put_u32(unsigned char *p, uint32_t v) {
  int i;
  for (i = 0; i < 4; i++) p[i] = (unsigned char)(v >> (8 * i));
}
static void put_u64(unsigned char *p, uint64_t v) {
  int i;
  for (i = 0; i < 8; i++) p[i] = (unsigned char)(v >> (8 * i));
}
static uint64_t get_u64(const unsigned char *p) {
  uint64_t v = 0;
  int i;
  for (i = 7; i >= 0; i--) v = (v << 8) | p[i];
  return v;
}
static void put_f64(unsigned char *p, double x) {
  uint64_t v;
  memcpy(&v, &x, sizeof v);
  put_u64(p, v);
}
static double get_f64(const unsigned char *p) {
  uint64_t v = get_u64(p);
  double x;
  memcpy(&x, &v, sizeof x);
  return x;
}
/* The CRC-32 of the first n - 4 bytes into the last 4. */
static void rewrite_crc(unsigned char *b, size_t n) {
  put_u32(b + n - 4, (uint32_t)rcb_monitor_crc32(0, b, n - 4));
}

/* ---- the series ---- */

typedef struct fixture {
  rcb_model *base;
  rcb_meas *setup;   /* commissioning values: the truth's FRFs, noisy */
  rcb_complex *fs;   /* the truth's FRFs, channel-major */
  rcb_complex *dh;   /* d(FRF)/d(kt), channel-major */
  rcb_complex *v;    /* one update's values */
  double kt, se;
} fixture;

static void values_of(const rcb_meas *ms, rcb_complex *v) {
  size_t c;
  for (c = 0; c < rcb_meas_channel_count(ms); c++) {
    rcb_meas_channel_info ci;
    assert_int_equal(rcb_meas_channel(ms, c, &ci), RCB_OK);
    memcpy(v + c * NPTS, ci.data, NPTS * sizeof *v);
  }
}

static rcb_model *edited(const rcb_model *m, const char *name, double value) {
  rcb_model *c = NULL;
  assert_int_equal(rcb_model_clone(&c, m, NULL), RCB_OK);
  assert_int_equal(rcb_model_finalize(c), RCB_OK);
  assert_int_equal(rcb_model_set_param(c, name, value), RCB_OK);
  return c;
}

static rcb_meas *frf_of(const rcb_model *m) {
  return rcb_test_frf_meas(m, OUTS, NCH, INS, 1, 100.0, 400.0, NPTS, 10000.0, RCB_INERTANCE);
}

/* Noise of the settings' kind (eq. 19 with beta_a 2 %, beta_s 0.5 %, as
 * normal variables): 1 % along each value (sd 1.15 % in the settings) and
 * a circular part of sd a / sqrt(6) per component, a = 0.5 % of the
 * channel's root sum of squares over its points / points; then a step of dkt
 * in kt (linearised). */
static void noisy(const fixture *f, double dkt, uint64_t *seed, rcb_complex *out) {
  size_t c, i;
  for (c = 0; c < NCH; c++) {
    const rcb_complex *e = f->fs + c * NPTS;
    double s2 = 0, sd;
    for (i = 0; i < NPTS; i++) s2 += creal(e[i] * conj(e[i]));
    sd = 0.005 * sqrt(s2) / (double)NPTS / sqrt(6.0);
    for (i = 0; i < NPTS; i++) {
      double re = rng_normal(seed), im = rng_normal(seed);
      out[c * NPTS + i] = e[i] * (1.0 + 0.01 * rng_normal(seed)) + sd * CMPLX(re, im) +
                          dkt * f->dh[c * NPTS + i];
    }
  }
}

static int fixture_setup(void **state) {
  fixture *f = calloc(1, sizeof *f);
  rcb_model *m2;
  rcb_meas *ms, *mt;
  rcb_complex *acc;
  uint64_t seed = 7;
  size_t c, i;
  double kxx;
  f->base = rcb_test_model_from_example("paper_system.ini");
  assert_int_equal(rcb_model_get_param(f->base, KT_NAME, &f->kt), RCB_OK);
  assert_int_equal(rcb_model_get_param(f->base, "bearing.B3.kxx", &kxx), RCB_OK);
  {
    rcb_model *truth = edited(f->base, "bearing.B3.kxx", 1.05 * kxx); /* a model bias */
    f->fs = malloc(NPT * sizeof *f->fs);
    f->dh = malloc(NPT * sizeof *f->dh);
    f->v = malloc(NPT * sizeof *f->v);
    acc = calloc(NPT, sizeof *acc);
    mt = frf_of(truth);
    values_of(mt, f->fs);
    m2 = edited(truth, KT_NAME, 1.001 * f->kt);
    ms = frf_of(m2);
    values_of(ms, f->dh);
    for (i = 0; i < NPT; i++) f->dh[i] = (f->dh[i] - f->fs[i]) / (1e-3 * f->kt);
    rcb_meas_destroy(ms);
    rcb_model_destroy(m2);
    rcb_model_destroy(truth);
  }
  /* commissioning: 4 noisy measurements averaged */
  for (c = 0; c < 4; c++) {
    noisy(f, 0.0, &seed, f->v);
    for (i = 0; i < NPT; i++) acc[i] += f->v[i] / 4.0;
  }
  assert_int_equal(rcb_meas_create(&f->setup, NULL), RCB_OK);
  assert_int_equal(rcb_meas_set_grid(f->setup, RCB_MEAS_FRF, NPTS, rcb_meas_grid(mt),
                                     rcb_meas_speed(mt)), RCB_OK);
  for (c = 0; c < NCH; c++) {
    rcb_meas_channel_info ci;
    assert_int_equal(rcb_meas_channel(mt, c, &ci), RCB_OK);
    assert_int_equal(rcb_meas_add_channel(f->setup, ci.response, ci.reference, ci.kind,
                                          acc + c * NPTS), RCB_OK);
  }
  rcb_meas_destroy(mt);
  free(acc);
  *state = f;
  return 0;
}

static int fixture_teardown(void **state) {
  fixture *f = *state;
  rcb_model_destroy(f->base);
  rcb_meas_destroy(f->setup);
  free(f->fs);
  free(f->dh);
  free(f->v);
  free(f);
  return 0;
}

/* The settings: kt tracked, 2 % noise, a catalogue of two families;
 * navg averages in the reference (HUGE_VAL: noise-free), with bvar
 * (non-NULL) as opts.baseline_cov. */
static rcb_monitor *monitor_of(const fixture *f, rcb_monitor_param *tp, double navg,
                               const double *bvar) {
  rcb_monitor_opts o;
  rcb_monitor *mon = NULL;
  memset(&o, 0, sizeof o);
  tp->name = KT_NAME, tp->lo = 0.5 * f->kt, tp->hi = 1.5 * f->kt;
  o.ntracked = 1, o.tracked = tp;
  o.beta_a = 2.0, o.beta_s = 0.5;
  o.setup_averages = navg;
  o.baseline_cov = bvar;
  o.effects = (1u << RCB_EFFECT_BEARING_CROSS_COUPLING) | (1u << RCB_EFFECT_BEARING_STIFFNESS);
  assert_int_equal(rcb_monitor_create(&mon, f->base, f->setup, &o, NULL), RCB_OK);
  return mon;
}

static int same_result(const rcb_monitor_result *a, const rcb_monitor_result *b) {
  return a->update == b->update && a->alarm == b->alarm && a->cusum_alarm == b->cusum_alarm &&
         memcmp(&a->T, &b->T, sizeof a->T) == 0 && a->ntracked == b->ntracked &&
         memcmp(&a->tracked[0], &b->tracked[0], sizeof a->tracked[0]) == 0 &&
         memcmp(&a->drift_glr, &b->drift_glr, sizeof a->drift_glr) == 0 &&
         a->drift_index == b->drift_index && a->drift_onset == b->drift_onset;
}

/* ---- crafted states ---- */

typedef struct crafted {
  const char *what;
  size_t off;     /* the field */
  int kind;       /* 0: u32, 1: u64, 2: f64 */
  uint64_t u;     /* its value (u32, u64) */
  double x;       /* its value (f64) */
  const char *msg; /* words the message must hold */
} crafted;

static void patch(unsigned char *b, const crafted *c) {
  if (c->kind == 0) put_u32(b + c->off, (uint32_t)c->u);
  if (c->kind == 1) put_u64(b + c->off, c->u);
  if (c->kind == 2) put_f64(b + c->off, c->x);
}

/* load must refuse b (n bytes) with st and a message holding every word
 * of msg (separated by '|'), and leave mon as keep (its state before). */
static void refused(rcb_monitor *mon, const unsigned char *b, size_t n, rcb_status st,
                    const char *what, const char *msg, const unsigned char *keep,
                    size_t nkeep) {
  static unsigned char now[STMAX];
  const char *w = msg, *e;
  size_t m = 0;
  rcb_status got = rcb_monitor_load(mon, b, n);
  print_message("  %-46s %s: %s\n", what, rcb_status_str(got), rcb_monitor_errmsg(mon));
  assert_int_equal(got, st);
  for (; *w; w = *e ? e + 1 : e) {
    char word[128];
    e = strchr(w, '|');
    if (!e) e = w + strlen(w);
    snprintf(word, sizeof word, "%.*s", (int)(e - w), w);
    if (!strstr(rcb_monitor_errmsg(mon), word)) {
      print_message("the message lacks '%s'\n", word);
      fail();
    }
  }
  assert_int_equal(rcb_monitor_save(mon, now, sizeof now, &m), RCB_OK);
  assert_int_equal(m, nkeep);
  assert_memory_equal(now, keep, nkeep); /* left as it was */
}

/* Five updates saved; each field patched (CRC made again) refused; the
 * untouched state loads and continues as the monitor that ran on. */
static void test_crafted(void **state) {
  fixture *f = *state;
  static unsigned char buf[STMAX], b[STMAX], keep[STMAX];
  const double inf = (double)INFINITY, nan = (double)NAN;
  const crafted cases[] = {
      {"infinite CUSUM S+ (a permanent alarm)", OFF_CUS_UP, 2, 0, inf, "CUSUM S+|finite"},
      {"NaN CUSUM S-", OFF_CUS_DN, 2, 0, nan, "CUSUM S-|finite >= 0"},
      {"negative CUSUM S-", OFF_CUS_DN, 2, 0, -1.0, "CUSUM S-"},
      {"infinite reference sum", OFF_REF_SUM, 2, 0, inf, "reference sum|finite"},
      {"NaN reference sum", OFF_REF_SUM, 2, 0, nan, "reference sum"},
      {"infinite reference weight (setup_averages 4)", OFF_REF_W, 2, 0, inf,
       "reference weight|noise-free"},
      {"negative reference weight", OFF_REF_W, 2, 0, -1.0, "reference weight"},
      {"reference's step sum NaN", OFF_BREF, 2, 0, nan, "reference's sum of step 1"},
      {"update count 2^64 - 1", OFF_UPDATES, 1, UINT64_MAX, 0, "update count|MAX_UPDATES"},
      {"update count 2^32 (one past the maximum)", OFF_UPDATES, 1, 1ull << 32, 0,
       "update count 4294967296"},
      {"update count 0 with 5 updates in the ring", OFF_UPDATES, 1, 0, 0,
       "drift window holds 5 updates|the monitor 0"},
      {"drift counter 2^64 - 1", OFF_DALL, 1, UINT64_MAX, 0, "drift window holds"},
      {"ring count 4 with 5 updates in the sums", OFF_DCOUNT, 0, 4, 0, "ring count 4"},
      {"newest slot 0 with 5 updates in the sums", OFF_DHEAD, 0, 0, 0, "newest slot 0"},
      {"drift sum infinite", OFF_DSUM, 2, 0, inf, "drift window's sum 1"},
      {"free-offset flag 2", OFF_DFREE, 0, 2, 0, "free-offset flag 2"},
      {"frozen flag 2", OFF_FROZEN, 0, 2, 0, "frozen flag 2"},
      {"padding after the frozen flag", OFF_FROZEN + 4, 0, 1, 0, "padding 1"},
      {"reference-started flag 7", OFF_STARTED, 0, 7, 0, "reference-started flag 7"},
      {"reference not started after 5 updates", OFF_STARTED, 0, 0, 0,
       "before the first update"},
      {"padding after the reference-started flag", OFF_PAD, 0, 1, 0, "padding 1"},
  };
  rcb_monitor_param tp, tp2;
  rcb_monitor *a = monitor_of(f, &tp, 4.0, NULL), *c = monitor_of(f, &tp2, 4.0, NULL);
  rcb_monitor_result ra, rc;
  uint64_t seed = 11;
  size_t u, k, n = 0, nkeep = 0;
  for (u = 0; u < 5; u++) {
    noisy(f, 0.0, &seed, f->v);
    assert_int_equal(rcb_monitor_update(a, f->v, NULL, &ra), RCB_OK);
  }
  assert_int_equal(rcb_monitor_save(a, buf, sizeof buf, &n), RCB_OK);
  /* the layout this test patches: one tracked parameter, 5 updates, all in
   * the drift ring, the reference started and its weight finite > 0 */
  assert_int_equal(get_u64(buf + OFF_UPDATES), 5);
  assert_int_equal(get_u64(buf + OFF_DALL), 5);
  assert_int_equal(buf[OFF_DCOUNT], 5);
  assert_int_equal(buf[OFF_DHEAD], 4);
  assert_int_equal(buf[OFF_STARTED], 1);
  assert_true(get_f64(buf + OFF_REF_W) > 0 && isfinite(get_f64(buf + OFF_REF_W)));
  assert_int_equal(rcb_monitor_save(c, keep, sizeof keep, &nkeep), RCB_OK);
  for (k = 0; k < sizeof cases / sizeof cases[0]; k++) {
    memcpy(b, buf, n);
    patch(b, &cases[k]);
    rewrite_crc(b, n);
    refused(c, b, n, RCB_ERR_CORRUPT, cases[k].what, cases[k].msg, keep, nkeep);
  }
  /* the infinite reference sum and weight together (NaN u, a CUSUM silenced for good) */
  memcpy(b, buf, n);
  put_f64(b + OFF_REF_SUM, inf), put_f64(b + OFF_REF_W, inf);
  rewrite_crc(b, n);
  refused(c, b, n, RCB_ERR_CORRUPT, "infinite reference sum and weight", "reference sum|finite",
          keep, nkeep);
  /* cut short, its length field and CRC made for the shorter content: by
   * 8 bytes, by 264 (the length of a monitor with one scored direction
   * less) and down to the header */
  {
    size_t cut[] = {8, 264, n - 76};
    for (k = 0; k < sizeof cut / sizeof cut[0]; k++) {
      size_t m = n - cut[k];
      memcpy(b, buf, m);
      put_u32(b + 8, (uint32_t)m);
      rewrite_crc(b, m);
      refused(c, b, m, RCB_ERR_CORRUPT, "cut short, length and CRC made again", "truncated",
              keep, nkeep);
      assert_null(strstr(rcb_monitor_errmsg(c), "another"));
      assert_null(strstr(rcb_monitor_errmsg(c), "tracked parameters"));
    }
  }
  /* the null case: the untouched state loads, and the next update is the
   * uninterrupted monitor's */
  assert_int_equal(rcb_monitor_load(c, buf, n), RCB_OK);
  assert_int_equal(rcb_monitor_update_count(c), 5);
  for (u = 0; u < 3; u++) {
    noisy(f, 0.0, &seed, f->v);
    assert_int_equal(rcb_monitor_update(a, f->v, NULL, &ra), RCB_OK);
    assert_int_equal(rcb_monitor_update(c, f->v, NULL, &rc), RCB_OK);
    assert_int_equal(rc.update, 6 + u);
    assert_true(same_result(&ra, &rc));
  }
  rcb_monitor_destroy(a);
  rcb_monitor_destroy(c);
}

/* 200 updates: kt drifts from update 60 (the CUSUM alarms, the reference
 * freezes), the CUSUM is reset at update 120 (the drift sums restart, the
 * offset free); the state saved after many updates (either side of the
 * ring's wrap, of the alarm and of the reset) loads into a new monitor and
 * saves back to its own bytes. */
static void long_run(const fixture *f, double navg, const double *bvar) {
  static unsigned char buf[STMAX], back[STMAX];
  rcb_monitor_param tp, tp2;
  rcb_monitor *a = monitor_of(f, &tp, navg, bvar), *c = monitor_of(f, &tp2, navg, bvar);
  rcb_monitor_result r;
  uint64_t seed = 23;
  size_t u, n = 0, m = 0, loads = 0, alarms = 0, infw = 0;
  double se = 0;
  assert_int_equal(rcb_monitor_save(a, buf, sizeof buf, &n), RCB_OK); /* no update yet */
  assert_int_equal(rcb_monitor_load(c, buf, n), RCB_OK);
  for (u = 1; u <= 200; u++) {
    double dkt = u < 60 ? 0.0 : -0.15 * se * (double)(u - 59);
    noisy(f, dkt, &seed, f->v);
    assert_int_equal(rcb_monitor_update(a, f->v, NULL, &r), RCB_OK);
    if (u == 1) se = r.tracked[0].stderr_;
    alarms += r.tracked[0].cusum_alarm != 0;
    if (u == 120) rcb_monitor_reset_cusum(a);
    if (u <= 40 || u % 7 == 0 || (u >= 118 && u <= 160) || u == 200) {
      assert_int_equal(rcb_monitor_save(a, buf, sizeof buf, &n), RCB_OK);
      if (rcb_monitor_load(c, buf, n) != RCB_OK) {
        print_message("update %zu: %s\n", u, rcb_monitor_errmsg(c));
        fail();
      }
      assert_int_equal(rcb_monitor_save(c, back, sizeof back, &m), RCB_OK);
      assert_int_equal(m, n);
      assert_memory_equal(back, buf, n);
      infw += isinf(get_f64(buf + OFF_REF_W)) != 0;
      loads++;
    }
  }
  assert_int_equal(rcb_monitor_update_count(c), 200);
  /* the run went where the checks look: alarms (a frozen reference), the
   * reset (fewer updates in the drift sums than updates) */
  assert_true(alarms > 0);
  assert_int_equal(get_u64(buf + OFF_DALL), 80);
  assert_true(isinf(navg) ? infw > 0 : infw == 0);
  print_message("  setup_averages %g%s: %zu states of 200 updates loaded (%zu CUSUM alarms, "
                "%zu with an infinite reference weight)\n", navg,
                bvar ? ", baseline_cov" : "", loads, alarms, infw);
  rcb_monitor_destroy(a);
  rcb_monitor_destroy(c);
}

static void test_written_states_load(void **state) {
  fixture *f = *state;
  double bvar = 1e-6 * f->kt * f->kt;
  long_run(f, 4.0, &bvar);
  long_run(f, HUGE_VAL, NULL); /* noise-free reference: +inf weight, written and loaded */
}

/* The update count at its maximum: the state loads, no further update is
 * taken (nothing wraps), and a count past it is refused. */
static void test_update_count_max(void **state) {
  fixture *f = *state;
  static unsigned char buf[STMAX];
  rcb_monitor_param tp, tp2;
  rcb_monitor *a = monitor_of(f, &tp, 4.0, NULL), *c = monitor_of(f, &tp2, 4.0, NULL);
  rcb_monitor_result r;
  uint64_t seed = 5;
  size_t n = 0;
  noisy(f, 0.0, &seed, f->v);
  assert_int_equal(rcb_monitor_update(a, f->v, NULL, &r), RCB_OK);
  a->updates = (size_t)RCB_MONITOR_MAX_UPDATES - 1; /* white box: 4 billion updates later */
  assert_int_equal(rcb_monitor_update(a, f->v, NULL, &r), RCB_OK);
  assert_true(r.update == (size_t)RCB_MONITOR_MAX_UPDATES);
  assert_int_equal(rcb_monitor_save(a, buf, sizeof buf, &n), RCB_OK);
  assert_int_equal(rcb_monitor_load(c, buf, n), RCB_OK);
  assert_true(rcb_monitor_update_count(c) == (size_t)RCB_MONITOR_MAX_UPDATES);
  assert_int_equal(rcb_monitor_update(c, f->v, NULL, &r), RCB_ERR_STATE);
  assert_non_null(strstr(rcb_monitor_errmsg(c), "RCB_MONITOR_MAX_UPDATES"));
  assert_true(rcb_monitor_update_count(c) == (size_t)RCB_MONITOR_MAX_UPDATES);
  put_u64(buf + OFF_UPDATES, (uint64_t)RCB_MONITOR_MAX_UPDATES + 1);
  rewrite_crc(buf, n);
  assert_int_equal(rcb_monitor_load(c, buf, n), RCB_ERR_CORRUPT);
  rcb_monitor_destroy(a);
  rcb_monitor_destroy(c);
}

/* The commissioning image (rcb_monitor_opts.image, issue #34 item 5): a
 * monitor created from it gives the full create's results bit for bit (the
 * re-linearised, reweighted path, whose low-rank blocks it carries too); a
 * damaged image (a value changed, a byte cut) is refused with
 * RCB_ERR_CORRUPT, one of other options (another tracked range, the
 * fingerprint) with RCB_ERR_OTHER_SETUP, another version with
 * RCB_ERR_VERSION; a buffer too small with RCB_ERR_WORKSPACE. */
static void test_image(void **state) {
  fixture *f = *state;
  rcb_monitor_param tp;
  rcb_monitor_opts o;
  rcb_monitor *a = NULL, *b = NULL;
  rcb_monitor_result ra, rb;
  unsigned char *im, *bad;
  uint64_t seed = 21;
  size_t n, w = 0, u;
  memset(&o, 0, sizeof o);
  tp.name = KT_NAME, tp.lo = 0.5 * f->kt, tp.hi = 1.5 * f->kt;
  o.ntracked = 1, o.tracked = &tp, o.beta_a = 2.0, o.beta_s = 0.5, o.setup_averages = 4.0;
  o.relinearise = 8, o.reweight = 1;
  o.effects = (1u << RCB_EFFECT_BEARING_CROSS_COUPLING) | (1u << RCB_EFFECT_BEARING_STIFFNESS);
  assert_int_equal(rcb_monitor_create(&a, f->base, f->setup, &o, NULL), RCB_OK);
  assert_true(rcb_monitor_fast_relinearise(a));
  n = rcb_monitor_image_size(a);
  assert_true(n > 0);
  im = malloc(n), bad = malloc(n);
  assert_non_null(im), assert_non_null(bad);
  assert_int_equal(rcb_monitor_image_save(a, im, n - 1, &w), RCB_ERR_WORKSPACE);
  assert_int_equal(rcb_monitor_image_save(a, im, n, &w), RCB_OK);
  assert_true(w == n);
  o.image = im, o.image_size = n;
  assert_int_equal(rcb_monitor_create(&b, f->base, f->setup, &o, NULL), RCB_OK);
  for (u = 0; u < 12; u++) { /* kt falling 1 % an update: alarms, re-linearised */
    noisy(f, -0.01 * (double)u * f->kt, &seed, f->v);
    assert_int_equal(rcb_monitor_update(a, f->v, NULL, &ra), RCB_OK);
    assert_int_equal(rcb_monitor_update(b, f->v, NULL, &rb), RCB_OK);
    assert_true(memcmp(&ra, &rb, sizeof ra) == 0);
  }
  rcb_monitor_destroy(b);
  b = NULL;
  /* damaged: a value of Q changed, the checksum kept; a byte short */
  memcpy(bad, im, n);
  bad[200] ^= 1;
  o.image = bad;
  assert_int_equal(rcb_monitor_create(&b, f->base, f->setup, &o, NULL), RCB_ERR_CORRUPT);
  assert_non_null(strstr(rcb_monitor_errmsg(b), "checksum"));
  rcb_monitor_destroy(b);
  b = NULL;
  o.image = im, o.image_size = n - 1;
  assert_int_equal(rcb_monitor_create(&b, f->base, f->setup, &o, NULL), RCB_ERR_CORRUPT);
  rcb_monitor_destroy(b);
  b = NULL;
  /* another version; other options */
  memcpy(bad, im, n);
  bad[4] = 2;
  o.image = bad, o.image_size = n;
  assert_int_equal(rcb_monitor_create(&b, f->base, f->setup, &o, NULL), RCB_ERR_VERSION);
  rcb_monitor_destroy(b);
  b = NULL;
  o.image = im;
  tp.hi = 1.6 * f->kt;
  assert_int_equal(rcb_monitor_create(&b, f->base, f->setup, &o, NULL), RCB_ERR_OTHER_SETUP);
  rcb_monitor_destroy(b);
  b = NULL;
  tp.hi = 1.5 * f->kt;
  o.beta_a = 2.5; /* the noise: other weights */
  assert_int_equal(rcb_monitor_create(&b, f->base, f->setup, &o, NULL), RCB_ERR_OTHER_SETUP);
  rcb_monitor_destroy(b);
  rcb_monitor_destroy(a);
  free(im), free(bad);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_image),
      cmocka_unit_test(test_crafted),
      cmocka_unit_test(test_written_states_load),
      cmocka_unit_test(test_update_count_max),
  };
  return cmocka_run_group_tests(tests, fixture_setup, fixture_teardown);
}
