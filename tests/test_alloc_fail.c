/*
 * Allocation-failure injection (issue #7): an allocator hook that fails the
 * k-th allocation, for every k of a run (issue #27: each in a child process
 * forked at allocation k, rcb_test_util.h), for each of: loading a model
 * from an INI string, creating an FRF object and sweeping it, a small fit
 * (the paper's method, noise-free data, 2 parameters; again with NLopt when
 * built with it), a small diagnosis (every candidate scored, one refit), the
 * refits of one on a frequency subset (screen, random starts, evaluation,
 * polish), a plan (rcb_plan), a comparison, and reading a CSV and a UFF58
 * measurement. Every run must
 *  - return an error status when the failing allocation was reached (never
 *    RCB_OK with a silently missing piece), RCB_ERR_NOMEM or an error that
 *    propagated from it, with a message;
 *  - free everything it allocated (the hook counts allocations and frees;
 *    the sanitizer build checks the same with LeakSanitizer);
 *  - not crash.
 * The run the children fork from checks the scenario's result, so the walk
 * covers a path that really works.
 */
#define _POSIX_C_SOURCE 200809L /* mkdtemp */
#include <complex.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "core/rcb_internal.h"
#include "rcb/rcb_config.h"
#include "rcb_test_util.h"

typedef rcb_test_failing failing;

static rcb_allocator hooks(failing *f) { return rcb_test_failing_allocator(f); }

/* Two shafts, nelson_crandall_1 coupling, bearings, a disk, an unbalance,
 * a probe and a UFF map: every kind of item the loader allocates for. */
static const char MODEL[] =
    "[model]\nname = alloc test\n"
    "[material steel]\ndensity = 7800\nyoung = 2e11\npoisson = 0.3\n"
    "[shaft A]\nmaterial = steel\nshear_factor = 0.9\nsegment = 0.3 0.02 0 3\n"
    "segment = 0.2 0.03 0.01 2\n"
    "[shaft B]\nmaterial = steel\nshear_factor = 0.9\nstart = 0.6\n"
    "damping_stiffness = 1e-5\nsegment = 0.5 0.02 0.0 5\n"
    "[bearing B1]\nat = A 0.1\nkxx = 1e7\nkyy = 2e7\ncxx = 100\ncyy = 100\n"
    "[bearing B2]\nat = B 1.0\nspeed_rpm = 0 3000 6000\nkxx = 1e7 2e7 3e7\nkyy = 1e7\n"
    "[disk D]\nat = A 0.2\ndensity = 7800\nouter_diameter = 0.1\ninner_diameter = 0.02\n"
    "width = 0.02\n"
    "[coupling C]\nmodel = nelson_crandall_1\nbetween = A end, B start\nkt = 1e5\n"
    "kr = 1e3\nhub_mass = 0.1\nhub_Id = 1e-4\nhub_Ip = 2e-4\n"
    "[unbalance U]\nat = D\namount = 1e-4\nphase_deg = 30\n"
    "[station P]\nat = B 0.8\n"
    "[uff]\nmap = 1 D, 2 P\n";

typedef rcb_status (*scenario)(const rcb_allocator *a, int check);

/* The walk: one complete run in which every allocation from `from` on
 * fails in turn, each in a child process forked there (rcb_test_util.h);
 * each child must end with an error and its message and free all it took.
 * The run itself is checked (check = 1) and returns the allocation count. */
static size_t walk_from(const char *name, scenario run, size_t from) {
  rcb_test_walk w = {from, rcb_test_walk_stride(), 0, 0, 0, 0};
  failing r = {0, 0, 0, 0, 0, &w};
  rcb_allocator a = hooks(&r);
  rcb_status st = run(&a, 1);
  rcb_test_walk_child_end(&r, name, st, 1); /* a child ends here */
  if (w.failed_at)
    fail_msg("%s: allocation %zu failing: the run went wrong (its child's message above; "
             "wait status %d)",
             name, w.failed_at, w.status);
  assert_int_equal(st, RCB_OK);
  assert_int_equal(r.live, 0);
  assert_int_equal(w.forks, (r.allocs - from) / w.stride + 1);
  if (w.stride > 1)
    print_message("%s: every %zu-th of allocations %zu to %zu failed in turn\n", name, w.stride,
                  from, r.allocs);
  else
    print_message("%s: allocations %zu to %zu failed in turn\n", name, from, r.allocs);
  return r.allocs;
}

static size_t walk(const char *name, scenario run) { return walk_from(name, run, 1); }

/* ---- scenarios; each frees everything before returning ---- */

static rcb_status load(const rcb_allocator *a, rcb_model **out) {
  rcb_model *m = NULL;
  rcb_status st = rcb_model_create(&m, a);
  *out = NULL;
  if (st) {
    assert_null(m);
    assert_int_equal(st, RCB_ERR_NOMEM);
    return st;
  }
  st = rcb_model_load_string(m, MODEL, "<alloc>");
  if (st) {
    assert_true(rcb_model_errmsg(m)[0] != '\0');
    rcb_model_destroy(m);
    return st;
  }
  *out = m;
  return RCB_OK;
}

static rcb_status sc_load(const rcb_allocator *a, int check) {
  rcb_model *m = NULL;
  rcb_status st = load(a, &m);
  if (st) return st;
  if (check) {
    long node;
    const char *station;
    assert_int_equal(rcb_model_node_count(m), 5 + 1 + 5 + 1);
    assert_int_equal(rcb_model_uff_node_count(m), 2);
    assert_int_equal(rcb_model_uff_node(m, 1, &node, &station), RCB_OK);
    assert_int_equal(node, 2);
    assert_string_equal(station, "P");
  }
  rcb_model_destroy(m);
  return RCB_OK;
}

static rcb_status sc_frf(const rcb_allocator *a, int check) {
  rcb_model *m = NULL;
  rcb_frf *f = NULL;
  rcb_dof d[2];
  rcb_complex H[4], Q[2];
  rcb_status st = load(a, &m);
  int i, s;
  if (st) return st;
  assert_int_equal(rcb_model_find_dof(m, "D.x", &d[0]), RCB_OK);
  assert_int_equal(rcb_model_find_dof(m, "P.y", &d[1]), RCB_OK);
  for (s = 1; s <= 2 && !st; s++) { /* dense and banded workspaces */
    st = rcb_frf_create(&f, m, 2, d, 2, d, (rcb_solver_kind)s, a);
    if (st) {
      assert_null(f);
      break;
    }
    for (i = 0; i < 5 && !st; i++) st = rcb_frf_eval(f, 50.0 * i + 10.0, 300.0, RCB_RECEPTANCE, H);
    if (!st) st = rcb_frf_unbalance(f, 300.0, Q);
    if (!st && check) {
      /* reciprocity without rotation-dependent terms is broken by G; at
       * speed 0 and no cross-coupled bearings H is symmetric */
      assert_int_equal(rcb_frf_eval(f, 100.0, 0.0, RCB_RECEPTANCE, H), RCB_OK);
      assert_true(cabs(H[1] - H[2]) <= 1e-9 * cabs(H[1]) + 1e-30);
      assert_true(cabs(Q[0]) > 0.0);
    }
    rcb_frf_destroy(f);
    f = NULL;
  }
  rcb_model_destroy(m);
  return st;
}

static const char *csv_path(void) {
  return rcb_test_tmp_path("meas.csv");
}

static rcb_status sc_csv(const rcb_allocator *a, int check) {
  rcb_meas *ms = NULL;
  rcb_status st = rcb_meas_create(&ms, a);
  if (st) {
    assert_null(ms);
    return st;
  }
  st = rcb_meas_read_csv(ms, csv_path());
  if (st) assert_true(rcb_meas_errmsg(ms)[0] != '\0');
  if (!st && check) {
    rcb_meas_channel_info ci;
    assert_int_equal(rcb_meas_point_count(ms), 3);
    assert_int_equal(rcb_meas_channel_count(ms), 2);
    assert_int_equal(rcb_meas_channel(ms, 1, &ci), RCB_OK);
    assert_string_equal(ci.response, "P.y");
    assert_true(creal(ci.data[2]) == 7.0 && cimag(ci.data[2]) == -8.0);
    assert_true(rcb_test_close(rcb_meas_grid(ms)[1], 2.0 * RCB_PI * 20.0, 1e-15, 0.0));
  }
  rcb_meas_destroy(ms);
  return st;
}

static const char *uff_path(void) {
  return rcb_test_tmp_path("meas.uff");
}

static const rcb_uff_node uff_map[2] = {{1, "D", NULL, NULL}, {2, "P", NULL, NULL}};

static rcb_status sc_uff(const rcb_allocator *a, int check) {
  rcb_meas *ms = NULL;
  rcb_status st = rcb_meas_create(&ms, a);
  if (st) {
    assert_null(ms);
    return st;
  }
  st = rcb_meas_read_uff(ms, uff_path(), 2, uff_map);
  if (st) assert_true(rcb_meas_errmsg(ms)[0] != '\0');
  if (!st && check) {
    rcb_meas_channel_info ci;
    assert_int_equal(rcb_meas_point_count(ms), 3);
    assert_int_equal(rcb_meas_channel_count(ms), 2);
    assert_int_equal(rcb_meas_channel(ms, 1, &ci), RCB_OK);
    assert_string_equal(ci.response, "P.y");
    assert_true(rcb_test_close(creal(ci.data[2]), 7.0, 1e-12, 0.0));
  }
  rcb_meas_destroy(ms);
  return st;
}

/* Noise-free FRF "measurement" of the model (plain malloc: not walked). */
static rcb_meas *truth_meas_n(size_t n, double f0, double df) {
  rcb_model *m = rcb_test_model_from_string(MODEL);
  rcb_meas *ms = NULL;
  rcb_frf *f = NULL;
  rcb_dof d[4];
  double *x = calloc(n, sizeof *x);
  rcb_complex *H = calloc(4 * n, sizeof *H), *col = calloc(n, sizeof *col);
  size_t i, o;
  static const char *const outs[4] = {"C.A.x", "C.B.x", "C.A.ry", "C.B.ry"};
  for (o = 0; o < 4; o++) assert_int_equal(rcb_model_find_dof(m, outs[o], &d[o]), RCB_OK);
  assert_int_equal(rcb_frf_create(&f, m, 4, d, 1, d, RCB_SOLVER_AUTO, NULL), RCB_OK);
  for (i = 0; i < n; i++) {
    x[i] = 2.0 * RCB_PI * (f0 + df * (double)i);
    assert_int_equal(rcb_frf_eval(f, x[i], 0.0, RCB_RECEPTANCE, H + 4 * i), RCB_OK);
  }
  assert_int_equal(rcb_meas_create(&ms, NULL), RCB_OK);
  assert_int_equal(rcb_meas_set_grid(ms, RCB_MEAS_FRF, n, x, 0.0), RCB_OK);
  for (o = 0; o < 4; o++) {
    for (i = 0; i < n; i++) col[i] = H[4 * i + o];
    assert_int_equal(rcb_meas_add_channel(ms, outs[o], "C.A.x", RCB_RECEPTANCE, col), RCB_OK);
  }
  rcb_frf_destroy(f);
  rcb_model_destroy(m);
  free(x);
  free(H);
  free(col);
  return ms;
}

/* The truth's 12 points, 50-490 Hz. */
static rcb_meas *truth_meas(void) { return truth_meas_n(12, 50.0, 40.0); }

static rcb_meas *g_truth;

static const char *g_method; /* NULL: the paper's method; else an NLopt name */

static rcb_status sc_fit(const rcb_allocator *a, int check) {
  rcb_model *m = NULL;
  rcb_fit *f = NULL;
  rcb_status st = load(a, &m);
  if (st) return st;
  /* start a factor 2 away from the truth (kt 1e5 N/m, kr 1e3 N m/rad) */
  assert_int_equal(rcb_model_set_param(m, "coupling.C.kt", 2e5), RCB_OK);
  assert_int_equal(rcb_model_set_param(m, "coupling.C.kr", 5e2), RCB_OK);
  st = rcb_fit_create(&f, m, g_truth, a);
  if (!st) st = rcb_fit_add_param(f, "coupling.C.kt", 1e3, 1e7, 1);
  if (!st) st = rcb_fit_add_param(f, "coupling.C.kr", 1e1, 1e5, 1);
  if (!st) st = rcb_fit_set_scale(f, RCB_SCALE_LOG10);
  if (!st && g_method) st = rcb_fit_set_method(f, RCB_FIT_NLOPT, g_method);
  if (!st) st = rcb_fit_run(f);
  if (st && f) assert_true(rcb_fit_errmsg(f)[0] != '\0');
  if (!st && check) {
    double kt, kr;
    rcb_fit_report r;
    assert_int_equal(rcb_model_get_param(m, "coupling.C.kt", &kt), RCB_OK);
    assert_int_equal(rcb_model_get_param(m, "coupling.C.kr", &kr), RCB_OK);
    print_message("fit: kt %.9g kr %.9g\n", kt, kr);
    assert_int_equal(rcb_fit_get_report(f, &r), RCB_OK);
    if (g_method) { /* a local derivative-free method: it must descend */
      assert_true(r.objective < r.objective0);
    } else {
      assert_true(rcb_test_close(kt, 1e5, 1e-5, 0.0));
      assert_true(rcb_test_close(kr, 1e3, 1e-5, 0.0));
      assert_true(r.converged);
    }
  }
  rcb_fit_destroy(f);
  rcb_model_destroy(m);
  return st;
}

/* The model (the truth's kr at 1/3) and a diagnosis of g_truth fitting kt,
 * on log magnitudes, one refit (and the other coupling models); *m NULL
 * when the model did not load. */
static rcb_status diag_setup(const rcb_allocator *a, rcb_model **m, rcb_diag **d) {
  rcb_status st = load(a, m);
  *d = NULL;
  if (st) return st;
  assert_int_equal(rcb_model_set_param(*m, "coupling.C.kr", 1e3 / 3.0), RCB_OK);
  st = rcb_diag_create(d, *m, g_truth, a);
  if (!st) st = rcb_diag_add_fitted_param(*d, "coupling.C.kt", 1e3, 1e7, 1);
  if (!st) st = rcb_diag_set_scale(*d, RCB_SCALE_LOG10);
  if (!st) st = rcb_diag_set_refits(*d, 1);
  return st;
}

/* The truth's kr is hidden at 1/3: the diagnosis fits kt, scores every
 * candidate, refits the best one (and the other coupling models). */
static rcb_status sc_diag(const rcb_allocator *a, int check) {
  rcb_model *m = NULL;
  rcb_diag *d = NULL;
  rcb_status st = diag_setup(a, &m, &d);
  if (!m) return st;
  if (!st) st = rcb_diag_run(d);
  if (st && d && rcb_diag_errmsg(d)[0] == '\0')
    fail_msg("diagnosis: status %s without a message", rcb_status_str(st));
  if (!st && check) {
    rcb_diag_candidate c;
    assert_true(rcb_diag_candidate_count(d) > 10);
    assert_int_equal(rcb_diag_candidate_get(d, 0, &c), RCB_OK);
    print_message("diagnosis: first %s at %s (%s), error %.3g %%\n", rcb_effect_name(c.effect),
                  c.place, c.params, c.error_pct);
    assert_true(c.refitted);
  }
  rcb_diag_destroy(d);
  rcb_model_destroy(m);
  return st;
}

/* The diagnosis on a grid long enough for the screen on a frequency subset
 * (301 points 50-650 Hz; the subset keeps 150 of them): the refits' screen,
 * random starts (with a noise model far below the data's, so that no
 * screen reaches the floor), evaluation on all points and polish. The walk
 * starts where the refits do: the allocation count at the last report of
 * the scores (a refit's first report jumps past the candidates refitted
 * only), recorded by the progress callback on a complete run. */
static size_t g_refits_from; /* allocations when the scores ended, 0: not known */

typedef struct refit_mark {
  const rcb_test_failing *f;
  size_t last_done, last_allocs;
} refit_mark;

static int mark_refits(void *user, size_t done, size_t total) {
  refit_mark *r = user;
  (void)total;
  if (!g_refits_from && r->last_done && done > r->last_done + 1) g_refits_from = r->last_allocs;
  r->last_done = done, r->last_allocs = r->f->allocs;
  return 0;
}

static rcb_status sc_diag_subset(const rcb_allocator *a, int check) {
  rcb_model *m = NULL;
  rcb_diag *d = NULL;
  rcb_diag_stats stats;
  refit_mark mark = {a->user, 0, 0};
  rcb_status st = diag_setup(a, &m, &d);
  if (!m) return st;
  if (!st) st = rcb_diag_set_noise_model(d, 0.1, 0.01);
  if (!st) st = rcb_diag_set_progress(d, mark_refits, &mark);
  if (!st) st = rcb_diag_run(d);
  if (st && d && rcb_diag_errmsg(d)[0] == '\0')
    fail_msg("diagnosis: status %s without a message", rcb_status_str(st));
  if (!st && check) {
    rcb_diag_candidate c;
    assert_int_equal(rcb_diag_candidate_get(d, 0, &c), RCB_OK);
    assert_int_equal(rcb_diag_get_stats(d, &stats), RCB_OK);
    print_message("diagnosis on the subset: first %s at %s, error %.3g %%, screened only %d; "
                  "%zu refits, %zu with random starts, %zu sweeps\n",
                  rcb_effect_name(c.effect), c.place, c.error_pct, c.screened_only,
                  stats.refits, stats.restarts, stats.evaluations);
    assert_true(c.refitted);
    assert_int_equal(c.screened_only, 0);
    assert_true(stats.restarts > 0);
  }
  rcb_diag_destroy(d);
  rcb_model_destroy(m);
  return st;
}

/* Modes at two speeds and a three-speed Campbell diagram (issue #17): every
 * array and the dgeev workspace come from the hooks. */
static rcb_status sc_modes(const rcb_allocator *a, int check) {
  rcb_model *m = NULL;
  rcb_modes *e = NULL;
  rcb_mode md[4];
  size_t n = 0;
  const double speeds[3] = {0.0, 300.0, 600.0};
  double wd[3 * 3];
  rcb_status st = load(a, &m);
  if (st) return st;
  st = rcb_modes_create(&e, m, a);
  if (st) assert_null(e);
  if (!st) st = rcb_modes_compute(e, 300.0, 4, md, &n, NULL);
  if (!st) st = rcb_campbell(e, 3, speeds, 3, wd, NULL, NULL);
  if (st && e) assert_true(rcb_modes_errmsg(e)[0] != '\0');
  if (!st && check) {
    assert_true(n >= 3);
    assert_true(wd[3] == md[0].wd); /* the Campbell column at 300 rad/s is that list */
    assert_true(wd[0] > 0.0 && wd[0] < wd[1]);
  }
  rcb_modes_destroy(e);
  rcb_model_destroy(m);
  return st;
}

#if RCB_WITH_SUNDIALS
/* A short run-up; CVODE's own vectors come from SUNDIALS' malloc (not
 * walked), its out-of-memory flag maps to RCB_ERR_NOMEM. */
static rcb_status sc_transient(const rcb_allocator *a, int check) {
  rcb_model *m = NULL;
  rcb_transient *t = NULL;
  rcb_dof d;
  rcb_speed_profile p = {100.0, 200.0, 1000.0};
  rcb_transient_stats s;
  rcb_status st = load(a, &m);
  if (st) return st;
  assert_int_equal(rcb_model_find_dof(m, "D.x", &d), RCB_OK);
  st = rcb_transient_create(&t, m, 1, &d, a); /* on failure t (if any) holds the message */
  if (!st) st = rcb_transient_run(t, &p, 0.02, 0.005, NULL, NULL, NULL, NULL);
  if (st && t) assert_true(rcb_transient_errmsg(t)[0] != '\0');
  if (!st && check) {
    assert_int_equal(rcb_transient_get_stats(t, &s), RCB_OK);
    assert_true(rcb_test_close(s.t_final, 0.02, 1e-12, 0.0));
    assert_true(s.steps > 0);
  }
  rcb_transient_destroy(t);
  rcb_model_destroy(m);
  return st;
}
#endif

/* ---- tests ---- */

static void test_load(void **state) {
  size_t n;
  (void)state;
  n = walk("model load", sc_load);
  assert_true(n > 10);
}

static void test_modes(void **state) {
  size_t n;
  (void)state;
  n = walk("modes + campbell", sc_modes);
  assert_true(n > 10);
}

static void test_transient(void **state) {
  (void)state;
#if RCB_WITH_SUNDIALS
  assert_true(walk("transient", sc_transient) > 10);
#else
  skip();
#endif
}

static void test_frf(void **state) {
  size_t n;
  (void)state;
  n = walk("FRF create + sweep", sc_frf);
  assert_true(n > 10);
}

static void test_csv(void **state) {
  size_t n;
  FILE *fp;
  (void)state;
  fp = fopen(csv_path(), "w");
  assert_non_null(fp);
  fputs("# kind = receptance\n# rpm = 0\nfreq_hz,D.x/D.x re,D.x/D.x im,P.y/D.x re,P.y/D.x im\n"
        "10,1,2,3,4\n20,5,6,7,8\n30,1e-9,-2e-9,7,-8\n",
        fp);
  fclose(fp);
  n = walk("CSV read", sc_csv);
  assert_true(n > 1);
}

/* A walk of a scenario that reads the noise-free measurement g_truth, with
 * the NLopt algorithm method (NULL: the paper's method). */
static size_t walk_on_truth(const char *name, scenario run, const char *method) {
  size_t n;
  g_truth = truth_meas();
  g_method = method;
  n = walk(name, run);
  g_method = NULL;
  rcb_meas_destroy(g_truth);
  g_truth = NULL;
  return n;
}

/* The plan (issue #23 item 6): the coupling's kt against bearing B1's kxx,
 * every station's x and y as candidates. */
static rcb_status sc_plan(const rcb_allocator *a, int check) {
  rcb_model *m = NULL;
  rcb_plan *p = NULL;
  rcb_status st = load(a, &m);
  if (st) return st;
  if (!(st = rcb_model_finalize(m))) st = rcb_plan_create(&p, m, g_truth, a);
  if (!st) st = rcb_plan_add_param(p, 0, "coupling.C.kt");
  if (!st) st = rcb_plan_add_param(p, 1, "bearing.B1.kxx");
  if (!st) st = rcb_plan_set_noise_model(p, 10.0, 1.0);
  if (!st) st = rcb_plan_run(p);
  if (st && p) assert_true(rcb_plan_errmsg(p)[0] != '\0');
  if (!st && check) {
    rcb_plan_result r;
    assert_int_equal(rcb_plan_get_result(p, &r), RCB_OK);
    print_message("plan: angle %.6g deg, chi2 %.6g, %zu candidates\n", r.angle_deg,
                  r.chi2_sep, r.candidates);
    assert_true(r.candidates > 0 && r.angle_deg > 0);
  }
  rcb_plan_destroy(p);
  rcb_model_destroy(m);
  return st;
}

/* The comparison with its outlier summary (one channel scaled). */
static rcb_status sc_compare(const rcb_allocator *a, int check) {
  rcb_model *m = NULL;
  rcb_compare *c = NULL;
  rcb_status st = load(a, &m);
  if (st) return st;
  if (!(st = rcb_model_finalize(m))) st = rcb_compare_create(&c, a);
  if (!st) st = rcb_compare_run(c, m, g_truth);
  if (st && c) assert_true(rcb_compare_errmsg(c)[0] != '\0');
  if (!st && check) assert_int_equal(rcb_compare_outlier_count(c), 0);
  rcb_compare_destroy(c);
  rcb_model_destroy(m);
  return st;
}

static void test_plan(void **state) {
  (void)state;
  g_truth = truth_meas();
  walk("plan", sc_plan);
  rcb_meas_destroy(g_truth);
  g_truth = NULL;
}

static void test_compare(void **state) {
  (void)state;
  walk_on_truth("compare", sc_compare, NULL);
}

static void test_fit(void **state) {
  (void)state;
  walk_on_truth("fit (paper method)", sc_fit, NULL);
}

static void test_uff(void **state) {
  size_t n;
  rcb_meas *ms = NULL;
  static const rcb_complex c0[3] = {1.0, 5.0, 1e-9}, c1[3] = {3.0, 7.0, 7.0};
  const double x[3] = {2.0 * RCB_PI * 10.0, 2.0 * RCB_PI * 20.0, 2.0 * RCB_PI * 30.0};
  (void)state;
  assert_int_equal(rcb_meas_create(&ms, NULL), RCB_OK);
  assert_int_equal(rcb_meas_set_grid(ms, RCB_MEAS_FRF, 3, x, 0.0), RCB_OK);
  assert_int_equal(rcb_meas_add_channel(ms, "D.x", "D.x", RCB_RECEPTANCE, c0), RCB_OK);
  assert_int_equal(rcb_meas_add_channel(ms, "P.y", "D.x", RCB_RECEPTANCE, c1), RCB_OK);
  assert_int_equal(rcb_meas_write_uff(ms, uff_path(), 0, 2, uff_map), RCB_OK);
  rcb_meas_destroy(ms);
  n = walk("UFF58 read", sc_uff);
  assert_true(n > 1);
}

static void test_fit_nlopt(void **state) {
  (void)state;
#if RCB_WITH_NLOPT
  /* NLopt's own allocations do not go through the hooks */
  walk_on_truth("fit (NLopt BOBYQA)", sc_fit, "LN_BOBYQA");
#else
  skip();
#endif
}

static void test_diagnose(void **state) {
  (void)state;
  walk_on_truth("diagnosis", sc_diag, NULL);
}

/* From where the refits start (the scores before them are the diagnosis
 * walk's). */
static void test_diagnose_subset(void **state) {
  failing f = {0, 0, 0, 0, 0, NULL};
  rcb_allocator a = hooks(&f);
  size_t n;
  (void)state;
  g_truth = truth_meas_n(301, 50.0, 2.0);
  g_refits_from = 0;
  assert_int_equal(sc_diag_subset(&a, 0), RCB_OK); /* where the refits start */
  assert_true(g_refits_from > 0 && g_refits_from < f.allocs);
  n = walk_from("diagnosis on the subset", sc_diag_subset, g_refits_from);
  assert_true(n > g_refits_from);
  rcb_meas_destroy(g_truth);
  g_truth = NULL;
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_load),
      cmocka_unit_test(test_frf),
      cmocka_unit_test(test_modes),
      cmocka_unit_test(test_transient),
      cmocka_unit_test(test_csv),
      cmocka_unit_test(test_uff),
      cmocka_unit_test(test_fit_nlopt),
      cmocka_unit_test(test_diagnose),
      cmocka_unit_test(test_diagnose_subset),
      cmocka_unit_test(test_fit),
      cmocka_unit_test(test_plan),
      cmocka_unit_test(test_compare),
  };
  return cmocka_run_group_tests(tests, rcb_test_setup_tmpdir, rcb_test_teardown_tmpdir);
}
