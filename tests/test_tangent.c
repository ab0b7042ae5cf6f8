/* test_tangent.c: the force kernels' tangents (runtime/core/elements/) against
 * central finite differences of the same kernels' forces: the spring-damper's
 * dF1/dd and dF1/d(dd) with linear, power and table laws, and the field's 6x6
 * derivatives of marker 1's wrench with respect to its displacement, rotation,
 * velocity and angular velocity, at a large relative rotation (the inverse
 * left Jacobian of the rotation vector) and at a tiny one (its series). */
#include <math.h>
#include <string.h>

#include "support.h"
#include "mb_model.h"

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

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_spring_tangent),
      cmocka_unit_test(test_field_tangent),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
