/* mb_tyre.h: the tyre-road element (one marker: the wheel centre, its z axis
 * the spin axis) and the road it rolls on.  docs/formulation.md ("Tyre")
 * derives the equations; the symbols below are its.
 *
 * Parameters (m->force_prm + padr, MB_TYRE_ROAD + road size reals):
 *   MB_TYRE_R0 .. MB_TYRE_DBLEND  the tyre's constants (enum below)
 *   MB_TYRE_ROAD ..               the road: its kind, then its data
 *     MB_ROAD_FLAT         height
 *     MB_ROAD_COSINE_BUMP  H, length, start, y_min, y_max
 *     MB_ROAD_TABLE        nx, ny, x[nx], y[ny], z[nx * ny] (z[i ny + j] at x_i, y_j)
 * No laws, no state (no slip relaxation).  Freestanding C99. */
#ifndef MB_TYRE_H
#define MB_TYRE_H

#include "../mb_kernels.h"

enum {
  MB_TYRE_R0 = 0,    /* unloaded radius R0, m */
  MB_TYRE_WIDTH,     /* tread width b, m (documentation; not in the forces) */
  MB_TYRE_KZ,        /* radial stiffness, N/m */
  MB_TYRE_CZ,        /* radial damping, N s/m */
  MB_TYRE_KS,        /* longitudinal slip stiffness, N per unit slip */
  MB_TYRE_KA,        /* cornering stiffness, N/rad */
  MB_TYRE_KG,        /* camber stiffness, N/rad */
  MB_TYRE_MU0,       /* friction at zero slip */
  MB_TYRE_MU1,       /* friction at full slip */
  MB_TYRE_CRR,       /* rolling-resistance lever arm, m */
  MB_TYRE_MODEL,     /* 0: Gim-Nikravesh comprehensive slip, 1: Fiala */
  MB_TYRE_VLOW,      /* velocity scale of the slips' regularization at standstill, m/s */
  MB_TYRE_DBLEND,    /* deflection over which the radial damping fades in, m */
  MB_TYRE_ROAD,      /* the road's kind and data follow */
  MB_TYRE_NPRM = MB_TYRE_ROAD
};

enum { MB_ROAD_FLAT = 0, MB_ROAD_COSINE_BUMP = 1, MB_ROAD_TABLE = 2 };

/* the tyre's quantities at one instant (the outputs' ten columns and the
 * contact frame); forces and moments in the contact frame, at the contact point */
typedef struct {
  mb_real Fx, Fy, Fz, Mx, My, Mz;
  mb_real slip, slip_angle, camber, deflection;
  mb_real X[3];          /* contact point, global */
  mb_real ex[3], ey[3], n[3]; /* contact frame: forward, lateral, road normal */
} mb_tyre_state;

/* the road's height at (x, y), its gradient g = (h_x, h_y) and its second
 * derivatives H = (h_xx, h_xy, h_yy) */
static inline mb_real mb_road_height(const mb_real *road, mb_real x, mb_real y, mb_real g[2],
                                     mb_real H[3]) {
  g[0] = g[1] = H[0] = H[1] = H[2] = 0;
  switch ((int)road[0]) {
  case MB_ROAD_FLAT:
    return road[1];
  case MB_ROAD_COSINE_BUMP: {
    mb_real Hb = road[1], Lb = road[2], x0 = road[3];
    if (x < x0 || x > x0 + Lb || y < road[4] || y > road[5]) return 0;
    mb_real k = 2 * MB_R(MB_PI) / Lb, ph = k * (x - x0);
    g[0] = MB_R(0.5) * Hb * k * MB_SIN(ph);
    H[0] = MB_R(0.5) * Hb * k * k * MB_COS(ph);
    return MB_R(0.5) * Hb * (1 - MB_COS(ph));
  }
  case MB_ROAD_TABLE: { /* bilinear; held at the edge values outside the grid */
    int nx = (int)road[1], ny = (int)road[2];
    const mb_real *xs = road + 3, *ys = xs + nx, *z = ys + ny;
    int i = 0, j = 0;
    while (i < nx - 2 && x > xs[i + 1]) i++;
    while (j < ny - 2 && y > ys[j + 1]) j++;
    mb_real hx = xs[i + 1] - xs[i], hy = ys[j + 1] - ys[j];
    mb_real u = (x - xs[i]) / hx, v = (y - ys[j]) / hy;
    int inside_x = u >= 0 && u <= 1, inside_y = v >= 0 && v <= 1;
    u = u < 0 ? 0 : u > 1 ? 1 : u;
    v = v < 0 ? 0 : v > 1 ? 1 : v;
    mb_real z00 = z[i * ny + j], z01 = z[i * ny + j + 1], z10 = z[(i + 1) * ny + j],
            z11 = z[(i + 1) * ny + j + 1];
    mb_real a = z10 - z00, b = z01 - z00, c = z11 - z10 - z01 + z00;
    if (inside_x) g[0] = (a + c * v) / hx;
    if (inside_y) g[1] = (b + c * u) / hy;
    if (inside_x && inside_y) H[1] = c / (hx * hy);
    return z00 + a * u + b * v + c * u * v;
  }
  }
  return 0;
}

/* cubic step from 0 at x <= 0 to 1 at x >= 1, and its slope */
static inline mb_real mb_tyre_step(mb_real x, mb_real *slope) {
  if (x <= 0) { *slope = 0; return 0; }
  if (x >= 1) { *slope = 0; return 1; }
  *slope = 6 * x * (1 - x);
  return x * x * (3 - 2 * x);
}

/* max(x, 0) with the corner rounded over [0, e]: 2x^2/e - x^3/e^2 there
 * (value and slope match at both ends, so no offset above e) */
static inline mb_real mb_tyre_pos(mb_real x, mb_real e, mb_real *slope) {
  if (x <= 0) { *slope = 0; return 0; }
  if (x >= e) { *slope = 1; return x; }
  *slope = 4 * x / e - 3 * x * x / (e * e);
  return 2 * x * x / e - x * x * x / (e * e);
}

/* The nearest road point X to the wheel centre C in the wheel plane (normal
 * a).  Points of the plane are C + s f + w u (f = unit(a x z) forward and
 * horizontal, u = f x a); w(s) puts the point on the road (fixed point: exact
 * in one pass without camber), and Newton on d/ds (s^2 + w^2) / 2 = s + w w'
 * finds the nearest (unique while the road's radius of curvature exceeds the
 * distance, as for the bump).  Returns 0 when the wheel lies flat. */
static inline int mb_tyre_contact(const mb_real *road, const mb_real C[3], const mb_real a[3],
                                  mb_real X[3], mb_real nrm[3]) {
  mb_real f[3] = {a[1], -a[0], 0}; /* a x z */
  mb_real fl = MB_SQRT(f[0] * f[0] + f[1] * f[1]);
  if (fl < MB_R(1e-6)) return 0;
  f[0] /= fl; f[1] /= fl;
  mb_real u[3], g[2], Hs[3];
  mb_cross3(f, a, u);
  mb_real s = 0, w = 0, h = 0, ds = 1;
  /* converged: a step below the precision's resolution of a metre-sized s */
  const mb_real tol = sizeof(mb_real) < sizeof(double) ? MB_R(1e-6) : MB_R(1e-13);
  for (int it = 0; it < 30; it++) {
    /* w(s): the road under the plane's line through C + s f along u */
    w = mb_road_height(road, C[0] + s * f[0], C[1] + s * f[1], g, Hs) - C[2];
    for (int k = 0; k < 3; k++) {
      h = mb_road_height(road, C[0] + s * f[0] + w * u[0], C[1] + s * f[1] + w * u[1], g, Hs);
      w = (h - C[2]) / u[2];
    }
    mb_real den = u[2] - (g[0] * u[0] + g[1] * u[1]);
    mb_real w1 = (g[0] * f[0] + g[1] * f[1]) / den;
    mb_real w2 = (Hs[0] * f[0] * f[0] + 2 * Hs[1] * f[0] * f[1] + Hs[2] * f[1] * f[1]) / den;
    mb_real curv = 1 + w1 * w1 + w * w2;
    if (curv < MB_R(0.1)) curv = MB_R(0.1);
    ds = -(s + w * w1) / curv;
    s += ds;
    if (MB_FABS(ds) < tol) break;
  }
  if (ds != 0) { /* w, g and Hs at the final s (a zero step, as on a flat road, left them there) */
    w = mb_road_height(road, C[0] + s * f[0], C[1] + s * f[1], g, Hs) - C[2];
    for (int k = 0; k < 3; k++) {
      h = mb_road_height(road, C[0] + s * f[0] + w * u[0], C[1] + s * f[1] + w * u[1], g, Hs);
      w = (h - C[2]) / u[2];
    }
  }
  for (int k = 0; k < 3; k++) X[k] = C[k] + s * f[k] + w * u[k];
  mb_real nl = MB_SQRT(1 + g[0] * g[0] + g[1] * g[1]);
  nrm[0] = -g[0] / nl; nrm[1] = -g[1] / nl; nrm[2] = 1 / nl;
  return 1;
}

/* Tyre: from the wheel marker (point C = the wheel centre, z axis the spin
 * axis a), the force F and torque T on the wheel (global, T about C); returns
 * the radial spring's potential energy 1/2 K_z delta^2.  st (NULL to skip)
 * receives the outputs.  tangent (NULL to skip), 72 reals, mb_field's
 * convention (6x6 of [F; T] with respect to [dC; dphi], then to [V; W]):
 * the radial spring-damper exactly, the slip forces through their slopes
 * K xi^2 (exact at free rolling and in pure slip at constant friction),
 * and the change of the friction, the aligning moment and the contact
 * point's move are left out (docs/formulation.md). */
#ifdef MB_NO_TYRE
/* An embedded package of a model without tyres defines MB_NO_TYRE (in its
 * mb_types.h): the element is left out (its asinf linked newlib's errno and
 * reentrancy data, 1 KB of RAM).  A tyre reaching it gives NaN, which the
 * step reports (MB_ERR_NONFINITE). */
static inline mb_real mb_tyre(const mb_marker *mk, const mb_real *prm, mb_real F[3], mb_real T[3],
                              mb_tyre_state *st, mb_real *tangent) {
  static const mb_tyre_state none;
  (void)mk, (void)prm, (void)tangent;
  if (st) *st = none;
  for (int k = 0; k < 3; k++) F[k] = T[k] = (mb_real)NAN;
  return (mb_real)NAN;
}
#else
static inline mb_real mb_tyre(const mb_marker *mk, const mb_real *prm, mb_real F[3], mb_real T[3],
                              mb_tyre_state *st, mb_real *tangent) {
  const mb_real *road = prm + MB_TYRE_ROAD;
  mb_real R0 = prm[MB_TYRE_R0], Kz = prm[MB_TYRE_KZ], Cz = prm[MB_TYRE_CZ];
  mb_real Ks = prm[MB_TYRE_KS], Ka = prm[MB_TYRE_KA], Kg = prm[MB_TYRE_KG];
  mb_real mu0 = prm[MB_TYRE_MU0], mu1 = prm[MB_TYRE_MU1], Crr = prm[MB_TYRE_CRR];
  mb_real vlow = prm[MB_TYRE_VLOW], dbl = prm[MB_TYRE_DBLEND];
  int fiala = prm[MB_TYRE_MODEL] != 0;
  mb_real a[3] = {mk->R[2], mk->R[5], mk->R[8]}, X[3], n[3], E = 0;
  mb_tyre_state s0;
  int want_state = st != 0; /* the outputs' camber angle costs an arcsine */
  if (!st) st = &s0;
  for (int k = 0; k < 3; k++) {
    F[k] = T[k] = 0;
    st->X[k] = st->ex[k] = st->ey[k] = st->n[k] = 0;
  }
  st->Fx = st->Fy = st->Fz = st->Mx = st->My = st->Mz = 0;
  st->slip = st->slip_angle = st->camber = st->deflection = 0;
  if (tangent)
    for (int k = 0; k < 72; k++) tangent[k] = 0;
  if (!mb_tyre_contact(road, mk->P, a, X, n)) return 0;
  mb_real r[3] = {X[0] - mk->P[0], X[1] - mk->P[1], X[2] - mk->P[2]}; /* centre to contact */
  mb_real rho = MB_SQRT(mb_dot3(r, r)), delta = R0 - rho;
  /* contact frame: x forward in the wheel plane and the road plane, z the normal */
  mb_real ex[3], ey[3];
  mb_cross3(a, n, ex);
  mb_real exl = MB_SQRT(mb_dot3(ex, ex));
  for (int k = 0; k < 3; k++) ex[k] /= exl;
  mb_cross3(n, ex, ey);
  mb_real sg = mb_dot3(a, n); /* sin(camber): the spin axis out of the road plane */
  for (int k = 0; k < 3; k++) { st->X[k] = X[k]; st->ex[k] = ex[k]; st->ey[k] = ey[k]; st->n[k] = n[k]; }
  if (want_state) st->camber = MB_ASIN(sg > 1 ? 1 : sg < -1 ? -1 : sg);
  st->deflection = delta;
  if (delta <= 0) return 0; /* off the road: no force at all */
  E = MB_R(0.5) * Kz * delta * delta;

  /* radial spring-damper that only pushes: the damping fades in over dbl
     and the clip at zero is rounded over a force of K_z dbl / 100 */
  mb_real e[3] = {-r[0] / rho, -r[1] / rho, -r[2] / rho}; /* contact point to centre */
  mb_real ddelta = -mb_dot3(e, mk->V);
  mb_real bs, bl = mb_tyre_step(delta / dbl, &bs), ps;
  mb_real Fz = mb_tyre_pos(Kz * delta + Cz * ddelta * bl, Kz * dbl / 100, &ps);
  mb_real dFz_dd = ps * (Kz + Cz * ddelta * bs / dbl), dFz_ddd = ps * Cz * bl;

  /* slips: S_x = (R_e Omega - V_x) / D, S_y = V_y / D with
     D = sqrt(max(V_x^2, (R_e Omega)^2) + vlow^2): Gim's braking and driving
     definitions at once, regularized at standstill */
  mb_real Re = R0 - delta / 3, Om = mb_dot3(mk->W, a);
  mb_real Vx = mb_dot3(mk->V, ex), Vy = mb_dot3(mk->V, ey), Vr = Re * Om;
  mb_real D = MB_SQRT(MB_FMAX(Vx * Vx, Vr * Vr) + vlow * vlow);
  mb_real Sx = (Vr - Vx) / D, Sy = Vy / D;
  mb_real Fx, Fy, cx, cy, xi;
  if (!fiala) {
    /* Gim-Nikravesh: comprehensive slip, one adhesion fraction xi */
    mb_real S = MB_SQRT(Sx * Sx + Sy * Sy);
    mb_real mu = mu0 - (mu0 - mu1) * (S < 1 ? S : 1);
    mb_real q = MB_SQRT(Ks * Ks * Sx * Sx + Ka * Ka * Sy * Sy) / (3 * mu * Fz + MB_R(1e-30));
    xi = q < 1 ? 1 - q : 0;
    mb_real Fs = mu * Fz * (1 - 3 * xi * xi + 2 * xi * xi * xi);
    mb_real cs = S > 0 ? Sx / S : 0, sn = S > 0 ? Sy / S : 0;
    Fx = Ks * Sx * xi * xi + Fs * cs;
    Fy = -(Ka * Sy * xi * xi + Fs * sn);
    cx = Ks * xi * xi;
    cy = Ka * xi * xi;
  } else {
    /* Fiala: each direction on its own at constant friction mu0,
       F = mu Fz (1 - H^3) sign, H = 1 - K |S| / (3 mu Fz) */
    mb_real m3 = 3 * mu0 * Fz + MB_R(1e-30);
    mb_real Hx = 1 - Ks * MB_FABS(Sx) / m3, Hy = 1 - Ka * MB_FABS(Sy) / m3;
    Hx = Hx > 0 ? Hx : 0;
    Hy = Hy > 0 ? Hy : 0;
    Fx = (Sx < 0 ? MB_R(-1.0) : MB_R(1.0)) * mu0 * Fz * (1 - Hx * Hx * Hx);
    Fy = -(Sy < 0 ? MB_R(-1.0) : MB_R(1.0)) * mu0 * Fz * (1 - Hy * Hy * Hy);
    cx = Ks * Hx * Hx;
    cy = Ka * Hy * Hy;
    xi = Hy;
  }
  /* aligning moment: the lateral slip force acts a trail t = l xi / 6 behind
     the contact point (l = sqrt(8 R0 delta), the brush's l/6 at small slip,
     none at full slide) */
  mb_real Mz = -(MB_SQRT(8 * R0 * delta) * xi / 6) * Fy;
  /* camber thrust, towards the side the wheel leans to; it builds up with
     the rolling speed as the slips do (factor V / D): at standstill nothing
     would hold it, and toed-in cambered wheels would push a car at rest */
  mb_real rolling = MB_SQRT(MB_FMAX(Vx * Vx, Vr * Vr)) / D;
  Fy -= Kg * sg * xi * rolling;
  /* rolling resistance: a lever arm C_rr against the spin (sign regularized) */
  mb_real sgn = Vr / MB_SQRT(Vr * Vr + vlow * vlow), My = -Crr * Fz * sgn;

  for (int k = 0; k < 3; k++) F[k] = Fx * ex[k] + Fy * ey[k] + Fz * n[k];
  mb_cross3(r, F, T);
  for (int k = 0; k < 3; k++) T[k] += My * a[k] + Mz * n[k];
  st->Fx = Fx; st->Fy = Fy; st->Fz = Fz; st->My = My; st->Mz = Mz;
  st->slip = Sx;
  st->slip_angle = MB_ATAN2(Sy, 1);

  if (tangent) {
    /* rows 0-2: dF, rows 3-5: dT = r x dF + a dMy; columns [dC dphi] (block 0), [V W] (block 1) */
    mb_real dF[2][3][6];
    for (int b = 0; b < 2; b++)
      for (int i = 0; i < 3; i++)
        for (int j = 0; j < 6; j++) dF[b][i][j] = 0;
    mb_real dMy[2][6] = {{0}};
    mb_real axe[3], axv[3], yxv[3], axw[3];
    mb_cross3(a, n, axe);
    mb_cross3(ex, mk->V, axv);
    mb_cross3(ey, mk->V, yxv);
    mb_cross3(a, mk->W, axw);
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++) {
        /* Fz n: d delta / dC = -e, d ddelta / dV = -e */
        dF[0][i][j] += -n[i] * dFz_dd * e[j];
        dF[1][i][j] += -n[i] * dFz_ddd * e[j];
        /* Fx ex: S_x through R_e (dR_e/dC = e/3), V_x and Omega */
        dF[0][i][j] += ex[i] * cx * Om * e[j] / (3 * D);
        dF[1][i][j] += -ex[i] * cx * ex[j] / D;
        dF[1][i][3 + j] += ex[i] * cx * Re * a[j] / D;
        /* Fy ey: S_y through V_y */
        dF[1][i][j] += -ey[i] * cy * ey[j] / D;
        /* turning the wheel: camber (d sin g = dphi . (a x n)), the contact
           frame turning under V (steer) and Omega (spin axis) */
        dF[0][i][3 + j] += -ey[i] * Kg * xi * rolling * axe[j] - ex[i] * cx * axv[j] / D -
                           ey[i] * cy * yxv[j] / D + ex[i] * cx * Re * axw[j] / D;
      }
    for (int j = 0; j < 3; j++) {
      dMy[0][j] = Crr * sgn * dFz_dd * e[j];
      dMy[1][j] = Crr * sgn * dFz_ddd * e[j];
    }
    /* the aligning moment through V_y; the lever r = -rho e shortening with delta */
    mb_real trail = MB_SQRT(8 * R0 * delta) * xi / 6, exF[3];
    mb_cross3(e, F, exF);
    for (int b = 0; b < 2; b++)
      for (int j = 0; j < 6; j++) {
        mb_real col[3] = {dF[b][0][j], dF[b][1][j], dF[b][2][j]}, rc[3];
        mb_cross3(r, col, rc);
        mb_real dMz = (b == 1 && j < 3) ? trail * cy * ey[j] / D : 0;
        for (int i = 0; i < 3; i++) {
          tangent[36 * b + 6 * i + j] = col[i];
          tangent[36 * b + 6 * (3 + i) + j] = rc[i] + a[i] * dMy[b][j] + n[i] * dMz -
                                              (b == 0 && j < 3 ? exF[i] * e[j] : 0);
        }
      }
  }
  return E;
}
#endif /* MB_NO_TYRE */

#endif
