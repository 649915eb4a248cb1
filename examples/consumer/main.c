/*
 * Out-of-tree librcb consumer: builds a Jeffcott-like rotor element by
 * element (no INI file, as a firmware host would), then prints its first
 * natural frequency and one receptance.
 *
 * Rotor: one steel shaft (d 50 mm, L 0.4 m, 4 elements), a rigid disk at
 * mid-span (10 kg), two soft isotropic bearings at the shaft ends
 * (k = 1e4 N/m each, undamped), at standstill.
 *
 * With --arena it runs as firmware does (issue #36): every librcb object in
 * the caller's memory, a static bump arena behind the allocator hooks, and
 * prints the hooks' counts (../arena.h). Built with -DRCB_EXAMPLE_COUNT_HEAP
 * and linked statically with the C heap wrapped (../heap_count.h), it also
 * counts every call of the C heap from librcb.a: 0 with --arena.
 *
 * Build:  cmake -S . -B build -DCMAKE_PREFIX_PATH=<rcb prefix> && cmake --build build
 *    or:  cc main.c $(pkg-config --cflags --libs rcb) -o consumer
 * Output lines "key value" (SI units, Hz for frequencies) for scripts.
 */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>
#if !defined(__cplusplus) && !defined(__STDC_NO_COMPLEX__)
#include <complex.h>
#endif

#include <rcb/rcb.h>

#include "../arena.h" /* the caller's memory (--arena): arena, arena_alloc, arena_free */
#ifdef RCB_EXAMPLE_COUNT_HEAP
#include "../heap_count.h" /* heap_calls */
#endif

#define PI 3.14159265358979323846

/* The model; its closed-form answer is in run_consumer_test.sh. */
static const double rho = 7850.0;     /* kg/m^3 */
static const double young = 2.1e11;   /* Pa */
static const double length = 0.4;     /* m */
static const double diameter = 0.05;  /* m */
static const double disk_mass = 10.0; /* kg */
static const double k_bearing = 1e4;  /* N/m, each bearing, xx and yy */
static const double f_probe = 2.0;    /* Hz, where the receptance is printed */



static int fail(const char *what, rcb_status st, const char *msg) {
  fprintf(stderr, "consumer: %s: %s (%s)\n", what, rcb_status_str(st), msg);
  return 1;
}

static rcb_status build(rcb_model *m) {
  rcb_bearing_coefs b = {0};
  rcb_status st;
  b.kxx = k_bearing;
  b.kyy = k_bearing;
  if ((st = rcb_model_add_material(m, "steel", rho, young, 0.3)) != RCB_OK ||
      (st = rcb_model_add_shaft(m, "A", "steel", 0.0, 0.9)) != RCB_OK ||
      (st = rcb_model_add_segment(m, "A", length, diameter, 0.0, 4)) != RCB_OK ||
      (st = rcb_model_add_disk(m, "D", "A", 0.5 * length, disk_mass, 0.02, 0.04)) != RCB_OK ||
      (st = rcb_model_add_bearing(m, "B1", "A", 0.0, &b)) != RCB_OK ||
      (st = rcb_model_add_bearing(m, "B2", "A", length, &b)) != RCB_OK)
    return st;
  return rcb_model_finalize(m);
}

/* al: the allocator hooks (NULL: malloc/free). */
static int report(const rcb_model *m, const rcb_allocator *al) {
  rcb_modes *modes = NULL;
  rcb_frf *frf = NULL;
  rcb_mode mode[4];
  size_t nmodes = 0;
  rcb_dof dof;
  rcb_complex H;
  rcb_status st;
  int rc = 0;

  if ((st = rcb_modes_create(&modes, m, al)) != RCB_OK)
    return fail("modes", st, rcb_model_errmsg(m));
  st = rcb_modes_compute(modes, 0.0, 4, mode, &nmodes, NULL);
  if (st != RCB_OK || nmodes == 0)
    rc = fail("modes", st, rcb_modes_errmsg(modes));
  else
    printf("f1_hz %.9g\n", mode[0].wd / (2.0 * PI));
  rcb_modes_destroy(modes);
  if (rc)
    return rc;

  if ((st = rcb_model_find_dof(m, "D.x", &dof)) != RCB_OK)
    return fail("D.x", st, rcb_model_errmsg(m));
  /* banded by name with hooks: RCB_SOLVER_AUTO may take KLU in a build with
   * SuiteSparse, and KLU allocates its factors with malloc */
  if ((st = rcb_frf_create(&frf, m, 1, &dof, 1, &dof, al ? RCB_SOLVER_BANDED : RCB_SOLVER_AUTO,
                           al)) != RCB_OK)
    return fail("frf", st, rcb_model_errmsg(m));
  st = rcb_frf_eval(frf, 2.0 * PI * f_probe, 0.0, RCB_RECEPTANCE, &H);
  if (st != RCB_OK)
    rc = fail("frf", st, rcb_frf_errmsg(frf));
  else
#if defined(__cplusplus) || defined(__STDC_NO_COMPLEX__)
    printf("h_dx_dx_m_per_n %.9g %.9g\n", H.re, H.im);
#else
    printf("h_dx_dx_m_per_n %.9g %.9g\n", creal(H), cimag(H));
#endif
  rcb_frf_destroy(frf);
  return rc;
}

int main(int argc, char **argv) {
  static unsigned char memory[1u << 20]; /* the firmware's heap */
  arena mem = {memory, sizeof memory, 0, 0, 0, 0, 0};
  rcb_allocator hooks = {arena_alloc, arena_free, &mem};
  const rcb_allocator *al = NULL;
  rcb_model *m = NULL;
  rcb_status st;
  int rc;
  if (argc > 1 && strcmp(argv[1], "--arena") == 0)
    al = &hooks;
  else if (argc > 1)
    return fprintf(stderr, "usage: %s [--arena]\n", argv[0]), 2;
  printf("librcb %s (header %d, library %d)\n", rcb_version_string(), RCB_VERSION_NUMBER,
         rcb_version_number());
#ifdef RCB_EXAMPLE_COUNT_HEAP
  heap_calls = 0; /* from here: librcb's calls only */
#endif
  if ((st = rcb_model_create(&m, al)) != RCB_OK)
    return fail("create", st, "");
  if ((st = build(m)) != RCB_OK) {
    rc = fail("model", st, rcb_model_errmsg(m));
  } else {
    printf("dofs %zu\n", rcb_model_dof_count(m));
    rc = report(m, al);
  }
  rcb_model_destroy(m);
  if (al)
    printf("arena_allocs %zu\narena_frees %zu\narena_bytes %zu\n", mem.allocs, mem.frees,
           mem.used);
#ifdef RCB_EXAMPLE_COUNT_HEAP
  printf("heap_calls %zu\n", heap_calls);
#endif
  return rc;
}
