/* mb_spring.h: the spring-damper between two marker points, and the force
 * laws it uses (linear, power, table).
 *
 * Parameters (m->force_prm + padr, MB_SPRING_NPRM reals):
 *   MB_SPRING_L0       free length (m)
 *   MB_SPRING_PRELOAD  tension at the free length (N)
 * Laws (m->force_law + ladr, MB_SPRING_NLAW records):
 *   MB_SPRING_STIFFNESS  tension of the elongation x = L - L0
 *   MB_SPRING_DAMPING    tension of the elongation rate Ld
 * No state.  Tension T = k(x) + c(Ld) + preload pulls the markers together. */
#ifndef MB_SPRING_H
#define MB_SPRING_H

#include "../mb_kernels.h"

typedef enum { MB_LAW_NONE = 0, MB_LAW_LINEAR, MB_LAW_POWER, MB_LAW_TABLE } mb_law_kind;

typedef struct {
  mb_law_kind kind;
  mb_real coef, exponent;
  int ntable;
  const mb_real *table; /* ntable pairs (x, F) */
} mb_law;

enum { MB_SPRING_L0 = 0, MB_SPRING_PRELOAD = 1, MB_SPRING_NPRM = 2 };
enum { MB_SPRING_STIFFNESS = 0, MB_SPRING_DAMPING = 1, MB_SPRING_NLAW = 2 };

/* the table segment x falls in (the end segments extend linearly): the
 * last k <= ntable - 2 with x > x_k, or 0, by bisection (the x_k strictly
 * increase, as the reader requires) */
static inline int mb_law_segment(const mb_law *l, mb_real x) {
  const mb_real *d = l->table;
  int lo = 0, hi = l->ntable - 2;
  while (lo < hi) {
    int mid = (lo + hi + 1) / 2;
    if (x > d[2 * mid]) lo = mid;
    else hi = mid - 1;
  }
  return lo;
}

/* An embedded package of a model without power laws defines MB_NO_POWER_LAW
 * (in its mb_types.h): no powf, and with it none of newlib's errno and
 * reentrancy data (about 1 KB of RAM, 3 KB of flash).  A power law reaching
 * the kernel then gives NaN, which the step reports (MB_ERR_NONFINITE). */
#ifdef MB_NO_POWER_LAW
#define MB_LAW_POW(x, y) ((void)(x), (void)(y), (mb_real)NAN)
#else
#define MB_LAW_POW(x, y) MB_POW(x, y)
#endif

/* F(x) of a force law */
static inline mb_real mb_law_force(const mb_law *l, mb_real x) {
  switch (l->kind) {
  case MB_LAW_NONE: return 0;
  case MB_LAW_LINEAR: return l->coef * x;
  case MB_LAW_POWER: return (x < 0 ? -1 : 1) * l->coef * MB_LAW_POW(MB_FABS(x), l->exponent);
  case MB_LAW_TABLE: { /* piecewise linear, extrapolated linearly */
    const mb_real *d = l->table;
    int k = mb_law_segment(l, x);
    mb_real s = (d[2 * k + 3] - d[2 * k + 1]) / (d[2 * k + 2] - d[2 * k]);
    return d[2 * k + 1] + s * (x - d[2 * k]);
  }
  }
  return 0;
}

/* the integral of F from 0 to x (the potential energy): apart from
 * mb_law_force, so that a caller that needs no energy (the evaluation's force
 * loop) does not integrate a table at every call */
static inline mb_real mb_law_energy(const mb_law *l, mb_real x) {
  mb_real E = 0;
  switch (l->kind) {
  case MB_LAW_NONE:
    break;
  case MB_LAW_LINEAR:
    E = MB_R(0.5) * l->coef * x * x;
    break;
  case MB_LAW_POWER: {
    mb_real ax = MB_FABS(x), pw = MB_LAW_POW(ax, l->exponent);
    E = l->coef * pw * ax / (l->exponent + 1);
    break;
  }
  case MB_LAW_TABLE: { /* the same piecewise-linear curve, segment by segment */
    const mb_real *d = l->table;
    int n = l->ntable;
    mb_real a = 0, b = x, sign = 1;
    if (b < a) { a = x; b = 0; sign = -1; }
    for (int j = 0; j <= n - 2; j++) {
      mb_real lo = (j == 0) ? -(mb_real)INFINITY : d[2 * j], hi = (j == n - 2) ? (mb_real)INFINITY : d[2 * j + 2];
      mb_real u0 = a > lo ? a : lo, u1 = b < hi ? b : hi;
      if (u1 <= u0) continue;
      mb_real sj = (d[2 * j + 3] - d[2 * j + 1]) / (d[2 * j + 2] - d[2 * j]);
      mb_real f0 = d[2 * j + 1] + sj * (u0 - d[2 * j]), f1 = d[2 * j + 1] + sj * (u1 - d[2 * j]);
      E += sign * MB_R(0.5) * (f0 + f1) * (u1 - u0);
    }
    break;
  }
  }
  return E;
}

/* F(x) of a force law, and its integral from 0 to x (energy NULL: not wanted) */
static inline mb_real mb_law_eval(const mb_law *l, mb_real x, mb_real *energy) {
  if (energy) *energy = mb_law_energy(l, x);
  return mb_law_force(l, x);
}

/* dF/dx of a force law (a power law with exponent < 1 has an infinite slope at 0) */
static inline mb_real mb_law_slope(const mb_law *l, mb_real x) {
  switch (l->kind) {
  case MB_LAW_NONE: return 0;
  case MB_LAW_LINEAR: return l->coef;
  case MB_LAW_POWER: return l->coef * l->exponent * MB_LAW_POW(MB_FABS(x), l->exponent - 1);
  case MB_LAW_TABLE: {
    const mb_real *d = l->table;
    int k = mb_law_segment(l, x);
    return (d[2 * k + 3] - d[2 * k + 1]) / (d[2 * k + 2] - d[2 * k]);
  }
  }
  return 0;
}

/* Spring-damper: writes the forces on marker 0 and marker 1 (global) and
 * returns the potential energy.  tangent (NULL to skip), 18 reals: the
 * derivatives of F1 with respect to d = P1 - P0 (3x3, row-major, entry
 * [3 i + j] = dF1_i / dd_j) and then with respect to its rate dd = V1 - V0;
 * F0 = -F1, so marker 0's derivatives are the negatives. */
static inline mb_real mb_spring(const mb_marker *m0, const mb_marker *m1, const mb_real *prm,
                                const mb_law *law, mb_real F0[3], mb_real F1[3],
                                mb_real *tangent) {
  mb_real d[3], dd[3];
  for (int j = 0; j < 3; j++) { d[j] = m1->P[j] - m0->P[j]; dd[j] = m1->V[j] - m0->V[j]; }
  mb_real L = MB_SQRT(mb_dot3(d, d));
  mb_real n[3] = {d[0] / L, d[1] / L, d[2] / L};
  mb_real x = L - prm[MB_SPRING_L0], Ld = mb_dot3(n, dd);
  mb_real T = mb_law_force(&law[MB_SPRING_STIFFNESS], x) + mb_law_force(&law[MB_SPRING_DAMPING], Ld) +
              prm[MB_SPRING_PRELOAD];
  for (int j = 0; j < 3; j++) { F0[j] = T * n[j]; F1[j] = -T * n[j]; }
  if (tangent) {
    /* F1 = -T n, n = d / L, dn/dd = (I - n n^T) / L, dLd/dd = dd^T (I - n n^T) / L:
       dF1/dd = -(n dT/dd + T (I - n n^T) / L), dF1/ddd = -c'(Ld) n n^T */
    mb_real ks = mb_law_slope(&law[MB_SPRING_STIFFNESS], x);
    mb_real cs = mb_law_slope(&law[MB_SPRING_DAMPING], Ld);
    mb_real tn[3]; /* (I - n n^T) dd / L */
    for (int j = 0; j < 3; j++) tn[j] = (dd[j] - Ld * n[j]) / L;
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++) {
        mb_real P = ((i == j) - n[i] * n[j]) / L;
        mb_real dTdd = ks * n[j] + cs * tn[j];
        tangent[3 * i + j] = -(n[i] * dTdd + T * P);
        tangent[9 + 3 * i + j] = -cs * n[i] * n[j];
      }
  }
  /* the energy last: a caller that drops it (the emitted evaluation) lets the
     C compiler drop the table's integral with it */
  return mb_law_energy(&law[MB_SPRING_STIFFNESS], x) + prm[MB_SPRING_PRELOAD] * x;
}

#endif
