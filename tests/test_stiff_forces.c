/* test_stiff_forces.c: stiffness in force elements under generalized-alpha,
 * whose iteration matrix carries the elements' tangents (the model asks for
 * genalpha, so its pattern has their coupling blocks):
 *   - a rigid link pinned to the ground carries a bob on a short stiff steel
 *     beam (4.5 kHz, overdamped by the beam's damping): the pin reaction and
 *     the energy against Dormand-Prince (before the tangents genalpha gave
 *     pin reactions of 656 N where the truth is at most 16.9 N, silently);
 *   - a heavy mass on a soft spring carrying a light mass on a stiff spring,
 *     at a fixed step ten times 1/omega of the stiff mode: the heavy mass
 *     follows the closed-form slow mode;
 *   - the same model without its tangents (a model compiled for an explicit
 *     method) at steps where the mass-only Newton cannot converge: the run
 *     stops with MB_ERR_NEWTON and the cause, and writes no rows after it;
 *   - generated and generic paths give the same trajectory;
 *   - a quarter car on a stiff tyre (2e8 N/m under a 40 kg wheel): with the
 *     tyre's tangent in the iteration matrix genalpha needs fewer Newton
 *     iterations per step than with the tangents left out, and agrees with
 *     Dormand-Prince;
 *   - the watchdog: the beam link without its tangents at a loose tolerance,
 *     where Newton's accepted iterates leave the stiff beam stretched (before
 *     the watchdog: pin reactions of 1.27e5 N and 12.6 J of energy printed as
 *     data, the truth 16.9 N and 0 J), stops with MB_ERR_ENERGY and writes no
 *     rows after it; with the tangents the same settings run to the end;
 *   - and does not stop a run whose energy comes from outside: a driver and
 *     a point force feed 850 J into a model whose own energy scale is 0. */
// models: stiff_beam_link stiff_spring_mass tyre_quarter_stiff watchdog_work
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "support.h"
#include "stiff_beam_link.h"
#include "stiff_spring_mass.h"
#include "tyre_quarter_stiff.h"
#include "watchdog_work.h"

static double pin_force(const mb_model *m, const trajectory *tr, int r) {
  int c = column(m, "pin_reaction.fx");
  assert_true(c >= 0);
  return sqrt(at(tr, r, c) * at(tr, r, c) + at(tr, r, c + 1) * at(tr, r, c + 1) +
              at(tr, r, c + 2) * at(tr, r, c + 2));
}

/* The reaction is the weight and the centripetal load of a 0.7 kg pendulum:
 * up to 16.9 N.  What separates the two methods is the truncation error of
 * the slow swing (a phase error where the reaction changes fast): against
 * DOPRI5 at rtol 1e-9 the largest difference falls from 0.87 to 0.22 to
 * 0.048 N as genalpha's rtol goes 1e-6, 1e-7, 1e-8.  At rtol 1e-8 for both,
 * 0.15 N (1% of the peak) bounds it; the silent failure this guards against
 * was 656 N.  The energy (about 2 J of swing, zero at the start) may drift
 * by genalpha's numerical dissipation on the slow swing: 1e-3 J. */
static void beam_link_against_dopri5(void **state) {
  (void)state;
  const mb_model *m = &stiff_beam_link_model;
  assert_non_null(m->force_tslot);
  mb_settings ref, ga;
  test_settings(&ref, 1.0, 0.01);
  ref.integrator = MB_DOPRI5;
  ref.rtol = 1e-8;
  ref.atol = 1e-11;
  test_settings(&ga, 1.0, 0.01);
  ga.integrator = MB_GENALPHA;
  ga.rtol = 1e-8;
  ga.atol = 1e-11;
  trajectory a, b;
  assert_int_equal(simulate(m, &ref, "ldl", &a), MB_OK);
  assert_int_equal(simulate(m, &ga, "ldl", &b), MB_OK);
  assert_int_equal(a.nrows, b.nrows);
  int ce = column(m, "energy");
  double dmax = 0, peak = 0, emax = 0;
  for (int r = 0; r < a.nrows; r++) {
    dmax = fmax(dmax, fabs(pin_force(m, &a, r) - pin_force(m, &b, r)));
    peak = fmax(peak, pin_force(m, &b, r));
    emax = fmax(emax, fabs(at(&b, r, ce)));
  }
  printf("  pin reaction: peak %.4f N, largest difference from DOPRI5 %.3e N; |energy| <= %.2e J; "
         "steps %ld (DOPRI5 %ld), Newton iterations %.2f per step\n",
         peak, dmax, emax, b.stats.steps, a.stats.steps,
         (double)b.stats.newton_iterations / (double)b.stats.steps);
  assert_true(peak > 10 && peak < 20);
  assert_true(dmax < 0.15);
  assert_true(emax < 1e-3);
  assert_true(b.stats.steps * 10 < a.stats.steps); /* the stiff beam no longer sets the step */
  trajectory_free(&a);
  trajectory_free(&b);
}

/* the slow mode of the two-mass chain in closed form: x_heavy(t) */
static double slow_mode(double t) {
  const double M = 10, mm = 0.01, k1 = 1000, k2 = 1e6, x0 = 0.1;
  double a = M * mm, b = -((k1 + k2) * mm + k2 * M), c = k1 * k2;
  double w2 = (-b - sqrt(b * b - 4 * a * c)) / (2 * a); /* the lower root */
  double phi1 = (k1 + k2 - w2 * M) / k2;               /* light / heavy */
  double coef = (M * x0 + mm * phi1 * x0) / (M + mm * phi1 * phi1);
  return coef * cos(sqrt(w2) * t);
}

static mb_settings fixed(double h) {
  mb_settings s;
  test_settings(&s, 2.0, 0.01);
  s.integrator = MB_GENALPHA;
  s.rtol = s.atol = 1e6;
  s.step = s.max_step = h;
  return s;
}

/* h = 1e-3 s against 1/omega_fast = 1e-4 s.  Generalized-alpha's phase error
 * on the slow mode (omega 10 rad/s) is about omega t (omega h)^2 / 12 of the
 * 0.1 m amplitude: 1.7e-5 m at t = 2 s; the stiff mode's share of the heavy
 * mass's motion is 1e-10 m.  Bound 5e-5 m. */
static void spring_mass_slow_mode(void **state) {
  (void)state;
  const mb_model *m = &stiff_spring_mass_model;
  mb_settings s = fixed(1e-3);
  trajectory tr;
  assert_int_equal(simulate(m, &s, "ldl", &tr), MB_OK);
  int cx = column(m, "heavy_pos.x"), ce = column(m, "energy");
  double err = 0, de = 0;
  for (int r = 0; r < tr.nrows; r++) {
    err = fmax(err, fabs(at(&tr, r, cx) - slow_mode(tr.t[r])));
    de = fmax(de, fabs(at(&tr, r, ce) - at(&tr, 0, ce)));
  }
  printf("  h = 1e-3 s (omega_fast h = 10): max |x - x_slow| = %.3e m, energy drift %.3e J of %.3g J, "
         "%.2f Newton iterations per step\n", err, de, at(&tr, 0, ce),
         (double)tr.stats.newton_iterations / (double)tr.stats.steps);
  assert_int_equal(tr.stats.newton_failures, 0);
  assert_true(err < 5e-5);
  assert_true(de < 1e-4 * at(&tr, 0, ce));
  trajectory_free(&tr);

  /* generic path: the same tangents from the same tables */
  mb_model g = generic_twin(m);
  trajectory tg, tr2;
  assert_int_equal(simulate(m, &s, "klu", &tr2), MB_OK);
  assert_int_equal(simulate(&g, &s, "klu", &tg), MB_OK);
  double d = max_rel_diff(m, &tr2, &tg, NULL);
  printf("  generated vs generic: max relative difference %.2e\n", d);
  assert_true(d < 1e-9);
  trajectory_free(&tg);
  trajectory_free(&tr2);
}

/* Without the tangents the Newton matrix has only the masses: its iteration
 * on the stiff spring contracts only for k2 beta h^2 / m below about 1,
 * h < 2e-4 s.  With steps held at or above 5e-4 s it must fail, stop with
 * the cause, and not hand back a state as a result. */
static void no_tangent_stops(void **state) {
  (void)state;
  mb_model m = stiff_spring_mass_model;
  m.force_tslot = NULL;
  m.tangent_slot = NULL;
  mb_settings s;
  test_settings(&s, 0.5, 0.01);
  s.integrator = MB_GENALPHA;
  s.step = 1e-3;
  s.max_step = 1e-3;
  s.min_step = 5e-4;
  trajectory tr;
  int st = simulate(&m, &s, "ldl", &tr);
  printf("  without tangents, min_step 5e-4 s: status %d (%s) at t = %g, %d rows\n", st,
         mb_status_text(st), tr.fail_time, tr.nrows);
  assert_int_equal(st, MB_ERR_NEWTON);
  assert_true(tr.nrows <= 1); /* only the initial row */
  trajectory_free(&tr);
}

/* The stiff tyre (omega 2236 rad/s, damping ratio 0.34) under the 1.3 Hz
 * body mode.  Left out of the iteration matrix, the tyre's stiffness makes the
 * mass-only modified Newton contract slowly (it diverges for
 * K_z beta h^2 (1 - af) / ((1 - am) m) above 1: h > 0.9 ms), so the steps stay
 * small and each takes more iterations.  With its tangent, Newton converges in
 * about two iterations at steps set by the body mode.  Against DOPRI5 (rtol
 * 1e-10) at the same rtol 1e-8: the body's travel is 0.15 m and genalpha's
 * error is its truncation error on the 8 rad/s mode, which the step control
 * keeps at about rtol times the 0.7 m coordinate per step, over some hundred
 * steps: 1e-5 m bounds it (7e-5 of the travel); the tyre load follows the
 * body's acceleration (peak 4387 N): 1 N, and the energy, 2249 J at the start
 * (genalpha's numerical dissipation on the body mode is tiny, the stiff mode
 * is damped by the tyre's own damping): 1e-2 J. */
static void stiff_tyre_tangent(void **state) {
  (void)state;
  const mb_model *m = &tyre_quarter_stiff_model;
  assert_non_null(m->force_tslot);
  assert_true(m->force_tslot[1] >= 0); /* the tyre has its block */
  mb_settings ref, ga;
  test_settings(&ref, 2.0, 0.01);
  ref.integrator = MB_DOPRI5;
  ref.rtol = 1e-10;
  ref.atol = 1e-13;
  test_settings(&ga, 2.0, 0.01);
  ga.integrator = MB_GENALPHA;
  ga.rtol = 1e-8;
  ga.atol = 1e-11;
  mb_model bare = *m; /* the same model without the force tangents */
  bare.force_tslot = NULL;
  bare.tangent_slot = NULL;
  trajectory a, b, c;
  assert_int_equal(simulate(m, &ref, "ldl", &a), MB_OK);
  assert_int_equal(simulate(m, &ga, "ldl", &b), MB_OK);
  assert_int_equal(simulate(&bare, &ga, "ldl", &c), MB_OK);
  assert_int_equal(a.nrows, b.nrows);
  int cz = column(m, "z"), cf = column(m, "ty.Fz"), ce = column(m, "energy");
  double dz = 0, df = 0, de = 0, dz_bare = 0;
  for (int r = 0; r < a.nrows; r++) {
    dz = fmax(dz, fabs(at(&a, r, cz) - at(&b, r, cz)));
    df = fmax(df, fabs(at(&a, r, cf) - at(&b, r, cf)));
    de = fmax(de, fabs(at(&a, r, ce) - at(&b, r, ce)));
    dz_bare = fmax(dz_bare, fabs(at(&a, r, cz) - at(&c, r, cz)));
  }
  double it_with = (double)b.stats.newton_iterations / (double)b.stats.steps;
  double it_without = (double)c.stats.newton_iterations / (double)c.stats.steps;
  printf("  stiff tyre: with its tangent %ld steps, %.2f Newton iterations per step (%ld in all); "
         "without: %ld steps, %.2f per step (%ld in all); DOPRI5 %ld steps\n",
         b.stats.steps, it_with, b.stats.newton_iterations, c.stats.steps, it_without,
         c.stats.newton_iterations, a.stats.steps);
  printf("  against DOPRI5: body z %.2e m, tyre load %.2e N, energy %.2e J (without the tangent: "
         "z %.2e m)\n", dz, df, de, dz_bare);
  assert_true(it_with < it_without);
  assert_true(b.stats.newton_iterations < c.stats.newton_iterations);
  assert_true(dz < 1e-5);
  assert_true(df < 1.0);
  assert_true(de < 1e-2);
  trajectory_free(&a);
  trajectory_free(&b);
  trajectory_free(&c);

  /* auto weighs the tyre: its radial rate (Kz, Cz on the wheel) sqrt(2e8 / 40)
     with the damping: 3108 1/s, a DOPRI5 step of 3.3 / 3108 = 1.06 ms; an
     output step of 0.1 s (a tenth: 10 ms) makes that stiff */
  char why[320];
  ga.output_step = ga.max_step = 0.1;
  assert_int_equal(mb_integrator_auto(m, &ga, why, sizeof why), MB_GENALPHA);
  assert_non_null(strstr(why, "tyre"));
}

/* The energy of the passive beam link (no driver, no applied load) cannot
 * rise; the watchdog allows the model's energy scale (the 0.7 kg at 9.81 m/s^2
 * over the 0.4 m it reaches: 2.75 J) and stops beyond it.  Without the
 * tangents at rtol 1e-2 the beam blows up within the first millisecond. */
static void watchdog_stops_blowup(void **state) {
  (void)state;
  mb_model m = stiff_beam_link_model;
  mb_settings s;
  test_settings(&s, 1.0, 0.01);
  s.integrator = MB_GENALPHA;
  s.rtol = 1e-2;
  s.atol = 1e-4;
  trajectory ok;
  assert_int_equal(simulate(&m, &s, "ldl", &ok), MB_OK); /* with the tangents */
  int ce = column(&m, "energy");
  double peak = 0, emax = 0;
  for (int r = 0; r < ok.nrows; r++) {
    peak = fmax(peak, pin_force(&m, &ok, r));
    emax = fmax(emax, fabs(at(&ok, r, ce)));
  }
  m.force_tslot = NULL;
  m.tangent_slot = NULL;
  trajectory tr;
  int st = simulate(&m, &s, "ldl", &tr);
  printf("  watchdog: with the tangents at rtol 1e-2 peak pin reaction %.3g N, |energy| <= %.3g J; "
         "without them status %d (%s) at t = %g s, %d rows\n", peak, emax, st, mb_status_text(st),
         tr.fail_time, tr.nrows);
  assert_true(peak < 25 && emax < 0.5);
  assert_int_equal(st, MB_ERR_ENERGY);
  assert_true(tr.fail_time > 0 && tr.fail_time < 1);
  assert_true(tr.nrows <= 1 + (int)(tr.fail_time / 0.01)); /* no row after the failure */
  for (int r = 0; r < tr.nrows; r++) assert_true(fabs(at(&tr, r, ce)) < 2.75);
  trajectory_free(&ok);
  trajectory_free(&tr);
}

/* watchdog_work.yaml: kinetic energy 800 t^2 (flywheel, omega = 40 t about
 * its 1 kg m^2 axis) + 50 t^2 (puck, v = 10 t); the run starts at rest
 * without gravity, so only the counted work of the driver and the force lets
 * it through.  genalpha on this quadratic motion is exact up to the
 * Newton tolerance: 1e-6 of the 850 J. */
static void watchdog_counts_work(void **state) {
  (void)state;
  const mb_model *m = &watchdog_work_model;
  mb_settings s;
  test_settings(&s, 1.0, 0.01);
  s.integrator = MB_GENALPHA;
  trajectory tr;
  assert_int_equal(simulate(m, &s, "ldl", &tr), MB_OK);
  int ce = column(m, "energy");
  for (int r = 0; r < tr.nrows; r++) assert_close(at(&tr, r, ce), 850 * tr.t[r] * tr.t[r], 850e-6);
  assert_close(tr.t[tr.nrows - 1], 1, 1e-12);
  trajectory_free(&tr);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(beam_link_against_dopri5),
      cmocka_unit_test(spring_mass_slow_mode),
      cmocka_unit_test(no_tangent_stops),
      cmocka_unit_test(stiff_tyre_tangent),
      cmocka_unit_test(watchdog_stops_blowup),
      cmocka_unit_test(watchdog_counts_work),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
