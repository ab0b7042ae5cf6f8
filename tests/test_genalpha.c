/* test_genalpha.c: the implicit generalized-alpha integrator (runtime/hosted/genalpha.c).
 *   - second-order convergence: fixed steps h, h/2, h/4 on the pendulum at
 *     90 degrees against a DOPRI5 solution at rtol 1e-11 (itself checked
 *     against the exact elliptic period in test_pendulum.c);
 *   - rho_inf = 1 (no numerical dissipation) keeps the energy of the undamped
 *     flexible beam at steps 29 times its highest mode's 1/omega;
 *   - stiff modal content (modes to 9.7 kHz): genalpha meets the accuracy of
 *     the explicit reference with a fraction of its steps;
 *   - integrator auto: genalpha for the stiff beam, dopri5 for the pendulum;
 *   - generated and generic paths give the same trajectory with genalpha. */
// models: pendulum hinged_flexible_stiff hinged_flexible
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "support.h"
#include "hinged_flexible.h"
#include "hinged_flexible_stiff.h"
#include "pendulum.h"

/* fixed steps h: every step is accepted (rtol huge) and no longer than h */
static mb_settings fixed_steps(double end, double out, double h) {
  mb_settings s;
  test_settings(&s, end, out);
  s.integrator = MB_GENALPHA;
  s.rtol = 1e6;
  s.atol = 1e6;
  s.step = h;
  s.max_step = h;
  return s;
}

static void second_order(void **state) {
  (void)state;
  const mb_model *m = &pendulum_model;
  mb_settings ref;
  test_settings(&ref, 1.0, 0.02);
  ref.rtol = 1e-11;
  ref.atol = 1e-13;
  trajectory tr_ref;
  assert_int_equal(simulate(m, &ref, "klu", &tr_ref), MB_OK);
  int cx = column(m, "bob_position.x");
  assert_true(cx >= 0);
  double err[3];
  for (int k = 0; k < 3; k++) {
    double h = 0.004 / (1 << k);
    mb_settings s = fixed_steps(1.0, 0.02, h);
    trajectory tr;
    assert_int_equal(simulate(m, &s, "klu", &tr), MB_OK);
    assert_int_equal(tr.nrows, tr_ref.nrows);
    assert_int_equal(tr.stats.rejected, 0);
    err[k] = 0;
    for (int r = 0; r < tr.nrows; r++) err[k] = fmax(err[k], fabs(at(&tr, r, cx) - at(&tr_ref, r, cx)));
    printf("  h = %.5f s: max |x - x_ref| = %.3e m (%ld steps, %.2f Newton iterations per step)\n", h,
           err[k], tr.stats.steps, (double)tr.stats.newton_iterations / (double)tr.stats.steps);
    trajectory_free(&tr);
  }
  double p1 = log2(err[0] / err[1]), p2 = log2(err[1] / err[2]);
  printf("  observed order %.3f, %.3f (generalized-alpha is second order)\n", p1, p2);
  assert_true(p1 > 1.8 && p1 < 2.3);
  assert_true(p2 > 1.8 && p2 < 2.3);
  trajectory_free(&tr_ref);
}

/* Energy of the undamped hinged beam (a conservative system) over 0.2 s at a
 * step far above its highest mode's period (930 Hz: omega h = 29 at h = 5 ms):
 * rho_inf = 1 is the non-dissipative trapezoidal rule; it must stay stable
 * and keep the energy to its O(h^2) error. */
static void energy_rho_one(void **state) {
  (void)state;
  const mb_model *m = &hinged_flexible_model;
  int ce = column(m, "energy");
  assert_true(ce >= 0);
  mb_settings s = fixed_steps(0.2, 0.005, 0.005);
  s.rho_inf = 1;
  trajectory tr;
  assert_int_equal(simulate(m, &s, "klu", &tr), MB_OK);
  /* energy scale: the potential energy released, m g L / 2 = 0.54 kg * 9.81 * 0.5 */
  double scale = 0.54 * 9.81 * 0.5, drift = 0;
  for (int r = 0; r < tr.nrows; r++) drift = fmax(drift, fabs(at(&tr, r, ce) - at(&tr, 0, ce)) / scale);
  printf("  rho_inf = 1: max |E - E0| / (m g L/2) = %.3e over %ld steps of 5 ms\n", drift, tr.stats.steps);
  assert_true(drift < 1e-3);
  trajectory_free(&tr);
}

static void stiff_modes(void **state) {
  (void)state;
  const mb_model *m = &hinged_flexible_stiff_model;
  mb_settings ref;
  test_settings(&ref, 0.05, 0.005);
  ref.rtol = 1e-8;
  ref.atol = 1e-10;
  trajectory tr_ref, tr;
  assert_int_equal(simulate(m, &ref, "klu", &tr_ref), MB_OK);
  mb_settings s = ref;
  s.integrator = MB_GENALPHA;
  s.rtol = 1e-6;
  s.atol = 1e-8;
  assert_int_equal(simulate(m, &s, "klu", &tr), MB_OK);
  const char *worst;
  /* tip position only: the energy column is compared to its own tiny range */
  int cy = column(m, "tip.y");
  assert_true(cy >= 0);
  double range = 0, err = 0;
  for (int r = 0; r < tr.nrows; r++) {
    range = fmax(range, fabs(at(&tr_ref, r, cy) - at(&tr_ref, 0, cy)));
    err = fmax(err, fabs(at(&tr, r, cy) - at(&tr_ref, r, cy)));
  }
  double all = max_rel_diff(m, &tr_ref, &tr, &worst);
  printf("  modes to 9.7 kHz, 0.05 s: dopri5 rtol 1e-8: %ld steps; genalpha rtol 1e-6: %ld steps\n",
         tr_ref.stats.steps, tr.stats.steps);
  printf("  tip.y error %.3e of its range %.3e m; all columns %.3e (worst %s)\n", err / range, range,
         all, worst);
  assert_true(err / range < 1e-3);
  /* the explicit method is held to about 3.3 / omega_max = 5.4e-5 s by stability */
  assert_true(tr_ref.stats.steps > 900);
  assert_true(tr.stats.steps * 5 < tr_ref.stats.steps);
  trajectory_free(&tr);
  trajectory_free(&tr_ref);
}

static void auto_choice(void **state) {
  (void)state;
  mb_settings s;
  test_settings(&s, 0.2, 0.005);
  char why[320];
  assert_int_equal(mb_integrator_auto(&hinged_flexible_stiff_model, &s, why, sizeof why), MB_GENALPHA);
  printf("  stiff beam: %s\n", why);
  assert_non_null(strstr(why, "beam"));
  assert_int_equal(mb_integrator_auto(&pendulum_model, &s, why, sizeof why), MB_DOPRI5);
  printf("  pendulum: %s\n", why);
  /* the 930 Hz beam: 3.3 / (2 pi 930 Hz) = 5.6e-4 s, above a tenth of a 5 ms
     output step (explicit), below a tenth of a 20 ms one (implicit) */
  assert_int_equal(mb_integrator_auto(&hinged_flexible_model, &s, why, sizeof why), MB_DOPRI5);
  s.output_step = s.max_step = 0.02;
  assert_int_equal(mb_integrator_auto(&hinged_flexible_model, &s, why, sizeof why), MB_GENALPHA);
  printf("  hinged beam at output step 0.02: %s\n", why);
}

static void generic_same(void **state) {
  (void)state;
  const mb_model *m = &hinged_flexible_model;
  mb_model g = generic_twin(m);
  mb_settings s;
  test_settings(&s, 0.02, 0.005);
  s.integrator = MB_GENALPHA;
  s.rtol = 1e-6;
  trajectory a, b;
  assert_int_equal(simulate(m, &s, "klu", &a), MB_OK);
  assert_int_equal(simulate(&g, &s, "klu", &b), MB_OK);
  double d = max_rel_diff(m, &a, &b, NULL);
  printf("  generated vs generic with genalpha: %.3e (steps %ld, %ld)\n", d, a.stats.steps, b.stats.steps);
  assert_int_equal(a.stats.steps, b.stats.steps);
  assert_true(d < 1e-12);
  trajectory_free(&a);
  trajectory_free(&b);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(second_order), cmocka_unit_test(energy_rho_one),
      cmocka_unit_test(stiff_modes), cmocka_unit_test(auto_choice),
      cmocka_unit_test(generic_same),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
