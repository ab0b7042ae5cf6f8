/* mb_field.h: the field element, a general 6x6 stiffness and damping between
 * two markers; bushings (diagonal K and C) and massless beams (the beam's K,
 * mb_beam_stiffness, with C a ratio of it) are fields too.
 *
 * Parameters (m->force_prm + padr, MB_FIELD_NPRM reals):
 *   MB_FIELD_D0  .. +2   undeformed offset of marker 1 from marker 0, marker 0's axes
 *   MB_FIELD_K   .. +35  stiffness, 6x6 row-major, [translation; rotation]
 *   MB_FIELD_C   .. +35  damping, 6x6 row-major
 *   MB_FIELD_PRE .. +5   preload force and torque, marker 0's axes
 * No laws, no state. */
#ifndef MB_FIELD_H
#define MB_FIELD_H

#include "../mb_kernels.h"

enum {
  MB_FIELD_D0 = 0,
  MB_FIELD_K = 3,
  MB_FIELD_C = 39,
  MB_FIELD_PRE = 75,
  MB_FIELD_NPRM = 81
};

/* In the axes R0 of marker 0, with u = [R0^T (P1 - P0) - d0; th] (th: rotation
 * vector of R0^T R1) and its rate ud = [R0^T (V1 - V0 - W0 x (P1 - P0)); R0^T (W1 - W0)],
 * the force F and torque T on marker 1 at P1 are R0 (-K u - C ud + pre); the
 * reaction acts on body 0 at the same point.  Returns 1/2 u^T K u - pre . u
 * (exact potential for the translations; for rotations when K's rotational
 * part is isotropic).
 * tangent (NULL to skip), 72 reals: with marker 0 held fixed, the 6x6
 * derivatives (row-major) of marker 1's wrench [F; T] with respect to its
 * displacement [dP1; dphi1] (global; dphi1 a small rotation, R1 -> (I + dphi1~) R1),
 * then the 6x6 with respect to its velocities [V1; W1]. */
/* mb_field's relative displacement and rate, translations: u[0..2], ud[0..2] */
static inline void mb_field_relative_translation(const mb_marker *m0, const mb_marker *m1, const mb_real d0[3],
                                                 mb_real u[3], mb_real ud[3]) {
  mb_real d[3], dd[3], wxd[3];
  for (int j = 0; j < 3; j++) d[j] = m1->P[j] - m0->P[j];
  mb_cross3(m0->W, d, wxd);
  for (int j = 0; j < 3; j++) dd[j] = m1->V[j] - m0->V[j] - wxd[j];
  mb_mul3t(m0->R, d, u);
  for (int j = 0; j < 3; j++) u[j] -= d0[j];
  mb_mul3t(m0->R, dd, ud);
}

/* ... and rotations: th = the rotation vector of R0^T R1 and R0^T (W1 - W0) */
static inline void mb_field_relative_rotation(const mb_marker *m0, const mb_marker *m1, mb_real th[3],
                                              mb_real thd[3]) {
  mb_real Rr[9], wd[3];
  for (int j = 0; j < 3; j++) wd[j] = m1->W[j] - m0->W[j];
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      Rr[3 * i + j] = m0->R[i] * m1->R[j] + m0->R[3 + i] * m1->R[3 + j] + m0->R[6 + i] * m1->R[6 + j];
  mb_real v[3] = {MB_R(0.5) * (Rr[7] - Rr[5]), MB_R(0.5) * (Rr[2] - Rr[6]), MB_R(0.5) * (Rr[3] - Rr[1])};
  mb_real sn = MB_SQRT(mb_dot3(v, v)), cs = MB_R(0.5) * (Rr[0] + Rr[4] + Rr[8] - 1);
  mb_real ang = MB_ATAN2(sn, cs), fac = (sn > MB_R(1e-12)) ? ang / sn : 1;
  for (int j = 0; j < 3; j++) th[j] = fac * v[j];
  mb_mul3t(m0->R, wd, thd);
}

/* the relative displacement u and rate ud of marker 1 from marker 0 (mb_field's) */
static inline void mb_field_relative(const mb_marker *m0, const mb_marker *m1, const mb_real d0[3], mb_real u[6],
                                     mb_real ud[6]) {
  mb_field_relative_translation(m0, m1, d0, u, ud);
  mb_field_relative_rotation(m0, m1, u + 3, ud + 3);
}

static inline mb_real mb_field(const mb_marker *m0, const mb_marker *m1, const mb_real *prm,
                               mb_real F[3], mb_real T[3], mb_real *tangent) {
  const mb_real *K = prm + MB_FIELD_K, *C = prm + MB_FIELD_C, *pre = prm + MB_FIELD_PRE;
  mb_real u[6], ud[6], f[6];
  mb_field_relative(m0, m1, prm + MB_FIELD_D0, u, ud);
  mb_real E = 0;
  for (int i = 0; i < 6; i++) {
    f[i] = pre[i];
    for (int j = 0; j < 6; j++) {
      f[i] -= K[6 * i + j] * u[j] + C[6 * i + j] * ud[j];
      E += MB_R(0.5) * u[i] * K[6 * i + j] * u[j];
    }
    E -= pre[i] * u[i];
  }
  mb_mul3(m0->R, f, F);
  mb_mul3(m0->R, f + 3, T);
  if (tangent) {
    /* du_t = R0^T dP1, dud_t = -R0^T W0~ dP1 + R0^T dV1, dud_r = R0^T dW1, and
       du_r = Jl^-1(th) R0^T dphi1: R0^T R1 turns by R0^T dphi1 on the left, and
       log(exp(a~) exp(th~)) = th + Jl^-1(th) a + O(a^2), with
       Jl^-1(th) = I - th~/2 + (1/|th|^2 - (1 + cos|th|) / (2 |th| sin|th|)) th~ th~ */
    const mb_real *th = u + 3;
    mb_real t2 = mb_dot3(th, th), b = MB_R(1.0) / 12, Rt[9], Jinv[9], G[9], Hw[9];
    if (t2 > MB_R(1e-8)) {
      mb_real t = MB_SQRT(t2);
      b = 1 / t2 - (1 + MB_COS(t)) / (2 * t * MB_SIN(t));
    }
    mb_real S[9] = {0, -th[2], th[1], th[2], 0, -th[0], -th[1], th[0], 0};
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++) {
        Rt[3 * i + j] = m0->R[3 * j + i];
        Jinv[3 * i + j] = (i == j) - MB_R(0.5) * S[3 * i + j] + b * (th[i] * th[j] - (i == j) * t2);
      }
    mb_real W0x[9] = {0, -m0->W[2], m0->W[1], m0->W[2], 0, -m0->W[0], -m0->W[1], m0->W[0], 0};
    mb_matmul3(Jinv, Rt, G);
    mb_matmul3(Rt, W0x, Hw);
    mb_real Lx[36], Lv[36]; /* in marker 0's axes */
    for (int i = 0; i < 6; i++)
      for (int j = 0; j < 3; j++) {
        mb_real kt = 0, kr = 0, ct = 0, cr = 0;
        for (int k = 0; k < 3; k++) {
          kt += -K[6 * i + k] * Rt[3 * k + j] + C[6 * i + k] * Hw[3 * k + j];
          kr += -K[6 * i + 3 + k] * G[3 * k + j];
          ct += -C[6 * i + k] * Rt[3 * k + j];
          cr += -C[6 * i + 3 + k] * Rt[3 * k + j];
        }
        Lx[6 * i + j] = kt;
        Lx[6 * i + 3 + j] = kr;
        Lv[6 * i + j] = ct;
        Lv[6 * i + 3 + j] = cr;
      }
    /* to global: each column's force and torque halves turn by R0 */
    for (int s = 0; s < 2; s++) {
      const mb_real *Ls = s ? Lv : Lx;
      for (int c = 0; c < 6; c++)
        for (int h = 0; h < 2; h++) {
          mb_real a[3] = {Ls[6 * (3 * h) + c], Ls[6 * (3 * h + 1) + c], Ls[6 * (3 * h + 2) + c]}, g[3];
          mb_mul3(m0->R, a, g);
          for (int i = 0; i < 3; i++) tangent[36 * s + 6 * (3 * h + i) + c] = g[i];
        }
    }
  }
  return E;
}

/* the 6x6 stiffness of a massless beam of length L clamped at marker 0 and
 * loaded at marker 1 (local x along the beam, y and z the section axes):
 * Euler-Bernoulli, or Timoshenko with shear flexibility phi = 12 E I / (G As L^2) */
static inline void mb_beam_stiffness(mb_real L, mb_real E, mb_real G, mb_real A, mb_real Iy,
                                     mb_real Iz, mb_real J, mb_real Asy, mb_real Asz, mb_real K[36]) {
  mb_real py = Asy > 0 ? 12 * E * Iz / (G * Asy * L * L) : 0;
  mb_real pz = Asz > 0 ? 12 * E * Iy / (G * Asz * L * L) : 0;
  for (int i = 0; i < 36; i++) K[i] = 0;
  K[0] = E * A / L;
  K[7] = 12 * E * Iz / (L * L * L * (1 + py));
  K[11] = K[31] = -6 * E * Iz / (L * L * (1 + py));
  K[14] = 12 * E * Iy / (L * L * L * (1 + pz));
  K[16] = K[26] = 6 * E * Iy / (L * L * (1 + pz));
  K[21] = G * J / L;
  K[28] = (4 + pz) * E * Iy / (L * (1 + pz));
  K[35] = (4 + py) * E * Iz / (L * (1 + py));
}

#endif
