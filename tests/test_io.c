/*
 * Measurements: container, UFF dataset 58 (ASCII and binary 58b), CSV, eq. 19
 * noise. Checked against things that could prove them wrong:
 *  - round trips: binary UFF and CSV bit-for-bit (1e-15), ASCII UFF to the
 *    13 significant digits of its E20.12 fields;
 *  - hand-written UFF records in the documented fixed-column layout (the same
 *    bytes pyuff writes), with known values, signs and node maps;
 *  - kind conversion identities: mobility = i w receptance, inertance =
 *    -w^2 receptance;
 *  - noise: the bound |f_e/f_s - 1| <= beta_a/100 and its coverage, the
 *    systematic bound, and the PRNG stream against an independent Python
 *    implementation of splitmix64 + xoshiro256**;
 *  - every kind of bad data gives RCB_ERR_PARSE (file) or RCB_ERR_ARG (API)
 *    with a message naming the problem and the line or record.
 */
#define _POSIX_C_SOURCE 200809L /* mkdtemp, fmemopen, access */
#include <complex.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>
#include <unistd.h>

#include "core/rcb_internal.h"
#include "rcb_test_util.h"

#define TWO_PI (2.0 * RCB_PI)
#define NPT 37

static void write_text(const char *path, const char *text) {
  FILE *fp = fopen(path, "wb");
  assert_non_null(fp);
  fputs(text, fp);
  fclose(fp);
}

static int cclose(double complex a, double complex b, double rtol) {
  return cabs(a - b) <= rtol * fmax(cabs(a), cabs(b));
}

/* An FRF measurement with values spanning many decades and both signs. */
static rcb_meas *sample_frf(double speed, int uneven) {
  rcb_meas *ms = NULL;
  double x[NPT];
  rcb_complex d[NPT];
  static const char *const resp[] = {"DA.x", "C.A.y", "#7.rx"};
  static const char *const ref[] = {"C.B.y", "DA.x", "DB.ry"};
  size_t i, c;
  assert_int_equal(rcb_meas_create(&ms, NULL), RCB_OK);
  for (i = 0; i < NPT; i++)
    x[i] = TWO_PI * (uneven ? 10.0 + 3.0 * (double)i + 0.1234567891 * (double)(i * i)
                            : 10.0 + 2.5 * (double)i);
  assert_int_equal(rcb_meas_set_grid(ms, RCB_MEAS_FRF, NPT, x, speed), RCB_OK);
  for (c = 0; c < 3; c++) {
    for (i = 0; i < NPT; i++)
      d[i] = CMPLX(sin(0.3 * (double)i + (double)c) * pow(10.0, -9.0 + 0.2 * (double)i),
                   -cos(0.7 * (double)i) / 3.0 * pow(10.0, -6.0 - 0.1 * (double)i));
    assert_int_equal(rcb_meas_add_channel(ms, resp[c], ref[c], (rcb_frf_kind)c, d), RCB_OK);
  }
  return ms;
}

static const rcb_uff_node MAP[] = {
    {10, "DA", NULL, NULL},
    {20, "C.A", NULL, NULL},
    {21, "C.B", NULL, NULL},
    {30, "DB", NULL, NULL}
};

static void assert_same(const rcb_meas *a, const rcb_meas *b, double xtol, double vtol) {
  size_t i, c, n = rcb_meas_point_count(a);
  assert_int_equal(rcb_meas_get_type(a), rcb_meas_get_type(b));
  assert_int_equal(n, rcb_meas_point_count(b));
  assert_int_equal(rcb_meas_channel_count(a), rcb_meas_channel_count(b));
  assert_true(rcb_test_close(rcb_meas_speed(a), rcb_meas_speed(b), 1e-7, 0.0));
  for (i = 0; i < n; i++)
    assert_true(rcb_test_close(rcb_meas_grid(a)[i], rcb_meas_grid(b)[i], xtol, 0.0));
  for (c = 0; c < rcb_meas_channel_count(a); c++) {
    rcb_meas_channel_info ia, ib;
    assert_int_equal(rcb_meas_channel(a, c, &ia), RCB_OK);
    assert_int_equal(rcb_meas_channel(b, c, &ib), RCB_OK);
    assert_string_equal(ia.response, ib.response);
    if (ia.reference) assert_string_equal(ia.reference, ib.reference);
    assert_int_equal(ia.kind, ib.kind);
    for (i = 0; i < n; i++) {
      if (!cclose(ia.data[i], ib.data[i], vtol))
        fail_msg("channel %zu point %zu: %.17g%+.17gi vs %.17g%+.17gi", c, i,
                 creal(ia.data[i]), cimag(ia.data[i]), creal(ib.data[i]), cimag(ib.data[i]));
    }
  }
}

/* ---------------------------------------------------------- round trips -- */

static void roundtrip_uff(int binary, int uneven, double speed, double xtol, double vtol) {
  rcb_meas *a = sample_frf(speed, uneven), *b = NULL;
  const char *p = rcb_test_tmp_path(binary ? "rt.bin.uff" : "rt.uff");
  assert_int_equal(rcb_meas_write_uff(a, p, binary, 4, MAP), RCB_OK);
  assert_int_equal(rcb_meas_create(&b, NULL), RCB_OK);
  if (rcb_meas_read_uff(b, p, 4, MAP) != RCB_OK) fail_msg("%s", rcb_meas_errmsg(b));
  assert_same(a, b, xtol, vtol);
  rcb_meas_destroy(a);
  rcb_meas_destroy(b);
}

static void test_uff_ascii_roundtrip(void **state) {
  (void)state;
  /* E20.12: 13 significant digits; an even grid written as min + i inc */
  roundtrip_uff(0, 0, 10000.0 * RCB_PI / 30.0, 1e-15, 5e-13);
  /* uneven abscissa: E13.5-wide fields (7 digits here) */
  roundtrip_uff(0, 1, -1.0, 5e-7, 5e-13);
}

static void test_uff_binary_roundtrip(void **state) {
  (void)state;
  roundtrip_uff(1, 0, 3000.0 * RCB_PI / 30.0, 1e-15, 1e-15);
  roundtrip_uff(1, 1, 0.0, 1e-15, 1e-15); /* uneven: abscissa as doubles */
}

static void test_csv_roundtrip(void **state) {
  rcb_meas *a = sample_frf(4500.0 * RCB_PI / 30.0, 1), *b = NULL;
  const char *p = rcb_test_tmp_path("rt.csv");
  (void)state;
  /* CSV has one kind line: mixed kinds are refused, nothing is written */
  assert_int_equal(rcb_meas_write_csv(a, p), RCB_ERR_ARG);
  assert_non_null(strstr(rcb_meas_errmsg(a), "differ in kind"));
  assert_int_equal(access(p, F_OK), -1);
  assert_int_equal(rcb_meas_convert(a, RCB_MOBILITY), RCB_OK);
  assert_int_equal(rcb_meas_write_csv(a, p), RCB_OK);
  assert_int_equal(rcb_meas_create(&b, NULL), RCB_OK);
  if (rcb_meas_read_csv(b, p) != RCB_OK) fail_msg("%s", rcb_meas_errmsg(b));
  assert_same(a, b, 1e-15, 1e-15);
  rcb_meas_destroy(a);
  rcb_meas_destroy(b);
}

static void test_unbalance_roundtrip(void **state) {
  rcb_meas *a = NULL, *b = NULL;
  double x[5];
  rcb_complex d[5];
  size_t i, f;
  (void)state;
  assert_int_equal(rcb_meas_create(&a, NULL), RCB_OK);
  for (i = 0; i < 5; i++) {
    x[i] = (300.0 + 4500.0 * (double)i) * RCB_PI / 30.0;
    d[i] = CMPLX(1e-5 * (double)(i + 1), -2e-6 * (double)i);
  }
  assert_int_equal(rcb_meas_set_grid(a, RCB_MEAS_UNBALANCE, 5, x, 0.0), RCB_OK);
  assert_int_equal(rcb_meas_add_channel(a, "C.A.x", NULL, RCB_RECEPTANCE, d), RCB_OK);
  assert_int_equal(rcb_meas_add_channel(a, "C.B.ry", NULL, RCB_RECEPTANCE, d), RCB_OK);
  assert_int_equal(rcb_meas_add_channel(a, "DA.y", NULL, RCB_MOBILITY, d), RCB_ERR_ARG);
  for (f = 0; f < 3; f++) {
    const char *p = rcb_test_tmp_path(f == 2 ? "unb.csv" : "unb.uff");
    assert_int_equal(f == 2 ? rcb_meas_write_csv(a, p) : rcb_meas_write_uff(a, p, (int)f, 4, MAP),
                     RCB_OK);
    assert_int_equal(rcb_meas_create(&b, NULL), RCB_OK);
    if ((f == 2 ? rcb_meas_read_csv(b, p) : rcb_meas_read_uff(b, p, 4, MAP)) != RCB_OK)
      fail_msg("%s", rcb_meas_errmsg(b));
    assert_same(a, b, f == 1 ? 1e-15 : 1e-12, f == 0 ? 5e-13 : 1e-15);
    rcb_meas_destroy(b);
  }
  /* phase lag (issue #25): the CSV states it and holds the conjugates (arg =
   * the lag a vibration monitor shows); read back, the model's values */
  {
    const char *p = rcb_test_tmp_path("lag.csv");
    rcb_meas_channel_info got;
    char text[512];
    FILE *fp;
    size_t len;
    assert_int_equal(rcb_meas_set_phase(a, RCB_PHASE_LAG, "keyphasor falling edge"), RCB_OK);
    assert_int_equal(rcb_meas_write_csv(a, p), RCB_OK);
    fp = fopen(p, "r");
    assert_non_null(fp);
    len = fread(text, 1, sizeof text - 1, fp);
    fclose(fp);
    text[len] = '\0';
    assert_non_null(strstr(text, "# phase = lag (keyphasor falling edge)\nrpm,"));
    assert_non_null(strstr(text, ",1.9999999999999999e-06\n")); /* conj of -2e-6 i, point 2 */
    assert_int_equal(rcb_meas_create(&b, NULL), RCB_OK);
    if (rcb_meas_read_csv(b, p) != RCB_OK) fail_msg("%s", rcb_meas_errmsg(b));
    assert_int_equal(rcb_meas_phase(b), RCB_PHASE_LAG);
    assert_same(a, b, 1e-15, 1e-15);
    assert_int_equal(rcb_meas_channel(b, 0, &got), RCB_OK);
    assert_true(cimag(got.data[1]) < 0.0); /* the model's -2e-6 */
    rcb_meas_destroy(b);
    assert_int_equal(rcb_meas_set_phase(a, (rcb_phase_convention)3, NULL), RCB_ERR_ARG);
  }
  rcb_meas_destroy(a);
}

/* ------------------------------------------- files from other writers -- */

/* One ASCII dataset 58 record in pyuff's fixed columns. */
static void rec58(FILE *fp, int ftype, long rn, int rd, long fn, int fd, int otype, long npts,
                  int even, double x0, double dx, double z, int s8, int s9, int s10, int s11,
                  const char *values) {
  fprintf(fp, "%6d\n%6d%74s\n", -1, 58, "");
  fprintf(fp, "%-80s\n%-80s\n%-80s\n%-80s\n%-80s\n", "id1", "NONE", "NONE", "NONE", "NONE");
  fprintf(fp, "%5d%10d%5d%10d %10s%10ld%4d %10s%10ld%4d\n", ftype, 0, 0, 0, "NONE", rn, rd,
          "NONE", fn, fd);
  fprintf(fp, "%10d%10ld%10d%13.5e%13.5e%13.5e\n", otype, npts, even, x0, dx, z);
  fprintf(fp, "%10d%5d%5d%5d %-20s %-20s\n", s8, 0, 0, 0, "NONE", "NONE");
  fprintf(fp, "%10d%5d%5d%5d %-20s %-20s\n", s9, 0, 0, 0, "NONE", "NONE");
  fprintf(fp, "%10d%5d%5d%5d %-20s %-20s\n", s10, 0, 0, 0, "NONE", "NONE");
  fprintf(fp, "%10d%5d%5d%5d %-20s %-20s\n", s11, 0, 0, 0, "NONE", "NONE");
  fputs(values, fp);
  fprintf(fp, "%6d\n", -1);
}

/* Three even points (10, 20, 30 Hz) of 1+2i, 3+4i, 5+6i as 4E20.12 (pyuff's %20.11e). */
static const char V3[] =
    "   1.00000000000e+00   2.00000000000e+00   3.00000000000e+00   4.00000000000e+00\n"
    "   5.00000000000e+00   6.00000000000e+00\n";

/* Direction entries of the node map (issue #35 item 2): an FRF from node 3's
 * own z (direction 3) over node 10's scalar force (direction 0) is skipped
 * without them, with a warning naming the entry that would read it; with
 * "3.z=DB.y" and "10.s=DA.x" it is DB.y/DA.x, and 3.x still reads through the
 * node entry 3=DB. A direction -3 flips the sign as any negative direction. */
/* Magnitude-only CSV (issue #35 item 4): a 'mag' or 'dB' column without
 * phase is a channel of magnitudes (|H| + 0i, flagged); a phase without its
 * magnitude, a negative magnitude, and UFF output are refused; conversion
 * multiplies by w^k (real), and the CSV writer gives one 'mag' column back. */
static void test_csv_magnitude_only(void **state) {
  const char *p = rcb_test_tmp_path("mag.csv"), *q = rcb_test_tmp_path("mag2.csv");
  FILE *fp = fopen(p, "w");
  rcb_meas *ms = NULL;
  rcb_meas_channel_info c;
  (void)state;
  assert_non_null(fp);
  fputs("# kind = receptance\nfreq_hz,DA.x/DA.x mag,DB.x/DA.x dB,DA.y/DA.x re,DA.y/DA.x im\n"
        "10,2,-20,1,2\n20,4,0,3,4\n", fp);
  fclose(fp);
  assert_int_equal(rcb_meas_create(&ms, NULL), RCB_OK);
  if (rcb_meas_read_csv(ms, p) != RCB_OK) fail_msg("%s", rcb_meas_errmsg(ms));
  assert_int_equal(rcb_meas_magnitude_only_count(ms), 2);
  assert_int_equal(rcb_meas_channel(ms, 0, &c), RCB_OK);
  assert_true(c.magnitude_only && creal(c.data[1]) == 4.0 && cimag(c.data[1]) == 0.0);
  assert_int_equal(rcb_meas_channel(ms, 1, &c), RCB_OK);
  assert_true(c.magnitude_only && fabs(creal(c.data[0]) - 0.1) < 1e-15);
  assert_int_equal(rcb_meas_channel(ms, 2, &c), RCB_OK);
  assert_false(c.magnitude_only);
  /* receptance -> inertance: |(i w)^2| = w^2 on the magnitudes, (i w)^2 on H */
  assert_int_equal(rcb_meas_convert(ms, RCB_INERTANCE), RCB_OK);
  assert_int_equal(rcb_meas_channel(ms, 0, &c), RCB_OK);
  assert_true(fabs(creal(c.data[0]) - 2.0 * pow(2 * 3.14159265358979323846 * 10, 2)) < 1e-9 && cimag(c.data[0]) == 0);
  assert_int_equal(rcb_meas_channel(ms, 2, &c), RCB_OK);
  assert_true(creal(c.data[0]) < 0);
  assert_int_equal(rcb_meas_write_uff(ms, rcb_test_tmp_path("mag.uff"), 0, 0, NULL),
                   RCB_ERR_ARG);
  assert_non_null(strstr(rcb_meas_errmsg(ms), "DA.x/DA.x holds magnitudes only"));
  assert_int_equal(rcb_meas_write_csv(ms, q), RCB_OK);
  assert_int_equal(rcb_meas_read_csv(ms, q), RCB_OK);
  assert_int_equal(rcb_meas_magnitude_only_count(ms), 2);
  fp = fopen(p, "w");
  fputs("freq_hz,DA.x/DA.x phase_deg\n10,2\n", fp);
  fclose(fp);
  assert_int_equal(rcb_meas_read_csv(ms, p), RCB_ERR_PARSE);
  assert_non_null(strstr(rcb_meas_errmsg(ms), "its phase_deg has no pair"));
  fp = fopen(p, "w");
  fputs("freq_hz,DA.x/DA.x mag\n10,2\n20,-1\n", fp);
  fclose(fp);
  assert_int_equal(rcb_meas_read_csv(ms, p), RCB_ERR_PARSE);
  assert_non_null(strstr(rcb_meas_errmsg(ms), "point 2 (20 Hz): magnitude -1"));
  rcb_meas_destroy(ms);
  remove(p);
  remove(q);
}

static void test_uff_map_directions(void **state) {
  const char *p = rcb_test_tmp_path("dirs.uff");
  FILE *fp = fopen(p, "w");
  rcb_meas *ms = NULL;
  rcb_meas_channel_info c;
  rcb_uff_node map[] = {{3, "DB", NULL, NULL}, {3, "DB", "z", "y"}, {10, "DA", "s", "x"}};
  rcb_uff_node bad[] = {{3, "DB", "q", "y"}, {3, "DB", "z", "z"}, {3, "DB", NULL, "x"}};
  (void)state;
  assert_non_null(fp);
  rec58(fp, 4, 3, -3, 10, 0, 6, 3, 1, 10.0, 10.0, 1200.0, 18, 8, 13, 19, V3);
  rec58(fp, 4, 3, 1, 10, 0, 6, 3, 1, 10.0, 10.0, 1200.0, 18, 8, 13, 19, V3);
  fclose(fp);
  assert_int_equal(rcb_meas_create(&ms, NULL), RCB_OK);
  assert_int_equal(rcb_meas_read_uff(ms, p, 1, map), RCB_ERR_PARSE);
  assert_int_equal(rcb_meas_warning_count(ms), 2);
  assert_non_null(strstr(rcb_meas_warning(ms, 0), "its response (node 3) is axial (direction "
                                                   "3, z); the model's channels are x, y, rx, "
                                                   "ry: the map entry 3.z=DB.DIR"));
  assert_non_null(strstr(rcb_meas_warning(ms, 1), "its reference (node 10) is scalar "
                                                   "(direction 0)"));
  assert_non_null(strstr(rcb_meas_warning(ms, 1), "the map entry 10.s=STATION.DIR"));
  if (rcb_meas_read_uff(ms, p, 3, map) != RCB_OK) fail_msg("%s", rcb_meas_errmsg(ms));
  assert_int_equal(rcb_meas_channel_count(ms), 2);
  assert_int_equal(rcb_meas_channel(ms, 0, &c), RCB_OK);
  assert_string_equal(c.response, "DB.y");
  assert_string_equal(c.reference, "DA.x");
  assert_true(creal(c.data[1]) == -3.0 && cimag(c.data[1]) == -4.0);
  assert_int_equal(rcb_meas_channel(ms, 1, &c), RCB_OK);
  assert_string_equal(c.response, "DB.x");
  assert_true(creal(c.data[1]) == 3.0 && cimag(c.data[1]) == 4.0);
  for (size_t k = 0; k < 3; k++) {
    rcb_uff_node one[1];
    one[0] = bad[k];
    assert_int_equal(rcb_meas_read_uff(ms, p, 1, one), RCB_ERR_ARG);
  }
  assert_non_null(strstr(rcb_meas_errmsg(ms), "model direction 'x' but no file direction"));
  rcb_meas_destroy(ms);
  remove(p);
}

static void test_uff_read_hand_written(void **state) {
  const char *p = rcb_test_tmp_path("hand.uff");
  FILE *fp = fopen(p, "w");
  rcb_meas *ms = NULL;
  rcb_meas_channel_info c;
  rcb_uff_node map[] = {{10, "DA", NULL, NULL}};
  (void)state;
  assert_non_null(fp);
  /* a dataset we skip (164, units), an FRF with a negative response
   * direction (velocity / force), a coherence record (type 6: skipped),
   * an acceleration FRF from node 3 (unmapped -> "#3") in uneven spacing */
  fputs("    -1\n   164\n         1  SI - mks (Newton)  2\n    -1\n", fp);
  rec58(fp, 4, 10, -2, 3, 1, 6, 3, 1, 10.0, 10.0, 1200.0, 18, 11, 13, 19, V3);
  rec58(fp, 6, 10, 1, 3, 1, 4, 3, 1, 10.0, 10.0, 0.0, 18, 0, 0, 0,
        "   1.00000000000e+00   1.00000000000e+00   1.00000000000e+00\n");
  rec58(fp, 4, 3, 5, 10, -4, 6, 3, 0, 0.0, 0.0, 1200.0, 18, 12, 13, 19,
        "  1.00000e+01   1.00000000000e+00   2.00000000000e+00\n"
        "  2.00000e+01   3.00000000000e+00   4.00000000000e+00\n"
        "  3.00000e+01   5.00000000000e+00   6.00000000000e+00\n");
  /* single-precision complex (type 5, 6E13.5) */
  rec58(fp, 4, 10, 1, 3, 2, 5, 3, 1, 10.0, 10.0, 1200.0, 18, 8, 13, 19,
        "  1.00000e+00  2.00000e+00  3.00000e+00  4.00000e+00  5.00000e+00  6.50000e+00\n");
  fclose(fp);
  assert_int_equal(rcb_meas_create(&ms, NULL), RCB_OK);
  if (rcb_meas_read_uff(ms, p, 1, map) != RCB_OK) fail_msg("%s", rcb_meas_errmsg(ms));
  assert_int_equal(rcb_meas_get_type(ms), RCB_MEAS_FRF);
  assert_int_equal(rcb_meas_point_count(ms), 3);
  assert_int_equal(rcb_meas_channel_count(ms), 3);
  assert_true(rcb_test_close(rcb_meas_grid(ms)[2], TWO_PI * 30.0, 1e-15, 0));
  assert_true(rcb_test_close(rcb_meas_speed(ms), 1200.0 * RCB_PI / 30.0, 1e-15, 0));
  assert_int_equal(rcb_meas_channel(ms, 0, &c), RCB_OK);
  assert_string_equal(c.response, "DA.y");
  assert_string_equal(c.reference, "#3.x");
  assert_int_equal(c.kind, RCB_MOBILITY);
  assert_true(c.data[1] == CMPLX(-3.0, -4.0)); /* -Y flips the sign */
  assert_int_equal(rcb_meas_channel(ms, 1, &c), RCB_OK);
  assert_string_equal(c.response, "#3.ry");
  assert_string_equal(c.reference, "DA.rx");
  assert_int_equal(c.kind, RCB_INERTANCE);
  assert_true(c.data[2] == CMPLX(-5.0, -6.0));
  assert_int_equal(rcb_meas_channel(ms, 2, &c), RCB_OK);
  assert_string_equal(c.response, "DA.x");
  assert_string_equal(c.reference, "#3.y");
  assert_int_equal(c.kind, RCB_RECEPTANCE);
  assert_true(c.data[2] == CMPLX(5.0, 6.5));
  /* issue #17: node 3 has no map entry: one warning naming it (4 channel ends) */
  assert_int_equal(rcb_meas_warning_count(ms), 1);
  assert_non_null(strstr(rcb_meas_warning(ms, 0), "UFF node 3 is not in the node map"));
  assert_non_null(strstr(rcb_meas_warning(ms, 0), "model node #3"));
  assert_int_equal(rcb_meas_speed_given(ms), 1); /* z axis type 19 */
  /* with node 3 mapped: no warning */
  {
    rcb_uff_node map2[] = {{10, "DA", NULL, NULL}, {3, "DB", NULL, NULL}};
    assert_int_equal(rcb_meas_read_uff(ms, p, 2, map2), RCB_OK);
    assert_int_equal(rcb_meas_warning_count(ms), 0);
  }
  rcb_meas_destroy(ms);
}

/* A UFF whose z axis is not of type 19 (the speed only in the ID text, as
 * several acquisition systems write it): read as 0 rpm, but not silently
 * (issue #17); rcb_meas_set_speed states it and drops the warning. */
static void test_uff_speed_not_stated(void **state) {
  const char *p = rcb_test_tmp_path("zaxis0.uff");
  FILE *fp = fopen(p, "w");
  rcb_meas *ms = NULL;
  rcb_uff_node map[] = {{10, "DA", NULL, NULL}, {3, "DB", NULL, NULL}};
  (void)state;
  assert_non_null(fp);
  rec58(fp, 4, 10, 1, 3, 1, 6, 3, 1, 10.0, 10.0, 0.0, 18, 8, 13, 0, V3);
  fclose(fp);
  assert_int_equal(rcb_meas_create(&ms, NULL), RCB_OK);
  if (rcb_meas_read_uff(ms, p, 2, map) != RCB_OK) fail_msg("%s", rcb_meas_errmsg(ms));
  assert_true(rcb_meas_speed(ms) == 0.0);
  assert_int_equal(rcb_meas_speed_given(ms), 0);
  assert_int_equal(rcb_meas_warning_count(ms), 1);
  assert_non_null(strstr(rcb_meas_warning(ms, 0), "z axis has data type 0, not 19"));
  assert_non_null(strstr(rcb_meas_warning(ms, 0), "reads as 0 rpm"));
  assert_int_equal(rcb_meas_set_speed(ms, -2.0), RCB_OK); /* synchronous */
  assert_true(rcb_meas_speed(ms) < 0.0);
  assert_int_equal(rcb_meas_set_speed(ms, 1000.0), RCB_OK);
  assert_true(rcb_meas_speed(ms) == 1000.0);
  assert_int_equal(rcb_meas_speed_given(ms), 1);
  assert_int_equal(rcb_meas_warning_count(ms), 0);
  assert_int_equal(rcb_meas_set_speed(ms, (double)NAN), RCB_ERR_ARG);
  /* a CSV states it with '# rpm', or leaves it out */
  write_text(p, "freq_hz,DA.x/DA.x re,DA.x/DA.x im\n10,1,2\n");
  assert_int_equal(rcb_meas_read_csv(ms, p), RCB_OK);
  assert_int_equal(rcb_meas_speed_given(ms), 0);
  assert_int_equal(rcb_meas_warning_count(ms), 1);
  assert_non_null(strstr(rcb_meas_warning(ms, 0), "no '# rpm = R' line"));
  write_text(p, "# rpm = 0\nfreq_hz,DA.x/DA.x re,DA.x/DA.x im\n10,1,2\n");
  assert_int_equal(rcb_meas_read_csv(ms, p), RCB_OK);
  assert_int_equal(rcb_meas_speed_given(ms), 1);
  assert_int_equal(rcb_meas_warning_count(ms), 0);
  rcb_meas_destroy(ms);
}

static void test_csv_read_rcbtool_output(void **state) {
  const char *p = rcb_test_tmp_path("frf.csv"), *q = rcb_test_tmp_path("unb_amp.csv");
  rcb_meas *ms = NULL;
  rcb_meas_channel_info c;
  (void)state;
  /* as rcbtool frf writes it (no comment lines: receptance at standstill) */
  write_text(p, "freq_hz,C.A.x/DA.x re,C.A.x/DA.x im,DB.y/DA.x mag,DB.y/DA.x phase_deg\n"
                "0,1e-6,0,2,90\n"
                "50,-2e-6,5e-7,4,-180\n");
  write_text(q, "rpm,DA.x amp,DA.x phase_deg,DA.y amp,DA.y phase_deg\n"
                "300,1e-5,0,1e-5,-90\n"
                "600,2e-5,45,2e-5,-45\n");
  assert_int_equal(rcb_meas_create(&ms, NULL), RCB_OK);
  if (rcb_meas_read_csv(ms, p) != RCB_OK) fail_msg("%s", rcb_meas_errmsg(ms));
  assert_int_equal(rcb_meas_get_type(ms), RCB_MEAS_FRF);
  assert_true(rcb_meas_speed(ms) == 0.0);
  assert_true(rcb_meas_grid(ms)[1] == TWO_PI * 50.0);
  assert_int_equal(rcb_meas_channel(ms, 1, &c), RCB_OK);
  assert_string_equal(c.response, "DB.y");
  assert_string_equal(c.reference, "DA.x");
  assert_int_equal(c.kind, RCB_RECEPTANCE);
  assert_true(cclose(c.data[0], CMPLX(0.0, 2.0), 1e-15));
  assert_true(cclose(c.data[1], CMPLX(-4.0, 0.0), 1e-15));
  if (rcb_meas_read_csv(ms, q) != RCB_OK) fail_msg("%s", rcb_meas_errmsg(ms));
  assert_int_equal(rcb_meas_get_type(ms), RCB_MEAS_UNBALANCE);
  assert_true(rcb_test_close(rcb_meas_grid(ms)[1], 600.0 * RCB_PI / 30.0, 1e-15, 0));
  assert_int_equal(rcb_meas_channel(ms, 1, &c), RCB_OK);
  assert_null(c.reference);
  assert_true(cclose(c.data[0], CMPLX(0.0, -1e-5), 1e-15));
  assert_true(cclose(c.data[1], 2e-5 * CMPLX(sqrt(0.5), -sqrt(0.5)), 1e-15));
  rcb_meas_destroy(ms);
}

/* Other tools' header spellings (issue #17): case, '_', spaces and a unit in
 * brackets do not matter; the values are those of the canonical header. */
static void test_csv_header_variants(void **state) {
  static const char *const heads[] = {
      "frequency_hz,DA.x/DB.y re,DA.x/DB.y im,DA.y/DB.y mag,DA.y/DB.y phase_deg\n",
      "Frequency (Hz),DA.x/DB.y Real,DA.x/DB.y Imag,DA.y/DB.y Magnitude,DA.y/DB.y Phase (deg)\n",
      "f [Hz],DA.x/DB.y re (m/N),DA.x/DB.y im (m/N),DA.y/DB.y amp [m/N],DA.y/DB.y phase [deg]\n",
      "FREQ_HZ,DA.x/DB.y RE,DA.x/DB.y IM,DA.y/DB.y ABS,DA.y/DB.y PHASE_DEG\n"};
  const char *p = rcb_test_tmp_path("variants.csv");
  rcb_meas *ms = NULL;
  rcb_meas_channel_info c;
  char text[512];
  size_t k;
  (void)state;
  assert_int_equal(rcb_meas_create(&ms, NULL), RCB_OK);
  for (k = 0; k < sizeof heads / sizeof heads[0]; k++) {
    snprintf(text, sizeof text, "%s10,1e-6,-2e-6,3e-6,90\n20,4e-6,5e-6,6e-6,180\n", heads[k]);
    write_text(p, text);
    if (rcb_meas_read_csv(ms, p) != RCB_OK) fail_msg("%s: %s", heads[k], rcb_meas_errmsg(ms));
    assert_int_equal(rcb_meas_get_type(ms), RCB_MEAS_FRF);
    assert_true(rcb_meas_grid(ms)[1] == TWO_PI * 20.0);
    assert_int_equal(rcb_meas_channel(ms, 0, &c), RCB_OK);
    assert_string_equal(c.response, "DA.x");
    assert_string_equal(c.reference, "DB.y");
    assert_true(cclose(c.data[1], CMPLX(4e-6, 5e-6), 1e-15));
    assert_int_equal(rcb_meas_channel(ms, 1, &c), RCB_OK);
    assert_true(cclose(c.data[0], CMPLX(0.0, 3e-6), 1e-15));
    assert_true(cclose(c.data[1], CMPLX(-6e-6, 0.0), 1e-15));
  }
  write_text(p, "Speed (rpm),DA.x re,DA.x im\n600,1,2\n");
  if (rcb_meas_read_csv(ms, p) != RCB_OK) fail_msg("%s", rcb_meas_errmsg(ms));
  assert_int_equal(rcb_meas_get_type(ms), RCB_MEAS_UNBALANCE);
  assert_true(rcb_test_close(rcb_meas_grid(ms)[0], 20.0 * RCB_PI, 1e-15, 0));
  rcb_meas_destroy(ms);
}

/* Lab scripts' column conventions (issue #35 item 3): the part after '_',
 * numeric stations through the node map, the two columns of a channel apart.
 * Each file holds the values of the canonical header's file and must read
 * to the very same doubles. */
static void test_csv_lab_conventions(void **state) {
  static const char rows[] = "10,1e-6,-2e-6,3e-6,90\n20,4e-6,5e-6,6e-6,180\n";
  static const char *const heads[] = {
      "freq_hz,DA.x/DB.y_re,DA.x/DB.y_im,DA.y/DB.y_mag,DA.y/DB.y_phase_deg\n",
      "freq_hz,2.x/11.y_re,2.x/11.y_im,2.y/11.y_mag,2.y/11.y_phase_deg\n",
      "freq_hz,2.x/11.y_Real,2.x/11.y_Imag,2.y/11.y_amp,2.y/11.y_phase [deg]\n",
      "freq_hz,DA.x/11.y re,DA.x/11.y im,2.y/DB.y mag,2.y/DB.y phase_deg\n",
      "freq_hz,002.x/011.y_re,002.x/011.y_im,2.y/11.y_abs,2.y/11.y_Phase (deg)\n"};
  static const rcb_uff_node map[] = {
      {11, "DB", NULL, NULL},
      {2, "DA", NULL, NULL},
      {7, "C.A", NULL, NULL}
  };
  const char *p = rcb_test_tmp_path("lab.csv");
  rcb_meas *ref = NULL, *ms = NULL;
  rcb_meas_channel_info a, b;
  char text[512];
  size_t k, c, i;
  (void)state;
  assert_int_equal(rcb_meas_create(&ref, NULL), RCB_OK);
  assert_int_equal(rcb_meas_create(&ms, NULL), RCB_OK);
  snprintf(text, sizeof text, "freq_hz,DA.x/DB.y re,DA.x/DB.y im,DA.y/DB.y mag,DA.y/DB.y "
           "phase_deg\n%s", rows);
  write_text(p, text);
  if (rcb_meas_read_csv(ref, p)) fail_msg("%s", rcb_meas_errmsg(ref));
  for (k = 0; k < sizeof heads / sizeof heads[0]; k++) {
    snprintf(text, sizeof text, "%s%s", heads[k], rows);
    write_text(p, text);
    if (rcb_meas_read_csv_map(ms, p, 3, map)) fail_msg("%s: %s", heads[k], rcb_meas_errmsg(ms));
    assert_int_equal(rcb_meas_channel_count(ms), 2);
    for (c = 0; c < 2; c++) {
      assert_int_equal(rcb_meas_channel(ref, c, &a), RCB_OK);
      assert_int_equal(rcb_meas_channel(ms, c, &b), RCB_OK);
      assert_string_equal(a.response, b.response);
      assert_string_equal(a.reference, b.reference);
      for (i = 0; i < 2; i++)
        if (a.data[i] != b.data[i]) fail_msg("%s: channel %zu point %zu differs", heads[k], c, i);
    }
  }
  /* all re columns first, then all im (a DataFrame built so): paired by
   * name, channels in the order of their re columns */
  write_text(p, "freq_hz,2.x/7.x_re,2.y/7.x_re,2.x/7.x_im,2.y/7.x_im\n5,1,2,3,4\n");
  if (rcb_meas_read_csv_map(ms, p, 3, map)) fail_msg("%s", rcb_meas_errmsg(ms));
  assert_int_equal(rcb_meas_channel(ms, 0, &b), RCB_OK);
  assert_string_equal(b.response, "DA.x");
  assert_string_equal(b.reference, "C.A.x");
  assert_true(b.data[0] == CMPLX(1.0, 3.0));
  assert_int_equal(rcb_meas_channel(ms, 1, &b), RCB_OK);
  assert_string_equal(b.response, "DA.y");
  assert_true(b.data[0] == CMPLX(2.0, 4.0));
  /* unbalance responses too */
  write_text(p, "rpm,2.x_amp,2.x_phase_deg\n600,2,90\n");
  if (rcb_meas_read_csv_map(ms, p, 3, map)) fail_msg("%s", rcb_meas_errmsg(ms));
  assert_int_equal(rcb_meas_channel(ms, 0, &b), RCB_OK);
  assert_string_equal(b.response, "DA.x");
  assert_true(cclose(b.data[0], CMPLX(0.0, 2.0), 1e-15));
  assert_int_equal(rcb_meas_read_csv_map(ms, p, 1, NULL), RCB_ERR_ARG);
  rcb_meas_destroy(ms);
  rcb_meas_destroy(ref);
}

/* "# kind" and "# rpm" comment lines. */
static void test_csv_comments(void **state) {
  const char *p = rcb_test_tmp_path("kind.csv");
  rcb_meas *ms = NULL;
  rcb_meas_channel_info c;
  (void)state;
  write_text(p, "# measured on the rig\n# kind = inertance\n# rpm = synchronous\n"
                "freq_hz,DA.x/DA.x re,DA.x/DA.x im\n10,1,2\n20,3,4\n");
  assert_int_equal(rcb_meas_create(&ms, NULL), RCB_OK);
  if (rcb_meas_read_csv(ms, p) != RCB_OK) fail_msg("%s", rcb_meas_errmsg(ms));
  assert_true(rcb_meas_speed(ms) < 0.0);
  assert_int_equal(rcb_meas_channel(ms, 0, &c), RCB_OK);
  assert_int_equal(c.kind, RCB_INERTANCE);
  write_text(p, "# rpm = 1500\nfreq_hz,DA.x/DA.x re,DA.x/DA.x im\n10,1,2\n");
  assert_int_equal(rcb_meas_read_csv(ms, p), RCB_OK);
  assert_true(rcb_test_close(rcb_meas_speed(ms), 50.0 * RCB_PI, 1e-15, 0));
  rcb_meas_destroy(ms);
}

/* Binary 58b written by hand: big-endian, uneven abscissa stored as 4-byte
 * floats (n_bytes = 20 n, the UC-SDRL layout), two points. */
static void be_double(FILE *fp, double v) {
  unsigned char b[8];
  uint64_t u;
  int i;
  memcpy(&u, &v, 8);
  for (i = 0; i < 8; i++) b[i] = (unsigned char)(u >> (56 - 8 * i));
  fwrite(b, 1, 8, fp);
}

static void be_float(FILE *fp, float v) {
  unsigned char b[4];
  uint32_t u;
  int i;
  memcpy(&u, &v, 4);
  for (i = 0; i < 4; i++) b[i] = (unsigned char)(u >> (24 - 8 * i));
  fwrite(b, 1, 4, fp);
}

static void test_uff_binary_big_endian(void **state) {
  const char *p = rcb_test_tmp_path("be.uff");
  FILE *fp = fopen(p, "wb");
  rcb_meas *ms = NULL;
  rcb_meas_channel_info c;
  (void)state;
  assert_non_null(fp);
  fprintf(fp, "%6d\n%6db%6d%6d%12d%12d%6d%6d%12d%12d\n", -1, 58, 2, 2, 11, 40, 0, 0, 0, 0);
  fprintf(fp, "NONE\nNONE\nNONE\nNONE\nNONE\n");
  fprintf(fp, "%5d%10d%5d%10d %10s%10ld%4d %10s%10ld%4d\n", 4, 1, 0, 0, "NONE", 4L, 2, "NONE",
          5L, 1);
  fprintf(fp, "%10d%10d%10d%13.5e%13.5e%13.5e\n", 6, 2, 0, 0.0, 0.0, 0.0);
  fprintf(fp, "%10d%5d%5d%5d %-20s %-20s\n", 18, 0, 0, 0, "NONE", "NONE");
  fprintf(fp, "%10d%5d%5d%5d %-20s %-20s\n", 8, 0, 0, 0, "NONE", "NONE");
  fprintf(fp, "%10d%5d%5d%5d %-20s %-20s\n", 13, 0, 0, 0, "NONE", "NONE");
  fprintf(fp, "%10d%5d%5d%5d %-20s %-20s\n", 0, 0, 0, 0, "NONE", "NONE");
  be_float(fp, 12.5f);
  be_double(fp, 1.0 / 3.0);
  be_double(fp, -2e-9);
  be_float(fp, 40.0f);
  be_double(fp, 10.0); /* 0x4024...: contains no '\n', but 0x0a may appear in others */
  be_double(fp, -1e300);
  fprintf(fp, "%6d\n", -1);
  fclose(fp);
  assert_int_equal(rcb_meas_create(&ms, NULL), RCB_OK);
  if (rcb_meas_read_uff(ms, p, 0, NULL) != RCB_OK) fail_msg("%s", rcb_meas_errmsg(ms));
  assert_int_equal(rcb_meas_point_count(ms), 2);
  assert_true(rcb_meas_grid(ms)[0] == TWO_PI * 12.5);
  assert_true(rcb_meas_grid(ms)[1] == TWO_PI * 40.0);
  assert_int_equal(rcb_meas_channel(ms, 0, &c), RCB_OK);
  assert_string_equal(c.response, "#4.y");
  assert_string_equal(c.reference, "#5.x");
  assert_true(c.data[0] == CMPLX(1.0 / 3.0, -2e-9));
  assert_true(c.data[1] == CMPLX(10.0, -1e300));
  rcb_meas_destroy(ms);
}

/* ------------------------------------------------------------- kinds -- */

static void test_kind_conversion(void **state) {
  rcb_meas *ms = NULL;
  double x[3] = {1.0, 10.0, 100.0};
  rcb_complex r[3] = {CMPLX(1.0, 2.0), CMPLX(-3.0, 0.5), CMPLX(1e-7, -1e-8)};
  rcb_meas_channel_info c;
  size_t i;
  (void)state;
  assert_int_equal(rcb_meas_create(&ms, NULL), RCB_OK);
  assert_int_equal(rcb_meas_set_grid(ms, RCB_MEAS_FRF, 3, x, 0.0), RCB_OK);
  assert_int_equal(rcb_meas_add_channel(ms, "DA.x", "DA.y", RCB_RECEPTANCE, r), RCB_OK);
  assert_int_equal(rcb_meas_convert(ms, RCB_INERTANCE), RCB_OK);
  assert_int_equal(rcb_meas_channel(ms, 0, &c), RCB_OK);
  assert_int_equal(c.kind, RCB_INERTANCE);
  for (i = 0; i < 3; i++) assert_true(cclose(c.data[i], -x[i] * x[i] * r[i], 1e-15));
  assert_int_equal(rcb_meas_convert(ms, RCB_MOBILITY), RCB_OK);
  for (i = 0; i < 3; i++) assert_true(cclose(c.data[i], CMPLX(0.0, x[i]) * r[i], 1e-15));
  assert_int_equal(rcb_meas_convert(ms, RCB_RECEPTANCE), RCB_OK);
  for (i = 0; i < 3; i++) assert_true(cclose(c.data[i], r[i], 1e-15));
  /* dividing by i w at 0 Hz is refused before anything changes */
  x[0] = 0.0;
  assert_int_equal(rcb_meas_set_grid(ms, RCB_MEAS_FRF, 3, x, 0.0), RCB_OK);
  assert_int_equal(rcb_meas_add_channel(ms, "DA.x", "DA.y", RCB_INERTANCE, r), RCB_OK);
  assert_int_equal(rcb_meas_convert(ms, RCB_RECEPTANCE), RCB_ERR_ARG);
  assert_non_null(strstr(rcb_meas_errmsg(ms), "0 Hz"));
  assert_int_equal(rcb_meas_channel(ms, 0, &c), RCB_OK);
  assert_int_equal(c.kind, RCB_INERTANCE);
  assert_true(c.data[1] == r[1]);
  rcb_meas_destroy(ms);
}

/* ------------------------------------------------------------- noise -- */

#define NN 20000

static rcb_meas *ones(size_t n, rcb_complex v) {
  rcb_meas *ms = NULL;
  double *x = malloc(n * sizeof *x);
  rcb_complex *d = malloc(n * sizeof *d);
  size_t i;
  assert_non_null(x);
  assert_non_null(d);
  for (i = 0; i < n; i++) {
    x[i] = 1.0 + (double)i;
    d[i] = v * (1.0 + 0.001 * (double)i);
  }
  assert_int_equal(rcb_meas_create(&ms, NULL), RCB_OK);
  assert_int_equal(rcb_meas_set_grid(ms, RCB_MEAS_FRF, n, x, 0.0), RCB_OK);
  assert_int_equal(rcb_meas_add_channel(ms, "DA.x", "DA.x", RCB_RECEPTANCE, d), RCB_OK);
  assert_int_equal(rcb_meas_add_channel(ms, "DB.x", "DA.x", RCB_RECEPTANCE, d), RCB_OK);
  free(x);
  free(d);
  return ms;
}

static const rcb_complex *chan(const rcb_meas *ms, size_t c) {
  rcb_meas_channel_info info;
  assert_int_equal(rcb_meas_channel(ms, c, &info), RCB_OK);
  return info.data;
}

static void test_noise_proportional(void **state) {
  const rcb_complex v = CMPLX(2e-6, -1e-6);
  rcb_meas *ms = ones(NN, v);
  const rcb_complex *d = chan(ms, 0);
  int bins[10] = {0};
  double lo = 1.0, hi = -1.0;
  size_t i;
  (void)state;
  assert_int_equal(rcb_meas_add_noise(ms, 10.0, 0.0, 7), RCB_OK);
  for (i = 0; i < NN; i++) {
    rcb_complex ratio = d[i] / (v * (1.0 + 0.001 * (double)i));
    double e = creal(ratio) - 1.0;
    assert_true(fabs(cimag(ratio)) < 1e-14); /* proportional: real factor */
    assert_true(fabs(e) <= 0.1 * (1.0 + 1e-14));
    lo = fmin(lo, e);
    hi = fmax(hi, e);
    bins[(int)fmin(9.0, floor((e + 0.1) / 0.02))]++;
  }
  /* covers [-0.1, 0.1]: both ends reached, each tenth holds ~NN/10 */
  assert_true(lo < -0.0995 && hi > 0.0995);
  for (i = 0; i < 10; i++) assert_true(abs(bins[i] - NN / 10) < NN / 40);
  rcb_meas_destroy(ms);
}

static void test_noise_systematic(void **state) {
  const rcb_complex v = CMPLX(0.0, 3.0);
  rcb_meas *ms = ones(1000, v);
  const rcb_complex *d = chan(ms, 1);
  double sum = 0.0, level, top = 0.0;
  size_t i;
  (void)state;
  for (i = 0; i < 1000; i++) sum += pow(3.0 * (1.0 + 0.001 * (double)i), 2);
  level = sqrt(sum) / 1000.0 * 0.05; /* beta_s = 5 % */
  assert_int_equal(rcb_meas_add_noise(ms, 0.0, 5.0, 99), RCB_OK);
  for (i = 0; i < 1000; i++) {
    double e = cabs(d[i] - v * (1.0 + 0.001 * (double)i));
    assert_true(e <= level * (1.0 + 1e-12));
    top = fmax(top, e);
  }
  assert_true(top > 0.99 * level);
  rcb_meas_destroy(ms);
}

static void test_noise_seeds(void **state) {
  rcb_meas *a = ones(100, 1.0), *b = ones(100, 1.0), *c = ones(100, 1.0);
  size_t i, differ = 0;
  (void)state;
  assert_int_equal(rcb_meas_add_noise(a, 10.0, 1.0, 12345), RCB_OK);
  assert_int_equal(rcb_meas_add_noise(b, 10.0, 1.0, 12345), RCB_OK);
  assert_int_equal(rcb_meas_add_noise(c, 10.0, 1.0, 12346), RCB_OK);
  assert_memory_equal(chan(a, 1), chan(b, 1), 100 * sizeof(rcb_complex));
  for (i = 0; i < 100; i++) differ += chan(a, 0)[i] != chan(c, 0)[i];
  assert_true(differ == 100);
  /* the two channels draw different numbers */
  for (i = 0, differ = 0; i < 100; i++) differ += chan(a, 0)[i] != chan(a, 1)[i];
  assert_true(differ == 100);
  assert_int_equal(rcb_meas_add_noise(a, -1.0, 0.0, 1), RCB_ERR_ARG);
  rcb_meas_destroy(a);
  rcb_meas_destroy(b);
  rcb_meas_destroy(c);
}

/* The stream itself, against an independent Python implementation of
 * splitmix64 seeding + xoshiro256** (r1 of points 1..3, seed 42). */
static void test_noise_stream(void **state) {
  static const double r1[3] = {-0.6645481157604711, 0.6987717813015502,
                               -0.12296568848833767};
  rcb_meas *ms = NULL;
  double x[3] = {1.0, 2.0, 3.0};
  rcb_complex d[3] = {1.0, 1.0, 1.0};
  const rcb_complex *e;
  size_t i;
  (void)state;
  assert_int_equal(rcb_meas_create(&ms, NULL), RCB_OK);
  assert_int_equal(rcb_meas_set_grid(ms, RCB_MEAS_FRF, 3, x, 0.0), RCB_OK);
  assert_int_equal(rcb_meas_add_channel(ms, "DA.x", "DA.x", RCB_RECEPTANCE, d), RCB_OK);
  assert_int_equal(rcb_meas_add_noise(ms, 100.0, 0.0, 42), RCB_OK);
  e = chan(ms, 0);
  for (i = 0; i < 3; i++) assert_true(creal(e[i]) - 1.0 == r1[i]);
  rcb_meas_destroy(ms);
}

/* ---------------------------------------------------------- bad data -- */

/* Read @p text as UFF; expect RCB_ERR_PARSE and each of the NULL-ended
 * fragments in the message. */
static void bad_uff(const char *text, ...) {
  const char *p = rcb_test_tmp_path("bad.uff"), *frag;
  rcb_meas *ms = NULL;
  va_list ap;
  write_text(p, text);
  assert_int_equal(rcb_meas_create(&ms, NULL), RCB_OK);
  if (rcb_meas_read_uff(ms, p, 0, NULL) != RCB_ERR_PARSE)
    fail_msg("expected RCB_ERR_PARSE, message '%s'", rcb_meas_errmsg(ms));
  va_start(ap, text);
  while ((frag = va_arg(ap, const char *)) != NULL)
    if (!strstr(rcb_meas_errmsg(ms), frag))
      fail_msg("message '%s' lacks '%s'", rcb_meas_errmsg(ms), frag);
  va_end(ap);
  assert_int_equal(rcb_meas_point_count(ms), 0);
  assert_int_equal(rcb_meas_channel_count(ms), 0);
  rcb_meas_destroy(ms);
}

static char *uff_text(int nrec, ...) {
  static char buf[16384];
  FILE *fp = fmemopen(buf, sizeof buf, "w");
  va_list ap;
  int k;
  assert_non_null(fp);
  va_start(ap, nrec);
  for (k = 0; k < nrec; k++) {
    int ftype = va_arg(ap, int), rd = va_arg(ap, int), otype = va_arg(ap, int);
    long npts = va_arg(ap, long);
    int even = va_arg(ap, int);
    double x0 = va_arg(ap, double);
    int s9 = va_arg(ap, int), s10 = va_arg(ap, int);
    const char *vals = va_arg(ap, const char *);
    rec58(fp, ftype, 1, rd, ftype == 1 ? 0 : 2, ftype == 1 ? 0 : 1, otype, npts, even, x0, 10.0,
          0.0, 18, s9, s10, 0, vals);
  }
  va_end(ap);
  fclose(fp);
  return buf;
}

/* Issue #25: an axial record (direction 3) beside a lateral one is skipped
 * with a warning naming it (it refused the whole file). */
static void test_uff_axial_skipped(void **state) {
  static const char v3[] = "   1.00000000000e+00   2.00000000000e+00   3.00000000000e+00   "
                           "4.00000000000e+00\n   5.00000000000e+00   6.00000000000e+00\n";
  const char *p = rcb_test_tmp_path("axial.uff");
  rcb_meas *ms = NULL;
  (void)state;
  write_text(p, uff_text(2, 4, 3, 6, 3L, 1, 10.0, 8, 13, v3, 4, 1, 6, 3L, 1, 10.0, 8, 13, v3));
  assert_int_equal(rcb_meas_create(&ms, NULL), RCB_OK);
  if (rcb_meas_read_uff(ms, p, 0, NULL)) fail_msg("%s", rcb_meas_errmsg(ms));
  assert_int_equal(rcb_meas_channel_count(ms), 1);
  assert_int_equal(rcb_meas_point_count(ms), 3);
  assert_true(rcb_meas_warning_count(ms) >= 1);
  assert_non_null(strstr(rcb_meas_warning(ms, 0), "axial.uff:8: dataset 58 record 1: skipped: "
                                                 "its response (node 1) is axial"));
  rcb_meas_destroy(ms);
}

static void test_bad_uff(void **state) {
  static const char uneven_dec[] =
      "  1.00000e+01   1.00000000000e+00   2.00000000000e+00\n"
      "  3.00000e+01   1.00000000000e+00   2.00000000000e+00\n"
      "  2.00000e+01   1.00000000000e+00   2.00000000000e+00\n";
  static const char uneven_neg[] =
      " -1.00000e+01   1.00000000000e+00   2.00000000000e+00\n"
      "  3.00000e+01   1.00000000000e+00   2.00000000000e+00\n"
      "  4.00000e+01   1.00000000000e+00   2.00000000000e+00\n";
  static const char nan3[] =
      "   1.00000000000e+00   2.00000000000e+00                 nan   4.00000000000e+00\n"
      "   5.00000000000e+00   6.00000000000e+00\n";
  static const char short3[] =
      "   1.00000000000e+00   2.00000000000e+00   3.00000000000e+00   4.00000000000e+00\n";
  (void)state;
  bad_uff(uff_text(1, 4, 1, 6, 3L, 0, 0.0, 8, 13, uneven_dec), "not increasing", "record 1",
          "point 3", NULL);
  bad_uff(uff_text(1, 4, 1, 6, 3L, 0, 0.0, 8, 13, uneven_neg), "point 1 is -10", NULL);
  bad_uff(uff_text(1, 4, 1, 6, 3L, 1, 10.0, 8, 13, nan3), "bad.uff:14:", "not finite", NULL);
  bad_uff(uff_text(1, 4, 1, 6, 3L, 1, 10.0, 8, 13, short3), "truncated", "4 of 6 values",
          NULL);
  bad_uff(uff_text(2, 4, 1, 6, 3L, 1, 10.0, 8, 13, V3, 4, 2, 6, 2L, 1, 10.0, 8, 13,
                   "   1.00000000000e+00   2.00000000000e+00   3.00000000000e+00   "
                   "4.00000000000e+00\n"),
          "record 2", "mismatched lengths", NULL);
  bad_uff(uff_text(2, 4, 1, 6, 3L, 1, 10.0, 8, 13, V3, 4, 2, 6, 3L, 1, 11.0, 8, 13, V3),
          "record 2", "abscissa differs from record 1", NULL);
  bad_uff(uff_text(1, 4, 3, 6, 3L, 1, 10.0, 8, 13, V3), "its response is axial (direction 3",
          "bad.uff:8:", "nothing to read", NULL);
  bad_uff(uff_text(1, 4, 7, 6, 3L, 1, 10.0, 8, 13, V3), "unknown response direction code 7",
          "bad.uff:8:", NULL);
  /* a count no file of this size can hold: refused before allocating it (it
   * said "expected at least 1") */
  bad_uff(uff_text(1, 4, 1, 6, 999999999L, 1, 10.0, 8, 13, V3), "bad.uff:9:",
          "claims 999999999 points", "truncated, or a wrong count", NULL);
  bad_uff(uff_text(1, 4, 1, 6, 3L, 1, 10.0, 9, 13, V3), "wrong units", "ordinate data type 9",
          NULL);
  bad_uff(uff_text(1, 4, 1, 6, 3L, 1, 10.0, 8, 0, V3), "wrong units", "denominator", NULL);
  bad_uff(uff_text(1, 4, 1, 4, 3L, 1, 10.0, 8, 13, V3), "real", NULL);
  bad_uff(uff_text(2, 4, 1, 6, 3L, 1, 10.0, 8, 13, V3, 4, 1, 6, 3L, 1, 10.0, 8, 13, V3),
          "record 2", "duplicate channel #1.x/#2.x", NULL);
  bad_uff(uff_text(2, 4, 1, 6, 3L, 1, 10.0, 8, 13, V3, 1, 2, 6, 3L, 1, 10.0, 8, 0, V3),
          "record 2", "all FRFs or all unbalance", NULL);
  bad_uff("    -1\n    58\nid1\n", "truncated", NULL);
  bad_uff("    -1\n   164\nx\n    -1\n", "no dataset 58 record", NULL);
}

static void test_bad_uff_binary(void **state) {
  rcb_meas *a = sample_frf(0.0, 0), *b = NULL;
  const char *p = rcb_test_tmp_path("trunc.uff");
  FILE *fp;
  long size;
  char *buf;
  (void)state;
  assert_int_equal(rcb_meas_write_uff(a, p, 1, 4, MAP), RCB_OK);
  fp = fopen(p, "rb");
  assert_non_null(fp);
  fseek(fp, 0, SEEK_END);
  size = ftell(fp);
  rewind(fp);
  buf = malloc((size_t)size);
  assert_non_null(buf);
  assert_int_equal(fread(buf, 1, (size_t)size, fp), (size_t)size);
  fclose(fp);
  fp = fopen(p, "wb"); /* cut inside the last record's binary data */
  assert_non_null(fp);
  fwrite(buf, 1, (size_t)size - 100, fp);
  fclose(fp);
  free(buf);
  assert_int_equal(rcb_meas_create(&b, NULL), RCB_OK);
  assert_int_equal(rcb_meas_read_uff(b, p, 4, MAP), RCB_ERR_PARSE);
  assert_non_null(strstr(rcb_meas_errmsg(b), "record 3"));
  assert_non_null(strstr(rcb_meas_errmsg(b), "truncated binary data"));
  rcb_meas_destroy(a);
  rcb_meas_destroy(b);
}

static void bad_csv(const char *text, const char *f1, const char *f2) {
  const char *p = rcb_test_tmp_path("bad.csv");
  rcb_meas *ms = NULL;
  write_text(p, text);
  assert_int_equal(rcb_meas_create(&ms, NULL), RCB_OK);
  if (rcb_meas_read_csv(ms, p) != RCB_ERR_PARSE)
    fail_msg("expected RCB_ERR_PARSE, message '%s'", rcb_meas_errmsg(ms));
  if (!strstr(rcb_meas_errmsg(ms), f1) || (f2 && !strstr(rcb_meas_errmsg(ms), f2)))
    fail_msg("message '%s' lacks '%s' / '%s'", rcb_meas_errmsg(ms), f1, f2 ? f2 : "");
  rcb_meas_destroy(ms);
}

static void test_bad_csv(void **state) {
  static const char h[] = "freq_hz,DA.x/DA.x re,DA.x/DA.x im\n";
  char t[512];
  (void)state;
  snprintf(t, sizeof t, "%s10,1,2\n5,1,2\n", h);
  bad_csv(t, "bad.csv:3:", "not increasing");
  snprintf(t, sizeof t, "%s-10,1,2\n5,1,2\n", h);
  bad_csv(t, "bad.csv:2:", "negative");
  snprintf(t, sizeof t, "%s10,1,2\n20,nan,2\n", h);
  bad_csv(t, "bad.csv:3: column 2 (DA.x/DA.x)", "not finite");
  snprintf(t, sizeof t, "%s10,1,2\n20,1\n", h);
  bad_csv(t, "bad.csv:3:", "2 fields, the header has 3");
  bad_csv("freq_hz,DA.x/DA.x re,DA.x/DA.x im,DA.x/DA.x re,DA.x/DA.x im\n1,1,2,3,4\n",
          "duplicate channel DA.x/DA.x", "column 4 repeats its re (column 2)");
  bad_csv("freq_hz,DA.z/DA.x re,DA.z/DA.x im\n1,1,2\n", "unknown direction", "DA.z");
  /* "imag" is read since issue #17; an unknown part word still is not */
  bad_csv("freq_hz,DA.x/DA.x re,DA.x/DA.x quad\n1,1,2\n", "bad.csv:1: column 3",
          "unknown part 'quad'");
  bad_csv("freq_hz,DA.x/DA.x re,DB.x/DA.x im\n1,1,2\n", "bad.csv:1: column 2", "pair");
  bad_csv("freq_hz,DA.x re,DA.x im\n1,1,2\n", "RESPONSE/REFERENCE", NULL);
  bad_csv("# kind = velocity\nfreq_hz,DA.x/DA.x re,DA.x/DA.x im\n1,1,2\n", "bad.csv:1:",
          "receptance, mobility or inertance");
  bad_csv("time_s,DA.x/DA.x re,DA.x/DA.x im\n1,1,2\n", "first column 'time_s'", NULL);
  bad_csv("freq_hz,DA.x/DA.x re,DA.x/DA.x im\n", "no data rows", NULL);
  /* issue #35 item 3: what stays refused among the lab conventions */
  bad_csv("freq_hz,DA.x/DB.y_re,DA.x/DB.y_im,DA.x/DB.y_mag,DA.x/DB.y_phase_deg\n1,1,2,3,4\n",
          "bad.csv:1: channel DA.x/DB.y is given both as re/im and as mag/phase (columns 2 "
          "and 4): ambiguous", NULL);
  bad_csv("freq_hz,DA.x/DB.y re,DA.x/DB.y mag,DA.x/DB.y im,DA.x/DB.y phase_deg\n1,1,2,3,4\n",
          "both as re/im and as mag/phase", NULL);
  bad_csv("freq_hz,DA.x/DB.y_mag,DA.x/DB.y_phase\n1,1,2\n", "bad.csv:1: column 3",
          "without the unit degrees");
  bad_csv("freq_hz,DA.x/DB.y_re,DA.y/DB.y_im\n1,1,2\n", "column 2 ('DA.x/DB.y'): its re has "
          "no pair", "\"DA.x/DB.y im\"");
  bad_csv("freq_hz,DA.x/DB.y_re,DA.x/DB.y_im,DA.x/DB.y_im\n1,1,2,3\n",
          "duplicate channel DA.x/DB.y: column 4 repeats its im (column 3)", NULL);
  bad_csv("freq_hz,DA.x/DB.y_quad,DA.x/DB.y_im\n1,1,2\n", "bad.csv:1: column 2",
          "or CHANNEL_re");
  bad_csv("freq_hz,2.x/11.y_re,2.x/11.y_im\n1,1,2\n", "station '2' is a number",
          "--map 2=STATION");
  bad_csv(",freq_hz,DA.x/DB.y_re,DA.x/DB.y_im\n0,1,1,2\n", "bad.csv:1: the first column has "
          "no name", "index=False");
  bad_csv("# freq_hz,DA.x/DB.y_re,DA.x/DB.y_im\n1,1,2\n", "bad.csv:2: the line starts with "
          "a number", "comments=''");
}

/* No fixed-size buffer cuts a header or a comment (issue #35 item 6): at the
 * limit read, past it refused with the limit. */
static void test_csv_limits(void **state) {
  char text[2048], ref[100], name[260];
  const char *p = rcb_test_tmp_path("lim.csv");
  rcb_meas *ms = NULL;
  (void)state;
  memset(ref, 'r', 80);
  ref[80] = '\0';
  snprintf(text, sizeof text, "# phase = lag (%s)\nfreq_hz,DA.x/DB.y re,DA.x/DB.y im\n1,1,2\n",
           ref);
  write_text(p, text);
  assert_int_equal(rcb_meas_create(&ms, NULL), RCB_OK);
  if (rcb_meas_read_csv(ms, p)) fail_msg("%s", rcb_meas_errmsg(ms));
  rcb_meas_destroy(ms);
  snprintf(text, sizeof text, "# phase = lag (%sr)\nfreq_hz,DA.x/DB.y re,DA.x/DB.y im\n1,1,2\n",
           ref);
  bad_csv(text, "bad.csv:1: phase reference 'rrrr", "81 characters; at most 80");
  memset(name, 'n', 250);
  name[250] = '\0';
  snprintf(text, sizeof text, "freq_hz,%s/DB.y re,%s/DB.y im\n1,1,2\n", name, name);
  bad_csv(text, "bad.csv:1: column 2: channel name 'nnnn", "255 characters; at most 209");
  /* a unit or a part word of 250 characters: not degrees, not a part (no cut
   * prefix matched) */
  memset(name, 'x', 250);
  snprintf(text, sizeof text, "freq_hz,DA.x/DB.y mag,DA.x/DB.y phase (deg%s)\n1,1,2\n", name);
  bad_csv(text, "bad.csv:1: column 3", "without the unit degrees");
  snprintf(text, sizeof text, "freq_hz,DA.x/DB.y mag,DA.x/DB.y phase_%s\n1,1,2\n", name);
  bad_csv(text, "bad.csv:1: column 3", "unknown part");
  /* a node map's station: 100 characters read whole ("S...S.rx" fills a
   * channel), 101 refused with the limit, by the CSV and the UFF reader */
  {
    char st[102];
    rcb_uff_node map[1] = {{1, st, NULL, NULL}};
    rcb_meas_channel_info c;
    memset(st, 's', 101);
    st[100] = '\0';
    write_text(p, "freq_hz,1.rx/1.x_re,1.rx/1.x_im\n1,1,2\n");
    assert_int_equal(rcb_meas_create(&ms, NULL), RCB_OK);
    if (rcb_meas_read_csv_map(ms, p, 1, map)) fail_msg("%s", rcb_meas_errmsg(ms));
    assert_int_equal(rcb_meas_channel(ms, 0, &c), RCB_OK);
    assert_int_equal(strlen(c.response), 103);
    assert_int_equal(strncmp(c.response, st, 100), 0);
    assert_string_equal(c.response + 100, ".rx");
    st[100] = 's';
    st[101] = '\0';
    assert_int_equal(rcb_meas_read_csv_map(ms, p, 1, map), RCB_ERR_ARG);
    assert_non_null(strstr(rcb_meas_errmsg(ms), "read_csv: node 1 of the map: station 'ssss"));
    assert_non_null(strstr(rcb_meas_errmsg(ms), "101 characters; at most 100"));
    assert_int_equal(rcb_meas_read_uff(ms, p, 1, map), RCB_ERR_ARG);
    assert_non_null(strstr(rcb_meas_errmsg(ms), "read_uff: node 1 of the map: station"));
    rcb_meas_destroy(ms);
  }
}

static void test_bad_api(void **state) {
  rcb_meas *ms = NULL;
  double x[3] = {1.0, 2.0, 2.0};
  rcb_complex d[3] = {1.0, NAN, 1.0};
  (void)state;
  assert_int_equal(rcb_meas_create(&ms, NULL), RCB_OK);
  assert_int_equal(rcb_meas_add_channel(ms, "DA.x", "DA.x", RCB_RECEPTANCE, d), RCB_ERR_STATE);
  assert_int_equal(rcb_meas_set_grid(ms, RCB_MEAS_FRF, 3, x, 0.0), RCB_ERR_ARG);
  assert_non_null(strstr(rcb_meas_errmsg(ms), "not increasing"));
  x[0] = -1.0;
  x[2] = 3.0;
  assert_int_equal(rcb_meas_set_grid(ms, RCB_MEAS_FRF, 3, x, 0.0), RCB_ERR_ARG);
  assert_non_null(strstr(rcb_meas_errmsg(ms), "negative"));
  x[0] = 1.0;
  assert_int_equal(rcb_meas_set_grid(ms, RCB_MEAS_FRF, 3, x, 0.0), RCB_OK);
  assert_int_equal(rcb_meas_add_channel(ms, "DA.x", "DA.x", RCB_RECEPTANCE, d), RCB_ERR_ARG);
  assert_non_null(strstr(rcb_meas_errmsg(ms), "point 2"));
  d[1] = 2.0;
  assert_int_equal(rcb_meas_add_channel(ms, "DA.z", "DA.x", RCB_RECEPTANCE, d), RCB_ERR_ARG);
  assert_non_null(strstr(rcb_meas_errmsg(ms), "unknown direction"));
  assert_int_equal(rcb_meas_add_channel(ms, "DA.x", NULL, RCB_RECEPTANCE, d), RCB_ERR_ARG);
  assert_int_equal(rcb_meas_add_channel(ms, "DA.x", "DA.x", RCB_RECEPTANCE, d), RCB_OK);
  assert_int_equal(rcb_meas_add_channel(ms, "DA.x", "DA.x", RCB_MOBILITY, d), RCB_ERR_ARG);
  assert_non_null(strstr(rcb_meas_errmsg(ms), "duplicate"));
  assert_int_equal(rcb_meas_channel_count(ms), 1);
  rcb_meas_destroy(ms);
}

/* ------------------------------------------------- writing, allocator -- */

static void test_write_atomic(void **state) {
  rcb_meas *a = sample_frf(0.0, 0);
  const char *p = rcb_test_tmp_path("nomap.uff");
  char cmd[600];
  (void)state;
  /* station DA without a node number: refused, nothing left behind */
  assert_int_equal(rcb_meas_write_uff(a, p, 0, 0, NULL), RCB_ERR_ARG);
  assert_non_null(strstr(rcb_meas_errmsg(a), "no UFF node number"));
  assert_int_equal(access(p, F_OK), -1);
  assert_int_equal(rcb_meas_write_uff(a, rcb_test_tmp_path("no/such/dir.uff"), 0, 4, MAP), RCB_ERR_IO);
  assert_non_null(strstr(rcb_meas_errmsg(a), "no/such/dir.uff"));
  /* an existing file is replaced whole */
  write_text(p, "old");
  assert_int_equal(rcb_meas_write_uff(a, p, 1, 4, MAP), RCB_OK);
  snprintf(cmd, sizeof cmd, "test $(ls '%s' | grep -c tmp) -eq 0", rcb_test_tmpdir());
  assert_int_equal(system(cmd), 0);
  rcb_meas_destroy(a);
}

static void test_allocator(void **state) {
  rcb_test_counter cnt = {0, 0};
  rcb_allocator al = rcb_test_counting_allocator(&cnt);
  rcb_meas *ms = NULL;
  const char *p = rcb_test_tmp_path("alloc.uff");
  rcb_meas *src = sample_frf(0.0, 0);
  (void)state;
  assert_int_equal(rcb_meas_write_uff(src, p, 1, 4, MAP), RCB_OK);
  rcb_meas_destroy(src);
  assert_int_equal(rcb_meas_create(&ms, &al), RCB_OK);
  assert_int_equal(rcb_meas_read_uff(ms, p, 4, MAP), RCB_OK);
  assert_int_equal(rcb_meas_write_csv(ms, rcb_test_tmp_path("alloc.csv")), RCB_ERR_ARG); /* mixed kinds */
  assert_int_equal(rcb_meas_convert(ms, RCB_RECEPTANCE), RCB_OK);
  assert_int_equal(rcb_meas_write_csv(ms, rcb_test_tmp_path("alloc.csv")), RCB_OK);
  assert_int_equal(rcb_meas_read_csv(ms, rcb_test_tmp_path("alloc.csv")), RCB_OK);
  rcb_meas_destroy(ms);
  assert_true(cnt.allocs > 5);
  assert_int_equal(cnt.allocs, cnt.frees);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_uff_ascii_roundtrip),   cmocka_unit_test(test_uff_binary_roundtrip),
      cmocka_unit_test(test_csv_roundtrip),         cmocka_unit_test(test_unbalance_roundtrip),
      cmocka_unit_test(test_uff_read_hand_written), cmocka_unit_test(test_csv_read_rcbtool_output),
      cmocka_unit_test(test_csv_comments),          cmocka_unit_test(test_kind_conversion),
      cmocka_unit_test(test_noise_proportional),    cmocka_unit_test(test_noise_systematic),
      cmocka_unit_test(test_noise_seeds),           cmocka_unit_test(test_noise_stream),
      cmocka_unit_test(test_bad_uff), cmocka_unit_test(test_uff_axial_skipped),               cmocka_unit_test(test_bad_uff_binary),
      cmocka_unit_test(test_csv_header_variants),
      cmocka_unit_test(test_csv_lab_conventions),
      cmocka_unit_test(test_csv_limits),
      cmocka_unit_test(test_uff_speed_not_stated),
      cmocka_unit_test(test_bad_csv),               cmocka_unit_test(test_bad_api),
      cmocka_unit_test(test_write_atomic),          cmocka_unit_test(test_allocator),
      cmocka_unit_test(test_uff_binary_big_endian), cmocka_unit_test(test_uff_map_directions),
      cmocka_unit_test(test_csv_magnitude_only),
  };
  return cmocka_run_group_tests(tests, rcb_test_setup_tmpdir, rcb_test_teardown_tmpdir);
}
