/*
 * The model edit API (issue #14): rcb_model_clone and the structural edits
 * of an unfinalized copy. Each edit made on a clone must give the matrices
 * (M, C, G, K through the public rcb_model_matrices) of the same model
 * written by hand as INI and loaded, to round-off; the same after the edited
 * clone is written by rcb_model_write_ini and read back; and the original
 * must be left bitwise as it was. Also the refusals (an edit of a finalized
 * model, an unknown item) and an allocation-failure walk over clone + edits.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "rcb/rcb.h"
#include "rcb_test_util.h"

#define SPEED 400.0 /* rad/s: inside the speed table of bearing B2 */

/* Two shafts joined by a nelson_crandall_1 coupling with hubs, a constant
 * and a tabulated bearing, a disk, an unbalance and a probe. The pieces are
 * put together with the edits written as INI by hand. */
static const char HEAD[] =
    "[material steel]\ndensity = 7800\nyoung = 2e11\npoisson = 0.3\n"
    "[shaft A]\nmaterial = steel\nshear_factor = 0.9\nsegment = 0.3 0.02 0 3\n"
    "segment = 0.2 0.03 0.01 2\n"
    "[shaft B]\nmaterial = steel\nshear_factor = 0.9\nstart = 0.6\n"
    "damping_stiffness = 1e-5\nsegment = 0.5 0.02 0.0 5\n"
    "[disk D]\nat = A 0.2\nmass = 1.5\nId = 2e-3\nIp = 4e-3\n"
    "[unbalance U]\nat = D\namount = 1e-4\nphase_deg = 30\n"
    "[station P]\nat = B 0.8\n"
    "[bearing B1]\nat = A 0.1\nkxx = 1e7\nkyy = 2e7\ncxx = 100\ncyy = 100\n";
static const char B2_TABLE[] =
    "[bearing B2]\nat = B 1.0\nspeed_rpm = 0 3000 6000\nkxx = 1e7 2e7 3e7\nkyy = 1e7\n";
static const char COUPLING_NC1[] =
    "[coupling C]\nmodel = nelson_crandall_1\nbetween = A end, B start\nkt = 1e5\n"
    "kr = 1e3\nhub_mass = 0.1\nhub_Id = 1e-4\nhub_Ip = 2e-4\n";

static char *text(const char *b1_extra, const char *b2, const char *coupling,
                  const char *extra) {
  size_t n = strlen(HEAD) + strlen(b1_extra) + strlen(b2) + strlen(coupling) + strlen(extra) + 1;
  char *t = malloc(n);
  assert_non_null(t);
  snprintf(t, n, "%s%s%s%s%s", HEAD, b1_extra, b2, coupling, extra);
  return t;
}

static rcb_model *load(const char *b1_extra, const char *b2, const char *coupling,
                       const char *extra) {
  char *t = text(b1_extra, b2, coupling, extra);
  rcb_model *m = rcb_test_model_from_string(t);
  free(t);
  return m;
}

static rcb_model *base(void) { return load("", B2_TABLE, COUPLING_NC1, ""); }

typedef struct mats {
  size_t n;
  double *a; /* M, C, G, K one after the other, n x n each */
} mats;

static mats matrices(const rcb_model *m) {
  mats x;
  size_t nn;
  x.n = rcb_model_dof_count(m);
  assert_true(x.n > 0);
  nn = x.n * x.n;
  x.a = calloc(4 * nn, sizeof *x.a);
  assert_non_null(x.a);
  assert_int_equal(rcb_model_matrices(m, SPEED, x.a, x.a + nn, x.a + 2 * nn, x.a + 3 * nn),
                   RCB_OK);
  return x;
}

/* Equal to round-off: each matrix within 1e-13 of its largest entry. */
static void assert_same(const char *what, const rcb_model *a, const rcb_model *b) {
  mats x = matrices(a), y = matrices(b);
  size_t nn = x.n * x.n, k, i;
  static const char *const nm[4] = {"M", "C", "G", "K"};
  assert_int_equal(x.n, y.n);
  for (k = 0; k < 4; k++) {
    double big = 0, diff = 0;
    for (i = 0; i < nn; i++) {
      big = fmax(big, fabs(x.a[k * nn + i]));
      diff = fmax(diff, fabs(x.a[k * nn + i] - y.a[k * nn + i]));
    }
    if (!(diff <= 1e-13 * big))
      fail_msg("%s: %s differs by %g (largest entry %g)", what, nm[k], diff, big);
  }
  free(x.a);
  free(y.a);
}

/* The edited clone, written as INI and read back, is the same model. */
static void assert_round_trip(const char *what, const rcb_model *m) {
  size_t need = 0;
  char *t;
  rcb_model *r;
  assert_int_equal(rcb_model_write_ini(m, NULL, 0, &need), RCB_ERR_WORKSPACE);
  t = malloc(need);
  assert_non_null(t);
  assert_int_equal(rcb_model_write_ini(m, t, need, &need), RCB_OK);
  r = rcb_test_model_from_string(t);
  assert_same(what, m, r);
  rcb_model_destroy(r);
  free(t);
}

/* A clone of the base (its own counting allocator), finalized after
 * edit(). The original's matrices must stay bitwise the same. */
typedef void (*edit_fn)(rcb_model *c);

static rcb_model *edited(rcb_model *orig, edit_fn edit, rcb_test_counter *cnt) {
  rcb_allocator a = rcb_test_counting_allocator(cnt);
  mats before = matrices(orig), after;
  rcb_model *c = NULL;
  assert_int_equal(rcb_model_clone(&c, orig, &a), RCB_OK);
  assert_int_equal(rcb_model_dof_count(c), 0); /* not finalized */
  if (edit) edit(c);
  if (rcb_model_finalize(c)) fail_msg("finalize: %s", rcb_model_errmsg(c));
  after = matrices(orig);
  assert_int_equal(before.n, after.n);
  assert_memory_equal(before.a, after.a, 4 * before.n * before.n * sizeof *before.a);
  free(before.a);
  free(after.a);
  return c;
}

static void check_edit(const char *what, edit_fn edit, void (*params)(rcb_model *c),
                       const rcb_model *ref) {
  rcb_test_counter cnt = {0, 0};
  rcb_model *orig = base();
  rcb_model *c = edited(orig, edit, &cnt);
  if (params) params(c);
  assert_same(what, c, ref);
  assert_round_trip(what, c);
  rcb_model_destroy(c);
  assert_true(cnt.allocs > 0);
  assert_int_equal(cnt.allocs, cnt.frees); /* the clone used its own allocator */
  rcb_model_destroy(orig);
}

static void set(rcb_model *m, const char *name, double v) {
  if (rcb_model_set_param(m, name, v)) fail_msg("%s: %s", name, rcb_model_errmsg(m));
}

/* ---- the edits ---- */

static void test_clone_unedited(void **state) {
  rcb_model *orig = base(), *c;
  rcb_test_counter cnt = {0, 0};
  mats x, y;
  (void)state;
  c = edited(orig, NULL, &cnt);
  x = matrices(orig);
  y = matrices(c);
  assert_int_equal(rcb_model_node_count(c), rcb_model_node_count(orig));
  assert_int_equal(rcb_model_station_count(c), rcb_model_station_count(orig));
  assert_int_equal(rcb_model_param_count(c), rcb_model_param_count(orig));
  assert_int_equal(x.n, y.n); /* same assembly: bitwise the same */
  assert_memory_equal(x.a, y.a, 4 * x.n * x.n * sizeof *x.a);
  /* the test speed ([test] rpm) is part of the model: it travels with the copy */
  {
    double w = 0.0, w0 = 2.0 * 3.141592653589793 * 10000.0 / 60.0; /* 10000 rpm, rad/s */
    rcb_model *c2 = NULL;
    assert_int_equal(rcb_model_get_test_speed(c, &w), RCB_ERR_NOT_FOUND);
    assert_int_equal(rcb_model_set_test_speed(orig, w0), RCB_OK);
    assert_int_equal(rcb_model_clone(&c2, orig, NULL), RCB_OK);
    assert_int_equal(rcb_model_get_test_speed(c2, &w), RCB_OK);
    assert_true(w == w0);
    rcb_model_destroy(c2);
  }
  /* a value changed on the clone only */
  set(c, "coupling.C.kt", 7e5);
  {
    double v;
    assert_int_equal(rcb_model_get_param(orig, "coupling.C.kt", &v), RCB_OK);
    assert_true(v == 1e5);
  }
  free(x.a);
  free(y.a);
  rcb_model_destroy(c);
  rcb_model_destroy(orig);
}

static void to_nc2(rcb_model *c) {
  assert_int_equal(rcb_model_set_coupling_model(c, "C", RCB_COUPLING_NELSON_CRANDALL_2), RCB_OK);
}
static void nc2_values(rcb_model *c) {
  set(c, "coupling.C.ct", 50.0);
  set(c, "coupling.C.cr", 2.0);
}
static void to_k2(rcb_model *c) {
  assert_int_equal(rcb_model_set_coupling_model(c, "C", RCB_COUPLING_KRAMER_2), RCB_OK);
}
static void k2_values(rcb_model *c) {
  double v;
  assert_int_equal(rcb_model_get_param(c, "coupling.C.kt", &v), RCB_ERR_NOT_FOUND);
  set(c, "coupling.C.cr", 2.0);
}
static void to_rigid(rcb_model *c) {
  assert_int_equal(rcb_model_set_coupling_model(c, "C", RCB_COUPLING_RIGID), RCB_OK);
}

static void test_coupling_model(void **state) {
  rcb_model *ref;
  (void)state;
  ref = load("", B2_TABLE,
             "[coupling C]\nmodel = nelson_crandall_2\nbetween = A end, B start\nkt = 1e5\n"
             "kr = 1e3\nct = 50\ncr = 2\nhub_mass = 0.1\nhub_Id = 1e-4\nhub_Ip = 2e-4\n",
             "");
  check_edit("nelson_crandall_2", to_nc2, nc2_values, ref);
  rcb_model_destroy(ref);
  ref = load("", B2_TABLE,
             "[coupling C]\nmodel = kramer_2\nbetween = A end, B start\nkr = 1e3\ncr = 2\n"
             "hub_mass = 0.1\nhub_Id = 1e-4\nhub_Ip = 2e-4\n",
             "");
  check_edit("kramer_2", to_k2, k2_values, ref);
  rcb_model_destroy(ref);
  ref = load("", B2_TABLE,
             "[coupling C]\nmodel = rigid\nbetween = A end, B start\n"
             "hub_mass = 0.1\nhub_Id = 1e-4\nhub_Ip = 2e-4\n",
             "");
  check_edit("rigid", to_rigid, NULL, ref);
  rcb_model_destroy(ref);
}

static void add_pedestal(rcb_model *c) {
  const rcb_pedestal p = {12.0, 3e7, 4e7, 500.0, 600.0};
  assert_int_equal(rcb_model_set_pedestal(c, "B1", &p), RCB_OK);
}

static void test_pedestal(void **state) {
  rcb_model *ref = load("pedestal_mass = 12\npedestal_kxx = 3e7\npedestal_kyy = 4e7\n"
                        "pedestal_cxx = 500\npedestal_cyy = 600\n",
                        B2_TABLE, COUPLING_NC1, "");
  (void)state;
  check_edit("pedestal", add_pedestal, NULL, ref);
  rcb_model_destroy(ref);
}

static void add_disks(rcb_model *c) {
  assert_int_equal(rcb_model_add_disk_at(c, "X1", "#3", 2.0, 0.01, 0.02), RCB_OK); /* A 0.3 */
  assert_int_equal(rcb_model_add_disk_at(c, "X2", "P", 0.5, 0, 0), RCB_OK); /* point mass */
  assert_int_equal(rcb_model_add_disk_at(c, "X3", "C.B", 0.7, 1e-3, 2e-3), RCB_OK);
  assert_int_equal(rcb_model_add_disk_at(c, "X4", "#11", 0.3, 0, 0), RCB_OK); /* B 1.1 */
}

static void test_add_disk(void **state) {
  rcb_model *ref = load("", B2_TABLE, COUPLING_NC1,
                        "[disk X1]\nat = A 0.3\nmass = 2\nId = 0.01\nIp = 0.02\n"
                        "[disk X2]\nat = B 0.8\nmass = 0.5\nId = 0\nIp = 0\n"
                        "[disk X3]\nat = B 0.6\nmass = 0.7\nId = 1e-3\nIp = 2e-3\n"
                        "[disk X4]\nat = B 1.1\nmass = 0.3\nId = 0\nIp = 0\n");
  (void)state;
  check_edit("added disks", add_disks, NULL, ref);
  rcb_model_destroy(ref);
}

static void bearing_constant(rcb_model *c) {
  /* the tabulated B2 made constant, with anisotropy, cross-coupling and damping */
  const rcb_bearing_coefs k = {1.5e7, 3e6, -3e6, 1e7, 200, 5, -5, 300};
  assert_int_equal(rcb_model_set_bearing_coefs(c, "B2", 1, NULL, &k), RCB_OK);
}
static void cross_param(rcb_model *c) { set(c, "bearing.B2.kcross", 4e6); }

static void bearing_table(rcb_model *c) {
  const double w[2] = {0.0, 2.0 * 3.14159265358979323846 * 100.0}; /* 0, 6000 rpm */
  const rcb_bearing_coefs k[2] = {{1e7, 1e6, -1e6, 1e7, 0, 0, 0, 0},
                                  {3e7, 2e6, -2e6, 2e7, 100, 0, 0, 100}};
  assert_int_equal(rcb_model_set_bearing_coefs(c, "B2", 2, w, k), RCB_OK);
}

static void test_bearing_coefs(void **state) {
  rcb_model *ref = load("",
                        "[bearing B2]\nat = B 1.0\nkxx = 1.5e7\nkxy = 4e6\nkyx = -4e6\n"
                        "kyy = 1e7\ncxx = 200\ncxy = 5\ncyx = -5\ncyy = 300\n",
                        COUPLING_NC1, "");
  (void)state;
  check_edit("constant bearing", bearing_constant, cross_param, ref);
  rcb_model_destroy(ref);
  ref = load("",
             "[bearing B2]\nat = B 1.0\nspeed_rpm = 0 6000\nkxx = 1e7 3e7\nkxy = 1e6 2e6\n"
             "kyx = -1e6 -2e6\nkyy = 1e7 2e7\ncxx = 0 100\ncyy = 0 100\n",
             COUPLING_NC1, "");
  check_edit("bearing table", bearing_table, NULL, ref);
  rcb_model_destroy(ref);
}

/* Every edit at once, on a clone of a clone. */
static void all_edits(rcb_model *c) {
  rcb_model *cc = NULL;
  to_nc2(c);
  add_pedestal(c);
  add_disks(c);
  bearing_constant(c);
  assert_int_equal(rcb_model_clone(&cc, c, NULL), RCB_OK); /* clone of an unfinalized model */
  rcb_model_destroy(cc);
}
static void all_values(rcb_model *c) {
  nc2_values(c);
  cross_param(c);
}

static void test_all_edits(void **state) {
  rcb_model *ref = load("pedestal_mass = 12\npedestal_kxx = 3e7\npedestal_kyy = 4e7\n"
                        "pedestal_cxx = 500\npedestal_cyy = 600\n",
                        "[bearing B2]\nat = B 1.0\nkxx = 1.5e7\nkxy = 4e6\nkyx = -4e6\n"
                        "kyy = 1e7\ncxx = 200\ncxy = 5\ncyx = -5\ncyy = 300\n",
                        "[coupling C]\nmodel = nelson_crandall_2\nbetween = A end, B start\n"
                        "kt = 1e5\nkr = 1e3\nct = 50\ncr = 2\nhub_mass = 0.1\nhub_Id = 1e-4\n"
                        "hub_Ip = 2e-4\n",
                        "[disk X1]\nat = A 0.3\nmass = 2\nId = 0.01\nIp = 0.02\n"
                        "[disk X2]\nat = B 0.8\nmass = 0.5\nId = 0\nIp = 0\n"
                        "[disk X3]\nat = B 0.6\nmass = 0.7\nId = 1e-3\nIp = 2e-3\n"
                        "[disk X4]\nat = B 1.1\nmass = 0.3\nId = 0\nIp = 0\n");
  (void)state;
  check_edit("all edits", all_edits, all_values, ref);
  rcb_model_destroy(ref);
}

/* Refusals: a finalized model is not edited (clone it), unknown items and
 * stations are named. */
static void test_refusals(void **state) {
  rcb_model *m = base(), *c = NULL;
  const rcb_bearing_coefs k = {1, 0, 0, 1, 0, 0, 0, 0};
  const rcb_bearing_coefs k2[2] = {{1, 0, 0, 1, 0, 0, 0, 0}, {1, 0, 0, 1, 0, 0, 0, 0}};
  const double bad_w[2] = {10.0, 5.0}; /* rad/s, not increasing */
  (void)state;
  assert_int_equal(rcb_model_set_coupling_model(m, "C", RCB_COUPLING_RIGID), RCB_ERR_STATE);
  assert_non_null(strstr(rcb_model_errmsg(m), "finalized"));
  assert_int_equal(rcb_model_add_disk_at(m, "X", "D", 1, 0, 0), RCB_ERR_STATE);
  assert_int_equal(rcb_model_set_bearing_coefs(m, "B1", 1, NULL, &k), RCB_ERR_STATE);
  assert_int_equal(rcb_model_clone(NULL, m, NULL), RCB_ERR_ARG);
  assert_int_equal(rcb_model_clone(&c, NULL, NULL), RCB_ERR_ARG);
  assert_null(c);
  assert_int_equal(rcb_model_clone(&c, m, NULL), RCB_OK);
  assert_int_equal(rcb_model_set_coupling_model(c, "Q", RCB_COUPLING_RIGID), RCB_ERR_NOT_FOUND);
  assert_non_null(strstr(rcb_model_errmsg(c), "'Q'"));
  assert_int_equal(rcb_model_set_coupling_model(c, "C", (rcb_coupling_model)9), RCB_ERR_ARG);
  assert_int_equal(rcb_model_add_disk_at(c, "X", "#12", 1, 0, 0), RCB_ERR_NOT_FOUND); /* 12 nodes */
  assert_non_null(strstr(rcb_model_errmsg(c), "#12"));
  assert_int_equal(rcb_model_add_disk_at(c, "X", "nowhere", 1, 0, 0), RCB_ERR_NOT_FOUND);
  assert_int_equal(rcb_model_add_disk_at(c, "X", "C.Z", 1, 0, 0), RCB_ERR_NOT_FOUND);
  assert_int_equal(rcb_model_add_disk_at(c, "D", "#0", 1, 0, 0), RCB_ERR_MODEL); /* name taken */
  assert_int_equal(rcb_model_add_disk_at(c, "X", "#0", -1, 0, 0), RCB_ERR_ARG);
  assert_int_equal(rcb_model_set_bearing_coefs(c, "B9", 1, NULL, &k), RCB_ERR_NOT_FOUND);
  assert_int_equal(rcb_model_set_bearing_coefs(c, "B2", 2, bad_w, k2), RCB_ERR_ARG);
  /* the failed edits left the clone as it was: it equals the original */
  assert_int_equal(rcb_model_finalize(c), RCB_OK);
  assert_same("after refused edits", c, m);
  rcb_model_destroy(c);
  rcb_model_destroy(m);
}

/* ---- allocation failures: the k-th allocation of clone + edits fails ---- */

/* Clone + every edit + finalize with allocator a: the status of the first
 * failing step (the clone destroyed), or RCB_OK and the model. */
static rcb_status clone_edit(const rcb_model *orig, const rcb_allocator *a, rcb_model **out) {
  const rcb_pedestal p = {12.0, 3e7, 4e7, 500.0, 600.0};
  const rcb_bearing_coefs k = {1.5e7, 3e6, -3e6, 1e7, 200, 5, -5, 300};
  rcb_model *c = NULL;
  rcb_status st = rcb_model_clone(&c, orig, a);
  *out = NULL;
  if (st) {
    assert_null(c);
    assert_int_equal(st, RCB_ERR_NOMEM);
    return st;
  }
  if (!st) st = rcb_model_set_coupling_model(c, "C", RCB_COUPLING_NELSON_CRANDALL_2);
  if (!st) st = rcb_model_set_pedestal(c, "B1", &p);
  if (!st) st = rcb_model_add_disk_at(c, "X1", "#3", 2.0, 0.01, 0.02);
  if (!st) st = rcb_model_add_disk_at(c, "X3", "C.B", 0.7, 1e-3, 2e-3);
  if (!st) st = rcb_model_set_bearing_coefs(c, "B2", 1, NULL, &k);
  if (!st) st = rcb_model_finalize(c);
  if (st) {
    assert_int_equal(st, RCB_ERR_NOMEM);
    assert_true(rcb_model_errmsg(c)[0] != '\0');
    rcb_model_destroy(c);
    return st;
  }
  *out = c;
  return RCB_OK;
}

static void test_alloc_failures(void **state) {
  rcb_model *orig = base(), *ok = NULL;
  mats before = matrices(orig), after;
  size_t k;
  rcb_test_failing f; /* outlives the loop: the model kept from the last run frees through it */
  (void)state;
  for (k = 1;; k++) {
    rcb_allocator a = rcb_test_failing_allocator(&f);
    rcb_model *c = NULL;
    rcb_status st;
    memset(&f, 0, sizeof f);
    f.fail_at = k;
    st = clone_edit(orig, &a, &c);
    if (f.hit && st == RCB_OK) fail_msg("allocation %zu failed but clone + edit succeeded", k);
    if (!f.hit) {
      assert_int_equal(st, RCB_OK);
      ok = c;
      rcb_model_set_param(ok, "coupling.C.ct", 50.0);
      rcb_model_set_param(ok, "coupling.C.cr", 2.0);
      break;
    }
    if (f.live != 0) fail_msg("allocation %zu failed: %zu blocks leaked", k, f.live);
    if (k > 10000) fail_msg("no end to the walk");
  }
  assert_true(k > 10); /* the walk went through the clone, the edits and finalize */
  print_message("clone + edits + finalize: %zu allocation sites walked\n", k - 1);
  {
    rcb_model *ref = load("pedestal_mass = 12\npedestal_kxx = 3e7\npedestal_kyy = 4e7\n"
                          "pedestal_cxx = 500\npedestal_cyy = 600\n",
                          "[bearing B2]\nat = B 1.0\nkxx = 1.5e7\nkxy = 3e6\nkyx = -3e6\n"
                          "kyy = 1e7\ncxx = 200\ncxy = 5\ncyx = -5\ncyy = 300\n",
                          "[coupling C]\nmodel = nelson_crandall_2\nbetween = A end, B start\n"
                          "kt = 1e5\nkr = 1e3\nct = 50\ncr = 2\nhub_mass = 0.1\n"
                          "hub_Id = 1e-4\nhub_Ip = 2e-4\n",
                          "[disk X1]\nat = A 0.3\nmass = 2\nId = 0.01\nIp = 0.02\n"
                          "[disk X3]\nat = B 0.6\nmass = 0.7\nId = 1e-3\nIp = 2e-3\n");
    assert_same("clone + edit after the walk", ok, ref);
    rcb_model_destroy(ref);
  }
  rcb_model_destroy(ok);
  after = matrices(orig); /* no failed run touched the original */
  assert_memory_equal(before.a, after.a, 4 * before.n * before.n * sizeof *before.a);
  free(before.a);
  free(after.a);
  rcb_model_destroy(orig);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_clone_unedited), cmocka_unit_test(test_coupling_model),
      cmocka_unit_test(test_pedestal),       cmocka_unit_test(test_add_disk),
      cmocka_unit_test(test_bearing_coefs),  cmocka_unit_test(test_all_edits),
      cmocka_unit_test(test_refusals),       cmocka_unit_test(test_alloc_failures),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
