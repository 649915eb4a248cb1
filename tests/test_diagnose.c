/*
 * Diagnosis on data whose generating model holds an effect the user's model
 * lacks (eq. 19 noise, 10 %, 1 %): the hidden effect, at the right place,
 * ranks first and is significant, and applying it brings the error to the
 * noise floor (a shaft element at 0.6 of its stiffness, issue #23: that
 * element or a neighbour); with nothing hidden, no candidate is significant,
 * the shaft elements' among them.
 */
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
#include "rcb_test_util.h"

#define RPM (RCB_PI / 30.0)

static const char *const outs[] = {"DA.x", "DA.y", "C.A.x", "C.A.y",
                                   "C.B.x", "C.B.y", "DB.x", "DB.y"};

/* Inertances outs / DA.x, n points f0-f1 Hz at 10000 rpm, with eq. 19 noise;
 * the channel of response probe (NULL: none) read gain times its value (a
 * probe reading off, before the noise). */
static rcb_meas *measure_probe(const rcb_model *truth, unsigned seed, size_t n, double f0,
                               double f1, const char *probe, double gain) {
  rcb_meas *ms = NULL;
  rcb_frf *fr = NULL;
  rcb_dof od[8], in;
  size_t i, o;
  double *x = calloc(n, sizeof *x);
  rcb_complex *H = calloc(8 * n, sizeof *H), *col = calloc(n, sizeof *col);
  for (o = 0; o < 8; o++) assert_int_equal(rcb_model_find_dof(truth, outs[o], &od[o]), 0);
  assert_int_equal(rcb_model_find_dof(truth, "DA.x", &in), RCB_OK);
  assert_int_equal(rcb_frf_create(&fr, truth, 8, od, 1, &in, RCB_SOLVER_AUTO, NULL), RCB_OK);
  for (i = 0; i < n; i++) {
    x[i] = 2 * RCB_PI * (f0 + (f1 - f0) * (double)i / (double)(n - 1));
    assert_int_equal(rcb_frf_eval(fr, x[i], 10000 * RPM, RCB_INERTANCE, H + 8 * i), RCB_OK);
  }
  assert_int_equal(rcb_meas_create(&ms, NULL), RCB_OK);
  assert_int_equal(rcb_meas_set_grid(ms, RCB_MEAS_FRF, n, x, 10000 * RPM), RCB_OK);
  for (o = 0; o < 8; o++) {
    double g = probe && strcmp(outs[o], probe) == 0 ? gain : 1.0;
    for (i = 0; i < n; i++) col[i] = g * H[8 * i + o];
    assert_int_equal(rcb_meas_add_channel(ms, outs[o], "DA.x", RCB_INERTANCE, col), RCB_OK);
  }
  assert_int_equal(rcb_meas_add_noise(ms, 10.0, 1.0, seed), RCB_OK);
  rcb_frf_destroy(fr);
  free(x);
  free(H);
  free(col);
  return ms;
}

static rcb_meas *measure_grid(const rcb_model *truth, unsigned seed, size_t n, double f0,
                              double f1) {
  return measure_probe(truth, seed, n, f0, f1, NULL, 1.0);
}

/* The tests' grid: 151 points 100-400 Hz (2 Hz apart). */
static rcb_meas *measure(const rcb_model *truth, unsigned seed) {
  return measure_grid(truth, seed, 151, 100.0, 400.0);
}

/* The one rule (issue #23): every candidate's claim is rcb_evidence_claim of
 * its own figures; the ranking puts what may be said first; the explanation
 * says "explains" exactly when the first candidate's claim does, and "No
 * candidate is significant" exactly when none is. */
static void claims_consistent(const rcb_diag *d, const char *text) {
  size_t k, n = rcb_diag_candidate_count(d), nsig = 0;
  double err0;
  rcb_claim prev = RCB_CLAIM_EXPLAINS, first = RCB_CLAIM_NONE;
  assert_int_equal(rcb_diag_baseline(d, &err0, NULL, NULL), RCB_OK);
  for (k = 0; k < n; k++) {
    rcb_diag_candidate c;
    rcb_evidence e;
    assert_int_equal(rcb_diag_candidate_get(d, k, &c), RCB_OK);
    if (!c.refitted) {
      assert_int_equal(c.claim, RCB_CLAIM_NONE);
      continue;
    }
    /* the evidence it was judged on holds its own figures (issue #33: the
     * dispersion, the candidates tried, the whiteness and plausibility are
     * in it too) */
    assert_int_equal(rcb_diag_candidate_evidence(d, k, &e), RCB_OK);
    assert_true(e.error_before_pct == err0 && e.error_after_pct == c.error_pct);
    assert_true(e.chi2 == c.chi2 && (e.chi2_limit == c.chi2_limit || isnan(c.chi2_limit)));
    assert_true(fabs(rcb_evidence_dbic(&e) - c.delta_bic) <= 1e-9 * fabs(c.delta_bic));
    assert_true(e.tried == (double)n);
    assert_int_equal(e.white, c.white == 1);
    assert_int_equal(e.beyond, c.beyond);
    assert_int_equal(c.claim, rcb_evidence_claim(&e));
    assert_int_equal(c.significant, rcb_evidence_significant(&e));
    assert_int_equal(c.significant, c.claim != RCB_CLAIM_NONE);
    assert_true(c.claim <= prev); /* ranked by claim first */
    prev = c.claim;
    if (k == 0) first = c.claim;
    nsig += c.significant;
  }
  assert_int_equal(strstr(text, "explains") != NULL, first == RCB_CLAIM_EXPLAINS);
  assert_int_equal(strstr(text, "No candidate is significant") != NULL, nsig == 0);
}

/* Diagnose the paper model (its coupling kt, kr, ct fitted) against data
 * from a truth with one extra effect; return the best candidate. */
static void diagnose(rcb_model *truth, unsigned seed, rcb_diag_candidate *best,
                     double *err0, double *floor0, rcb_diag **out) {
  rcb_model *m = rcb_test_model_from_example("paper_system.ini");
  rcb_meas *ms = measure(truth, seed);
  rcb_diag *d = NULL;
  char text[4096];
  size_t need;
  assert_int_equal(rcb_diag_create(&d, m, ms, NULL), RCB_OK);
  assert_int_equal(rcb_diag_set_noise_model(d, 10.0, 1.0), RCB_OK);
  assert_int_equal(rcb_diag_add_fitted_param(d, "coupling.C.kt", 46.095, 46.095e6, 1), 0);
  assert_int_equal(rcb_diag_add_fitted_param(d, "coupling.C.kr", 0.22076, 220760, 1), 0);
  assert_int_equal(rcb_diag_add_fitted_param(d, "coupling.C.ct", 0.010949, 10949, 1), 0);
  if (rcb_diag_run(d)) fail_msg("%s", rcb_diag_errmsg(d));
  assert_true(rcb_diag_candidate_count(d) > 30);
  assert_int_equal(rcb_diag_candidate_get(d, 0, best), RCB_OK);
  assert_int_equal(rcb_diag_baseline(d, err0, NULL, floor0), RCB_OK);
  assert_int_equal(rcb_diag_explain(d, text, sizeof text, &need), RCB_OK);
  print_message("  %s\n", text);
  claims_consistent(d, text);
  if (getenv("RCB_DIAG_VERBOSE")) {
    size_t k;
    for (k = 0; k < rcb_diag_candidate_count(d) &&
                k < (getenv("RCB_DIAG_ROWS") ? (size_t)atoi(getenv("RCB_DIAG_ROWS")) : 12u);
         k++) {
      rcb_diag_candidate c;
      rcb_diag_candidate_get(d, k, &c);
      print_message("    %2zu %-60s pred %6.2f%% refit %d err %.3g bic %+.1f %s\n", k + 1,
                    c.description, c.predicted_pct, c.refitted, c.error_pct, c.delta_bic,
                    c.fitted);
    }
  }
  *out = d;
  rcb_meas_destroy(ms);
  rcb_model_destroy(m);
}

/* Apply the best candidate: its model reaches the noise floor. */
static void apply_reaches_floor(rcb_diag *d, double floor0) {
  char *ini;
  size_t need = 0;
  rcb_model *m1 = NULL, *m2;
  assert_int_equal(rcb_diag_apply_model(d, 0, NULL, &m1), RCB_OK);
  assert_true(rcb_model_dof_count(m1) > 0); /* finalized */
  assert_int_equal(rcb_model_write_ini(m1, NULL, 0, &need), RCB_ERR_WORKSPACE);
  ini = malloc(need);
  assert_int_equal(rcb_model_write_ini(m1, ini, need, &need), RCB_OK);
  m2 = rcb_test_model_from_string(ini); /* the applied model written as INI loads */
  assert_int_equal(rcb_model_dof_count(m2), rcb_model_dof_count(m1));
  rcb_model_destroy(m2);
  rcb_model_destroy(m1);
  free(ini);
  {
    rcb_diag_candidate c;
    assert_int_equal(rcb_diag_candidate_get(d, 0, &c), RCB_OK);
    if (!(c.error_pct < 1.1 * floor0))
      fail_msg("applied: error %g %%, floor %g %%", c.error_pct, floor0);
  }
}

/* Diagnose data from truth (which holds the hidden effect `what`) over the
 * seeds; destroys truth. One noise seed per case (RCB_DIAG_SEEDS=N: N); the
 * success rate over seeds is measured by ./scripts/dev.sh diag-success, and
 * the second seed here was 100 s of the test command (issue #27). */
static void hidden_in(rcb_model *truth, const char *what, rcb_effect want, const char *place) {
  rcb_diag_candidate best;
  rcb_diag *d;
  double err0, floor0;
  unsigned seed;
  for (seed = 1; seed <= (getenv("RCB_DIAG_SEEDS") ? (unsigned)atoi(getenv("RCB_DIAG_SEEDS")) : 1u); seed++) {
    diagnose(truth, seed, &best, &err0, &floor0, &d);
    print_message("  hidden %s: first '%s' (%s), predicted %.1f %%, error %.3g -> %.3g "
                  "%% (floor %.3g), BIC %+.1f, %s\n",
                  what, best.description, best.place, best.predicted_pct, err0,
                  best.error_pct, floor0, best.delta_bic, best.fitted);
    assert_int_equal(best.effect, want);
    assert_non_null(strstr(best.place, place));
    assert_true(best.significant);
    assert_int_equal(best.claim, RCB_CLAIM_EXPLAINS); /* and the adequacy test agrees */
    apply_reaches_floor(d, floor0);
    rcb_diag_destroy(d);
  }
  rcb_model_destroy(truth);
}

static void hidden(const char *param, double value, rcb_effect want, const char *place) {
  rcb_model *truth = rcb_test_model_from_example("paper_system.ini");
  char what[160];
  assert_int_equal(rcb_model_set_param(truth, param, value), RCB_OK);
  snprintf(what, sizeof what, "%s = %g", param, value);
  hidden_in(truth, what, want, place);
}

static void test_hidden_cross_coupling(void **state) {
  (void)state;
  hidden("bearing.B2.kcross", 2e7, RCB_EFFECT_BEARING_CROSS_COUPLING, "bearing B2");
}

static void test_hidden_bearing_damping(void **state) {
  (void)state;
  hidden("bearing.B2.cxx", 2e4, RCB_EFFECT_BEARING_DAMPING, "bearing B2");
}

static void test_hidden_anisotropy(void **state) {
  (void)state;
  hidden("bearing.B1.kyy", 1.2e7, RCB_EFFECT_BEARING_STIFFNESS, "bearing B1");
}

static void test_hidden_hub(void **state) {
  (void)state;
  hidden("coupling.C.hub_mass", 0.07, RCB_EFFECT_COUPLING_HUB, "coupling C");
}

static void test_hidden_shaft_damping(void **state) {
  (void)state;
  hidden("shaft.B.damping_stiffness", 1e-4, RCB_EFFECT_SHAFT_DAMPING, "shaft B");
}

static void test_hidden_disk_mass(void **state) {
  (void)state;
  hidden("disk.DB.mass", 1.3, RCB_EFFECT_ADDED_MASS, "disk DB");
}

static void test_hidden_coupling_rotational_damping(void **state) {
  (void)state;
  hidden("coupling.C.cr", 0.02, RCB_EFFECT_COUPLING_ROTATIONAL_DAMPING, "coupling C");
}

/* A pedestal under bearing B2 (its mode in the band). Pedestals elsewhere
 * are the ROSS-made cases of tests/python/test_diag_ross.py (B4, moderate and
 * large): a second one here (B3) was 50 s of CPU on data of our own code. */
static void test_hidden_pedestal(void **state) {
  (void)state;
  hidden_in(rcb_test_model_edited("paper_system.ini", "[bearing B2]",
                                  "pedestal_mass = 10\npedestal_kxx = 3e7\npedestal_kyy = 3e7\n"
                                  "pedestal_cxx = 500\npedestal_cyy = 500"),
            "pedestal under B2 (10 kg on 3e7 N/m)", RCB_EFFECT_FLEXIBLE_SUPPORT, "bearing B2");
}

/* The rotor turns 20 % faster than the measurement says. */
static void test_hidden_speed(void **state) {
  (void)state;
  hidden("speed.factor", 1.2, RCB_EFFECT_SPEED, "operating speed");
}

/* A local loss of bending stiffness (issue #23): one element of shaft B at
 * 0.6 of its E and G (a crack, wear, a loose fit). The element stiffness
 * candidate ranks first, at that element or a neighbour (one element is
 * 0.05 m: the data place it to about that), is significant and brings the
 * error to the noise floor. */
static void test_hidden_element_stiffness(void **state) {
  static const int ks[2] = {5, 8};
  size_t i;
  (void)state;
  for (i = 0; i < 2; i++) {
    rcb_model *truth = rcb_test_model_from_example("paper_system.ini");
    rcb_diag_candidate best;
    rcb_diag *d;
    double err0, floor0;
    char name[64], near[3][64];
    int j;
    snprintf(name, sizeof name, "shaft.B.e%d.stiffness", ks[i]);
    assert_int_equal(rcb_model_set_param(truth, name, 0.6), RCB_OK);
    for (j = 0; j < 3; j++) snprintf(near[j], sizeof near[j], "shaft B element %d ", ks[i] - 1 + j);
    diagnose(truth, 1, &best, &err0, &floor0, &d);
    print_message("  hidden %s = 0.6: first '%s', predicted %.1f %%, error %.3g -> %.3g %% "
                  "(floor %.3g), BIC %+.1f, %s\n",
                  name, best.place, best.predicted_pct, err0, best.error_pct, floor0,
                  best.delta_bic, best.fitted);
    assert_int_equal(best.effect, RCB_EFFECT_ELEMENT_STIFFNESS);
    /* at its own element since its neighbours are refitted where the
     * placement points (neighbours.c): before, element 8 was found as
     * element 7 at 0.78 (5.84 %, floor 5.77 %) */
    assert_non_null(strstr(best.place, near[1]));
    assert_null(strstr(best.place, near[0]));
    assert_true(best.significant);
    apply_reaches_floor(d, floor0);
    rcb_diag_destroy(d);
    rcb_model_destroy(truth);
  }
}

/* Run a diagnosis of ms on nthreads threads (paper model, coupling kt, kr,
 * ct fitted), with the eq. 19 noise model beta_a, beta_s (%). */
static rcb_diag *run_diag(const rcb_model *m, const rcb_meas *ms, size_t nthreads,
                          double beta_a, double beta_s) {
  rcb_diag *d = NULL;
  assert_int_equal(rcb_diag_create(&d, m, ms, NULL), RCB_OK);
  assert_int_equal(rcb_diag_set_noise_model(d, beta_a, beta_s), RCB_OK);
  assert_int_equal(rcb_diag_set_threads(d, nthreads), RCB_OK);
  assert_int_equal(rcb_diag_add_fitted_param(d, "coupling.C.kt", 46.095, 46.095e6, 1), 0);
  assert_int_equal(rcb_diag_add_fitted_param(d, "coupling.C.kr", 0.22076, 220760, 1), 0);
  assert_int_equal(rcb_diag_add_fitted_param(d, "coupling.C.ct", 0.010949, 10949, 1), 0);
  if (rcb_diag_run(d)) fail_msg("%s", rcb_diag_errmsg(d));
  return d;
}

/* The same with the noise of the data (eq. 19, 10 %, 1 %). */
static rcb_diag *run_on_threads(const rcb_model *m, const rcb_meas *ms, size_t nthreads) {
  return run_diag(m, ms, nthreads, 10.0, 1.0);
}

static void same_double(double a, double b, const char *what, size_t rank) {
  if (memcmp(&a, &b, sizeof a) != 0)
    fail_msg("rank %zu: %s %.17g (1 thread) vs %.17g (threads)", rank + 1, what, a, b);
}

/* d1 and d3 gave the same numbers bit for bit: every candidate's rank,
 * score, refitted error, objective drop, BIC, fitted values and whether it
 * was polished, the work counters and the explanation; returns the
 * explanation of d1 in t1. */
static void same_diagnosis(const rcb_diag *d1, const rcb_diag *d3, char *t1, size_t size) {
  rcb_diag_stats s1, s3;
  char *t3 = malloc(size);
  size_t k, n = rcb_diag_candidate_count(d1);
  assert_int_equal(rcb_diag_candidate_count(d3), n);
  for (k = 0; k < n; k++) {
    rcb_diag_candidate c1, c3;
    assert_int_equal(rcb_diag_candidate_get(d1, k, &c1), RCB_OK);
    assert_int_equal(rcb_diag_candidate_get(d3, k, &c3), RCB_OK);
    assert_string_equal(c1.description, c3.description);
    assert_int_equal(c1.refitted, c3.refitted);
    assert_int_equal(c1.significant, c3.significant);
    assert_int_equal(c1.screened_only, c3.screened_only);
    same_double(c1.predicted_pct, c3.predicted_pct, "score", k);
    same_double(c1.error_pct, c3.error_pct, "error", k);
    same_double(c1.objective_drop_pct, c3.objective_drop_pct, "objective drop", k);
    same_double(c1.delta_bic, c3.delta_bic, "BIC", k);
    assert_string_equal(c1.fitted, c3.fitted);
  }
  assert_int_equal(rcb_diag_get_stats(d1, &s1), RCB_OK);
  assert_int_equal(rcb_diag_get_stats(d3, &s3), RCB_OK);
  assert_int_equal(s1.evaluations, s3.evaluations);
  assert_int_equal(s1.refits, s3.refits);
  assert_int_equal(s1.restarts, s3.restarts);
  assert_int_equal(rcb_diag_explain(d1, t1, size, NULL), RCB_OK);
  assert_int_equal(rcb_diag_explain(d3, t3, size, NULL), RCB_OK);
  assert_string_equal(t1, t3);
  free(t3);
}

/* Threads across candidates (rcb_diag_set_threads) give the results of one
 * thread bit for bit: every candidate's rank, scores, refitted error,
 * objective drop, BIC and fitted values, the work counters, the
 * explanation and the applied model's parameters. The case is the hidden
 * hub (0.07 kg), whose baseline fit runs off, so the pre-fits at the
 * nominal model run on the threads too; 3 threads on 2 cores also
 * exercises a thread taking jobs while another is descheduled. */
static void test_threads_identical(void **state) {
  rcb_model *truth = rcb_test_model_from_example("paper_system.ini");
  rcb_model *m = rcb_test_model_from_example("paper_system.ini");
  rcb_model *a1 = NULL, *a3 = NULL;
  rcb_meas *ms;
  rcb_diag *d1, *d3;
  char t1[4096];
  (void)state;
  assert_int_equal(rcb_model_set_param(truth, "coupling.C.hub_mass", 0.07), RCB_OK);
  ms = measure(truth, 1);
  d1 = run_on_threads(m, ms, 1);
  d3 = run_on_threads(m, ms, 3);
  same_diagnosis(d1, d3, t1, sizeof t1);
  assert_non_null(strstr(t1, "ran far from the nominal model")); /* the pre-fits ran */
  {
    rcb_diag_candidate c;
    assert_int_equal(rcb_diag_candidate_get(d1, 0, &c), RCB_OK);
    assert_int_equal(c.effect, RCB_EFFECT_COUPLING_HUB);
  }
  assert_int_equal(rcb_diag_apply_model(d1, 0, NULL, &a1), RCB_OK);
  assert_int_equal(rcb_diag_apply_model(d3, 0, NULL, &a3), RCB_OK);
  {
    double v1, v3;
    assert_int_equal(rcb_model_get_param(a1, "coupling.C.hub_mass", &v1), RCB_OK);
    assert_int_equal(rcb_model_get_param(a3, "coupling.C.hub_mass", &v3), RCB_OK);
    same_double(v1, v3, "applied hub mass", 0);
    assert_int_equal(rcb_model_get_param(a1, "coupling.C.kt", &v1), RCB_OK);
    assert_int_equal(rcb_model_get_param(a3, "coupling.C.kt", &v3), RCB_OK);
    same_double(v1, v3, "applied kt", 0);
  }
  assert_int_equal(rcb_diag_set_threads(d1, 0), RCB_ERR_ARG);
  assert_int_equal(rcb_diag_set_threads(d1, RCB_DIAG_MAX_THREADS + 1), RCB_ERR_ARG);
  rcb_model_destroy(a1);
  rcb_model_destroy(a3);
  rcb_diag_destroy(d1);
  rcb_diag_destroy(d3);
  rcb_meas_destroy(ms);
  rcb_model_destroy(m);
  rcb_model_destroy(truth);
}

/* The objective of candidate c on all points (F0 and its objective drop). */
static double candidate_F(const rcb_diag *d, const rcb_diag_candidate *c) {
  double F0;
  assert_int_equal(rcb_diag_baseline(d, NULL, &F0, NULL), RCB_OK);
  return F0 * (1.0 - c->objective_drop_pct / 100.0);
}

/* The polish the diagnosis left out: candidate rank's applied model fitted
 * on all points, with the coupling's kt, kr, ct and the candidate's own
 * parameters (bounds 1000 x either side of where its screen ended, or
 * 0-1e6 from 0, wider than the diagnosis' own), to the fit's own limits;
 * its objective. */
static double polished_F(const rcb_diag *d, const rcb_meas *ms, size_t rank) {
  static const char *const base[3] = {"coupling.C.kt", "coupling.C.kr", "coupling.C.ct"};
  static const double lo[3] = {46.095, 0.22076, 0.010949}, hi[3] = {46.095e6, 220760, 10949};
  rcb_diag_candidate c;
  rcb_model *m = NULL;
  rcb_fit *f = NULL;
  rcb_fit_report rep;
  char names[512], *name;
  size_t k, nall = rcb_meas_channel_count(ms) * rcb_meas_point_count(ms);
  rcb_complex *ref;
  assert_int_equal(rcb_diag_candidate_get(d, rank, &c), RCB_OK);
  assert_int_equal(rcb_diag_apply_model(d, rank, NULL, &m), RCB_OK);
  assert_int_equal(rcb_fit_create(&f, m, ms, NULL), RCB_OK);
  assert_int_equal(rcb_fit_set_scale(f, RCB_SCALE_LOG10), RCB_OK);
  assert_int_equal(rcb_fit_set_noise_model(f, 10.0, 1.0), RCB_OK);
  assert_int_equal(rcb_fit_set_uncertainty(f, 0), RCB_OK);
  /* weighed as the diagnosis weighs (its noise reference): the same F */
  ref = calloc(nall, sizeof *ref);
  assert_int_equal(rcb_diag_get_noise_reference(d, ref, nall), 1);
  assert_int_equal(rcb_fit_set_noise_reference(f, ref), RCB_OK);
  free(ref);
  for (k = 0; k < 3; k++) assert_int_equal(rcb_fit_add_param(f, base[k], lo[k], hi[k], 1), 0);
  snprintf(names, sizeof names, "%s", c.params);
  for (name = strtok(names, ", "); name; name = strtok(NULL, ", ")) {
    double v;
    assert_int_equal(rcb_model_get_param(m, name, &v), RCB_OK);
    assert_true(v >= 0); /* masses, stiffnesses, dampings, the speed factor */
    if (v > 0)
      assert_int_equal(rcb_fit_add_param(f, name, v / 1000, v * 1000, 1), RCB_OK);
    else /* a damping the screen left at 0 */
      assert_int_equal(rcb_fit_add_param(f, name, 0.0, 1e6, 0), RCB_OK);
  }
  if (rcb_fit_run(f)) fail_msg("%s: %s", c.description, rcb_fit_errmsg(f));
  assert_int_equal(rcb_fit_get_report(f, &rep), RCB_OK);
  rcb_fit_destroy(f);
  rcb_model_destroy(m);
  return rep.objective;
}

/* A set large enough for the screen on a frequency subset (8 inertances x
 * 551 points 50-600 Hz; the subset keeps 150), kcross = 2e7 N/m hidden at
 * B2. Every refit is screened on the subset and evaluated on all points
 * where its screen ended; only those within 10 % of the lowest are polished
 * there. The first is polished, named and significant; each candidate left
 * screened only, fitted on all points from its applied model (the polish
 * left out, with wider bounds and the fit's own limits), ends above the
 * first: polishing it would not change the ranking, and its reported
 * figures were upper bounds. No refit tried its random starts: a screen
 * reached the noise floor. With a noise model 10 x below the data's none
 * does: the random starts run, with the same numbers on 2 threads. */
static void test_large_screen(void **state) {
  rcb_model *truth = rcb_test_model_from_example("paper_system.ini");
  rcb_model *m = rcb_test_model_from_example("paper_system.ini");
  rcb_meas *ms;
  rcb_diag *d, *d2;
  rcb_diag_candidate first;
  rcb_diag_stats st;
  char text[4096];
  size_t k, checked = 0;
  double F1;
  (void)state;
  assert_int_equal(rcb_model_set_param(truth, "bearing.B2.kcross", 2e7), RCB_OK);
  ms = measure_grid(truth, 1, 551, 50.0, 600.0);
  d = run_on_threads(m, ms, 1);
  assert_int_equal(rcb_diag_candidate_get(d, 0, &first), RCB_OK);
  assert_int_equal(first.effect, RCB_EFFECT_BEARING_CROSS_COUPLING);
  assert_non_null(strstr(first.place, "bearing B2"));
  assert_true(first.significant);
  assert_int_equal(first.screened_only, 0);
  F1 = candidate_F(d, &first);
  for (k = 1; k < rcb_diag_candidate_count(d) && checked < 3; k++) {
    rcb_diag_candidate c;
    double F, Fp;
    assert_int_equal(rcb_diag_candidate_get(d, k, &c), RCB_OK);
    /* a fault of the measurement chain has no model to apply (the two
     * probes of a station swapped) */
    if (!c.refitted || !c.screened_only ||
        (c.effect >= RCB_EFFECT_SENSOR_GAIN && c.effect <= RCB_EFFECT_SENSOR_SWAP))
      continue;
    F = candidate_F(d, &c);
    Fp = polished_F(d, ms, k);
    print_message("  screened only: %s: F %.6g, polished %.6g (the first %.6g)\n",
                  c.description, F, Fp, F1);
    assert_true(Fp <= F * (1 + 1e-9));
    assert_true(Fp > F1);
    checked++;
  }
  assert_true(checked > 0);
  assert_int_equal(rcb_diag_get_stats(d, &st), RCB_OK);
  assert_int_equal(st.restarts, 0);
  rcb_diag_destroy(d);
  d = run_diag(m, ms, 1, 1.0, 0.1);
  d2 = run_diag(m, ms, 2, 1.0, 0.1);
  assert_int_equal(rcb_diag_get_stats(d, &st), RCB_OK);
  print_message("  noise model 1 %%, 0.1 %%: %zu refits, %zu tried their random starts\n",
                st.refits, st.restarts);
  assert_true(st.restarts > 0);
  same_diagnosis(d, d2, text, sizeof text);
  rcb_diag_destroy(d);
  rcb_diag_destroy(d2);
  rcb_meas_destroy(ms);
  rcb_model_destroy(m);
  rcb_model_destroy(truth);
}

/* Nothing hidden: no candidate is significant. */
/* The measurement chain (issue #23, item 4): the DA.x probe reads 20 % low.
 * The sensor's gain ranks first, significant, within 3 standard errors of
 * 0.8 (the standard error of the same joint fit with its uncertainty: the
 * diagnosis' refits skip that step); the fault is the chain's, so there is
 * no model to apply. DA.x, the driving point, carries most of the paper's
 * linear error %: with DB.y 20 % low instead the gain at DB.y also ranks
 * first (BIC -1663, gain 0.797) but is not significant, as the error %,
 * 5.39 before (floor 5.77), does not fall (5.44 %): the significance rule
 * asks both. On 601 points the refits are screened on a subset of 150 and
 * evaluated, polished on all points after: the gain must survive those
 * steps (it lives in the fit's chain, not in the candidate's model). */
static void sensor_gain_case(size_t npts) {
  rcb_model *truth = rcb_test_model_from_example("paper_system.ini");
  rcb_model *m = rcb_test_model_from_example("paper_system.ini");
  rcb_meas *ms = measure_probe(truth, 1, npts, 100.0, 400.0, "DA.x", 0.8);
  const char *names[] = {"coupling.C.kt", "coupling.C.kr", "coupling.C.ct"};
  const double lo[] = {46.095, 0.22076, 0.010949}, hi[] = {46.095e6, 220760, 10949};
  rcb_diag_candidate best, c;
  rcb_diag *d = NULL;
  rcb_fit *f = NULL;
  rcb_fit_param p;
  rcb_model *applied = NULL;
  const char *at;
  double g, err0, floor0;
  size_t k;
  assert_int_equal(rcb_diag_create(&d, m, ms, NULL), RCB_OK);
  assert_int_equal(rcb_diag_set_noise_model(d, 10.0, 1.0), RCB_OK);
  for (k = 0; k < 3; k++)
    assert_int_equal(rcb_diag_add_fitted_param(d, names[k], lo[k], hi[k], 1), RCB_OK);
  if (rcb_diag_run(d)) fail_msg("%s", rcb_diag_errmsg(d));
  assert_int_equal(rcb_diag_candidate_get(d, 0, &best), RCB_OK);
  assert_int_equal(rcb_diag_baseline(d, &err0, NULL, &floor0), RCB_OK);
  print_message("  %zu points, DA.x reading 0.8: first '%s' (%s), BIC %+.1f, error %.3g -> "
                "%.3g %% (floor %.3g), %s%s\n",
                npts, best.description, best.place, best.delta_bic, err0, best.error_pct,
                floor0, best.fitted, best.screened_only ? " (screened only)" : "");
  assert_int_equal(best.effect, RCB_EFFECT_SENSOR_GAIN);
  assert_non_null(strstr(best.place, "DA.x"));
  assert_true(best.significant);
  assert_non_null(at = strstr(best.fitted, "sensor.DA.x.gain = "));
  g = strtod(at + strlen("sensor.DA.x.gain = "), NULL);
  /* the same joint fit, with its standard errors */
  assert_int_equal(rcb_fit_create(&f, m, ms, NULL), RCB_OK);
  assert_int_equal(rcb_fit_set_scale(f, RCB_SCALE_LOG10), RCB_OK);
  assert_int_equal(rcb_fit_set_noise_model(f, 10.0, 1.0), RCB_OK);
  for (k = 0; k < 3; k++) assert_int_equal(rcb_fit_add_param(f, names[k], lo[k], hi[k], 1), 0);
  assert_int_equal(rcb_fit_add_param(f, "sensor.DA.x.gain", 0.1, 10.0, 1), RCB_OK);
  assert_int_equal(rcb_fit_run(f), RCB_OK);
  assert_int_equal(rcb_fit_get_param(f, 3, &p), RCB_OK);
  print_message("  diagnosis gain %.5g, joint fit %.5g +/- %.3g\n", g, p.value, p.stderr_);
  if (!(fabs(g - 0.8) <= 3 * p.stderr_) || !(fabs(p.value - 0.8) <= 3 * p.stderr_))
    fail_msg("gain %g (joint fit %g), se %g: not within 3 se of 0.8", g, p.value, p.stderr_);
  /* the second candidate is no other sensor's gain: the fault is located */
  assert_int_equal(rcb_diag_candidate_get(d, 1, &c), RCB_OK);
  assert_false(c.significant && c.effect == RCB_EFFECT_SENSOR_GAIN);
  assert_int_equal(rcb_diag_apply_model(d, 0, NULL, &applied), RCB_ERR_STATE);
  assert_null(applied);
  rcb_fit_destroy(f);
  rcb_diag_destroy(d);
  rcb_meas_destroy(ms);
  rcb_model_destroy(m);
  rcb_model_destroy(truth);
}

static void test_hidden_sensor_gain(void **state) {
  (void)state;
  sensor_gain_case(151);
  sensor_gain_case(601); /* refits screened on a subset */
}

static void test_null(void **state) {
  rcb_model *truth = rcb_test_model_from_example("paper_system.ini");
  rcb_diag_candidate best;
  rcb_diag *d;
  double err0, floor0;
  size_t k, nsensor = 0;
  (void)state;
  diagnose(truth, 3, &best, &err0, &floor0, &d);
  print_message("  null: first '%s', BIC %+.1f, error %.3g %% (floor %.3g)\n",
                best.description, best.delta_bic, err0, floor0);
  assert_false(best.significant);
  assert_true(err0 < 1.1 * floor0);
  {
    rcb_fit_adequacy a;
    assert_int_equal(rcb_diag_adequacy(d, &a), RCB_OK);
    assert_true(a.known && a.adequate); /* nothing is missing, and the test says so */
  }
  for (k = 0; k < rcb_diag_candidate_count(d); k++) { /* no sensor found at fault */
    rcb_diag_candidate c;
    assert_int_equal(rcb_diag_candidate_get(d, k, &c), RCB_OK);
    if (c.effect < RCB_EFFECT_SENSOR_GAIN || c.effect > RCB_EFFECT_SENSOR_SWAP) continue;
    nsensor++;
    if (c.significant) fail_msg("null: '%s' significant (BIC %+.1f)", c.description, c.delta_bic);
  }
  assert_int_equal(nsensor, 8 + 4); /* a gain per probe, a swap per station (log10 scale) */
  { /* the shaft elements' candidates (issue #23) among them: none significant */
    size_t nel = 0;
    for (k = 0; k < rcb_diag_candidate_count(d); k++) {
      rcb_diag_candidate c;
      assert_int_equal(rcb_diag_candidate_get(d, k, &c), RCB_OK);
      if (c.effect != RCB_EFFECT_ELEMENT_STIFFNESS && c.effect != RCB_EFFECT_ELEMENT_MASS)
        continue;
      nel++;
      if (c.significant) fail_msg("null: %s is significant (BIC %+.1f)", c.description, c.delta_bic);
    }
    assert_int_equal(nel, 2 * 20); /* stiffness and mass of each of the 20 elements */
  }
  rcb_diag_destroy(d);
  rcb_model_destroy(truth);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_hidden_cross_coupling),
      cmocka_unit_test(test_hidden_bearing_damping),
      cmocka_unit_test(test_hidden_anisotropy),
      cmocka_unit_test(test_hidden_hub),
      cmocka_unit_test(test_hidden_shaft_damping),
      cmocka_unit_test(test_hidden_disk_mass),
      cmocka_unit_test(test_hidden_coupling_rotational_damping),
      cmocka_unit_test(test_hidden_pedestal),
      cmocka_unit_test(test_hidden_speed),
      cmocka_unit_test(test_hidden_sensor_gain),
      cmocka_unit_test(test_hidden_element_stiffness),
      cmocka_unit_test(test_null),
      cmocka_unit_test(test_threads_identical),
      cmocka_unit_test(test_large_screen),
  };
  if (getenv("RCB_DIAG_ONLY")) cmocka_set_test_filter(getenv("RCB_DIAG_ONLY"));
  return cmocka_run_group_tests(tests, NULL, NULL);
}
