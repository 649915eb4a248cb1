/*
 * Condition monitoring the way firmware does it (issues #7 and #16): a
 * host-style program that links the static library, builds the model of the
 * paper's rotor from an INI string inside a caller-provided memory arena,
 * commissions an rcb_monitor on it, then runs a monitoring loop over a
 * simulated year, one FRF test a day at the operating speed (force at DA.x,
 * 4 probes at the disks, x and y, NFREQ frequencies; the 1X unbalance
 * response of this stiffly supported rotor hardly sees a bearing's
 * cross-coupling: 0.1 % for 9e6 N/m at B2 up to 12000 rpm), the monitor
 * updated. Nothing is allocated after initialisation: the arena's
 * allocator hook counts every call and the program fails if one comes from
 * the loop.
 *
 * The "measured" FRFs come from a second model, the machine as it
 * really is, with the paper's eq. 19 noise drawn here (own generator,
 * allocation-free). Over the year:
 *  - from day WEAR_START to day WEAR_END the coupling's kt wears linearly
 *    down by WEAR_PCT % (slow: a fraction of its standard error a day);
 *  - on day FAULT_DAY a cross-coupled stiffness kxy = -kyx appears at
 *    bearing B2 (the monitor is not told when).
 * The monitor tracks kt. The pattern it must show (exit status 0 only
 * then):
 *  - the CUSUM on kt (falling) alarms after WEAR_START and before FAULT_DAY,
 *    never before WEAR_START;
 *  - the instant test is silent before FAULT_DAY, fires on FAULT_DAY and
 *    after, and ranks "bearing cross-coupled stiffness" at "bearing B2"
 *    first;
 *  - the 95 % intervals cover the truth as often as 95 % intervals should:
 *    kt's over the year, and the cross-coupling's on the days after the
 *    fault, each at least the lower end of the binomial 99 % interval
 *    (335 of 365, 102 of 115; scipy.stats.binom.interval(0.99, n, 0.95));
 *  - no allocation in the loop;
 *  - the firmware "reboots" on day REBOOT_DAY (issue #24): the monitor's
 *    state is saved into a buffer (the flash a real host would write),
 *    the monitor destroyed, created again from the same model, commissioning
 *    values and settings, and the state loaded (no allocation in the load).
 *    A second monitor that never restarts runs beside it: every result
 *    after the reboot and the saved state at the year's end must be bit
 *    for bit the same.
 * It prints the arena used, the detection delays and the estimated sizes.
 * Built on its own against an installed librcb (CMakeLists.txt), on Linux,
 * the C heap is wrapped and counted (../heap_count.h): librcb.a must make no
 * call of it from the first model to the last destroy.
 */
#include <complex.h>
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "rcb/rcb.h"

#include "../arena.h" /* arena, arena_alloc, arena_free */
#ifdef RCB_EXAMPLE_COUNT_HEAP
#include "../heap_count.h" /* heap_calls */
#endif

/* ---- the caller's memory: a bump arena (../arena.h), free is a no-op ----
 * Two monitors (the one that restarts and its never-restarted shadow) and
 * the restart's create: the bump arena reclaims nothing. */
#define ARENA_BYTES (32u * 1024u * 1024u)
static unsigned char g_memory[ARENA_BYTES]; /* the firmware's heap */

static const char MODEL_INI[] =
    "[model]\nname = paper system (firmware)\n"
    "[material steel]\ndensity = 7759.255\nyoung = 1.936e11\npoisson = 0.3\n"
    "[shaft A]\nmaterial = steel\nshear_factor = 0.9\ndamping_mass = 15.691\n"
    "damping_stiffness = 22.989e-6\nsegment = 0.50 0.017 0.0 10\n"
    "[shaft B]\nmaterial = steel\nstart = 0.52\nshear_factor = 0.9\ndamping_mass = 15.691\n"
    "damping_stiffness = 22.989e-6\nsegment = 0.50 0.017 0.0 10\n"
    "[bearing B1]\nat = A 0.05\nkxx = 5e7\nkyy = 7e7\ncxx = 500\ncyy = 700\n"
    "[bearing B2]\nat = A 0.35\nkxx = 7e7\nkyy = 9e7\ncxx = 300\ncyy = 500\n"
    "[bearing B3]\nat = B 0.67\nkxx = 5e7\nkyy = 7e7\ncxx = 500\ncyy = 700\n"
    "[bearing B4]\nat = B 0.97\nkxx = 7e7\nkyy = 9e7\ncxx = 300\ncyy = 500\n"
    "[disk DA]\nat = A 0.20\ndensity = 6303.235\nouter_diameter = 0.090\n"
    "inner_diameter = 0.017\nwidth = 0.025\n"
    "[disk DB]\nat = B 0.82\ndensity = 6303.235\nouter_diameter = 0.090\n"
    "inner_diameter = 0.017\nwidth = 0.025\n"
    "[coupling C]\nmodel = nelson_crandall_2\nbetween = A end, B start\nkt = 46.095e3\n"
    "kr = 220.76\nct = 10.949\ncr = 10.949e-6\nhub_density = 2758.219\n"
    "hub_inner_radius = 0.006\nhub_outer_radius = 0.017\nhub_thickness = 0.043115\n"
    "[unbalance UA]\nat = DA\namount = 15e-5\nphase_deg = 0\n"
    "[unbalance UB]\nat = DB\namount = 15e-5\nphase_deg = 90\n";

#define NOUT 4
#define NFREQ 120
#define NPT ((size_t)NOUT * NFREQ)
#define RPM 10000.0      /* operating speed during the daily test */
#define DAYS 365
#define WEAR_START 60
#define WEAR_END 300
#define WEAR_PCT 4.0     /* %, kt lost from WEAR_START to WEAR_END */
#define FAULT_DAY 250
#define KCROSS 5.0e5     /* N/m, the cross-coupled stiffness that appears (B2: kxx 7e7 N/m) */
#define BETA_A 2.0       /* %, eq. 19 proportional noise */
#define BETA_S 2.0       /* %, eq. 19 additive noise */
#define N_COMMISSION 16  /* FRF tests averaged into the commissioning values */
#define PI 3.14159265358979323846
#define REBOOT_DAY 182   /* the host restarts before this day's test */
#define STATE_MAX 65536  /* bytes of "flash" for the monitor's state (the drift
                            window: 264 bytes per rank-space dimension) */

static const char *const OUTS[NOUT] = {"DA.x", "DA.y", "DB.x", "DB.y"};

typedef struct plant {
  rcb_model *model, *machine; /* the baseline model; the "real" machine */
  rcb_frf *frf_machine;       /* the machine's FRFs */
  rcb_monitor *mon;
  rcb_monitor *shadow;        /* the same monitor never restarted, for the check */
  rcb_meas *setup;            /* the commissioning values, kept for a restart */
  rcb_monitor_param kt;       /* the tracked parameter */
  rcb_monitor_opts opts;
  double freqs[NFREQ];        /* rad/s */
  rcb_complex clean[NPT], meas[NPT]; /* channel-major, m */
  uint64_t rng;
} plant;

/* ---- the machine's daily FRF test, with eq. 19 noise (no allocation) ---- */

static double uniform(uint64_t *s) { /* splitmix64 -> [0, 1) */
  uint64_t z = (*s += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return (double)((z ^ (z >> 31)) >> 11) * 0x1.0p-53;
}

static int daily_test(plant *p) {
  size_t i, c;
  rcb_complex q[NOUT];
  for (i = 0; i < NFREQ; i++) {
    if (rcb_frf_eval(p->frf_machine, p->freqs[i], RPM * PI / 30.0, RCB_RECEPTANCE, q)) return 1;
    for (c = 0; c < NOUT; c++) p->clean[c * NFREQ + i] = q[c];
  }
  for (c = 0; c < NOUT; c++) { /* eq. 19, per channel */
    double s2 = 0, a;
    for (i = 0; i < NFREQ; i++) s2 += creal(p->clean[c * NFREQ + i] * conj(p->clean[c * NFREQ + i]));
    a = sqrt(s2) / NFREQ * BETA_S / 100.0;
    for (i = 0; i < NFREQ; i++) {
      double r1 = 2 * uniform(&p->rng) - 1, r2 = 2 * uniform(&p->rng) - 1;
      double ph = 2 * PI * uniform(&p->rng);
      p->meas[c * NFREQ + i] = p->clean[c * NFREQ + i] * (1 + BETA_A / 100.0 * r1) +
                                a * r2 * (cos(ph) + CMPLX(0.0, sin(ph)));
    }
  }
  return 0;
}

/* ---- initialisation: everything the loop needs, from the arena ---- */

static int load(rcb_model **m, const rcb_allocator *al) {
  if (rcb_model_create(m, al) || rcb_model_load_string(*m, MODEL_INI, "<firmware>") != RCB_OK) {
    fprintf(stderr, "model: %s\n", *m ? rcb_model_errmsg(*m) : "out of memory");
    return 1;
  }
  return 0;
}

/* A monitor from the baseline model, the commissioning values and the settings. */
static int make_monitor(plant *p, const rcb_allocator *al, rcb_monitor **mon) {
  if (rcb_monitor_create(mon, p->model, p->setup, &p->opts, al)) {
    fprintf(stderr, "monitor: %s\n", rcb_monitor_errmsg(*mon));
    return 1;
  }
  return 0;
}

/* Commissioning: the average of N_COMMISSION FRF tests of the healthy machine. */
static int commission(plant *p, const rcb_allocator *al) {
  static rcb_complex avg[NPT];
  rcb_monitor_opts o;
  size_t n, c, j;
  for (n = 0; n < N_COMMISSION; n++) {
    if (daily_test(p)) return 1;
    for (j = 0; j < NPT; j++) avg[j] += p->meas[j] / N_COMMISSION;
  }
  if (rcb_meas_create(&p->setup, al) ||
      rcb_meas_set_grid(p->setup, RCB_MEAS_FRF, NFREQ, p->freqs, RPM * PI / 30.0))
    return 1;
  for (c = 0; c < NOUT; c++)
    if (rcb_meas_add_channel(p->setup, OUTS[c], "DA.x", RCB_RECEPTANCE, avg + c * NFREQ))
      return 1;
  p->kt.name = "coupling.C.kt", p->kt.lo = 20e3, p->kt.hi = 80e3;
  memset(&o, 0, sizeof o);
  o.ntracked = 1, o.tracked = &p->kt;
  o.beta_a = BETA_A, o.beta_s = BETA_S, o.setup_averages = N_COMMISSION;
  o.alpha = 1e-4;       /* false alarms: 1 in 10000 days */
  o.cusum_k = 0.5, o.cusum_h = 8; /* one side's ARL0 ~ 1.9e4 days */
  o.reweight = 1;       /* the proportional noise follows the response as it changes */
  o.relinearise = 2;    /* kt moves by many standard errors: re-evaluate the model */
  o.effects = (1u << RCB_EFFECT_BEARING_STIFFNESS) | (1u << RCB_EFFECT_BEARING_CROSS_COUPLING) |
              (1u << RCB_EFFECT_BEARING_DAMPING) | (1u << RCB_EFFECT_COUPLING_ROTATIONAL_STIFFNESS) |
              (1u << RCB_EFFECT_COUPLING_TRANSLATIONAL_DAMPING);
  p->opts = o;
  return make_monitor(p, al, &p->mon) || make_monitor(p, al, &p->shadow);
}

/* The restart: the state into "flash", the monitor destroyed (a real host
 * loses its RAM here; the bump arena is not reclaimed, a real one would
 * start afresh), created again and the state loaded. Creating allocates,
 * as at power-up; loading must not. 0 on success. */
static int reboot(plant *p, arena *ar, const rcb_allocator *al) {
  static unsigned char flash[STATE_MAX];
  size_t n = 0, before;
  if (rcb_monitor_save(p->mon, flash, sizeof flash, &n)) {
    fprintf(stderr, "reboot: the state needs %zu bytes, the flash has %zu\n",
            rcb_monitor_state_size(p->mon), sizeof flash);
    return 1;
  }
  rcb_monitor_destroy(p->mon);
  p->mon = NULL;
  ar->sealed = 0;
  if (make_monitor(p, al, &p->mon)) return 1;
  ar->sealed = 1;
  before = ar->allocs;
  if (rcb_monitor_load(p->mon, flash, n)) {
    fprintf(stderr, "reboot: %s\n", rcb_monitor_errmsg(p->mon));
    return 1;
  }
  printf("reboot before day %d: state of %zu bytes saved, monitor created again, state "
         "loaded (%zu allocations in the load)\n", REBOOT_DAY, n, ar->allocs - before);
  return ar->allocs != before;
}

/* The same double, bit for bit (a NaN or -0 would show). */
static int same(double x, double y) {
  uint64_t a, b;
  memcpy(&a, &x, sizeof a);
  memcpy(&b, &y, sizeof b);
  return a == b;
}

/* The two results the same, bit for bit, in every number the example uses. */
static int same_result(const rcb_monitor_result *a, const rcb_monitor_result *b) {
  const rcb_monitor_tracked *s = &a->tracked[0], *t = &b->tracked[0];
  size_t k;
  if (a->update != b->update || a->alarm != b->alarm || a->ntop != b->ntop || !same(a->T, b->T) ||
      !same(s->value, t->value) || !same(s->ci_lo, t->ci_lo) || !same(s->ci_hi, t->ci_hi) ||
      !same(s->stderr_, t->stderr_) || !same(s->u, t->u) || !same(s->cusum_up, t->cusum_up) ||
      !same(s->cusum_down, t->cusum_down) || s->cusum_alarm != t->cusum_alarm)
    return 0;
  for (k = 0; k < a->ntop; k++)
    if (a->top[k].index != b->top[k].index || !same(a->top[k].size[0], b->top[k].size[0]) ||
        !same(a->top[k].ci_lo[0], b->top[k].ci_lo[0]))
      return 0;
  return 1;
}

/* The states of the restarted monitor and of the shadow at the year's end. */
static int same_state(const plant *p) {
  static unsigned char s1[STATE_MAX], s2[STATE_MAX];
  size_t n1 = 0, n2 = 0;
  if (rcb_monitor_save(p->mon, s1, sizeof s1, &n1) ||
      rcb_monitor_save(p->shadow, s2, sizeof s2, &n2))
    return 0;
  return n1 == n2 && memcmp(s1, s2, n1) == 0;
}

static int init(plant *p, const rcb_allocator *al) {
  rcb_dof dof[NOUT], in;
  size_t i;
  if (load(&p->model, al) || load(&p->machine, al)) return 1;
  for (i = 0; i < NOUT; i++)
    if (rcb_model_find_dof(p->machine, OUTS[i], &dof[i])) return 1;
  if (rcb_model_find_dof(p->machine, "DA.x", &in)) return 1;
  for (i = 0; i < NFREQ; i++) /* the daily test: 20 .. 400 Hz */
    p->freqs[i] = 2 * PI * (20.0 + 380.0 * (double)i / (NFREQ - 1));
  /* all memory sized here. The banded LAPACK solver by name:
   * RCB_SOLVER_AUTO would take KLU in a build with SuiteSparse, and KLU
   * allocates its factors with malloc, not through this arena's hook (the
   * monitor asks for the banded solver too). */
  if (rcb_frf_create(&p->frf_machine, p->machine, NOUT, dof, 1, &in, RCB_SOLVER_BANDED, al)) {
    fprintf(stderr, "FRF workspace: out of arena memory\n");
    return 1;
  }
  p->rng = 20261125;
  return commission(p, al);
}

/* ---- the year ---- */

typedef struct verdict {
  int cusum_day, alarm_day, errors;
  size_t instant_before, instant_after, named_right, covered, kt_covered;
} verdict;

/* The machine on that day; *kt its true coupling stiffness, N/m. */
static int set_machine(plant *p, int day, double kt0, double *kt) {
  double wear = day < WEAR_START  ? 0
                : day > WEAR_END ? 1
                                 : (double)(day - WEAR_START) / (WEAR_END - WEAR_START);
  *kt = kt0 * (1 - WEAR_PCT / 100.0 * wear);
  if (rcb_model_set_param(p->machine, "coupling.C.kt", *kt)) return 1;
  if (day == FAULT_DAY && rcb_model_set_param(p->machine, "bearing.B2.kcross", KCROSS)) return 1;
  return rcb_frf_refresh(p->frf_machine) != RCB_OK;
}

static void judge(plant *p, int day, const rcb_monitor_result *r, verdict *v) {
  rcb_monitor_candidate_info ci;
  int right = 0;
  if (r->cusum_alarm && v->cusum_day < 0) v->cusum_day = day;
  if (r->alarm && r->ntop && !rcb_monitor_candidate_info_get(p->mon, r->top[0].index, &ci))
    right = r->top[0].effect == RCB_EFFECT_BEARING_CROSS_COUPLING &&
            strcmp(ci.place, "bearing B2") == 0;
  if (right) v->covered += r->top[0].ci_lo[0] <= KCROSS && KCROSS <= r->top[0].ci_hi[0];
  if (day < FAULT_DAY) v->instant_before += (size_t)r->alarm;
  else v->instant_after += (size_t)r->alarm, v->named_right += (size_t)right;
  if (r->alarm && v->alarm_day < 0 && day >= FAULT_DAY) v->alarm_day = day;
  if (day % 30 == 0 || day == FAULT_DAY || (r->cusum_alarm && day == v->cusum_day)) {
    printf("day %3d  kt %8.1f [%8.1f, %8.1f] N/m  CUSUM- %6.2f  T %7.1f (%.1f)  %s%s", day,
           r->tracked[0].value, r->tracked[0].ci_lo, r->tracked[0].ci_hi,
           r->tracked[0].cusum_down, r->T, r->threshold, r->cusum_alarm ? "DRIFT " : "",
           r->alarm ? "ALARM" : "ok");
    if (r->alarm && r->ntop && !rcb_monitor_candidate_info_get(p->mon, r->top[0].index, &ci))
      printf(": %s, %.3g [%.3g, %.3g]", ci.description, r->top[0].size[0], r->top[0].ci_lo[0],
             r->top[0].ci_hi[0]);
    printf("\n");
  }
}

int main(void) {
  static plant p;
  arena ar = {g_memory, sizeof g_memory, 0, 0, 0, 0, 0};
  rcb_allocator al = {arena_alloc, arena_free, &ar};
  rcb_monitor_result r, rs;
  verdict v = {-1, -1, 0, 0, 0, 0, 0, 0};
  size_t differ = 0;
  double kt0, kt;
  int day;
#ifdef RCB_EXAMPLE_COUNT_HEAP
  heap_calls = 0; /* from here: librcb's calls only */
#endif
  if (init(&p, &al)) return 1;
  if (rcb_model_get_param(p.machine, "coupling.C.kt", &kt0)) return 1;
  ar.sealed = 1; /* from here on the loop must not allocate */
  printf("init: %zu allocations, arena %zu of %zu bytes (monitor holds %zu), %zu candidates\n",
         ar.allocs, ar.used, ar.size, rcb_monitor_memory(p.mon),
         rcb_monitor_candidate_count(p.mon));

  for (day = 0; day < DAYS; day++) {
    if (set_machine(&p, day, kt0, &kt) || daily_test(&p)) {
      fprintf(stderr, "day %d: the machine's FRF test failed\n", day);
      return 1;
    }
    if (day == REBOOT_DAY && reboot(&p, &ar, &al)) return 1;
    if (rcb_monitor_update(p.mon, p.meas, NULL, &r) ||
        rcb_monitor_update(p.shadow, p.meas, NULL, &rs)) {
      fprintf(stderr, "day %d: %s %s\n", day, rcb_monitor_errmsg(p.mon),
              rcb_monitor_errmsg(p.shadow));
      return 1;
    }
    differ += !same_result(&r, &rs);
    judge(&p, day, &r, &v);
    v.kt_covered += r.tracked[0].ci_lo <= kt && kt <= r.tracked[0].ci_hi;
  }

  printf("drift: CUSUM alarm on day %d (wear from day %d: delay %d days)\n", v.cusum_day,
         WEAR_START, v.cusum_day - WEAR_START);
  printf("fault: first instant alarm on day %d (fault on day %d), %zu of %d days after it "
         "alarmed, %zu named cross-coupling at bearing B2; %zu instant alarms before it\n",
         v.alarm_day, FAULT_DAY, v.instant_after, DAYS - FAULT_DAY, v.named_right,
         v.instant_before);
  printf("size: the 95 %% interval of kcross covered %g N/m on %zu of those days; kt's "
         "covered the true kt on %zu of %d days\n", KCROSS, v.covered, v.kt_covered, DAYS);
  if (v.cusum_day < WEAR_START || v.cusum_day >= FAULT_DAY) v.errors++;
  if (v.alarm_day != FAULT_DAY || v.instant_before) v.errors++;
  if (v.instant_after != DAYS - FAULT_DAY || v.named_right != v.instant_after) v.errors++;
  if (v.kt_covered < 335 || v.covered < 102) v.errors++; /* binomial 99 % lower ends */
  printf("loop: %zu allocations after initialisation (the reboot's create aside)\n",
         ar.allocs_after_init);
  if (ar.allocs_after_init) v.errors++;
  printf("restart: %zu of %d days differ from the monitor never restarted; final state %s\n",
         differ, DAYS, same_state(&p) ? "bit-identical" : "DIFFERENT");
  if (differ || !same_state(&p)) v.errors++;
  rcb_monitor_destroy(p.mon);
  rcb_monitor_destroy(p.shadow);
  rcb_meas_destroy(p.setup);
  rcb_frf_destroy(p.frf_machine);
  rcb_model_destroy(p.machine);
  rcb_model_destroy(p.model);
  if (ar.frees != ar.allocs) {
    fprintf(stderr, "%zu allocations, %zu frees\n", ar.allocs, ar.frees);
    v.errors++;
  }
#ifdef RCB_EXAMPLE_COUNT_HEAP
  printf("heap: %zu calls of the C heap from the static objects (librcb.a)\n", heap_calls);
  if (heap_calls) v.errors++;
#endif
  printf("%s\n", v.errors ? "FAILED" : "OK: drift and fault alarmed on time and named, "
                                        "intervals covering, no allocation in the loop, "
                                        "restart bit-identical");
  return v.errors ? 1 : 0;
}
