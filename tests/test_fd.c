/* test_fd.c: the generated constraint Jacobian D, gamma and nu against
 * finite differences of phi and of D v at random configurations, for every
 * joint type and driver profile; generalized spring forces against finite
 * differences of the potential energy; M and the gyroscopic forces against
 * hand-derived values; the generated evaluation against the generic one. */
// models: fd_all fd_springs spatial_joints slider_crank slider_crank_flexible slider_crank_flexible@virtual2 free_flexible free_flexible_stiff fd_node_twins
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "support.h"
#include "fd_all.h"
#include "fd_springs.h"
#include "spatial_joints.h"
#include "slider_crank.h"
#include "slider_crank_flexible.h"
#include "slider_crank_flexible_virtual2.h"
#include "free_flexible.h"
#include "free_flexible_stiff.h"
#include "fd_node_twins.h"

typedef struct {
  const mb_model *m;
  double *Kx, *rhs, *phi, *nu;
  void *work;
} evaluator;

static void ev_init(evaluator *e, const mb_model *m) {
  e->m = m;
  e->Kx = calloc((size_t)m->nnz + 1, sizeof(double));
  e->rhs = calloc((size_t)m->n + 1, sizeof(double));
  e->phi = calloc((size_t)m->nc + 1, sizeof(double));
  e->nu = calloc((size_t)m->nc + 1, sizeof(double));
  e->work = malloc(mb_model_worksize(m) + 16);
  assert_non_null(e->Kx);
  assert_non_null(e->work);
}

static void ev_free(evaluator *e) {
  free(e->Kx); free(e->rhs); free(e->phi); free(e->nu); free(e->work);
}

static void ev(evaluator *e, double t, const double *q, const double *v) {
  e->m->init(e->m, e->Kx);
  e->m->eval(e->m, t, q, v, e->Kx, e->rhs, e->phi, e->nu, e->work);
}

/* D (nc x nv, row-major) from the constraint rows of K */
static void dense_D(const mb_model *m, const double *Kx, double *D) {
  memset(D, 0, sizeof(double) * (size_t)m->nc * (size_t)m->nv);
  for (int c = 0; c < m->nv; c++)
    for (int p = m->Kp[c]; p < m->Kp[c + 1]; p++)
      if (m->Ki[p] >= m->nv) D[(size_t)(m->Ki[p] - m->nv) * (size_t)m->nv + (size_t)c] = Kx[p];
}

/* the largest nodal displacement or rotation of mode j per unit modal coordinate */
static double shape_scale(const mb_body *B, int j) {
  double mx = 1e-300;
  const mb_flex *f = B->flex;
  for (int k = 0; k < f->nnode; k++)
    for (int i = 0; i < 3; i++) {
      mx = fmax(mx, fabs(f->node_X[3 * (k * f->nm + j) + i]));
      mx = fmax(mx, fabs(f->node_Psi[3 * (k * f->nm + j) + i]));
    }
  return mx;
}

/* the finite-difference step of velocity coordinate i: 1e-6 of a unit
   translation or rotation, and likewise for a modal coordinate */
static double fd_step(const mb_model *m, int i) {
  for (int b = 0; b < m->nbody; b++) {
    const mb_body *B = &m->body[b];
    if (i >= B->vadr + 6 && i < B->vadr + 6 + B->nm) return 1e-6 / shape_scale(B, i - B->vadr - 6);
  }
  return 1e-6;
}

/* a random state: positions in [-1, 1], unit Euler parameters, velocities in [-2, 2] */
static void random_state(const mb_model *m, double *q, double *v) {
  for (int b = 0; b < m->nbody; b++) {
    double *qb = q + m->body[b].qadr, n = 0;
    for (int j = 0; j < 3; j++) qb[j] = urand(-1, 1);
    for (int j = 0; j < 4; j++) { qb[3 + j] = urand(-1, 1); n += qb[3 + j] * qb[3 + j]; }
    for (int j = 0; j < 4; j++) qb[3 + j] /= sqrt(n);
    for (int j = 0; j < m->body[b].nm; j++) /* modal amplitudes: shape-scaled deformations of ~1e-2 */
      qb[7 + j] = urand(-1e-2, 1e-2) / shape_scale(&m->body[b], j);
  }
  for (int j = 0; j < m->nv; j++) v[j] = urand(-2, 2);
  for (int b = 0; b < m->nbody; b++) /* modal rates: deformation rates of ~1 per second */
    for (int j = 0; j < m->body[b].nm; j++) v[m->body[b].vadr + 6 + j] /= shape_scale(&m->body[b], j);
}

/* q (+) s dv */
static void moved(const mb_model *m, const double *q, const double *dv, double s, double *out) {
  double *d = malloc(sizeof(double) * (size_t)m->nv);
  memcpy(out, q, sizeof(double) * (size_t)m->nq);
  for (int j = 0; j < m->nv; j++) d[j] = s * dv[j];
  mb_model_qincrement(m, out, d);
  free(d);
}

static void check_constraints(const mb_model *m, int trials) {
  evaluator e;
  ev_init(&e, m);
  int nq = m->nq, nv = m->nv, nc = m->nc;
  double *q = malloc(sizeof(double) * (size_t)nq), *v = malloc(sizeof(double) * (size_t)nv);
  double *qp = malloc(sizeof(double) * (size_t)nq), *qm = malloc(sizeof(double) * (size_t)nq);
  double *D = malloc(sizeof(double) * (size_t)(nc * nv + 1));
  double *phip = malloc(sizeof(double) * (size_t)(nc + 1)), *phim = malloc(sizeof(double) * (size_t)(nc + 1));
  double *cp = malloc(sizeof(double) * (size_t)(nc + 1)), *cm = malloc(sizeof(double) * (size_t)(nc + 1));
  double *ej = calloc((size_t)nv, sizeof(double));
  double *gamma = malloc(sizeof(double) * (size_t)(nc + 1)), *nu = malloc(sizeof(double) * (size_t)(nc + 1));
  double *Dv = malloc(sizeof(double) * (size_t)(nc + 1));
  const double h = 1e-6;
  double worst_D = 0, worst_g = 0, worst_nu = 0;
  for (int trial = 0; trial < trials; trial++) {
    random_state(m, q, v);
    double t = urand(0, 1.5);
    ev(&e, t, q, v);
    dense_D(m, e.Kx, D);
    memcpy(gamma, e.rhs + nv, sizeof(double) * (size_t)nc);
    memcpy(nu, e.nu, sizeof(double) * (size_t)nc);
    for (int r = 0; r < nc; r++) {
      Dv[r] = 0;
      for (int j = 0; j < nv; j++) Dv[r] += D[(size_t)r * (size_t)nv + (size_t)j] * v[j];
    }
    /* D: central differences of phi along each velocity coordinate */
    for (int j = 0; j < nv; j++) {
      memset(ej, 0, sizeof(double) * (size_t)nv);
      ej[j] = 1;
      double h = fd_step(m, j);
      moved(m, q, ej, h, qp);
      moved(m, q, ej, -h, qm);
      ev(&e, t, qp, v);
      memcpy(phip, e.phi, sizeof(double) * (size_t)nc);
      ev(&e, t, qm, v);
      memcpy(phim, e.phi, sizeof(double) * (size_t)nc);
      for (int r = 0; r < nc; r++) {
        /* errors relative to the row's scale along this coordinate */
        double fd = (phip[r] - phim[r]) / (2 * h), an = D[(size_t)r * (size_t)nv + (size_t)j];
        double err = fabs(fd - an) * h / 1e-6 / (1 + fabs(an) * h / 1e-6);
        if (err > worst_D) worst_D = err;
        if (err > 1e-7) print_error("%s: D[%d][%d] = %.12g, finite difference %.12g\n", m->name, r, j, an, fd);
      }
    }
    /* phid = D v - nu: central difference of phi along (q (+) tau v, t + tau) */
    moved(m, q, v, h, qp);
    moved(m, q, v, -h, qm);
    ev(&e, t + h, qp, v);
    memcpy(phip, e.phi, sizeof(double) * (size_t)nc);
    ev(&e, t - h, qm, v);
    memcpy(phim, e.phi, sizeof(double) * (size_t)nc);
    for (int r = 0; r < nc; r++) {
      double fd = (phip[r] - phim[r]) / (2 * h), an = nu[r];
      double err = fabs(fd - an) / (1 + fabs(an));
      if (err > worst_nu) worst_nu = err;
      if (err > 1e-7) print_error("%s: phidot[%d] = %.12g, finite difference %.12g\n", m->name, r, an, fd);
    }
    /* phid = D v - nu, with D from K: nu = D v - phid must not depend on v */
    {
      double *v2 = malloc(sizeof(double) * (size_t)nv);
      for (int j = 0; j < nv; j++) v2[j] = urand(-2, 2);
      ev(&e, t, q, v2);
      for (int r = 0; r < nc; r++) {
        double Dv2 = 0;
        for (int j = 0; j < nv; j++) Dv2 += D[(size_t)r * (size_t)nv + (size_t)j] * v2[j];
        double nu1 = Dv[r] - nu[r], nu2 = Dv2 - e.nu[r];
        double err = fabs(nu1 - nu2) / (1 + fabs(nu1));
        if (err > worst_nu) worst_nu = err;
        if (err > 1e-9) print_error("%s: nu[%d] depends on v: %.12g vs %.12g\n", m->name, r, nu1, nu2);
      }
      free(v2);
    }
    /* gamma = -d/dt (D v - nu) at constant v */
    ev(&e, t + h, qp, v);
    for (int r = 0; r < nc; r++) cp[r] = e.nu[r];
    ev(&e, t - h, qm, v);
    for (int r = 0; r < nc; r++) cm[r] = e.nu[r];
    for (int r = 0; r < nc; r++) {
      double fd = -(cp[r] - cm[r]) / (2 * h);
      double err = fabs(fd - gamma[r]) / (1 + fabs(gamma[r]));
      if (err > worst_g) worst_g = err;
      if (err > 1e-6) print_error("%s: gamma[%d] = %.12g, finite difference %.12g\n", m->name, r, gamma[r], fd);
    }
  }
  print_message("%s: %d rows, worst relative error: D %.2e, nu %.2e, gamma %.2e\n", m->name, nc,
                worst_D, worst_nu, worst_g);
  /* central differences with h = 1e-6: truncation ~1e-12 x third derivative,
     round-off ~1e-16 / 1e-6 = 1e-10 per difference */
  assert_true(worst_D < 1e-7);
  assert_true(worst_nu < 1e-7);
  assert_true(worst_g < 1e-6);
  free(q); free(v); free(qp); free(qm); free(D); free(phip); free(phim); free(cp); free(cm);
  free(ej); free(gamma); free(nu); free(Dv);
  ev_free(&e);
}

static void test_constraints_all_joints(void **state) {
  (void)state;
  check_constraints(&fd_all_model, 5);
}

static void test_constraints_shipped(void **state) {
  (void)state;
  check_constraints(&spatial_joints_model, 3);
  check_constraints(&slider_crank_model, 3);
}

/* rows on flexible nodes (direct) and through virtual bodies */
static void test_constraints_flexible(void **state) {
  (void)state;
  check_constraints(&slider_crank_flexible_model, 3);
  check_constraints(&slider_crank_flexible_virtual2_model, 3);
  check_constraints(&fd_node_twins_model, 3); /* a revolute on a node: its rows' folded modal columns */
}

/* The flexible body's quadratic-velocity forces s against Lagrange's equations
 * evaluated by finite differences of its mass matrix M(q) (independent of how
 * s was derived):  r:  s_r = -d/dt(M_r. v);  w (true coordinates):
 * s_f = -d/dt(M_f. v) + dT/dw;  w' (quasi-velocities, Boltzmann-Hamel):
 * s_th = -d/dt(M_th. v) - w' x (M_th. v) + u x A^T rd, u = w' x S + S1 wd,
 * with T = 1/2 v^T M v and d/dt along q (+) tau v at constant v. */
static void flex_mass(const mb_flex *fx, const mb_flex_stiff *st, const double *q, const double *v, double *Mb,
                      double *fb) {
  static const double zero[3] = {0, 0, 0};
  mb_frame f;
  mb_frame_rigid(q, v, &f);
  mb_flex_body_stiff(fx, st, &f, q + 7, v + 6, zero, Mb, fb);
}

/* S = S0 + S1 w (+ the second-order part with geometric stiffening) */
static void flex_first_moment(const mb_flex *fx, const mb_flex_stiff *st, const double *w, double S[3]) {
  double dS[3];
  mb_modal3(fx->S1, fx->nm, w, S);
  mb_flex_stiff_S(st, fx, w, dS);
  for (int i = 0; i < 3; i++) S[i] += fx->S0[i] + dS[i];
}

static void check_flexible_inertia(const mb_model *m) {
  const mb_body *B = &m->body[0];
  const mb_flex *fx = B->flex;
  int nm = fx->nm, n = 6 + nm;
  double q[64], v[64], qp[64], qm[64], Mb[4096], Mp[4096], Mm[4096], fb[64], fp[64], worst = 0;
  assert_true(n <= 64);
  for (int trial = 0; trial < 5; trial++) {
    random_state(m, q, v);
    flex_mass(fx, B->stiff, q, v, Mb, fb);
    /* s = fb + K w + C wd (no gravity here) */
    double s[64];
    for (int i = 0; i < n; i++) s[i] = fb[i];
    for (int j = 0; j < nm; j++) s[6 + j] += fx->stiffness[j] * q[7 + j] + fx->damping[j] * v[6 + j];
    double h = 1e-6 / fmax(1, sqrt(mb_dot3(v + 3, v + 3)));
    moved(m, q, v, h, qp);
    moved(m, q, v, -h, qm);
    flex_mass(fx, B->stiff, qp, v, Mp, fp);
    flex_mass(fx, B->stiff, qm, v, Mm, fp);
    double dMv[64], Mv[64];
    for (int i = 0; i < n; i++) {
      dMv[i] = Mv[i] = 0;
      for (int l = 0; l < n; l++) {
        dMv[i] += (Mp[n * i + l] - Mm[n * i + l]) / (2 * h) * v[l];
        Mv[i] += Mb[n * i + l] * v[l];
      }
    }
    double ref[64];
    /* translation */
    for (int i = 0; i < 3; i++) ref[i] = -dMv[i];
    /* rotation: -d/dt(M_th. v) - w' x (M_th. v) + u x A^T rd */
    double A[9], S[3], S1wd[3], u[3], Ard[3], t1[3], t2[3];
    mb_euler_to_A(q + 3, A);
    flex_first_moment(fx, B->stiff, q + 7, S);
    { /* dS/dt = dS/dw wd by central differences */
      double wp[64], wm[64], Sp[3], Sm[3], e = 1e-4;
      for (int j = 0; j < nm; j++) { wp[j] = q[7 + j] + e * v[6 + j]; wm[j] = q[7 + j] - e * v[6 + j]; }
      flex_first_moment(fx, B->stiff, wp, Sp);
      flex_first_moment(fx, B->stiff, wm, Sm);
      for (int i = 0; i < 3; i++) S1wd[i] = (Sp[i] - Sm[i]) / (2 * e);
    }
    mb_cross3(v + 3, S, u);
    for (int i = 0; i < 3; i++) u[i] += S1wd[i];
    mb_mul3t(A, v, Ard);
    mb_cross3(v + 3, Mv + 3, t1);
    mb_cross3(u, Ard, t2);
    for (int i = 0; i < 3; i++) ref[3 + i] = -dMv[3 + i] - t1[i] + t2[i];
    /* modes: -d/dt(M_f. v) + dT/dw */
    for (int j = 0; j < nm; j++) {
      double e = 1e-6 / shape_scale(B, j), Tp = 0, Tm = 0;
      memcpy(qp, q, sizeof(double) * (size_t)m->nq);
      memcpy(qm, q, sizeof(double) * (size_t)m->nq);
      qp[7 + j] += e;
      qm[7 + j] -= e;
      flex_mass(fx, B->stiff, qp, v, Mp, fp);
      flex_mass(fx, B->stiff, qm, v, Mm, fp);
      for (int i = 0; i < n; i++)
        for (int l = 0; l < n; l++) {
          Tp += 0.5 * v[i] * Mp[n * i + l] * v[l];
          Tm += 0.5 * v[i] * Mm[n * i + l] * v[l];
        }
      ref[6 + j] = -dMv[6 + j] + (Tp - Tm) / (2 * e);
    }
    double scale = 0;
    for (int i = 0; i < n; i++) scale = fmax(scale, fabs(ref[i]));
    for (int i = 0; i < n; i++) {
      double err = fabs(s[i] - ref[i]) / scale;
      worst = fmax(worst, err);
      if (err > 1e-6) print_error("s[%d] = %.12g, from Lagrange's equations %.12g\n", i, s[i], ref[i]);
    }
  }
  print_message("%s: quadratic-velocity forces against Lagrange's equations: worst %.2e\n", m->name, worst);
  assert_true(worst < 1e-6);
}

static void test_flexible_inertia(void **state) {
  (void)state;
  check_flexible_inertia(&free_flexible_model);
  /* with geometric stiffening: its terms must be Lagrange's too, and present
     (the stiffening's share of the modal forces, so that this is no repeat) */
  check_flexible_inertia(&free_flexible_stiff_model);
  assert_non_null(free_flexible_stiff_model.body[0].stiff);
}

/* generalized forces of conservative elements = -dU/dq (v = 0: no damping, no gyroscopic terms) */
static void test_spring_forces(void **state) {
  (void)state;
  const mb_model *m = &fd_springs_model;
  evaluator e;
  ev_init(&e, m);
  double q[64], v[64] = {0}, qp[64], qm[64], ej[64], worst = 0;
  assert_true(m->nq <= 64);
  for (int trial = 0; trial < 5; trial++) {
    random_state(m, q, v);
    memset(v, 0, sizeof v);
    ev(&e, 0, q, v);
    for (int j = 0; j < m->nv; j++) {
      memset(ej, 0, sizeof ej);
      ej[j] = 1;
      const double h = 1e-6;
      double Tp, Up, Tm, Um;
      moved(m, q, ej, h, qp);
      moved(m, q, ej, -h, qm);
      mb_model_energy(m, 0, qp, v, &Tp, &Up, e.work);
      mb_model_energy(m, 0, qm, v, &Tm, &Um, e.work);
      double fd = -(Up - Um) / (2 * h);
      double err = fabs(fd - e.rhs[j]) / (1 + fabs(e.rhs[j]));
      if (err > worst) worst = err;
      if (err > 1e-6) print_error("generalized force %d = %.12g, -dU/dq = %.12g\n", j, e.rhs[j], fd);
    }
  }
  print_message("fd_springs: worst relative error of forces against -dU/dq: %.2e\n", worst);
  assert_true(worst < 1e-6);
  ev_free(&e);
}

/* M entries and the gyroscopic force -w' x (J w') of fd_all's body b5 (full inertia tensor) */
static void test_mass_and_gyroscopic(void **state) {
  (void)state;
  const mb_model *m = &fd_all_model;
  evaluator e;
  ev_init(&e, m);
  double q[64], v[64];
  random_state(m, q, v);
  ev(&e, 0, q, v);
  const mb_body *B = &m->body[4]; /* b5: m 0.7, J = [0.01 0.001 0.0005; 0.001 0.012 -0.002; 0.0005 -0.002 0.015] */
  const double J[9] = {0.01, 0.001, 0.0005, 0.001, 0.012, -0.002, 0.0005, -0.002, 0.015};
  assert_string_equal(B->name, "b5");
  for (int j = 0; j < 3; j++) assert_close(e.Kx[B->mslot[j]], 0.7, 0);
  for (int j = 0; j < 9; j++) assert_close(e.Kx[B->mslot[3 + j]], J[j], 0);
  const double *w = v + B->vadr + 3;
  double Jw[3] = {J[0] * w[0] + J[1] * w[1] + J[2] * w[2], J[3] * w[0] + J[4] * w[1] + J[5] * w[2],
                  J[6] * w[0] + J[7] * w[1] + J[8] * w[2]};
  double s[3] = {-(w[1] * Jw[2] - w[2] * Jw[1]), -(w[2] * Jw[0] - w[0] * Jw[2]), -(w[0] * Jw[1] - w[1] * Jw[0])};
  /* b5 carries no force element: its rhs is m g and the gyroscopic term */
  const double g[3] = {0.3, -9.81, 0.2};
  for (int j = 0; j < 3; j++) {
    assert_close(e.rhs[B->vadr + j], 0.7 * g[j], 1e-14);
    assert_close(e.rhs[B->vadr + 3 + j], s[j], 1e-13);
  }
  ev_free(&e);
}

/* the generated code and the generic table walk give the same numbers */
static void test_generated_equals_generic(void **state) {
  (void)state;
  const mb_model *models[] = {&fd_all_model, &fd_springs_model, &spatial_joints_model, &slider_crank_model,
                              &slider_crank_flexible_model, &slider_crank_flexible_virtual2_model,
                              &free_flexible_model, &free_flexible_stiff_model, &fd_node_twins_model};
  for (int k = 0; k < (int)(sizeof models / sizeof models[0]); k++) {
    const mb_model *m = models[k];
    mb_model g = generic_twin(m);
    evaluator a, b;
    ev_init(&a, m);
    ev_init(&b, &g);
    double *q = malloc(sizeof(double) * (size_t)m->nq), *v = malloc(sizeof(double) * (size_t)m->nv);
    double worst = 0;
    for (int trial = 0; trial < 5; trial++) {
      random_state(m, q, v);
      double t = urand(0, 1.5);
      ev(&a, t, q, v);
      ev(&b, t, q, v);
      for (int i = 0; i < m->nnz; i++) worst = fmax(worst, fabs(a.Kx[i] - b.Kx[i]) / (1 + fabs(b.Kx[i])));
      for (int i = 0; i < m->n; i++) worst = fmax(worst, fabs(a.rhs[i] - b.rhs[i]) / (1 + fabs(b.rhs[i])));
      for (int i = 0; i < m->nc; i++) {
        worst = fmax(worst, fabs(a.phi[i] - b.phi[i]));
        worst = fmax(worst, fabs(a.nu[i] - b.nu[i]));
      }
    }
    print_message("%s: generated vs generic, worst relative difference %.2e\n", m->name, worst);
    assert_true(worst < 1e-13);
    free(q); free(v);
    ev_free(&a);
    ev_free(&b);
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_constraints_all_joints),
      cmocka_unit_test(test_constraints_shipped),
      cmocka_unit_test(test_constraints_flexible),
      cmocka_unit_test(test_spring_forces),
      cmocka_unit_test(test_flexible_inertia),
      cmocka_unit_test(test_mass_and_gyroscopic),
      cmocka_unit_test(test_generated_equals_generic),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
