/* test_solvers.c: the interchangeable parts of the runtime must agree:
 *   - KLU and dense LU give the same trajectories to round-off;
 *   - the generated code and the generic (table-walking) path give the same
 *     trajectories;
 *   - RK4 (fixed step) agrees with DOPRI5 (adaptive);
 * and the conservative models conserve energy. */
// models: spatial_joints slider_crank double_pendulum pendulum
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "support.h"
#include "double_pendulum.h"
#include "pendulum.h"
#include "slider_crank.h"
#include "spatial_joints.h"

/* the models' own simulation settings (as in their YAML files) */
static mb_settings model_settings(const mb_model *m) {
  mb_settings s;
  if (m == &spatial_joints_model) { test_settings(&s, 2.0, 0.01); s.rtol = 1e-10; s.atol = 1e-12; }
  else if (m == &slider_crank_model) { test_settings(&s, 0.1, 2e-4); s.rtol = 1e-9; s.atol = 1e-11; }
  else if (m == &double_pendulum_model) { test_settings(&s, 3.0, 0.01); s.rtol = 1e-10; s.atol = 1e-12; }
  else { test_settings(&s, 5.0, 0.005); s.rtol = 1e-10; s.atol = 1e-12; }
  return s;
}

/* KLU and dense: the same K, factored by two codes; every difference is
 * round-off (~1e-16) carried through the integration (error-controlled
 * steps react smoothly to it).  1e-9 of the range leaves room for its growth
 * over the run, also in the chaotic double pendulum (3 s). */
static void klu_vs_dense(void **state) {
  (void)state;
  const mb_model *models[] = {&spatial_joints_model, &slider_crank_model, &double_pendulum_model};
  for (int i = 0; i < 3; i++) {
    const mb_model *m = models[i];
    mb_settings s = model_settings(m);
    trajectory a, b;
    assert_int_equal(simulate(m, &s, "klu", &a), MB_OK);
    assert_int_equal(simulate(m, &s, "dense", &b), MB_OK);
    const char *wc;
    double d = max_rel_diff(m, &a, &b, &wc);
    printf("  %s: klu vs dense: max relative difference %.3g (%s)\n", m->name, d, wc);
    assert_true(d < 1e-9);
    trajectory_free(&a);
    trajectory_free(&b);
  }
}

/* Generated code against the generic path: the same kernels with the same
 * tables, their compile-time zeros and ones folded; the dot-1 rows between two
 * bodies' own axes are written from the relative rotation A0^T A1 (identities
 * exact for orthonormal A, compiler/back/emit_rows.c).  So the two differ by
 * round-off only, as KLU and dense LU do: 1e-9 of the range, as above (energy,
 * nearly constant, has the smallest range). */
static void generated_vs_generic(void **state) {
  (void)state;
  const mb_model *models[] = {&spatial_joints_model, &slider_crank_model, &double_pendulum_model};
  for (int i = 0; i < 3; i++) {
    const mb_model *m = models[i];
    mb_model g = generic_twin(m);
    mb_settings s = model_settings(m);
    trajectory a, b;
    assert_int_equal(simulate(m, &s, "klu", &a), MB_OK);
    assert_int_equal(simulate(&g, &s, "klu", &b), MB_OK);
    const char *wc;
    double d = max_rel_diff(m, &a, &b, &wc);
    printf("  %s: generated vs generic: max relative difference %.3g (%s)\n", m->name, d, wc);
    assert_true(d < 1e-9);
    trajectory_free(&a);
    trajectory_free(&b);
  }
}

/* Energy conservation, relative to the largest kinetic energy of the run (the
 * scale of the motion; the zero of the potential is arbitrary). */
static double energy_drift(const mb_model *m, const mb_settings *s, double kinetic_scale_hint,
                           double *scale_out) {
  trajectory tr;
  assert_int_equal(simulate(m, s, "klu", &tr), MB_OK);
  int ce = column(m, "energy"), ck = column(m, "kinetic");
  assert_true(ce >= 0);
  double E0 = at(&tr, 0, ce), drift = 0, scale = kinetic_scale_hint;
  for (int k = 0; k < tr.nrows; k++) {
    drift = fmax(drift, fabs(at(&tr, k, ce) - E0));
    if (ck >= 0) scale = fmax(scale, at(&tr, k, ck));
  }
  trajectory_free(&tr);
  *scale_out = scale;
  return drift / scale;
}

static void spatial_energy(void **state) {
  (void)state;
  mb_settings s = model_settings(&spatial_joints_model);
  double scale;
  double d = energy_drift(&spatial_joints_model, &s, 0, &scale);
  printf("  spatial_joints: max |E - E0| = %.3g of the largest kinetic energy (%.4g J)\n", d, scale);
  assert_true(scale > 1); /* it does move */
  /* 1e-6: DOPRI5 at rtol 1e-10 with projection (|phi| < 1e-10) over 2 s;
     no dissipation in the model (springs and a bushing without damping) */
  assert_true(d < 1e-6);
}

/* Double pendulum of two uniform rods (m = 1 kg, L = 0.5 m) released from the
 * horizontal: E0 = 0; the scale is m g L (one rod dropping by its length:
 * 4.905 J; the largest kinetic energy is a few times that). */
static void double_pendulum_energy(void **state) {
  (void)state;
  mb_settings s = model_settings(&double_pendulum_model);
  trajectory tr;
  assert_int_equal(simulate(&double_pendulum_model, &s, "klu", &tr), MB_OK);
  int ce = column(&double_pendulum_model, "energy");
  assert_true(ce >= 0);
  double scale = 1.0 * 9.81 * 0.5, drift = 0;
  for (int k = 0; k < tr.nrows; k++) drift = fmax(drift, fabs(at(&tr, k, ce) - at(&tr, 0, ce)));
  printf("  double_pendulum: max |E - E0| / (m g L) = %.3g (E0 = %.3g J)\n", drift / scale,
         at(&tr, 0, ce));
  assert_true(fabs(at(&tr, 0, ce)) < 1e-12);
  /* 1e-7: DOPRI5 at rtol 1e-10 over 3 s of chaotic motion with projection */
  assert_true(drift / scale < 1e-7);
  trajectory_free(&tr);
}

/* RK4 at a fixed step of 1e-4 s on the 90-degree pendulum: global error
 * ~(w0 h)^4 ~ 1e-14 per radian of phase: it must match DOPRI5 (rtol 1e-10)
 * to 1e-8 rad and conserve energy to 1e-9 m g l. */
static void rk4_pendulum(void **state) {
  (void)state;
  const mb_model *m = &pendulum_model;
  mb_settings s = model_settings(m);
  trajectory a, b;
  assert_int_equal(simulate(m, &s, "klu", &a), MB_OK);
  s.integrator = MB_RK4;
  s.step = 1e-4;
  assert_int_equal(simulate(m, &s, "klu", &b), MB_OK);
  assert_int_equal(a.nrows, b.nrows);
  int ca = column(m, "angle"), ce = column(m, "energy");
  assert_true(ca >= 0 && ce >= 0);
  double da = 0, de = 0;
  for (int k = 0; k < a.nrows; k++) {
    da = fmax(da, fabs(at(&a, k, ca) - at(&b, k, ca)));
    de = fmax(de, fabs(at(&b, k, ce) - at(&b, 0, ce)) / 9.81);
  }
  printf("  pendulum: rk4 (1e-4 s) vs dopri5: max angle difference %.3g rad, rk4 energy drift %.3g m g l "
         "(%ld steps)\n", da, de, b.stats.steps);
  assert_true(b.stats.steps >= 50000); /* it did take fixed 1e-4 s steps */
  assert_true(da < 1e-8);
  assert_true(de < 1e-9);
  trajectory_free(&a);
  trajectory_free(&b);
}

/* RK4 at 1e-5 s on the slider-crank (crank at 124.8 rad/s: w h ~ 1.2e-3,
 * error ~(w h)^4 ~ 2e-12 per radian) against DOPRI5: every column to 1e-6 of
 * its range. */
static void rk4_slider_crank(void **state) {
  (void)state;
  const mb_model *m = &slider_crank_model;
  mb_settings s = model_settings(m);
  trajectory a, b;
  assert_int_equal(simulate(m, &s, "klu", &a), MB_OK);
  s.integrator = MB_RK4;
  s.step = 1e-5;
  assert_int_equal(simulate(m, &s, "klu", &b), MB_OK);
  const char *wc;
  double d = max_rel_diff(m, &a, &b, &wc);
  printf("  slider_crank: rk4 (1e-5 s) vs dopri5: max relative difference %.3g (%s), %ld steps\n", d,
         wc, b.stats.steps);
  assert_true(b.stats.steps >= 10000);
  assert_true(d < 1e-6);
  trajectory_free(&a);
  trajectory_free(&b);
}

/* A NaN in the state reaches the solution of the first solve (the velocity
 * projection's right side is -nu(q, v)); every solver's run must stop there
 * with MB_ERR_NONFINITE at t = 0, never return the NaN as data.  The emitted
 * LDL^T tests its own result (checks_finite: the integrator then skips its
 * test), KLU and dense LU are tested by the integrator. */
static void nonfinite_reported(void **state) {
  (void)state;
  const char *solvers[] = {"ldl", "klu", "dense"};
  for (int i = 0; i < 3; i++) {
    const mb_model *m = &slider_crank_model;
    mb_settings s = model_settings(m);
    mb_solver *ls = mb_solver_new(solvers[i], m);
    assert_non_null(ls);
    assert_int_equal(ls->checks_finite, !strcmp(solvers[i], "ldl"));
    mb_sim sim;
    assert_int_equal(mb_sim_init(&sim, m, ls, &s), MB_OK);
    sim.v[m->nv - 1] = NAN;
    int st = mb_sim_run(&sim, NULL, NULL);
    printf("  %s: %s at t = %g\n", solvers[i], sim.fail_detail, sim.fail_time);
    assert_int_equal(st, MB_ERR_NONFINITE);
    assert_true(sim.fail_time == 0);
    assert_non_null(strstr(sim.fail_detail, "non-finite"));
    mb_sim_free(&sim);
    ls->destroy(ls);
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(klu_vs_dense),   cmocka_unit_test(generated_vs_generic),
      cmocka_unit_test(spatial_energy), cmocka_unit_test(double_pendulum_energy),
      cmocka_unit_test(rk4_pendulum),   cmocka_unit_test(rk4_slider_crank),
      cmocka_unit_test(nonfinite_reported),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
