/* mb_kernels.h: the element kernels, written once and used by both drivers:
 * the generated code calls them with literal constants (so the C compiler
 * folds them), the generic path calls them in loops over element tables.
 *
 * Conventions (docs/formulation.md):
 *   body i: position r, Euler parameters p, rotation matrix A (row-major),
 *   velocities rd (global) and w' (body axes); w = A w' (global).
 *   A marker is a frame on a body: point P, axes R = A C (columns: x, y, z),
 *   point velocity V, angular velocity W (global), and the velocity-dependent
 *   parts aP, aW of its accelerations (dV/dt = J vdot + aP, likewise W).
 *   A constraint row gives phi, its derivatives with respect to the marker
 *   velocities (dV, dW for each side) and 'quad', the part of phi'' that
 *   depends on marker velocities only; gamma follows from them. */
#ifndef MB_KERNELS_H
#define MB_KERNELS_H

#include "mb_math.h"

/* --- small vector algebra --------------------------------------------------- */
static inline mb_real mb_dot3(const mb_real a[3], const mb_real b[3]) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
static inline void mb_cross3(const mb_real a[3], const mb_real b[3], mb_real c[3]) {
  mb_real c0 = a[1] * b[2] - a[2] * b[1];
  mb_real c1 = a[2] * b[0] - a[0] * b[2];
  mb_real c2 = a[0] * b[1] - a[1] * b[0];
  c[0] = c0; c[1] = c1; c[2] = c2;
}
/* y = A x and y = A^T x for row-major 3x3 A */
static inline void mb_mul3(const mb_real A[9], const mb_real x[3], mb_real y[3]) {
  mb_real y0 = A[0] * x[0] + A[1] * x[1] + A[2] * x[2];
  mb_real y1 = A[3] * x[0] + A[4] * x[1] + A[5] * x[2];
  mb_real y2 = A[6] * x[0] + A[7] * x[1] + A[8] * x[2];
  y[0] = y0; y[1] = y1; y[2] = y2;
}
static inline void mb_mul3t(const mb_real A[9], const mb_real x[3], mb_real y[3]) {
  mb_real y0 = A[0] * x[0] + A[3] * x[1] + A[6] * x[2];
  mb_real y1 = A[1] * x[0] + A[4] * x[1] + A[7] * x[2];
  mb_real y2 = A[2] * x[0] + A[5] * x[1] + A[8] * x[2];
  y[0] = y0; y[1] = y1; y[2] = y2;
}
/* C = A B, row-major 3x3 */
static inline void mb_matmul3(const mb_real A[9], const mb_real B[9], mb_real C[9]) {
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      C[3 * i + j] = A[3 * i] * B[j] + A[3 * i + 1] * B[3 + j] + A[3 * i + 2] * B[6 + j];
}
/* column k of a row-major 3x3 (a marker axis) */
static inline void mb_col3(const mb_real R[9], int k, mb_real a[3]) {
  a[0] = R[k]; a[1] = R[3 + k]; a[2] = R[6 + k];
}

/* Rotation matrix of Euler parameters p (normalized here, so that a state
 * whose p drifted off the unit sphere still gives a rotation). */
static inline void mb_euler_to_A(const mb_real p_in[4], mb_real A[9]) {
  mb_real n = MB_SQRT(p_in[0] * p_in[0] + p_in[1] * p_in[1] + p_in[2] * p_in[2] + p_in[3] * p_in[3]);
  mb_real e0 = p_in[0] / n, e1 = p_in[1] / n, e2 = p_in[2] / n, e3 = p_in[3] / n;
  A[0] = 2 * (e0 * e0 + e1 * e1) - 1; A[1] = 2 * (e1 * e2 - e0 * e3); A[2] = 2 * (e1 * e3 + e0 * e2);
  A[3] = 2 * (e1 * e2 + e0 * e3); A[4] = 2 * (e0 * e0 + e2 * e2) - 1; A[5] = 2 * (e2 * e3 - e0 * e1);
  A[6] = 2 * (e1 * e3 - e0 * e2); A[7] = 2 * (e2 * e3 + e0 * e1); A[8] = 2 * (e0 * e0 + e3 * e3) - 1;
}

/* pd = 1/2 L(p)^T w' : Euler-parameter rates from the body angular velocity */
static inline void mb_euler_rates(const mb_real p[4], const mb_real wl[3], mb_real pd[4]) {
  pd[0] = MB_R(0.5) * (-p[1] * wl[0] - p[2] * wl[1] - p[3] * wl[2]);
  pd[1] = MB_R(0.5) * (p[0] * wl[0] - p[3] * wl[1] + p[2] * wl[2]);
  pd[2] = MB_R(0.5) * (p[3] * wl[0] + p[0] * wl[1] - p[1] * wl[2]);
  pd[3] = MB_R(0.5) * (-p[2] * wl[0] + p[1] * wl[1] + p[0] * wl[2]);
}

/* p <- p (x) exp(dtheta'/2): rotate by a body-axes rotation vector, exactly */
static inline void mb_euler_rotate(mb_real p[4], const mb_real dth[3]) {
  mb_real a = MB_SQRT(dth[0] * dth[0] + dth[1] * dth[1] + dth[2] * dth[2]);
  mb_real c = MB_COS(MB_R(0.5) * a), s = (a > MB_R(1e-12)) ? MB_SIN(MB_R(0.5) * a) / a : MB_R(0.5);
  mb_real q0 = c, q1 = s * dth[0], q2 = s * dth[1], q3 = s * dth[2];
  mb_real e0 = p[0], e1 = p[1], e2 = p[2], e3 = p[3];
  p[0] = e0 * q0 - e1 * q1 - e2 * q2 - e3 * q3;
  p[1] = e0 * q1 + e1 * q0 + e2 * q3 - e3 * q2;
  p[2] = e0 * q2 - e1 * q3 + e2 * q0 + e3 * q1;
  p[3] = e0 * q3 + e1 * q2 - e2 * q1 + e3 * q0;
}

/* --- bodies ---------------------------------------------------------------- */
typedef struct {
  mb_real r[3];  /* origin (centre of mass), global */
  mb_real A[9];  /* rotation, body to global, row-major */
  mb_real rd[3]; /* origin velocity, global */
  mb_real wl[3]; /* angular velocity, body axes */
  mb_real w[3];  /* angular velocity, global */
} mb_frame;

/* frame of a rigid (or virtual) body from its 7 position and 6 velocity coordinates */
static inline void mb_frame_rigid(const mb_real *q, const mb_real *v, mb_frame *f) {
  f->r[0] = q[0]; f->r[1] = q[1]; f->r[2] = q[2];
  mb_euler_to_A(q + 3, f->A);
  f->rd[0] = v[0]; f->rd[1] = v[1]; f->rd[2] = v[2];
  f->wl[0] = v[3]; f->wl[1] = v[4]; f->wl[2] = v[5];
  mb_mul3(f->A, f->wl, f->w);
}

/* quadratic-velocity force of a rigid body, body axes: s = -w' x (J w') */
static inline void mb_rigid_gyro(const mb_real J[9], const mb_real wl[3], mb_real s[3]) {
  mb_real h[3];
  mb_mul3(J, wl, h);
  mb_cross3(wl, h, s);
  s[0] = -s[0]; s[1] = -s[1]; s[2] = -s[2];
}

/* kinetic energy of a rigid body */
static inline mb_real mb_rigid_kinetic(mb_real m, const mb_real J[9], const mb_frame *f) {
  mb_real h[3];
  mb_mul3(J, f->wl, h);
  return MB_R(0.5) * m * mb_dot3(f->rd, f->rd) + MB_R(0.5) * mb_dot3(f->wl, h);
}

/* --- markers ----------------------------------------------------------------- */
typedef struct {
  mb_real P[3], R[9]; /* point and axes (columns), global */
  mb_real V[3], W[3]; /* point velocity, angular velocity, global */
  mb_real aP[3], aW[3]; /* velocity-dependent parts of the accelerations */
  mb_real Jl[9];      /* flexible node markers: left Jacobian of the node's rotation
                         (mb_marker_node; for mb_node_cols_mk); else unset */
} mb_marker;

/* marker fixed on the ground: s and C are its global point and axes */
static inline void mb_marker_ground(const mb_real s[3], const mb_real C[9], mb_marker *m) {
  for (int k = 0; k < 3; k++) {
    m->P[k] = s[k]; m->V[k] = 0; m->W[k] = 0; m->aP[k] = 0; m->aW[k] = 0;
  }
  for (int k = 0; k < 9; k++) m->R[k] = C[k];
}

/* marker on a rigid body at body-axes point s with body-axes axes C */
static inline void mb_marker_rigid(const mb_frame *f, const mb_real s[3], const mb_real C[9],
                                   mb_marker *m) {
  mb_real u[3], wu[3];
  mb_mul3(f->A, s, u);
  mb_matmul3(f->A, C, m->R);
  mb_cross3(f->w, u, wu);
  mb_cross3(f->w, wu, m->aP);
  for (int k = 0; k < 3; k++) {
    m->P[k] = f->r[k] + u[k];
    m->V[k] = f->rd[k] + wu[k];
    m->W[k] = f->w[k];
    m->aW[k] = 0;
  }
}

/* Map a force-like pair at a marker of a rigid body (dV: force or the row's
 * derivative with respect to the point velocity; dW: torque or derivative with
 * respect to the angular velocity, global) to the body's 6 velocity
 * coordinates [rd; w']:  c = [dV; A^T((P - r) x dV + dW)]. */
static inline void mb_rigid_cols(const mb_frame *f, const mb_real P[3], const mb_real dV[3],
                                 const mb_real dW[3], mb_real c[6]) {
  mb_real u[3] = {P[0] - f->r[0], P[1] - f->r[1], P[2] - f->r[2]}, t[3];
  mb_cross3(u, dV, t);
  t[0] += dW[0]; t[1] += dW[1]; t[2] += dW[2];
  c[0] = dV[0]; c[1] = dV[1]; c[2] = dV[2];
  mb_mul3t(f->A, t, c + 3);
}

/* --- time functions ------------------------------------------------------------- */
typedef enum {
  MB_PROFILE_CONSTANT = 1, MB_PROFILE_CONSTANT_VELOCITY, MB_PROFILE_POLYNOMIAL,
  MB_PROFILE_RAMP, MB_PROFILE_SINE, MB_PROFILE_TABLE
} mb_profile_kind;

typedef struct {
  mb_profile_kind kind;
  mb_real c[8];
  int nc;
  int ntable;
  const mb_real *table;  /* ntable pairs (t, x) */
  const mb_real *spline; /* ntable second derivatives of the natural cubic spline */
} mb_profile;

/* x(t), x'(t), x''(t) */
static inline void mb_profile_eval(const mb_profile *p, mb_real t, mb_real x[3]) {
  x[0] = x[1] = x[2] = 0;
  switch (p->kind) {
  case MB_PROFILE_CONSTANT:
    x[0] = p->c[0];
    break;
  case MB_PROFILE_CONSTANT_VELOCITY:
    x[0] = p->c[0] + p->c[1] * t;
    x[1] = p->c[1];
    break;
  case MB_PROFILE_POLYNOMIAL:
    for (int k = p->nc - 1; k >= 0; k--) { /* Horner, with derivatives */
      x[2] = x[2] * t + 2 * x[1];
      x[1] = x[1] * t + x[0];
      x[0] = x[0] * t + p->c[k];
    }
    break;
  case MB_PROFILE_RAMP: { /* cubic step, as Adams STEP */
    mb_real t0 = p->c[0], x0 = p->c[1], t1 = p->c[2], x1 = p->c[3];
    if (t <= t0) { x[0] = x0; break; }
    if (t >= t1) { x[0] = x1; break; }
    mb_real T = t1 - t0, s = (t - t0) / T, h = x1 - x0;
    x[0] = x0 + h * s * s * (3 - 2 * s);
    x[1] = h * 6 * s * (1 - s) / T;
    x[2] = h * (6 - 12 * s) / (T * T);
    break;
  }
  case MB_PROFILE_SINE: {
    mb_real om = 2 * MB_R(MB_PI) * p->c[1], ph = om * t + p->c[2];
    x[0] = p->c[3] + p->c[0] * MB_SIN(ph);
    x[1] = p->c[0] * om * MB_COS(ph);
    x[2] = -p->c[0] * om * om * MB_SIN(ph);
    break;
  }
  case MB_PROFILE_TABLE: {
    const mb_real *d = p->table, *m = p->spline;
    int n = p->ntable;
    if (t <= d[0]) { x[0] = d[1]; break; }
    if (t >= d[2 * (n - 1)]) { x[0] = d[2 * n - 1]; break; }
    int lo = 0, hi = n - 1; /* bisection: d[2 lo] <= t < d[2 hi] */
    while (hi - lo > 1) {
      int mid = (lo + hi) / 2;
      if (d[2 * mid] <= t) lo = mid; else hi = mid;
    }
    mb_real h = d[2 * hi] - d[2 * lo], a = (d[2 * hi] - t) / h, b = 1 - a;
    mb_real y0 = d[2 * lo + 1], y1 = d[2 * hi + 1], m0 = m[lo], m1 = m[hi];
    x[0] = a * y0 + b * y1 + ((a * a * a - a) * m0 + (b * b * b - b) * m1) * h * h / 6;
    x[1] = (y1 - y0) / h + (-(3 * a * a - 1) * m0 + (3 * b * b - 1) * m1) * h / 6;
    x[2] = a * m0 + b * m1;
    break;
  }
  }
}

/* --- constraint primitives --------------------------------------------------------- */
typedef struct {
  mb_real phi;         /* position constraint value */
  mb_real dV[2][3];    /* d(phidot)/dV of marker 0 and 1 */
  mb_real dW[2][3];    /* d(phidot)/dW of marker 0 and 1 */
  mb_real quad;        /* part of phi'' quadratic in marker velocities (and time terms) */
  mb_real nu;          /* phidot = D v - nu: nu = -d(phi)/dt (drivers) */
} mb_row;

static inline void mb_row_zero(mb_row *r) {
  r->phi = r->quad = r->nu = 0;
  for (int s = 0; s < 2; s++)
    for (int k = 0; k < 3; k++) r->dV[s][k] = r->dW[s][k] = 0;
}

/* gamma = -(dV . aP + dW . aW + quad): the right side of D vdot = gamma */
static inline mb_real mb_row_gamma(const mb_row *r, const mb_marker *m0, const mb_marker *m1) {
  return -(mb_dot3(r->dV[0], m0->aP) + mb_dot3(r->dW[0], m0->aW) +
           mb_dot3(r->dV[1], m1->aP) + mb_dot3(r->dW[1], m1->aW) + r->quad);
}

/* phidot = D v - nu: the velocity-level constraint violation */
static inline mb_real mb_row_phidot(const mb_row *r, const mb_marker *m0, const mb_marker *m1) {
  return mb_dot3(r->dV[0], m0->V) + mb_dot3(r->dW[0], m0->W) + mb_dot3(r->dV[1], m1->V) +
         mb_dot3(r->dW[1], m1->W) - r->nu;
}

/* spherical, component k: phi = (P1 - P0)_k */
static inline void mb_prim_sph(const mb_marker *m0, const mb_marker *m1, int k, mb_row *r) {
  mb_row_zero(r);
  r->phi = m1->P[k] - m0->P[k];
  r->dV[0][k] = -1;
  r->dV[1][k] = 1;
}

/* w x (w x a) */
static inline void mb_wwa(const mb_real w[3], const mb_real a[3], mb_real out[3]) {
  mb_real wa[3];
  mb_cross3(w, a, wa);
  mb_cross3(w, wa, out);
}

/* dot-1: axis a of marker 0 perpendicular to axis b of marker 1: phi = a0 . b1 */
static inline void mb_prim_dot1(const mb_marker *m0, const mb_marker *m1, int a, int b, mb_row *r) {
  mb_real ai[3], aj[3], c[3], dw[3];
  mb_row_zero(r);
  mb_col3(m0->R, a, ai);
  mb_col3(m1->R, b, aj);
  r->phi = mb_dot3(ai, aj);
  mb_cross3(ai, aj, c);
  for (int k = 0; k < 3; k++) { r->dW[0][k] = c[k]; r->dW[1][k] = -c[k]; }
  /* quad = (W0 x (W0 x ai)) . aj + 2 (W0 x ai) . (W1 x aj) + ai . (W1 x (W1 x aj)),
     with (w x (w x u)) . v = (w.u)(w.v) - (w.w)(u.v) and (w0 x u) . (w1 x v) =
     (w0.w1)(u.v) - (w0.v)(w1.u): four dot products and |W0 - W1|^2 instead of
     six cross products (docs/formulation.md) */
  mb_real s00 = mb_dot3(m0->W, ai), s01 = mb_dot3(m0->W, aj);
  mb_real s10 = mb_dot3(m1->W, ai), s11 = mb_dot3(m1->W, aj);
  for (int k = 0; k < 3; k++) dw[k] = m0->W[k] - m1->W[k];
  r->quad = s00 * s01 + s11 * s10 - 2 * (s01 * s10) - r->phi * mb_dot3(dw, dw);
}

/* dot-2: axis a of marker 0 perpendicular to d = P1 - P0: phi = a0 . d - x(t)
 * (x = 0 for a plain constraint; a translation driver passes its profile) */
static inline void mb_prim_dot2(const mb_marker *m0, const mb_marker *m1, int a, const mb_real x[3],
                                mb_row *r) {
  mb_real ai[3], d[3], dd[3], wa[3], q[3];
  mb_row_zero(r);
  mb_col3(m0->R, a, ai);
  for (int k = 0; k < 3; k++) { d[k] = m1->P[k] - m0->P[k]; dd[k] = m1->V[k] - m0->V[k]; }
  r->phi = mb_dot3(ai, d) - x[0];
  mb_cross3(ai, d, r->dW[0]);
  for (int k = 0; k < 3; k++) { r->dV[0][k] = -ai[k]; r->dV[1][k] = ai[k]; }
  mb_cross3(m0->W, ai, wa);
  mb_wwa(m0->W, ai, q);
  r->quad = mb_dot3(q, d) + 2 * mb_dot3(wa, dd) - x[2];
  r->nu = x[1];
}

/* distance: phi = (d . d - L^2) / (2 L), d = P1 - P0 */
static inline void mb_prim_dist(const mb_marker *m0, const mb_marker *m1, mb_real L, mb_row *r) {
  mb_real d[3], dd[3];
  mb_row_zero(r);
  for (int k = 0; k < 3; k++) { d[k] = m1->P[k] - m0->P[k]; dd[k] = m1->V[k] - m0->V[k]; }
  r->phi = (mb_dot3(d, d) - L * L) / (2 * L);
  for (int k = 0; k < 3; k++) { r->dV[0][k] = -d[k] / L; r->dV[1][k] = d[k] / L; }
  r->quad = mb_dot3(dd, dd) / L;
}

/* rotation driver: the angle from x0 to x1 about z0 follows th(t):
 * phi = x1 . e,  e = -sin(th) x0 + cos(th) y0  (phi = sin(angle - th)) */
static inline void mb_prim_rot(const mb_marker *m0, const mb_marker *m1, const mb_real th[3],
                               mb_row *r) {
  mb_real f[3], g[3], a[3], e[3], c[3], ed[3], wa[3], q[3], t1[3], t2[3];
  mb_row_zero(r);
  mb_col3(m0->R, 0, f);
  mb_col3(m0->R, 1, g);
  mb_col3(m1->R, 0, a);
  mb_real s = MB_SIN(th[0]), co = MB_COS(th[0]);
  for (int k = 0; k < 3; k++) { e[k] = -s * f[k] + co * g[k]; c[k] = co * f[k] + s * g[k]; }
  r->phi = mb_dot3(a, e);
  mb_cross3(e, a, r->dW[0]);
  mb_cross3(a, e, r->dW[1]);
  r->nu = th[1] * mb_dot3(a, c);
  /* ed = W0 x e - th' c; phi'' = a'' . e + 2 a' . ed + a . e'' */
  mb_cross3(m0->W, e, ed);
  for (int k = 0; k < 3; k++) ed[k] -= th[1] * c[k];
  mb_cross3(m1->W, a, wa);
  mb_wwa(m1->W, a, q);
  mb_cross3(m0->W, ed, t1);
  mb_cross3(m0->W, c, t2);
  mb_real edd_q[3];
  for (int k = 0; k < 3; k++) edd_q[k] = t1[k] - th[2] * c[k] - th[1] * (t2[k] + th[1] * e[k]);
  r->quad = mb_dot3(q, e) + 2 * mb_dot3(wa, ed) + mb_dot3(a, edd_q);
}

/* Which primitive a row is: the generic path dispatches on this. */
typedef enum {
  MB_PRIM_SPH = 1, MB_PRIM_DOT1, MB_PRIM_DOT2, MB_PRIM_DIST, MB_PRIM_ROT, MB_PRIM_TRANS
} mb_prim_kind;

/* the force elements' kernels: elements/ (one family a file, included by mb_model.h) */

#endif
