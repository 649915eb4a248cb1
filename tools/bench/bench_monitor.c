/*
 * Condition monitoring (issue #16): the cost of rcb_monitor on the paper
 * system with 8 response channels (DA, coupling hubs A and B, DB; x and y)
 * x 400 frequencies (20-400 Hz at 10000 rpm, force at DA.x), tracking the
 * coupling's kt, every catalogue effect a candidate. Prints the create
 * time, the arena a host must give it (a bump allocator: peak bytes, as
 * examples/firmware does) and the bytes it keeps, then ms per update on the
 * calling thread (OPENBLAS_NUM_THREADS=1) for the linear path, the
 * reweighted path (opts.reweight) and re-linearisations (opts.relinearise
 * 8: at most 8, until converged); each over
 * updates of eq. 19 noise (rcb_meas_add_noise, 2 % + 2 %): the wall time
 * and the thread's CPU time (user + system) per update. The alarmed rows
 * name the candidates their updates named: the machine changed (kt -4 %,
 * cross-coupling at B2) with the default catalogue and with every probe's
 * gain among the candidates (rcbtool monitor --sensors), and the machine as
 * it is read by a DA.x probe at gain 0.85 with the settings of the probe
 * series (issue #34: kt, kr, ct tracked, --noise 10,1 --commission 10
 * --alpha 0.01 --sensors).
 *   OPENBLAS_NUM_THREADS=1 build/tools/bench/bench_monitor examples/paper_system.ini
 * An optional second argument runs one row only, with an optional update
 * count (for profiling: valgrind --tool=callgrind, perf stat):
 *   bench_monitor examples/paper_system.ini ross [N]   (reweighted + re-lin. 8)
 *   bench_monitor examples/paper_system.ini changed [N] (the same, changed)
 *   bench_monitor examples/paper_system.ini sensors [N] (changed, --sensors)
 *   bench_monitor examples/paper_system.ini probe [N]   (probe DA.x 0.85, series)
 * (and linear, reweighted, relin). BENCH_MONITOR_DUMP=FILE writes every
 * update's rcb_monitor_result to FILE as bytes, to compare two builds;
 * BENCH_MONITOR_IMAGE=1 runs the updates on the monitor created again from
 * the first one's commissioning image (rcb_monitor_opts.image).
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "rcb/rcb.h"

#define NCH ((size_t)8)
#define NPTS ((size_t)400)
#define NNOISY 16
#define PI 3.14159265358979323846

static const char *const outs[NCH] = {"DA.x", "DA.y", "C.A.x", "C.A.y",
                                      "C.B.x", "C.B.y", "DB.x", "DB.y"};

static double now(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* The calling thread's CPU time (user + system), s: the figure that holds on
 * a machine shared with other work, where the wall time above does not. */
static double cpu_now(void) {
  struct timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

typedef struct arena {
  unsigned char *base;
  size_t size, used;
} arena;

static void *arena_alloc(void *user, size_t n) {
  arena *a = user;
  size_t at = (a->used + 15u) & ~(size_t)15u;
  if (at > a->size || n > a->size - at) return NULL;
  a->used = at + n;
  return a->base + at;
}
static void arena_free(void *user, void *p) { (void)user, (void)p; }

/* A heap through the hooks that records its peak of live bytes. */
typedef struct heap {
  size_t live, peak;
} heap;
static void *heap_alloc(void *user, size_t n) {
  heap *h = user;
  size_t *p = malloc(n + 16);
  if (!p) return NULL;
  p[0] = n;
  h->live += n;
  if (h->live > h->peak) h->peak = h->live;
  return (unsigned char *)p + 16;
}
static void heap_free(void *user, void *q) {
  heap *h = user;
  size_t *p = (size_t *)(void *)((unsigned char *)q - 16);
  h->live -= p[0];
  free(p);
}

/* The model's FRFs on the set-up grid as a measurement, DA.x read by a
 * probe of gain g0 (1: the model's values). */
static rcb_meas *setup_of(const rcb_model *m, double g0) {
  rcb_dof od[NCH], in;
  rcb_frf *f = NULL;
  rcb_meas *ms = NULL;
  double w[NPTS], sp[NPTS], speed = 10000.0 * PI / 30.0;
  rcb_complex *H = malloc(NPTS * NCH * sizeof *H), *ch = malloc(NPTS * sizeof *ch);
  size_t i, c;
  int bad = !H || !ch || rcb_model_find_dof(m, "DA.x", &in);
  for (c = 0; !bad && c < NCH; c++) bad = rcb_model_find_dof(m, outs[c], &od[c]) != RCB_OK;
  for (i = 0; i < NPTS; i++) w[i] = 2 * PI * (20.0 + 380.0 * (double)i / (NPTS - 1)), sp[i] = speed;
  bad = bad || rcb_frf_create(&f, m, NCH, od, 1, &in, RCB_SOLVER_AUTO, NULL) ||
        rcb_frf_sweep(f, NPTS, w, sp, RCB_RECEPTANCE, H, 1) || rcb_meas_create(&ms, NULL) ||
        rcb_meas_set_grid(ms, RCB_MEAS_FRF, NPTS, w, speed);
  for (c = 0; !bad && c < NCH; c++) {
    for (i = 0; i < NPTS; i++) ch[i] = (c ? 1.0 : g0) * H[c + NCH * i];
    bad = rcb_meas_add_channel(ms, outs[c], "DA.x", RCB_RECEPTANCE, ch) != RCB_OK;
  }
  rcb_frf_destroy(f);
  free(H), free(ch);
  if (bad) {
    rcb_meas_destroy(ms);
    return NULL;
  }
  return ms;
}

static void values(const rcb_meas *ms, rcb_complex *v) {
  size_t c;
  for (c = 0; c < NCH; c++) {
    rcb_meas_channel_info ci;
    rcb_meas_channel(ms, c, &ci);
    memcpy(v + c * NPTS, ci.data, NPTS * sizeof *v);
  }
}

/* The state's save and load (each the mean of NSTATE calls), seconds. */
#define NSTATE 200
static int state_times(rcb_monitor *mon, double *ts, double *tl, size_t *n) {
  static unsigned char buf[1 << 16]; /* k = 83: 23 kB with the drift window */
  size_t i;
  double t0 = now();
  for (i = 0; i < NSTATE; i++)
    if (rcb_monitor_save(mon, buf, sizeof buf, n)) {
      fprintf(stderr, "save: %zu bytes needed\n", rcb_monitor_state_size(mon));
      return 1;
    }
  *ts = (now() - t0) / NSTATE;
  t0 = now();
  for (i = 0; i < NSTATE; i++)
    if (rcb_monitor_load(mon, buf, *n)) {
      fprintf(stderr, "load: %s\n", rcb_monitor_errmsg(mon));
      return 1;
    }
  *tl = (now() - t0) / NSTATE;
  return 0;
}

/* A row: its options beyond the common ones. */
typedef struct row {
  const char *label;
  size_t relin, nupd;
  int reweight;
  unsigned effects; /* opts.effects, 0: the default catalogue */
  int series;       /* 1: the probe series' settings (rcbtool monitor --params
                       coupling.C.kt,coupling.C.kr,coupling.C.ct --noise 10,1
                       --commission 10 --alpha 0.01) instead of kt, 2 % + 2 %, 16 */
} row;

/* The candidates an alarmed row named (top[0]), most NAMED of them. */
#define NAMED 4
static void print_named(const rcb_monitor *mon, const size_t *idx, const size_t *cnt, size_t n) {
  size_t i;
  for (i = 0; i < n; i++) {
    rcb_monitor_candidate_info ci;
    if (rcb_monitor_candidate_info_get(mon, idx[i], &ci)) continue;
    printf("%-24s named %s at %s (%s) on %zu updates\n", "", rcb_effect_name(ci.effect),
           ci.place, ci.params, cnt[i]);
  }
}

/* BENCH_MONITOR_DUMP=FILE: every update's rcb_monitor_result appended to
 * FILE as bytes (cmp two builds' dumps: results unchanged). */
static FILE *dump;

static int run(const rcb_model *m, const rcb_meas *setup, rcb_complex *const *noisy,
               const row *rw) {
  static unsigned char mem[64u << 20];
  arena ar = {mem, sizeof mem, 0};
  heap hp = {0, 0};
  rcb_allocator a = {arena_alloc, arena_free, &ar}, h = {heap_alloc, heap_free, &hp};
  rcb_monitor_param tp[3] = {{"coupling.C.kt", 0, 0}, {"coupling.C.kr", 0, 0},
                             {"coupling.C.ct", 0, 0}};
  rcb_monitor_opts o;
  rcb_monitor *mon = NULL, *mi = NULL;
  rcb_monitor_result r;
  void *im = NULL;
  size_t nim;
  size_t u, k = 0, kt = 0, alarms = 0, nst = 0, named[NAMED], ncount[NAMED] = {0}, nnamed = 0, i;
  double t0, c0, tc, ti, tu, cu, ts = 0, tl = 0;
  memset(&o, 0, sizeof o);
  for (i = 0; i < 3; i++) { /* rcbtool's default range: [v / 1000, 1000 v] */
    double v = 0;
    rcb_model_get_param(m, tp[i].name, &v);
    tp[i].lo = v / 1000, tp[i].hi = 1000 * v;
  }
  tp[0].lo = 1e3, tp[0].hi = 1e8;
  o.ntracked = 1, o.tracked = tp, o.beta_a = 2, o.beta_s = 2, o.setup_averages = 16;
  if (rw->series)
    o.ntracked = 3, o.beta_a = 10, o.beta_s = 1, o.setup_averages = 10, o.alpha = 0.01;
  o.relinearise = rw->relin, o.reweight = rw->reweight, o.effects = rw->effects;
  /* the peak a heap sees (temporaries freed as create goes) */
  if (rcb_monitor_create(&mon, m, setup, &o, &h)) {
    fprintf(stderr, "create: %s\n", rcb_monitor_errmsg(mon));
    return 1;
  }
  rcb_monitor_destroy(mon);
  mon = NULL;
  t0 = now();
  if (rcb_monitor_create(&mon, m, setup, &o, &a)) {
    fprintf(stderr, "create: %s\n", rcb_monitor_errmsg(mon));
    return 1;
  }
  tc = now() - t0;
  /* create again from the commissioning image (a process per measurement) */
  nim = rcb_monitor_image_size(mon);
  if (!(im = malloc(nim)) || rcb_monitor_image_save(mon, im, nim, NULL)) {
    fprintf(stderr, "image: %zu bytes\n", nim);
    return 1;
  }
  o.image = im, o.image_size = nim;
  t0 = now();
  if (rcb_monitor_create(&mi, m, setup, &o, NULL)) {
    fprintf(stderr, "create from the image: %s\n", rcb_monitor_errmsg(mi));
    return 1;
  }
  ti = now() - t0;
  if (getenv("BENCH_MONITOR_IMAGE")) { /* the updates on the monitor made from it */
    rcb_monitor *t = mon;
    mon = mi, mi = t;
  }
  rcb_monitor_rank(mon, &k, &kt);
  t0 = now();
  c0 = cpu_now();
  for (u = 0; u < rw->nupd; u++) {
    if (rcb_monitor_update(mon, noisy[u % NNOISY], NULL, &r)) {
      fprintf(stderr, "update: %s\n", rcb_monitor_errmsg(mon));
      return 1;
    }
    if (dump) fwrite(&r, sizeof r, 1, dump);
    alarms += (size_t)r.alarm;
    if (r.alarm && r.ntop) {
      for (i = 0; i < nnamed && named[i] != r.top[0].index; i++) continue;
      if (i == nnamed && nnamed < NAMED) named[nnamed++] = r.top[0].index;
      if (i < nnamed) ncount[i]++;
    }
  }
  cu = (cpu_now() - c0) / (double)rw->nupd;
  tu = (now() - t0) / (double)rw->nupd;
  if (state_times(mon, &ts, &tl, &nst)) return 1;
  printf("%-24s create %5.3f s  bump arena %6.0f kB, heap peak %6.0f kB, kept %6.0f kB  "
         "k = %zu (%zu candidates)  update %7.3f ms, CPU %7.3f ms  (%zu updates, "
         "%zu alarms%s)\n",
         rw->label, tc,
         (double)ar.used / 1024.0, (double)hp.peak / 1024.0,
         (double)rcb_monitor_memory(mon) / 1024.0, k, rcb_monitor_candidate_count(mon), 1e3 * tu,
         1e3 * cu, rw->nupd, alarms,
         rcb_monitor_fast_relinearise(mon) ? "; re-linearised without a sweep" : "");
  printf("%-24s state %zu bytes: save %.1f us, load %.1f us (issue #24)\n", "", nst, 1e6 * ts,
         1e6 * tl);
  printf("%-24s commissioning image %.1f MB: create from it %.3f s\n", "", (double)nim / 1e6, ti);
  print_named(mon, named, ncount, nnamed);
  rcb_monitor_destroy(mon);
  rcb_monitor_destroy(mi);
  free(im);
  return 0;
}

/* One eq. 19 noisy measurement (2 % + 2 %) of model m, DA.x's probe at gain
 * g0, malloc'ed into *out. */
static int noisy_of(const rcb_model *m, double g0, unsigned long seed, rcb_complex **out) {
  rcb_meas *ms = setup_of(m, g0);
  *out = malloc(NCH * NPTS * sizeof **out);
  if (!*out || !ms || rcb_meas_add_noise(ms, 2, 2, seed)) {
    fprintf(stderr, "noisy measurement (seed %lu) failed\n", seed);
    rcb_meas_destroy(ms);
    return 1;
  }
  values(ms, *out);
  rcb_meas_destroy(ms);
  return 0;
}

int main(int argc, char **argv) {
  const char *only = argc > 2 ? argv[2] : NULL;
  size_t nonly = argc > 3 ? (size_t)strtoul(argv[3], NULL, 10) : 0;
  rcb_model *m = NULL, *m2 = NULL, *m3 = NULL, *m4 = NULL;
  rcb_meas *setup;
  rcb_complex *noisy[NNOISY], *changed[NNOISY], *probe[NNOISY], *slower[NNOISY],
      *damped[NNOISY];
  double kt;
  size_t s, i;
  int rc = 0;
  const unsigned bearings_coupling =
      (1u << RCB_EFFECT_BEARING_STIFFNESS) | (1u << RCB_EFFECT_BEARING_CROSS_COUPLING) |
      (1u << RCB_EFFECT_BEARING_DAMPING) | (1u << RCB_EFFECT_COUPLING_TRANSLATIONAL_DAMPING) |
      (1u << RCB_EFFECT_COUPLING_ROTATIONAL_STIFFNESS) |
      (1u << RCB_EFFECT_COUPLING_ROTATIONAL_DAMPING);
  /* rcbtool monitor --sensors: the default catalogue and the measurement chain */
  const unsigned sensors = RCB_MONITOR_EFFECTS_SENSORS;
  /* label, relinearise, updates, reweight, effects, the probe series' settings */
  const row rows[] = {
      {"linear", 0, 400, 0, 0, 0},
      {"reweighted", 0, 100, 1, 0, 0},
      {"re-linearised (<= 8)", 8, 50, 0, 0, 0},
      {"reweighted + re-lin. 8", 8, 50, 1, 0, 0}, /* "ross" */
      {"the same, changed", 8, 20, 1, 0, 0},      /* "changed" */
      {"changed, --sensors", 8, 20, 1, sensors, 0}, /* "sensors" */
      {"probe DA.x 0.85, series", 8, 20, 1, sensors, 1}, /* "probe" */
      {"speed -3 %", 8, 20, 1, 0, 0},              /* "speed": a sweep-path effect */
      {"shaft A material damping", 8, 20, 1, 0, 0}, /* "damping": another */
      {"linear", 0, 400, 0, bearings_coupling, 0},
      {"reweighted", 0, 100, 1, bearings_coupling, 0}};
  static const char *const names[] = {"linear", "reweighted", "relin", "ross", "changed",
                                      "sensors", "probe", "speed", "damping"};
  if (argc < 2) {
    fprintf(stderr, "usage: bench_monitor MODEL.ini [ROW [UPDATES]]\n");
    return 2;
  }
  if (getenv("BENCH_MONITOR_DUMP") && !(dump = fopen(getenv("BENCH_MONITOR_DUMP"), "wb"))) {
    fprintf(stderr, "bench_monitor: cannot write %s\n", getenv("BENCH_MONITOR_DUMP"));
    return 2;
  }
  if (rcb_model_create(&m, NULL) || rcb_model_load_file(m, argv[1]) || rcb_model_finalize(m)) {
    fprintf(stderr, "%s\n", rcb_model_errmsg(m));
    return 1;
  }
  if (!(setup = setup_of(m, 1.0))) {
    fprintf(stderr, "could not evaluate the set-up's FRFs\n");
    return 1;
  }
  memset(noisy, 0, sizeof noisy);
  memset(changed, 0, sizeof changed);
  memset(probe, 0, sizeof probe);
  memset(slower, 0, sizeof slower);
  memset(damped, 0, sizeof damped);
  /* the machine changed as in examples/firmware: kt -4 %, 5e5 N/m of
   * cross-coupling at B2 (every update alarms) */
  if (rcb_model_clone(&m2, m, NULL) || rcb_model_finalize(m2) ||
      rcb_model_get_param(m2, "coupling.C.kt", &kt) ||
      rcb_model_set_param(m2, "coupling.C.kt", 0.96 * kt) ||
      rcb_model_set_param(m2, "bearing.B2.kcross", 5e5)) {
    fprintf(stderr, "changed machine: %s\n", m2 ? rcb_model_errmsg(m2) : "out of memory");
    rc = 1;
    goto done;
  }
  /* effects whose DOFs are not few (no low-rank evaluation: the joint
   * step by sweeps): the rotor 3 % slower than stated, and material damping
   * in shaft A */
  if (rcb_model_clone(&m3, m, NULL) || rcb_model_finalize(m3) ||
      rcb_model_set_param(m3, "speed.factor", 0.97) || rcb_model_clone(&m4, m, NULL) ||
      rcb_model_finalize(m4) || rcb_model_set_param(m4, "shaft.A.damping_stiffness", 4e-5)) {
    fprintf(stderr, "changed machine: %s\n",
            m4 ? rcb_model_errmsg(m4) : m3 ? rcb_model_errmsg(m3) : "out of memory");
    rc = 1;
    goto done;
  }
  /* and the machine as it is, read by a DA.x probe at gain 0.85 (the end of
   * tests/python/monitor_cases.py's probe_DA_x series) */
  for (s = 0; s < NNOISY && !rc; s++) rc = noisy_of(m, 1.0, 1000 + s, &noisy[s]) ||
                                          noisy_of(m2, 1.0, 2000 + s, &changed[s]) ||
                                          noisy_of(m, 0.85, 3000 + s, &probe[s]) ||
                                          noisy_of(m3, 1.0, 4000 + s, &slower[s]) ||
                                          noisy_of(m4, 1.0, 5000 + s, &damped[s]);
  if (rc) goto done;
  printf("paper system, %zu channels x %zu frequencies, kt tracked, eq. 19 noise 2 %% + 2 %%\n",
         NCH, NPTS);
  for (i = 0; only && i < sizeof names / sizeof names[0] && strcmp(only, names[i]); i++) continue;
  if (only && i == sizeof names / sizeof names[0]) {
    fprintf(stderr, "bench_monitor: unknown row '%s' (linear, reweighted, relin, ross, changed, "
            "sensors, probe, speed or damping)\n", only);
    rc = 2;
    goto done;
  }
  for (s = only ? i : 0; s < (only ? i + 1 : sizeof rows / sizeof rows[0]); s++) {
    row rw = rows[s];
    if (only && nonly) rw.nupd = nonly;
    if (s == 9) printf("bearing and coupling effects only (opts.effects):\n");
    rc |= run(m, setup,
              s == 4 || s == 5 ? changed : s == 6 ? probe : s == 7 ? slower : s == 8 ? damped
                                                                              : noisy,
              &rw);
  }
done:
  for (s = 0; s < NNOISY; s++)
    free(noisy[s]), free(changed[s]), free(probe[s]), free(slower[s]), free(damped[s]);
  rcb_model_destroy(m4);
  rcb_model_destroy(m3);
  rcb_model_destroy(m2);
  rcb_meas_destroy(setup);
  rcb_model_destroy(m);
  if (dump && fclose(dump)) rc = 1;
  return rc;
}
