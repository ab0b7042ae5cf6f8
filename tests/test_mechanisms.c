/* test_mechanisms.c: the driven mechanisms against their closed-form kinematics
 * and, for the slider-crank, the driver torque against the energy balance.
 * Geometry as written in the YAML files:
 *   slider_crank: crank r = 0.1524 m at 124.8 rad/s, rod L = 0.3048 m,
 *                 rod mass 0.07532161536 kg, I_cm 5.83117e-4 kg m^2, massless
 *                 slider, no gravity;
 *   four_bar:     ground pivots O = (0, 0), D = (0.3, 0); crank 0.1 m at
 *                 2 pi rad/s, coupler 0.3 m, rocker 0.25 m; the coupler point
 *                 is the rocker pin C. */
// models: four_bar slider_crank
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "support.h"
#include "four_bar.h"
#include "slider_crank.h"

#define SC_R 0.1524
#define SC_L 0.3048
#define SC_W 124.8
#define ROD_M 0.07532161536
#define ROD_I 5.83117e-4

static mb_settings settings_for(double end, double out_step) {
  mb_settings s;
  test_settings(&s, end, out_step);
  s.rtol = 1e-10;
  s.atol = 1e-12;
  return s;
}

/* slider_x = r cos th + sqrt(L^2 - r^2 sin^2 th), rod angle = -asin(r sin th / L) */
static void slider_crank_positions(void **state) {
  (void)state;
  const mb_model *m = &slider_crank_model;
  mb_settings s = settings_for(0.1, 2e-4);
  trajectory tr;
  assert_int_equal(simulate(m, &s, "klu", &tr), MB_OK);
  int cx = column(m, "slider_x"), cr = column(m, "rod_angle"), cc = column(m, "crank_angle");
  int cv = column(m, "slider_v");
  assert_true(cx >= 0 && cr >= 0 && cc >= 0 && cv >= 0);
  assert_int_equal(tr.nrows, 501);
  double ex = 0, er = 0, ec = 0, ev = 0;
  for (int k = 0; k < tr.nrows; k++) {
    double th = SC_W * tr.t[k], sn = sin(th), cs = cos(th);
    double root = sqrt(SC_L * SC_L - SC_R * SC_R * sn * sn);
    double x = SC_R * cs + root;
    double xd = -SC_R * SC_W * sn - SC_R * SC_R * SC_W * sn * cs / root;
    ex = fmax(ex, fabs(at(&tr, k, cx) - x));
    ev = fmax(ev, fabs(at(&tr, k, cv) - xd));
    er = fmax(er, fabs(at(&tr, k, cr) - (-asin(SC_R * sn / SC_L))));
    ec = fmax(ec, fabs(at(&tr, k, cc) - th)); /* unwrapped crank angle */
  }
  printf("  slider_crank: max |slider_x error| %.3g m, |slider_v error| %.3g m/s, "
         "|rod_angle error| %.3g rad, |crank_angle error| %.3g rad\n", ex, ev, er, ec);
  /* The driven mechanism has no free coordinate: positions come from the
     driver constraint and the projection (|phi| < 1e-10), so 1e-8 m / 1e-8 rad
     leave a wide margin while a wrong geometry (even 1e-6 m) fails. */
  assert_true(ex < 1e-8);
  assert_true(er < 1e-8);
  assert_true(ec < 1e-8);
  /* velocities: projected onto the velocity constraints; |xd| peaks ~20 m/s */
  assert_true(ev < 1e-7);
  trajectory_free(&tr);
}

/* Kinetic energy of the slider-crank as a function of the crank angle (the
 * crank turns at constant speed, so its own energy is constant and drops out;
 * the slider is massless): the rod's centre G = (B + P) / 2. */
static double rod_kinetic(double th) {
  double sn = sin(th), cs = cos(th);
  double root = sqrt(SC_L * SC_L - SC_R * SC_R * sn * sn);
  double xd = -SC_R * SC_W * sn - SC_R * SC_R * SC_W * sn * cs / root; /* slider velocity */
  double vBx = -SC_R * SC_W * sn, vBy = SC_R * SC_W * cs;               /* crank pin */
  double vGx = 0.5 * (vBx + xd), vGy = 0.5 * vBy;
  /* rod angle beta = -asin(r sin th / L): beta' = -r w cos th / (L cos beta) */
  double wr = -SC_R * SC_W * cs / root;
  return 0.5 * ROD_M * (vGx * vGx + vGy * vGy) + 0.5 * ROD_I * wr * wr;
}

/* Energy balance: with no gravity and no dissipation the driver's power is
 * the rate of change of kinetic energy, torque * w = dT/dt = w dT/dth, so
 * torque(th) = dT/dth of the closed-form T (5-point central difference,
 * truncation ~h^4 T^(5)/30 ~ 1e-13 relative for h = 1e-3 rad). */
static void slider_crank_torque(void **state) {
  (void)state;
  const mb_model *m = &slider_crank_model;
  mb_settings s = settings_for(0.1, 2e-4);
  trajectory tr;
  assert_int_equal(simulate(m, &s, "klu", &tr), MB_OK);
  int ct = column(m, "crank_torque");
  assert_true(ct >= 0);
  double peak = 0, err = 0;
  const double h = 1e-3;
  for (int k = 0; k < tr.nrows; k++) {
    double th = SC_W * tr.t[k];
    double dT = (-rod_kinetic(th + 2 * h) + 8 * rod_kinetic(th + h) - 8 * rod_kinetic(th - h) +
                 rod_kinetic(th - 2 * h)) / (12 * h);
    peak = fmax(peak, fabs(dT));
    err = fmax(err, fabs(at(&tr, k, ct) - dT));
  }
  trajectory_free(&tr);
  /* No dissipation: the driver's work over one revolution vanishes.  Sampled
     at 256 equal steps over exactly one revolution, the mean of the smooth
     periodic power torque * w is the periodic trapezoid rule: spectrally
     accurate, so the mean is round-off unless energy is lost or gained. */
  const int nsamp = 256;
  double rev = 2 * MB_PI / SC_W;
  mb_settings s1 = settings_for(rev, rev / nsamp);
  assert_int_equal(simulate(m, &s1, "klu", &tr), MB_OK);
  assert_int_equal(tr.nrows, nsamp + 1);
  double mean = 0, ppeak = 0;
  for (int k = 0; k < nsamp; k++) {
    double P = at(&tr, k, ct) * SC_W;
    mean += P / nsamp;
    ppeak = fmax(ppeak, fabs(P));
  }
  printf("  slider_crank: peak torque %.6g N m, max |torque - dT/dth| = %.3g N m (%.3g of the peak), "
         "mean power over a revolution %.3g of the peak\n", peak, err, err / peak, mean / ppeak);
  assert_true(peak > 1); /* the rod's inertia loads the crank: ~13 N m */
  /* 1e-6 of the peak: the torque is a Lagrange multiplier of the same solve as
     the accelerations; errors enter through the state (~1e-10) only */
  assert_true(err < 1e-6 * peak);
  assert_true(fabs(mean) < 1e-6 * ppeak);
  trajectory_free(&tr);
}

/* Four-bar: C is the intersection of the circle of radius 0.3 about the crank
 * pin B and the circle of radius 0.25 about D, on the branch of the initial
 * assembly (C above the line BD: a crank-rocker never changes branch). */
static void four_bar_C(double phi, double C[2]) {
  const double a = 0.1, b = 0.3, c = 0.25, Dx = 0.3;
  double Bx = a * cos(phi), By = a * sin(phi);
  double dx = Dx - Bx, dy = -By, d = sqrt(dx * dx + dy * dy);
  double p = (b * b - c * c + d * d) / (2 * d); /* from B along BD */
  double hh = sqrt(b * b - p * p);
  double ux = dx / d, uy = dy / d;
  /* left of B -> D: (-uy, ux) */
  C[0] = Bx + p * ux - hh * uy;
  C[1] = By + p * uy + hh * ux;
}

static void four_bar_positions(void **state) {
  (void)state;
  const mb_model *m = &four_bar_model;
  mb_settings s = settings_for(2.0, 0.005);
  trajectory tr;
  assert_int_equal(simulate(m, &s, "klu", &tr), MB_OK);
  int cr = column(m, "rocker_angle"), cp = column(m, "coupler_point.x"), cc = column(m, "crank_angle");
  assert_true(cr >= 0 && cp >= 0 && cc >= 0);
  double C0[2];
  four_bar_C(0, C0);
  /* the initial assembly of the YAML file */
  assert_true(fabs(C0[0] - 0.26875) < 1e-12 && fabs(C0[1] - 0.24803918541230538) < 1e-12);
  double psi0 = atan2(C0[1], C0[0] - 0.3);
  double er = 0, ep = 0, ec = 0, rmin = 1e9, rmax = -1e9;
  for (int k = 0; k < tr.nrows; k++) {
    double phi = 2 * MB_PI * tr.t[k], C[2];
    four_bar_C(phi, C);
    double psi = atan2(C[1], C[0] - 0.3) - psi0; /* the rocker stays above D: no wrap */
    er = fmax(er, fabs(at(&tr, k, cr) - psi));
    ep = fmax(ep, fmax(fabs(at(&tr, k, cp) - C[0]), fabs(at(&tr, k, cp + 1) - C[1])));
    ep = fmax(ep, fabs(at(&tr, k, cp + 2)));
    ec = fmax(ec, fabs(at(&tr, k, cc) - phi));
    rmin = fmin(rmin, psi);
    rmax = fmax(rmax, psi);
  }
  printf("  four_bar: max |rocker_angle error| %.3g rad, |coupler point error| %.3g m, "
         "|crank_angle error| %.3g rad; rocker swing %.4f rad\n", er, ep, ec, rmax - rmin);
  assert_true(rmax - rmin > 0.5); /* the rocker does rock */
  /* 1e-8: driven, no free coordinate; see slider_crank_positions */
  assert_true(er < 1e-8);
  assert_true(ep < 1e-8);
  assert_true(ec < 1e-8);
  trajectory_free(&tr);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(slider_crank_positions),
      cmocka_unit_test(slider_crank_torque),
      cmocka_unit_test(four_bar_positions),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
