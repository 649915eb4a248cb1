/*
 * rcb_strtod: strtod's result, bit for bit, without strtod's cost on the
 * spellings that text data files are made of (issue #25: strtod was 35-55 %
 * of `rcbtool estimate` on a CSV of '%.18e' numbers).
 *
 * A number [sign] digits [. digits] [e|E [sign] digits] of at most 19
 * significant digits is read into an integer mantissa m < 10^19 and a decimal
 * exponent k; its value is m 10^k. Two exact paths, then strtod:
 *  1. Clinger (1990): m <= 2^53 and |k| <= 22 (or m 10^(k-22) still <= 2^53):
 *     m and 10^|k| are both doubles exactly, so one IEEE multiplication or
 *     division rounds the exact value once: the correctly rounded result.
 *  2. |k| <= 44: m is an exact double-double, 10^k one exact (k >= 0) or
 *     within 2^-106 (k < 0) from a table; their product is formed to within
 *     2^-99 of its value (the error terms of double-double arithmetic,
 *     Dekker 1971, are below 8 2^-106). The leading double is the correctly
 *     rounded result unless the value lies within that bound of a midpoint
 *     between two doubles; then, and only then, the number goes to strtod.
 *  3. Everything else (20 or more significant digits, larger exponents, hex,
 *     inf, nan, leading white space other than blanks, "1e" with no exponent
 *     digits, x87 arithmetic): strtod on the same bytes, not copied.
 * Digits are read eight at a time (one word: checked, then valued in three
 * multiplications) where the caller says the bytes past the field are
 * readable (rcb_strtod_in: the CSV reader's buffer), one at a time otherwise.
 * The results of paths 1 and 2 are normal doubles, so strtod would not set
 * errno there either; tests/test_numparse.c checks value, end and errno
 * against strtod over a million fuzzed spellings.
 *
 * Locale: paths 1-2 take '.' as the decimal point, which is what strtod does
 * in the "C" locale; path 3 is strtod itself, which follows LC_NUMERIC. The
 * library never calls setlocale, nor does rcbtool, and Python leaves
 * LC_NUMERIC at "C", so both read '.' there, as the readers always have.
 */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "core/rcb_internal.h"

/* Double-double arithmetic needs each operation rounded once to double. */
#if defined(FLT_EVAL_METHOD) && FLT_EVAL_METHOD == 0
#define NUMPARSE_FAST 1
#else
#define NUMPARSE_FAST 0
#endif

static double pow10_exact(int k) { /* 10^k, 0 <= k <= 22: exact doubles */
  static const double p[23] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                               1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                               1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};
  return p[k];
}

/* a b = *hi + *lo exactly (no overflow, no underflow). With a hardware fma
 * (FP_FAST_FMA) its one rounding gives the low part; without one, Dekker's
 * product of halves: the compiler cannot fuse operations on a target without
 * the instruction, so each one rounds as written. */
static void two_prod(double a, double b, double *hi, double *lo) {
#ifdef FP_FAST_FMA
  *hi = a * b;
  *lo = fma(a, b, -*hi);
#else
  const double split = 134217729.0; /* 2^27 + 1 */
  double ca = split * a, cb = split * b;
  double ah = ca - (ca - a), al = a - ah, bh = cb - (cb - b), bl = b - bh;
  *hi = a * b;
  *lo = ((ah * bh - *hi) + ah * bl + al * bh) + al * bl;
#endif
}

/* 10^k and 10^-k, k = 0..44, as double-doubles hi + lo: 10^k exactly (5^44
 * < 2^106), 10^-k within 2^-106 of its value. Printed by Python:
 *   from fractions import Fraction as F
 *   for x in [F(10) ** k or F(1, 10 ** k)]: hi = float(x); lo = float(x - F(hi))
 *   print(hi.hex(), lo.hex())
 * tests/test_numparse.c reads m 10^k and m 10^-k for every k here. */
static const double POW10_DD[45][2] = {
    {0x1.0000000000000p+0, 0x0.0p+0}, /* 1e0 */
    {0x1.4000000000000p+3, 0x0.0p+0}, /* 1e1 */
    {0x1.9000000000000p+6, 0x0.0p+0}, /* 1e2 */
    {0x1.f400000000000p+9, 0x0.0p+0}, /* 1e3 */
    {0x1.3880000000000p+13, 0x0.0p+0}, /* 1e4 */
    {0x1.86a0000000000p+16, 0x0.0p+0}, /* 1e5 */
    {0x1.e848000000000p+19, 0x0.0p+0}, /* 1e6 */
    {0x1.312d000000000p+23, 0x0.0p+0}, /* 1e7 */
    {0x1.7d78400000000p+26, 0x0.0p+0}, /* 1e8 */
    {0x1.dcd6500000000p+29, 0x0.0p+0}, /* 1e9 */
    {0x1.2a05f20000000p+33, 0x0.0p+0}, /* 1e10 */
    {0x1.74876e8000000p+36, 0x0.0p+0}, /* 1e11 */
    {0x1.d1a94a2000000p+39, 0x0.0p+0}, /* 1e12 */
    {0x1.2309ce5400000p+43, 0x0.0p+0}, /* 1e13 */
    {0x1.6bcc41e900000p+46, 0x0.0p+0}, /* 1e14 */
    {0x1.c6bf526340000p+49, 0x0.0p+0}, /* 1e15 */
    {0x1.1c37937e08000p+53, 0x0.0p+0}, /* 1e16 */
    {0x1.6345785d8a000p+56, 0x0.0p+0}, /* 1e17 */
    {0x1.bc16d674ec800p+59, 0x0.0p+0}, /* 1e18 */
    {0x1.158e460913d00p+63, 0x0.0p+0}, /* 1e19 */
    {0x1.5af1d78b58c40p+66, 0x0.0p+0}, /* 1e20 */
    {0x1.b1ae4d6e2ef50p+69, 0x0.0p+0}, /* 1e21 */
    {0x1.0f0cf064dd592p+73, 0x0.0p+0}, /* 1e22 */
    {0x1.52d02c7e14af6p+76, 0x1.0000000000000p+23}, /* 1e23 */
    {0x1.a784379d99db4p+79, 0x1.0000000000000p+24}, /* 1e24 */
    {0x1.08b2a2c280291p+83, -0x1.b000000000000p+29}, /* 1e25 */
    {0x1.4adf4b7320335p+86, -0x1.1c00000000000p+32}, /* 1e26 */
    {0x1.9d971e4fe8402p+89, -0x1.8c00000000000p+33}, /* 1e27 */
    {0x1.027e72f1f1281p+93, 0x1.8440000000000p+38}, /* 1e28 */
    {0x1.431e0fae6d721p+96, 0x1.f2a8000000000p+42}, /* 1e29 */
    {0x1.93e5939a08ceap+99, -0x1.215c000000000p+44}, /* 1e30 */
    {0x1.f8def8808b024p+102, 0x1.4b26800000000p+48}, /* 1e31 */
    {0x1.3b8b5b5056e17p+106, -0x1.3107f00000000p+52}, /* 1e32 */
    {0x1.8a6e32246c99cp+109, 0x1.82b6140000000p+55}, /* 1e33 */
    {0x1.ed09bead87c03p+112, 0x1.e363990000000p+58}, /* 1e34 */
    {0x1.3426172c74d82p+116, 0x1.5c3c7f4000000p+61}, /* 1e35 */
    {0x1.812f9cf7920e3p+119, -0x1.265a307800000p+65}, /* 1e36 */
    {0x1.e17b84357691bp+122, 0x1.900f436a00000p+68}, /* 1e37 */
    {0x1.2ced32a16a1b1p+126, 0x1.e826288900000p+70}, /* 1e38 */
    {0x1.78287f49c4a1dp+129, 0x1.988becaad0000p+75}, /* 1e39 */
    {0x1.d6329f1c35ca5p+132, -0x1.0151182a7c000p+78}, /* 1e40 */
    {0x1.25dfa371a19e7p+136, -0x1.069578d46c000p+79}, /* 1e41 */
    {0x1.6f578c4e0a061p+139, -0x1.29075ae130e00p+85}, /* 1e42 */
    {0x1.cb2d6f618c879p+142, -0x1.cd24c665f4600p+86}, /* 1e43 */
    {0x1.1efc659cf7d4cp+146, -0x1.c80dbeffee2f0p+92}, /* 1e44 */
};
static const double NEGPOW10_DD[45][2] = {
    {0x1.0000000000000p+0, 0x0.0p+0}, /* 1e-0 */
    {0x1.999999999999ap-4, -0x1.999999999999ap-58}, /* 1e-1 */
    {0x1.47ae147ae147bp-7, -0x1.eb851eb851eb8p-63}, /* 1e-2 */
    {0x1.0624dd2f1a9fcp-10, -0x1.89374bc6a7efap-66}, /* 1e-3 */
    {0x1.a36e2eb1c432dp-14, -0x1.6a161e4f765fep-68}, /* 1e-4 */
    {0x1.4f8b588e368f1p-17, -0x1.ee78183f91e64p-71}, /* 1e-5 */
    {0x1.0c6f7a0b5ed8dp-20, 0x1.b5a63f9a49c2cp-75}, /* 1e-6 */
    {0x1.ad7f29abcaf48p-24, 0x1.5e1e99483b023p-78}, /* 1e-7 */
    {0x1.5798ee2308c3ap-27, -0x1.03023df2d4c94p-82}, /* 1e-8 */
    {0x1.12e0be826d695p-30, -0x1.34674bfabb83bp-84}, /* 1e-9 */
    {0x1.b7cdfd9d7bdbbp-34, -0x1.20a5465df8d2cp-88}, /* 1e-10 */
    {0x1.5fd7fe1796495p-37, 0x1.7f7bc7b4d28aap-91}, /* 1e-11 */
    {0x1.19799812dea11p-40, 0x1.97f27f0f6e886p-96}, /* 1e-12 */
    {0x1.c25c268497682p-44, -0x1.ecd79a5a0df95p-99}, /* 1e-13 */
    {0x1.6849b86a12b9bp-47, 0x1.ea70909833de7p-107}, /* 1e-14 */
    {0x1.203af9ee75616p-50, -0x1.937831647f5a0p-104}, /* 1e-15 */
    {0x1.cd2b297d889bcp-54, 0x1.5b4c2ebe68799p-109}, /* 1e-16 */
    {0x1.70ef54646d497p-57, -0x1.db7b2080a3029p-111}, /* 1e-17 */
    {0x1.2725dd1d243acp-60, -0x1.7c628066e8ceep-114}, /* 1e-18 */
    {0x1.d83c94fb6d2acp-64, 0x1.a52b31e9e3d07p-119}, /* 1e-19 */
    {0x1.79ca10c924223p-67, 0x1.75447a5d8e536p-121}, /* 1e-20 */
    {0x1.2e3b40a0e9b4fp-70, 0x1.f769fb7e0b75ep-124}, /* 1e-21 */
    {0x1.e392010175ee6p-74, -0x1.a7566d9cba769p-128}, /* 1e-22 */
    {0x1.82db34012b251p-77, 0x1.13badb829e079p-131}, /* 1e-23 */
    {0x1.357c299a88ea7p-80, 0x1.a96249354b394p-134}, /* 1e-24 */
    {0x1.ef2d0f5da7dd9p-84, -0x1.5762be11213e0p-138}, /* 1e-25 */
    {0x1.8c240c4aecb14p-87, -0x1.12b564da80fe7p-141}, /* 1e-26 */
    {0x1.3ce9a36f23c10p-90, -0x1.b788a15d9b30bp-145}, /* 1e-27 */
    {0x1.fb0f6be506019p-94, 0x1.06c5e54eb70c4p-148}, /* 1e-28 */
    {0x1.95a5efea6b347p-97, 0x1.9f04b7722c09dp-151}, /* 1e-29 */
    {0x1.4484bfeebc2a0p-100, -0x1.e72f6d3e432b6p-154}, /* 1e-30 */
    {0x1.039d665896880p-103, -0x1.85bf8a9835bc4p-157}, /* 1e-31 */
    {0x1.9f623d5a8a733p-107, -0x1.a2cc10f3892d4p-161}, /* 1e-32 */
    {0x1.4c4e977ba1f5cp-110, -0x1.4f09a7293a8aap-164}, /* 1e-33 */
    {0x1.09d8792fb4c49p-113, 0x1.5a5ead789df78p-167}, /* 1e-34 */
    {0x1.a95a5b7f87a0fp-117, -0x1.e1aa86c4e6d2fp-174}, /* 1e-35 */
    {0x1.54484932d2e72p-120, 0x1.696ef285e8eafp-174}, /* 1e-36 */
    {0x1.1039d428a8b8fp-123, -0x1.4540d794df441p-177}, /* 1e-37 */
    {0x1.b38fb9daa78e4p-127, 0x1.2acb73de9ac65p-181}, /* 1e-38 */
    {0x1.5c72fb1552d83p-130, 0x1.bbd5f64baf050p-184}, /* 1e-39 */
    {0x1.16c262777579cp-133, 0x1.631191d6259dap-187}, /* 1e-40 */
    {0x1.be03d0bf225c7p-137, -0x1.72524ee484eb4p-194}, /* 1e-41 */
    {0x1.64cfda3281e39p-140, -0x1.e3aa0fc74dc8ap-195}, /* 1e-42 */
    {0x1.1d7314f534b61p-143, -0x1.8e44064fb8b6bp-197}, /* 1e-43 */
    {0x1.c8b8218854567p-147, 0x1.82c65c4d3edbcp-201}, /* 1e-44 */
};

/* 2^(e-1075) for the biased exponent e of a normal double: half its ulp. */
static double half_ulp(double x, int *pow2) {
  uint64_t b, h;
  double r;
  memcpy(&b, &x, sizeof b);
  *pow2 = (b & 0xFFFFFFFFFFFFFull) == 0;
  h = (((b >> 52) & 0x7FFu) - 53u) << 52;
  memcpy(&r, &h, sizeof r);
  return r;
}

/* m 10^k for 0 < m < 10^19, |k| <= 44, positive: 0 when too close to a
 * midpoint to decide (the caller then asks strtod). */
static int dd_scale(uint64_t m, int k, double *out) {
  const double mh = (double)m;
  const double ml = (double)(int64_t)(m - (uint64_t)mh); /* |ml| <= 2^10: exact */
  const double *pk = k >= 0 ? POW10_DD[k] : NEGPOW10_DD[-k];
  int pow2;
  double h, l, s, lo, half;
  two_prod(mh, pk[0], &h, &l);
  l += mh * pk[1] + ml * pk[0];
  s = h + l;
  lo = l - (s - h); /* |h| >= |l|: s + lo = h + l exactly */
  half = half_ulp(s, &pow2);
  if (pow2 && lo < 0.0) half *= 0.5; /* the gap below a power of two is half */
  if (fabs(lo) + s * 0x1p-99 >= half) return 0;
  *out = s;
  return 1;
}

static int is_digit(char c) { return (unsigned)(c - '0') < 10u; }

/* Bytes s[0..7] as one word, s[0] the lowest byte (assembled explicitly, so
 * any byte order works; compilers make it one load). */
static uint64_t load8(const char *s) {
  const unsigned char *u = (const unsigned char *)s;
  return (uint64_t)u[0] | (uint64_t)u[1] << 8 | (uint64_t)u[2] << 16 | (uint64_t)u[3] << 24 |
         (uint64_t)u[4] << 32 | (uint64_t)u[5] << 40 | (uint64_t)u[6] << 48 |
         (uint64_t)u[7] << 56;
}

/* Each byte of w is '0'..'9': high nibble 3, and still 3 after adding 6. */
static int eight_are_digits(uint64_t w) {
  const uint64_t hi = 0xF0F0F0F0F0F0F0F0ull, three = 0x3030303030303030ull;
  return (w & hi) == three && ((w + 0x0606060606060606ull) & hi) == three;
}

/* The value of 8 digit bytes (first byte the most significant): 4 pairs,
 * 2 quads, then the whole, in 3 multiplications instead of a chain of 8. */
static uint64_t eight_value(uint64_t w) {
  uint64_t v = w - 0x3030303030303030ull;
  v = (v * 10u + (v >> 8)) & 0x00FF00FF00FF00FFull;
  v = (v * 100u + (v >> 16)) & 0x0000FFFF0000FFFFull;
  return (v * 10000u + (v >> 32)) & 0xFFFFFFFFull;
}

/* Appends the digits at *pp to *m, *nd the significant digits so far: 0, or
 * -1 past 19 of them. Eight at a time while [*pp, lim) holds eight bytes. */
static int take_digits(const char **pp, const char *lim, uint64_t *m, int *nd) {
  const char *p = *pp;
  uint64_t v = *m;
  int n = *nd;
  while (n <= 11 && lim - p >= 8) {
    uint64_t w = load8(p);
    if (!eight_are_digits(w)) break;
    v = v * 100000000u + eight_value(w);
    p += 8;
    n += 8;
  }
  for (; is_digit(*p); p++, n++) {
    if (n == 19) return -1;
    v = v * 10u + (uint64_t)(*p - '0');
  }
  *pp = p;
  *m = v;
  *nd = n;
  return 0;
}

double rcb_strtod(const char *str, char **endp) { return rcb_strtod_in(str, NULL, endp); }

double rcb_strtod_in(const char *str, const char *lim, char **endp) {
  const char *p = str, *q;
  uint64_t m = 0;
  int k = 0, nd = 0, neg = 0, any;
  double v;
  if (!NUMPARSE_FAST) return strtod(str, endp);
  if (!lim) lim = str;
  while (*p == ' ' || *p == '\t') p++;
  if (*p == '-' || *p == '+') neg = *p++ == '-';
  if (p[0] == '0' && (p[1] == 'x' || p[1] == 'X')) return strtod(str, endp);
  q = p;
  while (*p == '0') p++;
  if (take_digits(&p, lim, &m, &nd)) return strtod(str, endp);
  any = p > q;
  if (*p == '.') {
    const char *f = ++p;
    int n0;
    if (nd == 0) {
      while (*p == '0') p++;
      if (p - f > 400) return strtod(str, endp); /* k stays far from INT_MIN */
      k = -(int)(p - f);
    }
    n0 = nd;
    if (take_digits(&p, lim, &m, &nd)) return strtod(str, endp);
    k -= nd - n0;
    any = any || p > f;
  }
  if (!any) return strtod(str, endp); /* inf, nan, ".", "" */
  if (*p == 'e' || *p == 'E') {
    int eneg = 0, e = 0;
    q = p + 1;
    if (*q == '-' || *q == '+') eneg = *q++ == '-';
    if (!is_digit(*q)) return strtod(str, endp); /* "1e": strtod ends before the e */
    for (; is_digit(*q); q++)
      if (e < 100000) e = e * 10 + (*q - '0');
    k += eneg ? -e : e;
    p = q;
  }
  if (m == 0) {
    v = 0.0;
  } else if (m <= (1ull << 53) && k >= -22 && k <= 22) {
    v = k >= 0 ? (double)m * pow10_exact(k) : (double)m / pow10_exact(-k);
  } else if (m <= (1ull << 53) && k > 22 && k <= 22 + 15 &&
             m <= (1ull << 53) / (uint64_t)pow10_exact(k - 22)) {
    v = (double)(m * (uint64_t)pow10_exact(k - 22)) * 1e22;
  } else if (k < -44 || k > 44 || !dd_scale(m, k, &v)) {
    return strtod(str, endp);
  }
  if (endp) *endp = (char *)(uintptr_t)p;
  return neg ? -v : v;
}
