/* test_tyre.c: the tyre-road element (runtime/core/elements/mb_tyre.h).
 * The kernel's forces at given slips against the formulas of the
 * Gim-Nikravesh and Fiala models written out here from the spec (§8.1, 8.2)
 * with the unregularized slip definitions (braking and driving separately);
 * the radial force (only pushes); the cosine bump's height and the disc
 * contact on its flank against a brute-force nearest point; table roads
 * (inline and from a CSV file); the tangent
 * against finite differences; and, simulated: a quarter car falling freely
 * until it touches (no force while airborne) and settling to deflection =
 * load / K_z; a four-wheel cart at 60 km/h losing speed at the
 * rolling-resistance rate and holding its course; the generated evaluation
 * against the generic one. */
// models: tyre_cart tyre_quarter
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "support.h"
#include "mb_model.h"
#include "tyre_cart.h"
#include "tyre_quarter.h"

enum { NPRM = MB_TYRE_ROAD + 6 };

static const double R0 = 0.3213, KZ = 2.0e5, CZ = 200, KS = 6.0e4, KA = 4.5e4, KG = 3.0e3, MU0 = 1.0,
                    MU1 = 0.8, CRR = 0.005;

/* the spec's tyre on a flat road at z = 0; vlow tiny: the slips as defined
   without regularization */
static void tyre_prm(double *prm, int fiala) {
  memset(prm, 0, sizeof(double) * NPRM);
  prm[MB_TYRE_R0] = R0; prm[MB_TYRE_WIDTH] = 0.16; prm[MB_TYRE_KZ] = KZ; prm[MB_TYRE_CZ] = CZ;
  prm[MB_TYRE_KS] = KS; prm[MB_TYRE_KA] = KA; prm[MB_TYRE_KG] = KG;
  prm[MB_TYRE_MU0] = MU0; prm[MB_TYRE_MU1] = fiala ? MU0 : MU1; prm[MB_TYRE_CRR] = CRR;
  prm[MB_TYRE_MODEL] = fiala; prm[MB_TYRE_VLOW] = 1e-9; prm[MB_TYRE_DBLEND] = 1e-3;
  prm[MB_TYRE_ROAD] = MB_ROAD_FLAT;
}

/* a wheel with spin axis +y (no camber), centre height z, velocity V, spin w */
static void wheel(mb_marker *m, double z, const double V[3], double w) {
  memset(m, 0, sizeof *m);
  double Rm[9] = {1, 0, 0, 0, 0, 1, 0, -1, 0}; /* columns (1,0,0), (0,0,-1), (0,1,0) */
  memcpy(m->R, Rm, sizeof Rm);
  m->P[0] = 2.0; m->P[1] = 0.3; m->P[2] = z;
  for (int j = 0; j < 3; j++) m->V[j] = V[j];
  m->W[1] = w;
}

/* Gim-Nikravesh (spec 8.1) for a wheel with V_x > 0: forces along the
   contact x and y, from the braking/driving slip definitions */
static void gim_expected(double Fz, double Vx, double Vy, double ReOm, double *Fx, double *Fy) {
  double Ss, Sa;
  int driving = ReOm > Vx;
  if (!driving) { Ss = (Vx - ReOm) / Vx; Sa = fabs(Vy / Vx); }
  else { Ss = (ReOm - Vx) / ReOm; Sa = (1 - Ss) * fabs(Vy / Vx); }
  double S = sqrt(Ss * Ss + Sa * Sa), mu = MU0 - (MU0 - MU1) * fmin(S, 1);
  double xi = 1 - sqrt(KS * KS * Ss * Ss + KA * KA * Sa * Sa) / (3 * mu * Fz);
  if (xi < 0) xi = 0;
  double slide = mu * Fz * (1 - 3 * xi * xi + 2 * xi * xi * xi);
  double fx = KS * Ss * xi * xi + (S > 0 ? slide * Ss / S : 0);
  double fy = KA * Sa * xi * xi + (S > 0 ? slide * Sa / S : 0);
  *Fx = driving ? fx : -fx;       /* opposes the contact's slip velocity V_x - R_e Omega */
  *Fy = Vy > 0 ? -fy : fy;        /* opposes V_y */
}

/* the load Fz = K_z delta at rest vertically; the centre height for it */
static double height_for(double delta) { return R0 - delta; }

static void check_gim(double Vx, double Vy, double ReOm, double delta, double tol) {
  double prm[NPRM], F[3], T[3];
  tyre_prm(prm, 0);
  mb_marker m;
  double Re = R0 - delta / 3;
  wheel(&m, height_for(delta), (const double[3]){Vx, Vy, 0}, ReOm / Re);
  mb_tyre_state st;
  mb_tyre(&m, prm, F, T, &st, 0);
  double Fz = KZ * delta, ex, ey;
  gim_expected(Fz, Vx, Vy, ReOm, &ex, &ey);
  assert_close(st.Fz, Fz, 1e-9 * Fz);
  assert_close(st.Fx, ex, tol * Fz);
  assert_close(st.Fy, ey, tol * Fz);
  /* global force: Fx along +x, Fy along +y, Fz up (no camber, flat road) */
  assert_close(F[0], st.Fx, 1e-12 * Fz);
  assert_close(F[1], st.Fy, 1e-12 * Fz);
  assert_close(F[2], st.Fz, 1e-12 * Fz);
  /* never more than the friction allows */
  assert_true(hypot(st.Fx, st.Fy) <= MU0 * Fz * (1 + 1e-12));
}

static void test_gim_forces(void **state) {
  (void)state;
  const double delta = 0.01, Fz = KZ * delta, V = 20;
  /* pure longitudinal, braking and driving, through the adhesion range to full slide */
  const double slips[] = {1e-4, 0.01, 0.03, 0.08, 0.2, 0.5, 0.9};
  for (int k = 0; k < 7; k++) {
    check_gim(V, 0, V * (1 - slips[k]), delta, 1e-9);          /* braking */
    check_gim(V, 0, V / (1 - slips[k]), delta, 1e-9);          /* driving */
    check_gim(V, V * tan(0.02 * k + 1e-3), V, delta, 1e-9);    /* pure lateral, free rolling */
    check_gim(V, -V * slips[k], V * (1 - slips[k]), delta, 1e-9); /* combined, braking */
    check_gim(V, V * slips[k] / 2, V / (1 - slips[k]), delta, 1e-9); /* combined, driving */
  }
  double prm[NPRM], F[3], T[3];
  tyre_prm(prm, 0);
  mb_marker m;
  mb_tyre_state st;
  double Re = R0 - delta / 3;
  /* xi = 1 (tiny slip): linear, F_x = K_s S_s, F_y = -K_alpha tan(alpha) */
  wheel(&m, height_for(delta), (const double[3]){V, V * 1e-5, 0}, V * (1 + 1e-5) / Re);
  mb_tyre(&m, prm, F, T, &st, 0);
  assert_close(st.Fx, KS * 1e-5 / (1 + 1e-5), 1e-3 * KS * 1e-5);
  assert_close(st.Fy, -KA * 1e-5 / (1 + 1e-5), 1e-3 * KA * 1e-5);
  /* locked wheel (S_s = 1): full slide at mu1 Fz, against the motion */
  wheel(&m, height_for(delta), (const double[3]){V, 0, 0}, 0);
  mb_tyre(&m, prm, F, T, &st, 0);
  assert_close(st.Fx, -MU1 * Fz, 1e-9 * Fz);
  /* sliding sideways at 60 degrees, free rolling: the resultant is mu Fz */
  wheel(&m, height_for(delta), (const double[3]){V, V * tan(1.05), 0}, V / Re);
  mb_tyre(&m, prm, F, T, &st, 0);
  assert_close(hypot(st.Fx, st.Fy), MU1 * Fz, 1e-9 * Fz);
  /* rolling resistance: M_y = -C_rr Fz against the spin, about the spin axis;
     the torque about the centre also has the contact force's lever */
  wheel(&m, height_for(delta), (const double[3]){V, 0, 0}, V / Re);
  mb_tyre(&m, prm, F, T, &st, 0);
  assert_close(st.My, -CRR * Fz, 1e-6 * CRR * Fz);
  double rho = R0 - delta; /* contact point right below the centre */
  assert_close(T[1], -CRR * Fz + rho * st.Fx, 1e-9 * Fz);
  /* aligning moment at small slip: the lateral force a trail l/6 behind the
     contact point (brush model), l = 2 sqrt(2 R0 delta) */
  wheel(&m, height_for(delta), (const double[3]){V, V * 1e-4, 0}, V / Re);
  mb_tyre(&m, prm, F, T, &st, 0);
  double l = 2 * sqrt(2 * R0 * delta);
  assert_close(st.Mz / st.Fy, -l / 6, 1e-3 * l);
}

static void test_fiala_forces(void **state) {
  (void)state;
  const double delta = 0.012, Fz = KZ * delta, V = 15, Re = R0 - delta / 3;
  double prm[NPRM], F[3], T[3];
  tyre_prm(prm, 1);
  mb_marker m;
  mb_tyre_state st;
  for (int k = 0; k <= 40; k++) {
    double alpha = 0.005 * k; /* through the critical slip angle (about 0.14 rad) */
    wheel(&m, height_for(delta), (const double[3]){V, V * tan(alpha), 0}, V / Re);
    mb_tyre(&m, prm, F, T, &st, 0);
    double H = 1 - KA * fabs(tan(alpha)) / (3 * MU0 * Fz);
    double Fy = H > 0 ? -MU0 * Fz * (1 - H * H * H) : -MU0 * Fz;
    assert_close(st.Fy, Fy, 1e-9 * Fz);
    assert_close(st.Fx, 0, 1e-9 * Fz);
    double s = 0.01 * k; /* braking slip, through the critical 3 mu Fz / K_s = 0.12 */
    wheel(&m, height_for(delta), (const double[3]){V, 0, 0}, V * (1 - s) / Re);
    mb_tyre(&m, prm, F, T, &st, 0);
    H = 1 - KS * s / (3 * MU0 * Fz);
    double Fx = H > 0 ? -MU0 * Fz * (1 - H * H * H) : -MU0 * Fz;
    assert_close(st.Fx, Fx, 1e-9 * Fz);
  }
}

/* the radial force: K delta + C delta-dot, never pulling; nothing off the road */
static void test_radial(void **state) {
  (void)state;
  double prm[NPRM], F[3], T[3];
  tyre_prm(prm, 0);
  mb_marker m;
  mb_tyre_state st;
  const double delta = 0.02;
  wheel(&m, height_for(delta), (const double[3]){0, 0, -0.3}, 0); /* compressing */
  mb_tyre(&m, prm, F, T, &st, 0);
  assert_close(st.Fz, KZ * delta + CZ * 0.3, 1e-9 * KZ * delta);
  assert_close(st.deflection, delta, 1e-15);
  wheel(&m, height_for(0.001), (const double[3]){0, 0, 50}, 0); /* rebounding fast: the damper would pull */
  mb_tyre(&m, prm, F, T, &st, 0);
  assert_true(st.Fz == 0 && F[2] == 0);
  wheel(&m, R0 + 1e-6, (const double[3]){0, 0, -3}, 10); /* just above the road */
  double E = mb_tyre(&m, prm, F, T, &st, 0);
  assert_true(F[0] == 0 && F[1] == 0 && F[2] == 0 && T[0] == 0 && T[1] == 0 && T[2] == 0 && E == 0);
  /* the potential's slope is the spring force */
  wheel(&m, height_for(delta), (const double[3]){0, 0, 0}, 0);
  double h = 1e-7, Ep, Em;
  m.P[2] += h; Ep = mb_tyre(&m, prm, F, T, 0, 0);
  m.P[2] -= 2 * h; Em = mb_tyre(&m, prm, F, T, 0, 0);
  assert_close(-(Ep - Em) / (2 * h), KZ * delta, 1e-6 * KZ * delta);
}

/* the cosine bump: height against its closed form; the disc contact on its
   flank against the nearest point found by brute force in the wheel plane */
static void test_bump(void **state) {
  (void)state;
  const double Hb = 0.10, Lb = 1.0, x0 = 10.0;
  double prm[NPRM + 4];
  tyre_prm(prm, 0);
  double *road = prm + MB_TYRE_ROAD;
  road[0] = MB_ROAD_COSINE_BUMP; road[1] = Hb; road[2] = Lb; road[3] = x0; road[4] = 0.2; road[5] = 1.2;
  for (int k = -5; k <= 25; k++) {
    double x = x0 + 0.05 * k, g[2], H[3];
    double expect = (x >= x0 && x <= x0 + Lb) ? Hb / 2 * (1 - cos(2 * MB_PI * (x - x0) / Lb)) : 0;
    assert_close(mb_road_height(road, x, 0.7, g, H), expect, 1e-15);
    assert_close(mb_road_height(road, x, -0.7, g, H), 0, 0); /* the right track: no bump */
    assert_close(mb_road_height(road, x, 1.3, g, H), 0, 0);
  }
  /* crest: the wheel centre right above it */
  mb_marker m;
  mb_tyre_state st;
  double F[3], T[3];
  wheel(&m, Hb + R0 - 0.01, (const double[3]){10, 0, 0}, 10 / R0);
  m.P[0] = x0 + Lb / 2; m.P[1] = 0.7;
  mb_tyre(&m, prm, F, T, &st, 0);
  assert_close(st.deflection, 0.01, 1e-12);
  /* flank: centre at several x before and on the bump, 2 cm lower than
     flat-road contact; brute force over the profile z = h(x) in the plane y = 0.7 */
  for (int k = 0; k < 12; k++) {
    double xc = x0 - 0.2 + 0.06 * k, zc = R0 - 0.02 + 0.03 * k * (k < 9);
    wheel(&m, zc, (const double[3]){10, 0, 0}, 10 / R0);
    m.P[0] = xc; m.P[1] = 0.7;
    mb_tyre(&m, prm, F, T, &st, 0);
    double best = INFINITY, bx = 0, g[2], H[3];
    for (double x = xc - 0.4; x <= xc + 0.4; x += 1e-4) {
      double d = hypot(x - xc, mb_road_height(road, x, 0.7, g, H) - zc);
      if (d < best) { best = d; bx = x; }
    }
    for (double step = 1e-4; step > 1e-13; step /= 2) { /* refine around the sampled minimum */
      double dl = hypot(bx - step - xc, mb_road_height(road, bx - step, 0.7, g, H) - zc);
      double dr = hypot(bx + step - xc, mb_road_height(road, bx + step, 0.7, g, H) - zc);
      if (dl < best) { best = dl; bx -= step; }
      else if (dr < best) { best = dr; bx += step; }
    }
    assert_close(st.deflection, R0 - best, 1e-9);
    assert_close(st.X[0], bx, 1e-5);
    /* the force leans back on the rising flank (the bump's longitudinal impulse) */
    if (st.deflection > 0.005 && bx > x0 + 0.05 && bx < x0 + 0.45) assert_true(F[0] < 0);
  }
}

/* table roads: bilinear, so exact for z = a + b x + c y + d x y on every cell;
   the cart's rear tyres carry the CSV road (tests/models/tyre_cart_road.csv):
   x along the rows, y along the header */
static double bilinear_fn(double x, double y) { return 0.1 + 0.2 * x - 0.3 * y + 0.05 * x * y; }

static void test_table_road(void **state) {
  (void)state;
  const double xs[3] = {0, 1, 3}, ys[3] = {-1, 0.5, 2};
  double road[3 + 3 + 3 + 9] = {MB_ROAD_TABLE, 3, 3};
  for (int i = 0; i < 3; i++) { road[3 + i] = xs[i]; road[6 + i] = ys[i]; }
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) road[9 + 3 * i + j] = bilinear_fn(xs[i], ys[j]);
  for (int k = 0; k < 50; k++) {
    double x = urand(0, 3), y = urand(-1, 2), g[2], H[3];
    assert_close(mb_road_height(road, x, y, g, H), bilinear_fn(x, y), 1e-14);
    assert_close(g[0], 0.2 + 0.05 * y, 1e-13);
    assert_close(g[1], -0.3 + 0.05 * x, 1e-13);
  }
  const mb_model *m = &tyre_cart_model;
  int found = 0;
  for (int e = 0; e < m->nforce; e++) {
    const mb_real *rd = m->force_prm + m->force[e].padr + MB_TYRE_ROAD;
    if (m->force[e].kind != MB_FORCE_TYRE || rd[0] != MB_ROAD_TABLE) continue;
    found++;
    double g[2], H[3];
    assert_int_equal((int)rd[1], 12);
    assert_int_equal((int)rd[2], 6);
    assert_close(mb_road_height(rd, 50, 1.5, g, H), 0.01 * 11 * 0.6 + 0.005, 1e-12);
    assert_close(mb_road_height(rd, 0, -1.2, g, H), 0.01 * 1 * 0.3, 1e-12);
    assert_close(mb_road_height(rd, 12.5, 0.7, g, H), 0, 0); /* under the left wheels */
  }
  assert_int_equal(found, 2);
}

/* tangent: translation and velocity columns against central differences, at
   free rolling on the flat road and with a small slip */
static void test_tangent(void **state) {
  (void)state;
  double prm[NPRM];
  tyre_prm(prm, 0);
  prm[MB_TYRE_VLOW] = 0.5;
  const double delta = 0.01, Re = R0 - delta / 3;
  for (int c = 0; c < 2; c++) {
    mb_marker m;
    wheel(&m, height_for(delta), (const double[3]){12, 0, -0.05}, 12 / Re * (c ? 1.0001 : 1));
    double tan[72], F[3], T[3], Fp[3], Tp[3], Fm[3], Tm[3];
    mb_tyre(&m, prm, F, T, 0, tan);
    const double h = 1e-7;
    for (int b = 0; b < 2; b++)
      for (int j = 0; j < 6; j++) {
        if (b == 0 && j >= 3) continue; /* rotations: documented as approximate */
        mb_marker a = m, d = m;
        double *pa = b == 0 ? a.P : (j < 3 ? a.V : a.W), *pd = b == 0 ? d.P : (j < 3 ? d.V : d.W);
        pa[j % 3] += h;
        pd[j % 3] -= h;
        mb_tyre(&a, prm, Fp, Tp, 0, 0);
        mb_tyre(&d, prm, Fm, Tm, 0, 0);
        for (int i = 0; i < 3; i++) {
          double fd = (Fp[i] - Fm[i]) / (2 * h), td = (Tp[i] - Tm[i]) / (2 * h);
          double tolF = 2e-3 * (b == 0 ? KZ : KS / 12), tolT = tolF * R0;
          assert_close(tan[36 * b + 6 * i + j], fd, tolF);
          assert_close(tan[36 * b + 6 * (3 + i) + j], td, tolT);
        }
      }
  }
}

/* the quarter car falls freely, lands, and settles at delta = load / K_z */
static void test_quarter_car(void **state) {
  (void)state;
  const mb_model *m = &tyre_quarter_model;
  mb_settings s;
  test_settings(&s, 4.0, 0.005);
  trajectory tr;
  assert_int_equal(simulate(m, &s, "ldl", &tr), 0);
  int cz = column(m, "z"), cF = column(m, "ty.Fz"), cd = column(m, "ty.deflection");
  const double z0 = 0.5013, g = 9.81, load = 340 * g;
  double t_touch = sqrt(2 * (z0 - R0) / g);
  int airborne = 0;
  for (int k = 0; k < tr.nrows; k++) {
    double t = tr.t[k];
    if (t < t_touch - 1e-3) { /* free fall: no tyre force at all */
      airborne++;
      assert_true(at(&tr, k, cF) == 0);
      assert_close(at(&tr, k, cz), z0 - 0.5 * g * t * t, 1e-8);
    }
  }
  assert_true(airborne > 30);
  int last = tr.nrows - 1;
  assert_close(at(&tr, last, cF), load, 1e-3 * load);
  assert_close(at(&tr, last, cd), load / KZ, 1e-3 * load / KZ);
  /* and the wheel centre sits at R0 - delta */
  assert_close(at(&tr, last, cz), R0 - at(&tr, last, cd), 1e-12);
  trajectory_free(&tr);
}

/* the cart at 60 km/h: the rolling resistance C_rr Fz / R_e per wheel slows
   the cart and its spinning wheels; it runs straight */
static void test_cart_straight(void **state) {
  (void)state;
  const mb_model *m = &tyre_cart_model;
  mb_settings s;
  test_settings(&s, 1.0, 0.01);
  trajectory tr;
  assert_int_equal(simulate(m, &s, "ldl", &tr), 0);
  int cv = column(m, "v.x"), cvy = column(m, "v.y"), cy = column(m, "p.y");
  const double mass = 400 + 4 * 15, Iw = 1.0, W = mass * 9.81, delta = W / 4 / KZ, Re = R0 - delta / 3,
               rho = R0 - delta;
  /* The loss rate C_rr W / R / (m + 4 I / R^2) (the wheels' spin slows down
     too) with R between the rolling radius R_e (the power C_rr Fz Omega of
     the resisting moment) and the lever rho = R0 - delta of the contact
     force about the centre (the wheel's moment balance): Gim's R_e in the
     slip and the geometric lever differ by delta / 3 */
  double lo = CRR * W / Re / (mass + 4 * Iw / (Re * Re)), hi = CRR * W / rho / (mass + 4 * Iw / (Re * rho));
  int last = tr.nrows - 1;
  double T = tr.t[last], loss = at(&tr, 0, cv) - at(&tr, last, cv);
  print_message("cart: speed loss %.5f m/s in %.2f s, rolling resistance predicts %.5f to %.5f\n", loss, T,
                lo * T, hi * T);
  assert_true(loss > 0.995 * lo * T && loss < 1.005 * hi * T);
  for (int k = 0; k < tr.nrows; k++) {
    assert_true(fabs(at(&tr, k, cy)) < 1e-9);
    assert_true(fabs(at(&tr, k, cvy)) < 1e-9);
  }
  trajectory_free(&tr);
}

/* generated eval and the generic table walk give the same numbers, at
   states near the initial one (tyres in contact, slipping) */
static void test_generated_equals_generic(void **state) {
  (void)state;
  const mb_model *models[] = {&tyre_cart_model, &tyre_quarter_model};
  for (int k = 0; k < 2; k++) {
    const mb_model *m = models[k];
    mb_model g = generic_twin(m);
    double *q = malloc(sizeof(double) * (size_t)m->nq), *v = malloc(sizeof(double) * (size_t)m->nv);
    double *Ka = calloc((size_t)m->nnz + 1, sizeof(double)), *Kb = calloc((size_t)m->nnz + 1, sizeof(double));
    double *ra = calloc((size_t)m->n + 1, sizeof(double)), *rb = calloc((size_t)m->n + 1, sizeof(double));
    double *pa = calloc((size_t)m->nc + 1, sizeof(double)), *pb = calloc((size_t)m->nc + 1, sizeof(double));
    double *na = calloc((size_t)m->nc + 1, sizeof(double)), *nb = calloc((size_t)m->nc + 1, sizeof(double));
    void *work = malloc(mb_model_worksize(m) + 16);
    double worst = 0, fmaxabs = 0;
    for (int trial = 0; trial < 5; trial++) {
      memcpy(q, m->q0, sizeof(double) * (size_t)m->nq);
      memcpy(v, m->v0, sizeof(double) * (size_t)m->nv);
      for (int b = 0; b < m->nbody; b++) q[m->body[b].qadr + 2] -= urand(0, 0.03) - 0.005;
      for (int j = 0; j < m->nv; j++) v[j] += urand(-1, 1);
      m->init(m, Ka);
      g.init(&g, Kb);
      m->eval(m, 0.1, q, v, Ka, ra, pa, na, work);
      g.eval(&g, 0.1, q, v, Kb, rb, pb, nb, work);
      for (int i = 0; i < m->nnz; i++) worst = fmax(worst, fabs(Ka[i] - Kb[i]) / (1 + fabs(Kb[i])));
      for (int i = 0; i < m->n; i++) {
        worst = fmax(worst, fabs(ra[i] - rb[i]) / (1 + fabs(rb[i])));
        fmaxabs = fmax(fmaxabs, fabs(rb[i]));
      }
      for (int i = 0; i < m->nc; i++) worst = fmax(worst, fmax(fabs(pa[i] - pb[i]), fabs(na[i] - nb[i])));
    }
    print_message("%s: generated vs generic, worst relative difference %.2e (forces up to %.0f)\n", m->name,
                  worst, fmaxabs);
    assert_true(worst < 1e-13);
    assert_true(fmaxabs > 1000); /* the tyres did push */
    free(q); free(v); free(Ka); free(Kb); free(ra); free(rb); free(pa); free(pb); free(na); free(nb);
    free(work);
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_gim_forces),   cmocka_unit_test(test_fiala_forces),
      cmocka_unit_test(test_radial),       cmocka_unit_test(test_bump),
      cmocka_unit_test(test_table_road),
      cmocka_unit_test(test_tangent),      cmocka_unit_test(test_quarter_car),
      cmocka_unit_test(test_cart_straight), cmocka_unit_test(test_generated_equals_generic),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
