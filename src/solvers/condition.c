/* The 1-norm of the dynamic stiffness in any storage layout, taken before a
 * LAPACK backend factors it in place: zgecon / zgbcon need ||Z||_1 of the
 * original matrix to turn ||Z^-1||_1 into a reciprocal condition number.
 * And the pivot ratio min|U_ii| / max|U_ii| of the factors, the O(n) screen
 * that decides whether the estimate is worth its cost. */
#include <math.h>

#include "solvers/zsolver.h"

/* |z| without hypot's overflow care (several times faster; the entries of a
 * dynamic stiffness are far from 1e154). */
static double mag(rcb_complex z) {
  double re = creal(z), im = cimag(z);
  return sqrt(re * re + im * im);
}

double rcb_layout_pivot_ratio(const rcb_layout *L, const rcb_complex *Z) {
  size_t j;
  double lo = INFINITY, hi = 0.0;
  if (L->sparse) return rcb_zsolver_sparse_pivot_ratio(L);
  for (j = 0; j < L->n; j++) { /* U's diagonal sits where Z's was */
    double u = mag(Z[rcb_layout_at(L, j, j)]);
    if (!(u == u)) return (double)NAN;
    lo = u < lo ? u : lo;
    hi = u > hi ? u : hi;
  }
  return hi > 0.0 ? lo / hi : 0.0;
}

double rcb_layout_norm1(const rcb_layout *L, const rcb_complex *Z) {
  size_t i, j, lo, hi;
  double best = 0.0;
  for (j = 0; j < L->n; j++) {
    double sum = 0.0;
    if (L->sparse) {
      lo = (size_t)L->colp[j], hi = (size_t)L->colp[j + 1];
      for (i = lo; i < hi; i++) sum += mag(Z[i]);
    } else {
      lo = (L->banded && j > L->ku) ? j - L->ku : 0;
      hi = L->banded && j + L->kl + 1 < L->n ? j + L->kl + 1 : L->n;
      for (i = lo; i < hi; i++) sum += mag(Z[rcb_layout_at(L, i, j)]);
    }
    if (isnan(sum)) return sum;
    if (sum > best) best = sum;
  }
  return best;
}
