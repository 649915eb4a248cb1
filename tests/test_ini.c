/*
 * INI model loader: the examples load with the expected mesh and values
 * (checked against hand formulas), coupling models tie the expected number
 * of DOFs, and every kind of input error gives a message that names the
 * file, the line and what is expected.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "core/rcb_internal.h"
#include "rcb_test_util.h"

#define PI 3.14159265358979323846

/* A valid minimal model: lines 1-8. Error tests append from line 9. */
static const char BASE[] =
    "[material steel]\n"        /* 1 */
    "density = 7800\n"          /* 2 */
    "young = 2e11\n"            /* 3 */
    "poisson = 0.3\n"           /* 4 */
    "[shaft A]\n"               /* 5 */
    "material = steel\n"        /* 6 */
    "shear_factor = 0.9\n"      /* 7 */
    "segment = 1.0 0.05 0 10\n"; /* 8 */

/* Load text (BASE + extra when base is set); check the status and that every
 * phrase occurs in the message; the model must be left empty. */
static void expect_error(int base, const char *extra, rcb_status want, const char *p1,
                         const char *p2) {
  char text[4096];
  rcb_model *m = NULL;
  rcb_status st;
  const char *msg;
  snprintf(text, sizeof text, "%s%s", base ? BASE : "", extra);
  assert_int_equal(rcb_model_create(&m, NULL), RCB_OK);
  st = rcb_model_load_string(m, text, "t.ini");
  msg = rcb_model_errmsg(m);
  if (st != want || (p1 && !strstr(msg, p1)) || (p2 && !strstr(msg, p2)))
    fail_msg("status %d (want %d), message: %s\nexpected to contain '%s' and '%s'", (int)st,
             (int)want, msg, p1 ? p1 : "", p2 ? p2 : "");
  assert_int_equal(rcb_model_node_count(m), 0);
  assert_int_equal(m->n_shafts, 0);
  rcb_model_destroy(m);
}

/* ---- positive tests ---- */

static void test_paper_system(void **state) {
  rcb_model *m = rcb_test_model_from_example("paper_system.ini");
  const rcb_coupling_t *c;
  double rho = 2758.219, ri = 0.006, ro = 0.017, t = 0.043115, hub, md;
  rcb_dof dof;
  size_t k;
  (void)state;
  assert_int_equal(rcb_model_node_count(m), 22);
  assert_int_equal(rcb_model_dof_count(m), 88);
  assert_int_equal(rcb_model_element_count(m), 20);
  assert_int_equal(m->n_couplings, 1);
  c = &m->couplings[0];
  assert_int_equal(c->type, RCB_COUPLING_NELSON_CRANDALL_2);
  /* Table 1 hub: an annulus of the whole thickness, half at each station */
  hub = rho * PI * (ro * ro - ri * ri) * t / 2.0;
  assert_true(rcb_test_close(hub, 0.04726041538250081, 1e-12, 0));
  for (k = 0; k < 2; k++) {
    assert_true(rcb_test_close(c->p.mass[k], hub, 1e-12, 0));
    assert_true(rcb_test_close(c->p.Ip[k], hub * (ro * ro + ri * ri) / 2.0, 1e-12, 0));
    assert_true(rcb_test_close(c->p.Id[k],
                               hub * (ro * ro + ri * ri) / 4.0 + hub * (t / 2) * (t / 2) / 12.0,
                               1e-12, 0));
  }
  assert_true(c->p.kt == 46.095e3 && c->p.kr == 220.76 && c->p.ct == 10.949 &&
              c->p.cr == 10.949e-6);
  assert_int_equal(c->at[0].node, 10); /* A end, z = 0.50 */
  assert_int_equal(c->at[1].node, 11); /* B start, z = 0.52 */
  /* disks: rho pi/4 (D^2 - d^2) w */
  md = 6303.235 * PI / 4.0 * (0.09 * 0.09 - 0.017 * 0.017) * 0.025;
  assert_int_equal(m->n_disks, 2);
  assert_true(rcb_test_close(m->disks[0].m, md, 1e-12, 0));
  assert_true(rcb_test_close(m->disks[1].m, md, 1e-12, 0));
  assert_int_equal(m->disks[0].at.node, 4);  /* z = 0.20 */
  assert_int_equal(m->disks[1].at.node, 17); /* z = 0.82 = 0.52 + 6 x 0.05 */
  /* bearings */
  assert_int_equal(m->n_bearings, 4);
  assert_int_equal(m->bearings[0].at.node, 1);
  assert_int_equal(m->bearings[1].at.node, 7);
  assert_int_equal(m->bearings[2].at.node, 14);
  assert_int_equal(m->bearings[3].at.node, 20);
  assert_true(m->bearings[1].c[0].kxx == 7e7 && m->bearings[1].c[0].kyy == 9e7 &&
              m->bearings[1].c[0].cxx == 300 && m->bearings[1].c[0].cyy == 500 &&
              m->bearings[1].c[0].kxy == 0 && m->bearings[1].c[0].cyx == 0);
  /* unbalances on the disks, 90 degrees apart */
  assert_int_equal(m->n_unbalances, 2);
  assert_int_equal(m->unbalances[0].at.node, 4);
  assert_int_equal(m->unbalances[1].at.node, 17);
  assert_true(m->unbalances[0].phase == 0.0);
  assert_true(rcb_test_close(m->unbalances[1].phase, PI / 2, 1e-15, 0));
  assert_true(m->unbalances[1].amount == 15e-5);
  /* shaft damping and shear */
  assert_true(m->shafts[1].qz_m == 15.691 && m->shafts[1].qz_k == 22.989e-6);
  assert_true(m->shafts[1].kappa == 0.9 && m->shafts[1].z0 == 0.52);
  /* stations: 2 disks, 4 bearings, C, C.A, C.B, 2 unbalances, P1 */
  assert_int_equal(rcb_model_station_count(m), 12);
  assert_int_equal(rcb_model_find_dof(m, "P1.x", &dof), RCB_OK);
  assert_int_equal(dof.node, 6);
  assert_int_equal(rcb_model_find_dof(m, "C.B.y", &dof), RCB_OK);
  assert_int_equal(dof.node, 11);
  rcb_model_destroy(m);
}

static void test_paper_freefree(void **state) {
  rcb_model *m = rcb_test_model_from_example("paper_freefree.ini");
  (void)state;
  assert_int_equal(rcb_model_node_count(m), 22);
  assert_int_equal(rcb_model_dof_count(m), 88);
  assert_int_equal(m->n_bearings, 0);
  assert_int_equal(m->n_disks, 2);
  assert_int_equal(m->n_couplings, 1);
  rcb_model_destroy(m);
}

static void test_other_examples(void **state) {
  rcb_model *m = rcb_test_model_from_example("two_disk_aniso.ini");
  double md;
  rcb_bearing_coefs b;
  (void)state;
  assert_int_equal(rcb_model_node_count(m), 13);
  assert_int_equal(rcb_model_dof_count(m), 52);
  assert_int_equal(m->shafts[0].nseg, 3);
  assert_true(m->shafts[0].seg[1].id == 0.01 && m->shafts[0].seg[1].nel == 8);
  assert_int_equal(m->disks[0].at.node, 4);
  assert_int_equal(m->disks[1].at.node, 8);
  assert_int_equal(m->bearings[1].at.node, 12); /* "S end" */
  md = 7810 * PI / 4.0 * (0.28 * 0.28 - 0.06 * 0.06) * 0.07;
  assert_true(rcb_test_close(m->disks[1].m, md, 1e-12, 0));
  assert_true(rcb_test_close(m->unbalances[1].phase, 2 * PI / 3, 1e-15, 0));
  rcb_model_destroy(m);

  m = rcb_test_model_from_example("cross_coupled.ini");
  assert_int_equal(rcb_model_node_count(m), 11);
  assert_int_equal(rcb_model_dof_count(m), 44);
  assert_true(m->bearings[0].c[0].kxy == 5e6 && m->bearings[0].c[0].kyx == -5e6);
  assert_true(m->bearings[0].c[0].cxy == 300 && m->bearings[0].c[0].cyx == -300);
  assert_int_equal(m->bearings[1].n, 3);
  /* 3000 rpm = 100 pi rad/s */
  assert_true(rcb_test_close(m->bearings[1].speeds[1], 100 * PI, 1e-15, 0));
  /* halfway between 3000 and 6000 rpm: mean of the two columns */
  rcb_bearing_eval(&m->bearings[1], 150 * PI, &b);
  assert_true(rcb_test_close(b.kxx, 1.95e7, 1e-12, 0));
  assert_true(rcb_test_close(b.kyx, -5.0e6, 1e-12, 0));
  assert_true(rcb_test_close(b.kyy, 2.0e7, 1e-12, 0));
  assert_true(rcb_test_close(b.cxy, 275, 1e-12, 0));
  rcb_model_destroy(m);
}

/* Two shafts of 10 elements joined by a coupling of the given model. */
static rcb_model *coupled(const char *coupling_body) {
  char text[2048];
  snprintf(text, sizeof text,
           "%s"
           "[shaft B]\nmaterial = steel\nshear_factor = 0.9\nstart = 1.02\n"
           "segment = 1.0 0.05 0 10\n"
           "[coupling C]\nbetween = A end, B start\n%s",
           BASE, coupling_body);
  return rcb_test_model_from_string(text);
}

static void test_coupling_models(void **state) {
  rcb_model *m;
  (void)state;
  /* kramer_1 ties the two translations: 88 - 2 */
  m = coupled("model = kramer_1\nhub_mass = 0.1\nhub_Id = 1e-5\nhub_Ip = 2e-5\n");
  assert_int_equal(rcb_model_node_count(m), 22);
  assert_int_equal(rcb_model_dof_count(m), 86);
  assert_true(m->couplings[0].p.mass[1] == 0.1 && m->couplings[0].p.Ip[0] == 2e-5);
  rcb_model_destroy(m);
  m = coupled("model = kramer_2\nkr = 100\ncr = 1e-3\n");
  assert_int_equal(rcb_model_dof_count(m), 86);
  assert_true(m->couplings[0].p.kr == 100 && m->couplings[0].p.kt == 0);
  rcb_model_destroy(m);
  /* rigid ties all four: 88 - 4 */
  m = coupled("model = rigid\n");
  assert_int_equal(rcb_model_dof_count(m), 84);
  rcb_model_destroy(m);
  m = coupled("model = nelson_crandall_1\nkt = 1e4\nkr = 200\n");
  assert_int_equal(rcb_model_dof_count(m), 88);
  rcb_model_destroy(m);
}

static void test_table_bearing(void **state) {
  char text[2048];
  rcb_model *m;
  rcb_bearing_coefs b;
  (void)state;
  snprintf(text, sizeof text,
           "%s"
           "[bearing B]\n"
           "at = A start\n"
           "speed = 0 100\n"
           "   200            ; rad/s, continued on an indented line\n"
           "kxx = 1e6 2e6 4e6\n"
           "kyy = 3e6\n"
           "cxy = 10 20\n"
           "   30\n",
           BASE);
  m = rcb_test_model_from_string(text);
  assert_int_equal(m->bearings[0].n, 3);
  assert_true(m->bearings[0].speeds[2] == 200.0);
  assert_true(m->bearings[0].c[2].kxx == 4e6 && m->bearings[0].c[1].kyy == 3e6);
  assert_true(m->bearings[0].c[2].cxy == 30 && m->bearings[0].c[2].cyy == 0);
  rcb_bearing_eval(&m->bearings[0], 150.0, &b);
  assert_true(rcb_test_close(b.kxx, 3e6, 1e-14, 0));
  rcb_bearing_eval(&m->bearings[0], 1000.0, &b); /* clamped */
  assert_true(b.kxx == 4e6);
  rcb_model_destroy(m);
}

static void test_load_string_no_files(void **state) {
  rcb_test_counter cnt = {0, 0};
  rcb_allocator a = rcb_test_counting_allocator(&cnt);
  rcb_model *m = NULL;
  char text[2048];
  (void)state;
  /* segment continued on an indented line is a second segment */
  snprintf(text, sizeof text,
           "[material steel]\ndensity = 7800\nyoung = 2e11\npoisson = 0.3\n"
           "[shaft A]\nmaterial = steel\nshear_factor = 0\n"
           "segment = 0.5 0.05 0 5   ; first\n"
           "          0.5 0.04 0 5   ; second\n"
           "[station P]\nat = A 0.7\n");
  assert_int_equal(rcb_model_create(&m, &a), RCB_OK);
  assert_int_equal(rcb_model_load_string(m, text, "<firmware>"), RCB_OK);
  assert_int_equal(rcb_model_node_count(m), 11);
  assert_int_equal(m->shafts[0].nseg, 2);
  assert_true(m->shafts[0].seg[1].od == 0.04);
  assert_int_equal(m->probes[0].at.node, 7);
  assert_true(cnt.allocs > 0);
  rcb_model_destroy(m);
  assert_int_equal(cnt.allocs, cnt.frees);
  /* an error names the source given */
  assert_int_equal(rcb_model_create(&m, &a), RCB_OK);
  assert_int_equal(rcb_model_load_string(m, "[shaft]\n", "<firmware>"), RCB_ERR_PARSE);
  assert_non_null(strstr(rcb_model_errmsg(m), "<firmware>:1:"));
  rcb_model_destroy(m);
  assert_int_equal(cnt.allocs, cnt.frees);
}

/* Allocator that fails from the n-th call on. */
typedef struct failing {
  size_t allocs, frees, fail_at;
} failing;
static void *fail_alloc(void *user, size_t size) {
  failing *f = user;
  if (f->allocs + 1 >= f->fail_at) return NULL;
  f->allocs++;
  return malloc(size);
}
static void fail_free(void *user, void *p) {
  ((failing *)user)->frees++;
  free(p);
}

/* Every allocation of the loader is checked: failing any one of them gives
 * RCB_ERR_NOMEM, an empty model, and no leak. */
static void test_out_of_memory(void **state) {
  char path[1024];
  size_t k, done = 0;
  (void)state;
  snprintf(path, sizeof path, "%s/cross_coupled.ini", RCB_EXAMPLES_DIR);
  for (k = 1; k < 100000 && !done; k++) {
    failing f = {0, 0, (size_t)-1};
    rcb_allocator a = {fail_alloc, fail_free, &f};
    rcb_model *m = NULL;
    rcb_status st;
    assert_int_equal(rcb_model_create(&m, &a), RCB_OK);
    f.fail_at = f.allocs + k;
    st = rcb_model_load_file(m, path);
    if (st == RCB_OK) {
      done = 1;
      assert_int_equal(rcb_model_dof_count(m), 44);
    } else {
      if (st != RCB_ERR_NOMEM) fail_msg("k = %zu: %d %s", k, (int)st, rcb_model_errmsg(m));
      assert_int_equal(rcb_model_node_count(m), 0);
    }
    rcb_model_destroy(m);
    assert_int_equal(f.allocs, f.frees);
  }
  assert_true(done);
}

static void test_section_order(void **state) {
  /* the paper-like model with every section before the one it refers to
   * reversed: unbalance before its disk, disk before its shaft, shaft before
   * its material */
  static const char reversed[] =
      "[station P]\nat = DA\n"
      "[unbalance U]\nat = DA\namount = 1e-4\nphase_deg = 45\n"
      "[coupling C]\nmodel = kramer_1\nbetween = A end, B start\n"
      "[disk DA]\nat = A 0.2\nmass = 2\nId = 0.01\nIp = 0.02\n"
      "[bearing B1]\nat = B 0.62\nkxx = 1e7\nkyy = 1e7\n"
      "[shaft B]\nmaterial = steel\nshear_factor = 0.9\nstart = 0.52\n"
      "segment = 0.5 0.017 0 10\n"
      "[shaft A]\nmaterial = steel\nshear_factor = 0.9\nsegment = 0.5 0.017 0 10\n"
      "[material steel]\ndensity = 7800\nyoung = 2e11\npoisson = 0.3\n";
  static const char ordered[] =
      "[material steel]\ndensity = 7800\nyoung = 2e11\npoisson = 0.3\n"
      "[shaft A]\nmaterial = steel\nshear_factor = 0.9\nsegment = 0.5 0.017 0 10\n"
      "[shaft B]\nmaterial = steel\nshear_factor = 0.9\nstart = 0.52\n"
      "segment = 0.5 0.017 0 10\n"
      "[disk DA]\nat = A 0.2\nmass = 2\nId = 0.01\nIp = 0.02\n"
      "[bearing B1]\nat = B 0.62\nkxx = 1e7\nkyy = 1e7\n"
      "[coupling C]\nmodel = kramer_1\nbetween = A end, B start\n"
      "[unbalance U]\nat = DA\namount = 1e-4\nphase_deg = 45\n"
      "[station P]\nat = DA\n";
  rcb_model *a = rcb_test_model_from_string(reversed);
  rcb_model *b = rcb_test_model_from_string(ordered);
  size_t i, k;
  (void)state;
  assert_int_equal(rcb_model_node_count(a), rcb_model_node_count(b));
  assert_int_equal(rcb_model_dof_count(a), 86);
  assert_int_equal(rcb_model_dof_count(b), 86);
  /* shafts are meshed in definition order: B first in the reversed file */
  assert_string_equal(a->shafts[0].name, "B");
  for (i = 0; i < a->n_nodes; i++) {
    rcb_node_info na, nb;
    size_t j = i < 11 ? i + 11 : i - 11; /* same (shaft, z) in the other model */
    assert_int_equal(rcb_model_node_info(a, i, &na), RCB_OK);
    assert_int_equal(rcb_model_node_info(b, j, &nb), RCB_OK);
    assert_string_equal(na.shaft, nb.shaft);
    assert_true(na.z == nb.z);
  }
  assert_true(a->disks[0].m == b->disks[0].m);
  assert_int_equal(a->nodes[a->disks[0].at.node].shaft, 1);
  assert_true(a->nodes[a->disks[0].at.node].z == 0.2);
  assert_true(a->nodes[a->unbalances[0].at.node].z == 0.2);
  assert_true(a->nodes[a->probes[0].at.node].z == 0.2);
  assert_true(rcb_test_close(a->unbalances[0].phase, PI / 4, 1e-15, 0));
  for (k = 0; k < 2; k++)
    assert_true(a->nodes[a->couplings[0].at[k].node].z == b->nodes[b->couplings[0].at[k].node].z);
  rcb_model_destroy(a);
  rcb_model_destroy(b);
}

/* ---- errors ---- */

static void test_err_unknown_section(void **state) {
  (void)state;
  expect_error(1, "[bearng B1]\nat = A 0\n", RCB_ERR_PARSE, "t.ini:9:",
               "did you mean [bearing]?");
  expect_error(1, "[rotor R]\n", RCB_ERR_PARSE, "t.ini:9:", "unknown section type [rotor]");
  expect_error(1, "[disk]\n", RCB_ERR_PARSE, "t.ini:9:", "needs a name");
}

static void test_err_unknown_key(void **state) {
  (void)state;
  expect_error(1, "[bearing B1]\nat = A 0\nkx = 1e6\n", RCB_ERR_PARSE,
               "t.ini:11: [bearing B1] kx:", "did you mean kxx?");
  expect_error(0, "[material steel]\ndensty = 7800\n", RCB_ERR_PARSE,
               "t.ini:2: [material steel] densty:", "did you mean density?");
  expect_error(0, "name = x\n[model]\n", RCB_ERR_PARSE, "t.ini:1:", "outside any section");
}

static void test_err_missing_key(void **state) {
  (void)state;
  expect_error(0, "[material steel]\nyoung = 2e11\npoisson = 0.3\n", RCB_ERR_PARSE,
               "t.ini:1: [material steel]:", "missing key 'density'");
  expect_error(1, "[shaft B]\nmaterial = steel\nshear_factor = 0.9\n", RCB_ERR_PARSE,
               "t.ini:9: [shaft B]:", "missing key 'segment'");
  expect_error(1, "[shaft B]\nshear_factor = 0.9\nsegment = 1 0.05 0 4\n", RCB_ERR_PARSE,
               "t.ini:9: [shaft B]:", "missing key 'material'");
  expect_error(1, "[disk D]\nmass = 1\nId = 0\nIp = 0\n", RCB_ERR_PARSE, "t.ini:9: [disk D]:",
               "missing key 'at'");
  expect_error(1, "[disk D]\nat = A 0.5\nmass = 1\nIp = 0\n", RCB_ERR_PARSE,
               "t.ini:9: [disk D]:", "missing key 'Id'");
}

static void test_err_numbers(void **state) {
  (void)state;
  expect_error(1, "[bearing B1]\nat = A 0\nkxx = abc\n", RCB_ERR_PARSE,
               "t.ini:11: [bearing B1] kxx:", "'abc' is not a number; expected stiffness in N/m");
  expect_error(1, "[bearing B1]\nat = A 0\nkxx = 1e6x\n", RCB_ERR_PARSE, "t.ini:11:",
               "'1e6x' is not a number");
  expect_error(0, "[material steel]\ndensity = nan\n", RCB_ERR_PARSE,
               "t.ini:2: [material steel] density:", "not a finite number");
  expect_error(1, "[disk D]\nat = A 0.5\nmass = inf\nId = 0\nIp = 0\n", RCB_ERR_PARSE,
               "t.ini:11: [disk D] mass:", "not a finite number");
  expect_error(1, "[disk D]\nat = A 0.5\nmass = 1 2\nId = 0\nIp = 0\n", RCB_ERR_PARSE,
               "t.ini:11: [disk D] mass:", "expected one value");
  expect_error(1, "[station P]\nat = A 0.5\n[shaft B]\nmaterial = steel\nshear_factor = 0.9\n"
                  "segment = 1.0 0.05 0 2.5\n",
               RCB_ERR_PARSE, "t.ini:14: [shaft B] segment:", "whole number");
  /* a value rejected by the builder keeps the file and line */
  expect_error(0, "[material steel]\ndensity = -1\nyoung = 2e11\npoisson = 0.3\n",
               RCB_ERR_ARG, "t.ini:1: [material steel]:", "expected a positive value");
}

static void test_err_fields(void **state) {
  (void)state;
  expect_error(0,
               "[material steel]\ndensity = 7800\nyoung = 2e11\npoisson = 0.3\n"
               "[shaft A]\nmaterial = steel\nshear_factor = 0.9\nsegment = 1.0 0.05 10\n",
               RCB_ERR_PARSE, "t.ini:8: [shaft A] segment: 3 fields", "expected 4");
  expect_error(1, "[station P]\nat = A 0.5 0.6\n", RCB_ERR_PARSE,
               "t.ini:10: [station P] at: 3 fields", "expected 'SHAFT z'");
  expect_error(1, "[station P]\nat = A\n", RCB_ERR_PARSE, "t.ini:10: [station P] at:",
               "'A' is a shaft");
  expect_error(1, "[coupling C]\nmodel = rigid\nbetween = A end\n", RCB_ERR_PARSE,
               "t.ini:11: [coupling C] between:", "expected two stations");
}

static void test_err_undefined(void **state) {
  (void)state;
  expect_error(1, "[disk D]\nat = Z 0.5\nmass = 1\nId = 0\nIp = 0\n", RCB_ERR_NOT_FOUND,
               "t.ini:10: [disk D] at:", "shaft 'Z' is not defined");
  expect_error(1, "[shaft B]\nmaterial = iron\nshear_factor = 0.9\nsegment = 1 0.05 0 4\n",
               RCB_ERR_NOT_FOUND, "t.ini:10: [shaft B] material:",
               "material 'iron' is not defined (defined: steel)");
  expect_error(1, "[disk DA]\nat = A 0.5\nmass = 1\nId = 0\nIp = 0\n"
                  "[unbalance U]\nat = DB\namount = 1e-4\n",
               RCB_ERR_NOT_FOUND, "t.ini:15: [unbalance U] at:",
               "'DB' is not a defined disk, bearing, coupling or station (did you mean DA?)");
}

static void test_err_duplicate(void **state) {
  (void)state;
  expect_error(1, "[disk D]\nat = A 0.5\nmass = 1\nId = 0\nIp = 0\n[disk D]\n", RCB_ERR_PARSE,
               "t.ini:14:", "duplicate section [disk D] (first defined at line 9)");
  expect_error(1, "[disk D]\nat = A 0.5\nmass = 1\nId = 0\nIp = 0\n[station D]\n",
               RCB_ERR_PARSE, "t.ini:14:", "uses the name of [disk D] (line 9)");
  expect_error(1, "[disk D]\nat = A 0.5\nmass = 1\nmass = 2\n", RCB_ERR_PARSE,
               "t.ini:12: [disk D] mass:", "given twice (first at line 11)");
}

static void test_err_coupling_params(void **state) {
  static const char shaft_b[] =
      "[shaft B]\nmaterial = steel\nshear_factor = 0.9\nstart = 1.02\n"
      "segment = 1.0 0.05 0 10\n"; /* lines 9-13 */
  char text[1024];
  (void)state;
  snprintf(text, sizeof text, "%s[coupling C]\nmodel = kramer_2\nbetween = A end, B start\n"
                              "kt = 1e4\nkr = 100\ncr = 0\n", shaft_b);
  expect_error(1, text, RCB_ERR_PARSE, "t.ini:17: [coupling C] kt:",
               "not used by model kramer_2; expected only kr, cr");
  snprintf(text, sizeof text, "%s[coupling C]\nmodel = nelson_crandall_1\n"
                              "between = A end, B start\nkr = 100\n", shaft_b);
  expect_error(1, text, RCB_ERR_PARSE, "t.ini:14: [coupling C]:",
               "missing key 'kt'; expected kt = translational stiffness in N/m");
  snprintf(text, sizeof text, "%s[coupling C]\nmodel = nelson_crandall3\n"
                              "between = A end, B start\n", shaft_b);
  expect_error(1, text, RCB_ERR_PARSE, "t.ini:15: [coupling C] model:",
               "did you mean nelson_crandall_1?");
  snprintf(text, sizeof text, "%s[coupling C]\nmodel = rigid\nbetween = A end, B start\n"
                              "hub_mass = 1\nhub_Id = 0\nhub_Ip = 0\nhub_density = 2700\n",
           shaft_b);
  expect_error(1, text, RCB_ERR_PARSE, "t.ini:20: [coupling C] hub_density:",
               "both explicit inertia");
  snprintf(text, sizeof text, "%s[coupling C]\nmodel = rigid\nbetween = A end, A start\n",
           shaft_b);
  expect_error(1, text, RCB_ERR_MODEL, "t.ini:14: [coupling C]:", "both stations are on shaft");
}

static void test_err_table(void **state) {
  (void)state;
  expect_error(1, "[bearing B]\nat = A 0\nspeed_rpm = 0 1000 2000\nkxx = 1e6 2e6\n",
               RCB_ERR_PARSE, "t.ini:12: [bearing B] kxx:",
               "2 values but speed_rpm lists 3 speeds; expected 1 value (constant) or 3");
  expect_error(1, "[bearing B]\nat = A 0\nkxx = 1e6 2e6\n", RCB_ERR_PARSE,
               "t.ini:11: [bearing B] kxx:", "no speed table");
  expect_error(1, "[bearing B]\nat = A 0\nspeed = 0 100\nspeed_rpm = 0 1000\n", RCB_ERR_PARSE,
               "t.ini:12: [bearing B] speed_rpm:", "both speed_rpm and speed");
  expect_error(1, "[bearing B]\nat = A 0\nspeed = 100 0\nkxx = 1 2\n", RCB_ERR_ARG,
               "t.ini:9: [bearing B]:", "speeds must increase");
}

static void test_err_phase(void **state) {
  (void)state;
  expect_error(1, "[unbalance U]\nat = A 0.5\namount = 1e-4\nphase = 90\n", RCB_ERR_PARSE,
               "t.ini:12: [unbalance U] phase:", "phase_deg");
}

static void test_err_station_not_on_node(void **state) {
  (void)state;
  /* finalize's message, with the line of the station's header */
  expect_error(1, "[station P]\nat = A 0.33\n", RCB_ERR_MODEL, "t.ini:9: [station P]:",
               "is not on a node");
  expect_error(1, "\n[disk D]\nat = A 1.5\nmass = 1\nId = 0\nIp = 0\n", RCB_ERR_MODEL,
               "t.ini:10: [disk D]:", "outside shaft");
}

static void test_err_disk_both(void **state) {
  (void)state;
  expect_error(1,
               "[disk D]\nat = A 0.5\nmass = 1\nId = 0\nIp = 0\ndensity = 7800\n"
               "outer_diameter = 0.2\nwidth = 0.02\n",
               RCB_ERR_PARSE, "t.ini:14: [disk D] density:",
               "both explicit inertia (mass, Id, Ip) and geometry");
  expect_error(1, "[disk D]\nat = A 0.5\n", RCB_ERR_PARSE, "t.ini:9: [disk D]:",
               "missing the disk's inertia");
}

static void test_err_syntax(void **state) {
  char text[600];
  size_t i;
  (void)state;
  expect_error(1, "[disk D\n", RCB_ERR_PARSE, "t.ini:9:", "without closing ']'");
  expect_error(1, "[station P]\nthis line is garbage\n", RCB_ERR_PARSE, "t.ini:10:",
               "cannot read this line");
  /* a line longer than inih's buffer is reported, not split in two */
  memcpy(text, "[station P]\n; ", 14);
  for (i = 14; i < 14 + 300; i++) text[i] = 'x';
  memcpy(text + i, "\nat = A 0.5\n", 13);
  expect_error(1, text, RCB_ERR_PARSE, "t.ini:10:", "line too long (302 characters)");
}

static void test_err_file(void **state) {
  rcb_model *m = NULL;
  (void)state;
  assert_int_equal(rcb_model_create(&m, NULL), RCB_OK);
  assert_int_equal(rcb_model_load_file(m, RCB_EXAMPLES_DIR "/no_such_model.ini"), RCB_ERR_IO);
  assert_non_null(strstr(rcb_model_errmsg(m), "no_such_model.ini: cannot open"));
  /* loading twice into the same model is refused */
  assert_int_equal(rcb_model_load_file(m, RCB_EXAMPLES_DIR "/paper_system.ini"), RCB_OK);
  assert_int_equal(rcb_model_load_file(m, RCB_EXAMPLES_DIR "/paper_system.ini"), RCB_ERR_STATE);
  rcb_model_destroy(m);
}

/* [uff] map: UFF node numbers to stations; written back by the INI writer. */
static void test_uff_map(void **state) {
  char text[4096], out[8192];
  rcb_model *m, *m2;
  long node;
  const char *st;
  size_t need;
  (void)state;
  snprintf(text, sizeof text, "%s[disk D]\nat = A 0.5\nmass = 1\nId = 0.01\nIp = 0.02\n"
           "[uff]\nmap = 7 D, 12 #3\n", BASE);
  m = rcb_test_model_from_string(text);
  assert_int_equal(rcb_model_uff_node_count(m), 2);
  assert_int_equal(rcb_model_uff_node(m, 1, &node, &st), RCB_OK);
  assert_int_equal(node, 12);
  assert_string_equal(st, "#3");
  assert_int_equal(rcb_model_write_ini(m, out, sizeof out, &need), RCB_OK);
  m2 = rcb_test_model_from_string(out);
  assert_int_equal(rcb_model_uff_node_count(m2), 2);
  assert_int_equal(rcb_model_uff_node(m2, 0, &node, &st), RCB_OK);
  assert_int_equal(node, 7);
  assert_string_equal(st, "D");
  rcb_model_destroy(m);
  rcb_model_destroy(m2);
  expect_error(1, "[uff]\nmap = 7 NOPE\n", RCB_ERR_NOT_FOUND, "node 7 maps to 'NOPE'",
               "not a station");
  expect_error(1, "[uff]\nmap = 7\n", RCB_ERR_PARSE, "t.ini:10: [uff] map",
               "NODE STATION pairs");
  expect_error(1, "[uff]\nmap = 7 #1, 7 #2\n", RCB_ERR_PARSE, "mapped twice", NULL);
  expect_error(1, "[uff x]\n", RCB_ERR_PARSE, "takes no name", NULL);
}

/* [test] rpm: the rotor speed of the measurements (issue #17), in rad/s in the
 * model, written back by the INI writer; absent: not found. */
static void test_test_speed(void **state) {
  char text[4096], out[8192];
  rcb_model *m, *m2;
  double w = -1.0;
  size_t need;
  (void)state;
  m = rcb_test_model_from_string(BASE);
  assert_int_equal(rcb_model_get_test_speed(m, &w), RCB_ERR_NOT_FOUND);
  rcb_model_destroy(m);
  snprintf(text, sizeof text, "%s[test]\nrpm = 10000\n", BASE);
  m = rcb_test_model_from_string(text);
  assert_int_equal(rcb_model_get_test_speed(m, &w), RCB_OK);
  assert_true(rcb_test_close(w, 10000.0 * RCB_PI / 30.0, 1e-15, 0));
  assert_int_equal(rcb_model_write_ini(m, out, sizeof out, &need), RCB_OK);
  m2 = rcb_test_model_from_string(out);
  assert_int_equal(rcb_model_get_test_speed(m2, &w), RCB_OK);
  assert_true(rcb_test_close(w, 10000.0 * RCB_PI / 30.0, 1e-15, 0));
  assert_int_equal(rcb_model_set_test_speed(m2, -1.0), RCB_ERR_ARG);
  rcb_model_destroy(m);
  rcb_model_destroy(m2);
  expect_error(1, "[test]\nrpm = -5\n", RCB_ERR_PARSE, "t.ini:10: [test] rpm", ">= 0");
  expect_error(1, "[test]\nspeed = 5\n", RCB_ERR_PARSE, "unknown key", "rpm");
  expect_error(1, "[test x]\n", RCB_ERR_PARSE, "takes no name", NULL);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_paper_system),
      cmocka_unit_test(test_paper_freefree),
      cmocka_unit_test(test_other_examples),
      cmocka_unit_test(test_coupling_models),
      cmocka_unit_test(test_table_bearing),
      cmocka_unit_test(test_load_string_no_files),
      cmocka_unit_test(test_out_of_memory),
      cmocka_unit_test(test_section_order),
      cmocka_unit_test(test_err_unknown_section),
      cmocka_unit_test(test_err_unknown_key),
      cmocka_unit_test(test_err_missing_key),
      cmocka_unit_test(test_err_numbers),
      cmocka_unit_test(test_err_fields),
      cmocka_unit_test(test_err_undefined),
      cmocka_unit_test(test_err_duplicate),
      cmocka_unit_test(test_err_coupling_params),
      cmocka_unit_test(test_err_table),
      cmocka_unit_test(test_err_phase),
      cmocka_unit_test(test_err_station_not_on_node),
      cmocka_unit_test(test_err_disk_both),
      cmocka_unit_test(test_err_syntax),
      cmocka_unit_test(test_err_file),
      cmocka_unit_test(test_uff_map),
      cmocka_unit_test(test_test_speed),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
