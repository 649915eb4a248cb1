/*
 * The bad-input catalogue (issue #7), library level: every case is one wrong
 * input, with the status it must give and phrases its message must contain
 * (what is wrong, where, what is expected). The INI cases each change one
 * line of a small valid two-shaft model; the warning cases are valid but
 * implausible (unit slips, separate rotors) and must load with a warning that
 * names the item and its line. Then analyses, measurement files and fits.
 * On every failure the object must stay usable and unchanged: a failed load
 * leaves an empty model that loads the good text afterwards, a failed read
 * leaves the measurement empty, a refused parameter leaves the model as it was.
 * The CLI half of the catalogue (exit codes, no output file, inputs untouched)
 * is the bad_* block of tests/cli/cli_test.sh.
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
#include "rcb_test_util.h"

/* Shaft A 0 to 0.5 m, B 0.6 to 1.1 m, 5 elements each (nodes every 0.1 m). */
static const char BASE[] =
    "[model]\n"                       /* 1 */
    "name = bad input base\n"         /* 2 */
    "[material steel]\n"              /* 3 */
    "density = 7800\n"                /* 4 */
    "young = 2e11\n"                  /* 5 */
    "poisson = 0.3\n"                 /* 6 */
    "[shaft A]\n"                     /* 7 */
    "material = steel\n"              /* 8 */
    "shear_factor = 0.9\n"            /* 9 */
    "segment = 0.5 0.02 0 5\n"        /* 10 */
    "[shaft B]\n"                     /* 11 */
    "material = steel\n"              /* 12 */
    "shear_factor = 0.9\n"            /* 13 */
    "start = 0.6\n"                   /* 14 */
    "segment = 0.5 0.02 0.0 5\n"      /* 15 */
    "[bearing B1]\n"                  /* 16 */
    "at = A 0.1\n"                    /* 17 */
    "kxx = 1e7\n"                     /* 18 */
    "kyy = 1e7\n"                     /* 19 */
    "[bearing B2]\n"                  /* 20 */
    "at = B 1.0\n"                    /* 21 */
    "kxx = 1e7\n"                     /* 22 */
    "kyy = 1e7\n"                     /* 23 */
    "[disk D]\n"                      /* 24 */
    "at = A 0.2\n"                    /* 25 */
    "mass = 2\n"                      /* 26 */
    "Id = 0.01\n"                     /* 27 */
    "Ip = 0.02\n"                     /* 28 */
    "[coupling C]\n"                  /* 29 */
    "model = nelson_crandall_1\n"     /* 30 */
    "between = A end, B start\n"      /* 31 */
    "kt = 1e5\n"                      /* 32 */
    "kr = 1e3\n"                      /* 33 */
    "[unbalance U]\n"                 /* 34 */
    "at = D\n"                        /* 35 */
    "amount = 1e-4\n"                 /* 36 */
    "phase_deg = 0\n"                 /* 37 */
    "[station P]\n"                   /* 38 */
    "at = B 0.8\n";                   /* 39 */

/* One INI case: BASE with the first occurrence of `from` replaced by `to`. */
typedef struct ini_case {
  const char *from, *to;
  rcb_status st;
  const char *p1, *p2; /* phrases of the message (p2 may be NULL) */
} ini_case;

static const ini_case INI_CASES[] = {
    /* ---- magnitudes that overflow (issue #17: these read as "singular ... free-free") ---- */
    {"kxx = 1e7", "kxx = 1e308", RCB_ERR_MODEL, "<t>:16: [bearing B1]",
     "kxx = 1e+308 N/m is beyond any machine"},
    {"amount = 1e-4", "amount = 1e200", RCB_ERR_MODEL, "unbalance 'U': amount = 1e+200 kg m",
     "beyond any machine"},
    {"density = 7800", "density = 1e308", RCB_ERR_MODEL,
     "<t>:3: [material steel]", "density = 1e+308 kg/m^3 is beyond any machine"},
    {"kt = 1e5", "kt = 1e150", RCB_ERR_MODEL, "<t>:29: [coupling C]", "kt = 1e+150 N/m"},
    /* ---- sections and keys ---- */
    {"[station P]", "[gizmo P]", RCB_ERR_PARSE, "<t>:38:", "unknown section type [gizmo]"},
    {"[disk D]", "[disc D]", RCB_ERR_PARSE, "<t>:24:", "did you mean [disk]?"},
    {"[disk D]", "[disk]", RCB_ERR_PARSE, "[disk] needs a name", NULL},
    {"[disk D]", "[disk D", RCB_ERR_PARSE, "<t>:24:", "without closing ']'"},
    {"[disk D]", "[disk D E]", RCB_ERR_PARSE, "more than one name", NULL},
    {"[disk D]", "[shaft A]", RCB_ERR_PARSE, "duplicate section [shaft A]", "line 7"},
    {"[disk D]", "[station B1]", RCB_ERR_PARSE, "duplicate name", "[bearing B1]"},
    {"[model]\n", "", RCB_ERR_PARSE, "<t>:1:", "key outside any section"},
    {"kxx = 1e7\nkyy", "color = red\nkyy", RCB_ERR_PARSE, "<t>:18: [bearing B1] color",
     "unknown key"},
    {"kxx = 1e7", "kxz = 1e7", RCB_ERR_PARSE, "[bearing B1] kxz", "did you mean kxx?"},
    {"phase_deg = 0", "phase = 0", RCB_ERR_PARSE, "[unbalance U] phase", "phase_deg"},
    {"Id = 0.01", "Id = 0.01\nId = 0.02", RCB_ERR_PARSE, "<t>:28: [disk D] Id", "given twice"},
    {"kyy = 1e7\n[bearing B2]", "kyy = 1e7\nthis is not a key\n[bearing B2]", RCB_ERR_PARSE,
     "<t>:20:", "cannot read this line"},
    {"material = steel\nshear_factor = 0.9\nsegment", "shear_factor = 0.9\nsegment",
     RCB_ERR_PARSE, "[shaft A]", "missing key 'material'"},
    {"shear_factor = 0.9\nsegment = 0.5 0.02 0 5", "segment = 0.5 0.02 0 5", RCB_ERR_PARSE,
     "<t>:7: [shaft A]", "missing key 'shear_factor'"},
    {"segment = 0.5 0.02 0 5\n", "", RCB_ERR_PARSE, "[shaft A]", "missing key 'segment'"},
    {"mass = 2\n", "", RCB_ERR_PARSE, "[disk D]", "mass"},
    {"amount = 1e-4\n", "", RCB_ERR_PARSE, "[unbalance U]", "missing key 'amount'"},
    {"at = B 0.8", "", RCB_ERR_PARSE, "[station P]", "missing key 'at'"},
    {"[material steel]", "[material iron]", RCB_ERR_NOT_FOUND,
     "<t>:8: [shaft A] material: material 'steel' is not defined", "(defined: iron)"},
    {"model = nelson_crandall_1", "model = bendy", RCB_ERR_PARSE, "unknown coupling model 'bendy'",
     "nelson_crandall_2"},
    /* ---- lengths, diameters, counts ---- */
    {"segment = 0.5 0.02 0 5", "segment = -0.5 0.02 0 5", RCB_ERR_ARG, "<t>:",
     "segment length (m) = -0.5, expected a positive value"},
    {"segment = 0.5 0.02 0 5", "segment = 0 0.02 0 5", RCB_ERR_ARG, "[shaft A]",
     "segment length (m) = 0, expected a positive value"},
    {"segment = 0.5 0.02 0 5", "segment = 0.5 0 0 5", RCB_ERR_ARG, "[shaft A]",
     "outer diameter (m) = 0, expected a positive value"},
    {"segment = 0.5 0.02 0 5", "segment = 0.5 0.02 -0.01 5", RCB_ERR_ARG,
     "inner diameter (m) = -0.01", "expected a value >= 0"},
    {"segment = 0.5 0.02 0 5", "segment = 0.5 0.02 0.02 5", RCB_ERR_ARG,
     "inner diameter 0.02 m >= outer diameter 0.02 m", NULL},
    {"segment = 0.5 0.02 0 5", "segment = 0.5 0.02 0.03 5", RCB_ERR_ARG,
     "inner diameter 0.03 m >= outer diameter 0.02 m", NULL},
    {"segment = 0.5 0.02 0 5", "segment = 0.5 0.02 0 0", RCB_ERR_PARSE, "0 elements",
     "expected a whole number of elements from 1 to 100000"},
    {"segment = 0.5 0.02 0 5", "segment = 0.5 0.02 0 2.5", RCB_ERR_PARSE, "2.5 elements",
     NULL},
    {"segment = 0.5 0.02 0 5", "segment = 0.5 0.02 0", RCB_ERR_PARSE, "<t>:10:",
     "3 fields in '0.5 0.02 0'; expected 4"},
    {"density = 7800", "density = 0", RCB_ERR_ARG, "density (kg/m^3) = 0",
     "expected a positive value"},
    {"young = 2e11", "young = -2e11", RCB_ERR_ARG, "young (Pa) = -2e+11", "positive"},
    {"poisson = 0.3", "poisson = 0.5", RCB_ERR_ARG, "poisson = 0.5",
     "expected 0 <= poisson < 0.5"},
    {"shear_factor = 0.9", "shear_factor = 5", RCB_ERR_ARG, "shear_factor = 5", NULL},
    {"mass = 2", "mass = -2", RCB_ERR_ARG, "disk 'D': mass (kg) = -2",
     "expected a value >= 0"},
    {"kt = 1e5", "kt = -1e5", RCB_ERR_ARG, "kt (N/m) = -100000", ">= 0"},
    /* ---- NaN, Inf, not numbers ---- */
    {"segment = 0.5 0.02 0 5", "segment = 0.5 nan 0 5", RCB_ERR_PARSE, "'nan' is not a finite",
     "expected outer diameter in m"},
    {"kxx = 1e7", "kxx = inf", RCB_ERR_PARSE, "<t>:18: [bearing B1] kxx",
     "'inf' is not a finite number"},
    {"kxx = 1e7", "kxx = -Infinity", RCB_ERR_PARSE, "not a finite number", NULL},
    {"kxx = 1e7", "kxx = 1e400", RCB_ERR_PARSE, "'1e400' is not a finite number", NULL},
    {"kxx = 1e7", "kxx = abc", RCB_ERR_PARSE, "'abc' is not a number",
     "expected stiffness in N/m"},
    {"kxx = 1e7", "kxx = 1e7 2e7", RCB_ERR_PARSE, "2 values but the bearing has no speed table",
     NULL},
    {"amount = 1e-4", "amount = NaN", RCB_ERR_PARSE, "[unbalance U] amount", "not a finite"},
    /* ---- positions, stations, couplings ---- */
    {"at = A 0.1", "at = A 0.9", RCB_ERR_MODEL, "<t>:16: [bearing B1]",
     "z = 0.9 m is outside shaft 'A' (0 to 0.5 m)"},
    {"at = B 0.8", "at = B -0.1", RCB_ERR_MODEL, "[station P]", "outside shaft 'B'"},
    {"at = A 0.1", "at = A 0.15", RCB_ERR_MODEL, "is not on a node of shaft 'A'",
     "nearest nodes at 0.1 m and 0.2 m"},
    {"at = A 0.1", "at = Z 0.1", RCB_ERR_NOT_FOUND, "shaft 'Z' is not defined", NULL},
    {"at = A 0.1", "at = A", RCB_ERR_PARSE, "'A' is a shaft, not a position on it", NULL},
    {"at = A 0.1", "at = A middle", RCB_ERR_PARSE, "'middle' is not a number", NULL},
    {"at = D", "at = Q", RCB_ERR_NOT_FOUND, "'Q' is not a defined disk", "did you mean D?"},
    {"between = A end, B start", "between = A end, Q start", RCB_ERR_NOT_FOUND,
     "<t>:31: [coupling C] between", "shaft 'Q' is not defined"},
    {"between = A end, B start", "between = A end, A start", RCB_ERR_MODEL,
     "both stations are on shaft 'A'", NULL},
    {"between = A end, B start", "between = A end", RCB_ERR_PARSE, "has only one field",
     "two stations"},
    {"at = B 0.8", "at = B 0.8\n[uff]\nmap = 7 NOPE", RCB_ERR_NOT_FOUND, "uff map",
     "'NOPE', which is not a station"},
};

/* Valid but implausible: loads, with one warning naming the item's line. */
typedef struct warn_case {
  const char *from, *to;
  const char *p1, *p2;
} warn_case;

static const warn_case WARN_CASES[] = {
    {"density = 7800", "density = 7.8", "<t>:3: material 'steel': density = 7.8 kg/m^3",
     "g/cm^3"},
    {"density = 7800", "density = 78000", "density = 78000 kg/m^3", "outside the plausible"},
    {"young = 2e11", "young = 200e3", "<t>:3: material 'steel': young = 200000 Pa",
     "MPa or GPa"},
    {"young = 2e11", "young = 2e14", "young = 2e+14 Pa", NULL},
    {"segment = 0.5 0.02 0 5", "segment = 0.5 20 0 5",
     "<t>:7: shaft 'A': segment 1 outer diameter = 20 m", "mm where m is meant"},
    {"segment = 0.5 0.02 0 5", "segment = 0.5 0.0005 0 5", "outer diameter = 0.0005 m",
     "outside the plausible 0.001 to 5 m"},
    /* issue #17: layouts and magnitudes that compute but are likely wrong */
    {"between = A end, B start", "between = A start, B end",
     "<t>:29: coupling 'C': joins the start of shaft 'A' (z = 0 m) to the end of shaft 'B'",
     "'between = A end, B start'"},
    {"between = A end, B start", "between = A 0.3, B start",
     "coupling 'C': station a (shaft 'A', z = 0.3 m) is not an end", NULL},
    {"amount = 1e-4", "amount = 150", "<t>:34: unbalance 'U': amount = 150 kg m", "g mm"},
};

static char *subst(const char *base, const char *from, const char *to) {
  const char *p = strstr(base, from);
  size_t nb = strlen(base), nf = strlen(from), nt = strlen(to);
  char *out;
  if (!p) fail_msg("test bug: '%s' not in the base model", from);
  out = malloc(nb - nf + nt + 1);
  assert_non_null(out);
  memcpy(out, base, (size_t)(p - base));
  memcpy(out + (p - base), to, nt);
  memcpy(out + (p - base) + nt, p + nf, nb - (size_t)(p - base) - nf + 1);
  return out;
}

static void expect_msg(const char *what, const char *msg, const char *p1, const char *p2) {
  if ((p1 && !strstr(msg, p1)) || (p2 && !strstr(msg, p2)))
    fail_msg("%s: message '%s' lacks '%s' / '%s'", what, msg, p1 ? p1 : "", p2 ? p2 : "");
}

static void test_base_is_valid(void **state) {
  rcb_model *m = NULL;
  (void)state;
  assert_int_equal(rcb_model_create(&m, NULL), RCB_OK);
  if (rcb_model_load_string(m, BASE, "<t>")) fail_msg("%s", rcb_model_errmsg(m));
  assert_int_equal(rcb_model_node_count(m), 12);
  assert_int_equal(rcb_model_warning_count(m), 0);
  assert_null(rcb_model_warning(m, 0));
  rcb_model_destroy(m);
}

static void test_ini_catalogue(void **state) {
  size_t k, n = sizeof INI_CASES / sizeof INI_CASES[0], nbad = 0;
  (void)state;
  for (k = 0; k < n; k++) {
    const ini_case *c = &INI_CASES[k];
    char *text = subst(BASE, c->from, c->to), what[64];
    rcb_model *m = NULL;
    rcb_status st;
    snprintf(what, sizeof what, "INI case %zu", k + 1);
    assert_int_equal(rcb_model_create(&m, NULL), RCB_OK);
    st = rcb_model_load_string(m, text, "<t>");
    /* report every mismatch before failing */
    if (st != c->st || (c->p1 && !strstr(rcb_model_errmsg(m), c->p1)) ||
        (c->p2 && !strstr(rcb_model_errmsg(m), c->p2))) {
      print_error("%s ('%s' -> '%s'): status %s, expected %s; message '%s'\n", what, c->from,
                  c->to, rcb_status_str(st), rcb_status_str(c->st), rcb_model_errmsg(m));
      nbad++;
    }
    /* the failed load left an empty model: the good text loads into it */
    assert_int_equal(rcb_model_node_count(m), 0);
    if (rcb_model_load_string(m, BASE, "<t>") != RCB_OK)
      fail_msg("%s: reload after failure: %s", what, rcb_model_errmsg(m));
    assert_int_equal(rcb_model_node_count(m), 12);
    rcb_model_destroy(m);
    free(text);
  }
  assert_int_equal(nbad, 0);
  assert_true(n >= 40);
}

static void test_empty_and_binary_text(void **state) {
  rcb_model *m = NULL;
  (void)state;
  assert_int_equal(rcb_model_create(&m, NULL), RCB_OK);
  assert_int_equal(rcb_model_load_string(m, "", "<t>"), RCB_ERR_MODEL);
  expect_msg("empty", rcb_model_errmsg(m), "the model has no shaft", NULL);
  rcb_model_destroy(m);
  assert_int_equal(rcb_model_create(&m, NULL), RCB_OK);
  assert_int_equal(rcb_model_load_file(m, RCB_EXAMPLES_DIR "/no_such_model.ini"), RCB_ERR_IO);
  expect_msg("missing file", rcb_model_errmsg(m), "no_such_model.ini", "cannot open");
  rcb_model_destroy(m);
}

static void test_warning_catalogue(void **state) {
  size_t k, n = sizeof WARN_CASES / sizeof WARN_CASES[0];
  (void)state;
  for (k = 0; k < n; k++) {
    const warn_case *c = &WARN_CASES[k];
    char *text = subst(BASE, c->from, c->to), what[64];
    rcb_model *m = NULL;
    snprintf(what, sizeof what, "warning case %zu", k + 1);
    assert_int_equal(rcb_model_create(&m, NULL), RCB_OK);
    if (rcb_model_load_string(m, text, "<t>"))
      fail_msg("%s: load failed: %s", what, rcb_model_errmsg(m));
    if (rcb_model_warning_count(m) != 1)
      fail_msg("%s: %zu warnings, expected 1", what, rcb_model_warning_count(m));
    expect_msg(what, rcb_model_warning(m, 0), c->p1, c->p2);
    rcb_model_destroy(m);
    free(text);
  }
}

/* Two shafts without a coupling: legal (two machines), but most likely a
 * coupling placed wrong: a warning naming the separate shaft. Also through the
 * builder API, where no file line applies. */
static void test_unconnected_shafts(void **state) {
  char *t1 = subst(BASE, "[coupling C]\nmodel = nelson_crandall_1\nbetween = A end, B "
                         "start\nkt = 1e5\nkr = 1e3\n",
                   "");
  rcb_model *m = NULL;
  rcb_bearing_coefs bc = {1e7, 0, 0, 1e7, 0, 0, 0, 0};
  (void)state;
  assert_int_equal(rcb_model_create(&m, NULL), RCB_OK);
  if (rcb_model_load_string(m, t1, "<t>")) fail_msg("%s", rcb_model_errmsg(m));
  assert_int_equal(rcb_model_warning_count(m), 1);
  expect_msg("unconnected", rcb_model_warning(m, 0), "<t>:11: shaft 'B'",
             "2 separate rotors");
  rcb_model_destroy(m);
  free(t1);

  assert_int_equal(rcb_model_create(&m, NULL), RCB_OK);
  assert_int_equal(rcb_model_add_material(m, "s", 7800, 2e11, 0.3), RCB_OK);
  assert_int_equal(rcb_model_add_shaft(m, "A", "s", 0.0, 0.9), RCB_OK);
  assert_int_equal(rcb_model_add_shaft(m, "B", "s", 1.0, 0.9), RCB_OK);
  assert_int_equal(rcb_model_add_shaft(m, "E", "s", 2.0, 0.9), RCB_OK);
  assert_int_equal(rcb_model_add_segment(m, "A", 0.5, 0.02, 0, 2), RCB_OK);
  assert_int_equal(rcb_model_add_segment(m, "B", 0.5, 0.02, 0, 2), RCB_OK);
  assert_int_equal(rcb_model_add_segment(m, "E", 0.5, 0.02, 0, 2), RCB_OK);
  assert_int_equal(rcb_model_add_bearing(m, "B1", "A", 0.0, &bc), RCB_OK);
  /* E joined to A (through a coupling), B alone: 2 rotors, one warning for B;
   * the coupling reaches over B (issue #17), and B has no bearing */
  assert_int_equal(rcb_model_add_coupling(m, "C", RCB_COUPLING_RIGID, "E", 2.0, "A", 0.5, NULL),
                   RCB_OK);
  assert_int_equal(rcb_model_finalize(m), RCB_OK);
  assert_int_equal(rcb_model_warning_count(m), 3);
  expect_msg("builder", rcb_model_warning(m, 0), "shaft 'B': not joined to shaft 'A'",
             "2 separate rotors");
  expect_msg("builder", rcb_model_warning(m, 1), "coupling 'C': shaft 'B' (1 to 1.5 m) lies "
             "between the ends it joins", "expected adjacent shafts");
  expect_msg("builder", rcb_model_warning(m, 2), "shaft 'B': the rotor train", "no bearing");
  rcb_model_destroy(m);
}

/* Fuzz regression (fuzz_ini, crash-8761ec...): a shaft named with bytes
 * >= 0x80 loaded, but rcb_model_write_ini refused the name, so a loaded model
 * could not be written back. Now UTF-8 names load and write back, and names
 * the writer cannot represent (control characters, [ ] ; , = :) are refused
 * by the loader (the builder API keeps accepting them; the writer refuses
 * them with a message, see test_params). */
static void test_names_round_trip(void **state) {
  static const char *const bad[] = {"[disk D=E]", "[disk D:E]", "[disk D,E]", "[disk D\x01E]"};
  char *text = subst(BASE, "[shaft B]", "[shaft W\xc3\xa4lle]"), *t2, *ini;
  rcb_model *m = NULL, *m2 = NULL;
  size_t need = 0, k;
  (void)state;
  t2 = subst(text, "at = B 1.0", "at = W\xc3\xa4lle 1.0");
  free(text);
  text = subst(t2, "between = A end, B start", "between = A end, W\xc3\xa4lle start");
  free(t2);
  t2 = subst(text, "at = B 0.8", "at = W\xc3\xa4lle 0.8");
  m = rcb_test_model_from_string(t2);
  assert_int_equal(rcb_model_write_ini(m, NULL, 0, &need), RCB_ERR_WORKSPACE);
  ini = malloc(need);
  assert_non_null(ini);
  assert_int_equal(rcb_model_write_ini(m, ini, need, &need), RCB_OK);
  m2 = rcb_test_model_from_string(ini);
  assert_int_equal(rcb_model_dof_count(m2), rcb_model_dof_count(m));
  rcb_model_destroy(m2);
  rcb_model_destroy(m);
  free(ini);
  free(text);
  free(t2);
  for (k = 0; k < sizeof bad / sizeof bad[0]; k++) {
    text = subst(BASE, "[disk D]", bad[k]);
    assert_int_equal(rcb_model_create(&m, NULL), RCB_OK);
    assert_int_equal(rcb_model_load_string(m, text, "<t>"), RCB_ERR_PARSE);
    expect_msg(bad[k], rcb_model_errmsg(m), "<t>:24:", "cannot be used in a name");
    rcb_model_destroy(m);
    free(text);
  }
}

/* ---------------------------------------------------------- analyses -- */

/* All free (no bearing) at omega = 0: K is singular (rigid-body modes). */
/* BASE with several substitutions applied in turn (each its first occurrence). */
static char *subst_all(const char *const *pairs, size_t n) {
  char *t = subst(BASE, pairs[0], pairs[1]), *u;
  size_t k;
  for (k = 2; k + 1 < n; k += 2) {
    u = subst(t, pairs[k], pairs[k + 1]);
    free(t);
    t = u;
  }
  return t;
}

static rcb_model *load_warned(const char *text, size_t nwarn) {
  rcb_model *m = NULL;
  size_t w;
  assert_int_equal(rcb_model_create(&m, NULL), RCB_OK);
  if (rcb_model_load_string(m, text, "<t>")) fail_msg("load failed: %s", rcb_model_errmsg(m));
  if (rcb_model_warning_count(m) != nwarn) {
    for (w = 0; w < rcb_model_warning_count(m); w++)
      print_error("warning %zu: %s\n", w + 1, rcb_model_warning(m, w));
    fail_msg("%zu warnings, expected %zu", rcb_model_warning_count(m), nwarn);
  }
  return m;
}

/* Layouts that compute but are likely wrong (issue #17), each with the
 * warnings it must give; BASE itself gives none (test_base_is_valid). */
static void test_plausible_layouts(void **state) {
  static const char *const overlap[] = {"start = 0.6", "start = 0.4", "at = B 1.0",
                                        "at = B 0.8"};
  static const char *const zero[] = {"kxx = 1e7", "kxx = 0", "kxx = 1e7", "kxx = 0",
                                     "kyy = 1e7", "kyy = 0", "kyy = 1e7", "kyy = 0",
                                     "kt = 1e5",  "kt = 0",  "kr = 1e3",  "kr = 0"};
  static const char *const alone[] = {
      "[bearing B2]\nat = B 1.0\nkxx = 1e7\nkyy = 1e7\n", "",
      "[coupling C]\nmodel = nelson_crandall_1\nbetween = A end, B start\nkt = 1e5\nkr = "
      "1e3\n", ""};
  char *t;
  rcb_model *m;
  (void)state;
  /* B starts inside A: the shafts overlap, and the coupling's ends no longer face */
  t = subst_all(overlap, 4);
  m = load_warned(t, 2);
  expect_msg("overlap", rcb_model_warning(m, 0), "coupling 'C': joins the end of shaft 'A'",
             "do not face each other");
  expect_msg("overlap", rcb_model_warning(m, 1), "shaft 'B': overlaps shaft 'A' from z = 0.4 "
             "to 0.5 m", "check the 'start' keys");
  rcb_model_destroy(m);
  free(t);
  /* every stiffness 0 */
  t = subst_all(zero, sizeof zero / sizeof zero[0]);
  m = load_warned(t, 1);
  expect_msg("zero", rcb_model_warning(m, 0), "every bearing and coupling stiffness is zero",
             "2 bearings, 1 couplings");
  rcb_model_destroy(m);
  free(t);
  /* B neither coupled nor on a bearing: separate rotor, and floating free */
  t = subst_all(alone, 4);
  m = load_warned(t, 2);
  expect_msg("alone", rcb_model_warning(m, 0), "shaft 'B': not joined", NULL);
  expect_msg("alone", rcb_model_warning(m, 1), "shaft 'B': the rotor train it belongs to has "
             "no bearing", "floats free");
  rcb_model_destroy(m);
  free(t);
  /* the free-free example (no bearing at all, on purpose) is not warned */
  m = rcb_test_model_from_example("paper_freefree.ini");
  assert_int_equal(rcb_model_warning_count(m), 0);
  rcb_model_destroy(m);
}

static void test_free_free_at_zero(void **state) {
  rcb_model *m = rcb_test_model_from_example("paper_freefree.ini");
  rcb_frf *f = NULL;
  rcb_dof d;
  rcb_complex H[1];
  int s;
  (void)state;
  assert_int_equal(rcb_model_find_dof(m, "DA.x", &d), RCB_OK);
  for (s = 1; s <= 2; s++) {
    assert_int_equal(rcb_frf_create(&f, m, 1, &d, 1, &d, (rcb_solver_kind)s, NULL), RCB_OK);
    assert_int_equal(rcb_frf_eval(f, 0.0, 0.0, RCB_RECEPTANCE, H), RCB_ERR_SINGULAR);
    expect_msg("free-free", rcb_frf_errmsg(f), "singular at 0 rad/s", "free-free");
    /* the object stays usable: away from 0 the FRF is finite */
    assert_int_equal(rcb_frf_eval(f, 100.0, 0.0, RCB_RECEPTANCE, H), RCB_OK);
    assert_true(isfinite(creal(H[0])) && isfinite(cimag(H[0])));
    rcb_frf_destroy(f);
  }
  rcb_model_destroy(m);
}

static void test_bad_frequencies(void **state) {
  rcb_model *m = rcb_test_model_from_string(BASE);
  rcb_frf *f = NULL;
  rcb_dof d;
  rcb_complex H[1];
  (void)state;
  assert_int_equal(rcb_model_find_dof(m, "D.x", &d), RCB_OK);
  assert_int_equal(rcb_frf_create(&f, m, 1, &d, 1, &d, RCB_SOLVER_AUTO, NULL), RCB_OK);
  assert_int_equal(rcb_frf_eval(f, NAN, 0.0, RCB_RECEPTANCE, H), RCB_ERR_ARG);
  expect_msg("nan", rcb_frf_errmsg(f), "expected finite", NULL);
  assert_int_equal(rcb_frf_eval(f, -1.0, 0.0, RCB_RECEPTANCE, H), RCB_ERR_ARG);
  assert_int_equal(rcb_frf_eval(f, 1.0, INFINITY, RCB_RECEPTANCE, H), RCB_ERR_ARG);
  assert_int_equal(rcb_frf_unbalance(f, -5.0, H), RCB_ERR_ARG);
  expect_msg("negative speed", rcb_frf_errmsg(f), "expected a finite value >= 0", NULL);
  assert_int_equal(rcb_model_find_dof(m, "NOPE.x", &d), RCB_ERR_NOT_FOUND);
  expect_msg("channel", rcb_model_errmsg(m), "no station named 'NOPE'", NULL);
  assert_int_equal(rcb_model_find_dof(m, "D.z", &d), RCB_ERR_ARG);
  expect_msg("direction", rcb_model_errmsg(m), "expected x, y, rx or ry", NULL);
  rcb_frf_destroy(f);
  rcb_model_destroy(m);
}

/* ------------------------------------------------- measurement files -- */

static void write_bytes(const char *path, const char *text, size_t n) {
  FILE *fp = fopen(path, "wb");
  assert_non_null(fp);
  assert_int_equal(fwrite(text, 1, n, fp), n);
  fclose(fp);
}

static char *read_all(const char *path, size_t *n) {
  FILE *fp = fopen(path, "rb");
  char *buf;
  long size;
  assert_non_null(fp);
  fseek(fp, 0, SEEK_END);
  size = ftell(fp);
  rewind(fp);
  buf = malloc((size_t)size + 1);
  assert_non_null(buf);
  assert_int_equal(fread(buf, 1, (size_t)size, fp), (size_t)size);
  buf[size] = '\0';
  fclose(fp);
  *n = (size_t)size;
  return buf;
}

static const rcb_uff_node MAP[] = {{1, "D", NULL, NULL}, {2, "P", NULL, NULL}};

/* A 5-point FRF D.x/D.x, P.y/D.x of the base model, written as UFF58. */
static void write_sample_uff(const char *path, int binary) {
  rcb_model *m = rcb_test_model_from_string(BASE);
  rcb_meas *ms = NULL;
  rcb_frf *f = NULL;
  rcb_dof d[2];
  double x[5];
  rcb_complex H[2 * 5], c0[5], c1[5];
  size_t i;
  assert_int_equal(rcb_model_find_dof(m, "D.x", &d[0]), RCB_OK);
  assert_int_equal(rcb_model_find_dof(m, "P.y", &d[1]), RCB_OK);
  assert_int_equal(rcb_frf_create(&f, m, 2, d, 1, d, RCB_SOLVER_AUTO, NULL), RCB_OK);
  for (i = 0; i < 5; i++) {
    x[i] = 100.0 * (double)(i + 1);
    assert_int_equal(rcb_frf_eval(f, x[i], 0.0, RCB_RECEPTANCE, H + 2 * i), RCB_OK);
    c0[i] = H[2 * i];
    c1[i] = H[2 * i + 1];
  }
  assert_int_equal(rcb_meas_create(&ms, NULL), RCB_OK);
  assert_int_equal(rcb_meas_set_grid(ms, RCB_MEAS_FRF, 5, x, 0.0), RCB_OK);
  assert_int_equal(rcb_meas_add_channel(ms, "D.x", "D.x", RCB_RECEPTANCE, c0), RCB_OK);
  assert_int_equal(rcb_meas_add_channel(ms, "P.y", "D.x", RCB_RECEPTANCE, c1), RCB_OK);
  assert_int_equal(rcb_meas_write_uff(ms, path, binary, 2, MAP), RCB_OK);
  rcb_meas_destroy(ms);
  rcb_frf_destroy(f);
  rcb_model_destroy(m);
}

static void expect_read(const char *path, int uff, rcb_status want, const char *p1,
                        const char *p2) {
  rcb_meas *ms = NULL;
  rcb_status st;
  assert_int_equal(rcb_meas_create(&ms, NULL), RCB_OK);
  st = uff ? rcb_meas_read_uff(ms, path, 2, MAP) : rcb_meas_read_csv(ms, path);
  if (st != want)
    fail_msg("%s: status %s, expected %s; message '%s'", path, rcb_status_str(st),
             rcb_status_str(want), rcb_meas_errmsg(ms));
  expect_msg(path, rcb_meas_errmsg(ms), p1, p2);
  /* nothing half-read is kept */
  if (want != RCB_OK) assert_int_equal(rcb_meas_channel_count(ms), 0);
  rcb_meas_destroy(ms);
}

/* Replace the first `from` after offset `after` in buf (same length). */
static void patch(char *buf, size_t after, const char *from, const char *to) {
  char *p = strstr(buf + after, from);
  assert_non_null(p);
  assert_int_equal(strlen(from), strlen(to));
  memcpy(p, to, strlen(to));
}

static void test_bad_uff_files(void **state) {
  const char *good = rcb_test_tmp_path("good.uff");
  size_t n;
  char *buf;
  (void)state;
  write_sample_uff(good, 0);
  expect_read(good, 1, RCB_OK, NULL, NULL);
  buf = read_all(good, &n);
  /* truncated: cut in the middle of the second record's values, and inside
   * the first record's header lines */
  write_bytes(rcb_test_tmp_path("cut.uff"), buf, n - 200);
  expect_read(rcb_test_tmp_path("cut.uff"), 1, RCB_ERR_PARSE, "cut.uff:", "truncated");
  write_bytes(rcb_test_tmp_path("cut2.uff"), buf, 150);
  expect_read(rcb_test_tmp_path("cut2.uff"), 1, RCB_ERR_PARSE, "cut2.uff:", "truncated");
  /* mislabelled: the dataset number is not a number */
  {
    char *b2 = malloc(n + 1);
    memcpy(b2, buf, n + 1);
    patch(b2, 0, "    -1\n    58", "    -1\n    5x");
    write_bytes(rcb_test_tmp_path("label.uff"), b2, n);
    expect_read(rcb_test_tmp_path("label.uff"), 1, RCB_ERR_PARSE, "label.uff:2:", "is not a number");
    /* ordinate labelled with an unknown data type (record 9) */
    memcpy(b2, buf, n + 1);
    patch(b2, 0, "\n         8    0    0    0 Displacement",
          "\n        99    0    0    0 Displacement");
    write_bytes(rcb_test_tmp_path("units.uff"), b2, n);
    expect_read(rcb_test_tmp_path("units.uff"), 1, RCB_ERR_PARSE, "units.uff:", "ordinate data type 99");
    /* response direction 3 (z, not a lateral DOF) in record 6: that record
     * is skipped with a warning, the other one read (issue #25) */
    memcpy(b2, buf, n + 1);
    patch(b2, 0, " D         1   1          D", " D         1   3          D");
    write_bytes(rcb_test_tmp_path("dir.uff"), b2, n);
    {
      rcb_meas *ms = NULL;
      assert_int_equal(rcb_meas_create(&ms, NULL), RCB_OK);
      assert_int_equal(rcb_meas_read_uff(ms, rcb_test_tmp_path("dir.uff"), 2, MAP), RCB_OK);
      assert_int_equal(rcb_meas_channel_count(ms), 1);
      expect_msg("dir.uff", rcb_meas_warning(ms, 0), "dir.uff:8:", "axial (direction 3");
      rcb_meas_destroy(ms);
    }
    free(b2);
  }
  /* mislabelled: a dataset 58 with the block delimiter missing */
  write_bytes(rcb_test_tmp_path("nodelim.uff"), buf + 7, n - 7);
  expect_read(rcb_test_tmp_path("nodelim.uff"), 1, RCB_ERR_PARSE, "nodelim.uff:1:", "expected '    -1'");
  /* no dataset 58 at all */
  write_bytes(rcb_test_tmp_path("other.uff"), "    -1\n   151\nheader\n    -1\n", 28);
  expect_read(rcb_test_tmp_path("other.uff"), 1, RCB_ERR_PARSE, "no dataset 58 record", NULL);
  /* empty and missing files */
  write_bytes(rcb_test_tmp_path("empty.uff"), "", 0);
  expect_read(rcb_test_tmp_path("empty.uff"), 1, RCB_ERR_PARSE, "empty.uff", NULL);
  expect_read(rcb_test_tmp_path("missing.uff"), 1, RCB_ERR_IO, "missing.uff", NULL);
  free(buf);
  /* binary 58b cut inside its data */
  write_sample_uff(rcb_test_tmp_path("good.bin.uff"), 1);
  buf = read_all(rcb_test_tmp_path("good.bin.uff"), &n);
  write_bytes(rcb_test_tmp_path("cut.bin.uff"), buf, n - 40);
  expect_read(rcb_test_tmp_path("cut.bin.uff"), 1, RCB_ERR_PARSE, "cut.bin.uff:", "truncated");
  free(buf);
}

static void test_bad_csv_files(void **state) {
  static const struct {
    const char *text, *p1, *p2;
  } cases[] = {
      {"freq_hz\n1\n2\n", "no channel columns", NULL},
      {"freq_hz,D.x/D.x re\n1,2\n", "column 2", "pair"},
      {"freq_hz,D.x/D.x re,D.x/D.x im\n1,2\n", "bad.csv:2:", "2 fields, the header has 3"},
      {"freq_hz,D.x/D.x re,D.x/D.x im\n1,2,3,4\n", "bad.csv:2:", "4 fields, the header has 3"},
      {"D.x/D.x re,D.x/D.x im\n1,2\n", "bad.csv:1:", "first column"},
      {"freq_hz,D.x/D.x re,D.x/D.x im\n1,2,inf\n", "bad.csv:2:", "not finite"},
      {"", "no header line", NULL},
      /* issue #17: spellings that leave a unit open, node numbers as stations */
      {"frequency,D.x/D.x re,D.x/D.x im\n1,2,3\n", "gives no unit", "rename it freq_hz"},
      {"omega_rad_s,D.x/D.x re,D.x/D.x im\n1,2,3\n", "rad/s is not read", "freq_hz"},
      {"speed,D.x re,D.x im\n1,2,3\n", "gives no unit", "rename it rpm"},
      {"freq_hz,D.x/D.x mag,D.x/D.x phase\n1,2,3\n", "without the unit degrees",
       "\"D.x/D.x phase_deg\""},
      {"freq_hz,3.x/10.y re,3.x/10.y im\n1,2,3\n", "station '3' is a number",
       "or to '#3' for model node 3"},
      {"freq_hz,D.x/10.y re,D.x/10.y im\n1,2,3\n", "station '10' is a number", NULL},
  };
  size_t k;
  (void)state;
  for (k = 0; k < sizeof cases / sizeof cases[0]; k++) {
    write_bytes(rcb_test_tmp_path("bad.csv"), cases[k].text, strlen(cases[k].text));
    expect_read(rcb_test_tmp_path("bad.csv"), 0, RCB_ERR_PARSE, cases[k].p1, cases[k].p2);
  }
  expect_read(rcb_test_tmp_path("none.csv"), 0, RCB_ERR_IO, "none.csv", NULL);
}

/* ---------------------------------------------------------------- fits -- */

static rcb_meas *small_meas(const rcb_model *m) {
  rcb_meas *ms = NULL;
  rcb_frf *f = NULL;
  rcb_dof d;
  double x[4] = {100.0, 200.0, 300.0, 400.0};
  rcb_complex H[4];
  size_t i;
  assert_int_equal(rcb_model_find_dof(m, "D.x", &d), RCB_OK);
  assert_int_equal(rcb_frf_create(&f, m, 1, &d, 1, &d, RCB_SOLVER_AUTO, NULL), RCB_OK);
  for (i = 0; i < 4; i++)
    assert_int_equal(rcb_frf_eval(f, x[i], 0.0, RCB_RECEPTANCE, &H[i]), RCB_OK);
  assert_int_equal(rcb_meas_create(&ms, NULL), RCB_OK);
  assert_int_equal(rcb_meas_set_grid(ms, RCB_MEAS_FRF, 4, x, 0.0), RCB_OK);
  assert_int_equal(rcb_meas_add_channel(ms, "D.x", "D.x", RCB_RECEPTANCE, H), RCB_OK);
  rcb_frf_destroy(f);
  return ms;
}

static void test_bad_fits(void **state) {
  rcb_model *m = rcb_test_model_from_string(BASE);
  rcb_meas *ms = small_meas(m);
  rcb_fit *f = NULL;
  double kt0, kt;
  (void)state;
  assert_int_equal(rcb_model_get_param(m, "coupling.C.kt", &kt0), RCB_OK);
  assert_int_equal(rcb_fit_create(&f, m, ms, NULL), RCB_OK);
  /* no free parameter */
  assert_int_equal(rcb_fit_run(f), RCB_ERR_ARG);
  expect_msg("no param", rcb_fit_errmsg(f), "no parameter to fit", NULL);
  /* bounds that exclude the start, inverted bounds, NaN bounds, log with lo <= 0 */
  assert_int_equal(rcb_fit_add_param(f, "coupling.C.kt", 1e6, 1e7, 0), RCB_ERR_ARG);
  expect_msg("bounds", rcb_fit_errmsg(f), "start value 100000 is outside the bounds", NULL);
  assert_int_equal(rcb_fit_add_param(f, "coupling.C.kt", 1e6, 1e3, 0), RCB_ERR_ARG);
  expect_msg("inverted", rcb_fit_errmsg(f), "expected lo < hi", NULL);
  assert_int_equal(rcb_fit_add_param(f, "coupling.C.kt", NAN, 1e7, 0), RCB_ERR_ARG);
  assert_int_equal(rcb_fit_add_param(f, "coupling.C.kt", 0.0, 1e7, 1), RCB_ERR_ARG);
  expect_msg("log", rcb_fit_errmsg(f), "lower bound > 0", NULL);
  /* unknown parameter, and a parameter the coupling model does not use */
  assert_int_equal(rcb_fit_add_param(f, "coupling.C.zz", 1, 2, 0), RCB_ERR_NOT_FOUND);
  expect_msg("unknown", rcb_fit_errmsg(f), "coupling.C.zz", NULL);
  assert_int_equal(rcb_fit_add_param(f, "coupling.C.ct", 0, 2, 0), RCB_ERR_NOT_FOUND);
  /* still no parameter: the run is refused, the model untouched */
  assert_int_equal(rcb_fit_run(f), RCB_ERR_ARG);
  assert_int_equal(rcb_model_get_param(m, "coupling.C.kt", &kt), RCB_OK);
  assert_true(kt == kt0);
  assert_int_equal(rcb_fit_param_count(f), 0);
  rcb_fit_destroy(f);
  rcb_meas_destroy(ms);
  rcb_model_destroy(m);
}

/* A measurement on a station the model lacks: refused at create. */
static void test_fit_unknown_channel(void **state) {
  rcb_model *m = rcb_test_model_from_string(BASE);
  rcb_meas *ms = NULL;
  rcb_fit *f = NULL;
  double x[2] = {10.0, 20.0};
  rcb_complex d[2] = {1.0, 2.0};
  (void)state;
  assert_int_equal(rcb_meas_create(&ms, NULL), RCB_OK);
  assert_int_equal(rcb_meas_set_grid(ms, RCB_MEAS_FRF, 2, x, 0.0), RCB_OK);
  assert_int_equal(rcb_meas_add_channel(ms, "NOPE.x", "D.x", RCB_RECEPTANCE, d), RCB_OK);
  assert_int_equal(rcb_fit_create(&f, m, ms, NULL), RCB_ERR_NOT_FOUND);
  expect_msg("fit channel", f ? rcb_fit_errmsg(f) : "", "NOPE", NULL);
  rcb_fit_destroy(f);
  rcb_meas_destroy(ms);
  rcb_model_destroy(m);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_base_is_valid),       cmocka_unit_test(test_ini_catalogue),
      cmocka_unit_test(test_empty_and_binary_text), cmocka_unit_test(test_warning_catalogue),
      cmocka_unit_test(test_unconnected_shafts),  cmocka_unit_test(test_names_round_trip),
      cmocka_unit_test(test_free_free_at_zero),
      cmocka_unit_test(test_bad_frequencies),     cmocka_unit_test(test_bad_uff_files),
      cmocka_unit_test(test_plausible_layouts),
      cmocka_unit_test(test_bad_csv_files),       cmocka_unit_test(test_bad_fits),
      cmocka_unit_test(test_fit_unknown_channel),
  };
  return cmocka_run_group_tests(tests, rcb_test_setup_tmpdir, rcb_test_teardown_tmpdir);
}
