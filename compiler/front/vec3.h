/* vec3.h: the reader's small vector helpers and geometric tolerances. */
#ifndef MBCC_VEC3_H
#define MBCC_VEC3_H

#include <math.h>

static inline double dot3(const double a[3], const double b[3]) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* The length of a[0..n): the plain sum of squares where it cannot overflow
 * or underflow (so the usual values keep their usual bits), else scaled by
 * the largest component first ([0, 0, 1e308] has length 1e308, not inf). */
static inline double safe_norm(const double *a, int n) {
  double big = 0, sum = 0;
  for (int i = 0; i < n; i++) big = fmax(big, fabs(a[i]));
  if (big > 1e-150 && big < 1e150) {
    for (int i = 0; i < n; i++) sum += a[i] * a[i];
    return sqrt(sum);
  }
  if (big == 0 || !isfinite(big)) return big;
  for (int i = 0; i < n; i++) sum += (a[i] / big) * (a[i] / big);
  return big * sqrt(sum);
}

static inline double norm3(const double a[3]) { return safe_norm(a, 3); }

static inline double distance3(const double a[3], const double b[3]) {
  double d[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  return norm3(d);
}

/* rotation matrix (row-major, body to global) of unit Euler parameters */
static inline void quaternion_to_matrix(const double e[4], double A[9]) {
  double e0 = e[0], e1 = e[1], e2 = e[2], e3 = e[3];
  A[0] = 2 * (e0 * e0 + e1 * e1) - 1; A[1] = 2 * (e1 * e2 - e0 * e3); A[2] = 2 * (e1 * e3 + e0 * e2);
  A[3] = 2 * (e1 * e2 + e0 * e3); A[4] = 2 * (e0 * e0 + e2 * e2) - 1; A[5] = 2 * (e2 * e3 - e0 * e1);
  A[6] = 2 * (e1 * e3 - e0 * e2); A[7] = 2 * (e2 * e3 + e0 * e1); A[8] = 2 * (e0 * e0 + e3 * e3) - 1;
}

static inline void scale3(double a[3], double factor) {
  a[0] *= factor;
  a[1] *= factor;
  a[2] *= factor;
}

/* Lengths below this are treated as zero (axes, point separations). */
#define ZERO_LENGTH 1e-12
/* Tolerance on unit-vector dot products (perpendicular / orthonormal). */
#define ANGLE_TOLERANCE 1e-6
#define PI 3.14159265358979323846 /* M_PI is not in strict C11 */

#endif
