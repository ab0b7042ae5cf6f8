/* test_generic.c: the general generic path (element loops into triplets,
 * assembled into a general sparse matrix every step; KLU or dense LU) gives
 * the same trajectories as the generated code with the compile-time pattern. */
// models: spatial_joints slider_crank_flexible@virtual2 fd_all
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "support.h"
#include "spatial_joints.h"
#include "slider_crank_flexible_virtual2.h"
#include "fd_all.h"

static void check(const mb_model *m, double end, double step) {
  mb_settings s;
  test_settings(&s, end, step);
  trajectory ref, gk, gd;
  assert_int_equal(simulate(m, &s, "klu", &ref), MB_OK);
  mb_model g = *m;
  g.eval = mb_generic_triplet_eval;
  g.init = mb_generic_triplet_init;
  /* the general path through the integrator */
  for (int dense = 0; dense < 2; dense++) {
    trajectory *out = dense ? &gd : &gk;
    assert_int_equal(simulate(&g, &s, dense ? "generic-dense" : "generic-klu", out), MB_OK);
    double d = max_rel_diff(m, &ref, out, NULL);
    print_message("  %s: generic+%s vs generated+klu: max difference %.2e of the range\n", m->name,
                  dense ? "dense" : "klu", d);
    assert_true(d < 1e-9);
  }
  trajectory_free(&ref); trajectory_free(&gk); trajectory_free(&gd);
}

static void test_generic_path(void **state) {
  (void)state;
  check(&spatial_joints_model, 0.5, 0.01);
  check(&slider_crank_flexible_virtual2_model, 0.02, 2e-4);
  check(&fd_all_model, 0.2, 0.01);
}

int main(void) {
  const struct CMUnitTest tests[] = {cmocka_unit_test(test_generic_path)};
  return cmocka_run_group_tests(tests, NULL, NULL);
}
