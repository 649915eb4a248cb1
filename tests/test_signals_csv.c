/*
 * The signals CSV reader's one-pass streaming (signals/signals_csv.c, issue
 * #25): a file of several read buffers, whose numbers must come back as the
 * very doubles that were printed with %.17g (which names each double
 * exactly), with CRLF endings, comment and blank lines among the rows and no
 * final newline; the line number of a bad field far past the first buffer; a
 * line longer than the buffer; and every allocation failing in turn.
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

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_csv_streamed_exact),
      cmocka_unit_test(test_csv_streamed_errors),
      cmocka_unit_test(test_csv_alloc_fail),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
