/* test_outputs.c: the output kinds ADAMS users ask for (force, relative,
 * joint, center_of_mass, a flexible node's acceleration), each against an
 * independent truth:
 *   - a spring_damper's force against k (L - L0) + c Ld + preload, with L and
 *     Ld from the position and velocity outputs of its end points;
 *   - a bushing's force against -K u - C ud, with u and ud the relative
 *     displacement and velocity outputs in body a's axes (its frame);
 *   - a point force and a body-fixed torque against their definitions;
 *   - relative displacement, velocity and acceleration (in a turning body's
 *     axes) against central differences of each other, and against closed
 *     forms on driven joints; joint angle (unwrapped over two turns) and
 *     travel against the driver profiles;
 *   - the centre of mass: its velocity against differences of its position,
 *     its acceleration against g + (external force) / M on a free system (the
 *     applied point force) and on pendulums (the pivot or hinge reaction);
 *   - a spring holding a body at rest carries m g;
 *   - a flexible body's node acceleration against differences of the node's
 *     velocity, and of its position;
 *   - mb_force_wrench and the generic path give the generated path's numbers.
 * Physical parameters are those written in the YAML files. */
// models: outputs_free outputs_driven outputs_pendulum outputs_flexible
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "support.h"
#include "outputs_free.h"
#include "outputs_driven.h"
#include "outputs_pendulum.h"
#include "outputs_flexible.h"

static void run(const mb_model *m, double end, double step, trajectory *tr) {
  mb_settings s;
  test_settings(&s, end, step);
  s.rtol = 1e-10;
  s.atol = 1e-12;
  assert_int_equal(simulate(m, &s, "ldl", tr), MB_OK);
}

static int col(const mb_model *m, const char *name) {
  int c = column(m, name);
  if (c < 0) print_error("no column %s\n", name);
  assert_true(c >= 0);
  return c;
}

/* value of the 3 columns from 'first' at row k */
static void vec3_at(const trajectory *tr, int k, int first, double x[3]) {
  for (int j = 0; j < 3; j++) x[j] = at(tr, k, first + j);
}

/* rotation matrix (row-major) of normalized Euler parameters */
static void quat_to_R(const double e[4], double R[9]) {
  double e0 = e[0], e1 = e[1], e2 = e[2], e3 = e[3];
  R[0] = 1 - 2 * (e2 * e2 + e3 * e3); R[1] = 2 * (e1 * e2 - e0 * e3); R[2] = 2 * (e1 * e3 + e0 * e2);
  R[3] = 2 * (e1 * e2 + e0 * e3); R[4] = 1 - 2 * (e1 * e1 + e3 * e3); R[5] = 2 * (e2 * e3 - e0 * e1);
  R[6] = 2 * (e1 * e3 - e0 * e2); R[7] = 2 * (e2 * e3 + e0 * e1); R[8] = 1 - 2 * (e1 * e1 + e2 * e2);
}

/* Largest |central difference of column a - column b| over the interior rows,
 * relative to the largest |b| (at least 1e-6): the check that b is the time
 * derivative of a.  Fourth-order differences over 5 rows (error h^4 a^(5) / 30)
 * on the uniform output times. */
static double derivative_mismatch(const trajectory *tr, int a, int b) {
  double worst = 0, scale = 1e-3, h = tr->t[1] - tr->t[0];
  for (int k = 2; k + 2 < tr->nrows; k++) {
    double fd = (-at(tr, k + 2, a) + 8 * at(tr, k + 1, a) - 8 * at(tr, k - 1, a) + at(tr, k - 2, a)) / (12 * h);
    worst = fmax(worst, fabs(fd - at(tr, k, b)));
    scale = fmax(scale, fabs(at(tr, k, b)));
  }
  return worst / scale;
}

/* the same for b the second derivative of a (error h^4 a^(6) / 90) */
static double second_derivative_mismatch(const trajectory *tr, int a, int b) {
  double worst = 0, scale = 1e-3, h = tr->t[1] - tr->t[0];
  for (int k = 2; k + 2 < tr->nrows; k++) {
    double fd = (-at(tr, k + 2, a) + 16 * at(tr, k + 1, a) - 30 * at(tr, k, a) + 16 * at(tr, k - 1, a) -
                 at(tr, k - 2, a)) / (12 * h * h);
    worst = fmax(worst, fabs(fd - at(tr, k, b)));
    scale = fmax(scale, fabs(at(tr, k, b)));
  }
  return worst / scale;
}

static void check_derivatives(const trajectory *tr, const mb_model *m, const char *pos, const char *vel,
                              const char *acc, double tol) {
  const char *xyz[3] = {"x", "y", "z"};
  char a[64], b[64], c[64];
  for (int j = 0; j < 3; j++) {
    snprintf(a, sizeof a, "%s.%s", pos, xyz[j]);
    snprintf(b, sizeof b, "%s.%s", vel, xyz[j]);
    if (acc) snprintf(c, sizeof c, "%s.%s", acc, xyz[j]);
    double e1 = derivative_mismatch(tr, col(m, a), col(m, b));
    double e2 = acc ? derivative_mismatch(tr, col(m, b), col(m, c)) : 0;
    double e3 = acc ? second_derivative_mismatch(tr, col(m, a), col(m, c)) : 0;
    if (e1 > tol || e2 > tol || e3 > tol)
      print_error("%s: d/dt mismatch %.3g, %s: %.3g, second difference %.3g\n", b, e1, acc ? c : "-", e2, e3);
    assert_true(e1 <= tol && e2 <= tol && e3 <= tol);
  }
}

static void spring_and_bushing(void **state) {
  (void)state;
  const mb_model *m = &outputs_free_model;
  trajectory tr;
  run(m, 0.5, 0.001, &tr);
  int sf = col(m, "spring_force.fx"), st = col(m, "spring_tension"), sz = col(m, "spring_fz");
  int e0 = col(m, "end0.x"), e1 = col(m, "end1.x"), v0 = col(m, "end0_v.x"), v1 = col(m, "end1_v.x");
  int mf = col(m, "mount_force.fx"), qa = col(m, "a_orientation.e0");
  int u = col(m, "b_in_a.x"), ud = col(m, "b_in_a_v.x");
  const double K[3] = {3000, 2000, 4000}, C[3] = {5, 4, 3};
  double tmax = 0, fmax_b = 0;
  for (int k = 0; k < tr.nrows; k++) {
    double p0[3], p1[3], w0[3], w1[3], d[3], L = 0, Ld = 0;
    vec3_at(&tr, k, e0, p0); vec3_at(&tr, k, e1, p1); vec3_at(&tr, k, v0, w0); vec3_at(&tr, k, v1, w1);
    for (int j = 0; j < 3; j++) { d[j] = p1[j] - p0[j]; L += d[j] * d[j]; }
    L = sqrt(L);
    for (int j = 0; j < 3; j++) Ld += d[j] / L * (w1[j] - w0[j]);
    double T = 800 * (L - 0.25) + 6 * Ld + 3;
    tmax = fmax(tmax, fabs(T));
    assert_close(at(&tr, k, st), T, 1e-9 * fabs(T) + 1e-9);
    for (int j = 0; j < 3; j++) { /* on body b (body 1): -T n */
      assert_close(at(&tr, k, sf + j), -T * d[j] / L, 1e-9 * fabs(T) + 1e-9);
      assert_close(at(&tr, k, sf + 3 + j), 0, 1e-12);
    }
    assert_close(at(&tr, k, sz), at(&tr, k, sf + 2), 0);
    /* bushing, translations: R_a (-K u - C ud), u and ud in a's axes */
    double e[4], R[9], fl[3], uu[3], uv[3];
    vec3_at(&tr, k, u, uu); vec3_at(&tr, k, ud, uv);
    for (int j = 0; j < 4; j++) e[j] = at(&tr, k, qa + j);
    quat_to_R(e, R);
    for (int j = 0; j < 3; j++) fl[j] = -K[j] * uu[j] - C[j] * uv[j];
    for (int i = 0; i < 3; i++) {
      double f = R[3 * i] * fl[0] + R[3 * i + 1] * fl[1] + R[3 * i + 2] * fl[2];
      fmax_b = fmax(fmax_b, fabs(f));
      assert_close(at(&tr, k, mf + i), f, 1e-8 * (fabs(f) + 1));
    }
  }
  assert_true(tmax > 10 && fmax_b > 1); /* the elements do work: the checks are not vacuous */
  /* the relative motion in a's axes: velocity and acceleration are its derivatives */
  check_derivatives(&tr, m, "b_in_a", "b_in_a_v", "b_in_a_a", 3e-4);
  trajectory_free(&tr);
}

static void applied_loads_and_center_of_mass(void **state) {
  (void)state;
  const mb_model *m = &outputs_free_model;
  trajectory tr;
  run(m, 0.5, 0.001, &tr);
  int pf = col(m, "push_force.fx"), tq = col(m, "twist_torque.fx"), qb = col(m, "b_orientation.e0");
  int cm = col(m, "cm.x"), ca = col(m, "cm_a.x"), cby = col(m, "cm_b"), pa = col(m, "a_pos.x"), pb = col(m, "b_pos.x");
  const double ma = 2.0, mb = 1.5, M = ma + mb, g[3] = {0, 0, -9.81}, push[3] = {2, -1, 3}, twist[3] = {0, 0.2, -0.1};
  for (int k = 0; k < tr.nrows; k++) {
    double s = sin(2 * MB_PI * 3 * tr.t[k]), e[4], R[9];
    for (int j = 0; j < 4; j++) e[j] = at(&tr, k, qb + j);
    quat_to_R(e, R);
    for (int i = 0; i < 3; i++) {
      double Tg = R[3 * i] * twist[0] + R[3 * i + 1] * twist[1] + R[3 * i + 2] * twist[2];
      assert_close(at(&tr, k, pf + i), push[i] * s, 1e-12);
      assert_close(at(&tr, k, pf + 3 + i), 0, 0);
      assert_close(at(&tr, k, tq + i), 0, 0);
      assert_close(at(&tr, k, tq + 3 + i), Tg, 1e-9);
      /* the internal forces cancel: M a_cm = M g + the point force */
      assert_close(at(&tr, k, ca + i), g[i] + push[i] * s / M, 1e-7);
      assert_close(at(&tr, k, cm + i), (ma * at(&tr, k, pa + i) + mb * at(&tr, k, pb + i)) / M, 1e-12);
    }
    assert_close(at(&tr, k, cby), at(&tr, k, pb + 1), 1e-12);
  }
  check_derivatives(&tr, m, "cm", "cm_v", "cm_a", 1e-5);
  trajectory_free(&tr);
}

static void driven_closed_forms(void **state) {
  (void)state;
  const mb_model *m = &outputs_driven_model;
  trajectory tr;
  run(m, 0.5, 0.001, &tr);
  int d = col(m, "slider_in_table.x"), dv = col(m, "slider_in_table_v.x"), da = col(m, "slider_in_table_a.x");
  int sx = col(m, "slider_x"), svx = col(m, "slider_vx"), sax = col(m, "slider_ax");
  int ang = col(m, "spin_angle"), trv = col(m, "rail_travel"), qa = col(m, "quill_motion.angle"),
      qt = col(m, "quill_motion.travel");
  const double w = 25, A = 0.2, om = 4 * MB_PI, X0 = 0.5;
  for (int k = 0; k < tr.nrows; k++) {
    double t = tr.t[k], th = w * t, c = cos(th), s = sin(th);
    double X = X0 + A * sin(om * t), Xd = A * om * cos(om * t), Xdd = -A * om * om * sin(om * t);
    /* slider point (X, 0, 0.3) seen from the table's origin in its axes: Rz(th)^T */
    double dx = X * c - X0, dy = -X * s;
    double vx = Xd * c - X * w * s, vy = -Xd * s - X * w * c;
    double ax = Xdd * c - 2 * Xd * w * s - X * w * w * c, ay = -Xdd * s - 2 * Xd * w * c + X * w * w * s;
    assert_close(at(&tr, k, d), dx, 1e-8);
    assert_close(at(&tr, k, d + 1), dy, 1e-8);
    assert_close(at(&tr, k, d + 2), 0, 1e-8);
    assert_close(at(&tr, k, dv), vx, 1e-6);
    assert_close(at(&tr, k, dv + 1), vy, 1e-6);
    assert_close(at(&tr, k, da), ax, 1e-4);
    assert_close(at(&tr, k, da + 1), ay, 1e-4);
    assert_close(at(&tr, k, sx), X - X0, 1e-8);
    assert_close(at(&tr, k, svx), Xd, 1e-6);
    assert_close(at(&tr, k, sax), Xdd, 1e-4);
    assert_close(at(&tr, k, ang), th, 1e-8); /* unwrapped: reaches 12.5 rad */
    assert_close(at(&tr, k, trv), A * sin(om * t), 1e-8);
    assert_close(at(&tr, k, qa), -30 * t * t, 1e-8);
    assert_close(at(&tr, k, qt), 0.1 * t + 0.4 * t * t, 1e-8);
  }
  assert_true(at(&tr, tr.nrows - 1, ang) > 12);
  check_derivatives(&tr, m, "slider_in_table", "slider_in_table_v", "slider_in_table_a", 2e-4);
  trajectory_free(&tr);
}

static void pendulum_and_hanging_body(void **state) {
  (void)state;
  const mb_model *m = &outputs_pendulum_model;
  trajectory tr;
  run(m, 1.0, 0.002, &tr);
  int ca = col(m, "cm_a.x"), pf = col(m, "pivot_force.fx"), pj = col(m, "pivot_angle"), ua = col(m, "upper_angle");
  int hf = col(m, "hanger_force.fx"), ht = col(m, "hanger_tension"), bp = col(m, "bob_position.x");
  const double M = 1.0 + 0.7, g[3] = {0, -9.81, 0}, mg = 2.0 * 9.81;
  double swing = 0;
  for (int k = 0; k < tr.nrows; k++) {
    for (int i = 0; i < 3; i++) /* gravity and the pivot reaction are the external forces */
      assert_close(at(&tr, k, ca + i), g[i] + at(&tr, k, pf + i) / M, 1e-7);
    assert_close(at(&tr, k, pj), at(&tr, k, ua), 1e-9);
    swing = fmax(swing, fabs(at(&tr, k, pj)));
    /* the spring holds the bob at rest: it carries the weight, upwards */
    assert_close(at(&tr, k, hf), 0, 1e-9);
    assert_close(at(&tr, k, hf + 1), mg, 1e-6);
    assert_close(at(&tr, k, hf + 2), 0, 1e-9);
    assert_close(at(&tr, k, ht), mg, 1e-6);
    assert_close(at(&tr, k, bp + 1), 0.48038, 1e-9);
  }
  assert_true(swing > 1); /* the pendulum swings through a large angle */
  trajectory_free(&tr);
}

static void flexible_node_and_center_of_mass(void **state) {
  (void)state;
  const mb_model *m = &outputs_flexible_model;
  trajectory tr;
  run(m, 0.3, 0.0001, &tr);
  check_derivatives(&tr, m, "tip", "tip_v", "tip_a", 1e-4);
  check_derivatives(&tr, m, "cm", "cm_v", "cm_a", 1e-4);
  const char *xyz[3] = {"tip_rel_d.x", "tip_rel_d.y", "tip_rel_d.z"}, *axyz[3] = {"tip_rel.x", "tip_rel.y", "tip_rel.z"};
  for (int j = 0; j < 2; j++) {
    double e = second_derivative_mismatch(&tr, col(m, xyz[j]), col(m, axyz[j]));
    if (e > 1e-3) print_error("%s: second difference mismatch %.3g\n", axyz[j], e);
    assert_true(e <= 1e-3);
  }
  int ca = col(m, "cm_a.x"), hf = col(m, "hinge_force.fx");
  const double M = 2700 * 0.0002 * 1.0, g[3] = {0, -9.81, 0};
  for (int k = 0; k < tr.nrows; k++)
    for (int i = 0; i < 3; i++) assert_close(at(&tr, k, ca + i), g[i] + at(&tr, k, hf + i) / M, 1e-6);
  trajectory_free(&tr);
}

/* mb_force_wrench at the initial state, and the generic path's outputs */
static void wrench_and_generic_path(void **state) {
  (void)state;
  const mb_model *m = &outputs_free_model;
  trajectory tr, tg;
  run(m, 0.1, 0.001, &tr);
  void *work = malloc(mb_model_worksize(m) + 16);
  double F[3], T[3];
  int sf = col(m, "spring_force.fx"), mf = col(m, "mount_force.fx");
  mb_force_wrench(m, 0, 0, m->q0, m->v0, F, T, work); /* spring */
  for (int j = 0; j < 3; j++) { assert_close(F[j], at(&tr, 0, sf + j), 1e-12); assert_close(T[j], 0, 0); }
  mb_force_wrench(m, 1, 0, m->q0, m->v0, F, T, work); /* bushing */
  for (int j = 0; j < 3; j++) {
    assert_close(F[j], at(&tr, 0, mf + j), 1e-12);
    assert_close(T[j], at(&tr, 0, mf + 3 + j), 1e-12);
  }
  /* at the initial state itself (the very array q0), the displacement is 0 */
  double *out = calloc((size_t)m->ncols, sizeof(double)), *zero = calloc((size_t)(m->nv + m->nc + 1), sizeof(double));
  mb_model_outputs(m, 0, m->q0, m->v0, zero, zero, NULL, out, work);
  int u = col(m, "b_in_a.x");
  for (int j = 0; j < 3; j++) assert_close(out[u + j], 0, 0);
  free(out);
  free(zero);
  free(work);
  trajectory_free(&tr);
  const mb_model *models[3] = {&outputs_free_model, &outputs_driven_model, &outputs_flexible_model};
  for (int i = 0; i < 3; i++) {
    mb_model g = generic_twin(models[i]);
    run(models[i], 0.1, 0.001, &tr);
    mb_settings s;
    test_settings(&s, 0.1, 0.001);
    s.rtol = 1e-10;
    s.atol = 1e-12;
    assert_int_equal(simulate(&g, &s, "klu", &tg), MB_OK);
    const char *worst;
    double diff = max_rel_diff(models[i], &tr, &tg, &worst);
    if (diff > 1e-6) print_error("%s: generic path differs by %.3g in %s\n", models[i]->name, diff, worst);
    assert_true(diff <= 1e-6);
    trajectory_free(&tr);
    trajectory_free(&tg);
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(spring_and_bushing),
      cmocka_unit_test(applied_loads_and_center_of_mass),
      cmocka_unit_test(driven_closed_forms),
      cmocka_unit_test(pendulum_and_hanging_body),
      cmocka_unit_test(flexible_node_and_center_of_mass),
      cmocka_unit_test(wrench_and_generic_path),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
