/* test_loop_form.c: the evaluation in the loop form (compiler/back/emit_loops.c,
 * compiled with MBCC_LOOP_MIN=0: "+loops") gives the generic path's numbers
 * (runtime/core/model_generic.c, the same kernels walked over the model's
 * tables) at random states and times: every joint type, every driver
 * profile, springs (power and table laws), a bushing, a point force in body
 * axes with a time scale and a torque, a virtual body (fd_all), and a
 * hinged chain.  Mixed models, whose elements without a loop form are
 * written straight-line in the same evaluation: four tyres on a table road
 * (tyre_cart: the tyres looped), a flexible rod between looped bodies
 * (slider_crank_flexible), springs on flexible nodes (fd_node_twins), a
 * superelement (tangent_forces), the flexible car (sports_car: flexible
 * chassis, its tyres looped).  test_fd checks the straight-line form against
 * the same generic path and against finite differences;
 * tests/test_loop_form.sh the two forms' simulations against each other. */
// models: fd_all+loops hinged_chain10_rigid+loops tyre_cart+loops slider_crank_flexible+loops fd_node_twins+loops tangent_forces+loops sports_car+loops
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "support.h"
#include "fd_all.h"
#include "hinged_chain10_rigid.h"
#include "tyre_cart.h"
#include "slider_crank_flexible.h"
#include "fd_node_twins.h"
#include "tangent_forces.h"
#include "sports_car.h"

typedef struct {
  double *Kx, *rhs, *phi, *nu;
  void *work;
} outputs;

static void outputs_alloc(outputs *o, const mb_model *m) {
  o->Kx = calloc((size_t)m->nnz + 1, sizeof(double));
  o->rhs = calloc((size_t)m->n + 1, sizeof(double));
  o->phi = calloc((size_t)m->nc + 1, sizeof(double));
  o->nu = calloc((size_t)m->nc + 1, sizeof(double));
  o->work = malloc(mb_model_worksize(m) + 16);
  assert_true(o->Kx && o->rhs && o->phi && o->nu && o->work);
}

static void outputs_free(outputs *o) {
  free(o->Kx); free(o->rhs); free(o->phi); free(o->nu); free(o->work);
}

/* bodies anywhere in [-1, 1]^3, turned at random, moving at random; a
 * flexible body's modal coordinates small (after its 7 frame coordinates) */
static void scatter_state(const mb_model *m, double *q, double *v) {
  for (int b = 0; b < m->nbody; b++) {
    double *p = q + m->body[b].qadr, len = 0;
    for (int j = 0; j < 7; j++) p[j] = urand(-1, 1);
    for (int j = 3; j < 7; j++) len += p[j] * p[j];
    for (int j = 3; j < 7; j++) p[j] /= sqrt(len);
    if (m->body[b].kind == MB_BODY_FLEXIBLE)
      for (int j = 0; j < m->body[b].nm; j++) p[7 + j] = urand(-0.01, 0.01);
  }
  for (int j = 0; j < m->nv; j++) v[j] = urand(-2, 2);
}

static void loop_form_equals_generic(const mb_model *m) {
  mb_model g = generic_twin(m);
  outputs a, b;
  outputs_alloc(&a, m);
  outputs_alloc(&b, &g);
  double *q = malloc(sizeof(double) * (size_t)m->nq), *v = malloc(sizeof(double) * (size_t)m->nv);
  double worst = 0, largest = 0;
  for (int trial = 0; trial < 5; trial++) {
    scatter_state(m, q, v);
    double t = urand(0, 1.5);
    m->init(m, a.Kx);
    g.init(&g, b.Kx);
    m->eval(m, t, q, v, a.Kx, a.rhs, a.phi, a.nu, a.work);
    g.eval(&g, t, q, v, b.Kx, b.rhs, b.phi, b.nu, b.work);
    for (int i = 0; i < m->nnz; i++) {
      worst = fmax(worst, fabs(a.Kx[i] - b.Kx[i]) / (1 + fabs(b.Kx[i])));
      largest = fmax(largest, fabs(b.Kx[i]));
    }
    for (int i = 0; i < m->n; i++) worst = fmax(worst, fabs(a.rhs[i] - b.rhs[i]) / (1 + fabs(b.rhs[i])));
    for (int i = 0; i < m->nc; i++) worst = fmax(worst, fmax(fabs(a.phi[i] - b.phi[i]), fabs(a.nu[i] - b.nu[i])));
  }
  print_message("%s: loop form vs generic, worst relative difference %.2e\n", m->name, worst);
  assert_true(largest > 0.1); /* the comparison saw the varying entries */
  assert_true(worst < 1e-13);
  free(q); free(v);
  outputs_free(&a);
  outputs_free(&b);
}

static void test_all_joints_and_forces(void **state) {
  (void)state;
  loop_form_equals_generic(&fd_all_model);
}

static void test_chain(void **state) {
  (void)state;
  loop_form_equals_generic(&hinged_chain10_rigid_model);
}

static void test_mixed_tyres(void **state) {
  (void)state;
  loop_form_equals_generic(&tyre_cart_model);
}

static void test_mixed_flexible(void **state) {
  (void)state;
  loop_form_equals_generic(&slider_crank_flexible_model);
  loop_form_equals_generic(&fd_node_twins_model);
}

static void test_mixed_superelement(void **state) {
  (void)state;
  loop_form_equals_generic(&tangent_forces_model);
}

static void test_mixed_car(void **state) {
  (void)state;
  loop_form_equals_generic(&sports_car_model);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_all_joints_and_forces),
      cmocka_unit_test(test_chain),
      cmocka_unit_test(test_mixed_tyres),
      cmocka_unit_test(test_mixed_flexible),
      cmocka_unit_test(test_mixed_superelement),
      cmocka_unit_test(test_mixed_car),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
