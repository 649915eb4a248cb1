/*
 * rcb_strtod and rcb_strtod_in (core/numparse.c) against the C library's
 * strtod: the same value bit for bit, the same end pointer and the same errno, over a fixed
 * set of awkward spellings and a million fuzzed ones (fixed seed): random
 * digit counts with leading zeros, signs, e/E exponents with +/-, leading and
 * trailing '.', 17-20 significant digits, printf'd doubles of every
 * precision, exact and near midpoints between adjacent doubles, the
 * subnormal range and exponents past the double range.
 */
#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "core/rcb_internal.h"

typedef struct rng {
  uint64_t s;
} rng;

static uint64_t next(rng *r) { /* splitmix64 */
  uint64_t z = (r->s += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

static int below(rng *r, int n) { return (int)(next(r) % (uint64_t)n); }

static int same(const char *s, const char *what, double a, ptrdiff_t ea, int erra, double b,
                ptrdiff_t eb, int errb) {
  if (memcmp(&a, &b, sizeof a) == 0 && ea == eb && erra == errb) return 1;
  print_error("'%s': %s %.17g (end +%td, errno %d), strtod %.17g (end +%td, errno %d)\n", s,
              what, a, ea, erra, b, eb, errb);
  return 0;
}

/* 1 when rcb_strtod, rcb_strtod_in (the string followed by digits up to its
 * lim, which it must not take as part of the number) and strtod agree on s;
 * prints a disagreement. */
static int agree(const char *s) {
  char *e1, *e2, *e3, pad[1100];
  double a, b, c;
  int err1, err2, err3;
  size_t n = strlen(s);
  assert_true(n < sizeof pad);
  memset(pad, '7', sizeof pad);
  memcpy(pad, s, n + 1);
  errno = 0;
  a = rcb_strtod(s, &e1);
  err1 = errno;
  errno = 0;
  c = rcb_strtod_in(pad, pad + sizeof pad, &e3);
  err3 = errno;
  errno = 0;
  b = strtod(s, &e2);
  err2 = errno;
  return same(s, "rcb_strtod", a, e1 - s, err1, b, e2 - s, err2) &&
         same(s, "rcb_strtod_in", c, e3 - pad, err3, b, e2 - s, err2);
}

static void test_fixed_spellings(void **state) {
  static const char *const cases[] = {
      "0", "-0", "+0", "-0.0e-5", "0e999999999", "0.", ".0", ".5", "5.", "-.5e1", "1e308",
      "1e309", "-1e309", "1e-400", "1.7976931348623157e308", "1.7976931348623159e308",
      "2.2250738585072011e-308", "2.2250738585072014e-308", "4.9e-324", "2.4703282292062327e-324",
      "2.4703282292062328e-324", "9007199254740993", "9007199254740992", "9007199254740991",
      "18014398509481985", "9223372036854775807", "9999999999999999999", "10000000000000000000",
      "99999999999999999999", "0.1", "0.30000000000000004", "3.141592653589793238462643",
      "1e22", "1e23", "1e-22", "1e-23", "123456789012345678e-40", "8.98846567431158e307",
      "0x1p3", "0X1P-2", "inf", "-Infinity", "nan", "NAN(123)", "1e", "1e+", "1E-", "1ex",
      ".", "-.", "+", "", " 12", "\t-3.5", "\n7", "1.5x", "1,5", "00x1", "0.000000000000000000001",
      "1.5e+0003", "-2.5E-0003", "1e-0", "007", "1e2147483648", "1e-2147483649",
      "4.000000000000000000000000000000001", "1.00000000000000011102230246251565404236316680908203125",
      "1.00000000000000011102230246251565404236316680908203124",
      "1.00000000000000011102230246251565404236316680908203126"};
  static const char *const mantissas[] = {"1", "9007199254740993", "1234567890123456789",
                                          "9999999999999999999", "4.9406564584124654"};
  char buf[64];
  size_t i, j, bad = 0;
  int k;
  (void)state;
  for (i = 0; i < sizeof cases / sizeof *cases; i++) bad += !agree(cases[i]);
  /* a byte next to the digits ('0' - 1, '9' + 1 .. '9' + 6) at each place of
   * an eight-digit block */
  for (j = 0; j < 8; j++) {
    static const char near[] = "/:;<=>?";
    for (i = 0; near[i]; i++) {
      snprintf(buf, sizeof buf, "0.1234567890123456789");
      buf[2 + j] = near[i];
      bad += !agree(buf);
      snprintf(buf, sizeof buf, "12345678901234567");
      buf[j + 1] = near[i];
      bad += !agree(buf);
    }
  }
  /* every power of ten of the exact paths' table (|k| <= 44) and past it */
  for (j = 0; j < sizeof mantissas / sizeof *mantissas; j++)
    for (k = -70; k <= 70; k++) {
      snprintf(buf, sizeof buf, "%se%d", mantissas[j], k);
      bad += !agree(buf);
    }
  assert_int_equal(bad, 0);
}

static void put_digits(rng *r, char **p, int n, int lead_zero_ok) {
  int i;
  for (i = 0; i < n; i++) *(*p)++ = (char)('0' + (i == 0 && !lead_zero_ok ? 1 + below(r, 9)
                                                                           : below(r, 10)));
}

/* sign, integer digits (maybe leading zeros), '.', fraction, exponent */
static void random_spelling(rng *r, char *buf) {
  char *p = buf;
  int ni = below(r, 12), nf = below(r, 24), z = below(r, 4) == 0 ? below(r, 4) : 0;
  if (below(r, 3) == 0) *p++ = below(r, 2) ? '-' : '+';
  while (z--) *p++ = '0';
  put_digits(r, &p, ni, 1);
  if (nf > 0 || below(r, 4) == 0) *p++ = '.';
  put_digits(r, &p, nf, 1);
  if (ni == 0 && nf == 0) *p++ = '7';
  if (below(r, 2)) {
    int x = below(r, 8) == 0 ? below(r, 700) : below(r, 40);
    *p++ = below(r, 2) ? 'e' : 'E';
    if (below(r, 2)) *p++ = below(r, 3) ? '-' : '+';
    p += sprintf(p, below(r, 5) == 0 ? "%03d" : "%d", x);
  }
  *p = '\0';
}

/* a double of any normal or subnormal magnitude, printed as printf does */
static void printed_double(rng *r, char *buf) {
  uint64_t bits = next(r) & 0x7FFFFFFFFFFFFFFFull;
  double x;
  int prec = below(r, 21);
  if (below(r, 2)) /* the magnitudes of measured signals: 1e-12 .. 1e6 */
    bits = (bits & 0xFFFFFFFFFFFFFull) | ((uint64_t)(1023 - 40 + below(r, 60)) << 52);
  memcpy(&x, &bits, sizeof x);
  if (!isfinite(x)) x = 1.0;
  if (below(r, 2)) x = -x;
  switch (below(r, 3)) {
  case 0: snprintf(buf, 1024, "%.*e", prec, x); break;
  case 1: snprintf(buf, 1024, "%.*g", prec + 1, x); break;
  default: snprintf(buf, 1024, "%.*f", below(r, 25), x); break;
  }
}

/* exact midpoints (2^53 + odd) 2^j and the integers either side: ties to even */
static void midpoint_integer(rng *r, char *buf) {
  uint64_t m = ((1ull << 53) + (next(r) & ((1ull << 20) - 1)) * 2u + 1u) << below(r, 11);
  m += (uint64_t)below(r, 3) - 1u;
  if (below(r, 2))
    snprintf(buf, 1024, "%llu", (unsigned long long)m);
  else /* the same digits with the point moved: near a midpoint, scaled */
    snprintf(buf, 1024, "%llue-%d", (unsigned long long)m, below(r, 40));
}

/* 17-20 significant digits of the midpoint between a double and the next
 * one (exact in a long double of 64 or more mantissa bits), so that the
 * value is within a few units of the 20th digit of a tie */
static void midpoint_printed(rng *r, char *buf) {
  uint64_t bits = (next(r) & 0xFFFFFFFFFFFFFull) | ((uint64_t)(1023 - 60 + below(r, 120)) << 52);
  double x, y;
  memcpy(&x, &bits, sizeof x);
  y = nextafter(x, INFINITY);
#if LDBL_MANT_DIG >= 64
  {
    long double mid = ((long double)x + (long double)y) / 2.0L;
    snprintf(buf, 1024, "%.*Le", 16 + below(r, 4), mid);
  }
#else
  snprintf(buf, 1024, "%.*e", 16 + below(r, 4), x + (y - x) / 2.0);
#endif
}

static void test_fuzzed_spellings(void **state) {
  rng r = {20261127u};
  char buf[1024];
  long i, bad = 0;
  (void)state;
  for (i = 0; i < 1000000 && bad < 10; i++) {
    switch (i % 4) {
    case 0: random_spelling(&r, buf); break;
    case 1: printed_double(&r, buf); break;
    case 2: midpoint_integer(&r, buf); break;
    default: midpoint_printed(&r, buf); break;
    }
    bad += !agree(buf);
  }
  assert_int_equal(bad, 0);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_fixed_spellings),
      cmocka_unit_test(test_fuzzed_spellings),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
