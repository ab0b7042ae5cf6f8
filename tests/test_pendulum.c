/* test_pendulum.c: the pendulum against closed-form physics.
 *   - period at 90 and 5 degrees against the exact T = 4 K(k) / w0, with K
 *     from the arithmetic-geometric mean (computed here, not by the program);
 *   - energy conservation and the energy output against 1/2 I_O w^2 + m g y;
 *   - the pivot reaction: everywhere against Newton's law for the bob, and at
 *     the bottom of the swing against m (g + l w^2) with w^2 from energy;
 *   - models/virtual_fixed.yaml (the same bob carried through a massless body
 *     and a fixed joint) swings exactly like models/pendulum.yaml.
 * Physical parameters are those written in the YAML files (not read back
 * from the compiled tables): m = 1 kg, I_cm = 1e-4 kg m^2 about z, l = 1 m,
 * g = 9.81 m/s^2. */
// models: pendulum pendulum_small virtual_fixed
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "support.h"
#include "pendulum.h"
#include "pendulum_small.h"
#include "virtual_fixed.h"

#define MASS 1.0
#define ICM 1.0e-4
#define LEN 1.0
#define GRAV 9.81
#define IO (ICM + MASS * LEN * LEN) /* moment of inertia about the pivot */

/* complete elliptic integral of the first kind, K(k) = pi / (2 AGM(1, sqrt(1 - k^2))) */
static double ellip_K(double k) {
  double a = 1, b = sqrt(1 - k * k);
  for (int i = 0; i < 40 && fabs(a - b) > 1e-16 * a; i++) {
    double an = 0.5 * (a + b);
    b = sqrt(a * b);
    a = an;
  }
  return MB_PI / (a + b);
}

static double exact_period(double theta0) {
  double w0 = sqrt(MASS * GRAV * LEN / IO);
  return 4 * ellip_K(sin(theta0 / 2)) / w0;
}

static mb_settings tight(double end) {
  mb_settings s;
  test_settings(&s, end, 0.005);
  s.rtol = 1e-10;
  s.atol = 1e-12;
  return s;
}

/* angle from the bottom, counterclockwise about z, from the bob's position */
static double theta_at(const mb_model *m, const trajectory *tr, int k) {
  int cx = column(m, "bob_position.x"), cy = column(m, "bob_position.y");
  return atan2(at(tr, k, cx), -at(tr, k, cy));
}

/* Times where theta crosses zero: on each sampled sign change, the root of
 * the cubic Hermite interpolant of (theta, omega = dtheta/dt) at the two
 * samples.  Its error is O(h^4 theta''''), about 1e-10 rad here for h = 5 ms,
 * i.e. ~1e-10 s in time: far below the 1e-6 tolerance on the period. */
static int zero_crossings(const mb_model *m, const trajectory *tr, double *tc, int *kc, int max) {
  int cw = column(m, "omega");
  int n = 0;
  for (int k = 0; k + 1 < tr->nrows && n < max; k++) {
    double y0 = theta_at(m, tr, k), y1 = theta_at(m, tr, k + 1);
    if (!(y0 < 0 && y1 >= 0) && !(y0 > 0 && y1 <= 0)) continue;
    double h = tr->t[k + 1] - tr->t[k];
    double d0 = h * at(tr, k, cw), d1 = h * at(tr, k + 1, cw);
    double lo = 0, hi = 1;
    for (int it = 0; it < 100; it++) { /* bisection on the Hermite cubic */
      double s = 0.5 * (lo + hi), s2 = s * s, s3 = s2 * s;
      double p = (2 * s3 - 3 * s2 + 1) * y0 + (s3 - 2 * s2 + s) * d0 + (-2 * s3 + 3 * s2) * y1 +
                 (s3 - s2) * d1;
      if ((p < 0) == (y0 < 0)) lo = s; else hi = s;
    }
    kc[n] = k;
    tc[n++] = tr->t[k] + 0.5 * (lo + hi) * h;
  }
  return n;
}

static void check_period(const mb_model *m, double theta0) {
  mb_settings s = tight(5.0);
  trajectory tr;
  assert_int_equal(simulate(m, &s, "klu", &tr), MB_OK);
  assert_true(column(m, "omega") >= 0 && column(m, "bob_position.x") >= 0);
  double tc[16];
  int kc[16];
  int n = zero_crossings(m, &tr, tc, kc, 16);
  assert_true(n >= 4); /* T ~ 2.0 .. 2.4 s: crossings at T/4, 3T/4, ... within 5 s */
  double T = exact_period(theta0);
  /* successive crossings in the same direction are one period apart */
  double worst = 0;
  for (int i = 0; i + 2 < n; i++) worst = fmax(worst, fabs((tc[i + 2] - tc[i]) - T) / T);
  /* the first crossing is a quarter period after the release from rest */
  worst = fmax(worst, fabs(tc[0] - T / 4) / T);
  printf("  %s: theta0 = %g deg, exact T = %.12f s, max relative period error %.3g\n", m->name,
         theta0 * 180 / MB_PI, T, worst);
  /* 1e-6: DOPRI5 at rtol 1e-10 keeps the phase error ~1e-9; the interpolation
     error is ~1e-10 s.  A 1e-6 error in g, l or I_cm would show as 5e-7..1e-4. */
  assert_true(worst < 1e-6);
  /* the angle output is the rotation from the initial attitude about z */
  int ca = column(m, "angle");
  assert_true(ca >= 0);
  double ea = 0;
  for (int k = 0; k < tr.nrows; k++) ea = fmax(ea, fabs(at(&tr, k, ca) - (theta_at(m, &tr, k) - theta0)));
  printf("  %s: max |angle - (theta - theta0)| = %.3g rad\n", m->name, ea);
  /* the same state, but the angle comes from the attitude and theta from the
     position: they agree up to the constraint violation (projection 1e-10) */
  assert_true(ea < 1e-9);
  trajectory_free(&tr);
}

static void period_90(void **state) {
  (void)state;
  check_period(&pendulum_model, MB_PI / 2);
}

static void period_5(void **state) {
  (void)state;
  check_period(&pendulum_small_model, 5 * MB_PI / 180);
}

/* Energy is conserved, and the energy output is 1/2 I_O w^2 + m g y from the
 * bob's position and angular velocity. */
static void energy(void **state) {
  (void)state;
  const mb_model *m = &pendulum_model;
  mb_settings s = tight(5.0);
  trajectory tr;
  assert_int_equal(simulate(m, &s, "klu", &tr), MB_OK);
  int ce = column(m, "energy"), cy = column(m, "bob_position.y"), cw = column(m, "omega");
  assert_true(ce >= 0 && cy >= 0 && cw >= 0);
  double mgl = MASS * GRAV * LEN, E0 = at(&tr, 0, ce), drift = 0, formula = 0;
  for (int k = 0; k < tr.nrows; k++) {
    double E = at(&tr, k, ce), w = at(&tr, k, cw);
    drift = fmax(drift, fabs(E - E0) / mgl);
    formula = fmax(formula, fabs(E - (0.5 * IO * w * w + MASS * GRAV * at(&tr, k, cy))) / mgl);
  }
  printf("  energy drift max |E - E0| / mgl = %.3g, energy output vs formula %.3g\n", drift, formula);
  /* 1e-7: DOPRI5 at rtol 1e-10 over 2 periods, plus projection (phi < 1e-10) */
  assert_true(drift < 1e-7);
  /* 1e-9: the same state, two formulas: round-off and |phi| < 1e-10 only */
  assert_true(formula < 1e-9);
  assert_true(fabs(E0) < 1e-12); /* released at y = 0 from rest */
  trajectory_free(&tr);
}

/* The pivot force on the bob.  With theta from the bottom and e_r = (sin, -cos),
 * e_t = (cos, sin): m a = F + m g gives
 *   F . e_r = -m (l w^2 + g cos theta),  F . e_t = m g sin theta I_cm / I_O
 * (theta'' = -m g l sin theta / I_O).  The revolute joint could carry a force
 * along z and torques about x and y, but the motion is planar: they vanish,
 * and so does the torque about z (the hinge is free). */
static void newton_force(double th, double w, double *fx, double *fy) {
  double Fr = -MASS * (LEN * w * w + GRAV * cos(th)), Ft = MASS * GRAV * sin(th) * ICM / IO;
  *fx = Fr * sin(th) + Ft * cos(th);
  *fy = -Fr * cos(th) + Ft * sin(th);
}

static void reaction(void **state) {
  (void)state;
  const mb_model *m = &pendulum_model;
  mb_settings s = tight(2.5);
  trajectory tr;
  assert_int_equal(simulate(m, &s, "klu", &tr), MB_OK);
  int cf = column(m, "pivot_force.fx"), cw = column(m, "omega");
  assert_true(cf >= 0 && column(m, "pivot_force.fy") == cf + 1 && column(m, "pivot_force.fz") == cf + 2);
  double mg = MASS * GRAV, worst = 0, worst_z = 0;
  for (int k = 0; k < tr.nrows; k++) {
    double th = theta_at(m, &tr, k), w = at(&tr, k, cw);
    double fx, fy;
    newton_force(th, w, &fx, &fy);
    worst = fmax(worst, fmax(fabs(at(&tr, k, cf) - fx), fabs(at(&tr, k, cf + 1) - fy)) / mg);
    for (int j = 2; j < 6; j++) worst_z = fmax(worst_z, fabs(at(&tr, k, cf + j)) / mg);
  }
  /* At the bottom: |F| = m (g + l w_b^2), w_b^2 = 2 m g l (1 - cos theta0) / I_O
   * (energy).  The force magnitude is interpolated to the crossing time with
   * the cubic through the 4 samples around it: error ~h^4 |F''''| / 24 ~ 1e-7 N. */
  double tc[8];
  int kc[8];
  int n = zero_crossings(m, &tr, tc, kc, 8);
  assert_true(n >= 2);
  double wb2 = 2 * MASS * GRAV * LEN * (1 - cos(MB_PI / 2)) / IO;
  double Fb = MASS * (GRAV + LEN * wb2), worst_b = 0;
  for (int i = 0; i < n; i++) {
    int k0 = kc[i] - 1;
    assert_true(k0 >= 0 && k0 + 3 < tr.nrows);
    double F = 0;
    for (int a = 0; a < 4; a++) { /* Lagrange cubic through samples k0 .. k0+3 */
      double L = 1;
      for (int b = 0; b < 4; b++)
        if (b != a) L *= (tc[i] - tr.t[k0 + b]) / (tr.t[k0 + a] - tr.t[k0 + b]);
      double fx = at(&tr, k0 + a, cf), fy = at(&tr, k0 + a, cf + 1);
      F += L * sqrt(fx * fx + fy * fy);
    }
    worst_b = fmax(worst_b, fabs(F - Fb) / Fb);
  }
  printf("  reaction vs Newton max error / mg = %.3g, |Fz, T| / mg = %.3g, at the bottom |F| = %.9f N "
         "(closed form %.9f N), relative error %.3g\n",
         worst, worst_z, Fb * (1 + worst_b), Fb, worst_b);
  /* 1e-8 mg: the same instant's state; only the multipliers' round-off and
     the projection tolerance (1e-10) enter */
  assert_true(worst < 1e-8);
  assert_true(worst_z < 1e-10);
  /* 1e-6: the interpolation error (~1e-8 relative) plus the energy drift */
  assert_true(worst_b < 1e-6);
  trajectory_free(&tr);
}

/* The same bob through a virtual hub and a fixed joint: same angle history. */
static void virtual_hub(void **state) {
  (void)state;
  mb_settings s = tight(5.0);
  trajectory a, b;
  assert_int_equal(simulate(&pendulum_model, &s, "klu", &a), MB_OK);
  assert_int_equal(simulate(&virtual_fixed_model, &s, "klu", &b), MB_OK);
  assert_int_equal(a.nrows, b.nrows);
  int ca = column(&pendulum_model, "angle"), cb = column(&virtual_fixed_model, "angle");
  int pa = column(&pendulum_model, "bob_position.x"), pb = column(&virtual_fixed_model, "bob_position.x");
  assert_true(ca >= 0 && cb >= 0 && pa >= 0 && pb >= 0);
  double worst = 0, range = 0;
  for (int k = 0; k < a.nrows; k++) {
    worst = fmax(worst, fabs(at(&a, k, ca) - at(&b, k, cb)));
    worst = fmax(worst, fabs(at(&a, k, pa) - at(&b, k, pb)));
    range = fmax(range, fabs(at(&a, k, ca)));
  }
  /* The weld carries the whole bob: its force on the bob is the pendulum's
   * pivot force (closed form above, from pendulum's state at the same time),
   * and its torque about the weld point W (midway, 0.5 m from the pivot O)
   * is that force moved from O to W: (O - W) x F. */
  int cwf = column(&virtual_fixed_model, "weld_force.fx"), cw = column(&pendulum_model, "omega");
  assert_true(cwf >= 0 && cw >= 0 && column(&virtual_fixed_model, "weld_force.tz") == cwf + 5);
  double wf = 0;
  for (int k = 0; k < b.nrows; k++) {
    double th = theta_at(&pendulum_model, &a, k), fx, fy;
    newton_force(th, at(&a, k, cw), &fx, &fy);
    double Wx = 0.5 * sin(th), Wy = -0.5 * cos(th);
    double tz = -Wx * fy + Wy * fx;
    double e[6] = {at(&b, k, cwf) - fx, at(&b, k, cwf + 1) - fy, at(&b, k, cwf + 2),
                   at(&b, k, cwf + 3), at(&b, k, cwf + 4), at(&b, k, cwf + 5) - tz};
    for (int j = 0; j < 6; j++) wf = fmax(wf, fabs(e[j]) / (MASS * GRAV));
  }
  printf("  virtual_fixed vs pendulum: max angle/position difference %.3g (angle range %.3g rad); "
         "weld reaction vs closed form max error / mg %.3g\n", worst, range, wf);
  assert_true(wf < 1e-8); /* as for the pivot force, plus the 1e-13 state difference */
  assert_true(range > 3); /* it swings from 0 to -pi */
  /* 1e-7: two integrations of the same motion, each accurate to ~1e-9 */
  assert_true(worst < 1e-7);
  trajectory_free(&a);
  trajectory_free(&b);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(period_90), cmocka_unit_test(period_5), cmocka_unit_test(energy),
      cmocka_unit_test(reaction), cmocka_unit_test(virtual_hub),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
