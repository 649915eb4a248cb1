/*
 * Linear bearings and their pedestals. A bearing acts on the x, y DOFs of
 * its shaft node with the force -K q - C q' (K, C 2x2, cross terms allowed,
 * coefficients tabulated against rotor speed or constant); on a pedestal the
 * same force acts between the shaft node and the pedestal, which a mass and
 * springs and dampers hold to ground (x and y uncoupled).
 */
#include <string.h>

#include "core/rcb_internal.h"

void rcb_bearing_interp(size_t n, const double *speeds, const rcb_bearing_coefs *rows,
                        double speed, rcb_bearing_coefs *out) {
  size_t i = 0;
  double t;
  const double *lo, *hi;
  double *o = &out->kxx;
  int k;
  if (n == 1 || speed <= speeds[0]) {
    *out = rows[0];
    return;
  }
  if (speed >= speeds[n - 1]) {
    *out = rows[n - 1];
    return;
  }
  while (i + 1 < n && speeds[i + 1] < speed) i++;
  t = (speed - speeds[i]) / (speeds[i + 1] - speeds[i]);
  lo = &rows[i].kxx;
  hi = &rows[i + 1].kxx;
  for (k = 0; k < 8; k++) o[k] = lo[k] + t * (hi[k] - lo[k]);
}

void rcb_bearing_eval(const rcb_bearing_t *b, double speed, rcb_bearing_coefs *out) {
  rcb_bearing_interp(b->n, b->speeds, b->c, speed, out);
}

int rcb_bearing_element(const rcb_bearing_coefs *c, int pedestal, double Kb[16], double Cb[16]) {
  const double *kv = &c->kxx, *cv = &c->cxx; /* kxx kxy kyx kyy, row-major 2x2 */
  int nd = pedestal ? 4 : 2, bi, bj, r, s;
  /* every entry of the nd x nd block is written (no clearing: this runs at
   * every frequency point of a sweep, once per bearing) */
  for (bj = 0; bj < nd / 2; bj++)
    for (bi = 0; bi < nd / 2; bi++) {
      double sign = bi == bj ? 1.0 : -1.0;
      for (r = 0; r < 2; r++)
        for (s = 0; s < 2; s++) {
          Kb[(2 * bi + r) + nd * (2 * bj + s)] = sign * kv[2 * r + s];
          Cb[(2 * bi + r) + nd * (2 * bj + s)] = sign * cv[2 * r + s];
        }
    }
  return nd;
}

void rcb_pedestal_element(double mass, const double k[2], const double c[2], double Mp[4],
                          double Cp[4], double Kp[4]) {
  int a;
  memset(Mp, 0, 4 * sizeof *Mp);
  memset(Cp, 0, 4 * sizeof *Cp);
  memset(Kp, 0, 4 * sizeof *Kp);
  for (a = 0; a < 2; a++) {
    Mp[a + 2 * a] = mass;
    Cp[a + 2 * a] = c[a];
    Kp[a + 2 * a] = k[a];
  }
}
