/*
 * The signals CSV reader's one-pass streaming (signals/signals_csv.c, issue
 * #25): a file of several read buffers, whose numbers must come back as the
 * very doubles that were printed with %.17g (which names each double
 * exactly), with CRLF endings, comment and blank lines among the rows and no
 * final newline; the line number of a bad field far past the first buffer; a
 * line longer than the buffer; and every allocation failing in turn.
 * Issue #35 item 6, no silent cuts: a units line of 10 kB, the channel limit
 * (256 read, 257 refused), names and units at and past their limits, and
 * times whose spacing is not a finite number.
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

#include "rcb/rcb.h"
#include "rcb_test_util.h"

#define ROWS 60000 /* about 3 MB of text: three reads of the 1 MiB buffer */
#define RATE 2048.0

/* sample i of channel c: magnitudes from 1e-9 to 1e5, both signs */
static double sample(size_t i, int c) {
  uint64_t z = (uint64_t)i * 0x9E3779B97F4A7C15ull + (uint64_t)c * 0xBF58476D1CE4E5B9ull;
  double u;
  z = (z ^ (z >> 31)) * 0x94D049BB133111EBull;
  z ^= z >> 29;
  u = (double)(z >> 11) * 0x1p-53;             /* [0, 1) */
  return (u - 0.5) * pow(10.0, (double)(z % 15) - 9.0);
}

/* The file; bad_row (1-based, 0: none) gets "x" for its second field.
 * Returns the line number of that row. */
static size_t write_big(const char *path, size_t bad_row) {
  FILE *fp = fopen(path, "wb");
  size_t i, line = 3, bad_line = 0;
  assert_non_null(fp);
  fputs("# streamed\n# units = m,m\ntime_s,DA.x,DB.y\n", fp);
  for (i = 0; i < ROWS; i++) {
    if (i % 9999 == 5000) {
      fputs("# a comment among the rows\n\n", fp);
      line += 2;
    }
    line++;
    if (i + 1 == bad_row) {
      fprintf(fp, "%.17g,x,%.17g\n", (double)i / RATE, sample(i, 1));
      bad_line = line;
      continue;
    }
    fprintf(fp, "%.17g,%.17g,%.17g%s", (double)i / RATE, sample(i, 0), sample(i, 1),
            i + 1 == ROWS ? "" : (i % 3 ? "\n" : "\r\n"));
  }
  fclose(fp);
  return bad_line;
}

static void test_csv_streamed_exact(void **state) {
  const char *p = rcb_test_tmp_path("big.csv");
  rcb_signals *s;
  const double *v0, *v1;
  size_t i, wrong = 0;
  (void)state;
  write_big(p, 0);
  assert_int_equal(rcb_signals_create(&s, NULL), RCB_OK);
  if (rcb_signals_read_csv(s, p)) fail_msg("%s", rcb_signals_errmsg(s));
  assert_int_equal(rcb_signals_length(s), ROWS);
  assert_true(fabs(rcb_signals_rate(s) - RATE) < 1e-9 * RATE);
  assert_int_equal(rcb_signals_channel(s, 0, NULL, NULL, &v0), RCB_OK);
  assert_int_equal(rcb_signals_channel(s, 1, NULL, NULL, &v1), RCB_OK);
  for (i = 0; i < ROWS; i++) wrong += v0[i] != sample(i, 0) || v1[i] != sample(i, 1);
  assert_int_equal(wrong, 0);
  rcb_signals_destroy(s);
}

static void test_csv_streamed_errors(void **state) {
  const char *p = rcb_test_tmp_path("big.csv");
  char want[64], *huge;
  rcb_signals *s;
  size_t line, n = (size_t)3 << 20;
  FILE *fp;
  (void)state;
  assert_int_equal(rcb_signals_create(&s, NULL), RCB_OK);
  line = write_big(p, ROWS - 10);
  assert_int_equal(rcb_signals_read_csv(s, p), RCB_ERR_PARSE);
  snprintf(want, sizeof want, "big.csv:%zu: field 2 is not a finite number", line);
  if (!strstr(rcb_signals_errmsg(s), want))
    fail_msg("%s; expected %s", rcb_signals_errmsg(s), want);
  /* a 3 MiB comment line: the buffer grows to hold it */
  huge = malloc(n + 1);
  assert_non_null(huge);
  memset(huge, 'c', n);
  huge[0] = '#';
  huge[n] = '\0';
  fp = fopen(p, "wb");
  assert_non_null(fp);
  fprintf(fp, "%s\ntime_s,DA.x [m]\n0,1\n0.5,-2.5e-3\n1,3", huge);
  fclose(fp);
  free(huge);
  if (rcb_signals_read_csv(s, p)) fail_msg("%s", rcb_signals_errmsg(s));
  assert_int_equal(rcb_signals_length(s), 3);
  assert_true(rcb_signals_rate(s) == 2.0);
  rcb_signals_destroy(s);
}

/* Every allocation of a read failing in turn: an error with a message,
 * nothing leaked; then the complete read. */
static void test_csv_alloc_fail(void **state) {
  const char *p = rcb_test_tmp_path("small.csv");
  size_t k;
  FILE *fp = fopen(p, "wb");
  (void)state;
  assert_non_null(fp);
  fputs("time_s,DA.x [m],DB.x [mm]\n", fp);
  for (k = 1; k < 3000; k++) /* rows enough to double the arrays a few times */
    fprintf(fp, "%g,%zu,1\n", (double)k / 10.0, k);
  fclose(fp);
  for (k = 1;; k++) {
    rcb_test_failing f = {k, 0, 0, 0, 0, NULL};
    rcb_allocator a = rcb_test_failing_allocator(&f);
    rcb_signals *s = NULL;
    rcb_status st = rcb_signals_create(&s, &a);
    if (!st) {
      st = rcb_signals_read_csv(s, p);
      if (st) assert_true(rcb_signals_errmsg(s)[0] != '\0');
      if (!st) assert_int_equal(rcb_signals_length(s), 2999);
      rcb_signals_destroy(s);
    }
    if (f.live != 0) fail_msg("allocation %zu failing: %zu blocks leaked", k, f.live);
    if (f.hit && st == RCB_OK) fail_msg("allocation %zu failed, yet RCB_OK", k);
    if (!f.hit) break;
  }
  assert_true(k > 5);
}

/* A file of nch channels, each "m/s^2" in the units line padded with
 * spaces to pad characters, but the last one "mm/s^2" (issue #35: the last
 * unit of a units line over 1024 bytes was read cut). Two rows, 1 kS/s. */
static void write_wide(const char *path, size_t nch, size_t pad) {
  FILE *fp = fopen(path, "wb");
  size_t k, r;
  assert_non_null(fp);
  fputs("# units =", fp);
  for (k = 0; k < nch; k++)
    fprintf(fp, "%s%*s", k ? "," : " ", -(int)pad, k + 1 == nch ? "mm/s^2" : "m/s^2");
  fputs("\ntime_s", fp);
  for (k = 0; k < nch; k++) fprintf(fp, ",ch%zu.x", k);
  for (r = 0; r < 2; r++) {
    fprintf(fp, "\n%g", (double)r * 1e-3);
    for (k = 0; k < nch; k++) fprintf(fp, ",%zu", k + r);
  }
  fputc('\n', fp);
  fclose(fp);
}

static void expect_refused(rcb_signals *s, const char *p, const char *f1, const char *f2) {
  if (rcb_signals_read_csv(s, p) != RCB_ERR_PARSE)
    fail_msg("expected RCB_ERR_PARSE, message '%s'", rcb_signals_errmsg(s));
  if (!strstr(rcb_signals_errmsg(s), f1) || (f2 && !strstr(rcb_signals_errmsg(s), f2)))
    fail_msg("message '%s' lacks '%s' / '%s'", rcb_signals_errmsg(s), f1, f2 ? f2 : "");
  assert_int_equal(rcb_signals_channel_count(s), 0);
}

static void write_text(const char *path, const char *text) {
  FILE *fp = fopen(path, "wb");
  assert_non_null(fp);
  fputs(text, fp);
  fclose(fp);
}

/* Units lines past the old 1024-byte buffer, and the channel limit. */
static void test_csv_wide_units(void **state) {
  const char *p = rcb_test_tmp_path("wide.csv");
  rcb_signals *s;
  rcb_quantity q;
  const double *v;
  const char *name;
  FILE *fp;
  size_t k, nch[] = {40, 200, 256};
  (void)state;
  assert_int_equal(rcb_signals_create(&s, NULL), RCB_OK);
  /* 40 channels, each unit padded to 250 bytes: a units line of 10 kB */
  for (k = 0; k < 3; k++) {
    write_wide(p, nch[k], k == 0 ? 250 : 5);
    if (rcb_signals_read_csv(s, p)) fail_msg("%zu channels: %s", nch[k], rcb_signals_errmsg(s));
    assert_int_equal(rcb_signals_channel_count(s), nch[k]);
    assert_int_equal(rcb_signals_channel(s, 0, &name, &q, &v), RCB_OK);
    assert_true(q == RCB_QTY_ACCELERATION && v[1] == 1.0);
    assert_int_equal(rcb_signals_channel(s, nch[k] - 1, &name, &q, &v), RCB_OK);
    assert_true(q == RCB_QTY_ACCELERATION); /* mm/s^2, not a cut "m" or "mm" */
    if (v[1] != (double)nch[k] * 1e-3) fail_msg("%zu channels: last %.17g", nch[k], v[1]);
  }
  /* the file: "mm,mm/s^2" as the last units past byte 1024 */
  fp = fopen(p, "wb");
  assert_non_null(fp);
  fputs("# units = ", fp);
  for (k = 0; k < 200; k++) fputs("V      ,", fp);
  fputs("mm,mm/s^2\ntime_s", fp);
  for (k = 0; k < 201; k++) fprintf(fp, ",c%zu", k);
  fputs(",DA.y\n", fp);
  for (k = 0; k < 2; k++) {
    size_t c;
    fprintf(fp, "%g", (double)k);
    for (c = 0; c < 202; c++) fputs(",3", fp);
    fputc('\n', fp);
  }
  fclose(fp);
  if (rcb_signals_read_csv(s, p)) fail_msg("%s", rcb_signals_errmsg(s));
  assert_int_equal(rcb_signals_channel(s, 201, &name, &q, &v), RCB_OK);
  assert_string_equal(name, "DA.y");
  assert_true(q == RCB_QTY_ACCELERATION && v[0] == 3e-3);
  assert_int_equal(rcb_signals_channel(s, 200, &name, &q, &v), RCB_OK);
  assert_true(q == RCB_QTY_DISPLACEMENT && v[0] == 3e-3);
  /* one channel past the limit: refused at the header's line, the limit named */
  write_wide(p, 257, 5);
  expect_refused(s, p, "wide.csv:2: more than 256 channel columns", NULL);
  rcb_signals_destroy(s);
}

/* Names up to 63 characters read whole, 64 refused; bracketed units of any
 * length read whole (one of 120 bytes was dropped without a word). */
static void test_csv_long_names_units(void **state) {
  const char *p = rcb_test_tmp_path("long.csv");
  char text[1024], n63[64], n64[65], pad[121];
  rcb_signals *s;
  rcb_quantity q;
  const double *v;
  const char *name;
  (void)state;
  memset(n63, 'a', 63);
  n63[63] = '\0';
  memset(n64, 'b', 64);
  n64[64] = '\0';
  memset(pad, ' ', 120);
  pad[120] = '\0';
  assert_int_equal(rcb_signals_create(&s, NULL), RCB_OK);
  snprintf(text, sizeof text, "time_s,%s [%smm%s]\n0,1\n1,2\n", n63, pad, pad);
  write_text(p, text);
  if (rcb_signals_read_csv(s, p)) fail_msg("%s", rcb_signals_errmsg(s));
  assert_int_equal(rcb_signals_channel(s, 0, &name, &q, &v), RCB_OK);
  assert_string_equal(name, n63);
  assert_true(q == RCB_QTY_DISPLACEMENT && v[1] == 2e-3);
  snprintf(text, sizeof text, "time_s,DA.x [m],%s [m]\n0,1,1\n1,2,2\n", n64);
  write_text(p, text);
  expect_refused(s, p, "long.csv:1: column 3: name 'bbbb", "64 characters; at most 63");
  /* a long unknown unit: refused at its line, not read as "no unit" */
  snprintf(text, sizeof text, "time_s,DA.x [m%sm%s]\n0,1\n1,2\n", pad, pad);
  write_text(p, text);
  expect_refused(s, p, "long.csv:1: channel 'DA.x': unit 'm", "not one librcb knows");
  snprintf(text, sizeof text, "# units = m,mm\ntime_s,DA.x,DB.x [m%sm]\n0,1,1\n1,2,2\n", pad);
  write_text(p, text);
  expect_refused(s, p, "long.csv:2: channel 'DB.x'", "...' is not one librcb knows");
  write_text(p, "time_s,DA.x [mm\n0,1\n1,2\n");
  expect_refused(s, p, "long.csv:1: column 2", "'[' without ']'");
  write_text(p, "time_s,DA.x [mm] x\n0,1\n1,2\n");
  expect_refused(s, p, "long.csv:1: column 2: 'x' after the unit's ']'", NULL);
  rcb_signals_destroy(s);
}

/* Times whose spacing or rate is not a finite number: refused with the
 * lines, not read as a rate of 0 (issue #35: -1e308, 1e308 passed the
 * even-spacing test and failed later with no file nor line). */
static void test_csv_extreme_times(void **state) {
  const char *p = rcb_test_tmp_path("times.csv");
  rcb_signals *s;
  (void)state;
  assert_int_equal(rcb_signals_create(&s, NULL), RCB_OK);
  write_text(p, "time_s,DA.x [m]\n-1e308,1\n# a comment\n1e308,2\n");
  expect_refused(s, p, "times.csv:2: time -1e+308 s, and 1e+308 s at line 4",
                 "is not a finite number");
  write_text(p, "time_s,DA.x [m]\n-1e308,1\n0,1\n1e308,2\n");
  expect_refused(s, p, "times.csv:2:", "spacing of the time column");
  write_text(p, "time_s,DA.x [m]\n2.5e-308,1\n3e-308,2\n"); /* 5e-309 s: subnormal */
  expect_refused(s, p, "times.csv:2:", "sample rate is not a finite number");
  write_text(p, "time_s,DA.x [m]\n1,1\n1,2\n");
  expect_refused(s, p, "times.csv:2:", "at line 3: the time column is not increasing");
  rcb_signals_destroy(s);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_csv_streamed_exact),
      cmocka_unit_test(test_csv_streamed_errors),
      cmocka_unit_test(test_csv_alloc_fail),
      cmocka_unit_test(test_csv_wide_units),
      cmocka_unit_test(test_csv_long_names_units),
      cmocka_unit_test(test_csv_extreme_times),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
