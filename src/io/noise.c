/*
 * Synthetic measurement noise, the paper's eq. 19:
 *   f_e = f_s (1 + beta_a/100 r1) + (||f_s||_2 / n) (beta_s/100) r2 e^{i phi}
 * per channel (||f_s||_2 over the channel's n points), r1, r2 uniform in
 * [-1, 1], phi uniform in [0, 2 pi).
 *
 * The generator is xoshiro256** (Blackman & Vigna) seeded through
 * splitmix64: integer arithmetic only, so the same seed gives the same noise
 * on every platform and compiler. Draw order: channel by channel, point by
 * point, r1 then r2 then phi.
 */
#include <math.h>
#include <stdint.h>

#include "io/io.h"
#include "io/meas_internal.h"

typedef rcb_rng rng;

static uint64_t splitmix64(uint64_t *x) {
  uint64_t z = (*x += UINT64_C(0x9E3779B97F4A7C15));
  z = (z ^ (z >> 30)) * UINT64_C(0xBF58476D1CE4E5B9);
  z = (z ^ (z >> 27)) * UINT64_C(0x94D049BB133111EB);
  return z ^ (z >> 31);
}

static uint64_t rotl(uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }

static uint64_t next(rng *r) {
  uint64_t *s = r->s;
  uint64_t result = rotl(s[1] * 5, 7) * 9;
  uint64_t t = s[1] << 17;
  s[2] ^= s[0];
  s[3] ^= s[1];
  s[1] ^= s[2];
  s[0] ^= s[3];
  s[2] ^= t;
  s[3] = rotl(s[3], 45);
  return result;
}

void rcb_rng_seed(rng *r, uint64_t seed) {
  int i;
  for (i = 0; i < 4; i++) r->s[i] = splitmix64(&seed);
}

#define seed_rng rcb_rng_seed

/* Uniform in [0, 1): the top 53 bits, exact in a double. */
static double uniform01(rng *r) { return (double)(next(r) >> 11) * 0x1.0p-53; }

/* Uniform in [-1, 1]: 2^53 + 1 equally spaced values including both ends. */
static double uniform_pm1(rng *r) {
  uint64_t k = next(r) >> 10; /* 0 .. 2^54 - 1 */
  k %= (UINT64_C(1) << 53) + 1;
  return (double)k * 0x1.0p-52 - 1.0;
}

double rcb_noise_level(const rcb_complex *f, size_t n, double beta_s) {
  double sum = 0.0;
  size_t i;
  for (i = 0; i < n; i++) sum += creal(f[i]) * creal(f[i]) + cimag(f[i]) * cimag(f[i]);
  return n ? sqrt(sum) / (double)n * (beta_s / 100.0) : 0.0;
}

rcb_complex rcb_noise_draw(rng *r, rcb_complex fs, double beta_a, double level,
                           double phase) {
  double r1 = uniform_pm1(r), r2 = uniform_pm1(r), phi = 2.0 * RCB_PI * uniform01(r);
  rcb_complex e = fs * (1.0 + beta_a / 100.0 * r1) + level * r2 * CMPLX(cos(phi), sin(phi));
  if (phase > 0) { /* drawn after the three of eq. 19: without it, the same stream */
    double t = phase * uniform_pm1(r);
    e *= CMPLX(cos(t), sin(t));
  }
  return e;
}

rcb_status rcb_meas_add_noise(rcb_meas *ms, double beta_a, double beta_s, uint64_t seed) {
  return rcb_meas_add_noise_phase(ms, beta_a, beta_s, 0.0, seed);
}

rcb_status rcb_meas_add_noise_phase(rcb_meas *ms, double beta_a, double beta_s, double phase_rad,
                                    uint64_t seed) {
  rng r;
  size_t c, i;
  if (!ms) return RCB_ERR_ARG;
  if (!isfinite(beta_a) || beta_a < 0.0 || !isfinite(beta_s) || beta_s < 0.0)
    return rcb_meas_fail(ms, RCB_ERR_ARG, "noise: beta_a = %g %%, beta_s = %g %%: expected "
                         "finite percentages >= 0", beta_a, beta_s);
  if (!(phase_rad >= 0) || !isfinite(phase_rad) || phase_rad > RCB_PI)
    return rcb_meas_fail(ms, RCB_ERR_ARG, "noise: phase %g rad (%g deg): expected 0 to pi rad",
                         phase_rad, phase_rad * 180.0 / RCB_PI);
  seed_rng(&r, seed);
  for (c = 0; c < ms->nch; c++) {
    rcb_complex *f = ms->ch[c].data;
    double level = rcb_noise_level(f, ms->n, beta_s);
    for (i = 0; i < ms->n; i++) {
      f[i] = rcb_noise_draw(&r, f[i], beta_a, level, phase_rad);
      if (ms->ch[c].mag_only) f[i] = cabs(f[i]); /* the magnitude of the noisy value */
    }
  }
  return RCB_OK;
}
