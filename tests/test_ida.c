/* test_ida.c: the SUNDIALS IDA path (runtime/hosted/ida.c, the DAE in [q; v; lambda])
 * against the built-in integrator and against closed-form kinematics:
 *   - the pendulum (m = 1 kg, l = 1 m, released at 90 degrees; models/pendulum.yaml)
 *     over 2 s: every output column (position, angle, energies, the pivot
 *     reaction from lambda) within 1e-6 of DOPRI5 with projection;
 *   - the slider-crank (r = 0.1524 m, L = 0.3048 m, 124.8 rad/s;
 *     models/slider_crank.yaml): slider_x = r cos th + sqrt(L^2 - r^2 sin^2 th),
 *     th = 124.8 t, within 1e-6 m over two revolutions;
 *   - the same slider-crank with IDA's KLU on the analytic sparse Jacobian
 *     (MB_IDA_KLU), and that Jacobian's exact parts (dF/dy', the multiplier
 *     columns, the q rows) against central differences of the residual at a
 *     generic state;
 *   - statistics are reported and a bad setting is refused. */
// models: pendulum slider_crank
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "support.h"
#include "mb_ida.h"
#include "pendulum.h"
#include "slider_crank.h"

#define SC_R 0.1524
#define SC_L 0.3048
#define SC_W 124.8

/* collects IDA's outputs like simulate() does */
typedef struct {
  const mb_model *m;
  trajectory tr;
  int cap;
  void *work;
} ida_rec;

static int rec_out(void *user, double t, const double *q, const double *v, const double *vd,
                   const double *lambda) {
  ida_rec *r = user;
  if (r->tr.nrows == r->cap) return 1;
  double *row = r->tr.y + (size_t)r->tr.nrows * (size_t)r->tr.ncols;
  mb_model_outputs(r->m, t, q, v, vd, lambda, r->tr.nrows ? row - r->tr.ncols : NULL, row, r->work);
  r->tr.t[r->tr.nrows++] = t;
  return 0;
}

static int ida_linsol = MB_IDA_DENSE; /* the linear solver ida_run uses */

static int ida_run(const mb_model *m, const mb_settings *s, ida_rec *r, mb_stats *stats) {
  memset(r, 0, sizeof *r);
  r->m = m;
  r->cap = (int)floor(s->end_time / s->output_step + 1e-9) + 1;
  r->tr.ncols = m->ncols;
  r->tr.t = malloc(sizeof(double) * (size_t)r->cap);
  r->tr.y = malloc(sizeof(double) * (size_t)r->cap * (size_t)m->ncols);
  r->work = malloc(mb_model_worksize(m) + 16);
  assert_non_null(r->tr.t);
  assert_non_null(r->tr.y);
  assert_non_null(r->work);
  double ft = -1;
  int st = mb_ida_run(m, s, ida_linsol, rec_out, r, stats, &ft);
  if (st) print_error("mb_ida_run: %s at t = %g\n", mb_status_text(st), ft);
  return st;
}

static void ida_free(ida_rec *r) {
  trajectory_free(&r->tr);
  free(r->work);
}

static void pendulum_matches_dopri5(void **state) {
  (void)state;
  const mb_model *m = &pendulum_model;
  mb_settings s;
  test_settings(&s, 2.0, 0.005);
  s.rtol = 1e-10;
  s.atol = 1e-12;
  trajectory ref;
  assert_int_equal(simulate(m, &s, "klu", &ref), MB_OK);
  ida_rec r;
  mb_stats st;
  assert_int_equal(ida_run(m, &s, &r, &st), MB_OK);
  assert_int_equal(r.tr.nrows, ref.nrows);
  double worst = 0;
  int wj = 0, wk = 0;
  for (int k = 0; k < ref.nrows; k++) {
    assert_close(r.tr.t[k], ref.t[k], 1e-12);
    for (int j = 0; j < m->ncols; j++) {
      /* 1e-6 relative to the output's size (reactions are ~10-30 N) */
      double d = fabs(at(&r.tr, k, j) - at(&ref, k, j)) / fmax(1.0, fabs(at(&ref, k, j)));
      if (d > worst) { worst = d; wj = j; wk = k; }
    }
  }
  print_message("  pendulum: IDA vs DOPRI5: max difference %.2e (%s at t = %g); IDA %ld steps, "
                "%ld residuals\n", worst, m->col_name[wj], ref.t[wk], st.steps, st.evals);
  assert_true(worst < 1e-6);
  assert_true(st.steps > 0 && st.evals > st.steps && st.t_total > 0);
  ida_free(&r);
  trajectory_free(&ref);
}

static void slider_crank_closed_form(void **state) {
  (void)state;
  const mb_model *m = &slider_crank_model;
  mb_settings s;
  test_settings(&s, 0.1, 2e-4);
  s.rtol = 1e-10;
  s.atol = 1e-12;
  ida_rec r;
  mb_stats st;
  assert_int_equal(ida_run(m, &s, &r, &st), MB_OK);
  int cx = column(m, "slider_x");
  assert_true(cx >= 0);
  assert_int_equal(r.tr.nrows, 501);
  double worst = 0;
  for (int k = 0; k < r.tr.nrows; k++) {
    double th = SC_W * r.tr.t[k], sn = sin(th);
    double x = SC_R * cos(th) + sqrt(SC_L * SC_L - SC_R * SC_R * sn * sn);
    worst = fmax(worst, fabs(at(&r.tr, k, cx) - x));
  }
  print_message("  slider-crank: IDA (%s) slider_x vs closed form: max error %.2e m (%ld steps)\n",
                ida_linsol == MB_IDA_KLU ? "KLU, analytic Jacobian" : "dense", worst, st.steps);
  assert_true(worst < 1e-6);
  ida_free(&r);
}

static void slider_crank_closed_form_klu(void **state) {
  ida_linsol = MB_IDA_KLU;
  slider_crank_closed_form(state);
  ida_linsol = MB_IDA_DENSE;
}

/* dF/dy' (J at cj = 1 minus J at cj = 0), the multiplier columns and the q rows of J at
 * cj = 0 (dF/dy) against central differences of the residual at a generic state: q0
 * moved and turned off its assembled values, random v, v' and lambda.  Returns the largest
 * error relative to the largest entry; *left_out gets the largest difference in the
 * remaining entries (the K rows' q and v columns, partly left out by design), relative
 * likewise. */
static double jacobian_check(const mb_model *m, double *left_out) {
  int nq = m->nq, nv = m->nv, N = nq + m->n;
  double *y = malloc(sizeof(double) * (size_t)N), *yp = malloc(sizeof(double) * (size_t)N);
  double *J0 = malloc(sizeof(double) * (size_t)N * (size_t)N), *J1 = malloc(sizeof(double) * (size_t)N * (size_t)N);
  double *rp = malloc(sizeof(double) * (size_t)N), *rm = malloc(sizeof(double) * (size_t)N);
  assert_true(y && yp && J0 && J1 && rp && rm);
  srand(7);
  for (int i = 0; i < N; i++) {
    double u = (double)rand() / RAND_MAX - 0.5;
    y[i] = i < nq ? m->q0[i] + 0.1 * u : 2 * u;
    yp[i] = (double)rand() / RAND_MAX - 0.5;
  }
  int nnz = 0;
  assert_int_equal(mb_ida_jacobian_dense(m, 0.01, y, 0.0, J0, &nnz), MB_OK);
  assert_int_equal(mb_ida_jacobian_dense(m, 0.01, y, 1.0, J1, NULL), MB_OK);
  assert_true(nnz > 0 && nnz < N * N);
  double scale = 0, err = 0, rest = 0;
  for (size_t k = 0; k < (size_t)N * (size_t)N; k++) scale = fmax(scale, fmax(fabs(J0[k]), fabs(J1[k] - J0[k])));
  for (int j = 0; j < N; j++) {
    for (int pass = 0; pass < 2; pass++) { /* 0: d/dy_j, 1: d/dy'_j */
      double *x = pass ? yp : y, x0 = x[j], h = 1e-6 * fmax(1.0, fabs(x0));
      x[j] = x0 + h;
      assert_int_equal(mb_ida_residual(m, 0.01, y, yp, rp), MB_OK);
      x[j] = x0 - h;
      assert_int_equal(mb_ida_residual(m, 0.01, y, yp, rm), MB_OK);
      x[j] = x0;
      for (int i = 0; i < N; i++) {
        double fd = (rp[i] - rm[i]) / (2 * h);
        size_t k = (size_t)j * (size_t)N + (size_t)i;
        double an = pass ? J1[k] - J0[k] : J0[k];
        double d = fabs(an - fd) / scale;
        if (pass || i < nq || j >= nq + nv) err = fmax(err, d);
        else rest = fmax(rest, d);
      }
    }
  }
  free(y); free(yp); free(J0); free(J1); free(rp); free(rm);
  *left_out = rest;
  return err;
}

static void jacobian_against_differences(void **state) {
  (void)state;
  const mb_model *ms[] = {&pendulum_model, &slider_crank_model};
  for (int k = 0; k < 2; k++) {
    double rest, err = jacobian_check(ms[k], &rest);
    print_message("  %s: analytic IDA Jacobian vs central differences: exact parts %.1e, "
                  "left-out terms up to %.1e (relative to the largest entry at cj = 1)\n", ms[k]->name, err, rest);
    assert_true(err < 1e-6);
  }
}

static void bad_settings(void **state) {
  (void)state;
  mb_settings s;
  test_settings(&s, 0.1, 0.01);
  s.rtol = 0;
  mb_stats st;
  assert_int_equal(mb_ida_simulate(&pendulum_model, &s, NULL, NULL, &st, NULL), MB_ERR_INVALID);
  assert_int_equal(mb_ida_run(&pendulum_model, &s, MB_IDA_KLU, NULL, NULL, &st, NULL), MB_ERR_INVALID);
  test_settings(&s, 0.1, 0.01);
  assert_int_equal(mb_ida_run(&pendulum_model, &s, 7, NULL, NULL, &st, NULL), MB_ERR_INVALID);
  assert_int_equal(mb_ida_size(&pendulum_model),
                   pendulum_model.nq + pendulum_model.nv + pendulum_model.nc);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(pendulum_matches_dopri5),
      cmocka_unit_test(slider_crank_closed_form),
      cmocka_unit_test(slider_crank_closed_form_klu),
      cmocka_unit_test(jacobian_against_differences),
      cmocka_unit_test(bad_settings),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
