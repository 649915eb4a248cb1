/* Shared by the monitor harnesses (fuzz_monitor_state.c, fuzz_monitor_image.c):
 * one set-up of the paper system, 4 probes x 24 lines, and the noisy updates
 * drawn around it, so that both harnesses' seeds match one fingerprint.
 * Include after fuzz_common.h. */
#ifndef RCB_FUZZ_MONITOR_COMMON_H
#define RCB_FUZZ_MONITOR_COMMON_H

#define NCH 4
#define NPTS 24
#define NPT (NCH * NPTS)

static rcb_complex g_e0[NPT], g_v[NPT];

static uint64_t rng_next(uint64_t *s) {
  uint64_t z = (*s += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}
/* uniform on [-1, 1) */
static double rng_pm1(uint64_t *s) { return (double)(rng_next(s) >> 11) * 0x1.0p-52 - 1.0; }

/* The commissioning values plus 2 % of eq. 19-like noise along them and a
 * little around them. */
static void values(uint64_t *s, rcb_complex *v) {
  size_t i;
  for (i = 0; i < NPT; i++)
    v[i] = g_e0[i] * (1.0 + 0.02 * rng_pm1(s) + 0.002 * I * rng_pm1(s));
}

/* The set-up: the model's inertances at 4 probes for a force at DA.x,
 * 100 .. 400 Hz at 10000 rpm, rounded to 7 digits (as a CSV would: another
 * BLAS's last bits then give the same commissioning values, and the seeds
 * match this set-up's fingerprint). */
static rcb_meas *setup_of(const rcb_model *m) {
  static const char *const outs[NCH] = {"C.A.x", "C.A.y", "C.B.x", "C.B.y"};
  rcb_dof od[NCH], in;
  rcb_frf *fr = NULL;
  rcb_meas *ms = NULL;
  double x[NPTS], w = 10000.0 * 3.14159265358979323846 / 30.0;
  rcb_complex H[NCH];
  size_t i, c;
  for (c = 0; c < NCH; c++)
    if (rcb_model_find_dof(m, outs[c], &od[c])) abort();
  if (rcb_model_find_dof(m, "DA.x", &in) ||
      rcb_frf_create(&fr, m, NCH, od, 1, &in, RCB_SOLVER_AUTO, NULL))
    abort();
  for (i = 0; i < NPTS; i++) {
    x[i] = 2.0 * 3.14159265358979323846 * (100.0 + 300.0 * (double)i / (NPTS - 1));
    if (rcb_frf_eval(fr, x[i], w, RCB_INERTANCE, H)) abort();
    for (c = 0; c < NCH; c++) {
      char s[64];
      double re, im;
      snprintf(s, sizeof s, "%.6e %.6e", creal(H[c]), cimag(H[c]));
      if (sscanf(s, "%lf %lf", &re, &im) != 2) abort();
      g_e0[c * NPTS + i] = re + I * im;
    }
  }
  rcb_frf_destroy(fr);
  if (rcb_meas_create(&ms, NULL) || rcb_meas_set_grid(ms, RCB_MEAS_FRF, NPTS, x, w)) abort();
  for (c = 0; c < NCH; c++)
    if (rcb_meas_add_channel(ms, outs[c], "DA.x", RCB_INERTANCE, g_e0 + c * NPTS)) abort();
  return ms;
}

#endif /* RCB_FUZZ_MONITOR_COMMON_H */
