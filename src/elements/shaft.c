/*
 * Timoshenko beam element for a rotating shaft, lateral motion only: 8 DOFs
 * [x0, y0, rx0, ry0, x1, y1, rx1, ry1] (m, rad). Mass (translational plus
 * rotary inertia), stiffness with shear deformation, and gyroscopic matrices
 * of a uniform annular element, as in Nelson & McVaugh / Friswell et al.,
 * "Dynamics of Rotating Machines" (2010), ch. 5, written in the same sign
 * convention and coefficient form as ROSS's ShaftElement (lateral rows of its
 * 12-DOF matrices), so the two can be compared entry by entry.
 *
 * phi = 12 E I / (kappa G A L^2) is the shear parameter (0: Euler-Bernoulli).
 */
#include "core/rcb_internal.h"

/* Write an 8x8 row-major table r[][] into column-major out, times f. */
static void put8(const double r[8][8], double f, double *out) {
  int i, j;
  for (i = 0; i < 8; i++)
    for (j = 0; j < 8; j++) out[i + 8 * j] = f * r[i][j];
}

void rcb_shaft_element(const rcb_beam_props *p, double Me[64], double Ge[64], double Ke[64]) {
  const double L = p->L, L2 = L * L;
  const double A = RCB_PI * (p->od * p->od - p->id * p->id) / 4.0;     /* m^2 */
  const double Ie = RCB_PI * (p->od * p->od * p->od * p->od -
                             p->id * p->id * p->id * p->id) / 64.0;     /* m^4 */
  const double Gs = p->E / (2.0 * (1.0 + p->nu));                       /* Pa */
  const double phi = p->kappa > 0 ? 12.0 * p->E * Ie / (Gs * p->kappa * A * L2) : 0.0;
  const double q = (1.0 + phi) * (1.0 + phi);
  double Mt[64], Mr[64];
  int i;

  /* translational inertia, rho A L / (1260 (1+phi)^2) */
  {
    const double m1 = 468 + 882 * phi + 420 * phi * phi;
    const double m2 = (66 + 115.5 * phi + 52.5 * phi * phi) * L;
    const double m3 = 162 + 378 * phi + 210 * phi * phi;
    const double m4 = (39 + 94.5 * phi + 52.5 * phi * phi) * L;
    const double m5 = (12 + 21 * phi + 10.5 * phi * phi) * L2;
    const double m7 = (9 + 21 * phi + 10.5 * phi * phi) * L2;
    /* coupling x0-ry1 is -m4, x1-ry0 is +m4 (m6 = m4 for a uniform element) */
    const double t[8][8] = {
        {m1, 0, 0, m2, m3, 0, 0, -m4},   {0, m1, -m2, 0, 0, m3, m4, 0},
        {0, -m2, m5, 0, 0, -m4, -m7, 0}, {m2, 0, 0, m5, m4, 0, 0, -m7},
        {m3, 0, 0, m4, m1, 0, 0, -m2},   {0, m3, -m4, 0, 0, m1, m2, 0},
        {0, m4, -m7, 0, 0, m2, m5, 0},   {-m4, 0, 0, -m7, -m2, 0, 0, m5}};
    put8(t, p->rho * A * L / (1260.0 * q), Mt);
  }
  /* rotary inertia, rho Ie / (210 L (1+phi)^2) */
  {
    const double m11 = 252;
    const double m12 = (21 - 105 * phi) * L;
    const double m14 = (28 + 35 * phi + 70 * phi * phi) * L2;
    const double m15 = (7 + 35 * phi - 35 * phi * phi) * L2;
    const double t[8][8] = {
        {m11, 0, 0, m12, -m11, 0, 0, m12},   {0, m11, -m12, 0, 0, -m11, -m12, 0},
        {0, -m12, m14, 0, 0, m12, -m15, 0},  {m12, 0, 0, m14, -m12, 0, 0, -m15},
        {-m11, 0, 0, -m12, m11, 0, 0, -m12}, {0, -m11, m12, 0, 0, m11, m12, 0},
        {0, -m12, -m15, 0, 0, m12, m14, 0},  {m12, 0, 0, -m15, -m12, 0, 0, m14}};
    put8(t, p->rho * Ie / (210.0 * L * q), Mr);
  }
  for (i = 0; i < 64; i++) Me[i] = Mt[i] + Mr[i];

  /* stiffness, E / (L^3 (1+phi)^2) [Ie/105 K1 + Ie phi K2] */
  {
    const double k1 = 1260 * Ie / 105 + 12 * Ie * phi;
    const double k2 = 630 * L * Ie / 105 + 6 * L * Ie * phi;
    const double k4 = (420 + 210 * phi + 105 * phi * phi) * L2 * Ie / 105 + 3 * L2 * Ie * phi;
    const double k5 = (210 - 210 * phi - 105 * phi * phi) * L2 * Ie / 105 + 3 * L2 * Ie * phi;
    const double t[8][8] = {
        {k1, 0, 0, k2, -k1, 0, 0, k2},   {0, k1, -k2, 0, 0, -k1, -k2, 0},
        {0, -k2, k4, 0, 0, k2, k5, 0},   {k2, 0, 0, k4, -k2, 0, 0, k5},
        {-k1, 0, 0, -k2, k1, 0, 0, -k2}, {0, -k1, k2, 0, 0, k1, k2, 0},
        {0, -k2, k5, 0, 0, k2, k4, 0},   {k2, 0, 0, k5, -k2, 0, 0, k4}};
    put8(t, p->E / (L * L2 * q), Ke);
  }
  /* gyroscopic, 2 rho Ie / (210 L (1+phi)^2), skew-symmetric */
  {
    const double g1 = 252;
    const double g2 = (21 - 105 * phi) * L;
    const double g4 = (28 + 35 * phi + 70 * phi * phi) * L2;
    const double g5 = (7 + 35 * phi - 35 * phi * phi) * L2;
    const double t[8][8] = {
        {0, g1, -g2, 0, 0, -g1, -g2, 0},  {-g1, 0, 0, -g2, g1, 0, 0, -g2},
        {g2, 0, 0, g4, -g2, 0, 0, -g5},   {0, g2, -g4, 0, 0, -g2, g5, 0},
        {0, -g1, g2, 0, 0, g1, g2, 0},    {g1, 0, 0, g2, -g1, 0, 0, g2},
        {g2, 0, 0, -g5, -g2, 0, 0, g4},   {0, g2, g5, 0, 0, -g2, -g4, 0}};
    put8(t, 2.0 * p->rho * Ie / (210.0 * L * q), Ge);
  }
}
