/*
 * Condition monitoring the way firmware does it (issue #7): a host-style
 * program that links the static library, builds the model of the paper's
 * rotor from an INI string inside a caller-provided memory arena, then runs a
 * monitoring loop that, at the current speed, evaluates the unbalance
 * response (1X vectors) at the two disks and compares it with the measured 1X
 * vectors. Nothing is allocated after initialisation: the arena's allocator
 * hook counts every call and the program fails if one comes from the loop.
 *
 * The "measured" vectors come from a second model, the machine as it really
 * is: from cycle FAULT_CYCLE on its unbalance at disk DA grows from 15e-5 to
 * 45e-5 kg m (a lost balance weight). The monitor must stay quiet before and
 * raise the alarm from that cycle on: the relative 1X deviation
 * |Q_meas - Q_model| / |Q_model| at DA jumps from 0 to about 2 (linearity:
 * the DA contribution triples while DB's stays).
 *
 * Exit status 0 when the alarm pattern is right and no allocation happened
 * in the loop; prints the arena use.
 */
#include <complex.h>
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include "rcb/rcb.h"

/* ---- the caller's memory: a bump arena, free is a no-op ---- */
typedef struct arena {
  unsigned char *base;
  size_t size, used;
  size_t allocs, frees; /* calls through the hooks */
  int sealed;           /* 1 after initialisation: any allocation is a bug */
  size_t allocs_after_init;
} arena;

static void *arena_alloc(void *user, size_t n) {
  arena *a = user;
  size_t at = (a->used + 15u) & ~(size_t)15u; /* 16-byte alignment */
  a->allocs++;
  if (a->sealed) a->allocs_after_init++;
  if (at > a->size || n > a->size - at) return NULL;
  a->used = at + n;
  return a->base + at;
}

static void arena_free(void *user, void *p) {
  arena *a = user;
  (void)p;
  a->frees++;
}

static unsigned char g_memory[2u * 1024u * 1024u]; /* 2 MB, the firmware's heap */

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
#define CYCLES 40
#define FAULT_CYCLE 25
#define ALARM_LEVEL 0.5 /* relative 1X deviation that raises the alarm (-) */

typedef struct monitor {
  rcb_model *model, *machine; /* the reference model; the "real" machine */
  rcb_frf *frf, *frf_machine;
} monitor;

static int init(monitor *mon, const rcb_allocator *al) {
  static const char *const outs[NOUT] = {"DA.x", "DA.y", "DB.x", "DB.y"};
  rcb_dof dof[NOUT];
  rcb_model **ms[2];
  int k, i;
  ms[0] = &mon->model;
  ms[1] = &mon->machine;
  for (k = 0; k < 2; k++) {
    if (rcb_model_create(ms[k], al) ||
        rcb_model_load_string(*ms[k], MODEL_INI, "<firmware>") != RCB_OK) {
      fprintf(stderr, "model: %s\n", *ms[k] ? rcb_model_errmsg(*ms[k]) : "out of memory");
      return 1;
    }
  }
  for (i = 0; i < NOUT; i++)
    if (rcb_model_find_dof(mon->model, outs[i], &dof[i])) return 1;
  /* unbalance-only FRF objects (no force input): all memory sized here. The
   * banded LAPACK solver by name: RCB_SOLVER_AUTO would take KLU in a build
   * with SuiteSparse, and KLU allocates its factors with malloc, not through
   * this arena's hook. */
  if (rcb_frf_create(&mon->frf, mon->model, NOUT, dof, 0, NULL, RCB_SOLVER_BANDED, al) ||
      rcb_frf_create(&mon->frf_machine, mon->machine, NOUT, dof, 0, NULL, RCB_SOLVER_BANDED,
                     al)) {
    fprintf(stderr, "FRF workspace: out of arena memory\n");
    return 1;
  }
  return 0;
}

int main(void) {
  arena ar = {g_memory, sizeof g_memory, 0, 0, 0, 0, 0};
  rcb_allocator al = {arena_alloc, arena_free, &ar};
  monitor mon = {NULL, NULL, NULL, NULL};
  int cycle, errors = 0;
  if (init(&mon, &al)) return 1;
  ar.sealed = 1; /* from here on the loop must not allocate */
  printf("init: %zu allocations, arena %zu of %zu bytes\n", ar.allocs, ar.used, ar.size);

  for (cycle = 0; cycle < CYCLES; cycle++) {
    /* the speed the tachometer reports: a slow run-up 1200 -> 4320 rpm */
    double rpm = 1200.0 + 80.0 * cycle, speed = rpm * 3.14159265358979323846 / 30.0;
    rcb_complex q_model[NOUT], q_meas[NOUT];
    double dev_a, dev_b;
    int alarm;
    if (cycle == FAULT_CYCLE && rcb_model_set_param(mon.machine, "unbalance.UA.amount", 45e-5))
      return 1;
    if (cycle == FAULT_CYCLE && rcb_frf_refresh(mon.frf_machine)) return 1;
    if (rcb_frf_unbalance(mon.frf, speed, q_model) ||
        rcb_frf_unbalance(mon.frf_machine, speed, q_meas)) {
      fprintf(stderr, "cycle %d: %s\n", cycle, rcb_frf_errmsg(mon.frf));
      return 1;
    }
    /* relative 1X deviation at each disk (x and y together) */
    dev_a = sqrt(pow(cabs(q_meas[0] - q_model[0]), 2) + pow(cabs(q_meas[1] - q_model[1]), 2)) /
            sqrt(pow(cabs(q_model[0]), 2) + pow(cabs(q_model[1]), 2));
    dev_b = sqrt(pow(cabs(q_meas[2] - q_model[2]), 2) + pow(cabs(q_meas[3] - q_model[3]), 2)) /
            sqrt(pow(cabs(q_model[2]), 2) + pow(cabs(q_model[3]), 2));
    alarm = dev_a > ALARM_LEVEL || dev_b > ALARM_LEVEL;
    if (cycle % 5 == 0 || cycle == FAULT_CYCLE)
      printf("cycle %2d  %6.0f rpm  |DA.x| %.3e m  deviation DA %.3f DB %.3f  %s\n", cycle, rpm,
             cabs(q_meas[0]), dev_a, dev_b, alarm ? "ALARM" : "ok");
    if (alarm != (cycle >= FAULT_CYCLE)) {
      fprintf(stderr, "cycle %d: alarm %d, expected %d\n", cycle, alarm, cycle >= FAULT_CYCLE);
      errors++;
    }
  }

  printf("loop: %zu allocations after initialisation\n", ar.allocs_after_init);
  if (ar.allocs_after_init) errors++;
  rcb_frf_destroy(mon.frf_machine);
  rcb_frf_destroy(mon.frf);
  rcb_model_destroy(mon.machine);
  rcb_model_destroy(mon.model);
  if (ar.frees != ar.allocs) {
    fprintf(stderr, "%zu allocations, %zu frees\n", ar.allocs, ar.frees);
    errors++;
  }
  printf("%s\n", errors ? "FAILED" : "OK: alarm from the fault cycle on, no allocation in the loop");
  return errors ? 1 : 0;
}
