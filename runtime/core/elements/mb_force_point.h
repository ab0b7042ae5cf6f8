/* mb_force_point.h: the point force and the point torque (one marker).
 *
 * Parameters (m->force_prm + padr, MB_POINT_NPRM reals):
 *   MB_POINT_VEC .. +2  the force (N) or torque (N m): global axes, or marker 0's
 *                       body axes when the record's 'local' flag is set
 * The record's profile (or -1) scales the vector in time.  No laws, no state. */
#ifndef MB_FORCE_POINT_H
#define MB_FORCE_POINT_H

#include "../mb_kernels.h"

enum { MB_POINT_VEC = 0, MB_POINT_NPRM = 3 };

/* the applied vector, global: scale * vec, turned by the body rotation A when
 * the vector is given in body axes (A NULL: global) */
static inline void mb_point_vector(const mb_real *prm, mb_real scale, const mb_real *A,
                                   mb_real val[3]) {
  for (int j = 0; j < 3; j++) val[j] = scale * prm[MB_POINT_VEC + j];
  if (A) mb_mul3(A, val, val);
}

#endif
