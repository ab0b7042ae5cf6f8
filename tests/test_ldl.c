/* test_ldl.c: the emitted LDL^T (solver "ldl", compiler/back/emit_ldl.c).
 *   - for every shipped model and fd_all (virtual bodies, the massless
 *     slider: zero pivots without the augmented-Lagrangian term) at a few
 *     states near q0 with random velocities, random right sides and the
 *     model's own right side are solved to a relative residual
 *     ||b - K x||_inf / (||K||_inf ||x||_inf + ||b||_inf) below 1e-12 after
 *     refinement (measured here, independently of the residual the solver
 *     reports, which must agree), and the solution agrees with KLU to 1e-10
 *     relative; the single pass without residual or refinement (residual
 *     NULL, what the runtime does on 63 solves in 64 of a model without
 *     weighted rows) meets the same two bounds;
 *   - straight-line and looped code are both exercised (the flexible
 *     slider-crank with 10 normal modes, tests/models, is generated as
 *     loops: "+looped" above, MBCC_LDL_BUDGET=0), with and without block
 *     pivots (the welded virtual bodies of the virtual1 / virtual2 scenes)
 *     and with the massless slider eliminated first (every slider-crank);
 *   - the straight-line elimination of the massless slider with its rows of
 *     t = 0 falls back to pivoting when one of those rows loses the slider;
 *   - a zero pivot is reported with its unknown; a model without emitted
 *     LDL^T gives no "ldl" solver;
 *   - the flexible slider-crank with two virtual bodies simulated with "ldl"
 *     and with "klu" gives the same trajectory to 1e-9. */
// models: pendulum double_pendulum four_bar slider_crank spatial_joints virtual_fixed slider_crank_flexible slider_crank_flexible@virtual1 slider_crank_flexible@virtual2 fd_all slider_crank_flexible_fine+looped slider_crank_flexible_fine@virtual2+looped
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "support.h"
#include "double_pendulum.h"
#include "fd_all.h"
#include "four_bar.h"
#include "pendulum.h"
#include "slider_crank.h"
#include "slider_crank_flexible.h"
#include "slider_crank_flexible_virtual1.h"
#include "slider_crank_flexible_virtual2.h"
#include "slider_crank_flexible_fine.h"
#include "slider_crank_flexible_fine_virtual2.h"
#include "spatial_joints.h"
#include "virtual_fixed.h"

static const mb_model *const models[] = {
    &pendulum_model,       &double_pendulum_model,       &four_bar_model,
    &slider_crank_model,   &spatial_joints_model,        &virtual_fixed_model,
    &slider_crank_flexible_model, &slider_crank_flexible_virtual1_model,
    &slider_crank_flexible_virtual2_model, &fd_all_model,
    &slider_crank_flexible_fine_model, &slider_crank_flexible_fine_virtual2_model,
};
#define NMODELS ((int)(sizeof models / sizeof models[0]))

static void residual_and_klu(void **state) {
  (void)state;
  for (int im = 0; im < NMODELS; im++) {
    const mb_model *m = models[im];
    int n = m->n;
    assert_non_null(m->ldl_factor);
    mb_solver *ldl = mb_solver_new("ldl", m), *klu = mb_solver_new("klu", m);
    assert_non_null(ldl);
    assert_non_null(klu);
    double *Kx = calloc((size_t)m->nnz, sizeof(double)), *rhs = calloc((size_t)n, sizeof(double));
    double *b = malloc(sizeof(double) * (size_t)n), *x = malloc(sizeof(double) * (size_t)n);
    double *y = malloc(sizeof(double) * (size_t)n), *z = malloc(sizeof(double) * (size_t)n);
    void *work = malloc(mb_model_worksize(m) + 16);
    double *lwork = calloc(m->ldl_worksize + 1, sizeof(double));
    assert_true(Kx && rhs && b && x && y && z && work && lwork);
    ldl->check_every = 1; /* the residual of every solve */
    double worst_res = 0, worst_rep = 0, worst_klu = 0, worst_pass = 0;
    for (int k = 0; k < 4; k++) {
      k_near_q0(m, k, Kx, rhs, work);
      assert_int_equal(ldl->factor(ldl, Kx), MB_OK);
      assert_int_equal(m->ldl_factor(m, Kx, lwork), 0);
      assert_int_equal(ldl->bad_pivot, -1);
      assert_int_equal(klu->factor(klu, Kx), MB_OK);
      for (int s = 0; s < 6; s++) {
        for (int i = 0; i < n; i++) b[i] = s == 0 ? rhs[i] : urand(-1, 1);
        if (s == 1) /* body rows only / constraint rows only: different scales */
          for (int i = m->nv; i < n; i++) b[i] = 0;
        if (s == 2)
          for (int i = 0; i < m->nv; i++) b[i] = 0;
        memcpy(x, b, sizeof(double) * (size_t)n);
        memcpy(y, b, sizeof(double) * (size_t)n);
        memcpy(z, b, sizeof(double) * (size_t)n);
        assert_int_equal(ldl->solve(ldl, x), MB_OK);
        assert_int_equal(klu->solve(klu, y), MB_OK);
        assert_int_equal(m->ldl_solve(m, Kx, lwork, z, NULL), MB_OK);
        double res = k_rel_residual(m, Kx, x, b), res_pass = k_rel_residual(m, Kx, z, b);
        double xn = 0, d = 0, dz = 0;
        for (int i = 0; i < n; i++) {
          xn = fmax(xn, fabs(y[i]));
          d = fmax(d, fabs(x[i] - y[i]));
          dz = fmax(dz, fabs(z[i] - y[i]));
        }
        worst_pass = fmax(worst_pass, res_pass);
        if (!(res_pass < 1e-10) || !(dz <= 1e-9 * xn)) {
          print_error("%s: state %d, rhs %d: single pass: residual %.3g, |x - x_klu| / |x_klu| %.3g\n",
                      m->name, k, s, res_pass, dz / xn);
          fail();
        }
        worst_res = fmax(worst_res, res);
        worst_rep = fmax(worst_rep, ldl->residual);
        worst_klu = fmax(worst_klu, d / xn);
        if (!(res < 1e-12) || !(d <= 1e-10 * xn) || !(ldl->residual < 1e-12) ||
            !(fabs(ldl->residual - res) <= 1e-3 * res + 1e-17)) {
          print_error("%s: state %d, rhs %d: residual %.3g (reported %.3g), |x - x_klu| / |x_klu| %.3g\n",
                      m->name, k, s, res, ldl->residual, d / xn);
          fail();
        }
      }
    }
    printf("  %-32s n %3d  nnz(L) %5ld  flops %6.0f (%s): max residual %.2e (reported %.2e, "
           "single pass %.2e%s), vs klu %.2e\n", m->name, n, m->ldl_nnzL, m->ldl_flops,
           m->ldl_straight ? "straight" : "looped", worst_res, worst_rep, worst_pass,
           m->ldl_exact ? "" : ", refined", worst_klu);
    assert_true(ldl->residual_max >= worst_rep && ldl->residual_max <= worst_rep);
    ldl->destroy(ldl);
    klu->destroy(klu);
    free(Kx); free(rhs); free(b); free(x); free(y); free(z); free(work); free(lwork);
  }
}

/* both code forms are covered by the shipped models */
static void code_forms(void **state) {
  (void)state;
  int straight = 0, looped = 0;
  for (int im = 0; im < NMODELS; im++) {
    const mb_model *m = models[im];
    assert_true(m->ldl_nnzL > 0 && m->ldl_flops > 0 && m->ldl_worksize > 0);
    if (m->ldl_straight) straight++;
    else looped++;
  }
  assert_true(straight > 0);
  assert_true(looped > 0);
  assert_int_equal(SLIDER_CRANK_FLEXIBLE_FINE_LDL_STRAIGHT, 0);
  assert_int_equal(SLIDER_CRANK_FLEXIBLE_FINE_VIRTUAL2_LDL_STRAIGHT, 0);
  /* block pivots and the massless slider cost no fill (straight-line) */
  assert_int_equal(SLIDER_CRANK_FLEXIBLE_VIRTUAL2_LDL_STRAIGHT, 1);
  assert_int_equal(SLIDER_CRANK_FLEXIBLE_LDL_STRAIGHT, 1);
  assert_int_equal(PENDULUM_LDL_STRAIGHT, 1);
}

/* the runtime checks one solve in MB_LDL_CHECK_EVERY, and refines every solve
 * once a single pass was found above MB_LDL_PASS_TOL: the flexible slider-crank
 * stays sampled, the rigid one (the rod's axial inertia 1e-7 kg m^2 beside a
 * 10 kg crank: static pivots that far apart) switches; both give solutions
 * within 1e-12 of the refined ones */
static void sampled_checks(void **state) {
  (void)state;
  const mb_model *ms[2] = {&slider_crank_flexible_model, &slider_crank_model};
  for (int i = 0; i < 2; i++) {
    const mb_model *m = ms[i];
    int n = m->n, nsolve = 2 * MB_LDL_CHECK_EVERY + 2;
    mb_solver *ldl = mb_solver_new("ldl", m), *ref = mb_solver_new("ldl", m);
    assert_true(ldl && ref);
    ref->check_every = 1;
    assert_int_equal(ldl->check_every, MB_LDL_CHECK_EVERY);
    double *Kx = calloc((size_t)m->nnz, sizeof(double)), *rhs = calloc((size_t)n, sizeof(double));
    double *x = malloc(sizeof(double) * (size_t)n), *y = malloc(sizeof(double) * (size_t)n);
    void *work = malloc(mb_model_worksize(m) + 16);
    assert_true(Kx && rhs && x && y && work);
    k_near_q0(m, 1, Kx, rhs, work);
    assert_int_equal(ldl->factor(ldl, Kx), MB_OK);
    assert_int_equal(ref->factor(ref, Kx), MB_OK);
    double dmax = 0;
    for (int s = 0; s < nsolve; s++) {
      for (int k = 0; k < n; k++) x[k] = y[k] = k < m->nv ? urand(-1, 1) : 0;
      assert_int_equal(ldl->solve(ldl, x), MB_OK);
      assert_int_equal(ref->solve(ref, y), MB_OK);
      double xn = 0, d = 0;
      for (int k = 0; k < n; k++) {
        xn = fmax(xn, fabs(y[k]));
        d = fmax(d, fabs(x[k] - y[k]));
      }
      dmax = fmax(dmax, d / xn);
    }
    printf("  %s: %ld of %ld solves checked, single pass residual up to %.2e%s; vs refined %.2e\n",
           m->name, ldl->residual_checks, ldl->solves, ldl->residual_pass_max,
           ldl->refine_always ? ": refines every solve" : "", dmax);
    assert_int_equal(ldl->solves, nsolve);
    if (ldl->residual_pass_max <= MB_LDL_PASS_TOL) {
      assert_int_equal(ldl->refine_always, 0);
      assert_int_equal(ldl->residual_checks, 3); /* solves 0, 64, 128 */
    } else {
      assert_int_equal(ldl->refine_always, 1);
      assert_true(ldl->residual_checks > 3);
    }
    assert_true(dmax < 1e-12);
    /* which branch each model takes is part of the statement */
    assert_int_equal(ldl->refine_always, i == 1);
    ldl->destroy(ldl);
    ref->destroy(ref);
    free(Kx); free(rhs); free(x); free(y); free(work);
  }
}

/* a zero pivot is reported with its unknown; no emitted LDL^T, no solver */
static void zero_pivot_and_missing(void **state) {
  (void)state;
  const mb_model *ms[2] = {&pendulum_model, &slider_crank_flexible_virtual2_model};
  for (int i = 0; i < 2; i++) {
    const mb_model *m = ms[i];
    mb_solver *ldl = mb_solver_new("ldl", m);
    assert_non_null(ldl);
    double *Kx = calloc((size_t)m->nnz, sizeof(double));
    assert_non_null(Kx);
    assert_int_equal(ldl->factor(ldl, Kx), MB_ERR_SINGULAR); /* K = 0 */
    assert_true(ldl->bad_pivot >= 0 && ldl->bad_pivot < m->nv);
    /* massless bodies without the weighted rows: K itself has zero pivots,
       the emitted code still factors it (the weights are in the code) */
    void *work = malloc(mb_model_worksize(m) + 16);
    double *rhs = calloc((size_t)m->n, sizeof(double));
    k_near_q0(m, 0, Kx, rhs, work);
    assert_int_equal(ldl->factor(ldl, Kx), MB_OK);
    assert_int_equal(ldl->bad_pivot, -1);
    ldl->destroy(ldl);
    free(Kx); free(work); free(rhs);
  }
  mb_model g = generic_twin(&pendulum_model);
  g.ldl_factor = NULL;
  g.ldl_solve = NULL;
  assert_null(mb_solver_new("ldl", &g));
}


/* The straight-line code eliminates a massless body with the rows partial
 * pivoting chose at t = 0 (ldl_mlN_fixed) and falls back to pivoting when
 * they no longer suit.  Make them unsuitable: take one of the slider's
 * constraint rows that also act on other bodies (the wrist pin's) off the
 * slider (zero its entries in the slider's columns, both triangles): a
 * chosen row, so Du is singular.  Where K stays regular (KLU factors it
 * with a fair condition estimate), the emitted LDL^T must still factor it
 * and agree with KLU; without the fallback its factorization would fail. */
static void massless_rows_fallback(void **state) {
  (void)state;
  const mb_model *m = &slider_crank_flexible_model;
  int n = m->n, nv = m->nv, u0 = -1, tried = 0;
  for (int b = 0; b < m->nbody; b++)
    if (!strcmp(m->body[b].name, "slider")) u0 = m->body[b].vadr;
  assert_true(u0 >= 0);
  double *K0 = calloc((size_t)m->nnz, sizeof(double)), *Kx = calloc((size_t)m->nnz, sizeof(double));
  double *rhs = calloc((size_t)n, sizeof(double)), *b = malloc(sizeof(double) * (size_t)n);
  double *x = malloc(sizeof(double) * (size_t)n), *y = malloc(sizeof(double) * (size_t)n);
  void *work = malloc(mb_model_worksize(m) + 16);
  double *lwork = calloc(m->ldl_worksize + 1, sizeof(double));
  assert_true(K0 && Kx && rhs && b && x && y && work && lwork);
  k_near_q0(m, 1, K0, rhs, work);
  for (int row = nv; row < n; row++) {
    int on_u = 0, off_u = 0;
    for (int j = 0; j < nv; j++)
      for (int q = m->Kp[j]; q < m->Kp[j + 1]; q++)
        if (m->Ki[q] == row && K0[q] != 0) *(j >= u0 && j < u0 + 6 ? &on_u : &off_u) = 1;
    if (!on_u || !off_u) continue;
    memcpy(Kx, K0, sizeof(double) * (size_t)m->nnz);
    for (int j = 0; j < n; j++)
      for (int q = m->Kp[j]; q < m->Kp[j + 1]; q++) {
        int i = m->Ki[q];
        if ((i == row && j >= u0 && j < u0 + 6) || (j == row && i >= u0 && i < u0 + 6)) Kx[q] = 0;
      }
    mb_solver *klu = mb_solver_new("klu", m);
    assert_non_null(klu);
    if (klu->factor(klu, Kx) == MB_OK && klu->rcond > 1e-10) {
      tried++;
      assert_int_equal(m->ldl_factor(m, Kx, lwork), 0);
      for (int i = 0; i < n; i++) b[i] = urand(-1, 1);
      memcpy(x, b, sizeof(double) * (size_t)n);
      memcpy(y, b, sizeof(double) * (size_t)n);
      mb_real res[2];
      assert_int_equal(m->ldl_solve(m, Kx, lwork, x, res), MB_OK);
      assert_int_equal(klu->solve(klu, y), MB_OK);
      double d = 0, yn = 0;
      for (int i = 0; i < n; i++) { d = fmax(d, fabs(x[i] - y[i])); yn = fmax(yn, fabs(y[i])); }
      printf("  row %d off the slider: residual %.2g, against KLU %.2g\n", row, k_rel_residual(m, Kx, x, b),
             d / yn);
      assert_true(k_rel_residual(m, Kx, x, b) < 1e-12);
      assert_true(d <= 1e-10 * yn);
    }
    klu->destroy(klu);
  }
  assert_true(tried > 0);
  free(K0); free(Kx); free(rhs); free(b); free(x); free(y); free(work); free(lwork);
}

/* the flexible slider-crank with two virtual bodies (looped code, 18
 * massless unknowns): ldl against klu over a fifth of a crank revolution */
static void simulate_virtual2(void **state) {
  (void)state;
  const mb_model *m = &slider_crank_flexible_virtual2_model;
  mb_settings s;
  test_settings(&s, 0.01, 2e-4);
  s.rtol = 1e-8;
  s.atol = 1e-10;
  trajectory a, b;
  assert_int_equal(simulate(m, &s, "klu", &a), MB_OK);
  assert_int_equal(simulate(m, &s, "ldl", &b), MB_OK);
  double d = max_rel_diff(m, &a, &b, NULL);
  printf("  %s: ldl vs klu over %g s: max relative difference %.3g (%ld steps)\n", m->name,
         s.end_time, d, b.stats.steps);
  assert_true(d < 1e-9);
  trajectory_free(&a);
  trajectory_free(&b);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(residual_and_klu),
      cmocka_unit_test(code_forms),
      cmocka_unit_test(sampled_checks),
      cmocka_unit_test(zero_pivot_and_missing),
      cmocka_unit_test(massless_rows_fallback),
      cmocka_unit_test(simulate_virtual2),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
