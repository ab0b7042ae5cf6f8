/* test_tangent.c: the force kernels' tangents (runtime/core/elements/) against
 * central finite differences of the same kernels' forces: the spring-damper's
 * dF1/dd and dF1/d(dd) with linear, power and table laws, and the field's 6x6
 * derivatives of marker 1's wrench with respect to its displacement, rotation,
 * velocity and angular velocity, at a large relative rotation (the inverse
 * left Jacobian of the rotation vector) and at a tiny one (its series).
 * Then the assembled tangent of a whole model (mb_model_force_tangent: what
 * generalized-alpha adds to its iteration matrix) against central differences
 * of the model's generalized applied forces over every body column: springs,
 * bushings and a beam on rigid bodies and on FE nodes of a flexible body;
 * and a tyre (its radial spring-damper and slip forces) on a rolling wheel. */
// models: tangent_forces tyre_quarter_stiff
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "support.h"
#include "mb_model.h"
#include "tangent_forces.h"
#include "tyre_quarter_stiff.h"

/* R <- exp(a~) R (Rodrigues) */
static void rotate_left(const double a[3], double R[9]) {
  double t = sqrt(mb_dot3(a, a)), E[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, out[9];
  if (t > 0) {
    double k[3] = {a[0] / t, a[1] / t, a[2] / t}, s = sin(t), c = 1 - cos(t);
    double K[9] = {0, -k[2], k[1], k[2], 0, -k[0], -k[1], k[0], 0}, KK[9];
    mb_matmul3(K, K, KK);
    for (int i = 0; i < 9; i++) E[i] += s * K[i] + c * KK[i];
  }
  mb_matmul3(E, R, out);
  memcpy(R, out, sizeof out);
}

static void marker_at(mb_marker *m, const double P[3], const double rot[3], const double V[3],
                      const double W[3]) {
  static const double I3[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  memset(m, 0, sizeof *m);
  memcpy(m->R, I3, sizeof I3);
  rotate_left(rot, m->R);
  for (int j = 0; j < 3; j++) { m->P[j] = P[j]; m->V[j] = V[j]; m->W[j] = W[j]; }
}

/* spring: F1 against d = P1 - P0 and dd = V1 - V0, moving marker 1 */
static void check_spring(const mb_law law[2]) {
  const double prm[MB_SPRING_NPRM] = {[MB_SPRING_L0] = 0.3, [MB_SPRING_PRELOAD] = 12};
  mb_marker m0, m1;
  marker_at(&m0, (const double[3]){0.1, -0.2, 0.05}, (const double[3]){0.2, 0, 0},
            (const double[3]){0.3, 0.1, -0.2}, (const double[3]){0, 0, 0});
  marker_at(&m1, (const double[3]){0.4, 0.1, -0.3}, (const double[3]){0, 0.1, 0},
            (const double[3]){-0.5, 0.7, 0.4}, (const double[3]){0, 0, 0});
  double F0[3], F1[3], tan[18], Fp[3], Fm[3];
  mb_spring(&m0, &m1, prm, law, F0, F1, tan);
  double scale = 0;
  for (int i = 0; i < 18; i++) scale = fmax(scale, fabs(tan[i]));
  const double h = 1e-6;
  for (int s = 0; s < 2; s++)
    for (int j = 0; j < 3; j++) {
      mb_marker a = m1, b = m1;
      (s ? a.V : a.P)[j] += h;
      (s ? b.V : b.P)[j] -= h;
      mb_spring(&m0, &a, prm, law, F0, Fp, 0);
      mb_spring(&m0, &b, prm, law, F0, Fm, 0);
      for (int i = 0; i < 3; i++) assert_close(tan[9 * s + 3 * i + j], (Fp[i] - Fm[i]) / (2 * h), 1e-6 * scale);
    }
}

static void test_spring_tangent(void **state) {
  (void)state;
  static const mb_real table[8] = {-1, -300, 0, 0, 0.1, 50, 0.5, 900};
  mb_law linear[2] = {{.kind = MB_LAW_LINEAR, .coef = 2000}, {.kind = MB_LAW_LINEAR, .coef = 35}};
  mb_law power[2] = {{.kind = MB_LAW_POWER, .coef = 800, .exponent = 1.7},
                     {.kind = MB_LAW_POWER, .coef = 20, .exponent = 0.8}};
  mb_law tab[2] = {{.kind = MB_LAW_TABLE, .ntable = 4, .table = table}, {.kind = MB_LAW_NONE}};
  check_spring(linear);
  check_spring(power);
  check_spring(tab);
}

/* field: marker 1's wrench against its displacement, small rotation, velocity
 * and angular velocity; marker 0 fixed but turning (W0 enters the rate) */
static void check_field(const double rot1[3]) {
  double prm[MB_FIELD_NPRM];
  for (int i = 0; i < MB_FIELD_NPRM; i++) prm[i] = 0.1 * sin(1.3 * i + 0.4); /* d0 and preload */
  for (int i = 0; i < 36; i++) {
    prm[MB_FIELD_K + i] = 100 * cos(0.7 * i) + (i % 7 == 0 ? 500 : 0);
    prm[MB_FIELD_C + i] = 3 * sin(0.9 * i + 1) + (i % 7 == 0 ? 10 : 0);
  }
  mb_marker m0, m1;
  marker_at(&m0, (const double[3]){0.1, -0.2, 0.05}, (const double[3]){0.3, -0.4, 0.2},
            (const double[3]){0.3, 0.1, -0.2}, (const double[3]){0.5, -1.2, 0.8});
  marker_at(&m1, (const double[3]){0.2, 0.1, -0.1}, rot1, (const double[3]){-0.5, 0.7, 0.4},
            (const double[3]){2, 0.3, -1.1});
  /* marker 1 starts near marker 0's orientation turned by rot1 */
  double R1[9];
  mb_matmul3(m1.R, m0.R, R1); /* R1 = exp(rot1~) R0 */
  memcpy(m1.R, R1, sizeof R1);
  double F[3], T[3], tan[72], Fp[3], Tp[3], Fm[3], Tm[3];
  mb_field(&m0, &m1, prm, F, T, tan);
  double scale = 0;
  for (int i = 0; i < 72; i++) scale = fmax(scale, fabs(tan[i]));
  const double h = 1e-6;
  for (int s = 0; s < 2; s++)
    for (int c = 0; c < 6; c++) {
      mb_marker a = m1, b = m1;
      if (s == 0 && c < 3) { a.P[c] += h; b.P[c] -= h; }
      if (s == 0 && c >= 3) {
        double e[3] = {0, 0, 0};
        e[c - 3] = h;
        rotate_left(e, a.R);
        e[c - 3] = -h;
        rotate_left(e, b.R);
      }
      if (s == 1) { (c < 3 ? a.V : a.W)[c % 3] += h; (c < 3 ? b.V : b.W)[c % 3] -= h; }
      mb_field(&m0, &a, prm, Fp, Tp, 0);
      mb_field(&m0, &b, prm, Fm, Tm, 0);
      for (int i = 0; i < 6; i++) {
        double fd = i < 3 ? (Fp[i] - Fm[i]) / (2 * h) : (Tp[i - 3] - Tm[i - 3]) / (2 * h);
        assert_close(tan[36 * s + 6 * i + c], fd, 1e-6 * scale);
      }
    }
}

static void test_field_tangent(void **state) {
  (void)state;
  check_field((const double[3]){0.6, -0.9, 0.4}); /* 1.2 rad */
  check_field((const double[3]){2e-5, 1e-5, -3e-5});
  check_field((const double[3]){0, 0, 0});
}

/* the force elements' generalized forces at (q, v): the generic evaluation
 * with them minus the one without them (gravity, gyroscopic and elastic
 * terms cancel) */
static void element_forces(const mb_model *m, const double *q, const double *v, double *f) {
  mb_model with = *m, without = *m;
  without.nforce = 0;
  double *Kx = calloc((size_t)m->nnz + 1, sizeof(double)), *r0 = calloc((size_t)m->n + 1, sizeof(double));
  double *r1 = calloc((size_t)m->n + 1, sizeof(double)), *phi = calloc((size_t)m->nc + 1, sizeof(double));
  double *nu = calloc((size_t)m->nc + 1, sizeof(double));
  void *work = malloc(mb_model_worksize(m) + 16);
  assert_non_null(work);
  mb_generic_eval(&with, 0, q, v, Kx, r1, phi, nu, work);
  mb_generic_eval(&without, 0, q, v, Kx, r0, phi, nu, work);
  for (int i = 0; i < m->nv; i++) f[i] = r1[i] - r0[i];
  free(Kx); free(r0); free(r1); free(phi); free(nu); free(work);
}

/* the dense nv x nv of kfac (-df/dq) + cfac (-df/dv) from the slots, and
 * which entries the pattern has */
static void assembled(const mb_model *m, const double *q, const double *v, double kfac, double cfac,
                      double *T, char *has) {
  double *Kx = calloc((size_t)m->nnz + 1, sizeof(double));
  void *work = malloc(mb_model_worksize(m) + 16);
  assert_non_null(work);
  mb_model_force_tangent(m, 0, q, v, kfac, cfac, Kx, work);
  int nv = m->nv;
  memset(T, 0, sizeof(double) * (size_t)nv * (size_t)nv);
  memset(has, 0, (size_t)nv * (size_t)nv);
  for (int j = 0; j < nv; j++)
    for (int p = m->Kp[j]; p < m->Kp[j + 1]; p++)
      if (m->Ki[p] < nv) {
        T[m->Ki[p] * nv + j] = Kx[p];
        has[m->Ki[p] * nv + j] = 1;
      }
  free(Kx);
  free(work);
}

/* central differences of -f over q (velocity space, q (+) e_j h) or over v;
 * returns the relative Frobenius difference from T over the columns for
 * which use_col is not 0 (NULL: all) and checks that every nonzero
 * difference quotient lies on the pattern */
static double compare_fd_cols(const mb_model *m, const double *q, const double *v, int over_v,
                              const double *T, const char *has, const char *use_col) {
  int nv = m->nv;
  double *fp = calloc((size_t)nv + 1, sizeof(double)), *fm = calloc((size_t)nv + 1, sizeof(double));
  double *qq = malloc(sizeof(double) * ((size_t)m->nq + 1)), *vv = malloc(sizeof(double) * ((size_t)nv + 1));
  double *dv = calloc((size_t)nv + 1, sizeof(double)), *D = calloc((size_t)nv * (size_t)nv + 1, sizeof(double));
  const double h = 1e-6;
  for (int j = 0; j < nv; j++)
    for (int sgn = -1; sgn <= 1; sgn += 2) {
      memcpy(qq, q, sizeof(double) * (size_t)m->nq);
      memcpy(vv, v, sizeof(double) * (size_t)nv);
      if (over_v) {
        vv[j] += sgn * h;
      } else {
        memset(dv, 0, sizeof(double) * (size_t)nv);
        dv[j] = sgn * h;
        mb_model_qincrement(m, qq, dv);
      }
      element_forces(m, qq, vv, sgn > 0 ? fp : fm);
      if (sgn > 0)
        for (int i = 0; i < nv; i++) D[i * nv + j] = -(fp[i] - fm[i]) / (2 * h);
    }
  double num = 0, den = 0, scale = 0;
  for (int k = 0; k < nv * nv; k++) scale = fmax(scale, fabs(D[k]));
  for (int k = 0; k < nv * nv; k++) {
    if (use_col && !use_col[k % nv]) continue;
    num += (T[k] - D[k]) * (T[k] - D[k]);
    den += D[k] * D[k];
    if (fabs(D[k]) > 1e-7 * scale && !has[k])
      fail_msg("entry (%d, %d) = %g of the force tangent is not on the pattern", k / nv, k % nv, D[k]);
  }
  free(fp); free(fm); free(qq); free(vv); free(dv); free(D);
  return sqrt(num / fmax(den, 1e-300));
}

static double compare_fd(const mb_model *m, const double *q, const double *v, int over_v,
                         const double *T, const char *has) {
  return compare_fd_cols(m, q, v, over_v, T, has, NULL);
}

/* Unstressed (t = 0 positions, no velocity: every element's force is zero)
 * the omitted geometric terms, of order |force|, vanish and the stiffness
 * must match to the differences' accuracy; the damping tangent is exact at
 * any velocity (the forces are linear in it).  Loaded (positions moved by
 * about 1e-3 of the elements' lengths) the geometric terms are about that
 * fraction of the stiffness: 2e-3 bounds it. */
static void test_model_tangent(void **state) {
  (void)state;
  const mb_model *m = &tangent_forces_model;
  assert_non_null(m->force_tslot); /* the model asks for genalpha */
  int nv = m->nv;
  double *T = calloc((size_t)nv * (size_t)nv + 1, sizeof(double));
  char *has = calloc((size_t)nv * (size_t)nv + 1, 1);
  double *q = malloc(sizeof(double) * ((size_t)m->nq + 1)), *v = calloc((size_t)nv + 1, sizeof(double));
  double *dv = calloc((size_t)nv + 1, sizeof(double));
  memcpy(q, m->q0, sizeof(double) * (size_t)m->nq);
  assembled(m, q, v, 1, 0, T, has);
  double e_k0 = compare_fd(m, q, v, 0, T, has);
  for (int i = 0; i < nv; i++) v[i] = urand(-1, 1);
  assembled(m, q, v, 0, 1, T, has);
  double e_c = compare_fd(m, q, v, 1, T, has);
  for (int i = 0; i < nv; i++) { dv[i] = urand(-3e-4, 3e-4); v[i] = 0; }
  mb_model_qincrement(m, q, dv);
  assembled(m, q, v, 1, 0, T, has);
  double e_k1 = compare_fd(m, q, v, 0, T, has);
  printf("  relative difference from central differences: stiffness unstressed %.2e, damping %.2e, "
         "stiffness loaded %.2e\n", e_k0, e_c, e_k1);
  assert_true(e_k0 < 1e-6);
  assert_true(e_c < 1e-6);
  assert_true(e_k1 < 2e-3);
  free(T); free(has); free(q); free(v); free(dv);
}

/* The tyre on the quarter car's wheel, pressed 0.1 mm into the road and
 * rolling at 12 m/s, freely and then with 2% slip.  Its translation and
 * velocity columns: the radial spring-damper exactly (the lever r x F
 * included), the slip forces through their slopes, which are exact at free
 * rolling and leave out only the friction's change with the slip (none at
 * the Fiala model's constant friction) below full slide; the contact point's
 * move under a rotation of the wheel is left out (docs/formulation.md, Tyre),
 * so the rotation columns are only checked to lie on the pattern.  Rolling
 * freely the tangent is exact: what is left is the differences' round-off
 * and truncation (measured 5e-10 and 1e-8 relative); 1e-6 bounds both the
 * stiffness (2e8 N/m radial) and the damping (6e4 N s/m radial, the slip
 * slopes K / D with D = 12 m/s) columns.
 * With slip, the slip force's dependence on the load (through the Fiala
 * saturation 1 - K |S| / (3 mu F_z)) is left out too: 1.2e-3 of the tangent
 * at 2% slip, where the slip force is 6% of the load; 1e-2 bounds it, an
 * error a modified Newton iteration absorbs in an extra iteration at most. */
static void test_tyre_tangent(void **state) {
  (void)state;
  const mb_model *m = &tyre_quarter_stiff_model;
  assert_non_null(m->force_tslot);
  int nv = m->nv, w = m->body[0].vadr; /* the wheel */
  double *T = calloc((size_t)nv * (size_t)nv + 1, sizeof(double));
  char *has = calloc((size_t)nv * (size_t)nv + 1, 1), *trans = calloc((size_t)nv + 1, 1);
  double *q = malloc(sizeof(double) * ((size_t)m->nq + 1)), *v = calloc((size_t)nv + 1, sizeof(double));
  double *dv = calloc((size_t)nv + 1, sizeof(double));
  for (int j = 0; j < nv; j++) trans[j] = (j % 6) < 3; /* rigid bodies: 6 columns each */
  for (int c = 0; c < 2; c++) {
    memcpy(q, m->q0, sizeof(double) * (size_t)m->nq);
    memset(dv, 0, sizeof(double) * (size_t)nv);
    dv[w + 2] = -1e-4;
    mb_model_qincrement(m, q, dv);
    double Re = 0.3213 - (1e-4 + 1.96e-6) / 3;
    memset(v, 0, sizeof(double) * (size_t)nv);
    v[w + 0] = 12;
    v[w + 4] = 12 / Re * (c ? 1.02 : 1); /* spin about the axle, y */
    assembled(m, q, v, 1, 0, T, has);
    double e_k = compare_fd_cols(m, q, v, 0, T, has, trans);
    assembled(m, q, v, 0, 1, T, has);
    double e_c = compare_fd(m, q, v, 1, T, has);
    printf("  tyre %s: relative difference from central differences: stiffness (translations) "
           "%.2e, damping %.2e\n", c ? "at 2% slip" : "rolling freely", e_k, e_c);
    assert_true(e_k < (c ? 1e-2 : 1e-6));
    assert_true(e_c < (c ? 1e-2 : 1e-6));
  }
  free(T); free(has); free(trans); free(q); free(v); free(dv);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_spring_tangent),
      cmocka_unit_test(test_field_tangent),
      cmocka_unit_test(test_model_tangent),
      cmocka_unit_test(test_tyre_tangent),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
