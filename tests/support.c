/* support.c: test helpers (see support.h). */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>

#include "support.h"

void test_settings(mb_settings *s, double end_time, double output_step) {
  mb_settings_default(s);
  s->integrator = MB_DOPRI5;
  s->end_time = end_time;
  s->output_step = output_step;
  s->max_step = output_step;
  s->step = output_step / 10;
  s->rtol = 1e-9;
  s->atol = 1e-11;
}

typedef struct {
  const mb_model *m;
  trajectory *tr;
  int cap;
  double *prev;
  int have_prev;
  void *work;
} collector;

static int collect(void *user, double t, const double *q, const double *v, const double *vd,
                   const double *lambda) {
  collector *c = user;
  trajectory *tr = c->tr;
  if (tr->nrows == c->cap) {
    c->cap = c->cap ? 2 * c->cap : 256;
    tr->t = realloc(tr->t, sizeof(double) * (size_t)c->cap);
    tr->y = realloc(tr->y, sizeof(double) * (size_t)c->cap * (size_t)(tr->ncols + 1));
    if (!tr->t || !tr->y) return 1;
  }
  double *row = tr->y + (size_t)tr->nrows * (size_t)tr->ncols;
  mb_model_outputs(c->m, t, q, v, vd, lambda, c->have_prev ? c->prev : NULL, row, c->work);
  memcpy(c->prev, row, sizeof(double) * (size_t)tr->ncols);
  c->have_prev = 1;
  tr->t[tr->nrows++] = t;
  return 0;
}

int simulate(const mb_model *m, const mb_settings *s, const char *solver, trajectory *out) {
  memset(out, 0, sizeof *out);
  out->ncols = m->ncols;
  mb_solver *ls = mb_solver_new(solver, m);
  if (!ls) return MB_ERR_INVALID;
  collector c = {m, out, 0, calloc((size_t)m->ncols + 1, sizeof(double)), 0,
                 malloc(mb_model_worksize(m) + 16)};
  mb_sim sim;
  int st = mb_sim_init(&sim, m, ls, s);
  if (!st) st = mb_sim_run(&sim, collect, &c);
  out->status = st;
  out->fail_time = sim.fail_time;
  out->stats = sim.stats;
  mb_sim_free(&sim);
  ls->destroy(ls);
  free(c.prev);
  free(c.work);
  return st;
}

void trajectory_free(trajectory *tr) {
  free(tr->t);
  free(tr->y);
  memset(tr, 0, sizeof *tr);
}

int column(const mb_model *m, const char *name) {
  for (int j = 0; j < m->ncols; j++)
    if (!strcmp(m->col_name[j], name)) return j;
  return -1;
}

int run_capture(const char *cmd, char *out, size_t n) {
  char full[8192];
  snprintf(full, sizeof full, "%s 2>&1", cmd);
  FILE *p = popen(full, "r");
  if (!p) return -1;
  size_t k = 0;
  int ch;
  while ((ch = fgetc(p)) != EOF)
    if (k + 1 < n) out[k++] = (char)ch;
  if (n) out[k] = 0;
  int st = pclose(p);
  return WIFEXITED(st) ? WEXITSTATUS(st) : 128;
}

mb_model generic_twin(const mb_model *m) {
  mb_model g = *m;
  g.eval = mb_generic_eval;
  g.init = mb_generic_init;
  return g;
}

static uint64_t rng_state = 0x9E3779B97F4A7C15ull;
double urand(double a, double b) {
  rng_state ^= rng_state << 13;
  rng_state ^= rng_state >> 7;
  rng_state ^= rng_state << 17;
  return a + (b - a) * (double)(rng_state >> 11) / 9007199254740992.0;
}

double max_rel_diff(const mb_model *m, const trajectory *a, const trajectory *b,
                    const char **worst_col) {
  assert_int_equal(a->nrows, b->nrows);
  double worst = 0;
  if (worst_col) *worst_col = "";
  for (int c = 0; c < m->ncols; c++) {
    double lo = INFINITY, hi = -INFINITY, d = 0;
    for (int k = 0; k < a->nrows; k++) {
      lo = fmin(lo, at(a, k, c));
      hi = fmax(hi, at(a, k, c));
      d = fmax(d, fabs(at(a, k, c) - at(b, k, c)));
    }
    double r = d / fmax(hi - lo, 1e-3);
    if (!(r <= worst)) {
      worst = r;
      if (worst_col) *worst_col = m->col_name[c];
    }
  }
  for (int k = 0; k < a->nrows; k++) assert_true(a->t[k] == b->t[k]);
  return worst;
}

/* r = b - K x; returns ||r||_inf / (||K||_inf ||x||_inf + ||b||_inf) */
double k_rel_residual(const mb_model *m, const double *Kx, const double *x, const double *b) {
  int n = m->n;
  double *r = malloc(sizeof(double) * (size_t)n), *rs = calloc((size_t)n, sizeof(double));
  assert_non_null(r);
  assert_non_null(rs);
  memcpy(r, b, sizeof(double) * (size_t)n);
  for (int j = 0; j < n; j++)
    for (int p = m->Kp[j]; p < m->Kp[j + 1]; p++) {
      r[m->Ki[p]] -= Kx[p] * x[j];
      rs[m->Ki[p]] += fabs(Kx[p]);
    }
  double rn = 0, xn = 0, bn = 0, kn = 0;
  for (int i = 0; i < n; i++) {
    rn = fmax(rn, fabs(r[i]));
    xn = fmax(xn, fabs(x[i]));
    bn = fmax(bn, fabs(b[i]));
    kn = fmax(kn, rs[i]);
  }
  free(r);
  free(rs);
  return rn / (kn * xn + bn);
}

/* Kx and the right side at a state near q0: positions moved by a random
 * velocity-space increment (exact rotations), random velocities */
void k_near_q0(const mb_model *m, int k, double *Kx, double *rhs, void *work) {
  double *q = malloc(sizeof(double) * (size_t)m->nq), *v = malloc(sizeof(double) * (size_t)m->nv);
  double *dv = malloc(sizeof(double) * (size_t)m->nv);
  double *phi = malloc(sizeof(double) * (size_t)(m->nc + 1)), *nu = malloc(sizeof(double) * (size_t)(m->nc + 1));
  assert_true(q && v && dv && phi && nu);
  memcpy(q, m->q0, sizeof(double) * (size_t)m->nq);
  for (int i = 0; i < m->nv; i++) {
    dv[i] = k ? urand(-0.05, 0.05) : 0;
    v[i] = urand(-1, 1);
  }
  mb_model_qincrement(m, q, dv);
  mb_model_normalize(m, q);
  m->init(m, Kx);
  m->eval(m, 0.01 * k, q, v, Kx, rhs, phi, nu, work);
  free(q); free(v); free(dv); free(phi); free(nu);
}
