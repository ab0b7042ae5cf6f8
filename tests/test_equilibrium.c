/* test_equilibrium.c: static equilibrium before a dynamic run
 * (runtime/hosted/equilibrium.c, simulation: {equilibrium: true}, --equilibrium),
 * against statics worked out by hand:
 *   - a body on four vertical corner springs with its centre of mass off the
 *     middle ("car on springs"): the spring forces balance the weight and its
 *     moments to 1e-6 of the weight, and match the rigid-plate closed form;
 *   - a pendulum released 30 degrees off hangs straight down, the pivot
 *     carrying its weight;
 *   - a slider-crank held by a spring against a crank torque: virtual work;
 *   - a clamped flexible cantilever under gravity: the modal coordinates are
 *     the modal static solution w_j = S1_j . g / omega_j^2, and the tip
 *     deflection the closed form q L^4 / (8 E I) within the modal truncation;
 *   - every case then runs dynamically and stays at rest;
 *   - models/pendulum.yaml, released horizontally (a turning point: the
 *     tangent is singular there), hangs straight down too;
 *   - the command line: the model's own setting (a scene) on the generated
 *     simulator, and a body free under gravity, which has no equilibrium:
 *     stopped with the cause, exit status nonzero, no results file.
 * Physical data are those written in the YAML files. */
// models: equilibrium_car equilibrium_pendulum equilibrium_slider_crank cantilever_gravity
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "support.h"
#include "equilibrium_car.h"
#include "equilibrium_pendulum.h"
#include "equilibrium_slider_crank.h"
#include "cantilever_gravity.h"

static const char *mbcc(void) {
  const char *m = getenv("MBCC");
  return m && *m ? m : "build/mbcc";
}

/* the output rows of a run: the first (the equilibrium state) and the
   largest change of any column from it */
typedef struct {
  const mb_model *m;
  double *first, *row;
  double drift;
  int nrows;
  void *work;
} rows;

static int keep_row(void *user, double t, const mb_real *q, const mb_real *v, const mb_real *vd,
                    const mb_real *lambda) {
  rows *r = user;
  (void)t;
  mb_model_outputs(r->m, t, q, v, vd, lambda, NULL, r->row, r->work);
  for (int j = 0; j < r->m->ncols; j++) {
    if (r->nrows == 0) r->first[j] = r->row[j];
    else r->drift = fmax(r->drift, fabs(r->row[j] - r->first[j]));
  }
  r->nrows++;
  return 0;
}

/* equilibrium, then a dynamic run of end_time; the state at the start (the
   model's initial one) in q_start (nq reals), the equilibrium's in q_eq */
static void settle_and_run(const mb_model *m, double end_time, mb_equilibrium_info *info, rows *r,
                           double *q_start, double *q_eq) {
  mb_settings s;
  test_settings(&s, end_time, end_time / 100);
  assert_true(m->nq <= 256); /* the callers' q_start, q_eq */
  mb_solver *ls = mb_solver_new("ldl", m);
  assert_non_null(ls);
  memset(r, 0, sizeof *r);
  r->m = m;
  r->first = calloc((size_t)m->ncols + 1, sizeof(double));
  r->row = calloc((size_t)m->ncols + 1, sizeof(double));
  r->work = malloc(mb_model_worksize(m) + 16);
  mb_sim sim;
  assert_int_equal(mb_sim_init(&sim, m, ls, &s), MB_OK);
  for (int i = 0; i < m->nq; i++) q_start[i] = (double)sim.q[i];
  int st = mb_sim_equilibrium(&sim, info);
  if (st) print_error("%s: %s\n", m->name, info->why);
  assert_int_equal(st, MB_OK);
  for (int i = 0; i < m->nq; i++) q_eq[i] = (double)sim.q[i];
  print_message("%s: equilibrium in %d iterations, force residual %.3g of %.6g N, constraint "
                "residual %.3g, %d free directions\n", m->name, info->iterations, info->force_residual,
                info->force_scale, info->constraint_residual, info->free_directions);
  st = mb_sim_run(&sim, keep_row, r);
  if (st) print_error("%s: dynamic run failed: %s\n", m->name, sim.fail_detail);
  assert_int_equal(st, MB_OK);
  print_message("%s: largest change of an output over the %g s after the equilibrium: %.3g\n", m->name,
                end_time, r->drift);
  mb_sim_free(&sim);
  ls->destroy(ls);
}

static void rows_free(rows *r) { free(r->first); free(r->row); free(r->work); }

static int col(const mb_model *m, const char *name) {
  int c = column(m, name);
  if (c < 0) print_error("%s has no output column '%s'\n", m->name, name);
  assert_true(c >= 0);
  return c;
}

/* ---------------------------------------------------------------------------
 * The car on springs (tests/models/equilibrium_car.yaml): 1200 kg, centre of
 * mass at (0.30, 0.10, 0.5), springs k = 5e5 N/m, free length 0.3 m, from
 * (+-1.3, +-0.75, 0.2) on the ground to the same x, y at z = 0.5 on the body.
 * ------------------------------------------------------------------------- */
static void test_car_on_springs(void **state) {
  (void)state;
  const mb_model *m = &equilibrium_car_model;
  const double mass = 1200, g = 9.81, k = 5e5, L0 = 0.3, a = 1.3, b = 0.75, xc = 0.30, yc = 0.10;
  const double W = mass * g;
  const double corner[4][2] = {{a, b}, {a, -b}, {-a, b}, {-a, -b}};
  const char *name[4] = {"fl", "fr", "rl", "rr"};
  mb_equilibrium_info info;
  rows r;
  double q0[256], qe[256];
  settle_and_run(m, 1.0, &info, &r, q0, qe);
  double cg[3], sum[3] = {0, 0, 0}, moment[3] = {0, 0, 0}, worst_closed = 0;
  char cn[32];
  for (int j = 0; j < 3; j++) {
    snprintf(cn, sizeof cn, "cg.%c", "xyz"[j]);
    cg[j] = r.first[col(m, cn)];
  }
  /* it started level and 6 mm too high: the equilibrium moved it */
  assert_true(0.5 - cg[2] > 5e-3);
  for (int i = 0; i < 4; i++) {
    double top[3], bottom[3] = {corner[i][0], corner[i][1], 0.2}, d[3], L = 0;
    for (int j = 0; j < 3; j++) {
      snprintf(cn, sizeof cn, "%s.%c", name[i], "xyz"[j]);
      top[j] = r.first[col(m, cn)];
      d[j] = top[j] - bottom[j];
      L += d[j] * d[j];
    }
    L = sqrt(L);
    double push = k * (L0 - L); /* compression pushes the body up along the spring */
    double F[3], arm[3];
    for (int j = 0; j < 3; j++) { F[j] = push * d[j] / L; sum[j] += F[j]; arm[j] = top[j] - cg[j]; }
    moment[0] += arm[1] * F[2] - arm[2] * F[1];
    moment[1] += arm[2] * F[0] - arm[0] * F[2];
    moment[2] += arm[0] * F[1] - arm[1] * F[0];
    /* rigid plate on equal springs, linear statics */
    double closed = W / 4 + W * xc * corner[i][0] / (4 * a * a) + W * yc * corner[i][1] / (4 * b * b);
    print_message("car: spring %s load %.6f N, closed form %.6f N\n", name[i], F[2], closed);
    worst_closed = fmax(worst_closed, fabs(F[2] - closed));
  }
  print_message("car: sum of the spring forces (%.9g, %.9g, %.9g) N, weight %.9g N; moment about the "
                "centre of mass (%.3g, %.3g, %.3g) N m; worst load against the closed form %.3g N\n",
                sum[0], sum[1], sum[2], W, moment[0], moment[1], moment[2], worst_closed);
  assert_close(sum[2], W, 1e-6 * W);
  assert_true(fabs(sum[0]) < 1e-6 * W && fabs(sum[1]) < 1e-6 * W);
  for (int j = 0; j < 3; j++) assert_true(fabs(moment[j]) < 1e-6 * W * a);
  /* the linear closed form neglects the squares of rotations of about
     1e-3 rad (measured: 2e-9 of the weight) */
  assert_true(worst_closed < 1e-6 * W);
  /* then at rest for 1 s */
  assert_true(r.nrows == 101);
  assert_true(r.drift < 1e-6);
  assert_true(info.force_residual < 1e-9);
  rows_free(&r);
}

/* ---------------------------------------------------------------------------
 * The pendulum (tests/models/equilibrium_pendulum.yaml): 2 kg at l = 1 m,
 * released 30 degrees off the vertical.
 * ------------------------------------------------------------------------- */
static void test_pendulum_hangs(void **state) {
  (void)state;
  const mb_model *m = &equilibrium_pendulum_model;
  mb_equilibrium_info info;
  rows r;
  double q0[256], qe[256];
  settle_and_run(m, 1.0, &info, &r, q0, qe);
  double x = r.first[col(m, "bob_position.x")], y = r.first[col(m, "bob_position.y")];
  double angle = r.first[col(m, "angle")];
  double fx = r.first[col(m, "pivot_force.fx")], fy = r.first[col(m, "pivot_force.fy")];
  print_message("pendulum: bob at (%.3g, %.12g), turned by %.12g rad (-pi/6 = %.12g), pivot force "
                "(%.3g, %.12g) N\n", x, y, angle, -MB_PI / 6, fx, fy);
  assert_true(fabs(x) < 1e-9);
  assert_close(y, -1.0, 1e-9);
  assert_close(angle, -MB_PI / 6, 1e-9);
  assert_true(fabs(fx) < 1e-9 * 2 * 9.81);
  assert_close(fabs(fy), 2 * 9.81, 1e-9 * 2 * 9.81);
  assert_true(r.drift < 1e-6);
  rows_free(&r);
}

/* ---------------------------------------------------------------------------
 * The slider-crank (tests/models/equilibrium_slider_crank.yaml): r = 0.1 m,
 * l = 0.3 m, torque T = 15 N m on the crank, spring k = 2000 N/m of free
 * length 0.45 m from the slider to (1, 0, 0); the crank starts at 60 deg.
 * ------------------------------------------------------------------------- */
static void test_slider_crank_spring(void **state) {
  (void)state;
  const mb_model *m = &equilibrium_slider_crank_model;
  const double rc = 0.1, l = 0.3, T = 15, k = 2000, L0 = 0.45, theta0 = MB_PI / 3;
  mb_equilibrium_info info;
  rows r;
  double q0[256], qe[256];
  settle_and_run(m, 0.5, &info, &r, q0, qe);
  double theta = theta0 + r.first[col(m, "crank_angle")], x = r.first[col(m, "slider_x")];
  double s = sin(theta), c = cos(theta), root = sqrt(l * l - rc * rc * s * s);
  double x_closed = rc * c + root;
  double dx_dtheta = -rc * s - rc * rc * s * c / root;
  double tension = k * ((1 - x) - L0); /* pulls the slider towards +x */
  double virtual_work = T + tension * dx_dtheta;
  print_message("slider-crank: crank at %.9f rad (from %.9f), slider at %.12g (closed form %.12g), "
                "T + F dx/dtheta = %.3g N m of T = %g N m\n", theta, theta0, x, x_closed, virtual_work, T);
  assert_true(fabs(theta - theta0) > 0.1);
  assert_close(x, x_closed, 1e-9);
  assert_true(fabs(virtual_work) < 1e-6 * T);
  assert_true(r.drift < 1e-6);
  rows_free(&r);
}

/* ---------------------------------------------------------------------------
 * The flexible cantilever (tests/models/cantilever_gravity.yaml): L = 1 m,
 * A = 4e-4 m^2, Iz = 3e-8 m^4, E = 2e10 Pa, rho = 2700 kg/m^3, g = 9.81 m/s^2
 * along -y; the body frame welded to the ground at node 0 (axes global).
 * ------------------------------------------------------------------------- */
static void test_cantilever_static(void **state) {
  (void)state;
  const mb_model *m = &cantilever_gravity_model;
  mb_equilibrium_info info;
  rows r;
  double q0[256], qe[256];
  settle_and_run(m, 0.2, &info, &r, q0, qe);
  const mb_body *B = &m->body[0];
  const mb_flex *fx = B->flex;
  assert_non_null(fx);
  /* modal statics: omega_j^2 w_j = S1_j . (A^T g), A = I */
  assert_close(qe[B->qadr + 3], 1.0, 1e-12);
  double wmax = 0, worst = 0;
  for (int j = 0; j < B->nm; j++) wmax = fmax(wmax, fabs(qe[B->qadr + 7 + j]));
  for (int j = 0; j < B->nm; j++) {
    double load = 0;
    for (int i = 0; i < 3; i++) load += (double)fx->S1[3 * j + i] * (double)m->gravity[i];
    double w = load / (double)fx->stiffness[j];
    worst = fmax(worst, fabs(qe[B->qadr + 7 + j] - w));
  }
  double q = 2700 * 4e-4 * 9.81, exact = q / (8 * 2e10 * 3e-8);
  double tip = -r.first[col(m, "tip.y")];
  print_message("cantilever: modal coordinates against S1 . g / omega^2: worst difference %.3g of %.3g; "
                "tip deflection %.6g m, closed form q L^4 / (8 E I) %.6g m (%+.3g)\n", worst, wmax, tip,
                exact, tip / exact - 1);
  assert_true(wmax > 0 && q0[B->qadr + 7] == 0);
  assert_true(worst < 1e-9 * wmax);
  /* 3 y-bending modes and lumped nodal loads: 0.35 % over (test_flexible.c) */
  assert_true(fabs(tip - exact) < 0.01 * exact);
  assert_true(r.drift < 1e-6 * exact);
  rows_free(&r);
}

/* ---------------------------------------------------------------------------
 * The command line
 * ------------------------------------------------------------------------- */
static void test_cli_model_setting(void **state) {
  (void)state;
  char dir[] = "/tmp/mbcc_equilibrium_XXXXXX", cmd[1024], out[8192];
  assert_non_null(mkdtemp(dir));
  /* scene 'settled' has simulation: {equilibrium: true}: the generated simulator settles it */
  snprintf(cmd, sizeof cmd, "%s run tests/models/equilibrium_pendulum.yaml --scene settled --end 0.1 "
           "-o %s/p.csv --plot none 2>&1", mbcc(), dir);
  int rc = run_capture(cmd, out, sizeof out);
  if (rc) print_error("%s", out);
  assert_int_equal(rc, 0);
  assert_non_null(strstr(out, "static equilibrium in "));
  assert_non_null(strstr(out, "force residual"));
  char path[256];
  snprintf(path, sizeof path, "%s/p.csv", dir);
  FILE *f = fopen(path, "r");
  assert_non_null(f);
  char header[512], first[512];
  assert_non_null(fgets(header, sizeof header, f));
  assert_non_null(fgets(first, sizeof first, f));
  fclose(f);
  double t, angle, x, y;
  assert_int_equal(sscanf(first, "%lf,%lf,%lf,%lf", &t, &angle, &x, &y), 4);
  assert_true(fabs(x) < 1e-9 && fabs(y + 1) < 1e-9);
  /* the base model does not ask for it: the bob starts where the file puts it */
  snprintf(cmd, sizeof cmd, "%s run tests/models/equilibrium_pendulum.yaml --path generic --end 0.1 "
           "-o %s/b.csv --plot none 2>&1", mbcc(), dir);
  rc = run_capture(cmd, out, sizeof out);
  assert_int_equal(rc, 0);
  assert_null(strstr(out, "static equilibrium"));
  /* models/pendulum.yaml starts horizontal, a turning point of its potential
     (zero curvature: no Newton step): damped steps take it down */
  snprintf(cmd, sizeof cmd, "%s run models/pendulum.yaml --path generic --equilibrium --end 0.1 "
           "-o %s/h.csv --plot none 2>&1", mbcc(), dir);
  rc = run_capture(cmd, out, sizeof out);
  print_message("horizontal pendulum: %s", out);
  assert_int_equal(rc, 0);
  assert_non_null(strstr(out, "damped steps past a turning point"));
  snprintf(path, sizeof path, "%s/h.csv", dir);
  f = fopen(path, "r");
  assert_non_null(f);
  assert_non_null(fgets(header, sizeof header, f));
  assert_non_null(fgets(first, sizeof first, f));
  fclose(f);
  assert_int_equal(sscanf(first, "%lf,%lf,%lf,%lf", &t, &angle, &x, &y), 4);
  print_message("horizontal pendulum: settled at (%.3g, %.12g), turned by %.12g rad\n", x, y, angle);
  assert_true(fabs(x) < 1e-9 && fabs(y + 1) < 1e-9);
  assert_close(angle, -MB_PI / 2, 1e-9);
  snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
  assert_int_equal(system(cmd), 0);
}

static void test_cli_no_equilibrium(void **state) {
  (void)state;
  char dir[] = "/tmp/mbcc_equilibrium_XXXXXX", cmd[1024], out[8192], path[256];
  assert_non_null(mkdtemp(dir));
  snprintf(path, sizeof path, "%s/free.csv", dir);
  snprintf(cmd, sizeof cmd, "%s run tests/models/equilibrium_free.yaml --path generic --equilibrium "
           "-o %s --plot none 2>&1", mbcc(), path);
  int rc = run_capture(cmd, out, sizeof out);
  print_message("free body: exit %d: %s", rc, out);
  assert_true(rc != 0);
  assert_non_null(strstr(out, "error: static equilibrium: no equilibrium"));
  assert_non_null(strstr(out, "body 'box', translation z"));
  assert_non_null(strstr(out, "no results written"));
  assert_int_equal(access(path, F_OK), -1);
  /* without --equilibrium the same model falls freely and runs */
  snprintf(cmd, sizeof cmd, "%s run tests/models/equilibrium_free.yaml --path generic -o %s --plot none "
           "2>&1", mbcc(), path);
  assert_int_equal(run_capture(cmd, out, sizeof out), 0);
  assert_int_equal(access(path, F_OK), 0);
  snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
  assert_int_equal(system(cmd), 0);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_car_on_springs),
      cmocka_unit_test(test_pendulum_hangs),
      cmocka_unit_test(test_slider_crank_spring),
      cmocka_unit_test(test_cantilever_static),
      cmocka_unit_test(test_cli_model_setting),
      cmocka_unit_test(test_cli_no_equilibrium),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
