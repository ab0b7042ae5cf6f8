/* test_ldl_tail.c: the emitted LDL^T with a dense tail (emit_ldl.c: the last rows
 * of L formed by ldl_tail's vector loops instead of straight-line code; here
 * forced to 12 rows by MBCC_LDL_TAIL=12, the "+tail" models of run_tests.sh):
 *   - the solutions of K x = b at states near q0 agree with KLU's and leave a
 *     relative residual at roundoff, single pass (res NULL: no refinement);
 *   - a singular K is never factored silently: with one unknown's row and
 *     column of K set to zero, the factorization reports that unknown's zero
 *     pivot (returns 1 + u), whichever of the straight-line rows or the tail
 *     it falls in
 *     (every unknown without an entry that init writes: the emitted code takes
 *     those as the compile-time constants they are, whatever Kx holds). */
// models: four_bar+tail spatial_joints+tail double_pendulum+tail
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "support.h"
#include "double_pendulum.h"
#include "four_bar.h"
#include "spatial_joints.h"

/* the generated headers say how many rows the tail has: the test is of it */
static const int tails[] = {FOUR_BAR_LDL_TAIL, SPATIAL_JOINTS_LDL_TAIL, DOUBLE_PENDULUM_LDL_TAIL};
static const mb_model *const models[] = {&four_bar_model, &spatial_joints_model, &double_pendulum_model};
#define NMODELS ((int)(sizeof models / sizeof models[0]))

static void solves_agree_with_klu(void **state) {
  (void)state;
  for (int im = 0; im < NMODELS; im++) {
    const mb_model *m = models[im];
    int n = m->n;
    assert_true(tails[im] == 12);
    mb_solver *klu = mb_solver_new("klu", m);
    assert_non_null(klu);
    double *Kx = calloc((size_t)m->nnz, sizeof(double)), *rhs = calloc((size_t)n, sizeof(double));
    double *b = malloc(sizeof(double) * (size_t)n), *x = malloc(sizeof(double) * (size_t)n);
    double *y = malloc(sizeof(double) * (size_t)n);
    void *work = malloc(mb_model_worksize(m) + 16);
    double *lwork = calloc(m->ldl_worksize + 1, sizeof(double));
    assert_true(Kx && rhs && b && x && y && work && lwork);
    double worst_res = 0, worst_diff = 0;
    for (int k = 0; k < 4; k++) {
      k_near_q0(m, k, Kx, rhs, work);
      assert_int_equal(m->ldl_factor(m, Kx, lwork), 0);
      assert_int_equal(klu->factor(klu, Kx), MB_OK);
      for (int s = 0; s < 4; s++) {
        double xn = 0, d = 0;
        for (int i = 0; i < n; i++) b[i] = s == 0 ? rhs[i] : urand(-1, 1);
        memcpy(x, b, sizeof(double) * (size_t)n);
        memcpy(y, b, sizeof(double) * (size_t)n);
        assert_int_equal(m->ldl_solve(m, Kx, lwork, x, NULL), MB_OK);
        assert_int_equal(klu->solve(klu, y), MB_OK);
        for (int i = 0; i < n; i++) {
          xn = fmax(xn, fabs(y[i]));
          d = fmax(d, fabs(x[i] - y[i]));
        }
        worst_res = fmax(worst_res, k_rel_residual(m, Kx, x, b));
        worst_diff = fmax(worst_diff, d / xn);
      }
    }
    printf("%s: tail of %d rows, n = %d: relative residual <= %.2g, |x - x_klu| / |x_klu| <= %.2g\n", m->name,
           tails[im], n, worst_res, worst_diff);
    assert_true(worst_res < 1e-12);
    assert_true(worst_diff < 1e-9);
    klu->destroy(klu);
    free(Kx); free(rhs); free(b); free(x); free(y); free(work); free(lwork);
  }
}

static void singular_k_is_reported(void **state) {
  (void)state;
  for (int im = 0; im < NMODELS; im++) {
    const mb_model *m = models[im];
    double *Kx = calloc((size_t)m->nnz, sizeof(double)), *K0 = calloc((size_t)m->nnz, sizeof(double));
    double *rhs = calloc((size_t)m->n, sizeof(double));
    void *work = malloc(mb_model_worksize(m) + 16);
    double *lwork = calloc(m->ldl_worksize + 1, sizeof(double));
    assert_true(Kx && K0 && rhs && work && lwork);
    int tested = 0;
    m->init(m, Kx); /* the constant entries */
    k_near_q0(m, 1, K0, rhs, work);
    for (int u = 0; u < m->n; u++) {
      int constant = 0;
      for (int j = 0; j < m->n; j++)
        for (int p = m->Kp[j]; p < m->Kp[j + 1]; p++) constant |= (j == u || m->Ki[p] == u) && Kx[p] != 0;
      if (constant) continue;
      tested++;
      memcpy(Kx, K0, sizeof(double) * (size_t)m->nnz);
      for (int j = 0; j < m->n; j++)
        for (int p = m->Kp[j]; p < m->Kp[j + 1]; p++)
          if (j == u || m->Ki[p] == u) Kx[p] = 0;
      int rc = m->ldl_factor(m, Kx, lwork);
      /* the rows of L before u's pivot do not read row u: its own pivot is the zero */
      if (rc != u + 1) printf("%s: unknown %d zeroed: factorization returned %d\n", m->name, u, rc);
      assert_int_equal(rc, u + 1);
      memset(Kx, 0, sizeof(double) * (size_t)m->nnz);
      m->init(m, Kx);
    }
    printf("%s: %d of %d unknowns made singular, each reported\n", m->name, tested, m->n);
    assert_true(tested >= 1);
    /* and K itself factors again in the same workspace */
    assert_int_equal(m->ldl_factor(m, K0, lwork), 0);
    free(Kx); free(K0); free(rhs); free(work); free(lwork);
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(solves_agree_with_klu),
      cmocka_unit_test(singular_k_is_reported),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
