/* mb_flex.h: kernels of a flexible (modal) body, shared by the generated code
 * and the generic path.  A flexible body has the rigid body's coordinates
 * (r, p; rd, w') plus nm modal coordinates w (velocities wd).  Node k sits at
 * b_k = x_k + X_k w in body axes and rotates by theta_k = Psi_k w (exact
 * rotation exp(theta~)).  The mass matrix and the quadratic-velocity forces
 * come from inertia invariants computed at compile time (docs/formulation.md):
 *   S(w) = S0 + S1 w,  J(w) = J0 + sum_j w_j J1_j + sum_ij w_i w_j J2_ij,
 *   J1_j = 2 tr(E_j) I - E_j - E_j^T,  J2_ij = tr(F_ij) I - (F_ij + F_ij^T)/2,
 *   M_thf = C0 + sum_i w_i G_i.,  with E_j = sum_k m_k X_kj x_k^T,
 *   F_ij = sum_k m_k X_ki X_kj^T, G_ij = sum_k m_k X_ki x X_kj,
 *   C0 = sum_k (m_k x_k~ X_k + J_k Psi_k), CPsi = sum_k J_k Psi_k. */
#ifndef MB_FLEX_H
#define MB_FLEX_H

#include "mb_kernels.h"

#define MB_MAX_MODES 64

enum { MB_COUPLING_FULL = 0, MB_COUPLING_PARTIAL = 1, MB_COUPLING_CONSTANT = 2 };

typedef struct {
  int nm;              /* modes */
  int coupling;        /* MB_COUPLING_* */
  mb_real mass;
  mb_real S0[3];
  const mb_real *S1;   /* 3 x nm, column j at S1 + 3 j */
  mb_real J0[9];
  const mb_real *E;    /* nm matrices 3x3 (row-major), E_j at E + 9 j */
  const mb_real *F;    /* nm x nm matrices 3x3, F_ij at F + 9 (i nm + j) */
  const mb_real *G;    /* nm x nm vectors, G_ij at G + 3 (i nm + j) */
  const mb_real *C0;   /* 3 x nm, column j at C0 + 3 j */
  const mb_real *CPsi; /* 3 x nm */
  const mb_real *Mff;  /* nm x nm, row-major */
  const mb_real *stiffness; /* nm: omega_j^2 */
  const mb_real *damping;   /* nm: 2 zeta_j omega_j */
  int nnode;
  const mb_real *node_x;    /* 3 per node */
  const mb_real *node_X;    /* per node 3 x nm (column j at node_X + 3 (k nm + j)) */
  const mb_real *node_Psi;  /* per node 3 x nm, likewise */
} mb_flex;

/* Geometric stiffening of a flexible body (docs/formulation.md section 12.1;
 * the option geometric_stiffening): the second-order (foreshortening)
 * displacement d_k = 1/2 sum_ij w_i w_j D_kij of the nodes enters T through
 * P_ij = sum_k m_k D_kij and R_ij = sum_k m_k D_kij x_k^T, computed at compile
 * time from the beam elements' geometric stiffness (compiler/flex/stiffening.c).
 * Apart from mb_flex (whose initializers in generated code are positional). */
typedef struct mb_flex_stiff {
  const mb_real *P; /* nm x nm 3-vectors, P_ij at P + 3 (i nm + j) */
  const mb_real *R; /* nm x nm 3x3 (row-major), R_ij at R + 9 (i nm + j) */
  /* mb_flex_body_stiff, called by the generic library through this pointer so
     that the stiffening's code is linked only into models that use it (the
     embedded flash budget) */
  void (*body)(const mb_flex *fx, const struct mb_flex_stiff *st, const mb_frame *f, const mb_real *w,
               const mb_real *wd, const mb_real g[3], mb_real *Mb, mb_real *fb);
} mb_flex_stiff;

/* The coefficients of a node rotation exp(T), T = theta~, p = |theta|:
 *   exp(T) = I + s1 T + c1 T^2               (Rodrigues: s1 = sin p / p, c1 = (1 - cos p) / p^2)
 *   Jl = I + a T + b T^2                     (left Jacobian: a = c1, b = (p - sin p) / p^3,
 *                                             s1 = 1 - b p^2)
 * and a1 = a' / p, b1 = b' / p for its time derivative.  Below p = 1e-2 (node
 * rotations are small) their series, exact to round-off there and without
 * the cancellation of the closed forms: no sine or cosine per marker. */
typedef struct { mb_real s1, c1, a, b, a1, b1; } mb_so3_coef;

static inline void mb_so3_coefs(mb_real p2, mb_so3_coef *k) {
  mb_real p = MB_SQRT(p2);
  if (p < MB_R(1e-2)) {
    k->a = MB_R(0.5) - p2 / 24 + p2 * p2 / 720;
    k->b = MB_R(1.0) / 6 - p2 / 120 + p2 * p2 / 5040;
    k->a1 = -MB_R(1.0) / 12 + p2 / 180;
    k->b1 = -MB_R(1.0) / 60 + p2 / 1260;
    k->s1 = 1 - k->b * p2;
  } else {
    mb_real s = MB_SIN(p), c = MB_COS(p);
    k->a = (1 - c) / p2;
    k->b = (p - s) / (p2 * p);
    k->a1 = (p * s - 2 + 2 * c) / (p2 * p2);
    k->b1 = ((1 - c) * p - 3 * (p - s)) / (p2 * p2 * p);
    k->s1 = s / p;
  }
  k->c1 = k->a;
}

/* I + x T + y T^2 for T = th~, with T^2 = th th^T - |th|^2 I (no 3x3 product) */
static inline void mb_so3_poly(const mb_real th[3], mb_real p2, mb_real x, mb_real y, mb_real M[9]) {
  mb_real d = 1 - y * p2;
  M[0] = d + y * th[0] * th[0];
  M[4] = d + y * th[1] * th[1];
  M[8] = d + y * th[2] * th[2];
  M[1] = y * th[0] * th[1] - x * th[2];
  M[3] = y * th[0] * th[1] + x * th[2];
  M[2] = y * th[0] * th[2] + x * th[1];
  M[6] = y * th[0] * th[2] - x * th[1];
  M[5] = y * th[1] * th[2] - x * th[0];
  M[7] = y * th[1] * th[2] + x * th[0];
}

/* y = X w for a 3 x nm block stored by columns */
static inline void mb_modal3(const mb_real *X, int nm, const mb_real *w, mb_real y[3]) {
  y[0] = y[1] = y[2] = 0;
  for (int j = 0; j < nm; j++)
    for (int i = 0; i < 3; i++) y[i] += X[3 * j + i] * w[j];
}

/* C = A B (3x3, row-major) written out: mb_matmul3's loop form costs about
 * twice the instructions, and a node marker forms one or two per evaluation */
static inline void mb_flex_matmul3(const mb_real A[9], const mb_real B[9], mb_real C[9]) {
#ifdef __OPTIMIZE_SIZE__ /* -Os (the embedded target): the loop, a third of the code */
  mb_matmul3(A, B, C);
#else
  C[0] = A[0] * B[0] + A[1] * B[3] + A[2] * B[6];
  C[1] = A[0] * B[1] + A[1] * B[4] + A[2] * B[7];
  C[2] = A[0] * B[2] + A[1] * B[5] + A[2] * B[8];
  C[3] = A[3] * B[0] + A[4] * B[3] + A[5] * B[6];
  C[4] = A[3] * B[1] + A[4] * B[4] + A[5] * B[7];
  C[5] = A[3] * B[2] + A[4] * B[5] + A[5] * B[8];
  C[6] = A[6] * B[0] + A[7] * B[3] + A[8] * B[6];
  C[7] = A[6] * B[1] + A[7] * B[4] + A[8] * B[7];
  C[8] = A[6] * B[2] + A[7] * B[5] + A[8] * B[8];
#endif
}

/* marker on node k of a flexible body from the node's modal sums b = x_k + X_k w
 * (its position in body axes), th = Psi_k w, thd = Psi_k wd and Xwd = X_k wd
 * (the generated code forms them with the node's shapes as constants); C the
 * marker's axes in the node's, NULL for the identity.  Everything is formed
 * in locals and stored at the end: m may alias f as far as the compiler
 * knows, and a store before the last read of f reloads the frame. */
static inline void mb_marker_node_sums(const mb_frame *f, const mb_real b[3], const mb_real th[3],
                                       const mb_real thd[3], const mb_real Xwd[3], const mb_real C[9],
                                       mb_marker *m) {
  const mb_real *A = f->A, *wl = f->wl;
  mb_real Ex[9], AE[9], Jl[9], t1[3], t2[3], g[3], c[3], e[3], jd[3];
  mb_real P[3], V[3], aP[3], W[3], aW[3];
  mb_so3_coef k;
  mb_real p2 = mb_dot3(th, th);
  mb_so3_coefs(p2, &k);
  mb_so3_poly(th, p2, k.a, k.b, Jl);
  mb_so3_poly(th, p2, k.s1, k.c1, Ex);
  /* g = Jl thd = thd + a c + b th x c and jd = Jl' thd =
     (th . thd) (a1 c + b1 th x c) + b thd x c, with c = th x thd
     (the terms of Jl' in thd~ vanish on thd) */
  mb_cross3(th, thd, c);
  mb_cross3(th, c, e);
  mb_cross3(thd, c, t1);
  mb_real tt = mb_dot3(th, thd);
  for (int i = 0; i < 3; i++) {
    g[i] = thd[i] + k.a * c[i] + k.b * e[i];
    jd[i] = tt * (k.a1 * c[i] + k.b1 * e[i]) + k.b * t1[i];
  }
  mb_flex_matmul3(A, Ex, AE);
  mb_mul3(A, b, P);
  /* V = rd + A (w' x b + X wd) */
  mb_cross3(wl, b, t1);
  for (int i = 0; i < 3; i++) t1[i] += Xwd[i];
  mb_mul3(A, t1, V);
  /* aP = A (w' x (w' x b) + 2 w' x X wd) */
  mb_wwa(wl, b, t1);
  mb_cross3(wl, Xwd, t2);
  for (int i = 0; i < 3; i++) t1[i] += 2 * t2[i];
  mb_mul3(A, t1, aP);
  /* W = A (w' + Jl thd),  aW = A (w' x Jl thd + Jl' thd) */
  for (int i = 0; i < 3; i++) t1[i] = wl[i] + g[i];
  mb_mul3(A, t1, W);
  mb_cross3(wl, g, t1);
  for (int i = 0; i < 3; i++) t1[i] += jd[i];
  mb_mul3(A, t1, aW);
  for (int i = 0; i < 3; i++) {
    P[i] += f->r[i];
    V[i] += f->rd[i];
  }
  if (C) mb_flex_matmul3(AE, C, m->R);
  else
    for (int i = 0; i < 9; i++) m->R[i] = AE[i];
  for (int i = 0; i < 9; i++) m->Jl[i] = Jl[i];
  for (int i = 0; i < 3; i++) {
    m->P[i] = P[i];
    m->V[i] = V[i];
    m->aP[i] = aP[i];
    m->W[i] = W[i];
    m->aW[i] = aW[i];
  }
}

/* marker on node k of a flexible body (frame f, modal w, wd), axes C in body axes */
static inline void mb_marker_node(const mb_frame *f, const mb_flex *fx, int k, const mb_real *w,
                                  const mb_real *wd, const mb_real C[9], mb_marker *m) {
  int nm = fx->nm;
  const mb_real *X = fx->node_X + 3 * k * nm, *Psi = fx->node_Psi + 3 * k * nm;
  mb_real b[3], th[3], thd[3], Xwd[3];
  mb_modal3(X, nm, w, b);
  for (int i = 0; i < 3; i++) b[i] += fx->node_x[3 * k + i];
  mb_modal3(Psi, nm, w, th);
  mb_modal3(Psi, nm, wd, thd);
  mb_modal3(X, nm, wd, Xwd);
  mb_marker_node_sums(f, b, th, thd, Xwd, C, m);
}

/* the body columns of mb_node_cols_mk (c[0..5]) and what its modal columns
 * are made of: c[6 + j] = X_j . lV + Psi_j . JtW, lV = A^T dV,
 * JtW = Jl^T A^T dW */
static inline void mb_node_cols_local(const mb_frame *f, const mb_marker *mk, const mb_real dV[3],
                                      const mb_real dW[3], mb_real *c, mb_real lV[3], mb_real JtW[3]) {
  mb_real lW[3];
  mb_rigid_cols(f, mk->P, dV, dW, c);
  mb_mul3t(f->A, dV, lV);
  mb_mul3t(f->A, dW, lW);
  mb_mul3t(mk->Jl, lW, JtW);
}

/* Map (dV, dW) at the marker mk of node k (as set by mb_marker_node: its
 * point and the left Jacobian of the node rotation) to the body's 6 + nm
 * velocity coordinates:
 * [dV; A^T(u x dV + dW); X^T A^T dV + (Jl Psi)^T A^T dW], u = P - r. */
static inline void mb_node_cols_mk(const mb_frame *f, const mb_flex *fx, int k, const mb_marker *mk,
                                   const mb_real dV[3], const mb_real dW[3], mb_real *c) {
  int nm = fx->nm;
  const mb_real *X = fx->node_X + 3 * k * nm, *Psi = fx->node_Psi + 3 * k * nm;
  mb_real lV[3], JtW[3];
  mb_node_cols_local(f, mk, dV, dW, c, lV, JtW);
  for (int j = 0; j < nm; j++) c[6 + j] = mb_dot3(X + 3 * j, lV) + mb_dot3(Psi + 3 * j, JtW);
}

/* The per-step contractions of the inertia invariants with the modal
 * coordinates w and velocities wd (everything of mb_flex_body that is
 * quadratic in the number of modes):
 *   S = S0 + S1 w,  J = J0 + sum_j w_j J1_j + sum_ij w_i w_j J2_ij,
 *   Fw_j = sum_a w_a F_ja,  Gw_j = C0_j + sum_a w_a G_aj,  Gd_j = sum_a wd_a G_aj,
 *   S1wd = S1 wd,  Cw = CPsi wd.
 * mb_flex_contract computes them with loops over the tables (the generic
 * path); the generated code computes the same sums straight-line with the
 * invariants' nonzero entries as literal constants (compiler/back/emit.c). */
typedef struct {
  mb_real S[3], J[9], S1wd[3], Cw[3];
  mb_real Fw[9 * MB_MAX_MODES]; /* Fw_j at Fw + 9 j (zero unless coupling is partial or full) */
  mb_real Gw[3 * MB_MAX_MODES]; /* Gw_j at Gw + 3 j: column j of M_thf */
  mb_real Gd[3 * MB_MAX_MODES]; /* Gd_j at Gd + 3 j */
} mb_flex_step;

/* The geometric stiffening's own contractions (mb_flex_stiffen): Pw_j =
 * sum_i w_i P_ij, Rw_j = sum_i w_i R_ij, Rwd = sum_j wd_j Rw_j, and the sums
 * over wd_i wd_j of P_ij and R_ij.  Apart from mb_flex_step, so that a body
 * without the option keeps its small stack (embedded targets). */
typedef struct {
  mb_real Pw[3 * MB_MAX_MODES], Rw[9 * MB_MAX_MODES], Rwd[9], Pdd[3], Rdd[9];
} mb_flex_stiff_step;

static inline void mb_flex_contract(const mb_flex *fx, const mb_real *w, const mb_real *wd,
                                    mb_flex_step *c) {
  int nm = fx->nm;
  int lin = fx->coupling != MB_COUPLING_CONSTANT, quad = fx->coupling == MB_COUPLING_FULL;
  for (int i = 0; i < 3; i++) c->S[i] = fx->S0[i];
  for (int i = 0; i < 9; i++) c->J[i] = fx->J0[i];
  mb_modal3(fx->S1, nm, wd, c->S1wd);
  mb_modal3(fx->CPsi, nm, wd, c->Cw);
  for (int j = 0; j < nm; j++) {
    mb_real *Fw = c->Fw + 9 * j, *Gw = c->Gw + 3 * j, *Gd = c->Gd + 3 * j;
    for (int i = 0; i < 9; i++) Fw[i] = 0;
    for (int i = 0; i < 3; i++) { Gw[i] = fx->C0[3 * j + i]; Gd[i] = 0; }
    for (int a = 0; a < nm; a++) {
      const mb_real *G = fx->G + 3 * (a * nm + j);
      for (int i = 0; i < 3; i++) Gd[i] += wd[a] * G[i];
      if (!lin) continue;
      const mb_real *F = fx->F + 9 * (j * nm + a);
      for (int i = 0; i < 9; i++) Fw[i] += w[a] * F[i];
      for (int i = 0; i < 3; i++) Gw[i] += w[a] * G[i];
    }
  }
  if (lin)
    for (int j = 0; j < nm; j++) {
      const mb_real *E = fx->E + 9 * j, *Fw = c->Fw + 9 * j;
      mb_real tr = E[0] + E[4] + E[8], tf = Fw[0] + Fw[4] + Fw[8];
      for (int i = 0; i < 3; i++) c->S[i] += fx->S1[3 * j + i] * w[j];
      /* J1_j = 2 tr(E_j) I - E_j - E_j^T; with the full coupling also
         sum_a w_a J2_ja = tr(Fw_j) I - (Fw_j + Fw_j^T) / 2 */
      for (int i = 0; i < 3; i++)
        for (int l = 0; l < 3; l++) {
          mb_real t = 2 * tr * (i == l) - E[3 * i + l] - E[3 * l + i];
          if (quad) t += tf * (i == l) - MB_R(0.5) * (Fw[3 * i + l] + Fw[3 * l + i]);
          c->J[3 * i + l] += w[j] * t;
        }
    }
}

/* U = eps(R): U_a = eps_abc R_cb (the sum over the nodes of m_k x_k x D_k
 * from that of m_k D_k x_k^T) */
static inline void mb_flex_stiff_cross(const mb_real R[9], mb_real U[3]) {
  U[0] = R[7] - R[5];
  U[1] = R[2] - R[6];
  U[2] = R[3] - R[1];
}

/* Geometric stiffening (st of the body): the terms the nodes' second-order
 * displacement d_k(w) adds to the contractions c of mb_flex_contract, kept to
 * the products of the rigid velocities with d_k (docs/formulation.md 12.1):
 *   S += 1/2 sum_j w_j Pw_j,  S1wd += sum_j wd_j Pw_j   (A S1 column j += A Pw_j),
 *   J += 2 tr(Rww) I - Rww - Rww^T,  Rww = 1/2 sum_j w_j Rw_j,
 *   Gw_j += eps(Rw_j)  (column j of M_thf),
 * and the sums mb_flex_forces needs for the matching velocity terms. */
static inline void mb_flex_stiffen(const mb_flex_stiff *st, const mb_flex *fx, const mb_real *w,
                                   const mb_real *wd, mb_flex_step *c, mb_flex_stiff_step *sc) {
  int nm = fx->nm;
  mb_real Rww[9] = {0}, dS[3] = {0};
  for (int i = 0; i < 3; i++) sc->Pdd[i] = 0;
  for (int i = 0; i < 9; i++) sc->Rwd[i] = sc->Rdd[i] = 0;
  for (int j = 0; j < nm; j++) {
    mb_real *Pw = sc->Pw + 3 * j, *Rw = sc->Rw + 9 * j, Pd[3] = {0}, Rd[9] = {0};
    for (int i = 0; i < 3; i++) Pw[i] = 0;
    for (int i = 0; i < 9; i++) Rw[i] = 0;
    for (int a = 0; a < nm; a++) {
      const mb_real *P = st->P + 3 * (a * nm + j), *R = st->R + 9 * (a * nm + j);
      for (int i = 0; i < 3; i++) { Pw[i] += w[a] * P[i]; Pd[i] += wd[a] * P[i]; }
      for (int i = 0; i < 9; i++) { Rw[i] += w[a] * R[i]; Rd[i] += wd[a] * R[i]; }
    }
    for (int i = 0; i < 3; i++) {
      dS[i] += MB_R(0.5) * w[j] * Pw[i];
      c->S1wd[i] += wd[j] * Pw[i];
      sc->Pdd[i] += wd[j] * Pd[i];
    }
    for (int i = 0; i < 9; i++) {
      Rww[i] += MB_R(0.5) * w[j] * Rw[i];
      sc->Rwd[i] += wd[j] * Rw[i];
      sc->Rdd[i] += wd[j] * Rd[i];
    }
    mb_real U[3];
    mb_flex_stiff_cross(Rw, U);
    for (int i = 0; i < 3; i++) c->Gw[3 * j + i] += U[i];
  }
  mb_real tr = Rww[0] + Rww[4] + Rww[8];
  for (int i = 0; i < 3; i++) {
    c->S[i] += dS[i];
    for (int l = 0; l < 3; l++) c->J[3 * i + l] += 2 * tr * (i == l) - Rww[3 * i + l] - Rww[3 * l + i];
  }
}

/* the second-order part of S: 1/2 sum_ij w_i w_j P_ij (0 without stiffening: st NULL) */
static inline void mb_flex_stiff_S(const mb_flex_stiff *st, const mb_flex *fx, const mb_real *w,
                                   mb_real dS[3]) {
  int nm = fx->nm;
  dS[0] = dS[1] = dS[2] = 0;
  if (!st) return;
  for (int a = 0; a < nm; a++)
    for (int j = 0; j < nm; j++)
      for (int i = 0; i < 3; i++) dS[i] += MB_R(0.5) * w[a] * w[j] * st->P[3 * (a * nm + j) + i];
}

/* The blocks of the flexible body's mass matrix that change with the motion
 * and are not contractions already in c:  AS = A S~ (M_rth = -AS, M_thr =
 * -AS^T) and AS1 = A S1 (3 x nm by columns; M_rf = AS1, M_fr = AS1^T).  The
 * others are m I and Mff (constant), J (c->J) and M_thf (c->Gw). */
static inline void mb_flex_mass_moving(const mb_flex *fx, const mb_flex_step *c, const mb_frame *f,
                                       mb_real AS[9], mb_real *AS1) {
  const mb_real *S = c->S;
  mb_real Sx[9] = {0, -S[2], S[1], S[2], 0, -S[0], -S[1], S[0], 0};
  mb_matmul3(f->A, Sx, AS);
  for (int j = 0; j < fx->nm; j++) mb_mul3(f->A, fx->S1 + 3 * j, AS1 + 3 * j);
}

/* geometric stiffening: d S / d w_j gains Pw_j, so A S1 column j gains A Pw_j */
static inline void mb_flex_stiff_mass(const mb_flex *fx, const mb_flex_stiff_step *sc, const mb_frame *f,
                                      mb_real *AS1) {
  for (int j = 0; j < fx->nm; j++) {
    mb_real t[3];
    mb_mul3(f->A, sc->Pw + 3 * j, t);
    for (int i = 0; i < 3; i++) AS1[3 * j + i] += t[i];
  }
}

/* The flexible body's forces fb (6+nm), coordinates [rd; w'; wd]: gravity g
 * (global), quadratic-velocity terms, modal stiffness and damping, from the
 * contractions c of mb_flex_contract.  See the header comment. */
static inline void mb_flex_forces(const mb_flex *fx, const mb_flex_step *c, const mb_frame *f,
                                  const mb_real *w, const mb_real *wd, const mb_real g[3],
                                  mb_real *fb) {
  int nm = fx->nm;
  const mb_real *wl = f->wl, *S = c->S, *J = c->J;
  mb_real h = 0, H[9] = {0}, t[3], t2[3], Ag[3];
  /* rigid-frame part */
  mb_real wS[3];
  mb_wwa(wl, S, t);
  mb_cross3(wl, c->S1wd, t2);
  for (int i = 0; i < 3; i++) t[i] += 2 * t2[i];
  mb_mul3(f->A, t, t2);
  mb_mul3t(f->A, g, Ag);
  for (int i = 0; i < 3; i++) fb[i] = fx->mass * g[i] - t2[i];
  /* B_j = E_j + Fw_j; h = sum_k m_k (X_k^T b_k) . wd = sum_j wd_j tr B_j and
     H = sum_k m_k (X_k wd) b_k^T = sum_j wd_j B_j */
  for (int j = 0; j < nm; j++) {
    const mb_real *E = fx->E + 9 * j, *Fw = c->Fw + 9 * j;
    for (int i = 0; i < 9; i++) H[i] += wd[j] * (E[i] + Fw[i]);
    h += wd[j] * (E[0] + E[4] + E[8] + Fw[0] + Fw[4] + Fw[8]);
  }
  /* s_th = -w' x (J w') - 2 (w' h - H w') - w' x (CPsi wd) + S x (A^T g) */
  mb_real Jw[3], Hw[3];
  mb_mul3(J, wl, Jw);
  mb_mul3(H, wl, Hw);
  for (int i = 0; i < 3; i++) Jw[i] += c->Cw[i];
  mb_cross3(wl, Jw, t);
  mb_cross3(S, Ag, wS);
  for (int i = 0; i < 3; i++) fb[3 + i] = -t[i] - 2 * (wl[i] * h - Hw[i]) + wS[i];
  /* s_f(j) = -(w'^T B_j w' - |w'|^2 tr B_j) - 2 w'.Gd_j + S1_j . A^T g - k w - c wd */
  mb_real ww = mb_dot3(wl, wl);
  for (int j = 0; j < nm; j++) {
    const mb_real *E = fx->E + 9 * j, *Fw = c->Fw + 9 * j;
    mb_real B[9], Bw[3];
    for (int i = 0; i < 9; i++) B[i] = E[i] + Fw[i];
    mb_mul3(B, wl, Bw);
    fb[6 + j] = -(mb_dot3(wl, Bw) - ww * (B[0] + B[4] + B[8])) - 2 * mb_dot3(wl, c->Gd + 3 * j) +
                mb_dot3(fx->S1 + 3 * j, Ag) - fx->stiffness[j] * w[j] - fx->damping[j] * wd[j];
  }
}

/* The geometric stiffening's forces (added to fb of mb_flex_forces) from the
 * contractions of mb_flex_stiffen: Lagrange's equations of its terms of T
 * (docs/formulation.md 12.1) and of gravity's work on the second-order part. */
static inline void mb_flex_stiff_forces(const mb_flex *fx, const mb_flex_stiff_step *sc, const mb_frame *f,
                                        const mb_real g[3], mb_real *fb) {
  const mb_real *wl = f->wl;
  mb_real t[3], Ag[3], ww = mb_dot3(wl, wl);
  mb_mul3t(f->A, g, Ag);
  /* s_r -= A sum_ij wd_i wd_j P_ij */
  mb_mul3(f->A, sc->Pdd, t);
  for (int i = 0; i < 3; i++) fb[i] -= t[i];
  /* s_th -= dJ' w' + eps(Rdd) + w' x eps(Rwd),  dJ' = 2 tr(Rwd) I - Rwd - Rwd^T */
  const mb_real *Rd = sc->Rwd;
  mb_real trd = Rd[0] + Rd[4] + Rd[8], Ud[3], Udd[3], wU[3];
  mb_flex_stiff_cross(Rd, Ud);
  mb_flex_stiff_cross(sc->Rdd, Udd);
  mb_cross3(wl, Ud, wU);
  for (int i = 0; i < 3; i++) {
    mb_real dJw = 2 * trd * wl[i];
    for (int l = 0; l < 3; l++) dJw -= (Rd[3 * i + l] + Rd[3 * l + i]) * wl[l];
    fb[3 + i] -= dJw + Udd[i] + wU[i];
  }
  /* s_f,j += |w'|^2 tr Rw_j - w'^T Rw_j w' + Pw_j . A^T g: the stiffening */
  for (int j = 0; j < fx->nm; j++) {
    const mb_real *R = sc->Rw + 9 * j;
    mb_real Rw3[3];
    mb_mul3(R, wl, Rw3);
    fb[6 + j] += ww * (R[0] + R[4] + R[8]) - mb_dot3(wl, Rw3) + mb_dot3(sc->Pw + 3 * j, Ag);
  }
}

/* The flexible body's mass matrix Mb ((6+nm)^2, row-major, coordinates
 * [rd; w'; wd]) and its forces fb (6+nm) (mb_flex_forces), from the
 * contractions c of mb_flex_contract.  The generated code stores the moving
 * blocks (mb_flex_mass_moving, c->J, c->Gw) straight into K instead. */
static inline void mb_flex_assemble(const mb_flex *fx, const mb_flex_step *c, const mb_frame *f,
                                    const mb_real *w, const mb_real *wd, const mb_real g[3],
                                    mb_real *Mb, mb_real *fb) {
  int nm = fx->nm, n = 6 + nm;
  const mb_real *J = c->J;
  mb_real AS[9], AS1[3 * MB_MAX_MODES];
  for (int i = 0; i < n * n; i++) Mb[i] = 0;
  /* M_rr = m I, M_rth = -A S~, M_rf = A S1, M_thth = J, M_thf = [Gw_j] */
  mb_flex_mass_moving(fx, c, f, AS, AS1);
  for (int i = 0; i < 3; i++) {
    Mb[n * i + i] = fx->mass;
    for (int l = 0; l < 3; l++) {
      Mb[n * i + 3 + l] = -AS[3 * i + l];
      Mb[n * (3 + l) + i] = -AS[3 * i + l];
      Mb[n * (3 + i) + 3 + l] = J[3 * i + l];
    }
  }
  for (int j = 0; j < nm; j++) {
    const mb_real *col = AS1 + 3 * j, *thf = c->Gw + 3 * j;
    for (int i = 0; i < 3; i++) {
      Mb[n * i + 6 + j] = Mb[n * (6 + j) + i] = col[i];
      Mb[n * (3 + i) + 6 + j] = Mb[n * (6 + j) + 3 + i] = thf[i];
    }
    for (int l = 0; l < nm; l++) Mb[n * (6 + j) + 6 + l] = fx->Mff[nm * j + l];
  }
  mb_flex_forces(fx, c, f, w, wd, g, fb);
}

/* mb_flex_assemble of mb_flex_contract (the generic path's one call), with
 * the geometric stiffening's terms when st is not NULL */
static inline void mb_flex_body_stiff(const mb_flex *fx, const mb_flex_stiff *st, const mb_frame *f,
                                      const mb_real *w, const mb_real *wd, const mb_real g[3],
                                      mb_real *Mb, mb_real *fb) {
  mb_flex_step c;
  mb_flex_stiff_step sc;
  mb_flex_contract(fx, w, wd, &c);
  if (st) mb_flex_stiffen(st, fx, w, wd, &c, &sc);
  mb_flex_assemble(fx, &c, f, w, wd, g, Mb, fb);
  if (!st) return;
  int n = 6 + fx->nm;
  mb_real dAS1[3 * MB_MAX_MODES] = {0};
  mb_flex_stiff_mass(fx, &sc, f, dAS1);
  for (int j = 0; j < fx->nm; j++)
    for (int i = 0; i < 3; i++) {
      Mb[n * i + 6 + j] += dAS1[3 * j + i];
      Mb[n * (6 + j) + i] += dAS1[3 * j + i];
    }
  mb_flex_stiff_forces(fx, &sc, f, g, fb);
}

static inline void mb_flex_body(const mb_flex *fx, const mb_frame *f, const mb_real *w,
                                const mb_real *wd, const mb_real g[3], mb_real *Mb,
                                mb_real *fb) {
  mb_flex_step c;
  mb_flex_contract(fx, w, wd, &c);
  mb_flex_assemble(fx, &c, f, w, wd, g, Mb, fb);
}

/* kinetic energy 1/2 v^T M v of a flexible body, elastic energy 1/2 w^T K w */
static inline mb_real mb_flex_kinetic(const mb_flex *fx, const mb_flex_stiff *st, const mb_frame *f,
                                      const mb_real *w, const mb_real *wd, mb_real *Mb, mb_real *fb) {
  static const mb_real zero[3] = {0, 0, 0};
  int n = 6 + fx->nm;
  mb_real T = 0, v[6 + MB_MAX_MODES];
  mb_flex_body_stiff(fx, st, f, w, wd, zero, Mb, fb);
  for (int i = 0; i < 3; i++) { v[i] = f->rd[i]; v[3 + i] = f->wl[i]; }
  for (int j = 0; j < fx->nm; j++) v[6 + j] = wd[j];
  for (int i = 0; i < n; i++)
    for (int l = 0; l < n; l++) T += MB_R(0.5) * v[i] * Mb[n * i + l] * v[l];
  return T;
}

#endif
