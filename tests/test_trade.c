/* test_trade.c: `mbcc trade` (compiler/tools/trade_metric.c, compiler/tools/trade.c):
 * - the error metric on synthetic data with hand-derived answers (ranges,
 *   vector columns sharing a scale, the fallbacks, RMS, NaN = failure);
 * - the Pareto front on a hand-drawn set (ties, failed runs) and, on random
 *   sets, its defining properties; the cheapest run meeting an error target;
 * - end to end on the pendulum released at 90 degrees, whose angle has the
 *   closed form theta(t) = 2 asin(k sn(K - w0 t, k)), k = sin(theta0 / 2)
 *   (from the bottom; sn by the descending Landen / AGM method): the error
 *   the study reports for its reference (reference against a run 100x
 *   stricter) must match the reference's true error against the closed form.
 *   Criterion: with a loose reference (rtol 1e-6, output step 0.1 s, so the
 *   error is far above the 12 printed digits) true / reported lies in
 *   [0.5, 2]: the stricter run is accurate enough that the difference is the
 *   reference's error; with the default reference (rtol 1e-10) the true error
 *   is at most twice the reported one plus the CSV's print rounding (1e-11). */
#include "../compiler/tools/trade_metric.c"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "support.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* --- the error metric ---------------------------------------------------------- */

static void test_error_metric(void **state) {
  (void)state;
  /* column a: 0 1 2 3 (range 3); column b: constant 10 (no range: measured
     against |10|); the run is off by 0.3 in a at row 1 and by 0.5 in b at row 3 */
  const double ref[] = {0, 10, 1, 10, 2, 10, 3, 10};
  const double run[] = {0, 10, 1.3, 10, 2, 10, 3, 10.5};
  const char *names[] = {"a", "b"};
  int group[2];
  double scale[2];
  trade_column_groups(names, 2, group);
  assert_int_equal(group[0], 0);
  assert_int_equal(group[1], 1);
  trade_column_scales(ref, 4, 2, group, scale);
  assert_close(scale[0], 3.0, 1e-15);
  assert_close(scale[1], 10.0, 1e-15);
  trade_error e;
  assert_int_equal(trade_compare(ref, run, 4, 2, scale, &e), 0);
  assert_close(e.max_err, 0.1, 1e-14);          /* 0.3 / 3 beats 0.5 / 10 */
  assert_int_equal(e.worst_col, 0);
  assert_close(e.rms_err, sqrt((0.1 * 0.1 + 0.05 * 0.05) / 8), 1e-14); /* over all 8 samples */
  /* the same run is no error at all */
  assert_int_equal(trade_compare(ref, ref, 4, 2, scale, &e), 0);
  assert_true(e.max_err == 0 && e.rms_err == 0);
  /* a NaN anywhere is a failed run */
  double bad[8];
  memcpy(bad, run, sizeof bad);
  bad[5] = NAN;
  assert_int_equal(trade_compare(ref, bad, 4, 2, scale, &e), -1);
}

static void test_vector_columns_share_a_scale(void **state) {
  (void)state;
  /* p.x moves over 4, p.y over 1, p.z not at all; z gets the vector's range
     (so round-off out of the plane is not blown up), 'c' its own, and an
     all-zero column is measured in absolute terms (scale 1) */
  const char *names[] = {"p.x", "p.y", "p.z", "c", "zero"};
  const double ref[] = {0, 0, 0, 5, 0,   4, 1, 0, 7, 0};
  int group[5];
  double scale[5];
  trade_column_groups(names, 5, group);
  assert_int_equal(group[1], group[0]);
  assert_int_equal(group[2], group[0]);
  assert_true(group[3] != group[0] && group[4] != group[3]);
  trade_column_scales(ref, 2, 5, group, scale);
  assert_close(scale[0], 4, 0);
  assert_close(scale[1], 4, 0);
  assert_close(scale[2], 4, 0);
  assert_close(scale[3], 2, 0);
  assert_close(scale[4], 1, 0);
}

/* --- the Pareto front --------------------------------------------------------------- */

static void test_pareto_hand_drawn(void **state) {
  (void)state;
  /*          A     B     C     D     E     F(failed) G (= B) H (slower than B, as accurate) */
  double cpu[] = {1, 2, 3, 0.5, 4, 0.1, 2, 2.5};
  double err[] = {1e-2, 1e-3, 1e-3, 1e-1, 1e-5, 1e-9, 1e-3, 1e-3};
  int failed[] = {0, 0, 0, 0, 0, 1, 0, 0};
  int expect[] = {1, 1, 0, 1, 1, 0, 1, 0};
  int pareto[8];
  trade_pareto(cpu, err, failed, 8, pareto);
  for (int i = 0; i < 8; i++) {
    if (pareto[i] != expect[i]) print_error("run %c: pareto %d, expected %d\n", 'A' + i, pareto[i], expect[i]);
    assert_int_equal(pareto[i], expect[i]);
  }
  /* the cheapest meeting a target: a precision target first, then CPU time */
  assert_int_equal(trade_cheapest(cpu, err, failed, 8, 1e-2), 0);  /* A: 1 s */
  assert_int_equal(trade_cheapest(cpu, err, failed, 8, 5e-3), 1);  /* B (G ties, B first) */
  assert_int_equal(trade_cheapest(cpu, err, failed, 8, 1e-4), 4);  /* E */
  assert_int_equal(trade_cheapest(cpu, err, failed, 8, 1e-1), 3);  /* D: 0.5 s */
  assert_int_equal(trade_cheapest(cpu, err, failed, 8, 1e-8), -1); /* only F, and it failed */
}

static void test_pareto_properties(void **state) {
  (void)state;
  enum { N = 60 };
  for (int trial = 0; trial < 50; trial++) {
    double cpu[N], err[N];
    int failed[N], pareto[N];
    for (int i = 0; i < N; i++) {
      /* coarse values, so that ties happen */
      cpu[i] = floor(urand(1, 20));
      err[i] = pow(10, -floor(urand(1, 12)));
      failed[i] = urand(0, 1) < 0.15;
    }
    trade_pareto(cpu, err, failed, N, pareto);
    for (int i = 0; i < N; i++) {
      int dominated = 0;
      for (int j = 0; j < N; j++)
        dominated |= !failed[j] && cpu[j] <= cpu[i] && err[j] <= err[i] && (cpu[j] < cpu[i] || err[j] < err[i]);
      assert_int_equal(pareto[i], !failed[i] && !dominated);
    }
    /* along the front, more CPU time buys strictly less error */
    for (int i = 0; i < N; i++)
      for (int j = 0; j < N; j++)
        if (pareto[i] && pareto[j] && cpu[i] < cpu[j]) assert_true(err[j] < err[i]);
    /* the cheapest run meeting a target is on the front */
    for (double target = 1e-1; target > 1e-12; target /= 10) {
      int b = trade_cheapest(cpu, err, failed, N, target);
      if (b < 0) {
        for (int i = 0; i < N; i++) assert_true(failed[i] || err[i] > target);
      } else {
        assert_true(pareto[b] && err[b] <= target);
      }
    }
  }
}

/* --- the closed form --------------------------------------------------------------- */

/* sn(u, k) by the descending Landen transformation (arithmetic-geometric mean),
 * and K(k) = pi / (2 AGM(1, k')) */
static double jacobi_sn(double u, double k, double *K) {
  double a[40], c[40];
  a[0] = 1;
  double b = sqrt(1 - k * k);
  c[0] = k;
  int n = 0;
  while (fabs(c[n]) > 1e-16 && n < 38) {
    a[n + 1] = 0.5 * (a[n] + b);
    c[n + 1] = 0.5 * (a[n] - b);
    b = sqrt(a[n] * b);
    n++;
  }
  *K = M_PI / (2 * a[n]);
  double phi = ldexp(1.0, n) * a[n] * u;
  for (int i = n; i > 0; i--) phi = 0.5 * (phi + asin(c[i] / a[i] * sin(phi)));
  return sin(phi);
}

static void test_jacobi_sn(void **state) {
  (void)state;
  double K;
  /* k = 0: sin; sn(K) = 1; sn(u) for k -> 1 is tanh u; K(1/sqrt 2) = 1.854074677301372 */
  assert_close(jacobi_sn(0.7, 0, &K), sin(0.7), 1e-15);
  assert_close(K, M_PI / 2, 1e-15);
  jacobi_sn(0, sqrt(0.5), &K);
  assert_close(K, 1.854074677301372, 1e-14);
  assert_close(jacobi_sn(K, sqrt(0.5), &K), 1.0, 1e-14);
  assert_close(jacobi_sn(0.9, 1 - 1e-12, &K), tanh(0.9), 1e-9);
}

/* the reference's true error against the closed form, on the study's metric
 * (relative to the range of the reference's angle); its reported error */
static void pendulum_errors(const char *extra, double *true_err, double *reported) {
  const char *mbcc = getenv("MBCC") ? getenv("MBCC") : "build/mbcc";
  char dir[256], cmd[1024], out[8192];
  snprintf(dir, sizeof dir, "%s/mbcc_trade_%d", getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp", (int)getpid());
  snprintf(cmd, sizeof cmd,
           "%s trade models/pendulum.yaml --outputs angle --reps 1 --integrators dopri5@1e-6 --reals double "
           "--solvers ldl --workdir %s --plot none --quiet %s",
           mbcc, dir, extra);
  int rc = run_capture(cmd, out, sizeof out);
  if (rc) print_error("%s\n", out);
  assert_int_equal(rc, 0);
  const char *line = strstr(out, "reference error: max_err ");
  assert_non_null(line);
  *reported = strtod(line + strlen("reference error: max_err "), NULL);
  char path[300];
  snprintf(path, sizeof path, "%s/reference.csv", dir);
  FILE *f = fopen(path, "r");
  assert_non_null(f);
  char row[4096];
  assert_non_null(fgets(row, sizeof row, f));
  assert_true(!strncmp(row, "t,angle,", 8));
  double t[4000], angle[4000], exact[4000];
  int n = 0;
  /* pendulum.yaml: a 1 kg bob 1 m from the pivot with 1e-4 kg m^2 about its
     centre, g = 9.81, released from rest horizontal (theta0 = 90 degrees from
     the bottom); the output is the rotation from there, theta - theta0 */
  const double theta0 = M_PI / 2, w0 = sqrt(9.81 * 1.0 / (1.0 + 1e-4)), k = sin(theta0 / 2);
  double K;
  jacobi_sn(0, k, &K);
  while (n < 4000 && fgets(row, sizeof row, f) && sscanf(row, "%lf,%lf", &t[n], &angle[n]) == 2) {
    double unused;
    exact[n] = 2 * asin(k * jacobi_sn(K - w0 * t[n], k, &unused)) - theta0;
    n++;
  }
  fclose(f);
  assert_true(n > 10);
  snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
  assert_int_equal(system(cmd), 0);
  /* the reference's scale, then the metric with the closed form as the truth */
  const char *names[] = {"angle"};
  int group[1];
  double scale[1];
  trade_column_groups(names, 1, group);
  trade_column_scales(angle, n, 1, group, scale);
  /* the swing spans [-pi, 0] */
  assert_close(scale[0], M_PI, 1e-2); /* sampled: the extremes fall between output times */
  trade_error e;
  assert_int_equal(trade_compare(exact, angle, n, 1, scale, &e), 0);
  *true_err = e.max_err;
}

static void test_reference_error_matches_closed_form(void **state) {
  (void)state;
  double true_err, reported;
  /* a loose reference: its error far above print rounding */
  pendulum_errors("--ref-rtol 1e-6 --output-step 0.1", &true_err, &reported);
  print_message("loose reference: true error %.3e, reported %.3e\n", true_err, reported);
  assert_true(true_err > 1e-8);
  assert_true(true_err >= 0.5 * reported && true_err <= 2 * reported);
  /* the default reference: at most twice its report plus print rounding */
  pendulum_errors("--end 2", &true_err, &reported);
  print_message("default reference: true error %.3e, reported %.3e\n", true_err, reported);
  assert_true(true_err <= 2 * reported + 1e-11);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_error_metric),
      cmocka_unit_test(test_vector_columns_share_a_scale),
      cmocka_unit_test(test_pareto_hand_drawn),
      cmocka_unit_test(test_pareto_properties),
      cmocka_unit_test(test_jacobi_sn),
      cmocka_unit_test(test_reference_error_matches_closed_form),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
