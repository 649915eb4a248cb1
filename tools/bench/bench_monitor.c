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
 * and the thread's CPU time (user + system) per update.
 *   OPENBLAS_NUM_THREADS=1 build/tools/bench/bench_monitor examples/paper_system.ini
 * An optional second argument runs one row only, with an optional update
 * count (for profiling: valgrind --tool=callgrind, perf stat):
 *   bench_monitor examples/paper_system.ini ross [N]   (reweighted + re-lin. 8)
 *   bench_monitor examples/paper_system.ini changed [N] (the same, changed)
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

/* The model's FRFs on the set-up grid as a measurement. */
static rcb_meas *setup_of(const rcb_model *m) {
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
    for (i = 0; i < NPTS; i++) ch[i] = H[c + NCH * i];
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

static int run(const rcb_model *m, const rcb_meas *setup, rcb_complex *const *noisy,
               const char *label, size_t relin, int reweight, size_t nupd, unsigned effects) {
  static unsigned char mem[64u << 20];
  arena ar = {mem, sizeof mem, 0};
  heap hp = {0, 0};
  rcb_allocator a = {arena_alloc, arena_free, &ar}, h = {heap_alloc, heap_free, &hp};
  rcb_monitor_param tp = {"coupling.C.kt", 1e3, 1e8};
  rcb_monitor_opts o;
  rcb_monitor *mon = NULL;
  rcb_monitor_result r;
  size_t u, k = 0, kt = 0, alarms = 0, nst = 0;
  double t0, c0, tc, tu, cu, ts = 0, tl = 0;
  memset(&o, 0, sizeof o);
  o.ntracked = 1, o.tracked = &tp, o.beta_a = 2, o.beta_s = 2, o.setup_averages = 16;
  o.relinearise = relin, o.reweight = reweight, o.effects = effects;
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
  rcb_monitor_rank(mon, &k, &kt);
  t0 = now();
  c0 = cpu_now();
  for (u = 0; u < nupd; u++) {
    if (rcb_monitor_update(mon, noisy[u % NNOISY], NULL, &r)) {
      fprintf(stderr, "update: %s\n", rcb_monitor_errmsg(mon));
      return 1;
    }
    alarms += (size_t)r.alarm;
  }
  cu = (cpu_now() - c0) / (double)nupd;
  tu = (now() - t0) / (double)nupd;
  if (state_times(mon, &ts, &tl, &nst)) return 1;
  printf("%-24s create %5.3f s  bump arena %6.0f kB, heap peak %6.0f kB, kept %6.0f kB  "
         "k = %zu (%zu candidates)  update %7.3f ms, CPU %7.3f ms  (%zu updates, "
         "%zu alarms%s)\n",
         label, tc,
         (double)ar.used / 1024.0, (double)hp.peak / 1024.0,
         (double)rcb_monitor_memory(mon) / 1024.0, k, rcb_monitor_candidate_count(mon), 1e3 * tu,
         1e3 * cu, nupd, alarms,
         rcb_monitor_fast_relinearise(mon) ? "; re-linearised without a sweep" : "");
  printf("%-24s state %zu bytes: save %.1f us, load %.1f us (issue #24)\n", "", nst, 1e6 * ts,
         1e6 * tl);
  rcb_monitor_destroy(mon);
  return 0;
}

/* One eq. 19 noisy measurement (2 % + 2 %) of model m, malloc'ed into *out. */
static int noisy_of(const rcb_model *m, unsigned long seed, rcb_complex **out) {
  rcb_meas *ms = setup_of(m);
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
  rcb_model *m = NULL, *m2 = NULL;
  rcb_meas *setup;
  rcb_complex *noisy[NNOISY], *changed[NNOISY];
  double kt;
  size_t s;
  int rc = 0;
  const unsigned bearings_coupling =
      (1u << RCB_EFFECT_BEARING_STIFFNESS) | (1u << RCB_EFFECT_BEARING_CROSS_COUPLING) |
      (1u << RCB_EFFECT_BEARING_DAMPING) | (1u << RCB_EFFECT_COUPLING_TRANSLATIONAL_DAMPING) |
      (1u << RCB_EFFECT_COUPLING_ROTATIONAL_STIFFNESS) |
      (1u << RCB_EFFECT_COUPLING_ROTATIONAL_DAMPING);
  if (argc < 2) {
    fprintf(stderr, "usage: bench_monitor MODEL.ini\n");
    return 2;
  }
  if (rcb_model_create(&m, NULL) || rcb_model_load_file(m, argv[1]) || rcb_model_finalize(m)) {
    fprintf(stderr, "%s\n", rcb_model_errmsg(m));
    return 1;
  }
  if (!(setup = setup_of(m))) {
    fprintf(stderr, "could not evaluate the set-up's FRFs\n");
    return 1;
  }
  memset(noisy, 0, sizeof noisy);
  memset(changed, 0, sizeof changed);
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
  for (s = 0; s < NNOISY && !rc; s++) rc = noisy_of(m, 1000 + s, &noisy[s]) ||
                                          noisy_of(m2, 2000 + s, &changed[s]);
  if (rc) goto done;
  printf("paper system, %zu channels x %zu frequencies, kt tracked, eq. 19 noise 2 %% + 2 %%\n",
         NCH, NPTS);
  if (only && (!strcmp(only, "ross") || !strcmp(only, "changed"))) {
    int ch = !strcmp(only, "changed");
    rc = run(m, setup, ch ? changed : noisy, ch ? "the same, changed" : "reweighted + re-lin. 8",
             8, 1, nonly ? nonly : 50, 0);
    goto done;
  } else if (only) {
    fprintf(stderr, "bench_monitor: unknown row '%s' (ross or changed)\n", only);
    rc = 2;
    goto done;
  }
  rc |= run(m, setup, noisy, "linear", 0, 0, 400, 0);
  rc |= run(m, setup, noisy, "reweighted", 0, 1, 100, 0);
  rc |= run(m, setup, noisy, "re-linearised (<= 8)", 8, 0, 50, 0);
  rc |= run(m, setup, noisy, "reweighted + re-lin. 8", 8, 1, 50, 0);
  rc |= run(m, setup, changed, "the same, changed", 8, 1, 20, 0);
  printf("bearing and coupling effects only (opts.effects):\n");
  rc |= run(m, setup, noisy, "linear", 0, 0, 400, bearings_coupling);
  rc |= run(m, setup, noisy, "reweighted", 0, 1, 100, bearings_coupling);
done:
  for (s = 0; s < NNOISY; s++) free(noisy[s]), free(changed[s]);
  rcb_model_destroy(m2);
  rcb_meas_destroy(setup);
  rcb_model_destroy(m);
  return rc;
}
